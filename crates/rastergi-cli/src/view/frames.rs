//! How the viewer runs its renderer: the photon map or the path tracer ([`Active`]), a frame's
//! batch of iterations within [`FRAME_BUDGET`] ([`iterate_frame`], also `rastergi bench
//! frames`'s), and the iteration rate the panel shows.

use std::time::{Duration, Instant};

use anyhow::Result;
use rastergi::progressive::Progressive;

/// GPU time aimed at per displayed frame: iterations are batched up to this.
pub const FRAME_BUDGET: Duration = Duration::from_millis(30);
/// Most iterations in one frame (keeps a frame short when iterations are very cheap).
pub const MAX_BATCH: u32 = 64;
/// Iterations per second over the last half second or more.
pub(super) struct Rate {
    pub(super) since: Instant,
    pub(super) count: u32,
    pub(super) per_second: f64,
}

impl Rate {
    pub(super) fn add(&mut self, iterations: u32) {
        self.count += iterations;
        let dt = self.since.elapsed().as_secs_f64();
        if dt >= 0.5 {
            self.per_second = self.count as f64 / dt;
            self.since = Instant::now();
            self.count = 0;
        }
    }
}

/// One frame's iterations: up to `limit`, stopping once [`FRAME_BUDGET`] has passed (so at
/// least one where `limit` > 0), then waits for them and sets `batch` (the next frame's
/// limit) to as many as fit in the budget at this frame's time per iteration, 1 to
/// [`MAX_BATCH`]. Returns how many ran. `rastergi bench frames` runs the same.
pub fn iterate_frame(renderer: &mut dyn Progressive, limit: u32, batch: &mut u32) -> Result<u32> {
    let start = Instant::now();
    let mut done = 0;
    while done < limit {
        renderer.iterate()?;
        done += 1;
        if start.elapsed() >= FRAME_BUDGET {
            break;
        }
    }
    if done > 0 {
        renderer.wait()?;
        let per_iteration = start.elapsed().as_secs_f64() / done as f64;
        *batch = ((FRAME_BUDGET.as_secs_f64() / per_iteration.max(1e-6)) as u32).clamp(1, MAX_BATCH);
    }
    Ok(done)
}
