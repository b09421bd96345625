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
//! Every decision depends only on the pixel's own samples, whose jitter is one hash of the
//! pixel's seed (the (pixel, frame) hash) and the cell: the image is identical for any thread
//! count and decomposition.

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
    Plan::new(samples, settings).pixel(px, py, frame, shade)
}

/// What every pixel of a render shares: the grids of each level and the settings. Make it once
/// and call [`Plan::pixel`] for each pixel.
pub struct Plan {
    m: u32,
    /// Level `l`'s grid, m·2^l cells per pixel side.
    grids: [Grid; luxon_formats::ADAPTIVE_MAX_DEPTH as usize + 2],
    threshold: f32,
    max_depth: u32,
}

impl Plan {
    pub fn new(samples: u32, settings: &AdaptiveDesc) -> Plan {
        let m = base_cells(samples);
        Plan {
            m,
            grids: std::array::from_fn(|l| Grid::new(m << l)),
            threshold: settings.threshold as f32,
            max_depth: settings.max_depth.min(luxon_formats::ADAPTIVE_MAX_DEPTH),
        }
    }

    /// The value of pixel (`px`, `py`) from `shade(x, y)` (position in the pixel, in [0, 1)²).
    pub fn pixel(
        &self,
        px: u32,
        py: u32,
        frame: u32,
        shade: &mut impl FnMut(f32, f32) -> Vec3A,
    ) -> Vec3A {
        let walk = Walk {
            seed: hash(px, py, frame, 0xada9_5eed),
            plan: self,
        };
        let m = self.m;
        let mut sum = Vec3A::ZERO;
        for cy in 0..m {
            for cx in 0..m {
                // Written out: `array::from_fn` costs more than the sampling around it.
                let (gx, gy) = (2 * cx, 2 * cy);
                let s = [
                    walk.sample(1, gx, gy, shade),
                    walk.sample(1, gx + 1, gy, shade),
                    walk.sample(1, gx, gy + 1, shade),
                    walk.sample(1, gx + 1, gy + 1, shade),
                ];
                sum += walk.cell(0, cx, cy, s, shade);
            }
        }
        sum / (m * m) as f32
    }
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

/// One level's grid: `side` cells per pixel side.
#[derive(Clone, Copy)]
struct Grid {
    side: f64,
    /// When side is a power of two every step below is exact in f32 and gives the same bits
    /// as the f64 route, which other sides need.
    pow2: bool,
    side32: f32,
    inv32: f32,
}

impl Grid {
    fn new(side: u32) -> Grid {
        Grid {
            side: side as f64,
            pow2: side.is_power_of_two(),
            side32: side as f32,
            inv32: 1.0 / side as f32,
        }
    }

    /// (`g` + `j`) / side as an f32 that stays inside cell `g` (rounding to f32 must not move
    /// a sample into its neighbour's stratum).
    #[inline(always)]
    fn inside(self, g: u32, j: f32) -> f32 {
        if self.pow2 {
            // g + j rounds once (g < 2^24 is exact) and scaling by a power of two is exact, so
            // this is the f64 route's value; it can only round up onto g + 1, never below g.
            let s = g as f32 + j;
            let x = s * self.inv32;
            return if s >= (g + 1) as f32 {
                f32::from_bits(x.to_bits() - 1)
            } else {
                x
            };
        }
        let side = self.side;
        let mut x = ((g as f64 + j as f64) / side) as f32;
        while x as f64 * side >= (g + 1) as f64 {
            x = f32::from_bits(x.to_bits() - 1);
        }
        while (x as f64 * side) < g as f64 {
            x = f32::from_bits(x.to_bits() + 1);
        }
        x
    }

    /// Which cell holds `x`.
    #[inline(always)]
    fn cell_of(self, x: f32) -> u32 {
        if self.pow2 {
            // x · side is exact in f32 when side is a power of two.
            (x * self.side32) as u32
        } else {
            (x as f64 * self.side).floor() as u32
        }
    }
}

/// The first step of a sample's cell key, `mix(level ^ 0xada9_0000)`, for every level a walk
/// can reach (the deepest samples are at max_depth + 1).
const LEVEL_KEYS: [u32; luxon_formats::ADAPTIVE_MAX_DEPTH as usize + 2] = {
    let mut k = [0; luxon_formats::ADAPTIVE_MAX_DEPTH as usize + 2];
    let mut level = 0;
    while level < k.len() {
        k[level] = mix(level as u32 ^ 0xada9_0000);
        level += 1;
    }
    k
};

struct Walk<'a> {
    /// The (pixel, frame) hash every sample's jitter starts from.
    seed: u32,
    plan: &'a Plan,
}

impl Walk<'_> {
    /// A sample in cell (`gx`, `gy`) of the level-`level` grid (m·2^level cells per pixel
    /// side), jittered by the hash of the pixel's seed and the cell.
    fn sample(
        &self,
        level: u32,
        gx: u32,
        gy: u32,
        shade: &mut impl FnMut(f32, f32) -> Vec3A,
    ) -> Sample {
        let key = mix(mix(LEVEL_KEYS[level as usize].wrapping_add(gx)).wrapping_add(gy));
        // One mix per coordinate on top of the pixel's seed (hashing the pixel again for every
        // sample cost a fifth of an adaptive render on simple scenes).
        let jx = to_unit(mix(self.seed ^ key));
        let jy = to_unit(mix((self.seed ^ key).wrapping_add(0x9e37_79b9)));
        let grid = self.plan.grids[level as usize];
        let (x, y) = (grid.inside(gx, jx), grid.inside(gy, jy));
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
        if depth >= self.plan.max_depth || contrast(&v) <= self.plan.threshold {
            return (v[0] + v[1] + v[2] + v[3]) * 0.25;
        }
        let sub = self.plan.grids[depth as usize + 2];
        let mut total = Vec3A::ZERO;
        for (k, &kept) in s.iter().enumerate() {
            // The quadrant becomes a cell one level down; the parent's sample in it stays and
            // lies in one of its sub-quadrants.
            let (qx, qy) = (2 * cx + quad_x(k), 2 * cy + quad_y(k));
            let hx = sub.cell_of(kept.x).saturating_sub(2 * qx).min(1) as usize;
            let hy = sub.cell_of(kept.y).saturating_sub(2 * qy).min(1) as usize;
            let holds = hx | (hy << 1);
            let mut child = [kept; 4];
            for (j, c) in child.iter_mut().enumerate() {
                if j != holds {
                    *c = self.sample(depth + 2, 2 * qx + quad_x(j), 2 * qy + quad_y(j), shade);
                }
            }
            total += self.cell(depth + 1, qx, qy, child, shade);
        }
        total * 0.25
    }
}

/// Largest per-channel spread of the samples as displayed (clamped to [0, 1], sRGB-encoded):
/// a difference in the shadows counts as much as it shows.
///
/// The encoding is monotonic, so the spread is that of the encoded extremes: two encodings per
/// channel instead of four, and none where the samples agree (most cells).
fn contrast(s: &[Vec3A; 4]) -> f32 {
    let srgb = luxon_plugin::linear_to_srgb;
    // The encoding's own clamp (NaN to 0) first, so the extremes are those it sees.
    let c = s.map(|v| {
        let v = Vec3A::select(v.cmpeq(v), v, Vec3A::ZERO);
        v.clamp(Vec3A::ZERO, Vec3A::ONE)
    });
    let lo = c[0].min(c[1]).min(c[2].min(c[3]));
    let hi = c[0].max(c[1]).max(c[2].max(c[3]));
    let mut spread = 0.0f32;
    for k in 0..3 {
        if hi[k] > lo[k] {
            spread = spread.max(srgb(hi[k]) - srgb(lo[k]));
        }
    }
    spread
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
        let (mut split, mut deeper) = (0, 0);
        for px in 0..100 {
            assert_eq!(run_at(px, edge, 4, 0.05, 0).1, 4);
            // The base cell splits unless both left samples missed the dark strip
            // ((0.13 / 0.5)² = 7 % of pixels); a split cell gets 3 new samples per quadrant.
            let n1 = run_at(px, edge, 4, 0.05, 1).1;
            assert!(n1 == 4 || n1 == 16, "{n1}");
            split += (n1 == 16) as u32;
            // Only the cells along the edge split further: fewer than a full 256-sample grid.
            let n3 = run_at(px, edge, 4, 0.05, 3).1;
            assert!(n3 >= n1 && n3 < 256, "{n3}");
            deeper += (n3 > n1) as u32;
        }
        // A left quadrant splits again if one of its two right sub-cells' samples lands past
        // 0.37: 1 - 0.48² = 77 % each, 95 % for either of the two.
        assert!(split >= 85 && deeper >= 80, "{split} {deeper}");
        // Over many pixels the coverage comes out right, but for adaptive sampling's small bias
        // (a cell whose samples all miss a feature is never refined): 0.624 here.
        let mean = (0..4000)
            .map(|px| run_at(px, edge, 4, 0.05, 3).0)
            .sum::<f32>()
            / 4000.0;
        assert!((mean - 0.63).abs() < 0.01, "coverage {mean}");
        // Above the threshold nothing splits.
        assert_eq!(run(edge, 4, 1.0, 3).1, 4);
        assert_eq!(max_samples(16, 2), 256);
    }

    #[test]
    fn the_f32_route_gives_the_f64_routes_bits() {
        // Powers of two take the f32 route; it must place every sample where the f64 route
        // (what other sides use, and what images were made with) puts it.
        let f64_route = |g: u32, j: f32, side: u32| {
            let grid = Grid {
                pow2: false,
                ..Grid::new(side)
            };
            grid.inside(g, j)
        };
        let edge = 1.0 - 1.0 / (1u32 << 24) as f32;
        for side in [1u32, 2, 4, 8, 64, 512] {
            let grid = Grid::new(side);
            assert!(grid.pow2);
            for g in [0, 1, side / 2, side - 1] {
                for h in (0..4000u32).map(|i| mix(i ^ side)).chain([0, u32::MAX]) {
                    let j = if h == u32::MAX { edge } else { to_unit(h) };
                    let x = grid.inside(g, j);
                    assert_eq!(
                        x.to_bits(),
                        f64_route(g, j, side).to_bits(),
                        "{side} {g} {j}"
                    );
                    assert_eq!(grid.cell_of(x), g, "{side} {g} {j}");
                }
            }
        }
    }

    #[test]
    fn contrast_is_the_spread_of_the_encoded_samples() {
        // As defined: encode all four, then the largest per-channel spread.
        let by_definition = |s: &[Vec3A; 4]| {
            let srgb = luxon_plugin::linear_to_srgb;
            let c = s.map(|v| Vec3A::new(srgb(v.x), srgb(v.y), srgb(v.z)));
            let lo = c[0].min(c[1]).min(c[2].min(c[3]));
            let hi = c[0].max(c[1]).max(c[2].max(c[3]));
            (hi - lo).max_element()
        };
        let value = |h: u32| match h % 7 {
            0 => f32::NAN,
            1 => -0.5,
            2 => 3.0,
            3 => 0.002,
            _ => to_unit(mix(h)) * 1.2,
        };
        for i in 0..20_000u32 {
            let s: [Vec3A; 4] = std::array::from_fn(|k| {
                let h = mix(i * 4 + k as u32);
                // Often equal channels, as on flat cells.
                if h.is_multiple_of(3) {
                    Vec3A::splat(0.25)
                } else {
                    Vec3A::new(value(h), value(mix(h)), value(mix(h ^ 1)))
                }
            });
            assert_eq!(contrast(&s).to_bits(), by_definition(&s).to_bits(), "{s:?}");
        }
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
