//! Writer plugins: encoding an image into bytes (the host side of `ByteSink`).

use super::calls::{call_context, call_plugin, slice, wrong_kind};
use super::registry::{Entry, PluginKind, Registry, Table};
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

/// The host's `ByteSink::write`: appends the bytes to the `Vec` of the running `encode_image`.
///
/// # Safety
/// `ctx` is that `Vec`, not otherwise borrowed during the call; `data` is null or `len` bytes.
unsafe extern "C" fn collect_bytes(ctx: *mut c_void, data: *const u8, len: usize) -> abi::Status {
    // SAFETY: the plugin calls this only through the sink of a running `encode_image`, on its
    // thread and one call at a time (ABI contract): `ctx` is that call's `Vec`, which nothing
    // else touches until the plugin returns, and `data` is `len` readable bytes.
    let (v, data) = unsafe { (&mut *(ctx as *mut Vec<u8>), slice(data, len)) };
    // An encoder's output the system cannot hold is an error, not an abort.
    let append = || {
        v.try_reserve(data.len()).is_ok() && {
            v.extend_from_slice(data);
            true
        }
    };
    match catch_unwind(AssertUnwindSafe(append)) {
        Ok(true) => abi::STATUS_OK,
        _ => abi::STATUS_ERROR,
    }
}

/// Encodes an image with a writer plugin into bytes. `instance` names the output for the
/// plugin and for messages ("output `out.png`"): an error is "{instance}: {the plugin's}".
#[allow(clippy::too_many_arguments)]
pub fn encode_image(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    instance: &str,
    width: u32,
    height: u32,
    rgba: &[f32],
) -> Result<Vec<u8>, (Origin, String)> {
    let Table::Writer(vt) = entry.table else {
        return Err(wrong_kind(registry, entry, PluginKind::Writer, params_at));
    };
    // The plugin reads `width * height * 4` values.
    if Some(rgba.len())
        != (width as usize)
            .checked_mul(height as usize)
            .and_then(|n| n.checked_mul(4))
    {
        return Err((
            params_at.clone(),
            format!(
                "{width}x{height} image given {} values instead of 4 per pixel",
                rgba.len()
            ),
        ));
    }
    let mut bytes: Vec<u8> = Vec::new();
    let sink = abi::ByteSink {
        ctx: &mut bytes as *mut Vec<u8> as *mut c_void,
        write: collect_bytes,
    };
    let image = abi::ImageView {
        width,
        height,
        rgba: rgba.as_ptr(),
    };
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance, None);
    call_plugin(registry, entry, params_at, |err| {
        // SAFETY: the calling contract: `params`, `ctx`, `image` (with its `width * height * 4`
        // values, checked above), `sink` and `err` live across the call; `sink.ctx` is `bytes`,
        // which we do not touch until the plugin returns.
        unsafe { (vt.write)(abi::Str::new(params), &ctx, &image, &sink, err) }
    })
    .map_err(|(at, m)| (at, format!("{instance}: {m}")))?;
    Ok(bytes)
}
