//! `png`: PNG, sRGB-encoded (or display values, `encoding: display`), 8 or 16 bits per channel,
//! RGB or RGBA.

use std::io::Write;

use crate::encode::{
    check_bits, check_image, default_bits, encode_error, encoding_param, samples16, samples8,
    Encoding,
};
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use luxon_plugin::{Context, Describe, Error, Image, Writer};
use serde::Deserialize;

pub struct Png;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PngParams {
    #[serde(default = "default_bits")]
    bits: i64,
    #[serde(default)]
    alpha: bool,
    #[serde(default)]
    encoding: Encoding,
}

impl Describe for Png {
    const NAME: &'static str = "png";
    const DESCRIPTION: &'static str =
        "PNG, sRGB-encoded or display values, 8 or 16 bits per channel, RGB or RGBA.";
    const PARAMS: &'static str = concat!(
        "bits: int = 8  bits per channel: 8 or 16\n",
        "alpha: bool = false  write an alpha channel (RGBA instead of RGB)\n",
        encoding_param!()
    );
}

impl Writer for Png {
    const EXTENSIONS: &'static str = "png";
    type Params = PngParams;

    fn write(
        params: PngParams,
        _ctx: &Context,
        image: &Image,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        let bits = check_bits(params.bits)?;
        check_image(image)?;
        let mut bytes = Vec::new();
        let encoder = PngEncoder::new(&mut bytes);
        let (w, h, alpha) = (image.width, image.height, params.alpha);
        let result = if bits == 8 {
            let color = if alpha {
                ExtendedColorType::Rgba8
            } else {
                ExtendedColorType::Rgb8
            };
            encoder.write_image(&samples8(image, alpha, params.encoding), w, h, color)
        } else {
            let color = if alpha {
                ExtendedColorType::Rgba16
            } else {
                ExtendedColorType::Rgb16
            };
            // PngEncoder takes native-endian 16-bit samples and swaps them itself.
            let samples: Vec<u8> = samples16(image, alpha, params.encoding)
                .iter()
                .flat_map(|s| s.to_ne_bytes())
                .collect();
            encoder.write_image(&samples, w, h, color)
        };
        result.map_err(|e| encode_error("PNG", e))?;
        out.write_all(&bytes)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::encode::quantize16;
    use crate::testing::{decode, encode, gradient, srgb8_of, H, W};
    use luxon_plugin::linear_to_srgb;

    #[test]
    fn png_8bit_rgb_roundtrip() {
        let rgba = gradient();
        let img = decode(
            &encode::<Png>("()", &rgba).unwrap(),
            image::ImageFormat::Png,
        );
        let img = match img {
            image::DynamicImage::ImageRgb8(i) => i,
            other => panic!("expected RGB8, got {:?}", other.color()),
        };
        assert_eq!(img.dimensions(), (W, H));
        assert_eq!(img.get_pixel(0, 0).0, [0, 188, srgb8_of(0.25)]);
        assert_eq!(img.get_pixel(W - 1, 1).0, [255, 188, 255]);
        // NaN -> 0, 2.0 -> 255, -1 -> 0.
        assert_eq!(img.get_pixel(0, H - 1).0, [0, 255, 0]);
        for x in 1..W {
            let r = x as f32 / (W - 1) as f32;
            assert_eq!(img.get_pixel(x, 0).0[0], srgb8_of(r));
        }
    }

    #[test]
    fn png_8bit_rgba_keeps_alpha_linear() {
        let rgba = gradient();
        let bytes = encode::<Png>("(alpha: true)", &rgba).unwrap();
        let img = decode(&bytes, image::ImageFormat::Png).into_rgba8();
        assert_eq!(img.dimensions(), (W, H));
        assert_eq!(img.get_pixel(0, 0).0, [0, 188, srgb8_of(0.25), 0]);
        assert_eq!(img.get_pixel(3, 1).0[3], 85);
        assert_eq!(img.get_pixel(3, 2).0[3], 170);
        assert_eq!(img.get_pixel(3, 3).0[3], 255);
    }

    #[test]
    fn png_16bit_roundtrip() {
        let rgba = gradient();
        let img = decode(
            &encode::<Png>("(bits: 16)", &rgba).unwrap(),
            image::ImageFormat::Png,
        );
        let img = match img {
            image::DynamicImage::ImageRgb16(i) => i,
            other => panic!("expected RGB16, got {:?}", other.color()),
        };
        assert_eq!(img.dimensions(), (W, H));
        assert_eq!(
            img.get_pixel(0, 0).0,
            [0, 48192, quantize16(linear_to_srgb(0.25))]
        );
        assert_eq!(img.get_pixel(W - 1, 0).0[0], 65535);

        let img = decode(
            &encode::<Png>("(bits: 16, alpha: true)", &rgba).unwrap(),
            image::ImageFormat::Png,
        );
        let img = match img {
            image::DynamicImage::ImageRgba16(i) => i,
            other => panic!("expected RGBA16, got {:?}", other.color()),
        };
        assert_eq!(img.get_pixel(0, 1).0[3], 21845);
        assert_eq!(img.get_pixel(0, 0).0[1], 48192);
    }

    #[test]
    fn png_rejects_bad_bits() {
        let e = encode::<Png>("(bits: 12)", &gradient()).unwrap_err();
        assert!(e.message.contains("expected 8 or 16"), "{}", e.message);
        assert!(e.message.contains("12"), "{}", e.message);
    }

    #[test]
    fn png_rejects_unknown_param() {
        let e = encode::<Png>("(alhpa: true)", &gradient()).unwrap_err();
        assert!(e.message.contains("did you mean `alpha`"), "{}", e.message);
    }
}
