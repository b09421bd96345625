//! What every integer format shares: the image checks, the encoding and quantisation of the
//! samples (`encoding`), and the error of a failed encoder.

use luxon_plugin::{encode_rgb, invalid, linear_to_srgb, srgb8, Error, Image};
use serde::Deserialize;

/// How colour values become integer samples (parameter `encoding`).
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq)]
#[serde(rename_all = "lowercase")]
pub(crate) enum Encoding {
    /// Linear values through the sRGB curve, rounded to the nearest step.
    #[default]
    Srgb,
    /// The values are display values already (a Tachyon scene's colours are): written as they
    /// are, clamped to [0, 1] and truncated as Tachyon writes its images, floor(255·c) (and
    /// floor(65535·c) at 16 bits), so that `luxon tachyon` writes Tachyon's tones.
    Display,
}

/// The `PARAMS` line of `encoding`, shared by every integer writer (a literal, for `concat!`).
macro_rules! encoding_param {
    () => {
        "encoding: srgb|display = srgb  srgb: linear colours through the sRGB curve; display: \
         values written as they are, clamped and truncated (as Tachyon writes; luxon tachyon)"
    };
}
pub(crate) use encoding_param;

/// Checks the image is non-empty and its buffer matches its size; returns the pixel count.
pub(crate) fn check_image(image: &Image) -> Result<usize, Error> {
    if image.width == 0 || image.height == 0 {
        return Err(invalid(format!(
            "cannot write an empty image ({}x{} pixels)",
            image.width, image.height
        )));
    }
    let pixels = image.width as usize * image.height as usize;
    if image.rgba.len() != pixels * 4 {
        return Err(invalid(format!(
            "image of {}x{} pixels needs {} floats, got {}",
            image.width,
            image.height,
            pixels * 4,
            image.rgba.len()
        )));
    }
    Ok(pixels)
}

/// Alpha is coverage, not a colour: stored linearly.
fn linear_unit(x: f32) -> f32 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

fn quantize8(x: f32) -> u8 {
    (x * 255.0).round() as u8
}

pub(crate) fn quantize16(x: f32) -> u16 {
    (x * 65535.0).round() as u16
}

/// A display value's step, as Tachyon quantises (`floor(max · c)`, clamped; NaN is 0, as
/// for sRGB), before the `floor`: the cast to an integer truncates (and takes NaN to 0).
#[inline(always)]
fn unfloored(x: f32, max: f32) -> f32 {
    x.clamp(0.0, 1.0) * max
}

/// Every pixel's samples, RGB or RGBA, channel by channel through `step` (alpha linear and
/// rounded by `quantize`), into a buffer of known size: for steps cheaper than comparing a
/// pixel with the one before it.
fn each_sample<T: Copy>(
    image: &Image,
    alpha: bool,
    step: impl Fn(f32) -> T,
    quantize: impl Fn(f32) -> T,
    zero: T,
) -> Vec<T> {
    let pixels = image.rgba.chunks_exact(4);
    let mut out = vec![zero; pixels.len() * if alpha { 4 } else { 3 }];
    if alpha {
        for (o, p) in out.chunks_exact_mut(4).zip(pixels) {
            o[0] = step(p[0]);
            o[1] = step(p[1]);
            o[2] = step(p[2]);
            o[3] = quantize(linear_unit(p[3]));
        }
    } else {
        for (o, p) in out.chunks_exact_mut(3).zip(pixels) {
            o[0] = step(p[0]);
            o[1] = step(p[1]);
            o[2] = step(p[2]);
        }
    }
    out
}

pub(crate) fn samples8(image: &Image, alpha: bool, encoding: Encoding) -> Vec<u8> {
    match encoding {
        // A table lookup per sample (`srgb8`: 60 M instructions for a 1024² frame where the
        // curve's `powf`, even skipping repeated pixels, took 151 M).
        Encoding::Srgb => {
            let t = srgb8::tables();
            each_sample(image, alpha, |c| t.sample(c), quantize8, 0)
        }
        // Stepped without a `floor` (see `unfloored`): 23 M instructions, not 26 M.
        Encoding::Display => each_sample(image, alpha, |c| unfloored(c, 255.0) as u8, quantize8, 0),
    }
}

pub(crate) fn samples16(image: &Image, alpha: bool, encoding: Encoding) -> Vec<u16> {
    if encoding == Encoding::Display {
        let step = |c| unfloored(c, 65535.0) as u16;
        return each_sample(image, alpha, step, quantize16, 0);
    }
    // The curve's `powf` per sample, but not for a pixel the same as the one before.
    let mut out = Vec::with_capacity(image.rgba.len() / 4 * if alpha { 4 } else { 3 });
    let encode = |c: f32| quantize16(linear_to_srgb(c));
    encode_rgb(image.rgba, encode, |rgb, px| {
        out.extend_from_slice(&rgb);
        if alpha {
            out.push(quantize16(linear_unit(px[3])));
        }
    });
    out
}

pub(crate) fn check_bits(bits: i64) -> Result<u8, Error> {
    match bits {
        8 => Ok(8),
        16 => Ok(16),
        _ => Err(invalid(format!(
            "parameter `bits`: expected 8 or 16, got {bits}"
        ))),
    }
}

pub(crate) fn encode_error(format: &str, e: impl std::fmt::Display) -> Error {
    Error::new(format!("{format} encoding failed: {e}"))
}

pub(crate) fn default_bits() -> i64 {
    8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A display value's step as written before: truncated, as Tachyon quantises.
    fn truncate(x: f32, max: f32) -> f32 {
        (linear_unit(x) * max).floor().min(max)
    }

    /// The step casts to `truncate`'s sample for every kind of value: a
    /// spread of bit patterns (signs, NaNs, infinities, subnormals), and each step's edges.
    #[test]
    fn unfloored_steps_cast_as_truncated_ones() {
        let same = |x: f32| {
            assert_eq!(unfloored(x, 255.0) as u8, truncate(x, 255.0) as u8, "{x:e}");
            assert_eq!(
                unfloored(x, 65535.0) as u16,
                truncate(x, 65535.0) as u16,
                "{x:e}"
            );
        };
        for bits in (0..=u32::MAX).step_by(7919) {
            same(f32::from_bits(bits));
        }
        for k in 0..=65535u32 {
            for max in [255.0f32, 65535.0] {
                let x = k as f32 / max;
                [x, x.next_up(), x.next_down()].into_iter().for_each(same);
            }
        }
        [0.0, -0.0, 1.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY]
            .into_iter()
            .for_each(same);
    }

    #[test]
    fn srgb_quantization_known_values() {
        assert_eq!(quantize8(linear_to_srgb(0.5)), 188);
        assert_eq!(quantize8(linear_to_srgb(0.0)), 0);
        assert_eq!(quantize8(linear_to_srgb(1.0)), 255);
        assert_eq!(quantize8(linear_to_srgb(f32::NAN)), 0);
        assert_eq!(quantize8(linear_to_srgb(7.0)), 255);
        assert_eq!(quantize8(linear_to_srgb(-3.0)), 0);
        assert_eq!(quantize16(linear_to_srgb(0.5)), 48192);
        assert_eq!(quantize16(linear_to_srgb(1.0)), 65535);
    }

    #[test]
    fn display_values_are_truncated_as_tachyon_writes() {
        let rgba = [0.5, 0.999, 1.0, 1.0, 2.0, -1.0, f32::NAN, 0.5];
        let image = Image {
            width: 2,
            height: 1,
            rgba: &rgba,
        };
        assert_eq!(
            samples8(&image, false, Encoding::Display),
            [127, 254, 255, 255, 0, 0]
        );
        assert_eq!(
            samples8(&image, true, Encoding::Display),
            [127, 254, 255, 255, 255, 0, 0, 128]
        );
        assert_eq!(
            samples16(&image, false, Encoding::Display),
            [32767, 65469, 65535, 65535, 0, 0]
        );
        assert_eq!(samples8(&image, false, Encoding::Srgb)[0], 188);
    }

    /// Runs of equal pixels (copied samples) encode as every pixel computed on its own.
    #[test]
    fn repeated_pixels_encode_as_computed_alone() {
        let values = [
            0.0,
            -0.0,
            0.5,
            0.5,
            0.25,
            f32::NAN,
            f32::NAN,
            1.5,
            0.003,
            0.0031,
        ];
        let mut rgba = Vec::new();
        for (i, &v) in values.iter().enumerate() {
            // Each colour twice, then once with only blue changed, and alpha varying.
            for a in [1.0, 0.5] {
                rgba.extend([v, 0.2, v, a]);
            }
            rgba.extend([v, 0.2, values[(i + 3) % values.len()], 0.25]);
        }
        let image = Image {
            width: rgba.len() as u32 / 4,
            height: 1,
            rgba: &rgba,
        };
        for encoding in [Encoding::Srgb, Encoding::Display] {
            for alpha in [false, true] {
                let alone = |px: &[f32]| {
                    let one = Image {
                        width: 1,
                        height: 1,
                        rgba: px,
                    };
                    (
                        samples8(&one, alpha, encoding),
                        samples16(&one, alpha, encoding),
                    )
                };
                let (mut want8, mut want16) = (Vec::new(), Vec::new());
                for px in rgba.chunks_exact(4) {
                    let (a, b) = alone(px);
                    want8.extend(a);
                    want16.extend(b);
                }
                assert_eq!(samples8(&image, alpha, encoding), want8, "{encoding:?}");
                assert_eq!(samples16(&image, alpha, encoding), want16, "{encoding:?}");
            }
        }
    }
}
