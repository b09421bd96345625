//! # luxon-writers: image writer plugins for Luxon
//!
//! Encodes the finished render (linear RGBA `f32`, rows top to bottom) into a file format. The
//! host picks a writer by the output's `plugin`, or else by the file extension, and writes the
//! encoded bytes to disk atomically.
//!
//! | writer | extensions  | stores |
//! |--------|-------------|--------|
//! | `png`  | `png`       | sRGB, 8 or 16 bits, RGB or RGBA |
//! | `jpeg` | `jpg, jpeg` | sRGB, 8 bits, RGB (alpha is dropped) |
//! | `ppm`  | `ppm, pnm`  | sRGB, binary P6, 8 or 16 bits (big-endian), RGB |
//! | `tga`  | `tga`       | sRGB, 8 bits, RGB or RGBA, run-length encoded or not |
//! | `bmp`  | `bmp`       | sRGB, 8 bits, RGB (uncompressed Windows BMP) |
//! | `exr`  | `exr`       | linear float RGBA, 32-bit or half |
//!
//! The integer formats clamp each colour channel to [0, 1], apply the sRGB transfer function and
//! round to the nearest code; NaN becomes 0. With `encoding: display` (every integer format)
//! the values are display values already, as a Tachyon scene's colours are: clamped and
//! truncated as Tachyon writes them, floor(255·c) (floor(65535·c) at 16 bits), with no transfer
//! function; `luxon tachyon` writes so. Alpha is stored linearly (clamped, NaN → 0) and the
//! colour is stored as given, i.e. as straight alpha. EXR stores the values unchanged (including
//! values above 1, negative values, NaN and infinities).
//!
//! One file per writer (`png.rs`, `jpeg.rs`, `ppm.rs`, `tga.rs`, `bmp.rs`, `openexr.rs`); `encode.rs` holds
//! the checks and the encodings the integer formats share.
//!
//! ## Parameters
//!
//! `png`
//!
//! | name    | type   | default | meaning |
//! |---------|--------|---------|---------|
//! | `bits`  | int    | 8       | bits per channel: 8 or 16 |
//! | `alpha` | bool   | false   | write an alpha channel (RGBA instead of RGB) |
//! | `encoding` | `srgb` or `display` | `srgb` | the sRGB curve, or the values as they are (above) |
//!
//! `jpeg`
//!
//! | name      | type | default | meaning |
//! |-----------|------|---------|---------|
//! | `quality` | int  | 90      | encoder quality, 1 (smallest) to 100 (best) |
//! | `encoding` | `srgb` or `display` | `srgb` | as for `png` |
//!
//! `ppm`
//!
//! | name   | type | default | meaning |
//! |--------|------|---------|---------|
//! | `bits` | int  | 8       | 8 (maxval 255) or 16 (maxval 65535, big-endian samples) |
//! | `encoding` | `srgb` or `display` | `srgb` | as for `png` |
//!
//! `tga`
//!
//! | name    | type | default | meaning |
//! |---------|------|---------|---------|
//! | `alpha` | bool | false   | write an alpha channel (RGBA instead of RGB) |
//! | `rle`   | bool | true    | run-length encoded; `false`: uncompressed, as Tachyon writes |
//! | `encoding` | `srgb` or `display` | `srgb` | as for `png` |
//!
//! `bmp`: `encoding`, as for `png`.
//!
//! `exr`
//!
//! | name          | type   | default | meaning |
//! |---------------|--------|---------|---------|
//! | `half`        | bool   | false   | 16-bit half floats instead of 32-bit floats |
//! | `compression` | string | `"zip"` | `"none"`, `"rle"`, `"zips"` (zip, 1 line), `"zip"` (zip, 16 lines), `"piz"`, `"pxr24"`, `"b44"`, `"b44a"` |
//!
//! `none`, `rle`, `zips`, `zip` and `piz` are lossless. `pxr24` rounds 32-bit floats to 24 bits
//! (lossless for half); `b44`/`b44a` are lossy for half and leave 32-bit floats uncompressed.
//!
//! ## Scene
//!
//! ```ron
//! render: (
//!     width: 640, height: 480,
//!     outputs: [
//!         (path: "out.png"),
//!         (path: "out16.png", params: (bits: 16, alpha: true)),
//!         (path: "out.jpg", params: (quality: 95)),
//!         (path: "out.exr", plugin: "exr", params: (half: true, compression: "piz")),
//!     ],
//! )
//! ```

#![forbid(unsafe_code)]

mod bmp;
mod encode;
mod jpeg;
mod openexr;
mod png;
mod ppm;
#[cfg(test)]
mod testing;
mod tga;

pub use bmp::Bmp;
pub use jpeg::Jpeg;
pub use openexr::Exr;
pub use png::Png;
pub use ppm::Ppm;
pub use tga::Tga;

luxon_plugin::export!(library: "luxon-writers", writers: [Png, Jpeg, Ppm, Tga, Bmp, Exr]);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::ctx;
    use luxon_plugin::{parse_params, Describe, Image, Writer};

    #[test]
    fn empty_image_is_an_error() {
        fn check<T: Writer>(params: &str) {
            let image = Image {
                width: 0,
                height: 5,
                rgba: &[],
            };
            let mut out = Vec::new();
            let e = T::write(parse_params(params).unwrap(), &ctx(), &image, &mut out).unwrap_err();
            assert!(e.message.contains("empty image"), "{}", e.message);
            assert!(out.is_empty());
        }
        check::<Png>("()");
        check::<Jpeg>("()");
        check::<Ppm>("()");
        check::<Tga>("()");
        check::<Bmp>("()");
        check::<Exr>("()");
    }

    #[test]
    fn every_integer_writer_writes_display_values() {
        use crate::testing::{decode, encode, gradient, srgb8_of};
        use image::ImageFormat;
        let rgba = gradient();
        let first = |bytes: Vec<u8>, format| decode(&bytes, format).to_rgb8().get_pixel(0, 0).0;
        // (0, 0.5, 0.25) truncated, as Tachyon writes it; sRGB by default.
        for params in ["(encoding: display)", "()"] {
            let expected = match params {
                "()" => [0, srgb8_of(0.5), srgb8_of(0.25)],
                _ => [0, 127, 63],
            };
            let png = encode::<Png>(params, &rgba).unwrap();
            assert_eq!(first(png, ImageFormat::Png), expected, "png {params}");
            let ppm = encode::<Ppm>(params, &rgba).unwrap();
            assert_eq!(first(ppm, ImageFormat::Pnm), expected, "ppm {params}");
            let tga = encode::<Tga>(params, &rgba).unwrap();
            assert_eq!(first(tga, ImageFormat::Tga), expected, "tga {params}");
            let bmp = encode::<Bmp>(params, &rgba).unwrap();
            assert_eq!(first(bmp, ImageFormat::Bmp), expected, "bmp {params}");
            let jpeg = decode(&encode::<Jpeg>(params, &rgba).unwrap(), ImageFormat::Jpeg);
            let g = jpeg.to_rgb8().get_pixel(0, 0).0[1];
            assert!(g.abs_diff(expected[1]) < 12, "jpeg {params}: {g}");
        }
        let png16 = encode::<Png>("(bits: 16, encoding: display)", &rgba).unwrap();
        let px = decode(&png16, ImageFormat::Png)
            .to_rgb16()
            .get_pixel(0, 0)
            .0;
        assert_eq!(px, [0, 32767, 16383]);
        assert!(encode::<Png>("(encoding: linear)", &rgba).is_err());
    }

    #[test]
    fn short_buffer_is_an_error() {
        let image = Image {
            width: 4,
            height: 4,
            rgba: &[0.0; 12],
        };
        let e =
            <Png as Writer>::write(parse_params("()").unwrap(), &ctx(), &image, &mut Vec::new())
                .unwrap_err();
        assert!(
            e.message.contains("needs 64 floats, got 12"),
            "{}",
            e.message
        );
    }

    #[test]
    fn descriptions_are_consistent() {
        for (name, params) in [
            (Png::NAME, Png::PARAMS),
            (Jpeg::NAME, Jpeg::PARAMS),
            (Ppm::NAME, Ppm::PARAMS),
            (Tga::NAME, Tga::PARAMS),
            (Bmp::NAME, Bmp::PARAMS),
            (Exr::NAME, Exr::PARAMS),
        ] {
            for line in params.lines() {
                assert!(
                    line.contains(": ") && line.contains(" = "),
                    "{name}: {line}"
                );
            }
        }
        assert_eq!(Jpeg::EXTENSIONS, "jpg,jpeg");
        assert_eq!(Ppm::EXTENSIONS, "ppm,pnm");
    }
}
