//! `rastergi bench denoise`: the cost of one application of the denoiser
//! ([`rastergi::passes::denoise`]) on the accumulated image of a scene, at the window's size.

use anyhow::Result;
use clap::Args;
use rastergi::passes::denoise::DenoiseParams;
use rastergi::progressive::Denoising;
use rastergi::renderer::Renderer;
use rastergi::settings::RenderSettings;

use super::window_scene_and_gpu;
use crate::args::GpuArgs;

#[derive(Args, Debug)]
pub struct DenoiseArgs {
    #[command(flatten)]
    window: super::WindowArgs,
    /// Iterations rendered before the timing (the filter's work does not depend on them).
    #[arg(long, default_value_t = 4)]
    iterations: u32,
    /// Applications timed.
    #[arg(long, default_value_t = 5)]
    repeats: u32,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(a: &DenoiseArgs) -> Result<()> {
    let (scene, gpu) = window_scene_and_gpu(&a.window, &a.gpu)?;
    let (w, h) = (a.window.width, a.window.height);
    let settings = RenderSettings { width: w, height: h, photons: 1 << 16, seed: 1, ..Default::default() };
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    r.enable_denoiser()?;
    for _ in 0..a.iterations.max(2) {
        r.iterate()?;
    }
    r.wait()?;
    let params = DenoiseParams::default();
    let apply = || -> Result<()> {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        r.encode_denoise(&mut enc, &params)?;
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        Ok(())
    };
    let (median, min, max) = super::milliseconds(a.repeats, apply)?;
    println!(
        "denoise: {} at {w}x{h} on {} ({:?}), {} levels: {:.1} ms per application (median of {}; min {:.1}, max {:.1})",
        a.window.scene,
        gpu.info.name,
        gpu.info.backend,
        params.levels,
        median,
        a.repeats.max(1),
        min,
        max
    );
    Ok(())
}
