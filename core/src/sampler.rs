//! Deterministic per-pixel sample positions: a hash of (pixel, sample, frame, dimension), so the
//! image is bitwise identical for any thread count, rank count and work decomposition.

/// A 32-bit integer hash with good avalanche (lowbias32 by C. Wellons).
#[inline(always)]
pub const fn mix(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

#[inline(always)]
pub fn hash(x: u32, y: u32, frame: u32, dim: u32) -> u32 {
    mix(x ^ mix(y ^ mix(frame ^ mix(dim))))
}

/// Uniform in [0, 1).
#[inline(always)]
pub fn to_unit(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A pseudo-random permutation of `0..n` evaluated at `i` without storage (cycle-walking a
/// bijective hash over the next power of two).
pub fn permute(mut i: u32, n: u32, seed: u32) -> u32 {
    let mask = n.next_power_of_two().wrapping_sub(1);
    loop {
        // Each step is a bijection on [0, mask]: xor, odd multiply, xor-shift.
        i ^= seed & mask;
        i = i.wrapping_mul(0x9e37_79b1 | 1) & mask;
        i ^= (i >> 3) & mask;
        i = i.wrapping_mul(0x85eb_ca6b | 1) & mask;
        i ^= (i >> 5) & mask;
        if i < n {
            return i;
        }
    }
}

/// Position of sample `i` of `n` inside pixel (`px`, `py`), in [0, 1)². One sample: the pixel
/// centre. A square count: jittered grid. Otherwise: jittered N-rooks (one sample in every
/// row and every column stratum).
#[inline]
pub fn pixel_sample(px: u32, py: u32, i: u32, n: u32, frame: u32) -> (f32, f32) {
    if n <= 1 {
        return (0.5, 0.5);
    }
    let jx = to_unit(hash(px, py, frame, 2 * i));
    let jy = to_unit(hash(px, py, frame, 2 * i + 1));
    let m = (n as f64).sqrt() as u32;
    if m * m == n {
        let (sx, sy) = (i % m, i / m);
        ((sx as f32 + jx) / m as f32, (sy as f32 + jy) / m as f32)
    } else {
        let seed = hash(px, py, frame, 0xffff_fff0);
        let sy = permute(i, n, seed);
        ((i as f32 + jx) / n as f32, (sy as f32 + jy) / n as f32)
    }
}

/// Where in the shutter sample `i` of `n` of pixel (`px`, `py`) looks, in [0, 1): one stratum
/// of the shutter per sample, the strata shuffled per pixel by a permutation of their own (so
/// time is not tied to the sample's place in the pixel), jittered inside. Dimensions
/// `0x4000_0000 | i` and `0xffff_ffe0` are used by no other sample (`pixel_sample` uses
/// `2i`, `2i + 1` and `0xffff_fff0`; adaptive sampling `0xada9_5eed`).
#[inline]
pub fn time_sample(px: u32, py: u32, i: u32, n: u32, frame: u32) -> f32 {
    let n = n.max(1);
    let stratum = permute(i, n, hash(px, py, frame, 0xffff_ffe0));
    let u = (stratum as f32 + to_unit(hash(px, py, frame, 0x4000_0000 | i))) / n as f32;
    // The division can round up to 1.
    u.min(1.0 - f32::EPSILON / 2.0)
}

/// The time of an adaptive sample, which has no index: a hash of its position in the pixel
/// (each position is sampled once) and the pixel's own seed.
#[inline]
pub fn time_at(jx: f32, jy: f32, px: u32, py: u32, frame: u32) -> f32 {
    let seed = hash(px, py, frame, 0xffff_ffe1);
    to_unit(mix(jx.to_bits() ^ mix(jy.to_bits() ^ seed)))
}

/// [`pixel_sample`] for every pixel of one render (one sample count, one frame): what does not
/// depend on the pixel is computed once, not per sample (the inner half of each `hash`, the
/// square root, the grid cell's division), so a sample costs two hashes of two rounds. Same
/// values, bit for bit. Or, `centred`, Tachyon's antialiasing: sample 0 at the pixel's centre,
/// the others at the same jitter alone, anywhere in the pixel (no strata).
pub struct PixelSampler {
    n: u32,
    centred: bool,
    /// Side of the jittered grid when `n` is a square, else 0 (N-rooks).
    grid: u32,
    /// Per sample: `mix(frame ^ mix(dim))` of its two jitter dimensions, and its grid cell
    /// (column, row; N-rooks: the column only).
    per_sample: Vec<([u32; 2], [f32; 2])>,
    /// `mix(frame ^ mix(dim))` of the N-rooks permutation's seed dimension.
    seed_inner: u32,
}

impl PixelSampler {
    pub fn new(n: u32, frame: u32, centred: bool) -> PixelSampler {
        let inner = |dim: u32| mix(frame ^ mix(dim));
        let m = (n as f64).sqrt() as u32;
        let grid = if m * m == n { m } else { 0 };
        let cell = |i: u32| match grid {
            0 => [i as f32, 0.0],
            m => [(i % m) as f32, (i / m) as f32],
        };
        let per_sample = if n <= 1 {
            Vec::new()
        } else {
            (0..n)
                .map(|i| ([inner(2 * i), inner(2 * i + 1)], cell(i)))
                .collect()
        };
        PixelSampler {
            n,
            centred,
            grid,
            per_sample,
            seed_inner: inner(0xffff_fff0),
        }
    }

    /// The N-rooks permutation seed of pixel (`px`, `py`) (unused for square counts).
    #[inline]
    pub fn pixel_seed(&self, px: u32, py: u32) -> u32 {
        if self.n <= 1 || self.grid != 0 || self.centred {
            return 0;
        }
        mix(px ^ mix(py ^ self.seed_inner))
    }

    /// Sample `i` of pixel (`px`, `py`), whose [`PixelSampler::pixel_seed`] is `seed`: equal
    /// to `pixel_sample(px, py, i, n, frame)`.
    #[inline]
    pub fn sample(&self, px: u32, py: u32, seed: u32, i: u32) -> (f32, f32) {
        let n = self.n;
        if n <= 1 || (self.centred && i == 0) {
            return (0.5, 0.5);
        }
        let (inner, [sx, sy]) = self.per_sample[i as usize];
        let jx = to_unit(mix(px ^ mix(py ^ inner[0])));
        let jy = to_unit(mix(px ^ mix(py ^ inner[1])));
        if self.centred {
            return (jx, jy);
        }
        match self.grid {
            0 => {
                let sy = permute(i, n, seed) as f32;
                ((sx + jx) / n as f32, (sy + jy) / n as f32)
            }
            m => ((sx + jx) / m as f32, (sy + jy) / m as f32),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_sampler_equals_pixel_sample() {
        for n in [0u32, 1, 2, 3, 4, 5, 9, 16, 33] {
            for frame in [0u32, 7] {
                let s = PixelSampler::new(n, frame, false);
                for (px, py) in [(0u32, 0u32), (3, 7), (511, 200)] {
                    let seed = s.pixel_seed(px, py);
                    for i in 0..n.max(1) {
                        let (a, b) = s.sample(px, py, seed, i);
                        let (c, d) = pixel_sample(px, py, i, n, frame);
                        assert_eq!((a.to_bits(), b.to_bits()), (c.to_bits(), d.to_bits()));
                    }
                }
            }
        }
    }

    /// Tachyon's antialiasing: the centre first, then positions spread over the whole pixel
    /// (not one per stratum), the same for every thread count (a function of the pixel).
    #[test]
    fn centred_sampling_starts_at_the_centre_and_spreads_over_the_pixel() {
        let n = 5;
        let s = PixelSampler::new(n, 0, true);
        let mut quadrants = [0; 4];
        for (px, py) in (0..40u32).flat_map(|y| (0..40u32).map(move |x| (x, y))) {
            let seed = s.pixel_seed(px, py);
            assert_eq!(s.sample(px, py, seed, 0), (0.5, 0.5));
            for i in 1..n {
                let (x, y) = s.sample(px, py, seed, i);
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                assert_eq!(s.sample(px, py, seed, i), (x, y));
                quadrants[(x >= 0.5) as usize + 2 * (y >= 0.5) as usize] += 1;
            }
        }
        // 6400 positions: each quadrant near a quarter (not the strata's fixed shares).
        assert!(
            quadrants.iter().all(|&q| (1400..1800).contains(&q)),
            "{quadrants:?}"
        );
    }

    /// One sample per stratum of the shutter, in [0, 1), and not in the image-plane order.
    #[test]
    fn times_are_stratified_and_shuffled() {
        for n in [1u32, 4, 7, 64] {
            let mut strata = vec![0; n as usize];
            let mut in_order = 0;
            for i in 0..n {
                let t = time_sample(5, 9, i, n, 3);
                assert!((0.0..1.0).contains(&t));
                strata[(t * n as f32) as usize] += 1;
                in_order += u32::from((t * n as f32) as u32 == i);
            }
            assert!(strata.iter().all(|&c| c == 1), "n = {n}");
            if n == 64 {
                assert!(in_order < 8, "{in_order} samples in their own stratum");
            }
        }
        // Other pixels and frames shuffle differently.
        let a: Vec<u32> = (0..16)
            .map(|i| time_sample(0, 0, i, 16, 0).to_bits())
            .collect();
        let b: Vec<u32> = (0..16)
            .map(|i| time_sample(1, 0, i, 16, 0).to_bits())
            .collect();
        let c: Vec<u32> = (0..16)
            .map(|i| time_sample(0, 0, i, 16, 1).to_bits())
            .collect();
        assert!(a != b && a != c);
        // A shutter of no length gives +0.0 wherever it sits: the still frame's time.
        for (open, close) in [(0.0f32, 0.0f32), (-0.0, 0.0), (-0.0, -0.0)] {
            let t = open + time_sample(2, 3, 1, 4, 0) * (close - open);
            assert_eq!(t.to_bits(), 0.0f32.to_bits());
        }
        assert!((0.0..1.0).contains(&time_at(0.25, 0.5, 1, 2, 3)));
    }

    #[test]
    fn permute_is_a_permutation() {
        for n in [1u32, 2, 3, 5, 7, 100, 1000] {
            let mut seen = vec![false; n as usize];
            for i in 0..n {
                let p = permute(i, n, 1234);
                assert!(!seen[p as usize]);
                seen[p as usize] = true;
            }
        }
    }

    #[test]
    fn samples_are_stratified_and_in_the_pixel() {
        for n in [4u32, 5, 16] {
            let mut rows = vec![0; n as usize];
            for i in 0..n {
                let (x, y) = pixel_sample(3, 7, i, n, 0);
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                if n == 5 {
                    rows[(y * n as f32) as usize] += 1;
                }
            }
            if n == 5 {
                assert!(rows.iter().all(|&r| r == 1));
            }
        }
        assert_eq!(pixel_sample(1, 2, 0, 1, 0), (0.5, 0.5));
    }
}
