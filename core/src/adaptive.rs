//! Adaptive supersampling (Stone's thesis, II.E): more samples only where a pixel's samples
//! disagree.
//!
//! A pixel is an m x m grid of base cells (m = ⌊√(samples / 4)⌋, at least 1), each sampled by a
//! jittered 2x2 grid, so a flat pixel costs exactly 4m² samples. A cell whose four samples differ
//! by more than the threshold (in any colour channel, as displayed: clamped to [0, 1] and
//! sRGB-encoded) is split into its
//! four quadrants; each quadrant already holds one of the parent's samples (uniform in it) and
//! gets three new ones in its other sub-quadrants, so no sample is wasted and a fully split cell
//! is exactly a finer jittered grid. Splitting stops at the maximum depth.
//!
//! Every decision depends only on the pixel's own samples, whose positions come from the
//! (pixel, cell, frame) hash: the image is identical for any thread count and decomposition.

use crate::math::Vec3A;
use crate::sampler::{hash, mix, to_unit};
use luxon_formats::AdaptiveDesc;

/// Base cells per pixel side for a `samples` setting.
pub fn base_cells(samples: u32) -> u32 {
    ((samples as f64 / 4.0).sqrt().floor() as u32).max(1)
}

/// Samples a flat pixel gets: 4 per base cell.
pub fn base_samples(samples: u32) -> u32 {
    let m = base_cells(samples);
    4 * m * m
}

/// Most samples one pixel can get.
pub fn max_samples(samples: u32, max_depth: u32) -> u64 {
    base_samples(samples) as u64 * 4u64.pow(max_depth)
}

/// Parses `off`, `THRESHOLD` or `THRESHOLD:DEPTH` (the command line's spelling);
/// `default_depth` when the depth is left out.
pub fn parse(s: &str, default_depth: u32) -> Result<Option<AdaptiveDesc>, String> {
    let s = s.trim();
    if s.eq_ignore_ascii_case("off") {
        return Ok(None);
    }
    let (t, d) = match s.split_once(':') {
        Some((t, d)) => (t, Some(d)),
        None => (s, None),
    };
    let threshold: f64 = t.trim().parse().map_err(|_| {
        format!("adaptive `{s}`: expected THRESHOLD[:DEPTH] (e.g. 0.05 or 0.05:3) or off")
    })?;
    if !(threshold >= 0.0 && threshold.is_finite()) {
        return Err(format!(
            "adaptive threshold {threshold}: expected a number of at least 0"
        ));
    }
    let max_depth = match d {
        Some(d) => match d.trim().parse::<u32>() {
            Ok(n) if n <= luxon_formats::ADAPTIVE_MAX_DEPTH => n,
            _ => {
                return Err(format!(
                    "adaptive depth `{d}`: expected a whole number from 0 to {}",
                    luxon_formats::ADAPTIVE_MAX_DEPTH
                ))
            }
        },
        None => default_depth,
    };
    Ok(Some(AdaptiveDesc {
        threshold,
        max_depth,
    }))
}

/// The spelling [`parse`] reads.
pub fn label(a: Option<&AdaptiveDesc>) -> String {
    match a {
        None => "off".into(),
        Some(a) => format!("{}:{}", a.threshold, a.max_depth),
    }
}

/// The pixel's value from `shade(x, y)` (position in the pixel, in [0, 1)²).
pub fn pixel(
    px: u32,
    py: u32,
    frame: u32,
    samples: u32,
    settings: &AdaptiveDesc,
    shade: &mut impl FnMut(f32, f32) -> Vec3A,
) -> Vec3A {
    let m = base_cells(samples);
    let walk = Walk {
        px,
        py,
        frame,
        m,
        threshold: settings.threshold as f32,
        max_depth: settings.max_depth,
    };
    let mut sum = Vec3A::ZERO;
    for cy in 0..m {
        for cx in 0..m {
            let s = std::array::from_fn(|k| {
                walk.sample(1, 2 * cx + quad_x(k), 2 * cy + quad_y(k), shade)
            });
            sum += walk.cell(0, cx, cy, s, shade);
        }
    }
    sum / (m * m) as f32
}

fn quad_x(k: usize) -> u32 {
    (k & 1) as u32
}

fn quad_y(k: usize) -> u32 {
    (k >> 1) as u32
}

/// A sample's value and where it was taken in the pixel.
#[derive(Clone, Copy)]
struct Sample {
    v: Vec3A,
    x: f32,
    y: f32,
}

/// (`g` + `j`) / `side` as an f32 that stays inside cell `g` of the grid (rounding to f32 must
/// not move a sample into its neighbour's stratum).
fn inside(g: u32, j: f32, side: f64) -> f32 {
    let mut x = ((g as f64 + j as f64) / side) as f32;
    while x as f64 * side >= (g + 1) as f64 {
        x = f32::from_bits(x.to_bits() - 1);
    }
    while (x as f64 * side) < g as f64 {
        x = f32::from_bits(x.to_bits() + 1);
    }
    x
}

/// Which cell of a `side` grid holds `x`.
fn cell_of(x: f32, side: f64) -> u32 {
    (x as f64 * side).floor() as u32
}

struct Walk {
    px: u32,
    py: u32,
    frame: u32,
    m: u32,
    threshold: f32,
    max_depth: u32,
}

impl Walk {
    /// A sample in cell (`gx`, `gy`) of the level-`level` grid (m·2^level cells per pixel
    /// side), jittered by the (pixel, cell, frame) hash.
    fn sample(
        &self,
        level: u32,
        gx: u32,
        gy: u32,
        shade: &mut impl FnMut(f32, f32) -> Vec3A,
    ) -> Sample {
        let key = mix(mix(mix(level ^ 0xada9_0000).wrapping_add(gx)).wrapping_add(gy));
        let jx = to_unit(hash(self.px, self.py, self.frame, key));
        let jy = to_unit(hash(self.px, self.py, self.frame, key ^ 0x8000_0001));
        let side = (self.m << level) as f64;
        let (x, y) = (inside(gx, jx, side), inside(gy, jy, side));
        Sample {
            v: shade(x, y),
            x,
            y,
        }
    }

    /// The value of cell (`cx`, `cy`) at `depth` (grid of m·2^depth), whose quadrant samples
    /// are `s` (quadrant k at x + (k & 1), y + (k >> 1)).
    fn cell(
        &self,
        depth: u32,
        cx: u32,
        cy: u32,
        s: [Sample; 4],
        shade: &mut impl FnMut(f32, f32) -> Vec3A,
    ) -> Vec3A {
        let v = s.map(|s| s.v);
        if depth >= self.max_depth || contrast(&v) <= self.threshold {
            return (v[0] + v[1] + v[2] + v[3]) * 0.25;
        }
        let sub = (self.m << (depth + 2)) as f64;
        let mut total = Vec3A::ZERO;
        for (k, &kept) in s.iter().enumerate() {
            // The quadrant becomes a cell one level down; the parent's sample in it stays and
            // lies in one of its sub-quadrants.
            let (qx, qy) = (2 * cx + quad_x(k), 2 * cy + quad_y(k));
            let hx = cell_of(kept.x, sub).saturating_sub(2 * qx).min(1) as usize;
            let hy = cell_of(kept.y, sub).saturating_sub(2 * qy).min(1) as usize;
            let holds = hx | (hy << 1);
            let child = std::array::from_fn(|j| {
                if j == holds {
                    kept
                } else {
                    self.sample(depth + 2, 2 * qx + quad_x(j), 2 * qy + quad_y(j), shade)
                }
            });
            total += self.cell(depth + 1, qx, qy, child, shade);
        }
        total * 0.25
    }
}

/// Largest per-channel spread of the samples as displayed (clamped to [0, 1], sRGB-encoded):
/// a difference in the shadows counts as much as it shows.
fn contrast(s: &[Vec3A; 4]) -> f32 {
    let srgb = luxon_plugin::linear_to_srgb;
    let c = s.map(|v| Vec3A::new(srgb(v.x), srgb(v.y), srgb(v.z)));
    let lo = c[0].min(c[1]).min(c[2].min(c[3]));
    let hi = c[0].max(c[1]).max(c[2].max(c[3]));
    (hi - lo).max_element()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(f: impl Fn(f32, f32) -> f32, samples: u32, threshold: f64, depth: u32) -> (f32, u32) {
        run_at(3, f, samples, threshold, depth)
    }

    fn run_at(
        px: u32,
        f: impl Fn(f32, f32) -> f32,
        samples: u32,
        threshold: f64,
        depth: u32,
    ) -> (f32, u32) {
        let mut n = 0;
        let v = pixel(
            px,
            5,
            0,
            samples,
            &AdaptiveDesc {
                threshold,
                max_depth: depth,
            },
            &mut |x, y| {
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                n += 1;
                Vec3A::splat(f(x, y))
            },
        );
        (v.x, n)
    }

    #[test]
    fn parses_the_command_line_spelling() {
        let a = |threshold, max_depth| {
            Some(AdaptiveDesc {
                threshold,
                max_depth,
            })
        };
        assert_eq!(parse("0.05", 3), Ok(a(0.05, 3)));
        assert_eq!(parse(" 0.1:5 ", 3), Ok(a(0.1, 5)));
        assert_eq!(parse("OFF", 3), Ok(None));
        assert_eq!(label(a(0.1, 5).as_ref()), "0.1:5");
        for bad in ["", "x", "-1", "0.1:9", "0.1:x", "nan"] {
            assert!(parse(bad, 3).is_err(), "{bad}");
        }
    }

    #[test]
    fn flat_pixels_get_the_base_samples() {
        for (samples, base) in [(1, 4), (4, 4), (15, 4), (16, 16), (64, 64)] {
            assert_eq!(base_samples(samples), base);
            let (v, n) = run(|_, _| 0.3, samples, 0.0, 4);
            assert_eq!(n, base, "samples {samples}");
            assert!((v - 0.3).abs() < 1e-6);
        }
    }

    #[test]
    fn edges_get_more_samples_up_to_the_depth() {
        let edge = |x: f32, _| if x < 0.37 { 0.0 } else { 1.0 };
        let (_, n0) = run(edge, 4, 0.05, 0);
        assert_eq!(n0, 4);
        let (_, n1) = run(edge, 4, 0.05, 1);
        assert_eq!(n1, 16, "a split cell gets 3 new samples per quadrant");
        let (_, n3) = run(edge, 4, 0.05, 3);
        // Only the cells along the edge split: fewer than a full 256-sample grid.
        assert!(n3 > n1 && n3 < 256, "{n3}");
        // Over many pixels the coverage comes out right.
        let mean = (0..400)
            .map(|px| run_at(px, edge, 4, 0.05, 3).0)
            .sum::<f32>()
            / 400.0;
        assert!((mean - 0.63).abs() < 0.01, "coverage {mean}");
        // Above the threshold nothing splits.
        assert_eq!(run(edge, 4, 1.0, 3).1, 4);
        assert_eq!(max_samples(16, 2), 256);
    }

    #[test]
    fn full_splitting_is_a_fine_jittered_grid() {
        // With a threshold of 0 on a function that differs everywhere, every cell splits: the
        // 4^(d+1) samples fall one per cell of the 2^(d+1) grid.
        let mut seen = [false; 64];
        let mut n = 0;
        pixel(
            9,
            1,
            2,
            4,
            &AdaptiveDesc {
                threshold: 0.0,
                max_depth: 2,
            },
            &mut |x, y| {
                n += 1;
                let i = (y * 8.0) as usize * 8 + (x * 8.0) as usize;
                assert!(!seen[i], "two samples in one stratum");
                seen[i] = true;
                Vec3A::splat(x + 0.5 * y)
            },
        );
        assert_eq!(n, 64);
        assert!(seen.iter().all(|&s| s));
    }
}
