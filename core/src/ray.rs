//! Rays and the one function that spawns every secondary ray.

use crate::math::{next_down, next_up, Vec3A};

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
}

/// Moves a hit point off its surface, to the side `w` leaves toward, by the bound on the point's
/// rounding error (`p_error`, per component) projected on the geometric normal, then rounds away
/// from the surface. No fixed epsilon: the offset scales with the point's magnitude, so scenes
/// work at any scale and far from the origin (Wächter & Binder, Ray Tracing Gems ch. 6; pbrt-v4).
#[inline]
pub fn offset_origin(p: Vec3A, p_error: Vec3A, ng: Vec3A, w: Vec3A) -> Vec3A {
    let d = ng.abs().dot(p_error);
    let mut offset = d * ng;
    if w.dot(ng) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_down(po[i]);
        }
    }
    po
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
    let to = target - o;
    let dist = to.length();
    (Ray::new(o, to / dist, time), dist * (1.0 - 1e-4))
}
