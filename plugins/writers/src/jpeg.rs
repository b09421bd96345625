//! `jpeg`: JPEG, sRGB-encoded (or display values, `encoding: display`), 8 bits per channel
//! (alpha is dropped).

use std::io::Write;

use crate::encode::{check_image, encode_error, encoding_param, samples8, Encoding};
use image::codecs::jpeg::JpegEncoder;
use image::{ExtendedColorType, ImageEncoder};
use luxon_plugin::{invalid, Context, Describe, Error, Image, Writer};
use serde::Deserialize;

pub struct Jpeg;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JpegParams {
    #[serde(default = "default_quality")]
    quality: i64,
    #[serde(default)]
    encoding: Encoding,
}

fn default_quality() -> i64 {
    90
}

impl Describe for Jpeg {
    const NAME: &'static str = "jpeg";
    const DESCRIPTION: &'static str =
        "JPEG, sRGB-encoded or display values, 8 bits per channel (alpha is dropped).";
    const PARAMS: &'static str = concat!(
        "quality: int = 90  encoder quality, 1 (smallest) to 100 (best)\n",
        encoding_param!()
    );
}

impl Writer for Jpeg {
    const EXTENSIONS: &'static str = "jpg,jpeg";
    type Params = JpegParams;

    fn write(
        params: JpegParams,
        _ctx: &Context,
        image: &Image,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        if !(1..=100).contains(&params.quality) {
            return Err(invalid(format!(
                "parameter `quality`: expected 1 to 100, got {}",
                params.quality
            )));
        }
        check_image(image)?;
        let mut bytes = Vec::new();
        JpegEncoder::new_with_quality(&mut bytes, params.quality as u8)
            .write_image(
                &samples8(image, false, params.encoding),
                image.width,
                image.height,
                ExtendedColorType::Rgb8,
            )
            .map_err(|e| encode_error("JPEG", e))?;
        out.write_all(&bytes)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{decode, encode, gradient, H, W};

    #[test]
    fn jpeg_roundtrip_is_close() {
        // A flat image: JPEG should reproduce it almost exactly at high quality.
        let flat: Vec<f32> = (0..W * H).flat_map(|_| [0.5, 0.5, 0.5, 1.0]).collect();
        let bytes = encode::<Jpeg>("(quality: 100)", &flat).unwrap();
        assert_eq!(&bytes[..2], &[0xFF, 0xD8]);
        let img = decode(&bytes, image::ImageFormat::Jpeg).into_rgb8();
        assert_eq!(img.dimensions(), (W, H));
        for p in img.pixels() {
            for c in p.0 {
                assert!((c as i32 - 188).abs() <= 2, "{:?}", p.0);
            }
        }
        // Default quality works on the gradient too.
        let img = decode(
            &encode::<Jpeg>("()", &gradient()).unwrap(),
            image::ImageFormat::Jpeg,
        );
        assert_eq!((img.width(), img.height()), (W, H));
    }

    #[test]
    fn jpeg_quality_changes_size() {
        let rgba = gradient();
        let small = encode::<Jpeg>("(quality: 1)", &rgba).unwrap();
        let large = encode::<Jpeg>("(quality: 100)", &rgba).unwrap();
        assert!(
            small.len() < large.len(),
            "{} vs {}",
            small.len(),
            large.len()
        );
    }

    #[test]
    fn jpeg_rejects_bad_quality() {
        for q in ["0", "101", "-5"] {
            let e = encode::<Jpeg>(&format!("(quality: {q})"), &gradient()).unwrap_err();
            assert!(e.message.contains("expected 1 to 100"), "{}", e.message);
        }
    }
}
