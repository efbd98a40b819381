//! Final gather: per iteration a few directions ω per visible point, the nearest surface along
//! each found by one of several implementations of the same estimator ([`estimator`]).
//!
//! * Shared directions ([`GatherDirections::Shared`], every implementation): each ω is shared
//!   by all visible points at once (Hachisuka, GPU Gems 2, ch. 38). [`DirectionSampler`]:
//!   ω_j = S(P(j; s)), P the Owen-scrambled 2D Sobol' sequence of
//!   [`crate::sampling::sobol_owen_2d`] with a scramble seed s drawn per restart and S the
//!   uniform map to the sphere (pdf 1/4π). Iteration i with K directions takes j = i·K …
//!   i·K + K − 1: an aligned block, a (0, 2, 2)-net for K = 4 (the Halton (5, 7) points used
//!   before nearly lie on a line in such a batch), and consecutive blocks keep stratifying.
//!   Estimate (ρ_x/π) · L(h → x) · max(0, n_x·ω) · 4π.
//! * Per-pixel directions ([`GatherDirections::PerPixel`], the traced gather only): pixel
//!   (x, y) takes the Owen-scrambled 2D Sobol' points u_j = P(j; s_xy) of
//!   [`crate::sampling::sobol_owen_2d`], j = i·K … i·K + K − 1, with its own scramble seed
//!   s_xy = [`crate::sampling::pixel_seed`]`(key, x, y)` (the key drawn per restart), each mapped
//!   to a direction about the visible point's normal with pdf cos θ/π (Malley's method).
//!   Every aligned block of 2^m indices is a (0, m, 2)-net, so an iteration's K = 4 directions
//!   are stratified 2 × 2 and the iterations keep stratifying; neighbouring pixels are
//!   uncorrelated, so the image has noise instead of the shared directions' streaks.
//!   Estimate ρ_x · L(h → x): the cosine and 1/π cancel against the pdf.
//! * Nearest surface h along ω from each visible point x (t > ε, x's own triangle excluded), a
//!   [`Gather`] implementation: [`GatherMethod::Raster`] depth-peels an orthographic ray view
//!   ([`ray_view`]) and projects each layer onto the visible points ([`raster`]);
//!   [`GatherMethod::Lists`] rasterizes the ray view once into per-texel fragment lists that
//!   each visible point walks ([`lists`]); [`GatherMethod::Trace`] casts the ray through the
//!   BVH in a compute shader ([`trace`]). They differ only where a ray-view texel is crossed by
//!   a silhouette (the raster gathers take the texel's surface).
//! * Estimate ([`estimator`]): as above per mode, L(h → x) = (ρ_h/π) · E(h) from the photon map.
//!
//! Several directions per iteration share one G-buffer and direct pass (`--directions`): the
//! indirect estimate, by far the noisier, gets more samples per unit of time.
//!
//! [`GatherMethod::Auto`] lets the first iterations alternate between the implementations and
//! keeps the fastest on this adapter; every one of those iterations counts towards the image.
//! A new implementation is a module with a type implementing [`Gather`], a [`GatherMethod`]
//! variant and one arm in [`build`].

pub mod estimator;
pub mod lists;
pub mod raster;
pub mod ray_view;
pub mod trace;

use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};

pub use estimator::{GatherInputs, GatherSample, GatherSetup, GatherUniforms, PixelSamples};

use crate::error::Result;
use crate::frame::FrameBinding;
use crate::gpu::Gpu;
use crate::gpu_scene::GpuScene;
use crate::photons::gpu::GpuPhotonMap;
use crate::sampling::{Rng, pcg_hash, sobol_owen_2d, stream, uniform_sphere, unit_f32};

pub use crate::consts::MAX_DIRECTIONS;

/// How the nearest surface along the gather direction is found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GatherMethod {
    /// Time the implementations on the first iterations and keep the fastest.
    #[default]
    Auto,
    /// Depth-peeled orthographic ray view (rasterization).
    Raster,
    /// Per-texel fragment lists of the ray view in one raster pass (no read-back).
    Lists,
    /// BVH ray casting in a compute shader.
    Trace,
}

/// Whose directions the traced gather casts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GatherDirections {
    /// Each pixel its own K cosine-distributed directions from an Owen-scrambled Sobol'
    /// sequence (the traced gather; the raster gathers and `Auto` always share). The default:
    /// no streaks, and on the Cornell box at 128² (lavapipe) 2.2–2.6× less error² per
    /// iteration; an iteration costs 2.5× as much (every ray is cast), so in time it leads
    /// early and is level with shared by 20–27 s (README, performance).
    #[default]
    PerPixel,
    /// The iteration's K directions, uniform on the sphere, shared by every pixel.
    Shared,
}

/// Where the light reflected at a gather hit h comes from: L(h → x) = ρ_h/π · E(h).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HitLight {
    /// E(h) read from the photon map (direct and indirect alike): no ray beyond the gather's.
    #[default]
    Map,
    /// E(h) = the direct irradiance from one light sample with a shadow ray, plus the map's,
    /// which then holds indirect light only (photons deposit from their second surface on):
    /// the map's cell-sized blur then touches only light that has bounced twice.
    Exact,
}

/// One way of finding the nearest surface along an iteration's gather directions and adding
/// the estimate; each implementation owns its loop over the directions.
pub trait Gather: Send {
    /// Encodes the gather along every direction of `inputs.samples` (each estimate weighted
    /// 1/len) after the work already in `enc`. An implementation that reads a result back may
    /// submit `enc` and go on in a new encoder, which it leaves in `enc`.
    /// Reads: scene, frame, G-buffer, photon map, gather uniforms. Adds to: the film's
    /// indirect component.
    fn encode(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) -> Result<()>;
}

/// The implementations `Auto` chooses among, in trial order.
const CANDIDATES: [GatherMethod; 3] = [GatherMethod::Raster, GatherMethod::Lists, GatherMethod::Trace];

/// [`GatherMethod::Auto`] keeps the traced gather unless another is this many times faster.
pub const PREFER_TRACE: f64 = 1.25;

/// Iterations of each method timed by [`GatherMethod::Auto`] before it chooses.
pub const AUTO_TRIALS: u32 = 3;

/// Iterations after which [`GatherMethod::Auto`] has chosen, at most (candidates more than
/// twice as slow as the fastest are dropped after their first run).
pub const AUTO_ITERATIONS: u32 = CANDIDATES.len() as u32 * AUTO_TRIALS;

/// Builds the implementation `method` (not `Auto`) for a `bundle`² ray view, reading the
/// gather's `uniforms`.
fn build(
    method: GatherMethod,
    gpu: &Gpu,
    setup: &GatherSetup,
    uniforms: &wgpu::Buffer,
    bundle: u32,
) -> Result<Box<dyn Gather>> {
    Ok(match method {
        GatherMethod::Raster => Box::new(raster::RasterGather::new(gpu, setup, uniforms, bundle)?),
        GatherMethod::Lists => Box::new(lists::ListGather::new(gpu, setup, uniforms, bundle)?),
        GatherMethod::Trace => Box::new(trace::TraceGather::new(gpu, setup, uniforms)),
        GatherMethod::Auto => unreachable!("Auto is a choice among the others"),
    })
}

/// The shared gather direction of index `i` for a restart whose scramble seed is `scramble`
/// ([`shared_scramble`]): the Owen-scrambled Sobol' point mapped uniformly to the sphere.
pub fn gather_direction(i: u32, scramble: u32) -> Vec3 {
    let [u1, u2] = sobol_owen_2d(i, scramble);
    uniform_sphere(unit_f32(u1), unit_f32(u2))
}

/// The scramble seed of the shared directions for the stream (seed, restart).
pub fn shared_scramble(seed: u32, restart: u32) -> u32 {
    pcg_hash(restart ^ pcg_hash(seed ^ stream::GATHER_SHARED))
}

/// The key of the per-pixel scramble seeds for the stream (seed, restart).
pub fn pixel_key(seed: u32, restart: u32) -> u32 {
    pcg_hash(restart ^ pcg_hash(seed ^ stream::GATHER_PIXEL))
}

/// Values that replace the sampler's for one iteration (tests compare the gathers with other
/// estimators for the same samples).
#[derive(Clone, Copy, Debug, Default)]
pub struct FixedSample {
    /// One direction ω instead of the iteration's.
    pub direction: Option<Vec3>,
    /// The ray view's sub-texel offset instead of a random one.
    pub texel_jitter: Option<Vec2>,
}

/// The gather's random choices: the scramble of the shared directions and the key of the
/// per-pixel ones, drawn anew at every restart, and the ray view's sub-texel offsets, from the
/// streams keyed by the seed.
#[derive(Clone, Copy, Debug)]
pub struct DirectionSampler {
    seed: u32,
    /// Restarts so far (camera moves, resizes).
    restart: u32,
}

impl DirectionSampler {
    pub fn new(seed: u32) -> DirectionSampler {
        DirectionSampler { seed, restart: 0 }
    }

    /// The key of the per-pixel scramble seeds of this restart ([`PixelSamples::key`]).
    pub fn pixel_key(&self) -> u32 {
        pixel_key(self.seed, self.restart)
    }

    /// A new image: new scrambles of the sequences.
    pub fn restart(&mut self) {
        self.restart += 1;
    }

    /// The `count` directions of `iteration` (one where `fixed` gives the direction), each
    /// with a uniform sub-texel offset in [-½, ½)².
    pub fn samples(&self, iteration: u32, count: u32, fixed: &FixedSample) -> Vec<GatherSample> {
        let k = if fixed.direction.is_some() { 1 } else { count.clamp(1, MAX_DIRECTIONS) };
        (0..k)
            .map(|j| {
                let index = iteration * k + j;
                let direction = fixed
                    .direction
                    .unwrap_or_else(|| gather_direction(index, shared_scramble(self.seed, self.restart)));
                let texel_jitter = fixed.texel_jitter.unwrap_or_else(|| {
                    let mut rng = Rng::new(self.seed ^ stream::TEXEL_JITTER, index, self.restart);
                    Vec2::new(rng.next_f32(), rng.next_f32()) - 0.5
                });
                GatherSample { direction: direction.normalize(), texel_jitter }
            })
            .collect()
    }
}

/// An implementation and, while `Auto` tries it, its trial times.
struct Candidate {
    method: GatherMethod,
    gather: Box<dyn Gather>,
    trials: Vec<Duration>,
}

/// The final gather pass: the directions, the implementations behind one interface, and the
/// choice among them.
pub struct GatherPass {
    pub bundle: u32,
    uniforms: wgpu::Buffer,
    sampler: DirectionSampler,
    /// Per-pixel directions: the traced gather asked for by name with
    /// [`GatherDirections::PerPixel`].
    per_pixel: bool,
    /// One implementation once chosen; `Auto`'s remaining candidates while it tries them.
    candidates: Vec<Candidate>,
    chosen: bool,
}

/// What the gather pass reads, besides the G-buffer and film it was built with.
#[derive(Clone, Copy)]
pub struct GatherFrame<'a> {
    pub scene: &'a GpuScene,
    pub frame: &'a FrameBinding,
    pub map: &'a GpuPhotonMap,
    pub width: u32,
    pub height: u32,
}

impl GatherPass {
    /// The pass over `setup`'s resources with `method`, for a `bundle`² ray view, drawing
    /// directions from `sampler`; `directions` applies to [`GatherMethod::Trace`] (the others,
    /// `Auto` included, share them).
    pub fn new(
        gpu: &Gpu,
        setup: &GatherSetup,
        bundle: u32,
        method: GatherMethod,
        directions: GatherDirections,
        sampler: DirectionSampler,
    ) -> Result<GatherPass> {
        let uniforms = gpu.zeroed_buffer(
            "gather uniforms",
            std::mem::size_of::<GatherUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let mut candidates = Vec::new();
        for m in CANDIDATES.into_iter().filter(|&m| method == m || method == GatherMethod::Auto) {
            match build(m, gpu, setup, &uniforms, bundle) {
                Ok(gather) => candidates.push(Candidate { method: m, gather, trials: Vec::new() }),
                // Auto does without a candidate that does not fit.
                Err(e) if method == GatherMethod::Auto => log::info!("gather: no {m:?} gather ({e})"),
                Err(e) => return Err(e),
            }
        }
        let per_pixel = method == GatherMethod::Trace && directions == GatherDirections::PerPixel;
        Ok(GatherPass { bundle, uniforms, sampler, per_pixel, candidates, chosen: method != GatherMethod::Auto })
    }

    /// The implementation in use (`Auto` while the trials run).
    pub fn method(&self) -> GatherMethod {
        if self.chosen { self.candidates[0].method } else { GatherMethod::Auto }
    }

    /// Whose directions are cast: per pixel, or shared by all.
    pub fn directions(&self) -> GatherDirections {
        if self.per_pixel { GatherDirections::PerPixel } else { GatherDirections::Shared }
    }

    /// The direction sampler (kept when the pass is rebuilt for a new image size).
    pub fn sampler(&self) -> DirectionSampler {
        self.sampler
    }

    /// A new image: new random choices.
    pub fn restart(&mut self) {
        self.sampler.restart();
    }

    /// Encodes the gather of `iteration` along `directions` directions (1 to
    /// [`MAX_DIRECTIONS`]; one where `fixed` gives it, and then shared by every pixel even in
    /// per-pixel mode) after the work already in `enc`; the encoder to go on with is left in
    /// `enc`.
    pub fn encode(
        &mut self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        f: &GatherFrame,
        iteration: u32,
        directions: u32,
        fixed: &FixedSample,
    ) -> Result<()> {
        let samples = self.sampler.samples(iteration, directions, fixed);
        let pixel_samples = (self.per_pixel && fixed.direction.is_none()).then(|| PixelSamples {
            key: self.sampler.pixel_key(),
            first_index: iteration.wrapping_mul(samples.len() as u32),
        });
        // A handle (reference counted): the trials below change `self`.
        let uniforms = self.uniforms.clone();
        let inputs = GatherInputs {
            scene: f.scene,
            frame: f.frame,
            map: f.map,
            width: f.width,
            height: f.height,
            samples: &samples,
            pixel_samples,
            uniforms: &uniforms,
            bundle: self.bundle,
        };
        if self.chosen {
            return self.candidates[0].gather.encode(gpu, enc, &inputs);
        }
        self.encode_trial(gpu, enc, &inputs)
    }

    /// One timed trial iteration of `Auto`: the work before the gather is finished first so the
    /// gather alone is timed; after [`AUTO_TRIALS`] of each, the fastest (median) is kept.
    fn encode_trial(&mut self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) -> Result<()> {
        // The candidate with the fewest trials so far, in order.
        let k =
            (0..self.candidates.len()).min_by_key(|&k| self.candidates[k].trials.len()).expect("a gather candidate");
        estimator::submit_and_renew(gpu, enc, "gather");
        gpu.wait()?;
        let start = Instant::now();
        self.candidates[k].gather.encode(gpu, enc, inputs)?;
        estimator::submit_and_renew(gpu, enc, "iteration");
        gpu.wait()?;
        self.candidates[k].trials.push(start.elapsed());
        // Once every candidate has run, drop those whose fastest run is slower than twice the
        // fastest run of all: the trials cost little beyond the winner's time.
        let fastest = |c: &Candidate| c.trials.iter().min().copied().unwrap_or(Duration::MAX);
        if self.candidates.iter().all(|c| !c.trials.is_empty()) {
            let best = self.candidates.iter().map(fastest).min().unwrap_or(Duration::MAX);
            self.candidates.retain(|c| fastest(c) <= 2 * best);
        }
        if self.candidates.iter().all(|c| c.trials.len() as u32 >= AUTO_TRIALS) {
            self.choose(gpu);
        }
        Ok(())
    }

    /// Keeps the candidate with the fastest median trial; the traced gather unless another is
    /// more than [`PREFER_TRACE`] times faster.
    fn choose(&mut self, gpu: &Gpu) {
        let median = |v: &[Duration]| {
            let mut v = v.to_vec();
            v.sort();
            v[v.len() / 2]
        };
        let times: Vec<(GatherMethod, Duration)> =
            self.candidates.iter().map(|c| (c.method, median(&c.trials))).collect();
        let (fastest, t_fastest) = *times.iter().min_by_key(|(_, t)| *t).expect("a gather candidate");
        // The traced gather is exact and needs no ray-view memory: a raster gather must win
        // clearly, so that timing noise does not flip the choice between runs.
        let method = match times.iter().find(|(m, _)| *m == GatherMethod::Trace) {
            Some(&(_, t_trace)) if t_trace.as_secs_f64() <= PREFER_TRACE * t_fastest.as_secs_f64() => {
                GatherMethod::Trace
            }
            _ => fastest,
        };
        let list: Vec<String> = times.iter().map(|(m, t)| format!("{m:?} {:.2} ms", t.as_secs_f64() * 1e3)).collect();
        log::info!("gather per iteration on {}: {}; using {method:?}", gpu.info.name, list.join(", "));
        self.candidates.retain(|c| c.method == method);
        self.chosen = true;
    }
}
