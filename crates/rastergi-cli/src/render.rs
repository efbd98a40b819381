//! `rastergi render`: renders a scene progressively with the photon-map renderer or the
//! reference path tracer and writes the image (.exr linear, .png display).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Result;
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use rastergi::fit;
use rastergi::gather::GatherDirections;
use rastergi::image_io::{ImageFormat, write_exr, write_png};
use rastergi::path_tracer::PathTracer;
use rastergi::progressive::Progressive;
use rastergi::renderer::Renderer;

use crate::args::{SceneArgs, ShowArg, gpu_profiled, print_profile};

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Progressive iterations (one sample per pixel each).
    #[arg(long, default_value_t = 256)]
    iterations: u32,
    /// Stop after this many seconds of rendering (set-up not counted) if the iterations are
    /// not done by then; the image holds the iterations done, and a note says how many.
    #[arg(long, value_name = "SECONDS")]
    max_seconds: Option<f64>,
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
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
enum Method {
    Gather,
    Path,
}

/// Refuses, before any rendering, an output path the image could never be written to.
fn check_output_path(out: &Path) -> Result<()> {
    if out.is_dir() {
        anyhow::bail!("{}: is a directory; give --out a file name ending in .exr or .png", out.display());
    }
    let dir = match out.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        anyhow::bail!(
            "{}: the directory {} does not exist; create it first or choose another --out",
            out.display(),
            dir.display()
        );
    }
    Ok(())
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let format = ImageFormat::from_path(&args.out)?;
    check_output_path(&args.out)?;
    let a = &args.scene;
    let start = Instant::now();
    let scene = a.load_scene()?;
    log::info!("{}: {} triangles loaded in {:.2} s", a.scene, scene.triangles.len(), start.elapsed().as_secs_f64());
    if args.iterations == 0 {
        anyhow::bail!("--iterations must be at least 1");
    }
    if let Some(s) = args.max_seconds.filter(|s| !(s.is_finite() && *s > 0.0)) {
        anyhow::bail!("--max-seconds must be a positive number of seconds, got {s}");
    }
    let gpu = gpu_profiled(&a.gpu, args.profile)?;
    if args.method == Method::Path && !matches!(a.show, ShowArg::Full) {
        anyhow::bail!("--method path renders the full image only; drop --show or use --method gather");
    }
    let settings = a.settings(&scene, a.width, a.height, matches!(a.show, ShowArg::PhotonMap));
    let start = Instant::now();
    // `bundle`: the photon-map renderer's gather ray view and directions, for the log.
    let (mut renderer, gather_info): (Box<dyn Progressive>, Option<(u32, GatherDirections)>) = match args.method {
        Method::Gather => {
            let r = Renderer::new(&gpu, &scene, settings)?;
            let info = (r.bundle(), r.gather_directions());
            (Box::new(r), Some(info))
        }
        Method::Path => (Box::new(PathTracer::new(&gpu, &scene, settings)?), None),
    };
    renderer.wait()?;
    log::info!("set-up (BVH, upload, photon map) in {:.2} s", start.elapsed().as_secs_f64());
    print_profile(&gpu, args.profile, "set-up", 1, "set-up")?;
    if let Some((bundle, directions)) = gather_info {
        if a.gather.method() == rastergi::gather::GatherMethod::Auto {
            log::info!("gather ray view: {bundle}x{bundle} texels; auto chooses the gather on the first iterations");
        } else {
            log::info!("gather ray view: {bundle}x{bundle} texels; directions {directions:?}");
        }
    }
    let start = Instant::now();

    let progress = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::new(args.iterations as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} iterations  {per_sec}  eta {eta}")
                .expect("valid progress template"),
        );
        bar.enable_steady_tick(Duration::from_millis(200));
        bar
    } else {
        ProgressBar::hidden()
    };
    let mut done = 0;
    while done < args.iterations {
        renderer.iterate()?;
        done += 1;
        // Keep the GPU queue short so the progress bar (and --max-seconds) tell the truth.
        if done % 8 == 0 {
            renderer.wait()?;
            progress.set_position(done as u64);
            if args.max_seconds.is_some_and(|s| start.elapsed().as_secs_f64() >= s) {
                break;
            }
        }
    }
    renderer.wait()?;
    progress.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    log::info!("{done} iterations in {seconds:.2} s");
    if done < args.iterations {
        eprintln!(
            "note: --max-seconds {} reached: {done} of {} iterations in {seconds:.2} s",
            args.max_seconds.unwrap_or_default(),
            args.iterations
        );
    }
    if args.profile {
        println!(
            "{done} iterations in {seconds:.3} s wall clock ({:.3} ms per iteration)",
            1e3 * seconds / done as f64
        );
    }
    print_profile(&gpu, args.profile, "iterations", done as u64, "iteration")?;

    let show = a.show.show();
    let linear = renderer.read_linear(show)?;
    if format == ImageFormat::Exr {
        return Ok(write_exr(&args.out, &linear)?);
    }
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
    write_png(&args.out, &display)?;
    Ok(())
}
