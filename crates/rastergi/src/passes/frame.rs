//! Per-iteration uniforms shared by the eye passes (bind group 1, `frame.wgsl`): the jittered
//! camera, the image size, the iteration index and the seed.

use glam::{Mat4, Vec2, Vec3};

use crate::gpu::Gpu;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu_scene::GpuScene;
use crate::sampling::{pcg_hash, sobol_owen_2d, stream, unit_f32};
use crate::scene::{Aabb, Camera};

gpu_struct! {
    /// The per-iteration uniforms (bind group 1, `frame.wgsl`).
    pub struct FrameUniforms as "Frame" {
        /// World → clip, including this iteration's sub-pixel jitter.
        pub view_proj: [[f32; 4]; 4] as "mat4x4f",
        /// Its inverse (camera rays: `camera_ray` in `frame.wgsl`).
        pub inv_view_proj: [[f32; 4]; 4] as "mat4x4f",
        pub eye: [f32; 3],
        pub iteration: u32,
        pub resolution: [u32; 2],
        pub seed: u32,
        pub light_samples: u32,
        /// Minimum hit distance and origin offset of secondary rays.
        pub ray_epsilon: f32,
        /// The final gather's directions per pixel this iteration (0: no gather), and 1 where each
        /// visible point draws them from its own scattering (per-pixel: cosine-distributed on a
        /// Lambertian surface, by the BSDF elsewhere) rather than uniform on the hemisphere
        /// (shared): the gather's escaping rays and the direct pass's environment samples are
        /// combined by multiple importance sampling (`env_gather_weight`, `gather_density`).
        pub gather_count: u32,
        pub gather_importance: u32,
        /// 1 where the eye's specular chains ran this iteration ([`crate::passes::specular`]): the visible
        /// points are read through `eye_paths`.
        pub eye_chains: u32,
        /// 1 where the eye's visible points read textures at their footprint's level of detail,
        /// 0 where at level 0 ([`crate::settings::TextureFilter`]).
        pub texture_footprint: u32,
        /// 1 where the traced gather's per-pixel directions are guided by what it learned
        /// ([`crate::gather::guide`]): the direct pass weighs its environment samples against the
        /// guided density.
        pub gather_guided: u32,
        /// The rows of this dispatch: an iteration may run as row bands, one dispatch of
        /// `band_rows × width` pixels from row `band_y0` each
        /// ([`crate::renderer::Renderer::iterate_rows`]; `band_pixel`, `begin_pixel` in
        /// `frame.wgsl`); 0 and the height for a whole iteration.
        pub band_y0: u32,
        pub band_rows: u32,
        /// The index of this iteration's first light sample in each pixel's sequence: the light
        /// samples of the film's iterations before it (`iteration · light_samples` for a fixed
        /// count; [`crate::passes::light_budget`] where the count changes), so that a pixel's
        /// samples are always a prefix of its sequence.
        pub light_base: u32,
        /// n where the emission the eye sees is supersampled by n × n sub-pixel rays at the
        /// pixels on an emitter's edge (`seen_emission` in `visible_point.wgsl`,
        /// [`crate::passes::emitter_edges`]); 0: off.
        pub emitter_edges: u32,
        /// This iteration's sub-pixel offset ([`pixel_jitter`]): the G-buffer's sample of pixel
        /// (x, y) lies at (x + ½, y + ½) + jitter on the image plane.
        pub jitter: [f32; 2],
    }
}

/// The per-iteration uniforms' WGSL: [`FrameUniforms`]' declaration, then `frame.wgsl` (its
/// bindings and the camera and random-stream helpers every pass of an iteration uses).
pub fn wgsl() -> String {
    [FrameUniforms::wgsl().as_str(), include_str!("frame.wgsl")].join("\n")
}

impl FrameUniforms {
    /// The uniforms of `iteration` of a `size` = (width, height) image of `scene` seen by
    /// `camera` with sub-pixel offset `jitter` ([`pixel_jitter`]): the renderer's and the path
    /// tracer's, so both see the same jittered view.
    pub fn new(
        camera: &Camera,
        size: (u32, u32),
        scene: &GpuScene,
        iteration: u32,
        jitter: Vec2,
        seed: u32,
        light_samples: u32,
    ) -> FrameUniforms {
        let (w, h) = size;
        let view_proj = view_projection(camera, w, h, near_plane(&scene.bounds), jitter);
        FrameUniforms {
            view_proj: view_proj.to_cols_array_2d(),
            // Inverted in f64: the f32 matrix the rasterizer uses, inverted without further loss.
            inv_view_proj: glam::DMat4::from_cols_array_2d(&view_proj.to_cols_array_2d().map(|c| c.map(f64::from)))
                .inverse()
                .to_cols_array_2d()
                .map(|c| c.map(|v| v as f32)),
            eye: camera.eye.into(),
            iteration,
            resolution: [w, h],
            seed,
            light_samples: light_samples.max(1),
            ray_epsilon: scene.ray_epsilon,
            gather_count: 0,
            gather_importance: 0,
            gather_guided: 0,
            eye_chains: 0,
            texture_footprint: 1,
            band_y0: 0,
            band_rows: h,
            light_base: iteration.wrapping_mul(light_samples.max(1)),
            emitter_edges: 0,
            jitter: jitter.into(),
        }
    }
}

/// The sub-pixel offset of iteration `i`, in [-½, ½)²: the Owen-scrambled Sobol' point of
/// index i ([`sobol_owen_2d`]) with the scramble seed `pcg_hash(seed ^ stream::PIXEL_JITTER)`,
/// less ½. One offset per iteration for the whole image (the G-buffer is rasterized), so
/// every pixel's samples are the same 2D sequence: each over random seeds is uniform on the
/// pixel, and every aligned block of 2^m iterations — the first 2^m in particular — is a
/// (0, m, 2)-net, one sample in each of the pixel's elementary cells of area 2^−m.
/// Averaging samples spread uniformly over the pixel is the box pixel filter.
pub fn pixel_jitter(iteration: u32, seed: u32) -> Vec2 {
    let [x, y] = sobol_owen_2d(iteration, pcg_hash(seed ^ stream::PIXEL_JITTER));
    Vec2::new(unit_f32(x), unit_f32(y)) - Vec2::splat(0.5)
}

/// Distance of the near plane for a scene with these bounds: small against the scene, and
/// harmless with reversed-Z depth.
pub fn near_plane(bounds: &Aabb) -> f32 {
    1e-4 * bounds.extent().length().max(1e-3)
}

/// World → clip for `camera` at `width × height`: right-handed view, reversed-Z infinite
/// perspective (depth 1 at the near plane, 0 at infinity). With it, pixel (x, y) (row 0 at
/// the top) samples the image plane at (x + 0.5 + jitter.x, y + 0.5 + jitter.y) pixels.
pub fn view_projection(camera: &Camera, width: u32, height: u32, near: f32, jitter: Vec2) -> Mat4 {
    let view = Mat4::look_at_rh(camera.eye, camera.target, camera.up);
    let aspect = width as f32 / height as f32;
    let proj = Mat4::perspective_infinite_reverse_rh(camera.fov_y_deg.to_radians(), aspect, near);
    // NDC spans 2 units per image side; +y is up in NDC and down in pixel rows. Moving the
    // scene by −jitter puts the sample at +jitter relative to the pixel centre.
    let shift = Mat4::from_translation(Vec3::new(-2.0 * jitter.x / width as f32, 2.0 * jitter.y / height as f32, 0.0));
    shift * proj * view
}

/// The uniform buffer, the eye paths of the specular chains ([`crate::passes::specular`]: per pixel
/// the origin of the ray that found the visible point, its throughput and the point itself)
/// and their bind group.
pub struct FrameBinding {
    pub buffer: wgpu::Buffer,
    pub eye_paths: wgpu::Buffer,
    /// Whose emitter-edge keys the eye paths hold ([`crate::passes::emitter_edges`]).
    pub edge_keys: std::cell::Cell<crate::passes::emitter_edges::EdgeKeys>,
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
}

/// Bind group 1 of every per-iteration pass: the frame's uniforms (read) and the eye paths
/// that the specular chains leave for later passes (written).
pub fn group() -> Group {
    Group::new(
        "frame",
        wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE,
        &[
            Slot::uniform::<FrameUniforms>(0, "frame"),
            Slot::write::<[f32; 4]>(1, "eye_paths").only(wgpu::ShaderStages::COMPUTE),
        ],
    )
}

fn bind(
    gpu: &Gpu,
    layout: &wgpu::BindGroupLayout,
    uniforms: &wgpu::Buffer,
    eye_paths: &wgpu::Buffer,
) -> wgpu::BindGroup {
    group().bind(
        &gpu.device,
        layout,
        &[("frame", uniforms.as_entire_binding()), ("eye_paths", eye_paths.as_entire_binding())],
    )
}

/// Bytes of a pixel's eye path: three vec4f (`eye_paths` in `frame.wgsl`).
pub const EYE_PATH_BYTES: u64 = 48;

impl FrameBinding {
    pub fn new(gpu: &Gpu) -> Self {
        let buffer = gpu.zeroed_buffer(
            "frame uniforms",
            std::mem::size_of::<FrameUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let eye_paths = gpu.zeroed_buffer("eye paths", EYE_PATH_BYTES, wgpu::BufferUsages::STORAGE);
        let group = group();
        let layout = group.layout(&gpu.device);
        let bind_group = bind(gpu, &layout, &buffer, &eye_paths);
        Self { buffer, eye_paths, edge_keys: Default::default(), layout, bind_group }
    }

    /// Makes room for the eye paths of `pixels` pixels.
    pub fn reserve_eye_paths(&mut self, gpu: &Gpu, pixels: u64) {
        let size = (pixels * EYE_PATH_BYTES).max(EYE_PATH_BYTES);
        if self.eye_paths.size() >= size {
            return;
        }
        self.eye_paths = gpu.zeroed_buffer("eye paths", size, wgpu::BufferUsages::STORAGE);
        self.edge_keys.take();
        self.bind_group = bind(gpu, &self.layout, &self.buffer, &self.eye_paths);
    }

    pub fn write(&self, gpu: &Gpu, u: &FrameUniforms) {
        gpu.queue.write_buffer(&self.buffer, 0, bytemuck::bytes_of(u));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::tests::is_net;

    #[test]
    fn jitter_covers_the_pixel_uniformly() {
        // Mean of a uniform variable on [-0.5, 0.5) is 0, its variance 1/12; the low
        // discrepancy sequence must reach both far closer than random sampling would
        // (whose standard errors at n = 1024 are 9e-3 and 2.3e-3).
        let n = 1024;
        for seed in [0, 17, 0xdead_beef] {
            let js: Vec<Vec2> = (0..n).map(|i| pixel_jitter(i, seed)).collect();
            let mean = js.iter().copied().sum::<Vec2>() / n as f32;
            let var = js.iter().map(|j| (*j - mean) * (*j - mean)).sum::<Vec2>() / n as f32;
            assert!(mean.abs().max_element() < 1e-3, "{mean}");
            assert!((var - Vec2::splat(1.0 / 12.0)).abs().max_element() < 2e-4, "{var}");
            assert!(js.iter().all(|j| j.cmpge(Vec2::splat(-0.5)).all() && j.cmplt(Vec2::splat(0.5)).all()));
        }
        // The seed moves the points.
        assert_ne!(pixel_jitter(0, 1), pixel_jitter(0, 2));
    }

    #[test]
    fn every_aligned_block_of_jitters_is_a_02_net_in_the_pixel() {
        for seed in [0, 17, 0xdead_beef] {
            for m in 0..=10u32 {
                for block in [0u32, 1, 5] {
                    let first = block << m;
                    // As 32-bit fractions: exact, the offsets are multiples of 2^−24.
                    let points: Vec<[u32; 2]> = (first..first + (1 << m))
                        .map(|i| {
                            (pixel_jitter(i, seed) + Vec2::splat(0.5)).to_array().map(|v| (v * 4_294_967_296.0) as u32)
                        })
                        .collect();
                    assert!(is_net(&points, m), "seed {seed}: iterations {first}.. (2^{m}) are not a (0,{m},2)-net");
                }
            }
        }
        // The check rejects a non-net: four points in the pixel's lower left quarter.
        let clump: Vec<[u32; 2]> = (0..4).map(|i| [i << 29, i << 29]).collect();
        assert!(!is_net(&clump, 2));
    }

    #[test]
    fn centre_of_view_projects_to_the_image_centre_and_red_wall_side_to_the_left() {
        let cam = Camera { eye: Vec3::new(0.0, 0.0, 3.9), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 39.3077 };
        let m = view_projection(&cam, 64, 64, 0.01, Vec2::ZERO);
        let c = m.project_point3(Vec3::ZERO);
        assert!(c.x.abs() < 1e-6 && c.y.abs() < 1e-6 && c.z > 0.0 && c.z < 1.0);
        assert!(m.project_point3(Vec3::new(-1.0, 0.0, 0.0)).x < 0.0, "-x must be on the left");
        assert!(m.project_point3(Vec3::new(0.0, 1.0, 0.0)).y > 0.0, "+y must be up");
        // The front edge of the side walls (z = 1) is at the edge of the 39.3° view at z = 1:
        // tan(19.65°) · 2.9 ≈ 1.036, so x = -1 projects just inside the left border.
        let edge = m.project_point3(Vec3::new(-1.0, 0.0, 1.0)).x;
        assert!((edge - (-1.0 / (2.9 * (39.3077f32 / 2.0).to_radians().tan()))).abs() < 1e-4);
    }
}
