//! Bounding volume hierarchy: binned SAH build in parallel (rayon) into a binary tree, which
//! is then collapsed into wide nodes of 8 or 16 children (each holds its children's boxes side
//! by side, so one pass of vector arithmetic tests them all), and closure-based traversal so
//! each primitive kind gets its own monomorphised loop with the intersection test inlined.
//!
//! A node with more than eight children is 16 wide, else 8 wide: the top of the tree, where
//! every node has many children, is 16 wide, and the bottom, where subtrees run out of
//! children, is not padded with empty lanes. Trees have 16-wide nodes only where the CPU tests
//! one in a single pass (AVX-512, [`widest`]). The box tests are chosen at run time: a 16-wide
//! node in one AVX-512 pass, an 8-wide one in one AVX pass, else passes of SSE over four lanes.
//!
//! By concern: `build` (the binned SAH build of the binary tree), `wide` (wide nodes: the
//! collapse, their layout and words), `traversal` (closest- and any-hit loops), `simd` (the box
//! tests of a wide node and the choice of instruction set at run time) and `stack` (the
//! traversal's stack, sized by the tree, and node fetches). All unsafe code of the BVH is in
//! `simd` and `stack`.

mod build;
// Intrinsics and the AVX / AVX-512 dispatch.
#[allow(unsafe_code)]
mod simd;
// Unchecked stack and node accesses.
#[allow(unsafe_code)]
mod stack;
mod traversal;
mod wide;

use crate::math::Aabb;
use build::{build_node, BuildPrim, PARALLEL_CUTOFF};
use simd::Loops;
use wide::{Line, WIDE16};

/// Leaves hold at most this many primitives.
const MAX_LEAF: usize = 8;
/// Past this depth splits are by median, so the depth stays bounded whatever the input.
const MAX_SAH_DEPTH: usize = 64;
/// Deepest binary tree: median splits after `MAX_SAH_DEPTH` halve at least 2^48 primitives.
const MAX_DEPTH: usize = MAX_SAH_DEPTH + 64;
/// Children of the widest nodes, and of the narrow ones.
const WIDEST: usize = 16;
const NARROW: usize = 8;

// A link (in binary and wide nodes) packs an offset and a count in a u64: bits 0..48: a leaf's
// first primitive, or an inner node's index (its first cache line, in wide nodes); bits
// 48..56: the primitive count (0 for inner nodes); bits 56..58: a binary node's split axis, or
// in a wide node's inner link, bit 56 ([`WIDE16`]) for a 16-wide child.
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

/// The widest nodes a build makes: 16 where the CPU tests them in one pass (AVX-512), else 8
/// (two AVX passes per 16-wide node cost more than the shallower tree saves).
/// `LUXON_BVH_WIDTH=8` or `16` overrides it: to compare, or to give every MPI rank of a cluster
/// with mixed CPUs the same tree (trees of different widths can differ where two surfaces are
/// hit at exactly the same distance).
pub fn widest() -> usize {
    match std::env::var("LUXON_BVH_WIDTH").as_deref() {
        Ok("8") => NARROW,
        Ok("16") => WIDEST,
        _ if simd::level() == simd::AVX512 => WIDEST,
        _ => NARROW,
    }
}

/// A BVH over primitives `0..n`. After building, primitive `order[i]` is the i-th in leaf order;
/// owners reorder their arrays by `order` so leaves address contiguous ranges.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// Wide nodes depth first, each starting on a cache line: a node's inner children come
    /// after it; the root is first.
    nodes: Vec<Line>,
    /// The root's inner link: 0, or [`WIDE16`] for a 16-wide root.
    root: u64,
    /// The most entries a traversal's stack holds at once ([`Bvh::stack_need`]).
    stack: usize,
    /// The traversal loops this tree gets on this CPU (chosen once, in `Bvh::new`).
    loops: Loops,
}

impl Bvh {
    /// Builds over the given primitive bounds; returns the BVH and the leaf order.
    pub fn build(bounds: &[Aabb]) -> (Bvh, Vec<u64>) {
        Bvh::build_with(bounds.len(), |i| bounds[i])
    }

    /// Builds over primitives `0..n` whose bounds `bound(i)` gives (no array of bounds is kept
    /// alongside the build's own), with nodes up to [`widest`] children wide.
    pub fn build_with(n: usize, bound: impl Fn(usize) -> Aabb + Sync) -> (Bvh, Vec<u64>) {
        Bvh::build_wide(n, bound, widest())
    }

    /// [`Bvh::build_with`] with nodes of at most `widest` (8 or 16) children.
    fn build_wide(
        n: usize,
        bound: impl Fn(usize) -> Aabb + Sync,
        widest: usize,
    ) -> (Bvh, Vec<u64>) {
        use rayon::prelude::*;
        if n == 0 {
            return (Bvh::default(), Vec::new());
        }
        let mut prims: Vec<BuildPrim> = (0..n)
            .into_par_iter()
            .with_min_len(PARALLEL_CUTOFF)
            .map(|i| BuildPrim::new(bound(i), i))
            .collect();
        let mut binary = Vec::new();
        build_node(&mut prims, 0, 0, &mut binary);
        let order = prims.iter().map(|p| p.index).collect();
        drop(prims);
        (Bvh::collapse(&binary, widest), order)
    }

    /// The tree of the given nodes and root link, with what its traversals need to know.
    fn new(nodes: Vec<Line>, root: u64) -> Bvh {
        let mut bvh = Bvh {
            nodes,
            root,
            stack: 0,
            loops: Loops::default(),
        };
        bvh.stack = bvh.stack_need();
        bvh.loops = Loops::choose(bvh.node_counts().1 > 0, bvh.stack);
        bvh
    }

    /// How many nodes of each width (8, 16) the tree has.
    pub fn node_counts(&self) -> (usize, usize) {
        let (mut narrow, mut wide) = (0, 0);
        self.walk(|_, w| if w { wide += 1 } else { narrow += 1 });
        (narrow, wide)
    }

    /// Bytes the nodes take.
    pub fn node_bytes(&self) -> usize {
        std::mem::size_of_val(&self.nodes[..])
    }

    pub fn bounds(&self) -> Aabb {
        if self.nodes.is_empty() {
            Aabb::EMPTY
        } else if self.root & WIDE16 != 0 {
            self.node::<WIDEST>(0).bounds()
        } else {
            self.node::<NARROW>(0).bounds()
        }
    }
}

/// Helpers for the tests of every part.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3A;

    impl Bvh {
        pub(super) fn leaf_sizes(&self) -> Vec<usize> {
            let mut sizes = Vec::new();
            self.walk(|i, wide| {
                let links = self.links(i, wide);
                sizes.extend(links.iter().map(|&l| count_of(l)).filter(|&c| c > 0));
            });
            sizes
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

    /// The tree over `b` with each widest node (8 and 16), and its leaf order.
    pub(super) fn both(b: &[Aabb]) -> Vec<(usize, Bvh, Vec<u64>)> {
        [NARROW, WIDEST]
            .into_iter()
            .map(|w| {
                let (bvh, order) = Bvh::build_wide(b.len(), |i| b[i], w);
                (w, bvh, order)
            })
            .collect()
    }
}
