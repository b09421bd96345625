//! The traversal's memory accesses without bounds checks, each sound by how trees are built
//! (or checked, for cached trees): its stack, sized by the tree, and its node fetches from the
//! array of cache lines.

use super::wide::{Line, Wide, EMPTY};
use super::{count_of, offset_of, Bvh};
use std::mem::MaybeUninit;

/// The traversal stack: links (with their entry distances for closest-hit), never read before
/// written (so not zeroed per ray, which cost a memset of the whole stack). The entries live in
/// a separate local the stack borrows: about 1.5 % fewer traversal instructions than with the
/// array beside `len` in one struct. They are a small array in the traversal's frame when the
/// tree's [`Bvh::stack_need`] fits, else a vector of that size: a frame as large as the worst
/// case (15 entries per level of a `MAX_DEPTH` tree of 16-wide nodes, 30 KB) had every call
/// touch (stack-probe) its eight pages, which cost 10–20 % of a ray's time.
pub(super) struct Stack<'a, T> {
    /// `Bvh::stack_need` entries.
    entries: &'a mut [MaybeUninit<T>],
    /// Entries below `len` are initialised (private, so only `push` and `insert_sorted` raise
    /// it, each after writing the entry).
    len: usize,
}

/// Entries of the stack in the traversal's frame (3 KB for closest-hit, so the frame stays
/// within a page). The SPD scenes need 34–102 (teapot153); trees that need more take loops
/// with a stack on the heap (`Loops::Deep`).
pub(super) const SMALL_STACK: usize = 192;

/// The in-frame storage of a [`Stack`].
#[inline(always)]
pub(super) fn stack_space<T: Copy>() -> [MaybeUninit<T>; SMALL_STACK] {
    [const { MaybeUninit::uninit() }; SMALL_STACK]
}

/// The heap storage of a [`Stack`] for a tree that needs more than [`SMALL_STACK`].
pub(super) fn stack_vec<T: Copy>(bvh: &Bvh) -> Vec<MaybeUninit<T>> {
    vec![MaybeUninit::uninit(); bvh.stack]
}

impl<'a, T: Copy> Stack<'a, T> {
    /// A stack for a traversal of `bvh` in `space`, which must hold its `stack_need` entries
    /// (checked).
    #[inline(always)]
    pub(super) fn new(bvh: &Bvh, space: &'a mut [MaybeUninit<T>]) -> Self {
        Stack {
            entries: &mut space[..bvh.stack],
            len: 0,
        }
    }

    #[inline(always)]
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Pushes an entry. The traversals keep `len < entries.len()` here: they hold at most
    /// `Bvh::stack_need` entries at once (see there), and the stack has that many.
    #[inline(always)]
    pub(super) fn push(&mut self, entry: T) {
        debug_assert!(self.len < self.entries.len());
        // SAFETY: `len < entries.len()` (see above), so the slot is in bounds.
        unsafe { *self.entries.get_unchecked_mut(self.len) = MaybeUninit::new(entry) };
        self.len += 1;
    }

    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: `len` was at most `entries.len()`, so the slot is in bounds, and it is below
        // the old `len`, so it is initialised.
        Some(unsafe { self.entries.get_unchecked(self.len).assume_init() })
    }
}

impl Stack<'_, (u64, f32)> {
    /// Pushes keeping the entries above `base` (at most `len`) in decreasing order of `t`.
    #[inline(always)]
    pub(super) fn insert_sorted(&mut self, base: usize, link: u64, t: f32) {
        let mut j = self.len;
        debug_assert!(j < self.entries.len() && base <= j);
        // SAFETY: `len < entries.len()` as in `push`, so every slot up to `len` is in bounds;
        // the loop reads only slots `j - 1 >= base` below `len`, which are initialised, and
        // moves them up one, so slots up to the old `len` stay initialised.
        unsafe {
            while j > base && self.entries.get_unchecked(j - 1).assume_init().1 < t {
                *self.entries.get_unchecked_mut(j) = *self.entries.get_unchecked(j - 1);
                j -= 1;
            }
            *self.entries.get_unchecked_mut(j) = MaybeUninit::new((link, t));
        }
        self.len += 1;
    }
}

impl Bvh {
    /// The most entries a traversal's stack holds at once. At a node, closest-hit pushes the
    /// children it hits and takes one (any-hit pushes all but the one it takes), so while it
    /// is below a node it holds at most the sum of (children − 1) of the nodes on the path
    /// down to it, and pushing a node's children reaches that sum plus one. The links a
    /// traversal follows are the tree's: an empty lane's inverted box is never hit by a ray
    /// with finite coordinates, the only rays the loops (`Bvh::closest`, `Bvh::first`)
    /// trace. Nodes form a tree (`collapse` makes one, and `from_words` checks that every
    /// node has one parent), so the sums are taken down every path.
    pub(super) fn stack_need(&self) -> usize {
        let mut order = Vec::new();
        self.walk(|i, wide| order.push((i, wide)));
        // Children come after their parents: walking back, a node's children are known.
        let mut need = vec![0u32; self.nodes.len()];
        for &(i, wide) in order.iter().rev() {
            let links = self.links(i, wide);
            let below = links
                .iter()
                .filter(|&&l| l != EMPTY && count_of(l) == 0)
                .map(|&l| need[offset_of(l)])
                .max()
                .unwrap_or(0);
            let children = links.iter().filter(|&&l| l != EMPTY).count() as u32;
            need[i] = children.saturating_sub(1) + below;
        }
        need.first().map_or(0, |&n| n as usize + 1)
    }

    /// The `W`-wide node starting at line `i`. The traversal loops skip the bounds check.
    #[inline(always)]
    pub(super) fn node<const W: usize>(&self, i: usize) -> &Wide<W> {
        debug_assert!(i + W / 2 <= self.nodes.len());
        // SAFETY: a `W`-wide node starts at line `i` and its `W / 2` lines are in bounds: `i`
        // is the root's line 0 (asked for only when `nodes` is not empty) with the root's
        // width, or an inner link's line, which `collapse` makes and `from_words` checks to
        // start a node of the width the link says within `nodes` (`nodes` is private to `bvh`
        // and only ever set by those two). `Wide<W>` is `W / 2` lines long, aligned as lines
        // are, and made of floats and integers, which any bits are.
        unsafe { &*self.nodes.as_ptr().add(i).cast::<Wide<W>>() }
    }
}

impl<const W: usize> Wide<W> {
    /// The node as the cache lines it is stored in.
    pub(super) fn lines(&self) -> &[Line] {
        const { assert!(std::mem::size_of::<Wide<W>>() == W / 2 * std::mem::size_of::<Line>()) };
        const { assert!(std::mem::align_of::<Wide<W>>() == std::mem::align_of::<Line>()) };
        // SAFETY: `Wide<W>` is `W / 2` lines long and aligned as lines are (checked above),
        // and is made of floats and integers with no padding, as lines are of integers.
        unsafe { std::slice::from_raw_parts((self as *const Self).cast::<Line>(), W / 2) }
    }
}

#[cfg(test)]
mod tests {
    use super::super::build::Node;
    use super::super::{Aabb, NARROW, WIDEST};
    use super::*;
    use crate::math::Vec3A;

    /// A binary tree that is one long path (each inner node a leaf and an inner node, as
    /// the SAH makes of boxes spaced ever wider apart) collapses into a wide tree whose
    /// traversal needs more stack than the frame holds, so it gets the loops with a stack on
    /// the heap: closest-hit finds the nearest box and any-hit tests every box once.
    #[test]
    fn a_deep_tree_gets_a_stack_large_enough() {
        let n = 600;
        let b: Vec<Aabb> = (0..n)
            .map(|i| {
                Aabb::new(
                    Vec3A::new(i as f32, -1.0, -1.0),
                    Vec3A::new(i as f32 + 0.5, 1.0, 1.0),
                )
            })
            .collect();
        let rest = |i: usize| b[i..].iter().fold(Aabb::EMPTY, |a, &x| a.union(x));
        let mut binary = Vec::new();
        for (i, bi) in b[..n - 1].iter().enumerate() {
            let at = binary.len();
            binary.push(Node::new(&rest(i), at + 2, 0, 0));
            binary.push(Node::new(bi, i, 1, 0));
        }
        binary.push(Node::new(&b[n - 1], n - 1, 1, 0));
        for widest in [NARROW, WIDEST] {
            let bvh = Bvh::collapse(&binary, widest);
            assert!(
                bvh.stack > SMALL_STACK,
                "{widest}: stack need {}",
                bvh.stack
            );
            assert_eq!(bvh.loops, super::super::Loops::Deep);
            let o = Vec3A::new(-1.0, 0.0, 0.0);
            let t = bvh.intersect(o, Vec3A::X, f32::INFINITY, |p, tm| {
                Some(b[p].min.x + 1.0).filter(|&t| t < tm)
            });
            assert_eq!(t, 1.0, "{widest}");
            for (name, closest, any) in bvh.loops() {
                let t = closest(o, Vec3A::X, f32::INFINITY, &mut |p, tm| {
                    Some(b[p].min.x + 1.0).filter(|&t| t < tm)
                });
                assert_eq!(t, 1.0, "{widest} {name}");
                let mut count = 0;
                any(o, Vec3A::X, f32::INFINITY, &mut |_| {
                    count += 1;
                    false
                });
                assert_eq!(count, n, "{widest} {name}: any-hit tests every box once");
            }
        }
    }

    /// The stack need of a small tree, counted by hand: the root holds three leaves and
    /// nodes 1 and 3; node 1 two leaves and node 2; node 2 five leaves; node 3 eight leaves.
    #[test]
    fn the_stack_need_is_the_largest_sum_down_a_path() {
        let unit = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        let leaf = 1 << super::super::OFFSET_BITS;
        let mut nodes = [Wide::<NARROW>::NONE; 4];
        let children: [(usize, &[usize]); 4] = [(3, &[1, 3]), (2, &[2]), (5, &[]), (8, &[])];
        for (node, (leaves, inner)) in nodes.iter_mut().zip(children) {
            let links = inner.iter().map(|&k| (k * NARROW / 2) as u64);
            for (lane, link) in std::iter::repeat_n(leaf, leaves).chain(links).enumerate() {
                node.set(lane, &unit, link);
            }
        }
        let lines = nodes.iter().flat_map(|n| n.lines()).copied().collect();
        // Down to node 2: 4 + 2 + 4; down to node 3: 4 + 7, and one more while pushing.
        assert_eq!(Bvh::new(lines, 0).stack, 12);
    }
}
