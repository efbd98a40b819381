//! From options to a renderer, in one place: every front end (the `rastergi` program, the
//! Python package, the web page) describes what it wants as [`Options`] and gets its scene,
//! its [`RenderSettings`] and its [`Progressive`] renderer here, so that the same options
//! give the same image everywhere.
//!
//! - [`Options`]: the scene (built in or a file) and what overrides it (camera, lights, sun,
//!   sky, environment), the image size, the renderer's settings (photons, grid, gather …),
//!   the [`Method`] and the GPU. No parsing: the command line's parser ([`args`], feature
//!   `clap`) and the web page's controls fill it in.
//! - [`Options::load_scene`] (natively: it reads files) loads the scene and applies the
//!   overrides, [`Options::image_size`] and [`Options::settings`] fit the rest to it,
//!   [`Session`] holds the three, and [`new_renderer`] builds the renderer.
//! - [`run`]: the loop of a render (iterations, time limit, target error, checkpoints, a stop
//!   flag), which the program's `render` and the Python package drive.

#[cfg(feature = "clap")]
pub mod args;
pub mod interactive;
pub mod refine;
pub mod run;
#[cfg(test)]
mod tests;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::fit;
use crate::gather::{GatherDirections, GatherMethod, HitLight};
use crate::gpu::{Gpu, GpuOptions};
use crate::passes::film::Show;
use crate::path_tracer::PathTracer;
use crate::progressive::{Denoising, Progressive};
use crate::renderer::Renderer;
use crate::scene::{Light, Scene};
use crate::settings::{PhotonRegionChoice, RenderSettings, TextureFilter};

/// Which renderer makes the image.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Method {
    /// The photon map + rasterized final gather ([`Renderer`]).
    #[default]
    Gather,
    /// The reference path tracer ([`PathTracer`]).
    Path,
}

impl Method {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Gather => "gather",
            Method::Path => "path",
        }
    }

    /// Refuses a view the method does not render (the path tracer renders the full image only).
    pub fn check_show(self, show: Show) -> Result<()> {
        if self == Method::Path && show != Show::Full {
            return Err(Error::Invalid(
                "--method path renders the full image only; drop --show or use --method gather".into(),
            ));
        }
        Ok(())
    }
}

/// The sun of `--sun`: azimuth and elevation in degrees, and its irradiance in W/m² (none
/// with `--sky`, whose model gives it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    pub azimuth: f32,
    pub elevation: f32,
    pub irradiance: Option<f32>,
}

/// What a front end asks for: the scene and its overrides, the image size, the renderer and
/// its settings, and the GPU. `None` fields are fitted to the scene or taken from it. The
/// defaults are the command line's (and the scene, which it always names, `cornell`).
#[derive(Clone, Debug)]
pub struct Options {
    /// A built-in scene's name (`cornell`, `spheres:N` …) or a scene file's path (.obj, .gltf,
    /// .glb, Mitsuba .xml); also the name the messages give the scene.
    pub scene: String,
    /// Image width and height in pixels: as given, else the scene file's film (the other side
    /// from its aspect where one is given), else 256.
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Overrides of the scene's camera.
    pub eye: Option<Vec3>,
    pub target: Option<Vec3>,
    pub up: Option<Vec3>,
    pub fov: Option<f32>,
    /// A glTF file's camera, by its index.
    pub camera: Option<usize>,
    /// A Mitsuba file's parameters (`-D NAME=VALUE`).
    pub defines: Vec<(String, String)>,
    pub seed: u32,
    /// The sun added (with [`Options::sky`]: its position only).
    pub sun: Option<Sun>,
    /// A physical sky of this turbidity as the environment, for [`Options::sun`] or the
    /// scene's own sun.
    pub sky: Option<f32>,
    /// The sun's angular diameter in degrees.
    pub sun_size: f32,
    /// Lights added to the scene's (points, spots).
    pub lights: Vec<Light>,
    /// An environment map file; `none`: no environment, not even the neutral one a scene
    /// without lights gets.
    pub env: Option<std::path::PathBuf>,
    pub env_scale: f32,
    /// Rough metals and glass without their multiple-scattering compensation.
    pub single_scattering: bool,
    /// Light samples per pixel per iteration, the first count where `light_balance`.
    pub light_samples: u32,
    /// The light samples chosen by measurement ([`crate::passes::light_budget`]).
    pub light_balance: bool,
    /// Sub-pixel rays per axis for the emission at emitters' edges (0: off;
    /// [`crate::passes::emitter_edges`]).
    pub emitter_edges: u32,
    /// Photons per pass and photon grid cells along the longest axis (`None`: fitted).
    pub photons: Option<u32>,
    pub grid: Option<u32>,
    pub photon_passes: u32,
    pub pass_iterations: u32,
    /// How long each photon pass lasts where `pass_iterations` is 0.
    pub photon_budget: crate::settings::PhotonBudget,
    /// The sun's and the sky's photons guided to where the map is read.
    pub photon_guiding: bool,
    /// The traced gather's directions guided by the light its rays found.
    pub gather_guiding: bool,
    /// The direct pass's environment samples guided to the parts of the sky open from each
    /// visible point.
    pub sky_guiding: bool,
    /// The gather's ray-view resolution (`None`: fitted).
    pub bundle: Option<u32>,
    pub gather: GatherMethod,
    pub gather_directions: GatherDirections,
    pub directions: u32,
    pub hit_light: HitLight,
    pub photon_region: PhotonRegionChoice,
    pub texture_filter: TextureFilter,
    /// How the eye pass finds the visible points ([`crate::settings::EyeMethod`]).
    pub eye_pass: crate::settings::EyeMethod,
    /// What the image shows ([`Show::PhotonMap`] keeps the photon map's view).
    pub show: Show,
    pub method: Method,
    /// Enable the denoiser's guides from the first iteration (the photon-map renderer only).
    pub denoiser: bool,
    /// The GPU's backends and ray traversal.
    pub gpu: GpuOptions,
    /// What a scene file may make the loaders read and hold (`--budget NAME=N`).
    pub budgets: crate::scene::Budgets,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            scene: "cornell".into(),
            width: None,
            height: None,
            eye: None,
            target: None,
            up: None,
            fov: None,
            camera: None,
            defines: Vec::new(),
            seed: 0,
            sun: None,
            sky: None,
            sun_size: DEFAULT_SUN_SIZE,
            lights: Vec::new(),
            env: None,
            env_scale: 1.0,
            single_scattering: false,
            light_samples: 1,
            light_balance: true,
            emitter_edges: crate::passes::emitter_edges::DEFAULT_EMITTER_EDGES,
            photons: None,
            grid: None,
            photon_passes: 0,
            pass_iterations: crate::photons::passes::DEFAULT_PASS_ITERATIONS,
            photon_budget: crate::settings::PhotonBudget::Balanced,
            photon_guiding: false,
            gather_guiding: false,
            sky_guiding: false,
            bundle: None,
            gather: GatherMethod::Auto,
            gather_directions: GatherDirections::default(),
            directions: crate::settings::DEFAULT_DIRECTIONS,
            hit_light: HitLight::Punctual,
            photon_region: PhotonRegionChoice::Camera,
            texture_filter: TextureFilter::Footprint,
            eye_pass: crate::settings::EyeMethod::Auto,
            show: Show::Full,
            method: Method::Gather,
            denoiser: false,
            gpu: GpuOptions::default(),
            budgets: crate::scene::Budgets::default(),
        }
    }
}

/// The sun's angular diameter in degrees when none is given (the real sun's).
pub const DEFAULT_SUN_SIZE: f32 = 0.53;

impl Options {
    /// The scene with the camera options applied, its camera validated, and the light
    /// options: the lights added, the sun and sky, the environment map, and a neutral grey
    /// environment for a scene without light ([`Scene::light_if_unlit`]) unless `env` is
    /// `none`.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn load_scene(&self) -> Result<Scene> {
        use std::path::Path;
        let mut scene = load_scene_with(&self.scene, self.camera, &self.defines, &self.budgets)?;
        let c = &mut scene.camera;
        c.eye = self.eye.unwrap_or(c.eye);
        c.target = self.target.unwrap_or(c.target);
        c.up = self.up.unwrap_or(c.up);
        c.fov_y_deg = self.fov.unwrap_or(c.fov_y_deg);
        scene.camera.validate()?;
        scene.lights.extend(self.lights.iter().cloned());
        let invalid = |m: String| Err(Error::Invalid(m));
        match (self.sun, self.sky) {
            (Some(Sun { irradiance: Some(_), .. }), Some(_)) => {
                return invalid(
                    "with --sky the sky model gives the sun's irradiance: give --sun AZIMUTH,ELEVATION without IRRADIANCE"
                        .into(),
                );
            }
            (Some(Sun { irradiance: None, .. }), None) => {
                return invalid(
                    "--sun AZIMUTH,ELEVATION needs --sky (or add IRRADIANCE: --sun AZIMUTH,ELEVATION,IRRADIANCE)"
                        .into(),
                );
            }
            (Some(sun), None) => scene.lights.push(sun_light(sun, self.sun_size)),
            (sun, Some(turbidity)) => {
                if self.env.is_some() {
                    return invalid("--sky and --env each give the scene's environment; give one of them".into());
                }
                let light = match sun {
                    Some(sun) => sun_light(sun, self.sun_size),
                    None => {
                        let i = scene.lights.iter().rposition(|l| matches!(l, Light::Distant { .. }));
                        let Some(i) = i else {
                            return invalid(format!(
                                "--sky needs the sun's position: give --sun AZIMUTH,ELEVATION (the scene {} has no sun)",
                                self.scene
                            ));
                        };
                        scene.lights.remove(i)
                    }
                };
                let (environment, sun) = physical_sky(turbidity, light)?;
                scene.environment = Some(std::sync::Arc::new(environment));
                scene.lights.extend(sun);
            }
            (None, None) => {}
        }
        let no_default_light = self.env.as_deref() == Some(Path::new("none"));
        if let Some(path) = self.env.as_ref().filter(|_| !no_default_light) {
            let env = crate::environment::Environment::load_with(path, self.env_scale, &self.budgets)?;
            if env.is_dark() {
                log::warn!("{}: the environment map is black everywhere; it adds no light", path.display());
            }
            scene.environment = Some(env);
        }
        if self.single_scattering {
            scene.single_scattering();
        }
        let model = matches!(extension_of(&self.scene).as_deref(), Some("gltf" | "glb"));
        if no_default_light {
            let lit_by_env = scene.environment.as_ref().is_some_and(|e| !e.is_dark());
            if scene.lights.is_empty() && !lit_by_env && scene.emissive_triangles().is_empty() {
                log::warn!("{}: the scene has no light and --env none, so it renders black", self.scene);
            }
        } else if let Some(what) = scene.light_if_unlit(model) {
            // glTF models rarely carry lights, and glTF viewers show them in a neutral
            // image-based light by default: so does rastergi, a scene without any light too.
            log::warn!(
                "{}: {what}: lit by a neutral grey environment, as glTF viewers light models (--env none: \
                 no light; --env SKY.hdr, --sky TURBIDITY or --sun: other light)",
                self.scene
            );
        }
        Ok(scene)
    }

    /// The image size: `width` and `height` as given, else the scene file's film (where one
    /// of them is given, the other from the film's aspect), else 256 × 256.
    pub fn image_size(&self, scene: &Scene) -> (u32, u32) {
        let other = |given: u32, a: u32, b: u32| ((given as u64 * b as u64 + a as u64 / 2) / a as u64).max(1) as u32;
        match (self.width, self.height, scene.framing.filter(|f| f.width > 0 && f.height > 0)) {
            (Some(w), Some(h), _) => (w, h),
            (None, None, Some(f)) => (f.width, f.height),
            (Some(w), None, Some(f)) => (w, other(w, f.width, f.height)),
            (None, Some(h), Some(f)) => (other(h, f.height, f.width), h),
            (w, h, None) => (w.unwrap_or(256), h.unwrap_or(256)),
        }
    }

    /// The renderer's settings for `scene` at the given image size: the photon grid and count
    /// as given, else fitted to the scene ([`crate::fit`]); the photon map's own view kept
    /// where `show_photon_map` is set (the viewer keeps it to switch to it).
    pub fn settings(&self, scene: &Scene, width: u32, height: u32, show_photon_map: bool) -> RenderSettings {
        let grid = self.grid.unwrap_or_else(|| fit::grid_resolution(&scene.bounds()));
        // Progressive passes at the fitted cadence: no pass longer than about 64 iterations (a
        // balanced budget chooses the passes' length, with a looser cap for thumbnails).
        let progressive = self.photon_passes != 1 && self.pass_iterations == 0;
        // A web page cannot wait for the measurements of the balanced budget and the photon
        // guide ([`crate::gpu::READ_BACK_BLOCKS`]): it renders with the fitted budget.
        let (photon_budget, photon_guiding) = match crate::gpu::READ_BACK_BLOCKS {
            true => (self.photon_budget, self.photon_guiding),
            false => (crate::settings::PhotonBudget::Fitted, false),
        };
        let photons = self.photons.unwrap_or_else(|| {
            let fitted = fit::photon_count(scene, grid);
            let pixels = width as u64 * height as u64;
            match photon_budget {
                _ if !progressive => fitted,
                crate::settings::PhotonBudget::Fitted => fit::photons_for_image(fitted, pixels),
                crate::settings::PhotonBudget::Balanced => fit::photons_for_balanced_image(fitted, pixels),
            }
        });
        log::info!(
            "photons {photons}{}, grid {grid}{}",
            if self.photons.is_some() { "" } else { " (fitted)" },
            if self.grid.is_some() { "" } else { " (fitted)" }
        );
        RenderSettings {
            width,
            height,
            seed: self.seed,
            light_samples: self.light_samples,
            // A web page cannot wait for the film's read-back either.
            light_balance: self.light_balance && crate::gpu::READ_BACK_BLOCKS,
            emitter_edges: self.emitter_edges,
            photons,
            grid_resolution: grid,
            show_photon_map,
            bundle: self.bundle.unwrap_or(0),
            gather: self.gather,
            gather_directions: self.gather_directions,
            auto_trials_on_cpu: false,
            directions: self.directions,
            photon_passes: self.photon_passes,
            pass_iterations: self.pass_iterations,
            photon_budget,
            photon_guiding,
            gather_guiding: self.gather_guiding,
            sky_guiding: self.sky_guiding,
            hit_light: self.hit_light,
            photon_region: self.photon_region,
            texture_filter: self.texture_filter,
            eye_pass: self.eye_pass,
        }
    }
}

/// A scene made ready for a renderer: loaded or given, with the image size and the settings
/// the [`Options`] give for it. [`Session::renderer`] builds the renderer.
#[derive(Clone, Debug)]
pub struct Session {
    pub scene: Scene,
    pub settings: RenderSettings,
}

impl Session {
    /// Loads the scene as `options` say ([`Options::load_scene`]) and fits the settings.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn load(options: &Options) -> Result<Session> {
        Ok(Session::of_scene(options.load_scene()?, options))
    }

    /// `scene` as it is (loaded elsewhere: a web page's files) with the settings `options`
    /// give for it.
    pub fn of_scene(scene: Scene, options: &Options) -> Session {
        let (width, height) = options.image_size(&scene);
        let settings = options.settings(&scene, width, height, options.show == Show::PhotonMap);
        Session { scene, settings }
    }

    /// The renderer of `options.method` (with the denoiser's guides where `options.denoiser`).
    pub fn renderer(&self, gpu: &Gpu, options: &Options) -> Result<Built> {
        new_renderer(gpu, &self.scene, self.settings.clone(), options.method, options.denoiser)
    }
}

/// The photon-map renderer's gather as built: its ray view's resolution, directions and
/// method (`Auto` until its trials choose).
pub type GatherInfo = (u32, GatherDirections, GatherMethod);

/// A renderer, and for the photon-map renderer its gather ray view and directions (for the log).
pub type Built = (Box<dyn Progressive>, Option<GatherInfo>);

/// The renderer of `method` for `scene` (BVH, upload, the first photon map), with the
/// denoiser's guides enabled where `denoiser` is set (the photon-map renderer only). Every
/// front end builds its renderer here, so the same options give the same image.
pub fn new_renderer(
    gpu: &Gpu,
    scene: &Scene,
    settings: RenderSettings,
    method: Method,
    denoiser: bool,
) -> Result<Built> {
    Ok(match method {
        Method::Gather => {
            let mut r = Renderer::new(gpu, scene, settings)?;
            if denoiser {
                r.enable_denoiser()?;
            }
            let info = (r.bundle(), r.gather_directions(), r.gather_method());
            (Box::new(r), Some(info))
        }
        Method::Path => (Box::new(PathTracer::new(gpu, scene, settings)?), None),
    })
}

/// The sun of `--sun` with angular diameter `size` degrees: light travelling along
/// −(sin a cos e, sin e, cos a cos e), of the given irradiance (0 where none is given: `--sky`
/// replaces it).
pub fn sun_light(sun: Sun, size: f32) -> Light {
    let (a, e) = (sun.azimuth.to_radians(), sun.elevation.to_radians());
    let towards = Vec3::new(a.sin() * e.cos(), e.sin(), a.cos() * e.cos());
    Light::Distant {
        direction: -towards.normalize(),
        irradiance: Vec3::splat(sun.irradiance.unwrap_or(0.0)),
        angular_radius: 0.5 * size.to_radians(),
    }
}

/// `--sky TURBIDITY` for the sun `light` (a distant light: its direction and disc): Mitsuba
/// 3's `sunsky` with the zenith on +Y, as the environment (sky::SKY_WIDTH × SKY_HEIGHT) and
/// the sun with the model's irradiance (none below the horizon, where the sky is black too).
pub fn physical_sky(turbidity: f32, light: Light) -> Result<(crate::environment::Environment, Option<Light>)> {
    let Light::Distant { direction, angular_radius, .. } = light else {
        return Err(Error::Invalid("--sky needs a distant light as the sun".into()));
    };
    let sky = crate::scene::sky::SunSky { turbidity, ..crate::scene::sky::SunSky::new(-direction, Vec3::Y) };
    if sky.sun_elevation() < 0.0 {
        log::warn!("--sky: the sun is below the horizon, so the sky and the sun are black");
    }
    let environment = sky.environment(crate::scene::sky::SKY_WIDTH, crate::scene::sky::SKY_HEIGHT)?;
    let sun = sky.sun_light().map(|l| match l {
        Light::Distant { direction, irradiance, .. } => {
            log::info!("--sky {turbidity}: the sun's irradiance is {irradiance} W/m² (RGB)");
            Light::Distant { direction, irradiance, angular_radius }
        }
        other => other,
    });
    Ok((environment, sun))
}

/// The file extension of a scene name, lower case.
pub fn extension_of(name: &str) -> Option<String> {
    std::path::Path::new(name).extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}

/// The built-in scene of that name, or the scene file at that path.
#[cfg(not(target_arch = "wasm32"))]
pub fn load_scene(name: &str) -> Result<Scene> {
    load_scene_with(name, None, &[], &crate::scene::Budgets::default())
}

/// [`load_scene`] with the camera of a glTF file chosen by its index, the parameter values
/// of a Mitsuba file (`-D name=value`) and the budgets of what the files may make the loaders
/// read and hold.
#[cfg(not(target_arch = "wasm32"))]
pub fn load_scene_with(
    name: &str,
    camera: Option<usize>,
    defines: &[(String, String)],
    budgets: &crate::scene::Budgets,
) -> Result<Scene> {
    use crate::scene::generate::BUILTIN_NAMES;
    use crate::scene::{Files, GltfOptions, MitsubaOptions, load_gltf_with, load_mitsuba, load_obj_with};
    let path = std::path::Path::new(name);
    let extension = extension_of(name);
    if camera.is_some() && !matches!(extension.as_deref(), Some("gltf" | "glb")) {
        return Err(Error::Invalid(format!(
            "--camera chooses among a glTF file's cameras; '{name}' is not a .gltf or .glb file"
        )));
    }
    if let Some(scene) = crate::scene::generate::builtin(name)? {
        return Ok(scene);
    }
    match extension.as_deref() {
        Some("obj") => load_obj_with(Files::Disk, path, budgets),
        Some("gltf" | "glb") => load_gltf_with(path, &GltfOptions { camera, budgets: *budgets }),
        Some("xml") => {
            let m = load_mitsuba(path, &MitsubaOptions { defines: defines.to_vec(), budgets: *budgets })?;
            if let (Some((w, h)), Some(n)) = (m.film, m.sample_count) {
                log::info!(
                    "{name}: its film is {w}x{h} pixels with {n} samples per pixel (the default size and iterations)"
                );
            }
            Ok(m.scene)
        }
        _ => Err(Error::Invalid(format!(
            "unknown scene '{name}': use a built-in scene ({BUILTIN_NAMES}) or a path to a .obj, .gltf, .glb or Mitsuba .xml file"
        ))),
    }
}
