//! The pixel kernel: the values of a list of spans of pixels, each the average of its samples
//! (uniform, or adaptive supersampling) of the radiance along its camera rays.

use super::{IorStack, Whitted};
use crate::adaptive;
use crate::framebuffer::Span;
use crate::geometry::Counters;
use crate::math::Vec3A;
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
    let sampler = PixelSampler::new(n, s.frame);
    if plan.is_none() && n == 1 && s.shutter.is_none() {
        // One sample at each pixel's centre at the scene's time: the loop below without its
        // sampler, sample time and sum (bit for bit the same values).
        out.resize(count * 4, 1.0);
        let mut px = out.chunks_exact_mut(4);
        for span in spans {
            let py = span.y as f32 + 0.5;
            for x in span.xs() {
                let v = match scene.primary(x as f32 + 0.5, py, s.time) {
                    Some(ray) => {
                        c.primary += 1;
                        // `ZERO +` as the sum below: a -0.0 comes out +0.0.
                        Vec3A::ZERO + integrator.radiance(&ray, 0, 1.0, &media, c)
                    }
                    None => Vec3A::ZERO,
                };
                let v = if v.is_finite() {
                    v
                } else {
                    c.nan_pixels += 1;
                    Vec3A::ZERO
                };
                if let Some(p) = px.next() {
                    p[..3].copy_from_slice(&v.to_array());
                }
            }
        }
        return out;
    }
    for span in spans {
        let y = span.y;
        for x in span.xs() {
            let mut shade = |jx: f32, jy: f32, time: f32| {
                let (px, py) = (x as f32 + jx, y as f32 + jy);
                // Outside a fisheye's image circle there is no ray: black, as in Tachyon.
                match scene.primary(px, py, time) {
                    Some(ray) => {
                        c.primary += 1;
                        integrator.radiance(&ray, 0, 1.0, &media, c)
                    }
                    None => Vec3A::ZERO,
                }
            };
            let mut v = match &plan {
                Some(p) => p.pixel(x, y, s.frame, &mut |jx, jy| {
                    shade(jx, jy, sample_time(scene, x, y, 0, n, Some((jx, jy))))
                }),
                None => {
                    let mut sum = Vec3A::ZERO;
                    let seed = sampler.pixel_seed(x, y);
                    for i in 0..n {
                        let (jx, jy) = sampler.sample(x, y, seed, i);
                        sum += shade(jx, jy, sample_time(scene, x, y, i, n, None));
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
    let sampler = PixelSampler::new(n, s.frame);
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
