//! The interactive loop that a window and a web page share: a progressive render being looked
//! at. A camera move restarts the image; each frame's work is chosen within a frame budget,
//! coarse to fine ([`super::refine`]: previews while the camera moves, row bands where an
//! iteration is longer than a frame); the shown component, the exposure and the denoiser are
//! the viewer's choices; the denoised image is filtered again on a [`Schedule`] (more
//! iterations, or time) and resolved for display in between.

use crate::error::Result;
use crate::passes::denoise::{DenoiseParams, Schedule};
use crate::passes::film::Show;
use crate::progressive::{Denoising, Progressive};
use crate::scene::Camera;
use crate::session::refine::{Refine, Work};

/// A progressive render as a viewer shows it.
pub struct Interactive {
    renderer: Box<dyn Progressive>,
    /// The component shown (the full image where the renderer lacks it).
    pub show: Show,
    /// Exposure in stops.
    pub exposure: f32,
    /// Whether the denoised full image is shown (where the renderer has a denoiser).
    denoise: bool,
    /// When the denoiser last ran for the display.
    denoised: Schedule,
    /// The last resolve encoded a filter that has not been timed yet
    /// ([`Interactive::filter_encoded`]).
    filter_untimed: bool,
    /// The front end's clock (the `now` of the schedule) at its last resolve, and the instant
    /// then: the schedule's time between resolves.
    clock: Option<(f64, web_time::Instant)>,
    /// Whether the filter runs in steps across frames ([`Interactive::frame`] with a frame
    /// budget) rather than whole in the resolve (the page, or no budget); the run under way,
    /// and the seconds per row each of its stages last took (the steps' sizes).
    stepped_filter: bool,
    filter_run: Option<FilterRun>,
    filter_row_seconds: Vec<f64>,
    /// The GPU seconds of the steps timed so far of the filter under way.
    filter_seconds: f64,
    /// What each frame draws, coarse to fine, within the frame budget.
    refine: Refine,
    /// When the last frame's work ended, and the seconds the rest of a frame took since (the
    /// front end's display, input and resolve; running means of the frames without a resolve,
    /// of those with one, which on a slow device costs most of a frame, and of moving frames
    /// whose resolve was a preview's, upscaled, which costs little: indexed by [`Resolved`]):
    /// the work gets the budget less the rest its frame will have. Which resolve was encoded
    /// since the work ended.
    work_ended: Option<web_time::Instant>,
    rest: [f64; 3],
    resolved_since_work: Resolved,
    /// When the image was last resolved for display and the window's iterations then, and
    /// whether the camera has moved since.
    displayed: Option<(web_time::Instant, u32)>,
    moved_since_display: bool,
    /// The last frame planned its work around a resolve at its end (a shorter share of the
    /// budget): that resolve is due, even where the shorter frame ends before the interval.
    resolve_planned: bool,
    /// Whether the last frame did any work, and when the front end last drew the image on
    /// screen ([`Interactive::draw_due`]).
    worked: bool,
    drawn: Option<web_time::Instant>,
    /// Whether the last frame's camera had moved (its work a moving frame's).
    moving_frame: bool,
    /// The camera moved since the photon region was last fitted to the view.
    refit_due: bool,
}

/// A filter of the denoised image run in steps across frames: the next stage and row, the
/// film's iterations and the schedule's time.
#[derive(Clone, Copy, Debug)]
struct FilterRun {
    stage: usize,
    row: u32,
    stages: usize,
    samples: u32,
    began: f64,
}

/// One unit of a frame's work that [`Interactive::step`] submitted: the renderer's (a preview's
/// iteration, rows of the window's, photons) or steps of the denoiser's filter.
#[derive(Clone, Debug, PartialEq)]
pub enum Unit {
    Work(Work),
    Filter(Vec<FilterStep>),
}

/// A step of the denoiser's filter submitted: rows of one of its stages, the seconds they were
/// estimated to take (0: the stage's cost not known yet), and whether it was the filter's last.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterStep {
    stage: usize,
    rows: u32,
    estimate: f64,
    last: bool,
}

/// The rows of a filter step before its stage's cost per row is measured.
const FILTER_FIRST_ROWS: u32 = 16;

/// While the camera is still, the image is resolved for display at most this often (seconds)
/// while the previews refine: a frame's preview iteration changes the whole picture, but on a
/// slow device the resolve costs a good part of a frame.
pub const DISPLAY_INTERVAL: f64 = 0.2;
/// The same once the window's own iterations run: each one is shown as soon as it is done, and
/// the rows of one under way in bands this often (on lavapipe at 1280 × 720 the resolve takes
/// 30 ms: every 0.2 s it took 16 % of the time the iterations had).
pub const BAND_DISPLAY_INTERVAL: f64 = 0.3;
/// The longest a front end goes without drawing the image on screen while the view works and
/// nothing new is resolved ([`Interactive::draw_due`]), in seconds.
pub const REDRAW_INTERVAL: f64 = 0.5;

impl Interactive {
    pub fn new(renderer: Box<dyn Progressive>, show: Show, exposure: f32) -> Interactive {
        let refine = Refine::new(super::refine::DEFAULT_FRAME_BUDGET);
        let mut renderer = renderer;
        renderer.set_photon_steps(refine.budget() > 0.0);
        Interactive {
            renderer,
            show,
            exposure,
            denoise: false,
            denoised: Schedule::default(),
            filter_untimed: false,
            clock: None,
            stepped_filter: false,
            filter_run: None,
            filter_row_seconds: Vec::new(),
            filter_seconds: 0.0,
            refine,
            work_ended: None,
            rest: [0.0; 3],
            resolved_since_work: Resolved::None,
            displayed: None,
            moved_since_display: true,
            resolve_planned: false,
            worked: false,
            drawn: None,
            moving_frame: false,
            refit_due: false,
        }
    }

    /// The frame budget in seconds (0: one whole iteration a frame).
    pub fn frame_budget(&self) -> f64 {
        self.refine.budget()
    }

    /// Sets the frame budget (0: off); with one, new photon passes are traced in steps.
    pub fn set_frame_budget(&mut self, seconds: f64) {
        self.refine.set_budget(seconds);
        self.renderer.set_photon_steps(self.refine.budget() > 0.0);
    }

    /// The schedule of the frames' work (what is refined, what is blended in).
    pub fn refine(&self) -> &Refine {
        &self.refine
    }

    /// One frame's work, waited for: units of work ([`Refine::step`]) until the frame budget is
    /// spent — one preview iteration while the camera moves, the previews' refinement after it
    /// stops, then the window's own iterations, in row bands where one is longer than the
    /// budget — with at most `limit` of the window's iterations finished. The budget is the
    /// whole frame's: the work gets it less what the rest of the recent frames took (their
    /// resolve, display and input, measured from the end of one frame's work to the start of
    /// the next's). Returns the window's iterations it finished.
    pub fn frame(&mut self, limit: u32) -> Result<u32> {
        if self.filter_encoded() {
            // The last frame ran the denoiser's filter: what it took beside the work, the
            // filter waited for, is what the schedule spaces filters by; it is not a frame's
            // rest.
            self.renderer.wait()?;
            if let Some(ended) = self.work_ended.take() {
                self.filter_took(ended.elapsed().as_secs_f64());
            }
        }
        let start = web_time::Instant::now();
        if let Some(ended) = self.work_ended {
            // A stall (a dragged window, a build) is not a frame's rest.
            let rest = start.duration_since(ended).as_secs_f64().min(self.refine.budget());
            let mean = &mut self.rest[self.resolved_since_work as usize];
            *mean = if *mean == 0.0 { rest } else { 0.75 * *mean + 0.25 * rest };
        }
        self.resolved_since_work = Resolved::None;
        // The work's share of the frame: less a resolve's rest where one will be due by the
        // frame's end (re-planned below when the work makes one due: an iteration finished);
        // a moving frame's, where it will resolve, as moving frames' resolves took.
        let due = |resolving: bool, moving: bool| match (resolving, moving) {
            (false, _) => Resolved::None,
            (true, false) => Resolved::Whole,
            (true, true) => Resolved::Upscaled,
        };
        let mut resolving = self.display_due_within(self.refine.budget());
        let mut budget = work_budget(self.refine.budget(), self.rest, due(resolving, self.refine.moving()));
        // What the view before a move held, re-projected onto this one (once per view; while
        // moving, where it takes at most half the budget); once still, the photon region.
        let mut reprojected = None;
        if budget > 0.0 {
            self.refit_region()?;
            if self.refine.reprojection_fits() && self.renderer.reproject()? {
                self.renderer.wait()?;
                let seconds = start.elapsed().as_secs_f64();
                self.refine.reprojected(seconds);
                reprojected = Some(seconds);
            }
        }
        let mut finished = 0;
        // (scale, rows or whole, milliseconds) of each unit, for the debug log (scale 0: a step
        // of the denoiser's filter, and whether it finished it).
        let mut units = Vec::new();
        self.stepped_filter = budget > 0.0;
        loop {
            let left = budget - start.elapsed().as_secs_f64();
            let began = web_time::Instant::now();
            if self.filter_run.is_some() {
                // A filter under way takes the frame's time until it is done (the window's
                // iterations wait: they would change what it filters).
                let done = self.filter_step(left.max(0.0))?;
                units.push((0, done, (began.elapsed().as_secs_f64() * 1e4).round() / 10.0));
                if start.elapsed().as_secs_f64() >= budget {
                    break;
                }
                continue;
            }
            let Some(work) = self.refine.step(self.renderer.as_mut(), left.max(0.0), limit - finished)? else { break };
            self.renderer.wait()?;
            let seconds = began.elapsed().as_secs_f64();
            self.refine.finished(&work, seconds);
            units.push((work.scale, work.finished, (seconds * 1e4).round() / 10.0));
            let iterated = work.scale == 1 && work.finished;
            finished += u32::from(iterated);
            if !resolving && self.display_due() {
                resolving = true;
                budget = work_budget(self.refine.budget(), self.rest, due(resolving, self.refine.moving()));
            }
            // The denoiser filters whole iterations: where the denoised image is due a filter,
            // it begins with the iteration's end, not in the next one's first band.
            if iterated && self.filter_due() {
                self.begin_filter()?;
                if start.elapsed().as_secs_f64() >= budget {
                    break;
                }
                continue;
            }
            if self.refine.frame_done(&work) || start.elapsed().as_secs_f64() >= budget || finished >= limit {
                break;
            }
        }
        self.moving_frame = self.refine.moving();
        self.refine.end_frame();
        self.work_ended = Some(web_time::Instant::now());
        // A frame planned with a resolve's rest resolves at its end: else the next frame would
        // plan the same shorter share again (measured on the Cornell box at 1280 × 720 after a
        // stop: two of every three frames before each band's resolve did a quarter of the
        // budget's work and then did not resolve, a fifth of the iterations' time lost).
        self.resolve_planned = resolving;
        self.worked = !units.is_empty();
        log::debug!(
            "frame: work {:.1} ms of {:.1} (rest {:.1}, resolving {resolving}); re-projection {:?} ms; units (scale, finished, ms) {units:?}",
            start.elapsed().as_secs_f64() * 1e3,
            budget * 1e3,
            self.rest[due(resolving, self.moving_frame) as usize] * 1e3,
            reprojected.map(|s| (s * 1e4).round() / 10.0)
        );
        Ok(finished)
    }

    /// The front end's clock now, as the last resolve's `now` and the time since (0 before one).
    fn now(&self) -> f64 {
        self.clock.map_or(0.0, |(now, at)| now + at.elapsed().as_secs_f64())
    }

    /// The denoised image is no longer the view's: the next is filtered at once, and a filter
    /// under way is dropped.
    fn clear_filter(&mut self) {
        self.denoised.clear();
        self.filter_run = None;
        self.filter_seconds = 0.0;
    }

    /// Whether the denoised image is shown and due a filter.
    fn filter_due(&self) -> bool {
        self.denoising().is_some() && self.denoised.due(self.renderer.samples(), self.now())
    }

    /// Begins the filter of the window's image: in steps across frames where the loop has a
    /// budget (the image shown until it is done is the last filter's, or the raw one); else
    /// the next resolve filters it whole.
    fn begin_filter(&mut self) -> Result<()> {
        if !self.stepped_filter {
            return Ok(());
        }
        let params = DenoiseParams::default();
        let Some(r) = self.renderer.denoising() else { return Ok(()) };
        let stages = r.denoise_stages(&params)?;
        self.filter_row_seconds.resize(stages, 0.0);
        let samples = self.renderer.samples();
        self.filter_run = Some(FilterRun { stage: 0, row: 0, stages, samples, began: self.now() });
        self.filter_seconds = 0.0;
        Ok(())
    }

    /// One step of the filter under way, waited for and timed ([`Interactive::submit_filter_step`]).
    /// Returns whether the filter is done.
    fn filter_step(&mut self, left: f64) -> Result<bool> {
        let began = web_time::Instant::now();
        let Some(step) = self.submit_filter_step(left)? else { return Ok(false) };
        self.renderer.wait()?;
        self.filter_steps_took(&[step], began.elapsed().as_secs_f64());
        Ok(step.last)
    }

    /// The seconds per row of `stage` of the filter: as its last step measured, else the last
    /// whole filter's time spread evenly over its stages' rows, else 0 (not known).
    fn filter_row_cost(&self, stage: usize) -> f64 {
        let measured = self.filter_row_seconds.get(stage).copied().unwrap_or(0.0);
        if measured > 0.0 {
            return measured;
        }
        let rows = self.filter_row_seconds.len() as f64 * self.renderer.settings().height as f64;
        if rows > 0.0 { self.denoised.cost() / rows } else { 0.0 }
    }

    /// Submits one step of the filter under way, without waiting: as many rows of its stage as
    /// fit in `left` seconds at the stage's cost per row ([`Interactive::filter_row_cost`]; 16
    /// rows where it is not known; at least 8). Once its last step is submitted the filtered
    /// image is the view's (the queue runs the display's resolve after it). `None` where no
    /// filter is under way; an image that changed under it (another iteration, a restart) ends
    /// it undone. Its time goes to [`Interactive::filter_steps_took`].
    fn submit_filter_step(&mut self, left: f64) -> Result<Option<FilterStep>> {
        let Some(mut run) = self.filter_run.take() else { return Ok(None) };
        let height = self.renderer.settings().height;
        if self.renderer.samples() != run.samples || self.renderer.rows_ahead() != 0 {
            return Ok(None);
        }
        let per_row = self.filter_row_cost(run.stage);
        let Some(r) = self.renderer.denoising() else { return Ok(None) };
        let fit = if per_row > 0.0 { (left / per_row) as u32 } else { FILTER_FIRST_ROWS };
        let rows = fit.max(8).min(height - run.row);
        r.submit_denoise_rows(&DenoiseParams::default(), (run.stage, run.row..run.row + rows))?;
        let stage = run.stage;
        run.row += rows;
        if run.row >= height {
            (run.stage, run.row) = (run.stage + 1, 0);
        }
        let last = run.stage >= run.stages;
        if last {
            self.denoised.ran(run.samples, run.began);
            self.moved_since_display = true;
        } else {
            self.filter_run = Some(run);
        }
        Ok(Some(FilterStep { stage, rows, estimate: per_row * rows as f64, last }))
    }

    /// Submits steps of the filter under way, without waiting, across its stages, until their
    /// estimated seconds reach `left` (a stage whose cost is not known yet begins a unit of
    /// its own, so that its time measures it alone). `None` where no filter is under way.
    fn submit_filter_steps(&mut self, left: f64) -> Result<Option<Vec<FilterStep>>> {
        let mut steps: Vec<FilterStep> = Vec::new();
        let mut estimate = 0.0;
        while let Some(run) = self.filter_run {
            if !steps.is_empty() && (estimate >= left || self.filter_row_cost(run.stage) <= 0.0) {
                break;
            }
            let Some(step) = self.submit_filter_step((left - estimate).max(0.0))? else { break };
            estimate += step.estimate;
            steps.push(step);
            if step.estimate <= 0.0 {
                break;
            }
        }
        Ok((!steps.is_empty()).then_some(steps))
    }

    /// Steps of the filter submitted together took `seconds` on the GPU: each stage's cost per
    /// row (the next steps' sizes; shared in proportion to the estimates, or evenly over the
    /// rows where there were none), and after the last step the whole filter's, which spaces
    /// the filters.
    fn filter_steps_took(&mut self, steps: &[FilterStep], seconds: f64) {
        let estimate: f64 = steps.iter().map(|s| s.estimate).sum();
        let rows: u32 = steps.iter().map(|s| s.rows).sum();
        for s in steps {
            let per_row = if estimate > 0.0 {
                s.estimate / s.rows.max(1) as f64 * seconds / estimate
            } else {
                seconds / rows.max(1) as f64
            };
            if let Some(cost) = self.filter_row_seconds.get_mut(s.stage) {
                *cost = per_row;
            }
        }
        self.filter_seconds += seconds;
        if steps.iter().any(|s| s.last) {
            self.denoised.took(std::mem::take(&mut self.filter_seconds));
        }
    }

    /// Whether the last resolve encoded the denoiser's filter since this was last asked: a front
    /// end that does not wait for its frames ([`Interactive::step`], a web page) times that
    /// submission and gives its seconds to [`Interactive::filter_took`]; [`Interactive::frame`]
    /// does so itself.
    pub fn filter_encoded(&mut self) -> bool {
        std::mem::take(&mut self.filter_untimed)
    }

    /// The denoiser's last filter took `seconds` (with the resolve and display submitted with
    /// it): the next is spaced by it ([`Schedule::took`]).
    pub fn filter_took(&mut self, seconds: f64) {
        self.denoised.took(seconds);
    }

    /// Re-projects what the view before the last move held onto this one for the display,
    /// without waiting (a web page's frame, before its [`Interactive::step`]s); false where
    /// there was nothing to do.
    pub fn reproject(&mut self) -> Result<bool> {
        self.refit_region()?;
        self.renderer.reproject()
    }

    /// Once the camera is still after a move: the photon region fitted to the view, a pass
    /// over it begun where it moved ([`Progressive::refit_photon_region`]).
    fn refit_region(&mut self) -> Result<()> {
        if self.refit_due && !self.refine.moving() {
            self.refit_due = false;
            self.renderer.refit_photon_region()?;
        }
        Ok(())
    }

    /// One unit of a frame's work without waiting for it (a web page, which cannot block):
    /// give its time to [`Interactive::finished`] once the GPU has done it, and call
    /// [`Interactive::end_frame`] after the frame's last. With a frame budget the denoiser's
    /// filter runs in steps here as in [`Interactive::frame`]: begun where an iteration ends
    /// and a filter is due, then as many steps a unit as fit in `left` (the window's
    /// iterations wait, whatever `limit`).
    pub fn step(&mut self, left: f64, limit: u32) -> Result<Option<Unit>> {
        self.stepped_filter = self.refine.budget() > 0.0;
        if let Some(steps) = self.submit_filter_steps(left.max(0.0))? {
            return Ok(Some(Unit::Filter(steps)));
        }
        let Some(work) = self.refine.step(self.renderer.as_mut(), left, limit)? else { return Ok(None) };
        if work.scale == 1 && work.finished && self.filter_due() {
            self.begin_filter()?;
        }
        Ok(Some(Unit::Work(work)))
    }

    /// Whether a filter of the denoised image is under way in steps ([`Interactive::step`]
    /// runs it even where no iteration is left to do).
    pub fn filtering(&self) -> bool {
        self.filter_run.is_some()
    }

    /// `unit` took `seconds` on the GPU.
    pub fn finished(&mut self, unit: &Unit, seconds: f64) {
        match unit {
            Unit::Work(work) => self.refine.finished(work, seconds),
            Unit::Filter(steps) => self.filter_steps_took(steps, seconds),
        }
    }

    /// The frame is over ([`Interactive::step`]).
    pub fn end_frame(&mut self) {
        self.moving_frame = self.refine.moving();
        self.refine.end_frame();
    }

    pub fn renderer(&self) -> &dyn Progressive {
        self.renderer.as_ref()
    }

    /// The renderer, for iterating; a change to its image must be followed by
    /// [`Interactive::invalidate`].
    pub fn renderer_mut(&mut self) -> &mut dyn Progressive {
        self.renderer.as_mut()
    }

    /// A new renderer in place of the old (a setting changed): the camera goes with the view;
    /// where the denoiser is on, the new renderer's is enabled too.
    pub fn replace(&mut self, mut renderer: Box<dyn Progressive>, keep_camera: bool) -> Result<()> {
        if keep_camera {
            renderer.set_camera(self.renderer.camera())?;
        }
        if self.denoise {
            enable(renderer.as_mut())?;
        }
        renderer.set_photon_steps(self.refine.budget() > 0.0);
        self.renderer = renderer;
        self.clear_filter();
        self.refine.restart();
        self.moved_since_display = true;
        Ok(())
    }

    /// Changes the image size in place where the renderer can (see [`Progressive::resize`]);
    /// `Ok(false)`: it must be rebuilt at the new size ([`Interactive::replace`]).
    pub fn resize(&mut self, width: u32, height: u32) -> Result<bool> {
        let resized = self.renderer.resize(width, height)?;
        if resized {
            self.clear_filter();
            self.refine.restart();
            self.moved_since_display = true;
        }
        Ok(resized)
    }

    /// The denoised image was filtered at the current iterations at `now` (a screenshot
    /// filtered it to save it): the display need not filter it again until it is due.
    pub fn filtered(&mut self, now: f64) {
        self.clock = Some((now, web_time::Instant::now()));
        // The screenshot's filter was of the same iterations: one under way has nothing to add.
        self.filter_run = None;
        self.denoised.ran(self.renderer.samples(), now);
    }

    /// Moves the camera: the image restarts.
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        self.renderer.set_camera(camera)?;
        self.clear_filter();
        self.refine.moved();
        self.moved_since_display = true;
        self.refit_due = true;
        Ok(())
    }

    /// Shows the denoised image or not. Turning it on enables the renderer's denoiser where it
    /// has one and none yet (fails where its buffers exceed the device's limits, leaving it
    /// off); its guides hold the iterations from then on, so an image that has iterations
    /// restarts.
    pub fn set_denoise(&mut self, on: bool) -> Result<()> {
        if on {
            enable(self.renderer.as_mut())?;
        }
        self.denoise = on;
        self.clear_filter();
        self.moved_since_display = true;
        if self.renderer.samples() == 0 {
            self.refine.restart();
        }
        Ok(())
    }

    pub fn denoise(&self) -> bool {
        self.denoise
    }

    /// The renderer's denoiser while the denoised full image is shown.
    pub fn denoising(&self) -> Option<&dyn Denoising> {
        let shown = self.denoise && self.show == Show::Full;
        self.renderer.denoising().filter(|r| shown && r.denoiser_enabled())
    }

    /// The shown image changed other than by iterations (a new renderer, a restart, a save
    /// that filters at once): the next denoised image is filtered at once.
    pub fn invalidate(&mut self) {
        self.clear_filter();
        self.moved_since_display = true;
        if self.renderer.samples() == 0 && self.renderer.rows_ahead() == 0 {
            // A restart: the previews of the view before are gone.
            self.refine.restart();
        }
    }

    /// The display buffer was overwritten (a screenshot's read): resolve it again next frame.
    pub fn redisplay(&mut self) {
        self.moved_since_display = true;
    }

    /// Whether the image should be resolved for display this frame: always with the budget off,
    /// after a camera move or any change but iterations ([`Interactive::invalidate`]), when the
    /// window's image has finished an iteration since, and else at most every
    /// [`DISPLAY_INTERVAL`] while the previews refine, every [`BAND_DISPLAY_INTERVAL`] once the
    /// window's own iterations run (the front end presents its last image meanwhile, with its
    /// panel).
    pub fn display_due(&self) -> bool {
        self.display_due_within(0.0)
    }

    /// Whether the image will be resolved for display at the end of a frame `seconds` from now
    /// if its work finishes no iteration ([`Interactive::display_due`] then).
    fn display_due_within(&self, seconds: f64) -> bool {
        let Some((at, samples)) = self.displayed else { return true };
        if self.resolve_planned && self.filter_run.is_none() {
            return true;
        }
        let interval = if self.refine.refined() { BAND_DISPLAY_INTERVAL } else { DISPLAY_INTERVAL };
        if self.filter_run.is_some() {
            // A filter under way: nothing new until it is done (its last stage writes the
            // denoised image in bands).
            return self.moved_since_display;
        }
        self.refine.budget() <= 0.0
            || self.moved_since_display
            || self.renderer.samples() != samples
            || at.elapsed().as_secs_f64() + seconds >= interval
    }

    /// Whether the front end should draw the image on screen (its display pass and present)
    /// this frame, `resolved` whether it resolved it: where it did; where the frame did no work
    /// (a view that is done paces its loop by presenting); and else at least every
    /// [`REDRAW_INTERVAL`] (a window uncovered is drawn again soon). Between resolves the
    /// image is the same: on lavapipe at 1280 × 720 the display pass took 8 ms of every 50 ms
    /// frame after a stop, a sixth of the time the iterations had. A front end that draws
    /// calls [`Interactive::drawn`].
    pub fn draw_due(&self, resolved: bool) -> bool {
        resolved
            || !self.worked
            || self.refine.budget() <= 0.0
            || self.drawn.is_none_or(|t| t.elapsed().as_secs_f64() >= REDRAW_INTERVAL)
    }

    /// The front end drew the image on screen.
    pub fn drawn(&mut self) {
        self.drawn = Some(web_time::Instant::now());
    }

    /// Encodes the resolve of what is shown into the film's display buffer: the raw image of
    /// the shown component, or the denoised full image, filtered again first when the schedule
    /// says so at `now` (seconds from any fixed origin).
    pub fn encode_resolve(&mut self, enc: &mut wgpu::CommandEncoder, now: f64) -> Result<()> {
        // A frame of a move (the camera set since the last resolve) shows a preview upscaled
        // where the film has nothing yet ([`Progressive::encode_resolve_upscaled`]).
        let moving = self.moved_since_display && self.moving_frame;
        (self.displayed, self.moved_since_display) = (Some((web_time::Instant::now(), self.renderer.samples())), false);
        (self.resolved_since_work, self.resolve_planned) = (Resolved::Whole, false);
        if moving && self.denoising().is_none() {
            let show = if self.renderer.has(self.show) { self.show } else { Show::Full };
            if self.renderer.encode_resolve_upscaled(enc, (show, self.exposure), self.refine.blend()) {
                self.clock = Some((now, web_time::Instant::now()));
                self.resolved_since_work = Resolved::Upscaled;
                return Ok(());
            }
        }
        self.encode_shown(enc, now, true)
    }

    /// [`Interactive::encode_resolve`] without the previews and the history blended in: the
    /// render's own image, as a screenshot saves it (the next frame's display resolves again).
    pub fn encode_resolve_unblended(&mut self, enc: &mut wgpu::CommandEncoder, now: f64) -> Result<()> {
        self.moved_since_display = true;
        self.encode_shown(enc, now, false)
    }

    fn encode_shown(&mut self, enc: &mut wgpu::CommandEncoder, now: f64, blend: bool) -> Result<()> {
        self.clock = Some((now, web_time::Instant::now()));
        let samples = self.renderer.samples();
        // The denoiser filters whole iterations (not one under way in bands), from the first;
        // until it has filtered this view's image the raw one is shown (with what is blended
        // into it), not the last filter's of another view or none. Where the loop runs the
        // filter in steps (`frame` with a budget) only an unblended resolve (a screenshot's)
        // filters here.
        let whole = self.renderer.rows_ahead() == 0;
        let due = !(self.stepped_filter && blend) && whole && samples > 0 && self.denoised.due(samples, now);
        let filtered = due || self.denoised.filtered();
        if let Some(r) = self.denoising().filter(|_| samples > 0 && filtered) {
            if due {
                r.encode_denoise(enc, &DenoiseParams::default())?;
            }
            r.encode_resolve_denoised(enc, self.exposure)?;
            if due {
                self.denoised.ran(samples, now);
                self.filter_untimed = true;
                // Of the same iterations as a filter under way (a screenshot's).
                self.filter_run = None;
            }
        } else {
            let show = if self.renderer.has(self.show) { self.show } else { Show::Full };
            if blend {
                self.renderer.encode_resolve_blend(enc, (show, self.exposure), self.refine.blend());
            } else {
                self.renderer.encode_resolve(enc, show, self.exposure);
            }
            if self.denoising().is_none() {
                self.clear_filter();
            }
        }
        Ok(())
    }
}

/// What a frame's front end resolved after its work: nothing, the window's image, or (a moving
/// frame) a preview's, upscaled by the display ([`Progressive::encode_resolve_upscaled`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Resolved {
    None = 0,
    Whole = 1,
    Upscaled = 2,
}

/// The seconds of a frame of `budget` (0: none) its work gets: the budget less the rest the
/// frame will have — `rest[1]` where it ends with a resolve, `rest[0]` where not, each the
/// other where not measured yet; `rest[2]` where it ends with a moving frame's upscaled
/// preview, else as a resolve — and at least a quarter of it.
fn work_budget(budget: f64, rest: [f64; 3], resolved: Resolved) -> f64 {
    if budget <= 0.0 {
        return 0.0;
    }
    let order = match resolved {
        Resolved::None => [rest[0], rest[1]],
        Resolved::Whole => [rest[1], rest[0]],
        Resolved::Upscaled if rest[2] > 0.0 => [rest[2], rest[2]],
        Resolved::Upscaled => [rest[1], rest[0]],
    };
    let rest = if order[0] > 0.0 { order[0] } else { order[1] };
    (budget - rest).max(0.25 * budget)
}

/// Enables `renderer`'s denoiser where it has one and none yet, restarting an image that has
/// iterations (they have no guides).
fn enable(renderer: &mut dyn Progressive) -> Result<()> {
    let Some(d) = renderer.denoising_mut().filter(|d| !d.denoiser_enabled()) else { return Ok(()) };
    d.enable_denoiser()?;
    // The guides hold the iterations from here on: an iteration under way in row bands (the
    // first one too) would leave its rows above the band without it.
    if renderer.samples() > 0 || renderer.rows_ahead() > 0 {
        renderer.reset();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::{Gpu, GpuOptions};
    use crate::path_tracer::PathTracer;
    use crate::renderer::Renderer;
    use crate::settings::RenderSettings;

    #[test]
    fn a_frame_that_ends_with_a_resolve_leaves_its_work_the_time_the_resolve_will_not_take() {
        let b = 0.05;
        // Measured rests: 8 ms without a resolve, 35 ms with one.
        let (none, whole, upscaled) = (Resolved::None, Resolved::Whole, Resolved::Upscaled);
        assert!((work_budget(b, [0.008, 0.035, 0.0], none) - 0.042).abs() < 1e-12);
        assert!((work_budget(b, [0.008, 0.035, 0.0], whole) - 0.015).abs() < 1e-12);
        // Not measured yet: the other one's; nothing measured: the whole budget.
        assert!((work_budget(b, [0.0, 0.035, 0.0], none) - 0.015).abs() < 1e-12);
        assert!((work_budget(b, [0.008, 0.0, 0.0], whole) - 0.042).abs() < 1e-12);
        assert_eq!(work_budget(b, [0.0, 0.0, 0.0], whole), b);
        // A moving frame's upscaled preview: its own rest (12 ms), else a resolve's; a still
        // frame's resolve never takes it.
        assert!((work_budget(b, [0.008, 0.035, 0.012], upscaled) - 0.038).abs() < 1e-12);
        assert!((work_budget(b, [0.008, 0.035, 0.0], upscaled) - 0.015).abs() < 1e-12);
        assert!((work_budget(b, [0.008, 0.0, 0.012], whole) - 0.042).abs() < 1e-12);
        // At least a quarter of the budget; none without one.
        assert_eq!(work_budget(b, [0.008, 0.049, 0.0], whole), 0.25 * b);
        assert_eq!(work_budget(0.0, [0.008, 0.035, 0.0], none), 0.0);
    }

    fn settings() -> RenderSettings {
        let gather = crate::gather::GatherMethod::Trace;
        RenderSettings { width: 16, height: 16, photons: 1 << 12, grid_resolution: 8, gather, ..Default::default() }
    }

    /// The Cornell box in a view of the full image, rendered with `s`.
    fn cornell_view(gpu: &Gpu, s: RenderSettings) -> Interactive {
        let renderer = Renderer::new(gpu, &crate::scene::cornell_box(), s).unwrap();
        Interactive::new(Box::new(renderer), Show::Full, 0.0)
    }

    /// What the view shows now: its resolve for display, submitted and read back.
    fn shown(gpu: &Gpu, view: &mut Interactive) -> crate::image_io::DisplayImage {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        view.encode_resolve(&mut enc, 0.0).unwrap();
        gpu.queue.submit([enc.finish()]);
        view.renderer().film().read_display_buffer(gpu).unwrap()
    }

    /// The view's denoised image filtered now, whole, display-encoded.
    fn denoised_now(view: &Interactive) -> crate::image_io::DisplayImage {
        let params = crate::passes::denoise::DenoiseParams::default();
        view.denoising().unwrap().read_display_denoised(&params, 0.0).unwrap()
    }

    /// The loop's promises, checked on the renderers: a camera move and turning the denoiser
    /// on restart the image; the denoised image is shown only where the renderer has a
    /// denoiser, its guides on and the full image shown; a new renderer keeps the view's
    /// camera and gets the denoiser; the display buffer after a denoised resolve is what the
    /// renderer's own denoised read gives.
    #[test]
    fn the_view_restarts_and_denoises_as_a_viewer_expects() {
        let gpu = Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
        let scene = crate::scene::cornell_box();
        let mut view = cornell_view(&gpu, settings());
        for _ in 0..2 {
            view.renderer_mut().iterate().unwrap();
        }
        assert!(view.denoising().is_none(), "no denoiser before it is asked for");
        view.set_denoise(true).unwrap();
        assert_eq!(view.renderer().samples(), 0, "turning the denoiser on must restart the image");
        assert!(view.denoising().is_some());
        view.show = Show::Direct;
        assert!(view.denoising().is_none(), "the denoised image is the full one");
        view.show = Show::Full;
        for _ in 0..3 {
            view.renderer_mut().iterate().unwrap();
        }
        let displayed = shown(&gpu, &mut view);
        assert!(displayed.rgba == denoised_now(&view).rgba, "the display does not show the denoised image");

        let mut camera = view.renderer().camera();
        camera.eye += glam::Vec3::new(0.1, 0.0, 0.0);
        view.set_camera(camera).unwrap();
        assert_eq!(view.renderer().samples(), 0, "a camera move must restart the image");
        let next = Box::new(Renderer::new(&gpu, &scene, settings()).unwrap());
        view.replace(next, true).unwrap();
        assert_eq!(view.renderer().camera(), camera, "a new renderer must keep the view's camera");
        assert!(view.denoising().is_some(), "a new renderer must get the denoiser that is on");
        // The path tracer has none: the raw image is shown.
        let path = Box::new(PathTracer::new(&gpu, &scene, settings()).unwrap());
        view.replace(path, true).unwrap();
        assert!(view.denoise() && view.denoising().is_none());
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        view.encode_resolve(&mut enc, 0.0).unwrap();
        gpu.queue.submit([enc.finish()]);
    }

    /// The denoised image is shown only once the filter has run on this view's iterations: an
    /// image with an iteration under way in bands (which the filter cannot take) before any
    /// filter shows the raw image, not the denoiser's empty output (it showed black: `bench
    /// motion cornell --width 1280 --height 720 --denoise`, relRMSE 1043 % after the stop);
    /// once the iteration is whole the filter runs and the denoised image is shown.
    #[test]
    fn the_denoised_view_waits_for_its_first_filter() {
        let gpu = Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
        let mut view = cornell_view(&gpu, settings());
        view.set_denoise(true).unwrap();
        view.renderer_mut().iterate().unwrap();
        assert!(!view.renderer_mut().iterate_rows(4).unwrap(), "four rows of 16 end no iteration");
        assert!(view.renderer().rows_ahead() > 0);
        let raw = view.renderer().read_display(Show::Full, 0.0).unwrap();
        assert!(raw.rgba.iter().any(|&c| c > 0), "the raw image is not black");
        assert!(shown(&gpu, &mut view).rgba == raw.rgba, "before its first filter the view must show the raw image");
        while !view.renderer_mut().iterate_rows(4).unwrap() {}
        assert_eq!((view.renderer().samples(), view.renderer().rows_ahead()), (2, 0));
        let displayed = shown(&gpu, &mut view);
        assert!(displayed.rgba == denoised_now(&view).rgba, "a whole iteration must be filtered and shown denoised");
        assert!(displayed.rgba != raw.rgba);
    }

    /// The denoiser turned on while the first iteration is under way in row bands (a click in
    /// the page's first frames): the image restarts with it, so that the guides hold the same
    /// iterations as the film in every row — those of a view whose denoiser was on from the
    /// start. (The rows above the band lacked an iteration of albedo: half of it at two.)
    #[test]
    fn the_denoiser_turned_on_within_an_iteration_restarts_it() {
        let gpu = Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
        let albedo = |view: &Interactive| view.renderer().denoising().unwrap().read_guides().unwrap().albedo();
        let mut view = cornell_view(&gpu, settings());
        assert!(!view.renderer_mut().iterate_rows(4).unwrap(), "four rows of 16 end no iteration");
        assert_eq!((view.renderer().samples(), view.renderer().rows_ahead() > 0), (0, true));
        view.set_denoise(true).unwrap();
        assert_eq!(view.renderer().rows_ahead(), 0, "the iteration under way must be dropped");
        let mut fresh = cornell_view(&gpu, settings());
        fresh.set_denoise(true).unwrap();
        for v in [&mut view, &mut fresh] {
            for _ in 0..2 {
                v.renderer_mut().iterate().unwrap();
            }
        }
        let (a, b) = (albedo(&view), albedo(&fresh));
        for (p, (x, y)) in a.pixels.iter().zip(&b.pixels).enumerate() {
            for c in 0..3 {
                assert!((x[c] - y[c]).abs() <= 1e-6, "albedo at pixel {p}: {x:?} against {y:?} from the start");
            }
        }
    }

    /// With a frame budget the filter runs in steps across frames (here each stage's 20 rows as
    /// 16, unmeasured, then 4: bands across the 8-row workgroups), the window's iterations
    /// waiting: once done, the shown image is bit for bit the filter run whole on the same
    /// iterations.
    #[test]
    fn a_filter_in_steps_is_the_whole_filter() {
        let gpu = Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
        let mut view = cornell_view(&gpu, RenderSettings { width: 24, height: 20, ..settings() });
        view.set_denoise(true).unwrap();
        view.set_frame_budget(1e-6);
        let (mut frames, mut steps) = (0, 0);
        while !view.denoised.filtered() {
            assert!(frames < 2000, "no filter in {frames} frames");
            let samples = view.renderer().samples();
            view.frame(u32::MAX).unwrap();
            if view.filter_run.is_some() || view.denoised.filtered() {
                steps += 1;
                assert!(view.renderer().samples() <= samples.max(1), "an iteration ran during the filter");
            }
            frames += 1;
        }
        // One frame begins it; 7 stages of 2 steps each.
        assert_eq!(steps, 1 + 7 * 2, "steps of the filter");
        assert_eq!(view.renderer().rows_ahead(), 0);
        let displayed = shown(&gpu, &mut view);
        assert!(displayed.rgba == denoised_now(&view).rgba, "the filter in steps differs from the whole filter");
        let raw = view.renderer().read_display(Show::Full, 0.0).unwrap();
        assert!(displayed.rgba != raw.rgba, "the shown image is not the denoised one");
    }

    /// The page's loop ([`Interactive::step`], nothing waited for, each unit's time given
    /// afterwards): the filter runs in steps there too — begun where the iteration ends, the
    /// window's iterations waiting, and on after the iteration limit is reached — and once done
    /// the shown image is bit for bit the filter run whole on the same iterations. A unit takes
    /// as many steps, across stages, as its budget allows at the costs measured: with a budget
    /// of a microsecond two a stage (16 rows unmeasured, then the 4 left), with one of a second
    /// the next filter whole in one unit.
    #[test]
    fn the_pages_loop_filters_in_steps_too() {
        let gpu = Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
        let mut view = cornell_view(&gpu, RenderSettings { width: 24, height: 20, ..settings() });
        view.set_denoise(true).unwrap();
        let filter = |view: &mut Interactive, budget: f64, limit: u32| {
            view.set_frame_budget(budget);
            let (mut frames, mut units, mut begun) = (0, 0, false);
            while !begun || view.filtering() {
                assert!(frames < 2000, "no filter in {frames} frames");
                let left = limit - view.renderer().samples().min(limit);
                assert!(left > 0 || view.filtering(), "the iterations are done and no filter is under way");
                let samples = view.renderer().samples();
                if let Some(unit) = view.step(view.frame_budget(), left).unwrap() {
                    if matches!(unit, Unit::Filter(_)) {
                        units += 1;
                        assert_eq!(view.renderer().samples(), samples, "an iteration ran during the filter");
                    }
                    view.finished(&unit, 1e-3);
                }
                view.end_frame();
                begun |= view.filtering();
                frames += 1;
            }
            assert_eq!((view.renderer().samples(), view.renderer().rows_ahead()), (limit, 0));
            let displayed = shown(&gpu, view);
            assert!(displayed.rgba == denoised_now(view).rgba, "the filter in steps differs from the whole filter");
            let raw = view.renderer().read_display(Show::Full, 0.0).unwrap();
            assert!(displayed.rgba != raw.rgba, "the shown image is not the denoised one");
            units
        };
        assert_eq!(filter(&mut view, 1e-6, 1), 7 * 2, "units of the first filter (7 stages)");
        assert_eq!(filter(&mut view, 1.0, 2), 1, "units of the second filter");
    }

    /// While the camera moves, every frame shows a preview iteration of its own view, however
    /// short the budget: a frame whose budget is smaller than the coarsest preview's iteration
    /// still finishes one (the next frame's camera would restart a part of one, and the move
    /// would show nothing).
    #[test]
    fn every_frame_of_a_move_shows_a_preview_of_its_view() {
        let gpu = Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
        // 128 × 64: the coarsest preview is 4 × 2 pixels, two rows.
        let mut view = cornell_view(&gpu, RenderSettings { width: 128, height: 64, ..settings() });
        view.set_frame_budget(1e-6);
        let mut camera = view.renderer().camera();
        for frame in 0..4 {
            camera.eye += glam::Vec3::new(0.02, 0.0, 0.0);
            view.set_camera(camera).unwrap();
            view.frame(u32::MAX).unwrap();
            assert!(view.refine().blend().is_some(), "frame {frame} of the move finished no preview iteration");
        }
    }

    /// A frame that plans its work around a resolve at its end (a quarter of the budget, the
    /// resolve's rest measured at 45 ms of 50) ends with the resolve due, even where it ends
    /// before the display interval: the next frame would else plan the same short share again
    /// and the iterations lose the time. Between resolves the view asks the front end to draw
    /// only now and then while it works, and every frame once it has nothing to do.
    #[test]
    fn a_frame_planned_with_a_resolve_resolves_and_nothing_new_is_drawn_now_and_then() {
        let gpu = Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
        // An iteration long enough to run in bands: no frame below finishes one.
        let mut view = cornell_view(&gpu, RenderSettings { width: 512, height: 384, ..settings() });
        view.set_frame_budget(0.05);
        // The first frames: a preview, then the window's first iteration under way in bands,
        // resolved and drawn.
        while !view.refine().refined() || view.renderer().rows_ahead() == 0 {
            view.frame(u32::MAX).unwrap();
        }
        shown(&gpu, &mut view);
        assert!(view.draw_due(true));
        view.drawn();
        assert_eq!(view.renderer().samples(), 0);
        // The last resolve 45 ms short of the interval: one is due within the 50 ms budget.
        let interval = if view.refine().refined() { BAND_DISPLAY_INTERVAL } else { DISPLAY_INTERVAL };
        let ago = std::time::Duration::from_secs_f64(interval - 0.045);
        view.displayed = Some((web_time::Instant::now() - ago, 0));
        view.rest = [0.001, 0.045, 0.0];
        assert!(!view.display_due() && view.display_due_within(0.05));
        view.frame(u32::MAX).unwrap();
        assert_eq!(view.renderer().samples(), 0, "the frame finished an iteration: nothing is tested");
        assert!(view.display_due(), "a frame planned with a resolve did not end with one due");
        shown(&gpu, &mut view);
        assert!(!view.display_due());
        // Nothing new resolved: drawn only after REDRAW_INTERVAL while the view works (the
        // last drawing set just now: a loaded machine may take longer than the interval over
        // the frames above).
        view.frame(u32::MAX).unwrap();
        view.drawn();
        assert!(!view.draw_due(false), "an unchanged image was drawn again at once");
        view.drawn = Some(web_time::Instant::now() - std::time::Duration::from_secs_f64(REDRAW_INTERVAL));
        assert!(view.draw_due(false));
        view.drawn();
        // A frame with nothing to do (its iteration limit reached): drawn every frame.
        view.frame(0).unwrap();
        assert!(view.draw_due(false), "an idle view paces its loop by drawing");
    }
}
