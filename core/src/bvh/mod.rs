//! Bounding volume hierarchy: binned SAH build in parallel (rayon) into a binary tree, which
//! is then collapsed into 8-wide nodes (each holds its eight children's boxes side by side, so
//! one pass of vector arithmetic tests all eight: one AVX pass where the CPU has AVX, checked
//! at run time, else two SSE passes), and closure-based traversal so each primitive kind gets
//! its own monomorphised loop with the intersection test inlined.
//!
//! By concern: `build` (the binned SAH build of the binary tree), `wide` (8-wide nodes: the
//! collapse, their layout and words), `refit` (new bounds into a built tree, and its SAH cost),
//! `traversal` (closest- and any-hit loops), `top` (the top level of a two-level BVH: a BVH over
//! instances), `simd` (the box tests of a wide node and the choice
//! of AVX at run time) and `stack` (the traversal's stack and node fetches). All unsafe code of
//! the BVH is in `simd` and `stack`.

mod build;
mod refit;
// Intrinsics and the AVX dispatch.
#[allow(unsafe_code)]
mod simd;
// Unchecked stack and node accesses.
#[allow(unsafe_code)]
mod stack;
pub mod top;
mod traversal;
mod wide;

use crate::math::Aabb;
use build::{build_node, BuildPrim, LeafCost, PARALLEL_CUTOFF};
use wide::Wide;

pub use refit::REBUILD_RATIO;
pub use simd::BoxRay;

/// Leaves hold at most this many primitives.
const MAX_LEAF: usize = 8;
/// Past this depth splits are by median, so the depth stays bounded whatever the input.
const MAX_SAH_DEPTH: usize = 64;
/// Deepest binary tree: median splits after `MAX_SAH_DEPTH` halve at least 2^48 primitives.
const MAX_DEPTH: usize = MAX_SAH_DEPTH + 64;
/// Children per wide node.
const LANES: usize = 8;

// A link (in binary and wide nodes) packs an offset and a count in a u64: bits 0..48: a leaf's
// first primitive, or an inner node's index; bits 48..56: the primitive count (0 for inner
// nodes); bits 56..58: a binary node's split axis.
const OFFSET_BITS: u32 = 48;
const OFFSET_MASK: u64 = (1 << OFFSET_BITS) - 1;

#[inline(always)]
fn count_of(link: u64) -> usize {
    ((link >> OFFSET_BITS) & 0xff) as usize
}

#[inline(always)]
fn offset_of(link: u64) -> usize {
    (link & OFFSET_MASK) as usize
}

/// At most the bytes a build holds at once per primitive, for charging the memory budget
/// before building: its records, the binary tree, the wide nodes and the leaf order (at most
/// 196 per primitive in the tests, which check this bound), and the copy an owner makes to put
/// its primitives in leaf order (44 bytes for a triangle and its material).
pub const BUILD_BYTES_PER_PRIM: u64 = 256;

/// A BVH over primitives `0..n`. After building, primitive `order[i]` is the i-th in leaf order;
/// owners reorder their arrays by `order` so leaves address contiguous ranges.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// Wide nodes depth first: a node's inner children come after it; the root is first.
    nodes: Vec<Wide>,
}

/// Whether building over `n` primitives (or reordering them) is done on the calling thread:
/// below the size at which the build splits its work anyway. Then a small scene never starts
/// rayon's global pool, whose idle workers yield in a loop for a while after each job: on a
/// busy machine each yield lasts a time slice, so they spun through small renders (costing a
/// render thread its CPU).
pub fn serial(n: usize) -> bool {
    n <= PARALLEL_CUTOFF
}

impl Bvh {
    /// Builds over the given primitive bounds; returns the BVH and the leaf order.
    pub fn build(bounds: &[Aabb]) -> (Bvh, Vec<u64>) {
        Bvh::build_with(bounds.len(), |i| bounds[i])
    }

    /// Builds over primitives `0..n` whose bounds `bound(i)` gives (no array of bounds is kept
    /// alongside the build's own).
    pub fn build_with(n: usize, bound: impl Fn(usize) -> Aabb + Sync) -> (Bvh, Vec<u64>) {
        Bvh::build_blocks(n, LeafCost::PER_PRIM.block, bound)
    }

    /// [`Bvh::build_with`] for a kind whose leaves are tested `block` primitives at a time: the
    /// SAH prices a leaf by its blocks (a leaf of up to `block` costs one test), so leaves fill
    /// up and the tree is shallower. `block` 1 is `build_with`.
    pub fn build_blocks(
        n: usize,
        block: usize,
        bound: impl Fn(usize) -> Aabb + Sync,
    ) -> (Bvh, Vec<u64>) {
        use rayon::prelude::*;
        if n == 0 {
            return (Bvh::default(), Vec::new());
        }
        let prim = |i| BuildPrim::new(bound(i), i);
        // A small build stays on this thread: it never wakes (or starts) the thread pool,
        // whose idle workers would then spin beside the render (see `serial`).
        let mut prims: Vec<BuildPrim> = if serial(n) {
            (0..n).map(prim).collect()
        } else {
            (0..n)
                .into_par_iter()
                .with_min_len(PARALLEL_CUTOFF)
                .map(prim)
                .collect()
        };
        let mut binary = Vec::new();
        let cost = LeafCost {
            block: block.clamp(1, MAX_LEAF),
        };
        build_node(&mut prims, cost, 0, 0, &mut binary);
        let order = prims.iter().map(|p| p.index).collect();
        let bvh = Bvh::collapse(&binary, &|i| prims[i].bounds());
        (bvh, order)
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes of the nodes.
    pub fn memory_bytes(&self) -> u64 {
        (self.nodes.capacity() * std::mem::size_of::<Wide>()) as u64
    }

    /// Bytes of the nodes in use (the allocation may be larger: its untouched pages are not
    /// resident).
    pub fn used_bytes(&self) -> u64 {
        (self.nodes.len() * std::mem::size_of::<Wide>()) as u64
    }

    pub fn bounds(&self) -> Aabb {
        match self.nodes.first() {
            Some(n) => n.bounds(),
            None => Aabb::EMPTY,
        }
    }
}

/// Helpers for the tests of every part.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3A;

    impl Bvh {
        pub(super) fn leaf_sizes(&self) -> impl Iterator<Item = usize> + '_ {
            self.nodes
                .iter()
                .flat_map(|n| n.link)
                .filter(|&l| l != wide::EMPTY)
                .map(count_of)
                .filter(|&c| c > 0)
        }
    }

    /// The bytes a build holds at once (records, binary tree, wide nodes, collapse's depths and
    /// the leaf order) stay within `BUILD_BYTES_PER_PRIM` per primitive, for spread-out boxes,
    /// identical ones, and thin slivers along a line.
    #[test]
    fn a_build_holds_at_most_its_estimate_per_primitive() {
        let line = |n: usize| -> Vec<Aabb> {
            (0..n)
                .map(|i| {
                    let c = Vec3A::new(i as f32 * 0.01, 0.0, 0.0);
                    Aabb::new(c, c + Vec3A::new(0.001, 1.0, 1.0))
                })
                .collect()
        };
        let same = |n: usize| vec![Aabb::new(Vec3A::ZERO, Vec3A::ONE); n];
        for n in [1, 2, 7, 100, 5000, 40_000] {
            for bounds in [boxes(n), same(n), line(n)] {
                let mut prims: Vec<BuildPrim> =
                    (0..n).map(|i| BuildPrim::new(bounds[i], i)).collect();
                let mut binary = Vec::new();
                build_node(&mut prims, LeafCost::PER_PRIM, 0, 0, &mut binary);
                let wide = Bvh::collapse(&binary, &|i| prims[i].bounds());
                let peak = prims.capacity() * std::mem::size_of::<BuildPrim>()
                    + binary.capacity() * std::mem::size_of::<build::Node>()
                    + binary.len() * 2
                    + n * 8
                    + wide.memory_bytes() as usize;
                assert!(
                    peak as u64 <= n as u64 * BUILD_BYTES_PER_PRIM + 4096,
                    "{n} primitives: {peak} bytes"
                );
            }
        }
    }

    /// `n` deterministic pseudo-random unit boxes.
    pub(super) fn boxes(n: usize) -> Vec<Aabb> {
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
}
