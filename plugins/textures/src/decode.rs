//! Reading image files: the header at create time ([`probe`]), the texels on first use
//! ([`decode`]).
//!
//! PNG, JPEG, TGA and PPM/PGM/PBM/PAM go through the `image` crate, OpenEXR through `exr`.
//! Integer sources (8 and 16 bits) are sRGB-encoded unless `srgb: false`; their alpha is
//! linear. Float sources (EXR, float PNM) are linear already. Grey images become grey RGB.

use crate::mipmap::Level;
use image::{DynamicImage, ImageFormat, ImageReader};
use luxon_plugin::Error;
use std::path::Path;

/// Largest image accepted, in texels (16384 × 16384): 4 GiB of float RGBA before its MIP levels.
pub const MAX_TEXELS: u64 = 1 << 28;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Exr,
    Raster(ImageFormat),
}

impl Format {
    pub fn name(self) -> &'static str {
        match self {
            Format::Exr => "OpenEXR",
            Format::Raster(ImageFormat::Png) => "PNG",
            Format::Raster(ImageFormat::Jpeg) => "JPEG",
            Format::Raster(ImageFormat::Tga) => "TGA",
            Format::Raster(ImageFormat::Pnm) => "PNM",
            Format::Raster(_) => "image",
        }
    }
}

/// What [`probe`] learns from a file's header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    pub width: usize,
    pub height: usize,
    pub format: Format,
}

const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
const SUPPORTED: &str = "PNG, JPEG, TGA, PPM/PGM/PBM/PAM and OpenEXR";

fn is_exr(path: &Path) -> std::io::Result<bool> {
    use std::io::Read;
    let mut magic = [0u8; 4];
    let mut f = std::fs::File::open(path)?;
    let n = f.read(&mut magic)?;
    Ok(n == 4 && magic == EXR_MAGIC)
}

/// Checks that `path` exists, is a supported image and has a sane size; reads only the header.
pub fn probe(path: &Path) -> Result<Header, Error> {
    let shown = path.display();
    // By type, before opening: a directory is no missing file, and a FIFO would block the open.
    let what = match std::fs::metadata(path) {
        Err(_) => return Err(Error::new(format!("image file `{shown}` not found"))),
        Ok(m) if m.is_file() => None,
        Ok(m) if m.is_dir() => Some("a directory"),
        Ok(_) => Some("not a regular file (a FIFO, socket or device)"),
    };
    if let Some(what) = what {
        return Err(Error::new(format!(
            "image file `{shown}` is {what}; expected an image file"
        )));
    }
    let cannot =
        |e: &dyn std::fmt::Display| Error::new(format!("cannot read image `{shown}`: {e}"));
    let (width, height, format) = if is_exr(path).map_err(|e| cannot(&e))? {
        let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| cannot(&e))?;
        let has =
            |h: &exr::meta::header::Header, c: &str| h.channels.list.iter().any(|d| d.name.eq(c));
        let header = meta
            .headers
            .iter()
            .find(|h| !h.deep && ["R", "G", "B"].iter().all(|c| has(h, c)))
            .ok_or_else(|| {
                let found: Vec<String> = meta
                    .headers
                    .iter()
                    .flat_map(|h| h.channels.list.iter().map(|d| d.name.to_string()))
                    .collect();
                Error::new(format!(
                    "OpenEXR image `{shown}` has no layer with R, G and B channels \
                     (channels: {})",
                    found.join(", ")
                ))
            })?;
        (header.layer_size.0, header.layer_size.1, Format::Exr)
    } else {
        let reader = ImageReader::open(path)
            .and_then(|r| r.with_guessed_format())
            .map_err(|e| cannot(&e))?;
        let format = match reader.format() {
            Some(
                f @ (ImageFormat::Png | ImageFormat::Jpeg | ImageFormat::Tga | ImageFormat::Pnm),
            ) => f,
            Some(other) => {
                return Err(Error::new(format!(
                    "image `{shown}` is {other:?}, which is not supported (supported: {SUPPORTED})"
                )))
            }
            None => {
                return Err(Error::new(format!(
                    "image `{shown}` is not in a recognised format (supported: {SUPPORTED})"
                )))
            }
        };
        let (w, h) = reader.into_dimensions().map_err(|e| cannot(&e))?;
        (w as usize, h as usize, Format::Raster(format))
    };
    if width == 0 || height == 0 {
        return Err(Error::new(format!(
            "image `{shown}` is empty ({width}x{height})"
        )));
    }
    if width as u64 * height as u64 > MAX_TEXELS {
        return Err(Error::new(format!(
            "image `{shown}` is too large: {width}x{height} texels (at most {MAX_TEXELS})"
        )));
    }
    Ok(Header {
        width,
        height,
        format,
    })
}

/// The sRGB transfer function, decoded to linear.
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// The full-resolution texels of the image `header` describes (rows top to bottom).
/// Errors are plain text: they are logged, not returned to the host.
pub fn decode(path: &Path, header: &Header, srgb: bool) -> Result<Level, String> {
    let level = match header.format {
        Format::Exr => decode_exr(path)?,
        Format::Raster(format) => {
            let mut reader = ImageReader::open(path).map_err(|e| e.to_string())?;
            reader.set_format(format);
            // Our own size check (at create) replaces the crate's default allocation limit.
            reader.no_limits();
            let img = reader.decode().map_err(|e| e.to_string())?;
            convert(img, srgb)
        }
    };
    if (level.width, level.height) != (header.width, header.height) {
        return Err(format!(
            "the image changed since the scene was loaded: {}x{} texels, expected {}x{}",
            level.width, level.height, header.width, header.height
        ));
    }
    Ok(level)
}

fn convert(img: DynamicImage, srgb: bool) -> Level {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let texels = match img {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
            img.to_rgba32f().pixels().map(|p| p.0).collect()
        }
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => {
            let f = |v: u16| {
                let x = v as f32 / 65535.0;
                if srgb {
                    srgb_to_linear(x)
                } else {
                    x
                }
            };
            img.to_rgba16()
                .pixels()
                .map(|p| [f(p.0[0]), f(p.0[1]), f(p.0[2]), p.0[3] as f32 / 65535.0])
                .collect()
        }
        _ => {
            let table: [f32; 256] = std::array::from_fn(|i| {
                let x = i as f32 / 255.0;
                if srgb {
                    srgb_to_linear(x)
                } else {
                    x
                }
            });
            img.to_rgba8()
                .pixels()
                .map(|p| {
                    let [r, g, b, a] = p.0;
                    [
                        table[r as usize],
                        table[g as usize],
                        table[b as usize],
                        a as f32 / 255.0,
                    ]
                })
                .collect()
        }
    };
    Level::new(w, h, texels)
}

fn decode_exr(path: &Path) -> Result<Level, String> {
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
        .from_file(path)
        .map_err(|e| e.to_string())?;
    let size = image.layer_data.size;
    let (_, texels) = image.layer_data.channel_data.pixels;
    if size.0 == 0 || size.1 == 0 {
        return Err("the image is empty".into());
    }
    // Non-finite samples would poison every MIP level above them.
    let texels = texels
        .into_iter()
        .map(|t| t.map(|x| if x.is_finite() { x } else { 0.0 }))
        .collect();
    Ok(Level::new(size.0, size.1, texels))
}

#[cfg(test)]
mod tests {
    use super::probe;

    #[test]
    fn a_directory_is_not_reported_as_missing() {
        let dir = crate::testutil::TempDir::new("probe-types");
        std::fs::create_dir(dir.path("d.png")).unwrap();
        let e = probe(&dir.path("d.png")).unwrap_err().message;
        assert!(
            e.ends_with("d.png` is a directory; expected an image file"),
            "{e}"
        );
        let e = probe(&dir.path("gone.png")).unwrap_err().message;
        assert!(e.ends_with("gone.png` not found"), "{e}");
    }
}
