//! Bounding volume hierarchy: binned SAH build in parallel (rayon) into a binary tree, which
//! is then collapsed into 8-wide nodes (each holds its eight children's boxes side by side, so
//! one pass of vector arithmetic tests all eight: one AVX pass where the CPU has AVX, checked
//! at run time, else two SSE passes), and closure-based traversal so each primitive kind gets
//! its own monomorphised loop with the intersection test inlined.

use crate::math::{gamma, Aabb, Vec3A};
use std::mem::MaybeUninit;

/// Leaves hold at most this many primitives.
const MAX_LEAF: usize = 8;
const BINS: usize = 16;
/// Below this many primitives a subtree is built on the current thread.
const PARALLEL_CUTOFF: usize = 4096;
/// SAH cost of a node traversal relative to one primitive test.
const TRAVERSAL_COST: f32 = 1.0;
/// Past this depth splits are by median, so the depth stays bounded whatever the input.
const MAX_SAH_DEPTH: usize = 64;
/// Deepest binary tree: median splits after `MAX_SAH_DEPTH` halve at least 2^48 primitives.
const MAX_DEPTH: usize = MAX_SAH_DEPTH + 64;
/// Children per wide node.
const LANES: usize = 8;
/// A wide node pushes at most `LANES - 1` children, and no wide tree is deeper than the
/// binary one.
const STACK: usize = (LANES - 1) * MAX_DEPTH + 1;

/// A node of the binary build (and of the tree before it is collapsed).
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

    fn bounds(&self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }
}

/// A wide node: the boxes of up to `LANES` children as rows min x, min y, min z, max x, max y,
/// max z (one lane per child), and a link per child: a leaf (first primitive, count) packed as
/// in `Node`, an inner node (its index, count 0), or `EMPTY` (its box is inverted, so no ray
/// enters it). Four cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Wide {
    b: [[f32; LANES]; 6],
    link: [u64; LANES],
}

/// The root is never a child, so link 0 marks an unused slot.
const EMPTY: u64 = 0;

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
        for k in 0..3 {
            self.b[k][lane] = b.min[k];
            self.b[3 + k][lane] = b.max[k];
        }
        self.link[lane] = link;
    }

    fn bounds(&self) -> Aabb {
        (0..LANES)
            .filter(|&l| self.link[l] != EMPTY)
            .fold(Aabb::EMPTY, |acc, l| {
                acc.union(Aabb::new(
                    Vec3A::new(self.b[0][l], self.b[1][l], self.b[2][l]),
                    Vec3A::new(self.b[3][l], self.b[4][l], self.b[5][l]),
                ))
            })
    }
}

/// The lowest lane set in a non-empty hit mask (the mask has a bit per lane, so the `&` only
/// spares the bounds check).
#[inline(always)]
fn first_lane(mask: u32) -> usize {
    mask.trailing_zeros() as usize & (LANES - 1)
}

#[inline(always)]
fn count_of(link: u64) -> usize {
    ((link >> OFFSET_BITS) & 0xff) as usize
}

#[inline(always)]
fn offset_of(link: u64) -> usize {
    (link & OFFSET_MASK) as usize
}

/// What a ray precomputes for the box tests: for each axis the row of the plane it meets
/// first (min or max, by the sign of its direction) and the row of the other.
struct BoxRay {
    origin: [f32; 3],
    inv: [f32; 3],
    /// `inv` times [`WIDEN`], for the far planes.
    inv_far: [f32; 3],
    near: [usize; 3],
    far: [usize; 3],
}

/// Far-plane distances and `t_max` are widened by 2·gamma(3) so rounding never culls a box the
/// ray really touches (Ize 2013). The far planes get it through their reciprocals: as many
/// roundings as widening each result, and a multiply less on the path from one node to the next.
const WIDEN: f32 = 1.0 + 2.0 * gamma(3);

impl BoxRay {
    #[inline(always)]
    fn new(origin: Vec3A, dir: Vec3A) -> BoxRay {
        let inv: [f32; 3] = dir.recip().into();
        let neg = inv.map(|x| usize::from(x < 0.0) * 3);
        BoxRay {
            origin: origin.into(),
            inv,
            inv_far: inv.map(|x| x * WIDEN),
            near: [neg[0], 1 + neg[1], 2 + neg[2]],
            far: [3 - neg[0], 4 - neg[1], 5 - neg[2]],
        }
    }

    /// Which of the node's boxes the ray meets in [0, t_max] (bit l for lane l), and the entry
    /// distances. Slab distances 0 · ∞ (a ray parallel to a face and lying in its plane,
    /// which is inside that slab for every t) are NaN and are skipped: max(t, acc) and
    /// min(t, acc) keep `acc` when t is NaN (x86's maxps/minps return the second operand).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn enter(&self, node: &Wide, t_max: f32) -> (u32, [f32; LANES]) {
        use std::arch::x86_64::*;
        let mut t = [0.0; LANES];
        let mut mask = 0;
        for h in 0..LANES / 4 {
            // SAFETY: SSE is part of the x86_64 baseline; each load reads four floats of a row.
            unsafe {
                let row = |r: usize| _mm_loadu_ps(node.b[r].as_ptr().add(4 * h));
                let mut near = _mm_setzero_ps();
                let mut far = _mm_set1_ps(t_max * WIDEN);
                for k in 0..3 {
                    let o = _mm_set1_ps(self.origin[k]);
                    let inv = _mm_set1_ps(self.inv[k]);
                    let inv_far = _mm_set1_ps(self.inv_far[k]);
                    let t0 = _mm_mul_ps(_mm_sub_ps(row(self.near[k]), o), inv);
                    let t1 = _mm_mul_ps(_mm_sub_ps(row(self.far[k]), o), inv_far);
                    near = _mm_max_ps(t0, near);
                    far = _mm_min_ps(t1, far);
                }
                let hit = _mm_cmple_ps(near, far);
                _mm_storeu_ps(t.as_mut_ptr().add(4 * h), near);
                mask |= (_mm_movemask_ps(hit) as u32) << (4 * h);
            }
        }
        (mask, t)
    }

    /// The same with AVX: all eight lanes in one pass (bitwise the same results).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline]
    fn enter_avx(&self, node: &Wide, t_max: f32) -> (u32, [f32; LANES]) {
        use std::arch::x86_64::*;
        let row = |r: usize| {
            // SAFETY: reads one row of eight floats.
            unsafe { _mm256_loadu_ps(node.b[r].as_ptr()) }
        };
        let mut near = _mm256_setzero_ps();
        let mut far = _mm256_set1_ps(t_max * WIDEN);
        for k in 0..3 {
            let o = _mm256_set1_ps(self.origin[k]);
            let inv = _mm256_set1_ps(self.inv[k]);
            let inv_far = _mm256_set1_ps(self.inv_far[k]);
            let t0 = _mm256_mul_ps(_mm256_sub_ps(row(self.near[k]), o), inv);
            let t1 = _mm256_mul_ps(_mm256_sub_ps(row(self.far[k]), o), inv_far);
            near = _mm256_max_ps(t0, near);
            far = _mm256_min_ps(t1, far);
        }
        let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(near, far);
        let mut t = [0.0; LANES];
        // SAFETY: writes eight floats.
        unsafe { _mm256_storeu_ps(t.as_mut_ptr(), near) };
        (_mm256_movemask_ps(hit) as u32, t)
    }

    /// The box test of the traversal compiled for `avx` (see `Bvh::intersect`).
    #[inline(always)]
    fn enter_with<const AVX: bool>(&self, node: &Wide, t_max: f32) -> (u32, [f32; LANES]) {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: only the AVX instantiations call this, after checking the CPU.
            return unsafe { self.enter_avx(node, t_max) };
        }
        self.enter(node, t_max)
    }

    /// The same, lane by lane, for other targets.
    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    fn enter(&self, node: &Wide, t_max: f32) -> (u32, [f32; LANES]) {
        let mut near = [0.0f32; LANES];
        let mut far = [t_max * WIDEN; LANES];
        for k in 0..3 {
            let (lo, hi) = (&node.b[self.near[k]], &node.b[self.far[k]]);
            for l in 0..LANES {
                let t0 = (lo[l] - self.origin[k]) * self.inv[k];
                let t1 = (hi[l] - self.origin[k]) * self.inv_far[k];
                near[l] = if t0 > near[l] { t0 } else { near[l] };
                far[l] = if t1 < far[l] { t1 } else { far[l] };
            }
        }
        let mask = (0..LANES).fold(0, |m, l| m | u32::from(near[l] <= far[l]) << l);
        (mask, near)
    }
}

/// Whether this CPU has AVX (8-wide box tests); the check is a cached load.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx() -> bool {
    std::arch::is_x86_feature_detected!("avx")
}

/// The traversal stack: links (with their entry distances for closest-hit), never read before
/// written (so not zeroed per ray, which cost a memset of the whole stack). The entries live in
/// a separate local the stack borrows: about 1.5 % fewer traversal instructions than with the
/// array beside `len` in one struct.
struct Stack<'a, T> {
    entries: &'a mut [MaybeUninit<T>; STACK],
    len: usize,
}

/// The storage of a [`Stack`].
#[inline(always)]
fn stack_space<T: Copy>() -> [MaybeUninit<T>; STACK] {
    [const { MaybeUninit::uninit() }; STACK]
}

impl<'a, T: Copy> Stack<'a, T> {
    #[inline(always)]
    fn new(entries: &'a mut [MaybeUninit<T>; STACK]) -> Self {
        Stack { entries, len: 0 }
    }

    #[inline(always)]
    fn push(&mut self, entry: T) {
        debug_assert!(self.len < STACK);
        // SAFETY: a traversal holds at most `LANES - 1` entries per level of the tree plus one,
        // and no tree is deeper than `MAX_DEPTH` (built so, and checked for cached trees).
        unsafe { *self.entries.get_unchecked_mut(self.len) = MaybeUninit::new(entry) };
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<T> {
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
    fn insert_sorted(&mut self, base: usize, link: u64, t: f32) {
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

/// A BVH over primitives `0..n`. After building, primitive `order[i]` is the i-th in leaf order;
/// owners reorder their arrays by `order` so leaves address contiguous ranges.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// Wide nodes depth first: a node's inner children come after it; the root is first.
    nodes: Vec<Wide>,
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
    fn new(b: Aabb, index: usize) -> BuildPrim {
        BuildPrim {
            min: b.min.into(),
            max: b.max.into(),
            index: index as u64,
        }
    }

    #[inline(always)]
    fn bounds(&self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }

    #[inline(always)]
    fn centroid(&self, axis: usize) -> f32 {
        (self.min[axis] + self.max[axis]) * 0.5
    }
}

/// Words per wide node in `to_words`: the box rows, then a link of two words per lane.
const WORDS: usize = 8 * LANES;
/// Where the links start among a node's words.
const LINK_WORDS: usize = 6 * LANES;

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
            .map(|i| BuildPrim::new(bound(i), i))
            .collect();
        let mut binary = Vec::new();
        build_node(&mut prims, 0, 0, &mut binary);
        let order = prims.iter().map(|p| p.index).collect();
        drop(prims);
        (Bvh::collapse(&binary), order)
    }

    /// The wide tree of a binary one: each wide node takes the two children of a binary node
    /// and keeps opening the largest inner one among them until it has `LANES`.
    fn collapse(binary: &[Node]) -> Bvh {
        let mut nodes = Vec::with_capacity(binary.len() / 3 + 1);
        if binary[0].count() > 0 {
            let mut root = Wide::NONE;
            root.set(0, &binary[0].bounds(), binary[0].link);
            nodes.push(root);
        } else {
            collapse_node(binary, 0, &mut nodes);
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
                if link != EMPTY && count == 0 {
                    depth[offset] = depth[i] + 1;
                }
            }
            nodes.push(node);
        }
        Some(Bvh { nodes })
    }

    /// Node `i` of a link. Links come from `collapse` or passed `from_words`, so they are in
    /// range; the traversal loops skip the check.
    #[inline(always)]
    fn node(&self, i: usize) -> &Wide {
        debug_assert!(i < self.nodes.len());
        // SAFETY: see above; the root (0) exists whenever a traversal starts.
        unsafe { self.nodes.get_unchecked(i) }
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn bounds(&self) -> Aabb {
        match self.nodes.first() {
            Some(n) => n.bounds(),
            None => Aabb::EMPTY,
        }
    }

    /// Closest-hit traversal. `test(prim, t_max)` returns `Some(t)` for a hit closer than
    /// `t_max` (and records whatever it needs). Returns the final `t_max`.
    // Only this dispatch is inlined; the loops (`intersect_avx`, `intersect_base`) are not, or
    // their 14 KB stack would sit in every frame of the recursive integrator, and deep
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
        #[cfg(target_arch = "x86_64")]
        if avx() {
            // SAFETY: the CPU has AVX.
            return unsafe { self.intersect_avx(origin, dir, t_max, test) };
        }
        self.intersect_base(origin, dir, t_max, test)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    fn intersect_avx<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest::<true, F>(origin, dir, t_max, test)
    }

    #[inline(never)]
    fn intersect_base<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest::<false, F>(origin, dir, t_max, test)
    }

    #[inline(always)]
    fn closest<const AVX: bool, F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        mut t_max: f32,
        mut test: F,
    ) -> f32 {
        if self.nodes.is_empty() {
            return t_max;
        }
        let ray = BoxRay::new(origin, dir);
        let mut space = stack_space::<(u64, f32)>();
        let mut stack = Stack::new(&mut space);
        let mut i = 0usize;
        loop {
            let node = self.node(i);
            let (mut mask, t) = ray.enter_with::<AVX>(node, t_max);
            if mask.is_power_of_two() {
                // One child hit: enter or test it without going through the stack.
                let link = node.link[first_lane(mask)];
                let count = count_of(link);
                if count == 0 {
                    i = offset_of(link);
                    continue;
                }
                let start = offset_of(link);
                for p in start..start + count {
                    if let Some(t) = test(p, t_max) {
                        t_max = t;
                    }
                }
            } else {
                // Push the children hit, nearest last so it is taken first.
                let base = stack.len;
                while mask != 0 {
                    let l = first_lane(mask);
                    mask &= mask - 1;
                    stack.insert_sorted(base, node.link[l], t[l]);
                }
            }
            // Next: the nearest pending child still nearer than the closest hit; leaves are
            // tested as they come off the stack.
            loop {
                let Some((link, t)) = stack.pop() else {
                    return t_max;
                };
                if t > t_max {
                    continue;
                }
                let count = count_of(link);
                if count == 0 {
                    i = offset_of(link);
                    break;
                }
                let start = offset_of(link);
                for p in start..start + count {
                    if let Some(t) = test(p, t_max) {
                        t_max = t;
                    }
                }
            }
        }
    }

    /// Any-hit traversal: stops as soon as `test(prim)` returns true.
    #[inline]
    pub fn any<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        #[cfg(target_arch = "x86_64")]
        if avx() {
            // SAFETY: the CPU has AVX.
            return unsafe { self.any_avx(origin, dir, t_max, test) };
        }
        self.any_base(origin, dir, t_max, test)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    fn any_avx<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        self.first::<true, F>(origin, dir, t_max, test)
    }

    #[inline(never)]
    fn any_base<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        self.first::<false, F>(origin, dir, t_max, test)
    }

    #[inline(always)]
    fn first<const AVX: bool, F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        mut test: F,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let ray = BoxRay::new(origin, dir);
        let mut space = stack_space::<u64>();
        let mut stack = Stack::new(&mut space);
        // The root (an inner node, or the wide node holding a lone leaf).
        let mut link = 0u64;
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
                let node = self.node(offset_of(link));
                let (mut mask, _) = ray.enter_with::<AVX>(node, t_max);
                if mask != 0 {
                    // The last child hit is taken now, the others pushed (so the order is
                    // the stack's, whatever the count). It is found by a loop of branches,
                    // not by counting the mask's leading zeros: shadow rays of neighbouring
                    // pixels take the same path, so the CPU predicts the lane and loads the
                    // next node before the box test has finished (8 % faster shadow rays).
                    let mut last = LANES - 1;
                    while mask & (1 << last) == 0 {
                        last -= 1;
                    }
                    mask &= !(1 << last);
                    while mask != 0 {
                        stack.push(node.link[first_lane(mask)]);
                        mask &= mask - 1;
                    }
                    link = node.link[last & (LANES - 1)];
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

/// Emits the wide node for binary inner node `i` and, after it, its inner descendants;
/// returns its index.
fn collapse_node(binary: &[Node], i: usize, out: &mut Vec<Wide>) -> usize {
    let index = out.len();
    out.push(Wide::NONE);
    let (kids, len) = open_kids(binary, i);
    for (lane, &k) in kids[..len].iter().enumerate() {
        let link = if binary[k].count() > 0 {
            leaf_link(&binary[k])
        } else {
            collapse_node(binary, k, out) as u64
        };
        out[index].set(lane, &binary[k].bounds(), link);
    }
    index
}

/// Builds the subtree over `prims` (the primitives `start..start + prims.len()` of the final
/// order) depth-first into `out`: its root is the node pushed first, a node's first child
/// follows it.
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
    // Clamped first (max maps NaN to 0), so the cheap truncating conversion is exact; Rust's
    // saturating `as` cost a fifth of the build.
    let x: [f32; 3] = ((c - lo) * scale)
        .max(Vec3A::ZERO)
        .min(Vec3A::splat((bins - 1) as f32))
        .into();
    // SAFETY: each x is finite and in [0, bins - 1].
    x.map(|x| unsafe { x.to_int_unchecked::<u32>() } as usize)
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
            let cost = acc.half_area() * cnt as f32 + right_area[i] * right_count[i] as f32;
            if cost < best.0 {
                best = (cost, i, a);
            }
        }
    }
    best
}

fn build_node(prims: &mut [BuildPrim], start: usize, depth: usize, out: &mut Vec<Node>) {
    let (bounds, cb) = summarize(prims);
    let n = prims.len();
    if n <= 2 {
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
        return split_middle(prims, start, bounds, axis, n, depth, out);
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
        best_split::<4>(prims, lo, scale, bins, axis)
    } else if n <= 8 {
        best_split::<8>(prims, lo, scale, bins, axis)
    } else {
        best_split::<BINS>(prims, lo, scale, bins, axis)
    };
    let axis = best.2;
    let leaf_cost = n as f32;
    let split_cost = TRAVERSAL_COST + best.0 / bounds.half_area().max(f32::MIN_POSITIVE);
    if best.1 == 0 || (n <= MAX_LEAF && leaf_cost <= split_cost) {
        if n <= MAX_LEAF {
            return leaf(out, bounds, start, n);
        }
        return split_middle(prims, start, bounds, axis, n, depth, out);
    }
    let mid = partition(prims, |p| {
        bin_of(p.bounds().centroid(), lo, scale, bins)[axis] < best.1
    });
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

    impl Bvh {
        fn leaf_sizes(&self) -> impl Iterator<Item = usize> + '_ {
            self.nodes
                .iter()
                .flat_map(|n| n.link)
                .filter(|&l| l != EMPTY)
                .map(count_of)
                .filter(|&c| c > 0)
        }
    }

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
                for base in [false, true] {
                    let mut called = false;
                    let test = |_, _| {
                        called = true;
                        None
                    };
                    if base {
                        bvh.intersect_base(o, d, f32::INFINITY, test);
                    } else {
                        bvh.intersect(o, d, f32::INFINITY, test);
                    }
                    assert!(called, "closest-hit skipped {b:?} for {o} {d}");
                }
                assert!(
                    bvh.any(o, d, f32::INFINITY, |_| true),
                    "any-hit skipped {b:?}"
                );
                assert!(
                    bvh.any_base(o, d, f32::INFINITY, |_| true),
                    "baseline any-hit skipped {b:?}"
                );
            }
            // Parallel, in neither face's plane and outside: culled.
            let o = Vec3A::new(-1.0, 2.0, 0.5);
            assert!(!bvh.any(o, Vec3A::X, f32::INFINITY, |_| true));
            assert!(!bvh.any_base(o, Vec3A::X, f32::INFINITY, |_| true));
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
            let test =
                |p: usize, tmax: f32| hit_box(&b[order[p] as usize], o, d).filter(|&t| t < tmax);
            // The dispatched traversal (AVX where the CPU has it) and the baseline one.
            assert_eq!(bvh.intersect(o, d, f32::INFINITY, test), brute, "ray {k}");
            assert_eq!(
                bvh.intersect_base(o, d, f32::INFINITY, test),
                brute,
                "ray {k}"
            );
        }
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
        build_node(&mut prims, 0, 0, &mut binary);
        assert_eq!(binary[0].axis(), 1, "the root splits across the rows");
        for child in [1, binary[0].offset()] {
            let b = binary[child].bounds();
            assert!(b.max.y - b.min.y <= 1.0, "one row per side: {b:?}");
        }
    }

    /// The AVX and baseline traversals open the same boxes in the same order, rays parallel to
    /// the axes (NaN slab distances) included.
    #[test]
    fn every_traversal_visits_the_same_leaves() {
        let b = boxes(5000);
        let (bvh, _) = Bvh::build(&b);
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
            let visits = |base: bool| {
                let mut seen = Vec::new();
                let test = |p: usize, _| {
                    seen.push(p);
                    None
                };
                if base {
                    bvh.intersect_base(o, d, 1e3, test);
                } else {
                    bvh.intersect(o, d, 1e3, test);
                }
                seen
            };
            let v = visits(false);
            assert_eq!(v, visits(true), "ray {k}");
            tested += v.len();
            let leaves = |base: bool| {
                let mut seen = Vec::new();
                let test = |p: usize| {
                    seen.push(p);
                    false
                };
                if base {
                    bvh.any_base(o, d, 1e3, test);
                } else {
                    bvh.any(o, d, 1e3, test);
                }
                seen
            };
            assert_eq!(leaves(false), leaves(true), "ray {k}");
        }
        assert!(
            tested > 500,
            "the rays should meet many boxes, met {tested}"
        );
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
        assert!(bvh.leaf_sizes().all(|c| c <= MAX_LEAF));
        assert_eq!(bvh.leaf_sizes().sum::<usize>(), 100);
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

    #[test]
    fn a_single_leaf_tree_is_traversed() {
        let b = boxes(3);
        let (bvh, _) = Bvh::build(&b);
        assert_eq!(bvh.nodes.len(), 1);
        let o = b[0].centroid() - Vec3A::new(0.0, 0.0, 10.0);
        assert!(bvh.any(o, Vec3A::Z, f32::INFINITY, |_| true));
    }
}
