//! Rendering a whole scene into a framebuffer in this process. Which thread renders which
//! pixels is [`crate::schedule`]'s business, and a pixel's value the integrator's
//! ([`render_spans`](crate::integrator::render_spans)); every pixel's samples come from its own
//! deterministic sequence, so the result does not depend on the threads.

use crate::error::Error;
use crate::framebuffer::{Chunk, Framebuffer};
use crate::geometry::Counters;
use crate::scene::Scene;
use crate::schedule::{render_local, threads_for, RankStats, WorkerStats};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// What a render did.
#[derive(Clone, Debug)]
pub struct RenderStats {
    pub counters: Counters,
    pub render_time: Duration,
    /// Render threads of each process.
    pub threads: usize,
    /// Units of work (tiles, blocks or rows) rendered.
    pub tiles: usize,
    /// The work of every process (one entry without MPI), per thread.
    pub ranks: Vec<RankStats>,
    /// NaN results per plugin instance over every process (see [`Scene::nan_counts`]).
    pub nan_sources: Vec<u64>,
}

impl RenderStats {
    pub fn of(ranks: Vec<RankStats>, render_time: Duration) -> RenderStats {
        let mut total = WorkerStats::default();
        let mut nan_sources: Vec<u64> = Vec::new();
        for r in &ranks {
            total.add(&r.total());
            if nan_sources.len() < r.nan_sources.len() {
                nan_sources.resize(r.nan_sources.len(), 0);
            }
            for (sum, n) in nan_sources.iter_mut().zip(&r.nan_sources) {
                *sum += n;
            }
        }
        RenderStats {
            counters: total.counters,
            render_time,
            threads: ranks.first().map_or(0, |r| r.threads.len()),
            tiles: total.units as usize,
            ranks,
            nan_sources,
        }
    }
}

/// Called with (pixels done, pixels in all); may be called from any thread.
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// Renders `scene` in this process with its settings (threads, decomposition). `progress` is
/// told about finished pixels.
pub fn render(scene: &Scene, progress: Progress) -> Result<(Framebuffer, RenderStats), Error> {
    let s = &scene.settings;
    let (fb, _image) = Framebuffer::charged(s.width, s.height, &scene.budget)?;
    let fb = Mutex::new(fb);
    let total = s.width as u64 * s.height as u64;
    let done = AtomicU64::new(0);
    let start = Instant::now();
    let sink = |c: Chunk| {
        let n = c.pixels();
        fb.lock().unwrap_or_else(|e| e.into_inner()).put_chunk(&c);
        progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
    };
    let rank = render_local(scene, threads_for(scene), &sink)?;
    let stats = RenderStats::of(vec![rank], start.elapsed());
    Ok((fb.into_inner().unwrap_or_else(|e| e.into_inner()), stats))
}
