//! Rendering pixels, and a whole scene into a framebuffer in this process. Which thread renders
//! which pixels is [`crate::schedule`]'s business; every pixel's samples come from its own
//! deterministic sequence, so the result does not depend on it.

use crate::adaptive;
use crate::error::Error;
use crate::framebuffer::Framebuffer;
use crate::geometry::Counters;
use crate::integrator::{IorStack, Whitted};
use crate::math::Vec3A;
use crate::sampler::pixel_sample;
use crate::scene::Scene;
use crate::schedule::{render_local, threads_for, Chunk, RankStats, Span};
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
}

impl RenderStats {
    pub fn of(ranks: Vec<RankStats>, render_time: Duration) -> RenderStats {
        let mut total = crate::schedule::WorkerStats::default();
        for r in &ranks {
            total.add(&r.total());
        }
        RenderStats {
            counters: total.counters,
            render_time,
            threads: ranks.first().map_or(0, |r| r.threads.len()),
            tiles: total.units as usize,
            ranks,
        }
    }
}

/// Called with (pixels done, pixels in all); may be called from any thread.
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// Renders the pixels of `spans`, returning their RGBA values span after span.
pub fn render_spans(scene: &Scene, spans: &[Span], c: &mut Counters) -> Vec<f32> {
    let s = &scene.settings;
    let integrator = Whitted::new(scene);
    let count: usize = spans.iter().map(|s| s.count as usize).sum();
    let mut out = Vec::with_capacity(count * 4);
    let n = s.samples.max(1);
    let inv_n = 1.0 / n as f32;
    let media = IorStack::default();
    let plan = s.adaptive.as_ref().map(|a| adaptive::Plan::new(n, a));
    for span in spans {
        let y = span.y;
        for x in span.xs() {
            let mut shade = |jx: f32, jy: f32| {
                let (px, py) = (x as f32 + jx, y as f32 + jy);
                // Outside a fisheye's image circle there is no ray: black, as in Tachyon.
                match scene.camera.primary(px, py, s.width, s.height, s.time) {
                    Some(ray) => {
                        c.primary += 1;
                        integrator.radiance(&ray, 0, 1.0, &media, c)
                    }
                    None => Vec3A::ZERO,
                }
            };
            let mut v = match &plan {
                Some(p) => p.pixel(x, y, s.frame, &mut shade),
                None => {
                    let mut sum = Vec3A::ZERO;
                    for i in 0..n {
                        let (jx, jy) = pixel_sample(x, y, i, n, s.frame);
                        sum += shade(jx, jy);
                    }
                    sum * inv_n
                }
            };
            if !v.is_finite() {
                // A NaN never aborts a render: count it and clamp the pixel.
                c.nan_pixels += 1;
                v = Vec3A::ZERO;
            }
            out.extend_from_slice(&[v.x, v.y, v.z, 1.0]);
        }
    }
    out
}

/// Renders `scene` in this process with its settings (threads, decomposition). `progress` is
/// told about finished pixels.
pub fn render(scene: &Scene, progress: Progress) -> Result<(Framebuffer, RenderStats), Error> {
    let s = &scene.settings;
    let fb = Mutex::new(Framebuffer::new(s.width, s.height));
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
