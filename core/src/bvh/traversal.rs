//! Traversal: closest hit (children visited nearest first, pruned by the closest hit so far)
//! and any hit (stops at the first), each a loop generic over the primitive test. A tree of
//! one node (at most eight leaves: a kind with a few primitives) has loops of its own that
//! take the same steps without the deep loops' 14 KB stack; and a ray prepared once
//! ([`BoxRay`]) serves every tree it is traced through.

use super::simd::BoxRay;
use super::stack::{stack_space, Stack, STACK};
use super::{count_of, offset_of, Bvh, LANES};
use crate::math::Vec3A;

/// The lowest lane set in a non-empty hit mask (the mask has a bit per lane, so the `&` only
/// spares the bounds check).
#[inline(always)]
fn first_lane(mask: u32) -> usize {
    mask.trailing_zeros() as usize & (LANES - 1)
}

/// The highest lane set in a non-empty hit mask.
#[inline(always)]
fn last_lane(mask: u32) -> usize {
    (31 - mask.leading_zeros()) as usize & (LANES - 1)
}

impl Bvh {
    /// Closest-hit traversal. `test(prim, t_max)` returns `Some(t)` for a hit closer than
    /// `t_max` (and records whatever it needs). Returns the final `t_max`. A ray with a NaN or
    /// infinite coordinate meets nothing.
    #[inline]
    pub fn intersect<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.intersect_ray(&BoxRay::new(origin, dir), t_max, test)
    }

    /// [`Bvh::intersect`] for a ray prepared once for all the trees it meets.
    // Only this dispatch is inlined; the loops (`closest_avx`, `closest_base`...) are not, or
    // their 14 KB stack would sit in every frame of the recursive integrator, and deep
    // reflections (max_depth in the hundreds) would overflow the thread's stack. The primitive
    // test is inlined into the loops. The checks for an empty tree and a ray that is not
    // finite are made here, before any call.
    #[inline]
    pub fn intersect_ray<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        ray: &BoxRay,
        t_max: f32,
        test: F,
    ) -> f32 {
        if self.nodes.is_empty() || !ray.finite() {
            return t_max;
        }
        self.intersect_dispatch(ray, t_max, test)
    }

    /// The baseline loops (no AVX), dispatched as `intersect_ray` does (for the tests).
    #[cfg(test)]
    pub(super) fn intersect_base<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        let ray = BoxRay::new(origin, dir);
        if self.nodes.is_empty() || !ray.finite() {
            return t_max;
        }
        if self.is_flat() {
            self.closest_flat::<false, F>(&ray, t_max, test)
        } else {
            self.closest::<false, F>(&ray, t_max, test)
        }
    }

    /// A tree of one node: its links are all leaves (or empty).
    #[inline(always)]
    pub(super) fn is_flat(&self) -> bool {
        self.nodes.len() == 1
    }

    /// The closest-hit loop over a non-empty tree, for a finite ray.
    #[inline(always)]
    pub(super) fn closest<const AVX: bool, F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        ray: &BoxRay,
        mut t_max: f32,
        mut test: F,
    ) -> f32 {
        let slabs = ray.slabs();
        let mut space = stack_space::<(u64, f32), STACK>();
        let mut stack = Stack::new(&mut space);
        let mut i = 0usize;
        loop {
            let node = self.node(i);
            let (mut mask, t) = slabs.enter_with::<AVX>(node, t_max);
            if mask.is_power_of_two() {
                // One child hit: enter or test it without going through the stack.
                let link = node.link[first_lane(mask)];
                let count = count_of(link);
                if count == 0 {
                    i = offset_of(link);
                    continue;
                }
                let start = offset_of(link);
                for p in start..start + count {
                    if let Some(t) = test(p, t_max) {
                        t_max = t;
                    }
                }
            } else {
                // Push the children hit, nearest last so it is taken first.
                let base = stack.len();
                while mask != 0 {
                    let l = first_lane(mask);
                    mask &= mask - 1;
                    stack.insert_sorted(base, node.link[l], t[l]);
                }
            }
            // Next: the nearest pending child still nearer than the closest hit; leaves are
            // tested as they come off the stack.
            loop {
                let Some((link, t)) = stack.pop() else {
                    return t_max;
                };
                if t > t_max {
                    continue;
                }
                let count = count_of(link);
                if count == 0 {
                    i = offset_of(link);
                    break;
                }
                let start = offset_of(link);
                for p in start..start + count {
                    if let Some(t) = test(p, t_max) {
                        t_max = t;
                    }
                }
            }
        }
    }

    /// [`Bvh::closest`] on a tree of one node: the same box test, the same leaves in the same
    /// order (so the same hit on exact ties), with a stack of one entry per lane.
    #[inline(always)]
    pub(super) fn closest_flat<const AVX: bool, F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        ray: &BoxRay,
        mut t_max: f32,
        mut test: F,
    ) -> f32 {
        let slabs = ray.slabs();
        let node = self.node(0);
        let (mut mask, t) = slabs.enter_with::<AVX>(node, t_max);
        let mut leaf = |link: u64, t_max: &mut f32| {
            let start = offset_of(link);
            for p in start..start + count_of(link) {
                if let Some(t) = test(p, *t_max) {
                    *t_max = t;
                }
            }
        };
        if mask.is_power_of_two() {
            leaf(node.link[first_lane(mask)], &mut t_max);
            return t_max;
        }
        let mut space = stack_space::<(u64, f32), LANES>();
        let mut stack = Stack::new(&mut space);
        while mask != 0 {
            let l = first_lane(mask);
            mask &= mask - 1;
            stack.insert_sorted(0, node.link[l], t[l]);
        }
        while let Some((link, t)) = stack.pop() {
            if t > t_max {
                continue;
            }
            leaf(link, &mut t_max);
        }
        t_max
    }

    /// Any-hit traversal: stops as soon as `test(prim)` returns true. A ray with a NaN or
    /// infinite coordinate meets nothing.
    #[inline]
    pub fn any<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        self.any_ray(&BoxRay::new(origin, dir), t_max, test)
    }

    /// [`Bvh::any`] for a ray prepared once for all the trees it meets.
    #[inline]
    pub fn any_ray<F: FnMut(usize) -> bool>(&self, ray: &BoxRay, t_max: f32, test: F) -> bool {
        if self.nodes.is_empty() || !ray.finite() {
            return false;
        }
        self.any_dispatch(ray, t_max, test)
    }

    /// The baseline loops (no AVX), dispatched as `any_ray` does (for the tests).
    #[cfg(test)]
    pub(super) fn any_base<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        let ray = BoxRay::new(origin, dir);
        if self.nodes.is_empty() || !ray.finite() {
            return false;
        }
        if self.is_flat() {
            self.first_flat::<false, F>(&ray, t_max, test)
        } else {
            self.first::<false, F>(&ray, t_max, test)
        }
    }

    /// The any-hit loop over a non-empty tree, for a finite ray.
    #[inline(always)]
    pub(super) fn first<const AVX: bool, F: FnMut(usize) -> bool>(
        &self,
        ray: &BoxRay,
        t_max: f32,
        mut test: F,
    ) -> bool {
        let slabs = ray.slabs();
        let mut space = stack_space::<u64, STACK>();
        let mut stack = Stack::new(&mut space);
        // The root (an inner node, or the wide node holding a lone leaf).
        let mut link = 0u64;
        loop {
            let count = count_of(link);
            if count > 0 {
                let start = offset_of(link);
                for p in start..start + count {
                    if test(p) {
                        return true;
                    }
                }
            } else {
                let node = self.node(offset_of(link));
                let (mut mask, _) = slabs.enter_with::<AVX>(node, t_max);
                if mask != 0 {
                    // The last child hit is taken now, the others pushed (so the order is
                    // the stack's, whatever the count). It is found by a loop of branches,
                    // not by counting the mask's leading zeros: shadow rays of neighbouring
                    // pixels take the same path, so the CPU predicts the lane and loads the
                    // next node before the box test has finished (8 % faster shadow rays).
                    let mut last = LANES - 1;
                    while mask & (1 << last) == 0 {
                        last -= 1;
                    }
                    mask &= !(1 << last);
                    while mask != 0 {
                        stack.push(node.link[first_lane(mask)]);
                        mask &= mask - 1;
                    }
                    link = node.link[last & (LANES - 1)];
                    continue;
                }
            }
            match stack.pop() {
                Some(next) => link = next,
                None => return false,
            }
        }
    }

    /// [`Bvh::first`] on a tree of one node: its leaves hit, from the last lane to the first
    /// (the order `first` takes them in: the last now, the others off the stack), no stack.
    #[inline(always)]
    pub(super) fn first_flat<const AVX: bool, F: FnMut(usize) -> bool>(
        &self,
        ray: &BoxRay,
        t_max: f32,
        mut test: F,
    ) -> bool {
        let slabs = ray.slabs();
        let node = self.node(0);
        let (mut mask, _) = slabs.enter_with::<AVX>(node, t_max);
        while mask != 0 {
            let l = last_lane(mask);
            mask &= !(1 << l);
            let link = node.link[l];
            let start = offset_of(link);
            for p in start..start + count_of(link) {
                if test(p) {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::boxes;
    use super::*;
    use crate::math::Aabb;

    /// Rays parallel to box faces, lying exactly in a face's plane: 0 · ∞ in the slab test
    /// must not make the ray miss (or skip) the box.
    #[test]
    fn rays_in_the_plane_of_a_face_enter_the_box() {
        let unit = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        let flat = Aabb::new(Vec3A::new(0.0, 0.0, 0.0), Vec3A::new(1.0, 0.0, 1.0));
        for b in [unit, flat] {
            let (bvh, _) = Bvh::build(&[b]);
            for (o, d) in [
                ([-1.0, 0.0, 0.5], [1.0, 0.0, 0.0]),
                ([-1.0, 0.0, 0.5], [1.0, -0.0, 0.0]),
                ([2.0, 0.0, 0.5], [-1.0, -0.0, 0.0]),
                ([-1.0, 0.0, 0.0], [1.0, 0.0, -0.0]),
                ([0.5, 0.0, -1.0], [0.0, 0.0, 1.0]),
                ([0.5, 0.0, -1.0], [-0.0, -0.0, 1.0]),
            ] {
                let (o, d) = (Vec3A::from(o), Vec3A::from(d));
                for base in [false, true] {
                    let mut called = false;
                    let test = |_, _| {
                        called = true;
                        None
                    };
                    if base {
                        bvh.intersect_base(o, d, f32::INFINITY, test);
                    } else {
                        bvh.intersect(o, d, f32::INFINITY, test);
                    }
                    assert!(called, "closest-hit skipped {b:?} for {o} {d}");
                }
                assert!(
                    bvh.any(o, d, f32::INFINITY, |_| true),
                    "any-hit skipped {b:?}"
                );
                assert!(
                    bvh.any_base(o, d, f32::INFINITY, |_| true),
                    "baseline any-hit skipped {b:?}"
                );
            }
            // Parallel, in neither face's plane and outside: culled.
            let o = Vec3A::new(-1.0, 2.0, 0.5);
            assert!(!bvh.any(o, Vec3A::X, f32::INFINITY, |_| true));
            assert!(!bvh.any_base(o, Vec3A::X, f32::INFINITY, |_| true));
        }
    }

    #[test]
    fn closest_hit_matches_brute_force() {
        let b = boxes(2000);
        let (bvh, order) = Bvh::build(&b);
        let hit_box = |bx: &Aabb, o: Vec3A, d: Vec3A| -> Option<f32> {
            let inv = d.recip();
            let t0 = (bx.min - o) * inv;
            let t1 = (bx.max - o) * inv;
            let near = t0.min(t1).max_element().max(0.0);
            let far = t0.max(t1).min_element();
            (near <= far).then_some(near)
        };
        for k in 0..200 {
            let o = Vec3A::new(-10.0, k as f32 * 0.5, 50.0);
            let d = Vec3A::new(1.0, 0.01 * k as f32, -0.2).normalize();
            let brute = b
                .iter()
                .filter_map(|bx| hit_box(bx, o, d))
                .fold(f32::INFINITY, f32::min);
            let test =
                |p: usize, tmax: f32| hit_box(&b[order[p] as usize], o, d).filter(|&t| t < tmax);
            // The dispatched traversal (AVX where the CPU has it) and the baseline one.
            assert_eq!(bvh.intersect(o, d, f32::INFINITY, test), brute, "ray {k}");
            assert_eq!(
                bvh.intersect_base(o, d, f32::INFINITY, test),
                brute,
                "ray {k}"
            );
        }
    }

    /// The AVX and baseline traversals open the same boxes in the same order, rays parallel to
    /// the axes (NaN slab distances) included.
    #[test]
    fn every_traversal_visits_the_same_leaves() {
        let b = boxes(5000);
        let (bvh, _) = Bvh::build(&b);
        let mut seed = 7u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        let mut tested = 0;
        for k in 0..500 {
            let o = Vec3A::new(next(), next(), next()) * 120.0 - 10.0;
            let mut d = Vec3A::new(next(), next(), next()) - 0.5;
            // Every third ray lies parallel to one or two axes.
            if k % 3 == 0 {
                d[k % 2] = 0.0;
                d[2 - k % 2] *= (k % 4) as f32;
            }
            let d = d.normalize_or(Vec3A::Z);
            let visits = |base: bool| {
                let mut seen = Vec::new();
                let test = |p: usize, _| {
                    seen.push(p);
                    None
                };
                if base {
                    bvh.intersect_base(o, d, 1e3, test);
                } else {
                    bvh.intersect(o, d, 1e3, test);
                }
                seen
            };
            let v = visits(false);
            assert_eq!(v, visits(true), "ray {k}");
            tested += v.len();
            let leaves = |base: bool| {
                let mut seen = Vec::new();
                let test = |p: usize| {
                    seen.push(p);
                    false
                };
                if base {
                    bvh.any_base(o, d, 1e3, test);
                } else {
                    bvh.any(o, d, 1e3, test);
                }
                seen
            };
            assert_eq!(leaves(false), leaves(true), "ray {k}");
        }
        assert!(
            tested > 500,
            "the rays should meet many boxes, met {tested}"
        );
    }

    /// NaN or infinite coordinates (a zero-length direction normalised, a point at infinity)
    /// made the box tests enter every lane, empty ones included, whose link leads back to the
    /// root: the traversal never ended. Such rays meet nothing.
    #[test]
    fn rays_with_nan_or_infinite_coordinates_meet_nothing() {
        let b = boxes(5000);
        let (bvh, _) = Bvh::build(&b);
        let (nan, inf) = (f32::NAN, f32::INFINITY);
        // Aimed at a box.
        let o = b[0].centroid() - Vec3A::new(200.0, 0.0, 0.0);
        for (o, d) in [
            (Vec3A::splat(nan), Vec3A::X),
            (o, Vec3A::ZERO / 0.0),
            (o, Vec3A::new(1.0, nan, 0.0)),
            (Vec3A::splat(inf), -Vec3A::ONE.normalize()),
            (Vec3A::new(-inf, o.y, o.z), Vec3A::X),
        ] {
            for t_max in [1e3, inf] {
                let mut tests = 0;
                let t = bvh.intersect(o, d, t_max, |_, _| {
                    tests += 1;
                    None
                });
                assert_eq!((t, tests), (t_max, 0), "closest hit, {o} {d}");
                assert!(!bvh.any(o, d, t_max, |_| true), "any hit, {o} {d}");
            }
        }
        // The same tree meets a finite ray along that line.
        assert!(bvh.any(o, Vec3A::X, inf, |_| true));
    }

    /// Trees of one node (a kind with a few primitives) have loops of their own: they test
    /// the same leaves in the same order as the deep loops (the same closest hit on exact
    /// ties, the same order of shadow filters), AVX and baseline alike, rays parallel to the
    /// axes included.
    #[test]
    fn one_node_trees_visit_what_the_deep_loops_visit() {
        let mut seed = 11u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        let (mut flat_trees, mut visits) = (0, 0);
        for n in 1..=64 {
            // Boxes packed close together, so rays meet several at once, some identical (ties).
            let b: Vec<_> = boxes(n)
                .iter()
                .enumerate()
                .map(|(i, bx)| {
                    let c = if i % 5 == 4 {
                        Vec3A::splat(5.0)
                    } else {
                        bx.centroid() * 0.1
                    };
                    Aabb::new(c - 1.0, c + 1.0)
                })
                .collect();
            let (bvh, _) = Bvh::build(&b);
            if !bvh.is_flat() {
                continue;
            }
            flat_trees += 1;
            for k in 0..200 {
                // From around the boxes toward a point among them.
                let o = Vec3A::new(next(), next(), next()) * 30.0 - 10.0;
                let mut d = Vec3A::new(next(), next(), next()) * 10.0 - o;
                if k % 3 == 0 {
                    d[k % 2] = 0.0;
                }
                let d = d.normalize_or(Vec3A::Z);
                let ray = BoxRay::new(o, d);
                // Closest hit: each test "hits" at a distance that makes some ties.
                let closest = |avx: bool, flat: bool| {
                    let mut seen = Vec::new();
                    let test = |p: usize, tm: f32| {
                        seen.push(p);
                        let t = (p % 3) as f32 + 2.0;
                        (t < tm).then_some(t)
                    };
                    let t = match (avx, flat) {
                        (false, true) => bvh.closest_flat::<false, _>(&ray, 1e3, test),
                        (false, false) => bvh.closest::<false, _>(&ray, 1e3, test),
                        // The dispatched loop (AVX where the CPU has it).
                        (true, _) => bvh.intersect_ray(&ray, 1e3, test),
                    };
                    (t, seen)
                };
                let deep = closest(false, false);
                visits += deep.1.len();
                assert_eq!(closest(false, true), deep, "{n} boxes, ray {k}");
                assert_eq!(closest(true, true), deep, "{n} boxes, ray {k}");
                let any = |avx: bool, flat: bool, stop: usize| {
                    let mut seen = Vec::new();
                    let test = |p: usize| {
                        seen.push(p);
                        seen.len() == stop
                    };
                    let r = match (avx, flat) {
                        (false, true) => bvh.first_flat::<false, _>(&ray, 1e3, test),
                        (false, false) => bvh.first::<false, _>(&ray, 1e3, test),
                        (true, _) => bvh.any_ray(&ray, 1e3, test),
                    };
                    (r, seen)
                };
                for stop in [0, 2] {
                    let deep = any(false, false, stop);
                    assert_eq!(any(false, true, stop), deep, "{n} boxes, ray {k}");
                    assert_eq!(any(true, true, stop), deep, "{n} boxes, ray {k}");
                }
            }
        }
        assert!(flat_trees >= 8, "only {flat_trees} one-node trees");
        assert!(
            visits > 500,
            "the rays should meet many boxes, met {visits}"
        );
    }

    #[test]
    fn a_single_leaf_tree_is_traversed() {
        let b = boxes(3);
        let (bvh, _) = Bvh::build(&b);
        assert_eq!(bvh.nodes.len(), 1);
        let o = b[0].centroid() - Vec3A::new(0.0, 0.0, 10.0);
        assert!(bvh.any(o, Vec3A::Z, f32::INFINITY, |_| true));
    }
}
