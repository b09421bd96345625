//! `infinite_cylinder`: a cylinder around a line, cut far away (the host's BVH needs finite
//! bounds); intersected in the cylinder's own frame.

use super::{in_range, quadratic, usable};
use crate::params::positive;
use crate::vector::{add, dot, normalize, scale, sub, V3};
use luxon_plugin::{
    finite, invalid, Aabb, Context, CustomShape, Describe, Error, Geometry, Hit, Primitive, Ray,
};
use serde::Deserialize;

/// Two unit vectors completing the unit `w` to a right-handed orthonormal frame (the branchless
/// construction of Duff et al., "Building an orthonormal basis, revisited").
fn frame(w: V3) -> (V3, V3) {
    let sign = 1f64.copysign(w[2]);
    let a = -1.0 / (sign + w[2]);
    let b = w[0] * w[1] * a;
    (
        [1.0 + sign * w[0] * w[0] * a, sign * b, -sign * w[0]],
        [b, sign + w[1] * w[1] * a, -w[1]],
    )
}

/// Turns as a texture coordinate in [0, 1).
fn turn(angle: f64) -> f32 {
    let u = angle / std::f64::consts::TAU;
    (if u < 0.0 { u + 1.0 } else { u }) as f32
}

fn default_extent() -> f64 {
    1e6
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct InfiniteCylinderParams {
    pub center: V3,
    pub axis: V3,
    pub radius: f64,
    #[serde(default = "default_extent")]
    pub extent: f64,
}

/// A validated cylinder around a line, cut at `extent` along the axis on both sides.
#[derive(Clone, Debug)]
pub struct LineCylinder {
    center: V3,
    u: V3,
    v: V3,
    w: V3,
    radius: f64,
    extent: f64,
}

impl LineCylinder {
    pub fn new(p: &InfiniteCylinderParams) -> Result<LineCylinder, Error> {
        let center = finite("center", p.center)?;
        let w = normalize(finite("axis", p.axis)?)
            .ok_or_else(|| invalid("parameter `axis` has zero length"))?;
        let radius = positive("radius", p.radius)?;
        let extent = positive("extent", p.extent)?;
        let (u, v) = frame(w);
        Ok(LineCylinder {
            center,
            u,
            v,
            w,
            radius,
            extent,
        })
    }
}

impl CustomShape for LineCylinder {
    fn count(&self) -> u64 {
        1
    }

    fn bounds(&self, _index: u64) -> Aabb {
        // Box of the two end discs: along world axis k the axis contributes e |w_k| and a disc
        // of radius r perpendicular to w contributes r √(1 - w_k²).
        let mut min = [0.0; 3];
        let mut max = [0.0; 3];
        for k in 0..3 {
            let half = self.extent * self.w[k].abs()
                + self.radius * (1.0 - self.w[k] * self.w[k]).max(0.0).sqrt();
            min[k] = self.center[k] - half;
            max[k] = self.center[k] + half;
        }
        Aabb { min, max }
    }

    fn intersect(&self, _index: u64, ray: &Ray) -> Option<Hit> {
        if !usable(ray) {
            return None;
        }
        let rel = sub(ray.origin, self.center);
        let d = ray.direction;
        let o = [dot(rel, self.u), dot(rel, self.v), dot(rel, self.w)];
        let d = [dot(d, self.u), dot(d, self.v), dot(d, self.w)];
        let a = d[0] * d[0] + d[1] * d[1];
        if a == 0.0 {
            // Parallel to the axis: never crosses the surface.
            return None;
        }
        let b = 2.0 * (o[0] * d[0] + o[1] * d[1]);
        let c = o[0] * o[0] + o[1] * o[1] - self.radius * self.radius;
        let (roots, n) = quadratic(a, b, c);
        for &t in &roots[..n] {
            if !in_range(ray, t) {
                continue;
            }
            let p = add(o, scale(d, t));
            if p[2].abs() > self.extent {
                continue;
            }
            return Some(Hit {
                t,
                normal: add(scale(self.u, p[0]), scale(self.v, p[1])),
                uv: [
                    turn(p[1].atan2(p[0])),
                    ((p[2] + self.extent) / (2.0 * self.extent)) as f32,
                ],
            });
        }
        None
    }
}

pub struct InfiniteCylinder;

impl Describe for InfiniteCylinder {
    const NAME: &'static str = "infinite_cylinder";
    const DESCRIPTION: &'static str =
        "A cylinder around a line (Tachyon's cylinder), cut far away at `extent`.";
    const PARAMS: &'static str = "center: (x, y, z)  a point on the axis
axis: (x, y, z)  axis direction, any non-zero length
radius: f64 > 0  radius
extent: f64 > 0 = 1e6  half-length kept on each side of `center` (the bounds need an end)";
}

impl Primitive for InfiniteCylinder {
    type Params = InfiniteCylinderParams;
    fn create(p: InfiniteCylinderParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(LineCylinder::new(&p)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{assert_hit, close, close3, err, ray};
    use luxon_plugin::parse_params;

    fn z_cylinder(extent: &str) -> LineCylinder {
        let p = format!("(center: (1, 2, 0), axis: (0, 0, 3), radius: 0.5{extent})");
        LineCylinder::new(&parse_params(&p).unwrap()).unwrap()
    }

    #[test]
    fn cylinder_hits_outside_and_inside() {
        let c = z_cylinder("");
        assert_hit(
            &c,
            &ray([5.0, 2.0, 7.0], [-1.0, 0.0, 0.0]),
            3.5,
            [1.0, 0.0, 0.0],
        );
        // From the axis: the wall ahead, normal outward.
        assert_hit(
            &c,
            &ray([1.0, 2.0, 0.0], [0.0, -2.0, 0.0]),
            0.25,
            [0.0, -1.0, 0.0],
        );
        // Oblique: x hits 1.5 at t = 2 (z is irrelevant).
        assert_hit(
            &c,
            &ray([3.5, 2.0, 0.0], [-1.0, 0.0, 4.0]),
            2.0,
            [1.0, 0.0, 0.0],
        );
        let h = c
            .intersect(0, &ray([5.0, 2.0, 0.0], [-1.0, 0.0, 0.0]))
            .unwrap();
        assert!(close(h.uv[0] as f64, 0.0) && close(h.uv[1] as f64, 0.5));
    }

    #[test]
    fn cylinder_tangent_parallel_and_miss() {
        let c = z_cylinder("");
        // Tangent at (1.5, 2, 0): touches once.
        assert_hit(
            &c,
            &ray([1.5, -3.0, 0.0], [0.0, 1.0, 0.0]),
            5.0,
            [1.0, 0.0, 0.0],
        );
        assert!(c
            .intersect(0, &ray([1.6, -3.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
        // Parallel to the axis, inside or outside: no crossing.
        assert!(c
            .intersect(0, &ray([1.0, 2.0, 0.0], [0.0, 0.0, 1.0]))
            .is_none());
        assert!(c
            .intersect(0, &ray([3.0, 2.0, 0.0], [0.0, 0.0, -1.0]))
            .is_none());
        assert!(c
            .intersect(0, &ray([5.0, 2.0, 0.0], [1.0, 0.0, 0.0]))
            .is_none());
    }

    #[test]
    fn cylinder_extent_cuts_and_bounds() {
        let c = z_cylinder(", extent: 2");
        assert!(c
            .intersect(0, &ray([5.0, 2.0, 2.5], [-1.0, 0.0, 0.0]))
            .is_none());
        assert!(c
            .intersect(0, &ray([5.0, 2.0, 1.5], [-1.0, 0.0, 0.0]))
            .is_some());
        let b = c.bounds(0);
        assert!(close3(b.min, [0.5, 1.5, -2.0]) && close3(b.max, [1.5, 2.5, 2.0]));
        // A diagonal axis: the box holds both end discs.
        let d = LineCylinder::new(
            &parse_params("(center: (0, 0, 0), axis: (1, 1, 0), radius: 1, extent: 1)").unwrap(),
        )
        .unwrap();
        let half = 0.5f64.sqrt() + 0.5f64.sqrt();
        let b = d.bounds(0);
        assert!(close3(b.max, [half, half, 1.0]));
        assert!(close3(b.min, [-half, -half, -1.0]));
        // The default keeps the cylinder practically infinite.
        assert!(close(z_cylinder("").bounds(0).max[2], 1e6));
    }

    #[test]
    fn cylinder_errors() {
        let bad = |p: &str| err(LineCylinder::new(&parse_params(p).unwrap()));
        assert!(bad("(center: (0, 0, 0), axis: (0, 0, 0), radius: 1)").contains("zero length"));
        assert!(bad("(center: (0, 0, 0), axis: (0, 1, 0), radius: 0)").contains("`radius`"));
        assert!(
            bad("(center: (0, 0, 0), axis: (0, 1, 0), radius: 1, extent: -1)").contains("`extent`")
        );
    }
}
