//! A set of primitives of one kind in their own BVH. Each kind implements `Shape` (bounds and
//! the ray test); the set supplies storage, building, closest-hit and any-hit traversal, so a
//! new native primitive is one small file.

use super::{Counters, Hit, Kind};
use crate::bvh::Bvh;
use crate::math::Aabb;
use crate::ray::Ray;

pub trait Shape: Copy + Send + Sync {
    const KIND: Kind;
    /// What a ray precomputes once per traversal (e.g. the triangle test's shear).
    type Prep: Copy;
    fn prep(ray: &Ray) -> Self::Prep;
    fn bounds(&self) -> Aabb;
    /// The nearest hit in (0, t_max): t and two kind-specific values (triangle barycentrics).
    fn hit(&self, ray: &Ray, prep: &Self::Prep, t_max: f32) -> Option<(f32, f32, f32)>;
    /// How many times the ray crosses the surface in (0, t_max) (filtered shadows).
    fn crossings(&self, ray: &Ray, prep: &Self::Prep, t_max: f32) -> u32 {
        u32::from(self.hit(ray, prep, t_max).is_some())
    }
}

pub struct Set<S> {
    pub data: Vec<S>,
    pub material: Vec<u32>,
    bvh: Bvh,
}

impl<S> Default for Set<S> {
    fn default() -> Self {
        Set {
            data: Vec::new(),
            material: Vec::new(),
            bvh: Bvh::default(),
        }
    }
}

impl<S: Shape> Set<S> {
    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    pub fn push(&mut self, shape: S, material: u32) {
        self.data.push(shape);
        self.material.push(material);
    }

    /// Builds the BVH and stores the primitives in leaf order.
    pub fn build(&mut self) {
        let bounds: Vec<Aabb> = self.data.iter().map(S::bounds).collect();
        let (bvh, order) = Bvh::build(&bounds);
        self.data = order.iter().map(|&i| self.data[i as usize]).collect();
        self.material = order.iter().map(|&i| self.material[i as usize]).collect();
        self.bvh = bvh;
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: &mut f32, hit: &mut Option<Hit>, c: &mut Counters) {
        if self.data.is_empty() {
            return;
        }
        let prep = S::prep(ray);
        *t_max = self.bvh.intersect(ray.origin, ray.dir, *t_max, |i, tm| {
            c.tests += 1;
            let (t, b1, b2) = self.data[i as usize].hit(ray, &prep, tm)?;
            let mut h = Hit::new(t, S::KIND, i);
            h.b1 = b1;
            h.b2 = b2;
            *hit = Some(h);
            Some(t)
        });
    }

    /// Calls `on_hit(material, crossings)` for primitives the ray crosses in (0, t_max) until it
    /// returns true; returns whether it did.
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
        let prep = S::prep(ray);
        self.bvh.any(ray.origin, ray.dir, t_max, |i| {
            c.tests += 1;
            let n = self.data[i as usize].crossings(ray, &prep, t_max);
            n > 0 && on_hit(self.material[i as usize], n)
        })
    }
}
