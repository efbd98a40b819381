//! Photon-map view (`--show photon-map`): the radiance the photon map predicts at each
//! visible point, L = ρ/π · E(x) (no emission), for debugging the map and for comparing it
//! with a full reference: it is what the final gather reads at its secondary points.

use crate::film::Film;
use crate::frame::FrameBinding;
use crate::gbuffer::{GBUFFER_FILM_WGSL, GBufferPass, gbuffer_film_bind_group, gbuffer_film_layout};
use crate::gpu::{Gpu, dispatch_pixels};
use crate::gpu_scene::GpuScene;
use crate::photons::gpu::GpuPhotonMap;
use crate::photons::map::LOOKUP_WGSL;
use crate::profile::{Profiler, compute_pass};
use crate::shader;

/// The pass's composed shader.
pub fn source() -> String {
    shader::per_pixel(&[GBUFFER_FILM_WGSL, LOOKUP_WGSL, include_str!("photon_view.wgsl")])
}

pub struct PhotonViewPass {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    profiler: Option<Profiler>,
    label: &'static str,
}

/// What a [`PhotonViewPass`] adds to the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhotonView {
    /// ρ/π · E(x) of the whole map → the photon-view component (`--show photon-map`).
    Map,
    /// ρ/π · E_caustic(x) of the caustic twins → the indirect component: the caustic term of
    /// every render of a scene with perfect mirrors or smooth glass.
    Caustics,
}

impl PhotonViewPass {
    pub fn new(
        gpu: &Gpu,
        scene: &GpuScene,
        frame: &FrameBinding,
        gbuffer: &GBufferPass,
        film: &Film,
        map: &GpuPhotonMap,
        view: PhotonView,
    ) -> Self {
        let device = &gpu.device;
        let (label, entry) = match view {
            PhotonView::Map => ("photon view", "main"),
            PhotonView::Caustics => ("caustics", "caustics"),
        };
        let module = shader::module(device, label, &source());
        let layout = gbuffer_film_layout(device, label);
        let bind_group = gbuffer_film_bind_group(device, label, &layout, gbuffer, film);
        let pipeline = scene.compute_pipeline(
            device,
            label,
            &module,
            entry,
            &[&scene.layout, &frame.layout, &layout, &map.bind_layout],
        );
        Self { pipeline, bind_group, profiler: gpu.profiler.clone(), label }
    }

    /// Reads: scene, frame, G-buffer, photon map. Adds to: the film's photon-map component, or
    /// its indirect component (caustics).
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        frame: &FrameBinding,
        map: &GpuPhotonMap,
        width: u32,
        height: u32,
    ) {
        let mut pass = compute_pass(enc, self.profiler.as_ref(), self.label);
        let bind_groups = [&scene.bind_group, &frame.bind_group, &self.bind_group, &map.bind_group];
        dispatch_pixels(&mut pass, &self.pipeline, &bind_groups, width, height);
    }
}
