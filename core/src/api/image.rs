//! [`write_image`]: an image of the caller's written through the writer plugins.

use super::Context;
use crate::error::Error;
use crate::framebuffer::Framebuffer;
use crate::output::{resolve, write_all};
use luxon_formats::{Origin, OutputDesc};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Writes `rgba` (linear RGBA f32, rows top to bottom, `width`×`height` pixels) to `path`
/// with the writer plugin its extension names (`.png`, `.exr`, `.ppm`...). The file appears
/// whole or not at all: it is written beside its target and renamed over it.
pub fn write_image(
    ctx: &Context,
    path: &Path,
    rgba: &[f32],
    width: u32,
    height: u32,
) -> Result<(), Error> {
    let want = (width as usize)
        .checked_mul(height as usize)
        .and_then(|n| n.checked_mul(4));
    if width == 0 || height == 0 || want != Some(rgba.len()) {
        return Err(Error::Api(format!(
            "write_image: {} values for a {width}x{height} RGBA image; expected {}",
            rgba.len(),
            want.map_or("more than memory holds".into(), |n| n.to_string())
        )));
    }
    let output = OutputDesc {
        path: path.to_path_buf(),
        plugin: None,
        params: "()".into(),
        params_at: Origin {
            file: Arc::new(PathBuf::from("<write_image>")),
            line: 1,
            col: 1,
        },
    };
    let outputs = resolve(std::slice::from_ref(&output), &ctx.registry)?;
    let fb = Framebuffer {
        width,
        height,
        rgba: rgba.to_vec(),
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    ctx.install(|| write_all(&outputs, &fb, &ctx.registry, dir))?;
    Ok(())
}
