//! MIP levels built row by row, as an image is decoded: a cascade of 2× reducers.
//!
//! [`Pyramid`] takes the rows of level 0, top to bottom, and keeps only the levels from
//! `first` down to 1×1 (or level `first` alone, when no MIP levels are wanted). Level 0 is never held whole (unless `first` is 0): each reducer holds
//! at most three rows of its input, reduced horizontally, and emits a row of the next level as
//! soon as the rows it covers have arrived. The arithmetic is [`reduce_sample`]'s, in the order
//! `mipmap::downsample` uses (each row horizontally, then each column vertically), so every
//! level equals the one the whole-image filter gives, bit for bit.
//!
//! Memory: the kept levels, plus about `3 × width/2 × 16` bytes for the first reducer and half
//! as much for each next one.

use crate::mipmap::{last_tap, level_sizes, reduce_line, reduce_sample, Level};
use std::collections::VecDeque;

type Texel = [f32; 4];

/// A vector of `n` texels, or an error instead of an abort when the system refuses.
fn alloc(n: usize, what: &str) -> Result<Vec<Texel>, String> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        format!(
            "cannot allocate {} MiB for {what}",
            (n * std::mem::size_of::<Texel>()) >> 20
        )
    })?;
    Ok(v)
}

/// Reduces one level to the next, a row at a time.
struct Reducer {
    /// Size of the input level.
    w: usize,
    h: usize,
    /// Width of the output level.
    mw: usize,
    /// Input rows already reduced horizontally, the oldest being row `base`.
    window: VecDeque<Vec<Texel>>,
    base: usize,
    /// Rows received, output rows emitted.
    received: usize,
    emitted: usize,
    /// Buffers of dropped rows, reused.
    spare: Vec<Vec<Texel>>,
    /// The last output row.
    out: Vec<Texel>,
}

impl Reducer {
    fn new(w: usize, h: usize) -> Reducer {
        let mw = (w / 2).max(1);
        Reducer {
            w,
            h,
            mw,
            window: VecDeque::with_capacity(3),
            base: 0,
            received: 0,
            emitted: 0,
            spare: Vec::new(),
            out: vec![[0.0; 4]; mw],
        }
    }

    /// Takes the next input row; returns the output row it completes, if any (at most one).
    fn push(&mut self, row: &[Texel]) -> Option<&[Texel]> {
        debug_assert_eq!(row.len(), self.w);
        let mut reduced = self.spare.pop().unwrap_or_default();
        reduced.resize(self.mw, [0.0; 4]);
        reduce_line(self.w, |x| row[x], |x, v| reduced[x] = v);
        self.window.push_back(reduced);
        self.received += 1;
        let mh = (self.h / 2).max(1);
        if self.emitted == mh || last_tap(self.h, self.emitted) >= self.received {
            return None;
        }
        let y = self.emitted;
        let (base, h) = (self.base, self.h);
        let mut rows: [&[Texel]; 3] = [&[]; 3];
        for (r, held) in rows.iter_mut().zip(&self.window) {
            *r = held;
        }
        for (x, out) in self.out.iter_mut().enumerate() {
            *out = reduce_sample(h, y, |i| rows[i - base][x]);
        }
        self.emitted += 1;
        // The next output row starts at input row 2 × emitted; older rows are done with.
        while self.base < 2 * self.emitted && !self.window.is_empty() {
            self.spare.extend(self.window.pop_front());
            self.base += 1;
        }
        Some(&self.out)
    }
}

/// The MIP levels `first..` of a `width × height` image, fed the rows of level 0.
pub struct Pyramid {
    sizes: Vec<(usize, usize)>,
    first: usize,
    reducers: Vec<Reducer>,
    /// Texels of levels `first..`, filled as their rows arrive (allocated at their first row, so
    /// a file that claims a large image but holds little data costs little).
    levels: Vec<Vec<Texel>>,
    rows: usize,
}

impl Pyramid {
    /// `first` may be past the last level (1×1): then only the last level is kept. Without
    /// `mip`, only level `first` is kept, and nothing coarser is computed.
    pub fn new(width: usize, height: usize, first: usize, mip: bool) -> Pyramid {
        let sizes = level_sizes(width, height);
        let first = first.min(sizes.len() - 1);
        let last = if mip { sizes.len() - 1 } else { first };
        let reducers = sizes[..last]
            .iter()
            .map(|&(w, h)| Reducer::new(w, h))
            .collect();
        let levels = vec![Vec::new(); last + 1 - first];
        Pyramid {
            sizes,
            first,
            reducers,
            levels,
            rows: 0,
        }
    }

    /// Size of level 0.
    pub fn width(&self) -> usize {
        self.sizes[0].0
    }

    /// Takes the next row of level 0 (`width` texels).
    pub fn push_row(&mut self, row: &[Texel]) -> Result<(), String> {
        if row.len() != self.width() || self.rows == self.sizes[0].1 {
            return Err(format!(
                "the image has more rows or wider rows than its header says ({}x{})",
                self.sizes[0].0, self.sizes[0].1
            ));
        }
        self.rows += 1;
        let Pyramid {
            sizes,
            first,
            reducers,
            levels,
            ..
        } = self;
        let mut keep = |level: usize, row: &[Texel]| -> Result<(), String> {
            if level < *first {
                return Ok(());
            }
            let texels = &mut levels[level - *first];
            if texels.capacity() == 0 {
                let (w, h) = sizes[level];
                *texels = alloc(w * h, &format!("MIP level {level} ({w}x{h})"))?;
            }
            texels.extend_from_slice(row);
            Ok(())
        };
        keep(0, row)?;
        let mut input = row;
        for (i, reducer) in reducers.iter_mut().enumerate() {
            let Some(out) = reducer.push(input) else {
                break;
            };
            keep(i + 1, out)?;
            input = out;
        }
        Ok(())
    }

    /// The kept levels, finest first; an error if rows are missing.
    pub fn finish(self) -> Result<Vec<Level>, String> {
        let (w, h) = self.sizes[0];
        if self.rows != h {
            return Err(format!(
                "the image ends after {} of its {h} rows ({w}x{h})",
                self.rows
            ));
        }
        Ok(self
            .levels
            .into_iter()
            .zip(&self.sizes[self.first..])
            .map(|(texels, &(w, h))| Level::new(w, h, texels))
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mipmap::build_pyramid;

    /// A level of pseudo-random texels (values of many magnitudes, some negative zeros).
    fn noise(w: usize, h: usize, seed: u64) -> Level {
        let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let v = (s >> 40) as f32 / (1u64 << 24) as f32;
            match s % 7 {
                0 => -0.0,
                1 => v * 1000.0,
                _ => v,
            }
        };
        let texels = (0..w * h)
            .map(|_| [next(), next(), next(), next()])
            .collect();
        Level::new(w, h, texels)
    }

    fn streamed(base: &Level, first: usize) -> Vec<Level> {
        let mut p = Pyramid::new(base.width, base.height, first, true);
        for row in base.texels().chunks(base.width) {
            p.push_row(row).unwrap();
        }
        p.finish().unwrap()
    }

    fn bits(l: &Level) -> Vec<[u32; 4]> {
        l.texels().iter().map(|t| t.map(f32::to_bits)).collect()
    }

    #[test]
    fn streaming_equals_the_whole_image_filter_bit_for_bit() {
        let sizes = [
            (1, 1),
            (1, 7),
            (7, 1),
            (2, 2),
            (5, 3),
            (3, 5),
            (64, 64),
            (37, 23),
            (1023, 517),
            (6, 1),
            (2, 9),
        ];
        for (n, &(w, h)) in sizes.iter().enumerate() {
            let base = noise(w, h, n as u64 + 1);
            let want = build_pyramid(base.clone());
            for first in 0..want.len() {
                let got = streamed(&base, first);
                assert_eq!(got.len(), want.len() - first, "{w}x{h} from {first}");
                for (k, (g, l)) in got.iter().zip(&want[first..]).enumerate() {
                    assert_eq!((g.width, g.height), (l.width, l.height));
                    assert!(
                        bits(g) == bits(l),
                        "{w}x{h}, first {first}: level {} differs",
                        first + k
                    );
                }
            }
        }
    }

    #[test]
    fn without_mip_only_the_first_level_is_built_the_same() {
        for (n, &(w, h)) in [(1, 1), (5, 3), (37, 23), (64, 64), (6, 1)]
            .iter()
            .enumerate()
        {
            let base = noise(w, h, n as u64 + 20);
            let want = build_pyramid(base.clone());
            for first in 0..want.len() + 1 {
                let mut p = Pyramid::new(w, h, first, false);
                assert_eq!(p.reducers.len(), first.min(want.len() - 1));
                for row in base.texels().chunks(w) {
                    p.push_row(row).unwrap();
                }
                let got = p.finish().unwrap();
                let l = &want[first.min(want.len() - 1)];
                assert_eq!(got.len(), 1, "{w}x{h} from {first}");
                assert_eq!((got[0].width, got[0].height), (l.width, l.height));
                assert!(bits(&got[0]) == bits(l), "{w}x{h}: level {first} differs");
            }
        }
    }

    #[test]
    fn only_the_kept_levels_are_held() {
        let base = noise(1024, 1024, 9);
        let mut p = Pyramid::new(1024, 1024, 2, true);
        for row in base.texels().chunks(1024) {
            p.push_row(row).unwrap();
            // Each reducer holds at most three rows.
            assert!(p.reducers.iter().all(|r| r.window.len() <= 3));
        }
        assert!(p.levels[0].capacity() == 256 * 256, "level 2 exactly");
        let levels = p.finish().unwrap();
        assert_eq!(levels.len(), 9, "256 down to 1");
        assert_eq!((levels[0].width, levels[8].width), (256, 1));
        // Far past the last level: only 1×1.
        assert_eq!(streamed(&noise(5, 3, 2), 10).len(), 1);
    }

    #[test]
    fn missing_and_extra_rows_are_errors() {
        let base = noise(4, 3, 3);
        let mut p = Pyramid::new(4, 3, 0, true);
        p.push_row(&base.texels()[..4]).unwrap();
        let e = p.finish().unwrap_err();
        assert!(e.contains("ends after 1 of its 3 rows"), "{e}");
        let mut p = Pyramid::new(4, 1, 0, true);
        p.push_row(&base.texels()[..4]).unwrap();
        assert!(p.push_row(&base.texels()[4..8]).is_err());
        assert!(Pyramid::new(4, 1, 0, true)
            .push_row(&base.texels()[..3])
            .is_err());
    }
}
