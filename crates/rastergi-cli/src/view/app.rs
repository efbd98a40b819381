//! The winit application of `rastergi view`: the window and its surface, renderers built on
//! a worker thread, the frame loop (held keys, script steps, batched iterations, resolve,
//! overlay, present), resizes and screenshots. Input is interpreted by [`super::controls`].

use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow};
use rastergi::camera_control::CameraControl;
use rastergi::display::{Presented, WindowSurface};
use rastergi::film::Show;
use rastergi::gpu::{Gpu, GpuOptions};
use rastergi::renderer::{RenderSettings, Renderer, default_bundle};
use rastergi::scene::{Light, Scene};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoopProxy};
use winit::keyboard::{Key as LogicalKey, KeyCode, NamedKey, PhysicalKey};
use winit::window::{Window, WindowId};

use super::controls::{Controls, Key, Response, SunAngles, camera_options, show_name};
use super::screenshots::Screenshots;
use super::script::{Action, Step, When};
use crate::args::SceneArgs;

/// GPU time aimed at per displayed frame: iterations are batched up to this.
pub const FRAME_BUDGET: Duration = Duration::from_millis(30);
/// Most iterations in one frame (keeps a frame short when iterations are very cheap).
pub const MAX_BATCH: u32 = 64;
/// A resize rebuilds the size-dependent passes once the window size has been still this long.
const RESIZE_SETTLE: Duration = Duration::from_millis(150);
/// How long a script's `resize` may wait for the window to take the new size.
const RESIZE_TIMEOUT: Duration = Duration::from_secs(10);

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
            KeyCode::KeyJ => Some(Key::SunWest),
            KeyCode::KeyL => Some(Key::SunEast),
            KeyCode::KeyI => Some(Key::SunHigher),
            KeyCode::KeyK => Some(Key::SunLower),
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

/// One frame's iterations: up to `limit`, stopping once [`FRAME_BUDGET`] has passed (so at
/// least one where `limit` > 0), then waits for them and sets `batch` (the next frame's
/// limit) to as many as fit in the budget at this frame's time per iteration, 1 to
/// [`MAX_BATCH`]. Returns how many ran. `rastergi bench frames` runs the same.
pub fn iterate_frame(renderer: &mut Renderer, limit: u32, batch: &mut u32) -> Result<u32> {
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
        *batch = ((FRAME_BUDGET.as_secs_f64() / per_iteration.max(1e-6)) as u32).clamp(1, MAX_BATCH);
    }
    Ok(done)
}

/// A renderer being built on a worker thread.
pub enum UserEvent {
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

/// The viewer: its window, GPU, renderer, controls and script.
pub struct App {
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
    /// The sun of the build in flight and of the current renderer.
    building_sun: Option<SunAngles>,
    renderer_sun: Option<SunAngles>,
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

impl App {
    /// The viewer of `scene` for the options `a`, before its window opens (that happens once
    /// the event loop starts): renderers get `base` at the window's size, the script's `steps`
    /// run as they fall due, and build results come back through `proxy`.
    pub fn new(
        a: &SceneArgs,
        scene: Scene,
        base: RenderSettings,
        steps: Option<Vec<Step>>,
        screenshots: Screenshots,
        proxy: EventLoopProxy<UserEvent>,
    ) -> App {
        let camera = CameraControl::new(&scene.camera, &scene.bounds());
        let sun = last_sun(&scene).map(SunAngles::of_direction);
        let mut controls =
            Controls::new(camera, a.show.show(), a.exposure.unwrap_or(0.0), base.photons, base.grid_resolution);
        controls.sun = sun;
        App {
            args_scene: a.scene.clone(),
            scene: Arc::new(scene),
            controls,
            base,
            gpu_options: a.gpu.options(),
            proxy,
            window: None,
            gpu: None,
            surface: None,
            renderer: None,
            building: None,
            building_sun: sun,
            renderer_sun: sun,
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
            screenshots,
            error: None,
        }
    }

    /// Once the event loop has returned: the error that stopped the viewer, if any.
    pub fn finish(self) -> Result<()> {
        match self.error {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

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

    /// Whether the current renderer (if any) was built with `settings` and the controls' sun.
    fn renderer_matches(&self, s: &RenderSettings) -> bool {
        self.renderer_sun == self.controls.sun
            && self.renderer.as_ref().is_some_and(|r| {
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
        self.building_sun = self.controls.sun;
        if let (Some(sun), Some(Light::Distant { direction, .. })) =
            (self.controls.sun, scene.lights.iter_mut().rev().find(|l| matches!(l, Light::Distant { .. })))
        {
            *direction = sun.direction();
        }
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
            if let Some(s) = self.controls.sun.filter(|&s| Some(s) != self.renderer_sun) {
                self.status = format!("sun {:.0}°, {:.0}°: re-tracing", s.azimuth, s.elevation);
            }
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
        let done = iterate_frame(renderer, limit, &mut self.batch)?;
        if done > 0 {
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
        if let Some(sun) = c.sun {
            lines.push(format!("sun azimuth {:.0}  elevation {:.0} [J/L I/K]", sun.azimuth, sun.elevation));
        }
        if !self.status.is_empty() {
            lines.push(self.status.clone());
        }
        lines.push("WASDQE drag scroll  Tab mode  P save  H hide".into());
        lines
    }
}

/// The direction of the scene's last distant light (the viewer's sun), if any.
fn last_sun(scene: &Scene) -> Option<glam::Vec3> {
    scene.lights.iter().rev().find_map(|l| match l {
        Light::Distant { direction, .. } => Some(*direction),
        _ => None,
    })
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
                self.renderer_sun = self.building_sun;
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
                    let same_map = self.renderer_sun == self.controls.sun
                        && self.renderer.as_ref().is_some_and(|r| {
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
