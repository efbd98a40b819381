//! `rastergi bench frames`: frames per second of the viewer's frame loop, without a window.
//!
//! A frame does a viewer's per-frame work with whole iterations: its batch of iterations
//! ([`iterate_frame`]: as many as fit in [`FRAME_BUDGET`] at the last frame's time per
//! iteration, 1 to [`MAX_BATCH`]; the viewer's loop before its frame budget, whose frames
//! `rastergi bench motion` times), the resolve of the display image, the display
//! pass and the control panel (its egui pass, tessellation and egui-wgpu drawing), into a
//! texture of the window's size instead of a swapchain image ([`DisplayTarget::offscreen`]): nothing
//! is presented, so there is no vsync and the figure is what the GPU sustains. The renderer
//! has the viewer's settings (photons and grid fitted to the scene, the photon-map view
//! accumulated, `--gather auto`).
//!
//! Three phases of `--seconds` each, after a warm-up that lets `auto` choose its gather: the
//! viewer's batched loop with the panel, the same without it (H), then one iteration per
//! frame (a viewer that shows every iteration) with the panel.

use std::time::{Duration, Instant};

use anyhow::Result;
use clap::Args;
use rastergi::camera_control::CameraControl;
use rastergi::fit;
use rastergi::gather::GatherMethod;
use rastergi::gpu::Gpu;
use rastergi::passes::display::DisplayTarget;
use rastergi::passes::film::Show;
use rastergi::progressive::Progressive;
use rastergi::renderer::Renderer;
use rastergi::settings::RenderSettings;

use super::window_scene_and_gpu;
use crate::args::{GatherArg, GpuArgs};
use crate::view::controls::Controls;
use crate::view::panel::{self, Figures, PanelPainter, PanelState};

#[derive(Args, Debug)]
pub struct FramesArgs {
    #[command(flatten)]
    window: super::WindowArgs,
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

/// The viewer's control panel without a window: egui fed an empty input of the window's
/// size each frame, drawn as the viewer draws it.
struct HeadlessPanel {
    ctx: egui::Context,
    painter: PanelPainter,
    state: PanelState,
    controls: Controls,
}

/// The headless viewer: renderer, offscreen window, panel and the batch of the next frame.
struct Loop {
    gpu: Gpu,
    renderer: Renderer,
    target: DisplayTarget,
    panel: HeadlessPanel,
    batch: u32,
}

impl Loop {
    /// One frame with at most `limit` iterations (the viewer's batch where `limit` is
    /// `u32::MAX`), the panel drawn or not; returns the iterations it ran.
    fn frame(&mut self, limit: u32, with_panel: bool) -> Result<u32> {
        let done = iterate_frame(&mut self.renderer, self.batch.min(limit), &mut self.batch)?;
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        self.renderer.encode_resolve(&mut enc, Show::Full, 0.0);
        let film = Some(self.renderer.film());
        if !with_panel {
            self.target.present(&self.gpu, enc, film, &[])?;
            return Ok(done);
        }
        let r = &self.renderer;
        let (w, h) = (r.settings().width, r.settings().height);
        let figures = Figures {
            scene: "bench frames",
            size: (w, h),
            samples: r.samples(),
            iterations_per_second: 0.0,
            error: None,
            error_is_rough: true,
            photon_pass: Some((r.photon_pass(), r.settings().photons)),
            gather_in_use: Some(r.gather_method()),
            memory: None,
            history: &[],
            status: "",
        };
        let p = &mut self.panel;
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(w as f32, h as f32))),
            ..Default::default()
        };
        let output = p.ctx.run_pass(input, |ctx| {
            panel::window(ctx, &p.controls, &figures, &mut p.state);
        });
        let (gpu, ctx, painter) = (&self.gpu, &p.ctx, &mut p.painter);
        self.target
            .present_with(gpu, enc, film, &[], |enc, view, size| painter.encode(gpu, ctx, output, enc, view, size))?;
        Ok(done)
    }

    /// Frames for `seconds` with at most `limit` iterations each: (frames, iterations,
    /// seconds). The last frame's display work is waited for.
    fn run(&mut self, seconds: f64, limit: u32, with_panel: bool) -> Result<(u32, u32, f64)> {
        let start = Instant::now();
        let (mut frames, mut iterations) = (0, 0);
        while frames == 0 || start.elapsed().as_secs_f64() < seconds {
            iterations += self.frame(limit, with_panel)?;
            frames += 1;
        }
        self.gpu.wait()?;
        Ok((frames, iterations, start.elapsed().as_secs_f64()))
    }
}

pub fn run(a: &FramesArgs) -> Result<()> {
    anyhow::ensure!(a.seconds.is_finite() && a.seconds > 0.0, "--seconds must be positive, got {}", a.seconds);
    let (scene, gpu) = window_scene_and_gpu(&a.window, &a.gpu)?;
    let grid = a.grid.unwrap_or_else(|| fit::grid_resolution(&scene.bounds()));
    let photons = a.photons.unwrap_or_else(|| fit::photon_count(&scene, grid));
    let settings = RenderSettings {
        width: a.window.width,
        height: a.window.height,
        photons,
        grid_resolution: grid,
        show_photon_map: true,
        gather: a.gather.method(),
        ..Default::default()
    };
    let start = Instant::now();
    let controls = Controls::new(CameraControl::new(&scene.camera, &scene.bounds()), Show::Full, 0.0, &settings);
    let renderer = Renderer::new(&gpu, &scene, settings)?;
    renderer.wait()?;
    let setup = start.elapsed().as_secs_f64();
    let target = DisplayTarget::offscreen(&gpu, a.window.width, a.window.height)?;
    let painter = PanelPainter::new(&gpu.device, target.format());
    let panel = HeadlessPanel { ctx: egui::Context::default(), painter, state: PanelState::default(), controls };
    println!(
        "viewer frame loop (no window): {} at {}x{} on {} ({:?}), {photons} photons, grid {grid}, bundle {}",
        a.window.scene,
        a.window.width,
        a.window.height,
        gpu.info.name,
        gpu.info.backend,
        renderer.bundle()
    );
    println!(
        "  a frame: iterations batched to {} ms (1 to {MAX_BATCH}), resolve, display pass and the control panel into an offscreen {}x{} texture; no present, no vsync",
        FRAME_BUDGET.as_millis(),
        a.window.width,
        a.window.height
    );
    let mut l = Loop { gpu, renderer, target, panel, batch: 1 };
    // Warm-up: `auto` times its gathers on the first iterations; the batch size settles.
    let start = Instant::now();
    let mut warm = 0;
    while warm < 3 || (l.renderer.photon_map().is_some() && l.renderer.gather_method() == GatherMethod::Auto) {
        l.frame(u32::MAX, true)?;
        warm += 1;
    }
    l.gpu.wait()?;
    println!(
        "  set-up {setup:.2} s; warm-up {warm} frames in {:.2} s; gather {:?}",
        start.elapsed().as_secs_f64(),
        l.renderer.gather_method()
    );
    let phases = [
        ("viewer's batches", u32::MAX, true),
        ("the same, panel hidden", u32::MAX, false),
        ("one iteration per frame", 1, true),
    ];
    let mut rates = Vec::new();
    for (name, limit, with_panel) in phases {
        let (frames, iterations, seconds) = l.run(a.seconds, limit, with_panel)?;
        rates.push((seconds / frames as f64, iterations as f64 / seconds));
        println!(
            "  {name:<24} {:>8.2} frames/s  {:>8.2} iterations/s  ({frames} frames, {iterations} iterations in {seconds:.2} s; {:.1} ms per frame)",
            frames as f64 / seconds,
            iterations as f64 / seconds,
            1e3 * seconds / frames as f64
        );
    }
    println!(
        "  the panel, batched, shown vs hidden: {:+.1} ms per frame, iterations/s x {:.3}",
        1e3 * (rates[0].0 - rates[1].0),
        rates[0].1 / rates[1].1
    );
    Ok(())
}

/// GPU time aimed at per displayed frame: iterations are batched up to this.
pub const FRAME_BUDGET: Duration = Duration::from_millis(30);
/// Most iterations in one frame (keeps a frame short when iterations are very cheap).
pub const MAX_BATCH: u32 = 64;

/// One frame's iterations: up to `limit`, stopping once [`FRAME_BUDGET`] has passed (so at
/// least one where `limit` > 0), then waits for them and sets `batch` (the next frame's
/// limit) to as many as fit in the budget at this frame's time per iteration, 1 to
/// [`MAX_BATCH`]. Returns how many ran.
pub fn iterate_frame(renderer: &mut dyn Progressive, limit: u32, batch: &mut u32) -> Result<u32> {
    let start = Instant::now();
    let mut done = 0;
    while done < limit {
        renderer.iterate()?;
        done += 1;
        if start.elapsed() >= FRAME_BUDGET {
            break;
        }
    }
    if done > 0 {
        renderer.wait()?;
        let per_iteration = start.elapsed().as_secs_f64() / done as f64;
        *batch = ((FRAME_BUDGET.as_secs_f64() / per_iteration.max(1e-6)) as u32).clamp(1, MAX_BATCH);
    }
    Ok(done)
}
