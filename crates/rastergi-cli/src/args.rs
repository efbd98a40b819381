//! The arguments and helpers the subcommands share: the GPU (`--backend`) and its openers,
//! the scene and renderer options of `render` and `view` ([`SceneArgs`]), what is shown
//! ([`ShowArg`]), the gather implementation ([`GatherArg`]) and its directions
//! ([`GatherDirectionsArg`]), scene loading and the per-pass
//! GPU time report of `--profile`.

use std::path::Path;

use anyhow::Result;
use clap::{Args, ValueEnum};
use glam::Vec3;
use rastergi::accel::{Rays, parse_rays};
use rastergi::film::Show;
use rastergi::fit;
use rastergi::gather::{GatherDirections, GatherMethod, HitLight};
use rastergi::gpu::{Backends, Gpu, GpuOptions, parse_backend};
use rastergi::renderer::{PhotonRegionChoice, RenderSettings, TextureFilter};
use rastergi::scene::generate::BUILTIN_NAMES;
use rastergi::scene::{GltfOptions, MitsubaOptions, Scene, load_gltf_with, load_mitsuba, load_obj};

#[derive(Args, Clone, Debug)]
pub struct GpuArgs {
    /// Graphics backend: vulkan, metal, dx12, gl (default: WGPU_BACKEND, else the platform's primary).
    #[arg(long, value_parser = parse_backend)]
    backend: Option<Backends>,
    /// Ray traversal: auto (hardware ray queries where the adapter offers them, unless a
    /// start-up probe on the scene measures them slower), hardware, or compute (the
    /// compute-shader BVH) [default: RASTERGI_RAYS, else auto].
    #[arg(long, value_parser = parse_rays)]
    rays: Option<Rays>,
}

impl GpuArgs {
    /// The options of a GPU on the backends and ray path asked for (`None`: the default
    /// choice), unprofiled.
    pub fn options(&self) -> GpuOptions {
        let rays = self.rays.or_else(Rays::from_env).unwrap_or(Rays::Auto);
        GpuOptions { backends: self.backend, rays: Some(rays), ..Default::default() }
    }
}

#[derive(Copy, Clone, Debug, ValueEnum)]
pub enum ShowArg {
    /// Emission + direct + indirect light.
    Full,
    /// Emission + direct light.
    Direct,
    /// Indirect light only.
    Indirect,
    /// The photon map's radiance ρ/π·E at the visible points.
    PhotonMap,
}

impl ShowArg {
    pub fn show(self) -> Show {
        match self {
            ShowArg::Full => Show::Full,
            ShowArg::Direct => Show::Direct,
            ShowArg::Indirect => Show::Indirect,
            ShowArg::PhotonMap => Show::PhotonMap,
        }
    }
}

/// How the final gather finds the nearest surface along its direction.
#[derive(Copy, Clone, Debug, ValueEnum)]
pub enum GatherArg {
    /// Try each on the first iterations and keep the one whose error falls fastest on this
    /// GPU: least variance × time per iteration (trace unless another is over 1.25× better).
    Auto,
    /// Depth-peeled orthographic ray views (rasterization).
    Raster,
    /// Per-texel fragment lists of the ray view, one raster pass per direction.
    Lists,
    /// BVH ray casting in a compute shader.
    Trace,
}

/// Where the light at a gather ray's hit comes from.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum HitLightArg {
    /// All from the photon map.
    Map,
    /// The direct part from one light sample with a shadow ray, the rest from a photon map
    /// of indirect light only.
    Exact,
}

/// Where the photon grid's cells are finer.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum PhotonRegionArg {
    /// Where the camera and its gather rays look (a room, not the ground plane around it).
    Camera,
    /// Nowhere: one level of cells over the whole scene.
    Scene,
}

/// How the eye's visible points read textures.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum TextureFilterArg {
    /// Filtered over the pixel's footprint (trilinear mip maps): no texture noise.
    Footprint,
    /// Level 0, bilinearly, at each sample's point, as Mitsuba and pbrt read a `bilinear`
    /// bitmap: for comparisons with them.
    Bilinear,
}

impl TextureFilterArg {
    pub fn filter(self) -> TextureFilter {
        match self {
            TextureFilterArg::Footprint => TextureFilter::Footprint,
            TextureFilterArg::Bilinear => TextureFilter::Bilinear,
        }
    }
}

impl PhotonRegionArg {
    pub fn choice(self) -> PhotonRegionChoice {
        match self {
            PhotonRegionArg::Camera => PhotonRegionChoice::Camera,
            PhotonRegionArg::Scene => PhotonRegionChoice::Scene,
        }
    }
}

impl HitLightArg {
    pub fn hit_light(self) -> HitLight {
        match self {
            HitLightArg::Map => HitLight::Map,
            HitLightArg::Exact => HitLight::Exact,
        }
    }
}

impl GatherArg {
    pub fn method(self) -> GatherMethod {
        match self {
            GatherArg::Auto => GatherMethod::Auto,
            GatherArg::Raster => GatherMethod::Raster,
            GatherArg::Lists => GatherMethod::Lists,
            GatherArg::Trace => GatherMethod::Trace,
        }
    }
}

/// Whose directions the traced gather casts.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum GatherDirectionsArg {
    /// Each pixel its own directions (Owen-scrambled Sobol'), drawn as the visible point
    /// scatters (cosine-distributed on a Lambertian surface, by the BSDF on a glossy one):
    /// noise instead of streaks.
    PerPixel,
    /// Each direction shared by every pixel (uniform on the sphere, scrambled Sobol'; each
    /// point gathers along whichever of ±ω lies above it).
    Shared,
}

impl GatherDirectionsArg {
    pub fn directions(self) -> GatherDirections {
        match self {
            GatherDirectionsArg::PerPixel => GatherDirections::PerPixel,
            GatherDirectionsArg::Shared => GatherDirections::Shared,
        }
    }

    /// The renderer's default.
    pub fn default_value() -> GatherDirectionsArg {
        match GatherDirections::default() {
            GatherDirections::PerPixel => GatherDirectionsArg::PerPixel,
            GatherDirections::Shared => GatherDirectionsArg::Shared,
        }
    }

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            GatherDirectionsArg::PerPixel => "per-pixel",
            GatherDirectionsArg::Shared => "shared",
        }
    }
}

/// The options `render` and `view` share: the scene and its camera, the renderer's settings,
/// what is shown and the GPU.
#[derive(Args, Clone, Debug)]
pub struct SceneArgs {
    /// The scene: built in (`cornell`, `atrium`, `spheres:N` for about N triangles, `rooms`, `rooms:closed`, `glossy-room`, `sunroom`), a Wavefront .obj file, a glTF 2.0 .gltf/.glb file or a Mitsuba .xml scene file.
    pub scene: String,
    /// Image width in pixels (`view`: the window's initial width) [default: the scene file's
    /// film (Mitsuba), else 256].
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (`view`: the window's initial height) [default: the scene
    /// file's film (Mitsuba), else 256].
    #[arg(long)]
    pub height: Option<u32>,
    /// Camera position, overriding the scene's (x,y,z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Point the camera looks at (x,y,z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Camera up vector (x,y,z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees.
    #[arg(long)]
    pub fov: Option<f32>,
    /// glTF scenes: the camera to use, by its index in the file's cameras (default: the first).
    #[arg(long)]
    pub camera: Option<usize>,
    /// Mitsuba scene files: sets the parameter NAME (what `$NAME` stands for, over the file's
    /// `<default name="NAME">`) to VALUE (repeatable).
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define)]
    pub define: Vec<(String, String)>,
    /// Seed of every random decision; the same seed gives the same image.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Adds the sun: AZIMUTH,ELEVATION,IRRADIANCE — degrees from +Z towards +X about the +Y
    /// axis, degrees above the XZ plane, W/m² on a surface facing it (e.g. 30,45,1000). With
    /// --sky, AZIMUTH,ELEVATION alone: the sky model gives the irradiance.
    #[arg(long, value_parser = parse_sun, allow_hyphen_values = true, value_name = "AZIMUTH,ELEVATION[,IRRADIANCE]")]
    pub sun: Option<Sun>,
    /// Adds a physical sky of this turbidity (1–10: 2 clear and blue, 8 hazy): Mitsuba 3's
    /// `sunsky` (Hosek–Wilkie sky and sun, ground albedo 0.3, in its units) for the sun of
    /// --sun AZIMUTH,ELEVATION, or for the scene's own sun, which it replaces (same direction
    /// and disc, the model's irradiance and colour). The sky is the scene's environment.
    #[arg(long, value_parser = parse_turbidity, value_name = "TURBIDITY")]
    pub sky: Option<f32>,
    /// The sun's angular diameter in degrees (its soft shadows; 0 for a sharp one).
    #[arg(long, default_value_t = 0.53, requires = "sun", value_parser = parse_sun_size)]
    pub sun_size: f32,
    /// Adds a point light: X,Y,Z,R,G,B — position and intensity in W/sr (repeatable; the
    /// same values as `scripts/mitsuba_reference.py --point`).
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true, value_name = "X,Y,Z,R,G,B")]
    pub point: Vec<rastergi::scene::Light>,
    /// Adds a spot light: X,Y,Z,TX,TY,TZ,R,G,B,ANGLE[,INNER] — position, a point it aims at,
    /// intensity in W/sr on its axis and its cone's half-angle in degrees; a hard edge, or
    /// glTF's smooth falloff from INNER degrees out (repeatable; without INNER the same values
    /// as `scripts/mitsuba_reference.py --spot`).
    #[arg(long, value_parser = parse_spot, allow_hyphen_values = true, value_name = "X,Y,Z,TX,TY,TZ,R,G,B,ANGLE")]
    pub spot: Vec<rastergi::scene::Light>,
    /// Lights the scene with an environment map: an equirectangular .exr or .hdr image of
    /// the radiance from every direction (Mitsuba 3's `envmap` convention: row 0 is +Y, the
    /// image's left edge looks along −Z, its first quarter turns towards +X). A scene without
    /// lights (and a glTF model whose only light is emission) is lit by a neutral grey
    /// environment unless this is given; `none` turns that off.
    #[arg(long, value_name = "FILE")]
    pub env: Option<std::path::PathBuf>,
    /// Scales the environment map's radiance.
    #[arg(long, default_value_t = 1.0, requires = "env", value_parser = parse_env_scale)]
    pub env_scale: f32,
    /// Rough metals without their multiple-scattering energy compensation (Kulla & Conty):
    /// single-scattering GGX, which loses up to 69 % of the light at roughness 1 — the model of
    /// Mitsuba 3's `roughconductor`, for comparisons with it.
    #[arg(long)]
    pub single_scattering: bool,
    /// Light samples per pixel per iteration.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub light_samples: u32,
    /// Photons traced into the photon map (default: fitted to the scene: about 40 per
    /// cell-sized patch of surface, a power of two from 2^18 to 2^24; 2^20 for cornell).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub photons: Option<u32>,
    /// Photon grid cells along the scene's longest axis (default: fitted to the scene: as many
    /// cubic cells as 64³, so 64 for a cube like cornell and more for long or flat scenes).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub grid: Option<u32>,
    /// Photon passes: the photon map is re-traced with fresh photons in finer cells every
    /// --pass-iterations iterations, so its error keeps falling as the render goes on
    /// (cell area ∝ pass^-1/3). 1: one fixed map traced before the first iteration; 0: no limit.
    #[arg(long, default_value_t = 0)]
    pub photon_passes: u32,
    /// Iterations per photon pass (default 0: fitted, 4 × photons / pixels and at least 16, so
    /// tracing takes about a fifth of the time: 64 for cornell at 256², 16 at 512² and above).
    #[arg(long, default_value_t = rastergi::photons::passes::DEFAULT_PASS_ITERATIONS)]
    pub pass_iterations: u32,
    /// Ray-view resolution of the final gather, texels per side (default: fitted: twice the
    /// image's larger side, raised to 8 texels across the median triangle's shortest edge over
    /// the scene's bounding sphere; 128 to 2048).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub bundle: Option<u32>,
    /// How the final gather finds the nearest surface along each direction (three
    /// implementations of the same estimator).
    #[arg(long, value_enum, default_value_t = GatherArg::Auto)]
    pub gather: GatherArg,
    /// Whose directions the traced gather casts (`--gather trace`, and the traced gather that
    /// auto tries; raster and lists always share each direction among all pixels).
    #[arg(long, value_enum, default_value_t = GatherDirectionsArg::default_value())]
    pub gather_directions: GatherDirectionsArg,
    /// Gather directions per iteration (1–16): they share the iteration's G-buffer and direct
    /// light, so the noisier indirect light gets more samples per second.
    #[arg(long, default_value_t = rastergi::renderer::DEFAULT_DIRECTIONS, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub directions: u32,
    /// Where the light at a gather ray's hit comes from: the photon map (`map`), or direct
    /// light by a shadow ray plus a map of indirect light only (`exact`).
    #[arg(long, value_enum, default_value_t = HitLightArg::Map)]
    pub hit_light: HitLightArg,
    /// Where the photon grid's cells are finer: around what the camera and its gather rays
    /// reach (`camera`; a room beside a large ground plane gets cells sized to the room), or
    /// nowhere (`scene`: one size of cell over the whole scene).
    #[arg(long, value_enum, default_value_t = PhotonRegionArg::Camera)]
    pub photon_region: PhotonRegionArg,
    /// How the eye's visible points read textures: filtered over the pixel's footprint
    /// (`footprint`), or level 0 bilinearly at each sample (`bilinear`, as Mitsuba and pbrt
    /// do: for comparisons with them).
    #[arg(long, value_enum, default_value_t = TextureFilterArg::Footprint)]
    pub texture_filter: TextureFilterArg,
    /// What the image shows.
    #[arg(long, value_enum, default_value_t = ShowArg::Full)]
    pub show: ShowArg,
    /// Exposure in stops for PNG output and the window (the image is scaled by 2^exposure).
    /// Default: 0, except for a PNG whose median luminance is more than two stops from
    /// middle grey (0.18): then the whole stops that bring it there.
    #[arg(long, allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

impl SceneArgs {
    /// The scene with the camera options applied, its camera validated.
    pub fn load_scene(&self) -> Result<Scene> {
        let mut scene = load_scene_with(&self.scene, self.camera, &self.define)?;
        let c = &mut scene.camera;
        c.eye = self.eye.unwrap_or(c.eye);
        c.target = self.target.unwrap_or(c.target);
        c.up = self.up.unwrap_or(c.up);
        c.fov_y_deg = self.fov.unwrap_or(c.fov_y_deg);
        scene.camera.validate()?;
        scene.lights.extend(self.point.iter().chain(&self.spot).cloned());
        match (self.sun, self.sky) {
            (Some(Sun { irradiance: Some(_), .. }), Some(_)) => anyhow::bail!(
                "with --sky the sky model gives the sun's irradiance: give --sun AZIMUTH,ELEVATION without IRRADIANCE"
            ),
            (Some(Sun { irradiance: None, .. }), None) => {
                anyhow::bail!(
                    "--sun AZIMUTH,ELEVATION needs --sky (or add IRRADIANCE: --sun AZIMUTH,ELEVATION,IRRADIANCE)"
                )
            }
            (Some(sun), None) => scene.lights.push(sun_light(sun, self.sun_size)),
            (sun, Some(turbidity)) => {
                if self.env.is_some() {
                    anyhow::bail!("--sky and --env each give the scene's environment; give one of them");
                }
                let light = match sun {
                    Some(sun) => sun_light(sun, self.sun_size),
                    None => {
                        let i = scene.lights.iter().rposition(|l| matches!(l, rastergi::scene::Light::Distant { .. }));
                        let Some(i) = i else {
                            anyhow::bail!(
                                "--sky needs the sun's position: give --sun AZIMUTH,ELEVATION (the scene {} has no sun)",
                                self.scene
                            );
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
            let env = rastergi::environment::Environment::load(path, self.env_scale)?;
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

    /// The image size: `--width` and `--height` as given, else the scene file's film (where one
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
    /// as given, else fitted to the scene ([`rastergi::fit`]).
    pub fn settings(&self, scene: &Scene, width: u32, height: u32, show_photon_map: bool) -> RenderSettings {
        let grid = self.grid.unwrap_or_else(|| fit::grid_resolution(&scene.bounds()));
        let photons = self.photons.unwrap_or_else(|| fit::photon_count(scene, grid));
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
            photons,
            grid_resolution: grid,
            show_photon_map,
            bundle: self.bundle.unwrap_or(0),
            gather: self.gather.method(),
            gather_directions: self.gather_directions.directions(),
            auto_trials_on_cpu: false,
            directions: self.directions,
            photon_passes: self.photon_passes,
            pass_iterations: self.pass_iterations,
            hit_light: self.hit_light.hit_light(),
            photon_region: self.photon_region.choice(),
            texture_filter: self.texture_filter.filter(),
        }
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

/// The sun of `--sun` with angular diameter `size` degrees: light travelling along
/// −(sin a cos e, sin e, cos a cos e), of the given irradiance (0 where none is given: `--sky`
/// replaces it).
pub fn sun_light(sun: Sun, size: f32) -> rastergi::scene::Light {
    let (a, e) = (sun.azimuth.to_radians(), sun.elevation.to_radians());
    let towards = Vec3::new(a.sin() * e.cos(), e.sin(), a.cos() * e.cos());
    rastergi::scene::Light::Distant {
        direction: -towards.normalize(),
        irradiance: Vec3::splat(sun.irradiance.unwrap_or(0.0)),
        angular_radius: 0.5 * size.to_radians(),
    }
}

/// `--sky TURBIDITY` for the sun `light` (a distant light: its direction and disc): Mitsuba
/// 3's `sunsky` with the zenith on +Y, as the environment (sky::SKY_WIDTH × SKY_HEIGHT) and
/// the sun with the model's irradiance (none below the horizon, where the sky is black too).
pub fn physical_sky(
    turbidity: f32,
    light: rastergi::scene::Light,
) -> Result<(rastergi::environment::Environment, Option<rastergi::scene::Light>)> {
    let rastergi::scene::Light::Distant { direction, angular_radius, .. } = light else {
        anyhow::bail!("--sky needs a distant light as the sun");
    };
    let sky = rastergi::sky::SunSky { turbidity, ..rastergi::sky::SunSky::new(-direction, Vec3::Y) };
    if sky.sun_elevation() < 0.0 {
        log::warn!("--sky: the sun is below the horizon, so the sky and the sun are black");
    }
    let environment = sky.environment(rastergi::sky::SKY_WIDTH, rastergi::sky::SKY_HEIGHT)?;
    let sun = sky.sun_light().map(|l| match l {
        rastergi::scene::Light::Distant { direction, irradiance, .. } => {
            log::info!("--sky {turbidity}: the sun's irradiance is {irradiance} W/m² (RGB)");
            rastergi::scene::Light::Distant { direction, irradiance, angular_radius }
        }
        other => other,
    });
    Ok((environment, sun))
}

fn parse_sun(s: &str) -> Result<Sun, String> {
    let v = parse_floats(s, &[2, 3], "AZIMUTH,ELEVATION[,IRRADIANCE] like 30,45,1000")
        .map_err(|e| format!("{e} (azimuth°,elevation°,irradiance W/m²)"))?;
    if !(-90.0..=90.0).contains(&v[1]) {
        return Err(format!("the sun's elevation {}° is not within -90..90", v[1]));
    }
    if v.get(2).is_some_and(|&i| i < 0.0) {
        return Err(format!("the sun's irradiance {} W/m² is negative", v[2]));
    }
    Ok(Sun { azimuth: v[0], elevation: v[1], irradiance: v.get(2).copied() })
}

fn parse_turbidity(s: &str) -> Result<f32, String> {
    let t: f32 = s.parse().map_err(|_| format!("'{s}' is not a number"))?;
    if !(1.0..=10.0).contains(&t) {
        return Err(format!("the sky's turbidity {t} is not within the model's range 1..10"));
    }
    Ok(t)
}

fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((name, value)) if !name.trim().is_empty() => Ok((name.trim().to_owned(), value.to_owned())),
        _ => Err(format!("'{s}' is not NAME=VALUE")),
    }
}

fn parse_env_scale(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("'{s}' is not a number"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(format!("the environment's scale {v} must be a finite number ≥ 0"));
    }
    Ok(v)
}

fn parse_sun_size(s: &str) -> Result<f32, String> {
    let d: f32 = s.parse().map_err(|_| format!("'{s}' is not a number of degrees"))?;
    if !(0.0..=57.0).contains(&d) {
        return Err(format!("the sun's angular diameter {d}° is not within 0..57"));
    }
    Ok(d)
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    parse_floats(s, &[3], "three comma-separated numbers like 0,1,3.5").map(|v| Vec3::new(v[0], v[1], v[2]))
}

/// Comma-separated finite numbers, as many as one of `counts`; `shape` says what is expected.
fn parse_floats(s: &str, counts: &[usize], shape: &str) -> Result<Vec<f32>, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if !counts.contains(&parts.len()) {
        return Err(format!("expected {shape}, got '{s}'"));
    }
    parts
        .iter()
        .map(|p| match p.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(format!("'{p}' is not a finite number")),
            Err(_) => Err(format!("'{p}' is not a number")),
        })
        .collect()
}

fn parse_point(s: &str) -> Result<rastergi::scene::Light, String> {
    let v = parse_floats(s, &[6], "X,Y,Z,R,G,B (position, intensity W/sr)")?;
    let light =
        rastergi::scene::Light::Point { position: Vec3::new(v[0], v[1], v[2]), intensity: Vec3::new(v[3], v[4], v[5]) };
    light.validate()?;
    Ok(light)
}

fn parse_spot(s: &str) -> Result<rastergi::scene::Light, String> {
    let v = parse_floats(s, &[10, 11], "X,Y,Z,TX,TY,TZ,R,G,B,ANGLE[,INNER] (degrees)")?;
    let (position, aim) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
    if (aim - position).length() == 0.0 {
        return Err("the spot's aim point is its position; give a point it shines towards".into());
    }
    let outer = v[9].to_radians();
    let light = rastergi::scene::Light::Spot {
        position,
        direction: (aim - position).normalize(),
        intensity: Vec3::new(v[6], v[7], v[8]),
        inner: v.get(10).map_or(outer, |i| i.to_radians()),
        outer,
    };
    light.validate()?;
    Ok(light)
}

pub fn gpu(args: &GpuArgs) -> Result<Gpu> {
    gpu_profiled(args, false)
}

/// A GPU whose passes are timed when `profile` is set (see [`print_profile`]).
pub fn gpu_profiled(args: &GpuArgs, profile: bool) -> Result<Gpu> {
    Ok(Gpu::new(&GpuOptions { profile, ..args.options() })?)
}

/// Prints the GPU time per pass since the last call under `title` (per `per` `per_name`s),
/// then starts new sums. Nothing without `--profile`; a note where the adapter has no
/// timestamp queries.
pub fn print_profile(gpu: &Gpu, profile: bool, title: &str, per: u64, per_name: &str) -> Result<()> {
    if !profile {
        return Ok(());
    }
    let Some(p) = &gpu.profiler else {
        println!("{title}: {} has no timestamp queries; no per-pass GPU times", gpu.info.name);
        return Ok(());
    };
    let (times, dropped) = p.report(&gpu.device, &gpu.queue)?;
    p.clear(&gpu.device, &gpu.queue)?;
    println!("{title} (GPU timestamps, {}):", gpu.info.name);
    println!("{}", rastergi::profile::table(&times, per, per_name));
    if dropped > 0 {
        println!("({dropped} passes not timed: the query set was full)");
    }
    Ok(())
}

/// The built-in scene of that name, or the scene file at that path.
pub fn load_scene(name: &str) -> Result<Scene> {
    load_scene_with_camera(name, None)
}

/// [`load_scene`] with the camera of a glTF file chosen by its index.
pub fn load_scene_with_camera(name: &str, camera: Option<usize>) -> Result<Scene> {
    load_scene_with(name, camera, &[])
}

/// The file extension of a scene name, lower case.
fn extension_of(name: &str) -> Option<String> {
    Path::new(name).extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}

/// [`load_scene_with_camera`] with the parameter values of a Mitsuba file (`-D name=value`).
pub fn load_scene_with(name: &str, camera: Option<usize>, defines: &[(String, String)]) -> Result<Scene> {
    let path = Path::new(name);
    let extension = extension_of(name);
    if camera.is_some() && !matches!(extension.as_deref(), Some("gltf" | "glb")) {
        anyhow::bail!("--camera chooses among a glTF file's cameras; '{name}' is not a .gltf or .glb file");
    }
    if let Some(scene) = rastergi::scene::generate::builtin(name)? {
        return Ok(scene);
    }
    match extension.as_deref() {
        Some("obj") => Ok(load_obj(path)?),
        Some("gltf" | "glb") => Ok(load_gltf_with(path, &GltfOptions { camera })?),
        Some("xml") => {
            let m = load_mitsuba(path, &MitsubaOptions { defines: defines.to_vec() })?;
            if let (Some((w, h)), Some(n)) = (m.film, m.sample_count) {
                log::info!(
                    "{name}: its film is {w}x{h} pixels with {n} samples per pixel (the default size and iterations)"
                );
            }
            Ok(m.scene)
        }
        _ => anyhow::bail!(
            "unknown scene '{name}': use a built-in scene ({BUILTIN_NAMES}) or a path to a .obj, .gltf, .glb or Mitsuba .xml file"
        ),
    }
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Parser)]
    struct Command {
        #[command(flatten)]
        scene: SceneArgs,
    }

    /// `sunroom --sky 3`: the scene's sun (35° up, azimuth 200°, a delta direction) becomes
    /// the model's, of the irradiance Mitsuba 3.9.1's sunsky gives at 35° and turbidity 3 (its
    /// radiance at the disc's centre, (20755.25, 16636.76, 11582.435), × the disc's solid
    /// angle), same direction and disc; the sky is the environment, bright above the horizon
    /// and black below it.
    #[test]
    fn sky_replaces_the_scenes_sun_with_the_models() {
        let before = load_scene("sunroom").unwrap();
        let scene = Command::parse_from(["x", "sunroom", "--sky", "3"]).scene.load_scene().unwrap();
        let sun = |s: &Scene| {
            let distant: Vec<_> =
                s.lights.iter().filter(|l| matches!(l, rastergi::scene::Light::Distant { .. })).collect();
            assert_eq!(distant.len(), 1, "{:?}", s.lights);
            *distant[0]
        };
        let (
            rastergi::scene::Light::Distant { direction: d0, angular_radius: r0, .. },
            rastergi::scene::Light::Distant { direction, irradiance, angular_radius },
        ) = (sun(&before), sun(&scene))
        else {
            unreachable!()
        };
        assert_eq!((direction, angular_radius), (d0, r0));
        let omega = (std::f64::consts::TAU * (1.0 - (0.5 * 0.5358f64).to_radians().cos())) as f32;
        let mitsuba = Vec3::new(20755.25, 16636.76, 11582.435) * omega;
        assert!(((irradiance - mitsuba) / mitsuba).abs().max_element() < 2e-3, "{irradiance} vs {mitsuba}");
        let env = scene.environment.as_ref().expect("the sky");
        assert!(env.eval(Vec3::Y).min_element() > 0.0 && env.eval(-Vec3::Y) == Vec3::ZERO);
    }
}
