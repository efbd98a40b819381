//! The arguments and helpers the subcommands share. The options of the scene, the renderer
//! and the GPU ([`SceneArgs`], [`GpuArgs`], [`ShowArg`], [`GatherArg`] …) are the library's
//! (`rastergi::session::args`, shared with the Python package), as is scene loading
//! (`rastergi::session`); here are the GPU's openers and the per-pass GPU time report of
//! `--profile`.

use anyhow::Result;
use rastergi::gpu::Gpu;
pub use rastergi::session::args::{
    GatherArg, GatherDirectionsArg, GpuArgs, HitLightArg, PhotonRegionArg, SceneArgs, ShowArg, TextureFilterArg,
};
pub use rastergi::session::load_scene;

pub fn gpu(args: &GpuArgs) -> Result<Gpu> {
    gpu_profiled(args, false)
}

/// A GPU whose passes are timed when `profile` is set (see [`print_profile`]).
pub fn gpu_profiled(args: &GpuArgs, profile: bool) -> Result<Gpu> {
    Ok(args.open(profile)?)
}

/// Prints the GPU time per pass since the last call under `title` (per `per` `per_name`s),
/// then starts new sums. Nothing without `--profile`; a note where the adapter has no
/// timestamp queries.
pub fn print_profile(gpu: &Gpu, profile: bool, title: &str, per: u64, per_name: &str) -> Result<()> {
    if !profile {
        return Ok(());
    }
    let Some(p) = &gpu.profiler else {
        println!("{title}: {} has no timestamp queries; no per-pass GPU times", gpu.info.name);
        return Ok(());
    };
    let (times, dropped) = p.report(&gpu.device, &gpu.queue)?;
    p.clear(&gpu.device, &gpu.queue)?;
    println!("{title} (GPU timestamps, {}):", gpu.info.name);
    println!("{}", rastergi::gpu::profile::table(&times, per, per_name));
    if dropped > 0 {
        println!("({dropped} passes not timed: the query set was full)");
    }
    Ok(())
}
