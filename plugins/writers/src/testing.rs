//! Helpers the writers' unit tests share: a test image and encoding/decoding round trips.

use luxon_plugin::{linear_to_srgb, parse_params, Context, Error, Image, Writer};

pub(crate) const W: u32 = 8;
pub(crate) const H: u32 = 4;

pub(crate) fn ctx() -> Context {
    Context {
        scene_dir: ".".into(),
        instance: "test".into(),
        ..Default::default()
    }
}

/// Red ramps 0..1 along x, green is 0.5, blue 0.25 on even rows and 1 on odd ones; alpha
/// ramps along y. A few special values (NaN, >1, negative) sit in the last row.
pub(crate) fn gradient() -> Vec<f32> {
    let mut v = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let r = x as f32 / (W - 1) as f32;
            let b = if y % 2 == 0 { 0.25 } else { 1.0 };
            let a = y as f32 / (H - 1) as f32;
            v.extend([r, 0.5, b, a]);
        }
    }
    let last = ((H - 1) * W * 4) as usize;
    v[last..last + 4].copy_from_slice(&[f32::NAN, 2.0, -1.0, 1.0]);
    v
}

pub(crate) fn encode<T: Writer>(params: &str, rgba: &[f32]) -> Result<Vec<u8>, Error> {
    let image = Image {
        width: W,
        height: H,
        rgba,
    };
    let mut bytes = Vec::new();
    T::write(parse_params(params)?, &ctx(), &image, &mut bytes)?;
    Ok(bytes)
}

pub(crate) fn decode(bytes: &[u8], format: image::ImageFormat) -> image::DynamicImage {
    image::load_from_memory_with_format(bytes, format).unwrap()
}

pub(crate) fn srgb8_of(x: f32) -> u8 {
    (linear_to_srgb(x) * 255.0).round() as u8
}
