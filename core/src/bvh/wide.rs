//! Wide nodes: the binary tree collapsed into nodes of up to 16 children, stored 16 wide when
//! they have more than eight and 8 wide otherwise; their layout (the boxes side by side, for
//! the SIMD box tests) in one array of cache lines, and the words the geometry cache stores.

use super::build::Node;
use super::{count_of, offset_of, Bvh, MAX_DEPTH, MAX_LEAF, NARROW, WIDEST};
use crate::math::{Aabb, Vec3A};

/// A wide node: the boxes of up to `W` children as rows min x, min y, min z, max x, max y,
/// max z (one lane per child), and a link per child: a leaf (first primitive, count) packed as
/// in `Node`, an inner node (its first line, count 0, and [`WIDE16`] if it is 16 wide), or
/// `EMPTY` (its box is inverted, so no ray enters it). `W / 2` cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Wide<const W: usize> {
    pub(super) b: [[f32; W]; 6],
    pub(super) link: [u64; W],
}

/// One cache line of the node array; nodes of either width start on a line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Line([u32; LINE_WORDS]);

/// Words per cache line (in memory and in `to_words`).
const LINE_WORDS: usize = 16;

/// The root is never a child, so link 0 marks an unused slot.
pub(super) const EMPTY: u64 = 0;
/// The bit of an inner link that says its child is 16 wide.
pub(super) const WIDE16: u64 = 1 << 56;

impl<const W: usize> Wide<W> {
    pub(super) const NONE: Wide<W> = Wide {
        b: [
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
        ],
        link: [EMPTY; W],
    };

    pub(super) fn set(&mut self, lane: usize, b: &Aabb, link: u64) {
        for k in 0..3 {
            self.b[k][lane] = b.min[k];
            self.b[3 + k][lane] = b.max[k];
        }
        self.link[lane] = link;
    }

    pub(super) fn bounds(&self) -> Aabb {
        (0..W)
            .filter(|&l| self.link[l] != EMPTY)
            .fold(Aabb::EMPTY, |acc, l| {
                acc.union(Aabb::new(
                    Vec3A::new(self.b[0][l], self.b[1][l], self.b[2][l]),
                    Vec3A::new(self.b[3][l], self.b[4][l], self.b[5][l]),
                ))
            })
    }
}

impl Bvh {
    /// The wide tree of a binary one: each wide node takes the two children of a binary node
    /// and keeps opening the largest inner one among them until it has `widest`.
    pub(super) fn collapse(binary: &[Node], widest: usize) -> Bvh {
        // At most four lines per binary inner node (an 8-wide node of two children), so the
        // vector never moves while it fills: a move (growing, or shrinking to fit afterwards)
        // holds both copies at once, 15–24 MB more peak memory on balls6. The capacity beyond
        // the nodes is address space that is never touched, not memory.
        let mut nodes = Vec::with_capacity(binary.len() * 2 + NARROW / 2);
        let root = if binary[0].count() > 0 {
            let mut root = Wide::<NARROW>::NONE;
            root.set(0, &binary[0].bounds(), leaf_link(&binary[0]));
            nodes.extend_from_slice(root.lines());
            0
        } else {
            collapse_node(binary, 0, widest, &mut nodes)
        };
        Bvh::new(nodes, root)
    }

    /// Calls `f(line, wide)` for every node in order (its first line, and whether it is 16
    /// wide), learning each node's width from its parent's link.
    pub(super) fn walk(&self, mut f: impl FnMut(usize, bool)) {
        let mut wide = vec![false; self.nodes.len()];
        if let Some(w) = wide.first_mut() {
            *w = self.root & WIDE16 != 0;
        }
        let mut i = 0;
        while i < self.nodes.len() {
            for &l in self.links(i, wide[i]) {
                if l != EMPTY && count_of(l) == 0 {
                    wide[offset_of(l)] = l & WIDE16 != 0;
                }
            }
            f(i, wide[i]);
            i += if wide[i] { WIDEST / 2 } else { NARROW / 2 };
        }
    }

    /// The links of the node at line `i`.
    pub(super) fn links(&self, i: usize, wide: bool) -> &[u64] {
        if wide {
            &self.node::<WIDEST>(i).link
        } else {
            &self.node::<NARROW>(i).link
        }
    }

    /// The nodes as little-endian-ready words (for the geometry cache): whether the root is 16
    /// wide, then every node in order, its box rows then a link of two words per lane.
    pub(crate) fn to_words(&self, out: &mut impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        out(u32::from(self.root & WIDE16 != 0));
        let mut put = |b: &[f32], links: &[u64]| {
            b.iter().for_each(|x| out(x.to_bits()));
            for &l in links {
                out(l as u32);
                out((l >> 32) as u32);
            }
        };
        self.walk(|i, wide| {
            if wide {
                let n = self.node::<WIDEST>(i);
                put(n.b.as_flattened(), &n.link);
            } else {
                let n = self.node::<NARROW>(i);
                put(n.b.as_flattened(), &n.link);
            }
        });
    }

    /// Nodes read back from `to_words`, checked against `prims` primitives: every link and
    /// leaf range in bounds, every node the child of exactly one earlier node (so the nodes
    /// form a tree and traversal ends) and starting where that link says, with the width it
    /// says; empty slots with inverted boxes, and no deeper than `MAX_DEPTH`.
    pub(crate) fn from_words(w: &[u32], prims: usize) -> Option<Bvh> {
        if w.is_empty() || prims == 0 {
            return (w.is_empty() && prims == 0).then(Bvh::default);
        }
        let (&root, w) = w.split_first()?;
        if root > 1 || !w.len().is_multiple_of(LINE_WORDS) {
            return None;
        }
        let n = w.len() / LINE_WORDS;
        let mut lines = Lines {
            expect: vec![Expect::Nothing; n],
            depth: vec![0; n],
        };
        lines.expect[0] = if root == 1 {
            Expect::Wide
        } else {
            Expect::Narrow
        };
        let mut nodes = Vec::with_capacity(n);
        let mut i = 0;
        while i < n {
            i += match lines.expect[i] {
                Expect::Narrow => lines.read::<NARROW>(w, i, prims, &mut nodes)?,
                Expect::Wide => lines.read::<WIDEST>(w, i, prims, &mut nodes)?,
                Expect::Nothing | Expect::Read => return None,
            };
        }
        // Every link's node was read: it started on a line the nodes before it ended at.
        if i != n || lines.expect.contains(&Expect::Narrow) || lines.expect.contains(&Expect::Wide)
        {
            return None;
        }
        Some(Bvh::new(nodes, u64::from(root) * WIDE16))
    }
}

/// What `from_words` knows of a line: whether a link says a node starts there, and of which
/// width (`Read` once it is read).
#[derive(Clone, Copy, PartialEq)]
enum Expect {
    Nothing,
    Narrow,
    Wide,
    Read,
}

/// `from_words`' notes per line: what starts there, and the depth of the node that does.
struct Lines {
    expect: Vec<Expect>,
    depth: Vec<u16>,
}

impl Lines {
    /// Reads the `W`-wide node at line `i` of `w` into `nodes`, checking its links and noting
    /// the children they announce; returns its lines.
    fn read<const W: usize>(
        &mut self,
        w: &[u32],
        i: usize,
        prims: usize,
        nodes: &mut Vec<Line>,
    ) -> Option<usize> {
        let c = w.get(i * LINE_WORDS..(i + W / 2) * LINE_WORDS)?;
        if usize::from(self.depth[i]) >= MAX_DEPTH {
            return None;
        }
        self.expect[i] = Expect::Read;
        let mut node = Wide::<W>::NONE;
        for (x, &c) in node.b.as_flattened_mut().iter_mut().zip(c) {
            *x = f32::from_bits(c);
        }
        let links = &c[6 * W..];
        for l in 0..W {
            let link = u64::from(links[2 * l]) | u64::from(links[2 * l + 1]) << 32;
            node.link[l] = link;
            let (count, offset) = (count_of(link), offset_of(link));
            let ok = if link == EMPTY {
                // Inverted, so never entered (NaN would not compare).
                node.b[0][l] > node.b[3][l]
            } else if count > 0 {
                link >> 56 == 0 && count <= MAX_LEAF && offset + count <= prims
            } else {
                link >> 57 == 0
                    && offset >= i + W / 2
                    && offset < self.expect.len()
                    && self.expect[offset] == Expect::Nothing
            };
            if !ok {
                return None;
            }
            if link != EMPTY && count == 0 {
                self.expect[offset] = if link & WIDE16 != 0 {
                    Expect::Wide
                } else {
                    Expect::Narrow
                };
                self.depth[offset] = self.depth[i] + 1;
            }
        }
        nodes.extend_from_slice(node.lines());
        Some(W / 2)
    }
}

/// The children of the wide node for binary inner node `i`: its two children, then the widest
/// inner one replaced by its own two (the first of equals) until there are `widest`.
fn open_kids(binary: &[Node], i: usize, widest: usize) -> ([usize; WIDEST], usize) {
    let mut kids = [0usize; WIDEST];
    // Half areas of the inner children; -1 for leaves, which are never opened.
    let mut area = [0.0f32; WIDEST];
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
    while len < widest {
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

/// Emits the wide node for binary inner node `i` (16 wide if it has more than eight children)
/// and, after it, its inner descendants; returns its link.
fn collapse_node(binary: &[Node], i: usize, widest: usize, out: &mut Vec<Line>) -> u64 {
    let (kids, len) = open_kids(binary, i, widest);
    if len > NARROW {
        emit::<WIDEST>(binary, &kids[..len], widest, out) | WIDE16
    } else {
        emit::<NARROW>(binary, &kids[..len], widest, out)
    }
}

/// Emits the `W`-wide node of binary nodes `kids` and its inner descendants; returns its line.
fn emit<const W: usize>(
    binary: &[Node],
    kids: &[usize],
    widest: usize,
    out: &mut Vec<Line>,
) -> u64 {
    let index = out.len();
    out.resize(index + W / 2, Line([0; LINE_WORDS]));
    let mut node = Wide::<W>::NONE;
    for (lane, &k) in kids.iter().enumerate() {
        let link = if binary[k].count() > 0 {
            leaf_link(&binary[k])
        } else {
            collapse_node(binary, k, widest, out)
        };
        node.set(lane, &binary[k].bounds(), link);
    }
    out[index..index + W / 2].copy_from_slice(node.lines());
    index as u64
}

#[cfg(test)]
mod tests {
    use super::super::tests::{both, boxes};
    use super::super::OFFSET_MASK;
    use super::*;

    #[test]
    fn every_primitive_is_in_exactly_one_leaf() {
        let b = boxes(10_000);
        for (widest, bvh, order) in both(&b) {
            let mut seen = order.clone();
            seen.sort();
            assert_eq!(seen, (0..10_000).collect::<Vec<u64>>());
            let sizes = bvh.leaf_sizes();
            assert_eq!(sizes.iter().sum::<usize>(), 10_000);
            assert!(sizes.iter().all(|&c| c <= MAX_LEAF));
            // 16-wide nodes only where asked for (and then both widths are used); nodes hold
            // more than two children on average.
            let (narrow, wide) = bvh.node_counts();
            assert!(
                narrow > 0 && (wide > 0) == (widest == WIDEST),
                "{widest}: {narrow} 8-wide, {wide} 16-wide"
            );
            assert!(
                (narrow + wide) * 2 < sizes.len(),
                "{narrow} + {wide} nodes, {} leaves",
                sizes.len()
            );
            assert_eq!(bvh.node_bytes(), narrow * 256 + wide * 512);
        }
    }

    #[test]
    fn wide_nodes_are_four_or_eight_cache_lines() {
        assert_eq!(std::mem::size_of::<Wide<NARROW>>(), 256);
        assert_eq!(std::mem::size_of::<Wide<WIDEST>>(), 512);
        assert_eq!(std::mem::align_of::<Wide<WIDEST>>(), 64);
        assert_eq!(std::mem::size_of::<Line>(), 64);
    }

    #[test]
    fn words_round_trip_and_bad_links_are_refused() {
        let b = boxes(3000);
        for (widest, bvh, _) in both(&b) {
            let mut w = Vec::new();
            bvh.to_words(&mut |x| w.push(x));
            let back = Bvh::from_words(&w, 3000).unwrap_or_else(|| panic!("{widest}: round trip"));
            assert_eq!(back.node_counts(), bvh.node_counts());
            assert_eq!(back.stack, bvh.stack);
            let mut w2 = Vec::new();
            back.to_words(&mut |x| w2.push(x));
            assert_eq!(w, w2);
            // Too few primitives for the leaves, a truncated node, a root of the wrong width.
            assert!(Bvh::from_words(&w, 2999).is_none());
            assert!(Bvh::from_words(&w[..w.len() - 1], 3000).is_none());
            let mut root = w.clone();
            root[0] ^= 1;
            assert!(Bvh::from_words(&root, 3000).is_none());
            // An inner link of the root made to point backwards, into the middle of a node,
            // past the end, at a node another link already claims, with the wrong width, or
            // with stray high bits.
            let width = if w[0] == 1 { WIDEST } else { NARROW };
            let link_word = |l: usize| 1 + 6 * width + 2 * l;
            let link = |l: usize| u64::from(w[link_word(l)]) | u64::from(w[link_word(l) + 1]) << 32;
            let inner: Vec<usize> = (0..width)
                .filter(|&l| link(l) != EMPTY && count_of(link(l)) == 0)
                .collect();
            assert!(inner.len() >= 2, "{widest}: the root has inner children");
            let (a, b) = (link(inner[0]), link(inner[1]));
            let lines = (w.len() - 1) / LINE_WORDS;
            for bad in [
                a & !OFFSET_MASK,
                a + 1,
                (a & !OFFSET_MASK) | lines as u64,
                b,
                a ^ WIDE16,
                a | 1 << 60,
            ] {
                let mut c = w.clone();
                c[link_word(inner[0])] = bad as u32;
                c[link_word(inner[0]) + 1] = (bad >> 32) as u32;
                assert!(
                    Bvh::from_words(&c, 3000).is_none(),
                    "{widest}: accepted link {bad:#x}"
                );
            }
        }
    }

    /// Words of `n` 8-wide nodes with the given inner links (node, child) and one primitive in
    /// a leaf of the last node.
    fn chain_words(n: usize, links: &[(usize, usize)]) -> Vec<u32> {
        let mut nodes = vec![Wide::<NARROW>::NONE; n];
        let unit = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        for &(from, to) in links {
            let lane = nodes[from].link.iter().position(|&l| l == EMPTY).unwrap();
            nodes[from].set(lane, &unit, (to * NARROW / 2) as u64);
        }
        nodes[n - 1].set(0, &unit, 1 << super::super::OFFSET_BITS);
        let mut w = vec![0];
        for node in &nodes {
            node.lines().iter().for_each(|l| w.extend(l.0));
        }
        w
    }

    /// Cached words must form a tree no deeper than `MAX_DEPTH`: a node with two parents
    /// (which could make the traversal's stack need more than its tree's count) and too deep
    /// a chain are refused.
    #[test]
    fn words_of_a_dag_or_a_tree_too_deep_are_refused() {
        let chain = |n: usize| (0..n - 1).map(|i| (i, i + 1)).collect::<Vec<_>>();
        let ok = Bvh::from_words(&chain_words(MAX_DEPTH, &chain(MAX_DEPTH)), 1);
        assert_eq!(ok.map(|b| b.node_counts()), Some((MAX_DEPTH, 0)));
        assert!(Bvh::from_words(&chain_words(MAX_DEPTH + 1, &chain(MAX_DEPTH + 1)), 1).is_none());
        // 0 → 1 → 3 and 0 → 2 → 3.
        let dag = [(0, 1), (0, 2), (1, 3), (2, 3)];
        assert!(Bvh::from_words(&chain_words(4, &dag), 1).is_none());
        let tree = [(0, 1), (0, 2), (1, 3)];
        assert!(Bvh::from_words(&chain_words(4, &tree), 1).is_some());
    }
}
