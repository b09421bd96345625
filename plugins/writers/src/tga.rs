//! `tga`: Truevision TGA, sRGB-encoded (or display values, `encoding: display`), 8 bits per
//! channel, RGB or RGBA, run-length encoded unless `rle: false` (uncompressed, as Tachyon writes
//! its Targa files, for tools that read only those).

use std::io::Write;

use crate::encode::{check_image, encode_error, encoding_param, samples8, Encoding};
use image::codecs::tga::TgaEncoder;
use image::{ExtendedColorType, ImageEncoder};
use luxon_plugin::{Context, Describe, Error, Image, Writer};
use serde::Deserialize;

pub struct Tga;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TgaParams {
    #[serde(default)]
    alpha: bool,
    #[serde(default = "yes")]
    rle: bool,
    #[serde(default)]
    encoding: Encoding,
}

fn yes() -> bool {
    true
}

impl Describe for Tga {
    const NAME: &'static str = "tga";
    const DESCRIPTION: &'static str =
        "Truevision TGA, sRGB-encoded or display values, 8 bits per channel, RGB or RGBA, run-length encoded or not.";
    const PARAMS: &'static str = concat!(
        "alpha: bool = false  write an alpha channel (RGBA instead of RGB)\n",
        "rle: bool = true  run-length encode the pixels (false: uncompressed)\n",
        encoding_param!()
    );
}

impl Writer for Tga {
    const EXTENSIONS: &'static str = "tga";
    type Params = TgaParams;

    fn write(
        params: TgaParams,
        _ctx: &Context,
        image: &Image,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        check_image(image)?;
        let color = if params.alpha {
            ExtendedColorType::Rgba8
        } else {
            ExtendedColorType::Rgb8
        };
        let mut bytes = Vec::new();
        let encoder = match params.rle {
            true => TgaEncoder::new(&mut bytes),
            false => TgaEncoder::new(&mut bytes).disable_rle(),
        };
        encoder
            .write_image(
                &samples8(image, params.alpha, params.encoding),
                image.width,
                image.height,
                color,
            )
            .map_err(|e| encode_error("TGA", e))?;
        out.write_all(&bytes)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{decode, encode, gradient, srgb8_of, H, W};

    #[test]
    fn tga_roundtrip() {
        let rgba = gradient();
        let img = match decode(
            &encode::<Tga>("()", &rgba).unwrap(),
            image::ImageFormat::Tga,
        ) {
            image::DynamicImage::ImageRgb8(i) => i,
            other => panic!("expected RGB8, got {:?}", other.color()),
        };
        assert_eq!(img.dimensions(), (W, H));
        assert_eq!(img.get_pixel(0, 0).0, [0, 188, srgb8_of(0.25)]);
        assert_eq!(img.get_pixel(W - 1, 1).0, [255, 188, 255]);

        let bytes = encode::<Tga>("(alpha: true)", &rgba).unwrap();
        let img = match decode(&bytes, image::ImageFormat::Tga) {
            image::DynamicImage::ImageRgba8(i) => i,
            other => panic!("expected RGBA8, got {:?}", other.color()),
        };
        assert_eq!(img.get_pixel(0, 0).0, [0, 188, srgb8_of(0.25), 0]);
        assert_eq!(img.get_pixel(5, 2).0[3], 170);
    }

    #[test]
    fn uncompressed_tga_holds_the_same_pixels() {
        let rgba = gradient();
        let rle = encode::<Tga>("()", &rgba).unwrap();
        let raw = encode::<Tga>("(rle: false)", &rgba).unwrap();
        // Image type 10 (run-length RGB) and 2 (uncompressed RGB), as Tachyon writes.
        assert_eq!((rle[2], raw[2]), (10, 2));
        assert_eq!(raw.len(), 18 + (W * H * 3) as usize);
        let pixels = |b: &[u8]| decode(b, image::ImageFormat::Tga).to_rgb8().into_raw();
        assert_eq!(pixels(&rle), pixels(&raw));
    }
}
