//! `rastergi bench`: throughput figures, measured side by side in one run. Benchmarks print
//! figures; tests never assert wall-clock time.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use rastergi::film::Show;
use rastergi::gpu_scene::{GpuScene, PreparedScene};
use rastergi::image_io::{LinearImage, read_exr};
use rastergi::metrics::{compare, emitter_mask};
use rastergi::path_tracer::PathTracer;
use rastergi::photon_map::GridSpec;
use rastergi::photons::{PhotonSettings, cpu, gpu::GpuPhotonMap};
use rastergi::renderer::{RenderSettings, Renderer, default_bundle};

use crate::args::{GatherArg, GpuArgs, gpu, gpu_profiled, load_scene, print_profile};
use rastergi::gather::GatherMethod;

#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Photons per second on the GPU and on the CPU twin, same scene and count.
    Photons(PhotonArgs),
    /// Gather directions per second, and the time to reach a target error against a reference.
    Gather(GatherArgs),
    /// Relative RMSE against time for the photon/gather pipeline and the path tracer: CSV and plot.
    Converge(ConvergeArgs),
    /// Scene loading and BVH build times (e.g. `bench bvh spheres:1000000`), with the BVH's shape.
    Bvh(BvhArgs),
    /// GPU memory of a render (the device allocator's report), by resource.
    Memory(MemoryArgs),
}

#[derive(Args, Debug)]
pub struct MemoryArgs {
    #[arg(default_value = "cornell")]
    scene: String,
    #[arg(long, default_value_t = 1920)]
    width: u32,
    #[arg(long, default_value_t = 1080)]
    height: u32,
    /// Photon grid cells along the scene's longest axis.
    #[arg(long, default_value_t = 128)]
    grid: u32,
    /// Ray-view resolution of the raster gather.
    #[arg(long, default_value_t = 2048)]
    bundle: u32,
    /// Photons traced (the count does not change the memory).
    #[arg(long, default_value_t = 1 << 16)]
    photons: u32,
    /// The gather implementation: auto (both exist until the faster is chosen), raster, trace.
    #[arg(long, value_enum, default_value_t = GatherArg::Auto)]
    gather: GatherArg,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(Args, Debug)]
pub struct BvhArgs {
    /// The scene: built in (`cornell`, `atrium`, `spheres:N`) or a file.
    #[arg(default_value = "spheres:1000000")]
    scene: String,
    /// Timed builds (the median is reported).
    #[arg(long, default_value_t = 3)]
    repeats: u32,
}

#[derive(Args, Debug)]
pub struct PhotonArgs {
    /// The scene: `cornell` or a .obj file.
    #[arg(default_value = "cornell")]
    scene: String,
    #[arg(long, default_value_t = 1 << 22)]
    photons: u32,
    #[arg(long, default_value_t = 64)]
    grid: u32,
    /// Timed GPU runs (the median is reported), after one warm-up run.
    #[arg(long, default_value_t = 3)]
    repeats: u32,
    /// Print the GPU time of the photon passes (timestamp queries) over the timed runs.
    #[arg(long)]
    profile: bool,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(Args, Debug)]
pub struct GatherArgs {
    #[arg(default_value = "cornell")]
    scene: String,
    /// Eye resolutions (square) for the throughput figures.
    #[arg(long, value_delimiter = ',', default_values_t = [512u32, 1024])]
    sizes: Vec<u32>,
    /// Ray-view resolution.
    #[arg(long, default_value_t = 1024)]
    bundle: u32,
    /// Timed iterations per size (after two warm-up iterations).
    #[arg(long, default_value_t = 16)]
    iterations: u32,
    #[arg(long, default_value_t = 1 << 22)]
    photons: u32,
    #[arg(long, default_value_t = 64)]
    grid: u32,
    /// A converged reference (linear EXR) of the scene's camera view: also measure the time
    /// to reach each target error at its resolution. Several comma-separated independent
    /// renders are averaged (less reference noise).
    #[arg(long, value_delimiter = ',')]
    reference: Vec<PathBuf>,
    /// Target relative RMSEs in percent (emitter pixels masked).
    #[arg(long, value_delimiter = ',', default_values_t = [5.0f64, 2.0])]
    targets: Vec<f64>,
    /// Give up on a target after this many seconds of rendering.
    #[arg(long, default_value_t = 120.0)]
    max_seconds: f64,
    /// Also time Mitsuba 3's path tracer (scripts/mitsuba_reference.py; built-in cornell only).
    #[arg(long)]
    mitsuba: bool,
    /// Gather directions per iteration.
    #[arg(long, default_value_t = rastergi::renderer::DEFAULT_DIRECTIONS, value_parser = clap::value_parser!(u32).range(1..=16))]
    directions: u32,
    /// Print the GPU time of every pass (timestamp queries) for each size and method.
    #[arg(long)]
    profile: bool,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(command: &BenchCommand) -> Result<()> {
    match command {
        BenchCommand::Photons(a) => photons(a),
        BenchCommand::Gather(a) => gather(a),
        BenchCommand::Converge(a) => converge(a),
        BenchCommand::Bvh(a) => bvh(a),
        BenchCommand::Memory(a) => memory(a),
    }
}

/// The device allocator's live allocations summed by label, largest first, and the totals.
fn print_allocations(gpu: &rastergi::gpu::Gpu, title: &str) {
    let Some(report) = gpu.device.generate_allocator_report() else {
        println!("{title}: this backend ({:?}) gives no allocator report", gpu.info.backend);
        return;
    };
    let mut by_name: Vec<(String, u64, usize)> = Vec::new();
    for a in &report.allocations {
        match by_name.iter_mut().find(|(n, _, _)| *n == a.name) {
            Some(e) => {
                e.1 += a.size;
                e.2 += 1;
            }
            None => by_name.push((a.name.clone(), a.size, 1)),
        }
    }
    by_name.sort_by_key(|e| std::cmp::Reverse(e.1));
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    println!("{title}:");
    for (name, bytes, n) in by_name.iter().filter(|e| e.1 >= 1 << 20) {
        let name = if name.is_empty() { "(unlabelled)" } else { name };
        println!(
            "  {name:<34} {:>9.1} MiB{}",
            mib(*bytes),
            if *n > 1 { format!(" ({n} allocations)") } else { String::new() }
        );
    }
    let small: u64 = by_name.iter().filter(|e| e.1 < 1 << 20).map(|e| e.1).sum();
    println!("  {:<34} {:>9.1} MiB", "everything under 1 MiB", mib(small));
    println!(
        "  {:<34} {:>9.1} MiB allocated ({:.3} GB), {:.1} MiB reserved in {} blocks",
        "total",
        mib(report.total_allocated_bytes),
        report.total_allocated_bytes as f64 / 1e9,
        mib(report.total_reserved_bytes),
        report.blocks.len()
    );
}

fn memory(a: &MemoryArgs) -> Result<()> {
    let scene = load_scene(&a.scene)?;
    scene.validate()?;
    let gpu = gpu(&a.gpu)?;
    println!(
        "GPU memory: {} at {}x{}, grid {}, bundle {}², gather {:?}, on {} ({:?})",
        a.scene, a.width, a.height, a.grid, a.bundle, a.gather, gpu.info.name, gpu.info.backend
    );
    let settings = RenderSettings {
        width: a.width,
        height: a.height,
        photons: a.photons,
        grid_resolution: a.grid,
        bundle: a.bundle,
        gather: a.gather.method(),
        seed: 1,
        ..Default::default()
    };
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    r.wait()?;
    print_allocations(&gpu, "after set-up (scene, BVH, photon map, passes)");
    for _ in 0..rastergi::gather::AUTO_ITERATIONS {
        r.iterate()?;
    }
    r.wait()?;
    print_allocations(&gpu, &format!("while rendering (gather: {:?})", r.gather_method()));
    Ok(())
}

/// Load time, then the median BVH build time over the repeats (single-threaded binned SAH)
/// and the tree's size, depth and leaf occupancy.
fn bvh(a: &BvhArgs) -> Result<()> {
    let t = Instant::now();
    let scene = load_scene(&a.scene)?;
    let load = t.elapsed().as_secs_f64();
    scene.validate()?;
    let mut times = Vec::new();
    let mut built = None;
    for _ in 0..a.repeats.max(1) {
        let t = Instant::now();
        let b = rastergi::bvh::Bvh::build(&scene.triangles);
        times.push(t.elapsed());
        built = Some(b);
    }
    let b = built.expect("at least one build");
    let leaves: Vec<u32> = b.nodes.iter().filter(|n| n.count > 0).map(|n| n.count).collect();
    let n = scene.triangles.len() as f64;
    let build = median(times).as_secs_f64();
    println!("BVH: {} ({} triangles)", a.scene, scene.triangles.len());
    println!("  load   {load:>8.3} s");
    println!("  build  {build:>8.3} s  ({:.2} M triangles/s, median of {})", n / build / 1e6, a.repeats.max(1));
    println!(
        "  {} nodes, depth {}, {} leaves of {:.2} triangles on average (at most {})",
        b.nodes.len(),
        b.depth(),
        leaves.len(),
        n / leaves.len() as f64,
        leaves.iter().max().unwrap_or(&0)
    );
    Ok(())
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn photons(a: &PhotonArgs) -> Result<()> {
    let scene = load_scene(&a.scene)?;
    scene.validate()?;
    let gpu = gpu_profiled(&a.gpu, a.profile)?;
    let prepared = PreparedScene::new(&scene);
    let settings = PhotonSettings { count: a.photons, seed: 1, grid_resolution: a.grid };
    let gs = GpuScene::new(&gpu, &prepared)?;
    let map = GpuPhotonMap::new(&gpu, &gs, &prepared, &settings)?;
    map.trace(&gpu, &gs);
    gpu.wait()?;
    if let Some(p) = &gpu.profiler {
        p.clear(&gpu.device, &gpu.queue)?;
    }
    let mut times = Vec::new();
    for _ in 0..a.repeats.max(1) {
        let t = Instant::now();
        map.trace(&gpu, &gs);
        gpu.wait()?;
        times.push(t.elapsed());
    }
    let t_gpu = median(times).as_secs_f64();
    let grid = GridSpec::new(&prepared.bounds, a.grid);
    let t = Instant::now();
    let tally = cpu::trace_flux(&prepared, &grid, &settings);
    let t_cpu = t.elapsed().as_secs_f64();
    let deposits: u64 = tally.deposits.iter().map(|&d| d as u64).sum();
    let n = a.photons as f64;
    println!(
        "photon tracing: {}, {} photons, grid {}, {:.2} diffuse hits per photon",
        a.scene,
        a.photons,
        a.grid,
        deposits as f64 / n
    );
    println!(
        "  GPU  {:<40} {:>9.3} s  {:>10.2} M photons/s",
        format!("{} ({:?})", gpu.info.name, gpu.info.backend),
        t_gpu,
        n / t_gpu / 1e6
    );
    println!(
        "  CPU  {:<40} {:>9.3} s  {:>10.2} M photons/s",
        format!("{} threads (rayon)", rayon_threads()),
        t_cpu,
        n / t_cpu / 1e6
    );
    println!("  GPU / CPU: {:.2}x", t_cpu / t_gpu);
    print_profile(&gpu, a.profile, "GPU passes", a.repeats.max(1) as u64, "run")?;
    Ok(())
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

fn settings(a: &GatherArgs, width: u32, height: u32, bundle: u32) -> RenderSettings {
    RenderSettings {
        width,
        height,
        photons: a.photons,
        grid_resolution: a.grid,
        bundle,
        seed: 1,
        directions: a.directions,
        ..Default::default()
    }
}

fn gather(a: &GatherArgs) -> Result<()> {
    let scene = load_scene(&a.scene)?;
    scene.validate()?;
    let gpu = gpu_profiled(&a.gpu, a.profile)?;
    println!(
        "final gather: {} on {} ({:?}), bundle {}², {} photons, grid {}",
        a.scene, gpu.info.name, gpu.info.backend, a.bundle, a.photons, a.grid
    );
    println!("  {} gather directions per iteration (G-buffer and direct light shared by them)", a.directions);
    for &size in &a.sizes {
        for method in [GatherMethod::Raster, GatherMethod::Lists, GatherMethod::Trace] {
            let s = RenderSettings { gather: method, ..settings(a, size, size, a.bundle) };
            let mut r = Renderer::new(&gpu, &scene, s)?;
            for _ in 0..2 {
                r.iterate()?;
            }
            r.wait()?;
            if let Some(p) = &gpu.profiler {
                p.clear(&gpu.device, &gpu.queue)?;
            }
            let t = Instant::now();
            for _ in 0..a.iterations {
                r.iterate()?;
            }
            r.wait()?;
            let dt = t.elapsed().as_secs_f64();
            let what = match method {
                GatherMethod::Raster => "raster (count, read-back, peel + project per layer)",
                GatherMethod::Lists => "lists (one raster pass into per-texel lists, project)",
                _ => "trace (BVH ray casting, one dispatch)",
            };
            println!(
                "  eye {size}², {what}: {:>8.2} directions/s, {:.1} ms per iteration",
                (a.iterations * a.directions) as f64 / dt,
                1e3 * dt / a.iterations as f64
            );
            print_profile(&gpu, a.profile, &format!("  eye {size}², {method:?}"), a.iterations as u64, "iteration")?;
        }
    }
    if !a.reference.is_empty() {
        time_to_error(a, &gpu, &scene, &a.reference)?;
    }
    Ok(())
}

/// One point of a convergence curve: rendering time (readbacks excluded), samples per pixel
/// so far, and relative RMSE against the reference (emitter pixels masked).
#[derive(Clone, Copy, Debug)]
struct Point {
    seconds: f64,
    samples: u32,
    error: f64,
}

/// The renderers whose convergence is measured.
enum Method {
    Gather(Box<Renderer>),
    Path(Box<PathTracer>),
}

impl Method {
    fn name(&self) -> &'static str {
        match self {
            Method::Gather(_) => "rastergi photon map + final gather",
            Method::Path(_) => "rastergi path tracer",
        }
    }
    fn iterate(&mut self) -> Result<()> {
        match self {
            Method::Gather(r) => r.iterate()?,
            Method::Path(p) => p.iterate(),
        }
        Ok(())
    }
    fn wait(&self) -> Result<()> {
        match self {
            Method::Gather(r) => r.wait()?,
            Method::Path(p) => p.wait()?,
        }
        Ok(())
    }
    fn samples(&self) -> u32 {
        match self {
            Method::Gather(r) => r.samples(),
            Method::Path(p) => p.samples(),
        }
    }
    fn image(&self) -> Result<LinearImage> {
        Ok(match self {
            Method::Gather(r) => r.read_linear(Show::Full)?,
            Method::Path(p) => p.read_linear()?,
        })
    }
}

/// Renders, measuring the error at iteration counts growing by 25 %, until `max_seconds` of
/// rendering or an error at or under `stop_at`.
fn curve(m: &mut Method, reference: &LinearImage, mask: &[bool], max_seconds: f64, stop_at: f64) -> Result<Vec<Point>> {
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
        let error = compare(&m.image()?, reference, Some(mask)).relative_rmse;
        points.push(Point { seconds: rendering.as_secs_f64(), samples: m.samples(), error });
        if error <= stop_at {
            break;
        }
        next = (next as f64 * 1.25).ceil() as u32;
    }
    Ok(points)
}

fn first_below(points: &[Point], target: f64) -> Option<Point> {
    points.iter().copied().find(|p| p.error <= target)
}

fn print_targets(name: &str, points: &[Point], targets: &[f64], setup: f64, unit: &str) {
    for &target in targets {
        match first_below(points, target) {
            Some(p) => println!(
                "  {name:<36} {:>4.1} %: {:>8.2} s ({} {unit}, error {:.2} %; set-up {setup:.2} s)",
                100.0 * target,
                p.seconds,
                p.samples,
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

/// The reference (mean of `paths`) and its emitter mask.
fn load_reference(paths: &[PathBuf]) -> Result<(LinearImage, Vec<bool>)> {
    let reference = average_references(paths)?;
    let mask = emitter_mask(&reference, 3.0);
    Ok((reference, mask))
}

/// Renders at the reference's size and reports the rendering time at which each target was
/// first met (the photon map and set-up are reported separately).
fn time_to_error(
    a: &GatherArgs,
    gpu: &rastergi::gpu::Gpu,
    scene: &rastergi::scene::Scene,
    paths: &[PathBuf],
) -> Result<()> {
    let (reference, mask) = load_reference(paths)?;
    let (w, h) = (reference.width, reference.height);
    let targets = sorted_targets(&a.targets);
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    println!("time to error against the mean of {} ({w}x{h}, emitter pixels masked):", names.join(", "));
    let t = Instant::now();
    let mut m = Method::Gather(Box::new(Renderer::new(gpu, scene, settings(a, w, h, default_bundle(w, h)))?));
    m.wait()?;
    let setup = t.elapsed().as_secs_f64();
    let points = curve(&mut m, &reference, &mask, a.max_seconds, *targets.last().unwrap_or(&0.0))?;
    print_targets(m.name(), &points, &targets, setup, "iterations");
    if a.mitsuba {
        let points = mitsuba_curve(&a.scene, &reference, &mask, a.max_seconds, *targets.last().unwrap_or(&0.0))?;
        print_targets("Mitsuba 3 path (llvm_ad_rgb)", &points, &targets, 0.0, "spp");
    }
    Ok(())
}

fn sorted_targets(percent: &[f64]) -> Vec<f64> {
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
/// counts; process start-up (measured with 1 spp) is subtracted.
fn mitsuba_curve(
    scene: &str,
    reference: &LinearImage,
    mask: &[bool],
    max_seconds: f64,
    stop_at: f64,
) -> Result<Vec<Point>> {
    anyhow::ensure!(scene == "cornell", "--mitsuba supports the built-in cornell scene only");
    let script = Path::new("scripts/mitsuba_reference.py");
    anyhow::ensure!(script.is_file(), "--mitsuba needs scripts/mitsuba_reference.py: run from the repository root");
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("mitsuba.exr");
    let run = |spp: u32| -> Result<f64> {
        let t = Instant::now();
        let status = Command::new("python3")
            .arg(script)
            .args(["--width", &reference.width.to_string(), "--height", &reference.height.to_string()])
            .args(["--spp", &spp.to_string(), "--seed", "7", "--quiet", "--chunk-spp", "100000"])
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
        let error = compare(&read_exr(&out)?, reference, Some(mask)).relative_rmse;
        points.push(Point { seconds, samples: spp, error });
        if error <= stop_at || seconds > max_seconds {
            break;
        }
        spp *= 2;
    }
    Ok(points)
}

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
    /// Also measure Mitsuba 3 (built-in cornell only; needs python3 with mitsuba).
    #[arg(long)]
    mitsuba: bool,
    /// CSV output: method, seconds, samples, relative RMSE.
    #[arg(long, default_value = "converge.csv")]
    csv: PathBuf,
    /// Plot of relative RMSE against time (log-log), PNG.
    #[arg(long, default_value = "converge.png")]
    plot: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
}

fn converge(a: &ConvergeArgs) -> Result<()> {
    anyhow::ensure!(
        a.plot.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")),
        "{}: the plot is written as PNG; give a .png file name",
        a.plot.display()
    );
    let scene = load_scene(&a.scene)?;
    scene.validate()?;
    let gpu = gpu(&a.gpu)?;
    let (reference, mask) = load_reference(&a.reference)?;
    let (w, h) = (reference.width, reference.height);
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
        ..Default::default()
    };
    let mut curves: Vec<(String, Vec<Point>)> = Vec::new();
    let t = Instant::now();
    let mut gather = Method::Gather(Box::new(Renderer::new(&gpu, &scene, base.clone())?));
    gather.wait()?;
    let setup = t.elapsed().as_secs_f64();
    let points = curve(&mut gather, &reference, &mask, a.seconds, 0.0)?;
    print_targets(gather.name(), &points, &[0.05, 0.02], setup, "iterations");
    curves.push((gather.name().to_string(), points));
    let t = Instant::now();
    let mut path = Method::Path(Box::new(PathTracer::new(&gpu, &scene, base)?));
    path.wait()?;
    let setup = t.elapsed().as_secs_f64();
    let points = curve(&mut path, &reference, &mask, a.seconds, 0.0)?;
    print_targets(path.name(), &points, &[0.05, 0.02], setup, "spp");
    curves.push((path.name().to_string(), points));
    if a.mitsuba {
        let points = mitsuba_curve(&a.scene, &reference, &mask, a.seconds, 0.0)?;
        print_targets("Mitsuba 3 path (llvm_ad_rgb)", &points, &[0.05, 0.02], 0.0, "spp");
        curves.push(("Mitsuba 3 path (llvm_ad_rgb)".to_string(), points));
    }
    let mut csv = String::from("method,seconds,samples,relative_rmse\n");
    for (name, points) in &curves {
        for p in points {
            csv += &format!("{name},{:.4},{},{:.6}\n", p.seconds, p.samples, p.error);
        }
    }
    write_file(&a.csv, csv.as_bytes())?;
    plot(&a.plot, &curves, &format!("{} {w}x{h}, {}", a.scene, gpu.info.name))?;
    println!("wrote {} and {}", a.csv.display(), a.plot.display());
    Ok(())
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
