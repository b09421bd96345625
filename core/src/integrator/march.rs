//! Volumes along a ray: front-to-back compositing of the rendered volumes' samples (what the
//! transfer functions give them, shaded by their gradients), and their transmittance for shadow
//! rays. How a volume is prepared for this (transfer function, empty-space skipping cells) is
//! [`crate::volume_render`]'s.

use crate::geometry::Counters;
use crate::math::Vec3A;
use crate::ray::Ray;
use crate::scene::{Light, Scene};
use crate::volume::Volume;
use crate::volume_render::{Crossing, Reader, RenderVolume, Shading, MAX_RENDERED_VOLUMES};
use std::cell::Cell;

/// One rendered volume a ray crosses, and what its samples keep from step to step.
#[derive(Clone, Copy, Debug)]
struct Track<'a> {
    rv: &'a RenderVolume,
    vol: &'a Volume,
    x: Crossing,
    /// Whether the current sample is inside the crossing.
    active: bool,
    /// The current sample point in the volume's index space.
    p: Vec3A,
    /// The skipping cell last looked up ([`RenderVolume::cell_key`]; NaN: none) and what
    /// [`RenderVolume::cell_at`] said of it.
    cell_key: Vec3A,
    cell: Option<(f32, f32)>,
    reader: Reader<'a>,
}

impl<'a> Track<'a> {
    /// The skipping cell of the current sample: its largest extinction and where the ray
    /// leaves it (looked up again only when the sample moved to another cell).
    #[inline(always)]
    fn cell(&mut self) -> Option<(f32, f32)> {
        if !self.rv.has_cells() {
            return None;
        }
        let key = RenderVolume::cell_key(self.p);
        if key != self.cell_key {
            self.cell_key = key;
            self.cell = self.rv.cell_at(&self.x, key);
        }
        self.cell
    }

    /// Moves the current sample to `t`.
    #[inline(always)]
    fn at(&mut self, t: f32) {
        self.p = self.x.o + t * self.x.d;
    }

    /// Colour and extinction of the current sample.
    #[inline(always)]
    fn classify(&mut self) -> [f32; 4] {
        self.rv.classify(self.vol, self.p, &mut self.reader)
    }
}

/// What a walk does with each sample (a trait rather than a closure so that it is inlined
/// into both of the walk's loops).
trait Visit<'a> {
    /// Takes the sample at `t` covering `dt` of the ray (in each [`active`] track); `false`
    /// ends the walk.
    fn visit(&mut self, t: f32, dt: f32, tracks: &mut [Track<'a>], c: &mut Counters) -> bool;
}

/// The tracks the current sample is in.
#[inline(always)]
fn active<'s, 'a>(tracks: &'s mut [Track<'a>]) -> impl Iterator<Item = &'s mut Track<'a>> {
    tracks.iter_mut().filter(|tr| tr.active)
}

/// Steps along `ray` through every rendered volume it crosses before `t_end`, calling
/// `visit` for each sample until it returns `false`. Samples sit at the middle of segments `step`
/// long from the first entry (the last one shorter).
#[inline(always)]
fn walk<'a>(scene: &'a Scene, ray: &Ray, t_end: f32, c: &mut Counters, visit: &mut impl Visit<'a>) {
    let mut crossed = scene.render_volumes.iter().filter_map(|rv| {
        let x = rv.crossing(ray, t_end, &scene.clips)?;
        Some(Track {
            rv,
            vol: &scene.volumes[rv.volume],
            x,
            active: false,
            p: Vec3A::ZERO,
            cell_key: Vec3A::NAN,
            cell: None,
            reader: Reader::default(),
        })
    });
    let Some(first) = crossed.next() else {
        return;
    };
    // (The unused slots hold copies of the first.)
    let mut tracks = [first; MAX_RENDERED_VOLUMES];
    let mut n = 1;
    for tr in crossed {
        tracks[n] = tr;
        n += 1;
    }
    let mut step = f32::INFINITY;
    let (mut start, mut stop) = (f32::INFINITY, f32::NEG_INFINITY);
    for tr in &tracks[..n] {
        step = step.min(tr.rv.step);
        start = start.min(tr.x.t0);
        stop = stop.max(tr.x.t1);
    }
    let steps = Steps {
        skip: scene.settings.volume_skip,
        start,
        stop,
        step,
    };
    // One volume is the common case: its loops compiled for exactly one track.
    if n == 1 {
        steps.run(&mut tracks[..1], c, visit);
    } else {
        steps.run(&mut tracks[..n], c, visit);
    }
}

/// The samples of a walk: from `start` every `step` to `stop`.
struct Steps {
    skip: bool,
    start: f32,
    stop: f32,
    step: f32,
}

impl Steps {
    #[inline(always)]
    fn run<'a>(&self, tracks: &mut [Track<'a>], c: &mut Counters, visit: &mut impl Visit<'a>) {
        let Steps {
            skip,
            start,
            stop,
            step,
        } = *self;
        let count = ((stop - start) / step).ceil().max(1.0) as u64;
        // The volumes active at t (t0 <= t < t1) change only where t passes an entry or an
        // exit: the set, and the next entry, are kept until the next such event.
        let mut any_active = false;
        let mut next_entry = f32::INFINITY;
        let mut next_event = f32::NEG_INFINITY;
        let mut i = 0u64;
        while i < count {
            let a = start + i as f32 * step;
            let b = (a + step).min(stop);
            if b <= a {
                break;
            }
            let t = 0.5 * (a + b);
            // (Also taken for a NaN t: then nothing is active, as the comparisons say.
            // `next_event` is never NaN.)
            if t >= next_event || t.is_nan() {
                any_active = false;
                next_entry = f32::INFINITY;
                next_event = f32::INFINITY;
                for tr in tracks.iter_mut() {
                    let x = &tr.x;
                    tr.active = t >= x.t0 && t < x.t1;
                    any_active |= tr.active;
                    if x.t0 > t {
                        next_entry = next_entry.min(x.t0);
                        next_event = next_event.min(x.t0);
                    }
                    if x.t1 > t {
                        next_event = next_event.min(x.t1);
                    }
                }
            }
            if skip {
                // Skip when every volume here is transparent in its whole cell: up to the first
                // cell exit or the next volume's entry, whichever comes first.
                let mut target = next_entry;
                let mut empty = true;
                for tr in active(tracks) {
                    tr.at(t);
                    match tr.cell() {
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
            if any_active && !visit.visit(t, b - a, tracks, c) {
                return;
            }
            i += 1;
        }
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
    ALPHAS.with(|alphas| {
        let mut m = Composite {
            scene,
            ray,
            cutoff,
            color: Vec3A::ZERO,
            trans: 1.0,
            alphas,
        };
        walk(scene, ray, t_end, c, &mut m);
        (m.color, m.trans)
    })
}

/// Tachyon's SCALARVOL compositing along `ray` before `t_end`: (colour, summed opacity S).
/// Each sample adds its opacity σ·dt, and its colour times that, until the sum reaches 1; no
/// attenuation in between and no gradient shading (Tachyon's `scalar_volume_texture`).
pub fn march_additive(scene: &Scene, ray: &Ray, t_end: f32, c: &mut Counters) -> (Vec3A, f32) {
    let mut m = Additive {
        color: Vec3A::ZERO,
        sum: 0.0,
    };
    walk(scene, ray, t_end, c, &mut m);
    (m.color, m.sum)
}

/// Additive compositing (see [`march_additive`]).
struct Additive {
    color: Vec3A,
    sum: f32,
}

impl<'a> Visit<'a> for Additive {
    #[inline(always)]
    fn visit(&mut self, t: f32, dt: f32, tracks: &mut [Track<'a>], c: &mut Counters) -> bool {
        for tr in active(tracks) {
            c.volume_samples += 1;
            tr.at(t);
            let [r, g, b, s] = tr.classify();
            let a = s * dt;
            if a <= 0.0 {
                continue;
            }
            self.sum += a;
            if self.sum >= 1.0 {
                // Opaque: nothing further adds.
                self.sum = 1.0;
                return false;
            }
            self.color += a * Vec3A::new(r, g, b);
        }
        true
    }
}

/// Slots of the alpha cache (a power of two).
const ALPHA_SLOTS: usize = 1024;

std::thread_local! {
    /// Alphas computed on this thread: (extinction, segment length, alpha), in a slot chosen
    /// by the first two (NaN: empty). A ray's samples take few distinct pairs (a u8 volume's
    /// 256 extinctions, and segment lengths that differ only by rounding), so most samples
    /// find theirs here instead of calling `exp`; a hit is the same bits by construction.
    static ALPHAS: [Cell<(f32, f32, f32)>; ALPHA_SLOTS] =
        const { [const { Cell::new((f32::NAN, f32::NAN, 0.0)) }; ALPHA_SLOTS] };
}

/// `1 - exp(-sigma dt)`, through the thread's cache.
#[inline(always)]
fn alpha(alphas: &[Cell<(f32, f32, f32)>; ALPHA_SLOTS], sigma: f32, dt: f32) -> f32 {
    let h = sigma.to_bits().wrapping_mul(0x9e37_79b9) ^ dt.to_bits().wrapping_mul(0x85eb_ca6b);
    let slot = &alphas[(h >> 22) as usize % ALPHA_SLOTS];
    let (s, d, a) = slot.get();
    if s == sigma && d == dt {
        return a;
    }
    let a = 1.0 - (-sigma * dt).exp();
    slot.set((sigma, dt, a));
    a
}

/// Front-to-back compositing along a ray.
struct Composite<'r, 'a> {
    scene: &'a Scene,
    ray: &'r Ray,
    cutoff: f32,
    color: Vec3A,
    trans: f32,
    alphas: &'r [Cell<(f32, f32, f32)>; ALPHA_SLOTS],
}

impl<'a> Visit<'a> for Composite<'_, 'a> {
    #[inline(always)]
    fn visit(&mut self, t: f32, dt: f32, tracks: &mut [Track<'a>], c: &mut Counters) -> bool {
        let mut sigma = 0.0f32;
        let mut weighted = Vec3A::ZERO;
        for tr in active(tracks) {
            c.volume_samples += 1;
            tr.at(t);
            let [r, g, b, s] = tr.classify();
            if s <= 0.0 {
                continue;
            }
            let mut col = Vec3A::new(r, g, b);
            if let Some(sh) = tr.rv.shading {
                col = shade(self.scene, tr.rv, tr.vol, sh, col, self.ray, t, tr.p, c);
            }
            sigma += s;
            weighted += s * col;
        }
        if sigma > 0.0 {
            let alpha = alpha(self.alphas, sigma, dt);
            self.color += (self.trans * alpha / sigma) * weighted;
            self.trans *= 1.0 - alpha;
        }
        self.trans >= self.cutoff
    }
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
    let mut d = Depth(0.0);
    walk(scene, ray, t_end, c, &mut d);
    (-d.0).exp()
}

/// Optical depth along a ray.
struct Depth(f32);

impl<'a> Visit<'a> for Depth {
    #[inline(always)]
    fn visit(&mut self, t: f32, dt: f32, tracks: &mut [Track<'a>], c: &mut Counters) -> bool {
        for tr in active(tracks) {
            c.volume_samples += 1;
            tr.at(t);
            self.0 += tr.classify()[3] * dt;
        }
        // exp(-30) is below anything a pixel can show.
        self.0 < 30.0
    }
}
