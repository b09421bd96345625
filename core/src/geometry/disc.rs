//! Discs and rings (a disc with a hole): Tachyon's ring, and the caps of cylinders and cones.

use super::cone::disc_bounds;
use super::set::{Set, Shape};
use super::{material_of, Hit, Kind, Surface};
use crate::math::{gamma, Aabb, DVec3, Vec3A};
use crate::ray::Ray;
use glam::Vec3;

/// A disc, or a ring when `inner` > 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    pub center: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    pub inner: f32,
    pub outer: f32,
}

pub type Discs = Set<Disc>;

#[inline(always)]
fn disc_t(d: &Disc, o: Vec3A, dir: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let c = Vec3A::from(d.center);
    let n = Vec3A::from(d.normal);
    let denom = n.dot(dir);
    if denom.abs() < 1e-12 {
        return None;
    }
    let t = n.dot(c - o) / denom;
    if !(t > t_min && t < t_max) {
        return None;
    }
    let r2 = (o + t * dir - c).length_squared();
    (r2 >= d.inner * d.inner && r2 <= d.outer * d.outer).then_some(t)
}

impl Shape for Disc {
    const KIND: Kind = Kind::Disc;
    type Prep = ();
    fn prep(_: &Ray) {}

    fn bounds(&self) -> Aabb {
        disc_bounds(self.center.into(), self.normal.into(), self.outer)
    }

    #[inline(always)]
    fn hit_after(&self, ray: &Ray, _: &(), t_min: f32, t_max: f32) -> Option<(f32, f32, f32)> {
        disc_t(self, ray.origin, ray.dir, t_min, t_max).map(|t| (t, 0.0, 0.0))
    }
}

impl Set<Disc> {
    /// Validates and stores disc `i` of a batch given in world coordinates.
    pub fn push_world(
        &mut self,
        i: usize,
        d: [f64; 8],
        offset: DVec3,
        material: u32,
    ) -> Result<(), String> {
        if d.iter().any(|v| !v.is_finite()) {
            return Err(format!("disc {i} has a non-finite value {d:?}"));
        }
        let n = DVec3::new(d[3], d[4], d[5]);
        if n.length() == 0.0 {
            return Err(format!("disc {i} has a zero-length normal"));
        }
        if !(d[6] >= 0.0 && d[7] > d[6]) {
            return Err(format!(
                "disc {i} has inner radius {} and outer radius {}; expected 0 <= inner < outer",
                d[6], d[7]
            ));
        }
        let disc = Disc {
            center: (DVec3::new(d[0], d[1], d[2]) - offset).as_vec3(),
            normal: n.normalize().as_vec3(),
            inner: d[6] as f32,
            outer: d[7] as f32,
        };
        self.push(disc, material);
        Ok(())
    }

    /// The surface at a hit; its texture coordinates only when `uv` asks.
    pub fn surface(&self, hit: &Hit, ray: &Ray, uv: bool) -> Surface {
        let i = hit.index as usize;
        surface(&self.data[i], hit.t, ray, uv, material_of(self.material[i]))
    }
}

/// The surface of disc `d` hit at distance `t` along `ray`, of `material`; its texture
/// coordinates only when `uv` asks. Shared with the cylinder caps read from the caller's
/// arrays.
#[inline]
pub fn surface(d: &Disc, t: f32, ray: &Ray, uv: bool, material: u32) -> Surface {
    let c = Vec3A::from(d.center);
    let n = Vec3A::from(d.normal);
    let p0 = ray.at(t);
    let p = p0 - n.dot(p0 - c) * n;
    let uv = if uv {
        let r = p - c;
        let t = crate::math::orthogonal(n);
        let angle = r.dot(n.cross(t)).atan2(r.dot(t));
        [
            (r.length() - d.inner) / (d.outer - d.inner),
            0.5 + angle / std::f32::consts::TAU,
        ]
    } else {
        [0.0; 2]
    };
    Surface::solid(p, gamma(5) * (p.abs() + c.abs()), n, uv, material)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_has_a_hole() {
        let ring = Disc {
            center: Vec3::new(0.0, 0.0, 5.0),
            normal: -Vec3::Z,
            inner: 1.0,
            outer: 2.0,
        };
        assert_eq!(
            disc_t(&ring, Vec3A::ZERO, Vec3A::Z, 0.0, f32::INFINITY),
            None
        );
        let o = Vec3A::new(1.5, 0.0, 0.0);
        assert_eq!(disc_t(&ring, o, Vec3A::Z, 0.0, f32::INFINITY), Some(5.0));
        let far = Vec3A::new(2.5, 0.0, 0.0);
        assert_eq!(disc_t(&ring, far, Vec3A::Z, 0.0, f32::INFINITY), None);
        // Parallel to the disc: no division by zero, no hit.
        assert_eq!(
            disc_t(
                &ring,
                Vec3A::new(0.0, 0.0, 5.0),
                Vec3A::X,
                0.0,
                f32::INFINITY
            ),
            None
        );
    }
}
