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
    /// The kind has tests that pay only among [`Shape::dense`] primitives
    /// ([`Shape::hit_after_in`], [`Shape::crossings_in`]); sets of other kinds compile one
    /// traversal, not two.
    const DENSE_TESTS: bool = false;
    /// Whether these primitives (in leaf order) overlap so much that tests which pay only then
    /// should run (see `Set::dense`).
    fn dense(data: &[Self]) -> bool {
        let _ = data;
        false
    }
    fn bounds(&self) -> Aabb;
    /// The SAH prices a leaf by blocks of this many primitives (see `Bvh::build_blocks`): more
    /// than 1 for a kind whose leaf test takes a block at a time. Triangles stay at 1 until
    /// such a test pays and ties are canonical (examples/BENCHMARKS.md, h9-tri).
    const LEAF_BLOCK: usize = 1;
    /// The nearest hit in (0, t_max): t and two kind-specific values (triangle barycentrics).
    #[inline(always)]
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
    /// [`Shape::hit_after`] in a set that is [`Shape::dense`] (`DENSE`) or not: the same
    /// answer, by the tests that pay there.
    #[inline(always)]
    fn hit_after_in<const DENSE: bool>(
        &self,
        ray: &Ray,
        prep: &Self::Prep,
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, f32, f32)> {
        self.hit_after(ray, prep, t_min, t_max)
    }
    /// [`Shape::crossings`] in a set that is [`Shape::dense`] (`DENSE`) or not.
    #[inline(always)]
    fn crossings_in<const DENSE: bool>(&self, ray: &Ray, prep: &Self::Prep, t_max: f32) -> u32 {
        self.crossings(ray, prep, t_max)
    }
    /// In a [`Shape::dense`] set: which of the up to [`BLOCK`] primitives from `start` may
    /// meet the ray in (t_min, t_max) (bit k for `start + k`), tested together; a cleared bit
    /// promises that [`Shape::hit_after_in`] and [`Shape::crossings_in`] would find nothing
    /// there for this ray in any (t_min', t_max') inside (t_min, t_max).
    #[inline(always)]
    fn block_may_hit(data: &[Self], start: usize, ray: &Ray, t_min: f32, t_max: f32) -> u32 {
        let _ = (data, start, ray, t_min, t_max);
        u32::MAX
    }
}

/// Primitives a dense set's traversal tests together ([`Shape::block_may_hit`]): a leaf or
/// more, in leaf order.
pub const BLOCK: usize = 8;

/// The last block a dense set's traversal tested: its first primitive and its mask. Leaves
/// are visited in any order, but a block tested with a larger t_max than now only lets more
/// through, so a mask stays valid for the rest of the ray.
struct Block {
    start: usize,
    mask: u32,
}

impl Block {
    /// No block yet: every index lies outside it (`i - start` wraps to `i + BLOCK + 1`).
    const NONE: Block = Block {
        start: usize::MAX - BLOCK,
        mask: 0,
    };

    /// Whether primitive `i` may meet the ray, testing its block when `i` is outside the last.
    #[inline(always)]
    fn may_hit(&mut self, i: usize, test: impl FnOnce() -> u32) -> bool {
        let mut k = i.wrapping_sub(self.start);
        if k >= BLOCK {
            (self.start, self.mask, k) = (i, test(), 0);
        }
        self.mask >> k & 1 != 0
    }
}

/// Up to this many primitives of a kind, an opaque any-hit query tests them one by one,
/// without the box tests of the tree's node (eight boxes and their set-up): four spheres,
/// whose test rejects a miss about as cheaply as a box test, or two triangles; cones and discs
/// cost more than their boxes (measured on Tachyon's scenes).
const fn tiny(kind: Kind) -> usize {
    match kind {
        Kind::Sphere => 4,
        Kind::Triangle => 2,
        _ => 0,
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
    /// The primitives overlap much ([`Shape::dense`], set when built): a hint that only
    /// chooses which of a kind's equivalent tests run, never what they find.
    dense: bool,
}

impl<S> Default for Set<S> {
    fn default() -> Self {
        Set {
            data: Vec::new(),
            material: Vec::new(),
            bvh: Bvh::default(),
            clipped: false,
            dense: false,
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
        let dense = S::dense(&data);
        Set {
            data,
            material,
            bvh,
            clipped,
            dense,
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
        let (bvh, order) = Bvh::build_blocks(data.len(), S::LEAF_BLOCK, |i| data[i].bounds());
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
        self.dense = S::dense(&self.data);
    }

    /// A copy holding only the primitives whose packed material `keep` accepts, with its own
    /// BVH.
    pub fn filtered(&self, keep: impl Fn(u32) -> bool) -> Set<S> {
        let mut out = Set::default();
        for (s, &m) in self.data.iter().zip(&self.material) {
            if keep(m) {
                out.push(*s, m);
            }
        }
        out.build();
        out
    }

    /// The nearest hit of primitive `i` in (0, t_max) that its clip group keeps.
    #[inline(always)]
    fn kept_hit<const DENSE: bool>(
        &self,
        i: usize,
        ray: &Ray,
        prep: &S::Prep,
        t_max: f32,
        clips: &Clips,
    ) -> Option<(f32, f32, f32)> {
        let shape = &self.data[i];
        let hit = |t_max| match DENSE {
            true => shape.hit_after_in::<true>(ray, prep, 0.0, t_max),
            false => shape.hit(ray, prep, t_max),
        };
        if !self.clipped {
            return hit(t_max);
        }
        let clip = clip_of(self.material[i]);
        if clip == 0 {
            return hit(t_max);
        }
        let mut lo = 0.0;
        loop {
            let h = shape.hit_after_in::<DENSE>(ray, prep, lo, t_max)?;
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
        if S::DENSE_TESTS && self.dense {
            self.closest_with::<true>(ray, boxes, t_max, hit, clips, c, noted);
        } else {
            self.closest_with::<false>(ray, boxes, t_max, hit, clips, c, noted);
        }
    }

    /// [`Set::intersect_noting`] with the tests for `DENSE` primitives or the others (a
    /// constant, so the choice is made once per ray, not per test). Dense sets skip the
    /// primitives their [`Block`] rules out.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn closest_with<const DENSE: bool>(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: &mut f32,
        hit: &mut Option<Hit>,
        clips: &Clips,
        c: &mut Counters,
        noted: impl Fn(usize),
    ) {
        let prep = S::prep(ray);
        // Unused (and optimised away) in the other sets.
        let mut block = Block::NONE;
        *t_max = self.bvh.intersect_ray(
            boxes,
            *t_max,
            #[inline(always)]
            |i, tm| {
                c.tests += 1;
                if DENSE && !block.may_hit(i, || S::block_may_hit(&self.data, i, ray, 0.0, tm)) {
                    return None;
                }
                let (t, b1, b2) = self.kept_hit::<DENSE>(i, ray, &prep, tm, clips)?;
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

    /// Whether the ray crosses a primitive in (0, t_max) (that its clip group keeps): the
    /// query of a world where every primitive blocks, so the order of the tests does not
    /// matter. A handful of spheres or triangles are tested one by one, without the box tests
    /// (which only pass over primitives the ray cannot cross).
    #[inline]
    pub fn any_opaque(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
    ) -> bool {
        if self.few() {
            // A ray with a NaN or infinite coordinate, or a NaN length, meets nothing, as in
            // the trees.
            if self.data.is_empty() || !boxes.finite() || t_max.is_nan() {
                return false;
            }
            return self.any_few(ray, t_max, c);
        }
        self.any_with::<false>(ray, boxes, t_max, clips, c, |_| false, |_, _| true)
    }

    /// Whether [`Set::any_few`] may answer for this set: a handful of primitives, none clipped.
    #[inline(always)]
    pub fn few(&self) -> bool {
        self.data.len() <= const { tiny(S::KIND) } && !self.clipped
    }

    /// [`Set::any_opaque`] for a set that is [`Set::few`], tested one by one without a box
    /// set-up; the caller has checked that the ray is finite and `t_max` not NaN (the tree
    /// meets nothing otherwise).
    #[inline(always)]
    pub fn any_few(&self, ray: &Ray, t_max: f32, c: &mut Counters) -> bool {
        // No set-up for an empty kind (a triangle ray's shear is some 70 instructions).
        if self.data.is_empty() {
            return false;
        }
        let prep = S::prep(ray);
        self.data.iter().any(|s| {
            c.tests += 1;
            s.crossings(ray, &prep, t_max) > 0
        })
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
        on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.data.is_empty() {
            return false;
        }
        if S::DENSE_TESTS && self.dense {
            self.first_with::<SKIP, true>(ray, boxes, t_max, clips, c, skip, on_hit)
        } else {
            self.first_with::<SKIP, false>(ray, boxes, t_max, clips, c, skip, on_hit)
        }
    }

    /// [`Set::any_with`] with the tests for `DENSE` primitives or the others.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn first_with<const SKIP: bool, const DENSE: bool>(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        skip: impl Fn(u32) -> bool,
        mut on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        let prep = S::prep(ray);
        let mut block = Block::NONE;
        self.bvh.any_ray(
            boxes,
            t_max,
            #[inline(always)]
            |i| {
                if SKIP && skip(material_of(self.material[i])) {
                    return false;
                }
                c.tests += 1;
                if DENSE && !block.may_hit(i, || S::block_may_hit(&self.data, i, ray, 0.0, t_max)) {
                    return false;
                }
                if !self.clipped {
                    let n = self.data[i].crossings_in::<DENSE>(ray, &prep, t_max);
                    return n > 0 && on_hit(material_of(self.material[i]), n);
                }
                let packed = self.material[i];
                let n = if clip_of(packed) == 0 {
                    self.data[i].crossings_in::<DENSE>(ray, &prep, t_max)
                } else {
                    // Count only the crossings the clip group keeps.
                    let (mut n, mut lo) = (0, 0.0);
                    while let Some(h) = self.data[i].hit_after_in::<DENSE>(ray, &prep, lo, t_max) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sphere::Sphere;
    use crate::geometry::triangle::Triangle;
    use crate::math::Vec3A;
    use glam::Vec3;

    /// Rays from a grid of origins toward a grid of targets, with lengths ending before,
    /// inside and past the primitives, and some with non-finite coordinates.
    fn rays() -> Vec<(Ray, f32)> {
        let mut out = Vec::new();
        for i in 0..9 {
            for j in 0..9 {
                let o = Vec3A::new(i as f32 * 0.7 - 3.0, j as f32 * 0.6 - 2.5, -4.0);
                for k in 0..7 {
                    let target = Vec3A::new(k as f32 * 0.5 - 1.5, 0.3 * k as f32 - 1.0, 1.0);
                    let d = (target - o).normalize();
                    for t_max in [1.0, 4.5, f32::INFINITY] {
                        out.push((Ray::new(o, d, 0.0), t_max));
                    }
                }
            }
        }
        out.push((
            Ray::new(Vec3A::new(f32::NAN, 0.0, -4.0), Vec3A::Z, 0.0),
            9.0,
        ));
        out.push((
            Ray::new(Vec3A::new(0.0, 0.0, -4.0), Vec3A::Z, 0.0),
            f32::NAN,
        ));
        out
    }

    /// The loop over a handful of primitives answers as the tree does, on every ray.
    fn same_as_tree<S: Shape>(set: &Set<S>) -> usize {
        let (clips, mut c) = (Clips::default(), Counters::default());
        let mut blocked = 0;
        for (ray, t_max) in rays() {
            let b = BoxRay::new(ray.origin, ray.dir);
            let tree = set.any_prepared(&ray, &b, t_max, &clips, &mut c, |_, _| true);
            let one_by_one = set.any_opaque(&ray, &b, t_max, &clips, &mut c);
            assert_eq!(one_by_one, tree, "{ray:?} {t_max}");
            blocked += usize::from(tree);
        }
        blocked
    }

    /// A seashell's spheres (each overlapping the next) are dense, spaced or touching ones
    /// are not; and a dense set answers every query as the same set without the dense tests.
    #[test]
    fn dense_sets_answer_as_the_others() {
        let shell = |step: f32| {
            let mut set = Set::default();
            for k in 0..300 {
                let a = k as f32 * step;
                let r = 0.05 + 0.002 * k as f32;
                let center = Vec3::new(
                    a.cos() * (1.0 + 0.3 * a),
                    a.sin() * (1.0 + 0.3 * a),
                    2.0 + 0.05 * a,
                );
                set.push(Sphere { center, radius: r }, k);
            }
            set.build();
            set
        };
        let dense = shell(0.02);
        assert!(dense.dense);
        assert!(!shell(2.0).dense);
        let mut touching = Set::default();
        for k in 0..100 {
            let center = Vec3::new(2.0 * k as f32, 0.0, 0.0);
            touching.push(
                Sphere {
                    center,
                    radius: 1.0,
                },
                0,
            );
        }
        touching.build();
        assert!(!touching.dense);

        let mut plain = shell(0.02);
        plain.dense = false;
        let (clips, mut c) = (Clips::default(), Counters::default());
        // The test rays, and rays leaving points on the spheres' surfaces (shadow and
        // reflection rays, which start inside many boxes).
        let mut all = rays();
        for (k, s) in dense.data.iter().enumerate().step_by(7) {
            let n = Vec3A::new((k as f32).sin(), (k as f32).cos(), 0.3).normalize();
            let p = Vec3A::from(s.center) + n * s.radius * 1.0001;
            for d in [n, -n, Vec3A::Z, (n + Vec3A::X).normalize()] {
                all.push((Ray::new(p, d, 0.0), f32::INFINITY));
                all.push((Ray::new(p, d, 0.0), 0.5));
            }
        }
        let (mut hits, mut blocked) = (0, 0);
        for (ray, t_max) in &all {
            let b = BoxRay::new(ray.origin, ray.dir);
            let closest = |set: &Set<Sphere>, c: &mut Counters| {
                let (mut t, mut hit) = (*t_max, None);
                set.intersect_noting(ray, &b, &mut t, &mut hit, &clips, c, |_| {});
                (t.to_bits(), hit.map(|h| h.index))
            };
            let got = closest(&dense, &mut c);
            assert_eq!(got, closest(&plain, &mut c), "{ray:?} {t_max}");
            hits += usize::from(got.1.is_some());
            let any = |set: &Set<Sphere>, c: &mut Counters| {
                let mut n = 0;
                let a = set.any_prepared(ray, &b, *t_max, &clips, c, |_, k| {
                    n += k;
                    false
                });
                (a, n)
            };
            let got = any(&dense, &mut c);
            assert_eq!(got, any(&plain, &mut c), "{ray:?} {t_max}");
            blocked += usize::from(got.1 > 0);
        }
        let n = all.len();
        assert!(
            hits > n / 10 && blocked > n / 10,
            "{hits} hits, {blocked} blocked of {n}"
        );
    }

    #[test]
    fn opaque_queries_on_small_sets_match_the_tree() {
        let mut spheres = Set::default();
        for (k, (x, r)) in [(-1.0, 0.5), (0.0, 0.3), (1.2, 0.8), (0.5, 0.1)]
            .iter()
            .enumerate()
        {
            let center = Vec3::new(*x, 0.2 * k as f32, 2.0 + k as f32);
            spheres.push(Sphere { center, radius: *r }, k as u32);
        }
        spheres.build();
        let mut triangles = Set::default();
        let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        triangles.push(
            Triangle {
                v: [v(-1.0, -1.0, 2.0), v(1.0, -1.0, 2.5), v(0.0, 1.0, 3.0)],
                attr: 0,
            },
            0,
        );
        triangles.push(
            Triangle {
                v: [v(0.5, 0.5, 1.0), v(2.0, 0.5, 1.0), v(0.5, 2.0, 1.5)],
                attr: 0,
            },
            1,
        );
        triangles.build();
        // Some rays are blocked and some are not, so the comparison means something.
        let n = rays().len();
        for blocked in [same_as_tree(&spheres), same_as_tree(&triangles)] {
            assert!(blocked > n / 20 && blocked < n * 9 / 10, "{blocked} of {n}");
        }
        // Below the limit too: one sphere, and none.
        let one = spheres.filtered(|m| m == 2);
        assert_eq!((one.len(), one.data[0].radius), (1, 0.8));
        same_as_tree(&one);
        assert_eq!(same_as_tree(&spheres.filtered(|_| false)), 0);
    }
}
