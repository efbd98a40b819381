//! The viewer's control panel: an egui window over the image with the scene, the renderer's
//! settings, the lights, the camera and the display, and the live figures (iterations per
//! second, the estimated error, photons, GPU memory and a convergence plot).
//!
//! The panel changes nothing itself: every widget turns into an [`Action`], the same a
//! script line gives, and the application applies it through [`Controls::action`]. So a
//! script reproduces a click, and the tests drive the widgets (egui_kittest) and the actions
//! (a scripted viewer under Xvfb) separately. Drawing on the GPU is [`PanelPainter`]'s:
//! egui-wgpu on the viewer's device, over the swapchain image after the display pass.

use std::path::{Path, PathBuf};

use clap::ValueEnum;
use egui::{Color32, ComboBox, RichText, Slider, Stroke, Ui};
use egui_wgpu::wgpu;
use rastergi::gather::{GatherDirections, GatherMethod, MAX_DIRECTIONS};
use rastergi::passes::film::Show;
use rastergi::settings::PhotonBudget;

use super::controls::{Controls, SunAngles, show_name};
use super::script::Action;
use crate::args::GatherArg;
use crate::render::Method;

/// The built-in scenes the panel offers (`spheres:N` takes a count, so it is typed).
const BUILTINS: [&str; 4] = ["cornell", "atrium", "rooms", "rooms:closed"];
/// Scene files the browser lists.
const SCENE_EXTENSIONS: [&str; 4] = ["obj", "gltf", "glb", "xml"];
/// Photon counts offered: powers of two.
const PHOTON_EXPONENTS: std::ops::RangeInclusive<u32> = 12..=26;
/// Grid resolutions offered.
const GRIDS: [u32; 11] = [16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512];
/// Photon passes offered (0: no limit).
const PASSES: [u32; 8] = [0, 1, 2, 4, 8, 16, 32, 64];

/// What the panel shows besides the controls: the render's figures.
pub struct Figures<'a> {
    pub scene: &'a str,
    /// The image's size in pixels.
    pub size: (u32, u32),
    /// Iterations since the last restart.
    pub samples: u32,
    pub iterations_per_second: f64,
    /// The relative RMSE estimated without a reference (two halves of the iterations).
    pub error: Option<f64>,
    /// Too few blocks of iterations yet for the estimate to mean much.
    pub error_is_rough: bool,
    /// The photon pass the map is in (0-based) and the photons each pass traces (photon map
    /// renderer).
    pub photon_pass: Option<(u32, u32)>,
    /// The gather implementation in use (what `auto` chose, once it has).
    pub gather_in_use: Option<GatherMethod>,
    /// GPU memory allocated on the device, bytes, where the backend reports it.
    pub memory: Option<u64>,
    /// (iterations, estimated error) since the last restart, for the convergence plot.
    pub history: &'a [(u32, f64)],
    /// What the viewer is doing (tracing, a failure), if anything.
    pub status: &'a str,
}

/// The panel's own state between frames: the scene path being typed and the file browser.
#[derive(Debug, Default)]
pub struct PanelState {
    pub path: String,
    browser: Option<Browser>,
}

/// A directory listing: its sub-directories and scene files.
#[derive(Debug)]
struct Browser {
    dir: PathBuf,
    dirs: Vec<String>,
    files: Vec<String>,
    error: Option<String>,
}

impl Browser {
    fn open(dir: PathBuf) -> Browser {
        let mut b = Browser { dir, dirs: Vec::new(), files: Vec::new(), error: None };
        match std::fs::read_dir(&b.dir) {
            Ok(entries) => {
                for e in entries.flatten() {
                    let name = e.file_name().to_string_lossy().into_owned();
                    if name.starts_with('.') {
                        continue;
                    }
                    if e.path().is_dir() {
                        b.dirs.push(name);
                    } else if is_scene_file(Path::new(&name)) {
                        b.files.push(name);
                    }
                }
                b.dirs.sort();
                b.files.sort();
            }
            Err(e) => b.error = Some(format!("{}: {e}", b.dir.display())),
        }
        b
    }
}

/// Whether the viewer can open this file (by its extension).
pub fn is_scene_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| SCENE_EXTENSIONS.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// The panel as a window over the image; the actions its widgets asked for this frame.
pub fn window(ctx: &egui::Context, controls: &Controls, figures: &Figures, state: &mut PanelState) -> Vec<Action> {
    let mut actions = Vec::new();
    egui::Window::new("rastergi").default_pos([8.0, 8.0]).default_width(270.0).resizable(false).show(ctx, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| actions = contents(ui, controls, figures, state));
    });
    actions
}

/// The panel's widgets, top to bottom; the actions they asked for this frame.
pub fn contents(ui: &mut Ui, c: &Controls, f: &Figures, state: &mut PanelState) -> Vec<Action> {
    let mut out = Vec::new();
    figures(ui, f);
    ui.separator();
    egui::CollapsingHeader::new("Scene").default_open(true).show(ui, |ui| scene(ui, f, state, &mut out));
    egui::CollapsingHeader::new("Renderer").default_open(true).show(ui, |ui| renderer(ui, c, &mut out));
    if c.method == Method::Gather {
        egui::CollapsingHeader::new("Photon map").default_open(true).show(ui, |ui| photon_map(ui, c, &mut out));
    }
    if c.sun.is_some() || c.env_scale.is_some() {
        egui::CollapsingHeader::new("Lights").default_open(true).show(ui, |ui| lights(ui, c, &mut out));
    }
    egui::CollapsingHeader::new("Camera").default_open(false).show(ui, |ui| camera(ui, c, &mut out));
    egui::CollapsingHeader::new("Display").default_open(true).show(ui, |ui| display(ui, c, &mut out));
    ui.horizontal(|ui| {
        if ui.button("Screenshot").on_hover_text("rastergi-NNNN.png (as shown) and .exr (linear); P").clicked() {
            out.push(Action::Screenshot);
        }
        ui.label(RichText::new("H hides the panel").weak());
    });
    out
}

/// Figures: iterations, rate, estimated error, photons, memory and the convergence plot.
fn figures(ui: &mut Ui, f: &Figures) {
    ui.label(RichText::new(format!("{}  {}x{}", f.scene, f.size.0, f.size.1)).strong());
    ui.label(format!("{} iterations  {:.1}/s", f.samples, f.iterations_per_second));
    let rough = if f.error_is_rough { " (rough: few iterations yet)" } else { "" };
    let error = f.error.map_or("-".to_owned(), |e| format!("{:.2} %{rough}", 100.0 * e));
    ui.label(format!("estimated error {error}"))
        .on_hover_text("relative RMSE estimated without a reference, from two independent halves of the iterations");
    let mut line = Vec::new();
    if let Some((pass, photons)) = f.photon_pass {
        ui.label(format!("photons {} ({photons} in each of {} passes)", photons as u64 * (pass as u64 + 1), pass + 1));
    }
    if let Some(g) = f.gather_in_use {
        line.push(format!("gather {}", gather_name(g)));
    }
    if let Some(bytes) = f.memory {
        line.push(format!("GPU memory {:.0} MiB", bytes as f64 / (1 << 20) as f64));
    }
    if !line.is_empty() {
        ui.label(line.join("  "));
    }
    convergence_plot(ui, f.history);
    if !f.status.is_empty() {
        ui.label(RichText::new(f.status).color(Color32::YELLOW));
    }
}

/// log error against log iterations since the restart, with a grey line of slope −½ (the
/// 1/√n of noise alone) through the last point.
fn convergence_plot(ui: &mut Ui, history: &[(u32, f64)]) {
    let (response, painter) =
        ui.allocate_painter(egui::vec2(ui.available_width().min(260.0), 70.0), egui::Sense::hover());
    let rect = response.rect;
    painter.rect_filled(rect, 2.0, Color32::from_gray(24));
    let points: Vec<(f64, f64)> =
        history.iter().filter(|(n, e)| *n > 0 && *e > 0.0).map(|&(n, e)| ((n as f64).ln(), e.ln())).collect();
    if points.len() < 2 {
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "error vs iterations",
            egui::FontId::proportional(11.0),
            Color32::GRAY,
        );
        return;
    }
    let (x0, x1) = (points[0].0, points[points.len() - 1].0.max(points[0].0 + 1e-3));
    let (mut y0, mut y1) = points.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    if y1 - y0 < 1e-3 {
        (y0, y1) = (y0 - 0.5, y1 + 0.5);
    }
    let to_screen = |x: f64, y: f64| {
        egui::pos2(
            rect.left() + 4.0 + (rect.width() - 8.0) * ((x - x0) / (x1 - x0)) as f32,
            rect.bottom() - 4.0 - (rect.height() - 8.0) * ((y - y0) / (y1 - y0)) as f32,
        )
    };
    // The slope line starts where it leaves the plot (at its top or its left edge).
    let (xl, yl) = points[points.len() - 1];
    let xs = x0.max(xl - 2.0 * (y1 - yl));
    let slope = [to_screen(xs, yl + 0.5 * (xl - xs)), to_screen(xl, yl)];
    painter.line_segment(slope, Stroke::new(1.0, Color32::from_gray(90)));
    let line: Vec<egui::Pos2> = points.iter().map(|&(x, y)| to_screen(x, y)).collect();
    painter.add(egui::Shape::line(line, Stroke::new(1.5, Color32::LIGHT_GREEN)));
    let label = format!("{:.2} % to {:.2} %", 100.0 * y1.exp(), 100.0 * yl.exp());
    painter.text(
        rect.right_top() + egui::vec2(-4.0, 2.0),
        egui::Align2::RIGHT_TOP,
        label,
        egui::FontId::proportional(10.0),
        Color32::GRAY,
    );
}

fn scene(ui: &mut Ui, f: &Figures, state: &mut PanelState, out: &mut Vec<Action>) {
    ui.horizontal(|ui| {
        let edit =
            ui.add(egui::TextEdit::singleline(&mut state.path).hint_text("scene file or name").desired_width(170.0));
        let entered = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        if (ui.button("Open").clicked() || entered) && !state.path.trim().is_empty() {
            out.push(Action::Open(state.path.trim().to_owned()));
        }
    });
    ui.horizontal(|ui| {
        ComboBox::from_label("built in").selected_text("open").show_ui(ui, |ui| {
            for name in BUILTINS {
                if ui.selectable_label(f.scene == name, name).clicked() {
                    out.push(Action::Open(name.to_owned()));
                }
            }
        });
        if ui.button(if state.browser.is_some() { "Close browser" } else { "Browse..." }).clicked() {
            state.browser = match state.browser {
                Some(_) => None,
                None => Some(Browser::open(std::env::current_dir().unwrap_or_default())),
            };
        }
    });
    let mut go = None;
    if let Some(b) = &state.browser {
        ui.label(RichText::new(b.dir.display().to_string()).weak());
        if let Some(e) = &b.error {
            ui.label(RichText::new(e).color(Color32::YELLOW));
        }
        egui::ScrollArea::vertical().id_salt("browser").max_height(140.0).show(ui, |ui| {
            if b.dir.parent().is_some() && ui.selectable_label(false, ".. (up)").clicked() {
                go = b.dir.parent().map(Path::to_path_buf);
            }
            for d in &b.dirs {
                if ui.selectable_label(false, format!("{d}/")).clicked() {
                    go = Some(b.dir.join(d));
                }
            }
            for file in &b.files {
                if ui.selectable_label(false, file).clicked() {
                    let path = b.dir.join(file);
                    state.path = path.display().to_string();
                    out.push(Action::Open(state.path.clone()));
                }
            }
        });
    } else {
        ui.label(RichText::new("or drop a .obj, .gltf or .glb file on the window").weak());
    }
    if let Some(dir) = go {
        state.browser = Some(Browser::open(dir));
    }
}

fn renderer(ui: &mut Ui, c: &Controls, out: &mut Vec<Action>) {
    let mut method = c.method;
    ui.horizontal(|ui| {
        ui.radio_value(&mut method, Method::Gather, "photon map + gather");
        ui.radio_value(&mut method, Method::Path, "path tracer");
    });
    if method != c.method {
        out.push(Action::Method(method));
    }
    if c.method != Method::Gather {
        return;
    }
    let mut gather = c.gather;
    ComboBox::from_label("gather").selected_text(gather_name(gather)).show_ui(ui, |ui| {
        for g in GatherArg::value_variants().iter().map(|a| a.method()) {
            ui.selectable_value(&mut gather, g, gather_name(g));
        }
    });
    if gather != c.gather {
        out.push(Action::Gather(gather));
    }
    let mut d = c.gather_directions;
    ui.horizontal(|ui| {
        ui.add_enabled_ui(c.gather != GatherMethod::Raster && c.gather != GatherMethod::Lists, |ui| {
            ui.radio_value(&mut d, GatherDirections::PerPixel, "per pixel");
            ui.radio_value(&mut d, GatherDirections::Shared, "shared");
        });
    })
    .response
    .on_hover_text("the traced gather's directions: each pixel its own, or each shared by every pixel");
    if d != c.gather_directions {
        out.push(Action::GatherDirections(d));
    }
    let mut n = c.directions;
    if ui.add(Slider::new(&mut n, 1..=MAX_DIRECTIONS).text("directions / iteration")).changed() {
        out.push(Action::Directions(n));
    }
    let mut guided = c.gather_guiding;
    if ui
        .checkbox(&mut guided, "guided gather")
        .on_hover_text("half of the traced gather's directions drawn towards where its cell found light")
        .changed()
    {
        out.push(Action::GatherGuiding(guided));
    }
    let mut sky = c.sky_guiding;
    if ui
        .checkbox(&mut sky, "guided sky")
        .on_hover_text("half of the environment's light samples drawn towards the parts of the sky open from there")
        .changed()
    {
        out.push(Action::SkyGuiding(sky));
    }
    let mut balanced = c.light_balance;
    if ui
        .checkbox(&mut balanced, "balanced light samples")
        .on_hover_text(
            "light samples per iteration chosen from the direct light's variance against the rest's and their costs",
        )
        .changed()
    {
        out.push(Action::LightBalance(balanced));
    }
    let mut edges = c.emitter_edges > 0;
    if ui
        .checkbox(&mut edges, "supersampled emitter edges")
        .on_hover_text("the emission seen at pixels on an emitter's or the sky's edge from 16 sub-pixel rays")
        .changed()
    {
        out.push(Action::EmitterEdges(edges));
    }
}

fn photon_map(ui: &mut Ui, c: &Controls, out: &mut Vec<Action>) {
    ComboBox::from_label("photons").selected_text(c.photons.to_string()).show_ui(ui, |ui| {
        for k in PHOTON_EXPONENTS {
            let n = 1u32 << k;
            if ui.selectable_label(c.photons == n, format!("2^{k} = {n}")).clicked() && n != c.photons {
                out.push(Action::Photons(n));
            }
        }
    });
    ComboBox::from_label("grid").selected_text(c.grid.to_string()).show_ui(ui, |ui| {
        for g in GRIDS {
            if ui.selectable_label(c.grid == g, g.to_string()).clicked() && g != c.grid {
                out.push(Action::Grid(g));
            }
        }
    });
    let mut budget = c.photon_budget;
    ui.horizontal(|ui| {
        ui.radio_value(&mut budget, PhotonBudget::Balanced, "balanced");
        ui.radio_value(&mut budget, PhotonBudget::Fitted, "fitted");
    })
    .response
    .on_hover_text("iterations per photon pass: measured (balanced) or 4 × photons / pixels (fitted)");
    if budget != c.photon_budget {
        out.push(Action::PhotonBudget(budget));
    }
    let mut guided = c.photon_guiding;
    if ui
        .checkbox(&mut guided, "guided photons")
        .on_hover_text("the sun's and the sky's photons sent where the photon map is read")
        .changed()
    {
        out.push(Action::PhotonGuiding(guided));
    }
    let passes = |p: u32| if p == 0 { "no limit".to_owned() } else { p.to_string() };
    ComboBox::from_label("photon passes").selected_text(passes(c.photon_passes)).show_ui(ui, |ui| {
        for p in PASSES {
            if ui.selectable_label(c.photon_passes == p, passes(p)).clicked() && p != c.photon_passes {
                out.push(Action::PhotonPasses(p));
            }
        }
    });
}

fn lights(ui: &mut Ui, c: &Controls, out: &mut Vec<Action>) {
    if let Some(sun) = c.sun {
        let SunAngles { mut azimuth, mut elevation } = sun;
        let a = ui.add(Slider::new(&mut azimuth, 0.0..=360.0).text("sun azimuth (deg)"));
        let e = ui.add(Slider::new(&mut elevation, -90.0..=90.0).text("sun elevation (deg)"));
        if a.changed() || e.changed() {
            out.push(Action::Sun { azimuth, elevation });
        }
    }
    if let Some(mut scale) = c.env_scale {
        let r = ui.add(Slider::new(&mut scale, 0.0..=100.0).logarithmic(true).text("environment scale"));
        if r.changed() {
            out.push(Action::EnvScale(scale));
        }
    }
}

fn camera(ui: &mut Ui, c: &Controls, out: &mut Vec<Action>) {
    let mut orbit = c.camera.mode == rastergi::camera_control::Mode::Orbit;
    ui.horizontal(|ui| {
        ui.radio_value(&mut orbit, false, "fly");
        ui.radio_value(&mut orbit, true, "orbit");
        if ui.button("Home").clicked() {
            out.push(Action::Home);
        }
    });
    if orbit != (c.camera.mode == rastergi::camera_control::Mode::Orbit) {
        out.push(Action::Mode { orbit });
    }
    let mut speed = c.camera.speed;
    if ui.add(Slider::new(&mut speed, 1e-3..=1e4).logarithmic(true).text("speed (units/s)")).changed() {
        out.push(Action::Speed(speed));
    }
    ui.label(RichText::new("WASD QE fly, drag to look or orbit, right drag pans, scroll zooms").weak());
}

fn display(ui: &mut Ui, c: &Controls, out: &mut Vec<Action>) {
    let mut show = c.show;
    ui.horizontal_wrapped(|ui| {
        for s in [Show::Full, Show::Direct, Show::Indirect, Show::PhotonMap] {
            ui.add_enabled_ui(s == Show::Full || c.method == Method::Gather, |ui| {
                ui.radio_value(&mut show, s, show_name(s));
            });
        }
    });
    if show != c.show {
        out.push(Action::Show(show));
    }
    let mut ev = c.exposure;
    if ui.add(Slider::new(&mut ev, -10.0..=10.0).step_by(0.1).text("exposure (EV)")).changed() {
        out.push(Action::Exposure(ev));
    }
    let mut denoise = c.denoise;
    let why_not = match (c.method, show) {
        (Method::Path, _) => Some("the path tracer has no denoiser: choose the photon map + gather"),
        (_, Show::Full) => None,
        _ => Some("the denoiser filters the full image: show full"),
    };
    let r = ui
        .add_enabled(why_not.is_none(), egui::Checkbox::new(&mut denoise, "denoise"))
        .on_hover_text("the edge-avoiding a-trous filter of the full image (N); the first time restarts the image");
    if let Some(why) = why_not {
        r.on_disabled_hover_text(why);
    }
    if denoise != c.denoise {
        out.push(Action::Denoise(denoise));
    }
}

/// The name of a gather implementation as `--gather` spells it.
pub fn gather_name(g: GatherMethod) -> String {
    let arg = GatherArg::value_variants().iter().find(|a| a.method() == g);
    arg.and_then(|a| a.to_possible_value()).map_or_else(|| format!("{g:?}"), |v| v.get_name().to_owned())
}

/// egui-wgpu on the viewer's device: draws the panel's output over the swapchain image.
pub struct PanelPainter {
    renderer: egui_wgpu::Renderer,
}

impl PanelPainter {
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> PanelPainter {
        PanelPainter { renderer: egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default()) }
    }

    /// Encodes drawing `output` (one egui pass, tessellated here) over `target`, loading what
    /// the display pass drew there.
    pub fn encode(
        &mut self,
        gpu: &rastergi::gpu::Gpu,
        ctx: &egui::Context,
        output: egui::FullOutput,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        let screen =
            egui_wgpu::ScreenDescriptor { size_in_pixels: [size.0, size.1], pixels_per_point: output.pixels_per_point };
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                self.renderer.update_texture(&gpu.device, &gpu.queue, *id, delta);
            }
        }
        let jobs = ctx.tessellate(output.shapes, output.pixels_per_point);
        let extra = self.renderer.update_buffers(&gpu.device, &gpu.queue, enc, &jobs, &screen);
        if !extra.is_empty() {
            gpu.queue.submit(extra);
        }
        {
            let pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("panel"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.renderer.render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        for id in &output.textures_delta.free {
            self.renderer.free_texture(id);
        }
    }
}

/// The egui panel: its context, window-input state, GPU painter and own state.
pub(super) struct Panel {
    pub(super) ctx: egui::Context,
    pub(super) input: egui_winit::State,
    pub(super) painter: PanelPainter,
    pub(super) state: PanelState,
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui_kittest::Harness;
    use egui_kittest::kittest::{NodeT, Queryable};
    use glam::Vec3;
    use rastergi::camera_control::CameraControl;
    use rastergi::scene::{Aabb, Camera};
    use rastergi::settings::RenderSettings;

    /// Controls with a sun and an environment, and the actions the panel gave, applied as the
    /// viewer applies them.
    struct Model {
        controls: Controls,
        actions: Vec<Action>,
        state: PanelState,
    }

    fn harness() -> Harness<'static, Model> {
        let camera = Camera { eye: Vec3::new(0.0, 0.0, 3.9), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 39.3 };
        let bounds = Aabb { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) };
        let settings = RenderSettings { photons: 1 << 16, grid_resolution: 64, ..Default::default() };
        let mut controls = Controls::new(CameraControl::new(&camera, &bounds), Show::Full, 0.0, &settings);
        controls.sun = Some(SunAngles { azimuth: 30.0, elevation: 45.0 });
        controls.env_scale = Some(1.0);
        let model = Model { controls, actions: Vec::new(), state: PanelState::default() };
        Harness::builder().with_size(egui::vec2(320.0, 1200.0)).build_ui_state(
            |ui, m: &mut Model| {
                let history = [(1, 0.2), (4, 0.1), (16, 0.05)];
                let f = Figures {
                    scene: "cornell",
                    size: (64, 64),
                    samples: 16,
                    iterations_per_second: 10.0,
                    error: Some(0.05),
                    error_is_rough: false,
                    photon_pass: Some((0, 1 << 16)),
                    gather_in_use: Some(GatherMethod::Trace),
                    memory: Some(64 << 20),
                    history: &history,
                    status: "",
                };
                for a in contents(ui, &m.controls, &f, &mut m.state) {
                    m.controls.action(&a, 64.0);
                    m.actions.push(a);
                }
            },
            model,
        )
    }

    /// Clicks the widgets labelled `labels` in turn, running a frame after each.
    fn click(h: &mut Harness<'static, Model>, labels: &[&str]) {
        for label in labels {
            h.get_by_label(label).click();
            h.run();
        }
    }

    #[test]
    fn the_panels_widgets_give_the_scripts_actions() {
        let mut h = harness();
        h.run();
        click(&mut h, &["path tracer"]);
        assert_eq!(h.state().actions, [Action::Method(Method::Path)]);
        assert!(h.query_by_label("photons").is_none(), "no photon map settings for the path tracer");
        assert!(h.get_by_label("denoise").accesskit_node().is_disabled(), "the path tracer has no denoiser");
        click(&mut h, &["photon map + gather", "shared", "Screenshot", "denoise", "indirect"]);
        assert!(h.get_by_label("denoise").accesskit_node().is_disabled(), "the denoiser filters the full image alone");
        assert_eq!(
            h.state().actions[1..],
            [
                Action::Method(Method::Gather),
                Action::GatherDirections(GatherDirections::Shared),
                Action::Screenshot,
                Action::Denoise(true),
                Action::Show(Show::Indirect),
            ]
        );
        assert_eq!(
            (h.state().controls.show, h.state().controls.gather_directions),
            (Show::Indirect, GatherDirections::Shared)
        );
    }

    #[test]
    fn the_panels_menus_choose_the_gather_the_photons_and_a_scene() {
        let mut h = harness();
        h.run();
        click(&mut h, &["gather", "trace", "photons", "2^20 = 1048576", "built in", "atrium"]);
        assert_eq!(
            h.state().actions,
            [Action::Gather(GatherMethod::Trace), Action::Photons(1 << 20), Action::Open("atrium".into())]
        );
        assert_eq!(h.state().controls.photons, 1 << 20);
    }
}
