//! The vector arithmetic that needs `unsafe`: the box tests of a wide node (SSE, AVX or
//! AVX-512 intrinsics, a portable loop on other targets), running the traversal loops compiled
//! for the widest instruction set the CPU has, and the unchecked float-to-index conversion of
//! the build's binning.

use super::stack::{stack_space, SMALL_STACK};
use super::wide::Wide;
use super::{Bvh, NARROW, WIDEST};
use crate::math::{gamma, Vec3A};

/// The instruction sets a traversal loop is compiled for (`level()` says which this CPU has).
pub(super) const BASE: u8 = 0;
pub(super) const AVX: u8 = 1;
pub(super) const AVX512: u8 = 2;

/// The widest box tests this CPU has; the checks are cached loads.
pub(super) fn level() -> u8 {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            return AVX512;
        }
        if std::arch::is_x86_feature_detected!("avx") {
            return AVX;
        }
    }
    BASE
}

/// What a ray precomputes for the box tests: for each axis the row of the plane it meets
/// first (min or max, by the sign of its direction) and the row of the other.
pub(super) struct BoxRay {
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
    pub(super) fn new(origin: Vec3A, dir: Vec3A) -> BoxRay {
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
    /// distances, with the instructions of `LEVEL`: one AVX-512 pass for a 16-wide node, else
    /// passes of eight lanes (AVX) or four (SSE). Slab distances 0 · ∞ (a ray parallel to a
    /// face and lying in its plane, which is inside that slab for every t) are NaN and are
    /// skipped: max(t, acc) and min(t, acc) keep `acc` when t is NaN (x86's maxps/minps return
    /// the second operand). Every instruction set gives bitwise the same results.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn enter<const LEVEL: u8, const W: usize>(
        &self,
        node: &Wide<W>,
        t_max: f32,
    ) -> (u32, [f32; W]) {
        let mut t = [0.0; W];
        if LEVEL == AVX512 && W == 16 {
            debug_assert!(level() == AVX512);
            // SAFETY: the CPU has AVX-512F: loops with `LEVEL == AVX512` run only from
            // `intersect_avx512` and `any_avx512`, which the dispatch below calls only when
            // `Bvh::level` (this CPU's `level()`) says so.
            let mask = unsafe { self.pass16(node, t_max, &mut t) };
            return (mask, t);
        }
        let mut mask = 0;
        if LEVEL >= AVX {
            debug_assert!(level() >= AVX);
            for h in 0..W / 8 {
                // SAFETY: the CPU has AVX: loops with `LEVEL >= AVX` run only from the
                // `_avx` and `_avx512` functions, called only on such CPUs (as above).
                mask |= unsafe { self.pass8(node, 8 * h, t_max, &mut t) } << (8 * h);
            }
        } else {
            for h in 0..W / 4 {
                mask |= self.pass4(node, 4 * h, t_max, &mut t) << (4 * h);
            }
        }
        (mask, t)
    }

    /// Lanes `lane..lane + 4` with SSE; their entry distances go to `t`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn pass4<const W: usize>(
        &self,
        node: &Wide<W>,
        lane: usize,
        t_max: f32,
        t: &mut [f32; W],
    ) -> u32 {
        use std::arch::x86_64::*;
        let row = |r: usize| {
            let row = &node.b[r][lane..lane + 4];
            // SAFETY: `row` holds four floats; SSE is part of the x86_64 baseline.
            unsafe { _mm_loadu_ps(row.as_ptr()) }
        };
        // SAFETY: SSE is part of the x86_64 baseline.
        unsafe {
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
            _mm_storeu_ps(t[lane..lane + 4].as_mut_ptr(), near);
            _mm_movemask_ps(_mm_cmple_ps(near, far)) as u32
        }
    }

    /// Lanes `lane..lane + 8` with AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline]
    fn pass8<const W: usize>(
        &self,
        node: &Wide<W>,
        lane: usize,
        t_max: f32,
        t: &mut [f32; W],
    ) -> u32 {
        use std::arch::x86_64::*;
        let row = |r: usize| {
            let row = &node.b[r][lane..lane + 8];
            // SAFETY: `row` holds eight floats, and this function runs with AVX enabled.
            unsafe { _mm256_loadu_ps(row.as_ptr()) }
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
        // SAFETY: the slice holds eight floats.
        unsafe { _mm256_storeu_ps(t[lane..lane + 8].as_mut_ptr(), near) };
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32
    }

    /// All sixteen lanes of a 16-wide node with AVX-512.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    #[inline]
    fn pass16<const W: usize>(&self, node: &Wide<W>, t_max: f32, t: &mut [f32; W]) -> u32 {
        use std::arch::x86_64::*;
        let row = |r: usize| {
            let row = &node.b[r][..16];
            // SAFETY: `row` holds sixteen floats, and this function runs with AVX-512F enabled.
            unsafe { _mm512_loadu_ps(row.as_ptr()) }
        };
        let mut near = _mm512_setzero_ps();
        let mut far = _mm512_set1_ps(t_max * WIDEN);
        for k in 0..3 {
            let o = _mm512_set1_ps(self.origin[k]);
            let inv = _mm512_set1_ps(self.inv[k]);
            let inv_far = _mm512_set1_ps(self.inv_far[k]);
            let t0 = _mm512_mul_ps(_mm512_sub_ps(row(self.near[k]), o), inv);
            let t1 = _mm512_mul_ps(_mm512_sub_ps(row(self.far[k]), o), inv_far);
            near = _mm512_max_ps(t0, near);
            far = _mm512_min_ps(t1, far);
        }
        // SAFETY: the slice holds sixteen floats.
        unsafe { _mm512_storeu_ps(t[..16].as_mut_ptr(), near) };
        u32::from(_mm512_cmp_ps_mask::<_CMP_LE_OQ>(near, far))
    }

    /// The same, lane by lane, for other targets.
    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    pub(super) fn enter<const LEVEL: u8, const W: usize>(
        &self,
        node: &Wide<W>,
        t_max: f32,
    ) -> (u32, [f32; W]) {
        let mut near = [0.0f32; W];
        let mut far = [t_max * WIDEN; W];
        for k in 0..3 {
            let (lo, hi) = (&node.b[self.near[k]], &node.b[self.far[k]]);
            for l in 0..W {
                let t0 = (lo[l] - self.origin[k]) * self.inv[k];
                let t1 = (hi[l] - self.origin[k]) * self.inv_far[k];
                near[l] = if t0 > near[l] { t0 } else { near[l] };
                far[l] = if t1 < far[l] { t1 } else { far[l] };
            }
        }
        let mask = (0..W).fold(0, |m, l| m | u32::from(near[l] <= far[l]) << l);
        (mask, near)
    }
}

/// The lanes of `v` clamped to `[0, max]` (NaN to 0) and truncated to indices. Clamped with
/// SSE first, so the cheap truncating conversion is exact; Rust's saturating `as` cost a fifth
/// of the BVH build.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) fn clamped_index(v: Vec3A, max: u8) -> [usize; 3] {
    use std::arch::x86_64::*;
    // `maxps` returns its second operand when either is NaN (Intel's definition; glam's `max`
    // does not promise it on every target), so NaN lanes become 0 here.
    // SAFETY: SSE is part of the x86_64 baseline.
    let clamped = unsafe {
        _mm_min_ps(
            _mm_max_ps(v.into(), _mm_setzero_ps()),
            _mm_set1_ps(f32::from(max)),
        )
    };
    let x: [f32; 3] = Vec3A::from(clamped).into();
    // SAFETY: each x is in [0, max] with max <= 255 (no NaN, see above), so its truncation is
    // representable in a u32.
    x.map(|x| unsafe { x.to_int_unchecked::<u32>() } as usize)
}

/// The same with Rust's saturating conversion, which maps NaN to 0, on other targets.
#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
pub(super) fn clamped_index(v: Vec3A, max: u8) -> [usize; 3] {
    let x: [f32; 3] = v.into();
    x.map(|x| x.max(0.0).min(f32::from(max)) as usize)
}

/// The traversal loops a tree gets: compiled for the widest instruction set this CPU has, one
/// loop per function and per width of tree (a function holding the loops of both widths was
/// twice the code, and its 8-wide path 5–8 % slower in a render), so trees without 16-wide
/// nodes get loops that never look for one; `Deep` for trees whose stack does not fit the
/// frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) enum Loops {
    #[default]
    Base8,
    Base16,
    Avx8,
    Avx16,
    Avx512,
    Deep,
}

impl Loops {
    /// The loops for a tree with or without 16-wide nodes whose traversal needs `stack`
    /// entries, on this CPU. The `Avx` loops are chosen only here, and only when the CPU has
    /// the instructions they are compiled for.
    pub(super) fn choose(wide: bool, stack: usize) -> Loops {
        match (level(), wide) {
            _ if stack > SMALL_STACK => Loops::Deep,
            (AVX512, true) => Loops::Avx512,
            (AVX512 | AVX, false) => Loops::Avx8,
            (AVX, true) => Loops::Avx16,
            (_, true) => Loops::Base16,
            (_, false) => Loops::Base8,
        }
    }
}

/// Each traversal through the loops its tree got ([`Loops`]).
impl Bvh {
    #[inline(always)]
    pub(super) fn intersect_dispatch<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        match self.loops {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX-512F (`Loops::choose`, the only maker of `Avx512`).
            Loops::Avx512 => unsafe { self.intersect_avx512(origin, dir, t_max, test) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX (`Loops::choose`, the only maker of `Avx8`).
            Loops::Avx8 => unsafe { self.intersect_avx::<NARROW, F>(origin, dir, t_max, test) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX (`Loops::choose`, the only maker of `Avx16`).
            Loops::Avx16 => unsafe { self.intersect_avx::<WIDEST, F>(origin, dir, t_max, test) },
            Loops::Deep => self.intersect_deep(origin, dir, t_max, test),
            Loops::Base16 => self.intersect_base::<WIDEST, F>(origin, dir, t_max, test),
            _ => self.intersect_base::<NARROW, F>(origin, dir, t_max, test),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    #[inline(never)]
    fn intersect_avx512<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest::<AVX512, WIDEST, F>(origin, dir, t_max, test, &mut stack_space())
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    fn intersect_avx<const MAXW: usize, F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest::<AVX, MAXW, F>(origin, dir, t_max, test, &mut stack_space())
    }

    #[inline(always)]
    pub(super) fn any_dispatch<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        match self.loops {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX-512F (`Loops::choose`, the only maker of `Avx512`).
            Loops::Avx512 => unsafe { self.any_avx512(origin, dir, t_max, test) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX (`Loops::choose`, the only maker of `Avx8`).
            Loops::Avx8 => unsafe { self.any_avx::<NARROW, F>(origin, dir, t_max, test) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the CPU has AVX (`Loops::choose`, the only maker of `Avx16`).
            Loops::Avx16 => unsafe { self.any_avx::<WIDEST, F>(origin, dir, t_max, test) },
            Loops::Deep => self.any_deep(origin, dir, t_max, test),
            Loops::Base16 => self.any_base::<WIDEST, F>(origin, dir, t_max, test),
            _ => self.any_base::<NARROW, F>(origin, dir, t_max, test),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    #[inline(never)]
    fn any_avx512<F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        self.first::<AVX512, WIDEST, F>(origin, dir, t_max, test, &mut stack_space())
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    fn any_avx<const MAXW: usize, F: FnMut(usize) -> bool>(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        test: F,
    ) -> bool {
        self.first::<AVX, MAXW, F>(origin, dir, t_max, test, &mut stack_space())
    }
}

/// Every traversal loop of a tree, for the tests of `traversal`.
#[cfg(test)]
pub(super) mod tests {
    use super::*;

    pub(in super::super) type Closest<'a> =
        Box<dyn Fn(Vec3A, Vec3A, f32, &mut dyn FnMut(usize, f32) -> Option<f32>) -> f32 + 'a>;
    pub(in super::super) type AnyHit<'a> =
        Box<dyn Fn(Vec3A, Vec3A, f32, &mut dyn FnMut(usize) -> bool) -> bool + 'a>;

    impl Bvh {
        /// Every traversal loop this CPU can run on this tree: (name, closest hit, any hit);
        /// the AVX-512 loop and the deep one on trees of either width.
        pub(in super::super) fn loops(&self) -> Vec<(&'static str, Closest<'_>, AnyHit<'_>)> {
            let mut v = if self.stack > SMALL_STACK {
                // The others' stacks are too small for the tree.
                Vec::new()
            } else if self.node_counts().1 > 0 {
                self.loops_of::<WIDEST>()
            } else {
                self.loops_of::<NARROW>()
            };
            v.push((
                "deep",
                Box::new(|o, d, t, f| self.intersect_deep(o, d, t, f)),
                Box::new(|o, d, t, f| self.any_deep(o, d, t, f)),
            ));
            v
        }

        fn loops_of<const W: usize>(&self) -> Vec<(&'static str, Closest<'_>, AnyHit<'_>)> {
            let mut v: Vec<(&'static str, Closest<'_>, AnyHit<'_>)> = vec![(
                "base",
                Box::new(|o, d, t, f| self.intersect_base::<W, _>(o, d, t, f)),
                Box::new(|o, d, t, f| self.any_base::<W, _>(o, d, t, f)),
            )];
            #[cfg(target_arch = "x86_64")]
            {
                if level() >= AVX {
                    v.push((
                        "avx",
                        // SAFETY: the CPU has AVX (just checked).
                        Box::new(|o, d, t, f| unsafe { self.intersect_avx::<W, _>(o, d, t, f) }),
                        // SAFETY: as above.
                        Box::new(|o, d, t, f| unsafe { self.any_avx::<W, _>(o, d, t, f) }),
                    ));
                }
                if level() >= AVX512 {
                    v.push((
                        "avx512",
                        // SAFETY: the CPU has AVX-512F (just checked).
                        Box::new(|o, d, t, f| unsafe { self.intersect_avx512(o, d, t, f) }),
                        // SAFETY: as above.
                        Box::new(|o, d, t, f| unsafe { self.any_avx512(o, d, t, f) }),
                    ));
                }
            }
            v
        }
    }
}
