//! The start-up probe of `--rays auto`: [`GpuScene::new`] uploads the scene, then measures the
//! ray kernel ([`super::RayCaster`]) on both traversals and keeps the faster.

use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu::accel::{RayPath, Rays};
use crate::gpu_scene::GpuScene;
use crate::surface::PreparedScene;

use super::{RayCaster, RayKind, make_rays};

impl GpuScene {
    /// Uploads `prepared` (`GpuScene::upload`) and, under `--rays auto` where the device has ray
    /// queries, chooses the ray path by the start-up [`probe`].
    pub fn new(gpu: &Gpu, prepared: &PreparedScene) -> Result<GpuScene> {
        let mut scene = GpuScene::upload(gpu, prepared)?;
        if gpu.rays == Rays::Auto && scene.accel.is_some() {
            let (compute, hardware) = probe(gpu, prepared, &scene)?;
            let rate = |s: f64| format!("{:.1} Mrays/s", PROBE_RAYS as f64 / s / 1e6);
            scene.rays = if hardware <= compute { RayPath::Hardware } else { RayPath::Compute };
            scene.rays_why = if compute > 0.0 {
                format!(
                    "auto: the start-up probe measured hardware {} against compute {} on this scene",
                    rate(hardware),
                    rate(compute)
                )
            } else {
                "auto: offered, and the scene gave the probe no rays (its camera sees nothing, it has no lights)"
                    .to_owned()
            };
        }
        log::info!("rays: {} ({})", scene.rays.name(), scene.rays_why);
        // The probe's rays are not the render's.
        if let Some(count) = &scene.ray_count {
            gpu.queue.write_buffer(count, 0, &[0; 24]);
        }
        Ok(scene)
    }
}

/// How many rays the start-up probe of `--rays auto` traces on each path.
pub const PROBE_RAYS: u32 = 128 * 128;

/// The start-up probe of `--rays auto` (`GpuScene::new`): the seconds the ray kernel takes
/// on each path, (compute, hardware), to trace the scene's bounce rays from its camera's view at
/// 128² (incoherent closest hits, the passes' commonest), the faster of two timed runs after
/// a warm-up each; a scene whose camera sees nothing probes with its photon rays.
pub fn probe(gpu: &Gpu, prepared: &PreparedScene, scene: &GpuScene) -> Result<(f64, f64)> {
    let side = (PROBE_RAYS as f64).sqrt() as u32;
    let mut rays = make_rays(prepared, &prepared.scene.camera, (side, side), RayKind::Bounce, 1);
    if rays.is_empty() {
        rays = make_rays(prepared, &prepared.scene.camera, (side, side), RayKind::Photon, 1);
    }
    if rays.is_empty() {
        return Ok((0.0, 0.0));
    }
    let mut seconds = [0.0; 2];
    for (path, s) in [RayPath::Compute, RayPath::Hardware].into_iter().zip(&mut seconds) {
        let (_, times) = RayCaster::on(gpu, scene, path).trace(gpu, scene, &rays, 2)?;
        *s = times.iter().map(|t| t.as_secs_f64()).fold(f64::INFINITY, f64::min);
    }
    // Per PROBE_RAYS rays, whatever the batch held.
    let scale = PROBE_RAYS as f64 / rays.len() as f64;
    Ok((seconds[0] * scale, seconds[1] * scale))
}
