//! Wide nodes: the binary tree collapsed into nodes of up to eight children, their layout (the
//! eight boxes side by side, for the SIMD box tests), and the words the geometry cache stores.

use super::build::Node;
use super::{count_of, offset_of, Bvh, LANES, MAX_DEPTH, MAX_LEAF};
use crate::math::{Aabb, Vec3A};

/// A wide node: the boxes of up to `LANES` children as rows min x, min y, min z, max x, max y,
/// max z (one lane per child), and a link per child: a leaf (first primitive, count) packed as
/// in `Node`, an inner node (its index, count 0), or `EMPTY` (its box is inverted, so no ray
/// enters it). Four cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Wide {
    pub(super) b: [[f32; LANES]; 6],
    pub(super) link: [u64; LANES],
}

/// The root is never a child, so link 0 marks an unused slot.
pub(super) const EMPTY: u64 = 0;

impl Wide {
    const NONE: Wide = Wide {
        b: [
            [f32::INFINITY; LANES],
            [f32::INFINITY; LANES],
            [f32::INFINITY; LANES],
            [f32::NEG_INFINITY; LANES],
            [f32::NEG_INFINITY; LANES],
            [f32::NEG_INFINITY; LANES],
        ],
        link: [EMPTY; LANES],
    };

    fn set(&mut self, lane: usize, b: &Aabb, link: u64) {
        self.set_box(lane, b);
        self.link[lane] = link;
    }

    pub(super) fn set_box(&mut self, lane: usize, b: &Aabb) {
        for k in 0..3 {
            self.b[k][lane] = b.min[k];
            self.b[3 + k][lane] = b.max[k];
        }
    }

    pub(super) fn lane_box(&self, lane: usize) -> Aabb {
        let b = &self.b;
        Aabb::new(
            Vec3A::new(b[0][lane], b[1][lane], b[2][lane]),
            Vec3A::new(b[3][lane], b[4][lane], b[5][lane]),
        )
    }

    pub(super) fn bounds(&self) -> Aabb {
        (0..LANES)
            .filter(|&l| self.link[l] != EMPTY)
            .fold(Aabb::EMPTY, |acc, l| acc.union(self.lane_box(l)))
    }
}

/// Words per wide node in `to_words`: the box rows, then a link of two words per lane.
const WORDS: usize = 8 * LANES;
/// Where the links start among a node's words.
const LINK_WORDS: usize = 6 * LANES;

impl Bvh {
    /// The wide tree of a binary one: each wide node takes the two children of a binary node
    /// and keeps opening the largest inner one among them until it has `LANES`; lanes still
    /// free then take leaves' primitives one per lane (see `fill_lanes`). `bound(i)` is the
    /// box of the i-th primitive in leaf order.
    pub(super) fn collapse(binary: &[Node], bound: &impl Fn(usize) -> Aabb) -> Bvh {
        let mut nodes = Vec::with_capacity(binary.len() / 3 + 1);
        if binary[0].count() > 0 {
            let mut root = Wide::NONE;
            let (lanes, n) = fill_lanes(binary, &[0], 1);
            for (lane, &(k, p)) in lanes[..n].iter().enumerate() {
                set_leaf_lane(&mut root, lane, &binary[k], p, bound);
            }
            nodes.push(root);
        } else {
            collapse_node(binary, 0, &mut nodes, bound);
        }
        Bvh { nodes }
    }

    /// The nodes as little-endian-ready words, `WORDS` per node (for the geometry cache).
    pub(crate) fn to_words(&self, out: &mut impl FnMut(u32)) {
        for n in &self.nodes {
            n.b.iter().flatten().for_each(|x| out(x.to_bits()));
            for &l in &n.link {
                out(l as u32);
                out((l >> 32) as u32);
            }
        }
    }

    /// Nodes read back from `to_words`, checked against `prims` primitives: every link and
    /// leaf range in bounds, links pointing forward (so traversal ends), empty slots with
    /// inverted boxes, and no deeper than the traversal stack allows.
    pub(crate) fn from_words(w: &[u32], prims: usize) -> Option<Bvh> {
        if !w.len().is_multiple_of(WORDS) || (w.is_empty() != (prims == 0)) {
            return None;
        }
        let n = w.len() / WORDS;
        let mut nodes = Vec::with_capacity(n);
        let mut depth = vec![0u16; n];
        for (i, c) in w.chunks_exact(WORDS).enumerate() {
            let mut node = Wide::NONE;
            for (k, x) in node.b.iter_mut().flatten().enumerate() {
                *x = f32::from_bits(c[k]);
            }
            for l in 0..LANES {
                node.link[l] =
                    u64::from(c[LINK_WORDS + 2 * l]) | u64::from(c[LINK_WORDS + 1 + 2 * l]) << 32;
            }
            for l in 0..LANES {
                let link = node.link[l];
                let (count, offset) = (count_of(link), offset_of(link));
                let ok = link >> 56 == 0
                    && if link == EMPTY {
                        // Inverted, so never entered (NaN would not compare).
                        node.b[0][l] > node.b[3][l]
                    } else if count > 0 {
                        count <= MAX_LEAF && offset + count <= prims
                    } else {
                        offset > i && offset < n
                    };
                if !ok || depth[i] as usize >= MAX_DEPTH {
                    return None;
                }
                // A node may have several parents (cached words are not trusted to be a
                // tree): it is as deep as its deepest path. Parents come first, so a node's
                // depth is final when its own links are checked.
                if link != EMPTY && count == 0 {
                    depth[offset] = depth[offset].max(depth[i] + 1);
                }
            }
            nodes.push(node);
        }
        Some(Bvh { nodes })
    }
}

/// The children of the wide node for binary inner node `i`: its two children, then the widest
/// inner one replaced by its own two (the first of equals) until there are `LANES`.
fn open_kids(binary: &[Node], i: usize) -> ([usize; LANES], usize) {
    let mut kids = [0usize; LANES];
    // Half areas of the inner children; -1 for leaves, which are never opened.
    let mut area = [0.0f32; LANES];
    let area_of = |k: usize| {
        if binary[k].count() == 0 {
            binary[k].bounds().half_area()
        } else {
            -1.0
        }
    };
    let mut len = 2;
    (kids[0], kids[1]) = (i + 1, binary[i].offset());
    (area[0], area[1]) = (area_of(kids[0]), area_of(kids[1]));
    while len < LANES {
        let mut slot = None;
        for s in 0..len {
            if area[s] >= 0.0 && slot.is_none_or(|b: usize| area[s] > area[b]) {
                slot = Some(s);
            }
        }
        let Some(slot) = slot else { break };
        let k = kids[slot];
        kids.copy_within(slot + 1..len, slot + 2);
        area.copy_within(slot + 1..len, slot + 2);
        (kids[slot], kids[slot + 1]) = (k + 1, binary[k].offset());
        (area[slot], area[slot + 1]) = (area_of(kids[slot]), area_of(kids[slot + 1]));
        len += 1;
    }
    (kids, len)
}

/// A leaf's link in a wide node (the binary node's split axis bits cleared).
fn leaf_link(node: &Node) -> u64 {
    node.link & !(3 << 56)
}

/// A lane per child when there is room for it: the children `kids[..len]` (binary nodes), each
/// leaf among them, in order, given a lane per primitive while the lanes last (a box test of
/// the node is one vector pass whatever its lanes hold; a lane per primitive spares the
/// primitive tests of the boxes a ray misses). Each entry is (binary node, primitive): `NONE`
/// for the whole child. A split leaf's primitives take its place in reverse order, so the
/// any-hit loops, which take a node's lanes from the last to the first, test them in the same
/// order as before (a shadow ray through filters multiplies them in that order).
fn fill_lanes(binary: &[Node], kids: &[usize], len: usize) -> ([(usize, usize); LANES], usize) {
    let mut free = LANES - len;
    let mut lanes = [(0, NONE); LANES];
    let mut n = 0;
    for &k in &kids[..len] {
        let count = binary[k].count();
        if count > 1 && count - 1 <= free {
            free -= count - 1;
            for p in (0..count).rev() {
                lanes[n] = (k, binary[k].offset() + p);
                n += 1;
            }
        } else {
            lanes[n] = (k, NONE);
            n += 1;
        }
    }
    (lanes, n)
}

/// No single primitive: the lane holds the whole child.
const NONE: usize = usize::MAX;

/// Lane `lane` of `wide` set to leaf `node`, or to its primitive `p` alone.
fn set_leaf_lane(
    wide: &mut Wide,
    lane: usize,
    node: &Node,
    p: usize,
    bound: &impl Fn(usize) -> Aabb,
) {
    if p == NONE {
        wide.set(lane, &node.bounds(), leaf_link(node));
    } else {
        let link = p as u64 | 1 << super::OFFSET_BITS;
        wide.set(lane, &bound(p), link);
    }
}

/// Emits the wide node for binary inner node `i` and, after it, its inner descendants;
/// returns its index.
fn collapse_node(
    binary: &[Node],
    i: usize,
    out: &mut Vec<Wide>,
    bound: &impl Fn(usize) -> Aabb,
) -> usize {
    let index = out.len();
    out.push(Wide::NONE);
    let (kids, len) = open_kids(binary, i);
    let (lanes, n) = fill_lanes(binary, &kids, len);
    for (lane, &(k, p)) in lanes[..n].iter().enumerate() {
        if binary[k].count() > 0 {
            set_leaf_lane(&mut out[index], lane, &binary[k], p, bound);
        } else {
            let link = collapse_node(binary, k, out, bound) as u64;
            out[index].set(lane, &binary[k].bounds(), link);
        }
    }
    index
}

#[cfg(test)]
mod tests {
    use super::super::tests::boxes;
    use super::*;

    #[test]
    fn every_primitive_is_in_exactly_one_leaf() {
        let b = boxes(10_000);
        let (bvh, order) = Bvh::build(&b);
        let mut seen = order.clone();
        seen.sort();
        assert_eq!(seen, (0..10_000).collect::<Vec<u64>>());
        let leaf_total: usize = bvh.leaf_sizes().sum();
        assert_eq!(leaf_total, 10_000);
        assert!(bvh.leaf_sizes().all(|c| c <= MAX_LEAF));
        // Wide nodes hold more than two children on average.
        let leaves = bvh.leaf_sizes().count();
        assert!(
            bvh.nodes.len() * 2 < leaves,
            "{} nodes, {leaves} leaves",
            bvh.nodes.len()
        );
    }

    /// Lanes left free by the inner children take leaves' primitives one each: up to eight
    /// primitives make one node of one-primitive lanes, and a leaf split this way keeps its
    /// primitives in reverse lane order (the any-hit loops take lanes last to first).
    #[test]
    fn free_lanes_take_leaves_primitives_one_each() {
        for n in 1..=LANES {
            let (bvh, _) = Bvh::build(&boxes(n));
            assert_eq!(bvh.nodes.len(), 1, "{n} primitives");
            assert_eq!(bvh.leaf_sizes().count(), n, "{n} primitives");
            assert!(bvh.leaf_sizes().all(|c| c == 1));
        }
        // Two coincident boxes make one leaf of two at the root: now two lanes, the first
        // primitive in the higher one.
        let same = vec![Aabb::new(Vec3A::ZERO, Vec3A::ONE); 2];
        let (bvh, _) = Bvh::build(&same);
        let root = &bvh.nodes[0];
        assert_eq!(
            (root.link[0], root.link[1]),
            (
                1 | 1 << super::super::OFFSET_BITS,
                1 << super::super::OFFSET_BITS
            )
        );
    }

    #[test]
    fn wide_nodes_are_four_cache_lines() {
        assert_eq!(std::mem::size_of::<Wide>(), 256);
        assert_eq!(std::mem::align_of::<Wide>(), 64);
    }

    #[test]
    fn words_round_trip_and_bad_links_are_refused() {
        let b = boxes(3000);
        let (bvh, _) = Bvh::build(&b);
        let mut w = Vec::new();
        bvh.to_words(&mut |x| w.push(x));
        let back = Bvh::from_words(&w, 3000).expect("round trip");
        assert_eq!(back.nodes.len(), bvh.nodes.len());
        let mut w2 = Vec::new();
        back.to_words(&mut |x| w2.push(x));
        assert_eq!(w, w2);
        // Too few primitives for the leaves, a link pointing backwards, a truncated node.
        assert!(Bvh::from_words(&w, 2999).is_none());
        let mut backwards = w.clone();
        let inner = (0..LANES)
            .find(|&l| {
                let link =
                    u64::from(w[LINK_WORDS + 2 * l]) | u64::from(w[LINK_WORDS + 1 + 2 * l]) << 32;
                link != EMPTY && count_of(link) == 0
            })
            .unwrap();
        let last = w.len() / WORDS - 1;
        backwards[last * WORDS + LINK_WORDS + 2 * inner] = 0;
        backwards[last * WORDS + LINK_WORDS + 1 + 2 * inner] = 0;
        backwards[last * WORDS + LINK_WORDS] = 1;
        assert!(Bvh::from_words(&backwards, 3000).is_none());
        assert!(Bvh::from_words(&w[..w.len() - 1], 3000).is_none());
    }

    /// Words of `n` wide nodes with the given inner links (node, child) and one primitive in a
    /// leaf of the last node.
    fn dag_words(n: usize, links: &[(usize, usize)]) -> Vec<u32> {
        let mut nodes = vec![Wide::NONE; n];
        let unit = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        for &(from, to) in links {
            let lane = nodes[from].link.iter().position(|&l| l == EMPTY).unwrap();
            nodes[from].set(lane, &unit, to as u64);
        }
        nodes[n - 1].set(0, &unit, 1 << super::super::OFFSET_BITS);
        let mut w = Vec::new();
        Bvh { nodes }.to_words(&mut |x| w.push(x));
        w
    }

    /// A node reached both by a short and by a long path counts as deep as the long one: a
    /// cache file whose short parent comes last must not hide a path deeper than the traversal
    /// stack holds.
    #[test]
    fn words_deeper_than_the_stack_along_any_path_are_refused() {
        // 0 → 1 → … → m (depth m), and 0 → m + 1 (depth 1); both m and m + 1 lead to m + 2,
        // from which a chain of `tail` nodes goes on.
        let (m, tail) = (MAX_DEPTH - 20, 40);
        let n = m + 2 + tail;
        let mut links: Vec<(usize, usize)> = (0..m).map(|i| (i, i + 1)).collect();
        links.extend([(0, m + 1), (m, m + 2), (m + 1, m + 2)]);
        links.extend((m + 2..n - 1).map(|i| (i, i + 1)));
        assert!(Bvh::from_words(&dag_words(n, &links), 1).is_none());
        // The same shape with a short tail fits.
        let n = m + 2 + 10;
        let mut links: Vec<(usize, usize)> = (0..m).map(|i| (i, i + 1)).collect();
        links.extend([(0, m + 1), (m, m + 2), (m + 1, m + 2)]);
        links.extend((m + 2..n - 1).map(|i| (i, i + 1)));
        assert!(Bvh::from_words(&dag_words(n, &links), 1).is_some());
    }
}
