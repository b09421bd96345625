//! The traversal's memory accesses without bounds checks, each sound by how trees are built
//! (or checked, for cached trees): its stack and its node fetches.

use super::wide::Wide;
use super::{Bvh, LANES, MAX_DEPTH};
use std::mem::MaybeUninit;

/// A wide node pushes at most `LANES - 1` children, and no wide tree is deeper than the
/// binary one.
pub(super) const STACK: usize = (LANES - 1) * MAX_DEPTH + 1;

/// The traversal stack: links (with their entry distances for closest-hit), never read before
/// written (so not zeroed per ray, which cost a memset of the whole stack). The entries live in
/// a separate local the stack borrows: about 1.5 % fewer traversal instructions than with the
/// array beside `len` in one struct.
pub(super) struct Stack<'a, T, const N: usize = STACK> {
    entries: &'a mut [MaybeUninit<T>; N],
    /// Entries below `len` are initialised (private, so only `push` and `insert_sorted` raise
    /// it, each after writing the entry).
    len: usize,
}

/// The storage of a [`Stack`]: `STACK` entries for a whole tree, or `LANES` for a tree of one
/// node (whose traversal pushes at most one entry per lane).
#[inline(always)]
pub(super) fn stack_space<T: Copy, const N: usize>() -> [MaybeUninit<T>; N] {
    [const { MaybeUninit::uninit() }; N]
}

impl<'a, T: Copy, const N: usize> Stack<'a, T, N> {
    #[inline(always)]
    pub(super) fn new(entries: &'a mut [MaybeUninit<T>; N]) -> Self {
        Stack { entries, len: 0 }
    }

    #[inline(always)]
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Pushes an entry. The traversals keep `len < STACK` here: they push only a node's hit
    /// children, and after taking one of them hold at most `LANES - 1` entries per level above
    /// the current node; the links they follow go down the tree (an empty lane's inverted box
    /// is never hit: the loops `Bvh::closest` and `Bvh::first` trace only rays with finite
    /// coordinates, and `refit` leaves empty lanes alone), and every inner node is less than `MAX_DEPTH` deep (`collapse` keeps the
    /// binary tree's depth, and `from_words` refuses deeper cached trees along any path), so at
    /// most `(LANES - 1) * (MAX_DEPTH - 1) + LANES = STACK` entries are ever held. A stack of
    /// `N = LANES` entries serves only trees of one node: at most one push per lane.
    #[inline(always)]
    pub(super) fn push(&mut self, entry: T) {
        debug_assert!(self.len < N);
        // SAFETY: `len < N` (see above), so the slot is in bounds.
        unsafe { *self.entries.get_unchecked_mut(self.len) = MaybeUninit::new(entry) };
        self.len += 1;
    }

    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: `len` was at most `N`, so the slot is in bounds, and it is below the old
        // `len`, so it is initialised.
        Some(unsafe { self.entries.get_unchecked(self.len).assume_init() })
    }
}

impl<const N: usize> Stack<'_, (u64, f32), N> {
    /// Pushes keeping the entries above `base` (at most `len`) in decreasing order of `t`.
    #[inline(always)]
    pub(super) fn insert_sorted(&mut self, base: usize, link: u64, t: f32) {
        let mut j = self.len;
        debug_assert!(j < N && base <= j);
        // SAFETY: `len < N` as in `push`, so every slot up to `len` is in bounds; the loop
        // reads only slots `j - 1 >= base` below `len`, which are initialised, and moves them
        // up one, so slots up to the old `len` stay initialised.
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
    /// Node `i` of a link, or the root (0). The traversal loops skip the bounds check.
    #[inline(always)]
    pub(super) fn node(&self, i: usize) -> &Wide {
        debug_assert!(i < self.nodes.len());
        // SAFETY: `i` is in bounds: the traversals ask for the root only when `nodes` is not
        // empty, and otherwise for an inner node's link, which `collapse` makes and
        // `from_words` checks to be an index below `nodes.len()` (`nodes` is private to `bvh`,
        // only those two make its nodes, and `refit` changes boxes, never links).
        unsafe { self.nodes.get_unchecked(i) }
    }
}
