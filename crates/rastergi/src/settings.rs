//! The settings of a render ([`RenderSettings`]), shared by the photon-map renderer and the
//! path tracer, and what a front end fills in from its options (`crate::session`).

use crate::gather::{GatherDirections, GatherMethod, HitLight};
use crate::photons::PhotonSettings;
use crate::photons::passes::DEFAULT_PASS_ITERATIONS;

/// Settings of a render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub seed: u32,
    /// Light samples per pixel per iteration in the direct pass (where `light_balance`, the
    /// count the render starts from).
    pub light_samples: u32,
    /// The light samples per iteration chosen by measurement as the render goes on: the direct
    /// light's variance against the rest's, and what each costs on this GPU
    /// ([`crate::passes::light_budget`]). The library's settings default to a fixed count (a
    /// seed gives one image), the front ends ([`crate::session::Options`]) to balanced.
    pub light_balance: bool,
    /// n: the emission seen at pixels on the edge of an emitter or of the sky is estimated by
    /// n × n stratified sub-pixel rays per iteration ([`crate::passes::emitter_edges`]); 0: by
    /// the iteration's one jittered sample, as every other pixel. The same image in the mean,
    /// so not in the [fingerprint](Self::fingerprint): renders with different values may be merged.
    pub emitter_edges: u32,
    /// Photons traced into the photon map (0: no photon map, no indirect light).
    pub photons: u32,
    /// Photon grid cells along the scene's longest axis.
    pub grid_resolution: u32,
    /// Also accumulate the photon-map view (`Show::PhotonMap`).
    pub show_photon_map: bool,
    /// Ray-view resolution of the final gather (texels per side); 0 fits it to the scene and
    /// the image size ([`crate::fit::bundle`]: at least [`default_bundle`]).
    pub bundle: u32,
    /// How the final gather finds the nearest surface along its direction.
    pub gather: GatherMethod,
    /// The traced gather's directions: per pixel or shared by every pixel (applies to
    /// [`GatherMethod::Trace`] and the traced gather that `Auto` tries: the raster gathers
    /// always share them).
    pub gather_directions: GatherDirections,
    /// Whether [`GatherMethod::Auto`] tries the gathers on a CPU adapter too, where it takes
    /// the traced gather without trials otherwise ([`GatherPass::new`]).
    pub auto_trials_on_cpu: bool,
    /// Photon passes ([`crate::photons::passes`]): the map is re-traced with fresh photons in
    /// finer cells every `pass_iterations` iterations; 1: one fixed map; 0: no limit.
    pub photon_passes: u32,
    /// Iterations per photon pass; 0: chosen by `photon_budget`.
    pub pass_iterations: u32,
    /// How the iterations per photon pass are chosen where `pass_iterations` is 0: balanced by
    /// measurement ([`crate::photons::budget`]) or fitted to the photon count and the image
    /// size ([`crate::photons::passes::fitted_pass_iterations`]).
    pub photon_budget: PhotonBudget,
    /// The sun's and the sky's photons guided to where the map is read, as learned from the
    /// passes so far ([`crate::photons::guide`]); else only aimed at the photon region (the
    /// default: guiding measured no faster to an error on the rooms tried).
    pub photon_guiding: bool,
    /// The traced gather's per-pixel directions drawn from a mixture of the visible point's
    /// scattering and the light its cell's rays found ([`crate::gather::guide`]).
    pub gather_guiding: bool,
    /// The direct pass's environment samples drawn towards the parts of the sky that are open
    /// from each visible point, as its cell learned them ([`crate::passes::sky_guide`]); off
    /// by default (measured no better in the rooms tried).
    pub sky_guiding: bool,
    /// Gather directions per iteration, 1 to [`crate::gather::MAX_DIRECTIONS`]: they share the iteration's
    /// G-buffer and direct light.
    pub directions: u32,
    /// The light at the gather's hits: all from the photon map, or the direct part exact.
    pub hit_light: HitLight,
    /// Where the photon grid's cells are finer: where the camera reads the map, or nowhere.
    pub photon_region: PhotonRegionChoice,
    /// How the eye's visible points read textures: filtered over the pixel's footprint, or
    /// level 0 bilinearly as reference renderers do.
    pub texture_filter: TextureFilter,
    /// How the eye pass finds the visible points: rasterized, ray-cast, or (`Auto`) rasterized
    /// for the image and measured both ways for each of a viewer's coarse previews.
    pub eye_pass: EyeMethod,
}

/// How the eye pass finds each pixel's visible point (the G-buffer, `passes::gbuffer`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EyeMethod {
    /// The image rasterized; each coarse preview of a viewer ([`crate::session::refine`])
    /// times a G-buffer each way (where the GPU can be waited for) and keeps the faster.
    #[default]
    Auto,
    /// Every triangle drawn: its cost is mostly the triangles', whatever the pixels.
    Raster,
    /// A camera ray per pixel through the BVH: its cost is the pixels'.
    Trace,
}

/// How the eye's visible points (the G-buffer's, and the path tracer's first hits) read
/// textures. Every other point reads level 0 either way (crate::textures).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TextureFilter {
    /// Trilinear over the mip maps at the level of the pixel's footprint,
    /// λ = log2 max(|∂uv/∂x|, |∂uv/∂y|): the pixel's average texture, without noise.
    #[default]
    Footprint,
    /// Level 0, bilinearly, at the sample's own point: the pixel's samples average it, as
    /// Mitsuba's and pbrt's `bilinear` bitmap lookups do — what to compare with them.
    Bilinear,
}

/// How long each photon pass lasts ([`RenderSettings::pass_iterations`] 0). The library's
/// settings default to `Fitted` (a seed gives one image); the front ends' options
/// ([`crate::session::Options`]: the command line, the viewer, the page, Python) to `Balanced`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PhotonBudget {
    /// Measured as the render goes on: the variance the map adds to the image against the
    /// iterations' own, and what a pass and an iteration cost on this GPU, give the iterations
    /// per pass that lower the image's error fastest ([`crate::photons::budget`]). The choice
    /// depends on timings, so two renders of one seed may differ: `Fitted` repeats bit for bit.
    Balanced,
    /// 4 · photons / pixels iterations, at least 16, whatever the scene
    /// ([`crate::photons::passes::fitted_pass_iterations`]): the same for every run of a seed.
    #[default]
    Fitted,
}

/// Where the photon grid is refined ([`crate::fit::photon_region`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PhotonRegionChoice {
    /// Around what the scene's camera (when the renderer is made) and its gather rays reach:
    /// a room beside a large ground plane gets cells sized to the room.
    #[default]
    Camera,
    /// One level of cells over the whole scene.
    Scene,
}

/// Gather directions per iteration by default. On the Cornell box at 256² (lavapipe), the
/// indirect light carries 97 % of an iteration's variance while the G-buffer and the direct
/// pass take 60 % of its time: sharing them among 4 directions reaches a given error in about
/// half the time (docs/performance.md).
pub const DEFAULT_DIRECTIONS: u32 = 4;

impl RenderSettings {
    /// The settings other than the seed, as `(key, value)` text in a fixed order: what a
    /// checkpoint records of them, so a render resumed or merged with other settings is
    /// refused with what differs.
    pub fn fingerprint(&self) -> Vec<(String, String)> {
        let s = self;
        [
            ("size", format!("{}x{}", s.width, s.height)),
            ("light-samples", if s.light_balance { "balanced".into() } else { s.light_samples.to_string() }),
            ("photons", s.photons.to_string()),
            ("grid", s.grid_resolution.to_string()),
            ("photon-view", s.show_photon_map.to_string()),
            ("bundle", s.bundle.to_string()),
            ("gather", format!("{:?}", s.gather)),
            ("gather-directions", format!("{:?}", s.gather_directions)),
            ("photon-passes", s.photon_passes.to_string()),
            ("pass-iterations", s.pass_iterations.to_string()),
            ("directions", s.directions.to_string()),
            ("hit-light", format!("{:?}", s.hit_light)),
            ("photon-region", format!("{:?}", s.photon_region)),
            ("texture-filter", format!("{:?}", s.texture_filter)),
            ("eye-pass", format!("{:?}", s.eye_pass)),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect()
    }

    /// The gather's bundle: as set, or (0) fitted to a scene of this [`crate::fit::detail_bundle`].
    pub fn bundle_for(&self, detail_bundle: u32) -> u32 {
        if self.bundle == 0 { crate::fit::bundle(detail_bundle, self.width, self.height) } else { self.bundle }
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        let p = PhotonSettings::default();
        Self {
            width: 256,
            height: 256,
            seed: 0,
            light_samples: 1,
            light_balance: false,
            emitter_edges: crate::passes::emitter_edges::DEFAULT_EMITTER_EDGES,
            photons: p.count,
            grid_resolution: p.grid_resolution,
            show_photon_map: false,
            bundle: 0,
            gather: GatherMethod::Auto,
            gather_directions: GatherDirections::default(),
            auto_trials_on_cpu: false,
            directions: DEFAULT_DIRECTIONS,
            photon_passes: 0,
            pass_iterations: DEFAULT_PASS_ITERATIONS,
            photon_budget: PhotonBudget::default(),
            photon_guiding: false,
            gather_guiding: false,
            sky_guiding: false,
            hit_light: HitLight::Punctual,
            photon_region: PhotonRegionChoice::Camera,
            texture_filter: TextureFilter::Footprint,
            eye_pass: EyeMethod::Auto,
        }
    }
}
