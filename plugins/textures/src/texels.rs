//! A decoded row of samples, at the source's precision, turned into linear RGBA texels.
//!
//! Integer sources (8 and 16 bits) are sRGB-encoded unless `srgb` is false; their alpha is
//! linear. Float sources are linear already. Grey becomes grey RGB; a missing alpha is 1.

/// How one sample is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sample {
    U8,
    /// Big-endian, as PNG rows are.
    U16Be,
    /// Native-endian, as the `image` crate's buffers are.
    U16Ne,
    F32Ne,
}

impl Sample {
    fn bytes(self) -> usize {
        match self {
            Sample::U8 => 1,
            Sample::U16Be | Sample::U16Ne => 2,
            Sample::F32Ne => 4,
        }
    }
}

/// The layout of a row: the sample type and the channels per texel (1 grey, 2 grey and
/// alpha, 3 RGB, 4 RGBA).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RowFormat {
    pub sample: Sample,
    pub channels: usize,
}

impl RowFormat {
    /// The format of the `image` crate's decoded buffer, if one Luxon reads.
    pub fn of_image(c: image::ColorType) -> Option<RowFormat> {
        use image::ColorType::*;
        let (sample, channels) = match c {
            L8 => (Sample::U8, 1),
            La8 => (Sample::U8, 2),
            Rgb8 => (Sample::U8, 3),
            Rgba8 => (Sample::U8, 4),
            L16 => (Sample::U16Ne, 1),
            La16 => (Sample::U16Ne, 2),
            Rgb16 => (Sample::U16Ne, 3),
            Rgba16 => (Sample::U16Ne, 4),
            Rgb32F => (Sample::F32Ne, 3),
            Rgba32F => (Sample::F32Ne, 4),
            _ => return None,
        };
        Some(RowFormat { sample, channels })
    }

    /// The format of the `png` crate's rows (after `EXPAND`: no palette, no fewer than 8 bits).
    pub fn of_png(c: png::ColorType, depth: png::BitDepth) -> Option<RowFormat> {
        let sample = match depth {
            png::BitDepth::Eight => Sample::U8,
            png::BitDepth::Sixteen => Sample::U16Be,
            _ => return None,
        };
        let channels = match c {
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Indexed => return None,
        };
        Some(RowFormat { sample, channels })
    }

    pub fn bytes_per_texel(self) -> usize {
        self.sample.bytes() * self.channels
    }
}

/// The sRGB transfer function, decoded to linear.
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// Converts rows of one format.
pub struct Converter {
    format: RowFormat,
    srgb: bool,
    /// Colour of each 8-bit value.
    table: [f32; 256],
}

impl Converter {
    pub fn new(format: RowFormat, srgb: bool) -> Converter {
        let table = std::array::from_fn(|i| {
            let x = i as f32 / 255.0;
            if srgb {
                srgb_to_linear(x)
            } else {
                x
            }
        });
        Converter {
            format,
            srgb,
            table,
        }
    }

    /// One texel's colour channel and alpha, from its raw sample.
    fn colour(&self, raw: &[u8]) -> f32 {
        match self.format.sample {
            Sample::U8 => self.table[raw[0] as usize],
            Sample::U16Be | Sample::U16Ne => {
                let x = self.u16(raw) as f32 / 65535.0;
                if self.srgb {
                    srgb_to_linear(x)
                } else {
                    x
                }
            }
            Sample::F32Ne => f32::from_ne_bytes([raw[0], raw[1], raw[2], raw[3]]),
        }
    }

    fn alpha(&self, raw: &[u8]) -> f32 {
        match self.format.sample {
            Sample::U8 => raw[0] as f32 / 255.0,
            Sample::U16Be | Sample::U16Ne => self.u16(raw) as f32 / 65535.0,
            Sample::F32Ne => f32::from_ne_bytes([raw[0], raw[1], raw[2], raw[3]]),
        }
    }

    fn u16(&self, raw: &[u8]) -> u16 {
        let b = [raw[0], raw[1]];
        match self.format.sample {
            Sample::U16Be => u16::from_be_bytes(b),
            _ => u16::from_ne_bytes(b),
        }
    }

    /// Whether rows are 8-bit samples, which [`Converter::codes`] keeps as they are.
    pub fn is_u8(&self) -> bool {
        self.format.sample == Sample::U8
    }

    /// What [`Converter::codes`]'s bytes decode to: `[0]` a colour sample's value, `[1]` an
    /// alpha sample's (the values [`Converter::row`] gives them).
    pub fn decode_table(&self) -> [[f32; 256]; 2] {
        [self.table, std::array::from_fn(|i| i as f32 / 255.0)]
    }

    /// Appends the texels of a row of 8-bit samples as RGBA bytes (grey repeated, a missing
    /// alpha 255, which decodes to 1): [`Converter::row`]'s texels through
    /// [`Converter::decode_table`].
    pub fn codes(&self, row: &[u8], out: &mut Vec<[u8; 4]>) {
        debug_assert!(self.is_u8());
        match self.format.channels {
            1 => out.extend(row.iter().map(|&l| [l, l, l, 255])),
            2 => out.extend(row.chunks_exact(2).map(|p| [p[0], p[0], p[0], p[1]])),
            3 => out.extend(row.chunks_exact(3).map(|p| [p[0], p[1], p[2], 255])),
            _ => out.extend(row.chunks_exact(4).map(|p| [p[0], p[1], p[2], p[3]])),
        }
    }

    /// Converts `row` (at least `out.len()` texels of samples) into `out`.
    pub fn row(&self, row: &[u8], out: &mut [[f32; 4]]) {
        if self.format.sample == Sample::U8 {
            return self.row_u8(row, out);
        }
        let s = self.format.sample.bytes();
        let texel = self.format.bytes_per_texel();
        for (raw, o) in row.chunks_exact(texel).zip(out.iter_mut()) {
            let ch = |i: usize| &raw[i * s..(i + 1) * s];
            *o = match self.format.channels {
                1 => {
                    let l = self.colour(ch(0));
                    [l, l, l, 1.0]
                }
                2 => {
                    let l = self.colour(ch(0));
                    [l, l, l, self.alpha(ch(1))]
                }
                3 => [
                    self.colour(ch(0)),
                    self.colour(ch(1)),
                    self.colour(ch(2)),
                    1.0,
                ],
                _ => [
                    self.colour(ch(0)),
                    self.colour(ch(1)),
                    self.colour(ch(2)),
                    self.alpha(ch(3)),
                ],
            };
        }
    }

    /// [`Converter::row`] for 8-bit samples (most image maps), the same values (`colour` and
    /// `alpha` of one byte) read straight from the table, a loop per layout.
    fn row_u8(&self, row: &[u8], out: &mut [[f32; 4]]) {
        let t = &self.table;
        let a = |x: u8| x as f32 / 255.0;
        match self.format.channels {
            1 => {
                for (&l, o) in row.iter().zip(out.iter_mut()) {
                    let l = t[l as usize];
                    *o = [l, l, l, 1.0];
                }
            }
            2 => {
                for (raw, o) in row.chunks_exact(2).zip(out.iter_mut()) {
                    let l = t[raw[0] as usize];
                    *o = [l, l, l, a(raw[1])];
                }
            }
            3 => {
                for (raw, o) in row.chunks_exact(3).zip(out.iter_mut()) {
                    let c = |i: usize| t[raw[i] as usize];
                    *o = [c(0), c(1), c(2), 1.0];
                }
            }
            _ => {
                let n = self.format.channels;
                for (raw, o) in row.chunks_exact(n).zip(out.iter_mut()) {
                    let c = |i: usize| t[raw[i] as usize];
                    *o = [c(0), c(1), c(2), a(raw[3])];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 8-bit rows of every layout give each channel's `colour` (alpha: `alpha`), sRGB or not.
    #[test]
    fn eight_bit_rows_read_the_table() {
        let bytes: Vec<u8> = (0..48u32).map(|i| (i * 53 % 256) as u8).collect();
        for channels in 1..=4 {
            for srgb in [false, true] {
                let sample = Sample::U8;
                let c = Converter::new(RowFormat { sample, channels }, srgb);
                let mut out = vec![[0.0; 4]; bytes.len() / channels];
                c.row(&bytes, &mut out);
                for (raw, o) in bytes.chunks_exact(channels).zip(&out) {
                    let v = |i: usize| c.colour(&raw[i..=i]);
                    let want = match channels {
                        1 => [v(0), v(0), v(0), 1.0],
                        2 => [v(0), v(0), v(0), c.alpha(&raw[1..2])],
                        3 => [v(0), v(1), v(2), 1.0],
                        _ => [v(0), v(1), v(2), c.alpha(&raw[3..4])],
                    };
                    assert_eq!(*o, want, "{channels} channels, sRGB {srgb}: {raw:?}");
                }
            }
        }
    }

    #[test]
    fn samples_of_every_layout() {
        let c = Converter::new(
            RowFormat {
                sample: Sample::U8,
                channels: 2,
            },
            true,
        );
        let mut out = [[0.0; 4]; 2];
        c.row(&[255, 51, 0, 255], &mut out);
        assert_eq!(out, [[1.0, 1.0, 1.0, 0.2], [0.0, 0.0, 0.0, 1.0]]);
        let be = Converter::new(
            RowFormat {
                sample: Sample::U16Be,
                channels: 3,
            },
            false,
        );
        let mut one = [[0.0; 4]; 1];
        be.row(&[0xff, 0xff, 0x80, 0x00, 0, 0], &mut one);
        assert_eq!(one[0], [1.0, 32768.0 / 65535.0, 0.0, 1.0]);
        let ne = Converter::new(
            RowFormat {
                sample: Sample::U16Ne,
                channels: 4,
            },
            true,
        );
        let raw: Vec<u8> = [65535u16, 0, 65535, 13107]
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        ne.row(&raw, &mut one);
        assert_eq!(one[0], [1.0, 0.0, 1.0, 0.2]);
        let f = Converter::new(
            RowFormat {
                sample: Sample::F32Ne,
                channels: 3,
            },
            true,
        );
        let raw: Vec<u8> = [2.5f32, -1.0, 0.25]
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        f.row(&raw, &mut one);
        assert_eq!(one[0], [2.5, -1.0, 0.25, 1.0], "floats are linear");
    }
}
