//! Photon-map view (`--show photon-map`): the radiance the photon map predicts at each
//! visible point, L = ρ/π · E(x) (no emission), for debugging the map and for comparing it
//! with a full reference: it is what the final gather reads at its secondary points.

use crate::gpu::Gpu;
use crate::gpu_scene::GpuScene;
use crate::passes::film::Film;
use crate::passes::frame::FrameBinding;
use crate::passes::gbuffer::{GBUFFER_FILM_WGSL, GBufferPass, GroupThree, PixelPass, PixelShader};
use crate::photons::gpu::GpuPhotonMap;

/// The pass's composed shader.
pub fn source() -> String {
    crate::passes::per_pixel(&[
        GBUFFER_FILM_WGSL,
        &crate::photons::gpu::lookup_wgsl(),
        include_str!("photon_view.wgsl"),
    ])
}

/// What a photon-view [`pass`] adds to the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhotonView {
    /// ρ/π · E(x) of the whole map → the photon-view component (`--show photon-map`).
    Map,
    /// ρ/π · E_caustic(x) of the caustic twins → the indirect component: the caustic term of
    /// every render of a scene with perfect mirrors or smooth glass.
    Caustics,
}

/// The photon-view pass of `view`. Reads: scene, frame, G-buffer, photon map (bind group 3:
/// encode it with `&[&map.bind_group]`). Adds to: the film's photon-map component, or its
/// indirect component (caustics).
pub fn pass(
    gpu: &Gpu,
    scene: &GpuScene,
    frame: &FrameBinding,
    gbuffer: &GBufferPass,
    film: &Film,
    map: &GpuPhotonMap,
    view: PhotonView,
) -> PixelPass {
    let (label, entry) = match view {
        PhotonView::Map => ("photon view", "main"),
        PhotonView::Caustics => ("caustics", "caustics"),
    };
    let shader = PixelShader { label, source: &source(), entry };
    PixelPass::new(gpu, (scene, frame), (gbuffer, film), shader, GroupThree::PhotonMap(map))
}
