//! The binary tree: a binned SAH build (sixteen bins per axis, all three axes weighed), in
//! parallel over subtrees and, for the largest nodes, over the binning itself; median splits
//! where the SAH finds none or the tree grows too deep.

use super::simd::clamped_index;
use super::{MAX_LEAF, MAX_SAH_DEPTH, OFFSET_BITS, OFFSET_MASK};
use crate::math::{Aabb, Vec3A};

const BINS: usize = 16;
/// Below this many primitives a subtree is built on the current thread.
pub(super) const PARALLEL_CUTOFF: usize = 4096;
/// SAH cost of a node traversal relative to one primitive test.
const TRAVERSAL_COST: f32 = 1.0;

/// How the SAH prices a leaf: by its primitives (`block` 1, every kind but triangles), or by
/// its blocks of `block` primitives, each priced as one test (a leaf of up to `block`
/// primitives costs as much as a leaf of one), so leaves fill up to a block.
#[derive(Clone, Copy, Debug)]
pub(super) struct LeafCost {
    pub(super) block: usize,
}

impl LeafCost {
    pub(super) const PER_PRIM: LeafCost = LeafCost { block: 1 };

    /// The cost of testing `n` primitives in one leaf, in primitive tests.
    #[inline(always)]
    fn of(self, n: usize) -> f32 {
        n.div_ceil(self.block) as f32
    }
}

/// A node of the binary build (and of the tree before it is collapsed).
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub(super) struct Node {
    min: [f32; 3],
    max: [f32; 3],
    /// Bits 0..48: leaf: first primitive; inner: index of the second child (the first follows
    /// this node). Bits 48..56: primitive count (0 for inner nodes). Bits 56..58: split axis.
    /// 64-bit indices in 32 bytes: 2^48 primitives is more than any machine holds.
    pub(super) link: u64,
}

impl Node {
    pub(super) fn new(bounds: &Aabb, offset: usize, count: usize, axis: usize) -> Node {
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
    pub(super) fn offset(&self) -> usize {
        (self.link & OFFSET_MASK) as usize
    }

    pub(super) fn set_offset(&mut self, offset: usize) {
        self.link = Node::pack(offset, self.count(), self.axis());
    }

    #[inline(always)]
    pub(super) fn count(&self) -> usize {
        ((self.link >> OFFSET_BITS) & 0xff) as usize
    }

    #[inline(always)]
    pub(super) fn axis(&self) -> usize {
        ((self.link >> 56) & 3) as usize
    }

    pub(super) fn bounds(&self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }
}

/// 32 bytes (a million-triangle build holds one per triangle): the centroid is recomputed
/// from the bounds where needed.
#[derive(Clone, Copy)]
pub(super) struct BuildPrim {
    min: [f32; 3],
    max: [f32; 3],
    pub(super) index: u64,
}

impl BuildPrim {
    pub(super) fn new(b: Aabb, index: usize) -> BuildPrim {
        BuildPrim {
            min: b.min.into(),
            max: b.max.into(),
            index: index as u64,
        }
    }

    #[inline(always)]
    pub(super) fn bounds(&self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }

    #[inline(always)]
    fn centroid(&self, axis: usize) -> f32 {
        (self.min[axis] + self.max[axis]) * 0.5
    }
}

/// Nodes with more primitives than this are summed up and binned on every thread (the top of
/// the tree would otherwise run on one).
const PARALLEL_BINNING: usize = 1 << 16;

/// The bounds of the primitives and of their centroids, in one pass.
fn summarize(prims: &[BuildPrim]) -> (Aabb, Aabb) {
    use rayon::prelude::*;
    let one = |prims: &[BuildPrim]| {
        prims.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), p| {
            let pb = p.bounds();
            (b.union(pb), c.grow(pb.centroid()))
        })
    };
    if prims.len() <= PARALLEL_BINNING {
        return one(prims);
    }
    prims.par_chunks(PARALLEL_BINNING / 4).map(one).reduce(
        || (Aabb::EMPTY, Aabb::EMPTY),
        |a, b| (a.0.union(b.0), a.1.union(b.1)),
    )
}

/// Primitive bounds and counts per centroid bin, for each axis (`K` bins at most).
type Bins<const K: usize> = ([[Aabb; K]; 3], [[usize; K]; 3]);

/// The bin of centroid `c` on each axis: `(c - lo) * scale` clamped to `[0, bins - 1]`. The
/// binning and the partition that follows it both call this, so they agree on every primitive.
#[inline(always)]
fn bin_of(c: Vec3A, lo: Vec3A, scale: Vec3A, bins: usize) -> [usize; 3] {
    // At most `BINS` bins, so `bins - 1` fits a u8.
    clamped_index((c - lo) * scale, (bins - 1) as u8)
}

/// Adds the primitives to `bins` by centroid ([`bin_of`]).
fn bin_into<const K: usize>(
    prims: &[BuildPrim],
    lo: Vec3A,
    scale: Vec3A,
    bins: usize,
    (bin_bounds, bin_count): &mut Bins<K>,
) {
    for p in prims {
        let b = p.bounds();
        for (a, i) in bin_of(b.centroid(), lo, scale, bins)
            .into_iter()
            .enumerate()
        {
            // bins <= K, so i < K.
            bin_bounds[a][i] = bin_bounds[a][i].union(b);
            bin_count[a][i] += 1;
        }
    }
}

/// [`bin_into`] for a large node, on every thread.
fn bin_parallel<const K: usize>(
    prims: &[BuildPrim],
    lo: Vec3A,
    scale: Vec3A,
    bins: usize,
) -> Bins<K> {
    use rayon::prelude::*;
    let empty = || ([[Aabb::EMPTY; K]; 3], [[0; K]; 3]);
    prims
        .par_chunks(PARALLEL_BINNING / 4)
        .map(|chunk| {
            let mut b = empty();
            bin_into(chunk, lo, scale, bins, &mut b);
            b
        })
        .reduce(empty, |mut a, b| {
            for k in 0..3 {
                for i in 0..K {
                    a.0[k][i] = a.0[k][i].union(b.0[k][i]);
                    a.1[k][i] += b.1[k][i];
                }
            }
            a
        })
}

/// The cheapest binned SAH split over the axes whose `scale` is not 0: (cost, bin, axis), bin 0
/// when there is none. `K` (at least `bins`) sizes the arrays: small nodes, most of the tree,
/// neither clear nor sweep sixteen bins.
fn best_split<const K: usize>(
    prims: &[BuildPrim],
    leaf_cost: LeafCost,
    lo: Vec3A,
    scale: Vec3A,
    bins: usize,
    axis: usize,
) -> (f32, usize, usize) {
    // Filled in place: returned, the arrays cost a copy per node.
    let mut binned = ([[Aabb::EMPTY; K]; 3], [[0; K]; 3]);
    if prims.len() <= PARALLEL_BINNING {
        bin_into(prims, lo, scale, bins, &mut binned);
    } else {
        binned = bin_parallel(prims, lo, scale, bins);
    }
    let (bin_bounds, bin_count) = &binned;
    let mut best = (f32::INFINITY, 0usize, axis);
    for a in 0..3 {
        if scale[a] == 0.0 {
            continue;
        }
        let (bin_bounds, bin_count) = (&bin_bounds[a], &bin_count[a]);
        let mut right_area = [0.0f32; K];
        let mut right_count = [0usize; K];
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in (1..bins).rev() {
            acc = acc.union(bin_bounds[i]);
            cnt += bin_count[i];
            right_area[i] = acc.half_area();
            right_count[i] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in 1..bins {
            acc = acc.union(bin_bounds[i - 1]);
            cnt += bin_count[i - 1];
            if cnt == 0 || right_count[i] == 0 {
                continue;
            }
            let cost =
                acc.half_area() * leaf_cost.of(cnt) + right_area[i] * leaf_cost.of(right_count[i]);
            if cost < best.0 {
                best = (cost, i, a);
            }
        }
    }
    best
}

/// Builds the subtree over `prims` (the primitives `start..start + prims.len()` of the final
/// order) depth-first into `out`: its root is the node pushed first, a node's first child
/// follows it.
pub(super) fn build_node(
    prims: &mut [BuildPrim],
    cost: LeafCost,
    start: usize,
    depth: usize,
    out: &mut Vec<Node>,
) {
    let (bounds, cb) = summarize(prims);
    let n = prims.len();
    // A leaf of one block is never dearer than a split (a traversal plus two blocks' worth).
    if n <= cost.block.max(2) {
        return leaf(out, bounds, start, n);
    }
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
        return split_middle(prims, cost, start, bounds, axis, n, depth, out);
    }

    // Bin centroids along every axis in one pass over the primitives, and sweep each for the
    // cheapest split.
    let lo = cb.min;
    // No more bins than primitives: small nodes, most of the tree, sweep fewer.
    let bins = BINS.min(n);
    let scale = extent.map(|e| {
        if e > 0.0 && e.is_finite() {
            bins as f32 / e
        } else {
            0.0
        }
    });
    let best = if n <= 4 {
        best_split::<4>(prims, cost, lo, scale, bins, axis)
    } else if n <= 8 {
        best_split::<8>(prims, cost, lo, scale, bins, axis)
    } else {
        best_split::<BINS>(prims, cost, lo, scale, bins, axis)
    };
    let axis = best.2;
    let leaf_cost = cost.of(n);
    let split_cost = TRAVERSAL_COST + best.0 / bounds.half_area().max(f32::MIN_POSITIVE);
    if best.1 == 0 || (n <= MAX_LEAF && leaf_cost <= split_cost) {
        if n <= MAX_LEAF {
            return leaf(out, bounds, start, n);
        }
        return split_middle(prims, cost, start, bounds, axis, n, depth, out);
    }
    let mid = partition(prims, |p| {
        bin_of(p.bounds().centroid(), lo, scale, bins)[axis] < best.1
    });
    if mid == 0 || mid == n {
        return split_middle(prims, cost, start, bounds, axis, n, depth, out);
    }
    children(prims, cost, start, bounds, axis, mid, depth, out)
}

#[allow(clippy::too_many_arguments)]
fn split_middle(
    prims: &mut [BuildPrim],
    cost: LeafCost,
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
    children(prims, cost, start, bounds, axis, mid, depth, out)
}

#[allow(clippy::too_many_arguments)]
fn children(
    prims: &mut [BuildPrim],
    cost: LeafCost,
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
            || build_node(left, cost, start, depth + 1, out),
            || build_node(right, cost, start + mid, depth + 1, &mut second),
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
        build_node(left, cost, start, depth + 1, out);
        let second = out.len();
        out[index].set_offset(second);
        build_node(right, cost, start + mid, depth + 1, out);
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
    use super::super::tests::boxes;
    use super::super::Bvh;
    use super::*;

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

    /// The SAH weighs every axis, not only the one the centroids spread widest along: two
    /// long thin rows of boxes, 100 apart in y and each 400 long in x, split between the rows.
    #[test]
    fn the_sah_splits_along_the_cheapest_axis() {
        let b: Vec<Aabb> = (0..400)
            .map(|i| {
                let c = Vec3A::new((i / 2) as f32 * 2.0, (i % 2) as f32 * 100.0, 0.0);
                Aabb::new(c - 0.5, c + 0.5)
            })
            .collect();
        let mut prims: Vec<BuildPrim> = (0..b.len()).map(|i| BuildPrim::new(b[i], i)).collect();
        let mut binary = Vec::new();
        build_node(&mut prims, LeafCost::PER_PRIM, 0, 0, &mut binary);
        assert_eq!(binary[0].axis(), 1, "the root splits across the rows");
        for child in [1, binary[0].offset()] {
            let b = binary[child].bounds();
            assert!(b.max.y - b.min.y <= 1.0, "one row per side: {b:?}");
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

    /// Leaves priced by blocks of four fill up: over the same boxes, fewer and fuller leaves
    /// than the per-primitive SAH makes, still every primitive once; a block of one is the
    /// per-primitive build itself.
    #[test]
    fn leaves_priced_by_blocks_fill_up() {
        let b = boxes(20_000);
        let (one, order_one) = Bvh::build(&b);
        let (same, order_same) = Bvh::build_blocks(b.len(), 1, |i| b[i]);
        assert_eq!(order_one, order_same);
        assert_eq!(one.node_count(), same.node_count());
        let (four, order_four) = Bvh::build_blocks(b.len(), 4, |i| b[i]);
        let mut seen = order_four.clone();
        seen.sort();
        assert_eq!(seen, (0..20_000).collect::<Vec<u64>>());
        assert!(four.leaf_sizes().all(|c| c <= MAX_LEAF));
        assert_eq!(four.leaf_sizes().sum::<usize>(), 20_000);
        let mean = |t: &Bvh| 20_000.0 / t.leaf_sizes().count() as f64;
        assert!(
            mean(&four) > 1.5 * mean(&one),
            "mean leaf {} against {}",
            mean(&four),
            mean(&one)
        );
        assert!(four.node_count() < one.node_count());
    }

    #[test]
    fn coincident_centroids_still_make_small_leaves() {
        let b = vec![Aabb::new(Vec3A::ZERO, Vec3A::ONE); 100];
        let (bvh, _) = Bvh::build(&b);
        assert!(bvh.leaf_sizes().all(|c| c <= MAX_LEAF));
        assert_eq!(bvh.leaf_sizes().sum::<usize>(), 100);
    }
}
