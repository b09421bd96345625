//! Infinite planes: unbounded, so they stay outside the BVHs and are tested one by one.

use super::{clip_of, material_of, Clips, Counters, Hit, Kind, Surface};
use crate::budget::{Budget, Use};
use crate::math::{gamma, DVec3, Vec3A};
use crate::ray::Ray;

#[derive(Clone, Copy, Debug)]
pub struct Plane {
    pub point: Vec3A,
    /// Unit normal.
    pub normal: Vec3A,
    pub material: u32,
}

#[inline(always)]
fn plane_t(p: &Plane, ray: &Ray, t_max: f32) -> Option<f32> {
    let denom = p.normal.dot(ray.dir);
    // Parallel (or nearly): no hit rather than a division by zero.
    if denom.abs() < 1e-12 {
        return None;
    }
    let t = p.normal.dot(p.point - ray.origin) / denom;
    (t > 0.0 && t < t_max).then_some(t)
}

#[derive(Default)]
pub struct Planes {
    pub planes: Vec<Plane>,
}

impl Planes {
    /// Bytes of the planes (capacity).
    pub fn bytes(&self) -> u64 {
        (self.planes.capacity() * std::mem::size_of::<Plane>()) as u64
    }

    /// Room for `n` more planes, charged to `budget` (see `Set::reserve`).
    pub fn reserve(
        &mut self,
        n: usize,
        budget: &Budget,
        what: &dyn Fn() -> String,
    ) -> Result<(), String> {
        Ok(budget.grow(&mut self.planes, n, Use::Geometry, what)?)
    }

    /// Validates and stores plane `i` (point, normal) given in world coordinates.
    pub fn push_world(
        &mut self,
        i: usize,
        p: [f64; 6],
        offset: DVec3,
        material: u32,
    ) -> Result<(), String> {
        if p.iter().any(|x| !x.is_finite()) {
            return Err(format!("plane {i} has a non-finite value {p:?}"));
        }
        let n = DVec3::new(p[3], p[4], p[5]);
        if n.length() == 0.0 {
            return Err(format!("plane {i} has a zero-length normal"));
        }
        let point = (DVec3::new(p[0], p[1], p[2]) - offset).as_vec3();
        self.planes.push(Plane {
            point: point.into(),
            normal: Vec3A::from(n.normalize().as_vec3()),
            material,
        });
        Ok(())
    }

    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        hit: &mut Option<Hit>,
        clips: &Clips,
        c: &mut Counters,
    ) {
        for (i, p) in self.planes.iter().enumerate() {
            c.tests += 1;
            if let Some(t) =
                plane_t(p, ray, *t_max).filter(|&t| !clips.cut(clip_of(p.material), ray.at(t)))
            {
                *t_max = t;
                *hit = Some(Hit::new(t, Kind::Plane, i));
            }
        }
    }

    #[inline]
    pub fn any(
        &self,
        ray: &Ray,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        mut on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        self.planes.iter().any(|p| {
            c.tests += 1;
            plane_t(p, ray, t_max).is_some_and(|t| !clips.cut(clip_of(p.material), ray.at(t)))
                && on_hit(material_of(p.material), 1)
        })
    }

    /// The surface at a hit; its texture coordinates only when `uv` asks.
    pub fn surface(&self, hit: &Hit, ray: &Ray, uv: bool) -> Surface {
        let pl = &self.planes[hit.index as usize];
        // Project the parametric point back onto the plane.
        let p0 = ray.at(hit.t);
        let p = p0 - pl.normal.dot(p0 - pl.point) * pl.normal;
        let p_error = gamma(5) * (p.abs() + pl.point.abs());
        let uv = if uv {
            let t = crate::math::orthogonal(pl.normal);
            let b = pl.normal.cross(t);
            [(p - pl.point).dot(t), (p - pl.point).dot(b)]
        } else {
            [0.0; 2]
        };
        Surface::solid(p, p_error, pl.normal, uv, material_of(pl.material))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallel_and_behind() {
        let p = Plane {
            point: Vec3A::ZERO,
            normal: Vec3A::Y,
            material: 0,
        };
        let along = Ray::new(Vec3A::new(0.0, 1.0, 0.0), Vec3A::X, 0.0);
        assert_eq!(plane_t(&p, &along, f32::INFINITY), None);
        let inside = Ray::new(Vec3A::ZERO, Vec3A::X, 0.0);
        assert_eq!(plane_t(&p, &inside, f32::INFINITY), None);
        let down = Ray::new(Vec3A::new(0.0, 2.0, 0.0), -Vec3A::Y, 0.0);
        assert_eq!(plane_t(&p, &down, f32::INFINITY), Some(2.0));
        let up = Ray::new(Vec3A::new(0.0, 2.0, 0.0), Vec3A::Y, 0.0);
        assert_eq!(plane_t(&p, &up, f32::INFINITY), None);
    }
}
