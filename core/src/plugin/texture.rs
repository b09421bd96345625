//! Texture plugins: creating an instance, and evaluating it while rendering.

use super::calls::{call_context, call_plugin};
use super::registry::{Entry, Registry};
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::path::Path;

/// A texture instance created by a plugin; destroyed through it on drop.
pub struct TextureInstance {
    object: *mut c_void,
    vtable: *const abi::TextureInstanceVTable,
    pub plugin: String,
    /// The scene's name for the texture, and where its parameters are.
    pub name: String,
    pub at: Origin,
}

// SAFETY: the SDK requires textures to be Send + Sync.
unsafe impl Send for TextureInstance {}
unsafe impl Sync for TextureInstance {}

impl TextureInstance {
    /// Linear RGBA, or the plugin's status when it panicked or failed (see [`Self::failure`]).
    #[inline]
    pub fn eval(&self, q: &abi::TexQuery) -> Result<[f32; 4], abi::Status> {
        let mut out = [0.0f32; 4];
        // SAFETY: valid table of a loaded plugin.
        let s = unsafe { ((*self.vtable).eval)(self.object, q, &mut out) };
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
        // SAFETY: created by this plugin, destroyed once.
        unsafe { ((*self.vtable).destroy)(self.object) };
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
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance);
    let mut out = abi::TextureObject {
        object: std::ptr::null_mut(),
        vtable: std::ptr::null(),
    };
    // SAFETY: the entry is a texture, so its vtable is a TextureVTable.
    let vt = unsafe { &*(entry.vtable as *const abi::TextureVTable) };
    call_plugin(registry, entry, params_at, |err| {
        (vt.create)(abi::Str::new(params), &ctx, &mut out, err)
    })?;
    if out.vtable.is_null() {
        return Err((
            params_at.clone(),
            format!("plugin `{}` returned no texture", entry.name),
        ));
    }
    Ok(TextureInstance {
        object: out.object,
        vtable: out.vtable,
        plugin: entry.name.clone(),
        name: instance.to_string(),
        at: params_at.clone(),
    })
}
