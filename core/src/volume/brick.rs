//! One brick of 8³ voxels, stored at the precision its data came in, and how its voxel codes
//! become values.
//!
//! A reader that sends u8 or u16 data (`add_dense_typed`) has its bricks kept as bytes or
//! 16-bit words: a u8 volume costs a byte per voxel instead of four. The value of a code is
//! `code as f32 / divisor`, computed in f32 exactly as a reader converting the data itself
//! would, so every value (and every image) is the same bits as with f32 bricks. Bytes go
//! through a table of their 256 values; words are divided when read.

use super::BRICK_VOXELS;
use crate::budget::try_vec;

/// The storage of one 8³ brick; voxel `(x, y, z)` of the brick is element `x + 8y + 64z`.
/// Voxels no data reached hold the background (as a code of the brick's format, which
/// therefore must have one for it; otherwise the brick is f32).
#[derive(Clone, Debug, PartialEq)]
pub enum Brick {
    /// Every voxel has this value.
    Constant(f32),
    /// One value per voxel.
    F32(Box<[f32; BRICK_VOXELS]>),
    /// One byte per voxel: value [`Codes::u8`].
    U8(Box<[u8; BRICK_VOXELS]>),
    /// One `u16` per voxel: value [`Codes::u16`].
    U16(Box<[u16; BRICK_VOXELS]>),
}

impl Brick {
    /// The value of voxel `i` of the brick.
    #[inline]
    pub fn value(&self, i: usize, codes: &Codes) -> f32 {
        match self {
            Brick::Constant(v) => *v,
            Brick::F32(v) => v[i],
            Brick::U8(v) => codes.u8(v[i]),
            Brick::U16(v) => codes.u16(v[i]),
        }
    }

    /// Smallest and largest value of the brick's voxels. The decoding is monotonic (a
    /// division by a positive number), so the extremes of the codes give those of the values.
    pub fn range(&self, codes: &Codes) -> (f32, f32) {
        fn fold<T: Copy + PartialOrd>(v: &[T]) -> (T, T) {
            v.iter().fold((v[0], v[0]), |(a, b), &x| {
                (if x < a { x } else { a }, if x > b { x } else { b })
            })
        }
        match self {
            Brick::Constant(v) => (*v, *v),
            Brick::F32(v) => v
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x), b.max(x))
                }),
            Brick::U8(v) => {
                let (a, b) = fold(&v[..]);
                (codes.u8(a), codes.u8(b))
            }
            Brick::U16(v) => {
                let (a, b) = fold(&v[..]);
                (codes.u16(a), codes.u16(b))
            }
        }
    }

    /// The one value of the brick when all its voxels hold the same bits (`-0.0` and `0.0`
    /// differ: a collapsed brick must read exactly as the voxels given).
    pub fn uniform(&self, codes: &Codes) -> Option<f32> {
        fn same_bits(mut values: impl Iterator<Item = f32>) -> Option<f32> {
            let first = values.next()?;
            values
                .all(|v| v.to_bits() == first.to_bits())
                .then_some(first)
        }
        match self {
            Brick::Constant(v) => Some(*v),
            Brick::F32(v) => same_bits(v.iter().copied()),
            Brick::U8(v) => {
                let first = v[0];
                // No early exit, so that the 512 comparisons vectorise.
                codes.u8_uniform(v, v.iter().fold(0, |d, &c| d | (c ^ first)) == 0)
            }
            Brick::U16(v) => same_bits(v.iter().map(|&c| codes.u16(c))),
        }
    }

    /// Bytes the brick holds besides itself.
    pub fn heap_bytes(&self) -> usize {
        match self {
            Brick::Constant(_) => 0,
            Brick::F32(_) => std::mem::size_of::<[f32; BRICK_VOXELS]>(),
            Brick::U8(_) => std::mem::size_of::<[u8; BRICK_VOXELS]>(),
            Brick::U16(_) => std::mem::size_of::<[u16; BRICK_VOXELS]>(),
        }
    }

    /// Whether the brick stores one value per voxel (not a constant).
    pub fn is_dense(&self) -> bool {
        !matches!(self, Brick::Constant(_))
    }

    /// The brick as f32 values (lossless: every code's value is an f32); `None` when the
    /// system refuses the memory.
    pub fn to_f32(&self, codes: &Codes) -> Option<Box<[f32; BRICK_VOXELS]>> {
        let mut out = array(0.0)?;
        for (i, v) in out.iter_mut().enumerate() {
            *v = self.value(i, codes);
        }
        Some(out)
    }

    /// The heap bytes of a dense brick of each format: u8, u16, f32.
    pub const BYTES: [u64; 3] = [
        BRICK_VOXELS as u64,
        2 * BRICK_VOXELS as u64,
        4 * BRICK_VOXELS as u64,
    ];
}

/// A brick's array of `fill`, or `None` when the system refuses the memory (never an abort).
pub fn array<T: Copy>(fill: T) -> Option<Box<[T; BRICK_VOXELS]>> {
    try_vec(BRICK_VOXELS, fill)?
        .into_boxed_slice()
        .try_into()
        .ok()
}

/// A copy of a brick's array, or `None` when the system refuses the memory (never an abort).
pub fn copy_of<T: Copy>(values: &[T; BRICK_VOXELS]) -> Option<Box<[T; BRICK_VOXELS]>> {
    let mut v = Vec::new();
    v.try_reserve_exact(BRICK_VOXELS).ok()?;
    v.extend_from_slice(values);
    v.into_boxed_slice().try_into().ok()
}

/// How the codes of u8 and u16 bricks become values: `code as f32 / divisor`, one divisor per
/// format for the whole volume (the reader's, checked by the builder).
#[derive(Clone, Debug)]
pub struct Codes {
    /// The value of every byte.
    u8_values: Box<[f32; 256]>,
    /// Whether no two bytes have the same value (only a divisor so small that codes overflow to
    /// infinity makes some alike).
    u8_distinct: bool,
    u8_divisor: f32,
    u16_divisor: f32,
}

impl Default for Codes {
    /// Divisor 1 for both formats (until a reader's first typed block says otherwise).
    fn default() -> Codes {
        Codes {
            u8_values: Box::new(std::array::from_fn(|i| i as f32)),
            u8_distinct: true,
            u8_divisor: 1.0,
            u16_divisor: 1.0,
        }
    }
}

impl Codes {
    /// The value of byte `c`.
    #[inline]
    pub fn u8(&self, c: u8) -> f32 {
        self.u8_values[usize::from(c)]
    }

    /// The one value of u8 codes `b` when all decode to the same bits: equal codes decode
    /// alike, and only when two differ (and some codes decode alike) are the values compared.
    pub fn u8_uniform(&self, b: &[u8; BRICK_VOXELS], all_equal: bool) -> Option<f32> {
        if all_equal {
            return Some(self.u8(b[0]));
        }
        if self.u8_distinct {
            return None;
        }
        let first = self.u8(b[0]).to_bits();
        b.iter()
            .all(|&c| self.u8(c).to_bits() == first)
            .then(|| self.u8(b[0]))
    }

    /// The value of word `c`.
    #[inline]
    pub fn u16(&self, c: u16) -> f32 {
        f32::from(c) / self.u16_divisor
    }

    /// Sets the divisor of u8 codes (before any u8 brick exists).
    pub fn set_u8_divisor(&mut self, divisor: f32) {
        if divisor.to_bits() != self.u8_divisor.to_bits() {
            self.u8_divisor = divisor;
            *self.u8_values = std::array::from_fn(|i| i as f32 / divisor);
            // Division by a positive divisor keeps the order, so alike values are neighbours.
            let bits = self.u8_values.map(f32::to_bits);
            self.u8_distinct = bits.windows(2).all(|w| w[0] != w[1]);
        }
    }

    /// Sets the divisor of u16 codes (before any u16 brick exists).
    pub fn set_u16_divisor(&mut self, divisor: f32) {
        self.u16_divisor = divisor;
    }

    /// The byte whose value is exactly `v` (same bits), if there is one.
    pub fn u8_code(&self, v: f32) -> Option<u8> {
        let guess = f64::from(v) * f64::from(self.u8_divisor);
        near(guess, 255.0)
            .map(|c| c as u8)
            .find(|&c| self.u8(c).to_bits() == v.to_bits())
    }

    /// The word whose value is exactly `v` (same bits), if there is one.
    pub fn u16_code(&self, v: f32) -> Option<u16> {
        let guess = f64::from(v) * f64::from(self.u16_divisor);
        near(guess, 65535.0)
            .map(|c| c as u16)
            .find(|&c| self.u16(c).to_bits() == v.to_bits())
    }
}

/// The whole numbers next to `x` that lie in `0..=max` (the code of a value is its product with
/// the divisor, up to the rounding of the division).
fn near(x: f64, max: f64) -> impl Iterator<Item = f64> {
    let r = if x.is_finite() { x.round() } else { -2.0 };
    [r, r - 1.0, r + 1.0]
        .into_iter()
        .filter(move |&c| (0.0..=max).contains(&c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_decode_as_the_reader_divides() {
        let mut c = Codes::default();
        assert_eq!(c.u8(200), 200.0);
        c.set_u8_divisor(255.0);
        c.set_u16_divisor(65535.0);
        for b in 0..=255u8 {
            assert_eq!(c.u8(b).to_bits(), (f32::from(b) / 255.0).to_bits());
            assert_eq!(c.u8_code(f32::from(b) / 255.0), Some(b));
        }
        for w in [0u16, 1, 255, 32768, 65534, 65535] {
            assert_eq!(c.u16(w).to_bits(), (f32::from(w) / 65535.0).to_bits());
            assert_eq!(c.u16_code(f32::from(w) / 65535.0), Some(w));
        }
        for v in [0.3, -0.0, -1.0, 2.0, f32::NAN, f32::INFINITY] {
            assert_eq!(c.u8_code(v), None, "{v}");
            assert_eq!(c.u16_code(v), None, "{v}");
        }
        assert_eq!(c.u8_code(0.0), Some(0));
    }

    #[test]
    fn ranges_and_uniformity_follow_the_values() {
        let mut c = Codes::default();
        c.set_u8_divisor(2.0);
        let mut b = [4u8; BRICK_VOXELS];
        assert_eq!(Brick::U8(Box::new(b)).uniform(&c), Some(2.0));
        b[7] = 9;
        b[9] = 1;
        let brick = Brick::U8(Box::new(b));
        assert_eq!(brick.uniform(&c), None);
        assert_eq!(brick.range(&c), (0.5, 4.5));
        assert_eq!(brick.value(7, &c), 4.5);
        assert_eq!(brick.to_f32(&c).unwrap()[9], 0.5);
        assert_eq!(brick.heap_bytes(), 512);
        // Codes that differ but decode alike (a divisor so small that both overflow) are
        // one value, as the values are compared.
        let mut c = Codes::default();
        c.set_u8_divisor(1e-38);
        let mut b = [200u8; BRICK_VOXELS];
        b[100] = 201;
        assert_eq!(c.u8_uniform(&b, false), Some(f32::INFINITY));
        b[3] = 0;
        assert_eq!(c.u8_uniform(&b, false), None);
        assert_eq!(Brick::U8(Box::new(b)).uniform(&c), None);
        let w = Brick::U16(Box::new([3; BRICK_VOXELS]));
        assert_eq!((w.uniform(&c), w.heap_bytes()), (Some(3.0), 1024));
    }
}
