//! Bounding volume hierarchy: binned SAH build in parallel (rayon), flattened depth-first into
//! 32-byte nodes, and closure-based traversal so each primitive kind gets its own monomorphised
//! loop with the intersection test inlined.

use crate::math::{gamma, Aabb, Vec3A};

/// Leaves hold at most this many primitives.
const MAX_LEAF: usize = 8;
const BINS: usize = 16;
/// Below this many primitives a subtree is built on the current thread.
const PARALLEL_CUTOFF: usize = 4096;
/// SAH cost of a node traversal relative to one primitive test.
const TRAVERSAL_COST: f32 = 1.0;
/// Past this depth splits are by median, so the depth stays below `STACK` whatever the input.
const MAX_SAH_DEPTH: usize = 64;
const STACK: usize = MAX_SAH_DEPTH + 64;

#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Node {
    min: [f32; 3],
    max: [f32; 3],
    /// Bits 0..48: leaf: first primitive; inner: index of the second child (the first follows
    /// this node). Bits 48..56: primitive count (0 for inner nodes). Bits 56..58: split axis.
    /// 64-bit indices in 32 bytes: 2^48 primitives is more than any machine holds.
    link: u64,
}

const OFFSET_BITS: u32 = 48;
const OFFSET_MASK: u64 = (1 << OFFSET_BITS) - 1;

impl Node {
    fn new(bounds: &Aabb, offset: usize, count: usize, axis: usize) -> Node {
        Node {
            min: bounds.min.into(),
            max: bounds.max.into(),
            link: Node::pack(offset, count, axis),
        }
    }

    fn pack(offset: usize, count: usize, axis: usize) -> u64 {
        debug_assert!((offset as u64) <= OFFSET_MASK && count <= MAX_LEAF && axis < 3);
        offset as u64 | (count as u64) << OFFSET_BITS | (axis as u64) << 56
    }

    #[inline(always)]
    fn offset(&self) -> usize {
        (self.link & OFFSET_MASK) as usize
    }

    fn set_offset(&mut self, offset: usize) {
        self.link = Node::pack(offset, self.count(), self.axis());
    }

    #[inline(always)]
    fn count(&self) -> usize {
        ((self.link >> OFFSET_BITS) & 0xff) as usize
    }

    #[inline(always)]
    fn axis(&self) -> usize {
        ((self.link >> 56) & 3) as usize
    }
}

/// A BVH over primitives `0..n`. After building, primitive `order[i]` is the i-th in leaf order;
/// owners reorder their arrays by `order` so leaves address contiguous ranges.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
}

/// 32 bytes (a million-triangle build holds one per triangle): the centroid is recomputed
/// from the bounds where needed.
#[derive(Clone, Copy)]
struct BuildPrim {
    min: [f32; 3],
    max: [f32; 3],
    index: u64,
}

impl BuildPrim {
    #[inline(always)]
    fn bounds(&self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }

    #[inline(always)]
    fn centroid(&self, axis: usize) -> f32 {
        (self.min[axis] + self.max[axis]) * 0.5
    }

    #[inline(always)]
    fn center(&self) -> Vec3A {
        self.bounds().centroid()
    }
}

impl Bvh {
    /// Builds over the given primitive bounds; returns the BVH and the leaf order.
    pub fn build(bounds: &[Aabb]) -> (Bvh, Vec<u64>) {
        Bvh::build_with(bounds.len(), |i| bounds[i])
    }

    /// Builds over primitives `0..n` whose bounds `bound(i)` gives (no array of bounds is kept
    /// alongside the build's own).
    pub fn build_with(n: usize, bound: impl Fn(usize) -> Aabb + Sync) -> (Bvh, Vec<u64>) {
        use rayon::prelude::*;
        if n == 0 {
            return (Bvh::default(), Vec::new());
        }
        let mut prims: Vec<BuildPrim> = (0..n)
            .into_par_iter()
            .with_min_len(PARALLEL_CUTOFF)
            .map(|i| {
                let b = bound(i);
                BuildPrim {
                    min: b.min.into(),
                    max: b.max.into(),
                    index: i as u64,
                }
            })
            .collect();
        let mut nodes = Vec::new();
        build_node(&mut prims, 0, 0, &mut nodes);
        nodes.shrink_to_fit();
        let order = prims.iter().map(|p| p.index).collect();
        (Bvh { nodes }, order)
    }

    /// The nodes as little-endian-ready words, 8 per node (for the geometry cache).
    pub(crate) fn to_words(&self, out: &mut impl FnMut(u32)) {
        for n in &self.nodes {
            n.min.iter().for_each(|x| out(x.to_bits()));
            out(n.link as u32);
            n.max.iter().for_each(|x| out(x.to_bits()));
            out((n.link >> 32) as u32);
        }
    }

    /// Nodes read back from `to_words`, checked against `prims` primitives: every link and
    /// leaf range in bounds, links pointing forward (so traversal ends), axes valid.
    pub(crate) fn from_words(w: &[u32], prims: usize) -> Option<Bvh> {
        if !w.len().is_multiple_of(8) || (w.is_empty() != (prims == 0)) {
            return None;
        }
        let n = w.len() / 8;
        let mut nodes = Vec::with_capacity(n);
        // Depth of every node, so that traversal's fixed stack suffices.
        let mut depth = vec![0u16; n];
        for (i, c) in w.chunks_exact(8).enumerate() {
            let f = |k: usize| f32::from_bits(c[k]);
            let node = Node {
                min: [f(0), f(1), f(2)],
                max: [f(4), f(5), f(6)],
                link: u64::from(c[3]) | u64::from(c[7]) << 32,
            };
            let (count, axis, offset) = (node.count(), node.axis(), node.offset());
            let ok = node.link >> 58 == 0
                && if count > 0 {
                    count <= MAX_LEAF && offset + count <= prims
                } else {
                    axis < 3 && offset > i + 1 && offset < n && i + 1 < n
                };
            if !ok || depth[i] as usize >= STACK - 1 {
                return None;
            }
            if count == 0 {
                depth[i + 1] = depth[i] + 1;
                depth[offset] = depth[i] + 1;
            }
            nodes.push(node);
        }
        Some(Bvh { nodes })
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn bounds(&self) -> Aabb {
        match self.nodes.first() {
            Some(n) => Aabb::new(n.min.into(), n.max.into()),
            None => Aabb::EMPTY,
        }
    }

    /// Closest-hit traversal. `test(prim, t_max)` returns `Some(t)` for a hit closer than
    /// `t_max` (and records whatever it needs). Returns the final `t_max`.
    #[inline]
    pub fn intersect<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        mut t_max: f32,
        mut test: F,
    ) -> f32 {
        if self.nodes.is_empty() {
            return t_max;
        }
        let inv = dir.recip();
        let neg = [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0];
        let mut stack = [0usize; STACK];
        let mut sp = 0usize;
        let mut i = 0usize;
        loop {
            let node = &self.nodes[i];
            if slab(node, origin, inv, t_max) {
                let count = node.count();
                if count > 0 {
                    let start = node.offset();
                    for p in start..start + count {
                        if let Some(t) = test(p, t_max) {
                            t_max = t;
                        }
                    }
                } else {
                    // Near child first.
                    let (first, second) = if neg[node.axis()] {
                        (node.offset(), i + 1)
                    } else {
                        (i + 1, node.offset())
                    };
                    stack[sp] = second;
                    sp += 1;
                    i = first;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            i = stack[sp];
        }
        t_max
    }

    /// Any-hit traversal: stops as soon as `test(prim)` returns true.
    #[inline]
    pub fn any<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        mut test: F,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv = dir.recip();
        let mut stack = [0usize; STACK];
        let mut sp = 0usize;
        let mut i = 0usize;
        loop {
            let node = &self.nodes[i];
            if slab(node, origin, inv, t_max) {
                let count = node.count();
                if count > 0 {
                    let start = node.offset();
                    for p in start..start + count {
                        if test(p) {
                            return true;
                        }
                    }
                } else {
                    stack[sp] = node.offset();
                    sp += 1;
                    i += 1;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            i = stack[sp];
        }
    }
}

/// Ray/box slab test; `t_max` is widened by 2·gamma(3) so rounding never culls a box the ray
/// really touches (Ize 2013). Zero direction components give ±inf reciprocals, which work,
/// except when the origin lies exactly in a face plane on that axis: 0 · ∞ is NaN there, and
/// the ray, parallel to the face and in its plane, is inside that slab for every t.
#[inline(always)]
fn slab(node: &Node, origin: Vec3A, inv: Vec3A, t_max: f32) -> bool {
    let t0 = (Vec3A::from(node.min) - origin) * inv;
    let t1 = (Vec3A::from(node.max) - origin) * inv;
    let defined = t0.cmpeq(t0) & t1.cmpeq(t1);
    let lo = Vec3A::select(defined, t0.min(t1), Vec3A::NEG_INFINITY);
    let hi = Vec3A::select(defined, t0.max(t1), Vec3A::INFINITY);
    let near = lo.max_element().max(0.0);
    let far = hi.min_element().min(t_max) * (1.0 + 2.0 * gamma(3));
    near <= far
}

/// Builds the subtree over `prims` (the primitives `start..start + prims.len()` of the final
/// order) depth-first into `out`: its root is the node pushed first, a node's first child
/// follows it.
fn build_node(prims: &mut [BuildPrim], start: usize, depth: usize, out: &mut Vec<Node>) {
    let bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds()));
    let n = prims.len();
    if n <= 2 {
        return leaf(out, bounds, start, n);
    }
    let cb = prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.center()));
    let extent = cb.max - cb.min;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    if extent[axis] <= 0.0 || !extent[axis].is_finite() || depth >= MAX_SAH_DEPTH {
        // All centroids coincide (or the tree is already deep): split by count.
        return split_middle(prims, start, bounds, axis, n, depth, out);
    }

    // Bin centroids along the widest axis and sweep for the cheapest split.
    let scale = BINS as f32 / extent[axis];
    let lo = cb.min[axis];
    let bin_of = |c: f32| (((c - lo) * scale) as usize).min(BINS - 1);
    let mut bin_bounds = [Aabb::EMPTY; BINS];
    let mut bin_count = [0usize; BINS];
    for p in prims.iter() {
        let b = bin_of(p.centroid(axis));
        bin_bounds[b] = bin_bounds[b].union(p.bounds());
        bin_count[b] += 1;
    }
    let mut right_area = [0.0f32; BINS];
    let mut right_count = [0usize; BINS];
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    for i in (1..BINS).rev() {
        acc = acc.union(bin_bounds[i]);
        cnt += bin_count[i];
        right_area[i] = acc.half_area();
        right_count[i] = cnt;
    }
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    let mut best = (f32::INFINITY, 0usize);
    for i in 1..BINS {
        acc = acc.union(bin_bounds[i - 1]);
        cnt += bin_count[i - 1];
        if cnt == 0 || right_count[i] == 0 {
            continue;
        }
        let cost = acc.half_area() * cnt as f32 + right_area[i] * right_count[i] as f32;
        if cost < best.0 {
            best = (cost, i);
        }
    }
    let leaf_cost = n as f32;
    let split_cost = TRAVERSAL_COST + best.0 / bounds.half_area().max(f32::MIN_POSITIVE);
    if best.1 == 0 || (n <= MAX_LEAF && leaf_cost <= split_cost) {
        if n <= MAX_LEAF {
            return leaf(out, bounds, start, n);
        }
        return split_middle(prims, start, bounds, axis, n, depth, out);
    }
    let mid = partition(prims, |p| bin_of(p.centroid(axis)) < best.1);
    if mid == 0 || mid == n {
        return split_middle(prims, start, bounds, axis, n, depth, out);
    }
    children(prims, start, bounds, axis, mid, depth, out)
}

fn split_middle(
    prims: &mut [BuildPrim],
    start: usize,
    bounds: Aabb,
    axis: usize,
    n: usize,
    depth: usize,
    out: &mut Vec<Node>,
) {
    if n <= MAX_LEAF {
        return leaf(out, bounds, start, n);
    }
    let mid = n / 2;
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid(axis)
            .total_cmp(&b.centroid(axis))
            .then(a.index.cmp(&b.index))
    });
    children(prims, start, bounds, axis, mid, depth, out)
}

fn children(
    prims: &mut [BuildPrim],
    start: usize,
    bounds: Aabb,
    axis: usize,
    mid: usize,
    depth: usize,
    out: &mut Vec<Node>,
) {
    let n = prims.len();
    let index = out.len();
    out.push(Node::new(&bounds, 0, 0, axis));
    let (left, right) = prims.split_at_mut(mid);
    if n > PARALLEL_CUTOFF {
        // The second child builds into its own array, appended with its child links shifted.
        let mut second = Vec::new();
        rayon::join(
            || build_node(left, start, depth + 1, out),
            || build_node(right, start + mid, depth + 1, &mut second),
        );
        let base = out.len();
        out[index].set_offset(base);
        out.extend(second.into_iter().map(|mut node| {
            if node.count() == 0 {
                node.set_offset(node.offset() + base);
            }
            node
        }));
    } else {
        build_node(left, start, depth + 1, out);
        let second = out.len();
        out[index].set_offset(second);
        build_node(right, start + mid, depth + 1, out);
    }
}

fn leaf(out: &mut Vec<Node>, bounds: Aabb, start: usize, count: usize) {
    out.push(Node::new(&bounds, start, count, 0));
}

/// Stable-enough in-place partition (order within each side does not matter, but it must be
/// deterministic, which this is).
fn partition(prims: &mut [BuildPrim], pred: impl Fn(&BuildPrim) -> bool) -> usize {
    let mut i = 0;
    for j in 0..prims.len() {
        if pred(&prims[j]) {
            prims.swap(i, j);
            i += 1;
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxes(n: usize) -> Vec<Aabb> {
        // Deterministic pseudo-random unit boxes.
        let mut s = 12345u32;
        let mut r = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1u32 << 24) as f32 * 100.0
        };
        (0..n)
            .map(|_| {
                let c = Vec3A::new(r(), r(), r());
                Aabb::new(c - 0.5, c + 0.5)
            })
            .collect()
    }

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
            }
            // Parallel, in neither face's plane and outside: culled.
            let o = Vec3A::new(-1.0, 2.0, 0.5);
            assert!(!bvh.any(o, Vec3A::X, f32::INFINITY, |_| true));
        }
    }

    #[test]
    fn nodes_hold_64_bit_offsets_in_32_bytes() {
        assert_eq!(std::mem::size_of::<Node>(), 32);
        let b = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        // Past u32: a leaf 5 * 2^32 primitives in, and an inner node's second child.
        let leaf = Node::new(&b, 5 << 32 | 7, MAX_LEAF, 0);
        assert_eq!((leaf.offset(), leaf.count()), (5 << 32 | 7, MAX_LEAF));
        let mut inner = Node::new(&b, 3, 0, 2);
        inner.set_offset((1 << 47) + 3);
        assert_eq!(
            (inner.offset(), inner.count(), inner.axis()),
            ((1 << 47) + 3, 0, 2)
        );
    }

    #[test]
    fn every_primitive_is_in_exactly_one_leaf() {
        let b = boxes(10_000);
        let (bvh, order) = Bvh::build(&b);
        let mut seen = order.clone();
        seen.sort();
        assert_eq!(seen, (0..10_000).collect::<Vec<u64>>());
        let leaf_total: usize = bvh.nodes.iter().map(|n| n.count()).sum();
        assert_eq!(leaf_total, 10_000);
        assert!(bvh.nodes.iter().all(|n| n.count() <= MAX_LEAF));
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
            let got = bvh.intersect(o, d, f32::INFINITY, |p, tmax| {
                hit_box(&b[order[p] as usize], o, d).filter(|&t| t < tmax)
            });
            assert_eq!(got, brute, "ray {k}");
        }
    }

    #[test]
    fn build_is_deterministic_across_thread_counts() {
        let b = boxes(50_000);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let (_, o1) = one.install(|| Bvh::build(&b));
        let (_, o2) = two.install(|| Bvh::build(&b));
        assert_eq!(o1, o2);
    }

    #[test]
    fn coincident_centroids_still_make_small_leaves() {
        let b = vec![Aabb::new(Vec3A::ZERO, Vec3A::ONE); 100];
        let (bvh, _) = Bvh::build(&b);
        assert!(bvh.nodes.iter().all(|n| n.count() <= MAX_LEAF));
    }
}
