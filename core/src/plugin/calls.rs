//! Calling into plugins: one call with an error sink, its errors mapped back to the scene file,
//! and the helpers every kind's sink callbacks share.

use super::registry::{Entry, PluginKind, Registry};
use crate::budget::Budget;
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;

/// An error reported by a plugin, with its position inside the params text.
struct Reported {
    message: Option<String>,
    line: u32,
    col: u32,
}

/// The host's `ErrorSink::set`.
///
/// # Safety
/// `ctx` is the `Reported` of the running [`call_plugin`]; `message` is readable for the call.
unsafe extern "C" fn set_error(ctx: *mut c_void, message: abi::Str, line: u32, col: u32) {
    // SAFETY: the plugin calls this only through the sink of a running `call_plugin`, on its
    // thread (ABI contract), so `ctx` is that call's `Reported` and nothing else touches it
    // until the plugin returns; the message is copied before returning.
    let (r, message) = unsafe { (&mut *(ctx as *mut Reported), message.as_str()) };
    r.message = Some(message.unwrap_or("(invalid UTF-8)").to_string());
    r.line = line;
    r.col = col;
}

/// Maps a position inside params text that starts at `start` to the scene file.
pub fn offset_origin(start: &Origin, line: u32, col: u32) -> Origin {
    if line == 0 {
        return start.clone();
    }
    Origin {
        file: start.file.clone(),
        line: start.line + line - 1,
        col: if line == 1 {
            start.col + col.max(1) - 1
        } else {
            col
        },
    }
}

/// Runs one plugin call with an error sink; returns the message and its scene position on error.
pub fn call_plugin(
    registry: &Registry,
    entry: &Entry,
    params_at: &Origin,
    f: impl FnOnce(&abi::ErrorSink) -> abi::Status,
) -> Result<(), (Origin, String)> {
    let mut reported = Reported {
        message: None,
        line: 0,
        col: 0,
    };
    let sink = abi::ErrorSink {
        ctx: &mut reported as *mut Reported as *mut c_void,
        set: set_error,
    };
    let status = f(&sink);
    if status == abi::STATUS_OK {
        return Ok(());
    }
    let lib = registry.library_of(entry);
    let file = lib
        .path
        .file_name()
        .map(|f| f.to_string_lossy().to_string())
        .unwrap_or_default();
    let what = if status == abi::STATUS_PANIC {
        "panicked"
    } else {
        "failed"
    };
    let detail = reported.message.unwrap_or_else(|| "no message".into());
    let detail = detail
        .strip_prefix("panicked: ")
        .unwrap_or(&detail)
        .to_string();
    Err((
        offset_origin(params_at, reported.line, reported.col),
        format!("plugin `{}` ({file}) {what}: {detail}", entry.name),
    ))
}

/// The bytes a plugin call may allocate for what it produces or keeps
/// ([`abi::CallContext::memory_budget`]): what is left of `budget` at the call, at least 1;
/// 0 (unknown) without a budget or a limit.
pub fn memory_budget_for_plugins(budget: Option<&Budget>) -> u64 {
    match budget.and_then(Budget::limit) {
        Some(_) => budget.map_or(0, |b| b.remaining().max(1)),
        None => 0,
    }
}

/// The context of a plugin call: where the scene is, which instance, and the memory it may use
/// (`budget`: the run's; `None` for calls outside a scene's build, such as writers, which get
/// 0, "unknown").
pub fn call_context<'a>(
    scene_dir: &'a str,
    instance: &'a str,
    budget: Option<&Budget>,
) -> abi::CallContext {
    abi::CallContext {
        scene_dir: abi::Str::new(scene_dir),
        instance: abi::Str::new(instance),
        // 0 lets the plugin choose (1 GiB).
        texture_cache_bytes: budget.map_or(0, Budget::texture_cache),
        threads: pool_threads() as u32,
        memory_budget: memory_budget_for_plugins(budget),
    }
}

/// `rayon::current_num_threads()` without starting rayon's global pool when called outside
/// every pool (as scene builds are): the size that pool would have (`RAYON_NUM_THREADS`, else
/// every CPU). Started just to be counted, its idle workers spun beside small renders.
fn pool_threads() -> usize {
    if rayon::current_thread_index().is_some() {
        return rayon::current_num_threads();
    }
    std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Reports `msg` through the plugin's error sink (if it gave one); the status to return.
pub(super) fn fail(err: Option<&abi::ErrorSink>, msg: &str) -> abi::Status {
    if let Some(e) = err {
        // SAFETY: `e` is the error sink the plugin passed to the running sink call, valid for
        // it, and `ctx` its own (ABI contract); `msg` is borrowed across the call.
        unsafe { (e.set)(e.ctx, abi::Str::new(msg), 0, 0) };
    }
    abi::STATUS_ERROR
}

/// A borrowed array from a plugin: `len` elements at `ptr` (none when null or empty).
///
/// # Safety
/// Unless `ptr` is null or `len` is 0, `ptr` points to `len` initialised values of one
/// allocation that stay valid and unmodified for `'a`.
pub(super) unsafe fn slice<'a, T>(ptr: *const T, len: usize) -> &'a [T] {
    if len == 0 || ptr.is_null() {
        &[]
    } else {
        // SAFETY: the caller's promise, for non-null `ptr` and non-zero `len`.
        unsafe { std::slice::from_raw_parts(ptr, len) }
    }
}

/// The error `call` gives for an entry of another kind than the call needs.
pub(super) fn wrong_kind(
    registry: &Registry,
    entry: &Entry,
    expected: PluginKind,
    params_at: &Origin,
) -> (Origin, String) {
    (
        params_at.clone(),
        format!(
            "{} is a {}, but a {expected} is expected here",
            plugin_label(registry, entry),
            entry.kind
        ),
    )
}

/// `count` records of `per` values each, as a length that fits memory.
pub(super) fn checked_len(count: u64, per: u64, what: &str) -> Result<usize, String> {
    count
        .checked_mul(per)
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| format!("{what} count {count} is too large"))
}

/// "plugin `name` (library file)", as messages name a plugin.
pub fn plugin_label(registry: &Registry, entry: &Entry) -> String {
    let file = registry
        .library_of(entry)
        .path
        .file_name()
        .map(|f| f.to_string_lossy().to_string())
        .unwrap_or_default();
    format!("plugin `{}` ({file})", entry.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plugins are told what is left of the budget and the texture cache's share; without a
    /// budget or a limit, 0 ("unknown", "choose").
    #[test]
    fn call_contexts_carry_the_budget() {
        let b = Budget::new(1 << 30, "test".into(), None);
        b.reserve(crate::budget::Use::Geometry, 1 << 20, String::new)
            .unwrap();
        let ctx = call_context(".", "t", Some(&b));
        assert_eq!(ctx.memory_budget, (1 << 30) - (1 << 20));
        assert_eq!(ctx.texture_cache_bytes, 256 << 20);
        let ctx = call_context(".", "t", Some(&Budget::unlimited()));
        assert_eq!((ctx.memory_budget, ctx.texture_cache_bytes), (0, 1 << 30));
        let ctx = call_context(".", "t", None);
        assert_eq!((ctx.memory_budget, ctx.texture_cache_bytes), (0, 0));
        let full = Budget::new(10, "test".into(), None);
        full.reserve(crate::budget::Use::Image, 10, String::new)
            .unwrap();
        assert_eq!(memory_budget_for_plugins(Some(&full)), 1);
    }
}
