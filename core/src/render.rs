//! Rendering a whole scene in this process, into a framebuffer or the caller's buffers. Which
//! thread renders which pixels is [`crate::schedule`]'s business, and a pixel's value the
//! integrator's ([`render_spans`](crate::integrator::render_spans)); every pixel's samples come
//! from its own deterministic sequence, so the result does not depend on the threads.

use crate::error::Error;
use crate::framebuffer::{Chunk, Framebuffer, Target};
use crate::geometry::Counters;
use crate::scene::Scene;
use crate::schedule::{render_local, thread_pool, threads_for, RankStats, RunOptions, WorkerStats};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
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

/// Renders `scene` in this process with its settings (threads, decomposition) on a pool of its
/// own. `progress` is told about finished pixels.
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
    let pool = thread_pool(threads_for(scene))?;
    let rank = render_local(scene, &pool, RunOptions::default(), &sink)?;
    let stats = RenderStats::of(vec![rank], start.elapsed());
    Ok((fb.into_inner().unwrap_or_else(|e| e.into_inner()), stats))
}

/// Renders `scene` on `pool` straight into the caller's `target` (which must be the scene's
/// size): colour in the target's format, depth when it has a depth plane. No image of the
/// renderer's own is allocated. Setting `cancel` (from any thread) stops the render within a
/// tile per thread with [`Error::Cancelled`]; the target then holds the pixels finished so far.
/// The same pixels as [`render`], bit for bit (decomposition and thread count do not matter).
pub fn render_into(
    scene: &Scene,
    pool: &rayon::ThreadPool,
    target: Target,
    cancel: &AtomicBool,
    progress: Progress,
) -> Result<RenderStats, Error> {
    let s = &scene.settings;
    target.check().map_err(Error::Target)?;
    if (target.width, target.height) != (s.width, s.height) {
        return Err(Error::Target(format!(
            "the target is {}x{} pixels but the scene renders {}x{}",
            target.width, target.height, s.width, s.height
        )));
    }
    let options = RunOptions {
        cancel,
        depth: target.depth.is_some(),
    };
    let target = Mutex::new(target);
    let total = s.width as u64 * s.height as u64;
    let done = AtomicU64::new(0);
    let start = Instant::now();
    let sink = |c: Chunk| {
        let n = c.pixels();
        target
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .put_chunk(&c);
        progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
    };
    let rank = render_local(scene, pool, options, &sink)?;
    Ok(RenderStats::of(vec![rank], start.elapsed()))
}
