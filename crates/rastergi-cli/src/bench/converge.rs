//! Convergence measurements of `rastergi bench converge` and `bench gather --reference`:
//! the error curve of any [`Progressive`] renderer and of Mitsuba 3 against a reference, the
//! times to target errors, and the CSV and log-log plot of `converge`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::Args;
use rastergi::image_io::{LinearImage, read_exr};
use rastergi::metrics::{compare, emitter_mask};
use rastergi::passes::film::Show;
use rastergi::path_tracer::PathTracer;
use rastergi::progressive::Progressive;
use rastergi::renderer::Renderer;
use rastergi::settings::RenderSettings;

use super::load_valid_scene;
use crate::args::GpuArgs;

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    #[arg(default_value = "cornell")]
    scene: String,
    /// Converged reference render(s) of the scene's camera view (linear EXR); several
    /// comma-separated independent renders are averaged.
    #[arg(long, value_delimiter = ',', required = true)]
    reference: Vec<PathBuf>,
    /// Rendering time per method.
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
    #[arg(long, default_value_t = 1 << 20)]
    photons: u32,
    #[arg(long, default_value_t = 64)]
    grid: u32,
    /// Photon passes of the photon-map renderer (see `render --photon-passes`); several
    /// comma-separated values are measured side by side, e.g. 1,0 for the fixed map and the
    /// unlimited passes.
    #[arg(long, value_delimiter = ',', default_value = "0")]
    photon_passes: Vec<u32>,
    /// Iterations per photon pass (0: fitted to the photons and the image size).
    #[arg(long, default_value_t = rastergi::photons::passes::DEFAULT_PASS_ITERATIONS)]
    pass_iterations: u32,
    /// The final gather's implementation (auto times them on the first iterations, so two
    /// curves may end up with different ones: pin it to compare other settings).
    #[arg(long, value_enum, default_value_t = crate::args::GatherArg::Auto)]
    gather: crate::args::GatherArg,
    /// Whose directions the traced gather casts (see `render --gather-directions`; `trace`
    /// only, the others share); several comma-separated values are measured side by side,
    /// e.g. shared,per-pixel (each with every --photon-passes value).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [crate::args::GatherDirectionsArg::default_value()])]
    gather_directions: Vec<crate::args::GatherDirectionsArg>,
    /// Where the light at gather hits comes from (see `render --hit-light`); several
    /// comma-separated values are measured side by side, e.g. punctual,map,exact.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "punctual")]
    hit_light: Vec<crate::args::HitLightArg>,
    /// Also measure Mitsuba 3 (built-in cornell only; needs python3 with mitsuba).
    #[arg(long)]
    mitsuba: bool,
    /// Mitsuba's variant for --mitsuba, e.g. cuda_ad_rgb (default: the script's, llvm_ad_rgb
    /// where usable).
    #[arg(long, value_name = "VARIANT", requires = "mitsuba")]
    mitsuba_variant: Option<String>,
    /// Count the rays each renderer traces (see `render --count-rays`) and print them per
    /// pixel at each target: one atomic add per ray, so its times are a little longer.
    #[arg(long)]
    count_rays: bool,
    /// CSV output: method, seconds, samples, relative RMSE (and rays per pixel with
    /// --count-rays).
    #[arg(long, default_value = "converge.csv")]
    csv: PathBuf,
    /// Plot of relative RMSE against time (log-log), PNG.
    #[arg(long, default_value = "converge.png")]
    plot: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(a: &ConvergeArgs) -> Result<()> {
    anyhow::ensure!(
        a.plot.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")),
        "{}: the plot is written as PNG; give a .png file name",
        a.plot.display()
    );
    let scene = load_valid_scene(&a.scene)?;
    let gpu = rastergi::gpu::Gpu::new(&rastergi::gpu::GpuOptions { count_rays: a.count_rays, ..a.gpu.options() })?;
    let reference = Reference::load(&a.reference)?;
    let (w, h) = reference.size();
    println!(
        "convergence: {} at {w}x{h} on {} ({:?}), {:.0} s per method",
        a.scene, gpu.info.name, gpu.info.backend, a.seconds
    );
    let base = RenderSettings {
        width: w,
        height: h,
        photons: a.photons,
        grid_resolution: a.grid,
        seed: 1,
        gather: a.gather.method(),
        ..Default::default()
    };
    let mut curves: Vec<(String, Vec<Point>)> = Vec::new();
    for &directions in &a.gather_directions {
        for &passes in &a.photon_passes {
            for &hit_light in &a.hit_light {
                let settings = RenderSettings {
                    photon_passes: passes,
                    pass_iterations: a.pass_iterations,
                    gather_directions: directions.directions(),
                    hit_light: hit_light.hit_light(),
                    ..base.clone()
                };
                let light = format!("{hit_light:?}").to_lowercase();
                println!(
                    "photon passes {passes} (0: unlimited), a pass every {} iterations (0: fitted), {} directions, hit light {light}:",
                    a.pass_iterations,
                    directions.name()
                );
                let (name, points) = measure(
                    || Renderer::new(&gpu, &scene, settings),
                    &reference,
                    a.seconds,
                    0.0,
                    &TARGETS,
                    "iterations",
                )?;
                let passes = if passes == 0 { "unlimited".to_string() } else { passes.to_string() };
                let mut name = format!("{name}, photon passes {passes}");
                if a.gather_directions.len() > 1 {
                    name += &format!(", {} directions", directions.name());
                }
                if a.hit_light.len() > 1 {
                    name += &format!(", hit light {light}");
                }
                curves.push((name, points));
            }
        }
    }
    let (name, points) = measure(|| PathTracer::new(&gpu, &scene, base), &reference, a.seconds, 0.0, &TARGETS, "spp")?;
    curves.push((name.to_string(), points));
    if a.mitsuba {
        let variant = a.mitsuba_variant.as_deref();
        let points = mitsuba_curve(&a.scene, &reference, a.seconds, 0.0, variant)?;
        let name = mitsuba_name(variant);
        print_targets(&name, &points, &TARGETS, 0.0, "spp");
        curves.push((name, points));
    }
    print_equal_time(&curves);
    let mut csv = String::from("method,seconds,samples,relative_rmse,rays_per_pixel\n");
    for (name, points) in &curves {
        for p in points {
            // Quoted: the names hold commas.
            let rays = p.rays_per_pixel.map_or(String::new(), |r| format!("{r:.2}"));
            csv += &format!("\"{name}\",{:.4},{},{:.6},{rays}\n", p.seconds, p.samples, p.error);
        }
    }
    write_file(&a.csv, csv.as_bytes())?;
    plot(&a.plot, &curves, &format!("{} {w}x{h}, {}", a.scene, gpu.info.name))?;
    println!("wrote {} and {}", a.csv.display(), a.plot.display());
    Ok(())
}

/// The target errors whose times `converge` prints.
const TARGETS: [f64; 2] = [0.05, 0.02];

/// The name of Mitsuba 3's curve for a `--mitsuba-variant` (`None`: the script's default).
pub fn mitsuba_name(variant: Option<&str>) -> String {
    format!("Mitsuba 3 path ({})", variant.unwrap_or("llvm_ad_rgb"))
}

/// One point of a convergence curve: rendering time (readbacks excluded), samples per pixel
/// so far, and relative RMSE against the reference (emitter pixels masked).
#[derive(Clone, Copy, Debug)]
pub struct Point {
    seconds: f64,
    samples: u32,
    error: f64,
    /// Rays traced per pixel so far, set-up included, where they are counted (`--count-rays`).
    rays_per_pixel: Option<f64>,
}

/// A converged reference, the mean of one or more renders, and its emitter pixels (left out
/// of every error).
pub struct Reference {
    image: LinearImage,
    mask: Vec<bool>,
}

impl Reference {
    /// The mean of the renders at `paths` (of one size) and its emitter mask.
    pub fn load(paths: &[PathBuf]) -> Result<Reference> {
        let image = average_references(paths)?;
        let mask = emitter_mask(&image, 3.0);
        Ok(Reference { image, mask })
    }

    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.image.width, self.image.height)
    }

    /// The relative RMSE of `image` against the reference, emitter pixels masked.
    fn error(&self, image: &LinearImage) -> f64 {
        compare(image, &self.image, Some(&self.mask)).relative_rmse
    }
}

/// Builds a renderer with `build`, timing its set-up (BVH, upload, photon map), renders its
/// [`curve`] and prints the time to each of `targets` (samples counted in `unit`). Returns the
/// renderer's name and the curve.
pub fn measure<P: Progressive>(
    build: impl FnOnce() -> rastergi::error::Result<P>,
    reference: &Reference,
    max_seconds: f64,
    stop_at: f64,
    targets: &[f64],
    unit: &str,
) -> Result<(&'static str, Vec<Point>)> {
    let t = Instant::now();
    let mut m = build()?;
    m.wait()?;
    let setup = t.elapsed().as_secs_f64();
    let points = curve(&mut m, reference, max_seconds, stop_at)?;
    print_targets(m.name(), &points, targets, setup, unit);
    Ok((m.name(), points))
}

/// Renders, measuring the error at iteration counts growing by 25 %, until `max_seconds` of
/// rendering or an error at or under `stop_at`.
fn curve(m: &mut dyn Progressive, reference: &Reference, max_seconds: f64, stop_at: f64) -> Result<Vec<Point>> {
    let mut points = Vec::new();
    let mut rendering = Duration::ZERO;
    let mut next = 4u32;
    m.wait()?;
    while rendering.as_secs_f64() < max_seconds {
        let t = Instant::now();
        while m.samples() < next {
            m.iterate()?;
        }
        m.wait()?;
        rendering += t.elapsed();
        let error = reference.error(&m.read_linear(Show::Full)?);
        let (w, h) = reference.size();
        let rays_per_pixel = m.rays_traced()?.map(|r| r.total() as f64 / (f64::from(w) * f64::from(h)));
        points.push(Point { seconds: rendering.as_secs_f64(), samples: m.samples(), error, rays_per_pixel });
        if error <= stop_at {
            break;
        }
        next = (next as f64 * 1.25).ceil() as u32;
    }
    Ok(points)
}

/// The error of `points` at `seconds`, interpolated log-log between the measured points
/// (`None` outside them).
fn error_at(points: &[Point], seconds: f64) -> Option<f64> {
    let pairs = points.windows(2).find(|w| w[0].seconds <= seconds && seconds <= w[1].seconds)?;
    let (p, q) = (pairs[0], pairs[1]);
    if p.seconds <= 0.0 || q.seconds <= p.seconds {
        return Some(q.error);
    }
    let t = (seconds / p.seconds).ln() / (q.seconds / p.seconds).ln();
    Some((p.error.ln() + t * (q.error / p.error).ln()).exp())
}

/// Every curve's error at the latest time all of them reached (rendering time, set-up
/// excluded), and its error² against the first curve's: the ratio of their variances per
/// unit of time where noise dominates.
fn print_equal_time(curves: &[(String, Vec<Point>)]) {
    let Some(t) = curves.iter().map(|(_, p)| p.last().map_or(0.0, |p| p.seconds)).reduce(f64::min) else {
        return;
    };
    let errors: Vec<Option<f64>> = curves.iter().map(|(_, p)| error_at(p, t)).collect();
    println!("error at equal time, {t:.1} s of rendering:");
    for ((name, _), e) in curves.iter().zip(&errors) {
        match (e, errors[0]) {
            (Some(e), Some(e0)) => {
                println!("  {name:<56} {:>6.2} % (error² {:.2}× the first's)", 100.0 * e, (e / e0).powi(2))
            }
            _ => println!("  {name:<56} not measured at {t:.1} s"),
        }
    }
}

fn first_below(points: &[Point], target: f64) -> Option<Point> {
    points.iter().copied().find(|p| p.error <= target)
}

/// For each target error, when the curve first met it (or that it did not).
pub fn print_targets(name: &str, points: &[Point], targets: &[f64], setup: f64, unit: &str) {
    for &target in targets {
        match first_below(points, target) {
            Some(p) => println!(
                "  {name:<36} {:>4.1} %: {:>8.2} s ({} {unit}{}, error {:.2} %; set-up {setup:.2} s)",
                100.0 * target,
                p.seconds,
                p.samples,
                p.rays_per_pixel.map_or(String::new(), |r| format!(", {r:.0} rays per pixel")),
                100.0 * p.error
            ),
            None => println!(
                "  {name:<36} {:>4.1} %: not reached in {:.1} s",
                100.0 * target,
                points.last().map_or(0.0, |p| p.seconds)
            ),
        }
    }
}

/// Target errors given in percent, as fractions, largest first.
pub fn sorted_targets(percent: &[f64]) -> Vec<f64> {
    let mut t: Vec<f64> = percent.iter().map(|t| t / 100.0).collect();
    t.sort_by(|x, y| y.total_cmp(x));
    t
}

/// The mean of equally sized reference renders.
fn average_references(paths: &[PathBuf]) -> Result<LinearImage> {
    let mut mean = read_exr(&paths[0])?;
    for p in &paths[1..] {
        let other = read_exr(p)?;
        anyhow::ensure!(
            (other.width, other.height) == (mean.width, mean.height),
            "{}: {}x{} differs from the first reference's {}x{}",
            p.display(),
            other.width,
            other.height,
            mean.width,
            mean.height
        );
        for (m, o) in mean.pixels.iter_mut().zip(&other.pixels) {
            for c in 0..3 {
                m[c] += o[c];
            }
        }
    }
    let k = paths.len() as f32;
    mean.pixels.iter_mut().for_each(|m| m.iter_mut().for_each(|v| *v /= k));
    Ok(mean)
}

/// Mitsuba 3's `path` integrator through scripts/mitsuba_reference.py at doubling sample
/// counts, in Mitsuba's `variant` (`None`: the script's default); process start-up (measured
/// with 1 spp) is subtracted. A render call holds at most 2^28 samples (chunks of fewer spp
/// at large sizes), which bounds the wavefront's memory on the GPU variants.
pub fn mitsuba_curve(
    scene: &str,
    reference: &Reference,
    max_seconds: f64,
    stop_at: f64,
    variant: Option<&str>,
) -> Result<Vec<Point>> {
    anyhow::ensure!(scene == "cornell", "--mitsuba supports the built-in cornell scene only");
    let script = Path::new("scripts/mitsuba_reference.py");
    anyhow::ensure!(script.is_file(), "--mitsuba needs scripts/mitsuba_reference.py: run from the repository root");
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("mitsuba.exr");
    let (w, h) = reference.size();
    let chunk = ((1u64 << 28) / (w as u64 * h as u64)).clamp(1, 100_000);
    let run = |spp: u32| -> Result<f64> {
        let t = Instant::now();
        let mut command = Command::new("python3");
        command.arg(script).args(["--width", &w.to_string(), "--height", &h.to_string()]).args([
            "--spp",
            &spp.to_string(),
            "--seed",
            "7",
            "--quiet",
            "--chunk-spp",
            &chunk.to_string(),
        ]);
        if let Some(v) = variant {
            command.args(["--variant", v]);
        }
        let status = command
            .arg("--out")
            .arg(&out)
            .stdout(std::process::Stdio::null())
            .status()
            .context("cannot run python3 for --mitsuba")?;
        anyhow::ensure!(status.success(), "the Mitsuba script failed (pip install mitsuba numpy?)");
        Ok(t.elapsed().as_secs_f64())
    };
    let startup = run(1)?;
    let mut points = Vec::new();
    let mut spp = 4u32;
    loop {
        let seconds = (run(spp)? - startup).max(0.0);
        let error = reference.error(&read_exr(&out)?);
        points.push(Point { seconds, samples: spp, error, rays_per_pixel: None });
        if error <= stop_at || seconds > max_seconds {
            break;
        }
        spp *= 2;
    }
    Ok(points)
}

/// Writes `bytes` via a temporary file renamed into place.
fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let mut tmp =
        tempfile::NamedTempFile::new_in(dir).with_context(|| format!("{}: cannot write here", path.display()))?;
    std::io::Write::write_all(&mut tmp, bytes)?;
    tmp.persist(path).with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(())
}

/// Relative RMSE against time, log-log, one line per method.
fn plot(path: &Path, curves: &[(String, Vec<Point>)], title: &str) -> Result<()> {
    use plotters::prelude::*;
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
    let all: Vec<&Point> = curves.iter().flat_map(|(_, p)| p).filter(|p| p.seconds > 0.0).collect();
    anyhow::ensure!(!all.is_empty(), "no measurement to plot");
    let (t0, t1) = all.iter().fold((f64::MAX, 0.0f64), |(a, b), p| (a.min(p.seconds), b.max(p.seconds)));
    let (e0, e1) = all.iter().fold((f64::MAX, 0.0f64), |(a, b), p| (a.min(p.error), b.max(p.error)));
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let tmp = tempfile::Builder::new().suffix(".png").tempfile_in(dir)?;
    {
        let root = BitMapBackend::new(tmp.path(), (800, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("plot: {e}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d((t0 * 0.8..t1 * 1.25).log_scale(), (e0 * 0.8..e1 * 1.25).log_scale())
            .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
        chart
            .configure_mesh()
            .x_desc("rendering time (s)")
            .y_desc("relative RMSE")
            .y_label_formatter(&|v| format!("{:.1} %", 100.0 * v))
            .draw()
            .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
        let colours = [RGBColor(200, 60, 40), RGBColor(40, 90, 200), RGBColor(40, 150, 70)];
        for (i, (name, points)) in curves.iter().enumerate() {
            let c = colours[i % colours.len()];
            let series: Vec<(f64, f64)> =
                points.iter().filter(|p| p.seconds > 0.0).map(|p| (p.seconds, p.error)).collect();
            chart
                .draw_series(LineSeries::new(series.clone(), c.stroke_width(2)))
                .map_err(|e| anyhow::anyhow!("plot: {e}"))?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
            chart
                .draw_series(series.iter().map(|&p| Circle::new(p, 3, c.filled())))
                .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
        root.present().map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    }
    tmp.persist(path).with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(())
}
