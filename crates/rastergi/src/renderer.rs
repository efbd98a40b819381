//! The progressive renderer: owns the passes and runs one iteration at a time.
//! [`Renderer::iterate`] is the pipeline, top to bottom.

use glam::{Vec2, Vec3};

use crate::checkpoint::Progress;
use crate::error::Result;
use crate::gather::{DirectionSampler, GatherDirections, GatherMethod, GatherPass, GatherSetup, HitLight};
use crate::gpu::Gpu;
use crate::gpu_scene::GpuScene;
use crate::image_io::{DisplayImage, LinearImage};
use crate::passes::denoise::{DenoiseParams, Denoiser, GuideState, Guides};
use crate::passes::emitter_edges::EmitterEdges;
use crate::passes::film::{Blend, BlendResolve, Film, FilmState, ImageResolve, Show};
use crate::passes::frame::{FrameBinding, FrameUniforms, pixel_jitter};
use crate::passes::gbuffer::{GBufferPass, PixelPass};
use crate::passes::history::History;
use crate::passes::light_budget::LightBudget;
use crate::passes::photon_view::PhotonView;
use crate::passes::{FixedSample, FrameContext, IterationPass};
use crate::photons::budget::Budget;
use crate::photons::gpu::GpuPhotonMap;
use crate::photons::map::GridSpec;
use crate::photons::passes::{PhotonPasses, fitted_pass_iterations};
use crate::photons::{PhotonSettings, SampledDirect};
use crate::progressive::{Denoising, Progressive};
use crate::scene::{Camera, Scene};
use crate::settings::{EyeMethod, PhotonBudget, PhotonRegionChoice, RenderSettings, TextureFilter};
use crate::surface::PreparedScene;

/// Fixed values for one iteration's random choices, so tests can compare the passes with
/// other estimators for the same samples.
#[derive(Clone, Copy, Debug, Default)]
pub struct Overrides {
    /// One gather direction ω instead of the sequence's, shared by every pixel (in per-pixel
    /// mode too).
    pub direction: Option<Vec3>,
    /// Sub-pixel offset in [-0.5, 0.5)² instead of the sequence's.
    pub pixel_jitter: Option<Vec2>,
    /// Ray-view sub-texel offset instead of a random one.
    pub texel_jitter: Option<Vec2>,
}

pub use crate::fit::default_bundle;

/// The most iterations the re-projected history of the view before a move counts for in the
/// display ([`crate::passes::history`]): more would let a glossy surface's old view linger.
pub const HISTORY_WEIGHT: u32 = 16;
/// The film's iterations from which a preview is no longer blended in (its weight
/// w/(1 + n)² is then below 0.4 % of the film's for w ≤ 4).
pub const PREVIEW_FADED: u32 = 32;
/// The film's iterations, in multiples of the history's weight h, from which the history is no
/// longer blended in (its share h'/(n + h') is then below 1/HISTORY_FADED).
pub const HISTORY_FADED: u32 = 16;

/// The passes whose resources depend on the image size.
struct ImagePasses {
    gbuffer: GBufferPass,
    specular: Option<PixelPass>,
    /// The keys of what the pixels' centres see as light, where the emission at emitters'
    /// edges is supersampled (`RenderSettings::emitter_edges` > 0).
    emitter_edges: Option<crate::passes::emitter_edges::EmitterEdges>,
    direct: PixelPass,
    photon_view: Option<PixelPass>,
    caustics: Option<PixelPass>,
    gather: Option<GatherPass>,
    /// The pass that makes the guides' tables (the sky's, the gather's) from what the passes
    /// learned, at the start of each iteration, where the photon map's guide has cells.
    guide_build: Option<crate::gather::guide::GuideBuild>,
    film: Film,
    /// The denoiser's guides and filter, once enabled ([`Renderer::enable_denoiser`]).
    denoise: Option<DenoisePasses>,
}

/// The denoiser's passes: the guides (per iteration), the filter (on demand) and the resolve
/// of its output into the film's display buffer (for the window).
struct DenoisePasses {
    guides: Guides,
    denoiser: Denoiser,
    resolve: ImageResolve,
}

impl ImagePasses {
    fn new(
        gpu: &Gpu,
        scene: &GpuScene,
        frame: &FrameBinding,
        map: Option<&GpuPhotonMap>,
        settings: &RenderSettings,
        (detail_bundle, preview): (u32, bool),
        sampler: DirectionSampler,
    ) -> Result<ImagePasses> {
        let (width, height) = (settings.width, settings.height);
        let film = Film::new(gpu, width, height)?;
        // The window's image rasterizes where the way is not given: its many pixels make the
        // triangles' cost a small part (a preview times both ways: `new_preview`).
        let eye = match settings.eye_pass {
            EyeMethod::Auto if !preview => EyeMethod::Raster,
            m => m,
        };
        let gbuffer = GBufferPass::new(gpu, scene, frame, (width, height), eye);
        let specular = scene.eye_chains.then(|| crate::passes::specular::pass(gpu, scene, frame, &gbuffer, &film));
        let emitter_edges = (settings.emitter_edges > 0).then(|| EmitterEdges::new(gpu, scene, frame, &gbuffer, &film));
        // The guides' tables: the guided sky's for the direct pass's environment samples, and
        // the guided gather's density that weighs them.
        let guided = map.filter(|m| m.guide_cells > 0);
        let direct = crate::passes::direct::pass(gpu, scene, frame, (&gbuffer, &film), guided);
        let photon_view = match map {
            Some(map) if settings.show_photon_map => {
                Some(crate::passes::photon_view::pass(gpu, scene, frame, &gbuffer, &film, map, PhotonView::Map))
            }
            _ => None,
        };
        let caustics = match map {
            Some(map) if scene.caustics => {
                Some(crate::passes::photon_view::pass(gpu, scene, frame, &gbuffer, &film, map, PhotonView::Caustics))
            }
            _ => None,
        };
        let bundle = settings.bundle_for(detail_bundle);
        let gather = match map {
            Some(map) => {
                let setup = GatherSetup { scene, frame, gbuffer: &gbuffer, film: &film, map };
                Some(GatherPass::new(
                    gpu,
                    &setup,
                    bundle,
                    settings.gather,
                    settings.gather_directions,
                    sampler,
                    settings.auto_trials_on_cpu,
                )?)
            }
            None => None,
        };
        let guide_build = map
            .filter(|m| m.guide_cells > 0)
            .map(|m| crate::gather::guide::GuideBuild::new(gpu, &m.guide, m.guide_cells));
        Ok(ImagePasses {
            gbuffer,
            specular,
            emitter_edges,
            direct,
            photon_view,
            caustics,
            gather,
            guide_build,
            film,
            denoise: None,
        })
    }

    fn enable_denoiser(&mut self, gpu: &Gpu, scene: &GpuScene, frame: &FrameBinding) -> Result<()> {
        if self.denoise.is_none() {
            let (w, h) = (self.film.width, self.film.height);
            gpu.check_image_size(w, h, crate::passes::denoise::LARGEST_BUFFER_PER_PIXEL)?;
            let guides = Guides::new(gpu, (scene, frame), &self.gbuffer, &self.film);
            let denoiser = Denoiser::new(
                gpu,
                (w, h),
                &self.film.accumulation,
                (&guides.buffer, &guides.extra),
                crate::passes::denoise::LEVELS,
            );
            let resolve = self.film.image_resolve(gpu, denoiser.image());
            self.denoise = Some(DenoisePasses { guides, denoiser, resolve });
        }
        Ok(())
    }
}

pub struct Renderer {
    gpu: Gpu,
    settings: RenderSettings,
    camera: Camera,
    scene: GpuScene,
    frame: FrameBinding,
    /// The photon map of the current pass, and what the next pass needs.
    photons: Option<PhotonPasses>,
    /// How long the photon passes last, measured ([`crate::photons::budget`]); `None` where
    /// their length is fixed.
    budget: Option<Budget>,
    passes: ImagePasses,
    /// The scene's part of the default bundle ([`crate::fit::detail_bundle`]).
    detail_bundle: u32,
    /// The denoiser's guides are accumulated ([`Renderer::enable_denoiser`]).
    denoise: bool,
    /// The iteration under way in row bands ([`Renderer::iterate_rows`]).
    band: Option<Band>,
    /// Smaller images of the same view, made as a viewer asks for them
    /// ([`Renderer::iterate_preview_rows`]).
    previews: Vec<Preview>,
    /// What the film held before the last camera move ([`crate::passes::history`]), made at
    /// the first move, and whether it is re-projected onto the current view.
    history: Option<History>,
    reprojected: bool,
    /// The resolves that blend previews (by scale; 0: none) and the history in.
    blends: Vec<(u32, BlendResolve)>,
    /// Seconds spent tracing the photon pass under way in steps ([`Renderer::photon_step`]).
    stepped_seconds: f64,
    /// The light samples per iteration, measured ([`crate::passes::light_budget`]); `None`
    /// where the count is fixed.
    light_budget: Option<LightBudget>,
    /// When the iteration under way began, where the light budget times it.
    timing: Option<web_time::Instant>,
}

/// The view at 1/`scale` of the image's size, with its own passes and film (the scene and the
/// photon map shared), the preview's iteration under way, and the resolve that blends it into
/// the film's.
struct Preview {
    scale: u32,
    passes: ImagePasses,
    band: Option<Band>,
}

impl Renderer {
    pub fn new(gpu: &Gpu, scene: &Scene, settings: RenderSettings) -> Result<Renderer> {
        scene.validate()?;
        // Fail on an impossible image size before the BVH and the photon map are built.
        gpu.check_image_size(settings.width, settings.height, crate::passes::film::COMPONENTS * 16)?;
        // Fail on a scene, photon grid or bundle too large for this GPU before the BVH is built.
        let limits = gpu.device.limits();
        crate::gpu_scene::check_scene(&limits, scene)?;
        let detail_bundle = crate::fit::detail_bundle(scene);
        if settings.photons > 0 {
            crate::photons::map::check_photon_grid(&limits, &GridSpec::new(&scene.bounds(), settings.grid_resolution))?;
            if settings.gather != GatherMethod::Trace {
                crate::gpu::limits::check_bundle(&limits, settings.bundle_for(detail_bundle))?;
            }
        }
        let start = web_time::Instant::now();
        let prepared = PreparedScene::new(scene);
        log::info!(
            "BVH over {} triangles: {} nodes, depth {}, built in {:.2} s",
            scene.triangles.len(),
            prepared.bvh.nodes.len(),
            prepared.bvh.depth(),
            start.elapsed().as_secs_f64()
        );
        prepared.textures.check_limits(gpu)?;
        let gpu_scene = GpuScene::new(gpu, &prepared)?;
        let mut frame = FrameBinding::new(gpu);
        frame.reserve_eye_paths(gpu, settings.width as u64 * settings.height as u64);
        let region = match settings.photon_region {
            PhotonRegionChoice::Camera if settings.photons > 0 => {
                let aspect = settings.width as f32 / settings.height as f32;
                let region = crate::fit::photon_region(&prepared, &scene.camera, aspect, settings.grid_resolution);
                if let Some(r) = &region {
                    log::info!("photon region: {r}");
                }
                region
            }
            _ => None,
        };
        let photon_settings = PhotonSettings {
            count: settings.photons,
            seed: settings.seed,
            grid_resolution: settings.grid_resolution,
            sampled_direct: match settings.hit_light {
                HitLight::Map => SampledDirect::None,
                HitLight::Exact => SampledDirect::All,
                HitLight::Punctual => SampledDirect::Punctual,
            },
            region,
            guided: settings.photon_guiding && crate::gpu::READ_BACK_BLOCKS,
        };
        let photons = (settings.photons > 0)
            .then(|| {
                let pixels = settings.width as u64 * settings.height as u64;
                let k = match settings.pass_iterations {
                    0 => fitted_pass_iterations(settings.photons, pixels),
                    k => k,
                };
                let n = settings.photon_passes;
                // The guides' cells over the photon region (or the scene): the gather's tables
                // and the sky's, where each is on.
                let sky = prepared.scene.environment.as_deref().filter(|e| settings.sky_guiding && !e.is_dark());
                let field = (settings.gather_guiding || sky.is_some()).then(|| {
                    let bounds = region.as_ref().map_or(prepared.bounds, |r| r.bounds);
                    let area: f64 =
                        prepared.scene.triangles.iter().map(|t| crate::scene::triangle_area(t) as f64).sum();
                    let mut field = crate::gather::guide::GuideField::new(&bounds, prepared.lights.power, area);
                    field.gather = settings.gather_guiding;
                    field.sky = sky.map(crate::passes::sky_guide::SkyBlocks::new);
                    field
                });
                PhotonPasses::new(gpu, &gpu_scene, prepared, photon_settings, n, k, field)
            })
            .transpose()?;
        let mut photons = photons;
        let map = photons.as_ref().map(PhotonPasses::map);
        let sampler = DirectionSampler::new(settings.seed);
        let passes = ImagePasses::new(gpu, &gpu_scene, &frame, map, &settings, (detail_bundle, false), sampler)?;
        let budget = new_budget(gpu, &settings, &passes.film, photons.as_mut(), true);
        let light_budget = settings.light_balance.then(LightBudget::new);
        Ok(Renderer {
            gpu: gpu.clone(),
            settings,
            camera: scene.camera,
            scene: gpu_scene,
            frame,
            photons,
            budget,
            passes,
            detail_bundle,
            denoise: false,
            band: None,
            previews: Vec::new(),
            history: None,
            reprojected: false,
            blends: Vec::new(),
            stepped_seconds: 0.0,
            light_budget,
            timing: None,
        })
    }

    /// Changes the image size: the passes that depend on it are rebuilt and the image
    /// restarts; the scene, its BVH and the photon map are kept.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        let settings = RenderSettings { width, height, ..self.settings.clone() };
        // The gather's random choices go on where they were.
        let sampler =
            self.passes.gather.as_ref().map_or_else(|| DirectionSampler::new(settings.seed), GatherPass::sampler);
        self.frame.reserve_eye_paths(&self.gpu, width as u64 * height as u64);
        self.passes = ImagePasses::new(
            &self.gpu,
            &self.scene,
            &self.frame,
            self.photons.as_ref().map(PhotonPasses::map),
            &settings,
            (self.detail_bundle, false),
            sampler,
        )?;
        self.budget = new_budget(&self.gpu, &settings, &self.passes.film, self.photons.as_mut(), false);
        self.settings = settings;
        self.previews.clear();
        (self.history, self.reprojected) = (None, false);
        self.blends.clear();
        if self.denoise {
            self.passes.enable_denoiser(&self.gpu, &self.scene, &self.frame)?;
        }
        self.reset();
        Ok(())
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// The gather's ray-view resolution in use (texels per side; 0 without a photon map).
    pub fn bundle(&self) -> u32 {
        self.passes.gather.as_ref().map_or(0, |g| g.bundle)
    }

    /// The gather's random choices as they stand (for tests: the per-pixel scramble key of
    /// this restart); `None` without a photon map.
    pub fn gather_sampler(&self) -> Option<DirectionSampler> {
        self.passes.gather.as_ref().map(GatherPass::sampler)
    }

    /// Whose directions the gather casts: per pixel or shared.
    pub fn gather_directions(&self) -> GatherDirections {
        self.passes.gather.as_ref().map_or(GatherDirections::Shared, GatherPass::directions)
    }

    /// The gather implementation in use (`Auto` until its trials have chosen).
    pub fn gather_method(&self) -> GatherMethod {
        self.passes.gather.as_ref().map_or(self.settings.gather, |g| g.method())
    }

    pub fn camera(&self) -> Camera {
        self.camera
    }

    /// Light samples per pixel of the iterations now: the fixed count, or the light budget's
    /// choice so far ([`crate::passes::light_budget`]; its first iterations time others).
    pub fn light_samples(&self) -> u32 {
        self.light_budget.as_ref().map_or(self.settings.light_samples, LightBudget::chosen)
    }

    /// Iterations accumulated since the last reset.
    pub fn samples(&self) -> u32 {
        self.passes.film.samples
    }

    /// Moves the camera; the image starts converging again. What the film held is kept for
    /// the display ([`crate::passes::history`]) where it has iterations (at least as many as
    /// the history kept before, up to 8: a view passed through quickly does not replace a
    /// converged one).
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        camera.validate()?;
        let kept = self.history.as_ref().map_or(0, |h| h.samples);
        if self.passes.film.samples >= kept.clamp(1, 8) {
            self.snapshot()?;
        }
        self.camera = camera;
        self.reprojected = false;
        self.reset();
        Ok(())
    }

    /// The frame of the current camera without jitter, for the whole image, and its
    /// view-projection.
    fn still_frame(&self) -> (FrameUniforms, glam::Mat4) {
        let (w, h) = (self.settings.width, self.settings.height);
        let (seed, samples) = (self.settings.seed, self.settings.light_samples);
        let mut u = FrameUniforms::new(&self.camera, (w, h), &self.scene, 0, Vec2::ZERO, seed, samples);
        u.texture_footprint = (self.settings.texture_filter == TextureFilter::Footprint) as u32;
        let near = crate::passes::frame::near_plane(&self.scene.bounds);
        (u, crate::passes::frame::view_projection(&self.camera, w, h, near, Vec2::ZERO))
    }

    /// Keeps the film's mean and what its pixels see, before a move.
    fn snapshot(&mut self) -> Result<()> {
        if self.history.is_none() {
            let (scene, frame) = (&self.scene, &self.frame);
            self.history = Some(History::new(&self.gpu, (scene, frame), (&self.passes.gbuffer, &self.passes.film)));
            self.blends.clear();
        }
        let (u, view_proj) = self.still_frame();
        self.frame.write(&self.gpu, &u);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let map = self.photons.as_ref().map(PhotonPasses::map);
            let target = Target { gpu: &self.gpu, scene: &self.scene, frame: &self.frame, map };
            let ctx = target.whole_image(&self.settings);
            let history = self.history.as_mut().expect("made above");
            history.encode_snapshot(&mut enc, &ctx, &self.passes.film, (Show::Full, view_proj))?;
        }
        self.gpu.queue.submit([enc.finish()]);
        Ok(())
    }

    /// Re-projects the history onto the current view for the display: the window's G-buffer
    /// of this camera (without jitter), then each pixel's kept mean where the old view saw the
    /// same triangle. Nothing where there is no history, it is re-projected already, or an
    /// iteration is under way in bands (it reads the G-buffer); returns whether it ran.
    pub fn reproject(&mut self) -> Result<bool> {
        if self.reprojected || self.band.is_some() || self.history.as_ref().is_none_or(|h| h.samples == 0) {
            return Ok(false);
        }
        let (u, _) = self.still_frame();
        self.frame.write(&self.gpu, &u);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let map = self.photons.as_ref().map(PhotonPasses::map);
            let target = Target { gpu: &self.gpu, scene: &self.scene, frame: &self.frame, map };
            let ctx = target.whole_image(&self.settings);
            self.passes.gbuffer.encode(&mut enc, &ctx)?;
            self.history.as_mut().expect("checked above").encode_reproject(&mut enc, &ctx)?;
        }
        self.gpu.queue.submit([enc.finish()]);
        self.reprojected = true;
        Ok(true)
    }

    /// Discards the accumulated iterations.
    pub fn reset(&mut self) {
        self.band = None;
        self.frame.edge_keys.take();
        for p in &mut self.previews {
            p.band = None;
            p.passes.film.clear(&self.gpu);
        }
        self.passes.film.clear(&self.gpu);
        if let Some(b) = &mut self.budget {
            b.restart();
        }
        if let Some(b) = &mut self.light_budget {
            b.restart();
        }
        self.timing = None;
        if let Some(d) = &mut self.passes.denoise {
            d.guides.clear(&self.gpu);
        }
        if let Some(gather) = &mut self.passes.gather {
            gather.restart();
        }
    }

    /// One progressive iteration: one new estimate per pixel, added to the film.
    pub fn iterate(&mut self) -> Result<()> {
        self.iterate_with(&Overrides::default())
    }

    /// One iteration with some random choices fixed (see [`Overrides`]); an iteration under
    /// way in row bands ([`Renderer::iterate_rows`]) is finished instead, with its own choices.
    pub fn iterate_with(&mut self, o: &Overrides) -> Result<()> {
        if self.band.is_none() {
            self.begin_iteration(o, true)?;
        }
        while !self.encode_rows(u32::MAX)? {}
        Ok(())
    }

    /// Runs the next `rows` rows of the image (at least one) of the iteration under way,
    /// beginning one where none is; returns whether that finished the iteration (its sample
    /// then counts in [`samples`](Self::samples)). The viewer splits an iteration so into row
    /// bands across frames when a whole one would take longer than a frame. A band is the
    /// whole iteration's work restricted to its rows — the same uniforms, photon map, gather
    /// directions and per-pixel random sequences — so the film after the last band is bit for
    /// bit that of [`iterate`](Self::iterate). The G-buffer is rasterized whole with the first
    /// band. While `Auto` still tries the gathers (it times whole iterations), the band is the
    /// whole image.
    pub fn iterate_rows(&mut self, rows: u32) -> Result<bool> {
        let whole = self.gather_method() == GatherMethod::Auto;
        if self.band.is_none() {
            self.begin_iteration(&Overrides::default(), whole || rows >= self.settings.height)?;
        }
        self.encode_rows(if whole { u32::MAX } else { rows.max(1) })
    }

    /// The rows of the image that the iteration under way has added to the film (0 where none
    /// is under way): the film's sums hold [`samples`](Self::samples) + 1 iterations above
    /// that row and `samples` below it.
    pub fn rows_ahead(&self) -> u32 {
        self.band.map_or(0, |b| b.next_row)
    }

    /// [`iterate_rows`](Self::iterate_rows) for the preview at 1/`scale` of the image's size
    /// (made on first use): the same view, its own film and random sequences, the current
    /// photon map (a preview never begins a photon pass); true when its iteration is done.
    pub fn iterate_preview_rows(&mut self, scale: u32, rows: u32) -> Result<bool> {
        let k = match self.previews.iter().position(|p| p.scale == scale) {
            Some(k) => k,
            None => {
                let preview = self.new_preview(scale)?;
                self.previews.push(preview);
                self.previews.len() - 1
            }
        };
        let light = self.light_samples();
        let map = self.photons.as_ref().map(PhotonPasses::map);
        let target = Target { gpu: &self.gpu, scene: &self.scene, frame: &self.frame, map };
        let p = &mut self.previews[k];
        if p.band.is_none() {
            let block = p.passes.film.samples / crate::passes::film::BLOCK_ITERATIONS;
            let view = (&self.settings, &self.camera);
            let first = p.passes.film.samples.wrapping_mul(light);
            p.band = Some(Band::begin(&target, view, &mut p.passes, (&Overrides::default(), (light, first)), block));
        }
        run_band(&mut p.band, &target, &mut p.passes, self.settings.directions, rows.max(1))
    }

    /// The preview at 1/`scale`: the image's passes at ⌈W/scale⌉ × ⌈H/scale⌉ over the same
    /// scene and photon map, with the gather the full image uses (the traced one while `Auto`
    /// still tries them: a preview is not timed).
    fn new_preview(&self, scale: u32) -> Result<Preview> {
        let gather = match self.gather_method() {
            GatherMethod::Auto => GatherMethod::Trace,
            chosen => chosen,
        };
        let (w, h) = (self.settings.width.div_ceil(scale), self.settings.height.div_ceil(scale));
        let settings = RenderSettings { width: w, height: h, gather, ..self.settings.clone() };
        let map = self.photons.as_ref().map(PhotonPasses::map);
        let sampler = DirectionSampler::new(settings.seed);
        let passes =
            ImagePasses::new(&self.gpu, &self.scene, &self.frame, map, &settings, (self.detail_bundle, true), sampler)?;
        Ok(Preview { scale, passes, band: None })
    }

    /// The film of the preview at 1/`scale`, once made.
    pub fn preview_film(&self, scale: u32) -> Option<&Film> {
        self.previews.iter().find(|p| p.scale == scale).map(|p| &p.passes.film)
    }

    /// Encodes the resolve of `show` blended with the preview at 1/`scale` weighted as `weight`
    /// iterations, and with the history re-projected onto this view where it is and shows
    /// `show` (weighed as its iterations, at most [`HISTORY_WEIGHT`]; [`Film::encode_resolve_blend`]);
    /// the plain resolve where there is neither.
    pub fn encode_resolve_blend(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        (show, exposure): (Show, f32),
        preview: Option<(u32, f32)>,
    ) {
        // Each is dropped once its weight has faded below a few parts in a thousand of the
        // film's: the preview's w/(1 + n)² from n = PREVIEW_FADED, the history's share
        // h'/(n + h') ≤ h/n from n = HISTORY_FADED · h.
        let n = self.passes.film.samples;
        let preview = preview
            .filter(|_| n < PREVIEW_FADED)
            .and_then(|(scale, w)| self.previews.iter().position(|p| p.scale == scale).map(|k| (k, w)));
        let history = self.history.as_ref().filter(|h| {
            let h_weight = h.samples.min(HISTORY_WEIGHT);
            self.reprojected && h.samples > 0 && h.show == show && n < HISTORY_FADED * h_weight
        });
        if preview.is_none() && history.is_none() {
            return self.encode_resolve(enc, show, exposure);
        }
        let key = preview.map_or(0, |(k, _)| self.previews[k].scale);
        let film = &self.passes.film;
        if !self.blends.iter().any(|(s, _)| *s == key) {
            let pre = preview.map(|(k, _)| &self.previews[k].passes.film);
            let resolve = film.blend_resolve(&self.gpu, pre, self.history.as_ref().map(|h| &h.reprojected));
            self.blends.push((key, resolve));
        }
        let resolve = &self.blends.iter().find(|(s, _)| *s == key).expect("made above").1;
        let blend = Blend {
            resolve,
            preview: preview.map(|(k, w)| (&self.previews[k].passes.film, w)),
            history_weight: history.map_or(0.0, |h| h.samples.min(HISTORY_WEIGHT) as f32),
        };
        film.encode_resolve_blend(&self.gpu, enc, (show, exposure), blend);
    }

    /// A moving frame's resolve where the film holds nothing of this view yet (no iteration,
    /// none under way) and the history is not blended in: [`Renderer::encode_resolve_blend`]
    /// is then the preview alone, stretched over the window; instead the preview's own
    /// resolve, at its size, which the display pass stretches the same way
    /// ([`Film::show_upscaled`]; bilinear between the same pixel centres, of the encoded
    /// values). On lavapipe at 1280 × 720 the window-sized blend took 31 ms of each 50 ms
    /// frame while moving, the work getting the quarter left. The film's linear and display
    /// buffers keep what they held. Returns whether it did so (else nothing is encoded).
    pub fn encode_resolve_upscaled(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        (show, exposure): (Show, f32),
        preview: Option<(u32, f32)>,
    ) -> bool {
        let film = &self.passes.film;
        let history = self.history.as_ref().is_some_and(|h| self.reprojected && h.samples > 0 && h.show == show);
        if film.samples > 0 || film.rows_ahead > 0 || history {
            return false;
        }
        let Some(pre) = preview
            .and_then(|(scale, _)| self.previews.iter().find(|p| p.scale == scale))
            .map(|p| &p.passes.film)
            .filter(|f| f.samples > 0)
        else {
            return false;
        };
        pre.encode_resolve(&self.gpu, enc, show, exposure);
        film.show_upscaled(pre);
        true
    }

    /// Traces each new photon pass in steps ([`Renderer::photon_step`]) beside the current one,
    /// which the iterations go on reading until it is done (an interactive view: no frame
    /// waits for a whole pass), or at once before the iteration that needs it (`false`: the
    /// default, and `render`'s). Not where the photons are guided.
    pub fn set_photon_steps(&mut self, on: bool) {
        if let Some(p) = &mut self.photons {
            p.set_stepped(on);
        }
    }

    /// Where the photon region follows the camera (`PhotonRegionChoice::Camera`) and the passes
    /// are traced in steps: fits the region to the current view and, where it has moved
    /// ([`crate::photons::passes::region_moved`]), begins the next pass at once over it (it
    /// replaces the map when it is all traced, [`Renderer::photon_step`]). Returns whether it
    /// began. A viewer calls it when the camera stops.
    pub fn refit_photon_region(&mut self) -> Result<bool> {
        let Some(p) = self.photons.as_mut().filter(|p| p.stepped()) else { return Ok(false) };
        if self.settings.photon_region != PhotonRegionChoice::Camera {
            return Ok(false);
        }
        let aspect = self.settings.width as f32 / self.settings.height as f32;
        let region = crate::fit::photon_region(p.prepared(), &self.camera, aspect, self.settings.grid_resolution);
        let began = p.refit(&self.gpu, &self.scene, region)?;
        if began && let Some(r) = p.region() {
            log::info!("photon region refitted to the view: {r}");
        }
        Ok(began)
    }

    /// The next photon pass's photons traced and in all, while it is traced in steps.
    pub fn photons_pending(&self) -> Option<(u32, u32)> {
        self.photons.as_ref().and_then(PhotonPasses::pending)
    }

    /// Traces up to `photons` more of the photon pass under way in steps, between iterations
    /// (nothing while one is under way in bands); once it is all traced it becomes the map
    /// that the next iteration reads, and the photon budget measures the pass that ends.
    /// Returns whether that happened.
    pub fn photon_step(&mut self, photons: u32) -> Result<bool> {
        let Some(p) = self.photons.as_mut().filter(|_| self.band.is_none()) else { return Ok(false) };
        let done = p.iterations_in_pass();
        let began = web_time::Instant::now();
        let swapped = p.trace_step(&self.gpu, &self.scene, photons);
        if let Some(budget) = &mut self.budget {
            self.gpu.wait()?;
            self.stepped_seconds += began.elapsed().as_secs_f64();
            if swapped {
                budget.pass_traced(&self.gpu, p, done, std::mem::take(&mut self.stepped_seconds))?;
            }
        }
        Ok(swapped)
    }

    /// Begins an iteration (`whole`: run at once, not in bands): the photon pass it reads, the
    /// film's block, its light samples, its uniforms.
    fn begin_iteration(&mut self, o: &Overrides, whole: bool) -> Result<()> {
        let iteration = self.passes.film.samples;
        // The light budget reads the film where it chooses again, before the photon budget
        // times the pass that begins (the read waits for the iterations under way).
        if let Some(b) = self.light_budget.as_mut().filter(|b| b.decides_before(iteration)) {
            b.decide(&self.passes.film.read_state(&self.gpu)?);
        }
        // 0. A new photon pass, when the current one has had its iterations (as many as the
        //    photon budget chose from its measurements of the passes so far).
        if let Some(photons) = &mut self.photons {
            match &mut self.budget {
                Some(budget) => budget.advance(&self.gpu, &self.scene, photons)?,
                None => {
                    photons.advance(&self.gpu, &self.scene)?;
                }
            }
        }
        // The film's blocks for its error estimate: the photon passes (each its own photons),
        // or runs of BLOCK_ITERATIONS iterations where the map is fixed.
        let block = match &self.photons {
            Some(p) if p.progressive() => p.pass(),
            _ => iteration / crate::passes::film::BLOCK_ITERATIONS,
        };
        // The light samples: a fixed count, or as the light budget chose from its
        // measurements (some early iterations timed).
        let light = match &mut self.light_budget {
            Some(b) => {
                let (k, first, timed) = b.begin(iteration, whole);
                if timed {
                    // Timed from here (the photon pass begun before) to the iteration's end.
                    self.gpu.wait()?;
                    self.timing = Some(web_time::Instant::now());
                }
                if let Some(photons) = &mut self.budget {
                    photons.set_light_samples(k, b.costs().map(|c| c.sample));
                }
                (k, first)
            }
            None => (self.settings.light_samples, iteration.wrapping_mul(self.settings.light_samples)),
        };
        let map = self.photons.as_ref().map(PhotonPasses::map);
        let target = Target { gpu: &self.gpu, scene: &self.scene, frame: &self.frame, map };
        let view = (&self.settings, &self.camera);
        self.band = Some(Band::begin(&target, view, &mut self.passes, (o, light), block));
        Ok(())
    }

    /// The next `rows` rows of the iteration under way (all that are left at most); true when
    /// they finish it.
    fn encode_rows(&mut self, rows: u32) -> Result<bool> {
        let map = self.photons.as_ref().map(PhotonPasses::map);
        let target = Target { gpu: &self.gpu, scene: &self.scene, frame: &self.frame, map };
        let k = self.band.as_ref().map_or(1, |b| b.uniforms.light_samples);
        let done = run_band(&mut self.band, &target, &mut self.passes, self.settings.directions, rows)?;
        if done && let Some(p) = self.gpu.profiler.as_ref().filter(|p| p.half_full()) {
            p.collect(&self.gpu.device, &self.gpu.queue)?;
        }
        // A timed iteration began whole ([`LightBudget::begin`]), so one call finishes it.
        if let Some(began) = self.timing.take().filter(|_| done)
            && let Some(b) = &mut self.light_budget
        {
            self.gpu.wait()?;
            b.timed(k, began.elapsed().as_secs_f64());
        }
        Ok(done)
    }

    /// Blocks until the submitted iterations have finished on the GPU.
    pub fn wait(&self) -> Result<()> {
        self.gpu.wait()
    }

    /// Where the render stands besides its film (for a checkpoint).
    pub fn progress(&self) -> Progress {
        Progress {
            photon_pass: self.photons.as_ref().map_or(0, PhotonPasses::pass),
            iterations_in_pass: self.photons.as_ref().map_or(0, PhotonPasses::iterations_in_pass),
            gather: self.passes.gather.as_ref().and_then(GatherPass::choice),
        }
    }

    /// Continues from a checkpoint's state (of this scene and these settings: the caller
    /// checks, [`crate::checkpoint::Checkpoint::check_matches`]): the film's sums, the photon
    /// pass, the gather chosen. The next iteration is the one the checkpointed render would
    /// have run next.
    pub fn resume(&mut self, progress: &Progress, film: &FilmState) -> Result<()> {
        if let Some(photons) = &mut self.photons {
            photons.resume_at(&self.gpu, &self.scene, progress.photon_pass, progress.iterations_in_pass)?;
        }
        if let Some((method, directions)) = progress.gather {
            let chosen = self.passes.gather.as_mut().map(|g| g.choose_as(method, directions));
            if matches!(chosen, Some(Err(_))) && !self.settings.auto_trials_on_cpu {
                // Auto took the traced gather without trials on this CPU adapter and the
                // checkpoint's render chose another: build every candidate, as trials would.
                self.settings.auto_trials_on_cpu = true;
                let (width, height) = (self.settings.width, self.settings.height);
                self.resize(width, height)?;
                if let Some(g) = &mut self.passes.gather {
                    g.choose_as(method, directions)?;
                }
            } else if let Some(chosen) = chosen {
                chosen?;
            }
        }
        self.passes.film.restore(&self.gpu, film)?;
        if let Some(b) = &mut self.budget {
            b.restart();
        }
        if let Some(b) = &mut self.light_budget {
            b.resume(film.samples, self.settings.light_samples);
        }
        if let Some(d) = &mut self.passes.denoise {
            d.guides.restart_from(&self.gpu, &self.passes.film);
        }
        Ok(())
    }

    /// The photon map of the current pass, if the render has one.
    pub fn photon_map(&self) -> Option<&GpuPhotonMap> {
        self.photons.as_ref().map(PhotonPasses::map)
    }

    /// The photon guide: where the map is read, and what the passes learned of where the sun's
    /// and the sky's photons land there (`None` without a photon map).
    pub fn photon_guide(&self) -> Option<&crate::photons::guide::PhotonGuide> {
        self.photons.as_ref().map(PhotonPasses::guide)
    }

    /// The balanced photon budget, where this render has one.
    pub fn photon_budget(&self) -> Option<&crate::photons::budget::Budget> {
        self.budget.as_ref()
    }

    /// The current photon pass (0-based; 0 without a photon map).
    pub fn photon_pass(&self) -> u32 {
        self.photons.as_ref().map_or(0, PhotonPasses::pass)
    }

    /// The film: accumulated sums and the resolved images (for drawing it in a window).
    pub fn film(&self) -> &Film {
        &self.passes.film
    }

    /// The film's sums and their odd half, read back (checkpoints, the error estimate).
    pub fn film_state(&self) -> Result<FilmState> {
        self.passes.film.read_state(&self.gpu)
    }

    /// Encodes the resolve of `show` at `exposure` into the film's linear and display
    /// buffers (what [`read_display`](Self::read_display) reads, without the readback).
    pub fn encode_resolve(&self, enc: &mut wgpu::CommandEncoder, show: Show, exposure: f32) {
        self.passes.film.encode_resolve(&self.gpu, enc, show, exposure);
    }

    pub fn read_linear(&self, show: Show) -> Result<LinearImage> {
        self.passes.film.read_linear(&self.gpu, show)
    }

    pub fn read_display(&self, show: Show, exposure: f32) -> Result<DisplayImage> {
        self.passes.film.read_display(&self.gpu, show, exposure)
    }

    fn denoiser(&self) -> Result<&DenoisePasses> {
        self.passes.denoise.as_ref().ok_or_else(|| {
            crate::error::Error::Gpu("the denoiser was not enabled (Renderer::enable_denoiser)".to_owned())
        })
    }

    /// Raw G-buffer texels `(triangle + 1, b1 bits, b2 bits, texture level of detail bits)`,
    /// row by row (for tests and tools).
    pub fn read_gbuffer(&self) -> Result<Vec<[u32; 4]>> {
        self.passes.gbuffer.read(&self.gpu)
    }
}

/// What every band of an iteration reads besides the image's own passes.
struct Target<'a> {
    gpu: &'a Gpu,
    scene: &'a GpuScene,
    frame: &'a FrameBinding,
    map: Option<&'a GpuPhotonMap>,
}

impl Target<'_> {
    /// The frame context of a pass over the whole image of `settings`' size outside an
    /// iteration (the history's: no jitter, iteration 0).
    fn whole_image(&self, settings: &RenderSettings) -> FrameContext<'_> {
        FrameContext {
            gpu: self.gpu,
            scene: self.scene,
            frame: self.frame,
            map: self.map,
            width: settings.width,
            height: settings.height,
            y0: 0,
            rows: settings.height,
            iteration: 0,
            directions: settings.directions,
            fixed: FixedSample::default(),
        }
    }
}

/// Runs the next `rows` rows of the iteration under way in `slot` into `passes`' film, which
/// counts the rows ahead meanwhile and the iteration once it is done (the slot then empty);
/// true when it is.
fn run_band(slot: &mut Option<Band>, t: &Target, passes: &mut ImagePasses, directions: u32, rows: u32) -> Result<bool> {
    let band = slot.as_mut().expect("an iteration under way");
    let done = band.encode(t, passes, directions, rows)?;
    passes.film.rows_ahead = if done { 0 } else { band.next_row };
    if done {
        *slot = None;
        passes.film.samples += 1;
    }
    Ok(done)
}

/// An iteration under way: its uniforms and random choices, fixed when it began, and the next
/// row to run ([`Renderer::iterate_rows`]).
#[derive(Clone, Copy)]
struct Band {
    uniforms: FrameUniforms,
    fixed: FixedSample,
    next_row: u32,
}

impl Band {
    /// The iteration of `passes`' film that comes next (its `block` opened), seen by `camera`.
    fn begin(
        t: &Target,
        (settings, camera): (&RenderSettings, &Camera),
        passes: &mut ImagePasses,
        (o, (light_samples, light_base)): (&Overrides, (u32, u32)),
        block: u32,
    ) -> Band {
        let (scene, map) = (t.scene, t.map);
        let film = &mut passes.film;
        let (iteration, size) = (film.samples, (film.width, film.height));
        film.begin_iteration(t.gpu, block);
        let seed = settings.seed;
        let jitter = o.pixel_jitter.unwrap_or_else(|| pixel_jitter(iteration, seed));
        let mut uniforms = FrameUniforms::new(camera, size, scene, iteration, jitter, seed, light_samples);
        uniforms.light_base = light_base;
        uniforms.emitter_edges = settings.emitter_edges;
        uniforms.eye_chains = scene.eye_chains as u32;
        uniforms.texture_footprint = (settings.texture_filter == TextureFilter::Footprint) as u32;
        let fixed = FixedSample { direction: o.direction, texel_jitter: o.texel_jitter };
        if let (Some(gather), Some(_)) = (&passes.gather, map) {
            let (count, per_pixel) = gather.strategy(settings.directions, &fixed);
            uniforms.gather_count = count;
            uniforms.gather_importance = per_pixel as u32;
            uniforms.gather_guided = (per_pixel && settings.gather_guiding) as u32;
        }
        Band { uniforms, fixed, next_row: 0 }
    }

    /// The iteration's pipeline over the next `rows` rows (all that are left at most), added
    /// to `passes`' film; true when the iteration is done.
    fn encode(&mut self, t: &Target, passes: &mut ImagePasses, directions: u32, rows: u32) -> Result<bool> {
        let [w, h] = self.uniforms.resolution;
        let y0 = self.next_row;
        let rows = rows.min(h - y0);
        (self.uniforms.band_y0, self.uniforms.band_rows) = (y0, rows);
        t.frame.write(t.gpu, &self.uniforms);
        let ctx = FrameContext {
            gpu: t.gpu,
            scene: t.scene,
            frame: t.frame,
            map: t.map,
            width: w,
            height: h,
            y0,
            rows,
            iteration: self.uniforms.iteration,
            directions,
            fixed: self.fixed,
        };
        let mut enc = t.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("iteration") });
        let p = passes;
        // 1. Eye pass: the visible point of each pixel, at this iteration's jitter (G-buffer),
        //    rasterized whole with the first band; through mirrors and glass to the first
        //    surface that is not purely specular (eye paths). The guides' tables are made
        //    then from what the iterations before learned, at iterations 1, 2, 4, 8 …: every
        //    band of an iteration (its direct light and its gather alike) reads the same
        //    tables, and each aligned run of 2^m iterations one table, so that the pixels'
        //    Sobol' points stay stratified through the guided warps ([`crate::passes::sky_guide`]).
        if y0 == 0 {
            if let Some(build) = p.guide_build.as_ref().filter(|_| self.uniforms.iteration.is_power_of_two()) {
                build.encode(&mut enc, t.gpu.profiler.as_ref());
            }
            if !p.gbuffer.timed(&ctx)? {
                p.gbuffer.encode(&mut enc, &ctx)?;
            }
        }
        if let Some(specular) = &mut p.specular {
            specular.encode(&mut enc, &ctx)?;
        }
        // 2. Emission + direct light with soft shadows at the visible points → film (direct);
        //    first, once per view, which pixels straddle an emitter's edge: their emission is
        //    supersampled.
        if let Some(edges) = &mut p.emitter_edges {
            let mut keys = t.frame.edge_keys.get();
            edges.encode(&mut enc, &ctx, &mut keys)?;
            t.frame.edge_keys.set(keys);
        }
        p.direct.encode(&mut enc, &ctx)?;
        // Debug view: the photon map's radiance at the visible points → film (photon view).
        if let Some(view) = &mut p.photon_view {
            view.encode(&mut enc, &ctx)?;
        }
        // 3. Caustics: the light that came through mirrors and glass, from the caustic map.
        if let Some(caustics) = &mut p.caustics {
            caustics.encode(&mut enc, &ctx)?;
        }
        // 4. Final gather along the iteration's directions for every visible point, reading
        //    the photon map where the directions land → film (indirect).
        if let Some(gather) = &mut p.gather {
            gather.encode(&mut enc, &ctx)?;
        }
        // 5. Denoiser guides (when enabled): the visible points' albedo, normal, distance and
        //    the moments of what this iteration added to the film.
        if let Some(d) = &mut p.denoise {
            d.guides.encode(&mut enc, &ctx)?;
        }
        // 6. Accumulate: every pass above added its estimate to the film's sums.
        t.gpu.queue.submit([enc.finish()]);
        self.next_row = y0 + rows;
        Ok(self.next_row >= h)
    }
}

/// The photon budget of a render with these settings ([`RenderSettings::photon_budget`]):
/// balanced where the passes' length is not given (`pass_iterations` 0) and the map changes
/// (more than one pass); `fresh` for a new renderer, whose film and first pass are untouched.
fn new_budget(
    gpu: &Gpu,
    settings: &RenderSettings,
    film: &Film,
    photons: Option<&mut PhotonPasses>,
    fresh: bool,
) -> Option<Budget> {
    let photons = photons.filter(|p| p.progressive())?;
    let balanced = settings.pass_iterations == 0
        && settings.photon_budget == PhotonBudget::Balanced
        && crate::gpu::READ_BACK_BLOCKS;
    balanced.then(|| Budget::new(gpu, &film.accumulation, film.width * film.height, photons, fresh))
}

impl Progressive for Renderer {
    fn name(&self) -> &'static str {
        "rastergi photon map + final gather"
    }
    fn settings(&self) -> &RenderSettings {
        Renderer::settings(self)
    }
    fn iterate(&mut self) -> Result<()> {
        Renderer::iterate(self)
    }
    fn iterate_rows(&mut self, rows: u32) -> Result<bool> {
        Renderer::iterate_rows(self, rows)
    }
    fn rows_ahead(&self) -> u32 {
        Renderer::rows_ahead(self)
    }
    fn iterate_preview_rows(&mut self, scale: u32, rows: u32) -> Result<Option<bool>> {
        Renderer::iterate_preview_rows(self, scale, rows).map(Some)
    }
    fn preview_film(&self, scale: u32) -> Option<&Film> {
        Renderer::preview_film(self, scale)
    }
    fn encode_resolve_blend(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        shown: (Show, f32),
        preview: Option<(u32, f32)>,
    ) {
        Renderer::encode_resolve_blend(self, enc, shown, preview)
    }
    fn encode_resolve_upscaled(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        shown: (Show, f32),
        preview: Option<(u32, f32)>,
    ) -> bool {
        Renderer::encode_resolve_upscaled(self, enc, shown, preview)
    }
    fn reproject(&mut self) -> Result<bool> {
        Renderer::reproject(self)
    }
    fn set_photon_steps(&mut self, on: bool) {
        Renderer::set_photon_steps(self, on)
    }
    fn photons_pending(&self) -> Option<(u32, u32)> {
        Renderer::photons_pending(self)
    }
    fn refit_photon_region(&mut self) -> Result<bool> {
        Renderer::refit_photon_region(self)
    }
    fn photon_step(&mut self, photons: u32) -> Result<bool> {
        Renderer::photon_step(self, photons)
    }
    fn wait(&self) -> Result<()> {
        Renderer::wait(self)
    }
    fn rays_traced(&self) -> Result<Option<crate::gpu_scene::RaysTraced>> {
        self.scene.rays_traced(&self.gpu)
    }
    fn samples(&self) -> u32 {
        Renderer::samples(self)
    }
    fn camera(&self) -> Camera {
        Renderer::camera(self)
    }
    fn set_camera(&mut self, camera: Camera) -> Result<()> {
        Renderer::set_camera(self, camera)
    }
    fn reset(&mut self) {
        Renderer::reset(self)
    }
    fn film(&self) -> &Film {
        Renderer::film(self)
    }
    fn has(&self, show: Show) -> bool {
        show != Show::PhotonMap || self.settings().show_photon_map
    }
    fn encode_resolve(&self, enc: &mut wgpu::CommandEncoder, show: Show, exposure: f32) {
        Renderer::encode_resolve(self, enc, show, exposure)
    }
    fn read_linear(&self, show: Show) -> Result<LinearImage> {
        Renderer::read_linear(self, show)
    }
    fn read_display(&self, show: Show, exposure: f32) -> Result<DisplayImage> {
        Renderer::read_display(self, show, exposure)
    }
    fn progress(&self) -> Progress {
        Renderer::progress(self)
    }
    fn film_state(&self) -> Result<FilmState> {
        Renderer::film_state(self)
    }
    fn resume(&mut self, progress: &Progress, film: &FilmState) -> Result<()> {
        Renderer::resume(self, progress, film)
    }
    fn resize(&mut self, width: u32, height: u32) -> Result<bool> {
        Renderer::resize(self, width, height)?;
        Ok(true)
    }
    fn photon_pass_and_gather(&self) -> Option<(u32, GatherMethod)> {
        Some((self.photon_pass(), self.gather_method()))
    }
    fn denoising(&self) -> Option<&dyn Denoising> {
        Some(self)
    }
    fn denoising_mut(&mut self) -> Option<&mut dyn Denoising> {
        Some(self)
    }
}

impl Denoising for Renderer {
    /// Accumulates the denoiser's guides from the next iteration on (a per-pixel pass after
    /// the others; the image itself is unchanged) so that [`read_denoised`](Denoising::read_denoised),
    /// [`read_guides`](Denoising::read_guides) can be called. Enable it before the first iteration:
    /// the guides hold the iterations since (the viewer, turning it on mid-render, restarts the
    /// image). Fails where the image's extra buffers
    /// ([`crate::passes::denoise::LARGEST_BUFFER_PER_PIXEL`]) exceed the GPU's limits.
    fn enable_denoiser(&mut self) -> Result<()> {
        self.passes.enable_denoiser(&self.gpu, &self.scene, &self.frame)?;
        self.denoise = true;
        Ok(())
    }
    /// Whether the denoiser's guides are accumulated ([`enable_denoiser`](Denoising::enable_denoiser)).
    fn denoiser_enabled(&self) -> bool {
        self.denoise
    }
    /// The denoised full image ([`crate::passes::denoise`]), linear RGB.
    fn read_denoised(&self, params: &DenoiseParams) -> Result<LinearImage> {
        let d = self.denoiser()?;
        let angle = crate::passes::denoise::pixel_angle(&self.camera, self.settings.height);
        d.denoiser.apply(&self.gpu, (self.passes.film.samples, d.guides.samples), angle, params)
    }
    /// Encodes the denoiser into `enc` without reading it back: its output image holds the
    /// filtered image once `enc` has run (timing; the window, with
    /// [`encode_resolve_denoised`](Self::encode_resolve_denoised)).
    fn encode_denoise(&self, enc: &mut wgpu::CommandEncoder, params: &DenoiseParams) -> Result<()> {
        let d = self.denoiser()?;
        let angle = crate::passes::denoise::pixel_angle(&self.camera, self.settings.height);
        d.denoiser.encode(&self.gpu, enc, (self.passes.film.samples, d.guides.samples), angle, params);
        Ok(())
    }
    fn denoise_stages(&self, params: &DenoiseParams) -> Result<usize> {
        Ok(self.denoiser()?.denoiser.stages(params))
    }
    fn submit_denoise_rows(&self, params: &DenoiseParams, step: (usize, std::ops::Range<u32>)) -> Result<()> {
        let d = self.denoiser()?;
        let angle = crate::passes::denoise::pixel_angle(&self.camera, self.settings.height);
        let mut enc =
            self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("denoise step") });
        d.denoiser.encode_rows(&self.gpu, &mut enc, (self.passes.film.samples, d.guides.samples), angle, params, step);
        self.gpu.queue.submit([enc.finish()]);
        Ok(())
    }
    fn encode_resolve_denoised(&self, enc: &mut wgpu::CommandEncoder, exposure: f32) -> Result<()> {
        let d = self.denoiser()?;
        self.passes.film.encode_resolve_image(&self.gpu, enc, &d.resolve, exposure);
        Ok(())
    }
    /// The display encoding of the denoised full image (filtered now): 2^exposure · value,
    /// clamped to [0,1], sRGB, 8 bits, as [`read_display`](Self::read_display) of the raw one.
    fn read_display_denoised(&self, params: &DenoiseParams, exposure: f32) -> Result<DisplayImage> {
        let mut enc =
            self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("denoise") });
        self.encode_denoise(&mut enc, params)?;
        self.encode_resolve_denoised(&mut enc, exposure)?;
        self.gpu.queue.submit([enc.finish()]);
        self.passes.film.read_display_buffer(&self.gpu)
    }
    /// The denoiser's guide sums read back: the albedo and normal AOVs
    /// ([`GuideState::albedo`], [`GuideState::normal`]).
    fn read_guides(&self) -> Result<GuideState> {
        self.denoiser()?.guides.read(&self.gpu)
    }
}
