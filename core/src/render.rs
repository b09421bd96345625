//! Rendering a scene into a framebuffer: the image is cut into tiles that rayon's work stealing
//! spreads over the threads. Every pixel's samples come from its own deterministic sequence, so
//! the result does not depend on which thread renders which tile.

use crate::error::Error;
use crate::framebuffer::Framebuffer;
use crate::geometry::Counters;
use crate::integrator::{IorStack, Whitted};
use crate::math::Vec3A;
use crate::sampler::pixel_sample;
use crate::scene::Scene;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// What a render did.
#[derive(Clone, Debug)]
pub struct RenderStats {
    pub counters: Counters,
    pub render_time: Duration,
    pub threads: usize,
    pub tiles: usize,
}

/// Called after each finished tile with (tiles done, tiles in all); may be called from any thread.
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

#[derive(Clone, Copy, Debug)]
struct Tile {
    x0: u32,
    y0: u32,
    w: u32,
    h: u32,
}

fn tiles(width: u32, height: u32, size: u32) -> Vec<Tile> {
    let size = size.max(1);
    let mut v = Vec::new();
    for y0 in (0..height).step_by(size as usize) {
        for x0 in (0..width).step_by(size as usize) {
            v.push(Tile {
                x0,
                y0,
                w: size.min(width - x0),
                h: size.min(height - y0),
            });
        }
    }
    v
}

fn render_tile(scene: &Scene, t: Tile, c: &mut Counters) -> Vec<f32> {
    let s = &scene.settings;
    let integrator = Whitted { scene };
    let mut out = Vec::with_capacity((t.w * t.h * 4) as usize);
    let n = s.samples.max(1);
    let inv_n = 1.0 / n as f32;
    let media = IorStack::default();
    for y in t.y0..t.y0 + t.h {
        for x in t.x0..t.x0 + t.w {
            let mut sum = Vec3A::ZERO;
            for i in 0..n {
                let (jx, jy) = pixel_sample(x, y, i, n, s.frame);
                let ray = scene
                    .camera
                    .ray(x as f32 + jx, y as f32 + jy, s.width, s.height, s.time);
                c.primary += 1;
                sum += integrator.radiance(&ray, 0, 1.0, &media, c);
            }
            let mut v = sum * inv_n;
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

/// Renders `scene` with its settings. `progress` is told about finished tiles.
pub fn render(scene: &Scene, progress: Progress) -> Result<(Framebuffer, RenderStats), Error> {
    let s = &scene.settings;
    let threads = match s.threads {
        Some(n) => n as usize,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("luxon-render-{i}"))
        .build()
        .map_err(|e| Error::Render(format!("cannot start {threads} render threads: {e}")))?;
    let list = tiles(s.width, s.height, s.tile_size);
    let total = list.len() as u64;
    let done = AtomicU64::new(0);
    let start = Instant::now();
    let results: Vec<(Vec<f32>, Counters)> = pool.install(|| {
        list.par_iter()
            .map(|&t| {
                let mut c = Counters::default();
                // After a plugin fault the remaining tiles are skipped.
                let px = if scene.customs.fault.is_raised() {
                    vec![0.0; (t.w * t.h * 4) as usize]
                } else {
                    render_tile(scene, t, &mut c)
                };
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                (px, c)
            })
            .collect()
    });
    if let Some(m) = scene.customs.fault.message() {
        return Err(Error::Plugin(m));
    }
    let mut fb = Framebuffer::new(s.width, s.height);
    let mut counters = Counters::default();
    for (t, (px, c)) in list.iter().zip(&results) {
        fb.put_block(t.x0, t.y0, t.w, t.h, px);
        counters.add(c);
    }
    Ok((
        fb,
        RenderStats {
            counters,
            render_time: start.elapsed(),
            threads,
            tiles: list.len(),
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        let t = tiles(37, 20, 16);
        let area: u32 = t.iter().map(|t| t.w * t.h).sum();
        assert_eq!(area, 37 * 20);
        assert_eq!(t.len(), 3 * 2);
    }
}
