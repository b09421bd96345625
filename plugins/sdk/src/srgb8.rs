//! 8-bit sRGB samples from linear values without a `powf` per sample: the same bytes as
//! `round(255 · linear_to_srgb(x))`, read from tables made once from that function.
//!
//! That function is a staircase of 256 steps over the floats: non-decreasing, so a sample is
//! the number of steps whose first float lies at or below `x`. The tables are those first
//! floats (found by bisection over the float's bits, which order non-negative floats) and,
//! per run of 2^16 consecutive floats, the step at its start. No run holds more than one
//! step's start (where the floats are far apart the curve is flat: a test checks it), but the
//! lookup walks on as long as it must: the answer is exact for a non-decreasing staircase,
//! which a test checks within 4096 floats of every step (the only place `powf`'s rounding
//! could break it). Checked once over every float
//! from 0 to 1 too (1,065,353,217, all equal; 3 s in a release build, so not a test).
//!
//! A 1024² frame: the curve took 151 M instructions through `powf` (skipping repeated
//! pixels), the tables 60 M. For a whole image take [`tables`] once and call
//! [`Tables::sample`]; [`srgb8`] is the same for one value.

use crate::linear_to_srgb;
use std::sync::OnceLock;

/// Bits of 1.0: every float from 0 to 1 has bits at or below it.
const ONE: u32 = 0x3F80_0000;
/// Floats per run of the coarse table.
const RUN_BITS: u32 = 16;

/// Runs of 2^16 floats from 0 to 1 (1.0 starts the last).
const RUNS: usize = (ONE >> RUN_BITS) as usize + 1;

/// The step starts and the coarse table (see the module's documentation).
pub struct Tables {
    /// `first[k]`: the bits of the first float in [0, 1] whose sample is at least `k`
    /// (`first[0]` = 0).
    first: [u32; 256],
    /// Per run of 2^16 floats from 0 to 1: the sample of its first float.
    start: Box<[u8; RUNS]>,
}

/// The sample `linear_to_srgb` and rounding give: the function the tables stand for.
pub fn direct(x: f32) -> u8 {
    (linear_to_srgb(x) * 255.0).round() as u8
}

/// The tables, made on first use (about 24 000 evaluations of the curve).
pub fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut first = [0u32; 256];
        for (k, f) in first.iter_mut().enumerate().skip(1) {
            // The first bits in [0, ONE] whose sample reaches k (255's is at most ONE).
            let (mut lo, mut hi) = (0u32, ONE);
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if usize::from(direct(f32::from_bits(mid))) >= k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            *f = lo;
        }
        let mut start = Box::new([0u8; RUNS]);
        for (r, s) in start.iter_mut().enumerate() {
            *s = direct(f32::from_bits((r as u32) << RUN_BITS));
        }
        Tables { first, start }
    })
}

/// `round(255 · linear_to_srgb(x))`, from the tables.
#[inline]
pub fn srgb8(x: f32) -> u8 {
    tables().sample(x)
}

impl Tables {
    /// `direct(x)`, from the tables.
    #[inline]
    pub fn sample(&self, x: f32) -> u8 {
        let bits = x.to_bits();
        // Negative values (and -0.0) clamp to 0, above 1 (and +inf) to 255; NaN (either
        // sign) is 0.
        if bits > ONE {
            return if x.is_nan() || bits >> 31 == 1 {
                0
            } else {
                255
            };
        }
        let mut k = self.start[(bits >> RUN_BITS) as usize];
        while k < 255 && bits >= self.first[usize::from(k) + 1] {
            k += 1;
        }
        k
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables give `direct`'s sample within 4096 floats of every step's start (where a
    /// staircase made with `powf` could fail to be non-decreasing), at a spread of bit
    /// patterns over all floats, and for the special values.
    #[test]
    fn tables_give_the_curves_samples() {
        let t = tables();
        for k in 1..256 {
            let f = t.first[k];
            for b in f.saturating_sub(4096)..=(f + 4096).min(ONE) {
                let x = f32::from_bits(b);
                assert_eq!(t.sample(x), direct(x), "{x:e} (bits {b:#x}) near step {k}");
            }
        }
        for bits in (0..=u32::MAX).step_by(4099) {
            let x = f32::from_bits(bits);
            assert_eq!(srgb8(x), direct(x), "{x:e} (bits {bits:#x})");
        }
        for x in [
            0.0,
            -0.0,
            1.0,
            0.5,
            0.003_130_8,
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
        ] {
            assert_eq!(srgb8(x), direct(x), "{x:e}");
        }
        assert_eq!(srgb8(f32::NEG_INFINITY), 0);
        // Steps start in order, and each run of the coarse table holds at most one.
        assert!(t.first.windows(2).all(|w| w[0] < w[1]));
        let runs = t.first[1..].iter().map(|f| f >> RUN_BITS);
        assert!(runs.collect::<Vec<_>>().windows(2).all(|w| w[0] < w[1]));
    }
}
