//! Small numeric helpers shared by the geometry code.

pub use glam::{DVec3, Vec3A};

/// Bound on the relative rounding error of `n` chained f32 operations (pbrt's gamma(n)).
pub const fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// The next representable f32 above `v` (toward +inf).
pub fn next_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    f32::from_bits(if v >= 0.0 { bits + 1 } else { bits - 1 })
}

/// The next representable f32 below `v` (toward -inf).
pub fn next_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    f32::from_bits(if v > 0.0 { bits - 1 } else { bits + 1 })
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    pub fn new(min: Vec3A, max: Vec3A) -> Aabb {
        Aabb { min, max }
    }

    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn grow(self, p: Vec3A) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn centroid(&self) -> Vec3A {
        (self.min + self.max) * 0.5
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// Half the surface area (the SAH only needs ratios).
    pub fn half_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.max - self.min;
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// Reflects `d` about the normal `n` (both unit; `n` on either side).
pub fn reflect(d: Vec3A, n: Vec3A) -> Vec3A {
    d - 2.0 * d.dot(n) * n
}

/// Refracts unit `d` through a surface with unit normal `n` facing against `d`, with
/// `eta = n1 / n2`. `None` on total internal reflection.
pub fn refract(d: Vec3A, n: Vec3A, eta: f32) -> Option<Vec3A> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((eta * d + (eta * cos_i - cos_t) * n).normalize())
}

/// Any unit vector orthogonal to unit `n`.
pub fn orthogonal(n: Vec3A) -> Vec3A {
    let a = if n.x.abs() > 0.9 { Vec3A::Y } else { Vec3A::X };
    n.cross(a).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_float() {
        assert!(next_up(1.0) > 1.0 && next_down(1.0) < 1.0);
        assert!(next_up(0.0) > 0.0 && next_down(0.0) < 0.0);
        assert!(next_up(-1.0) > -1.0);
    }

    #[test]
    fn snell_and_tir() {
        let d = Vec3A::new(1.0, -1.0, 0.0).normalize();
        let n = Vec3A::Y;
        let t = refract(d, n, 1.0 / 1.5).unwrap();
        let sin_i = d.x;
        let sin_t = t.x;
        assert!((sin_i / sin_t - 1.5).abs() < 1e-5);
        // From glass to air at 45 degrees: beyond the critical angle (41.8).
        assert!(refract(d, n, 1.5).is_none());
    }
}
