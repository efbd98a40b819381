//! `rastergi bench motion`: the viewer's loop through a scripted camera move, without a window.
//!
//! Each variant (the frame budget off — one whole iteration a frame, the viewer before issue
//! 58 — and on) runs the same script on its own renderer: the view held still for
//! `--still` seconds (the loop measures its costs, as a viewer does while one looks), then an
//! orbit of `--orbit` degrees about the target and a walk forward of a tenth of the scene's
//! diagonal, each over half of `--motion` seconds, the camera placed each frame where the
//! script is at that time (a slow frame makes a long step, as it does under a hand), then still
//! again. A frame is the viewer's: [`Interactive::frame`], the resolve when due and the display
//! pass into an offscreen texture of the window's size when due ([`Interactive::draw_due`]).
//!
//! Printed per variant: the frame times during the motion (median, and the 95th percentile on
//! a line with `p95 … ms`), the time from the last move to the first frame whose film holds a
//! whole iteration of the window, and the relative RMSE of what is shown (the linear image the
//! resolve wrote, previews blended in) against the converged view — a fresh render of the final
//! camera with another seed, `--reference-iterations` iterations (kept in `--reference`, an EXR,
//! to reuse) — 0.5, 1, 2 and 5 s after the camera stops. The read-backs of those images are not
//! counted in the times.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, ensure};
use clap::Args;
use rastergi::camera_control::CameraControl;
use rastergi::fit;
use rastergi::gpu::Gpu;
use rastergi::image_io::LinearImage;
use rastergi::passes::display::DisplayTarget;
use rastergi::passes::film::Show;
use rastergi::renderer::Renderer;
use rastergi::scene::{Camera, Scene};
use rastergi::session::args::LightSamplesArg;
use rastergi::session::interactive::Interactive;
use rastergi::session::refine::DEFAULT_FRAME_BUDGET;
use rastergi::settings::RenderSettings;

use super::window_scene_and_gpu;
use crate::args::{GatherArg, GpuArgs};

/// Seconds after the camera stops at which the shown image is compared with the converged view.
const MARKS: [f64; 4] = [0.5, 1.0, 2.0, 5.0];

#[derive(Args, Debug)]
pub struct MotionArgs {
    #[command(flatten)]
    window: super::WindowArgs,
    /// The frame budget of the second variant, in milliseconds (the first has none).
    #[arg(long, default_value_t = 1e3 * DEFAULT_FRAME_BUDGET)]
    frame_budget: f64,
    /// Seconds the view is held still before the move.
    #[arg(long, default_value_t = 2.0)]
    still: f64,
    /// Seconds the move lasts: an orbit, then a walk, half each.
    #[arg(long, default_value_t = 4.0)]
    motion: f64,
    /// Degrees of the orbit about the target.
    #[arg(long, default_value_t = 30.0)]
    orbit: f32,
    /// Iterations of the converged view (rendered with another seed).
    #[arg(long, default_value_t = 64)]
    reference_iterations: u32,
    /// An EXR holding the converged view: read where it exists (of the window's size), written
    /// otherwise.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// A directory to write the shown images at the marks to (`budget-B-at-T.exr`).
    #[arg(long)]
    images: Option<PathBuf>,
    /// Photons traced (default: fitted to the scene, as `view` does).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    photons: Option<u32>,
    /// The gather implementation (as `view --gather`).
    #[arg(long, value_enum, default_value_t = GatherArg::Auto)]
    gather: GatherArg,
    /// Light samples per pixel per iteration (as `view --light-samples`: `balanced`, the
    /// viewer's default, or a count)
    #[arg(long, default_value = "balanced", value_parser = rastergi::session::args::parse_light_samples)]
    light_samples: LightSamplesArg,
    /// Show the denoised image (as `view --denoise`): its filter runs on the viewer's schedule,
    /// and its time counts as drawing.
    #[arg(long)]
    denoise: bool,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// What one variant measured.
struct Measured {
    /// Frame times during the motion, seconds.
    frames: Vec<f64>,
    /// Seconds from the last move to the first frame whose film holds a whole iteration.
    to_full: Option<f64>,
    /// The relative RMSE at each of [`MARKS`], and the window's iterations then.
    errors: Vec<Option<f64>>,
    iterations: Vec<u32>,
    /// The share of the frames' time after the stop spent on the resolve and display pass, and
    /// the frames after the stop (seconds).
    drawing: f64,
    still: Vec<f64>,
}

/// The camera `t` seconds into the move of `a` from `start`.
fn camera_at(a: &MotionArgs, start: &CameraControl, diagonal: f32, t: f64) -> Camera {
    let half = 0.5 * a.motion.max(1e-3);
    let orbit = (t / half).clamp(0.0, 1.0) as f32;
    let walk = ((t - half) / half).clamp(0.0, 1.0) as f32;
    let mut c = start.clone();
    c.orbit(orbit * a.orbit.to_radians(), 0.0);
    c.translate(0.0, 0.0, walk * 0.1 * diagonal);
    c.camera()
}

/// One variant: the script with a frame budget of `budget` seconds (0: off).
fn run_variant(
    a: &MotionArgs,
    gpu: &Gpu,
    scene: &Scene,
    settings: &RenderSettings,
    budget: f64,
    reference: &LinearImage,
) -> Result<Measured> {
    let renderer = Renderer::new(gpu, scene, settings.clone())?;
    renderer.wait()?;
    let mut view = Interactive::new(Box::new(renderer), Show::Full, 0.0);
    view.set_frame_budget(budget);
    if a.denoise {
        view.set_denoise(true)?;
    }
    let mut target = DisplayTarget::offscreen(gpu, settings.width, settings.height)?;
    // A frame: its work, then the resolve and the display pass; returns the seconds of the
    // work and of the drawing. The resolve is waited for alone where debug output is on, so
    // that each frame's line splits the drawing into the resolve's and the display pass's.
    //
    // After the stop (`hold`) the image on screen before the frame's resolve is copied on the
    // GPU into `held`, so that the image shown at a mark can be read back when a frame crosses
    // it, and only then: a read-back every frame would lengthen each frame's rest, which the
    // viewer's loop measures and takes from the next frame's work (a 14 MB read-back at
    // 1280 × 720 on lavapipe is a fifth of a 50 ms frame).
    let clock = Instant::now();
    let split = log::log_enabled!(log::Level::Debug);
    let bytes = 16 * u64::from(settings.width) * u64::from(settings.height);
    let copy = egui_wgpu::wgpu::BufferUsages::COPY_DST | egui_wgpu::wgpu::BufferUsages::COPY_SRC;
    let held = gpu.zeroed_buffer("bench motion: the image shown before the frame's resolve", bytes, copy);
    let mut frame = |view: &mut Interactive, hold: bool| -> Result<(f64, f64, bool)> {
        let began = Instant::now();
        view.frame(u32::MAX)?;
        let work = began.elapsed().as_secs_f64();
        // As the viewer: the resolve when due, the display pass when the view says it is
        // (a new image, else now and then).
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let mut resolve = None;
        let resolved = view.display_due();
        if resolved {
            if hold {
                enc.copy_buffer_to_buffer(view.renderer().film().linear_buffer(), 0, &held, 0, bytes);
            }
            view.encode_resolve(&mut enc, clock.elapsed().as_secs_f64())?;
            if split {
                let at = Instant::now();
                gpu.queue.submit([
                    std::mem::replace(&mut enc, gpu.device.create_command_encoder(&Default::default())).finish()
                ]);
                gpu.wait()?;
                resolve = Some(at.elapsed().as_secs_f64());
            }
        }
        let at = Instant::now();
        let drawn = view.draw_due(resolved);
        if drawn {
            target.present(gpu, enc, Some(view.renderer().film()), &[])?;
            view.drawn();
        } else {
            gpu.queue.submit([enc.finish()]);
        }
        gpu.wait()?;
        if split {
            let ms = |t: Option<f64>| t.map_or("-".to_owned(), |t| format!("{:.1}", 1e3 * t));
            let display = drawn.then(|| at.elapsed().as_secs_f64());
            log::debug!("  drawing: resolve {} ms, display {} ms", ms(resolve), ms(display));
        }
        Ok((work, began.elapsed().as_secs_f64() - work, resolved))
    };
    let start = Instant::now();
    while start.elapsed().as_secs_f64() < a.still {
        frame(&mut view, false)?;
    }
    let control = CameraControl::new(&scene.camera, &scene.bounds());
    let diagonal = (scene.bounds().max - scene.bounds().min).length();
    let mut frames = Vec::new();
    let moving = Instant::now();
    loop {
        let t = moving.elapsed().as_secs_f64();
        let began = Instant::now();
        view.set_camera(camera_at(a, &control, diagonal, t))?;
        let camera = began.elapsed().as_secs_f64();
        let (work, drawing, _) = frame(&mut view, false)?;
        frames.push(began.elapsed().as_secs_f64());
        log::debug!(
            "moving frame {}: {:.1} ms (camera {:.1}, work {:.1}, drawing {:.1})",
            frames.len(),
            1e3 * frames.last().unwrap(),
            1e3 * camera,
            1e3 * work,
            1e3 * drawing
        );
        if t >= a.motion {
            break;
        }
    }
    // Still at the final camera: the clock runs but for the read-backs. The image on screen at a
    // mark is the last frame's that ended before it: the one the crossing frame's resolve
    // replaced (held), or the film's last resolve where it did not resolve.
    let (mut clock, mut to_full, mut errors, mut iterations) = (0.0, None, Vec::new(), Vec::new());
    let mut shown_samples = view.renderer().samples();
    let (mut work, mut drawing, mut still) = (0.0, 0.0, Vec::new());
    while errors.len() < MARKS.len() {
        let (w, d, resolved) = frame(&mut view, true)?;
        (work, drawing) = (work + w, drawing + d);
        still.push(w + d);
        clock += w + d;
        if to_full.is_none() && view.renderer().samples() > 0 {
            to_full = Some(clock);
        }
        if clock > MARKS[errors.len()] {
            let film = view.renderer().film();
            let shown = if resolved { film.read_linear_copy(gpu, &held)? } else { film.read_linear_buffer(gpu)? };
            while errors.len() < MARKS.len() && clock > MARKS[errors.len()] {
                if let Some(dir) = &a.images {
                    let name = format!("budget-{:.0}-at-{}.exr", 1e3 * budget, MARKS[errors.len()]);
                    rastergi::image_io::write_exr(&dir.join(name), &shown)?;
                }
                errors.push(Some(rastergi::metrics::compare(&shown, reference, None).relative_rmse));
                iterations.push(shown_samples);
            }
        }
        shown_samples = view.renderer().samples();
    }
    Ok(Measured { frames, to_full, errors, iterations, drawing: drawing / (work + drawing), still })
}

/// The 100·q-th percentile of `v` (nearest rank).
fn percentile(v: &[f64], q: f64) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1]
}

pub fn run(a: &MotionArgs) -> Result<()> {
    ensure!(
        a.frame_budget.is_finite() && a.frame_budget > 0.0,
        "--frame-budget must be positive milliseconds, got {}",
        a.frame_budget
    );
    ensure!(a.motion.is_finite() && a.motion > 0.0, "--motion must be positive seconds, got {}", a.motion);
    ensure!(a.still.is_finite() && a.still >= 0.0, "--still must be 0 or more seconds, got {}", a.still);
    // Where the images and the converged view go is checked before minutes of rendering.
    if let Some(dir) = &a.images {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--images {}: cannot make the directory", dir.display()))?;
    }
    if let Some(path) = &a.reference
        && !path.exists()
        && let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty())
    {
        ensure!(
            parent.is_dir(),
            "--reference {}: the directory {} does not exist; make it or name another",
            path.display(),
            parent.display()
        );
    }
    let (scene, gpu) = window_scene_and_gpu(&a.window, &a.gpu)?;
    let (w, h) = (a.window.width, a.window.height);
    let grid = fit::grid_resolution(&scene.bounds());
    let photons = a.photons.unwrap_or_else(|| fit::photon_count(&scene, grid));
    let settings = RenderSettings {
        width: w,
        height: h,
        photons,
        grid_resolution: grid,
        gather: a.gather.method(),
        light_samples: a.light_samples.first(),
        light_balance: a.light_samples == LightSamplesArg::Balanced,
        ..Default::default()
    };
    println!(
        "bench motion: {} at {w}x{h} on {} ({:?}), {photons} photons, grid {grid}; still {} s, then an orbit of {} degrees and a walk, {} s in all, then still{}",
        a.window.scene,
        gpu.info.name,
        gpu.info.backend,
        a.still,
        a.orbit,
        a.motion,
        if a.denoise { "; the denoised image shown" } else { "" }
    );
    // The converged view of the final camera, another seed.
    let control = CameraControl::new(&scene.camera, &scene.bounds());
    let last = camera_at(a, &control, (scene.bounds().max - scene.bounds().min).length(), a.motion);
    let reference = match &a.reference {
        Some(path) if path.exists() => {
            let image = rastergi::image_io::read_exr(path)?;
            ensure!(
                (image.width, image.height) == (w, h),
                "{}: the reference is {}x{}, not {w}x{h}; delete it to render it again",
                path.display(),
                image.width,
                image.height
            );
            println!("  converged view: {}", path.display());
            image
        }
        _ => {
            let began = Instant::now();
            let mut r =
                Renderer::new(&gpu, &scene, RenderSettings { seed: settings.seed ^ 0x5eed, ..settings.clone() })?;
            r.set_camera(last)?;
            for _ in 0..a.reference_iterations {
                r.iterate()?;
            }
            let image = r.read_linear(Show::Full)?;
            println!(
                "  converged view: {} iterations of the final camera, another seed, in {:.1} s",
                a.reference_iterations,
                began.elapsed().as_secs_f64()
            );
            if let Some(path) = &a.reference {
                rastergi::image_io::write_exr(path, &image)?;
            }
            image
        }
    };
    let variants = [("budget off: whole iterations", 0.0), ("frame budget", 1e-3 * a.frame_budget)];
    let mut results = Vec::new();
    for (name, budget) in variants {
        let m = run_variant(a, &gpu, &scene, &settings, budget, &reference)?;
        let label = if budget > 0.0 { format!("{name} {:.0} ms", 1e3 * budget) } else { name.to_owned() };
        println!("  {label}:");
        println!(
            "    during motion: {} frames, median {:.1} ms, p95 {:.1} ms, longest {:.1} ms",
            m.frames.len(),
            1e3 * percentile(&m.frames, 0.5),
            1e3 * percentile(&m.frames, 0.95),
            1e3 * percentile(&m.frames, 1.0)
        );
        let to_full = m.to_full.map_or("not within 5 s".to_owned(), |t| format!("{t:.2} s"));
        println!("    from the last move to the first full-resolution iteration: {to_full}");
        let errors: Vec<String> = MARKS
            .iter()
            .zip(m.errors.iter().zip(&m.iterations))
            .map(|(t, (e, n))| {
                format!("{t} s {} ({n} it.)", e.map_or("-".to_owned(), |e| format!("{:.1} %", 100.0 * e)))
            })
            .collect();
        println!("    relRMSE against the converged view after the stop: {}", errors.join(", "));
        println!(
            "    after the stop: frames median {:.1} ms, p95 {:.1} ms, the longest {:.1} ms; {:.0} % of their time drawing (the resolve and the display pass)",
            1e3 * percentile(&m.still, 0.5),
            1e3 * percentile(&m.still, 0.95),
            1e3 * percentile(&m.still, 1.0),
            100.0 * m.drawing
        );
        results.push(m);
    }
    let (before, after) = (&results[0], &results[1]);
    let ratio = |k: usize| match (before.errors[k], after.errors[k]) {
        (Some(b), Some(a)) if b > 0.0 => format!("{:.2}", a / b),
        _ => "-".to_owned(),
    };
    println!(
        "  budget on / off: p95 frame {:.2}x; relRMSE at 1 s {}x, at 5 s {}x",
        percentile(&after.frames, 0.95) / percentile(&before.frames, 0.95),
        ratio(1),
        ratio(3)
    );
    Ok(())
}
