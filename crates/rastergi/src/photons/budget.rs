//! The photon budget: how many iterations each photon pass lasts, chosen by measurement
//! (`RenderSettings::photon_budget`, issue 57).
//!
//! Every iteration of a photon pass reads the same map, so the image's error has two parts:
//! the map's, which only fresh photons lower, and the iterations' own (the G-buffer's jitter,
//! the light samples, the gather's directions), which more iterations lower. A pass of N
//! photons and M iterations gives its mean image a variance (summed over the pixels)
//!
//! ```text
//!   a/N + W/M        at a cost   C + M·c
//! ```
//!
//! (a/N the map's: a map's variance falls as 1/N; W/M the iterations'; C the pass's tracing,
//! with its layout where the cells shrink; c an iteration). Over a render of time T the mean of
//! the passes has variance (a/N + W/M)·(C + M·c)/T, least at
//!
//! ```text
//!   M* = √(W·C / ((a/N)·c))
//! ```
//!
//! where the time splits evenly between what each term costs. A fixed rule misses it far: in a
//! room lit through its windows, at 96 × 72, the map's noise was 15 times the iterations' at the
//! fitted cadence of 2¹⁷ photons per 76 iterations (photons 13 times as many per iteration were
//! worth it), and the Cornell box at 128² wants about 3 times its photons per iteration.
//!
//! **Measured, not modelled.** At each pass's end a compute pass (`budget.wgsl`) sums over the
//! pixels (those that never saw light itself, as the error estimate takes them) the squared
//! difference between the pass's mean and the previous pass's. Their maps are independent and
//! their iterations nearly so, so
//!
//! ```text
//!   E[Σ (x_k − x_{k−1})²] = a·(1/N_k + 1/N_{k−1}) + W·(1/M_k + 1/M_{k−1}),
//! ```
//!
//! linear in the unknowns a and W: they are fitted by least squares to the last [`HISTORY`]
//! pairs of passes ([`fit`]). For both to be known the passes must differ: the first two
//! last [`FIRST_ITERATIONS`]·s (the first with a quarter of the photons), the third twice as
//! many, and after that every [`EXPLORE`]-th pass lasts twice (or half) the chosen length.
//! The start-up's scale s ([`startup_scale`]) makes each of these passes' iterations cost
//! about as much as tracing a pass of all the photons (estimated from the first pass's
//! tracing, timed, and its first [`FIRST_ITERATIONS`] iterations): knowing nothing yet of a
//! and W, passes whose tracing and iterations cost the same have at most twice the least
//! variance × time that any length could give ((a/N + W/M)(C + M·c) with M = C/c is
//! 2(a·C/N + W·c) ≤ 2(√(a·C/N) + √(W·c))²), where passes of a fixed 16 iterations, in a room
//! whose tracing costs 80 iterations, spend 5/6 of the start-up tracing. The costs are
//! wall-clock times on this GPU: C from a pass's tracing's start to its end (the GPU waited
//! for), c per iteration between a pass's start and its end. M* is rounded to a power of two in
//! [[`MIN_ITERATIONS`], [`MAX_ITERATIONS`]], so that noise in the timings seldom changes it (the
//! ceiling keeps the cells shrinking: the map's blur, a bias, goes with passes); where tracing
//! a pass costs more than [`TRACE_SHARE`] of 64 iterations the ceiling rises until it does not
//! ([`longest_pass`]: a scene whose map's variance is small would otherwise spend a third of
//! its time tracing, the staircase measured 1.8× slower than the fitted cadence at 16 s). The
//! iterations' samples are consecutive points of per-pixel Sobol' sequences, whose blocks are
//! slightly anti-correlated: W comes out a little high (as the film's error estimate does).
//!
//! A camera move clears the film: the pass under way and the next pair are not measured.

use super::passes::PhotonPasses;
use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu::{Gpu, compute_pipeline, shader};
use crate::gpu_scene::GpuScene;

/// Iterations of each of the first three passes, before the measurements choose (the third
/// lasts twice as long).
pub const FIRST_ITERATIONS: u32 = 16;
/// The fewest and most iterations a balanced pass lasts (the most where tracing a pass costs
/// no more than [`TRACE_SHARE`] of the pass: see [`longest_pass`]).
pub const MIN_ITERATIONS: u32 = 2;
pub const MAX_ITERATIONS: u32 = 64;
/// Where the map's variance is too small to call for short passes, the share of a pass's time
/// that tracing its photons may take: the ceiling rises above [`MAX_ITERATIONS`] until
/// tracing is at most this share (the staircase at 160 × 90: a pass of 2²¹ photons took
/// 2.5 s against 89 ms an iteration, a third of the time at 64 iterations a pass).
pub const TRACE_SHARE: f64 = 1.0 / 8.0;
/// The most iterations a pass lasts however costly its tracing.
pub const LONGEST_PASS: u32 = 1024;
/// The largest start-up scale: the third pass lasts at most [`LONGEST_PASS`] iterations.
pub const MAX_STARTUP_SCALE: u32 = LONGEST_PASS / (2 * FIRST_ITERATIONS);
/// Pairs of passes the fit uses.
pub const HISTORY: usize = 8;
/// Every EXPLORE-th pass after the first three lasts twice (or half) the chosen length.
pub const EXPLORE: u32 = 4;
const WORKGROUP: u64 = 64;

gpu_struct! {
    /// The budget pass's uniforms (`budget.wgsl`).
    pub(crate) struct BudgetUniforms as "Budget" {
        pub(crate) pixels: u32,
        /// The iterations of the pass that ends.
        pub(crate) iterations: f32,
        /// 1 where the previous pass's mean is in the snapshots.
        pub(crate) has_previous: u32,
        pub(crate) _pad: u32,
    }
}

/// The budget pass's bind group: the film read, the snapshots and the per-workgroup sums written.
pub fn group() -> Group {
    Group::compute(
        "photon budget",
        &[
            Slot::uniform::<BudgetUniforms>(0, "params"),
            Slot::read::<[f32; 4]>(1, "film"),
            Slot::write::<[f32; 4]>(2, "snapshots"),
            Slot::write::<[f32; 4]>(3, "partials"),
        ],
    )
}

/// The budget pass's composed shader.
pub fn source() -> String {
    shader::compose(&[&BudgetUniforms::wgsl(), include_str!("budget.wgsl")])
}

/// A pair of consecutive passes as measured: their photons and iterations, and the squared
/// difference of their means summed over the pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassPair {
    pub photons: [u32; 2],
    pub iterations: [u32; 2],
    pub squared_difference: f64,
}

/// The variance model's constants: a (the map's variance × its photons) and W (one iteration's
/// variance), both summed over the pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variances {
    pub map_times_photons: f64,
    pub iteration: f64,
}

/// Least squares of E[Σ(x_k − x_{k−1})²] = a·(1/N_k + 1/N_{k−1}) + W·(1/M_k + 1/M_{k−1})
/// over `pairs`: `None` where they do not tell a from W (all pairs alike). A negative estimate
/// is clamped at 0 (that part too small to measure).
pub fn fit(pairs: &[PassPair]) -> Option<Variances> {
    // In units of the first pair's photons, so the normal equations are well scaled.
    let unit = pairs.first()?.photons[1] as f64;
    let (mut uu, mut ux, mut xx, mut uy, mut xy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for p in pairs {
        let u = unit / p.photons[0].max(1) as f64 + unit / p.photons[1].max(1) as f64;
        let x = 1.0 / p.iterations[0].max(1) as f64 + 1.0 / p.iterations[1].max(1) as f64;
        let y = p.squared_difference;
        (uu, ux, xx, uy, xy) = (uu + u * u, ux + u * x, xx + x * x, uy + u * y, xy + x * y);
    }
    let det = uu * xx - ux * ux;
    if det.is_nan() || det <= 1e-6 * uu * xx {
        return None;
    }
    let a = (uy * xx - xy * ux) / det;
    let w = (xy * uu - uy * ux) / det;
    if !(a.is_finite() && w.is_finite()) {
        return None;
    }
    Some(Variances { map_times_photons: a.max(0.0) * unit, iteration: w.max(0.0) })
}

/// The iterations per pass of least variance per unit of time for a pass whose map adds
/// `map_variance` and whose iterations each `iteration_variance`, costing `pass_seconds` and
/// `iteration_seconds`: √(W·C / (V_map·c)) as a power of two (the nearest in log scale) within
/// [MIN_ITERATIONS, [`longest_pass`]].
pub fn balanced_iterations(
    map_variance: f64,
    iteration_variance: f64,
    pass_seconds: f64,
    iteration_seconds: f64,
) -> u32 {
    let longest = longest_pass(pass_seconds, iteration_seconds);
    let m = (iteration_variance * pass_seconds / (map_variance * iteration_seconds)).sqrt();
    if m.is_nan() || m <= 0.0 {
        return MIN_ITERATIONS;
    }
    if m.is_infinite() {
        return longest;
    }
    let m = 2f64.powi(m.log2().round() as i32);
    (m.clamp(MIN_ITERATIONS as f64, longest as f64)) as u32
}

/// The start-up's scale s: the power of two (nearest in log scale, in [1,
/// [`MAX_STARTUP_SCALE`]]) at which [`FIRST_ITERATIONS`]·s iterations of `iteration_seconds`
/// cost as much as tracing a pass, `pass_seconds`.
pub fn startup_scale(pass_seconds: f64, iteration_seconds: f64) -> u32 {
    let s = pass_seconds / (FIRST_ITERATIONS as f64 * iteration_seconds);
    if !(s.is_finite() && s > 1.0) {
        return 1;
    }
    (2f64.powi(s.log2().round() as i32) as u32).clamp(1, MAX_STARTUP_SCALE)
}

/// The ceiling of a balanced pass's iterations: [`MAX_ITERATIONS`] (the cells keep shrinking:
/// the map's blur, a bias, goes with passes), raised to the power of two at which tracing
/// (`pass_seconds`) takes at most [`TRACE_SHARE`] of the pass, at most [`LONGEST_PASS`].
pub fn longest_pass(pass_seconds: f64, iteration_seconds: f64) -> u32 {
    let m = pass_seconds * (1.0 - TRACE_SHARE) / (TRACE_SHARE * iteration_seconds);
    if !(m.is_finite() && m > MAX_ITERATIONS as f64) {
        return MAX_ITERATIONS;
    }
    (m.ceil() as u32).next_power_of_two().min(LONGEST_PASS)
}

/// The GPU side: snapshots of the film where a pass starts and the sums of its end
/// (`budget.wgsl`).
struct PassVariance {
    pixels: u32,
    uniforms: wgpu::Buffer,
    partials: wgpu::Buffer,
    workgroups: (u32, u32),
    bind_group: wgpu::BindGroup,
    /// `start`, `end`.
    pipelines: [wgpu::ComputePipeline; 2],
    /// Keeps the snapshots alive with the bind group.
    _snapshots: wgpu::Buffer,
}

impl PassVariance {
    /// Over the film `accumulation` of `pixels` pixels (its components as `passes::film` lays
    /// them out).
    fn new(gpu: &Gpu, accumulation: &wgpu::Buffer, pixels: u32) -> PassVariance {
        let device = &gpu.device;
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let n = (pixels as u64).div_ceil(WORKGROUP).max(1);
        let x = n.min(65535);
        let workgroups = (x as u32, n.div_ceil(x) as u32);
        let uniforms = gpu.zeroed_buffer(
            "photon budget uniforms",
            size_of::<BudgetUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let snapshots = gpu.zeroed_buffer("photon budget snapshots", pixels.max(1) as u64 * 16, rw);
        let partials = gpu.zeroed_buffer("photon budget sums", x * workgroups.1 as u64 * 16, rw);
        let (layout, bind_group) = group().layout_and_bind(
            device,
            &[
                ("params", uniforms.as_entire_binding()),
                ("film", accumulation.as_entire_binding()),
                ("snapshots", snapshots.as_entire_binding()),
                ("partials", partials.as_entire_binding()),
            ],
        );
        let module = shader::module(device, "photon budget", &source());
        let pipelines =
            ["start", "end"].map(|e| compute_pipeline(device, "photon budget", &module, e, &[&layout], &[]));
        PassVariance { pixels, uniforms, partials, workgroups, bind_group, pipelines, _snapshots: snapshots }
    }

    fn dispatch(&self, gpu: &Gpu, which: usize, iterations: u32, has_previous: bool) {
        let u = BudgetUniforms {
            pixels: self.pixels,
            iterations: iterations.max(1) as f32,
            has_previous: has_previous as u32,
            _pad: 0,
        };
        gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let mut enc =
            gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("photon budget") });
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipelines[which]);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(self.workgroups.0, self.workgroups.1, 1);
        }
        gpu.queue.submit([enc.finish()]);
    }

    /// Snapshot of the film where a pass starts whose previous pass was not measured.
    fn start(&self, gpu: &Gpu) {
        self.dispatch(gpu, 0, 1, false);
    }

    /// The end of a pass of `iterations`: (Σe², Σx, pixels counted), read back (waits for the
    /// GPU); the snapshots become the next pass's start.
    fn end(&self, gpu: &Gpu, iterations: u32, has_previous: bool) -> Result<[f64; 3]> {
        self.dispatch(gpu, 1, iterations, has_previous);
        let bytes = gpu.read_buffer(&self.partials, self.partials.size())?;
        let mut sums = [0.0f64; 3];
        for p in bytemuck::cast_slice::<u8, [f32; 4]>(&bytes) {
            for (s, v) in sums.iter_mut().zip(p) {
                *s += *v as f64;
            }
        }
        Ok(sums)
    }
}

/// One measured pass: its photons and iterations, and the costs.
#[derive(Clone, Copy, Debug)]
struct Pass {
    photons: u32,
    /// Its start's snapshot is in place (no camera move since).
    measured: bool,
    /// When its iterations began, and its tracing's cost.
    started: web_time::Instant,
    pass_seconds: Option<f64>,
    /// Σ of its iterations' light samples, and their count.
    light: (f64, u32),
}

/// The balanced budget of a render: the GPU's measurements and what they said so far.
pub struct Budget {
    gpu: PassVariance,
    current: Pass,
    /// The previous pass (photons, iterations), where its mean is in the snapshots.
    previous: Option<(u32, u32)>,
    pairs: Vec<PassPair>,
    /// Recent costs: seconds per pass's tracing, per iteration.
    pass_seconds: Vec<f64>,
    /// With the mean light samples its iterations drew.
    iteration_seconds: Vec<(f64, f64)>,
    /// The light samples of the iterations now and a light sample's cost, where the light
    /// budget measured it ([`crate::passes::light_budget`] changes the count as it goes).
    light_samples: Option<(u32, f64)>,
    /// Passes begun since the budget was made (the exploration's count).
    passes: u32,
    /// The length chosen for the passes that do not explore.
    chosen: u32,
    /// The start-up's scale ([`startup_scale`]), once the first pass has had
    /// [`FIRST_ITERATIONS`] (1 until then, and where the first pass was not timed).
    scale: Option<u32>,
}

impl Budget {
    /// Over the film `accumulation` of `pixels` pixels, for `photons`' passes: their current
    /// pass is measured where it has had no iteration yet and the film is empty (`fresh`: a new
    /// renderer), and lasts [`FIRST_ITERATIONS`] unless it has had more.
    pub fn new(gpu: &Gpu, accumulation: &wgpu::Buffer, pixels: u32, photons: &mut PhotonPasses, fresh: bool) -> Budget {
        let iterations = FIRST_ITERATIONS.max(photons.iterations_in_pass());
        photons.set_pass_iterations(iterations);
        Budget {
            gpu: PassVariance::new(gpu, accumulation, pixels),
            current: Pass {
                photons: photons.pass_photons(),
                measured: fresh && photons.iterations_in_pass() == 0,
                started: web_time::Instant::now(),
                pass_seconds: None,
                light: (0.0, 0),
            },
            previous: None,
            pairs: Vec::new(),
            pass_seconds: Vec::new(),
            iteration_seconds: Vec::new(),
            light_samples: None,
            passes: 1,
            chosen: FIRST_ITERATIONS,
            scale: None,
        }
    }

    /// The iteration that begins draws `k` light samples, each costing `sample_seconds` where
    /// that is measured ([`crate::passes::light_budget`]).
    pub fn set_light_samples(&mut self, k: u32, sample_seconds: Option<f64>) {
        self.light_samples = Some((k, sample_seconds.unwrap_or(0.0)));
        self.current.light = (self.current.light.0 + k as f64, self.current.light.1 + 1);
    }

    /// Recent seconds per iteration ([`iteration_costs`]).
    fn iteration_costs(&self) -> Vec<f64> {
        iteration_costs(&self.iteration_seconds, self.light_samples)
    }

    /// The film was cleared (a camera move): the pass under way is not measured.
    pub fn restart(&mut self) {
        self.current.measured = false;
        self.previous = None;
    }

    /// The pairs of passes measured so far.
    pub fn pairs(&self) -> &[PassPair] {
        &self.pairs
    }

    /// The start-up's scale ([`startup_scale`]), once the first pass has had
    /// [`FIRST_ITERATIONS`] iterations.
    pub fn startup(&self) -> Option<u32> {
        self.scale
    }

    /// The iterations of the passes that do not explore, as chosen so far.
    pub fn chosen(&self) -> u32 {
        self.chosen
    }

    /// Step 0 of an iteration (`Renderer::iterate`): the photon pass advances, as
    /// [`PhotonPasses::advance`] does; where the pass under way has had its iterations, its end
    /// is measured first and the next pass lasts as long as the measurements say.
    pub fn advance(&mut self, gpu: &Gpu, scene: &GpuScene, photons: &mut PhotonPasses) -> Result<()> {
        let done = photons.iterations_in_pass();
        if photons.pass_ends() && self.scale.is_none() {
            self.scale_startup(gpu, photons, done)?;
        }
        // Traced in steps, the next pass begins in `pass_traced`, once it is all traced.
        if !photons.pass_ends() || photons.stepped() {
            if done == 0 {
                self.current.started = web_time::Instant::now();
            }
            photons.advance(gpu, scene)?;
            return Ok(());
        }
        self.end_pass(gpu, done)?;
        let iterations = self.next_iterations();
        let began = web_time::Instant::now();
        // The pass under way ends (it has had its iterations), then the new one gets its
        // length: set before, a longer length would extend the pass under way instead.
        photons.advance(gpu, scene)?;
        photons.set_pass_iterations(iterations);
        gpu.wait()?;
        self.begin_pass(gpu, photons, began.elapsed().as_secs_f64());
        Ok(())
    }

    /// The first pass has had its [`FIRST_ITERATIONS`]: the start-up's scale s from their cost
    /// and the first pass's tracing, the first pass lengthened to `FIRST_ITERATIONS`·s (the
    /// next two follow in [`next_iterations`](Self::next_iterations)). Where the first pass was
    /// not measured from its start (a resumed render, a camera move) or not timed, s = 1.
    fn scale_startup(&mut self, gpu: &Gpu, photons: &mut PhotonPasses, done: u32) -> Result<()> {
        let mut scale = 1;
        if let (true, 0, Some(first)) =
            (self.current.measured && done > 0, photons.pass(), photons.first_pass_seconds())
        {
            gpu.wait()?;
            let iteration = self.current.started.elapsed().as_secs_f64() / done as f64;
            let pass = first * photons.next_pass_photons() as f64 / photons.pass_photons().max(1) as f64;
            scale = startup_scale(pass, iteration);
            log::info!(
                "photon budget: start-up passes of {} iterations (a pass's tracing estimated at {:.0} ms, an iteration {:.1} ms)",
                FIRST_ITERATIONS * scale,
                pass * 1e3,
                iteration * 1e3
            );
        }
        self.scale = Some(scale);
        if scale > 1 {
            photons.set_pass_iterations(FIRST_ITERATIONS * scale);
        }
        Ok(())
    }

    /// The pass `photons` is now in began, traced in `seconds`: measured from here.
    fn begin_pass(&mut self, gpu: &Gpu, photons: &PhotonPasses, seconds: f64) {
        if self.previous.is_none() {
            self.gpu.start(gpu);
        }
        self.passes += 1;
        self.current = Pass {
            photons: photons.pass_photons(),
            measured: true,
            started: web_time::Instant::now(),
            pass_seconds: Some(seconds),
            light: (0.0, 0),
        };
    }

    /// A pass traced in steps ([`PhotonPasses::trace_step`]) in `seconds` in all has become the
    /// current one after `done` iterations of the one before: as [`advance`](Self::advance)
    /// does at a pass's end, the end is measured and the new pass's length chosen.
    pub fn pass_traced(&mut self, gpu: &Gpu, photons: &mut PhotonPasses, done: u32, seconds: f64) -> Result<()> {
        self.end_pass(gpu, done)?;
        photons.set_pass_iterations(self.next_iterations());
        self.begin_pass(gpu, photons, seconds);
        Ok(())
    }

    /// The pass under way has had its `done` iterations: the squared difference of its mean and
    /// the previous pass's, and its costs (waits for the GPU).
    fn end_pass(&mut self, gpu: &Gpu, done: u32) -> Result<()> {
        let c = self.current;
        if !(c.measured && done > 0) {
            gpu.wait()?;
            self.previous = None;
            return Ok(());
        }
        let [e2, sum_x, pixels] = self.gpu.end(gpu, done, self.previous.is_some())?;
        let seconds = c.started.elapsed().as_secs_f64() / done as f64;
        keep_recent(&mut self.iteration_seconds, (seconds, c.light.0 / c.light.1.max(1) as f64));
        if let Some(s) = c.pass_seconds {
            keep_recent(&mut self.pass_seconds, s);
        }
        if let Some((photons, iterations)) = self.previous {
            self.pairs.push(PassPair {
                photons: [photons, c.photons],
                iterations: [iterations, done],
                squared_difference: e2,
            });
            if self.pairs.len() > HISTORY {
                self.pairs.remove(0);
            }
            let mean = sum_x / pixels.max(1.0);
            let relative = |v: f64| v / pixels.max(1.0) / (mean * mean).max(1e-30);
            log::info!(
                "photon budget: passes of {photons} and {} photons, {iterations} and {done} iterations: the means differ by {:.2} % (relative RMS); {}",
                c.photons,
                100.0 * relative(e2).sqrt(),
                match fit(&self.pairs) {
                    Some(v) => format!(
                        "fitted per pixel, relative to the mean: the map's variance {:.3e} at {} photons, an iteration's {:.3e}",
                        relative(v.map_times_photons / c.photons as f64),
                        c.photons,
                        relative(v.iteration)
                    ),
                    None => "not enough passes to tell the map's variance from the iterations'".into(),
                }
            );
        }
        self.previous = Some((c.photons, done));
        Ok(())
    }

    /// The next pass's iterations: the first three passes' fixed lengths, then the balanced
    /// length, twice or half of it every [`EXPLORE`]-th pass.
    fn next_iterations(&mut self) -> u32 {
        let k = self.passes;
        let first = FIRST_ITERATIONS * self.scale.unwrap_or(1);
        if k < 2 {
            return first;
        }
        if k == 2 {
            return 2 * first;
        }
        let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
        if let (Some(v), Some(cost), Some(c)) =
            (fit(&self.pairs), mean(&self.pass_seconds), mean(&self.iteration_costs()))
        {
            let photons = self.current.photons.max(1) as f64;
            self.chosen = balanced_iterations(v.map_times_photons / photons, v.iteration, cost, c);
            log::info!(
                "photon budget: {} iterations per pass (tracing {:.0} ms, an iteration {:.1} ms)",
                self.chosen,
                cost * 1e3,
                c * 1e3
            );
        }
        if k.is_multiple_of(EXPLORE) {
            let longest = match (mean(&self.pass_seconds), mean(&self.iteration_costs())) {
                (Some(cost), Some(c)) => longest_pass(cost, c),
                _ => MAX_ITERATIONS,
            };
            if self.chosen < longest { 2 * self.chosen } else { self.chosen / 2 }
        } else {
            self.chosen
        }
    }
}

/// Appends `v`, keeping the last [`HISTORY`].
/// The passes' seconds per iteration `(t, k̄)` (k̄ their iterations' mean light samples), each
/// as if its iterations had drawn the light samples `now` = (k, c), c a sample's cost:
/// t − (k̄ − k)·c, at least a tenth of t. The light budget's first iterations draw more, and
/// its choices change the count; the passes' costs would otherwise follow them.
fn iteration_costs(seconds: &[(f64, f64)], now: Option<(u32, f64)>) -> Vec<f64> {
    let extra = |mean: f64| now.map_or(0.0, |(k, c)| (mean - k as f64) * c);
    seconds.iter().map(|&(t, mean)| (t - extra(mean)).max(0.1 * t)).collect()
}

fn keep_recent<T>(values: &mut Vec<T>, v: T) {
    values.push(v);
    if values.len() > HISTORY {
        values.remove(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounded choice is the power of two of least (V_map + W/M)(C + M·c) among all of them
    /// in range, or within 7 % of it where the optimum lies between two; the unrounded one is
    /// the continuous optimum (brute force).
    #[test]
    fn an_iterations_cost_is_taken_at_the_light_samples_drawn_now() {
        // Passes of 8, 2 and a mix averaging 5.5 light samples at 0.5 ms each over a 9 ms rest.
        let passes = [(13e-3, 8.0), (10e-3, 2.0), (11.75e-3, 5.5)];
        for c in iteration_costs(&passes, Some((2, 0.5e-3))) {
            assert!((c - 10e-3).abs() < 1e-12, "{c}");
        }
        assert_eq!(iteration_costs(&passes, None), vec![13e-3, 10e-3, 11.75e-3]);
        // A light budget that has not timed a sample yet (cost 0) leaves them as measured.
        assert_eq!(iteration_costs(&passes, Some((1, 0.0))), vec![13e-3, 10e-3, 11.75e-3]);
    }

    #[test]
    fn the_balanced_iterations_minimise_the_variance_per_unit_of_time() {
        let cases = [(1.0, 1.0, 1.0, 1.0), (0.01, 5.0, 0.2, 0.01), (3.0, 0.1, 0.05, 0.02), (1e-2, 10.0, 0.5, 1e-2)];
        for (v_map, w, c_pass, c_it) in cases {
            let m = balanced_iterations(v_map, w, c_pass, c_it);
            let cost = |m: f64| (v_map + w / m) * (c_pass + m * c_it);
            let best = (MIN_ITERATIONS.ilog2()..=MAX_ITERATIONS.ilog2())
                .map(|k| 1u32 << k)
                .min_by(|&a, &b| cost(a as f64).total_cmp(&cost(b as f64)))
                .unwrap();
            let exact = (w * c_pass / (v_map * c_it)).sqrt();
            let brute = (1..=400_000).map(|i| i as f64 * 0.01).min_by(|a, b| cost(*a).total_cmp(&cost(*b))).unwrap();
            assert!((brute - exact).abs() <= 0.011 * exact.max(1.0), "{brute} against {exact}");
            assert!(m == best || cost(m as f64) <= cost(best as f64) * 1.07, "{m} against {best}");
        }
        assert_eq!(balanced_iterations(0.0, 1.0, 1.0, 1.0), MAX_ITERATIONS);
        assert_eq!(balanced_iterations(1.0, 0.0, 1.0, 1.0), MIN_ITERATIONS);
    }

    /// The start-up's length: tracing a pass and its iterations cost alike, which is never
    /// worse than twice the least variance × time of any length, for any split of the variance
    /// between the map and the iterations; rounded to a power of two (within √2 of it), never
    /// worse than 1 + √2 times (brute force). Where tracing costs less than 16 iterations, the
    /// start-up's 16 stay (as before the scale).
    #[test]
    fn the_startups_passes_cost_their_tracing_and_are_never_far_from_the_best() {
        assert_eq!(startup_scale(2.37, 0.03), 4); // `rooms`: 79 iterations' worth, 4.9 × 16
        assert_eq!(startup_scale(0.05, 0.01), 1);
        assert_eq!(startup_scale(0.24, 0.01), 2); // 1.5 × 16: log-nearest is 2 (√2 the boundary)
        assert_eq!(startup_scale(f64::NAN, 0.01), 1);
        assert_eq!(startup_scale(1.0, 0.0), 1);
        assert_eq!(startup_scale(1e3, 1e-3), MAX_STARTUP_SCALE);
        for (c_pass, c_it) in [(2.37, 0.03), (0.24, 0.01), (0.6, 0.002), (0.7, 0.03)] {
            let m = (FIRST_ITERATIONS * startup_scale(c_pass, c_it)) as f64;
            for (v_map, w) in [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1e-3, 1.0), (1.0, 1e-3), (0.2, 30.0)] {
                let cost = |m: f64| (v_map + w / m) * (c_pass + m * c_it);
                let best = (1..=200_000).map(|i| cost(i as f64 * 0.01)).fold(f64::INFINITY, f64::min);
                let at = |m: f64| format!("{c_pass} s, {c_it} s, V {v_map}, W {w}: {m} iterations");
                assert!(cost(c_pass / c_it) <= 2.0 * best * (1.0 + 1e-9), "{}", at(c_pass / c_it));
                assert!(cost(m) <= (1.0 + std::f64::consts::SQRT_2) * best, "{}", at(m));
            }
        }
    }

    /// Where the map's variance calls for long passes, the ceiling keeps tracing to at most
    /// an eighth of a pass: 64 iterations where tracing is cheap, more where it is dear (the
    /// staircase: 2.5 s a pass, 89 ms an iteration), never over 1024.
    #[test]
    fn costly_tracing_raises_the_ceiling_to_keep_its_share() {
        assert_eq!(longest_pass(0.1, 0.02), MAX_ITERATIONS);
        let m = longest_pass(2.532, 0.0888);
        assert_eq!(m, 256);
        assert!(2.532 / (2.532 + m as f64 * 0.0888) <= TRACE_SHARE);
        assert!(2.532 / (2.532 + (m / 2) as f64 * 0.0888) > TRACE_SHARE);
        assert_eq!(balanced_iterations(0.0, 1.0, 2.532, 0.0888), 256);
        assert_eq!(balanced_iterations(1e-9, 1.0, 2.532, 0.0888), 256);
        assert_eq!(longest_pass(100.0, 0.001), LONGEST_PASS);
        assert_eq!(longest_pass(f64::NAN, 0.0), MAX_ITERATIONS);
    }

    /// Pairs made from known a and W (with noise of 5 % on each squared difference) give them
    /// back; pairs that are all alike give nothing.
    #[test]
    fn the_fit_recovers_the_map_and_the_iterations_variances() {
        let (a, w) = (3.0e6, 40.0);
        let n = 1u32 << 20;
        let pair = |p: [u32; 2], m: [u32; 2], noise: f64| PassPair {
            photons: p,
            iterations: m,
            squared_difference: (a * (1.0 / p[0] as f64 + 1.0 / p[1] as f64)
                + w * (1.0 / m[0] as f64 + 1.0 / m[1] as f64))
                * (1.0 + noise),
        };
        let pairs = [
            pair([n / 4, n], [16, 16], 0.05),
            pair([n, n], [16, 32], -0.05),
            pair([n, n], [32, 8], 0.03),
            pair([n, n], [8, 8], -0.02),
        ];
        let v = fit(&pairs).unwrap();
        assert!((v.map_times_photons / a - 1.0).abs() < 0.15, "{v:?}");
        assert!((v.iteration / w - 1.0).abs() < 0.15, "{v:?}");
        let exact =
            fit(&pairs
                .map(|p| PassPair { squared_difference: pair(p.photons, p.iterations, 0.0).squared_difference, ..p }))
            .unwrap();
        assert!((exact.map_times_photons / a - 1.0).abs() < 1e-9 && (exact.iteration / w - 1.0).abs() < 1e-9);
        assert_eq!(fit(&[pair([n, n], [16, 16], 0.0), pair([n, n], [16, 16], 0.1)]), None);
        assert_eq!(fit(&[]), None);
    }
}
