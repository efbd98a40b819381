//! `rastergi bench photons`: photon tracing on the GPU and on its CPU twin, same scene,
//! count and grid.

use std::time::Instant;

use anyhow::Result;
use clap::Args;
use rastergi::gpu_scene::GpuScene;
use rastergi::photons::{PhotonSettings, cpu, gpu::GpuPhotonMap};
use rastergi::surface::PreparedScene;

use super::{load_valid_scene, median};
use crate::args::{GpuArgs, gpu_profiled, print_profile};

#[derive(Args, Debug)]
pub struct PhotonArgs {
    /// The scene: `cornell` or a .obj file.
    #[arg(default_value = "cornell")]
    scene: String,
    #[arg(long, default_value_t = 1 << 22)]
    photons: u32,
    #[arg(long, default_value_t = 64)]
    grid: u32,
    /// Refine the grid where the scene's camera reads the map and aim the sun's and sky's
    /// photons there (as `render` does by default), and report the fraction of photon hits
    /// that land there with and without aiming.
    #[arg(long)]
    region: bool,
    /// Timed GPU runs (the median is reported), after one warm-up run.
    #[arg(long, default_value_t = 3)]
    repeats: u32,
    /// Print the GPU time of the photon passes (timestamp queries) over the timed runs.
    #[arg(long)]
    profile: bool,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(a: &PhotonArgs) -> Result<()> {
    let scene = load_valid_scene(&a.scene)?;
    let gpu = gpu_profiled(&a.gpu, a.profile)?;
    let prepared = PreparedScene::new(&scene);
    let region = if a.region { rastergi::fit::photon_region(&prepared, &scene.camera, 1.0, a.grid) } else { None };
    let settings = PhotonSettings { count: a.photons, seed: 1, grid_resolution: a.grid, region, ..Default::default() };
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
    // The GPU map's layout (slots and areas, made on the CPU once per grid): the twin traces
    // into the same slots, and is timed for the tracing alone like the GPU.
    let t = Instant::now();
    let tally = cpu::trace_flux(&prepared, &map.layout, &settings, 0);
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
    if let Some(r) = &region {
        // The same photons' hits in the region's cells, aimed and not (CPU twin).
        let unaimed = cpu::trace_flux(&prepared, &map.layout, &PhotonSettings { region: None, ..settings }, 0);
        let share = |t: &cpu::Tally| {
            let (inside, all) = map.layout.region_share(&t.deposits);
            inside as f64 / all.max(1) as f64
        };
        println!(
            "  region {r}: {:.2} % of photon hits land there unaimed, {:.2} % aimed",
            100.0 * share(&unaimed),
            100.0 * share(&tally)
        );
    }
    print_profile(&gpu, a.profile, "GPU passes", a.repeats.max(1) as u64, "run")?;
    Ok(())
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}
