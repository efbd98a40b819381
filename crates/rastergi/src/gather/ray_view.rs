//! The gather's ray view: an orthographic camera looking along −ω that encloses the scene's
//! bounding sphere, shifted by a sub-texel offset, shared by the raster gathers
//! ([`super::raster`], [`super::lists`]) and the bound on their fragment counts.
//!
//! * Radius: the bounding sphere of the scene's box, r = ½‖extent‖ · 1.001
//!   ([`ray_view_radius`]), so every triangle lies inside the view whatever ω.
//! * Projection: eye at c + 2r·ω looking at the centre c, depth range [r, 3r]: ray-view depth
//!   grows along −ω, so a gather ray leaving x along +ω meets surfaces of decreasing depth.
//! * Texel side s = 2r / bundle.
//!
//! `ray_view.wgsl` holds the raster stages (vertex pulling, the depth-complexity count, the
//! peel, the fragment lists); `ray_view_lookup.wgsl` the visible point's projection into the
//! view (a shadow-map lookup) and the plane test of a texel's triangle.

use glam::{Mat4, Vec2, Vec3};

use super::MAX_DIRECTIONS;
use super::estimator::{GatherSample, GatherUniforms, PixelSamples};
use crate::gpu::{scene_raster_pipeline, shader};
use crate::sampling::orthonormal_basis;
use crate::scene::Aabb;

/// Depth target of the peeling pass.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Radius of the ray view: the bounding sphere of `bounds` with a margin of 0.1 %.
pub fn ray_view_radius(bounds: &Aabb) -> f32 {
    (0.5 * bounds.extent().length()).max(1e-6) * 1.001
}

/// Side of a ray-view texel of a `bundle`² view over `bounds`: 2r / bundle.
pub fn texel_size(bounds: &Aabb, bundle: u32) -> f64 {
    2.0 * ray_view_radius(bounds) as f64 / bundle as f64
}

/// World → ray-view clip space for direction ω over `bounds`, shifted by `jitter` texels.
pub fn ray_view_projection(bounds: &Aabb, direction: Vec3, bundle: u32, jitter: Vec2) -> Mat4 {
    let center = bounds.center();
    let radius = ray_view_radius(bounds);
    let (_, b) = orthonormal_basis(direction);
    let eye = center + direction * 2.0 * radius;
    let view = Mat4::look_at_rh(eye, center, b);
    let proj = Mat4::orthographic_rh(-radius, radius, -radius, radius, radius, 3.0 * radius);
    let shift = Mat4::from_translation(Vec3::new(2.0 * jitter.x / bundle as f32, -2.0 * jitter.y / bundle as f32, 0.0));
    shift * proj * view
}

/// The ray-view raster shaders (`ray_view.wgsl`: the vertex stage and the count, peel and
/// list fragment stages), shared by the peeled and the fragment-list gathers.
pub fn ray_view_module(device: &wgpu::Device) -> wgpu::ShaderModule {
    shader::module(device, "gather ray view", &ray_view_source())
}

/// The composed source of [`ray_view_module`].
pub fn ray_view_source() -> String {
    let (scene, uniforms) = (crate::gpu_scene::wgsl(), super::estimator::uniforms_wgsl());
    shader::compose(&[shader::SAMPLING, &scene, &uniforms, include_str!("ray_view.wgsl")])
}

/// A ray-view raster pipeline ([`scene_raster_pipeline`]): fragment stage `fs` into a
/// `target` (format, write mask); with `depth`, a Depth32Float test that keeps the farthest
/// fragment (back to front: ray-view depth grows along −ω).
pub fn ray_view_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layouts: &[&wgpu::BindGroupLayout],
    fs: &str,
    target: (wgpu::TextureFormat, wgpu::ColorWrites),
    depth: bool,
) -> wgpu::RenderPipeline {
    let target = wgpu::ColorTargetState { format: target.0, blend: None, write_mask: target.1 };
    scene_raster_pipeline(device, label, (module, layouts), fs, target, depth.then_some(DEPTH_FORMAT))
}

/// The uniforms are built here, where the ray view is: the raster gathers read its matrix.
impl GatherUniforms {
    /// The uniforms for `samples` (sample indices `first_index` on) with sample `current` as
    /// the raster gathers' ray view of a `bundle`² view over `bounds`; with `pixel`, the
    /// traced gather's per-pixel directions.
    pub fn new(
        bounds: &Aabb,
        samples: &[GatherSample],
        current: usize,
        bundle: u32,
        first_index: u32,
        pixel: Option<PixelSamples>,
    ) -> GatherUniforms {
        let s = samples[current];
        let mut directions = [[0.0; 4]; MAX_DIRECTIONS as usize];
        for (d, s) in directions.iter_mut().zip(samples) {
            *d = s.direction.extend(0.0).into();
        }
        GatherUniforms {
            view_proj: ray_view_projection(bounds, s.direction, bundle, s.texel_jitter).to_cols_array_2d(),
            direction: s.direction.into(),
            bundle,
            count: samples.len() as u32,
            per_pixel: pixel.is_some() as u32,
            pixel_key: pixel.map_or(0, |p| p.key),
            first_index,
            current: current as u32,
            _pad: [0; 3],
            directions,
        }
    }
}
