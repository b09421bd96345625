//! Test helpers: temporary directories and image fixtures written on the fly.

use luxon_plugin::abi::TexQuery;
use luxon_plugin::{parse_params, Context, Error, Texture};
use std::path::{Path, PathBuf};

/// A fresh directory under the system temp dir, removed on drop.
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(name: &str) -> TempDir {
        let p = std::env::temp_dir().join(format!("luxon-textures-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        TempDir(p)
    }

    pub fn dir(&self) -> &Path {
        &self.0
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Writes an 8-bit RGBA PNG whose texel (x, y) (row 0 at the top) is `f(x, y)`.
pub fn write_png(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) {
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(f(x, y)));
    img.save_with_format(path, image::ImageFormat::Png).unwrap();
}

/// Writes a float RGBA OpenEXR file whose texel (x, y) is `f(x, y)`.
pub fn write_exr(path: &Path, w: usize, h: usize, f: impl Fn(usize, usize) -> [f32; 4] + Sync) {
    exr::prelude::write_rgba_file(path, w, h, |x, y| {
        let [r, g, b, a] = f(x, y);
        (r, g, b, a)
    })
    .unwrap();
}

/// A context whose relative paths resolve in `dir`.
pub fn ctx_in(dir: &Path) -> Context {
    Context {
        scene_dir: dir.to_path_buf(),
        instance: "test".into(),
        ..Default::default()
    }
}

/// Creates texture `T` from params text in `ctx`.
pub fn make_in<T: Texture>(params: &str, ctx: &Context) -> Result<T, Error> {
    T::create(parse_params(params)?, ctx)
}

/// Creates texture `T` from params text outside any scene.
pub fn make<T: Texture>(params: &str) -> Result<T, Error> {
    make_in(params, &ctx_in(Path::new(".")))
}

pub fn at<T: Texture>(t: &T, p: [f64; 3]) -> [f32; 4] {
    t.eval(&TexQuery {
        p,
        ..Default::default()
    })
}

pub fn at_uv<T: Texture>(t: &T, uv: [f32; 2], uv_footprint: f32) -> [f32; 4] {
    t.eval(&TexQuery {
        uv,
        uv_footprint,
        ..Default::default()
    })
}

pub fn close(a: [f32; 4], b: [f32; 4], eps: f32) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= eps)
}

/// CRC-32 of PNG chunks (reflected polynomial 0xEDB88320).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A zlib stream holding `data` in stored (uncompressed) blocks.
fn zlib_stored(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = data.chunks(65_535).collect();
    for (i, block) in blocks.iter().enumerate() {
        out.push((i + 1 == blocks.len()) as u8);
        let n = block.len() as u16;
        out.extend(n.to_le_bytes());
        out.extend((!n).to_le_bytes());
        out.extend(*block);
    }
    if blocks.is_empty() {
        out.extend([1, 0, 0, 0xff, 0xff]);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &x in data {
        a = (a + x as u32) % 65_521;
        b = (b + a) % 65_521;
    }
    out.extend(((b << 16) | a).to_be_bytes());
    out
}

/// A PNG file from its header fields and its raw (filtered) image data, written by hand so
/// that tests can make what encoders refuse to: interlaced files, and headers that lie.
pub fn png_file(w: u32, h: u32, depth: u8, colour: u8, interlaced: bool, raw: &[u8]) -> Vec<u8> {
    let chunk = |out: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
        out.extend((data.len() as u32).to_be_bytes());
        let start = out.len();
        out.extend(kind);
        out.extend(data);
        let crc = crc32(&out[start..]);
        out.extend(crc.to_be_bytes());
    };
    let mut ihdr = Vec::new();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([depth, colour, 0, 0, interlaced as u8]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &zlib_stored(raw));
    chunk(&mut out, b"IEND", &[]);
    out
}

/// An 8-bit RGBA Adam7-interlaced PNG whose texel (x, y) is `f(x, y)`.
pub fn interlaced_png(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
    const PASSES: [(u32, u32, u32, u32); 7] = [
        (0, 0, 8, 8),
        (4, 0, 8, 8),
        (0, 4, 4, 8),
        (2, 0, 4, 4),
        (0, 2, 2, 4),
        (1, 0, 2, 2),
        (0, 1, 1, 2),
    ];
    let mut raw = Vec::new();
    for (x0, y0, dx, dy) in PASSES {
        if x0 >= w {
            continue;
        }
        for y in (y0..h).step_by(dy as usize) {
            raw.push(0);
            for x in (x0..w).step_by(dx as usize) {
                raw.extend(f(x, y));
            }
        }
    }
    png_file(w, h, 8, 6, true, &raw)
}

/// Writes a PNG through the `png` crate's encoder: `samples` are the rows' bytes (16-bit
/// samples big-endian), `setup` sets anything beyond the colour type and depth.
pub fn write_png_with(
    path: &Path,
    w: u32,
    h: u32,
    colour: png::ColorType,
    depth: png::BitDepth,
    setup: impl FnOnce(&mut png::Encoder<std::io::BufWriter<std::fs::File>>),
    samples: &[u8],
) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut enc = png::Encoder::new(file, w, h);
    enc.set_color(colour);
    enc.set_depth(depth);
    setup(&mut enc);
    let mut writer = enc.write_header().unwrap();
    writer.write_image_data(samples).unwrap();
}
