//! `rastergi bench memory`: the GPU memory of a render, from the device allocator's report,
//! after set-up and while rendering.

use anyhow::Result;
use clap::Args;
use rastergi::gpu::Gpu;
use rastergi::renderer::Renderer;
use rastergi::settings::RenderSettings;

use super::window_scene_and_gpu;
use crate::args::{GatherArg, GpuArgs};

#[derive(Args, Debug)]
pub struct MemoryArgs {
    #[command(flatten)]
    window: super::WindowArgs,
    /// Photon grid cells along the scene's longest axis.
    #[arg(long, default_value_t = 128)]
    grid: u32,
    /// Ray-view resolution of the raster gathers (raster, lists).
    #[arg(long, default_value_t = 2048)]
    bundle: u32,
    /// Photons traced (the count does not change the memory).
    #[arg(long, default_value_t = 1 << 16)]
    photons: u32,
    /// The gather implementation: auto (all three exist until the fastest is chosen), raster,
    /// lists, trace.
    #[arg(long, value_enum, default_value_t = GatherArg::Auto)]
    gather: GatherArg,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(a: &MemoryArgs) -> Result<()> {
    let (scene, gpu) = window_scene_and_gpu(&a.window, &a.gpu)?;
    println!(
        "GPU memory: {} at {}x{}, grid {}, bundle {}², gather {:?}, on {} ({:?})",
        a.window.scene, a.window.width, a.window.height, a.grid, a.bundle, a.gather, gpu.info.name, gpu.info.backend
    );
    let settings = RenderSettings {
        width: a.window.width,
        height: a.window.height,
        photons: a.photons,
        grid_resolution: a.grid,
        bundle: a.bundle,
        gather: a.gather.method(),
        seed: 1,
        // Throughput of one fixed map: no photon pass between the timed iterations.
        photon_passes: 1,
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

/// The device allocator's live allocations summed by label, largest first, and the totals.
fn print_allocations(gpu: &Gpu, title: &str) {
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
