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
