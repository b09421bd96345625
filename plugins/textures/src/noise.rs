//! Perlin's improved gradient noise (Ken Perlin, "Improving Noise", SIGGRAPH 2002) with a
//! permutation table shuffled from a seed, and fractal sums of it.
//!
//! Everything here is a pure function of the seed and the point: the same on every run, every
//! thread and every machine (IEEE double arithmetic, no platform-dependent functions).

/// Gradient noise over a lattice of period 256 in each axis.
#[derive(Clone)]
pub struct Perlin {
    /// A permutation of 0..=255, stored twice so that `perm[i + j]` needs no wrap-around.
    perm: [u8; 512],
}

/// SplitMix64: a small, well-mixed generator used only to shuffle the table.
fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The quintic fade curve 6t⁵ - 15t⁴ + 10t³ (zero first and second derivatives at 0 and 1).
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn lerp(t: f64, a: f64, b: f64) -> f64 {
    a + t * (b - a)
}

/// Dot product of (x, y, z) with one of the twelve edge-midpoint directions of a cube
/// (±1, ±1, 0) and permutations, chosen by the low four bits of `hash` (four of the sixteen
/// codes repeat directions so that the choice is a cheap bit test).
fn grad(hash: u8, x: f64, y: f64, z: f64) -> f64 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

impl Perlin {
    pub fn new(seed: u64) -> Perlin {
        let mut table: [u8; 256] = std::array::from_fn(|i| i as u8);
        let mut state = seed;
        // Fisher-Yates.
        for i in (1..256usize).rev() {
            let j = (splitmix64(&mut state) % (i as u64 + 1)) as usize;
            table.swap(i, j);
        }
        Perlin {
            perm: std::array::from_fn(|i| table[i & 255]),
        }
    }

    /// Noise at `p`, in about [-1, 1]; exactly 0 at lattice points; 0 for non-finite points.
    pub fn noise(&self, p: [f64; 3]) -> f64 {
        if !p.iter().all(|c| c.is_finite()) {
            return 0.0;
        }
        let cell = p.map(f64::floor);
        // Lattice coordinates modulo 256 (`as` saturates far away; still in range after `& 255`).
        let [xi, yi, zi] = cell.map(|c| ((c as i64) & 255) as usize);
        let [x, y, z] = [p[0] - cell[0], p[1] - cell[1], p[2] - cell[2]];
        let (u, v, w) = (fade(x), fade(y), fade(z));
        let perm = &self.perm;
        let a = perm[xi] as usize + yi;
        let aa = perm[a] as usize + zi;
        let ab = perm[a + 1] as usize + zi;
        let b = perm[xi + 1] as usize + yi;
        let ba = perm[b] as usize + zi;
        let bb = perm[b + 1] as usize + zi;
        lerp(
            w,
            lerp(
                v,
                lerp(u, grad(perm[aa], x, y, z), grad(perm[ba], x - 1.0, y, z)),
                lerp(
                    u,
                    grad(perm[ab], x, y - 1.0, z),
                    grad(perm[bb], x - 1.0, y - 1.0, z),
                ),
            ),
            lerp(
                v,
                lerp(
                    u,
                    grad(perm[aa + 1], x, y, z - 1.0),
                    grad(perm[ba + 1], x - 1.0, y, z - 1.0),
                ),
                lerp(
                    u,
                    grad(perm[ab + 1], x, y - 1.0, z - 1.0),
                    grad(perm[bb + 1], x - 1.0, y - 1.0, z - 1.0),
                ),
            ),
        )
    }
}

/// A fractal sum of octaves of [`Perlin`] noise: octave `i` has frequency `lacunarity^i` and
/// amplitude `gain^i`; sums are divided by the total amplitude so they keep the noise's range.
#[derive(Clone)]
pub struct Fractal {
    pub perlin: Perlin,
    pub octaves: u32,
    pub gain: f64,
    pub lacunarity: f64,
}

/// Each octave after the first is shifted by a multiple of this, so that octaves do not share
/// their lattice points (where every octave would be 0 at once).
const OCTAVE_SHIFT: [f64; 3] = [19.19, 7.37, 43.71];

impl Fractal {
    fn sum(&self, p: [f64; 3], f: impl Fn(f64) -> f64) -> f64 {
        let (mut total, mut norm, mut amp, mut freq) = (0.0, 0.0, 1.0, 1.0);
        for i in 0..self.octaves {
            let k = i as f64;
            let q = std::array::from_fn(|j| p[j] * freq + k * OCTAVE_SHIFT[j]);
            total += amp * f(self.perlin.noise(q));
            norm += amp;
            amp *= self.gain;
            freq *= self.lacunarity;
        }
        if norm > 0.0 {
            total / norm
        } else {
            0.0
        }
    }

    /// Signed fractal noise ("fBm"), in about [-1, 1].
    pub fn smooth(&self, p: [f64; 3]) -> f64 {
        self.sum(p, |n| n)
    }

    /// Perlin's turbulence: the sum of absolute values, in about [0, 1].
    pub fn turbulent(&self, p: [f64; 3]) -> f64 {
        self.sum(p, f64::abs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic scatter of points (a lattice walked with irrational steps).
    fn points(n: usize) -> impl Iterator<Item = [f64; 3]> {
        (0..n).map(|i| {
            let t = i as f64;
            [
                (t * 0.618_033_988_7).fract() * 40.0 - 20.0,
                (t * 0.414_213_562_3).fract() * 40.0 - 20.0,
                (t * 0.732_050_807_5).fract() * 40.0 - 20.0,
            ]
        })
    }

    #[test]
    fn zero_at_lattice_points() {
        let n = Perlin::new(7);
        for p in [
            [0.0; 3],
            [1.0, 2.0, 3.0],
            [-5.0, 17.0, -200.0],
            [255.0, 256.0, 1e6],
        ] {
            assert_eq!(n.noise(p), 0.0, "{p:?}");
        }
    }

    #[test]
    fn range_and_spread() {
        let n = Perlin::new(1);
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for p in points(200_000) {
            let v = n.noise(p);
            lo = lo.min(v);
            hi = hi.max(v);
        }
        // The true extremes are about ±1.04; a broken gradient table would leave this range or
        // collapse it.
        assert!(lo >= -1.1 && hi <= 1.1, "{lo} {hi}");
        assert!(lo < -0.7 && hi > 0.7, "{lo} {hi}");
    }

    #[test]
    fn deterministic_seeded_and_periodic() {
        let a = Perlin::new(42);
        let b = Perlin::new(42);
        let c = Perlin::new(43);
        let mut differ = 0;
        for p in points(1000) {
            assert_eq!(a.noise(p).to_bits(), b.noise(p).to_bits());
            if a.noise(p) != c.noise(p) {
                differ += 1;
            }
            // The lattice repeats every 256 units (up to rounding in the fraction).
            let q = [p[0] + 256.0, p[1] - 512.0, p[2]];
            assert!((a.noise(p) - a.noise(q)).abs() < 1e-9);
        }
        assert!(differ > 900, "seeds 42 and 43 agree too often: {differ}");
        // A pinned value: the table and the formula must not change between versions.
        let v = Perlin::new(0).noise([0.3, 1.7, -2.2]);
        assert!((v - PINNED).abs() < 1e-12, "{v}");
    }

    /// `Perlin::new(0).noise([0.3, 1.7, -2.2])`, recorded when the generator was written.
    const PINNED: f64 = 0.034_685_310_822_144_32;

    #[test]
    fn continuous() {
        let n = Perlin::new(3);
        for p in points(500) {
            let q = [p[0] + 1e-6, p[1], p[2] - 1e-6];
            assert!((n.noise(p) - n.noise(q)).abs() < 1e-4);
        }
    }

    #[test]
    fn non_finite_points_give_zero() {
        let n = Perlin::new(0);
        assert_eq!(n.noise([f64::NAN, 0.5, 0.5]), 0.0);
        assert_eq!(n.noise([f64::INFINITY, 0.5, 0.5]), 0.0);
        // Far away but finite: no panic, a finite value.
        assert!(n.noise([1e300, -1e300, 0.5]).is_finite());
    }

    #[test]
    fn fractal_ranges() {
        let f = Fractal {
            perlin: Perlin::new(5),
            octaves: 6,
            gain: 0.5,
            lacunarity: 2.0,
        };
        for p in points(20_000) {
            let s = f.smooth(p);
            let t = f.turbulent(p);
            assert!((-1.1..=1.1).contains(&s), "{s}");
            assert!((0.0..=1.1).contains(&t), "{t}");
        }
        let one = Fractal { octaves: 1, ..f };
        let p = [0.25, 0.5, 0.75];
        assert_eq!(one.smooth(p), one.perlin.noise(p));
        assert_eq!(one.turbulent(p), one.perlin.noise(p).abs());
    }
}
