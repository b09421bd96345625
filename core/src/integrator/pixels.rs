//! The pixel kernel: the values of a list of spans of pixels, each the average of its samples
//! (uniform, or adaptive supersampling) of the radiance along its camera rays.

use super::{IorStack, Whitted};
use crate::adaptive;
use crate::framebuffer::Span;
use crate::geometry::Counters;
use crate::math::Vec3A;
use crate::ray::Ray;
use crate::sampler::{time_at, time_sample, PixelSampler};
use crate::scene::Scene;

/// The time of sample `i` of `n` of pixel (`x`, `y`): the scene's `time`, or with motion blur
/// a point of the shutter (`time_sample`; a shutter of no length gives +0.0, the still
/// frame's time). `at`: an adaptive sample's position in the pixel, which gives its time
/// instead of its index. Always inlined: a still frame then costs no call per sample.
#[inline(always)]
fn sample_time(scene: &Scene, x: u32, y: u32, i: u32, n: u32, at: Option<(f32, f32)>) -> f32 {
    let s = &scene.settings;
    match s.shutter {
        None => s.time,
        Some((open, close)) => {
            let u = match at {
                Some((jx, jy)) => time_at(jx, jy, x, y, s.frame),
                None => time_sample(x, y, i, n, s.frame),
            };
            open + u * (close - open)
        }
    }
}

/// Camera rays made at a time.
const BATCH_RAYS: usize = 64;

/// Image points and times whose camera rays are made together ([`Scene::primaries`]) before
/// any of them is traced, so that no ray waits on the arithmetic that made it.
struct Batch {
    len: usize,
    xs: [f32; BATCH_RAYS],
    ys: [f32; BATCH_RAYS],
    times: [f32; BATCH_RAYS],
    rays: [Option<Ray>; BATCH_RAYS],
}

impl Batch {
    fn new() -> Batch {
        Batch {
            len: 0,
            xs: [0.0; BATCH_RAYS],
            ys: [0.0; BATCH_RAYS],
            times: [0.0; BATCH_RAYS],
            rays: [None; BATCH_RAYS],
        }
    }

    fn is_full(&self) -> bool {
        self.len == BATCH_RAYS
    }

    fn push(&mut self, x: f32, y: f32, time: f32) {
        let k = self.len;
        (self.xs[k], self.ys[k], self.times[k]) = (x, y, time);
        self.len += 1;
    }

    /// The rays of the points pushed since the last call, in their order; forgets the points.
    fn rays(&mut self, scene: &Scene) -> &[Option<Ray>] {
        let k = std::mem::take(&mut self.len);
        let (xs, ys, times) = (&self.xs[..k], &self.ys[..k], &self.times[..k]);
        scene.primaries(xs, ys, times, &mut self.rays[..k]);
        &self.rays[..k]
    }
}

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
    let sampler = PixelSampler::new(n, s.frame, s.tachyon.centre_sample);
    if let Some(plan) = &plan {
        for span in spans {
            let y = span.y;
            for x in span.xs() {
                let v = plan.pixel(x, y, s.frame, &mut |jx, jy| {
                    let time = sample_time(scene, x, y, 0, n, Some((jx, jy)));
                    // Outside a fisheye's image circle there is no ray: black, as in Tachyon.
                    match scene.primary(x as f32 + jx, y as f32 + jy, time) {
                        Some(ray) => {
                            c.primary += 1;
                            integrator.radiance(&ray, 0, 1.0, &media, c)
                        }
                        None => Vec3A::ZERO,
                    }
                });
                push_pixel(&mut out, v, c);
            }
        }
        return out;
    }
    // Each span's samples, pixel after pixel, are made into rays a batch at a time; the rays
    // are then traced in the same order, each pixel's sum complete after its `n`th.
    let mut batch = Batch::new();
    for span in spans {
        let y = span.y;
        let (mut made, mut i, mut seed) = (0, 0, 0);
        let (mut traced, mut sum) = (0, Vec3A::ZERO);
        while made < span.count {
            while made < span.count && !batch.is_full() {
                let x = span.x0 + made * span.step;
                if i == 0 && n > 1 {
                    seed = sampler.pixel_seed(x, y);
                }
                let (jx, jy) = sampler.sample(x, y, seed, i);
                let time = sample_time(scene, x, y, i, n, None);
                batch.push(x as f32 + jx, y as f32 + jy, time);
                i += 1;
                if i == n {
                    (i, made) = (0, made + 1);
                }
            }
            for ray in batch.rays(scene) {
                // Outside a fisheye's image circle there is no ray: black, as in Tachyon.
                sum += match ray {
                    Some(ray) => {
                        c.primary += 1;
                        integrator.radiance(ray, 0, 1.0, &media, c)
                    }
                    None => Vec3A::ZERO,
                };
                traced += 1;
                if traced == n {
                    // From `ZERO`: a -0.0 comes out +0.0; times 1.0 for one sample is exact.
                    push_pixel(&mut out, sum * inv_n, c);
                    (traced, sum) = (0, Vec3A::ZERO);
                }
            }
        }
    }
    out
}

/// Appends a pixel's value; a NaN never aborts a render: it is counted and the pixel clamped.
fn push_pixel(out: &mut Vec<f32>, v: Vec3A, c: &mut Counters) {
    let v = if v.is_finite() {
        v
    } else {
        c.nan_pixels += 1;
        Vec3A::ZERO
    };
    out.extend_from_slice(&[v.x, v.y, v.z, 1.0]);
}

/// The depth of the pixels of `spans`, span after span: for each pixel, the smallest distance
/// along its camera rays from where they start (the eye, a lens point, an orthographic camera's
/// image plane) to the first surface they hit, [`f32::INFINITY`] where none hits (volumes are
/// not surfaces). The rays are the colour's own sample positions (under adaptive sampling its
/// base samples), one closest-hit query each; the colour path is not touched.
pub fn render_depth(scene: &Scene, spans: &[Span], c: &mut Counters) -> Vec<f32> {
    let s = &scene.settings;
    let count: usize = spans.iter().map(|s| s.count as usize).sum();
    let mut out = Vec::with_capacity(count);
    let n = s.samples.max(1);
    let plan = s.adaptive.as_ref().map(|a| adaptive::Plan::new(n, a));
    let sampler = PixelSampler::new(n, s.frame, s.tachyon.centre_sample);
    for span in spans {
        let y = span.y;
        for x in span.xs() {
            let mut nearest = f32::INFINITY;
            let mut probe = |jx: f32, jy: f32, time: f32| {
                let (px, py) = (x as f32 + jx, y as f32 + jy);
                if let Some(ray) = scene.primary(px, py, time) {
                    c.primary += 1;
                    if let Some(hit) = scene.intersect(&ray, f32::INFINITY, c) {
                        nearest = nearest.min(hit.t);
                    }
                }
                // Every sample alike: adaptive sampling splits no cell, so only its base
                // samples are probed.
                Vec3A::ZERO
            };
            match &plan {
                Some(p) => {
                    p.pixel(x, y, s.frame, &mut |jx, jy| {
                        probe(jx, jy, sample_time(scene, x, y, 0, n, Some((jx, jy))))
                    });
                }
                None => {
                    let seed = sampler.pixel_seed(x, y);
                    for i in 0..n {
                        let (jx, jy) = sampler.sample(x, y, seed, i);
                        probe(jx, jy, sample_time(scene, x, y, i, n, None));
                    }
                }
            }
            out.push(nearest);
        }
    }
    out
}
