//! The animated preview of a sequence (`luxon render --preview anim.png|anim.gif`): the frames
//! read back from their first output that can be decoded here (PNG, JPEG, TGA, PPM),
//! downscaled to at most [`PREVIEW_WIDTH`] pixels wide, and written as an animated PNG (APNG)
//! or a GIF that loops, atomically (a reader never sees half a preview).

use crate::error::Error;
use crate::files::write_atomic;
use image::RgbaImage;
use std::path::{Path, PathBuf};

/// The widest preview, in pixels (narrower frames keep their size).
pub const PREVIEW_WIDTH: u32 = 320;

/// What a preview file is, by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Apng,
    Gif,
}

/// A preview to write: where, as what, and how long each frame shows.
#[derive(Clone, Debug)]
pub struct Preview {
    path: PathBuf,
    format: Format,
    /// Milliseconds per frame.
    delay_ms: u32,
}

/// Extensions of frame files the preview can read back.
const READABLE: &[&str] = &["png", "jpg", "jpeg", "tga", "ppm", "pnm"];

fn extension(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

impl Preview {
    /// A preview at `path` (`.png`: APNG, `.gif`: GIF) of frames shown `seconds` each.
    pub fn new(path: &Path, seconds: f64) -> Result<Preview, Error> {
        let format = match extension(path).as_str() {
            "png" | "apng" => Format::Apng,
            "gif" => Format::Gif,
            _ => {
                return Err(Error::Usage(format!(
                    "--preview {}: expected a `.png` (animated PNG) or `.gif` file",
                    path.display()
                )))
            }
        };
        let delay_ms = (seconds * 1000.0).round().clamp(10.0, 65_535.0) as u32;
        Ok(Preview {
            path: path.to_path_buf(),
            format,
            delay_ms,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Of a frame's outputs, the first the preview can read back; an error names the outputs
    /// when none can be.
    pub fn source<'a>(&self, outputs: &'a [PathBuf]) -> Result<&'a Path, Error> {
        outputs
            .iter()
            .find(|p| READABLE.contains(&extension(p).as_str()))
            .map(PathBuf::as_path)
            .ok_or_else(|| {
                let names: Vec<String> = outputs.iter().map(|p| p.display().to_string()).collect();
                Error::Usage(format!(
                    "--preview {} needs a frame output it can read back (.png, .jpg, .tga or \
                     .ppm); the outputs are {}",
                    self.path.display(),
                    names.join(", ")
                ))
            })
    }

    /// Reads `frames` (image files, in order), downscales them and writes the preview.
    pub fn write(&self, frames: &[PathBuf]) -> Result<(), Error> {
        let mut images = Vec::with_capacity(frames.len());
        for f in frames {
            let img = image::open(f).map_err(|e| {
                Error::Render(format!(
                    "--preview: cannot read the frame `{}`: {e}",
                    f.display()
                ))
            })?;
            images.push(downscale(img.to_rgba8()));
        }
        let Some(first) = images.first() else {
            return Ok(());
        };
        let (w, h) = first.dimensions();
        if let Some((f, _)) = frames
            .iter()
            .zip(&images)
            .find(|(_, i)| i.dimensions() != (w, h))
        {
            return Err(Error::Render(format!(
                "--preview: the frame `{}` is not the size of the first ({w}x{h})",
                f.display()
            )));
        }
        let bytes = match self.format {
            Format::Apng => apng(&images, self.delay_ms),
            Format::Gif => gif(images, self.delay_ms),
        }
        .map_err(|e| Error::Render(format!("--preview {}: {e}", self.path.display())))?;
        write_atomic(&self.path, &bytes)
    }
}

/// `img` at most `PREVIEW_WIDTH` wide, its aspect kept.
fn downscale(img: RgbaImage) -> RgbaImage {
    let (w, h) = img.dimensions();
    if w <= PREVIEW_WIDTH {
        return img;
    }
    let nh = ((u64::from(h) * u64::from(PREVIEW_WIDTH) + u64::from(w) / 2) / u64::from(w)).max(1);
    image::imageops::resize(
        &img,
        PREVIEW_WIDTH,
        nh as u32,
        image::imageops::FilterType::Triangle,
    )
}

/// An animated PNG of `frames` (all one size), looping.
fn apng(frames: &[RgbaImage], delay_ms: u32) -> Result<Vec<u8>, String> {
    let (w, h) = frames[0].dimensions();
    let mut out = Vec::new();
    {
        let mut e = png::Encoder::new(&mut out, w, h);
        e.set_color(png::ColorType::Rgba);
        e.set_depth(png::BitDepth::Eight);
        let n = u32::try_from(frames.len()).map_err(|e| e.to_string())?;
        e.set_animated(n, 0).map_err(|e| e.to_string())?;
        e.set_frame_delay(delay_ms as u16, 1000)
            .map_err(|e| e.to_string())?;
        let mut writer = e.write_header().map_err(|e| e.to_string())?;
        for f in frames {
            writer
                .write_image_data(f.as_raw())
                .map_err(|e| e.to_string())?;
        }
        writer.finish().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// A GIF of `frames`, looping.
fn gif(frames: Vec<RgbaImage>, delay_ms: u32) -> Result<Vec<u8>, String> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let mut out = Vec::new();
    {
        let mut e = GifEncoder::new_with_speed(&mut out, 10);
        e.set_repeat(Repeat::Infinite).map_err(|e| e.to_string())?;
        let delay = image::Delay::from_numer_denom_ms(delay_ms, 1);
        let frames = frames
            .into_iter()
            .map(|f| image::Frame::from_parts(f, 0, 0, delay));
        e.encode_frames(frames).map_err(|e| e.to_string())?;
    }
    Ok(out)
}
