//! A set of primitives of one kind in their own BVH. Each kind implements `Shape` (bounds and
//! the ray test); the set supplies storage, building, closest-hit and any-hit traversal, so a
//! new native primitive is one small file.

use super::{clip_of, material_of, Clips, Counters, Hit, Kind};
use crate::budget::{Budget, Use};
use crate::bvh::{BoxRay, Bvh};
use crate::math::Aabb;
use crate::ray::Ray;
use rayon::prelude::*;

pub trait Shape: Copy + Send + Sync {
    const KIND: Kind;
    /// What a ray precomputes once per traversal (e.g. the triangle test's shear).
    type Prep: Copy;
    fn prep(ray: &Ray) -> Self::Prep;
    fn bounds(&self) -> Aabb;
    /// The nearest hit in (0, t_max): t and two kind-specific values (triangle barycentrics).
    fn hit(&self, ray: &Ray, prep: &Self::Prep, t_max: f32) -> Option<(f32, f32, f32)> {
        self.hit_after(ray, prep, 0.0, t_max)
    }
    /// The nearest hit in (t_min, t_max): clipping asks again past a root it cut away.
    fn hit_after(
        &self,
        ray: &Ray,
        prep: &Self::Prep,
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, f32, f32)>;
    /// How many times the ray crosses the surface in (0, t_max) (filtered shadows).
    #[inline(always)]
    fn crossings(&self, ray: &Ray, prep: &Self::Prep, t_max: f32) -> u32 {
        u32::from(self.hit(ray, prep, t_max).is_some())
    }
}

pub struct Set<S> {
    pub data: Vec<S>,
    /// Material and clip group, packed (see `pack`).
    pub material: Vec<u32>,
    bvh: Bvh,
    /// Some primitive belongs to a clip group (set when built): without, tests skip the
    /// packed-material load.
    clipped: bool,
}

impl<S> Default for Set<S> {
    fn default() -> Self {
        Set {
            data: Vec::new(),
            material: Vec::new(),
            bvh: Bvh::default(),
            clipped: false,
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

    /// Primitives, packed materials and BVH, for the geometry cache.
    pub(crate) fn parts(&self) -> (&[S], &[u32], &Bvh) {
        (&self.data, &self.material, &self.bvh)
    }

    /// A set already built (read back from the geometry cache).
    pub(crate) fn from_parts(data: Vec<S>, material: Vec<u32>, bvh: Bvh) -> Set<S> {
        let clipped = material.iter().any(|&m| clip_of(m) != 0);
        Set {
            data,
            material,
            bvh,
            clipped,
        }
    }

    /// Room for `n` more primitives, charged to `budget` for good (the set keeps them); the
    /// error names `what` needed it.
    pub fn reserve(
        &mut self,
        n: usize,
        budget: &Budget,
        what: &dyn Fn() -> String,
    ) -> Result<(), String> {
        budget.grow(&mut self.data, n, Use::Geometry, what)?;
        budget.grow(&mut self.material, n, Use::Geometry, what)?;
        Ok(())
    }

    /// The box around every primitive (once built; empty when the set is).
    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// Bytes of the built BVH.
    pub fn bvh_bytes(&self) -> u64 {
        self.bvh.memory_bytes()
    }

    /// Bytes of the primitives and their materials (capacities).
    pub fn bytes(&self) -> u64 {
        (self.data.capacity() * std::mem::size_of::<S>() + self.material.capacity() * 4) as u64
    }

    pub fn push(&mut self, shape: S, material: u32) {
        self.data.push(shape);
        self.material.push(material);
    }

    /// Builds the BVH and stores the primitives in leaf order.
    pub fn build(&mut self) {
        let data = &self.data;
        let (bvh, order) = Bvh::build_with(data.len(), |i| data[i].bounds());
        if crate::bvh::serial(order.len()) {
            self.data = order.iter().map(|&i| self.data[i as usize]).collect();
            self.material = order.iter().map(|&i| self.material[i as usize]).collect();
        } else {
            self.data = order.par_iter().map(|&i| self.data[i as usize]).collect();
            self.material = order
                .par_iter()
                .map(|&i| self.material[i as usize])
                .collect();
        }
        self.bvh = bvh;
        self.clipped = self.material.iter().any(|&m| clip_of(m) != 0);
    }

    /// The nearest hit of primitive `i` in (0, t_max) that its clip group keeps.
    #[inline(always)]
    fn kept_hit(
        &self,
        i: usize,
        ray: &Ray,
        prep: &S::Prep,
        t_max: f32,
        clips: &Clips,
    ) -> Option<(f32, f32, f32)> {
        let shape = &self.data[i];
        if !self.clipped {
            return shape.hit(ray, prep, t_max);
        }
        let clip = clip_of(self.material[i]);
        if clip == 0 {
            return shape.hit(ray, prep, t_max);
        }
        let mut lo = 0.0;
        loop {
            let h = shape.hit_after(ray, prep, lo, t_max)?;
            if !clips.cut(clip, ray.at(h.0)) {
                return Some(h);
            }
            lo = h.0;
        }
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
        if self.data.is_empty() {
            return;
        }
        let boxes = BoxRay::new(ray.origin, ray.dir);
        self.intersect_noting(ray, &boxes, t_max, hit, clips, c, |_| {});
    }

    /// [`Set::intersect`] for a ray whose box tests are prepared (`boxes`, once for every
    /// kind), calling `noted(prim)` for every closer hit found on the way (for prefetching
    /// what shading that primitive will read).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn intersect_noting(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: &mut f32,
        hit: &mut Option<Hit>,
        clips: &Clips,
        c: &mut Counters,
        noted: impl Fn(usize),
    ) {
        if self.data.is_empty() {
            return;
        }
        let prep = S::prep(ray);
        *t_max = self.bvh.intersect_ray(
            boxes,
            *t_max,
            #[inline(always)]
            |i, tm| {
                c.tests += 1;
                let (t, b1, b2) = self.kept_hit(i, ray, &prep, tm, clips)?;
                let mut h = Hit::new(t, S::KIND, i);
                h.b1 = b1;
                h.b2 = b2;
                *hit = Some(h);
                noted(i);
                Some(t)
            },
        );
    }

    /// Calls `on_hit(material, crossings)` for primitives the ray crosses in (0, t_max) until it
    /// returns true; returns whether it did.
    #[inline]
    pub fn any(
        &self,
        ray: &Ray,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.data.is_empty() {
            return false;
        }
        let boxes = BoxRay::new(ray.origin, ray.dir);
        self.any_with::<false>(ray, &boxes, t_max, clips, c, |_| false, on_hit)
    }

    /// [`Set::any`] for a ray whose box tests are prepared (`boxes`, once for every kind).
    #[inline]
    pub fn any_prepared(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        self.any_with::<false>(ray, boxes, t_max, clips, c, |_| false, on_hit)
    }

    /// [`Set::any_prepared`] passing over, untested, the primitives whose material `skip`
    /// names (those a shadow ray crosses unchanged: testing them cannot change what it
    /// carries).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn any_skipping(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        skip: impl Fn(u32) -> bool,
        on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        self.any_with::<true>(ray, boxes, t_max, clips, c, skip, on_hit)
    }

    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn any_with<const SKIP: bool>(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        skip: impl Fn(u32) -> bool,
        mut on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.data.is_empty() {
            return false;
        }
        let prep = S::prep(ray);
        self.bvh.any_ray(
            boxes,
            t_max,
            #[inline(always)]
            |i| {
                if SKIP && skip(material_of(self.material[i])) {
                    return false;
                }
                c.tests += 1;
                if !self.clipped {
                    let n = self.data[i].crossings(ray, &prep, t_max);
                    return n > 0 && on_hit(material_of(self.material[i]), n);
                }
                let packed = self.material[i];
                let n = if clip_of(packed) == 0 {
                    self.data[i].crossings(ray, &prep, t_max)
                } else {
                    // Count only the crossings the clip group keeps.
                    let (mut n, mut lo) = (0, 0.0);
                    while let Some(h) = self.data[i].hit_after(ray, &prep, lo, t_max) {
                        n += u32::from(!clips.cut(clip_of(packed), ray.at(h.0)));
                        lo = h.0;
                    }
                    n
                };
                n > 0 && on_hit(material_of(packed), n)
            },
        )
    }
}
