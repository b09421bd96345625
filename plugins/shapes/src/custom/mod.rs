//! Custom geometry: shapes the plugin intersects itself in `f64` (the host only stores their
//! bounds in its BVH), one file each, and the ray and box routines they share.

mod boxes;
mod heightfield;
mod infinite_cylinder;
#[cfg(test)]
mod props;
mod quadric;

pub use boxes::BoxEntry;
pub use heightfield::Heightfield;
pub use infinite_cylinder::InfiniteCylinder;
pub use quadric::Quadric;

use crate::vector::{add, scale, V3};
use luxon_plugin::{finite, invalid, Error, Ray};

/// The point at `t` along the ray.
fn at(ray: &Ray, t: f64) -> V3 {
    add(ray.origin, scale(ray.direction, t))
}

/// Rays the shapes can work with: finite origin, finite non-zero direction.
fn usable(ray: &Ray) -> bool {
    ray.origin
        .iter()
        .chain(&ray.direction)
        .all(|x| x.is_finite())
        && ray.direction.iter().any(|&x| x != 0.0)
}

/// Whether `t` lies inside the ray's open interval.
fn in_range(ray: &Ray, t: f64) -> bool {
    ray.tmin < t && t < ray.tmax
}

/// `min` and `max` of a box, finite, with `min < max` on every axis.
fn check_box(min: V3, max: V3) -> Result<(V3, V3), Error> {
    let min = finite("min", min)?;
    let max = finite("max", max)?;
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        if min[k] >= max[k] {
            return Err(invalid(format!(
                "`min` must be smaller than `max` on every axis; on {axis}: min {} >= max {}",
                min[k], max[k]
            )));
        }
    }
    Ok((min, max))
}

/// Where the ray's line is inside the closed box: `(t_enter, enter_axis, t_leave, leave_axis)`.
///
/// A direction component of exactly 0 is not divided by: the ray is then inside that slab for
/// every `t` when its origin lies in the closed interval (a face plane included) and outside for
/// every `t` otherwise, so no NaN (0/0, inf - inf) can arise. Needs a usable ray.
fn slabs(min: V3, max: V3, ray: &Ray) -> Option<(f64, usize, f64, usize)> {
    let (mut t0, mut a0, mut t1, mut a1) = (f64::NEG_INFINITY, 0, f64::INFINITY, 0);
    for k in 0..3 {
        let (o, d) = (ray.origin[k], ray.direction[k]);
        if d == 0.0 {
            if o < min[k] || o > max[k] {
                return None;
            }
            continue;
        }
        let (mut near, mut far) = ((min[k] - o) / d, (max[k] - o) / d);
        if d < 0.0 {
            std::mem::swap(&mut near, &mut far);
        }
        if near > t0 {
            (t0, a0) = (near, k);
        }
        if far < t1 {
            (t1, a1) = (far, k);
        }
    }
    (t0 <= t1).then_some((t0, a0, t1, a1))
}

/// Roots of `a u² + b u + c = 0` in increasing order, by the cancellation-free form
/// `q = -(b + sign(b) √disc) / 2`, `u = q / a`, `u = c / q`. A zero `a` leaves the linear root.
fn quadratic(a: f64, b: f64, c: f64) -> ([f64; 2], usize) {
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 || !disc.is_finite() {
        return ([0.0; 2], 0);
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    if q == 0.0 {
        // b = 0 and disc = 0: with a != 0 also c = 0, a double root at 0.
        return if a != 0.0 {
            ([0.0; 2], 1)
        } else {
            ([0.0; 2], 0)
        };
    }
    let (r1, r2) = (q / a, c / q);
    match (r1.is_finite(), r2.is_finite()) {
        (true, true) => ([r1.min(r2), r1.max(r2)], 2),
        (true, false) => ([r1, 0.0], 1),
        (false, true) => ([r2, 0.0], 1),
        (false, false) => ([0.0; 2], 0),
    }
}
