//! The command line's options of the scene, the renderer and the GPU, as clap `Args` (feature
//! `clap`): [`SceneArgs`] and [`GpuArgs`], which `rastergi render` and `rastergi view` flatten
//! and the Python package parses its keyword options into, the value enums of their flags, and
//! the flags' parsers (their messages are the command line's). [`SceneArgs::options`] turns
//! them into the library's [`Options`], from which everything else follows.

use clap::{Args, ValueEnum};
use glam::Vec3;

use super::{DEFAULT_SUN_SIZE, Method, Options, Sun};
use crate::error::Result;
use crate::gather::{GatherDirections, GatherMethod, HitLight};
use crate::gpu::accel::{Rays, parse_rays};
use crate::gpu::{Backends, Gpu, GpuOptions, parse_backend};
use crate::passes::film::Show;
use crate::scene::Scene;
use crate::settings::{PhotonRegionChoice, RenderSettings, TextureFilter};

// `--backend` and `--rays`: which GPU and which ray traversal (no doc comment: clap would
// take it for the help of the subcommands that flatten it).
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

    /// Opens the GPU of [`GpuArgs::options`], its passes timed where `profile` is set.
    pub fn open(&self, profile: bool) -> Result<Gpu> {
        Gpu::new(&GpuOptions { profile, ..self.options() })
    }
}

/// What the image shows (`--show`).
#[derive(Copy, Clone, Debug, ValueEnum)]
pub enum ShowArg {
    /// Emission + direct + indirect light.
    Full,
    /// Emission + direct light.
    Direct,
    /// Indirect light only.
    Indirect,
    /// The photon map's radiance ρ/π·E at the visible points (without the direct light of the
    /// lights `--hit-light` samples at the gather's hits: by default the sun's and other
    /// punctual lights').
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
    /// The punctual lights' (points, spots, the sun) direct part from one sample of them with a
    /// shadow ray, the rest (emitters, the sky, light that bounced) from the photon map.
    Punctual,
}

/// A strategy on or off.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Switch {
    On,
    Off,
}

impl Switch {
    pub fn on(self) -> bool {
        self == Switch::On
    }
}

/// `--light-samples`: a count, or balanced by measurement.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum LightSamplesArg {
    Balanced,
    Fixed(u32),
}

impl LightSamplesArg {
    /// The count of the first iterations.
    pub fn first(self) -> u32 {
        match self {
            LightSamplesArg::Balanced => 1,
            LightSamplesArg::Fixed(n) => n,
        }
    }
}

pub fn parse_light_samples(s: &str) -> std::result::Result<LightSamplesArg, String> {
    if s == "balanced" {
        return Ok(LightSamplesArg::Balanced);
    }
    match s.parse::<u32>() {
        Ok(n @ 1..=64) => Ok(LightSamplesArg::Fixed(n)),
        _ => Err(format!("`{s}` is neither `balanced` nor a count from 1 to 64")),
    }
}

/// How long each photon pass lasts where `--pass-iterations` is not given.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum PhotonBudgetArg {
    /// Measured as the render goes on: the iterations per pass of least error per second, from
    /// the variance the map adds against the iterations' own and what each costs on this GPU
    /// (depends on timings: give `fitted` for images that repeat bit for bit)
    Balanced,
    /// 4 × photons / pixels iterations per pass, at least 16 (the photons capped so that a pass
    /// lasts at most about 64 iterations): the same for every run of a seed
    Fitted,
}

impl PhotonBudgetArg {
    pub fn budget(self) -> crate::settings::PhotonBudget {
        match self {
            PhotonBudgetArg::Balanced => crate::settings::PhotonBudget::Balanced,
            PhotonBudgetArg::Fitted => crate::settings::PhotonBudget::Fitted,
        }
    }
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

/// How the eye pass finds the visible points.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum EyeArg {
    /// The image rasterized; the viewer's previews timed both ways, the faster kept.
    Auto,
    /// Every triangle drawn.
    Raster,
    /// A camera ray per pixel.
    Trace,
}

impl EyeArg {
    pub fn method(self) -> crate::settings::EyeMethod {
        match self {
            EyeArg::Auto => crate::settings::EyeMethod::Auto,
            EyeArg::Raster => crate::settings::EyeMethod::Raster,
            EyeArg::Trace => crate::settings::EyeMethod::Trace,
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
            HitLightArg::Punctual => HitLight::Punctual,
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
    #[arg(long, default_value_t = DEFAULT_SUN_SIZE, requires = "sun", value_parser = parse_sun_size)]
    pub sun_size: f32,
    /// Adds a point light: X,Y,Z,R,G,B — position and intensity in W/sr (repeatable; the
    /// same values as `scripts/mitsuba_reference.py --point`).
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true, value_name = "X,Y,Z,R,G,B")]
    pub point: Vec<crate::scene::Light>,
    /// Adds a spot light: X,Y,Z,TX,TY,TZ,R,G,B,ANGLE[,INNER] — position, a point it aims at,
    /// intensity in W/sr on its axis and its cone's half-angle in degrees; a hard edge, or
    /// glTF's smooth falloff from INNER degrees out (repeatable; without INNER the same values
    /// as `scripts/mitsuba_reference.py --spot`).
    #[arg(long, value_parser = parse_spot, allow_hyphen_values = true, value_name = "X,Y,Z,TX,TY,TZ,R,G,B,ANGLE")]
    pub spot: Vec<crate::scene::Light>,
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
    /// Light samples per pixel per iteration: `balanced` chooses them as the render goes on, from
    /// the direct light's variance against the rest's and what each costs on this GPU (depends
    /// on timings: give a number, 1 to 64, for images that repeat bit for bit)
    #[arg(long, default_value = "balanced", value_parser = parse_light_samples)]
    pub light_samples: LightSamplesArg,
    /// Sub-pixel rays per axis (n: n × n rays) for the emission seen at the pixels on the edge
    /// of an emitter or of the sky, per iteration; 0: one jittered sample, as elsewhere (the
    /// same image in the mean)
    #[arg(long, default_value_t = crate::passes::emitter_edges::DEFAULT_EMITTER_EDGES, value_parser = clap::value_parser!(u32).range(0..=16))]
    pub emitter_edges: u32,
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
    /// Iterations per photon pass (default 0: as --photon-budget chooses)
    #[arg(long, default_value_t = crate::photons::passes::DEFAULT_PASS_ITERATIONS)]
    pub pass_iterations: u32,
    /// How many iterations each photon pass lasts where --pass-iterations is not given:
    /// `balanced` measures the map's noise against the iterations' and the cost of each on
    /// this GPU and takes the pass length of least error per second; `fitted` takes 4 ×
    /// photons / pixels iterations (at least 16)
    #[arg(long, value_enum, default_value_t = PhotonBudgetArg::Balanced)]
    pub photon_budget: PhotonBudgetArg,
    /// Whether the sun's and the sky's photons are guided to where the photon map is read
    /// (`on`: each pass learns where the photons that landed there started, through a window
    /// or onto the ground the gather sees through it), or only aimed at the region the camera
    /// reads (`off`: as fast to an error on the rooms measured, and without the guided
    /// photons' skew when a pass has few)
    #[arg(long, value_enum, default_value_t = Switch::Off)]
    pub photon_guiding: Switch,
    /// Whether the traced gather's directions are guided by the light its rays found (`on`:
    /// half of them drawn towards where a visible point's cell found it, the rest as the
    /// surface scatters), or drawn as the surface scatters alone (`off`: measured better on
    /// every scene tried, whose Sobol'-stratified directions guiding halves)
    #[arg(long, value_enum, default_value_t = Switch::Off)]
    pub gather_guiding: Switch,
    /// The direct light's environment samples: drawn from a mixture of the sky's brightness
    /// and, where a visible point's cell has learned which parts of the sky are open from
    /// there (through the windows), those parts (`on`), or by its brightness alone (`off`:
    /// measured no worse on every room tried)
    #[arg(long, value_enum, default_value_t = Switch::Off)]
    pub sky_guiding: Switch,
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
    #[arg(long, default_value_t = crate::settings::DEFAULT_DIRECTIONS, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub directions: u32,
    /// Where the light at a gather ray's hit comes from: the punctual lights' (points, spots, the
    /// sun) direct light by a shadow ray and the rest from the photon map (`punctual`: sharp sun
    /// patches through windows exact, no extra ray in a scene without punctual lights), all from
    /// the map (`map`), or every light's direct light by a shadow ray plus a map of indirect
    /// light only (`exact`).
    #[arg(long, value_enum, default_value_t = HitLightArg::Punctual)]
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
    /// How the eye pass finds each pixel's visible point: `raster` draws every triangle,
    /// `trace` casts a camera ray per pixel into the BVH (cheaper where the pixels are few and
    /// the triangles many), `auto` rasterizes the image and times both ways for each of the
    /// viewer's coarse previews.
    #[arg(long, value_enum, default_value_t = EyeArg::Auto)]
    pub eye_pass: EyeArg,
    /// What the image shows.
    #[arg(long, value_enum, default_value_t = ShowArg::Full)]
    pub show: ShowArg,
    /// Exposure in stops for PNG output and the window (the image is scaled by 2^exposure).
    /// Default: 0, except for a PNG whose median luminance is more than two stops from
    /// middle grey (0.18): then the whole stops that bring it there.
    #[arg(long, allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// Raises (or lowers) a budget of what a scene file may make rastergi read and hold:
    /// NAME=N with NAME one of triangles, vertices, texels, decompressed, xml-bytes, xml-depth,
    /// expansion (repeatable; the defaults and what each counts: docs/user-guide.md, "Budgets").
    #[arg(long, value_name = "NAME=N", value_parser = crate::scene::parse_budget)]
    pub budget: Vec<(crate::scene::Budget, u64)>,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

impl SceneArgs {
    /// The library's options of these flags (the method and denoiser as given: they are
    /// `render`'s flags).
    pub fn options(&self, method: Method, denoiser: bool) -> Options {
        Options {
            scene: self.scene.clone(),
            width: self.width,
            height: self.height,
            eye: self.eye,
            target: self.target,
            up: self.up,
            fov: self.fov,
            camera: self.camera,
            defines: self.define.clone(),
            seed: self.seed,
            sun: self.sun,
            sky: self.sky,
            sun_size: self.sun_size,
            lights: self.point.iter().chain(&self.spot).cloned().collect(),
            env: self.env.clone(),
            env_scale: self.env_scale,
            single_scattering: self.single_scattering,
            light_samples: self.light_samples.first(),
            light_balance: self.light_samples == LightSamplesArg::Balanced,
            emitter_edges: self.emitter_edges,
            photons: self.photons,
            grid: self.grid,
            photon_passes: self.photon_passes,
            pass_iterations: self.pass_iterations,
            photon_budget: self.photon_budget.budget(),
            photon_guiding: self.photon_guiding.on(),
            gather_guiding: self.gather_guiding.on(),
            sky_guiding: self.sky_guiding.on(),
            bundle: self.bundle,
            gather: self.gather.method(),
            gather_directions: self.gather_directions.directions(),
            directions: self.directions,
            hit_light: self.hit_light.hit_light(),
            photon_region: self.photon_region.choice(),
            texture_filter: self.texture_filter.filter(),
            eye_pass: self.eye_pass.method(),
            show: self.show.show(),
            method,
            denoiser,
            gpu: self.gpu.options(),
            budgets: self.budgets(),
        }
    }

    /// The default budgets with those `--budget` sets.
    pub fn budgets(&self) -> crate::scene::Budgets {
        let mut b = crate::scene::Budgets::default();
        self.budget.iter().for_each(|&(name, n)| b.set(name, n));
        b
    }

    /// The scene with the camera and light options applied ([`Options::load_scene`]).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn load_scene(&self) -> Result<Scene> {
        self.options(Method::Gather, false).load_scene()
    }

    /// The image size ([`Options::image_size`]).
    pub fn image_size(&self, scene: &Scene) -> (u32, u32) {
        self.options(Method::Gather, false).image_size(scene)
    }

    /// The renderer's settings for `scene` at the given image size ([`Options::settings`]).
    pub fn settings(&self, scene: &Scene, width: u32, height: u32, show_photon_map: bool) -> RenderSettings {
        self.options(Method::Gather, false).settings(scene, width, height, show_photon_map)
    }
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

fn parse_point(s: &str) -> Result<crate::scene::Light, String> {
    let v = parse_floats(s, &[6], "X,Y,Z,R,G,B (position, intensity W/sr)")?;
    let light =
        crate::scene::Light::Point { position: Vec3::new(v[0], v[1], v[2]), intensity: Vec3::new(v[3], v[4], v[5]) };
    light.validate()?;
    Ok(light)
}

fn parse_spot(s: &str) -> Result<crate::scene::Light, String> {
    let v = parse_floats(s, &[10, 11], "X,Y,Z,TX,TY,TZ,R,G,B,ANGLE[,INNER] (degrees)")?;
    let (position, aim) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
    if (aim - position).length() == 0.0 {
        return Err("the spot's aim point is its position; give a point it shines towards".into());
    }
    let outer = v[9].to_radians();
    let light = crate::scene::Light::Spot {
        position,
        direction: (aim - position).normalize(),
        intensity: Vec3::new(v[6], v[7], v[8]),
        inner: v.get(10).map_or(outer, |i| i.to_radians()),
        outer,
    };
    light.validate()?;
    Ok(light)
}
