//! Direct pass: emitted radiance of the visible point plus direct light from the area
//! lights, with soft shadows from shadow rays traced against the BVH.
//!
//! For a visible point x with normal n and albedo ρ, each of the K light samples picks an
//! emitter point y with density p(y) = pmf(triangle)/area(triangle) and adds
//!
//! ```text
//!   (1/K) · (ρ/π) · Le(y) · V(x,y) · max(0, n·ω) · max(0, n_y·(−ω)) / |y − x|² / p(y)
//! ```
//!
//! (ω = (y − x)/|y − x|), an unbiased estimate of ∫ (ρ/π) Le cos θ_x cos θ_y / r² V dA.
//! Light samples are fresh every iteration, so penumbrae converge with the image.

use crate::film::Film;
use crate::frame::FrameBinding;
use crate::gbuffer::{GBUFFER_FILM_WGSL, GBufferPass, gbuffer_film_bind_group, gbuffer_film_layout};
use crate::gpu::{Gpu, compute_pipeline, dispatch_pixels};
use crate::gpu_scene::GpuScene;
use crate::profile::{Profiler, compute_pass};
use crate::shader;

/// The pass's composed shader.
pub fn source() -> String {
    shader::per_pixel(&[GBUFFER_FILM_WGSL, include_str!("direct.wgsl")])
}

pub struct DirectPass {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    profiler: Option<Profiler>,
}

impl DirectPass {
    pub fn new(gpu: &Gpu, scene: &GpuScene, frame: &FrameBinding, gbuffer: &GBufferPass, film: &Film) -> Self {
        let device = &gpu.device;
        let module = shader::module(device, "direct", &source());
        let layout = gbuffer_film_layout(device, "direct");
        let bind_group = gbuffer_film_bind_group(device, "direct", &layout, gbuffer, film);
        let pipeline = compute_pipeline(device, "direct", &module, "main", &[&scene.layout, &frame.layout, &layout]);
        Self { pipeline, bind_group, profiler: gpu.profiler.clone() }
    }

    /// Reads: scene, frame, G-buffer. Adds to: the film's direct component.
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        frame: &FrameBinding,
        width: u32,
        height: u32,
    ) {
        let mut pass = compute_pass(enc, self.profiler.as_ref(), "direct");
        dispatch_pixels(
            &mut pass,
            &self.pipeline,
            &[&scene.bind_group, &frame.bind_group, &self.bind_group],
            width,
            height,
        );
    }
}
