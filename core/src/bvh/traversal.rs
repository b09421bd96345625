//! Traversal: closest hit (children visited nearest first, pruned by the closest hit so far)
//! and any hit (stops at the first), each a loop generic over the primitive test, over the
//! instruction set of its box tests, and over the widest node of its tree.

use super::simd::{BoxRay, BASE};
use super::stack::{stack_space, stack_vec, Stack};
use super::wide::{Wide, WIDE16};
use super::{count_of, offset_of, Bvh, NARROW, WIDEST};
use crate::math::Vec3A;
use std::mem::MaybeUninit;

/// The lowest lane set in a non-empty hit mask of a `W`-wide node (the mask has a bit per
/// lane, so the `&` only spares the bounds check).
#[inline(always)]
fn first_lane<const W: usize>(mask: u32) -> usize {
    mask.trailing_zeros() as usize & (W - 1)
}

/// Whether a ray's coordinates are all finite. Others meet nothing: a NaN (from a zero-length
/// direction, say) or an infinity makes the box tests enter empty lanes too, whose link is the
/// root's, so their traversal would never end (and would overrun its stack). Checked in the
/// loops, after the check for an empty tree: inlined into every caller, it cost 30
/// instructions per ray (one check per primitive kind).
#[inline(always)]
fn finite(origin: Vec3A, dir: Vec3A) -> bool {
    // x - x is 0 for finite x and NaN for the others (three instructions fewer than glam's
    // `is_finite`, which masks the sign bits and compares with infinity).
    ((origin - origin) + (dir - dir)).cmpeq(Vec3A::ZERO).all()
}

impl Bvh {
    /// Closest-hit traversal. `test(prim, t_max)` returns `Some(t)` for a hit closer than
    /// `t_max` (and records whatever it needs). Returns the final `t_max`. A ray with a NaN or
    /// infinite coordinate meets nothing.
    // Only this dispatch is inlined; the loops (`intersect_avx`, `intersect_base`, ...) are
    // not, or their stacks would sit in every frame of the recursive integrator, and deep
    // reflections (max_depth in the hundreds) would overflow the thread's stack. The primitive
    // test is inlined into the loops.
    #[inline]
    pub fn intersect<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.intersect_dispatch(origin, dir, t_max, test)
    }

    #[inline(never)]
    pub(super) fn intersect_base<const MAXW: usize, F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest::<BASE, MAXW, F>(origin, dir, t_max, test, &mut stack_space())
    }

    /// For trees whose traversal needs more stack than the frame holds: the baseline loop
    /// (a deep tree is rare enough not to need its own AVX loops), with its stack on the heap.
    #[cold]
    #[inline(never)]
    pub(super) fn intersect_deep<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest::<BASE, WIDEST, F>(origin, dir, t_max, test, &mut stack_vec(self))
    }

    /// The closest-hit loop for trees of nodes up to `MAXW` wide, with the box tests of
    /// `LEVEL`, and its stack in `space`.
    #[inline(always)]
    pub(super) fn closest<const LEVEL: u8, const MAXW: usize, F>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        mut t_max: f32,
        mut test: F,
        space: &mut [MaybeUninit<(u64, f32)>],
    ) -> f32
    where
        F: FnMut(usize, f32) -> Option<f32>,
    {
        if self.nodes.is_empty() || !finite(origin, dir) {
            return t_max;
        }
        let ray = BoxRay::new(origin, dir);
        let mut stack = Stack::new(self, space);
        let mut link = self.root;
        loop {
            let next = if MAXW == WIDEST && link & WIDE16 != 0 {
                let node = self.node::<WIDEST>(offset_of(link));
                open::<LEVEL, WIDEST, F>(&ray, node, &mut t_max, &mut stack, &mut test)
            } else {
                let node = self.node::<NARROW>(offset_of(link));
                open::<LEVEL, NARROW, F>(&ray, node, &mut t_max, &mut stack, &mut test)
            };
            if let Some(next) = next {
                link = next;
                continue;
            }
            // Next: the nearest pending child still nearer than the closest hit; leaves are
            // tested as they come off the stack.
            loop {
                let Some((next, t)) = stack.pop() else {
                    return t_max;
                };
                if t > t_max {
                    continue;
                }
                let count = count_of(next);
                if count == 0 {
                    link = next;
                    break;
                }
                let start = offset_of(next);
                for p in start..start + count {
                    if let Some(t) = test(p, t_max) {
                        t_max = t;
                    }
                }
            }
        }
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
        self.any_dispatch(origin, dir, t_max, test)
    }

    #[inline(never)]
    pub(super) fn any_base<const MAXW: usize, F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        self.first::<BASE, MAXW, F>(origin, dir, t_max, test, &mut stack_space())
    }

    /// [`Bvh::intersect_deep`] for any-hit.
    #[cold]
    #[inline(never)]
    pub(super) fn any_deep<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        self.first::<BASE, WIDEST, F>(origin, dir, t_max, test, &mut stack_vec(self))
    }

    /// The any-hit loop for trees of nodes up to `MAXW` wide, with the box tests of `LEVEL`,
    /// and its stack in `space`.
    #[inline(always)]
    pub(super) fn first<const LEVEL: u8, const MAXW: usize, F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        mut test: F,
        space: &mut [MaybeUninit<u64>],
    ) -> bool {
        if self.nodes.is_empty() || !finite(origin, dir) {
            return false;
        }
        let ray = BoxRay::new(origin, dir);
        let mut stack = Stack::new(self, space);
        // The root (an inner node, or the wide node holding a lone leaf).
        let mut link = self.root;
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
                let next = if MAXW == WIDEST && link & WIDE16 != 0 {
                    let node = self.node::<WIDEST>(offset_of(link));
                    descend::<LEVEL, WIDEST>(&ray, node, t_max, &mut stack)
                } else {
                    let node = self.node::<NARROW>(offset_of(link));
                    descend::<LEVEL, NARROW>(&ray, node, t_max, &mut stack)
                };
                if let Some(next) = next {
                    link = next;
                    continue;
                }
            }
            match stack.pop() {
                Some(next) => link = next,
                None => return false,
            }
        }
    }
}

/// Closest-hit at an inner node: tests its boxes; one child hit is returned to be entered
/// next (an inner node) or tested at once (a leaf) without going through the stack; more are
/// pushed, nearest last so it is taken first.
#[inline(always)]
fn open<const LEVEL: u8, const W: usize, F: FnMut(usize, f32) -> Option<f32>>(
    ray: &BoxRay,
    node: &Wide<W>,
    t_max: &mut f32,
    stack: &mut Stack<'_, (u64, f32)>,
    test: &mut F,
) -> Option<u64> {
    let (mut mask, t) = ray.enter::<LEVEL, W>(node, *t_max);
    if mask.is_power_of_two() {
        let link = node.link[first_lane::<W>(mask)];
        let count = count_of(link);
        if count == 0 {
            return Some(link);
        }
        let start = offset_of(link);
        for p in start..start + count {
            if let Some(t) = test(p, *t_max) {
                *t_max = t;
            }
        }
    } else {
        let base = stack.len();
        while mask != 0 {
            let l = first_lane::<W>(mask);
            mask &= mask - 1;
            stack.insert_sorted(base, node.link[l], t[l]);
        }
    }
    None
}

/// Any-hit at an inner node: the last child hit is returned to be taken now, the others
/// pushed (so the order is the stack's, whatever the count). It is found by a loop of
/// branches, not by counting the mask's leading zeros: shadow rays of neighbouring pixels take
/// the same path, so the CPU predicts the lane and loads the next node before the box test has
/// finished (8 % faster shadow rays).
#[inline(always)]
fn descend<const LEVEL: u8, const W: usize>(
    ray: &BoxRay,
    node: &Wide<W>,
    t_max: f32,
    stack: &mut Stack<'_, u64>,
) -> Option<u64> {
    let (mut mask, _) = ray.enter::<LEVEL, W>(node, t_max);
    if mask == 0 {
        return None;
    }
    let mut last = W - 1;
    while mask & (1 << last) == 0 {
        last -= 1;
    }
    mask &= !(1 << last);
    while mask != 0 {
        stack.push(node.link[first_lane::<W>(mask)]);
        mask &= mask - 1;
    }
    Some(node.link[last & (W - 1)])
}

#[cfg(test)]
mod tests {
    use super::super::tests::{both, boxes};
    use super::*;
    use crate::math::Aabb;

    /// Rays parallel to box faces, lying exactly in a face's plane: 0 · ∞ in the slab test
    /// must not make the ray miss (or skip) the box, in any loop.
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
                let mut called = false;
                bvh.intersect(o, d, f32::INFINITY, |_, _| {
                    called = true;
                    None
                });
                assert!(called, "closest-hit skipped {b:?} for {o} {d}");
                assert!(
                    bvh.any(o, d, f32::INFINITY, |_| true),
                    "any-hit skipped {b:?}"
                );
                for (name, closest, any) in bvh.loops() {
                    let mut called = false;
                    closest(o, d, f32::INFINITY, &mut |_, _| {
                        called = true;
                        None
                    });
                    assert!(called, "{name} closest-hit skipped {b:?} for {o} {d}");
                    assert!(
                        any(o, d, f32::INFINITY, &mut |_| true),
                        "{name} any-hit skipped {b:?}"
                    );
                }
            }
            // Parallel, in neither face's plane and outside: culled.
            let o = Vec3A::new(-1.0, 2.0, 0.5);
            assert!(!bvh.any(o, Vec3A::X, f32::INFINITY, |_| true));
            for (name, _, any) in bvh.loops() {
                assert!(!any(o, Vec3A::X, f32::INFINITY, &mut |_| true), "{name}");
            }
        }
    }

    #[test]
    fn closest_hit_matches_brute_force() {
        let b = boxes(2000);
        let hit_box = |bx: &Aabb, o: Vec3A, d: Vec3A| -> Option<f32> {
            let inv = d.recip();
            let t0 = (bx.min - o) * inv;
            let t1 = (bx.max - o) * inv;
            let near = t0.min(t1).max_element().max(0.0);
            let far = t0.max(t1).min_element();
            (near <= far).then_some(near)
        };
        for (widest, bvh, order) in both(&b) {
            for k in 0..200 {
                let o = Vec3A::new(-10.0, k as f32 * 0.5, 50.0);
                let d = Vec3A::new(1.0, 0.01 * k as f32, -0.2).normalize();
                let brute = b
                    .iter()
                    .filter_map(|bx| hit_box(bx, o, d))
                    .fold(f32::INFINITY, f32::min);
                let mut test = |p: usize, tmax: f32| {
                    hit_box(&b[order[p] as usize], o, d).filter(|&t| t < tmax)
                };
                // The dispatched traversal and every loop this CPU runs.
                let t = bvh.intersect(o, d, f32::INFINITY, test);
                assert_eq!(t, brute, "{widest} ray {k}");
                for (name, closest, _) in bvh.loops() {
                    let t = closest(o, d, f32::INFINITY, &mut test);
                    assert_eq!(t, brute, "{widest} {name} ray {k}");
                }
            }
        }
    }

    /// The AVX-512, AVX and baseline traversals open the same boxes in the same order, rays
    /// parallel to the axes (NaN slab distances) included, in trees of either width.
    #[test]
    fn every_traversal_visits_the_same_leaves() {
        let b = boxes(5000);
        for (widest, bvh, _) in both(&b) {
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
                let (mut hits, mut leaves) = (Vec::new(), Vec::new());
                bvh.intersect(o, d, 1e3, |p, _| {
                    hits.push(p);
                    None
                });
                bvh.any(o, d, 1e3, |p| {
                    leaves.push(p);
                    false
                });
                tested += hits.len();
                for (name, closest, any) in bvh.loops() {
                    let (mut h, mut l) = (Vec::new(), Vec::new());
                    closest(o, d, 1e3, &mut |p, _| {
                        h.push(p);
                        None
                    });
                    any(o, d, 1e3, &mut |p| {
                        l.push(p);
                        false
                    });
                    assert_eq!(h, hits, "{widest} {name} closest, ray {k}");
                    assert_eq!(l, leaves, "{widest} {name} any, ray {k}");
                }
            }
            assert!(
                tested > 500,
                "{widest}: the rays should meet many boxes, met {tested}"
            );
        }
    }

    /// NaN or infinite coordinates (a zero-length direction normalised, a point at infinity)
    /// made the box tests enter every lane, empty ones included, whose link leads back to the
    /// root: the traversal never ended. Such rays meet nothing.
    #[test]
    fn rays_with_nan_or_infinite_coordinates_meet_nothing() {
        let b = boxes(5000);
        let (nan, inf) = (f32::NAN, f32::INFINITY);
        // Aimed at a box.
        let o = b[0].centroid() - Vec3A::new(200.0, 0.0, 0.0);
        for (widest, bvh, _) in both(&b) {
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
                    assert_eq!((t, tests), (t_max, 0), "{widest}: closest hit, {o} {d}");
                    assert!(
                        !bvh.any(o, d, t_max, |_| true),
                        "{widest}: any hit, {o} {d}"
                    );
                }
            }
            // The same tree meets a finite ray along that line.
            assert!(bvh.any(o, Vec3A::X, inf, |_| true), "{widest}");
        }
    }

    #[test]
    fn a_single_leaf_tree_is_traversed() {
        let b = boxes(3);
        let (bvh, _) = Bvh::build(&b);
        assert_eq!(bvh.node_counts(), (1, 0));
        let o = b[0].centroid() - Vec3A::new(0.0, 0.0, 10.0);
        assert!(bvh.any(o, Vec3A::Z, f32::INFINITY, |_| true));
    }
}
