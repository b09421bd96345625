//! Texture plugins: creating an instance, and evaluating it while rendering.

use super::calls::{call_context, call_plugin, wrong_kind};
use super::registry::{Entry, PluginKind, Registry, Table};
use crate::budget::Budget;
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// A texture instance created by a plugin; destroyed through it on drop.
pub struct TextureInstance {
    /// Live until `drop` passes it to `vtable.destroy`.
    object: *mut c_void,
    vtable: &'static abi::TextureInstanceVTable,
    pub plugin: String,
    /// The scene's name for the texture, and where its parameters are.
    pub name: String,
    pub at: Origin,
    /// Which fields of the query `eval` reads (`abi::READS_*`, the plugin's declaration).
    pub reads: u32,
    /// Evaluations that gave NaN or an infinity, for the warning after the render.
    pub nan_results: AtomicU64,
}

// SAFETY: the ABI requires a plugin's texture objects to take `eval` from several threads at
// once and `destroy` from any thread (the SDK makes that `Texture: Send + Sync`); the host owns
// the object and touches it only through its table.
unsafe impl Send for TextureInstance {}
// SAFETY: see `Send`: `&TextureInstance` only ever calls `eval`.
unsafe impl Sync for TextureInstance {}

/// Why a texture gave no value: its status ([`abi::STATUS_ERROR`] or [`abi::STATUS_PANIC`]) and
/// the message the plugin sent with it.
#[derive(Debug)]
pub struct EvalFailure {
    pub status: abi::Status,
    pub message: Option<String>,
}

/// The host's `ErrorSink::set` for `eval`.
///
/// # Safety
/// `ctx` is the `Option<String>` of the running [`TextureInstance::eval`]; `message` is
/// readable for the call.
unsafe extern "C" fn set_eval_error(ctx: *mut c_void, message: abi::Str, _line: u32, _col: u32) {
    // SAFETY: the plugin calls this only through the sink of a running `eval`, on its thread
    // (ABI contract), so `ctx` is that call's slot, which nothing else touches until `eval`
    // returns; the message is copied before returning.
    let (slot, message) = unsafe { (&mut *(ctx as *mut Option<String>), message.as_str()) };
    *slot = Some(message.unwrap_or("(invalid UTF-8)").to_string());
}

impl TextureInstance {
    /// Linear RGBA, or why the plugin could give none (see [`Self::failure`]).
    #[inline]
    pub fn eval(&self, q: &abi::TexQuery) -> Result<[f32; 4], EvalFailure> {
        let mut out = [0.0f32; 4];
        let mut message: Option<String> = None;
        let err = abi::ErrorSink {
            ctx: &mut message as *mut Option<String> as *mut c_void,
            set: set_eval_error,
        };
        // SAFETY: `object` is live until `drop`, the query, result and error sink (with its
        // slot, untouched until the call returns) live across the call, and the ABI allows
        // concurrent `eval`s.
        let status = unsafe { (self.vtable.eval)(self.object, q, &mut out, &err) };
        if status == abi::STATUS_OK {
            if !out.iter().all(|v| v.is_finite()) {
                self.nan_results.fetch_add(1, Ordering::Relaxed);
            }
            Ok(out)
        } else {
            Err(EvalFailure { status, message })
        }
    }

    /// The error of a failed `eval`, on one line: where the texture is in the scene, its name,
    /// its plugin and the plugin's message.
    pub fn failure(&self, f: &EvalFailure) -> String {
        let what = if f.status == abi::STATUS_PANIC {
            "panicked"
        } else {
            "failed"
        };
        let message = f.message.as_deref().unwrap_or("no message");
        let message = message.strip_prefix("panicked: ").unwrap_or(message);
        format!(
            "{}: texture `{}` (plugin `{}`) {what} during the render: {message}",
            self.at, self.name, self.plugin
        )
    }
}

impl TextureInstance {
    /// How many evaluations gave NaN or an infinity so far.
    pub fn nan_results(&self) -> u64 {
        self.nan_results.load(Ordering::Relaxed)
    }
}

impl Drop for TextureInstance {
    fn drop(&mut self) {
        // SAFETY: `object` is live and this is its last use: the host owns it, and `drop` runs
        // once, when nothing can call `eval` any more.
        unsafe { (self.vtable.destroy)(self.object) };
    }
}

/// Creates a texture instance; `budget` gives the plugin its memory budget and texture cache
/// share (the caller charges the cache).
pub fn create_texture(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    instance: &str,
    budget: &Budget,
) -> Result<TextureInstance, (Origin, String)> {
    let Table::Texture(vt) = entry.table else {
        return Err(wrong_kind(registry, entry, PluginKind::Texture, params_at));
    };
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance, Some(budget));
    let mut out = abi::TextureObject {
        object: std::ptr::null_mut(),
        vtable: std::ptr::null(),
        reads: abi::READS_ALL,
    };
    call_plugin(registry, entry, params_at, |err| {
        // SAFETY: the calling contract: `params`, `ctx`, `out` and `err` live across the call,
        // and `out` is only written by the plugin.
        unsafe { (vt.create)(abi::Str::new(params), &ctx, &mut out, err) }
    })?;
    // SAFETY: a non-null table of a texture object is a static of the library (ABI), which is
    // never unloaded.
    let Some(vtable) = (unsafe { out.vtable.as_ref() }) else {
        return Err((
            params_at.clone(),
            format!("plugin `{}` returned no texture", entry.name),
        ));
    };
    Ok(TextureInstance {
        object: out.object,
        vtable,
        plugin: entry.name.clone(),
        name: instance.to_string(),
        at: params_at.clone(),
        reads: out.reads,
        nan_results: AtomicU64::new(0),
    })
}
