//! Coarse to fine within a frame budget: how a viewer spends each frame so that it answers
//! within the budget on any device and any scene.
//!
//! - **While the camera moves** each frame draws one iteration of a *preview* — the same view
//!   at 1/s of the window's size, s = 2, 4 … [`COARSEST`] (its own film, the photon map
//!   shared: [`Progressive::iterate_preview_rows`]) — at the finest s whose iteration fits the
//!   budget by the measured cost per pixel (the coarsest where none fits, drawn whole even
//!   past the budget: the next frame's camera would restart a part of one), shown upscaled
//!   (bilinear). Where a whole iteration of the window fits, the window's own iterations run
//!   instead.
//! - **When it stops** the previews refine from there where a whole iteration of the window
//!   takes longer than [`REFINE_ABOVE`]: [`LEVEL_ITERATIONS`] iterations at each level, then the
//!   next finer one; then (at once, where it takes less) the window's own iterations, which
//!   accumulate in its film as they always have. The display blends the finest preview that holds at least
//!   half the iterations of the coarser one shown before into the film's mean, weighted as the
//!   preview's iterations against the film's
//!   ([`Progressive::encode_resolve_preview`]): the coarse image stays on screen until the fine
//!   one has more iterations, and its weight w/(S + w) vanishes as the film's S grow, so the
//!   image converges to exactly the film's, which no preview ever enters.
//! - **No frame longer than the budget at full size either**: an iteration that would take
//!   longer runs as row bands across frames ([`Progressive::iterate_rows`]; input is handled
//!   between them), each band as many rows as fit in what is left of the frame's budget.
//!
//! The cost model is one line per level, a unit's seconds = a + b · its pixels, fitted robustly
//! (Theil–Sen: the median of the pairwise slopes, then the median intercept) to its recent
//! units of work and how long each took ([`Refine::finished`]): a unit's fixed cost a — its
//! submission and the wait for it, about 5 ms on lavapipe — is paid once per unit, so a frame
//! does not begin one in the little time it has left. While the units all had one size, b is
//! their median cost per pixel and a is 0. A level not yet measured borrows the nearest
//! measured one's. A budget of 0 turns it off: one whole iteration per frame, the loop the
//! viewer had before.

use crate::error::Result;
use crate::progressive::Progressive;

/// The frame budget a viewer aims at by default, in seconds.
pub const DEFAULT_FRAME_BUDGET: f64 = 0.05;
/// The coarsest preview: 1/32 of the window's size (a 1280 × 720 window: 40 × 23 pixels).
pub const COARSEST: u32 = 32;
/// Levels: the window (0) and the previews at 1/2^k, k = 1 … log2(COARSEST).
const LEVELS: usize = COARSEST.trailing_zeros() as usize + 1;
/// Iterations of each preview level after the camera stops, before the next finer level: a
/// level costs a quarter of the next, so the ladder from the coarsest level to the window
/// costs about 4/3 of the finest preview's own iterations.
pub const LEVEL_ITERATIONS: u32 = 4;

/// Seconds of one iteration of the window above which the previews refine after a stop
/// (below, the window's own iterations start at once). The ladder costs about 4/3 of a window
/// iteration before the window's first, so it pays only where that first iteration is long:
/// the window's bands show their progress meanwhile (every [`BAND_DISPLAY_INTERVAL`]), over
/// the view kept from before the move. Measured on the Cornell box at 1280 × 720 (lavapipe,
/// 0.9 s an iteration, timed at 0.9–1.1 s): where the ladder ran, its first window iteration
/// came 4.2–4.8 s after the stop and the error shown at 1 and 2 s was 110–121 % (the coarse
/// previews' blur of the light); going straight, 1.3–1.9 s and 29–33 %.
///
/// [`BAND_DISPLAY_INTERVAL`]: crate::session::interactive::BAND_DISPLAY_INTERVAL
pub const REFINE_ABOVE: f64 = 2.0;

/// The median of `v`, `None` where it is empty.
fn median(v: &[f64]) -> Option<f64> {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied()
}

/// Units of work whose cost each level keeps.
const COSTS_KEPT: usize = 8;

/// A level's cost model: a unit of p pixels takes `fixed` + `per_pixel` · p seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cost {
    fixed: f64,
    per_pixel: f64,
}

impl Cost {
    /// The line through the units (pixels, seconds): Theil–Sen (robust to the odd unit that
    /// began a photon pass or waited for a re-projection), kept where it has a positive slope
    /// and a non-negative intercept; else the median seconds per pixel alone.
    fn fit(units: &[(f64, f64)]) -> Option<Cost> {
        let per_pixel = median(&units.iter().map(|&(p, t)| t / p).collect::<Vec<_>>())?;
        let slopes: Vec<f64> = units
            .iter()
            .enumerate()
            .flat_map(|(i, a)| units[i + 1..].iter().map(move |b| (a, b)))
            .filter(|(a, b)| (b.0 - a.0).abs() > 0.0)
            .map(|(a, b)| (b.1 - a.1) / (b.0 - a.0))
            .collect();
        if let Some(b) = median(&slopes).filter(|&b| b > 0.0)
            && let Some(a) = median(&units.iter().map(|&(p, t)| t - b * p).collect::<Vec<_>>()).filter(|&a| a >= 0.0)
        {
            return Some(Cost { fixed: a, per_pixel: b });
        }
        Some(Cost { fixed: 0.0, per_pixel })
    }

    /// Seconds for a unit of `pixels`.
    fn time(&self, pixels: f64) -> f64 {
        self.fixed + self.per_pixel * pixels
    }
}

/// The scale (1 = the window) of level `k`.
fn scale(level: usize) -> u32 {
    1 << level
}

/// One unit of work a frame submitted: rows of one level, so many pixels; or photons of the
/// next photon pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Work {
    /// 1: the window's own iteration; s: the preview at 1/s; 0: photons.
    pub scale: u32,
    /// Pixels computed (rows × the level's width), or photons traced.
    pub pixels: u64,
    /// Whether it finished an iteration of its level (the photon pass).
    pub finished: bool,
}

/// The coarse-to-fine schedule of an interactive view (see the module's notes).
#[derive(Clone, Debug)]
pub struct Refine {
    /// Seconds per frame aimed at; 0: whole iterations, one per frame.
    budget: f64,
    /// The last [`COSTS_KEPT`] units of each level: (pixels, seconds).
    cost: [Vec<(f64, f64)>; LEVELS],
    /// The level being refined: 0 once the window's own iterations run.
    level: usize,
    /// Iterations finished at `level` since it began.
    level_iterations: u32,
    /// The camera moved since the last frame.
    moving: bool,
    /// The finest preview that holds a finished iteration of this view (its scale), and the
    /// iterations it holds: what the display blends in.
    shown: Option<(u32, u32)>,
    /// Whether the renderer draws previews (the path tracer does not).
    previews: bool,
    /// Seconds the last re-projection of the history took ([`Progressive::reproject`]).
    reprojection: Option<f64>,
    /// The photon passes' last units traced in steps: (photons, seconds).
    photon_cost: Vec<(f64, f64)>,
    /// Units of work submitted in this frame.
    units: u32,
}

impl Refine {
    /// A schedule of `budget` seconds a frame (0: off).
    pub fn new(budget: f64) -> Refine {
        Refine {
            budget: budget.max(0.0),
            cost: Default::default(),
            level: LEVELS - 1,
            level_iterations: 0,
            moving: true,
            shown: None,
            previews: true,
            reprojection: None,
            photon_cost: Vec::new(),
            units: 0,
        }
    }

    /// Whether the camera moved in this frame (or the last, before [`Refine::end_frame`]).
    pub fn moving(&self) -> bool {
        self.moving
    }

    /// Whether this frame re-projects the history: always while still, while moving where the
    /// last one took at most half the budget.
    pub fn reprojection_fits(&self) -> bool {
        !self.moving || self.reprojection.is_none_or(|t| t <= 0.5 * self.budget)
    }

    /// A re-projection took `seconds`.
    pub fn reprojected(&mut self, seconds: f64) {
        self.reprojection = Some(seconds);
    }

    /// The budget in seconds (0: off).
    pub fn budget(&self) -> f64 {
        self.budget
    }

    /// Sets the budget (0: off); the measured costs stay.
    pub fn set_budget(&mut self, budget: f64) {
        self.budget = budget.max(0.0);
        self.restart();
    }

    /// The camera moved (the renderer's image restarted): the previews start again at the
    /// level that fits a frame.
    pub fn moved(&mut self) {
        self.moving = true;
        self.restart();
    }

    /// The image restarted for another reason (a new renderer, a setting): as a move.
    pub fn restart(&mut self) {
        self.level = LEVELS - 1;
        self.level_iterations = 0;
        self.shown = None;
        self.previews = true;
    }

    /// The preview the display blends in: its scale and its weight in iterations, where one is.
    pub fn blend(&self) -> Option<(u32, f32)> {
        self.shown.map(|(scale, iterations)| (scale, iterations as f32))
    }

    /// Whether the window's own iterations are under way (the previews are done).
    pub fn refined(&self) -> bool {
        self.level == 0
    }

    /// The cost model at `level` from its recent units, or the nearest measured level's.
    fn cost_at(&self, level: usize) -> Option<Cost> {
        let k = (0..LEVELS)
            .flat_map(|d| [level.checked_sub(d), Some(level + d)])
            .flatten()
            .find(|&k| k < LEVELS && !self.cost[k].is_empty())?;
        Cost::fit(&self.cost[k])
    }

    /// The finest level whose whole iteration of `pixels` (the window's) fits in `seconds`;
    /// the coarsest while nothing is measured.
    fn fitting_level(&self, pixels: u64, seconds: f64) -> usize {
        (0..LEVELS)
            .find(|&k| {
                let p = pixels as f64 / f64::from(scale(k) * scale(k));
                self.cost_at(k).is_some_and(|c| c.time(p) <= seconds)
            })
            .unwrap_or(LEVELS - 1)
    }

    /// Submits the next unit of this frame's work with `left` seconds of the budget left, at
    /// most one whole iteration of the window's where `limit` is 0 (a script waits for a
    /// count), and returns it; `None` when there is nothing to do. Call
    /// [`finished`](Self::finished) with its time once it has run.
    pub fn step(&mut self, r: &mut dyn Progressive, left: f64, limit: u32) -> Result<Option<Work>> {
        let (w, h) = (r.settings().width, r.settings().height);
        if self.budget <= 0.0 {
            // Off: a whole iteration of the window per step.
            if limit == 0 {
                return Ok(None);
            }
            r.iterate()?;
            return Ok(Some(Work { scale: 1, pixels: w as u64 * h as u64, finished: true }));
        }
        if self.moving {
            // While moving: the finest level whose iteration fits (the window's own where it
            // does).
            self.level = self.fitting_level(w as u64 * h as u64, left);
            self.level_iterations = 0;
        }
        // Still: the previews refine only where the window's own iteration would keep the
        // image from changing for longer than REFINE_ABOVE (else they cost more than they show).
        let whole = self.cost_at(0).map(|c| c.time((w as u64 * h as u64) as f64));
        if !self.previews || (!self.moving && whole.is_some_and(|t| t <= REFINE_ABOVE)) {
            self.level = 0;
        }
        // The next photon pass, traced in steps between the window's iterations, once the
        // window holds one (the iterations read the current pass until the next is done: the
        // first iteration after a stop is what the screen waits for, the pass is not).
        if self.level == 0
            && r.rows_ahead() == 0
            && r.samples() > 0
            && let Some((traced, count)) = r.photons_pending()
        {
            let n = match Cost::fit(&self.photon_cost) {
                Some(c) => {
                    let fit = ((left - c.fixed).max(0.0) / c.per_pixel) as u32;
                    if fit < 1024 && self.units > 0 {
                        return Ok(None);
                    }
                    fit
                }
                None => count / 64,
            };
            // At least a few thousand photons a unit (a dispatch's worth), at most the rest.
            let n = n.max(1024).min(count - traced);
            let finished = r.photon_step(n)?;
            self.units += 1;
            return Ok(Some(Work { scale: 0, pixels: u64::from(n), finished }));
        }
        let k = self.level;
        let s = scale(k);
        let (lw, lh) = (w.div_ceil(s), h.div_ceil(s));
        // The rows that fit in what is left (all of them while nothing is measured at a
        // preview level; a tenth of the window's); after the frame's first unit, none where
        // not one fits: the frame is done (a unit's fixed cost would overrun it).
        let rows = match self.cost_at(k) {
            // While moving, a preview's iteration is drawn whole, even past the budget where
            // the coarsest level does not fit: the next frame's camera restarts it, so a part
            // of one would show nothing (the staircase at 1280 × 720 on a slow lavapipe: the
            // 1/32 preview's iteration took longer than a frame's work, and every frame of the
            // move was thrown away).
            _ if self.moving && k > 0 => lh,
            Some(c) => {
                let fit = ((left - c.fixed) / (c.per_pixel * lw as f64)).floor().max(0.0) as u32;
                if fit == 0 && self.units > 0 {
                    return Ok(None);
                }
                fit.clamp(1, lh)
            }
            None if k > 0 => lh,
            None => lh.div_ceil(10),
        };
        let work = if k == 0 {
            if limit == 0 {
                return Ok(None);
            }
            let before = r.rows_ahead();
            let finished = r.iterate_rows(rows)?;
            let after = if finished { lh } else { r.rows_ahead() };
            Work { scale: 1, pixels: (after - before) as u64 * lw as u64, finished }
        } else {
            let before = r.preview_film(s).map_or(0, |f| f.rows_ahead);
            match r.iterate_preview_rows(s, rows)? {
                None => {
                    // No previews here: the window's own iterations, banded.
                    self.previews = false;
                    self.level = 0;
                    return self.step(r, left, limit);
                }
                Some(finished) => {
                    let after = if finished { lh } else { r.preview_film(s).map_or(0, |f| f.rows_ahead) };
                    if finished {
                        let n = r.preview_film(s).map_or(0, |f| f.samples);
                        // The display takes a finer preview once it holds half as many
                        // iterations as the one shown (its noise is then no more than twice
                        // that one's, its blur less than half).
                        let finer = |&(shown, m): &(u32, u32)| s == shown || (s < shown && 2 * n >= m);
                        if self.shown.is_none_or(|ref shown| finer(shown)) {
                            self.shown = Some((s, n));
                        }
                        self.level_iterations += 1;
                        if !self.moving && self.level_iterations >= LEVEL_ITERATIONS {
                            self.level -= 1;
                            self.level_iterations = 0;
                        }
                    }
                    Work { scale: s, pixels: (after - before) as u64 * lw as u64, finished }
                }
            }
        };
        self.units += 1;
        Ok(Some(work))
    }

    /// `work` took `seconds`: a unit of its level's cost model.
    pub fn finished(&mut self, work: &Work, seconds: f64) {
        if work.pixels == 0 || self.budget <= 0.0 {
            return;
        }
        let kept = match work.scale {
            0 => &mut self.photon_cost,
            s => &mut self.cost[s.trailing_zeros() as usize],
        };
        if kept.len() == COSTS_KEPT {
            kept.remove(0);
        }
        kept.push((work.pixels as f64, seconds));
    }

    /// The frame is over: from the next one on, the camera is still unless it moves again.
    pub fn end_frame(&mut self) {
        self.moving = false;
        self.units = 0;
    }

    /// Whether this frame's work is done: a moving camera gets one preview iteration a frame
    /// (the next frame's view replaces it).
    pub fn frame_done(&self, work: &Work) -> bool {
        self.moving && work.scale > 1 && work.finished
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cost model recovers a unit's fixed cost and its cost per pixel from units of
    /// several sizes on a line (t = 5 ms + 0.5 µs · p), one of them an outlier (a unit that
    /// waited for something else), which least squares would follow; units of one size give
    /// the median per pixel.
    #[test]
    fn the_cost_model_is_a_robust_line_through_the_units() {
        let line = |p: f64| 5e-3 + 0.5e-6 * p;
        let mut units: Vec<(f64, f64)> =
            [2560.0, 14080.0, 37120.0, 42240.0, 10240.0, 1280.0, 51200.0].iter().map(|&p| (p, line(p))).collect();
        units.push((20000.0, 0.4));
        let c = Cost::fit(&units).unwrap();
        assert!((c.fixed - 5e-3).abs() < 1e-6 && (c.per_pixel - 0.5e-6).abs() < 1e-10, "{c:?}");
        // The rows that fit in 20 ms of a 1280-pixel-wide level: (20 − 5) ms / (0.64 ms a row).
        assert_eq!(((20e-3 - c.fixed) / (c.per_pixel * 1280.0)).floor(), 23.0);
        let same = Cost::fit(&[(1000.0, 2e-3), (1000.0, 3e-3), (1000.0, 2.5e-3)]).unwrap();
        assert_eq!(same, Cost { fixed: 0.0, per_pixel: 2.5e-6 });
        assert_eq!(Cost::fit(&[]), None);
    }
}
