//! Discs and rings (a disc with a hole): Tachyon's ring, and the caps of cylinders and cones.

use super::cone::disc_bounds;
use super::{Counters, Hit, Kind, Surface};
use crate::bvh::Bvh;
use crate::math::{gamma, Aabb, DVec3, Vec3A};
use crate::ray::Ray;

#[derive(Default)]
pub struct Discs {
    /// Centre x, y, z, unit normal x, y, z, inner radius, outer radius.
    pub data: Vec<[f32; 8]>,
    pub material: Vec<u32>,
    bvh: Bvh,
}

#[inline(always)]
fn disc_t(d: &[f32; 8], o: Vec3A, dir: Vec3A, t_max: f32) -> Option<f32> {
    let c = Vec3A::new(d[0], d[1], d[2]);
    let n = Vec3A::new(d[3], d[4], d[5]);
    let denom = n.dot(dir);
    if denom.abs() < 1e-12 {
        return None;
    }
    let t = n.dot(c - o) / denom;
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let r2 = (o + t * dir - c).length_squared();
    (r2 >= d[6] * d[6] && r2 <= d[7] * d[7]).then_some(t)
}

impl Discs {
    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    pub fn push(
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
        let c = (DVec3::new(d[0], d[1], d[2]) - offset).as_vec3();
        let n = n.normalize().as_vec3();
        self.data
            .push([c.x, c.y, c.z, n.x, n.y, n.z, d[6] as f32, d[7] as f32]);
        self.material.push(material);
        Ok(())
    }

    pub fn bounds(&self) -> Vec<Aabb> {
        self.data
            .iter()
            .map(|d| {
                disc_bounds(
                    Vec3A::new(d[0], d[1], d[2]),
                    Vec3A::new(d[3], d[4], d[5]),
                    d[7],
                )
            })
            .collect()
    }

    pub fn build(&mut self) {
        let (bvh, order) = Bvh::build(&self.bounds());
        self.data = order.iter().map(|&i| self.data[i as usize]).collect();
        self.material = order.iter().map(|&i| self.material[i as usize]).collect();
        self.bvh = bvh;
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: &mut f32, hit: &mut Option<Hit>, c: &mut Counters) {
        if self.data.is_empty() {
            return;
        }
        *t_max = self.bvh.intersect(ray.origin, ray.dir, *t_max, |i, tm| {
            c.tests += 1;
            let t = disc_t(&self.data[i as usize], ray.origin, ray.dir, tm)?;
            *hit = Some(Hit::new(t, Kind::Disc, i));
            Some(t)
        });
    }

    #[inline]
    pub fn any(
        &self,
        ray: &Ray,
        t_max: f32,
        c: &mut Counters,
        mut on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.data.is_empty() {
            return false;
        }
        self.bvh.any(ray.origin, ray.dir, t_max, |i| {
            c.tests += 1;
            disc_t(&self.data[i as usize], ray.origin, ray.dir, t_max).is_some()
                && on_hit(self.material[i as usize], 1)
        })
    }

    pub fn surface(&self, hit: &Hit, ray: &Ray) -> Surface {
        let d = &self.data[hit.index as usize];
        let c = Vec3A::new(d[0], d[1], d[2]);
        let n = Vec3A::new(d[3], d[4], d[5]);
        let p0 = ray.at(hit.t);
        let p = p0 - n.dot(p0 - c) * n;
        let r = p - c;
        let t = crate::math::orthogonal(n);
        let angle = r.dot(n.cross(t)).atan2(r.dot(t));
        Surface {
            p,
            p_error: gamma(5) * (p.abs() + c.abs()),
            ng: n,
            ns: n,
            uv: [
                (r.length() - d[6]) / (d[7] - d[6]),
                0.5 + angle / std::f32::consts::TAU,
            ],
            material: self.material[hit.index as usize],
            color: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_has_a_hole() {
        let ring = [0.0, 0.0, 5.0, 0.0, 0.0, -1.0, 1.0, 2.0];
        assert_eq!(disc_t(&ring, Vec3A::ZERO, Vec3A::Z, f32::INFINITY), None);
        let o = Vec3A::new(1.5, 0.0, 0.0);
        assert_eq!(disc_t(&ring, o, Vec3A::Z, f32::INFINITY), Some(5.0));
        let far = Vec3A::new(2.5, 0.0, 0.0);
        assert_eq!(disc_t(&ring, far, Vec3A::Z, f32::INFINITY), None);
        // Parallel to the disc: no division by zero, no hit.
        assert_eq!(
            disc_t(&ring, Vec3A::new(0.0, 0.0, 5.0), Vec3A::X, f32::INFINITY),
            None
        );
    }
}
