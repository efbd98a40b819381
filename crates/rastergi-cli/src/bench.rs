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
use rastergi::photon_map::GridSpec;
use rastergi::photons::{PhotonSettings, cpu, gpu::GpuPhotonMap};
use rastergi::renderer::{RenderSettings, Renderer};

use crate::render::{GpuArgs, gpu, load_scene};

#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Photons per second on the GPU and on the CPU twin, same scene and count.
    Photons(PhotonArgs),
    /// Gather directions per second, and the time to reach a target error against a reference.
    Gather(GatherArgs),
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
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(command: &BenchCommand) -> Result<()> {
    match command {
        BenchCommand::Photons(a) => photons(a),
        BenchCommand::Gather(a) => gather(a),
    }
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn photons(a: &PhotonArgs) -> Result<()> {
    let scene = load_scene(&a.scene)?;
    scene.validate()?;
    let gpu = gpu(&a.gpu)?;
    let prepared = PreparedScene::new(&scene);
    let settings = PhotonSettings { count: a.photons, seed: 1, grid_resolution: a.grid };
    let gs = GpuScene::new(&gpu, &prepared);
    let map = GpuPhotonMap::new(&gpu, &gs, &prepared, &settings)?;
    map.trace(&gpu, &gs);
    gpu.wait()?;
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
    Ok(())
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

fn settings(a: &GatherArgs, width: u32, height: u32, bundle: u32) -> RenderSettings {
    RenderSettings { width, height, photons: a.photons, grid_resolution: a.grid, bundle, seed: 1, ..Default::default() }
}

fn gather(a: &GatherArgs) -> Result<()> {
    let scene = load_scene(&a.scene)?;
    scene.validate()?;
    let gpu = gpu(&a.gpu)?;
    println!(
        "final gather: {} on {} ({:?}), bundle {}², {} photons, grid {}",
        a.scene, gpu.info.name, gpu.info.backend, a.bundle, a.photons, a.grid
    );
    for &size in &a.sizes {
        let mut r = Renderer::new(&gpu, &scene, settings(a, size, size, a.bundle))?;
        for _ in 0..2 {
            r.iterate()?;
        }
        r.wait()?;
        let t = Instant::now();
        for _ in 0..a.iterations {
            r.iterate()?;
        }
        r.wait()?;
        let dt = t.elapsed().as_secs_f64();
        println!(
            "  eye {size}²: {:>8.2} directions/s ({:.1} ms per iteration: G-buffer, direct, count, peel + project per layer)",
            a.iterations as f64 / dt,
            1e3 * dt / a.iterations as f64
        );
    }
    if !a.reference.is_empty() {
        time_to_error(a, &gpu, &scene, &a.reference)?;
    }
    Ok(())
}

/// Renders at the reference's size, checking the error at growing iteration counts, and
/// reports the render time (readbacks excluded) at which each target was first met.
fn time_to_error(
    a: &GatherArgs,
    gpu: &rastergi::gpu::Gpu,
    scene: &rastergi::scene::Scene,
    paths: &[PathBuf],
) -> Result<()> {
    let reference = average_references(paths)?;
    let mask = emitter_mask(&reference, 3.0);
    let (w, h) = (reference.width, reference.height);
    let mut targets: Vec<f64> = a.targets.iter().map(|t| t / 100.0).collect();
    targets.sort_by(|x, y| y.total_cmp(x));
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    println!("time to error against the mean of {} ({w}x{h}, emitter pixels masked):", names.join(", "));
    let t_setup = Instant::now();
    let mut r = Renderer::new(gpu, scene, settings(a, w, h, rastergi::renderer::default_bundle(w, h)))?;
    gpu.wait()?;
    let setup = t_setup.elapsed().as_secs_f64();
    let mut rendering = Duration::ZERO;
    let mut next = 8u32;
    let mut reached = vec![None; targets.len()];
    while reached.iter().any(Option::is_none) && rendering.as_secs_f64() < a.max_seconds {
        let t = Instant::now();
        while r.samples() < next {
            r.iterate()?;
        }
        r.wait()?;
        rendering += t.elapsed();
        let err = compare(&r.read_linear(Show::Full)?, &reference, Some(&mask)).relative_rmse;
        for (i, &target) in targets.iter().enumerate() {
            if reached[i].is_none() && err <= target {
                reached[i] = Some((rendering.as_secs_f64(), r.samples(), err));
            }
        }
        next = (next as f64 * 1.25).ceil() as u32;
    }
    for (target, result) in targets.iter().zip(&reached) {
        match result {
            Some((s, n, e)) => println!(
                "  rastergi {:>4.1} %: {s:>8.2} s ({n} iterations, error {:.2} %; plus {setup:.2} s photon map + setup)",
                100.0 * target,
                100.0 * e
            ),
            None => println!("  rastergi {:>4.1} %: not reached in {:.0} s", 100.0 * target, a.max_seconds),
        }
    }
    if a.mitsuba {
        mitsuba_time_to_error(a, &reference, &mask, &targets)?;
    }
    Ok(())
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
fn mitsuba_time_to_error(
    a: &GatherArgs,
    reference: &rastergi::image_io::LinearImage,
    mask: &[bool],
    targets: &[f64],
) -> Result<()> {
    anyhow::ensure!(a.scene == "cornell", "--mitsuba supports the built-in cornell scene only");
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
    let mut reached = vec![None; targets.len()];
    let mut spp = 16u32;
    loop {
        let t = run(spp)? - startup;
        let err = compare(&read_exr(&out)?, reference, Some(mask)).relative_rmse;
        for (i, &target) in targets.iter().enumerate() {
            if reached[i].is_none() && err <= target {
                reached[i] = Some((t, spp, err));
            }
        }
        if reached.iter().all(Option::is_some) || t > a.max_seconds {
            break;
        }
        spp *= 2;
    }
    for (target, result) in targets.iter().zip(&reached) {
        match result {
            Some((s, n, e)) => {
                println!("  Mitsuba  {:>4.1} %: {s:>8.2} s ({n} spp, error {:.2} %)", 100.0 * target, 100.0 * e)
            }
            None => println!("  Mitsuba  {:>4.1} %: not reached in {:.0} s", 100.0 * target, a.max_seconds),
        }
    }
    Ok(())
}
