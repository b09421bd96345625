//! Texture plugins: creating an instance, and evaluating it while rendering.

use super::calls::{call_context, call_plugin, wrong_kind};
use super::registry::{Entry, PluginKind, Registry, Table};
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::path::Path;

/// A texture instance created by a plugin; destroyed through it on drop.
pub struct TextureInstance {
    /// Live until `drop` passes it to `vtable.destroy`.
    object: *mut c_void,
    vtable: &'static abi::TextureInstanceVTable,
    pub plugin: String,
    /// The scene's name for the texture, and where its parameters are.
    pub name: String,
    pub at: Origin,
}

// SAFETY: the ABI requires a plugin's texture objects to take `eval` from several threads at
// once and `destroy` from any thread (the SDK makes that `Texture: Send + Sync`); the host owns
// the object and touches it only through its table.
unsafe impl Send for TextureInstance {}
// SAFETY: see `Send`: `&TextureInstance` only ever calls `eval`.
unsafe impl Sync for TextureInstance {}

impl TextureInstance {
    /// Linear RGBA, or the plugin's status when it panicked or failed (see [`Self::failure`]).
    #[inline]
    pub fn eval(&self, q: &abi::TexQuery) -> Result<[f32; 4], abi::Status> {
        let mut out = [0.0f32; 4];
        // SAFETY: `object` is live until `drop`, the query and result live across the call, and
        // the ABI allows concurrent `eval`s.
        let s = unsafe { (self.vtable.eval)(self.object, q, &mut out) };
        if s == abi::STATUS_OK {
            Ok(out)
        } else {
            Err(s)
        }
    }

    /// The error of an `eval` that returned `status`. A failing texture logged its cause
    /// before (plugin ABI 1 has no error sink for `eval`).
    pub fn failure(&self, status: abi::Status) -> String {
        if status == abi::STATUS_PANIC {
            format!("plugin `{}` panicked evaluating a texture", self.plugin)
        } else {
            format!(
                "{}: texture `{}` (plugin `{}`) failed during the render (its error is above)",
                self.at, self.name, self.plugin
            )
        }
    }
}

impl Drop for TextureInstance {
    fn drop(&mut self) {
        // SAFETY: `object` is live and this is its last use: the host owns it, and `drop` runs
        // once, when nothing can call `eval` any more.
        unsafe { (self.vtable.destroy)(self.object) };
    }
}

pub fn create_texture(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    instance: &str,
) -> Result<TextureInstance, (Origin, String)> {
    let Table::Texture(vt) = entry.table else {
        return Err(wrong_kind(registry, entry, PluginKind::Texture, params_at));
    };
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance);
    let mut out = abi::TextureObject {
        object: std::ptr::null_mut(),
        vtable: std::ptr::null(),
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
    })
}
