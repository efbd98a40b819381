//! The light budget: how many light samples the direct pass ([`crate::passes::direct`]) draws per
//! pixel and iteration, chosen by measurement (`RenderSettings::light_balance`, issue 57).
//!
//! An iteration's estimate of a pixel is its direct light, drawn from k light samples, plus the
//! rest (the gather, and through it the photon map). Per iteration the image's variance
//! (summed over the pixels) and the iteration's cost are
//!
//! ```text
//!   D/k + R        at a cost   k·c + r
//! ```
//!
//! (D one light sample's variance, R the rest's, c a light sample's cost, r the rest of the
//! iteration's). Over a render of time T the mean has variance (D/k + R)·(k·c + r)/T, least at
//!
//! ```text
//!   k* = √(D·r / (R·c))
//! ```
//!
//! where the time splits evenly between what each part costs. One sample is far from it
//! where sun and sky come through windows: in the sky-lit room at 96 × 72 the direct light held
//! most of the image's squared error while its pass took 6 % of an iteration (four samples
//! reached 3.5 % in the time one took to reach 5.3 %); a lamp-lit room wants one or two.
//!
//! **Measured, not modelled.** One light sample's variance D: where an iteration draws k ≥ 2,
//! the direct pass adds each pixel's sample variance of its k estimates,
//! s² = (Σe² − (Σe)²/k)/(k − 1), to the film (`film_add_light_variance`), so D is their sum
//! over the pixels divided by those iterations. The pixel's jitter moves the visible point
//! from iteration to iteration (edges, textures), a variance J that more light samples do not
//! lower: the film's direct component over n iterations of k_i samples has variance
//! (n·J + D·Σ1/k_i)/n², estimated from its two halves as the error estimate does
//! ([`crate::passes::film`]), which gives J; the rest R is the indirect component's n·Var plus
//! J. (In the sunlit room the iterations' direct variance was twice the indirect's, yet almost
//! all of it jitter: the sun's disc is small; there one sample is best, and the iterations'
//! variance alone asked for eight.) The costs: after [`WARM_UP`] iterations ([`BEFORE`]
//! samples each, as until the first decision), [`TIMED`] iterations are timed with [`LOW`]
//! samples and [`TIMED`] with [`PROBE`] (each iteration waited for from after its photon pass
//! began to its end; the median of each set), so c = (t_P − t_L)/(P − L) and r = t_L − L·c.
//! At [`DECISIONS`] (iterations of the film) the film is read back and k* is chosen, a power
//! of two (the nearest in log scale) in [1, [`MOST`]]. Within an iteration the light samples
//! are stratified, which makes s² slightly high (E[s²] = k·(σ² − Var ē)/(k − 1)); D is taken
//! at most as large as the whole direct variance the film shows. The first photon pass's map
//! (a quarter of the photons) makes R high at the first decision; the later ones see the
//! render's own passes. Near k* the cost is flat (twice or half k* costs 6 % in time), so
//! powers of two lose little.
//!
//! The light samples stay one sequence: iteration i draws the points Σ_{j<i} k_j … of each
//! pixel's Owen-scrambled Sobol' sequence ([`crate::passes::frame::FrameUniforms::light_base`]),
//! so a pixel's samples are a prefix of it whatever the counts were; each iteration's estimate
//! is unbiased for any k, and so is the film's mean.

use crate::passes::film::{FilmState, Show};

/// Iterations before the timings (the first ones build pipelines and tables).
pub const WARM_UP: u32 = 4;
/// Iterations timed with [`LOW`] light samples, then with [`PROBE`].
pub const TIMED: u32 = 4;
/// Light samples of the two timed sets.
pub const LOW: u32 = 2;
pub const PROBE: u32 = 8;
/// Light samples of the iterations before the first decision that are not timed. The film's
/// mean weighs every iteration alike, so where many samples are best, early iterations of one
/// sample stay in the image's noise for long (in the sky-lit room 22 of them, of 236 in 6 s,
/// made the error at 6 s 30 % larger than 16 samples throughout), while where one is best,
/// each extra sample of these iterations is time lost before the image reaches a first
/// error (the sunlit room reaches 5 % within 2 s; four here and [`PROBE`] 8, [`TIMED`] 4, were
/// as good as or better than 8, 16 and 6 under both the sun and the sky at 1–3 s).
pub const BEFORE: u32 = 4;
/// The most light samples an iteration draws (the model counts the jitter's variance as the
/// light's: where the rest is nearly noise-free it would otherwise ask for ever more).
pub const MOST: u32 = 16;
/// The film's iterations at which the count is chosen again.
pub const DECISIONS: [u32; 5] = [32, 128, 512, 2048, 8192];

/// What an iteration costs: seconds per light sample, and for the rest of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Costs {
    pub sample: f64,
    pub rest: f64,
}

impl Costs {
    /// From the median times `low` of iterations with `l` light samples and `probe` of
    /// iterations with `p` > `l`: c = (t_p − t_l)/(p − l), at least 1 % of t_l (timing noise
    /// may make the difference vanish; a light sample is never free), r = t_l − l·c.
    pub fn from_timings((low, l): (f64, u32), (probe, p): (f64, u32)) -> Costs {
        let sample = ((probe - low) / p.saturating_sub(l).max(1) as f64).max(0.01 * low);
        Costs { sample, rest: (low - l as f64 * sample).max(0.01 * low) }
    }
}

/// The light samples of least variance per unit of time: √(D·r / (R·c)) as a power of two
/// (the nearest in log scale) in [1, [`MOST`]], for one sample's variance `direct`, the rest's
/// `rest` and the `costs`.
pub fn balanced_samples(direct: f64, rest: f64, costs: Costs) -> u32 {
    let k = (direct * costs.rest / (rest * costs.sample)).sqrt();
    if k.is_nan() || k <= 0.0 {
        return 1;
    }
    if k.is_infinite() {
        return MOST;
    }
    2f64.powi(k.log2().round() as i32).clamp(1.0, MOST as f64) as u32
}

/// The variances per iteration, summed over the pixels that never saw light (as
/// [`FilmState::error_estimate`] takes them), of a render whose film holds `film`: one light
/// sample's D and the rest's R (see the module's notes), where its iterations drew `varied`
/// times two or more light samples and Σ 1/k_i is `inverse`; `None` until both halves hold
/// iterations and some drew two.
pub fn variances(film: &FilmState, varied: u32, inverse: f64) -> Option<(f64, f64)> {
    let n = film.samples as f64;
    let (direct, indirect) = (film.variance_of_mean(Show::Direct)?.0, film.variance_of_mean(Show::Indirect)?.0);
    if varied == 0 || inverse <= 0.0 {
        return None;
    }
    // n²·Var(direct mean) = n·J + D·Σ1/k_i.
    let whole = direct * n * n;
    let one = (film.light_sample_variance() / varied as f64).min(whole / inverse);
    let jitter = (whole - one * inverse).max(0.0) / n;
    Some((one, indirect * n + jitter))
}

/// The light budget of a render: what was timed and chosen so far, and the light samples of
/// the film's iterations.
#[derive(Clone, Debug)]
pub struct LightBudget {
    /// Light samples of the iterations that are not timed.
    chosen: u32,
    /// The film's iteration where this budget's schedule starts: 0, or where a resumed render
    /// picked up (its timings come after that).
    origin: u32,
    /// A count was chosen, and a restart since: no more choices.
    decided: bool,
    settled: bool,
    /// Σ k and Σ 1/k over the film's iterations begun, and how many of them drew two or more.
    drawn: u32,
    inverse: f64,
    varied: u32,
    /// Seconds of the timed iterations with [`LOW`] samples and with [`PROBE`].
    low: Vec<f64>,
    probed: Vec<f64>,
    costs: Option<Costs>,
}

impl Default for LightBudget {
    fn default() -> Self {
        LightBudget::new()
    }
}

impl LightBudget {
    pub fn new() -> LightBudget {
        LightBudget {
            chosen: BEFORE,
            origin: 0,
            decided: false,
            settled: false,
            drawn: 0,
            inverse: 0.0,
            varied: 0,
            low: Vec::new(),
            probed: Vec::new(),
            costs: None,
        }
    }

    /// The light samples chosen so far (of the iterations that do not probe).
    pub fn chosen(&self) -> u32 {
        self.chosen
    }

    /// The costs as timed (`None` until they are).
    pub fn costs(&self) -> Option<Costs> {
        self.costs
    }

    /// The film was cleared: its light samples start again from the sequence's first point (a
    /// restart replays them, as with a fixed count); what was timed and chosen is kept, and
    /// once chosen the count is not chosen again (a viewer's camera moves would read the film
    /// back at every view's 32nd, 128th … iteration: a frame's stall each).
    pub fn restart(&mut self) {
        (self.drawn, self.inverse, self.varied, self.origin) = (0, 0.0, 0, 0);
        self.settled |= self.decided;
    }

    /// The film was restored with `samples` iterations of `k` light samples each (a checkpoint
    /// does not record them: `k` is the count the resumed render starts from); the schedule
    /// (timings, then choices) starts from there.
    pub fn resume(&mut self, samples: u32, k: u32) {
        let k = k.max(1);
        self.origin = samples;
        (self.drawn, self.inverse) = (samples.saturating_mul(k), samples as f64 / k as f64);
        self.varied = if k > 1 { samples } else { 0 };
    }

    /// The light samples of the film's `iteration`, which begins now and runs `whole` (at once,
    /// not in a viewer's row bands, which wait for frames and cannot be timed): (k, the index
    /// of its first sample in each pixel's sequence, whether to time it). Until a count is
    /// chosen, every film draws [`BEFORE`], [`LOW`] and [`PROBE`] at the same iterations (a
    /// restart replays the light samples of a fresh render, as with a fixed count), timed
    /// until the costs are known; an iteration in bands draws one sample until then (a viewer
    /// whose iterations never fit a frame keeps the count it had before the budget).
    pub fn begin(&mut self, iteration: u32, whole: bool) -> (u32, u32, bool) {
        // Until a count is chosen every film begins alike (a restart replays a fresh render's
        // light samples), timed while the costs are not known.
        let untimed = self.costs.is_none();
        let (k, timed) = match iteration.saturating_sub(self.origin).checked_sub(WARM_UP) {
            _ if self.decided => (self.chosen, false),
            _ if untimed && !whole => (1, false),
            Some(i) if i < TIMED => (LOW, untimed),
            Some(i) if i < 2 * TIMED => (PROBE, untimed),
            _ => (BEFORE, false),
        };
        let first = self.drawn;
        self.drawn = self.drawn.wrapping_add(k);
        self.inverse += 1.0 / k as f64;
        self.varied += (k > 1) as u32;
        (k, first, timed)
    }

    /// A timed iteration of `k` light samples took `seconds`; once both sets are timed the
    /// costs follow.
    pub fn timed(&mut self, k: u32, seconds: f64) {
        if self.costs.is_some() {
            return;
        }
        if k == LOW { &mut self.low } else { &mut self.probed }.push(seconds);
        if self.low.len() >= TIMED as usize && self.probed.len() >= TIMED as usize {
            let (low, probe) = (median(&mut self.low), median(&mut self.probed));
            self.costs = Some(Costs::from_timings((low, LOW), (probe, PROBE)));
        }
    }

    /// Whether the count is chosen again before the film's `iteration` (the film is read).
    pub fn decides_before(&self, iteration: u32) -> bool {
        self.costs.is_some() && !self.settled && DECISIONS.contains(&iteration)
    }

    /// Chooses the count from the film ([`variances`]) and the costs; returns it.
    pub fn decide(&mut self, film: &FilmState) -> u32 {
        let (Some(costs), Some((one_sample, rest))) = (self.costs, variances(film, self.varied, self.inverse)) else {
            return self.chosen;
        };
        let k = balanced_samples(one_sample, rest, costs);
        log::info!(
            "light budget at {} iterations: one light sample's variance {one_sample:.3e}, the rest's {rest:.3e}; a sample {:.3} ms, the rest {:.3} ms: {k} light samples",
            film.samples,
            1e3 * costs.sample,
            1e3 * costs.rest,
        );
        (self.chosen, self.decided) = (k, true);
        k
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The variance × time of k samples, the quantity the count minimises.
    fn work(direct: f64, rest: f64, c: Costs, k: u32) -> f64 {
        (direct / k as f64 + rest) * (k as f64 * c.sample + c.rest)
    }

    #[test]
    fn the_balanced_count_is_the_best_power_of_two_by_brute_force() {
        let mut checked = 0;
        for direct in [1e-3, 0.1, 1.0, 10.0, 300.0] {
            for rest in [1e-2, 1.0, 30.0] {
                for (sample, r) in [(0.6e-3, 15e-3), (5e-3, 5e-3), (1e-3, 200e-3)] {
                    let c = Costs { sample, rest: r };
                    let k = balanced_samples(direct, rest, c);
                    let best = (0..=4)
                        .map(|m| 1u32 << m)
                        .min_by(|&a, &b| work(direct, rest, c, a).total_cmp(&work(direct, rest, c, b)))
                        .unwrap();
                    // The work is D·c + R·r + 2√(D·r·R·c)·cosh(ln(k/k*)), symmetric in ln k: the
                    // nearest power of two in log scale is the best one.
                    let (w, wb) = (work(direct, rest, c, k), work(direct, rest, c, best));
                    assert!(w <= wb * (1.0 + 1e-9), "D {direct} R {rest} {c:?}: {k} against {best}");
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 45);
        // The extremes: a free rest or no direct variance wants one sample; none of the rest's
        // variance wants the most.
        assert_eq!(balanced_samples(0.0, 1.0, Costs { sample: 1.0, rest: 1.0 }), 1);
        assert_eq!(balanced_samples(1.0, 0.0, Costs { sample: 1.0, rest: 1.0 }), MOST);
    }

    #[test]
    fn costs_follow_from_the_two_timed_sets() {
        let c = Costs::from_timings((16e-3, 2), (16e-3 + 14.0 * 0.7e-3, 16));
        assert!((c.sample - 0.7e-3).abs() < 1e-12 && (c.rest - 14.6e-3).abs() < 1e-12, "{c:?}");
        // Noise making the probe no slower: a sample costs 1 % of an iteration, not nothing.
        let c = Costs::from_timings((10e-3, 2), (9e-3, 16));
        assert!((c.sample - 0.1e-3).abs() < 1e-12, "{c:?}");
    }

    #[test]
    fn the_light_samples_are_one_sequence_and_the_schedule_times_then_chooses() {
        let mut b = LightBudget::new();
        let mut next = 0;
        for i in 0..WARM_UP + 2 * TIMED + 4 {
            let (k, first, timed) = b.begin(i, true);
            assert_eq!(first, next, "iteration {i}");
            next += k;
            let probing = (WARM_UP + TIMED..WARM_UP + 2 * TIMED).contains(&i);
            let timing_low = (WARM_UP..WARM_UP + TIMED).contains(&i);
            assert_eq!(
                k,
                if probing {
                    PROBE
                } else if timing_low {
                    LOW
                } else {
                    BEFORE
                },
                "iteration {i}"
            );
            assert_eq!(timed, (WARM_UP..WARM_UP + 2 * TIMED).contains(&i), "iteration {i}");
            if timed {
                b.timed(k, 0.01 + 0.001 * k as f64);
            }
        }
        let c = b.costs().expect("timed");
        assert!((c.sample - 1e-3).abs() < 1e-9 && (c.rest - 0.01).abs() < 1e-9, "{c:?}");
        let inverse = TIMED as f64 / LOW as f64 + TIMED as f64 / PROBE as f64 + (WARM_UP + 4) as f64 / BEFORE as f64;
        assert!((b.inverse - inverse).abs() < 1e-9, "{} against {inverse}", b.inverse);
        assert!(b.decides_before(32) && !b.decides_before(33));
        // One pixel whose halves differ in the direct light only, by hand: per channel the
        // halves' means differ by 24/16 − 16/16 = ½, so n²·Var(direct mean) = 3·¼·16·16 = 192;
        // D = 96/16 = 6 (16 iterations drew two or more), Σ1/k = 4/2 + 4/8 + 8/4 = 4.5, so
        // J = (192 − 6·4.5)/32 = 5.16 is the rest (no indirect variance) and
        // k* = √(6·0.01/(5.16·0.001)) = 3.4: four.
        let comp = |d: f32, light: f32| [d, d, d, 0.0, 0.0, 0.0, 0.0, light, 0.0, 0.0, 0.0, 0.0];
        let film = FilmState {
            width: 1,
            height: 1,
            samples: 32,
            half_samples: 16,
            sums: comp(40.0, 32.0 * 3.0).to_vec(),
            half: comp(16.0, 16.0 * 3.0).to_vec(),
        };
        assert_eq!(b.decide(&film), 4);
        // A restart after a choice begins its sequence from the first point with the count
        // chosen, and chooses no more.
        b.restart();
        assert!(!b.decides_before(32));
        assert_eq!(b.begin(0, true), (4, 0, false));
        assert_eq!(b.begin(WARM_UP + TIMED, true), (4, 4, false));
        // Before a choice a restart replays a fresh render's counts, untimed once timed.
        let mut b = LightBudget::new();
        for i in 0..WARM_UP + 2 * TIMED {
            let (k, _, timed) = b.begin(i, true);
            if timed {
                b.timed(k, 0.01 + 0.001 * k as f64);
            }
        }
        assert!(b.costs().is_some());
        b.restart();
        let counts: Vec<_> = (0..WARM_UP + 2 * TIMED + 1).map(|i| b.begin(i, true)).collect();
        let mut fresh = LightBudget::new();
        let fresh: Vec<_> =
            (0..WARM_UP + 2 * TIMED + 1).map(|i| fresh.begin(i, true)).map(|(k, f, _)| (k, f, false)).collect();
        assert_eq!(counts, fresh);
        // A resumed render times its own iterations after the restored ones.
        let mut b = LightBudget::new();
        b.resume(100, 1);
        assert_eq!(b.begin(100 + WARM_UP, true), (LOW, 100, true));
        // Iterations in bands are not timed: until some are, one sample, as before the budget.
        let mut b = LightBudget::new();
        assert_eq!(b.begin(WARM_UP, false), (1, 0, false));
        assert_eq!(b.begin(WARM_UP + 1, true), (LOW, 1, true));
    }
}
