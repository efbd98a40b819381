//! `rastergi bench gather`: gather directions per second of each final-gather implementation
//! (raster, lists, trace) at several image sizes, and with `--reference` the rendering time
//! to each target error.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use rastergi::gather::GatherMethod;
use rastergi::gpu::Gpu;
use rastergi::renderer::{Renderer, default_bundle};
use rastergi::scene::Scene;
use rastergi::settings::RenderSettings;

use super::converge::{Reference, measure, mitsuba_curve, mitsuba_name, print_targets, sorted_targets};
use super::load_valid_scene;
use crate::args::{GpuArgs, gpu_profiled, print_profile};

#[derive(Args, Debug)]
pub struct GatherArgs {
    #[arg(default_value = "cornell")]
    scene: String,
    /// Eye resolutions (square) for the throughput figures.
    #[arg(long, value_delimiter = ',', default_values_t = [512u32, 1024])]
    sizes: Vec<u32>,
    /// Ray-view resolution of the raster gathers (raster, lists).
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
    /// Mitsuba's variant for --mitsuba, e.g. cuda_ad_rgb (default: the script's, llvm_ad_rgb
    /// where usable).
    #[arg(long, value_name = "VARIANT", requires = "mitsuba")]
    mitsuba_variant: Option<String>,
    /// Gather directions per iteration.
    #[arg(long, default_value_t = rastergi::settings::DEFAULT_DIRECTIONS, value_parser = clap::value_parser!(u32).range(1..=16))]
    directions: u32,
    /// Print the GPU time of every pass (timestamp queries) for each size and method.
    #[arg(long)]
    profile: bool,
    #[command(flatten)]
    gpu: GpuArgs,
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
        // Throughput of one fixed map: no photon pass between the timed iterations.
        photon_passes: 1,
        ..Default::default()
    }
}

pub fn run(a: &GatherArgs) -> Result<()> {
    let scene = load_valid_scene(&a.scene)?;
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

/// Renders at the reference's size and reports the rendering time at which each target was
/// first met (the photon map and set-up are reported separately).
fn time_to_error(a: &GatherArgs, gpu: &Gpu, scene: &Scene, paths: &[PathBuf]) -> Result<()> {
    let reference = Reference::load(paths)?;
    let (w, h) = reference.size();
    let targets = sorted_targets(&a.targets);
    let stop_at = *targets.last().unwrap_or(&0.0);
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    println!("time to error against the mean of {} ({w}x{h}, emitter pixels masked):", names.join(", "));
    let settings = settings(a, w, h, default_bundle(w, h));
    measure(|| Renderer::new(gpu, scene, settings), &reference, a.max_seconds, stop_at, &targets, "iterations")?;
    if a.mitsuba {
        let variant = a.mitsuba_variant.as_deref();
        let points = mitsuba_curve(&a.scene, &reference, a.max_seconds, stop_at, variant)?;
        print_targets(&mitsuba_name(variant), &points, &targets, 0.0, "spp");
    }
    Ok(())
}
