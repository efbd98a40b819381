//! rastergi in a web page: the progressive renderer on the browser's WebGPU, driven from
//! JavaScript (`web/main.js`) through [`Viewer`].
//!
//! The page owns the loop: on each animation frame it calls [`Viewer::frame`], which submits
//! one unit of the library's interactive loop within its frame budget
//! ([`rastergi::session::refine`]: a preview while the camera moves, row bands of an iteration
//! longer than the budget, the view before a move re-projected), while fewer than
//! [`FRAMES_IN_FLIGHT`] are still on the GPU (so the queue does not grow faster than the GPU
//! empties it), and draws the image onto the canvas. The units' times come back from the
//! GPU's completion callbacks, which the loop's cost model learns from. Nothing here waits for the GPU: the read-backs (the error estimate, "save PNG")
//! return promises that the browser resolves once the GPU has answered
//! (`rastergi::gpu::Gpu::read_buffer_async`).
//!
//! Scenes: the built-in ones by name, or files from the page (dropped or picked) held in
//! memory ([`rastergi::scene::MemoryFiles`]): a `.glb`, a `.gltf` with its buffers and images,
//! an `.obj` with its `.mtl` libraries and textures, or a Mitsuba `.xml` with its folder. A
//! file that is not a scene is refused with one line, and the scene shown stays.
//!
//! Natively this crate is empty (it builds for `wasm32-unknown-unknown` only, with
//! `scripts/web-build.sh`).
#![cfg(target_arch = "wasm32")]

use std::path::Path;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use rastergi::camera_control::{CameraControl, DRAG_RADIANS_PER_PIXEL, MoveKeys};
use rastergi::gather::GatherMethod;
use rastergi::gpu::{Gpu, GpuOptions};
use rastergi::passes::display::DisplayTarget;
use rastergi::passes::film::Show;
use rastergi::progressive::Progressive;

use rastergi::scene::{Files, GltfOptions, MemoryFiles, Scene, SunAngles};
use rastergi::session::interactive::Interactive;
use rastergi::session::interactive::Unit;
use rastergi::session::{Method, Session};
use wasm_bindgen::prelude::*;

mod console;

/// Iterations submitted and not yet finished on the GPU, at most.
pub const FRAMES_IN_FLIGHT: u32 = 2;

/// What the page chose besides the scene.
#[derive(Clone, Debug)]
struct Options {
    width: u32,
    height: u32,
    seed: u32,
    /// Photons per pass; `None`: fitted to the scene, as `rastergi render` does.
    photons: Option<u32>,
    gather: GatherMethod,
    method: Method,
    /// The sun (the scene's last distant light).
    sun: Option<SunAngles>,
}

/// The renderer of a page: the device, the canvas, the scene and its progressive image.
#[wasm_bindgen]
pub struct Viewer {
    /// Kept for the device's lifetime: the browser loses a device whose instance is dropped.
    _instance: wgpu::Instance,
    gpu: Gpu,
    surface: DisplayTarget,
    scene_name: String,
    scene: Scene,
    /// The renderer as the canvas shows it (component, exposure, denoised image).
    view: Interactive,
    control: CameraControl,
    options: Options,
    in_flight: Arc<AtomicU32>,
    /// Units of work the GPU has finished since the last frame, with their seconds from
    /// submission.
    done: Arc<Mutex<Vec<(Unit, f64)>>>,
    /// The seconds from the submission of a frame that ran the denoiser's filter to its end on
    /// the GPU (with whatever was queued before it: an over-estimate that spaces filters more).
    filter_took: Arc<Mutex<Option<f64>>>,
}

/// Opens the browser's WebGPU adapter for `canvas` and shows the Cornell box at
/// `width × height` with `seed`. Fails with one line where the browser has no WebGPU or its
/// limits are too small.
#[wasm_bindgen(js_name = createViewer)]
pub async fn create_viewer(
    canvas: web_sys::HtmlCanvasElement,
    width: u32,
    height: u32,
    seed: u32,
) -> Result<Viewer, JsError> {
    console::init();
    let options = GpuOptions { backends: Some(wgpu::Backends::BROWSER_WEBGPU), ..GpuOptions::default() };
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::BROWSER_WEBGPU;
    let instance = wgpu::Instance::new(desc);
    let (canvas_width, canvas_height) = (canvas.width(), canvas.height());
    let surface = instance
        .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
        .map_err(|e| JsError::new(&format!("this browser cannot draw WebGPU into a canvas ({e})")))?;
    let gpu = Gpu::open_async(&instance, &options, Some(&surface)).await.map_err(|e| {
        JsError::new(&format!(
            "{e}: this browser offers no WebGPU adapter (enable WebGPU, or use Chrome, Edge or Firefox 141+)"
        ))
    })?;
    log::info!("{}", gpu.describe().replace('\n', "; "));
    let storage = gpu.device.limits().max_storage_buffers_per_shader_stage;
    if storage < rastergi::gpu::WEB_STORAGE_BUFFERS {
        return Err(JsError::new(&format!(
            "this browser's WebGPU allows {storage} storage buffers per shader stage and rastergi needs {} (Chrome and Edge grant 10)",
            rastergi::gpu::WEB_STORAGE_BUFFERS
        )));
    }
    let surface = DisplayTarget::new(&gpu, surface, canvas_width, canvas_height).map_err(error)?;
    let options = Options {
        width,
        height,
        seed,
        photons: None,
        // The raster gathers bind more storage buffers than browsers grant (10).
        gather: GatherMethod::Trace,
        method: Method::Gather,
        sun: None,
    };
    let scene = rastergi::scene::cornell_box();
    let renderer = build(&gpu, &scene, &options).map_err(error)?;
    let control = CameraControl::new(&scene.camera, &scene.bounds());
    Ok(Viewer {
        _instance: instance,
        gpu,
        surface,
        scene_name: "cornell".into(),
        scene,
        view: Interactive::new(renderer, Show::Full, 0.0),
        control,
        options,
        in_flight: Arc::new(AtomicU32::new(0)),
        done: Arc::new(Mutex::new(Vec::new())),
        filter_took: Arc::new(Mutex::new(None)),
    })
}

/// Seconds since the epoch (the denoiser's schedule).
fn now() -> f64 {
    js_sys::Date::now() / 1000.0
}

fn error(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

impl Options {
    /// The library's options of the page's (the rest as `rastergi render` has them by default:
    /// the photon grid and count fitted to the scene).
    fn session(&self) -> rastergi::session::Options {
        rastergi::session::Options {
            width: Some(self.width),
            height: Some(self.height),
            seed: self.seed,
            photons: self.photons,
            gather: self.gather,
            method: self.method,
            ..rastergi::session::Options::default()
        }
    }
}

/// The renderer `options` ask for, for `scene` (its sun turned as they say), built by the
/// library's session as every front end's is.
fn build(gpu: &Gpu, scene: &Scene, options: &Options) -> rastergi::Result<Box<dyn Progressive>> {
    let mut scene = scene.clone();
    if let Some(sun) = options.sun {
        scene.turn_sun(sun);
    }
    let session_options = options.session();
    let (renderer, _) = Session::of_scene(scene, &session_options).renderer(gpu, &session_options)?;
    Ok(renderer)
}

/// The scene among `files`: a Mitsuba `.xml` (whose meshes are often `.obj` files beside it),
/// else the first `.glb`, `.gltf` or `.obj` by name.
fn load_scene(files: &MemoryFiles) -> rastergi::Result<(String, Scene)> {
    let mut names: Vec<&str> = files.names().collect();
    names.sort();
    let kind = |n: &str| Path::new(n).extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let mitsuba = names.iter().find(|n| kind(n).as_deref() == Some("xml"));
    let Some(name) =
        mitsuba.or_else(|| names.iter().find(|n| matches!(kind(n).as_deref(), Some("glb" | "gltf" | "obj"))))
    else {
        return Err(rastergi::Error::InvalidScene(format!(
            "{} is not a scene: drop a .glb, a .gltf with its files, an .obj with its .mtl and textures, or a Mitsuba .xml with its folder",
            names.join(", ")
        )));
    };
    let path = Path::new(name);
    let scene = match kind(name).as_deref() {
        Some("xml") => {
            let options = rastergi::scene::MitsubaOptions::default();
            rastergi::scene::load_mitsuba_in(Files::Memory(files), path, &options)?.scene
        }
        Some("obj") => rastergi::scene::load_obj_in(Files::Memory(files), path)?,
        _ => rastergi::scene::load_gltf_in(Files::Memory(files), path, &GltfOptions::default())?,
    };
    let mut scene = scene;
    if let Some(what) = scene.light_if_unlit(matches!(kind(name).as_deref(), Some("glb" | "gltf"))) {
        log::warn!("{name}: {what}: lit by a neutral grey environment, as glTF viewers light models");
    }
    Ok((name.to_string(), scene))
}

#[wasm_bindgen]
impl Viewer {
    /// Shows the built-in scene `name` (cornell, rooms, atrium, glossy-room, spheres:N).
    #[wasm_bindgen(js_name = loadBuiltin)]
    pub fn load_builtin(&mut self, name: &str) -> Result<(), JsError> {
        let scene = rastergi::scene::generate::builtin(name)
            .map_err(error)?
            .ok_or_else(|| JsError::new(&format!("there is no built-in scene '{name}'")))?;
        self.show_scene(name.to_string(), scene)
    }

    /// Shows the scene among the files `names` with `contents` (dropped on the page or picked):
    /// its name, or one line saying why not (the scene shown stays).
    #[wasm_bindgen(js_name = loadFiles)]
    pub fn load_files(&mut self, names: Vec<String>, contents: Vec<js_sys::Uint8Array>) -> Result<String, JsError> {
        let mut files = MemoryFiles::new();
        for (name, bytes) in names.iter().zip(&contents) {
            files.insert(name, bytes.to_vec());
        }
        let (name, scene) = load_scene(&files).map_err(error)?;
        self.show_scene(name.clone(), scene)?;
        Ok(name)
    }

    fn show_scene(&mut self, name: String, scene: Scene) -> Result<(), JsError> {
        let mut options = self.options.clone();
        options.sun = scene.sun().map(SunAngles::of_direction);
        // Built before anything is replaced: a scene that fails leaves the page as it was.
        let renderer = build(&self.gpu, &scene, &options).map_err(error)?;
        self.control = CameraControl::new(&scene.camera, &scene.bounds());
        self.view.replace(renderer, false).map_err(error)?;
        (self.scene_name, self.scene, self.options) = (name, scene, options);
        Ok(())
    }

    /// Changes one setting: `method` (photons | path), `gather` (lists | trace), `photons`
    /// (a count, or auto), `show` (full | direct | indirect), `exposure` (stops), `sun`
    /// ("azimuth,elevation" in degrees), `size` ("WIDTHxHEIGHT"), `seed`, `denoise` (on | off:
    /// show the denoised full image; the photon-map renderer's, which restarts the image the
    /// first time, as its guides start then). Settings that change what is traced rebuild the
    /// renderer; the image restarts.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), JsError> {
        let bad = || JsError::new(&format!("'{value}' is not a valid {key}"));
        let mut options = self.options.clone();
        match key {
            "show" => {
                self.view.show = match value {
                    "full" => Show::Full,
                    "direct" => Show::Direct,
                    "indirect" => Show::Indirect,
                    _ => return Err(bad()),
                };
                return Ok(());
            }
            "exposure" => {
                self.view.exposure = value.parse().ok().filter(|e: &f32| e.is_finite()).ok_or_else(bad)?;
                return Ok(());
            }
            "denoise" => {
                let on = match value {
                    "on" => true,
                    "off" => false,
                    _ => return Err(bad()),
                };
                // A failure (its buffers beyond the device's limits) leaves the denoiser off.
                self.view.set_denoise(on).map_err(error)?;
                return Ok(());
            }
            "method" => {
                options.method = match value {
                    "photons" => Method::Gather,
                    "path" => Method::Path,
                    _ => return Err(bad()),
                }
            }
            "gather" => {
                options.gather = match value {
                    "lists" => GatherMethod::Lists,
                    "trace" => GatherMethod::Trace,
                    _ => return Err(bad()),
                }
            }
            "photons" => {
                options.photons = match value {
                    "auto" => None,
                    n => Some(n.parse().ok().filter(|&n| n > 0).ok_or_else(bad)?),
                }
            }
            "sun" => {
                let (a, e) = value.split_once(',').ok_or_else(bad)?;
                let (a, e): (f32, f32) = (a.trim().parse().map_err(|_| bad())?, e.trim().parse().map_err(|_| bad())?);
                if options.sun.is_none() {
                    return Err(JsError::new("this scene has no sun (a distant light) to turn"));
                }
                options.sun = Some(SunAngles { azimuth: a.rem_euclid(360.0), elevation: e.clamp(-90.0, 90.0) });
            }
            "size" => {
                let (w, h) = value.split_once('x').ok_or_else(bad)?;
                (options.width, options.height) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
            }
            "seed" => options.seed = value.parse().map_err(|_| bad())?,
            _ => return Err(JsError::new(&format!("unknown setting '{key}'"))),
        }
        let renderer = build(&self.gpu, &self.scene, &options).map_err(error)?;
        self.view.replace(renderer, true).map_err(error)?;
        self.options = options;
        Ok(())
    }

    /// One animation frame: a unit of the interactive loop's work within its frame budget
    /// (unless `limit` > 0 iterations are done and no filter is under way, or the GPU is
    /// [`FRAMES_IN_FLIGHT`] behind; a filter's steps wait until it has nothing queued), then
    /// the image drawn onto the canvas. Returns the iterations accumulated.
    pub fn frame(&mut self, limit: u32) -> Result<u32, JsError> {
        let finished: Vec<(Unit, f64)> = std::mem::take(&mut *self.done.lock().unwrap_or_else(|e| e.into_inner()));
        for (unit, seconds) in finished {
            self.view.finished(&unit, seconds);
        }
        if let Some(seconds) = self.filter_took.lock().unwrap_or_else(|e| e.into_inner()).take() {
            self.view.filter_took(seconds);
        }
        let samples = self.view.renderer().samples();
        let left = if limit > 0 { limit.saturating_sub(samples) } else { u32::MAX };
        // A filter of the denoised image under way in steps goes on after the last iteration;
        // its steps wait for the queue to empty, so that their time is theirs alone (it sizes
        // the next).
        let in_flight = self.in_flight.load(Ordering::Acquire);
        let free = if self.view.filtering() { in_flight == 0 } else { left > 0 && in_flight < FRAMES_IN_FLIGHT };
        if free {
            self.view.reproject().map_err(error)?;
            if let Some(unit) = self.view.step(self.view.frame_budget(), left).map_err(error)? {
                self.in_flight.fetch_add(1, Ordering::AcqRel);
                let (in_flight, done, submitted) = (self.in_flight.clone(), self.done.clone(), now());
                self.gpu.queue.on_submitted_work_done(move || {
                    done.lock().unwrap_or_else(|e| e.into_inner()).push((unit, now() - submitted));
                    in_flight.fetch_sub(1, Ordering::AcqRel);
                });
            }
            self.view.end_frame();
        }
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        if self.view.display_due() {
            self.view.encode_resolve(&mut enc, now()).map_err(error)?;
        }
        let (filtered, submitted) = (self.view.filter_encoded(), now());
        self.surface.present(&self.gpu, enc, Some(self.view.renderer().film()), &[]).map_err(error)?;
        if filtered {
            // The denoiser's schedule spaces filters by what this one takes.
            let took = self.filter_took.clone();
            self.gpu.queue.on_submitted_work_done(move || {
                *took.lock().unwrap_or_else(|e| e.into_inner()) = Some(now() - submitted);
            });
        }
        self.gpu.check().map_err(error)?;
        Ok(self.view.renderer().samples())
    }

    /// Whether every submitted iteration has finished on the GPU.
    pub fn idle(&self) -> bool {
        self.in_flight.load(Ordering::Acquire) == 0
    }

    /// The canvas was resized to `width × height` pixels (the image keeps its size and is
    /// scaled to fit).
    #[wasm_bindgen(js_name = resizeCanvas)]
    pub fn resize_canvas(&mut self, width: u32, height: u32) {
        self.surface.resize(&self.gpu, width, height);
    }

    /// A mouse drag of (dx, dy) pixels: orbits the target, or turns the view in fly mode.
    pub fn drag(&mut self, dx: f32, dy: f32) -> Result<(), JsError> {
        let (yaw, pitch) = (dx * DRAG_RADIANS_PER_PIXEL, -dy * DRAG_RADIANS_PER_PIXEL);
        let moved = match self.control.mode {
            rastergi::camera_control::Mode::Orbit => self.control.orbit(yaw, pitch),
            rastergi::camera_control::Mode::Fly => self.control.look(yaw, pitch),
        };
        self.moved(moved)
    }

    /// `steps` scroll notches: closer (positive) or farther.
    pub fn zoom(&mut self, steps: f32) -> Result<(), JsError> {
        let moved = self.control.zoom(steps);
        self.moved(moved)
    }

    /// Flies for `seconds` with keys held: `keys` holds the letters of W A S D E Q (forward,
    /// left, back, right, up, down) and `F` for fast.
    pub fn fly(&mut self, keys: &str, seconds: f32) -> Result<(), JsError> {
        let held = MoveKeys {
            forward: keys.contains('W'),
            back: keys.contains('S'),
            left: keys.contains('A'),
            right: keys.contains('D'),
            up: keys.contains('E'),
            down: keys.contains('Q'),
            fast: keys.contains('F'),
        };
        let moved = self.control.fly(&held, seconds);
        self.moved(moved)
    }

    /// Switches orbit ↔ fly; returns the new mode's name.
    #[wasm_bindgen(js_name = toggleMode)]
    pub fn toggle_mode(&mut self) -> String {
        self.control.toggle_mode();
        self.control.mode.name().to_string()
    }

    /// Back to the scene's own camera.
    pub fn home(&mut self) -> Result<(), JsError> {
        self.control = CameraControl::new(&self.scene.camera, &self.scene.bounds());
        self.moved(true)
    }

    fn moved(&mut self, moved: bool) -> Result<(), JsError> {
        if moved {
            self.view.set_camera(self.control.camera()).map_err(error)?;
        }
        Ok(())
    }

    /// Iterations accumulated since the last restart.
    pub fn samples(&self) -> u32 {
        self.view.renderer().samples()
    }

    #[wasm_bindgen(js_name = sceneName)]
    pub fn scene_name(&self) -> String {
        self.scene_name.clone()
    }

    /// What is rendering, for the page's status line.
    pub fn describe(&self) -> String {
        let s = self.view.renderer().settings();
        let what = match self.options.method {
            Method::Gather => format!(
                "photon map ({} photons a pass) + {:?} gather{}",
                s.photons,
                s.gather,
                if self.view.denoising().is_some() { ", denoised" } else { "" }
            ),
            Method::Path => "path tracer".to_string(),
        };
        let i = &self.gpu.info;
        let adapter = if i.name.is_empty() { "the browser's WebGPU adapter".to_string() } else { i.name.clone() };
        format!(
            "{}: {} triangles, {}x{}, {what}, on {adapter}",
            self.scene_name,
            self.scene.triangles.len(),
            s.width,
            s.height
        )
    }

    /// The sun's "azimuth,elevation" in degrees, or an empty string where the scene has none.
    pub fn sun(&self) -> String {
        self.options.sun.map_or_else(String::new, |s| format!("{:.0},{:.0}", s.azimuth, s.elevation))
    }

    /// The warnings logged since the last call (a loaded file's ignored parts, say).
    #[wasm_bindgen(js_name = takeWarnings)]
    pub fn take_warnings(&self) -> Vec<String> {
        console::take_warnings()
    }

    /// The film's relative error estimate (from its two independent halves): a promise of a
    /// number, or `null` before the halves hold enough iterations.
    #[wasm_bindgen(js_name = errorEstimate)]
    pub fn error_estimate(&self) -> js_sys::Promise {
        let state = self.view.renderer().film().read_state_async(&self.gpu);
        wasm_bindgen_futures::future_to_promise(async move {
            let state = state.await.map_err(|e| JsValue::from(error(e)))?;
            Ok(state.error_estimate().map_or(JsValue::NULL, JsValue::from))
        })
    }

    /// The image as shown (the film's display encoding at its own size; the denoised image
    /// filtered at the current iterations where it is shown) as PNG bytes: a promise of a
    /// `Uint8Array`. With `raw` true, the film's own image of the shown component instead of
    /// the denoised one (the same iterations, unfiltered); the canvas shows its image again at
    /// the next frame.
    #[wasm_bindgen(js_name = savePng)]
    pub fn save_png(&mut self, raw: bool) -> js_sys::Promise {
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        if raw {
            let renderer = self.view.renderer();
            let show = if renderer.has(self.view.show) { self.view.show } else { Show::Full };
            renderer.encode_resolve(&mut enc, show, self.view.exposure);
            self.view.redisplay();
        } else {
            self.view.invalidate();
            if let Err(e) = self.view.encode_resolve_unblended(&mut enc, now()) {
                return js_sys::Promise::reject(&JsValue::from(error(e)));
            }
        }
        self.gpu.queue.submit([enc.finish()]);
        let image = self.view.renderer().film().read_display_buffer_async(&self.gpu);
        wasm_bindgen_futures::future_to_promise(async move {
            let image = image.await.map_err(|e| JsValue::from(error(e)))?;
            let mut png = Vec::new();
            let encoder = image::codecs::png::PngEncoder::new(&mut png);
            image::ImageEncoder::write_image(
                encoder,
                &image.rgba,
                image.width,
                image.height,
                image::ExtendedColorType::Rgba8,
            )
            .map_err(|e| JsValue::from(error(e)))?;
            Ok(js_sys::Uint8Array::from(png.as_slice()).into())
        })
    }
}
