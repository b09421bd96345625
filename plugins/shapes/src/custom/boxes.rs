//! `box`: an axis-aligned box; the ray enters through the face it hits first (or, from inside,
//! leaves through the far one).

use super::{at, check_box, in_range, slabs, usable};
use crate::vector::V3;
use luxon_plugin::{Aabb, Context, CustomShape, Describe, Error, Geometry, Hit, Primitive, Ray};
use serde::Deserialize;

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct BoxParams {
    pub min: V3,
    pub max: V3,
}

/// A validated axis-aligned box.
#[derive(Clone, Debug)]
pub struct Cuboid {
    min: V3,
    max: V3,
}

impl Cuboid {
    pub fn new(p: &BoxParams) -> Result<Cuboid, Error> {
        let (min, max) = check_box(p.min, p.max)?;
        Ok(Cuboid { min, max })
    }

    fn face_hit(&self, ray: &Ray, t: f64, axis: usize, outward: f64) -> Hit {
        let mut normal = [0.0; 3];
        normal[axis] = outward;
        let p = at(ray, t);
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        let rel = |k: usize| ((p[k] - self.min[k]) / (self.max[k] - self.min[k])).clamp(0.0, 1.0);
        Hit {
            t,
            normal,
            uv: [rel(a) as f32, rel(b) as f32],
        }
    }
}

impl CustomShape for Cuboid {
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
        let (t0, a0, t1, a1) = slabs(self.min, self.max, ray)?;
        if in_range(ray, t0) {
            // Entering: the face faces against the ray.
            Some(self.face_hit(ray, t0, a0, -ray.direction[a0].signum()))
        } else if in_range(ray, t1) {
            // From inside: the far face, normal still outward.
            Some(self.face_hit(ray, t1, a1, ray.direction[a1].signum()))
        } else {
            None
        }
    }
}

pub struct BoxEntry;

impl Describe for BoxEntry {
    const NAME: &'static str = "box";
    const DESCRIPTION: &'static str = "An axis-aligned box (Tachyon's box), custom geometry.";
    const PARAMS: &'static str = "min: (x, y, z)  lowest corner
max: (x, y, z)  highest corner, > min on every axis";
}

impl Primitive for BoxEntry {
    type Params = BoxParams;
    fn create(p: BoxParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(Cuboid::new(&p)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{assert_hit, close, err, hit, ray};
    use luxon_plugin::parse_params;

    fn unit_box() -> Cuboid {
        Cuboid::new(&parse_params("(min: (-1, -1, -1), max: (1, 1, 1))").unwrap()).unwrap()
    }

    #[test]
    fn box_hits_the_near_face_with_its_normal() {
        let b = unit_box();
        assert_hit(
            &b,
            &ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]),
            4.0,
            [0.0, 0.0, -1.0],
        );
        assert_hit(
            &b,
            &ray([5.0, 0.5, 0.2], [-2.0, 0.0, 0.0]),
            2.0,
            [1.0, 0.0, 0.0],
        );
        assert_hit(
            &b,
            &ray([0.3, 3.0, 0.2], [0.0, -1.0, 0.0]),
            2.0,
            [0.0, 1.0, 0.0],
        );
        // Oblique, through the top face at (0.5, 1, 0).
        assert_hit(
            &b,
            &ray([-0.5, 2.0, 0.0], [1.0, -1.0, 0.0]),
            1.0,
            [0.0, 1.0, 0.0],
        );
        assert_eq!(b.bounds(0).max, [1.0; 3]);
    }

    #[test]
    fn box_from_inside_hits_the_far_face() {
        let b = unit_box();
        assert_hit(&b, &ray([0.0; 3], [0.0, 0.0, 1.0]), 1.0, [0.0, 0.0, 1.0]);
        assert_hit(
            &b,
            &ray([0.5, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            1.5,
            [-1.0, 0.0, 0.0],
        );
    }

    #[test]
    fn box_misses_and_respects_the_ray_interval() {
        let b = unit_box();
        assert!(b
            .intersect(0, &ray([0.0, 2.0, -5.0], [0.0, 0.0, 1.0]))
            .is_none());
        assert!(b
            .intersect(0, &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]))
            .is_none());
        assert!(b
            .intersect(0, &ray([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]))
            .is_none());
        let mut short = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
        short.tmax = 3.9;
        assert!(b.intersect(0, &short).is_none());
        short.tmax = 6.5;
        short.tmin = 4.0; // t = 4 is excluded: the far face is next.
        assert_hit(&b, &short, 6.0, [0.0, 0.0, 1.0]);
    }

    #[test]
    fn box_parallel_rays_give_no_nan() {
        let b = unit_box();
        // Parallel to the x and y faces, inside those slabs.
        assert_hit(
            &b,
            &ray([0.2, -0.3, -5.0], [0.0, 0.0, 1.0]),
            4.0,
            [0.0, 0.0, -1.0],
        );
        // Parallel to the x faces, outside their slab.
        assert!(b
            .intersect(0, &ray([1.5, 0.0, -5.0], [0.0, 0.0, 1.0]))
            .is_none());
        // Exactly in the face plane y = 1: touches the box, enters through x = -1.
        assert_hit(
            &b,
            &ray([-3.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
            2.0,
            [-1.0, 0.0, 0.0],
        );
        // Along an edge (in two face planes at once).
        assert_hit(
            &b,
            &ray([-3.0, 1.0, 1.0], [1.0, 0.0, 0.0]),
            2.0,
            [-1.0, 0.0, 0.0],
        );
        // Tiny direction components do not produce NaN either.
        let h = b
            .intersect(0, &ray([0.0, 0.0, -5.0], [1e-320, -1e-320, 1.0]))
            .unwrap();
        assert!(close(h.t, 4.0));
    }

    #[test]
    fn box_grazing_a_corner_touches() {
        let b = unit_box();
        // The line x + y = 2 in the z = 0 plane touches the corner (1, 1) only.
        let (t, _) = hit(&b, &ray([0.0, 2.0, 0.0], [1.0, -1.0, 0.0])).unwrap();
        assert!(close(t, 1.0));
    }

    #[test]
    fn box_errors() {
        let p: BoxParams = parse_params("(min: (0, 0, 0), max: (1, 0, 1))").unwrap();
        let m = err(Cuboid::new(&p));
        assert!(
            m.contains("smaller than `max`") && m.contains("on y"),
            "{m}"
        );
        let p = BoxParams {
            min: [f64::NAN, 0.0, 0.0],
            max: [1.0; 3],
        };
        assert!(err(Cuboid::new(&p)).contains("`min` must be finite"));
        assert!(parse_params::<BoxParams>("(min: (0, 0, 0))").is_err());
    }
}
