//! The winit application of `rastergi view`: the window and its surface, renderers (and
//! scenes opened meanwhile) built on a worker thread, the frame loop (held keys, script
//! steps, batched iterations, resolve, the panel, present), resizes and screenshots. Input is
//! interpreted by [`super::controls`]; the panel by [`super::panel`].

mod events;

use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow};
use rastergi::camera_control::CameraControl;
use rastergi::gather::GatherMethod;
use rastergi::gpu::{Gpu, GpuOptions};
use rastergi::passes::display::{DisplayTarget, Presented};
use rastergi::passes::film::Show;
use rastergi::progressive::{Denoising, Progressive};
use rastergi::scene::Scene;
use rastergi::session::interactive::Interactive;
use rastergi::settings::RenderSettings;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoopProxy};
use winit::window::{Window, WindowId};

use super::build::{Build, Opened, env_scale, prepare, same_but_size};
use super::controls::{Controls, Response, SunAngles, camera_options, show_name};
use super::frames::Rate;
use super::keys::key_of;
use super::panel::{self, Figures, Panel, PanelPainter, PanelState};
use super::screenshots::Screenshots;
use super::script::{Action, ScriptRun, Step, When};
use crate::args::SceneArgs;
use crate::render::Method;

/// A resize rebuilds the size-dependent passes once the window size has been still this long.
const RESIZE_SETTLE: Duration = Duration::from_millis(150);
/// How long a script's `resize` may wait for the window to take the new size.
const RESIZE_TIMEOUT: Duration = Duration::from_secs(10);

/// A built renderer, what it was built for, and the scene it opened (if it opened one).
pub type Arrived = (Box<dyn Progressive>, Build, Option<Opened>);

/// A renderer being built on a worker thread (with the scene it opened, if it opened one).
pub enum UserEvent {
    Built { generation: u64, result: Result<Arrived, String> },
}

/// The live figures the panel shows, refreshed about once a second.
#[derive(Default)]
struct Measured {
    at: Option<Instant>,
    error: Option<f64>,
    /// The film holds too few blocks for the estimate to mean much yet.
    rough: bool,
    memory: Option<u64>,
    /// (iterations, estimated error) since the last restart.
    history: Vec<(u32, f64)>,
}

/// The viewer: its window, GPU, renderer, controls, panel and script.
pub struct App {
    /// The command line's scene options (a scene opened later gets them too, but the camera).
    args: SceneArgs,
    scene_name: String,
    scene: Arc<Scene>,
    scene_id: u64,
    base: RenderSettings,
    gpu_options: GpuOptions,
    proxy: EventLoopProxy<UserEvent>,
    window: Option<Arc<Window>>,
    gpu: Option<Gpu>,
    surface: Option<DisplayTarget>,
    panel: Option<Panel>,
    /// The renderer as the window shows it (the library's interactive loop), and what it was
    /// built for.
    renderer: Option<(Interactive, Build)>,
    /// The generation of the build in flight, if any; results of older ones are dropped.
    building: Option<u64>,
    generation: u64,
    /// A scene to open once no build is in flight.
    pending_open: Option<String>,
    pub(super) controls: Controls,
    /// The window's inner size (0 while minimised on some platforms).
    size: (u32, u32),
    /// When the size last changed, until a renderer of that size is on its way.
    resized_at: Option<Instant>,
    occluded: bool,
    retry_at: Option<Instant>,
    /// The next frame draws whatever the view says (input reached the panel, the window was
    /// resized or uncovered), and when the panel last asked to be drawn again.
    draw_next: bool,
    panel_repaint_at: Option<Instant>,
    /// Mouse buttons held (left, right) and the last cursor position.
    dragging: (bool, bool),
    cursor: Option<(f64, f64)>,
    last_frame: Instant,
    /// Seconds a frame aims at (`--frame-budget`; 0: one whole iteration a frame).
    pub frame_budget: f64,
    rate: Rate,
    measured: Measured,
    /// The origin of the denoiser schedule's times.
    clock: Instant,
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
        let mut controls = Controls::new(camera, a.show.show(), a.exposure.unwrap_or(0.0), &base);
        controls.sun = scene.sun().map(SunAngles::of_direction);
        controls.env_scale = env_scale(a, &scene);
        App {
            args: a.clone(),
            scene_name: a.scene.clone(),
            scene: Arc::new(scene),
            scene_id: 0,
            controls,
            base,
            gpu_options: a.gpu.options(),
            proxy,
            window: None,
            gpu: None,
            surface: None,
            panel: None,
            renderer: None,
            building: None,
            generation: 0,
            pending_open: None,
            size: (a.width.unwrap_or(256), a.height.unwrap_or(256)),
            resized_at: None,
            occluded: false,
            retry_at: None,
            draw_next: true,
            panel_repaint_at: None,
            dragging: (false, false),
            cursor: None,
            last_frame: Instant::now(),
            frame_budget: rastergi::session::refine::DEFAULT_FRAME_BUDGET,
            rate: Rate { since: Instant::now(), count: 0, per_second: 0.0 },
            measured: Measured::default(),
            clock: Instant::now(),
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

    /// The renderer the current window and controls ask for.
    fn wanted(&self) -> Build {
        Build {
            settings: self.controls.settings(&self.base, self.size.0, self.size.1),
            method: self.controls.method,
            sun: self.controls.sun,
            env_scale: self.controls.env_scale,
            scene: self.scene_id,
        }
    }

    /// Whether the current renderer (if any) is the one wanted.
    fn renderer_matches(&self, wanted: &Build) -> bool {
        self.renderer.as_ref().is_some_and(|(_, built)| built == wanted)
    }

    /// Whether the current renderer is the wanted one and nothing is about to replace it.
    fn settled(&self) -> bool {
        self.building.is_none() && self.pending_open.is_none() && self.renderer_matches(&self.wanted())
    }

    /// Starts building the wanted renderer on a worker thread; with `open`, for that scene
    /// (loaded there too, its photons and grid fitted as on the command line).
    fn start_build(&mut self, open: Option<String>) {
        let Some(gpu) = self.gpu.clone() else { return };
        let mut wanted = self.wanted();
        if wanted.settings.width == 0 || wanted.settings.height == 0 {
            return;
        }
        self.generation += 1;
        self.building = Some(self.generation);
        self.resized_at = None;
        let generation = self.generation;
        let current = (self.scene.clone(), self.controls.camera.camera());
        let args = open.as_ref().map(|name| SceneArgs {
            scene: name.clone(),
            eye: None,
            target: None,
            up: None,
            fov: None,
            camera: None,
            ..self.args.clone()
        });
        self.status = match &open {
            Some(name) => format!("opening {name}..."),
            None if wanted.method == Method::Path => "starting the path tracer...".into(),
            None => format!("tracing {} photons...", wanted.settings.photons),
        };
        let loaded_scale = self.args.env_scale;
        let proxy = self.proxy.clone();
        std::thread::spawn(move || {
            let build = std::panic::AssertUnwindSafe(|| -> Result<Arrived> {
                let (scene, opened) = match args {
                    Some(a) => {
                        let mut scene = a.load_scene()?;
                        // The camera as the controls will hold it, so that it does not
                        // restart the image when the renderer arrives.
                        scene.camera = CameraControl::new(&scene.camera, &scene.bounds()).camera();
                        let fitted = a.settings(&scene, 1, 1, true);
                        let opened = Opened {
                            name: a.scene.clone(),
                            photons: fitted.photons,
                            grid: fitted.grid_resolution,
                            sun: scene.sun().map(SunAngles::of_direction),
                            env_scale: env_scale(&a, &scene).and(wanted.env_scale),
                            scene: Arc::new(scene),
                        };
                        (wanted.settings.photons, wanted.settings.grid_resolution) = (opened.photons, opened.grid);
                        (wanted.sun, wanted.env_scale) = (opened.sun, opened.env_scale);
                        wanted.scene += 1;
                        ((*opened.scene).clone(), Some(opened))
                    }
                    None => {
                        let (scene, camera) = current;
                        let mut scene = (*scene).clone();
                        scene.camera = camera;
                        (scene, None)
                    }
                };
                let scene = prepare(scene, &wanted, loaded_scale);
                // The denoiser, where asked for, is enabled by sync_denoiser before the first
                // iteration: its guides hold them all, nothing restarts.
                let (renderer, _) =
                    rastergi::session::new_renderer(&gpu, &scene, wanted.settings.clone(), wanted.method, false)?;
                Ok((renderer, wanted, opened))
            });
            // A panic (wgpu reports validation errors so) must still answer, or the viewer
            // would wait forever; the panic message itself is already on stderr.
            let result = match std::panic::catch_unwind(build) {
                Ok(built) => built.map_err(|e| format!("{e:#}")),
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
            self.status = "re-building the renderer".into();
            if let Some(s) =
                self.controls.sun.filter(|&s| self.renderer.as_ref().is_some_and(|(_, b)| b.sun != Some(s)))
            {
                self.status = format!("sun {:.0}°, {:.0}°: re-tracing", s.azimuth, s.elevation);
            }
        }
        if let Some(name) = r.open {
            self.status = format!("opening {name}...");
            self.pending_open = Some(name);
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
        if let Some((view, _)) = &mut self.renderer
            && view.renderer().camera() != camera
        {
            view.set_camera(camera)?;
        }
        Ok(())
    }

    /// What the image shows: the controls' choice where the renderer has it, else the full image.
    fn shown(&self) -> Show {
        match &self.renderer {
            Some((view, _)) if !view.renderer().has(self.controls.show) => Show::Full,
            _ => self.controls.show,
        }
    }

    /// The renderer's denoiser while the window shows its denoised image: the denoiser asked
    /// for, its guides accumulating, the full image shown.
    fn denoising(&self) -> Option<&dyn Denoising> {
        // The controls' toggle and the shown component count at once; the loop takes them up
        // before the next iterations (sync_denoiser) and at the resolve.
        let shown = self.controls.denoise && self.shown() == Show::Full;
        let (view, _) = self.renderer.as_ref().filter(|_| shown)?;
        view.renderer().denoising().filter(|d| d.denoiser_enabled())
    }

    /// Turns the denoiser's guides on where the controls ask for the denoiser and the renderer
    /// (the photon map's) has none yet. The guides hold the iterations from then on, so an
    /// image that has iterations restarts. Where the GPU cannot hold them the toggle goes off
    /// with a warning.
    fn sync_denoiser(&mut self) {
        let Some((view, _)) = &mut self.renderer else { return };
        if view.denoise() == self.controls.denoise {
            return;
        }
        let had = view.renderer().samples() > 0;
        match view.set_denoise(self.controls.denoise) {
            Ok(()) => {
                if had && view.renderer().samples() == 0 {
                    log::info!("denoiser on: the image restarts (its guides start now)");
                }
            }
            Err(e) => {
                eprintln!("warning: the denoiser cannot be turned on: {e}");
                self.status = format!("no denoiser: {e}");
                self.controls.denoise = false;
                let _ = view.set_denoise(false);
            }
        }
    }

    /// Encodes the resolve of what the window shows into the film's display buffer where one is
    /// due: the raw image of the component shown ([`App::draw_due`] sets it), or the denoised
    /// one, filtered again first when it is due ([`denoise::Schedule`]).
    fn encode_resolve(&mut self, enc: &mut egui_wgpu::wgpu::CommandEncoder) -> Result<()> {
        let now = self.clock.elapsed().as_secs_f64();
        if let Some((view, _)) = &mut self.renderer {
            // While the camera is still the image is resolved a few times a second (the last
            // one stays on screen).
            if view.display_due() {
                view.encode_resolve(enc, now)?;
            }
        }
        Ok(())
    }

    /// Whether this frame draws the window (the display pass, the panel, present): where the
    /// view resolves a new image or says so otherwise ([`Interactive::draw_due`]: an idle view
    /// every frame, a working one at least every half second), where input reached the panel
    /// or the window was resized or uncovered, or where the panel asked to be drawn by now.
    /// Between resolves the image is the same, and on a slow adapter the display pass costs a
    /// good part of a frame that the iterations would have.
    fn draw_due(&mut self, show: Show) -> bool {
        let panel = self.controls.panel && self.panel.is_some();
        let view = self.renderer.as_mut().map(|(view, _)| {
            if (view.show, view.exposure) != (show, self.controls.exposure) {
                (view.show, view.exposure) = (show, self.controls.exposure);
                view.invalidate();
            }
            view.draw_due(view.display_due())
        });
        std::mem::take(&mut self.draw_next)
            || view != Some(false)
            || (panel && self.panel_repaint_at.is_some_and(|t| Instant::now() >= t))
    }

    fn screenshot(&mut self) {
        let show = self.shown();
        let denoised = self.denoising().is_some();
        let Some((active, _)) = &self.renderer else {
            self.status = "no image yet to save".into();
            return;
        };
        let (renderer, exposure) = (active.renderer(), self.controls.exposure);
        match self.screenshots.save(renderer, show, exposure, denoised) {
            Ok((png, exr)) => {
                println!(
                    "screenshot: {} {} ({} iterations, {}x{}, show {}{}, exposure {}; camera {})",
                    png.display(),
                    exr.display(),
                    renderer.samples(),
                    renderer.settings().width,
                    renderer.settings().height,
                    show_name(show),
                    if denoised { " denoised" } else { "" },
                    exposure,
                    camera_options(&renderer.camera())
                );
                // The denoiser's image now holds the current iterations' filter; the display
                // buffer the saved image.
                if let Some((view, _)) = &mut self.renderer {
                    if denoised {
                        view.filtered(self.clock.elapsed().as_secs_f64());
                    }
                    view.redisplay();
                }
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
            let ready = self.settled();
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
            let Some(step) = run.steps.get(run.next).cloned() else { return };
            if !ready {
                return;
            }
            let samples = self.renderer.as_ref().map_or(0, |(r, _)| r.renderer().samples());
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
        let samples = self.renderer.as_ref().map_or(0, |(r, _)| r.renderer().samples());
        match &self.script {
            Some(run) if run.resizing.is_none() => match run.steps.get(run.next) {
                Some(Step { when: When::Iterations(n), .. }) => n.saturating_sub(samples),
                _ => u32::MAX,
            },
            _ => u32::MAX,
        }
    }

    /// Runs this frame's work within the frame budget ([`Interactive::frame`]: previews while
    /// the camera moves and just after, then the window's iterations, banded where one is
    /// longer than the budget), stopping where the script waits for a count. Only a renderer
    /// that fits the window and is not about to be replaced iterates.
    fn iterate_batch(&mut self) -> Result<()> {
        let current = self.settled();
        let limit = self.iteration_limit();
        let Some((view, _)) = self.renderer.as_mut().filter(|_| current) else { return Ok(()) };
        let done = view.frame(limit)?;
        if done > 0 {
            self.rate.add(done);
        }
        Ok(())
    }

    /// Refreshes the panel's figures about once a second: the estimated error (a read-back of
    /// the film), its history since the restart, and the device's allocated memory.
    fn measure(&mut self) -> Result<()> {
        if self.measured.at.is_some_and(|t| t.elapsed() < Duration::from_secs(1)) {
            return Ok(());
        }
        self.measured.at = Some(Instant::now());
        let Some((view, _)) = &self.renderer else { return Ok(()) };
        let r = view.renderer();
        if r.rows_ahead() > 0 {
            // An iteration under way in bands: its sums are not yet an image's; next time.
            self.measured.at = None;
            return Ok(());
        }
        let samples = r.samples();
        let history = &mut self.measured.history;
        if history.last().is_some_and(|&(n, _)| n > samples) {
            history.clear();
        }
        self.measured.error = r.film_state()?.error_estimate();
        // As for `render --target-error`: the halves need a few blocks each before their
        // difference means much.
        self.measured.rough = r.film().blocks() < 4;
        if let Some(e) = self.measured.error.filter(|_| !self.measured.rough)
            && history.last().is_none_or(|&(n, _)| n < samples)
        {
            history.push((samples, e));
        }
        if let Some(gpu) = &self.gpu {
            self.measured.memory =
                gpu.device.generate_allocator_report().map(|r| r.allocations.iter().map(|a| a.size).sum());
        }
        Ok(())
    }

    /// One displayed frame: input over time, script, iterations, resolve, panel, draw, present.
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
        self.sync_denoiser();
        if let Err(e) = self.iterate_batch() {
            return self.fail(event_loop, e);
        }
        let show = self.shown();
        if !self.draw_due(show) {
            return self.refresh_title();
        }
        let panel_shown = self.controls.panel && self.panel.is_some();
        if panel_shown && let Err(e) = self.measure() {
            return self.fail(event_loop, e);
        }
        let (panel_output, actions) = match panel_shown.then(|| self.run_panel()).flatten() {
            Some((output, actions)) => (Some(output), actions),
            None => (None, Vec::new()),
        };
        // egui's next repaint: at once while it animates, else when it asked (a tooltip's delay).
        self.panel_repaint_at = panel_output.as_ref().and_then(|o| {
            let delay = o.viewport_output.values().map(|v| v.repaint_delay).min()?;
            Instant::now().checked_add(delay)
        });
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        if let Err(e) = self.encode_resolve(&mut enc) {
            return self.fail(event_loop, e);
        }
        if let Some((view, _)) = &mut self.renderer {
            view.drawn();
        }
        let (Some(surface), Some(window)) = (&mut self.surface, &self.window) else { return };
        let film = self.renderer.as_ref().map(|(r, _)| r.renderer().film());
        let presented = match (panel_output, &mut self.panel) {
            (Some(mut output), Some(panel)) => {
                panel.input.handle_platform_output(window, std::mem::take(&mut output.platform_output));
                let (ctx, painter) = (&panel.ctx, &mut panel.painter);
                surface.present_with(&gpu, enc, film, &[], |enc, view, size| {
                    painter.encode(&gpu, ctx, output, enc, view, size)
                })
            }
            _ => surface.present(&gpu, enc, film, &[]),
        };
        match presented {
            Ok(Presented::Shown) => self.retry_at = None,
            Ok(Presented::Skipped) => self.retry_at = Some(Instant::now() + Duration::from_millis(100)),
            Err(e) => return self.fail(event_loop, e.into()),
        }
        // The panel's actions act from the next frame, as a script's do.
        for action in actions {
            log::info!("panel: {action:?}");
            let r = self.controls.action(&action, self.size.1 as f32);
            self.apply(event_loop, r);
        }
        self.refresh_title();
    }

    /// The window's title (the scene, the iterations and their rate) about twice a second.
    fn refresh_title(&mut self) {
        if self.title_at.elapsed() >= Duration::from_millis(500) {
            self.title_at = Instant::now();
            if let Some(w) = &self.window {
                w.set_title(&self.title());
            }
        }
    }

    /// Runs the panel's egui pass: its output, for drawing, and the actions its widgets gave.
    fn run_panel(&mut self) -> Option<(egui::FullOutput, Vec<Action>)> {
        let window = self.window.clone()?;
        let renderer = self.renderer.as_ref().map(|(view, _)| view.renderer());
        let photon_map = renderer.and_then(|r| r.photon_pass_and_gather().map(|m| (m, r.settings().photons)));
        let size = renderer.map_or(self.size, |r| (r.settings().width, r.settings().height));
        let figures = Figures {
            scene: &self.scene_name,
            size,
            samples: renderer.map_or(0, |r| r.samples()),
            iterations_per_second: self.rate.per_second,
            error: self.measured.error,
            error_is_rough: self.measured.rough,
            photon_pass: photon_map.filter(|&(_, photons)| photons > 0).map(|((pass, _), photons)| (pass, photons)),
            gather_in_use: photon_map.map(|((_, gather), _)| gather).filter(|&g| g != GatherMethod::Auto),
            memory: self.measured.memory,
            history: &self.measured.history,
            status: &self.status,
        };
        let panel = self.panel.as_mut()?;
        let raw = panel.input.take_egui_input(&window);
        let mut actions = Vec::new();
        let output = panel.ctx.run_pass(raw, |ctx| {
            actions = panel::window(ctx, &self.controls, &figures, &mut panel.state);
        });
        Some((output, actions))
    }

    fn title(&self) -> String {
        let samples = self.renderer.as_ref().map_or(0, |(r, _)| r.renderer().samples());
        format!(
            "rastergi - {} - {} iterations, {:.1}/s - {}{} - {}",
            self.scene_name,
            samples,
            self.rate.per_second,
            show_name(self.shown()),
            if self.denoising().is_some() { " denoised" } else { "" },
            self.controls.camera.mode.name()
        )
    }

    /// The controls back to the settings of the renderer that stays (its build failed).
    fn revert_controls(&mut self) {
        let Some((_, b)) = &self.renderer else { return };
        let c = &mut self.controls;
        (c.photons, c.grid, c.photon_passes) =
            (b.settings.photons, b.settings.grid_resolution, b.settings.photon_passes);
        (c.gather, c.gather_directions, c.directions) =
            (b.settings.gather, b.settings.gather_directions, b.settings.directions);
        (c.photon_budget, c.photon_guiding, c.gather_guiding, c.sky_guiding) =
            (b.settings.photon_budget, b.settings.photon_guiding, b.settings.gather_guiding, b.settings.sky_guiding);
        (c.method, c.sun, c.env_scale) = (b.method, b.sun, b.env_scale);
        c.light_balance = b.settings.light_balance;
    }
}
