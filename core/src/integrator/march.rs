//! Volumes along a ray: front-to-back compositing of the rendered volumes' samples (what the
//! transfer functions give them, shaded by their gradients), and their transmittance for shadow
//! rays. How a volume is prepared for this (transfer function, empty-space skipping cells) is
//! [`crate::volume_render`]'s.

use crate::geometry::Counters;
use crate::math::Vec3A;
use crate::ray::Ray;
use crate::scene::{Light, Scene};
use crate::volume::Volume;
use crate::volume_render::{Crossing, RenderVolume, Shading, MAX_RENDERED_VOLUMES};

/// Steps along `ray` through every rendered volume it crosses before `t_end`, calling
/// `visit(t, dt, crossings active at t)` for each sample until it returns `false`. Samples sit
/// at the middle of segments `step` long from the first entry (the last one shorter).
fn walk(
    scene: &Scene,
    ray: &Ray,
    t_end: f32,
    c: &mut Counters,
    mut visit: impl FnMut(f32, f32, &[Crossing], &mut Counters) -> bool,
) {
    let mut all = [Crossing::default(); MAX_RENDERED_VOLUMES];
    let mut n = 0;
    let mut step = f32::INFINITY;
    let (mut start, mut stop) = (f32::INFINITY, f32::NEG_INFINITY);
    for (v, rv) in scene.render_volumes.iter().enumerate() {
        if let Some(x) = rv.crossing(v, ray, t_end, &scene.clips) {
            all[n] = x;
            n += 1;
            step = step.min(rv.step);
            start = start.min(x.t0);
            stop = stop.max(x.t1);
        }
    }
    if n == 0 {
        return;
    }
    let all = &all[..n];
    let skip = scene.settings.volume_skip;
    let count = ((stop - start) / step).ceil().max(1.0) as u64;
    let mut active = [Crossing::default(); MAX_RENDERED_VOLUMES];
    let mut i = 0u64;
    while i < count {
        let a = start + i as f32 * step;
        let b = (a + step).min(stop);
        if b <= a {
            break;
        }
        let t = 0.5 * (a + b);
        let mut k = 0;
        for x in all {
            if t >= x.t0 && t < x.t1 {
                active[k] = *x;
                k += 1;
            }
        }
        if skip {
            // Skip when every volume here is transparent in its whole cell: up to the first
            // cell exit or the next volume's entry, whichever comes first.
            let mut target = all
                .iter()
                .filter(|x| x.t0 > t)
                .fold(f32::INFINITY, |m, x| m.min(x.t0));
            let mut empty = true;
            for x in &active[..k] {
                match scene.render_volumes[x.v].cell(x, t) {
                    Some((max, exit)) if max <= 0.0 => target = target.min(exit),
                    _ => {
                        empty = false;
                        break;
                    }
                }
            }
            if empty {
                // A margin keeps samples near the cell's face (rounding) out of the skip.
                let target = target - 1e-3 * step;
                let j = ((target - start) / step - 0.5).floor();
                i = if j.is_finite() && j > i as f32 {
                    (j as u64).min(count)
                } else {
                    i + 1
                };
                continue;
            }
        }
        if k > 0 && !visit(t, b - a, &active[..k], c) {
            return;
        }
        i += 1;
    }
}

/// A light as seen from point `p`: direction toward it, distance, radiance arriving (area
/// lights are taken at their centre).
fn toward(light: &Light, p: Vec3A) -> Option<(Vec3A, f32, Vec3A)> {
    let point = |q: Vec3A, color: Vec3A, a: &[f32; 3]| {
        let d = q - p;
        let dist = d.length();
        (dist > 0.0).then(|| {
            let att = Light::attenuate(a, dist);
            (d / dist, dist, color * att)
        })
    };
    match light {
        Light::Directional {
            to_light, color, ..
        } => Some((*to_light, f32::INFINITY, *color)),
        Light::Point {
            position,
            color,
            attenuation,
            ..
        } => point(*position, *color, attenuation),
        Light::Spot {
            position,
            axis,
            cos_inner,
            cos_outer,
            fade,
            color,
            attenuation,
            ..
        } => {
            let cos = (p - *position).normalize_or_zero().dot(*axis);
            if cos <= *cos_outer {
                return None;
            }
            let w = Light::spot_weight(cos, *cos_inner, *cos_outer, *fade);
            point(*position, *color * w, attenuation)
        }
        Light::Sphere {
            center,
            color,
            attenuation,
            ..
        } => point(*center, *color, attenuation),
        Light::Rect {
            corner,
            edge1,
            edge2,
            normal,
            color,
            attenuation,
            ..
        } => {
            if (p - *corner).dot(*normal) <= 0.0 {
                return None;
            }
            point(*corner + 0.5 * (*edge1 + *edge2), *color, attenuation)
        }
    }
}

/// What the volumes add along `ray` before `t_end` and what they let through:
/// (colour, transmittance). Marching stops once the transmittance is below `cutoff`.
pub fn march(scene: &Scene, ray: &Ray, t_end: f32, cutoff: f32, c: &mut Counters) -> (Vec3A, f32) {
    let mut color = Vec3A::ZERO;
    let mut trans = 1.0f32;
    walk(scene, ray, t_end, c, |t, dt, active, c| {
        let mut sigma = 0.0f32;
        let mut weighted = Vec3A::ZERO;
        for x in active {
            let rv = &scene.render_volumes[x.v];
            let vol = &scene.volumes[rv.volume];
            let p = x.o + t * x.d;
            c.volume_samples += 1;
            let [r, g, b, s] = rv.transfer.eval(rv.sample(vol, p));
            if s <= 0.0 {
                continue;
            }
            let mut col = Vec3A::new(r, g, b);
            if let Some(sh) = rv.shading {
                col = shade(scene, rv, vol, sh, col, ray, t, p, c);
            }
            sigma += s;
            weighted += s * col;
        }
        if sigma > 0.0 {
            let alpha = 1.0 - (-sigma * dt).exp();
            color += (trans * alpha / sigma) * weighted;
            trans *= 1.0 - alpha;
        }
        trans >= cutoff
    });
    (color, trans)
}

/// Gradient shading of one sample: two-sided diffuse and Blinn highlight per light, through
/// shadow rays when asked for.
#[allow(clippy::too_many_arguments)]
fn shade(
    scene: &Scene,
    rv: &RenderVolume,
    vol: &Volume,
    sh: Shading,
    base: Vec3A,
    ray: &Ray,
    t: f32,
    p_index: Vec3A,
    c: &mut Counters,
) -> Vec3A {
    let g = rv.gradient(vol, p_index);
    let len = g.length();
    // (Also catches a NaN gradient.)
    if len.is_nan() || len <= 1e-12 {
        // Homogeneous: no surface to light; lit as if facing every light.
        return base * (sh.ambient + sh.diffuse);
    }
    let n = -g / len;
    let p = ray.origin + t * ray.dir;
    let view = -ray.dir;
    let mut out = base * sh.ambient;
    for light in &scene.lights {
        let Some((l, dist, mut arriving)) = toward(light, p) else {
            continue;
        };
        if sh.shadows && light.casts_shadows() {
            c.shadow += 1;
            let sray = Ray::new(p, l, ray.time);
            if scene.features.shadows {
                arriving *= scene.transmittance(&sray, dist, scene.settings.min_weight, c);
            }
            arriving *= transmittance(scene, &sray, dist, c);
            if arriving == Vec3A::ZERO {
                continue;
            }
        }
        let ndotl = n.dot(l).abs();
        let mut lit = sh.diffuse * ndotl * base;
        if sh.specular > 0.0 {
            let h = (l + view).normalize_or_zero();
            lit += Vec3A::splat(sh.specular * n.dot(h).abs().powf(sh.shininess));
        }
        out += arriving * lit;
    }
    out
}

/// The fraction of light the volumes let through along `ray` before `t_end`: exp(-optical
/// depth), grey (extinction has no colour).
pub fn transmittance(scene: &Scene, ray: &Ray, t_end: f32, c: &mut Counters) -> f32 {
    let mut depth = 0.0f32;
    walk(scene, ray, t_end, c, |t, dt, active, c| {
        for x in active {
            let rv = &scene.render_volumes[x.v];
            let vol = &scene.volumes[rv.volume];
            c.volume_samples += 1;
            depth += rv.transfer.eval(rv.sample(vol, x.o + t * x.d))[3] * dt;
        }
        // exp(-30) is below anything a pixel can show.
        depth < 30.0
    });
    (-depth).exp()
}
