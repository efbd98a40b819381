//! The final gather's estimator and what every implementation shares: the uniforms, the
//! resources a pass binds, and the per-pixel estimator pipeline.
//!
//! For a visible point x (normal n_x facing the eye, BSDF f, f = ρ_x/π on a Lambertian
//! surface) and a direction ω, with h the nearest surface along ω (t > ε, x's own triangle
//! excluded) and L(h → x) = (ρ_h/π) · E(h), E(h) the photon map's irradiance on the side of h
//! facing x (zero from the back of a one-sided h; emission is never added: the direct pass
//! owns it):
//!
//! ```text
//!   shared ω, uniform on the sphere; x gathers along w = sign(n_x·ω)·ω, uniform on its
//!   hemisphere (pdf 1/2π):             L_ind(x) ≈ f(ω_eye, w) · L(h → x) · (n_x·w) · 2π
//!   per-pixel w, drawn from x's own scattering (pdf p(w): cos θ_x/π on a Lambertian
//!   surface, the BSDF's sampling density of its non-specular lobes elsewhere):
//!                                      L_ind(x) ≈ f(ω_eye, w) cos θ_x / p(w) · L(h → x)
//!                                               = ρ_x · L(h → x) on a Lambertian surface
//! ```
//!
//! Both are unbiased for ∫ f(ω_eye, w) L(h → x) cos θ_x dω over the hemisphere (the specular
//! lobes are the eye chains'). `estimator.wgsl` holds `gather_estimate` (shared: every
//! implementation) and `gather_direction` (per-pixel: the traced gather only); each of an
//! iteration's K directions adds its estimate weighted 1/K.

use glam::{Vec2, Vec3};

use super::MAX_DIRECTIONS;
use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu_scene::GpuScene;
use crate::passes::film::Film;
use crate::passes::frame::FrameBinding;
use crate::passes::gbuffer::GBufferPass;
use crate::photons::gpu::GpuPhotonMap;

/// The gather's uniforms in WGSL (`struct Gather`, [`GatherUniforms`]), read by the ray-view
/// raster stages and the estimator passes.
pub fn uniforms_wgsl() -> String {
    GatherUniforms::wgsl()
}

/// `ray_view_texel` and `plane_distance` in WGSL, for the raster gathers' estimator passes.
pub const RAY_VIEW_LOOKUP: &str = include_str!("ray_view_lookup.wgsl");

gpu_struct! {
    /// The gather's uniforms (`struct Gather` in WGSL).
    pub struct GatherUniforms as "Gather" {
        /// Raster: the ray view of `direction`.
        pub view_proj: [[f32; 4]; 4] as "mat4x4f",
        /// Raster: the direction being rasterized.
        pub direction: [f32; 3],
        pub bundle: u32,
        /// Directions this iteration: each estimate is weighted 1/count.
        pub count: u32,
        /// Trace: 1 where each pixel draws its own directions ([`PixelSamples`]), else 0.
        pub per_pixel: u32,
        /// Trace, per-pixel: [`PixelSamples::key`].
        pub pixel_key: u32,
        /// The sample index of the iteration's first direction, i·K: direction k has index
        /// `first_index + k` (its per-pixel Sobol' point, its light sample at the hit).
        pub first_index: u32,
        /// Raster: the index among the iteration's directions of the ray view's.
        pub current: u32,
        pub _pad: [u32; 3],
        /// Trace, shared directions: all the iteration's directions (xyz).
        pub directions: [[f32; 4]; MAX_DIRECTIONS as usize] as "array<vec4f, MAX_DIRECTIONS>",
    }
}

/// One gather direction of an iteration: ω and the ray view's sub-texel offset.
#[derive(Clone, Copy, Debug)]
pub struct GatherSample {
    pub direction: Vec3,
    pub texel_jitter: Vec2,
}

/// Per-pixel directions of an iteration (the traced gather): pixel (x, y) takes the
/// Owen-scrambled Sobol' points `first_index` … `first_index + K − 1` with scramble seed
/// [`crate::sampling::pixel_seed`]`(key, x, y)`, each mapped to a cosine-distributed direction
/// about its normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelSamples {
    /// Keys the pixels' scramble seeds: one per seed and restart.
    pub key: u32,
    /// Sample index of the iteration's first direction: iteration · K.
    pub first_index: u32,
}

/// The composed shader of an estimator pass: the scene prelude, the visible point, the film
/// writes, the photon-map lookup, the uniforms, the estimator and `pieces`.
pub fn estimate_source(pieces: &[&str]) -> String {
    let (lookup, uniforms) = (crate::photons::gpu::lookup_wgsl(), uniforms_wgsl());
    let mut all = vec![
        lookup.as_str(),
        &uniforms,
        include_str!("estimator.wgsl"),
        super::guide::WGSL,
        super::guide::DENSITY_WGSL,
        crate::passes::sky_guide::WGSL,
    ];
    all.extend_from_slice(pieces);
    crate::passes::per_pixel(&all)
}

/// An estimate pass's bind group 2: the gather's uniforms and the G-buffer (bindings 0 and 1,
/// read), then `own` (from binding 2).
pub fn estimate_group(label: &'static str, own: &[Slot]) -> Group {
    let mut g =
        Group::compute(label, &[Slot::uniform::<GatherUniforms>(0, "gather"), Slot::uint_texture(1, "gbuffer")]);
    g.slots.extend_from_slice(own);
    g
}

/// The resources of [`estimate_group`]'s first two slots.
pub fn estimate_resources<'a>(
    uniforms: &'a wgpu::Buffer,
    gbuffer: &'a GBufferPass,
) -> [(&'static str, wgpu::BindingResource<'a>); 2] {
    [("gather", uniforms.as_entire_binding()), ("gbuffer", wgpu::BindingResource::TextureView(&gbuffer.view))]
}

/// What a gather's passes bind besides the [`GatherUniforms`], for building them: the scene,
/// the frame uniforms, the G-buffer (visible points), the film (indirect component) and the
/// photon map.
#[derive(Clone, Copy)]
pub struct GatherSetup<'a> {
    pub scene: &'a GpuScene,
    pub frame: &'a FrameBinding,
    pub gbuffer: &'a GBufferPass,
    pub film: &'a Film,
    pub map: &'a GpuPhotonMap,
}

impl GatherSetup<'_> {
    /// A per-pixel compute pipeline ending in the estimator ([`estimate_source`] of
    /// `pieces`); bind groups scene, frame, `own`, photon map.
    pub fn estimate_pipeline(
        &self,
        device: &wgpu::Device,
        label: &str,
        pieces: &[&str],
        own: &wgpu::BindGroupLayout,
    ) -> wgpu::ComputePipeline {
        let [pipeline] = self.estimate_pipelines(device, label, pieces, own, ["main"]);
        pipeline
    }

    /// [`GatherSetup::estimate_pipeline`] for each of `entries`, entry points of one module.
    pub fn estimate_pipelines<const N: usize>(
        &self,
        device: &wgpu::Device,
        label: &str,
        pieces: &[&str],
        own: &wgpu::BindGroupLayout,
        entries: [&str; N],
    ) -> [wgpu::ComputePipeline; N] {
        let module = self.scene.module(device, label, &estimate_source(pieces), crate::gpu_scene::RayUse::Gather);
        let layouts = [&self.scene.layout, &self.frame.layout, own, &self.map.bind_layout];
        entries.map(|entry| self.scene.compute_pipeline(device, label, &module, entry, &layouts))
    }
}

/// What a gather reads when it is encoded: the scene, the frame uniforms and the photon map
/// it was built with, the image size, the iteration's directions and the uniform buffer.
#[derive(Clone, Copy)]
pub struct GatherInputs<'a> {
    pub scene: &'a GpuScene,
    pub frame: &'a FrameBinding,
    pub map: &'a GpuPhotonMap,
    pub width: u32,
    pub height: u32,
    /// The rows of this dispatch ([`crate::passes::FrameContext::rows`]).
    pub rows: u32,
    /// The iteration's directions, 1 to [`MAX_DIRECTIONS`].
    pub samples: &'a [GatherSample],
    /// Where each pixel draws its own directions instead (then only `samples.len()` counts).
    pub pixel_samples: Option<PixelSamples>,
    /// The sample index of the iteration's first direction: iteration · K.
    pub first_index: u32,
    pub uniforms: &'a wgpu::Buffer,
    pub bundle: u32,
}

impl<'a> GatherInputs<'a> {
    /// The per-pixel pipeline's bind groups around `own`: scene, frame, `own`, photon map.
    pub fn groups(&self, own: &'a wgpu::BindGroup) -> [&'a wgpu::BindGroup; 4] {
        [&self.scene.bind_group, &self.frame.bind_group, own, &self.map.bind_group]
    }

    /// Writes the uniforms with sample `current` as the ray view. The write lands before the
    /// next submission: work already in an encoder sees it too.
    pub fn write_uniforms(&self, gpu: &Gpu, current: usize) {
        let u = GatherUniforms::new(
            &self.scene.bounds,
            self.samples,
            current,
            self.bundle,
            self.first_index,
            self.pixel_samples,
        );
        gpu.queue.write_buffer(self.uniforms, 0, bytemuck::bytes_of(&u));
    }

    /// Encodes `each(enc, k)` for every direction k of the iteration, one ray view after the
    /// other: the uniforms are written with k as the ray view before its work, and the work of
    /// direction k − 1 is submitted first, since it reads the uniforms written before it.
    pub fn for_each_direction(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        mut each: impl FnMut(&mut wgpu::CommandEncoder, usize) -> Result<()>,
    ) -> Result<()> {
        for k in 0..self.samples.len() {
            if k > 0 {
                submit_and_renew(gpu, enc, "gather");
            }
            self.write_uniforms(gpu, k);
            each(enc, k)?;
        }
        Ok(())
    }
}

/// Submits the work in `enc` and replaces it with a new encoder labelled `label`.
pub fn submit_and_renew(gpu: &Gpu, enc: &mut wgpu::CommandEncoder, label: &str) {
    let next = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    gpu.queue.submit([std::mem::replace(enc, next).finish()]);
}
