//! The vector arithmetic that needs `unsafe`: the box tests of a wide node (SSE or AVX
//! intrinsics, a portable loop on other targets), running the traversal loops compiled for AVX
//! when the CPU has it, and the unchecked float-to-index conversion of the build's binning.

use super::wide::Wide;
use super::{Bvh, LANES};
use crate::math::{gamma, Vec3A};

/// What a ray precomputes for the box tests, once for every tree it is traced through (a few
/// vector instructions, stored in three vectors and a mask).
pub struct BoxRay {
    origin: Vec3A,
    inv: Vec3A,
    /// `inv` times [`WIDEN`], for the far planes.
    inv_far: Vec3A,
    /// Bit k: the direction is negative along axis k (it meets the box's max plane first).
    neg: u32,
    /// All coordinates finite. Other rays meet nothing: a NaN (from a zero-length direction,
    /// say) or an infinity makes the box tests enter empty lanes too, whose link is the
    /// root's, so their traversal would never end (and would overrun its stack).
    finite: bool,
}

/// Far-plane distances and `t_max` are widened by 2·gamma(3) so rounding never culls a box the
/// ray really touches (Ize 2013). The far planes get it through their reciprocals: as many
/// roundings as widening each result, and a multiply less on the path from one node to the next.
const WIDEN: f32 = 1.0 + 2.0 * gamma(3);

/// Whether a ray's coordinates are all finite.
#[inline(always)]
#[allow(clippy::eq_op)] // x - x on purpose (below)
fn finite(origin: Vec3A, dir: Vec3A) -> bool {
    // x - x is 0 for finite x and NaN for the others (fewer instructions than glam's
    // `is_finite`, which masks the sign bits and compares with infinity).
    ((origin - origin) + (dir - dir)).cmpeq(Vec3A::ZERO).all()
}

impl BoxRay {
    #[inline(always)]
    pub fn new(origin: Vec3A, dir: Vec3A) -> BoxRay {
        let inv = dir.recip();
        BoxRay {
            origin,
            inv,
            inv_far: inv * WIDEN,
            neg: inv.cmplt(Vec3A::ZERO).bitmask(),
            finite: finite(origin, dir),
        }
    }

    #[inline(always)]
    pub(crate) fn finite(&self) -> bool {
        self.finite
    }

    /// The box tests' operands, made at the start of each traversal.
    #[inline(always)]
    pub(super) fn slabs(&self) -> Slabs {
        // Row k (min) or 3 + k (max) per axis: looked up by the signs, not worked out (a
        // dozen instructions less per traversal).
        const ROWS: [([usize; 3], [usize; 3]); 8] = {
            let mut rows = [([0; 3], [0; 3]); 8];
            let mut neg = 0;
            while neg < 8 {
                let mut k = 0;
                while k < 3 {
                    let n = (neg >> k) & 1;
                    rows[neg].0[k] = k + 3 * n;
                    rows[neg].1[k] = k + 3 - 3 * n;
                    k += 1;
                }
                neg += 1;
            }
            rows
        };
        let (near, far) = ROWS[self.neg as usize & 7];
        Slabs {
            origin: self.origin.into(),
            inv: self.inv.into(),
            inv_far: self.inv_far.into(),
            near,
            far,
        }
    }
}

/// A [`BoxRay`] as one traversal's box tests read it: per axis the row of the plane the ray
/// meets first (min or max, by the sign of its direction) and the row of the other, resolved
/// once, not at every node.
pub(super) struct Slabs {
    origin: [f32; 3],
    inv: [f32; 3],
    inv_far: [f32; 3],
    near: [usize; 3],
    far: [usize; 3],
}

impl Slabs {
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
            // SAFETY: SSE is part of the x86_64 baseline. Each row of `node.b` and `t` hold
            // `LANES` = 8 floats and h < 2, so the four floats at `4 * h` are in bounds.
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
            // SAFETY: a row of `node.b` holds `LANES` = 8 floats (`r` itself is bounds-checked),
            // and this function only runs with AVX enabled.
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
        // SAFETY: `t` holds `LANES` = 8 floats.
        unsafe { _mm256_storeu_ps(t.as_mut_ptr(), near) };
        (_mm256_movemask_ps(hit) as u32, t)
    }

    /// The box test of the traversal compiled for `avx` (see `Bvh::intersect`).
    #[inline(always)]
    pub(super) fn enter_with<const AVX: bool>(
        &self,
        node: &Wide,
        t_max: f32,
    ) -> (u32, [f32; LANES]) {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            debug_assert!(avx());
            // SAFETY: the CPU has AVX: `AVX` is true only in the loops the `_avx` functions
            // below instantiate, which run only after `avx()` said so (the `_dispatch`
            // functions); nothing else in `bvh` passes `true`.
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

/// The traversal loops (`Bvh::closest` and `Bvh::first`, or their one-node forms) compiled
/// for AVX where the CPU has it, else for the baseline. Each loop is a function of its own, so
/// only the deep ones reserve the deep stack.
impl Bvh {
    #[inline(always)]
    pub(super) fn intersect_dispatch<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        ray: &BoxRay,
        t_max: f32,
        test: F,
    ) -> f32 {
        let flat = self.is_flat();
        #[cfg(target_arch = "x86_64")]
        if avx() {
            // SAFETY: the CPU has AVX (just checked), the feature these loops are built for.
            return unsafe {
                if flat {
                    self.closest_flat_avx(ray, t_max, test)
                } else {
                    self.closest_avx(ray, t_max, test)
                }
            };
        }
        if flat {
            self.closest_flat::<false, F>(ray, t_max, test)
        } else {
            self.closest_base(ray, t_max, test)
        }
    }

    #[inline(never)]
    fn closest_base<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        ray: &BoxRay,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest::<false, F>(ray, t_max, test)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    fn closest_avx<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        ray: &BoxRay,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest::<true, F>(ray, t_max, test)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    fn closest_flat_avx<F: FnMut(usize, f32) -> Option<f32>>(
        &self,
        ray: &BoxRay,
        t_max: f32,
        test: F,
    ) -> f32 {
        self.closest_flat::<true, F>(ray, t_max, test)
    }

    #[inline(always)]
    pub(super) fn any_dispatch<F: FnMut(usize) -> bool>(
        &self,
        ray: &BoxRay,
        t_max: f32,
        test: F,
    ) -> bool {
        let flat = self.is_flat();
        #[cfg(target_arch = "x86_64")]
        if avx() {
            // SAFETY: the CPU has AVX (just checked), the feature these loops are built for.
            return unsafe {
                if flat {
                    self.first_flat_avx(ray, t_max, test)
                } else {
                    self.first_avx(ray, t_max, test)
                }
            };
        }
        if flat {
            self.first_flat::<false, F>(ray, t_max, test)
        } else {
            self.first_base(ray, t_max, test)
        }
    }

    #[inline(never)]
    fn first_base<F: FnMut(usize) -> bool>(&self, ray: &BoxRay, t_max: f32, test: F) -> bool {
        self.first::<false, F>(ray, t_max, test)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    fn first_avx<F: FnMut(usize) -> bool>(&self, ray: &BoxRay, t_max: f32, test: F) -> bool {
        self.first::<true, F>(ray, t_max, test)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    fn first_flat_avx<F: FnMut(usize) -> bool>(&self, ray: &BoxRay, t_max: f32, test: F) -> bool {
        self.first_flat::<true, F>(ray, t_max, test)
    }
}
