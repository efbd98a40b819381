//! Specular chains from the eye (`specular.wgsl`): where the camera sees a perfect mirror or
//! glass (rough or smooth, without a diffuse base), its ray continues through such surfaces
//! (one direction drawn from the BSDF at each; at a smooth one a delta lobe: Fresnel picks
//! reflection or refraction, so the mean over iterations is the sum of both) to the first
//! other surface. That point is the pixel's visible point for
//! the direct light, the gather and the photon view, seen from the last ray's origin, and their
//! estimates are weighed by the chain's throughput (`visible_point_at` in
//! `visible_point.wgsl`). The pass runs after the G-buffer, only for scenes with such materials
//! ([`crate::scene::Material::passes_rays`]).
//!
//! A surface that mixes a delta lobe with a diffuse or glossy one (a smooth specular layer over
//! a diffuse base) stays the visible point; its delta reflection is not followed (stated in
//! docs/design.md).

use crate::gpu::Gpu;
use crate::gpu_scene::GpuScene;
use crate::passes::film::Film;
use crate::passes::frame::FrameBinding;
use crate::passes::gbuffer::{GBUFFER_FILM_WGSL, GBufferPass, GroupThree, PixelPass, PixelShader};

/// The pass's composed shader.
pub fn source() -> String {
    crate::passes::per_pixel(&[GBUFFER_FILM_WGSL, include_str!("specular.wgsl")])
}

/// The specular-chain pass. Reads: scene, frame, G-buffer. Writes: the eye paths. Adds to: the
/// film's direct component (the environment seen through the chains).
pub fn pass(gpu: &Gpu, scene: &GpuScene, frame: &FrameBinding, gbuffer: &GBufferPass, film: &Film) -> PixelPass {
    let shader = PixelShader { label: "specular chains", source: &source(), entry: "main" };
    PixelPass::new(gpu, (scene, frame), (gbuffer, film), shader, GroupThree::None)
}
