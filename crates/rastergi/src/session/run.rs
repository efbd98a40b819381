//! The loop of a progressive render: iterations up to a total, a time limit, a target for
//! the error estimated without a reference, periodic checkpoints and a stop flag (which the
//! program's signal handlers set). The front end watches through an [`Observer`] (a progress
//! bar, Python's Ctrl-C) and writes what it wants when [`run`] returns.
//!
//! The GPU queue is kept short so that the limits and a stop act soon: at most 8 iterations
//! in flight, or one where iterations take over 50 ms; the film is read back (the error
//! estimate) at most once a second, and only where it is wanted.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicUsize, Ordering};

use web_time::{Duration, Instant};

use crate::error::Result;
use crate::passes::film::FilmState;
use crate::progressive::Progressive;

/// When a render stops (besides its stop flag and its observer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Iterations in all, those the renderer holds already (a resumed checkpoint's) included.
    pub iterations: u32,
    /// Seconds of rendering.
    pub time_limit: Option<f64>,
    /// Stop once the estimated relative RMSE falls under this (and the film holds 4 blocks).
    pub target_error: Option<f64>,
    /// Seconds between checkpoints ([`Observer::checkpoint`]); `None`: none.
    pub checkpoint_every: Option<f64>,
}

impl Limits {
    /// `iterations` in all and nothing else.
    pub fn iterations(iterations: u32) -> Limits {
        Limits { iterations, time_limit: None, target_error: None, checkpoint_every: None }
    }
}

/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stop {
    /// All the iterations are done.
    Done,
    TimeLimit,
    /// The estimated error that reached the target.
    TargetError(f64),
    /// The stop flag's value (the program sets a signal's number).
    Signal(i32),
    /// [`Observer::synced`] asked to stop.
    Requested,
}

/// How a render ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    pub stop: Stop,
    /// The iterations the renderer held when the loop started.
    pub first: u32,
    /// The iterations it holds now (all finished on the GPU).
    pub done: u32,
    /// Seconds the loop ran.
    pub seconds: f64,
    /// The last error estimate read during the loop, if one was.
    pub error: Option<f64>,
}

/// What a front end does while a render runs; every method has a default that does nothing.
pub trait Observer {
    /// An iteration was submitted; the renderer holds `done` (a test's hook).
    fn iterated(&mut self, _done: u32) {}
    /// The submitted iterations have finished: `done` in all. `Break` stops the render
    /// ([`Stop::Requested`]).
    fn synced(&mut self, _done: u32) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
    /// Whether the error estimate is wanted (once a second) without a target error: for a
    /// progress display.
    fn wants_estimate(&self) -> bool {
        false
    }
    /// A new error estimate.
    fn estimated(&mut self, _error: f64) {}
    /// A checkpoint is due ([`Limits::checkpoint_every`]): the renderer and its film.
    fn checkpoint(&mut self, _renderer: &dyn Progressive, _film: FilmState) -> Result<()> {
        Ok(())
    }
}

/// An observer that watches nothing.
impl Observer for () {}

/// Iterations in flight at most between waits.
const MAX_QUEUED: u32 = 8;

/// Runs `renderer` until `limits` or the stop flag (`stop`: nonzero stops, its value is
/// [`Stop::Signal`]'s) or `observer` end it, and waits for the GPU.
pub fn run(
    renderer: &mut dyn Progressive,
    limits: &Limits,
    stop: Option<&AtomicUsize>,
    observer: &mut dyn Observer,
) -> Result<Outcome> {
    let start = Instant::now();
    let first = renderer.samples();
    let mut done = first;
    let mut last_checkpoint = Instant::now();
    let mut last_estimate: Option<Instant> = None;
    let mut error = None;
    let (mut queued, mut sync_every, mut last_sync) = (0u32, MAX_QUEUED, Instant::now());
    let why = loop {
        let sig = stop.map_or(0, |s| s.load(Ordering::Relaxed));
        if sig != 0 {
            break Stop::Signal(sig as i32);
        }
        if done >= limits.iterations {
            break Stop::Done;
        }
        renderer.iterate()?;
        done += 1;
        observer.iterated(done);
        // Keep the GPU queue short so the progress, the limits and a signal act soon: at
        // most 8 iterations in flight, or one where iterations take over 50 ms.
        queued += 1;
        if queued < sync_every {
            continue;
        }
        renderer.wait()?;
        let per_iteration = last_sync.elapsed().as_secs_f64() / queued as f64;
        sync_every = if per_iteration > 0.05 { 1 } else { MAX_QUEUED };
        (queued, last_sync) = (0, Instant::now());
        if observer.synced(done).is_break() {
            break Stop::Requested;
        }
        if limits.time_limit.is_some_and(|s| start.elapsed().as_secs_f64() >= s) {
            break Stop::TimeLimit;
        }
        // The error estimate reads the film back: at most once a second.
        let estimate_due = last_estimate.is_none_or(|t| t.elapsed() >= Duration::from_secs(1));
        let checkpoint_due =
            limits.checkpoint_every.is_some_and(|every| last_checkpoint.elapsed().as_secs_f64() >= every);
        if !(checkpoint_due || estimate_due && (limits.target_error.is_some() || observer.wants_estimate())) {
            continue;
        }
        let film = renderer.film_state()?;
        last_estimate = Some(Instant::now());
        error = film.error_estimate();
        if let Some(e) = error {
            observer.estimated(e);
        }
        // The halves need a few blocks each before their difference means much.
        let blocks = renderer.film().blocks();
        if let (Some(target), Some(e)) = (limits.target_error, error)
            && blocks >= 4
            && e <= target
        {
            break Stop::TargetError(e);
        }
        if checkpoint_due {
            observer.checkpoint(renderer, film)?;
            last_checkpoint = Instant::now();
        }
    };
    renderer.wait()?;
    Ok(Outcome { stop: why, first, done, seconds: start.elapsed().as_secs_f64(), error })
}
