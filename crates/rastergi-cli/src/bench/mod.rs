//! `rastergi bench`: throughput figures, measured side by side in one run. Benchmarks print
//! figures; tests never assert wall-clock time.
//!
//! One module per subcommand: [`photons`] (GPU against CPU photon tracing), [`gather`] (the
//! three final-gather implementations, and the time to a target error), [`converge`] (error
//! against time for the renderer, the path tracer and Mitsuba 3), [`frames`] (the viewer's
//! frame loop without a window), [`bvh`] (scene loading and BVH build), [`rays`] (rays per
//! second of each kind, GPU and CPU twin), [`memory`] (the GPU memory of a render), [`denoise`]
//! (one application of the denoiser) and [`resolve`] (one resolve for display, blended or not).

mod bvh;
mod converge;
mod denoise;
mod frames;
mod gather;
mod memory;
mod motion;
mod photons;
mod rays;
mod resolve;

use std::time::Duration;

use anyhow::Result;
use clap::Subcommand;
use rastergi::gpu::Gpu;
use rastergi::scene::Scene;

use crate::args::{GpuArgs, gpu, load_scene};

#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Photons per second on the GPU and on the CPU twin, same scene and count.
    Photons(photons::PhotonArgs),
    /// Gather directions per second of each implementation (raster, lists, trace), and the time
    /// to reach a target error against a reference.
    Gather(gather::GatherArgs),
    /// Relative RMSE against time for the photon/gather pipeline and the path tracer: CSV and plot.
    Converge(converge::ConvergeArgs),
    /// Frames and iterations per second of the viewer's frame loop at a window size (default
    /// 1920x1080), without a window: batched iterations, resolve, display pass offscreen.
    Frames(frames::FramesArgs),
    /// The viewer's loop through a scripted camera move (an orbit and a walk): frame times
    /// during the motion (median, p95), the time to the first full-resolution iteration, and
    /// the error against the converged view 0.5, 1, 2 and 5 s after the stop — with the frame
    /// budget off and on, side by side.
    Motion(motion::MotionArgs),
    /// Scene loading and BVH build times (e.g. `bench bvh spheres:1000000`), with the BVH's shape.
    Bvh(bvh::BvhArgs),
    /// GPU memory of a render (the device allocator's report), by resource.
    Memory(memory::MemoryArgs),
    /// Milliseconds per application of the denoiser at the window's size.
    Denoise(denoise::DenoiseArgs),
    /// Milliseconds per resolve of the film for display at the window's size: the film alone,
    /// a moving frame's upscaled preview, and the blend just after a stop.
    Resolve(resolve::ResolveArgs),
    /// Rays per second of each kind the renderer casts (camera, shadow, bounce, gather, photon)
    /// on the GPU kernel and the CPU twin, hit for hit, and the BVH's build time, SAH cost and size.
    Rays(rays::RaysArgs),
}

pub fn run(command: &BenchCommand) -> Result<()> {
    match command {
        BenchCommand::Photons(a) => photons::run(a),
        BenchCommand::Gather(a) => gather::run(a),
        BenchCommand::Converge(a) => converge::run(a),
        BenchCommand::Frames(a) => frames::run(a),
        BenchCommand::Motion(a) => motion::run(a),
        BenchCommand::Bvh(a) => bvh::run(a),
        BenchCommand::Memory(a) => memory::run(a),
        BenchCommand::Denoise(a) => denoise::run(a),
        BenchCommand::Resolve(a) => resolve::run(a),
        BenchCommand::Rays(a) => rays::run(a),
    }
}

/// The scene and the window size of the benchmarks that measure a full-HD viewer (`frames`,
/// `memory`).
#[derive(clap::Args, Debug)]
pub struct WindowArgs {
    /// The scene: built in (`cornell`, `atrium`, `spheres:N`, `rooms`, `glossy-room`, `sunroom`) or a file.
    #[arg(default_value = "cornell")]
    pub scene: String,
    /// The window's width in pixels.
    #[arg(long, default_value_t = 1920)]
    pub width: u32,
    /// The window's height in pixels.
    #[arg(long, default_value_t = 1080)]
    pub height: u32,
}

/// The scene of that name (built in or a file), validated.
fn load_valid_scene(name: &str) -> Result<Scene> {
    let scene = load_scene(name)?;
    scene.validate()?;
    Ok(scene)
}

/// The set-up of the window benchmarks (`frames`, `memory`, `denoise`, `resolve`): the scene of `window`,
/// validated as [`load_valid_scene`] does, then the GPU `gpu_args` choose.
fn window_scene_and_gpu(window: &WindowArgs, gpu_args: &GpuArgs) -> Result<(Scene, Gpu)> {
    let scene = load_valid_scene(&window.scene)?;
    Ok((scene, gpu(gpu_args)?))
}

/// The median of timed runs (at least one).
fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// Milliseconds of `repeats` (at least one) runs of `run`, after one untimed (shaders
/// compiled, caches warm): their median, minimum and maximum.
fn milliseconds(repeats: u32, mut run: impl FnMut() -> Result<()>) -> Result<(f64, f64, f64)> {
    run()?;
    let mut times = vec![];
    for _ in 0..repeats.max(1) {
        let start = std::time::Instant::now();
        run()?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok((times[times.len() / 2], times[0], times[times.len() - 1]))
}
