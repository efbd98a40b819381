//! The viewer's input handling, free of any window so that it is unit-tested: the keys that
//! mean something ([`Key`]), the interactive state ([`Controls`]: camera controller, held
//! keys, what is shown, exposure, renderer settings, panel) and what an input asks of the
//! application ([`Response`]); also the camera and the shown image as text.

use rastergi::camera_control::{CameraControl, Mode, MoveKeys};
use rastergi::gather::{GatherDirections, GatherMethod};
use rastergi::passes::film::Show;
use rastergi::scene::Camera;
use rastergi::settings::RenderSettings;

use super::script::Action;
use crate::render::Method;

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
    /// Turn the sun (a distant light) by [`SUN_STEP`]: azimuth down / up, elevation up / down.
    SunWest,
    SunEast,
    SunHigher,
    SunLower,
    Screenshot,
    TogglePanel,
    /// The denoised image on / off.
    ToggleDenoise,
    Quit,
}

pub use rastergi::scene::SunAngles;

/// Degrees per press of the sun keys.
pub const SUN_STEP: f32 = 5.0;

/// What the application must do after an input.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Response {
    /// The camera moved: restart the accumulation.
    pub camera_moved: bool,
    /// The renderer's settings changed: build a new renderer (new photon map).
    pub retrace: bool,
    /// Open this scene (a built-in name or a file) in place of the current one.
    pub open: Option<String>,
    pub screenshot: bool,
    pub quit: bool,
}

/// Exposure step of the + and - keys, in stops.
pub const EXPOSURE_STEP: f32 = 0.5;

/// The viewer's interactive state, free of any window: the camera controller, held keys,
/// what is shown and the renderer's settings. Inputs come in as [`Key`]s, drags, scrolls and
/// [`Action`]s (a script's or the panel's) and return what the application must do.
#[derive(Clone, Debug)]
pub struct Controls {
    pub camera: CameraControl,
    home: CameraControl,
    pub keys: MoveKeys,
    pub show: Show,
    pub exposure: f32,
    pub method: Method,
    pub photons: u32,
    pub grid: u32,
    pub photon_passes: u32,
    pub gather: GatherMethod,
    pub gather_directions: GatherDirections,
    pub directions: u32,
    /// How long photon passes last, and the guides of photons and of the gather.
    pub photon_budget: rastergi::settings::PhotonBudget,
    pub photon_guiding: bool,
    pub gather_guiding: bool,
    pub sky_guiding: bool,
    /// The light samples per iteration balanced by measurement (else the fixed count).
    pub light_balance: bool,
    /// Sub-pixel rays per axis for the emission at emitters' edges (0: off).
    pub emitter_edges: u32,
    /// The scene's sun (its last distant light), if it has one.
    pub sun: Option<SunAngles>,
    /// The environment map's radiance scale, if the scene has one that can be scaled.
    pub env_scale: Option<f32>,
    /// The control panel is shown (H).
    pub panel: bool,
    /// Show the denoised image (N): where the renderer has a denoiser (the photon map's) and
    /// the full image is shown.
    pub denoise: bool,
}

impl Controls {
    /// Controls starting at `camera` (also the Home position), showing `show` at `exposure`,
    /// with the renderer settings of `settings`.
    pub fn new(camera: CameraControl, show: Show, exposure: f32, settings: &RenderSettings) -> Controls {
        Controls {
            home: camera.clone(),
            camera,
            keys: MoveKeys::default(),
            show,
            exposure,
            method: Method::Gather,
            photons: settings.photons,
            grid: settings.grid_resolution,
            photon_passes: settings.photon_passes,
            gather: settings.gather,
            gather_directions: settings.gather_directions,
            directions: settings.directions,
            photon_budget: settings.photon_budget,
            photon_guiding: settings.photon_guiding,
            gather_guiding: settings.gather_guiding,
            sky_guiding: settings.sky_guiding,
            light_balance: settings.light_balance,
            emitter_edges: settings.emitter_edges,
            sun: None,
            env_scale: None,
            panel: true,
            denoise: false,
        }
    }

    /// A new scene's camera (also the new Home), its speed fitted to that scene; the drag
    /// mode stays.
    pub fn set_home(&mut self, camera: CameraControl) {
        let mode = self.camera.mode;
        self.home = camera.clone();
        self.camera = camera;
        if self.camera.mode != mode {
            self.camera.toggle_mode();
        }
    }

    /// Back to the starting camera, keeping the mode and speed; whether the camera moved.
    fn home(&mut self) -> bool {
        let (mode, speed) = (self.camera.mode, self.camera.speed);
        let moved = self.camera.camera() != self.home.camera();
        self.camera = self.home.clone();
        (self.camera.mode, self.camera.speed) = (mode, speed);
        moved
    }

    /// The settings of the renderer these controls ask for: `base` with the controls'
    /// photon map, gather and directions, at `width × height`.
    pub fn settings(&self, base: &RenderSettings, width: u32, height: u32) -> RenderSettings {
        RenderSettings {
            width,
            height,
            photons: self.photons,
            grid_resolution: self.grid,
            photon_passes: self.photon_passes,
            gather: self.gather,
            gather_directions: self.gather_directions,
            directions: self.directions,
            photon_budget: self.photon_budget,
            photon_guiding: self.photon_guiding,
            gather_guiding: self.gather_guiding,
            sky_guiding: self.sky_guiding,
            light_balance: self.light_balance,
            emitter_edges: self.emitter_edges,
            ..base.clone()
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
        // Auto-repeat steps the exposure and the sun; other keys act once per press.
        match key {
            Key::ExposureUp => self.exposure += EXPOSURE_STEP,
            Key::ExposureDown => self.exposure -= EXPOSURE_STEP,
            Key::SunWest | Key::SunEast | Key::SunHigher | Key::SunLower if repeat => {
                return self.key(key, true, false);
            }
            _ if repeat => {}
            Key::ToggleMode => self.camera.toggle_mode(),
            Key::Home => r.camera_moved = self.home(),
            Key::Show(show) => self.show = show,
            Key::FewerPhotons => r.retrace = self.set_photons(self.photons / 2),
            Key::MorePhotons => r.retrace = self.set_photons(self.photons.saturating_mul(2)),
            Key::CoarserGrid => r.retrace = self.set_grid(self.grid / 2),
            Key::FinerGrid => r.retrace = self.set_grid(self.grid * 2),
            Key::SunWest => r.retrace = self.turn_sun(-SUN_STEP, 0.0),
            Key::SunEast => r.retrace = self.turn_sun(SUN_STEP, 0.0),
            Key::SunHigher => r.retrace = self.turn_sun(0.0, SUN_STEP),
            Key::SunLower => r.retrace = self.turn_sun(0.0, -SUN_STEP),
            Key::Screenshot => r.screenshot = true,
            Key::TogglePanel => self.panel = !self.panel,
            Key::ToggleDenoise => self.denoise = !self.denoise,
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

    /// Turns the sun by (azimuth, elevation) degrees (the elevation kept within ±90°);
    /// whether that is a change (none without a sun).
    pub fn turn_sun(&mut self, azimuth: f32, elevation: f32) -> bool {
        let Some(s) = self.sun else { return false };
        self.set_sun(SunAngles { azimuth: s.azimuth + azimuth, elevation: s.elevation + elevation })
    }

    /// Puts the sun at these angles (azimuth wrapped to [0, 360), elevation clamped to ±90°);
    /// whether that is a change (none without a sun).
    pub fn set_sun(&mut self, to: SunAngles) -> bool {
        let Some(sun) = &mut self.sun else { return false };
        let to = SunAngles { azimuth: to.azimuth.rem_euclid(360.0), elevation: to.elevation.clamp(-90.0, 90.0) };
        std::mem::replace(sun, to) != to
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

    /// An action of a script or the panel: the camera, what is shown, the renderer's settings
    /// (a change asks for a new renderer), a scene to open, a screenshot, quit. (`resize` is
    /// the window's: the application handles it.)
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
            Action::Denoise(on) => self.denoise = on,
            Action::Photons(n) => r.retrace = self.set_photons(n),
            Action::Grid(n) => r.retrace = self.set_grid(n),
            Action::Sun { azimuth, elevation } => r.retrace = self.set_sun(SunAngles { azimuth, elevation }),
            Action::PhotonPasses(n) => r.retrace = std::mem::replace(&mut self.photon_passes, n) != n,
            Action::EnvScale(s) => {
                let s = s.max(0.0);
                r.retrace = self.env_scale.is_some_and(|old| old != s);
                if let Some(scale) = &mut self.env_scale {
                    *scale = s;
                }
            }
            Action::Method(e) => r.retrace = std::mem::replace(&mut self.method, e) != e,
            Action::Gather(g) => r.retrace = std::mem::replace(&mut self.gather, g) != g,
            Action::GatherDirections(d) => r.retrace = std::mem::replace(&mut self.gather_directions, d) != d,
            Action::Directions(n) => {
                let n = n.clamp(1, rastergi::gather::MAX_DIRECTIONS);
                r.retrace = std::mem::replace(&mut self.directions, n) != n;
            }
            Action::PhotonBudget(b) => r.retrace = std::mem::replace(&mut self.photon_budget, b) != b,
            Action::PhotonGuiding(on) => r.retrace = std::mem::replace(&mut self.photon_guiding, on) != on,
            Action::GatherGuiding(on) => r.retrace = std::mem::replace(&mut self.gather_guiding, on) != on,
            Action::SkyGuiding(on) => r.retrace = std::mem::replace(&mut self.sky_guiding, on) != on,
            Action::LightBalance(on) => r.retrace = std::mem::replace(&mut self.light_balance, on) != on,
            Action::EmitterEdges(on) => {
                let n = if on { rastergi::passes::emitter_edges::DEFAULT_EMITTER_EDGES } else { 0 };
                r.retrace = std::mem::replace(&mut self.emitter_edges, n) != n;
            }
            Action::Speed(s) => self.camera.speed = s.max(1e-6),
            Action::Home => r.camera_moved = self.home(),
            Action::Open(ref name) => r.open = Some(name.clone()),
            Action::Panel(on) => self.panel = on,
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

/// The name of `show` as `--show` and scripts spell it.
pub fn show_name(show: Show) -> &'static str {
    match show {
        Show::Full => "full",
        Show::Direct => "direct",
        Show::Indirect => "indirect",
        Show::PhotonMap => "photon-map",
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
        let settings = RenderSettings { photons: 1 << 20, grid_resolution: 64, ..Default::default() };
        Controls::new(CameraControl::new(&camera, &bounds), Show::Full, 0.0, &settings)
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
    fn show_exposure_mode_and_panel_keys_do_not_restart() {
        let mut c = controls();
        let camera = c.camera.camera();
        for key in [
            Key::Show(Show::PhotonMap),
            Key::ExposureUp,
            Key::ExposureUp,
            Key::ExposureDown,
            Key::ToggleMode,
            Key::TogglePanel,
            Key::ToggleDenoise,
            Key::Fast,
        ] {
            assert_eq!(c.key(key, true, false), Response::default(), "{key:?}");
        }
        assert_eq!((c.show, c.exposure, c.camera.mode, c.panel), (Show::PhotonMap, 0.5, Mode::Orbit, false));
        // The denoiser's toggle asks for nothing here: the application restarts the image the
        // first time it enables the denoiser's guides.
        assert!(c.denoise);
        assert!(!c.key(Key::ToggleDenoise, true, true).retrace && c.denoise, "auto-repeat does not toggle again");
        assert_eq!(c.action(&Action::Denoise(false), 64.0), Response::default());
        assert!(!c.denoise);
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
    fn renderer_actions_ask_for_a_new_renderer_only_when_they_change_a_setting() {
        let mut c = controls();
        let base = RenderSettings::default();
        let before = c.settings(&base, 64, 48);
        let changes = [
            Action::Method(Method::Path),
            Action::Gather(GatherMethod::Lists),
            Action::GatherDirections(GatherDirections::Shared),
            Action::Directions(7),
            Action::PhotonPasses(3),
        ];
        for a in &changes {
            assert!(c.action(a, 64.0).retrace, "{a:?}");
            assert!(!c.action(a, 64.0).retrace, "{a:?} again");
        }
        let after = c.settings(&base, 64, 48);
        assert_eq!((after.width, after.height, after.photons), (64, 48, before.photons));
        assert_eq!(
            (after.gather, after.gather_directions, after.directions, after.photon_passes),
            (GatherMethod::Lists, GatherDirections::Shared, 7, 3)
        );
        assert_eq!(c.method, Method::Path);
        assert!(!c.action(&Action::EnvScale(2.0), 64.0).retrace, "no environment, nothing to scale");
        c.env_scale = Some(1.0);
        assert!(c.action(&Action::EnvScale(2.0), 64.0).retrace && c.env_scale == Some(2.0));
        let r = c.action(&Action::Open("atrium".into()), 64.0);
        assert_eq!((r.open.as_deref(), r.retrace), (Some("atrium"), false));
        let camera = c.camera.camera();
        assert_eq!(c.action(&Action::Speed(3.0), 64.0), Response::default());
        assert_eq!((c.camera.speed, c.camera.camera()), (3.0, camera));
    }

    #[test]
    fn the_sun_keys_turn_a_sun_and_nothing_else() {
        let mut c = controls();
        assert!(!c.key(Key::SunEast, true, false).retrace, "no sun, nothing to turn");
        c.sun = Some(SunAngles::of_direction(SunAngles { azimuth: 30.0, elevation: 45.0 }.direction()));
        let s = c.sun.unwrap();
        assert!((s.azimuth - 30.0).abs() < 1e-3 && (s.elevation - 45.0).abs() < 1e-3, "{s:?}");
        assert!(c.key(Key::SunWest, true, false).retrace && (c.sun.unwrap().azimuth - 25.0).abs() < 1e-3);
        assert!(c.key(Key::SunHigher, true, true).retrace, "auto-repeat turns it on");
        assert!((c.sun.unwrap().elevation - 50.0).abs() < 1e-3);
        for _ in 0..10 {
            c.key(Key::SunHigher, true, false);
        }
        assert_eq!(c.sun.unwrap().elevation, 90.0, "the elevation stops at the zenith");
        assert!(!c.key(Key::SunHigher, true, false).retrace);
        assert!(c.action(&Action::Sun { azimuth: -10.0, elevation: 20.0 }, 64.0).retrace);
        assert_eq!(c.sun, Some(SunAngles { azimuth: 350.0, elevation: 20.0 }));
        // --sun's convention: azimuth 90° (towards +X), elevation 0 shines along −X.
        let d = SunAngles { azimuth: 90.0, elevation: 0.0 }.direction();
        assert!(d.abs_diff_eq(-glam::Vec3::X, 1e-6), "{d}");
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
}
