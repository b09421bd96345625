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
        let samples = samples8(image, params.alpha, params.encoding);
        if !params.rle {
            return write_raw(image.width, image.height, params.alpha, samples, out);
        }
        let color = if params.alpha {
            ExtendedColorType::Rgba8
        } else {
            ExtendedColorType::Rgb8
        };
        let mut bytes = Vec::new();
        TgaEncoder::new(&mut bytes)
            .write_image(&samples, image.width, image.height, color)
            .map_err(|e| encode_error("TGA", e))?;
        out.write_all(&bytes)?;
        Ok(())
    }
}

/// An uncompressed TGA, byte for byte as the `image` crate writes one (a test compares
/// them): its 18-byte header, then the rows from the top in BGR(A). Written here, the samples
/// are reordered in place and go out in one call, where the crate copies them first and
/// writes its header field by field (a 1024² frame: 3 MB more to copy and fault in, about a
/// third of the write's time).
fn write_raw(
    width: u32,
    height: u32,
    alpha: bool,
    mut samples: Vec<u8>,
    out: &mut dyn Write,
) -> Result<(), Error> {
    let side = |what: &str, n: u32| {
        u16::try_from(n).map_err(|_| {
            encode_error(
                "TGA",
                format!("the {what} {n} is more than a TGA holds (65535)"),
            )
        })
    };
    let (w, h) = (side("width", width)?, side("height", height)?);
    let (depth, alpha_bits) = if alpha { (32, 8) } else { (24, 0) };
    // Image type 2 (uncompressed true colour), no id or colour map, origin (0, 0); the
    // descriptor's bit 5: rows from the top.
    let mut header = [0u8; 18];
    header[2] = 2;
    header[12..14].copy_from_slice(&w.to_le_bytes());
    header[14..16].copy_from_slice(&h.to_le_bytes());
    header[16] = depth;
    header[17] = alpha_bits | 0x20;
    let channels = usize::from(depth / 8);
    for pixel in samples.chunks_exact_mut(channels) {
        pixel.swap(0, 2);
    }
    out.write_all(&header)?;
    out.write_all(&samples)?;
    Ok(())
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

    /// The uncompressed TGA written here is the `image` crate's, byte for byte, RGB and RGBA.
    #[test]
    fn uncompressed_tga_is_the_image_crates() {
        let rgba = gradient();
        for (params, alpha) in [("(rle: false)", false), ("(rle: false, alpha: true)", true)] {
            let ours = encode::<Tga>(params, &rgba).unwrap();
            let color = match alpha {
                true => ExtendedColorType::Rgba8,
                false => ExtendedColorType::Rgb8,
            };
            let image = Image {
                width: W,
                height: H,
                rgba: &rgba,
            };
            let samples = samples8(&image, alpha, Encoding::Srgb);
            let mut theirs = Vec::new();
            TgaEncoder::new(&mut theirs)
                .disable_rle()
                .write_image(&samples, W, H, color)
                .unwrap();
            assert_eq!(ours, theirs, "{params}");
        }
        let err = write_raw(70_000, 1, false, vec![0; 210_000], &mut Vec::new()).unwrap_err();
        assert!(err.to_string().contains("width 70000"), "{err}");
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
