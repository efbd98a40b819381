//! The iteration rate the viewer's panel shows (a frame's work is the library's
//! [`rastergi::session::interactive::Interactive::frame`]).

use std::time::Instant;

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
