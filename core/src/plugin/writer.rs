//! Writer plugins: encoding an image into bytes (the host side of `ByteSink`).

use super::calls::{call_context, call_plugin, slice};
use super::registry::{Entry, Registry};
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

extern "C" fn collect_bytes(ctx: *mut c_void, data: *const u8, len: usize) -> abi::Status {
    // SAFETY: ctx is the Vec owned by `encode_image` for the duration of the call.
    let v = unsafe { &mut *(ctx as *mut Vec<u8>) };
    match catch_unwind(AssertUnwindSafe(|| {
        v.extend_from_slice(unsafe { slice(data, len) })
    })) {
        Ok(()) => abi::STATUS_OK,
        Err(_) => abi::STATUS_ERROR,
    }
}

/// Encodes an image with a writer plugin into bytes.
#[allow(clippy::too_many_arguments)]
pub fn encode_image(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    width: u32,
    height: u32,
    rgba: &[f32],
) -> Result<Vec<u8>, (Origin, String)> {
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
    let ctx = call_context(&dir, "");
    // SAFETY: the entry is a writer, so its vtable is a WriterVTable.
    let vt = unsafe { &*(entry.vtable as *const abi::WriterVTable) };
    call_plugin(registry, entry, params_at, |err| {
        (vt.write)(abi::Str::new(params), &ctx, &image, &sink, err)
    })?;
    Ok(bytes)
}
