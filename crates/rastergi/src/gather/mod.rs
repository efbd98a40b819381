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
//!   Bidirectional: x gathers along whichever of ±ω lies above its surface, w = sign(n_x·ω)·ω,
//!   uniform on its hemisphere (pdf 1/2π), so one ray view serves every point.
//!   Estimate (ρ_x/π) · L(h → x) · (n_x·w) · 2π.
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
//! keeps the one that lowers the error fastest on this adapter (see [`Efficiency`]): the
//! implementations differ in speed, and the traced gather's per-pixel directions also in
//! variance. Every one of those iterations counts towards the image.
//! A new implementation is a module with a type implementing [`Gather`], a [`GatherMethod`]
//! variant and one arm in [`build`].

mod directions;
pub mod estimator;
pub mod guide;
pub mod lists;
pub mod raster;
pub mod ray_view;
pub mod trace;

use std::time::Duration;

use web_time::Instant;

pub use directions::{DirectionSampler, gather_direction, pixel_key, shared_scramble};
pub use estimator::{GatherInputs, GatherSample, GatherSetup, GatherUniforms, PixelSamples};

use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu::consts::{FILM_DIRECT, FILM_INDIRECT};
use crate::passes::{FixedSample, FrameContext, IterationPass};

pub use crate::gpu::consts::MAX_DIRECTIONS;

/// How the nearest surface along the gather direction is found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GatherMethod {
    /// Try the implementations on the first iterations and keep the one whose error falls
    /// fastest: least variance × time per iteration. On a CPU adapter (lavapipe, WARP), which
    /// rasterizes in software, the traced gather without trials (see [`GatherPass::new`]).
    #[default]
    Auto,
    /// Depth-peeled orthographic ray view (rasterization).
    Raster,
    /// Per-texel fragment lists of the ray view in one raster pass (no read-back).
    Lists,
    /// BVH ray casting in a compute shader.
    Trace,
}

/// Whose directions the traced gather casts (the raster gathers always share; `Auto` tries
/// the traced gather with these directions against them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GatherDirections {
    /// Each pixel its own K cosine-distributed directions from an Owen-scrambled Sobol'
    /// sequence. The default: no streaks, and less error per iteration than shared
    /// directions (docs/performance.md).
    #[default]
    PerPixel,
    /// The iteration's K directions, uniform on the sphere, shared by every pixel: each
    /// point gathers along whichever of ±ω lies above its surface.
    Shared,
}

/// Where the light reflected at a gather hit h comes from: L(h → x) = ρ_h/π · E(h).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HitLight {
    /// E(h) read from the photon map (direct and indirect alike): no ray beyond the gather's.
    Map,
    /// E(h) = the direct irradiance from one light sample with a shadow ray, plus the map's,
    /// which then holds indirect light only (photons deposit from their second surface on):
    /// the map's cell-sized blur then touches only light that has bounced twice.
    Exact,
    /// E(h) = the direct irradiance of the punctual lights (points, spots and distant lights
    /// such as the sun) from one sample of them with a shadow ray, plus the map's, which holds
    /// the rest (the emitters' and the sky's direct light, and all that has bounced): a sun's
    /// sharp patches through windows are then exact at the hit instead of counted in cells,
    /// while the sky and area lights, which one light sample at a hit finds mostly blocked,
    /// stay the map's. The default: in the shared classroom under its `sunsky` and in Sponza
    /// under a sun and sky, 0.74 and 0.57 times the map's squared error at equal time; the
    /// same image as `Map` in a scene without punctual lights (docs/measurements.md).
    #[default]
    Punctual,
}

/// One way of finding the nearest surface along an iteration's gather directions and adding
/// the estimate; each implementation owns its loop over the directions. `Send` natively (it
/// is part of a [`crate::progressive::Progressive`] renderer), no bound on wasm32.
pub trait Gather: wgpu::WasmNotSend {
    /// Encodes the gather along every direction of `inputs.samples` (each estimate weighted
    /// 1/len) after the work already in `enc`. An implementation that reads a result back may
    /// submit `enc` and go on in a new encoder, which it leaves in `enc`.
    /// Reads: scene, frame, G-buffer, photon map, gather uniforms. Adds to: the film's
    /// indirect component.
    fn encode(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) -> Result<()>;
}

/// The implementations `Auto` chooses among, in trial order.
const CANDIDATES: [GatherMethod; 3] = [GatherMethod::Raster, GatherMethod::Lists, GatherMethod::Trace];

/// [`GatherMethod::Auto`] keeps the traced gather unless another lowers the error this many
/// times faster (its variance × time per iteration this many times smaller).
pub const PREFER_TRACE: f64 = 1.25;

/// [`GatherMethod::Auto`] drops a candidate whose first run is this many times slower than the
/// fastest: no estimator here has that much less variance than another.
const DROP_SLOWER: u32 = 3;

/// Iterations of each method timed by [`GatherMethod::Auto`] before it chooses.
pub const AUTO_TRIALS: u32 = 3;

/// Iterations after which [`GatherMethod::Auto`] has chosen, at most (candidates more than
/// [`DROP_SLOWER`] times as slow as the fastest are dropped after their first run).
pub const AUTO_ITERATIONS: u32 = CANDIDATES.len() as u32 * AUTO_TRIALS;

/// Storage buffers that the raster gathers' projection passes bind in their compute stage
/// (the scene, the visible points, the film, the photon map, and the ray view's layers or
/// lists): more than the 10 that browsers' WebGPU grants, where only the traced gather runs.
/// `tests/limits.rs` runs them on a device that allows exactly this many.
pub const RASTER_STORAGE_BUFFERS: u32 = 12;

/// Builds the implementation `method` (not `Auto`) for a `bundle`² ray view, reading the
/// gather's `uniforms`.
fn build(
    method: GatherMethod,
    gpu: &Gpu,
    setup: &GatherSetup,
    uniforms: &wgpu::Buffer,
    bundle: u32,
) -> Result<Box<dyn Gather>> {
    let allowed = gpu.device.limits().max_storage_buffers_per_shader_stage;
    if matches!(method, GatherMethod::Raster | GatherMethod::Lists) && allowed < RASTER_STORAGE_BUFFERS {
        return Err(crate::Error::Limits(format!(
            "the {method:?} gather binds {RASTER_STORAGE_BUFFERS} storage buffers in one shader stage and this GPU allows {allowed} (a web browser's WebGPU allows 8 or 10); use the trace gather"
        )));
    }
    Ok(match method {
        GatherMethod::Raster => Box::new(raster::RasterGather::new(gpu, setup, uniforms, bundle)?),
        GatherMethod::Lists => Box::new(lists::ListGather::new(gpu, setup, uniforms, bundle)?),
        GatherMethod::Trace => Box::new(trace::TraceGather::new(gpu, setup, uniforms)),
        GatherMethod::Auto => unreachable!("Auto is a choice among the others"),
    })
}

/// An implementation with its directions and, while `Auto` tries it, its trial times.
struct Candidate {
    method: GatherMethod,
    per_pixel: bool,
    gather: Box<dyn Gather>,
    trials: Vec<Duration>,
    /// The film's indirect increments of its trials.
    noise: PixelVariance,
}

/// Per-pixel running sums of one estimate over iterations, for its variance.
#[derive(Default)]
struct PixelVariance {
    /// The image's width (for the neighbours of a pixel).
    width: u32,
    n: u32,
    sum: Vec<f32>,
    sum_sq: Vec<f32>,
}

impl PixelVariance {
    fn new(width: u32) -> PixelVariance {
        PixelVariance { width, ..Default::default() }
    }

    /// Adds one iteration's estimate of every pixel.
    fn add(&mut self, values: &[f32]) {
        if self.n == 0 {
            self.sum = vec![0.0; values.len()];
            self.sum_sq = vec![0.0; values.len()];
        }
        for ((s, q), &v) in self.sum.iter_mut().zip(&mut self.sum_sq).zip(values) {
            *s += v;
            *q += v * v;
        }
        self.n += 1;
    }

    /// Σ over the pixels that `keep` keeps of the unbiased variance, (Σv² − (Σv)²/n)/(n − 1),
    /// and its degrees of freedom n − 1 (none before two iterations).
    fn total(&self, keep: &[bool]) -> Option<(f64, u32)> {
        if self.n < 2 {
            return None;
        }
        let n = f64::from(self.n);
        let ss: f64 = (self.sum.iter().zip(&self.sum_sq).zip(keep))
            .filter(|(_, k)| **k)
            .map(|((&s, &q), _)| f64::from(q) - f64::from(s).powi(2) / n)
            .sum();
        Some((ss.max(0.0) / (n - 1.0), self.n - 1))
    }

    /// The pixels to keep: all but those whose mean is over `factor` times the image's mean,
    /// and their 8 neighbours ([`crate::metrics::emitter_mask`]), or all where there are none.
    fn keep_all_but_brightest(&self, factor: f32) -> Vec<bool> {
        let pixels = self.sum.len();
        if self.n == 0 || pixels == 0 {
            return vec![true; pixels];
        }
        let mean: Vec<f32> = self.sum.iter().map(|&s| s / self.n as f32).collect();
        let image_mean = mean.iter().map(|&m| f64::from(m)).sum::<f64>() / pixels as f64;
        let width = self.width.max(1);
        let image = crate::image_io::LinearImage {
            width,
            height: (pixels as u32).div_ceil(width),
            pixels: mean.iter().map(|&m| [m; 3]).collect(),
        };
        crate::metrics::emitter_mask(&image, factor * image_mean as f32)
    }
}

/// What `Auto` measures of each candidate while trying it, to compare how fast each lowers
/// the error. After T seconds an estimator of per-iteration variance σ² (summed over pixels)
/// whose iterations take t has error² ≈ σ²·t/T: the efficiency to maximise is 1/(σ²·t). With
/// σ² = σ²_direct + σ²_gather (the gather's: all it adds, the environment's share of the
/// direct light through its escaping rays included) and t = t_rest + t_gather — the direct pass's noise and the
/// G-buffer and direct passes' time are the same for every candidate — each candidate's cost
/// is (σ²_direct + σ²_gather)·(t_rest + t_gather). σ² is the per-pixel sample variance of the
/// film's per-iteration increments, pooled over the candidates with the same directions
/// (raster, lists and shared trace are one estimator); the pixels' value is the mean of R, G
/// and B. Emitters are left out, as the error measures of `bench converge` leave them out:
/// pixels whose mean direct value is over [`EMITTER_FACTOR`] times the image's, and their
/// neighbours, whose noise (the light's edges under the pixel jitter) no gather changes.
#[derive(Default)]
struct Efficiency {
    /// The film's direct sums after the last trial's gather, while the film has not been
    /// cleared since (the next trial's before its gather minus these are one iteration's
    /// direct-pass estimates).
    last_direct: Option<Vec<f32>>,
    direct: PixelVariance,
    /// The time of the work before the gather in each trial iteration.
    rest: Vec<Duration>,
}

/// The mean of R, G and B of each pixel of component `c` in film sums read back.
fn film_component(bytes: &[u8], pixels: usize, c: usize) -> Vec<f32> {
    let sums: &[[f32; 4]] = bytemuck::cast_slice(bytes);
    sums[c * pixels..(c + 1) * pixels].iter().map(|v| (v[0] + v[1] + v[2]) / 3.0).collect()
}

/// [`Efficiency`] leaves out pixels this many times brighter than the image's mean (emitters).
const EMITTER_FACTOR: f32 = 16.0;

fn median(v: &[Duration]) -> Duration {
    let mut v = v.to_vec();
    v.sort();
    v[v.len() / 2]
}

/// The final gather pass: the directions, the implementations behind one interface, and the
/// choice among them.
pub struct GatherPass {
    pub bundle: u32,
    uniforms: wgpu::Buffer,
    sampler: DirectionSampler,
    /// Per-pixel directions: the traced gather with [`GatherDirections::PerPixel`], asked
    /// for by name or chosen by `Auto`.
    per_pixel: bool,
    /// One implementation once chosen; `Auto`'s remaining candidates while it tries them.
    candidates: Vec<Candidate>,
    chosen: bool,
    /// The settings asked for `Auto`.
    auto: bool,
    /// `Auto`: the film (its sums are read back after each trial) and the measurements.
    film: wgpu::Buffer,
    pixels: usize,
    efficiency: Efficiency,
}

impl GatherPass {
    /// The pass over `setup`'s resources with `method`, for a `bundle`² ray view, drawing
    /// directions from `sampler`; `directions` applies to [`GatherMethod::Trace`], and to
    /// the traced gather that `Auto` tries (the raster gathers share them).
    ///
    /// `Auto` on a CPU adapter takes the traced gather without trials unless `trials_on_cpu`:
    /// rasterization is emulated in software there, the traced gather won every trial measured
    /// on lavapipe (docs/performance.md), and the raster gathers' pipelines, compiled only for
    /// their trials, cost lavapipe minutes on a first run.
    pub fn new(
        gpu: &Gpu,
        setup: &GatherSetup,
        bundle: u32,
        method: GatherMethod,
        directions: GatherDirections,
        sampler: DirectionSampler,
        trials_on_cpu: bool,
    ) -> Result<GatherPass> {
        // Both read back from the GPU within an iteration (the peel's layer count, the trials'
        // timings), which a web page cannot wait for.
        if cfg!(target_arch = "wasm32") && matches!(method, GatherMethod::Auto | GatherMethod::Raster) {
            return Err(crate::Error::Gpu(format!(
                "the {method:?} gather reads back from the GPU within an iteration, which a web page cannot wait for; choose the lists or trace gather"
            )));
        }
        let uniforms = gpu.zeroed_buffer(
            "gather uniforms",
            std::mem::size_of::<GatherUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let auto = method == GatherMethod::Auto;
        let cpu = gpu.info.device_type == wgpu::DeviceType::Cpu;
        let tried = if auto && cpu && !trials_on_cpu { GatherMethod::Trace } else { method };
        let mut candidates = Vec::new();
        for m in CANDIDATES.into_iter().filter(|&m| tried == m || tried == GatherMethod::Auto) {
            let per_pixel = m == GatherMethod::Trace && directions == GatherDirections::PerPixel;
            match build(m, gpu, setup, &uniforms, bundle) {
                Ok(gather) => candidates.push(Candidate {
                    method: m,
                    per_pixel,
                    gather,
                    trials: Vec::new(),
                    noise: PixelVariance::new(setup.film.width),
                }),
                // Auto does without a candidate that does not fit.
                Err(e) if tried == GatherMethod::Auto => log::info!("gather: no {m:?} gather ({e})"),
                Err(e) => return Err(e),
            }
        }
        let chosen = tried != GatherMethod::Auto;
        if auto && chosen {
            log::info!("gather on {} (a CPU adapter): the traced gather, without trials", gpu.info.name);
        }
        let per_pixel = chosen && candidates[0].per_pixel;
        Ok(GatherPass {
            bundle,
            uniforms,
            sampler,
            per_pixel,
            candidates,
            chosen,
            auto,
            film: setup.film.accumulation.clone(),
            pixels: setup.film.width as usize * setup.film.height as usize,
            efficiency: Efficiency { direct: PixelVariance::new(setup.film.width), ..Default::default() },
        })
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
        // The film is cleared: the next trial's direct sums start afresh.
        self.efficiency.last_direct = None;
    }

    /// The directions per pixel that [`IterationPass::encode`] will gather along with the same
    /// arguments, and whether each point draws its own from its scattering (per-pixel; else
    /// uniform on the hemisphere): the direct pass weighs its environment samples against them
    /// ([`crate::passes::frame::FrameUniforms::gather_count`]).
    pub fn strategy(&self, directions: u32, fixed: &FixedSample) -> (u32, bool) {
        let count = if fixed.direction.is_some() { 1 } else { directions.clamp(1, MAX_DIRECTIONS) };
        let trial = (!self.chosen).then(|| self.next_candidate());
        let per_pixel = trial.map_or(self.per_pixel, |k| self.candidates[k].per_pixel);
        (count, per_pixel && fixed.direction.is_none())
    }

    /// The candidate `Auto` tries next: the one with the fewest trials so far, in order.
    fn next_candidate(&self) -> usize {
        (0..self.candidates.len()).min_by_key(|&k| self.candidates[k].trials.len()).expect("a gather candidate")
    }

    /// One measured trial iteration of `Auto` with candidate `k`: the work before the gather is
    /// finished (and timed) first, the film's sums read back, the gather run and timed alone,
    /// and the sums read again: their differences are this iteration's estimates
    /// ([`Efficiency`]). After [`AUTO_TRIALS`] of each candidate, the most efficient is kept.
    fn encode_trial(
        &mut self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        inputs: &GatherInputs,
        k: usize,
    ) -> Result<()> {
        let start = Instant::now();
        estimator::submit_and_renew(gpu, enc, "gather");
        gpu.wait()?;
        self.efficiency.rest.push(start.elapsed());
        let sums = 2 * self.pixels as u64 * 16;
        let before = gpu.read_buffer(&self.film, sums)?;
        let start = Instant::now();
        self.candidates[k].gather.encode(gpu, enc, inputs)?;
        estimator::submit_and_renew(gpu, enc, "iteration");
        gpu.wait()?;
        self.candidates[k].trials.push(start.elapsed());
        let after = gpu.read_buffer(&self.film, sums)?;

        // The direct pass's estimate: the direct sums since the previous trial's gather. The
        // gather's: what it added to both components (escaping rays add the environment's
        // share of the direct light).
        let e = &mut self.efficiency;
        let component = |sums: &[u8], c: u32| film_component(sums, self.pixels, c as usize);
        if let Some(last) = &e.last_direct {
            let increment: Vec<f32> = component(&before, FILM_DIRECT).iter().zip(last).map(|(a, b)| a - b).collect();
            e.direct.add(&increment);
        }
        e.last_direct = Some(component(&after, FILM_DIRECT));
        let total = |sums: &[u8]| -> Vec<f32> {
            component(sums, FILM_DIRECT).iter().zip(component(sums, FILM_INDIRECT)).map(|(d, i)| d + i).collect()
        };
        let increment: Vec<f32> = total(&after).iter().zip(total(&before)).map(|(a, b)| a - b).collect();
        self.candidates[k].noise.add(&increment);

        // Once every candidate has run, drop those whose fastest run is more than DROP_SLOWER
        // times the fastest run of all.
        let fastest = |c: &Candidate| c.trials.iter().min().copied().unwrap_or(Duration::MAX);
        if self.candidates.iter().all(|c| !c.trials.is_empty()) {
            let best = self.candidates.iter().map(fastest).min().unwrap_or(Duration::MAX);
            self.candidates.retain(|c| fastest(c) <= DROP_SLOWER * best);
        }
        if self.candidates.iter().all(|c| c.trials.len() as u32 >= AUTO_TRIALS) {
            self.choose(gpu);
        }
        Ok(())
    }

    /// Keeps the candidate of least cost (σ²_direct + σ²_gather)·(t_rest + t_gather)
    /// ([`Efficiency`]; median times, pooled variances); the traced gather unless another's
    /// cost is more than [`PREFER_TRACE`] times lower.
    fn choose(&mut self, gpu: &Gpu) {
        let e = &self.efficiency;
        let keep = e.direct.keep_all_but_brightest(EMITTER_FACTOR);
        let direct = e.direct.total(&keep).map_or(0.0, |(v, _)| v);
        let rest = median(&e.rest).as_secs_f64();
        // Σ of the squared deviations over Σ of the degrees of freedom, per directions mode.
        let pooled = |per_pixel: bool| {
            let (ss, dof) = (self.candidates.iter())
                .filter(|c| c.per_pixel == per_pixel)
                .filter_map(|c| c.noise.total(&keep))
                .fold((0.0, 0), |(ss, dof), (v, n)| (ss + v * f64::from(n), dof + n));
            if dof > 0 { ss / f64::from(dof) } else { f64::INFINITY }
        };
        let costs: Vec<f64> = (self.candidates.iter())
            .map(|c| (direct + pooled(c.per_pixel)) * (rest + median(&c.trials).as_secs_f64()))
            .collect();
        let best = (0..costs.len()).min_by(|&a, &b| costs[a].total_cmp(&costs[b])).expect("a gather candidate");
        // The traced gather is exact and needs no ray-view memory: a raster gather must win
        // clearly, so that noise in the measurements does not flip the choice between runs.
        let k = (0..costs.len())
            .find(|&k| self.candidates[k].method == GatherMethod::Trace && costs[k] <= PREFER_TRACE * costs[best])
            .unwrap_or(best);
        let list: Vec<String> = (self.candidates.iter().zip(&costs))
            .map(|(c, cost)| {
                let directions = if c.per_pixel { "per-pixel" } else { "shared" };
                let t = median(&c.trials).as_secs_f64() * 1e3;
                let v = pooled(c.per_pixel);
                format!("{:?} ({directions}) {t:.2} ms, variance {v:.3e}, cost {cost:.3e}", c.method)
            })
            .collect();
        log::info!(
            "gather on {}: rest of an iteration {:.2} ms, direct variance {direct:.3e}; {}; using {:?}{}",
            gpu.info.name,
            rest * 1e3,
            list.join("; "),
            self.candidates[k].method,
            if self.candidates[k].per_pixel { " with per-pixel directions" } else { "" }
        );
        self.keep(k);
    }

    /// Keeps candidate `k` alone: the choice is made.
    fn keep(&mut self, k: usize) {
        let chosen = self.candidates.swap_remove(k);
        self.per_pixel = chosen.per_pixel;
        self.candidates = vec![chosen];
        self.chosen = true;
        self.efficiency = Efficiency::default();
    }

    /// What `Auto` chose (`None` before its trials have ended, and where the settings fixed
    /// the gather): for checkpoints, so a resumed render gathers as the render before it.
    pub fn choice(&self) -> Option<(GatherMethod, GatherDirections)> {
        (self.chosen && self.auto).then(|| (self.candidates[0].method, self.directions()))
    }

    /// Makes `Auto`'s choice without trials (a resumed render's): `method` with `directions`.
    /// An error where this pass has no such candidate (it was not `Auto`, or the GPU cannot
    /// run it, or `Auto` chose another without trials on a CPU adapter).
    pub fn choose_as(&mut self, method: GatherMethod, directions: GatherDirections) -> Result<()> {
        let per_pixel = directions == GatherDirections::PerPixel;
        let k =
            self.candidates.iter().position(|c| c.method == method && c.per_pixel == per_pixel).filter(|_| self.auto);
        match k {
            Some(k) => {
                if !self.chosen {
                    self.keep(k);
                }
                Ok(())
            }
            None => Err(crate::error::Error::Checkpoint(format!(
                "the checkpoint's gather ({method:?}, {directions:?}) is not available here"
            ))),
        }
    }
}

impl IterationPass for GatherPass {
    /// Encodes the gather of the context's iteration along its directions (one where `fixed`
    /// gives it, and then shared by every pixel even in per-pixel mode) after the work already
    /// in `enc`; the encoder to go on with is left in `enc`. Nothing where the render has no
    /// photon map.
    fn encode(&mut self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext) -> Result<()> {
        let Some(map) = ctx.map else { return Ok(()) };
        let (iteration, fixed, gpu) = (ctx.iteration, &ctx.fixed, ctx.gpu);
        let samples = self.sampler.samples(iteration, ctx.directions, fixed);
        // While Auto tries them: the directions of the candidate whose turn it is.
        let trial = (!self.chosen).then(|| self.next_candidate());
        let per_pixel = trial.map_or(self.per_pixel, |k| self.candidates[k].per_pixel);
        let pixel_samples = (per_pixel && fixed.direction.is_none()).then(|| PixelSamples {
            key: self.sampler.pixel_key(),
            first_index: iteration.wrapping_mul(samples.len() as u32),
        });
        // A handle (reference counted): the trials below change `self`.
        let uniforms = self.uniforms.clone();
        let inputs = GatherInputs {
            scene: ctx.scene,
            frame: ctx.frame,
            map,
            width: ctx.width,
            height: ctx.height,
            rows: ctx.rows,
            samples: &samples,
            pixel_samples,
            first_index: iteration.wrapping_mul(samples.len() as u32),
            uniforms: &uniforms,
            bundle: self.bundle,
        };
        match trial {
            None => self.candidates[0].gather.encode(gpu, enc, &inputs),
            Some(k) => self.encode_trial(gpu, enc, &inputs, k),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn pixel_variance_matches_the_two_pass_sample_variance() {
        let (pixels, n) = (37usize, 5u32);
        let mut rng = Rng::new(11, 0, 0);
        let values: Vec<Vec<f32>> =
            (0..n).map(|_| (0..pixels).map(|p| p as f32 * 0.1 + 3.0 * rng.next_f32()).collect()).collect();
        let mut v = PixelVariance::new(pixels as u32);
        assert!(v.total(&vec![true; pixels]).is_none());
        values.iter().for_each(|it| v.add(it));
        let keep: Vec<bool> = (0..pixels).map(|p| p % 3 != 0).collect();
        let mut expected = 0.0f64;
        for p in (0..pixels).filter(|&p| keep[p]) {
            let mean = values.iter().map(|it| f64::from(it[p])).sum::<f64>() / f64::from(n);
            expected += values.iter().map(|it| (f64::from(it[p]) - mean).powi(2)).sum::<f64>() / f64::from(n - 1);
        }
        let (total, dof) = v.total(&keep).unwrap();
        assert_eq!(dof, n - 1);
        assert!((total - expected).abs() < 1e-4 * expected, "{total} against {expected}");
    }

    #[test]
    fn the_brightest_pixels_and_their_neighbours_are_left_out() {
        // A 6×4 image of ones with one emitter pixel at (4, 1) of 1000.
        let (w, h) = (6u32, 4u32);
        let mut image = vec![1.0f32; (w * h) as usize];
        image[(w + 4) as usize] = 1000.0;
        let mut v = PixelVariance::new(w);
        v.add(&image);
        let keep = v.keep_all_but_brightest(EMITTER_FACTOR);
        for y in 0..h {
            for x in 0..w {
                let near = (x as i32 - 4).abs() <= 1 && (y as i32 - 1).abs() <= 1;
                assert_eq!(keep[(y * w + x) as usize], !near, "pixel ({x}, {y})");
            }
        }
        // Without an outlier every pixel counts.
        let mut flat = PixelVariance::new(w);
        flat.add(&vec![2.0; (w * h) as usize]);
        assert!(flat.keep_all_but_brightest(EMITTER_FACTOR).iter().all(|&k| k));
    }
}
