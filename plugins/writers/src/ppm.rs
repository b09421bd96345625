//! `ppm`: binary PPM (P6), sRGB-encoded (or display values, `encoding: display`), 8 or 16 bits
//! per channel, RGB; written directly.

use std::io::Write;

use crate::encode::{
    check_bits, check_image, default_bits, encoding_param, samples16, samples8, Encoding,
};
use luxon_plugin::{Context, Describe, Error, Image, Writer};
use serde::Deserialize;

pub struct Ppm;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PpmParams {
    #[serde(default = "default_bits")]
    bits: i64,
    #[serde(default)]
    encoding: Encoding,
}

impl Describe for Ppm {
    const NAME: &'static str = "ppm";
    const DESCRIPTION: &'static str =
        "Binary PPM (P6), sRGB-encoded or display values, 8 or 16 bits per channel, RGB.";
    const PARAMS: &'static str = concat!(
        "bits: int = 8  8 (maxval 255) or 16 (maxval 65535, big-endian samples)\n",
        encoding_param!()
    );
}

impl Writer for Ppm {
    const EXTENSIONS: &'static str = "ppm,pnm";
    type Params = PpmParams;

    fn write(
        params: PpmParams,
        _ctx: &Context,
        image: &Image,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        let bits = check_bits(params.bits)?;
        check_image(image)?;
        // P6 is simple enough to write directly, and this pins the 16-bit byte order.
        let maxval = if bits == 8 { 255 } else { 65535 };
        // The header and the samples go out as they are: no copy of the image joins them.
        let header = format!("P6\n{} {}\n{maxval}\n", image.width, image.height);
        out.write_all(header.as_bytes())?;
        if bits == 8 {
            out.write_all(&samples8(image, false, params.encoding))?;
        } else {
            let samples = samples16(image, false, params.encoding);
            let bytes: Vec<u8> = samples.iter().flat_map(|s| s.to_be_bytes()).collect();
            out.write_all(&bytes)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{decode, encode, gradient, srgb8_of, H, W};

    #[test]
    fn ppm_8bit_roundtrip() {
        let rgba = gradient();
        let bytes = encode::<Ppm>("()", &rgba).unwrap();
        let header = format!("P6\n{W} {H}\n255\n");
        assert!(bytes.starts_with(header.as_bytes()));
        assert_eq!(bytes.len(), header.len() + (W * H * 3) as usize);
        let img = match decode(&bytes, image::ImageFormat::Pnm) {
            image::DynamicImage::ImageRgb8(i) => i,
            other => panic!("expected RGB8, got {:?}", other.color()),
        };
        assert_eq!(img.dimensions(), (W, H));
        assert_eq!(img.get_pixel(0, 0).0, [0, 188, srgb8_of(0.25)]);
        assert_eq!(img.get_pixel(0, H - 1).0, [0, 255, 0]);
    }

    #[test]
    fn ppm_16bit_is_big_endian() {
        let rgba = gradient();
        let bytes = encode::<Ppm>("(bits: 16)", &rgba).unwrap();
        let header = format!("P6\n{W} {H}\n65535\n");
        assert!(bytes.starts_with(header.as_bytes()));
        let data = &bytes[header.len()..];
        assert_eq!(data.len(), (W * H * 6) as usize);
        // First pixel's green: 48192 = 0xBC40, most significant byte first.
        assert_eq!(&data[2..4], &[0xBC, 0x40]);
        let img = match decode(&bytes, image::ImageFormat::Pnm) {
            image::DynamicImage::ImageRgb16(i) => i,
            other => panic!("expected RGB16, got {:?}", other.color()),
        };
        assert_eq!(img.dimensions(), (W, H));
        assert_eq!(img.get_pixel(0, 0).0[1], 48192);
        assert_eq!(img.get_pixel(W - 1, 0).0[0], 65535);
    }

    #[test]
    fn ppm_rejects_bad_bits() {
        let e = encode::<Ppm>("(bits: 12)", &gradient()).unwrap_err();
        assert!(e.message.contains("expected 8 or 16"), "{}", e.message);
    }
}
