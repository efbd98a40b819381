//! The reference path tracer: a progressive GPU compute path tracer over the same scene, BVH,
//! camera, pixel jitter and film as the rasterizing renderer, the in-project ground truth the
//! fast passes are measured against.
//!
//! Each iteration traces one path per pixel from the eye through the pixel's centre in the
//! iteration's jittered view ([`pixel_jitter`], [`view_projection`]): the same ray the
//! G-buffer's pixel sees, so the mean over iterations is the same box-filtered image. Along
//! the path x₁, x₂, … (x₀ the eye) the estimate is
//!
//! ```text
//!   L = Σₖ Tₖ · [ w_σ,k · Le(xₖ → xₖ₋₁)  +  w_L,k · (ρₖ/π) · Le(yₖ) · V(xₖ,yₖ) · cos θₓ · cos θ_y / (|yₖ − xₖ|² · p_A(yₖ)) ]
//!   Tₖ = Π_{j<k} ρⱼ / qⱼ
//! ```
//!
//! - BSDF sampling: Lambertian BRDF ρ/π, directions with density p_σ(ω) = cos θ/π, so each
//!   bounce multiplies the throughput by f·cos θ/p_σ = ρ.
//! - Next-event estimation: one light sample per vertex from the light table
//!   (`sample_light_at`: a light by power; on an emissive triangle a point uniformly, density
//!   p_A(y) per area, p_L = p_A(y) · |y − x|² / cos θ_y per solid angle at x). Point, spot
//!   and distant lights (`crate::lights`) are reached by light samples only: their term is
//!   (ρₖ/π) · V · e · cos θₓ with weight 1 (e: I·s/(d²·pmf) or E/pmf, `sample_light_at`).
//! - Multiple importance sampling, power heuristic: for the light sample
//!   w_L = p_L² / (p_L² + p_σ²); for emission found by the BSDF-sampled direction from xₖ₋₁,
//!   w_σ = p_σ² / (p_σ² + p_L²) with both densities of that direction at xₖ₋₁. Emission
//!   seen by the camera ray has w_σ = 1 (no light sample competes for it).
//! - Russian roulette from the [`RR_START`]-th scattering event on: the path continues with
//!   probability q = max(ρ) (qⱼ = 1 before), and ends after [`MAX_BOUNCES`] events at the
//!   latest (a safety cap; the energy left there is ρ_max^1024, nothing for any albedo < 1).
//! - Emitters are one-sided (the front face, counter-clockwise, emits); a ray reaching the back
//!   of a one-sided surface is absorbed, a two-sided one reflects on both faces.
//! - Textured albedo: at x₁ the texture is read filtered over the pixel's footprint, its level
//!   of detail from ray differentials (the rays through the neighbouring pixels meet x₁'s plane
//!   where the G-buffer's screen-space derivatives would put them), so the reference sees the
//!   same filtered texture as the rasterizer's visible points; at x₂, x₃, … unfiltered
//!   (level 0), the exact albedo at the point, as the renderer's secondary points read it.
//!
//! The radiance is accumulated into component 0 of a [`Film`], whose other components stay
//! zero, so the film's resolve, EXR/PNG output and display work unchanged with [`Show::Full`].

use crate::checkpoint::Progress;
use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu::{Gpu, groups, shader};
use crate::gpu_scene::GpuScene;
use crate::image_io::{DisplayImage, LinearImage};
use crate::passes::film::{Film, FilmState, Show};
use crate::passes::frame::{FrameBinding, FrameUniforms, pixel_jitter};
use crate::progressive::Progressive;
use crate::scene::{Camera, Scene};
use crate::settings::RenderSettings;
use crate::surface::PreparedScene;

/// Scattering events after which every path ends (a safety cap; roulette ends them first).
pub const MAX_BOUNCES: u32 = 1024;
/// Index of the first scattering event (0 = the surface the camera sees) at which Russian
/// roulette may end the path.
pub const RR_START: u32 = 1;

gpu_struct! {
    /// The path tracer's uniforms (`path_tracer.wgsl`).
    pub struct PathParams as "PathParams" {
        /// Σ over the emissive triangles of area · (Le.r + Le.g + Le.b), the light table's
        /// normaliser: an emitter point with radiance Le has density (Le.r + Le.g + Le.b) / this.
        pub light_weight: f32,
        pub light_count: u32,
        /// Scattering events after which a path ends regardless of Russian roulette.
        pub max_bounces: u32,
        /// Russian roulette decides from the scattering event with this index (0 = primary
        /// hit) on.
        pub rr_start: u32,
    }
}

/// The path tracer's composed shader.
pub fn source() -> String {
    shader::compose(&[
        &PathParams::wgsl(),
        shader::SAMPLING,
        &crate::gpu_scene::wgsl(),
        shader::BVH,
        &crate::passes::frame::wgsl(),
        crate::passes::FILM,
        crate::passes::EYE_RAY,
        include_str!("path_tracer.wgsl"),
    ])
}

pub struct PathTracer {
    gpu: Gpu,
    settings: RenderSettings,
    camera: Camera,
    scene: GpuScene,
    frame: FrameBinding,
    film: Film,
    light_weight: f32,
    params: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    trace: wgpu::ComputePipeline,
    primary: wgpu::ComputePipeline,
}

/// The path tracer's bind group 2: the film written, the parameters read, the primary hits
/// written (by `primary_hits` only).
pub fn group() -> Group {
    Group::compute(
        "path tracer",
        &[
            Slot::write::<[f32; 4]>(0, "film"),
            Slot::uniform::<PathParams>(1, "params"),
            Slot::write::<[u32; 4]>(2, "visibility"),
        ],
    )
}

fn bind(
    gpu: &Gpu,
    layout: &wgpu::BindGroupLayout,
    film: &wgpu::Buffer,
    params: &wgpu::Buffer,
    visibility: &wgpu::Buffer,
) -> wgpu::BindGroup {
    let resources = [
        ("film", film.as_entire_binding()),
        ("params", params.as_entire_binding()),
        ("visibility", visibility.as_entire_binding()),
    ];
    group().bind(&gpu.device, layout, &resources)
}

impl PathTracer {
    /// Uploads `scene` and builds the pipeline. Of `settings`, the size and seed are used:
    /// every vertex takes one light sample, and no photon map is involved.
    pub fn new(gpu: &Gpu, scene: &Scene, settings: RenderSettings) -> Result<PathTracer> {
        scene.validate()?;
        let (width, height) = (settings.width, settings.height);
        let film = Film::new(gpu, width, height)?;
        crate::gpu_scene::check_scene(&gpu.device.limits(), scene)?;
        let prepared = PreparedScene::new(scene);
        prepared.textures.check_limits(gpu)?;
        let light_weight = prepared.lights.weight as f32;
        let gpu_scene = GpuScene::new(gpu, &prepared)?;
        let frame = FrameBinding::new(gpu);

        let device = &gpu.device;
        let layout = group().layout(device);
        let params = gpu.zeroed_buffer(
            "path tracer params",
            std::mem::size_of::<PathParams>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        // `main` does not write the visibility buffer; a placeholder fills its binding.
        let placeholder = gpu.zeroed_buffer("path tracer visibility placeholder", 16, wgpu::BufferUsages::STORAGE);
        let bind_group = bind(gpu, &layout, &film.accumulation, &params, &placeholder);
        let module = gpu_scene.module(device, "path tracer", &source(), crate::gpu_scene::RayUse::Eye);
        let layouts = [&gpu_scene.layout, &frame.layout, &layout];
        let trace = gpu_scene.compute_pipeline(device, "path tracer", &module, "main", &layouts);
        let primary = gpu_scene.compute_pipeline(device, "path tracer primary hits", &module, "primary_hits", &layouts);
        Ok(PathTracer {
            gpu: gpu.clone(),
            settings,
            camera: scene.camera,
            scene: gpu_scene,
            frame,
            film,
            light_weight,
            params,
            layout,
            bind_group,
            trace,
            primary,
        })
    }

    /// The uniforms of `iteration`: exactly the rasterizer's jittered view-projection
    /// (`Renderer`'s near plane, which the rays do not depend on) and its inverse.
    fn uniforms(&self, iteration: u32) -> (FrameUniforms, PathParams) {
        let (w, h) = (self.settings.width, self.settings.height);
        let jitter = pixel_jitter(iteration, self.settings.seed);
        // The path tracer takes one light sample per vertex.
        let mut frame = FrameUniforms::new(&self.camera, (w, h), &self.scene, iteration, jitter, self.settings.seed, 1);
        frame.texture_footprint = (self.settings.texture_filter == crate::settings::TextureFilter::Footprint) as u32;
        let params = PathParams {
            light_weight: self.light_weight,
            light_count: self.scene.light_count,
            max_bounces: MAX_BOUNCES,
            rr_start: RR_START,
        };
        (frame, params)
    }

    fn write_uniforms(&self, iteration: u32) {
        let (frame, params) = self.uniforms(iteration);
        self.frame.write(&self.gpu, &frame);
        self.gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
    }

    /// One progressive iteration: one path per pixel, added to the film.
    pub fn iterate(&mut self) {
        let (w, h) = (self.settings.width, self.settings.height);
        // The film's error estimate: blocks of BLOCK_ITERATIONS iterations.
        self.film.begin_iteration(&self.gpu, self.film.samples / crate::passes::film::BLOCK_ITERATIONS);
        self.write_uniforms(self.film.samples);
        let mut enc =
            self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("path tracer") });
        {
            let mut pass = crate::gpu::profile::compute_pass(&mut enc, self.gpu.profiler.as_ref(), "path tracer");
            pass.set_pipeline(&self.trace);
            pass.set_bind_group(0, &self.scene.bind_group, &[]);
            pass.set_bind_group(1, &self.frame.bind_group, &[]);
            pass.set_bind_group(2, &self.bind_group, &[]);
            pass.dispatch_workgroups(groups(w, 8), groups(h, 8), 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        self.film.samples += 1;
    }

    /// The mean radiance so far, linear RGB.
    pub fn read_linear(&self) -> Result<LinearImage> {
        self.film.read_linear(&self.gpu, Show::Full)
    }

    /// The display encoding of the mean: 2^exposure · mean, clamped, sRGB, 8 bits.
    pub fn read_display(&self, exposure: f32) -> Result<DisplayImage> {
        self.film.read_display(&self.gpu, Show::Full, exposure)
    }

    /// The first surface each camera ray of `iteration` hits, in the format of
    /// `Renderer::read_gbuffer` without the level of detail: `(triangle + 1, b1 bits, b2 bits,
    /// 0)` per pixel, row by row, 0 where the ray escapes; triangles in BVH order. The
    /// ray-traced twin of the G-buffer.
    pub fn primary_hits(&self, iteration: u32) -> Result<Vec<[u32; 4]>> {
        let (w, h) = (self.settings.width, self.settings.height);
        let size = w as u64 * h as u64 * 16;
        let visibility = self.gpu.zeroed_buffer(
            "path tracer visibility",
            size,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        );
        let bind_group = bind(&self.gpu, &self.layout, &self.film.accumulation, &self.params, &visibility);
        self.write_uniforms(iteration);
        let mut enc = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("path tracer primary hits") });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("path tracer primary hits"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.primary);
            pass.set_bind_group(0, &self.scene.bind_group, &[]);
            pass.set_bind_group(1, &self.frame.bind_group, &[]);
            pass.set_bind_group(2, &bind_group, &[]);
            pass.dispatch_workgroups(groups(w, 8), groups(h, 8), 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        let bytes = self.gpu.read_buffer(&visibility, size)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }
}

impl Progressive for PathTracer {
    fn name(&self) -> &'static str {
        "rastergi path tracer"
    }
    fn settings(&self) -> &RenderSettings {
        &self.settings
    }
    fn iterate(&mut self) -> Result<()> {
        PathTracer::iterate(self);
        Ok(())
    }
    fn wait(&self) -> Result<()> {
        self.gpu.wait()
    }
    /// Iterations (paths per pixel) accumulated since the last reset.
    fn rays_traced(&self) -> Result<Option<crate::gpu_scene::RaysTraced>> {
        self.scene.rays_traced(&self.gpu)
    }
    fn samples(&self) -> u32 {
        self.film.samples
    }
    fn camera(&self) -> Camera {
        self.camera
    }
    fn set_camera(&mut self, camera: Camera) -> Result<()> {
        camera.validate()?;
        self.camera = camera;
        self.reset();
        Ok(())
    }
    fn reset(&mut self) {
        self.film.clear(&self.gpu);
    }
    /// The film: the radiance sums in its full component.
    fn film(&self) -> &Film {
        &self.film
    }
    /// Only [`Show::Full`]: the path tracer does not split the image.
    fn has(&self, show: Show) -> bool {
        show == Show::Full
    }
    fn encode_resolve(&self, enc: &mut wgpu::CommandEncoder, _show: Show, exposure: f32) {
        self.film.encode_resolve(&self.gpu, enc, Show::Full, exposure);
    }
    fn read_linear(&self, _show: Show) -> Result<LinearImage> {
        PathTracer::read_linear(self)
    }
    fn read_display(&self, _show: Show, exposure: f32) -> Result<DisplayImage> {
        PathTracer::read_display(self, exposure)
    }
    fn progress(&self) -> Progress {
        Progress::default()
    }
    fn film_state(&self) -> Result<FilmState> {
        self.film.read_state(&self.gpu)
    }
    /// Continues from a checkpoint's film: the next iteration is the one after its last.
    fn resume(&mut self, _progress: &Progress, film: &FilmState) -> Result<()> {
        self.film.restore(&self.gpu, film)
    }
}
