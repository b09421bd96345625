//! The traversal's memory accesses without bounds checks, each sound by how trees are built
//! (or checked, for cached trees): its stack and its node fetches.

use super::wide::Wide;
use super::{Bvh, LANES, MAX_DEPTH};
use std::mem::MaybeUninit;

/// A wide node pushes at most `LANES - 1` children, and no wide tree is deeper than the
/// binary one.
const STACK: usize = (LANES - 1) * MAX_DEPTH + 1;

/// The traversal stack: links (with their entry distances for closest-hit), never read before
/// written (so not zeroed per ray, which cost a memset of the whole stack). The entries live in
/// a separate local the stack borrows: about 1.5 % fewer traversal instructions than with the
/// array beside `len` in one struct.
pub(super) struct Stack<'a, T> {
    entries: &'a mut [MaybeUninit<T>; STACK],
    pub(super) len: usize,
}

/// The storage of a [`Stack`].
#[inline(always)]
pub(super) fn stack_space<T: Copy>() -> [MaybeUninit<T>; STACK] {
    [const { MaybeUninit::uninit() }; STACK]
}

impl<'a, T: Copy> Stack<'a, T> {
    #[inline(always)]
    pub(super) fn new(entries: &'a mut [MaybeUninit<T>; STACK]) -> Self {
        Stack { entries, len: 0 }
    }

    #[inline(always)]
    pub(super) fn push(&mut self, entry: T) {
        debug_assert!(self.len < STACK);
        // SAFETY: a traversal holds at most `LANES - 1` entries per level of the tree plus one,
        // and no tree is deeper than `MAX_DEPTH` (built so, and checked for cached trees).
        unsafe { *self.entries.get_unchecked_mut(self.len) = MaybeUninit::new(entry) };
        self.len += 1;
    }

    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: entries below `len` were written by `push`.
        Some(unsafe { self.entries.get_unchecked(self.len).assume_init() })
    }
}

impl Stack<'_, (u64, f32)> {
    /// Pushes keeping the entries above `base` in decreasing order of `t`.
    #[inline(always)]
    pub(super) fn insert_sorted(&mut self, base: usize, link: u64, t: f32) {
        let mut j = self.len;
        debug_assert!(j < STACK);
        // SAFETY: entries in base..len were written by `push` or here, and len stays in range
        // as in `push`.
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
    /// Node `i` of a link. Links come from `collapse` or passed `from_words`, so they are in
    /// range; the traversal loops skip the check.
    #[inline(always)]
    pub(super) fn node(&self, i: usize) -> &Wide {
        debug_assert!(i < self.nodes.len());
        // SAFETY: see above; the root (0) exists whenever a traversal starts.
        unsafe { self.nodes.get_unchecked(i) }
    }
}
