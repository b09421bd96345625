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

/// `x.acos()` within 3e-8 (radians) on [-1, 1], inline: a spot light's linear fade takes
/// one for every point in its band, and libm's call was a tenth of Tachyon's `spotlight`
/// scene. Abramowitz and Stegun 4.4.46 (|error| ≤ 2e-8 on [0, 1]) in f64, then rounded;
/// outside [-1, 1] or NaN: NaN, as `acos`.
#[inline]
pub fn acos(x: f32) -> f32 {
    const A: [f64; 8] = [
        1.570_796_305_0,
        -0.214_598_801_6,
        0.088_978_987_4,
        -0.050_174_304_6,
        0.030_891_881_0,
        -0.017_088_125_6,
        0.006_670_090_1,
        -0.001_262_491_1,
    ];
    let a = f64::from(x).abs();
    if a.is_nan() || a > 1.0 {
        return f32::NAN;
    }
    // Estrin's scheme: three levels of multiply-adds rather than seven in a chain.
    let a2 = a * a;
    let a4 = a2 * a2;
    let p01 = A[0] + A[1] * a;
    let p23 = A[2] + A[3] * a;
    let p45 = A[4] + A[5] * a;
    let p67 = A[6] + A[7] * a;
    let p = (p01 + p23 * a2) + (p45 + p67 * a2) * a4;
    let r = (1.0 - a).sqrt() * p;
    (if x < 0.0 { std::f64::consts::PI - r } else { r }) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acos_is_libms_within_3e8() {
        // Off libm's correctly rounded f32 by at most one step, and only where the exact
        // value lies within 3e-8 of halfway between two floats.
        for i in 0..=200_000 {
            let x = (-1.0 + i as f32 * 1e-5).clamp(-1.0, 1.0);
            let exact = f64::from(x).acos();
            let (got, want) = (acos(x), exact as f32);
            if got != want {
                let step = f64::from(next_up(want) - want);
                let from_half = (exact - f64::from(want)).abs() - step / 2.0;
                assert!(from_half.abs() < 3e-8, "acos({x}) = {got}, not {want}");
            }
        }
        assert_eq!(acos(1.0), 0.0);
        assert_eq!(acos(-1.0), std::f32::consts::PI);
        assert!(acos(1.0001).is_nan() && acos(-2.0).is_nan() && acos(f32::NAN).is_nan());
    }

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
