//! What every integer format shares: the image checks, sRGB encoding and quantisation of the
//! samples, and the error of a failed encoder.

use luxon_plugin::{invalid, linear_to_srgb, Error, Image};

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

/// sRGB-encoded samples, RGB or RGBA, one `T` per channel.
fn encode_samples<T>(image: &Image, alpha: bool, quantize: impl Fn(f32) -> T) -> Vec<T> {
    let channels = if alpha { 4 } else { 3 };
    let mut out = Vec::with_capacity(image.rgba.len() / 4 * channels);
    for px in image.rgba.chunks_exact(4) {
        out.extend(px[..3].iter().map(|&c| quantize(linear_to_srgb(c))));
        if alpha {
            out.push(quantize(linear_unit(px[3])));
        }
    }
    out
}

pub(crate) fn srgb8(image: &Image, alpha: bool) -> Vec<u8> {
    encode_samples(image, alpha, quantize8)
}

pub(crate) fn srgb16(image: &Image, alpha: bool) -> Vec<u16> {
    encode_samples(image, alpha, quantize16)
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
}
