//! Spheres: 16 bytes each (centre + radius) plus a material index, in their own BVH.

use super::set::{Set, Shape};
use super::{material_of, Hit, Kind, Surface};
use crate::math::{gamma, Aabb, DVec3, Vec3A};
use crate::ray::Ray;
use glam::Vec3;

/// A sphere: 16 bytes (the molecular case stores millions).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}

pub type Spheres = Set<Sphere>;

/// The nearest root of a unit-direction ray against a sphere in (0, t_max), and how many roots
/// lie in (0, t_max). Solved in sphere-centred coordinates with the cancellation-free form of the
/// quadratic (Haines et al., Ray Tracing Gems ch. 7). A cheap f32 test rejects most misses; hits
/// are solved in f64 so that a huge sphere seen from close by (an Earth-sized ground) keeps its
/// precision: in f32, |f|² − r² loses every digit when |f| ≈ r ≈ 1e6.
#[inline(always)]
pub fn intersect_sphere(
    s: &Sphere,
    o: Vec3A,
    d: Vec3A,
    t_min: f32,
    t_max: f32,
) -> (Option<f32>, u32) {
    let c = Vec3A::from(s.center);
    let r = s.radius;
    let f = o - c;
    let l = f - f.dot(d) * d;
    let r2 = r * r;
    if r2 - l.dot(l) < -r2 * 1e-4 {
        return (None, 0);
    }
    solve_sphere(c, r, o, d, t_min, t_max)
}

/// [`intersect_sphere`] past its f32 rejection (which `scene::few` also makes four spheres
/// at a time): the roots in f64.
#[inline(always)]
pub fn solve_sphere(
    c: Vec3A,
    r: f32,
    o: Vec3A,
    d: Vec3A,
    t_min: f32,
    t_max: f32,
) -> (Option<f32>, u32) {
    let f = o.as_dvec3() - c.as_dvec3();
    let d = d.as_dvec3();
    let r = r as f64;
    let b = -f.dot(d);
    let cc = f.dot(f) - r * r;
    // Outside (cc > 0) and moving away (b < 0): q < 0, so both roots below are negative and
    // neither lies past t_min >= 0. Answered first, without the discriminant, the square
    // root and the division (a shadow ray leaving the sphere it starts on).
    if cc > 0.0 && b < 0.0 && t_min >= 0.0 {
        return (None, 0);
    }
    let l = f + b * d;
    let disc = r * r - l.dot(l);
    if disc < 0.0 {
        return (None, 0);
    }
    let q = b + disc.sqrt().copysign(b);
    if q == 0.0 {
        return (None, 0);
    }
    let (mut t0, mut t1) = ((cc / q) as f32, q as f32);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    let in0 = t0 > t_min && t0 < t_max;
    let in1 = t1 > t_min && t1 < t_max;
    let n = u32::from(in0) + u32::from(in1);
    if in0 {
        (Some(t0), n)
    } else if in1 {
        (Some(t1), n)
    } else {
        (None, 0)
    }
}

impl Sphere {
    /// Sphere `i` of a batch given in world coordinates (x, y, z, radius), checked, in render
    /// space (`offset`: the world position of its origin).
    pub fn from_world(i: usize, s: [f64; 4], offset: DVec3) -> Result<Sphere, String> {
        if s.iter().any(|x| !x.is_finite()) {
            return Err(format!("sphere {i} has a non-finite value {s:?}"));
        }
        if s[3] <= 0.0 {
            return Err(format!(
                "sphere {i} has radius {}; expected a radius > 0",
                s[3]
            ));
        }
        Ok(Sphere {
            center: (DVec3::new(s[0], s[1], s[2]) - offset).as_vec3(),
            radius: s[3] as f32,
        })
    }
}

impl Shape for Sphere {
    const KIND: Kind = Kind::Sphere;
    type Prep = ();
    fn prep(_: &Ray) {}

    fn bounds(&self) -> Aabb {
        let c = Vec3A::from(self.center);
        Aabb::new(c - self.radius, c + self.radius)
    }

    #[inline(always)]
    fn hit_after(&self, ray: &Ray, _: &(), t_min: f32, t_max: f32) -> Option<(f32, f32, f32)> {
        intersect_sphere(self, ray.origin, ray.dir, t_min, t_max)
            .0
            .map(|t| (t, 0.0, 0.0))
    }

    #[inline(always)]
    fn crossings(&self, ray: &Ray, _: &(), t_max: f32) -> u32 {
        intersect_sphere(self, ray.origin, ray.dir, 0.0, t_max).1
    }
}

impl Set<Sphere> {
    /// Validates and stores sphere `i` of a batch given in world coordinates.
    pub fn push_world(
        &mut self,
        i: usize,
        s: [f64; 4],
        offset: DVec3,
        material: u32,
    ) -> Result<(), String> {
        self.push(Sphere::from_world(i, s, offset)?, material);
        Ok(())
    }

    /// The surface at a hit; its texture coordinates only when `uv` asks (an `atan2` and an
    /// `acos`: no texture reads them on most spheres).
    pub fn surface(&self, hit: &Hit, ray: &Ray, uv: bool) -> Surface {
        let i = hit.index as usize;
        surface(self.data[i], hit.t, ray, uv, material_of(self.material[i]))
    }
}

/// The surface of sphere `s` hit at distance `t` along `ray`, of `material`; its texture
/// coordinates only when `uv` asks. Shared by the spheres stored here and those read from the
/// caller's arrays (`array_set`), so both shade alike.
#[inline]
pub fn surface(s: Sphere, t: f32, ray: &Ray, uv: bool, material: u32) -> Surface {
    let c = Vec3A::from(s.center);
    // Re-project onto the sphere: the error is then a few ulps of the coordinates. The
    // direction from the centre is taken in f64: for a sphere smaller than the f32 spacing
    // of its position, `ray.at(t) - c` can be exactly zero (a NaN normal).
    let rel = ray.origin.as_dvec3() - c.as_dvec3() + ray.dir.as_dvec3() * t as f64;
    let n = match rel.try_normalize() {
        Some(n) => Vec3A::from(n.as_vec3()),
        None => -ray.dir,
    };
    let pr = n * s.radius;
    let (p, p_error) = {
        let p_proj = c + pr;
        let e_proj = gamma(6) * (pr.abs() + c.abs());
        // Far from the centre of a huge sphere (an Earth-sized ground near the camera), the
        // re-projected point rounds to the f32 spacing at the centre's magnitude (0.5 at
        // 6.4e6): a shadow ray offset by that bound starts above small things on the
        // ground. The point along the ray is then far more precise: rounding of o + t·d
        // and of t to f32, plus the f64 solve's error (relative to the sphere's size).
        let p_ray = ray.at(t);
        let solve = 4.0 * f64::EPSILON as f32 * ((c - ray.origin).length() + s.radius);
        let e_ray = gamma(3) * (ray.origin.abs() + (t * ray.dir).abs()) + solve;
        if e_ray.max_element() < e_proj.max_element() {
            (p_ray, e_ray)
        } else {
            (p_proj, e_proj)
        }
    };
    let uv = if uv {
        let u = 0.5 + n.z.atan2(n.x) / std::f32::consts::TAU;
        let v = n.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        [u, v]
    } else {
        [0.0; 2]
    };
    Surface {
        // u spans 2πr, v spans πr: their geometric mean.
        uv_scale: 1.0 / (std::f32::consts::PI * std::f32::consts::SQRT_2 * s.radius),
        ..Surface::solid(p, p_error, n, uv, material)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_from_outside_and_inside() {
        let s = &Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
        };
        let (t, n) = intersect_sphere(s, Vec3A::ZERO, Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!((t, n), (Some(4.0), 2));
        let (t, n) = intersect_sphere(s, Vec3A::new(0.0, 0.0, 5.0), Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!((t, n), (Some(1.0), 1));
        let (t, _) = intersect_sphere(s, Vec3A::ZERO, -Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!(t, None);
        let (t, _) = intersect_sphere(s, Vec3A::ZERO, Vec3A::Z, 0.0, 3.0);
        assert_eq!(t, None);
    }

    #[test]
    fn huge_far_sphere_has_no_cancellation() {
        // Earth-sized sphere, camera 1 unit above its surface looking straight down.
        let r = 6.4e6f32;
        let s = &Sphere {
            center: Vec3::new(0.0, -r, 0.0),
            radius: r,
        };
        let (t, _) = intersect_sphere(s, Vec3A::new(0.0, 1.0, 0.0), -Vec3A::Y, 0.0, f32::INFINITY);
        let t = t.unwrap();
        assert!((t - 1.0).abs() < 1e-6, "t = {t}");
    }
}
