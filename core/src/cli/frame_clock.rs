//! Where one rank's time goes in a sequence (`--stats`): getting the next frame, rendering
//! frames (set, render, write), and reporting them. On a job of several ranks the time a rank
//! spends waiting, and how long after the others it finishes, is what the frames lose to the
//! ranks being many, whatever the load of the machine.

use std::io::Write;
use std::time::{Duration, Instant};

pub(super) struct FrameClock {
    /// When the command started (before the scene was loaded).
    start: Instant,
    /// From `start` to the first request for a frame.
    ready: Option<Duration>,
    frames: usize,
    waiting: Duration,
    rendering: Duration,
    reporting: Duration,
}

impl FrameClock {
    pub(super) fn new(start: Instant) -> FrameClock {
        FrameClock {
            start,
            ready: None,
            frames: 0,
            waiting: Duration::ZERO,
            rendering: Duration::ZERO,
            reporting: Duration::ZERO,
        }
    }

    /// Getting the next frame (asking for it, claiming it, passing it to the group).
    pub(super) fn wait<T>(&mut self, f: impl FnOnce() -> T) -> T {
        if self.ready.is_none() {
            self.ready = Some(self.start.elapsed());
        }
        let t = Instant::now();
        let v = f();
        self.waiting += t.elapsed();
        v
    }

    /// Rendering one frame and writing it.
    pub(super) fn render<T>(&mut self, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let v = f();
        self.rendering += t.elapsed();
        self.frames += 1;
        v
    }

    /// Reporting a frame (on rank 0: recording it).
    pub(super) fn report<T>(&mut self, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let v = f();
        self.reporting += t.elapsed();
        v
    }

    /// Prints this rank's line for `--stats`, once it has no frame left: in one write, so that
    /// the lines of ranks printing at once do not mix.
    pub(super) fn print(&self, rank: usize, ranks: usize) {
        let line = format!("luxon: {}\n", self.summary(rank, ranks));
        let _ = std::io::stderr().lock().write_all(line.as_bytes());
    }

    fn summary(&self, rank: usize, ranks: usize) -> String {
        let ready = self.ready.unwrap_or_default().as_secs_f64();
        let end = self.start.elapsed().as_secs_f64();
        let loop_time = (end - ready).max(f64::MIN_POSITIVE);
        let share = |d: Duration| 100.0 * d.as_secs_f64() / loop_time;
        format!(
            "rank {rank} of {ranks}: ready after {ready:.3} s, {} frames rendered in {:.3} s \
             ({:.1} %), waiting for frames {:.3} s ({:.1} %), reporting {:.3} s ({:.1} %), \
             done after {end:.3} s",
            self.frames,
            self.rendering.as_secs_f64(),
            share(self.rendering),
            self.waiting.as_secs_f64(),
            share(self.waiting),
            self.reporting.as_secs_f64(),
            share(self.reporting),
        )
    }
}
