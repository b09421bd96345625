//! Rays and the one function that spawns every secondary ray.

use crate::math::Vec3A;
#[cfg(any(test, not(target_arch = "x86_64")))]
use crate::math::{next_down, next_up};

#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3A,
    /// Unit length.
    pub dir: Vec3A,
    /// Shutter time the ray samples (animation, motion blur).
    pub time: f32,
}

impl Ray {
    pub fn new(origin: Vec3A, dir: Vec3A, time: f32) -> Ray {
        Ray { origin, dir, time }
    }

    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + t * self.dir
    }

    /// Whether every coordinate of origin and direction is finite (the same answer as the
    /// box tests' `BoxRay::finite`: the trees meet nothing otherwise).
    #[inline(always)]
    #[allow(clippy::eq_op)] // x - x on purpose: 0 for finite x, NaN for the others
    pub fn finite(&self) -> bool {
        ((self.origin - self.origin) + (self.dir - self.dir))
            .cmpeq(Vec3A::ZERO)
            .all()
    }
}

/// Moves a hit point off its surface, to the side `w` leaves toward, by the bound on the point's
/// rounding error (`p_error`, per component) projected on the geometric normal, then rounds away
/// from the surface. No fixed epsilon: the offset scales with the point's magnitude, so scenes
/// work at any scale and far from the origin (Wächter & Binder, Ray Tracing Gems ch. 6; pbrt-v4).
#[inline]
pub fn offset_origin(p: Vec3A, p_error: Vec3A, ng: Vec3A, w: Vec3A) -> Vec3A {
    // |−ng| = |ng| and d·(−ng) = −(d·ng) exactly, so this is the offset negated.
    let side = if w.dot(ng) < 0.0 { -ng } else { ng };
    offset_up(p, p_error, side)
}

/// [`offset_origin`] for any `w` that does not leave against `ng` (`w · ng` not below 0,
/// or NaN): the same origin for all of them, so a shading point's shadow rays can share it.
#[inline]
pub fn offset_up(p: Vec3A, p_error: Vec3A, ng: Vec3A) -> Vec3A {
    let offset = ng.abs().dot(p_error) * ng;
    away(p + offset, offset)
}

/// `po` rounded one float further along the sign of `offset`, per coordinate: `next_up`
/// where it is positive, `next_down` where negative, unchanged where zero or NaN.
#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn away(mut po: Vec3A, offset: Vec3A) -> Vec3A {
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_down(po[i]);
        }
    }
    po
}

/// The same in the four lanes at once (a shadow ray per light term: the scalar loop's
/// branches cost about 20 instructions). Bitwise `next_up` / `next_down`, also for zeros,
/// infinities and NaNs (a test compares them).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn away(po: Vec3A, offset: Vec3A) -> Vec3A {
    use std::arch::x86_64::*;
    // SAFETY: SSE and SSE2 are part of the x86_64 baseline; no memory is read or written.
    unsafe {
        let (x, o): (__m128, __m128) = (po.into(), offset.into());
        let zero = _mm_setzero_ps();
        let up = _mm_cmpgt_ps(o, zero);
        let down = _mm_cmplt_ps(o, zero);
        // Zeros of either sign step from +0 up and from -0 down.
        let is_zero = _mm_cmpeq_ps(x, zero);
        let sign = _mm_and_ps(down, _mm_set1_ps(-0.0));
        let xz = _mm_or_ps(_mm_andnot_ps(is_zero, x), _mm_and_ps(is_zero, sign));
        // Up: +1 on the bits of a value >= 0, else -1 (NaN too); down: -1 on those of a value
        // > 0, else +1. A mask is -1 or 0, so `mask | 1` is -1 or +1.
        let one = _mm_set1_epi32(1);
        let ge = _mm_castps_si128(_mm_cmpge_ps(xz, zero));
        let gt = _mm_castps_si128(_mm_cmpgt_ps(xz, zero));
        let step_up = _mm_sub_epi32(_mm_setzero_si128(), _mm_or_si128(ge, one));
        let step_down = _mm_or_si128(gt, one);
        // +inf stays up, -inf stays down.
        let inf = _mm_set1_ps(f32::INFINITY);
        let up = _mm_castps_si128(_mm_andnot_ps(_mm_cmpeq_ps(x, inf), up));
        let down = _mm_castps_si128(_mm_andnot_ps(
            _mm_cmpeq_ps(x, _mm_set1_ps(-f32::INFINITY)),
            down,
        ));
        let step = _mm_or_si128(_mm_and_si128(up, step_up), _mm_and_si128(down, step_down));
        let moved = _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(xz), step));
        let any = _mm_castsi128_ps(_mm_or_si128(up, down));
        Vec3A::from(_mm_or_ps(_mm_and_ps(any, moved), _mm_andnot_ps(any, x)))
    }
}

/// A ray leaving a surface point in direction `dir`.
#[inline]
pub fn spawn(p: Vec3A, p_error: Vec3A, ng: Vec3A, dir: Vec3A, time: f32) -> Ray {
    Ray::new(offset_origin(p, p_error, ng, dir), dir, time)
}

/// A ray from a surface point toward `target`; returns the ray and the distance to just short
/// of the target (for shadow rays toward point lights).
#[inline]
pub fn spawn_to(p: Vec3A, p_error: Vec3A, ng: Vec3A, target: Vec3A, time: f32) -> (Ray, f32) {
    let d = target - p;
    let o = offset_origin(p, p_error, ng, d);
    ray_to(o, target, time)
}

/// [`spawn_to`] bit for bit, given `up()`, the point's [`offset_up`] (made once per point
/// by the caller): only a target behind the geometric normal pays for its own offset. The
/// third value: the ray starts at `up()` (the target is on `ng`'s side).
#[inline(always)]
pub fn spawn_to_or(
    p: Vec3A,
    p_error: Vec3A,
    ng: Vec3A,
    target: Vec3A,
    time: f32,
    up: impl FnOnce() -> Vec3A,
) -> (Ray, f32, bool) {
    let d = target - p;
    let (o, above) = if d.dot(ng) < 0.0 {
        (offset_origin(p, p_error, ng, d), false)
    } else {
        (up(), true)
    };
    let (ray, t_max) = ray_to(o, target, time);
    (ray, t_max, above)
}

/// [`spawn`] bit for bit, given the point's [`offset_up`] as `up()` (see [`spawn_to_or`]);
/// with whether the ray starts at `up()`.
#[inline(always)]
pub fn spawn_or(
    p: Vec3A,
    p_error: Vec3A,
    ng: Vec3A,
    dir: Vec3A,
    time: f32,
    up: impl FnOnce() -> Vec3A,
) -> (Ray, bool) {
    if dir.dot(ng) < 0.0 {
        (
            Ray::new(offset_origin(p, p_error, ng, dir), dir, time),
            false,
        )
    } else {
        (Ray::new(up(), dir, time), true)
    }
}

/// The ray from `o` toward `target` and the distance to just short of it.
#[inline(always)]
fn ray_to(o: Vec3A, target: Vec3A, time: f32) -> (Ray, f32) {
    let to = target - o;
    let dist = to.length();
    (Ray::new(o, to / dist, time), dist * (1.0 - 1e-4))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lanes' rounding is `next_up` / `next_down` bit for bit, special values included.
    #[test]
    fn away_matches_next_up_and_down() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            1e-45,
            -1e-45,
            1.17e-38,
            -3.5e7,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            f32::from_bits(0x7f80_0001),
        ];
        let offsets = [0.5, -0.5, 0.0, -0.0, f32::NAN, 1e-30, -1e30];
        let mut n = 0;
        for (i, &a) in values.iter().enumerate() {
            for &b in &values[i..] {
                for &c in &values {
                    for &oa in &offsets {
                        for &ob in &offsets {
                            let oc = offsets[n % offsets.len()];
                            n += 1;
                            let (po, off) = (Vec3A::new(a, b, c), Vec3A::new(oa, ob, oc));
                            let got = away(po, off);
                            for k in 0..3 {
                                let want = if off[k] > 0.0 {
                                    next_up(po[k])
                                } else if off[k] < 0.0 {
                                    next_down(po[k])
                                } else {
                                    po[k]
                                };
                                assert_eq!(got[k].to_bits(), want.to_bits(), "{po:?} {off:?} {k}");
                            }
                        }
                    }
                }
            }
        }
        assert!(n > 10_000);
    }

    /// The shared origin's spawns are `spawn_to` and `spawn` bit for bit, on either side of
    /// the normal, along it and across it.
    #[test]
    fn shared_offset_spawns_match() {
        let bits = |r: &Ray| {
            (
                r.origin.to_array().map(f32::to_bits),
                r.dir.to_array().map(f32::to_bits),
            )
        };
        let ng = Vec3A::new(0.3, -0.8, 0.52).normalize();
        let mut n = 0;
        for p in [
            Vec3A::new(1.5, -2.25, 7.0),
            Vec3A::new(-1e4, 0.0, 3e-3),
            Vec3A::ZERO,
        ] {
            let p_error = 3e-7 * (p.abs() + Vec3A::ONE);
            let up = offset_up(p, p_error, ng);
            for k in 0..64 {
                let a = k as f32 * 0.37;
                let w = Vec3A::new(a.cos(), (1.3 * a).sin(), (0.7 * a).cos() - 0.2);
                let w = if k % 5 == 0 { ng.cross(w) } else { w };
                let target = p + 3.0 * w;
                let (want, wt) = spawn_to(p, p_error, ng, target, 0.5);
                let (got, gt, above) = spawn_to_or(p, p_error, ng, target, 0.5, || up);
                assert_eq!((bits(&got), gt.to_bits()), (bits(&want), wt.to_bits()));
                assert_eq!(above, (target - p).dot(ng) >= 0.0);
                let dir = w.normalize();
                let want = spawn(p, p_error, ng, dir, 0.5);
                let (got, above) = spawn_or(p, p_error, ng, dir, 0.5, || up);
                assert_eq!(bits(&got), bits(&want));
                assert_eq!(above, dir.dot(ng) >= 0.0);
                n += 1;
            }
        }
        assert_eq!(n, 192);
    }
}
