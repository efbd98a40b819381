//! `rastergi render`: renders a scene progressively with the photon-map renderer or the
//! reference path tracer and writes the image (.exr linear, .png display).
//!
//! A render stops at `--iterations` (the total, counting a resumed checkpoint's), at
//! `--time-limit`, when the error estimated without a reference falls under `--target-error`,
//! or at SIGINT/SIGTERM (a second one exits at once); every way it stops writes the image of
//! the iterations done, and the checkpoint where one is asked for (`--checkpoint`, also
//! written every `--checkpoint-every` seconds). `--resume` continues a checkpoint.

use std::io::IsTerminal;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize};
use std::time::{Duration, Instant};

use anyhow::Result;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rastergi::checkpoint::Checkpoint;
use rastergi::fit;
use rastergi::gather::GatherMethod;
use rastergi::gpu::Gpu;
use rastergi::image_io::{ImageFormat, write_exr, write_png};
use rastergi::passes::denoise::DenoiseParams;
use rastergi::passes::film::FilmState;
use rastergi::progressive::Progressive;
pub use rastergi::session::Method;
use rastergi::session::new_renderer;
use rastergi::session::run::{Limits, Observer, Stop};

use crate::args::{SceneArgs, ShowArg, print_profile};
use rastergi::gpu_scene::RaysTraced;

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Progressive iterations (one sample per pixel each) in all, a resumed checkpoint's
    /// included [default: the scene file's sample count (Mitsuba's sampler), else 256].
    #[arg(long)]
    iterations: Option<u32>,
    /// Stop after this many seconds of rendering (set-up not counted) if the iterations are
    /// not done by then; the image holds the iterations done, and a note says how many.
    #[arg(long, value_name = "SECONDS", alias = "max-seconds")]
    time_limit: Option<f64>,
    /// Stop once the image's estimated relative RMSE (its noise, estimated without a
    /// reference from two independent halves of the iterations; the photon passes are the
    /// halves' blocks, so a fixed map's own noise is not in it) falls under this, e.g. 0.02.
    #[arg(long, value_name = "E")]
    target_error: Option<f64>,
    /// Write the render's state here when it stops and every --checkpoint-every seconds
    /// (atomically), to --resume it later or `rastergi merge` it with other seeds' renders.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints while rendering (0: at every progress update).
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
    checkpoint_every: f64,
    /// Continue the render of this checkpoint (same scene, options and seed), up to
    /// --iterations in all.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
    /// Output image: .exr (linear radiance, f32 RGB) or .png (exposure, sRGB).
    #[arg(long)]
    out: PathBuf,
    /// `gather`: photon map + rasterized final gather; `path`: the reference path tracer
    /// (same scene, camera and pixel filter; unlimited depth, next-event estimation + MIS).
    #[arg(long, value_enum, default_value_t = Method::Gather)]
    method: Method,
    /// Print the GPU time of every pass (timestamp queries): the set-up's and the iterations'.
    #[arg(long)]
    profile: bool,
    /// Count the rays every pass traces (photons, the eye's chains, shadow rays, the gather's
    /// rays) and print them per pixel: what a GPU's ray throughput projects a render's time
    /// from. One atomic add per ray, so the render is a little slower; the image is the same.
    #[arg(long)]
    count_rays: bool,
    /// Denoise the accumulated image (a weighted regression on distance and normal guided by an
    /// edge-avoiding à-trous filter, docs/denoiser.md): --out gets the denoised image and NAME.raw.EXT beside it the
    /// raw one (what --out holds without --denoise). Gather method, full image only.
    #[arg(long)]
    denoise: bool,
    /// Also write the mean albedo of the visible points here (.exr linear, .png sRGB): a guide
    /// for external denoisers (OIDN, OptiX; scripts/oidn.py applies OIDN). Gather method only.
    #[arg(long, value_name = "FILE")]
    albedo: Option<PathBuf>,
    /// Also write the mean world-space shading normal of the visible points here (.exr, unit
    /// vectors facing the eye, 0 where nothing is seen): a guide for external denoisers.
    #[arg(long, value_name = "FILE")]
    normal: Option<PathBuf>,
}

/// Where `--denoise` writes the raw image: `NAME.raw.EXT` beside `out`.
pub fn raw_path(out: &Path) -> PathBuf {
    let ext = out.extension().map(|e| e.to_string_lossy().into_owned()).unwrap_or_default();
    out.with_extension(format!("raw.{ext}"))
}

/// Refuses, before any rendering, an output path the image could never be written to: a
/// directory, a missing directory, or one where no file can be created (read-only, `/proc`,
/// full): a file is written there as the image will be, beside it, and removed. `option`
/// names it in the message (`--out`, `--checkpoint`).
pub fn check_output_path(out: &Path, option: &str) -> Result<()> {
    if out.is_dir() {
        let ending = if option == "--out" { " ending in .exr or .png" } else { "" };
        anyhow::bail!("{}: is a directory; give {option} a file name{ending}", out.display());
    }
    let dir = match out.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        anyhow::bail!(
            "{}: the directory {} does not exist; create it first or choose another {option}",
            out.display(),
            dir.display()
        );
    }
    // Where the image will be written first (image_io writes a temporary file and renames it).
    let probe = tempfile::Builder::new().prefix(".rastergi-").tempfile_in(dir);
    if let Err(e) = probe {
        // tempfile's message ends "at path …" (the probe's own name): the reason alone.
        let why = e.to_string();
        let why = why.split(" at path ").next().unwrap_or_default();
        anyhow::bail!(
            "{}: no file can be written in {} ({why}); choose another {option} (checked before rendering)",
            out.display(),
            dir.display()
        );
    }
    Ok(())
}

/// SIGINT and SIGTERM set the returned number (the signal's) that the render loop reads
/// between iterations; a second one of either ends the process at once (exit 130).
fn catch_signals() -> Result<Arc<AtomicUsize>> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let caught = Arc::new(AtomicUsize::new(0));
    let any = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        // In this order: the shutdown sees the flag of an earlier signal only.
        signal_hook::flag::register_conditional_shutdown(sig, 130, any.clone())?;
        signal_hook::flag::register(sig, any.clone())?;
        signal_hook::flag::register_usize(sig, caught.clone(), sig as usize)?;
    }
    Ok(caught)
}

/// What `render` shows and writes while the library's loop runs: the progress bar and its
/// error estimate, the periodic checkpoint, and the test hook that loses the device.
struct Watch<'a> {
    progress: &'a ProgressBar,
    gpu: &'a Gpu,
    /// The iterations held before the loop (a resumed checkpoint's).
    first: u32,
    lose_device_after: Option<u32>,
    /// Where `--checkpoint` goes.
    checkpoint: Option<&'a Path>,
    /// A checkpoint of the renderer and its film.
    checkpoint_of: &'a dyn Fn(&dyn Progressive, FilmState) -> Checkpoint,
}

impl Observer for Watch<'_> {
    fn iterated(&mut self, done: u32) {
        if self.lose_device_after == Some(done - self.first) {
            self.gpu.device.destroy();
        }
    }
    fn synced(&mut self, done: u32) -> ControlFlow<()> {
        self.progress.set_position(done as u64);
        ControlFlow::Continue(())
    }
    fn wants_estimate(&self) -> bool {
        !self.progress.is_hidden()
    }
    fn estimated(&mut self, error: f64) {
        self.progress.set_message(format!("error ≈ {:.2} %", 100.0 * error));
    }
    fn checkpoint(&mut self, renderer: &dyn Progressive, film: FilmState) -> rastergi::Result<()> {
        match self.checkpoint {
            Some(path) => (self.checkpoint_of)(renderer, film).write(path),
            None => Ok(()),
        }
    }
}

/// The rays counted (`--count-rays`): `setup` before the first iteration (the first photon
/// pass), `total` at the end, over `iterations` iterations of `pixels` pixels, by use.
fn print_rays(setup: RaysTraced, total: RaysTraced, iterations: u32, pixels: u64) {
    let per_pixel = |n: u64| n as f64 / pixels as f64;
    let run = total.since(&setup);
    let per_iteration = |n: u64| per_pixel(n) / f64::from(iterations.max(1));
    println!(
        "rays traced: {} ({:.1} per pixel): set-up {} ({:.1} per pixel, photons), {iterations} iterations {} ({:.1} per pixel per iteration: eye and direct light {:.2}, gather {:.2}, photon passes {:.2})",
        total.total(),
        per_pixel(total.total()),
        setup.total(),
        per_pixel(setup.total()),
        run.total(),
        per_iteration(run.total()),
        per_iteration(run.eye),
        per_iteration(run.gather),
        per_iteration(run.photons),
    );
}

pub fn run(args: &RenderArgs) -> Result<ExitCode> {
    let format = ImageFormat::from_path(&args.out)?;
    check_output_path(&args.out, "--out")?;
    if args.denoise {
        check_output_path(&raw_path(&args.out), "--out (its .raw twin)")?;
    }
    let guides_wanted = args.denoise || args.albedo.is_some() || args.normal.is_some();
    if guides_wanted && args.method != Method::Gather {
        anyhow::bail!("--denoise, --albedo and --normal need --method gather");
    }
    if args.denoise && !matches!(args.scene.show, ShowArg::Full) {
        anyhow::bail!("--denoise applies to the full image; drop --show");
    }
    if let Some(path) = &args.albedo {
        ImageFormat::from_path(path)?;
        check_output_path(path, "--albedo")?;
    }
    if let Some(path) = &args.normal {
        if ImageFormat::from_path(path)? != ImageFormat::Exr {
            anyhow::bail!("{}: --normal writes signed vectors: give it a .exr file", path.display());
        }
        check_output_path(path, "--normal")?;
    }
    if let Some(path) = &args.checkpoint {
        check_output_path(path, "--checkpoint")?;
    }
    let a = &args.scene;
    let mut options = a.options(args.method, guides_wanted);
    // The GPU first: the scene's triangle budget follows what it binds.
    let gpu = rastergi::gpu::Gpu::new(&rastergi::gpu::GpuOptions {
        profile: args.profile,
        count_rays: args.count_rays,
        ..a.gpu.options()
    })?;
    options.budgets = options.budgets.fit_device(&gpu.device.limits());
    let start = Instant::now();
    let scene = options.load_scene()?;
    log::info!("{}: {} triangles loaded in {:.2} s", a.scene, scene.triangles.len(), start.elapsed().as_secs_f64());
    let iterations = args.iterations.or(scene.framing.and_then(|f| f.samples)).unwrap_or(256);
    if iterations == 0 {
        anyhow::bail!("--iterations must be at least 1");
    }
    if let Some(s) = args.time_limit.filter(|s| !(s.is_finite() && *s > 0.0)) {
        anyhow::bail!("--time-limit must be a positive number of seconds, got {s}");
    }
    if let Some(e) = args.target_error.filter(|e| !(e.is_finite() && *e > 0.0)) {
        anyhow::bail!("--target-error must be a positive relative error such as 0.02, got {e}");
    }
    if !(args.checkpoint_every.is_finite() && args.checkpoint_every >= 0.0) {
        anyhow::bail!("--checkpoint-every must be a number of seconds ≥ 0, got {}", args.checkpoint_every);
    }
    let (width, height) = options.image_size(&scene);
    let settings = options.settings(&scene, width, height, matches!(a.show, ShowArg::PhotonMap));
    let mut fingerprint = settings.fingerprint();
    fingerprint.insert(0, ("method".to_owned(), args.method.name().to_owned()));
    let scene_hash = scene.content_hash();
    let resume = match &args.resume {
        Some(path) => {
            let c = Checkpoint::read(path)?;
            c.check_matches(path, scene_hash, &fingerprint, Some(settings.seed))?;
            Some(c)
        }
        None => None,
    };
    let caught = catch_signals()?;
    args.method.check_show(options.show)?;
    let seed = settings.seed;
    let start = Instant::now();
    let (mut renderer, gather_info) = new_renderer(&gpu, &scene, settings, args.method, guides_wanted)?;
    if let Some(c) = &resume {
        renderer.resume(&c.progress, &c.film)?;
        log::info!("resumed {} iterations", c.film.samples);
    }
    renderer.wait()?;
    log::info!("set-up (BVH, upload, photon map) in {:.2} s", start.elapsed().as_secs_f64());
    print_profile(&gpu, args.profile, "set-up", 1, "set-up")?;
    let setup_rays = renderer.rays_traced()?;
    if let Some((bundle, directions, method)) = gather_info {
        // Auto without trials (a CPU adapter) has chosen already.
        if method == GatherMethod::Auto {
            log::info!("gather ray view: {bundle}x{bundle} texels; auto chooses the gather on the first iterations");
        } else {
            log::info!("gather ray view: {bundle}x{bundle} texels; {method:?} gather, directions {directions:?}");
        }
    }
    let checkpoint_of = |r: &dyn Progressive, film: FilmState| Checkpoint {
        scene_hash,
        seed,
        settings: fingerprint.clone(),
        progress: r.progress(),
        film,
    };
    let first = renderer.samples();
    let progress = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::new(iterations as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} iterations  {per_sec}  eta {eta}  {msg}")
                .expect("valid progress template"),
        );
        bar.set_position(first as u64);
        bar.enable_steady_tick(Duration::from_millis(200));
        bar
    } else {
        ProgressBar::hidden()
    };
    let limits = Limits {
        iterations,
        time_limit: args.time_limit,
        target_error: args.target_error,
        checkpoint_every: args.checkpoint.as_ref().map(|_| args.checkpoint_every),
    };
    let mut watch = Watch {
        progress: &progress,
        gpu: &gpu,
        first,
        // Test hook: destroy the device after this many iterations, as a lost GPU would be.
        lose_device_after: std::env::var("RASTERGI_TEST_LOSE_DEVICE_AFTER").ok().and_then(|v| v.parse().ok()),
        checkpoint: args.checkpoint.as_deref(),
        checkpoint_of: &checkpoint_of,
    };
    let outcome = rastergi::session::run::run(renderer.as_mut(), &limits, Some(&*caught), &mut watch)?;
    progress.finish_and_clear();
    let (stop, done, seconds, mut error) = (outcome.stop, outcome.done, outcome.seconds, outcome.error);
    let rendered = done - first;
    log::info!("{rendered} iterations in {seconds:.2} s");
    let film = renderer.film_state()?;
    if error.is_none() || stop != Stop::Done {
        error = film.error_estimate();
    }
    if let Some(path) = &args.checkpoint {
        checkpoint_of(renderer.as_ref(), film).write(path)?;
    }
    if args.profile && rendered > 0 {
        println!(
            "{rendered} iterations in {seconds:.3} s wall clock ({:.3} ms per iteration)",
            1e3 * seconds / rendered as f64
        );
    }
    print_profile(&gpu, args.profile, "iterations", rendered.max(1) as u64, "iteration")?;
    if let (Some(before), Some(after)) = (setup_rays, renderer.rays_traced()?) {
        print_rays(before, after, rendered, width as u64 * height as u64);
    }

    let show = a.show.show();
    let linear = renderer.read_linear(show)?;
    let denoised = match renderer.denoising().filter(|_| args.denoise) {
        Some(r) => Some(r.read_denoised(&DenoiseParams::default())?),
        None => None,
    };
    // With --denoise the raw image goes beside --out, the denoised one to --out.
    let raw_out = if args.denoise { raw_path(&args.out) } else { args.out.clone() };
    if let Some(r) = renderer.denoising().filter(|_| args.albedo.is_some() || args.normal.is_some()) {
        let guides = r.read_guides()?;
        if let Some(path) = &args.albedo {
            let albedo = guides.albedo();
            match ImageFormat::from_path(path)? {
                ImageFormat::Exr => write_exr(path, &albedo)?,
                _ => write_png(path, &rastergi::image_io::display_encode(&albedo, 0.0))?,
            }
        }
        if let Some(path) = &args.normal {
            write_exr(path, &guides.normal())?;
        }
    }
    if format == ImageFormat::Exr {
        write_exr(&raw_out, &linear)?;
        if let Some(d) = &denoised {
            write_exr(&args.out, d)?;
        }
    } else {
        let exposure = a.exposure.unwrap_or_else(|| {
            let fitted = fit::exposure(&linear);
            if fitted != 0.0 {
                eprintln!(
                    "note: exposure {fitted:+} EV fitted to the image (its median luminance is far from middle grey); give --exposure to choose"
                );
            }
            fitted
        });
        let display = renderer.read_display(show, exposure)?;
        write_png(&raw_out, &display)?;
        if let Some(d) = &denoised {
            write_png(&args.out, &rastergi::image_io::display_encode(d, exposure))?;
        }
    }
    let error_text = error.map_or(String::new(), |e| format!(", estimated error {:.2} %", 100.0 * e));
    let saved = args.checkpoint.as_ref().map_or(String::new(), |p| format!("; checkpoint {}", p.display()));
    match stop {
        Stop::Done | Stop::Requested => {
            if first >= iterations && resume.is_some() {
                eprintln!("note: the checkpoint already holds {first} iterations (--iterations {iterations})");
            }
            Ok(ExitCode::SUCCESS)
        }
        Stop::TimeLimit => {
            eprintln!(
                "note: --time-limit {} reached: {done} of {} iterations in {seconds:.2} s{error_text}{saved}",
                args.time_limit.unwrap_or_default(),
                iterations
            );
            Ok(ExitCode::SUCCESS)
        }
        Stop::TargetError(e) => {
            eprintln!(
                "note: --target-error {} reached: estimated error {:.2} % after {done} iterations in {seconds:.2} s{saved}",
                args.target_error.unwrap_or_default(),
                100.0 * e
            );
            Ok(ExitCode::SUCCESS)
        }
        Stop::Signal(sig) => {
            let name = if sig == signal_hook::consts::SIGTERM { "SIGTERM" } else { "SIGINT" };
            eprintln!(
                "interrupted ({name}): {} holds {done} of {} iterations{error_text}{saved}",
                args.out.display(),
                iterations
            );
            Ok(ExitCode::from(128 + sig as u8))
        }
    }
}
