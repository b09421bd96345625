//! `exr`: OpenEXR, linear float RGBA (32-bit or half), stored unchanged, with any compression
//! the `exr` crate can write.

use std::io::Write;

use crate::encode::{check_image, encode_error};
use luxon_plugin::{invalid, Context, Describe, Error, Image, Writer};
use serde::Deserialize;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{encode, gradient, H, W};

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
}
