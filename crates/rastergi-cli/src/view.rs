//! `rastergi view`: a window showing the progressive image as it converges; the camera moves
//! with the keyboard and mouse, and every move restarts the accumulation (the photon map is
//! kept).
//!
//! The loop, per displayed frame: apply held keys and the script's due steps to the camera;
//! if the camera moved, `Renderer::set_camera` restarts the image; run as many iterations as
//! fit in [`FRAME_BUDGET`] of GPU time (at least one); resolve the film and draw it with the
//! overlay ([`rastergi::display`]); present. Building a renderer (photon tracing) runs on a
//! worker thread so the window stays live meanwhile; a new photon count or grid
//! builds a new renderer at the window's size (the film is the window's size) and shows the
//! old image, scaled, until it is ready. A resize alone keeps the scene and photon map and
//! rebuilds only the size-dependent passes (`Renderer::resize`). While the window is minimised, occluded or zero-sized
//! the loop waits for events and renders nothing.
//!
//! The overlay (top left; H hides it) shows the iterations, iterations per second, photons,
//! grid and bundle resolution, what is shown, the exposure and the drag mode; the window title
//! repeats the main figures. It is drawn with a small bitmap font in the display shader: the
//! egui-wgpu releases built on wgpu 30 require Rust 1.95, above this project's 1.88.
//!
//! Scripts (`--script`) are described in [`crate::script`].

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use rastergi::camera_control::{CameraControl, Mode, MoveKeys};
use rastergi::display::{Presented, WindowSurface};
use rastergi::film::Show;
use rastergi::gpu::{Gpu, GpuOptions};
use rastergi::image_io::{write_exr, write_png};
use rastergi::renderer::{RenderSettings, Renderer, default_bundle};
use rastergi::scene::{Camera, Scene};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::keyboard::{Key as LogicalKey, KeyCode, NamedKey, PhysicalKey};
use winit::window::{Window, WindowId};

use crate::args::SceneArgs;
use crate::script::{self, Action, Step, When};

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
  [ ]               halve / double the photons (re-traces the photon map)
  , .               halve / double the photon grid resolution (re-traces)
  P                 screenshot: rastergi-NNNN.png (as shown) and .exr (linear)
  H                 hide / show the overlay
  Esc               quit
Any camera move restarts the accumulation; the photon map is kept.\n"
    };
}

/// The keys, for the start-up message.
pub const KEYS: &str = keys_text!();

/// GPU time aimed at per displayed frame: iterations are batched up to this.
pub const FRAME_BUDGET: Duration = Duration::from_millis(30);
/// Most iterations in one frame (keeps a frame short when iterations are very cheap).
const MAX_BATCH: u32 = 64;
/// A resize rebuilds the size-dependent passes once the window size has been still this long.
const RESIZE_SETTLE: Duration = Duration::from_millis(150);
/// How long a script's `resize` may wait for the window to take the new size.
const RESIZE_TIMEOUT: Duration = Duration::from_secs(10);

#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Timed actions to run, one per line (see `rastergi view --help` for the format).
    #[arg(long)]
    script: Option<PathBuf>,
    /// Directory for screenshots (default: the current directory).
    #[arg(long)]
    screenshot_dir: Option<PathBuf>,
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
  mode fly|orbit | show full|direct|indirect|photon-map | exposure EV | photons N |
  grid N | resize W,H | screenshot | quit
Each screenshot prints its files and the camera as render options to stdout."
);

/// A key that means something to the viewer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Key {
    Forward,
    Back,
    Left,
    Right,
    Up,
    Down,
    Fast,
    ToggleMode,
    Home,
    Show(Show),
    ExposureUp,
    ExposureDown,
    FewerPhotons,
    MorePhotons,
    CoarserGrid,
    FinerGrid,
    Screenshot,
    ToggleOverlay,
    Quit,
}

/// The viewer's meaning of a keyboard event: movement by key position (WASD wherever the
/// layout puts those letters), the rest by position or by the character typed.
fn key_of(event: &KeyEvent) -> Option<Key> {
    if let PhysicalKey::Code(code) = event.physical_key {
        let key = match code {
            KeyCode::KeyW | KeyCode::ArrowUp => Some(Key::Forward),
            KeyCode::KeyS | KeyCode::ArrowDown => Some(Key::Back),
            KeyCode::KeyA | KeyCode::ArrowLeft => Some(Key::Left),
            KeyCode::KeyD | KeyCode::ArrowRight => Some(Key::Right),
            KeyCode::KeyE | KeyCode::PageUp => Some(Key::Up),
            KeyCode::KeyQ | KeyCode::PageDown => Some(Key::Down),
            KeyCode::ShiftLeft | KeyCode::ShiftRight => Some(Key::Fast),
            KeyCode::Tab => Some(Key::ToggleMode),
            KeyCode::Home => Some(Key::Home),
            KeyCode::Digit1 | KeyCode::Numpad1 => Some(Key::Show(Show::Full)),
            KeyCode::Digit2 | KeyCode::Numpad2 => Some(Key::Show(Show::Direct)),
            KeyCode::Digit3 | KeyCode::Numpad3 => Some(Key::Show(Show::Indirect)),
            KeyCode::Digit4 | KeyCode::Numpad4 => Some(Key::Show(Show::PhotonMap)),
            KeyCode::NumpadAdd => Some(Key::ExposureUp),
            KeyCode::NumpadSubtract => Some(Key::ExposureDown),
            KeyCode::BracketLeft => Some(Key::FewerPhotons),
            KeyCode::BracketRight => Some(Key::MorePhotons),
            KeyCode::Comma => Some(Key::CoarserGrid),
            KeyCode::Period => Some(Key::FinerGrid),
            KeyCode::KeyP => Some(Key::Screenshot),
            KeyCode::KeyH | KeyCode::F1 => Some(Key::ToggleOverlay),
            KeyCode::Escape => Some(Key::Quit),
            _ => None,
        };
        if key.is_some() {
            return key;
        }
    }
    match &event.logical_key {
        LogicalKey::Character(c) if c == "+" || c == "=" => Some(Key::ExposureUp),
        LogicalKey::Character(c) if c == "-" || c == "_" => Some(Key::ExposureDown),
        LogicalKey::Named(NamedKey::Escape) => Some(Key::Quit),
        _ => None,
    }
}

/// What the application must do after an input.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Response {
    /// The camera moved: restart the accumulation.
    pub camera_moved: bool,
    /// The photon settings changed: build a new renderer (new photon map).
    pub retrace: bool,
    pub screenshot: bool,
    pub quit: bool,
}

/// Exposure step of the + and - keys, in stops.
pub const EXPOSURE_STEP: f32 = 0.5;

/// The viewer's interactive state, free of any window: the camera controller, held keys,
/// what is shown and the photon settings. Inputs come in as [`Key`]s, drags and scrolls and
/// return what the application must do.
#[derive(Clone, Debug)]
pub struct Controls {
    pub camera: CameraControl,
    home: CameraControl,
    pub keys: MoveKeys,
    pub show: Show,
    pub exposure: f32,
    pub photons: u32,
    pub grid: u32,
    pub overlay: bool,
}

impl Controls {
    pub fn new(camera: CameraControl, show: Show, exposure: f32, photons: u32, grid: u32) -> Controls {
        Controls {
            home: camera.clone(),
            camera,
            keys: MoveKeys::default(),
            show,
            exposure,
            photons,
            grid,
            overlay: true,
        }
    }

    /// A key went down (`pressed`) or up. Held keys (movement, Shift) act in [`tick`](Self::tick).
    pub fn key(&mut self, key: Key, pressed: bool, repeat: bool) -> Response {
        let mut r = Response::default();
        let held = match key {
            Key::Forward => Some(&mut self.keys.forward),
            Key::Back => Some(&mut self.keys.back),
            Key::Left => Some(&mut self.keys.left),
            Key::Right => Some(&mut self.keys.right),
            Key::Up => Some(&mut self.keys.up),
            Key::Down => Some(&mut self.keys.down),
            Key::Fast => Some(&mut self.keys.fast),
            _ => None,
        };
        if let Some(state) = held {
            *state = pressed;
            return r;
        }
        if !pressed {
            return r;
        }
        // Auto-repeat steps the exposure; other keys act once per press.
        match key {
            Key::ExposureUp => self.exposure += EXPOSURE_STEP,
            Key::ExposureDown => self.exposure -= EXPOSURE_STEP,
            _ if repeat => {}
            Key::ToggleMode => self.camera.toggle_mode(),
            Key::Home => {
                let (mode, speed) = (self.camera.mode, self.camera.speed);
                r.camera_moved = self.camera.camera() != self.home.camera();
                self.camera = self.home.clone();
                (self.camera.mode, self.camera.speed) = (mode, speed);
            }
            Key::Show(show) => self.show = show,
            Key::FewerPhotons => r.retrace = self.set_photons(self.photons / 2),
            Key::MorePhotons => r.retrace = self.set_photons(self.photons.saturating_mul(2)),
            Key::CoarserGrid => r.retrace = self.set_grid(self.grid / 2),
            Key::FinerGrid => r.retrace = self.set_grid(self.grid * 2),
            Key::Screenshot => r.screenshot = true,
            Key::ToggleOverlay => self.overlay = !self.overlay,
            Key::Quit => r.quit = true,
            _ => {}
        }
        r
    }

    /// Photons for the next photon map (at least 1); whether that is a change.
    pub fn set_photons(&mut self, photons: u32) -> bool {
        let photons = photons.max(1);
        std::mem::replace(&mut self.photons, photons) != photons
    }

    /// Grid resolution for the next photon map (1 to 1024); whether that is a change.
    pub fn set_grid(&mut self, grid: u32) -> bool {
        let grid = grid.clamp(1, 1024);
        std::mem::replace(&mut self.grid, grid) != grid
    }

    /// Time passes with the held keys down: fly.
    pub fn tick(&mut self, dt: f32) -> Response {
        Response { camera_moved: self.camera.fly(&self.keys, dt), ..Default::default() }
    }

    /// A drag by `(dx, dy)` pixels with the left (look/orbit) or right (pan) button.
    pub fn drag(&mut self, dx: f32, dy: f32, pan: bool, viewport_height: f32) -> Response {
        let moved = if pan { self.camera.pan(dx, dy, viewport_height) } else { self.camera.drag(dx, dy) };
        Response { camera_moved: moved, ..Default::default() }
    }

    /// Scroll by `steps` notches (positive: toward the target).
    pub fn scroll(&mut self, steps: f32) -> Response {
        Response { camera_moved: self.camera.zoom(steps), ..Default::default() }
    }

    /// Keys are no longer reported once the window loses focus: release them all.
    pub fn release_keys(&mut self) {
        self.keys = MoveKeys::default();
    }

    /// A script action that the controls handle (camera, show, exposure, photon settings).
    pub fn action(&mut self, action: &Action, viewport_height: f32) -> Response {
        let mut r = Response::default();
        let c = &mut self.camera;
        match *action {
            Action::Move { right, up, forward } => r.camera_moved = c.translate(right, up, forward),
            Action::Look { yaw_deg, pitch_deg } => {
                r.camera_moved = c.look(yaw_deg.to_radians(), pitch_deg.to_radians())
            }
            Action::Orbit { yaw_deg, pitch_deg } => {
                r.camera_moved = c.orbit(yaw_deg.to_radians(), pitch_deg.to_radians())
            }
            Action::Pan { dx, dy } => r.camera_moved = c.pan(dx, dy, viewport_height),
            Action::Zoom { steps } => r.camera_moved = c.zoom(steps),
            Action::Mode { orbit } => {
                if (c.mode == Mode::Orbit) != orbit {
                    c.toggle_mode();
                }
            }
            Action::Show(show) => self.show = show,
            Action::Exposure(ev) => self.exposure = ev,
            Action::Photons(n) => r.retrace = self.set_photons(n),
            Action::Grid(n) => r.retrace = self.set_grid(n),
            Action::Screenshot => r.screenshot = true,
            Action::Quit => r.quit = true,
            Action::Resize { .. } => {}
        }
        r
    }
}

/// The camera as `render` options, with every value printed so that it parses back to the
/// same f32.
pub fn camera_options(c: &Camera) -> String {
    let v = |v: glam::Vec3| format!("{},{},{}", v.x, v.y, v.z);
    format!("--eye {} --target {} --up {} --fov {}", v(c.eye), v(c.target), v(c.up), c.fov_y_deg)
}

fn show_name(show: Show) -> &'static str {
    match show {
        Show::Full => "full",
        Show::Direct => "direct",
        Show::Indirect => "indirect",
        Show::PhotonMap => "photon-map",
    }
}

/// Screenshot names `rastergi-NNNN.png` / `.exr` in a directory, counting up.
struct Screenshots {
    dir: PathBuf,
    next: u32,
}

impl Screenshots {
    /// Reserves the first `rastergi-NNNN` at or after the counter for which neither the PNG
    /// nor the EXR exists, by creating both empty (`create_new`): existing files are never
    /// overwritten, and another viewer saving into the same directory cannot take the name.
    fn reserve(&mut self) -> Result<(PathBuf, PathBuf)> {
        for n in self.next..=9999 {
            let png = self.dir.join(format!("rastergi-{n:04}.png"));
            let exr = self.dir.join(format!("rastergi-{n:04}.exr"));
            let create = |p: &Path| std::fs::OpenOptions::new().write(true).create_new(true).open(p);
            match create(&png) {
                Ok(_) => {}
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e).with_context(|| format!("{}: cannot create the screenshot", png.display())),
            }
            match create(&exr) {
                Ok(_) => {}
                Err(e) => {
                    let _ = std::fs::remove_file(&png);
                    if e.kind() == std::io::ErrorKind::AlreadyExists {
                        continue;
                    }
                    return Err(e).with_context(|| format!("{}: cannot create the screenshot", exr.display()));
                }
            }
            self.next = n + 1;
            return Ok((png, exr));
        }
        bail!("{}: rastergi-0000 to rastergi-9999 are all taken; choose another --screenshot-dir", self.dir.display())
    }

    /// Saves the image as shown (PNG) and its linear radiance (EXR); returns the two paths.
    fn save(&mut self, renderer: &Renderer, show: Show, exposure: f32) -> Result<(PathBuf, PathBuf)> {
        let display = renderer.read_display(show, exposure)?;
        let linear = renderer.read_linear(show)?;
        let (png, exr) = self.reserve()?;
        let written = write_png(&png, &display).and_then(|()| write_exr(&exr, &linear));
        if let Err(e) = written {
            let _ = std::fs::remove_file(&png);
            let _ = std::fs::remove_file(&exr);
            return Err(e.into());
        }
        Ok((png, exr))
    }
}

/// Iterations per second over the last half second or more.
struct Rate {
    since: Instant,
    count: u32,
    per_second: f64,
}

impl Rate {
    fn add(&mut self, iterations: u32) {
        self.count += iterations;
        let dt = self.since.elapsed().as_secs_f64();
        if dt >= 0.5 {
            self.per_second = self.count as f64 / dt;
            self.since = Instant::now();
            self.count = 0;
        }
    }
}

/// A renderer being built on a worker thread.
enum UserEvent {
    Built { generation: u64, result: Result<Renderer, String> },
}

/// The script's progress.
struct ScriptRun {
    steps: Vec<Step>,
    next: usize,
    /// When the previous step ran.
    last: Instant,
    /// A `resize` waiting for the image to take that size, and since when.
    resizing: Option<((u32, u32), Instant)>,
}

struct App {
    args_scene: String,
    scene: Arc<Scene>,
    base: RenderSettings,
    gpu_options: GpuOptions,
    proxy: EventLoopProxy<UserEvent>,
    window: Option<Arc<Window>>,
    gpu: Option<Gpu>,
    surface: Option<WindowSurface>,
    renderer: Option<Renderer>,
    /// The generation of the build in flight, if any; results of older ones are dropped.
    building: Option<u64>,
    generation: u64,
    controls: Controls,
    /// The window's inner size (0 while minimised on some platforms).
    size: (u32, u32),
    /// When the size last changed, until a renderer of that size is on its way.
    resized_at: Option<Instant>,
    occluded: bool,
    retry_at: Option<Instant>,
    /// Mouse buttons held (left, right) and the last cursor position.
    dragging: (bool, bool),
    cursor: Option<(f64, f64)>,
    last_frame: Instant,
    batch: u32,
    rate: Rate,
    title_at: Instant,
    status: String,
    script: Option<ScriptRun>,
    screenshots: Screenshots,
    error: Option<anyhow::Error>,
}

pub fn run(args: &ViewArgs) -> Result<()> {
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
    let a = &args.scene;
    let scene = a.load_scene()?;
    let base = a.settings(&scene, a.width, a.height, true);
    // Building the first renderer validates the rest; check the size here for a clear error.
    if a.width == 0 || a.height == 0 {
        bail!("the window size {}x{} is empty; give a --width and --height of at least 1", a.width, a.height);
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
    let camera = CameraControl::new(&scene.camera, &scene.bounds());
    let mut app = App {
        args_scene: a.scene.clone(),
        scene: Arc::new(scene),
        controls: Controls::new(camera, a.show.show(), a.exposure.unwrap_or(0.0), base.photons, base.grid_resolution),
        base,
        gpu_options: a.gpu.options(),
        proxy: event_loop.create_proxy(),
        window: None,
        gpu: None,
        surface: None,
        renderer: None,
        building: None,
        generation: 0,
        size: (a.width, a.height),
        resized_at: None,
        occluded: false,
        retry_at: None,
        dragging: (false, false),
        cursor: None,
        last_frame: Instant::now(),
        batch: 1,
        rate: Rate { since: Instant::now(), count: 0, per_second: 0.0 },
        title_at: Instant::now(),
        status: String::new(),
        script: steps.map(|steps| ScriptRun { steps, next: 0, last: Instant::now(), resizing: None }),
        screenshots: Screenshots { dir, next: 1 },
        error: None,
    };
    event_loop.run_app(&mut app).map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
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

impl App {
    /// Stops with an error (reported once the event loop has returned).
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        event_loop.exit();
    }

    /// The settings a renderer for the current window and controls would have.
    fn wanted(&self) -> RenderSettings {
        RenderSettings {
            width: self.size.0,
            height: self.size.1,
            photons: self.controls.photons,
            grid_resolution: self.controls.grid,
            ..self.base.clone()
        }
    }

    /// Whether the current renderer (if any) was built with `settings`.
    fn renderer_matches(&self, s: &RenderSettings) -> bool {
        self.renderer.as_ref().is_some_and(|r| {
            let t = r.settings();
            (t.width, t.height, t.photons, t.grid_resolution) == (s.width, s.height, s.photons, s.grid_resolution)
        })
    }

    /// Starts building a renderer with the wanted settings on a worker thread.
    fn start_build(&mut self) {
        let Some(gpu) = self.gpu.clone() else { return };
        let settings = self.wanted();
        if settings.width == 0 || settings.height == 0 {
            return;
        }
        self.generation += 1;
        self.building = Some(self.generation);
        self.resized_at = None;
        let generation = self.generation;
        let mut scene = (*self.scene).clone();
        scene.camera = self.controls.camera.camera();
        let proxy = self.proxy.clone();
        self.status = format!("tracing {} photons...", settings.photons);
        std::thread::spawn(move || {
            // A panic (wgpu reports validation errors so) must still answer, or the viewer
            // would wait forever; the panic message itself is already on stderr.
            let build = std::panic::AssertUnwindSafe(|| Renderer::new(&gpu, &scene, settings));
            let result = match std::panic::catch_unwind(build) {
                Ok(built) => built.map_err(|e| e.to_string()),
                Err(_) => Err("building the renderer failed (see the message above)".to_owned()),
            };
            // The viewer may have closed meanwhile; then nobody is listening.
            let _ = proxy.send_event(UserEvent::Built { generation, result });
        });
    }

    fn redraw(&self) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }

    fn apply(&mut self, event_loop: &ActiveEventLoop, r: Response) {
        // While a new renderer is being built the old image stays as it is; the new one
        // starts from the camera of the moment it arrives.
        if r.camera_moved
            && self.building.is_none()
            && let Err(e) = self.sync_camera()
        {
            return self.fail(event_loop, e);
        }
        if r.retrace {
            // Applied by about_to_wait once no build is in flight.
            self.status = format!("photons {}, grid {}: re-tracing", self.controls.photons, self.controls.grid);
        }
        if r.screenshot {
            self.screenshot();
        }
        if r.quit {
            event_loop.exit();
        }
    }

    /// Gives the renderer the controls' camera if it has another one (restarting the image).
    fn sync_camera(&mut self) -> Result<()> {
        let camera = self.controls.camera.camera();
        if let Some(renderer) = &mut self.renderer
            && renderer.camera() != camera
        {
            renderer.set_camera(camera)?;
        }
        Ok(())
    }

    fn screenshot(&mut self) {
        let Some(renderer) = &self.renderer else {
            self.status = "no image yet to save".into();
            return;
        };
        let (show, exposure) = (self.controls.show, self.controls.exposure);
        match self.screenshots.save(renderer, show, exposure) {
            Ok((png, exr)) => {
                println!(
                    "screenshot: {} {} ({} iterations, {}x{}, show {}, exposure {}; camera {})",
                    png.display(),
                    exr.display(),
                    renderer.samples(),
                    renderer.settings().width,
                    renderer.settings().height,
                    show_name(show),
                    exposure,
                    camera_options(&renderer.camera())
                );
                self.status = format!("saved {}", png.display());
            }
            Err(e) => {
                eprintln!("warning: the screenshot failed: {e:#}");
                self.status = format!("screenshot failed: {e:#}");
            }
        }
    }

    /// Runs the script's steps that are due. Steps wait while no renderer of the window's
    /// size and settings is ready.
    fn run_script(&mut self, event_loop: &ActiveEventLoop) {
        loop {
            let ready = self.building.is_none() && self.renderer_matches(&self.wanted());
            let Some(run) = &mut self.script else { return };
            if let Some((size, since)) = run.resizing {
                if ready && self.size == size {
                    run.resizing = None;
                    run.last = Instant::now();
                } else if since.elapsed() > RESIZE_TIMEOUT {
                    let e = anyhow!("script: the window did not take the size {}x{} asked for", size.0, size.1);
                    return self.fail(event_loop, e);
                } else {
                    return;
                }
            }
            let Some(step) = run.steps.get(run.next).copied() else { return };
            if !ready {
                return;
            }
            let samples = self.renderer.as_ref().map_or(0, |r| r.samples());
            let due = match step.when {
                When::Now => true,
                When::Iterations(n) => samples >= n,
                When::Elapsed(t) => run.last.elapsed() >= t,
            };
            if !due {
                return;
            }
            run.next += 1;
            run.last = Instant::now();
            log::info!("script line {}: {:?}", step.line, step.action);
            if let Action::Resize { width, height } = step.action {
                run.resizing = Some(((width, height), Instant::now()));
                if let Some(w) = &self.window {
                    let _ = w.request_inner_size(PhysicalSize::new(width, height));
                }
                continue;
            }
            let r = self.controls.action(&step.action, self.size.1 as f32);
            self.apply(event_loop, r);
        }
    }

    /// The most iterations this frame may run: the script's next `after N iterations` must
    /// find exactly N.
    fn iteration_limit(&self) -> u32 {
        let samples = self.renderer.as_ref().map_or(0, |r| r.samples());
        match &self.script {
            Some(run) if run.resizing.is_none() => match run.steps.get(run.next) {
                Some(Step { when: When::Iterations(n), .. }) => n.saturating_sub(samples),
                _ => u32::MAX,
            },
            _ => u32::MAX,
        }
    }

    /// Runs this frame's iterations: as many as fit in [`FRAME_BUDGET`] by the last frame's
    /// time per iteration, at least one, stopping where the script waits for a count. Only a
    /// renderer that fits the window and is not about to be replaced iterates.
    fn iterate_batch(&mut self) -> Result<()> {
        let current = self.building.is_none() && self.renderer_matches(&self.wanted());
        let limit = self.batch.min(self.iteration_limit());
        let Some(renderer) = self.renderer.as_mut().filter(|_| current) else { return Ok(()) };
        let start = Instant::now();
        let mut done = 0;
        while done < limit {
            renderer.iterate()?;
            done += 1;
            if start.elapsed() >= FRAME_BUDGET {
                break;
            }
        }
        if done > 0 {
            renderer.wait()?;
            let per_iteration = start.elapsed().as_secs_f64() / done as f64;
            self.batch = ((FRAME_BUDGET.as_secs_f64() / per_iteration.max(1e-6)) as u32).clamp(1, MAX_BATCH);
            self.rate.add(done);
        }
        Ok(())
    }

    /// One displayed frame: input over time, script, iterations, resolve, draw, present.
    fn frame(&mut self, event_loop: &ActiveEventLoop) {
        let now = Instant::now();
        // A stall (a slow build, a dragged window) must not turn into a long flight.
        let dt = now.duration_since(self.last_frame).min(Duration::from_millis(100));
        self.last_frame = now;
        let r = self.controls.tick(dt.as_secs_f32());
        self.apply(event_loop, r);
        self.run_script(event_loop);
        if self.error.is_some() {
            return;
        }
        let Some(gpu) = self.gpu.clone() else { return };

        if let Err(e) = self.iterate_batch() {
            return self.fail(event_loop, e);
        }

        let overlay = if self.controls.overlay { self.overlay_lines() } else { Vec::new() };
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        if let Some(renderer) = &self.renderer {
            renderer.encode_resolve(&mut enc, self.controls.show, self.controls.exposure);
        }
        let Some(surface) = &mut self.surface else { return };
        match surface.present(&gpu, enc, self.renderer.as_ref().map(|r| r.film()), &overlay) {
            Ok(Presented::Shown) => self.retry_at = None,
            Ok(Presented::Skipped) => self.retry_at = Some(Instant::now() + Duration::from_millis(100)),
            Err(e) => return self.fail(event_loop, e.into()),
        }
        if self.title_at.elapsed() >= Duration::from_millis(500) {
            self.title_at = Instant::now();
            if let Some(w) = &self.window {
                w.set_title(&self.title());
            }
        }
    }

    fn title(&self) -> String {
        let samples = self.renderer.as_ref().map_or(0, |r| r.samples());
        format!(
            "rastergi - {} - {} iterations, {:.1}/s - {} - {}",
            self.args_scene,
            samples,
            self.rate.per_second,
            show_name(self.controls.show),
            self.controls.camera.mode.name()
        )
    }

    fn overlay_lines(&self) -> Vec<String> {
        let c = &self.controls;
        let s = self.renderer.as_ref().map_or_else(|| self.wanted(), |r| r.settings().clone());
        // The renderer's own bundle: 0 in the settings is fitted to the scene as well.
        let fitted = self.renderer.as_ref().map_or(0, |r| r.bundle());
        let bundle = if fitted > 0 {
            fitted
        } else if s.bundle == 0 {
            default_bundle(s.width, s.height)
        } else {
            s.bundle
        };
        let samples = self.renderer.as_ref().map_or(0, |r| r.samples());
        let size = (s.width, s.height);
        let mut lines = vec![
            format!("{}  {}x{}  {} mode", self.args_scene, size.0, size.1, c.camera.mode.name()),
            format!("iterations {samples}  ({:.1}/s, {} per frame)", self.rate.per_second, self.batch),
            format!("photons {}  grid {}  bundle {}", c.photons, c.grid, bundle),
            format!("show {} [1-4]  exposure {:+.1} EV [+/-]", show_name(c.show), c.exposure),
        ];
        if !self.status.is_empty() {
            lines.push(self.status.clone());
        }
        lines.push("WASDQE drag scroll  Tab mode  P save  H hide".into());
        lines
    }
}

impl ApplicationHandler<UserEvent> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title(format!("rastergi - {}", self.args_scene))
            .with_inner_size(PhysicalSize::new(self.size.0, self.size.1));
        let window = match event_loop.create_window(attributes) {
            Ok(w) => Arc::new(w),
            Err(e) => return self.fail(event_loop, anyhow!("cannot open a window: {e}")),
        };
        let size = window.inner_size();
        if size.width > 0 && size.height > 0 {
            self.size = (size.width, size.height);
        }
        let display = event_loop.owned_display_handle();
        match WindowSurface::open(&self.gpu_options, display, window.clone(), self.size.0, self.size.1) {
            Ok((gpu, surface)) => {
                self.gpu = Some(gpu);
                self.surface = Some(surface);
            }
            Err(e) => return self.fail(event_loop, e.into()),
        }
        self.window = Some(window);
        self.start_build();
        self.redraw();
    }

    fn user_event(&mut self, event_loop: &ActiveEventLoop, event: UserEvent) {
        let UserEvent::Built { generation, result } = event;
        if self.building != Some(generation) {
            return;
        }
        self.building = None;
        match result {
            Ok(renderer) => {
                self.status.clear();
                self.renderer = Some(renderer);
                if let Some(run) = &mut self.script {
                    run.last = Instant::now();
                }
            }
            Err(e) if self.renderer.is_none() => return self.fail(event_loop, anyhow!(e)),
            Err(e) => {
                // Keep the image that works; go back to its settings.
                eprintln!("warning: {e}");
                self.status = format!("re-trace failed: {e}");
                if let Some(r) = &self.renderer {
                    self.controls.photons = r.settings().photons;
                    self.controls.grid = r.settings().grid_resolution;
                }
            }
        }
        if let Err(e) = self.sync_camera() {
            return self.fail(event_loop, e);
        }
        self.last_frame = Instant::now();
        self.redraw();
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let viewport_height = self.size.1 as f32;
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => event_loop.exit(),
            WindowEvent::Resized(size) => {
                // A zero size (minimised on some platforms) pauses rendering in about_to_wait;
                // the swapchain keeps its last size until a real one comes.
                if let (Some(gpu), Some(surface)) = (&self.gpu, &mut self.surface) {
                    surface.resize(gpu, size.width, size.height);
                }
                if (size.width, size.height) != self.size {
                    self.size = (size.width, size.height);
                    self.resized_at = Some(Instant::now());
                }
                self.redraw();
            }
            WindowEvent::Occluded(occluded) => {
                self.occluded = occluded;
                if !occluded {
                    self.redraw();
                }
            }
            WindowEvent::Focused(false) => self.controls.release_keys(),
            WindowEvent::ModifiersChanged(m) => self.controls.keys.fast = m.state().shift_key(),
            WindowEvent::KeyboardInput { event, .. } => {
                if let Some(key) = key_of(&event) {
                    let r = self.controls.key(key, event.state == ElementState::Pressed, event.repeat);
                    self.apply(event_loop, r);
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let pressed = state == ElementState::Pressed;
                match button {
                    MouseButton::Left => self.dragging.0 = pressed,
                    MouseButton::Right | MouseButton::Middle => self.dragging.1 = pressed,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let p = (position.x, position.y);
                if let Some(last) = self.cursor
                    && (self.dragging.0 || self.dragging.1)
                {
                    let (dx, dy) = ((p.0 - last.0) as f32, (p.1 - last.1) as f32);
                    let r = self.controls.drag(dx, dy, self.dragging.1, viewport_height);
                    self.apply(event_loop, r);
                }
                self.cursor = Some(p);
            }
            WindowEvent::CursorLeft { .. } => self.cursor = None,
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                let r = self.controls.scroll(steps);
                self.apply(event_loop, r);
            }
            WindowEvent::RedrawRequested => self.frame(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.error.is_some() || event_loop.exiting() {
            return;
        }
        let minimised = self.window.as_ref().and_then(|w| w.is_minimized()).unwrap_or(false);
        if minimised || self.occluded || self.size.0 == 0 || self.size.1 == 0 {
            // Nothing to show: sleep until the window manager says otherwise.
            event_loop.set_control_flow(ControlFlow::Wait);
            return;
        }
        // Replace the renderer when the window size or the photon settings changed, once the
        // size has settled and no other build is in flight.
        if self.building.is_none() && self.gpu.is_some() && !self.renderer_matches(&self.wanted()) {
            let settle = self.resized_at.map(|t| t + RESIZE_SETTLE);
            match settle {
                Some(at) if Instant::now() < at => {
                    event_loop.set_control_flow(ControlFlow::WaitUntil(at));
                    return;
                }
                _ => {
                    // A new size alone keeps the scene and its photon map: only the
                    // size-dependent passes are rebuilt. New photon settings re-trace.
                    let wanted = self.wanted();
                    let same_map = self.renderer.as_ref().is_some_and(|r| {
                        let t = r.settings();
                        (t.photons, t.grid_resolution) == (wanted.photons, wanted.grid_resolution)
                    });
                    match self.renderer.as_mut() {
                        Some(r) if same_map => {
                            self.resized_at = None;
                            if let Err(e) = r.resize(wanted.width, wanted.height) {
                                return self.fail(event_loop, e.into());
                            }
                        }
                        _ => self.start_build(),
                    }
                }
            }
        }
        if let Some(at) = self.retry_at {
            // The swapchain had nothing to give: try again shortly rather than spin.
            event_loop.set_control_flow(ControlFlow::WaitUntil(at));
            if Instant::now() >= at {
                self.redraw();
            }
            return;
        }
        if self.building.is_some() {
            // The finished build wakes the loop; keep the title's and overlay's status fresh.
            event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(250)));
            self.redraw();
            return;
        }
        event_loop.set_control_flow(ControlFlow::Wait);
        self.redraw();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use rastergi::scene::Aabb;

    fn controls() -> Controls {
        let camera = Camera { eye: Vec3::new(0.0, 0.0, 3.9), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 39.3077 };
        let bounds = Aabb { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) };
        Controls::new(CameraControl::new(&camera, &bounds), Show::Full, 0.0, 1 << 20, 64)
    }

    #[test]
    fn held_movement_keys_move_the_camera_on_tick_and_restart_the_image() {
        let mut c = controls();
        assert_eq!(c.key(Key::Forward, true, false), Response::default(), "pressing alone does nothing yet");
        let before = c.camera.camera();
        assert!(c.tick(0.1).camera_moved);
        assert!(c.camera.camera().eye.z < before.eye.z);
        c.key(Key::Forward, false, false);
        assert!(!c.tick(0.1).camera_moved, "released: no move, no restart");
        c.key(Key::Left, true, false);
        c.release_keys();
        assert!(!c.tick(0.1).camera_moved, "focus lost: keys released");
    }

    #[test]
    fn show_exposure_mode_and_overlay_keys_do_not_restart() {
        let mut c = controls();
        let camera = c.camera.camera();
        for key in [
            Key::Show(Show::PhotonMap),
            Key::ExposureUp,
            Key::ExposureUp,
            Key::ExposureDown,
            Key::ToggleMode,
            Key::ToggleOverlay,
            Key::Fast,
        ] {
            assert_eq!(c.key(key, true, false), Response::default(), "{key:?}");
        }
        assert_eq!((c.show, c.exposure, c.camera.mode, c.overlay), (Show::PhotonMap, 0.5, Mode::Orbit, false));
        assert_eq!(c.camera.camera(), camera);
        assert_eq!(c.action(&Action::Show(Show::Direct), 64.0), Response::default());
        assert_eq!(c.action(&Action::Mode { orbit: false }, 64.0), Response::default());
    }

    #[test]
    fn drags_scrolls_and_camera_actions_restart_and_home_returns() {
        let mut c = controls();
        let home = c.camera.camera();
        assert!(c.drag(10.0, 0.0, false, 64.0).camera_moved);
        assert!(c.drag(3.0, 2.0, true, 64.0).camera_moved);
        assert!(c.scroll(1.0).camera_moved);
        for a in [
            Action::Move { right: 0.1, up: 0.0, forward: 0.0 },
            Action::Look { yaw_deg: 5.0, pitch_deg: 0.0 },
            Action::Orbit { yaw_deg: 5.0, pitch_deg: 1.0 },
            Action::Pan { dx: 1.0, dy: 0.0 },
            Action::Zoom { steps: -1.0 },
        ] {
            assert!(c.action(&a, 64.0).camera_moved, "{a:?}");
        }
        assert!(c.key(Key::Home, true, false).camera_moved);
        assert_eq!(c.camera.camera(), home);
        assert!(!c.key(Key::Home, true, false).camera_moved, "already home");
    }

    #[test]
    fn photon_keys_ask_for_a_retrace_only_when_the_setting_changes() {
        let mut c = controls();
        assert!(c.key(Key::FewerPhotons, true, false).retrace);
        assert_eq!(c.photons, 1 << 19);
        assert!(!c.key(Key::MorePhotons, true, true).retrace, "auto-repeat does not re-trace again");
        assert!(c.key(Key::FinerGrid, true, false).retrace && c.grid == 128);
        c.grid = 1024;
        assert!(!c.key(Key::FinerGrid, true, false).retrace, "grid capped at 1024");
        assert!(c.action(&Action::Photons(7), 64.0).retrace && c.photons == 7);
        assert!(!c.action(&Action::Photons(7), 64.0).retrace);
        assert!(c.key(Key::Screenshot, true, false).screenshot && c.key(Key::Quit, true, false).quit);
    }

    #[test]
    fn camera_options_parse_back_to_the_same_camera() {
        let c = Camera {
            eye: Vec3::new(0.1, -2.5e-8, 3.900001),
            target: Vec3::new(-0.3333333, 0.0, -1.0),
            up: Vec3::Y,
            fov_y_deg: 39.3077,
        };
        let s = camera_options(&c);
        let value = |flag: &str| s.split_whitespace().skip_while(|w| *w != flag).nth(1).unwrap().to_owned();
        let vec3 = |t: String| {
            let v: Vec<f32> = t.split(',').map(|x| x.parse().unwrap()).collect();
            Vec3::new(v[0], v[1], v[2])
        };
        assert_eq!(vec3(value("--eye")), c.eye);
        assert_eq!(vec3(value("--target")), c.target);
        assert_eq!(value("--fov").parse::<f32>().unwrap(), c.fov_y_deg);
    }

    #[test]
    fn screenshots_never_overwrite_and_count_on() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("rastergi-0001.png"), b"keep").unwrap();
        std::fs::write(dir.path().join("rastergi-0002.exr"), b"keep").unwrap();
        let mut s = Screenshots { dir: dir.path().to_path_buf(), next: 1 };
        let (png, exr) = s.reserve().unwrap();
        assert_eq!(
            (png.file_name().unwrap(), exr.file_name().unwrap()),
            ("rastergi-0003.png".as_ref(), "rastergi-0003.exr".as_ref())
        );
        assert_eq!(std::fs::read(dir.path().join("rastergi-0001.png")).unwrap(), b"keep");
        assert!(!dir.path().join("rastergi-0002.png").exists(), "a half-taken pair is left alone");
        assert_eq!(s.reserve().unwrap().0.file_name().unwrap(), "rastergi-0004.png");
    }
}
