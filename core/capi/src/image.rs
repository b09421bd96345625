//! Writing images through the writer plugins.

use crate::context::CONTEXTS;
use crate::guard::guard;
use crate::handles::luxon_context;
use crate::status::{luxon_status, Failure};
use crate::text::text;
use std::ffi::c_char;
use std::path::Path;

/// Writes `rgba` (linear RGBA floats, `width`×`height` pixels, rows top to bottom,
/// `row_floats` apart; 0: packed, `4 * width`) to `path` with the writer plugin its extension
/// names (`.png`, `.exr`, `.ppm`...). The file appears whole or not at all.
///
/// # Safety
/// `path` is a valid string; `rgba` is valid for reads of
/// `(height - 1) * row_floats + 4 * width` floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_write_image(
    context: luxon_context,
    path: *const c_char,
    rgba: *const f32,
    width: u32,
    height: u32,
    row_floats: usize,
) -> luxon_status {
    guard("luxon_write_image", || {
        // SAFETY: a valid string (caller).
        let path = unsafe { text(path, "path") }?;
        let ctx = CONTEXTS.get(context.id)?;
        if rgba.is_null() {
            return Err(Failure::invalid("`rgba` is NULL"));
        }
        if width == 0 || height == 0 {
            return Err(Failure::invalid(format!(
                "the image is {width}x{height} pixels; expected at least 1x1"
            )));
        }
        let row = 4 * width as usize;
        let stride = match row_floats {
            0 => row,
            n if n < row => {
                return Err(Failure::invalid(format!(
                    "row_floats {n} is less than a row of {width} RGBA pixels ({row} floats)"
                )))
            }
            n => n,
        };
        let mut packed = Vec::new();
        let bytes = row
            .checked_mul(height as usize)
            .and_then(|n| n.checked_mul(4));
        if bytes.is_none() || packed.try_reserve_exact(row * height as usize).is_err() {
            return Err(Failure::from(luxon_core::Error::OutOfMemory {
                what: format!("a copy of a {width}x{height} image"),
                bytes: bytes.map_or(u128::MAX, |b| b as u128),
            }));
        }
        for y in 0..height as usize {
            // SAFETY: row y lies within the caller's `(height - 1) * stride + row` floats.
            let line = unsafe { std::slice::from_raw_parts(rgba.add(y * stride), row) };
            packed.extend_from_slice(line);
        }
        luxon_core::api::write_image(&ctx.value, Path::new(path), &packed, width, height)?;
        Ok(())
    })
}
