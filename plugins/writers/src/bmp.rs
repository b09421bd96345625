//! `bmp`: Windows BMP, sRGB-encoded (or display values, `encoding: display`), 24-bit RGB,
//! uncompressed (what Tachyon's `-format BMP` writes).

use std::io::Write;

use crate::encode::{check_image, encode_error, encoding_param, samples8, Encoding};
use image::codecs::bmp::BmpEncoder;
use image::{ExtendedColorType, ImageEncoder};
use luxon_plugin::{Context, Describe, Error, Image, Writer};
use serde::Deserialize;

pub struct Bmp;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BmpParams {
    #[serde(default)]
    encoding: Encoding,
}

impl Describe for Bmp {
    const NAME: &'static str = "bmp";
    const DESCRIPTION: &'static str =
        "Windows BMP, sRGB-encoded or display values, 24-bit RGB, uncompressed.";
    const PARAMS: &'static str = encoding_param!();
}

impl Writer for Bmp {
    const EXTENSIONS: &'static str = "bmp";
    type Params = BmpParams;

    fn write(
        params: BmpParams,
        _ctx: &Context,
        image: &Image,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        check_image(image)?;
        let mut bytes = Vec::new();
        BmpEncoder::new(&mut bytes)
            .write_image(
                &samples8(image, false, params.encoding),
                image.width,
                image.height,
                ExtendedColorType::Rgb8,
            )
            .map_err(|e| encode_error("BMP", e))?;
        out.write_all(&bytes)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{decode, encode, gradient, srgb8_of, H, W};

    #[test]
    fn bmp_roundtrip() {
        let rgba = gradient();
        let bytes = encode::<Bmp>("()", &rgba).unwrap();
        assert_eq!(&bytes[..2], b"BM");
        let img = match decode(&bytes, image::ImageFormat::Bmp) {
            image::DynamicImage::ImageRgb8(i) => i,
            other => panic!("expected RGB8, got {:?}", other.color()),
        };
        assert_eq!(img.dimensions(), (W, H));
        assert_eq!(img.get_pixel(0, 0).0, [0, 188, srgb8_of(0.25)]);
        assert_eq!(img.get_pixel(W - 1, 1).0, [255, 188, 255]);
        assert_eq!(img.get_pixel(0, H - 1).0, [0, 255, 0]);
        assert!(encode::<Bmp>("(alpha: true)", &rgba).is_err());
    }
}
