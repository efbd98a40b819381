//! `rastergi bench frames`: frames per second of the viewer's frame loop, without a window.
//!
//! A frame does the viewer's per-frame GPU work: its batch of iterations
//! ([`crate::view::iterate_frame`]: as many as fit in [`FRAME_BUDGET`] at the last frame's
//! time per iteration, 1 to [`MAX_BATCH`]), the resolve of the display image and the display
//! pass with a four-line overlay, drawn into a texture of the window's size instead of a
//! swapchain image ([`OffscreenTarget`]): nothing is presented, so there is no vsync and the
//! figure is what the GPU sustains. The renderer has the viewer's settings (photons and grid
//! fitted to the scene, the photon-map view accumulated, `--gather auto`).
//!
//! Two phases of `--seconds` each, after a warm-up that lets `auto` choose its gather: the
//! viewer's batched loop, then one iteration per frame (a viewer that shows every iteration).

use std::time::Instant;

use anyhow::Result;
use clap::Args;
use rastergi::display::OffscreenTarget;
use rastergi::film::Show;
use rastergi::fit;
use rastergi::gather::GatherMethod;
use rastergi::gpu::Gpu;
use rastergi::renderer::{RenderSettings, Renderer};

use super::load_valid_scene;
use crate::args::{GatherArg, GpuArgs, gpu};
use crate::view::{FRAME_BUDGET, MAX_BATCH, iterate_frame};

#[derive(Args, Debug)]
pub struct FramesArgs {
    #[arg(default_value = "cornell")]
    scene: String,
    /// The window's width in pixels.
    #[arg(long, default_value_t = 1920)]
    width: u32,
    /// The window's height in pixels.
    #[arg(long, default_value_t = 1080)]
    height: u32,
    /// Timed seconds of each phase (batched, then one iteration per frame).
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Photons traced (default: fitted to the scene, as `view` does).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    photons: Option<u32>,
    /// Photon grid cells along the scene's longest axis (default: fitted, as `view` does).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    grid: Option<u32>,
    /// The gather implementation (as `view --gather`).
    #[arg(long, value_enum, default_value_t = GatherArg::Auto)]
    gather: GatherArg,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// The headless viewer: renderer, offscreen window and the batch of the next frame.
struct Loop {
    gpu: Gpu,
    renderer: Renderer,
    target: OffscreenTarget,
    batch: u32,
}

impl Loop {
    /// One frame with at most `limit` iterations (the viewer's batch where `limit` is
    /// `u32::MAX`); returns the iterations it ran.
    fn frame(&mut self, limit: u32) -> Result<u32> {
        let done = iterate_frame(&mut self.renderer, self.batch.min(limit), &mut self.batch)?;
        let overlay = vec![
            format!("bench frames  {}x{}", self.renderer.settings().width, self.renderer.settings().height),
            format!("iterations {}  ({} per frame)", self.renderer.samples(), done),
            format!("gather {:?}", self.renderer.gather_method()),
            "show full [1-4]  exposure +0.0 EV [+/-]".to_owned(),
        ];
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        self.renderer.encode_resolve(&mut enc, Show::Full, 0.0);
        self.target.draw(&self.gpu, enc, Some(self.renderer.film()), &overlay);
        Ok(done)
    }

    /// Frames for `seconds` with at most `limit` iterations each: (frames, iterations,
    /// seconds). The last frame's display work is waited for.
    fn run(&mut self, seconds: f64, limit: u32) -> Result<(u32, u32, f64)> {
        let start = Instant::now();
        let (mut frames, mut iterations) = (0, 0);
        while frames == 0 || start.elapsed().as_secs_f64() < seconds {
            iterations += self.frame(limit)?;
            frames += 1;
        }
        self.gpu.wait()?;
        Ok((frames, iterations, start.elapsed().as_secs_f64()))
    }
}

pub fn run(a: &FramesArgs) -> Result<()> {
    anyhow::ensure!(a.seconds.is_finite() && a.seconds > 0.0, "--seconds must be positive, got {}", a.seconds);
    let scene = load_valid_scene(&a.scene)?;
    let gpu = gpu(&a.gpu)?;
    let grid = a.grid.unwrap_or_else(|| fit::grid_resolution(&scene.bounds()));
    let photons = a.photons.unwrap_or_else(|| fit::photon_count(&scene, grid));
    let settings = RenderSettings {
        width: a.width,
        height: a.height,
        photons,
        grid_resolution: grid,
        show_photon_map: true,
        gather: a.gather.method(),
        ..Default::default()
    };
    let start = Instant::now();
    let renderer = Renderer::new(&gpu, &scene, settings)?;
    renderer.wait()?;
    let setup = start.elapsed().as_secs_f64();
    let target = OffscreenTarget::new(&gpu, a.width, a.height)?;
    println!(
        "viewer frame loop (no window): {} at {}x{} on {} ({:?}), {photons} photons, grid {grid}, bundle {}",
        a.scene,
        a.width,
        a.height,
        gpu.info.name,
        gpu.info.backend,
        renderer.bundle()
    );
    println!(
        "  a frame: iterations batched to {} ms (1 to {MAX_BATCH}), resolve, display pass into an offscreen {}x{} texture; no present, no vsync",
        FRAME_BUDGET.as_millis(),
        a.width,
        a.height
    );
    let mut l = Loop { gpu, renderer, target, batch: 1 };
    // Warm-up: `auto` times its gathers on the first iterations; the batch size settles.
    let start = Instant::now();
    let mut warm = 0;
    while warm < 3 || (l.renderer.photon_map().is_some() && l.renderer.gather_method() == GatherMethod::Auto) {
        l.frame(u32::MAX)?;
        warm += 1;
    }
    l.gpu.wait()?;
    println!(
        "  set-up {setup:.2} s; warm-up {warm} frames in {:.2} s; gather {:?}",
        start.elapsed().as_secs_f64(),
        l.renderer.gather_method()
    );
    for (name, limit) in [("viewer's batches", u32::MAX), ("one iteration per frame", 1)] {
        let (frames, iterations, seconds) = l.run(a.seconds, limit)?;
        println!(
            "  {name:<24} {:>8.2} frames/s  {:>8.2} iterations/s  ({frames} frames, {iterations} iterations in {seconds:.2} s; {:.1} ms per frame)",
            frames as f64 / seconds,
            iterations as f64 / seconds,
            1e3 * seconds / frames as f64
        );
    }
    Ok(())
}
