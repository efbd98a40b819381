//! `rastergi view`: a window showing the progressive image as it converges; the camera moves
//! with the keyboard and mouse, and every move restarts the accumulation (the photon map is
//! kept).
//!
//! The loop, per displayed frame: apply held keys and the script's due steps to the camera;
//! if the camera moved, `Renderer::set_camera` restarts the image; spend the frame budget
//! (`--frame-budget`, 50 ms) coarse to fine ([`rastergi::session::refine`]: a preview at a
//! fraction of the window's size while the camera moves, the previews refined once it stops,
//! then the window's own iterations, in row bands where one takes longer than the budget);
//! resolve the film blended with the finest preview (or, with the
//! denoiser on, its denoised image, filtered again only when due: `app.rs`) and draw it
//! ([`rastergi::passes::display`]) with the control panel over it; present. Building a renderer
//! (photon tracing, or opening a scene) runs on a worker thread so the window stays live
//! meanwhile; new settings build a new renderer at the window's size (the film is the window's size) and shows the
//! old image, scaled, until it is ready. A resize alone keeps the scene and photon map and
//! rebuilds only the size-dependent passes (`Renderer::resize`). While the window is minimised, occluded or zero-sized
//! the loop waits for events and renders nothing.
//!
//! The control panel ([`panel`], egui drawn by egui-wgpu on the same device over the image;
//! H hides it) opens scenes (a path, the built-in list, a file browser, or a file dropped on
//! the window), switches between the photon map and the path tracer, sets the gather, the
//! photon map, the sun, the environment's scale, the camera and the display, and shows the
//! iterations per second, the estimated error, the photon pass, the GPU memory and a
//! convergence plot. Each of its widgets gives a script [`script::Action`], applied as a
//! script's is; the window title repeats the main figures.
//!
//! Scripts (`--script`) are described in [`script`].
//!
//! The parts: [`controls`] (window-free input handling: keys, drags, script actions and what
//! each asks of the application), [`app`] (the winit application: window, renderer builds,
//! the frame loop), [`panel`], [`screenshots`] and [`script`].

mod app;
mod build;
pub(crate) mod controls;
mod frames;
mod keys;
pub(crate) mod panel;
mod screenshots;
mod script;

use std::path::PathBuf;

use anyhow::{Result, anyhow, bail};
use clap::Args;
use winit::event_loop::EventLoop;

use crate::args::SceneArgs;
use app::{App, UserEvent};
use screenshots::Screenshots;

/// The keys and mouse bindings (a macro so that `--help` can join it to the script text).
macro_rules! keys_text {
    () => {
        "\
Keys and mouse:
  W A S D / Q E     fly forward, left, back, right / down, up (Shift: 4x faster)
  left drag         look around (fly mode) or orbit the target (orbit mode)
  right drag        pan
  scroll            zoom toward the target
  Tab               switch fly / orbit mode
  Home              back to the starting camera
  1 2 3 4           show full / direct / indirect / photon map (no restart)
  + -               exposure up / down by half a stop
  N                 denoiser on / off (photon map, full image; the first time restarts the image)
  [ ]               halve / double the photons (re-traces the photon map)
  , .               halve / double the photon grid resolution (re-traces)
  J L / I K         turn the sun (the scene's distant light): azimuth / elevation by 5 degrees (re-traces)
  P                 screenshot: rastergi-NNNN.png (as shown) and .exr (linear)
  H                 hide / show the control panel
  Esc               quit
Any camera move restarts the accumulation; the photon map is kept.\n"
    };
}

/// The keys, for the start-up message.
pub const KEYS: &str = keys_text!();

#[derive(Args, Clone, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Timed actions to run, one per line (see `rastergi view --help` for the format).
    #[arg(long)]
    script: Option<PathBuf>,
    /// Directory for screenshots (default: the current directory).
    #[arg(long)]
    screenshot_dir: Option<PathBuf>,
    /// Start with the denoiser on (N and the panel's checkbox toggle it; docs/denoiser.md):
    /// its guides accumulate from the first iteration. Photon map method, full image only.
    #[arg(long)]
    denoise: bool,
    /// Milliseconds a frame aims at: while the camera moves each frame draws a preview at the
    /// finest fraction of the window's size that fits (1/2 … 1/32, upscaled); once it stops
    /// the previews refine, then the window's own iterations accumulate, in row bands where
    /// one is longer than this. 0: one whole iteration a frame, whatever it takes.
    #[arg(long, default_value_t = 50.0, value_parser = parse_budget)]
    frame_budget: f64,
}

/// A frame budget in milliseconds: finite, 0 or more.
fn parse_budget(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("'{s}' is not a number of milliseconds, 0 or more (e.g. 50; 0 turns the budget off)")),
    }
}

/// The `after_help` of `rastergi view`: the keys and the script format.
pub const AFTER_HELP: &str = concat!(
    keys_text!(),
    "
Script (--script FILE): one action per line, optionally after a condition; # comments.
  after N iterations: ACTION   once the image holds N iterations since its last restart
  after T s: ACTION            T seconds after the previous line
  ACTION                       right after the previous line
Actions: move R,U,F | look YAW,PITCH | orbit YAW,PITCH | pan X,Y | zoom STEPS |
  mode fly|orbit | speed S | home | show full|direct|indirect|photon-map | exposure EV | denoise on|off |
  photons N | grid N | passes N | sun AZIMUTH,ELEVATION | env-scale S | method gather|path |
  gather auto|raster|lists|trace | gather-directions per-pixel|shared | directions N |
  open SCENE | panel on|off | resize W,H | screenshot | quit
The control panel's widgets act through the same actions.
Each screenshot prints its files and the camera as render options to stdout."
);

pub fn run(args: &ViewArgs) -> Result<()> {
    let mut args = args.clone();
    // Everything that can be checked without a window is checked first.
    let steps = args.script.as_deref().map(script::load).transpose()?;
    // No directory: names relative to the current directory, printed as such.
    let dir = args.screenshot_dir.clone().unwrap_or_default();
    if args.screenshot_dir.is_some() && !dir.is_dir() {
        bail!(
            "{}: the screenshot directory does not exist; create it first or choose another --screenshot-dir",
            dir.display()
        );
    }
    let scene = args.scene.load_scene()?;
    // The window's first size: the scene file's film unless given.
    let (width, height) = args.scene.image_size(&scene);
    args.scene.width = Some(width);
    args.scene.height = Some(height);
    let a = &args.scene;
    let base = a.settings(&scene, width, height, true);
    // Building the first renderer validates the rest; check the size here for a clear error.
    if width == 0 || height == 0 {
        bail!("the window size {width}x{height} is empty; give a --width and --height of at least 1");
    }

    check_display()?;
    let event_loop = EventLoop::<UserEvent>::with_user_event().build().map_err(|e| {
        // winit's OS errors start with the source location that raised them: keep the message.
        let message = e.to_string();
        let message = match message.strip_prefix("os error at ") {
            Some(rest) => rest.split_once(": ").map_or(rest, |(_, m)| m).to_owned(),
            None => message,
        };
        anyhow!("cannot open a window: {message} (DISPLAY={})", std::env::var("DISPLAY").unwrap_or_default())
    })?;
    println!("rastergi view: {}\n{KEYS}", a.scene);
    let mut app = App::new(a, scene, base, steps, Screenshots::new(dir), event_loop.create_proxy());
    app.controls.denoise = args.denoise;
    app.frame_budget = args.frame_budget / 1000.0;
    event_loop.run_app(&mut app).map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    app.finish()
}

/// On X11/Wayland systems, refuses to start without a display to talk to.
fn check_display() -> Result<()> {
    if cfg!(all(unix, not(any(target_os = "macos", target_os = "ios", target_os = "android"))))
        && ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"]
            .iter()
            .all(|v| std::env::var_os(v).is_none_or(|s| s.is_empty()))
    {
        bail!(
            "cannot open a window: no display (DISPLAY and WAYLAND_DISPLAY are not set); run it in a desktop session, under xvfb-run, or use `rastergi render` for images without a window"
        );
    }
    Ok(())
}
