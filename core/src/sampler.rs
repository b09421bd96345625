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

#[cfg(test)]
mod tests {
    use super::*;

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
