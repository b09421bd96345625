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
//! | `tga`  | `tga`       | sRGB, 8 bits, RGB or RGBA |
//! | `exr`  | `exr`       | linear float RGBA, 32-bit or half |
//!
//! The integer formats clamp each colour channel to [0, 1], apply the sRGB transfer function and
//! round to the nearest code; NaN becomes 0. Alpha is stored linearly (clamped, NaN → 0) and the
//! colour is stored as given, i.e. as straight alpha. EXR stores the values unchanged (including
//! values above 1, negative values, NaN and infinities).
//!
//! ## Parameters
//!
//! `png`
//!
//! | name    | type   | default | meaning |
//! |---------|--------|---------|---------|
//! | `bits`  | int    | 8       | bits per channel: 8 or 16 |
//! | `alpha` | bool   | false   | write an alpha channel (RGBA instead of RGB) |
//!
//! `jpeg`
//!
//! | name      | type | default | meaning |
//! |-----------|------|---------|---------|
//! | `quality` | int  | 90      | encoder quality, 1 (smallest) to 100 (best) |
//!
//! `ppm`
//!
//! | name   | type | default | meaning |
//! |--------|------|---------|---------|
//! | `bits` | int  | 8       | 8 (maxval 255) or 16 (maxval 65535, big-endian samples) |
//!
//! `tga`
//!
//! | name    | type | default | meaning |
//! |---------|------|---------|---------|
//! | `alpha` | bool | false   | write an alpha channel (RGBA instead of RGB) |
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

use std::io::Write;

use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::PngEncoder;
use image::codecs::tga::TgaEncoder;
use image::{ExtendedColorType, ImageEncoder};
use luxon_plugin::{invalid, linear_to_srgb, Context, Describe, Error, Image, Writer};
use serde::Deserialize;

// ------------------------------------------------------------------------------------------------
// Shared helpers
// ------------------------------------------------------------------------------------------------

/// Checks the image is non-empty and its buffer matches its size; returns the pixel count.
fn check_image(image: &Image) -> Result<usize, Error> {
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

fn quantize16(x: f32) -> u16 {
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

fn srgb8(image: &Image, alpha: bool) -> Vec<u8> {
    encode_samples(image, alpha, quantize8)
}

fn srgb16(image: &Image, alpha: bool) -> Vec<u16> {
    encode_samples(image, alpha, quantize16)
}

fn check_bits(bits: i64) -> Result<u8, Error> {
    match bits {
        8 => Ok(8),
        16 => Ok(16),
        _ => Err(invalid(format!(
            "parameter `bits`: expected 8 or 16, got {bits}"
        ))),
    }
}

fn encode_error(format: &str, e: impl std::fmt::Display) -> Error {
    Error::new(format!("{format} encoding failed: {e}"))
}

fn default_bits() -> i64 {
    8
}

// ------------------------------------------------------------------------------------------------
// PNG
// ------------------------------------------------------------------------------------------------

pub struct Png;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PngParams {
    #[serde(default = "default_bits")]
    bits: i64,
    #[serde(default)]
    alpha: bool,
}

impl Describe for Png {
    const NAME: &'static str = "png";
    const DESCRIPTION: &'static str = "PNG, sRGB-encoded, 8 or 16 bits per channel, RGB or RGBA.";
    const PARAMS: &'static str = "\
bits: int = 8  bits per channel: 8 or 16
alpha: bool = false  write an alpha channel (RGBA instead of RGB)";
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
            encoder.write_image(&srgb8(image, alpha), w, h, color)
        } else {
            let color = if alpha {
                ExtendedColorType::Rgba16
            } else {
                ExtendedColorType::Rgb16
            };
            // PngEncoder takes native-endian 16-bit samples and swaps them itself.
            let samples: Vec<u8> = srgb16(image, alpha)
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

// ------------------------------------------------------------------------------------------------
// JPEG
// ------------------------------------------------------------------------------------------------

pub struct Jpeg;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JpegParams {
    #[serde(default = "default_quality")]
    quality: i64,
}

fn default_quality() -> i64 {
    90
}

impl Describe for Jpeg {
    const NAME: &'static str = "jpeg";
    const DESCRIPTION: &'static str = "JPEG, sRGB-encoded, 8 bits per channel (alpha is dropped).";
    const PARAMS: &'static str = "quality: int = 90  encoder quality, 1 (smallest) to 100 (best)";
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
                &srgb8(image, false),
                image.width,
                image.height,
                ExtendedColorType::Rgb8,
            )
            .map_err(|e| encode_error("JPEG", e))?;
        out.write_all(&bytes)?;
        Ok(())
    }
}

// ------------------------------------------------------------------------------------------------
// PPM
// ------------------------------------------------------------------------------------------------

pub struct Ppm;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PpmParams {
    #[serde(default = "default_bits")]
    bits: i64,
}

impl Describe for Ppm {
    const NAME: &'static str = "ppm";
    const DESCRIPTION: &'static str =
        "Binary PPM (P6), sRGB-encoded, 8 or 16 bits per channel, RGB.";
    const PARAMS: &'static str =
        "bits: int = 8  8 (maxval 255) or 16 (maxval 65535, big-endian samples)";
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
        let mut bytes = format!("P6\n{} {}\n{maxval}\n", image.width, image.height).into_bytes();
        if bits == 8 {
            bytes.extend(srgb8(image, false));
        } else {
            bytes.extend(srgb16(image, false).iter().flat_map(|s| s.to_be_bytes()));
        }
        out.write_all(&bytes)?;
        Ok(())
    }
}

// ------------------------------------------------------------------------------------------------
// TGA
// ------------------------------------------------------------------------------------------------

pub struct Tga;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TgaParams {
    #[serde(default)]
    alpha: bool,
}

impl Describe for Tga {
    const NAME: &'static str = "tga";
    const DESCRIPTION: &'static str =
        "Truevision TGA, sRGB-encoded, 8 bits per channel, RGB or RGBA.";
    const PARAMS: &'static str =
        "alpha: bool = false  write an alpha channel (RGBA instead of RGB)";
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
        TgaEncoder::new(&mut bytes)
            .write_image(
                &srgb8(image, params.alpha),
                image.width,
                image.height,
                color,
            )
            .map_err(|e| encode_error("TGA", e))?;
        out.write_all(&bytes)?;
        Ok(())
    }
}

// ------------------------------------------------------------------------------------------------
// OpenEXR
// ------------------------------------------------------------------------------------------------

pub struct Exr;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExrParams {
    #[serde(default)]
    half: bool,
    #[serde(default = "default_compression")]
    compression: String,
}

fn default_compression() -> String {
    "zip".to_string()
}

/// The compressions the `exr` crate can write, by their OpenEXR names.
const COMPRESSIONS: &[(&str, exr::compression::Compression)] = {
    use exr::compression::Compression::*;
    &[
        ("none", Uncompressed),
        ("rle", RLE),
        ("zips", ZIP1),
        ("zip", ZIP16),
        ("piz", PIZ),
        ("pxr24", PXR24),
        ("b44", B44),
        ("b44a", B44A),
    ]
};

fn exr_compression(name: &str) -> Result<exr::compression::Compression, Error> {
    if let Some(&(_, c)) = COMPRESSIONS
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
    {
        return Ok(c);
    }
    let names = COMPRESSIONS.iter().map(|(n, _)| *n);
    let mut msg = format!("parameter `compression`: unknown compression \"{name}\"");
    if let Some(s) = luxon_plugin::suggest(&name.to_ascii_lowercase(), names.clone()) {
        msg.push_str(&format!(", did you mean \"{s}\"?"));
    }
    let list: Vec<_> = names.collect();
    msg.push_str(&format!(" (expected one of: {})", list.join(", ")));
    Err(invalid(msg))
}

impl Describe for Exr {
    const NAME: &'static str = "exr";
    const DESCRIPTION: &'static str =
        "OpenEXR, linear float RGBA (32-bit or half), stored unchanged.";
    const PARAMS: &'static str = "\
half: bool = false  16-bit half floats instead of 32-bit floats
compression: string = \"zip\"  none, rle, zips (1 line), zip (16 lines), piz, pxr24, b44, b44a";
}

impl Writer for Exr {
    const EXTENSIONS: &'static str = "exr";
    type Params = ExrParams;

    fn write(
        params: ExrParams,
        _ctx: &Context,
        image: &Image,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        use exr::prelude::{f16, Encoding, LineOrder, SpecificChannels, Vec2, WritableImage};

        let compression = exr_compression(&params.compression)?;
        check_image(image)?;
        let (w, h) = (image.width as usize, image.height as usize);
        let encoding = Encoding {
            compression,
            blocks: exr::image::Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        let px = |Vec2(x, y): Vec2<usize>| {
            let i = (y * w + x) * 4;
            let p = &image.rgba[i..i + 4];
            (p[0], p[1], p[2], p[3])
        };
        // The exr writer needs `Seek`; encode in memory first.
        let mut buf = std::io::Cursor::new(Vec::new());
        let result = if params.half {
            let channels = SpecificChannels::rgba(|pos| {
                let (r, g, b, a) = px(pos);
                (
                    f16::from_f32(r),
                    f16::from_f32(g),
                    f16::from_f32(b),
                    f16::from_f32(a),
                )
            });
            exr::image::Image::from_encoded_channels((w, h), encoding, channels)
                .write()
                .to_buffered(&mut buf)
        } else {
            let channels = SpecificChannels::rgba(px);
            exr::image::Image::from_encoded_channels((w, h), encoding, channels)
                .write()
                .to_buffered(&mut buf)
        };
        result.map_err(|e| encode_error("EXR", e))?;
        out.write_all(buf.get_ref())?;
        Ok(())
    }
}

luxon_plugin::export!(library: "luxon-writers", writers: [Png, Jpeg, Ppm, Tga, Exr]);

#[cfg(test)]
mod tests {
    use super::*;
    use luxon_plugin::parse_params;

    const W: u32 = 8;
    const H: u32 = 4;

    fn ctx() -> Context {
        Context {
            scene_dir: ".".into(),
            instance: "test".into(),
            ..Default::default()
        }
    }

    /// Red ramps 0..1 along x, green is 0.5, blue 0.25 on even rows and 1 on odd ones; alpha
    /// ramps along y. A few special values (NaN, >1, negative) sit in the last row.
    fn gradient() -> Vec<f32> {
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

    fn encode<T: Writer>(params: &str, rgba: &[f32]) -> Result<Vec<u8>, Error> {
        let image = Image {
            width: W,
            height: H,
            rgba,
        };
        let mut bytes = Vec::new();
        T::write(parse_params(params)?, &ctx(), &image, &mut bytes)?;
        Ok(bytes)
    }

    fn decode(bytes: &[u8], format: image::ImageFormat) -> image::DynamicImage {
        image::load_from_memory_with_format(bytes, format).unwrap()
    }

    fn srgb8_of(x: f32) -> u8 {
        (linear_to_srgb(x) * 255.0).round() as u8
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

    fn read_exr(bytes: &[u8]) -> (usize, usize, Vec<[f32; 4]>, exr::prelude::SampleType) {
        use exr::prelude::*;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |size: Vec2<usize>, _: &RgbaChannels| (size.0, vec![[0.0f32; 4]; size.area()]),
                |(w, px): &mut (usize, Vec<[f32; 4]>),
                 pos: Vec2<usize>,
                 (r, g, b, a): (f32, f32, f32, f32)| {
                    px[pos.y() * *w + pos.x()] = [r, g, b, a];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(bytes))
            .unwrap();
        let size = image.layer_data.size;
        let sample_type = image.layer_data.channel_data.channels.0.sample_type;
        (
            size.0,
            size.1,
            image.layer_data.channel_data.pixels.1,
            sample_type,
        )
    }

    #[test]
    fn exr_f32_is_exact() {
        let rgba = gradient();
        for compression in ["none", "rle", "zips", "zip", "piz"] {
            let params = format!("(compression: \"{compression}\")");
            let (w, h, px, ty) = read_exr(&encode::<Exr>(&params, &rgba).unwrap());
            assert_eq!((w, h), (W as usize, H as usize));
            assert_eq!(ty, exr::prelude::SampleType::F32);
            for (got, want) in px.iter().zip(rgba.chunks_exact(4)) {
                for (g, w) in got.iter().zip(want) {
                    // NaN survives as NaN; everything else bit for bit.
                    assert!(
                        g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan()),
                        "{compression}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn exr_default_is_zip_and_over_one_survives() {
        let mut rgba = gradient();
        rgba[4] = 1234.5;
        let (_, _, px, _) = read_exr(&encode::<Exr>("()", &rgba).unwrap());
        assert_eq!(px[1][0], 1234.5);
        assert_eq!(px[H as usize * W as usize - 1], [1.0, 0.5, 1.0, 1.0]);
    }

    #[test]
    fn exr_half_within_tolerance() {
        let rgba = gradient();
        for compression in ["zip", "piz", "pxr24", "none"] {
            let params = format!("(half: true, compression: \"{compression}\")");
            let (w, h, px, ty) = read_exr(&encode::<Exr>(&params, &rgba).unwrap());
            assert_eq!((w, h), (W as usize, H as usize));
            assert_eq!(ty, exr::prelude::SampleType::F16);
            for (got, want) in px
                .iter()
                .zip(rgba.chunks_exact(4))
                .take((W * (H - 1)) as usize)
            {
                for (g, w) in got.iter().zip(want) {
                    assert!((g - w).abs() <= 1e-3, "{compression}: {got:?} vs {want:?}");
                }
            }
        }
    }

    #[test]
    fn exr_lossy_compressions_write() {
        let rgba = gradient();
        for params in [
            "(half: true, compression: \"b44\")",
            "(half: true, compression: \"b44a\")",
            "(compression: \"pxr24\")",
        ] {
            let (w, h, px, _) = read_exr(&encode::<Exr>(params, &rgba).unwrap());
            assert_eq!((w, h), (W as usize, H as usize));
            assert!(
                (px[W as usize - 1][0] - 1.0).abs() < 1e-2,
                "{params}: {:?}",
                px[W as usize - 1]
            );
        }
    }

    #[test]
    fn exr_rejects_unknown_compression() {
        let e = encode::<Exr>("(compression: \"pix\")", &gradient()).unwrap_err();
        assert!(
            e.message.contains("parameter `compression`"),
            "{}",
            e.message
        );
        assert!(e.message.contains("did you mean \"piz\""), "{}", e.message);
        let e = encode::<Exr>("(compression: \"dwaa\")", &gradient()).unwrap_err();
        assert!(e.message.contains("expected one of"), "{}", e.message);
    }

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
        check::<Exr>("()");
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
