//! `(0.5 · (1 + sin x)) as f32` and the same with `cos`, as the platform's `sin` and `cos`
//! give them, at a fraction of their cost: Tachyon's marble needs three per hit.
//!
//! A short polynomial gives sin x within `SLACK` of the platform's value; rounding to f32 is
//! monotonic, so when both ends of that interval round to the same f32, so does the platform's
//! value, and it is the answer. Otherwise (about once in ten million calls, and for arguments
//! outside the reduced range) the platform's function decides. Bitwise identical by
//! construction, not by luck; the tests sweep millions of arguments to check the bound.

use std::f64::consts::{FRAC_2_PI, FRAC_PI_2};

/// π/2 as the nearest f64 plus the rest (π/2 − HI rounded): Cody and Waite's reduction.
const PIO2_HI: f64 = FRAC_PI_2;
const PIO2_LO: f64 = 6.123_233_995_736_766e-17;

/// Bound on |polynomial − platform|: reduction ≤ 3e-16, Horner ≤ 5e-16, truncation ≤ 1e-16,
/// the platform's own error ≤ 1.2e-16; ten times their sum.
const SLACK: f64 = 1e-14;

/// 1.5·2⁵²: see `approx`.
const SHIFTER: f64 = 6_755_399_441_055_744.0;

/// Arguments past this reduce with more error than `SLACK` allows for; they go to the platform.
const MAX_ARG: f64 = 64.0;

/// sin r for |r| ≤ π/4 + ε: Taylor to r¹⁵ (the next term is below 5e-17).
#[inline]
fn sin_poly(r: f64) -> f64 {
    let r2 = r * r;
    let p: f64 = -1.0 / 1_307_674_368_000.0;
    let p = p.mul_add(r2, 1.0 / 6_227_020_800.0);
    let p = p.mul_add(r2, -1.0 / 39_916_800.0);
    let p = p.mul_add(r2, 1.0 / 362_880.0);
    let p = p.mul_add(r2, -1.0 / 5_040.0);
    let p = p.mul_add(r2, 1.0 / 120.0);
    let p = p.mul_add(r2, -1.0 / 6.0);
    (p * r2).mul_add(r, r)
}

/// cos r for |r| ≤ π/4 + ε: Taylor to r¹⁶ (the next term is below 3e-18).
#[inline]
fn cos_poly(r: f64) -> f64 {
    let r2 = r * r;
    let p: f64 = 1.0 / 20_922_789_888_000.0;
    let p = p.mul_add(r2, -1.0 / 87_178_291_200.0);
    let p = p.mul_add(r2, 1.0 / 479_001_600.0);
    let p = p.mul_add(r2, -1.0 / 3_628_800.0);
    let p = p.mul_add(r2, 1.0 / 40_320.0);
    let p = p.mul_add(r2, -1.0 / 720.0);
    let p = p.mul_add(r2, 1.0 / 24.0);
    let p = p.mul_add(r2, -0.5);
    p.mul_add(r2, 1.0)
}

/// sin(x + quarter·π/2) for 0 ≤ x ≤ MAX_ARG, within SLACK.
#[inline]
fn approx(x: f64, quarter: i64) -> f64 {
    // Adding 1.5·2⁵² rounds x·2/π to an integer k held in the low bits of the mantissa: k and
    // its quadrant without a call to `round` or a saturating cast.
    let shifted = x * FRAC_2_PI + SHIFTER;
    let k = shifted - SHIFTER;
    let r = (-k).mul_add(PIO2_HI, x);
    let r = (-k).mul_add(PIO2_LO, r);
    match (shifted.to_bits() as i64 + quarter) & 3 {
        0 => sin_poly(r),
        1 => cos_poly(r),
        2 => -sin_poly(r),
        _ => -cos_poly(r),
    }
}

/// Rounds 0.5·(1 + s) to f32, as `(0.5 * (1.0 + s)) as f32` (monotonic in s).
#[inline]
fn to_band(s: f64) -> f32 {
    (0.5 * (1.0 + s)) as f32
}

#[inline]
fn band(x: f64, quarter: i64, exact: impl Fn(f64) -> f64) -> f32 {
    if (0.0..=MAX_ARG).contains(&x) {
        let s = approx(x, quarter);
        let lo = to_band(s - SLACK);
        if lo == to_band(s + SLACK) {
            return lo;
        }
    }
    to_band(exact(x))
}

/// `(0.5 * (1.0 + x.sin())) as f32`, bitwise.
#[inline]
pub fn sin_band(x: f64) -> f32 {
    band(x, 0, f64::sin)
}

/// `(0.5 * (1.0 + x.cos())) as f32`, bitwise.
#[inline]
pub fn cos_band(x: f64) -> f32 {
    band(x, 1, f64::cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(x: f64) {
        assert_eq!(
            sin_band(x).to_bits(),
            to_band(x.sin()).to_bits(),
            "sin {x:e}"
        );
        assert_eq!(
            cos_band(x).to_bits(),
            to_band(x.cos()).to_bits(),
            "cos {x:e}"
        );
    }

    /// The polynomial stays within a tenth of the slack of the platform's functions.
    #[test]
    fn polynomial_within_slack() {
        let n = 2_000_000;
        for j in 0..=n {
            let x = MAX_ARG * j as f64 / n as f64;
            let (s, c) = (approx(x, 0), approx(x, 1));
            assert!((s - x.sin()).abs() < SLACK / 10.0, "sin {x:e}: {s:e}");
            assert!((c - x.cos()).abs() < SLACK / 10.0, "cos {x:e}: {c:e}");
        }
    }

    /// The arguments marble passes (i·6.28, i·16.28, i·30.28 for i in [0, 1]), densely, the
    /// whole reduced range, and arguments that take the platform's path.
    // Marble's factors (6.28 is Tachyon's, not quite 2π).
    #[allow(clippy::approx_constant)]
    #[test]
    fn same_bits_as_the_platform() {
        let n = 1_000_000;
        for j in 0..=n {
            let i = j as f64 / n as f64;
            for f in [6.28, 16.28, 30.28] {
                check(i * f);
            }
            check(MAX_ARG * (j as f64 * 0.618_033_988_749_895).fract());
        }
        for x in [
            0.0,
            -0.0,
            1e-300,
            -1.0,
            MAX_ARG,
            MAX_ARG + 1.0,
            1e6,
            std::f64::consts::PI,
            3.0 * std::f64::consts::FRAC_PI_2,
        ] {
            check(x);
        }
        assert!(sin_band(f64::NAN).is_nan() && cos_band(f64::INFINITY).is_nan());
    }
}
