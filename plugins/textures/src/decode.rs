//! Reading image files within a memory cap: the header at create time ([`probe`]), which MIP
//! level to decode at ([`plan`]), the texels on first use ([`decode`]).
//!
//! PNG, JPEG, TGA and PPM/PGM/PBM/PAM go through the `image` crate, except non-interlaced PNG,
//! which the `png` crate decodes row by row; OpenEXR goes through `exr`. Sample conversion is in
//! `texels.rs`, the row-by-row MIP reduction in `reduce.rs`.
//!
//! **The cap.** Each image may use `cap` bytes while it is decoded (`image::decode_cap`): the
//! MIP levels kept plus what the decoder holds. If the whole float pyramid fits, the image is
//! used at full size, as it always was. Otherwise it is used from MIP level `k`, the first whose
//! decode fits: a non-interlaced PNG is streamed through the reducers, so only levels `k..` and a
//! few rows are ever held; the other formats are decoded whole at their own precision (that
//! buffer must fit the cap, or the image is refused at create) and reduced from that buffer,
//! without further full-size copies. Either way level `k` holds the same texels as level `k` of
//! the full image.
//!
//! A header that claims a large image costs nothing until rows arrive: levels are allocated at
//! their first row, so a short file fails before it is paid for.

use crate::mipmap::{level_sizes, pyramid_bytes};
use crate::reduce::Pyramid;
use crate::texels::{Converter, RowFormat};
use image::{ImageDecoder, ImageFormat, ImageReader};
use luxon_plugin::Error;
use std::io::{BufRead, BufReader, Read, Seek};
use std::path::Path;

pub use crate::mipmap::Level;
pub use crate::texels::srgb_to_linear;

/// Largest image decoded whole (JPEG, TGA, PNM, interlaced PNG, OpenEXR), in texels: 16384².
pub const MAX_TEXELS: u64 = 1 << 28;

/// Largest image streamed row by row (non-interlaced PNG), in texels: 65536². Only the levels
/// that fit the cap are held, so this bounds the decoding time, not the memory.
pub const MAX_STREAM_TEXELS: u64 = 1 << 32;

/// Bytes held per image column while streaming: the PNG decoder's rows, the converted row and
/// the reducers' rows (three rows of half the width for the first, half that for each next).
const STREAM_BYTES_PER_COLUMN: u64 = 128;

const TEXEL_BYTES: u64 = std::mem::size_of::<[f32; 4]>() as u64;

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

/// How a decoder delivers the texels, which decides what a decode holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Row by row (non-interlaced PNG): the levels kept and a few rows.
    Rows,
    /// The whole image in one buffer of `bytes`, at the source's precision, held while the
    /// levels are built (JPEG, TGA, PNM, interlaced PNG).
    Whole { bytes: u64 },
    /// The whole image as float RGBA (OpenEXR), which becomes level 0 when that is kept.
    Float,
}

/// What [`probe`] learns from a file's header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    pub width: usize,
    pub height: usize,
    pub format: Format,
    pub layout: Layout,
}

impl Header {
    /// Bytes a decode that keeps the levels from `first` on holds at its peak.
    pub fn decode_bytes(&self, first: usize) -> u64 {
        let sizes = level_sizes(self.width, self.height);
        let kept = pyramid_bytes(&sizes[first.min(sizes.len() - 1)..]);
        let texels = self.width as u64 * self.height as u64;
        kept.saturating_add(match self.layout {
            Layout::Rows => STREAM_BYTES_PER_COLUMN * self.width as u64,
            Layout::Whole { bytes } => bytes,
            Layout::Float if first == 0 => 0,
            Layout::Float => texels * TEXEL_BYTES,
        })
    }
}

const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
const SUPPORTED: &str = "PNG, JPEG, TGA, PPM/PGM/PBM/PAM and OpenEXR";

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
    let file = std::fs::File::open(path)
        .map_err(|e| Error::new(format!("cannot read image `{shown}`: {e}")))?;
    probe_reader(BufReader::new(file), &shown.to_string())
}

/// [`probe`] on the bytes of a file. `shown` names it in messages, and its extension tells the
/// format when the content does not (TGA has no signature).
pub fn probe_reader<R: BufRead + Seek>(mut r: R, shown: &str) -> Result<Header, Error> {
    let cannot =
        |e: &dyn std::fmt::Display| Error::new(format!("cannot read image `{shown}`: {e}"));
    let mut magic = Vec::new();
    (&mut r)
        .take(4)
        .read_to_end(&mut magic)
        .map_err(|e| cannot(&e))?;
    r.rewind().map_err(|e| cannot(&e))?;
    let header = if magic == EXR_MAGIC {
        let meta = exr::meta::MetaData::read_from_buffered(r, false).map_err(|e| cannot(&e))?;
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
        Header {
            width: header.layer_size.0,
            height: header.layer_size.1,
            format: Format::Exr,
            layout: Layout::Float,
        }
    } else {
        let mut reader = ImageReader::new(r);
        if let Ok(by_name) = ImageFormat::from_path(shown) {
            reader.set_format(by_name);
        }
        let reader = reader.with_guessed_format().map_err(|e| cannot(&e))?;
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
        if format == ImageFormat::Png {
            probe_png(reader.into_inner(), shown)?
        } else {
            let decoder = reader.into_decoder().map_err(|e| cannot(&e))?;
            let (w, h) = decoder.dimensions();
            Header {
                width: w as usize,
                height: h as usize,
                format: Format::Raster(format),
                layout: Layout::Whole {
                    bytes: decoder.total_bytes(),
                },
            }
        }
    };
    let (width, height) = (header.width, header.height);
    if width == 0 || height == 0 {
        return Err(Error::new(format!(
            "image `{shown}` is empty ({width}x{height})"
        )));
    }
    let max = match header.layout {
        Layout::Rows => MAX_STREAM_TEXELS,
        _ => MAX_TEXELS,
    };
    if width as u64 * height as u64 > max {
        let hint = match header.layout {
            Layout::Rows => "",
            _ => "; a non-interlaced PNG may be larger (it is decoded row by row)",
        };
        return Err(Error::new(format!(
            "image `{shown}` is too large: {width}x{height} texels (at most {max} as {}{hint})",
            header.format.name()
        )));
    }
    Ok(header)
}

/// A PNG decoder set up as every read here uses it: palettes and low bit depths expanded (as
/// the `image` crate does), text and colour profiles skipped (never used).
fn png_decoder<R: BufRead + Seek>(r: R, cap: u64) -> png::Decoder<R> {
    let limits = png::Limits {
        bytes: usize::try_from(cap).unwrap_or(usize::MAX),
    };
    let mut d = png::Decoder::new_with_limits(r, limits);
    d.set_transformations(png::Transformations::EXPAND);
    d.set_ignore_text_chunk(true);
    d.set_ignore_iccp_chunk(true);
    d
}

fn probe_png<R: BufRead + Seek>(mut r: R, shown: &str) -> Result<Header, Error> {
    let cannot =
        |e: &dyn std::fmt::Display| Error::new(format!("cannot read image `{shown}`: {e}"));
    r.rewind().map_err(|e| cannot(&e))?;
    let mut d = png_decoder(r, 64 << 20);
    let info = d.read_header_info().map_err(|e| cannot(&e))?;
    let (width, height, interlaced) = (info.width as usize, info.height as usize, info.interlaced);
    if width as u64 * height as u64 > MAX_STREAM_TEXELS {
        // Before `read_info`, which sizes the whole image.
        return Err(Error::new(format!(
            "image `{shown}` is too large: {width}x{height} texels (at most {MAX_STREAM_TEXELS} as PNG)"
        )));
    }
    // The chunks up to the image data: a broken file is found at create, not mid-render.
    let reader = d.read_info().map_err(|e| cannot(&e))?;
    let layout = if interlaced {
        let bytes = reader.output_buffer_size().unwrap_or(usize::MAX);
        Layout::Whole {
            bytes: bytes as u64,
        }
    } else {
        Layout::Rows
    };
    Ok(Header {
        width,
        height,
        format: Format::Raster(ImageFormat::Png),
        layout,
    })
}

/// A byte count for people.
pub fn size(bytes: u64) -> String {
    let b = bytes as f64;
    match bytes {
        0..1024 => format!("{bytes} bytes"),
        1024..1_048_576 => format!("{:.1} KiB", b / 1024.0),
        1_048_576..1_073_741_824 => format!("{:.1} MiB", b / 1_048_576.0),
        _ => format!("{:.1} GiB", b / 1_073_741_824.0),
    }
}

/// How an image is decoded: from which MIP level on, within how many bytes, and whether the
/// coarser levels are built at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    /// The first MIP level kept: the image is used at that level's size.
    pub first_level: usize,
    pub cap: u64,
    /// Whether the levels below the first are kept too: only MIP filtering reads them, so a
    /// nearest or bilinear texture skips building them. The first level is chosen as if they
    /// were kept, so an image is used at the same size whatever its filter.
    pub mip: bool,
}

/// The first level whose decode fits `cap`, or an error naming the image (`shown`), its size
/// and the cap when not even the last level (1×1) does.
pub fn plan(shown: &str, header: &Header, cap: u64) -> Result<Plan, Error> {
    let levels = level_sizes(header.width, header.height).len();
    match (0..levels).find(|&k| header.decode_bytes(k) <= cap) {
        Some(first_level) => Ok(Plan {
            first_level,
            cap,
            mip: true,
        }),
        None => {
            let hint = match header.layout {
                Layout::Rows => "use a smaller image",
                Layout::Float => "use a smaller image",
                Layout::Whole { .. } => {
                    "use a smaller image, or a non-interlaced PNG (decoded row by row)"
                }
            };
            Err(Error::new(format!(
                "image `{shown}` ({}x{} {}) needs {} to decode, more than the texture memory \
                 cap of {}; {hint}",
                header.width,
                header.height,
                header.format.name(),
                size(header.decode_bytes(levels - 1)),
                size(cap)
            )))
        }
    }
}

impl Plan {
    /// Size of the first level kept.
    pub fn size(&self, header: &Header) -> (usize, usize) {
        let sizes = level_sizes(header.width, header.height);
        sizes[self.first_level.min(sizes.len() - 1)]
    }

    /// The warning for an image used below its full size.
    pub fn warning(&self, shown: &str, header: &Header) -> Option<String> {
        if self.first_level == 0 {
            return None;
        }
        let (w, h) = self.size(header);
        Some(format!(
            "image `{shown}` ({}x{}) is decoded at {w}x{h} to stay within the texture memory cap \
             of {} (at full size it needs {} with its MIP levels)",
            header.width,
            header.height,
            size(self.cap),
            size(header.decode_bytes(0))
        ))
    }
}

/// The MIP levels `plan.first_level..` of the image `header` describes (rows top to bottom);
/// only the first of them without `plan.mip`.
/// Errors are plain text: they are logged, not returned to the host.
pub fn decode(path: &Path, header: &Header, srgb: bool, plan: &Plan) -> Result<Vec<Level>, String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    decode_reader(BufReader::new(file), header, srgb, plan)
}

/// [`decode`] on the bytes of a file.
pub fn decode_reader<R: BufRead + Seek>(
    r: R,
    header: &Header,
    srgb: bool,
    plan: &Plan,
) -> Result<Vec<Level>, String> {
    match (header.format, header.layout) {
        (Format::Exr, _) => decode_exr(r, header, plan),
        (Format::Raster(_), Layout::Rows) => decode_png_rows(r, header, srgb, plan),
        (Format::Raster(format), _) => decode_whole(r, format, header, srgb, plan),
    }
}

fn changed(w: usize, h: usize, header: &Header) -> String {
    format!(
        "the image changed since the scene was loaded: {w}x{h} texels, expected {}x{}",
        header.width, header.height
    )
}

/// A row of `n` texels, or an error instead of an abort.
fn texel_row(n: usize) -> Result<Vec<[f32; 4]>, String> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| format!("cannot allocate a row of {n} texels"))?;
    v.resize(n, [0.0; 4]);
    Ok(v)
}

/// Where an image's rows of samples go: converted into the MIP pyramid, except that an 8-bit
/// image's level 0, when kept, is kept as its samples ([`Level::from_bytes`]) and only the
/// coarser levels are built from the converted rows.
struct Rows {
    convert: Converter,
    size: (usize, usize),
    /// Level 0's texels as bytes, when it is kept so.
    codes: Option<Vec<[u8; 4]>>,
    /// The float levels; none when level 0 alone is kept as bytes.
    pyramid: Option<Pyramid>,
    row: Vec<[f32; 4]>,
}

impl Rows {
    fn new(convert: Converter, w: usize, h: usize, plan: &Plan) -> Result<Rows, String> {
        let bytes = convert.is_u8() && plan.first_level == 0;
        // Allocated at the first row, as the levels are.
        let codes = bytes.then(Vec::new);
        let coarser = plan.mip && level_sizes(w, h).len() > 1;
        let pyramid = match (bytes, coarser) {
            (false, _) => Some(Pyramid::new(w, h, plan.first_level, plan.mip)),
            (true, true) => Some(Pyramid::new(w, h, 1, true)),
            (true, false) => None,
        };
        let row = if pyramid.is_some() {
            texel_row(w)?
        } else {
            Vec::new()
        };
        Ok(Rows {
            convert,
            size: (w, h),
            codes,
            pyramid,
            row,
        })
    }

    /// Takes the next row's samples (exactly a row's).
    fn push(&mut self, samples: &[u8]) -> Result<(), String> {
        let (w, h) = self.size;
        if let Some(codes) = &mut self.codes {
            if codes.len() == w * h {
                return Err(format!(
                    "the image has more rows than its header says ({w}x{h})"
                ));
            }
            if codes.capacity() == 0 {
                let e = |_| format!("cannot allocate level 0 ({w}x{h}, 4 bytes a texel)");
                codes.try_reserve_exact(w * h).map_err(e)?;
            }
            self.convert.codes(samples, codes);
        }
        if let Some(pyramid) = &mut self.pyramid {
            self.convert.row(samples, &mut self.row);
            pyramid.push_row(&self.row)?;
        }
        Ok(())
    }

    /// The kept levels, finest first; an error if rows are missing.
    fn finish(self) -> Result<Vec<Level>, String> {
        let Some(codes) = self.codes else {
            return self.pyramid.expect("a pyramid without bytes").finish();
        };
        let (w, h) = self.size;
        if codes.len() != w * h {
            return Err(format!(
                "the image ends after {} of its {h} rows ({w}x{h})",
                codes.len() / w
            ));
        }
        let table = self.convert.decode_table();
        let mut levels = vec![Level::from_bytes(w, h, codes, table)];
        if let Some(pyramid) = self.pyramid {
            levels.extend(pyramid.finish()?);
        }
        Ok(levels)
    }
}

/// Non-interlaced PNG, row by row into the reducers.
fn decode_png_rows<R: BufRead + Seek>(
    r: R,
    header: &Header,
    srgb: bool,
    plan: &Plan,
) -> Result<Vec<Level>, String> {
    let mut reader = png_decoder(r, plan.cap)
        .read_info()
        .map_err(|e| e.to_string())?;
    let info = reader.info();
    let (w, h) = (info.width as usize, info.height as usize);
    if (w, h) != (header.width, header.height) || info.interlaced {
        return Err(changed(w, h, header));
    }
    let (colour, depth) = reader.output_color_type();
    let format = RowFormat::of_png(colour, depth)
        .ok_or_else(|| format!("unsupported PNG sample layout {colour:?} {depth:?}"))?;
    let mut rows = Rows::new(Converter::new(format, srgb), w, h, plan)?;
    while let Some(r) = reader.next_row().map_err(|e| e.to_string())? {
        if r.data().len() != w * format.bytes_per_texel() {
            return Err("a PNG row has the wrong length".into());
        }
        rows.push(r.data())?;
    }
    rows.finish()
}

/// Formats decoded whole by the `image` crate into their own buffer, then reduced row by row.
fn decode_whole<R: BufRead + Seek>(
    r: R,
    format: ImageFormat,
    header: &Header,
    srgb: bool,
    plan: &Plan,
) -> Result<Vec<Level>, String> {
    let mut reader = ImageReader::new(r);
    reader.set_format(format);
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(plan.cap);
    reader.limits(limits);
    let decoder = reader.into_decoder().map_err(|e| e.to_string())?;
    let (w, h) = decoder.dimensions();
    let (w, h) = (w as usize, h as usize);
    if (w, h) != (header.width, header.height) {
        return Err(changed(w, h, header));
    }
    let colour = decoder.color_type();
    let format = RowFormat::of_image(colour)
        .ok_or_else(|| format!("unsupported sample layout {colour:?}"))?;
    // The buffer the plan counted on, unless the file changed since.
    let bytes = decoder.total_bytes();
    let now = Header {
        layout: Layout::Whole { bytes },
        ..*header
    };
    if now.decode_bytes(plan.first_level) > plan.cap {
        return Err(format!(
            "the image changed since the scene was loaded: it now needs {} to decode, more \
             than the texture memory cap of {}",
            size(now.decode_bytes(plan.first_level)),
            size(plan.cap)
        ));
    }
    let len = usize::try_from(bytes).map_err(|_| "the image is too large".to_string())?;
    let mut buf = Vec::new();
    buf.try_reserve_exact(len)
        .map_err(|_| format!("cannot allocate {} to decode the image", size(bytes)))?;
    buf.resize(len, 0u8);
    decoder.read_image(&mut buf).map_err(|e| e.to_string())?;
    let mut rows = Rows::new(Converter::new(format, srgb), w, h, plan)?;
    for samples in buf.chunks_exact(w * format.bytes_per_texel()) {
        rows.push(samples)?;
    }
    rows.finish()
}

/// OpenEXR: read whole as float RGBA (the `exr` crate calls back per texel, in block order),
/// then reduced row by row; the buffer itself is level 0 when that is kept.
fn decode_exr<R: BufRead + Seek>(r: R, header: &Header, plan: &Plan) -> Result<Vec<Level>, String> {
    use exr::prelude::*;
    let want = (header.width, header.height);
    /// The texels, or none when the layer is not the size probed (then nothing is allocated).
    struct Texels {
        width: usize,
        px: Vec<[f32; 4]>,
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size: Vec2<usize>, _: &RgbaChannels| Texels {
                width: size.0,
                px: if (size.0, size.1) == want {
                    vec![[0.0f32; 4]; size.area()]
                } else {
                    Vec::new()
                },
            },
            |t: &mut Texels, pos: Vec2<usize>, (r, g, b, a): (f32, f32, f32, f32)| {
                // Non-finite samples would poison every MIP level above them.
                let clean = |x: f32| if x.is_finite() { x } else { 0.0 };
                if let Some(p) = t.px.get_mut(pos.y() * t.width + pos.x()) {
                    *p = [clean(r), clean(g), clean(b), clean(a)];
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(r)
        .map_err(|e| e.to_string())?;
    let size = image.layer_data.size;
    if (size.0, size.1) != want {
        return Err(changed(size.0, size.1, header));
    }
    let px = image.layer_data.channel_data.pixels.px;
    let (w, h) = want;
    if level_sizes(w, h).len() == 1 || (plan.first_level == 0 && !plan.mip) {
        return Ok(vec![Level::new(w, h, px)]);
    }
    let mut pyramid = Pyramid::new(w, h, plan.first_level.max(1), plan.mip);
    for row in px.chunks_exact(w) {
        pyramid.push_row(row)?;
    }
    let coarser = pyramid.finish()?;
    if plan.first_level > 0 {
        return Ok(coarser);
    }
    let mut levels = vec![Level::new(w, h, px)];
    levels.extend(coarser);
    Ok(levels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mipmap::build_pyramid;
    use crate::testutil::*;
    use image::DynamicImage;
    use std::path::PathBuf;

    const ALL: u64 = u64::MAX;

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

    /// Level 0 the way it was decoded before the cap existed: the `image` crate's whole
    /// `DynamicImage`, copied to RGBA, then to linear float. The reference the new paths match.
    fn reference(path: &Path, srgb: bool) -> Level {
        let mut reader = ImageReader::open(path)
            .unwrap()
            .with_guessed_format()
            .unwrap();
        reader.no_limits();
        let img = reader.decode().unwrap();
        let (w, h) = (img.width() as usize, img.height() as usize);
        let f = |x: f32| if srgb { srgb_to_linear(x) } else { x };
        let texels = match img {
            DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
                img.to_rgba32f().pixels().map(|p| p.0).collect()
            }
            DynamicImage::ImageLuma16(_)
            | DynamicImage::ImageLumaA16(_)
            | DynamicImage::ImageRgb16(_)
            | DynamicImage::ImageRgba16(_) => {
                let c = |v: u16| f(v as f32 / 65535.0);
                img.to_rgba16()
                    .pixels()
                    .map(|p| [c(p.0[0]), c(p.0[1]), c(p.0[2]), p.0[3] as f32 / 65535.0])
                    .collect()
            }
            _ => {
                let c = |v: u8| f(v as f32 / 255.0);
                img.to_rgba8()
                    .pixels()
                    .map(|p| [c(p.0[0]), c(p.0[1]), c(p.0[2]), p.0[3] as f32 / 255.0])
                    .collect()
            }
        };
        Level::new(w, h, texels)
    }

    /// Pseudo-random bytes.
    fn bytes(n: usize, seed: u64) -> Vec<u8> {
        let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 32) as u8
            })
            .collect()
    }

    /// One file of every layout the decoders deliver, with random content.
    fn fixtures(dir: &TempDir) -> Vec<PathBuf> {
        use png::{BitDepth::*, ColorType::*};
        let (w, h) = (37u32, 23u32);
        let n = (w * h) as usize;
        let mut files = Vec::new();
        let mut add = |name: &str| {
            files.push(dir.path(name));
            dir.path(name)
        };
        let big = bytes(1023 * 517 * 4, 1);
        let p = add("rgba8-odd.png");
        write_png(&p, 1023, 517, |x, y| {
            let i = 4 * (y as usize * 1023 + x as usize);
            [big[i], big[i + 1], big[i + 2], big[i + 3]]
        });
        write_png_with(
            &add("rgb16.png"),
            w,
            h,
            Rgb,
            Sixteen,
            |_| {},
            &bytes(n * 6, 2),
        );
        write_png_with(
            &add("grey8.png"),
            w,
            h,
            Grayscale,
            Eight,
            |_| {},
            &bytes(n, 3),
        );
        write_png_with(
            &add("greya16.png"),
            w,
            h,
            GrayscaleAlpha,
            Sixteen,
            |_| {},
            &bytes(n * 4, 4),
        );
        write_png_with(
            &add("greya8.png"),
            w,
            h,
            GrayscaleAlpha,
            Eight,
            |_| {},
            &bytes(n * 2, 9),
        );
        write_png_with(&add("one8.png"), 1, 1, Rgb, Eight, |_| {}, &[7, 200, 255]);
        let grey2: Vec<u8> = bytes(h as usize * 10, 5);
        write_png_with(&add("grey2.png"), 40, h, Grayscale, Two, |_| {}, &grey2);
        let palette = bytes(16 * 3, 6);
        let index: Vec<u8> = bytes(n, 7).iter().map(|b| b % 16).collect();
        write_png_with(
            &add("palette.png"),
            w,
            h,
            Indexed,
            Eight,
            |e| {
                e.set_palette(palette.clone());
                e.set_trns(vec![0, 128, 255]);
            },
            &index,
        );
        let tex = bytes(n * 4, 8);
        let at = |x: u32, y: u32| {
            let i = 4 * (y * w + x) as usize;
            [tex[i], tex[i + 1], tex[i + 2], tex[i + 3]]
        };
        std::fs::write(add("interlaced.png"), interlaced_png(w, h, at)).unwrap();
        let rgb = image::RgbImage::from_fn(w, h, |x, y| {
            let [r, g, b, _] = at(x, y);
            image::Rgb([r, g, b])
        });
        rgb.save(add("photo.jpg")).unwrap();
        rgb.save(add("t.tga")).unwrap();
        rgb.save(add("t.ppm")).unwrap();
        let rgb16 = image::ImageBuffer::<image::Rgb<u16>, _>::from_fn(w, h, |x, y| {
            let [r, g, b, _] = at(x, y);
            image::Rgb([r as u16 * 257, g as u16 * 251 + 7, b as u16])
        });
        rgb16.save(add("t16.ppm")).unwrap();
        files
    }

    fn decoded(path: &Path, srgb: bool, first_level: usize) -> Vec<Level> {
        decoded_as(path, srgb, first_level, true)
    }

    fn decoded_as(path: &Path, srgb: bool, first_level: usize, mip: bool) -> Vec<Level> {
        let h = probe(path).unwrap();
        decode(
            path,
            &h,
            srgb,
            &Plan {
                first_level,
                cap: ALL,
                mip,
            },
        )
        .unwrap()
    }

    fn bits(l: &Level) -> Vec<[u32; 4]> {
        l.texels().iter().map(|t| t.map(f32::to_bits)).collect()
    }

    #[test]
    fn every_layout_decodes_as_before_bit_for_bit() {
        let dir = TempDir::new("decode-layouts");
        for path in fixtures(&dir) {
            let header = probe(&path).unwrap();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let want_rows = name.ends_with(".png") && name != "interlaced.png";
            assert_eq!(header.layout == Layout::Rows, want_rows, "{name}");
            for srgb in [true, false] {
                let want = build_pyramid(reference(&path, srgb));
                let got = decoded(&path, srgb, 0);
                assert_eq!(got.len(), want.len(), "{name}");
                // 8-bit samples (also 2-bit grey and palettes, expanded to 8) keep level 0
                // as bytes; the coarser levels are floats.
                let bytes = !name.contains("16") && !name.ends_with(".exr");
                assert_eq!(got[0].is_bytes(), bytes, "{name}");
                assert!(got[1..].iter().all(|l| !l.is_bytes()), "{name}");
                for (k, (g, l)) in got.iter().zip(&want).enumerate() {
                    assert!(bits(g) == bits(l), "{name}, srgb {srgb}: level {k} differs");
                }
            }
        }
    }

    #[test]
    fn a_capped_decode_gives_the_full_images_coarser_levels_bit_for_bit() {
        let dir = TempDir::new("decode-capped");
        let mut paths = fixtures(&dir);
        write_exr(&dir.path("hdr.exr"), 37, 23, |x, y| {
            let v = (x * 31 + y * 17) as f32;
            [
                v.sin() * 4.0,
                v.cos(),
                v * 0.01,
                if x == 3 { f32::NAN } else { 0.5 },
            ]
        });
        paths.push(dir.path("hdr.exr"));
        for path in paths {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let full = decoded(&path, true, 0);
            for first in 1..full.len() + 2 {
                let got = decoded(&path, true, first);
                let want = &full[first.min(full.len() - 1)..];
                assert_eq!(got.len(), want.len(), "{name} from {first}");
                for (g, l) in got.iter().zip(want) {
                    assert!(bits(g) == bits(l), "{name} from level {first}");
                }
            }
        }
    }

    #[test]
    fn without_mip_levels_only_the_first_is_decoded_the_same() {
        let dir = TempDir::new("decode-no-mip");
        let mut paths = fixtures(&dir);
        write_exr(&dir.path("hdr.exr"), 37, 23, |x, y| {
            let v = (x * 31 + y * 17) as f32;
            [v.sin() * 4.0, v.cos(), v * 0.01, 0.5]
        });
        paths.push(dir.path("hdr.exr"));
        for path in paths {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let full = decoded(&path, false, 0);
            for first in 0..full.len() + 2 {
                let got = decoded_as(&path, false, first, false);
                let want = &full[first.min(full.len() - 1)];
                assert_eq!(got.len(), 1, "{name} from {first}");
                assert_eq!((got[0].width, got[0].height), (want.width, want.height));
                assert!(bits(&got[0]) == bits(want), "{name}: level {first} differs");
            }
        }
    }

    fn header(width: usize, height: usize, format: Format, layout: Layout) -> Header {
        Header {
            width,
            height,
            format,
            layout,
        }
    }

    #[test]
    fn the_plan_keeps_the_first_level_that_fits() {
        let png = Format::Raster(ImageFormat::Png);
        let big = header(16000, 16000, png, Layout::Rows);
        // The full float pyramid: 16000² × 16 B × about 4/3.
        assert!(big.decode_bytes(0) > 5 << 30 && big.decode_bytes(0) < 6 << 30);
        let p = plan("big.png", &big, 1 << 30).unwrap();
        assert_eq!((p.first_level, p.size(&big)), (2, (4000, 4000)));
        assert_eq!(
            p.warning("big.png", &big).unwrap(),
            "image `big.png` (16000x16000) is decoded at 4000x4000 to stay within the texture \
             memory cap of 1.0 GiB (at full size it needs 5.1 GiB with its MIP levels)"
        );
        let p = plan("big.png", &big, 6 << 30).unwrap();
        assert_eq!(p.first_level, 0);
        assert_eq!(p.warning("big.png", &big), None);
        // Whole formats count their buffer too, and are refused when it alone does not fit.
        let jpeg = Format::Raster(ImageFormat::Jpeg);
        let photo = header(8000, 8000, jpeg, Layout::Whole { bytes: 192_000_000 });
        assert_eq!(plan("p.jpg", &photo, 1 << 30).unwrap().first_level, 1);
        let e = plan("p.jpg", &photo, 100 << 20).unwrap_err().message;
        assert_eq!(
            e,
            "image `p.jpg` (8000x8000 JPEG) needs 183.1 MiB to decode, more than the texture \
             memory cap of 100.0 MiB; use a smaller image, or a non-interlaced PNG (decoded row \
             by row)"
        );
        // OpenEXR: at full size the float buffer is level 0; below it, it is extra.
        let exr = header(4096, 4096, Format::Exr, Layout::Float);
        assert_eq!(exr.decode_bytes(0), pyramid_bytes(&level_sizes(4096, 4096)));
        assert_eq!(
            exr.decode_bytes(1),
            (4096 * 4096 * 16) + pyramid_bytes(&level_sizes(2048, 2048))
        );
        // A cap below even 1×1 plus the row buffers.
        let wide = header(1 << 20, 1, png, Layout::Rows);
        assert!(plan("w.png", &wide, 1 << 20).is_err());
    }

    #[test]
    fn a_header_that_lies_is_an_error_not_an_allocation() {
        let dir = TempDir::new("decode-lies");
        // 65535² RGB claimed, two rows of data held.
        let raw = vec![0u8; 2 * (1 + 3 * 65535)];
        let p = dir.path("liar.png");
        std::fs::write(&p, png_file(65535, 65535, 8, 2, false, &raw)).unwrap();
        let h = probe(&p).unwrap();
        assert_eq!(h.layout, Layout::Rows);
        let plan = plan("liar.png", &h, 1 << 30).unwrap();
        assert_eq!(plan.size(&h), (4095, 4095));
        let e = decode(&p, &h, true, &plan).unwrap_err();
        assert!(e.contains("not have enough data"), "{e}");
        // Larger than any stream, or than a JPEG decoded whole: refused at create.
        std::fs::write(&p, png_file(65536, 65537, 8, 2, false, &[0])).unwrap();
        let e = probe(&p).unwrap_err().message;
        assert!(e.contains("too large: 65536x65537"), "{e}");
        let jpg = dir.path("liar.jpg");
        image::RgbImage::new(8, 8).save(&jpg).unwrap();
        let mut bytes = std::fs::read(&jpg).unwrap();
        let sof = bytes.windows(2).position(|m| m == [0xff, 0xc0]).unwrap();
        bytes[sof + 5..sof + 9].copy_from_slice(&[0xea, 0x60, 0xea, 0x60]); // 60000×60000
        std::fs::write(&jpg, &bytes).unwrap();
        let e = probe(&jpg).unwrap_err().message;
        assert!(e.contains("too large: 60000x60000 texels"), "{e}");
        bytes[sof + 5..sof + 9].copy_from_slice(&[0x3e, 0x80, 0x3e, 0x80]); // 16000×16000
        std::fs::write(&jpg, &bytes).unwrap();
        let h = probe(&jpg).unwrap();
        assert_eq!(h.layout, Layout::Whole { bytes: 768_000_000 });
        let e = super::plan("liar.jpg", &h, 1 << 20).unwrap_err().message;
        assert!(
            e.contains("(16000x16000 JPEG) needs 732.4 MiB to decode"),
            "{e}"
        );
    }
}
