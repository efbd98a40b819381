//! `rastergi bench resolve`: the cost of one resolve of the film for display at the window's
//! size, in the three states a viewer resolves it in — the film alone (a render, or a still
//! view long after a move), a moving frame (a preview upscaled, the film empty), and just
//! after a stop (the film's first iteration, the preview and the view before the move
//! re-projected, blended where no edge of light forbids it).

use anyhow::Result;
use clap::Args;
use rastergi::passes::film::Show;
use rastergi::renderer::Renderer;
use rastergi::settings::RenderSettings;

use super::window_scene_and_gpu;
use crate::args::GpuArgs;

#[derive(Args, Debug)]
pub struct ResolveArgs {
    #[command(flatten)]
    window: super::WindowArgs,
    /// Resolves timed in each state.
    #[arg(long, default_value_t = 9)]
    repeats: u32,
    /// The preview's scale (1/s of the window's size).
    #[arg(long, default_value_t = 4)]
    preview: u32,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(a: &ResolveArgs) -> Result<()> {
    let (scene, gpu) = window_scene_and_gpu(&a.window, &a.gpu)?;
    let (w, h) = (a.window.width, a.window.height);
    let settings = RenderSettings { width: w, height: h, photons: 1 << 16, seed: 1, ..Default::default() };
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    for _ in 0..2 {
        r.iterate()?;
    }
    r.wait()?;
    let show = (Show::Full, 0.0);
    // The resolve of the film alone, or blended with the preview at 1/s weighed as w
    // iterations (and the history where re-projected), timed.
    let time = |r: &mut Renderer, blend: Option<(u32, f32)>| {
        super::milliseconds(a.repeats, || {
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            match blend {
                None => r.encode_resolve(&mut enc, show.0, show.1),
                Some(p) => r.encode_resolve_blend(&mut enc, show, Some(p)),
            }
            gpu.queue.submit([enc.finish()]);
            Ok(gpu.wait()?)
        })
    };
    let film = time(&mut r, None)?;
    // A move: the camera turned a little (the view before kept as history), a preview drawn.
    let mut camera = r.camera();
    let (right, _, _) = camera.frame();
    let step = 0.02 * (camera.target - camera.eye).length();
    camera.eye += right * step;
    r.set_camera(camera)?;
    let s = a.preview.max(2);
    while !r.iterate_preview_rows(s, u32::MAX)? {}
    r.wait()?;
    let moving = time(&mut r, Some((s, 1.0)))?;
    // The stop: the history re-projected, the window's first iteration.
    r.reproject()?;
    r.iterate()?;
    r.wait()?;
    let stopped = time(&mut r, Some((s, 1.0)))?;
    println!(
        "resolve: {} at {w}x{h} on {} ({:?}), median of {} (min, max) in ms:",
        a.window.scene,
        gpu.info.name,
        gpu.info.backend,
        a.repeats.max(1)
    );
    for (name, (median, lo, hi)) in [
        ("the film alone", film),
        (&format!("moving: the 1/{s} preview upscaled, the film empty") as &str, moving),
        ("after the stop: film, preview and history blended", stopped),
    ] {
        println!("  {name}: {median:.1} ({lo:.1}, {hi:.1})");
    }
    Ok(())
}
