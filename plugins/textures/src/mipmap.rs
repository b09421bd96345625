//! Texel storage, MIP pyramids and filtered lookups.
//!
//! A [`Level`] is linear RGBA `f32`, rows top to bottom (an 8-bit image's level 0 is held as
//! its bytes and decoded through a table on each read, to the same floats). Texture
//! coordinates `(s, t)` put `(0, 0)` at the bottom-left corner of the image and `(1, 1)` at the
//! top-right, so texel `(x, y)` (column, row from the top) covers `s ∈ [x/w, (x+1)/w)`,
//! `t ∈ (1 - (y+1)/h, 1 - y/h]` and its centre is `((x + 0.5)/w, 1 - (y + 0.5)/h)`.
//!
//! Level `i + 1` has `max(1, ⌊w/2⌋) × max(1, ⌊h/2⌋)` texels. Each of its texels is the exact
//! area average of the texels of level `i` it covers: for an even size that is a 2×2 box; for
//! an odd size `2n + 1` each output texel covers `2 + 1/n` source texels and the three it
//! touches are weighted by their overlap, so every level keeps the image's mean.

use serde::Deserialize;

/// One MIP level.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub width: usize,
    pub height: usize,
    store: Store,
    /// `width` and `height` as f64, converted once (a lookup scales by them).
    size: (f64, f64),
    /// The last column's and row's index as f64 (lookups clamp to them).
    last: (f64, f64),
}

/// How a level's texels are held.
#[derive(Clone, Debug, PartialEq)]
enum Store {
    Floats(Vec<[f32; 4]>),
    /// An 8-bit image's level 0 as its samples (RGBA: grey repeated, a missing alpha 255),
    /// read through `decode` (`[0]` colour, `[1]` alpha): the float texels the converter
    /// makes of them, bit for bit, in a quarter of the memory and of the cache lines a
    /// lookup touches (fog's two maps: 1.5 MB each as floats).
    Bytes {
        codes: Vec<[u8; 4]>,
        decode: Box<[[f32; 256]; 2]>,
        /// `decode` is `code / 255` on every channel (an image read as linear bytes).
        linear: bool,
    },
}

impl Level {
    /// The last column's and row's index, as f64.
    pub fn last(&self) -> (f64, f64) {
        self.last
    }

    pub fn new(width: usize, height: usize, texels: Vec<[f32; 4]>) -> Level {
        Level::with(width, height, texels.len(), Store::Floats(texels))
    }

    /// A level of 8-bit texels: channel `c < 3` of texel `i` is `decode[0][codes[i][c]]`,
    /// its alpha `decode[1][codes[i][3]]`.
    pub fn from_bytes(
        width: usize,
        height: usize,
        codes: Vec<[u8; 4]>,
        decode: [[f32; 256]; 2],
    ) -> Level {
        let n = codes.len();
        let linear = (0..256).all(|i| decode.iter().all(|d| d[i] == i as f32 / 255.0));
        let decode = Box::new(decode);
        let store = Store::Bytes {
            codes,
            decode,
            linear,
        };
        Level::with(width, height, n, store)
    }

    fn with(width: usize, height: usize, n: usize, store: Store) -> Level {
        assert_eq!(n, width * height, "texel count");
        assert!(width > 0 && height > 0, "empty level");
        Level {
            width,
            height,
            store,
            size: (width as f64, height as f64),
            last: ((width - 1) as f64, (height - 1) as f64),
        }
    }

    /// Bytes of texel data.
    pub fn bytes(&self) -> usize {
        match &self.store {
            Store::Floats(t) => std::mem::size_of_val(t.as_slice()),
            Store::Bytes { codes, decode, .. } => {
                std::mem::size_of_val(codes.as_slice()) + std::mem::size_of_val(&**decode)
            }
        }
    }

    /// Whether the texels are held as 8-bit samples.
    pub fn is_bytes(&self) -> bool {
        matches!(self.store, Store::Bytes { .. })
    }

    /// Every texel's value, rows top to bottom.
    pub fn texels(&self) -> std::borrow::Cow<'_, [[f32; 4]]> {
        match &self.store {
            Store::Floats(t) => t.into(),
            Store::Bytes { codes, decode, .. } => {
                codes.iter().map(|&c| decoded(decode, c)).collect()
            }
        }
    }

    fn at(&self, x: usize, y: usize) -> [f32; 4] {
        let i = y * self.width + x;
        match &self.store {
            Store::Floats(t) => t[i],
            Store::Bytes { codes, decode, .. } => decoded(decode, codes[i]),
        }
    }
}

#[inline(always)]
fn decoded(decode: &[[f32; 256]; 2], c: [u8; 4]) -> [f32; 4] {
    let [colour, alpha] = decode;
    [
        colour[c[0] as usize],
        colour[c[1] as usize],
        colour[c[2] as usize],
        alpha[c[3] as usize],
    ]
}

/// Sizes of every level of a `width × height` image, finest first, down to 1×1.
pub fn level_sizes(width: usize, height: usize) -> Vec<(usize, usize)> {
    let mut sizes = vec![(width.max(1), height.max(1))];
    while let Some(&(w, h)) = sizes.last() {
        if w == 1 && h == 1 {
            break;
        }
        sizes.push(((w / 2).max(1), (h / 2).max(1)));
    }
    sizes
}

/// Output sample `x` of a line of `n` samples (read through `get`) reduced to `max(1, n/2)`
/// area averages: the weighted sum of the one to three samples it covers. The one definition of
/// the filter: [`downsample`] and the streaming reducers (`reduce.rs`) both call it, so they
/// agree bit for bit.
#[inline]
pub fn reduce_sample(n: usize, x: usize, get: impl Fn(usize) -> [f32; 4]) -> [f32; 4] {
    if n == 1 {
        return get(0);
    }
    let add = |acc: &mut [f32; 4], w: f32, v: [f32; 4]| {
        for c in 0..4 {
            acc[c] += w * v[c];
        }
    };
    let mut acc = [0.0f32; 4];
    if n.is_multiple_of(2) {
        add(&mut acc, 0.5, get(2 * x));
        add(&mut acc, 0.5, get(2 * x + 1));
    } else {
        let (m, nf) = (n / 2, n as f32);
        add(&mut acc, (m - x) as f32 / nf, get(2 * x));
        add(&mut acc, m as f32 / nf, get(2 * x + 1));
        add(&mut acc, (x + 1) as f32 / nf, get(2 * x + 2));
    }
    acc
}

/// The last input sample output sample `x` of a line of `n` reads (see [`reduce_sample`]).
pub fn last_tap(n: usize, x: usize) -> usize {
    match n {
        1 => 0,
        _ if n.is_multiple_of(2) => 2 * x + 1,
        _ => 2 * x + 2,
    }
}

/// Reduces a line of `n` samples (read through `get`) to `max(1, n/2)` area averages.
pub fn reduce_line(
    n: usize,
    get: impl Fn(usize) -> [f32; 4],
    mut put: impl FnMut(usize, [f32; 4]),
) {
    for x in 0..(n / 2).max(1) {
        put(x, reduce_sample(n, x, &get));
    }
}

/// The next coarser level (separable: rows first, then columns). The reference definition of
/// the MIP filter: images are reduced row by row as they are decoded (`reduce.rs`), which is
/// tested to give these texels bit for bit.
#[cfg(test)]
pub fn downsample(src: &Level) -> Level {
    let (w, h) = (src.width, src.height);
    let (mw, mh) = ((w / 2).max(1), (h / 2).max(1));
    let mut rows = vec![[0.0f32; 4]; mw * h];
    for y in 0..h {
        reduce_line(w, |x| src.at(x, y), |x, v| rows[y * mw + x] = v);
    }
    let mut out = vec![[0.0f32; 4]; mw * mh];
    for x in 0..mw {
        reduce_line(h, |y| rows[y * mw + x], |y, v| out[y * mw + x] = v);
    }
    Level::new(mw, mh, out)
}

/// Every level, finest (the image itself) first.
#[cfg(test)]
pub fn build_pyramid(base: Level) -> Vec<Level> {
    let mut levels = vec![base];
    loop {
        let last = levels.last().expect("at least the base");
        if last.width == 1 && last.height == 1 {
            return levels;
        }
        let next = downsample(last);
        levels.push(next);
    }
}

/// Bytes of the float RGBA texels of levels of these sizes.
pub fn pyramid_bytes(sizes: &[(usize, usize)]) -> u64 {
    sizes
        .iter()
        .map(|&(w, h)| w as u64 * h as u64 * std::mem::size_of::<[f32; 4]>() as u64)
        .sum()
}

/// What a lookup outside [0, 1) does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum Wrap {
    /// Tile the image (modulo).
    #[default]
    #[serde(rename = "repeat", alias = "Repeat")]
    Repeat,
    /// Extend the edge texels.
    #[serde(rename = "clamp", alias = "Clamp")]
    Clamp,
    /// Tile with every other copy mirrored, so edges meet seamlessly.
    #[serde(rename = "mirror", alias = "Mirror")]
    Mirror,
}

/// Texel index `i` on an axis of `n` texels under `wrap`. Always inlined: a lookup calls it
/// four times, mostly for the first branch.
#[inline(always)]
pub fn wrap_index(i: i64, n: usize, wrap: Wrap) -> usize {
    // Inside the image every rule keeps the index: no division (most lookups).
    if (i as u64) < n as u64 {
        return i as usize;
    }
    let n = n as i64;
    (match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let k = i.rem_euclid(2 * n);
            if k < n {
                k
            } else {
                2 * n - 1 - k
            }
        }
    }) as usize
}

/// Texel indices `i` and `i + 1` on an axis of `n` texels under `wrap`, as [`wrap_index`]
/// gives them; repeating, the second follows from the first without a second division.
#[inline(always)]
pub fn wrap_pair(i: i64, n: usize, wrap: Wrap) -> (usize, usize) {
    let a = wrap_index(i, n, wrap);
    if wrap == Wrap::Repeat && i < i64::MAX {
        // (i + 1) mod n = (i mod n + 1) mod n.
        return (a, if a + 1 < n { a + 1 } else { 0 });
    }
    (a, wrap_index(i.saturating_add(1), n, wrap))
}

/// Continuous texel coordinates of `(s, t)` on `level` (texel centres at integers + 0.5);
/// non-finite coordinates become 0.
fn texel_coords(level: &Level, s: f64, t: f64) -> (f64, f64) {
    let s = if s.is_finite() { s } else { 0.0 };
    let t = if t.is_finite() { t } else { 0.0 };
    (s * level.size.0, (1.0 - t) * level.size.1)
}

/// The texel containing `(s, t)`.
pub fn nearest(level: &Level, s: f64, t: f64, wrap: Wrap) -> [f32; 4] {
    let (x, y) = texel_coords(level, s, t);
    // `as` saturates, so far-away coordinates cannot overflow.
    let xi = wrap_index(x.floor() as i64, level.width, wrap);
    let yi = wrap_index(y.floor() as i64, level.height, wrap);
    level.at(xi, yi)
}

/// Bilinear interpolation between the four texel centres around `(s, t)`.
pub fn bilinear(level: &Level, s: f64, t: f64, wrap: Wrap) -> [f32; 4] {
    // One copy per rule, the rule a constant in each: no branches on it per texel index.
    match wrap {
        Wrap::Repeat => bilinear_with(level, s, t, Wrap::Repeat),
        Wrap::Clamp => bilinear_with(level, s, t, Wrap::Clamp),
        Wrap::Mirror => bilinear_with(level, s, t, Wrap::Mirror),
    }
}

#[inline(always)]
fn bilinear_with(level: &Level, s: f64, t: f64, wrap: Wrap) -> [f32; 4] {
    // The store decided once, outside the texel reads.
    match &level.store {
        Store::Floats(texels) => bilinear_in(level, s, t, wrap, |i| texels[i]),
        Store::Bytes { codes, decode, .. } => {
            bilinear_in(level, s, t, wrap, |i| decoded(decode, codes[i]))
        }
    }
}

#[inline(always)]
fn bilinear_in(
    level: &Level,
    s: f64,
    t: f64,
    wrap: Wrap,
    texel: impl Fn(usize) -> [f32; 4],
) -> [f32; 4] {
    let (x, y) = texel_coords(level, s, t);
    let (x, y) = (x - 0.5, y - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let (xa, xb) = wrap_pair(x0, level.width, wrap);
    let (ya, yb) = wrap_pair(y0, level.height, wrap);
    blend(level.width, [xa, xb, ya, yb], fx, fy, texel)
}

/// The four texels at columns `xa`, `xb` and rows `ya`, `yb` of a level `w` wide, blended by
/// `fx` across and `fy` down.
#[inline(always)]
fn blend(
    w: usize,
    [xa, xb, ya, yb]: [usize; 4],
    fx: f32,
    fy: f32,
    texel: impl Fn(usize) -> [f32; 4],
) -> [f32; 4] {
    let (p00, p10, p01, p11) = (
        texel(ya * w + xa),
        texel(ya * w + xb),
        texel(yb * w + xa),
        texel(yb * w + xb),
    );
    std::array::from_fn(|c| {
        let top = p00[c] + (p10[c] - p00[c]) * fx;
        let bottom = p01[c] + (p11[c] - p01[c]) * fx;
        top + (bottom - top) * fy
    })
}

/// Bilinear between the texel centres around texel position (`x`, `y`) (centres at integers,
/// `y` from the top row), each within [0, size − 1]: nothing wraps, a last row or column is
/// its own neighbour.
pub fn bilinear_inside(level: &Level, x: f64, y: f64) -> [f32; 4] {
    match &level.store {
        Store::Floats(texels) => inside(level, x, y, |i| texels[i]),
        // Linear bytes: blended as their codes, divided once (not four table reads each).
        Store::Bytes {
            codes,
            linear: true,
            ..
        } => inside(level, x, y, |i| codes[i].map(f32::from)).map(|c| c / 255.0),
        Store::Bytes { codes, decode, .. } => inside(level, x, y, |i| decoded(decode, codes[i])),
    }
}

#[inline(always)]
fn inside(level: &Level, x: f64, y: f64, texel: impl Fn(usize) -> [f32; 4]) -> [f32; 4] {
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
    let (w, h) = (level.width, level.height);
    let (xa, ya) = (index(x0, level.last.0), index(y0, level.last.1));
    let (xb, yb) = ((xa + 1).min(w - 1), (ya + 1).min(h - 1));
    blend(w, [xa, xb, ya, yb], fx, fy, texel)
}

/// Whole `x` clamped to [0, `last`] as an index; NaN gives 0. (Clamped as f64 first: the
/// cast is then to i64, a few instructions, not a saturating one to usize.)
#[inline(always)]
fn index(x: f64, last: f64) -> usize {
    // `max` passes over a NaN.
    x.max(0.0).min(last) as i64 as usize
}

/// The continuous MIP level for a footprint `texels` wide on level 0: `log2(texels)`, clamped
/// to `[0, levels - 1]` (a footprint of at most one texel, or 0, is level 0).
pub fn mip_level(texels: f64, levels: usize) -> f64 {
    if texels.is_nan() || texels <= 1.0 {
        return 0.0;
    }
    texels.log2().min(levels.saturating_sub(1) as f64)
}

/// Which two levels a continuous level falls between, and the weight of the coarser one.
pub fn level_pair(level: f64, levels: usize) -> (usize, usize, f32) {
    let lo = (level.floor() as usize).min(levels - 1);
    let hi = (lo + 1).min(levels - 1);
    let f = if hi == lo {
        0.0
    } else {
        (level - lo as f64) as f32
    };
    (lo, hi, f)
}

/// Trilinear: bilinear on two adjacent levels, blended by `f` (the weight of `b`).
pub fn trilinear(a: &Level, b: &Level, f: f32, s: f64, t: f64, wrap: Wrap) -> [f32; 4] {
    let ca = bilinear(a, s, t, wrap);
    if f <= 0.0 {
        return ca;
    }
    let cb = bilinear(b, s, t, wrap);
    std::array::from_fn(|c| ca[c] + (cb[c] - ca[c]) * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: f32) -> [f32; 4] {
        [v, v, v, 1.0]
    }

    /// A `w × h` level whose texel (x, y) is grey `x + 10 y`.
    fn ramp(w: usize, h: usize) -> Level {
        let t = (0..h)
            .flat_map(|y| (0..w).map(move |x| grey((x + 10 * y) as f32)))
            .collect();
        Level::new(w, h, t)
    }

    fn centre(l: &Level, x: usize, y: usize) -> (f64, f64) {
        (
            (x as f64 + 0.5) / l.width as f64,
            1.0 - (y as f64 + 0.5) / l.height as f64,
        )
    }

    fn mean(l: &Level) -> f64 {
        l.texels().iter().map(|t| t[0] as f64).sum::<f64>() / l.texels().len() as f64
    }

    #[test]
    fn sizes_handle_non_powers_of_two() {
        assert_eq!(level_sizes(8, 8), [(8, 8), (4, 4), (2, 2), (1, 1)]);
        assert_eq!(
            level_sizes(5, 3),
            [(5, 3), (2, 1), (1, 1)],
            "odd sizes round down"
        );
        assert_eq!(
            level_sizes(7, 1),
            [(7, 1), (3, 1), (1, 1)],
            "a 1-texel axis stays 1"
        );
        assert_eq!(level_sizes(1, 1), [(1, 1)]);
    }

    #[test]
    fn even_levels_are_2x2_boxes() {
        let l1 = downsample(&ramp(4, 2));
        assert_eq!((l1.width, l1.height), (2, 1));
        // (0 + 1 + 10 + 11) / 4 and (2 + 3 + 12 + 13) / 4.
        assert_eq!(*l1.texels(), [grey(5.5), grey(7.5)]);
    }

    #[test]
    fn pyramid_of_a_non_power_of_two_image() {
        let base = ramp(5, 3);
        let m0 = mean(&base);
        let p = build_pyramid(base);
        assert_eq!(p.len(), 3);
        assert_eq!((p[1].width, p[1].height), (2, 1));
        assert_eq!((p[2].width, p[2].height), (1, 1));
        // Level 1, texel 0: columns 0, 1, 2 weighted 2/5, 2/5, 1/5, of rows averaged 1/3 each.
        // Row means of column x are x + 10; so (0.4·10 + 0.4·11 + 0.2·12) = 10.8.
        assert!(
            (p[1].texels()[0][0] - 10.8).abs() < 1e-5,
            "{:?}",
            p[1].texels()
        );
        // Texel 1: columns 2, 3, 4 weighted 1/5, 2/5, 2/5: 0.2·12 + 0.4·13 + 0.4·14 = 13.2.
        assert!(
            (p[1].texels()[1][0] - 13.2).abs() < 1e-5,
            "{:?}",
            p[1].texels()
        );
        // The mean survives every level; the last texel is the image's mean.
        for l in &p {
            assert!((mean(l) - m0).abs() < 1e-4, "{} vs {m0}", mean(l));
        }
        assert!((p[2].texels()[0][0] as f64 - m0).abs() < 1e-4);
        assert!(p.iter().all(|l| l.texels().iter().all(|t| t[3] == 1.0)));
    }

    #[test]
    fn nearest_and_bilinear_at_centres_and_between() {
        let l = ramp(4, 3);
        for y in 0..3 {
            for x in 0..4 {
                let (s, t) = centre(&l, x, y);
                let want = grey((x + 10 * y) as f32);
                assert_eq!(nearest(&l, s, t, Wrap::Clamp), want);
                assert_eq!(bilinear(&l, s, t, Wrap::Clamp), want);
            }
        }
        // Half-way between the centres of (1, 1) and (2, 1): bilinear averages, nearest picks.
        let s = 2.0 / 4.0;
        let t = 1.0 - 1.5 / 3.0;
        assert_eq!(bilinear(&l, s, t, Wrap::Clamp), grey(11.5));
        assert_eq!(nearest(&l, s, t, Wrap::Clamp), grey(12.0));
        // A quarter of the way towards (2, 2) as well: 11 + 0.5 + 0.25·10.
        let t = 1.0 - 1.75 / 3.0;
        let v = bilinear(&l, s, t, Wrap::Clamp)[0];
        assert!((v - 14.0).abs() < 1e-5, "{v}");
        assert_eq!(nearest(&l, 0.01, 0.99, Wrap::Clamp), grey(0.0));
        assert_eq!(nearest(&l, 0.99, 0.01, Wrap::Clamp), grey(23.0));
    }

    #[test]
    fn byte_texels_look_up_as_their_floats() {
        let (w, h) = (7, 5);
        let codes: Vec<[u8; 4]> = (0..w * h)
            .map(|i| std::array::from_fn(|c| ((i * 37 + c * 101) % 256) as u8))
            .collect();
        let decode = [
            std::array::from_fn(|i| crate::texels::srgb_to_linear(i as f32 / 255.0)),
            std::array::from_fn(|i| i as f32 / 255.0),
        ];
        let bytes = Level::from_bytes(w, h, codes.clone(), decode);
        let floats = Level::new(w, h, bytes.texels().into_owned());
        assert!(bytes.is_bytes() && !floats.is_bytes());
        assert_eq!(bytes.texels()[8], floats.texels()[8]);
        let c = codes[8];
        assert_eq!(bytes.texels()[8][3], c[3] as f32 / 255.0, "alpha is linear");
        assert_eq!(bytes.bytes(), w * h * 4 + 2 * 256 * 4);
        let bits = |v: [f32; 4]| v.map(f32::to_bits);
        for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror] {
            for k in 0..200 {
                let (s, t) = (k as f64 * 0.0137 - 0.7, k as f64 * 0.0291 - 1.3);
                assert_eq!(
                    bits(bilinear(&bytes, s, t, wrap)),
                    bits(bilinear(&floats, s, t, wrap))
                );
                assert_eq!(
                    bits(nearest(&bytes, s, t, wrap)),
                    bits(nearest(&floats, s, t, wrap))
                );
            }
        }
    }

    #[test]
    fn wrap_modes() {
        assert_eq!(
            (-3..7)
                .map(|i| wrap_index(i, 4, Wrap::Repeat))
                .collect::<Vec<_>>(),
            [1, 2, 3, 0, 1, 2, 3, 0, 1, 2]
        );
        assert_eq!(
            (-3..7)
                .map(|i| wrap_index(i, 4, Wrap::Clamp))
                .collect::<Vec<_>>(),
            [0, 0, 0, 0, 1, 2, 3, 3, 3, 3]
        );
        assert_eq!(
            (-3..9)
                .map(|i| wrap_index(i, 4, Wrap::Mirror))
                .collect::<Vec<_>>(),
            [2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]
        );
        // Pairs of neighbours agree with the rule applied to each, also at the extremes.
        for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror] {
            for n in [1, 2, 5] {
                let far = [i64::MIN, i64::MIN + 1, i64::MAX - 1, i64::MAX];
                for i in (-12..12).chain(far) {
                    let want = (
                        wrap_index(i, n, wrap),
                        wrap_index(i.saturating_add(1), n, wrap),
                    );
                    assert_eq!(wrap_pair(i, n, wrap), want, "{wrap:?} {i} of {n}");
                }
            }
        }
        let l = ramp(4, 1);
        // s = 1.1 is texel 4.4: repeat -> 0, clamp -> 3, mirror -> 3.
        assert_eq!(nearest(&l, 1.1, 0.5, Wrap::Repeat), grey(0.0));
        assert_eq!(nearest(&l, 1.1, 0.5, Wrap::Clamp), grey(3.0));
        assert_eq!(nearest(&l, 1.1, 0.5, Wrap::Mirror), grey(3.0));
        // s = 1.3 is texel 5.2: repeat -> 1, clamp -> 3, mirror -> 2.
        assert_eq!(nearest(&l, 1.3, 0.5, Wrap::Repeat), grey(1.0));
        assert_eq!(nearest(&l, 1.3, 0.5, Wrap::Mirror), grey(2.0));
        // s = -0.2 is texel -0.8: repeat -> 3, clamp -> 0, mirror -> 0.
        assert_eq!(nearest(&l, -0.2, 0.5, Wrap::Repeat), grey(3.0));
        assert_eq!(nearest(&l, -0.2, 0.5, Wrap::Clamp), grey(0.0));
        assert_eq!(nearest(&l, -0.2, 0.5, Wrap::Mirror), grey(0.0));
        // Bilinear across the seam at s = 0 (between texel centres 3 and 0):
        // repeat blends the last and first texels, clamp holds the edge.
        assert_eq!(bilinear(&l, 0.0, 0.5, Wrap::Repeat), grey(1.5));
        assert_eq!(bilinear(&l, 0.0, 0.5, Wrap::Clamp), grey(0.0));
        assert_eq!(bilinear(&l, 0.0, 0.5, Wrap::Mirror), grey(0.0));
        // Far away and non-finite coordinates do not panic.
        let _ = bilinear(&l, 1e300, -1e300, Wrap::Repeat);
        let _ = nearest(&l, f64::NAN, f64::INFINITY, Wrap::Mirror);
    }

    #[test]
    fn level_selection_from_footprint() {
        assert_eq!(mip_level(0.0, 7), 0.0, "footprint 0 is level 0");
        assert_eq!(mip_level(0.5, 7), 0.0);
        assert_eq!(mip_level(1.0, 7), 0.0);
        assert_eq!(mip_level(2.0, 7), 1.0);
        assert_eq!(mip_level(4.0, 7), 2.0, "4 texels is level 2");
        assert!((mip_level(6.0, 7) - 6f64.log2()).abs() < 1e-12);
        assert_eq!(mip_level(1e9, 7), 6.0, "clamped to the last level");
        assert_eq!(mip_level(f64::NAN, 7), 0.0);
        assert_eq!(level_pair(2.0, 7), (2, 3, 0.0));
        assert_eq!(level_pair(2.25, 7), (2, 3, 0.25));
        assert_eq!(level_pair(6.0, 7), (6, 6, 0.0));
    }

    #[test]
    fn trilinear_blends_between_levels() {
        // Level k filled with the value k: the result is the continuous level itself.
        let sizes = level_sizes(64, 64);
        let levels: Vec<Level> = sizes
            .iter()
            .enumerate()
            .map(|(k, &(w, h))| Level::new(w, h, vec![grey(k as f32); w * h]))
            .collect();
        for texels in [0.0, 1.0, 3.0, 4.0, 6.0, 11.0, 64.0, 1000.0] {
            let lambda = mip_level(texels, levels.len());
            let (lo, hi, f) = level_pair(lambda, levels.len());
            let v = trilinear(&levels[lo], &levels[hi], f, 0.3, 0.6, Wrap::Repeat)[0];
            assert!(
                (v as f64 - lambda).abs() < 1e-6,
                "{texels}: {v} vs {lambda}"
            );
        }
        // 6 texels: between level 2 and 3, 58.5 % of the way.
        let (lo, hi, f) = level_pair(mip_level(6.0, levels.len()), levels.len());
        assert_eq!((lo, hi), (2, 3));
        assert!((f - 0.585).abs() < 1e-3);
    }
}
