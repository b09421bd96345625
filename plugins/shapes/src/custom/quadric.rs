//! `quadric`: a general second-order surface clipped to a box, solved along the ray from
//! where it enters the box.

use super::{at, check_box, in_range, quadratic, slabs, usable};
use crate::vector::{dot, scale, V3};
use luxon_plugin::{
    finite, invalid, Aabb, Context, CustomShape, Describe, Error, Geometry, Hit, Primitive, Ray,
};
use serde::Deserialize;

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct QuadricParams {
    pub coefficients: [f64; 10],
    pub min: V3,
    pub max: V3,
}

/// A validated quadric surface clipped to a box.
#[derive(Clone, Debug)]
pub struct ClippedQuadric {
    /// a..j of `a x² + b y² + c z² + d xy + e xz + f yz + g x + h y + i z + j`.
    k: [f64; 10],
    min: V3,
    max: V3,
}

impl ClippedQuadric {
    pub fn new(p: &QuadricParams) -> Result<ClippedQuadric, Error> {
        let k = finite("coefficients", p.coefficients)?;
        if k[..9].iter().all(|&x| x == 0.0) {
            return Err(invalid(
                "parameter `coefficients`: the first nine (a to i) are all 0, so there is no \
                 surface; give at least one non-zero term in x, y or z",
            ));
        }
        let (min, max) = check_box(p.min, p.max)?;
        Ok(ClippedQuadric { k, min, max })
    }

    fn value(&self, p: V3) -> f64 {
        let [a, b, c, d, e, f, g, h, i, j] = self.k;
        let [x, y, z] = p;
        x * (a * x + d * y + e * z + g) + y * (b * y + f * z + h) + z * (c * z + i) + j
    }

    fn gradient(&self, p: V3) -> V3 {
        let [a, b, c, d, e, f, g, h, i, _] = self.k;
        let [x, y, z] = p;
        [
            2.0 * a * x + d * y + e * z + g,
            2.0 * b * y + d * x + f * z + h,
            2.0 * c * z + e * x + f * y + i,
        ]
    }

    /// The second-order part alone (the quadratic coefficient along a direction).
    fn second_order(&self, v: V3) -> f64 {
        let [a, b, c, d, e, f, ..] = self.k;
        let [x, y, z] = v;
        a * x * x + b * y * y + c * z * z + d * x * y + e * x * z + f * y * z
    }
}

impl CustomShape for ClippedQuadric {
    fn count(&self) -> u64 {
        1
    }

    fn bounds(&self, _index: u64) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }

    fn intersect(&self, _index: u64, ray: &Ray) -> Option<Hit> {
        if !usable(ray) {
            return None;
        }
        let (t0, _, t1, _) = slabs(self.min, self.max, ray)?;
        // Expand around a point on the ray where it enters the box, so the coefficients are
        // computed at box scale even when the ray starts far away: t = t0 + s.
        let base = at(ray, t0);
        let dir = ray.direction;
        let a = self.second_order(dir);
        let b = dot(self.gradient(base), dir);
        let c = self.value(base);
        let (roots, n) = quadratic(a, b, c);
        for &s in &roots[..n] {
            let t = t0 + s;
            // Inside the box is decided on t so a root on a face is not lost to rounding.
            if t < t0 || t > t1 || !in_range(ray, t) {
                continue;
            }
            let g = self.gradient(at(ray, t));
            // At a singular point (a cone's apex) the gradient vanishes: face the ray.
            let normal = if g.iter().all(|&x| x == 0.0) {
                scale(dir, -1.0)
            } else {
                g
            };
            return Some(Hit {
                t,
                normal,
                uv: [0.0; 2],
            });
        }
        None
    }
}

pub struct Quadric;

impl Describe for Quadric {
    const NAME: &'static str = "quadric";
    const DESCRIPTION: &'static str =
        "A general second-order surface (Tachyon's quadric) clipped to a box.";
    const PARAMS: &'static str = "coefficients: (a, b, c, d, e, f, g, h, i, j)  a x² + b y² + c z² + d xy + e xz + f yz + g x + h y + i z + j = 0
min: (x, y, z)  lowest corner of the clipping box
max: (x, y, z)  highest corner, > min on every axis";
}

impl Primitive for Quadric {
    type Params = QuadricParams;
    fn create(p: QuadricParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(ClippedQuadric::new(&p)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{assert_hit, err, ray};
    use crate::vector::normalize;
    use luxon_plugin::parse_params;

    fn quadric(k: &str, min: &str, max: &str) -> ClippedQuadric {
        let p = format!("(coefficients: {k}, min: {min}, max: {max})");
        ClippedQuadric::new(&parse_params(&p).unwrap()).unwrap()
    }

    #[test]
    fn quadric_sphere() {
        let s = quadric(
            "(1, 1, 1, 0, 0, 0, 0, 0, 0, -1)",
            "(-2, -2, -2)",
            "(2, 2, 2)",
        );
        assert_hit(
            &s,
            &ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]),
            4.0,
            [0.0, 0.0, -1.0],
        );
        // Far away: the expansion at the box keeps it accurate.
        assert_hit(
            &s,
            &ray([0.0, 0.0, -1e9], [0.0, 0.0, 1.0]),
            1e9 - 1.0,
            [0.0, 0.0, -1.0],
        );
        // From inside: the far side.
        assert_hit(&s, &ray([0.0; 3], [0.0, 2.0, 0.0]), 0.5, [0.0, 1.0, 0.0]);
        // Tangent at (1, 0, 0).
        assert_hit(
            &s,
            &ray([1.0, -3.0, 0.0], [0.0, 1.0, 0.0]),
            3.0,
            [1.0, 0.0, 0.0],
        );
        assert!(s
            .intersect(0, &ray([1.1, -3.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
        assert!(s
            .intersect(0, &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]))
            .is_none());
    }

    #[test]
    fn quadric_clipping_tries_both_roots() {
        // Upper half of the unit sphere only.
        let s = quadric(
            "(1, 1, 1, 0, 0, 0, 0, 0, 0, -1)",
            "(-2, 0, -2)",
            "(2, 2, 2)",
        );
        // From below: the first root (y = -1) is clipped, the second (y = 1) wins; the normal is
        // the gradient, outward.
        assert_hit(
            &s,
            &ray([0.0, -5.0, 0.0], [0.0, 1.0, 0.0]),
            6.0,
            [0.0, 1.0, 0.0],
        );
        // Both roots clipped.
        let low = quadric(
            "(1, 1, 1, 0, 0, 0, 0, 0, 0, -1)",
            "(-2, -0.5, -2)",
            "(2, 0.5, 2)",
        );
        assert!(low
            .intersect(0, &ray([0.0, -5.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
        // A ray missing the box entirely.
        assert!(s
            .intersect(0, &ray([5.0, -5.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
    }

    #[test]
    fn quadric_cylinder() {
        // x² + y² = 1 for |z| <= 1.
        let c = quadric(
            "(1, 1, 0, 0, 0, 0, 0, 0, 0, -1)",
            "(-2, -2, -1)",
            "(2, 2, 1)",
        );
        assert_hit(
            &c,
            &ray([3.0, 0.0, 0.5], [-1.0, 0.0, 0.0]),
            2.0,
            [1.0, 0.0, 0.0],
        );
        // Along the axis: A = 0 and the equation has no root.
        assert!(c
            .intersect(0, &ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]))
            .is_none());
        // Beyond the clipped end.
        assert!(c
            .intersect(0, &ray([3.0, 0.0, 1.5], [-1.0, 0.0, 0.0]))
            .is_none());
        // From inside.
        assert_hit(&c, &ray([0.0; 3], [0.0, -1.0, 0.0]), 1.0, [0.0, -1.0, 0.0]);
    }

    #[test]
    fn quadric_paraboloid() {
        // y = x² + z²: x² + z² - y = 0; a vertical ray meets it once (linear case).
        let p = quadric(
            "(1, 0, 1, 0, 0, 0, 0, -1, 0, 0)",
            "(-2, -1, -2)",
            "(2, 4, 2)",
        );
        let n = normalize([2.0, -1.0, 0.0]).unwrap();
        assert_hit(&p, &ray([1.0, 10.0, 0.0], [0.0, -1.0, 0.0]), 9.0, n);
        // Its inside is y > x² + z²: from the vertex region upward nothing is hit before the
        // box top; a horizontal ray at y = 1 hits x = -1 first.
        assert_hit(
            &p,
            &ray([-3.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
            2.0,
            normalize([-2.0, -1.0, 0.0]).unwrap(),
        );
        assert!(p
            .intersect(0, &ray([0.0, 1.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
    }

    #[test]
    fn quadric_hyperboloid_clipped() {
        // One sheet: x² + y² - z² = 1, for |z| <= 1 (waist radius 1, rim radius √2).
        let h = quadric(
            "(1, 1, -1, 0, 0, 0, 0, 0, 0, -1)",
            "(-3, -3, -1)",
            "(3, 3, 1)",
        );
        // At the waist.
        assert_hit(
            &h,
            &ray([5.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            4.0,
            [1.0, 0.0, 0.0],
        );
        // At z = 1 the radius is √2; the gradient (2x, 0, -2z) there is (2√2, 0, -2).
        let r2 = 2f64.sqrt();
        let n = normalize([2.0 * r2, 0.0, -2.0]).unwrap();
        assert_hit(&h, &ray([5.0, 0.0, 1.0], [-1.0, 0.0, 0.0]), 5.0 - r2, n);
        // Along the axis it never meets the surface; past the clip neither.
        assert!(h
            .intersect(0, &ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]))
            .is_none());
        assert!(h
            .intersect(0, &ray([5.0, 0.0, 1.5], [-1.0, 0.0, 0.0]))
            .is_none());
        // A ray along an asymptote direction (A = 0): x = 1 + s, z = s hits where
        // (1+s)² - s² = 1, s = 0, i.e. the linear root.
        assert_hit(
            &h,
            &ray([0.5, 0.0, -0.5], [1.0, 0.0, 1.0]),
            0.5,
            [1.0, 0.0, 0.0],
        );
    }

    #[test]
    fn quadric_errors() {
        let bad = |p: &str| err(ClippedQuadric::new(&parse_params(p).unwrap()));
        let m =
            bad("(coefficients: (0, 0, 0, 0, 0, 0, 0, 0, 0, 1), min: (0, 0, 0), max: (1, 1, 1))");
        assert!(m.contains("no surface"), "{m}");
        let m =
            bad("(coefficients: (1, 1, 1, 0, 0, 0, 0, 0, 0, 1), min: (0, 0, 0), max: (1, 1, -1))");
        assert!(m.contains("on z"), "{m}");
        assert!(parse_params::<QuadricParams>(
            "(coefficients: (1, 1, 1), min: (0, 0, 0), max: (1, 1, 1))"
        )
        .is_err());
    }
}
