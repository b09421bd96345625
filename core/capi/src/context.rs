//! Contexts (plugins and a thread pool) and the log callback.

use crate::guard::guard;
use crate::handles::{luxon_context, Kind, Table};
use crate::status::{luxon_status, Failure};
use crate::text::{optional_text, put, read_sized, Versioned};
use luxon_core::api::{Context, ContextOptions};
use luxon_core::error::{set_log, Level};
use std::ffi::{c_char, c_void, CString};
use std::path::PathBuf;

pub(crate) static CONTEXTS: Table<Context> = Table::new(Kind::Context);

/// How a context starts (`luxon_context_create`). Set `size` to `sizeof(luxon_context_options)`;
/// zero the fields you leave to their defaults.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct luxon_context_options {
    /// `sizeof(luxon_context_options)`.
    pub size: u32,
    /// Threads of the context's pool (its renderers share it unless given their own);
    /// 0: every CPU this process may run on.
    pub threads: u32,
    /// Directories (or plugin files) searched for plugins first, separated by ':' (';' on
    /// Windows); NULL: none. Then come `$LUXON_PLUGIN_PATH`, the directory of the Luxon
    /// library itself (where its plugins are installed) and the program's directory.
    pub plugin_path: *const c_char,
}

impl Default for luxon_context_options {
    fn default() -> Self {
        luxon_context_options {
            size: 0,
            threads: 0,
            plugin_path: std::ptr::null(),
        }
    }
}

impl Versioned for luxon_context_options {}

/// Starts a context: finds the plugins (once) and starts its thread pool, whose threads sleep
/// between renders. `options` may be NULL (every default). Plugin files that could not be
/// loaded are skipped silently (the log callback gets nothing about them either).
///
/// # Safety
/// `options` is NULL or a valid `luxon_context_options` (its `plugin_path` NULL or a valid
/// string); `out` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_context_create(
    options: *const luxon_context_options,
    out: *mut luxon_context,
) -> luxon_status {
    guard("luxon_context_create", || {
        // SAFETY: `out` is NULL or writable (caller); cleared first so a failure leaves {0}.
        unsafe { put(out, "out", luxon_context::default()) }?;
        cpu_supported()?;
        let o = match options.is_null() {
            true => luxon_context_options::default(),
            // SAFETY: a valid struct, as the caller guarantees.
            false => unsafe { read_sized(options, "options", 16) }?,
        };
        // SAFETY: NULL or a valid string (the caller's guarantee for the struct's fields).
        let path = unsafe { optional_text(o.plugin_path, "options->plugin_path") }?;
        let plugin_path: Vec<PathBuf> = path
            .map(|p| {
                std::env::split_paths(p)
                    .filter(|d| !d.as_os_str().is_empty())
                    .collect()
            })
            .unwrap_or_default();
        let options = ContextOptions {
            plugin_path,
            threads: o.threads as usize,
        };
        let ctx = Context::with_plugin_home(options, library_dir().as_deref())?;
        let id = CONTEXTS.insert(ctx)?;
        // SAFETY: as above.
        unsafe { put(out, "out", luxon_context { id }) }
    })
}

/// Releases a context. Scenes and renderers made from it keep what they need of it (its
/// plugins, its pool) until they are released too, so the order of releases is free.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_context_release(context: luxon_context) -> luxon_status {
    guard("luxon_context_release", || {
        CONTEXTS.release(context.id).map(drop)
    })
}

/// Threads of the context's pool, written to `out`.
///
/// # Safety
/// `out` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_context_threads(
    context: luxon_context,
    out: *mut u32,
) -> luxon_status {
    guard("luxon_context_threads", || {
        let ctx = CONTEXTS.get(context.id)?;
        let n = u32::try_from(ctx.value.threads()).unwrap_or(u32::MAX);
        // SAFETY: NULL or writable, as the caller guarantees.
        unsafe { put(out, "out", n) }
    })
}

/// A library built for x86-64-v3 (the workspace's default, `.cargo/config.toml`) says so on an
/// older CPU instead of dying on an illegal instruction in a render (as the `luxon` command).
fn cpu_supported() -> Result<(), Failure> {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    if !(std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("bmi2"))
    {
        return Err(Failure::new(
            crate::status::LUXON_ERROR_UNSUPPORTED,
            "this build of Luxon needs an x86-64-v3 CPU (AVX2, FMA, BMI2), which this one is \
             not; rebuild it for any x86-64 with RUSTFLAGS=\"-C target-cpu=x86-64\" cargo build \
             --release",
        ));
    }
    Ok(())
}

/// The directory of the file this code was loaded from (`libluxon.so`, or the program that
/// linked `libluxon.a`): plugins are installed beside the library.
#[cfg(not(unix))]
fn library_dir() -> Option<PathBuf> {
    None
}

/// The directory of the file this code was loaded from (`libluxon.so`, or the program that
/// linked `libluxon.a`): plugins are installed beside the library.
#[cfg(unix)]
fn library_dir() -> Option<PathBuf> {
    let mut info = std::mem::MaybeUninit::<libc::Dl_info>::zeroed();
    let here = library_dir as *const c_void;
    // SAFETY: `here` is an address in this library; `info` is writable. dladdr fills it and
    // returns non-zero when it found the object.
    let found = unsafe { libc::dladdr(here, info.as_mut_ptr()) };
    if found == 0 {
        return None;
    }
    // SAFETY: dladdr succeeded, so `info` is filled.
    let info = unsafe { info.assume_init() };
    if info.dli_fname.is_null() {
        return None;
    }
    // SAFETY: dladdr's file name is a NUL-terminated string owned by the loader, valid while
    // the object is loaded (it is: this code runs from it).
    let name = unsafe { std::ffi::CStr::from_ptr(info.dli_fname) };
    use std::os::unix::ffi::OsStrExt;
    let file = PathBuf::from(std::ffi::OsStr::from_bytes(name.to_bytes()));
    file.parent().map(|d| d.to_path_buf())
}

/// Receives the library's log lines: `level` 0 error, 1 warning, 2 info, 3 debug; `message`
/// is valid during the call only. Called from any thread, possibly several at once.
pub type luxon_log_fn =
    Option<unsafe extern "C" fn(level: i32, message: *const c_char, user: *mut c_void)>;

/// The caller's log callback and its pointer.
struct LogTarget {
    call: unsafe extern "C" fn(i32, *const c_char, *mut c_void),
    user: *mut c_void,
    max_level: i32,
}

impl LogTarget {
    fn send(&self, level: Level, message: &str) {
        let code = level as i32;
        if code > self.max_level {
            return;
        }
        let text = CString::new(message.replace('\0', "\\0")).unwrap_or_default();
        // SAFETY: the caller's callback, callable from any thread (luxon_set_log's contract);
        // `text` lives through the call.
        unsafe { (self.call)(code, text.as_ptr(), self.user) };
    }
}

// SAFETY: `luxon_set_log`'s contract: the callback may be called from any thread with `user`.
unsafe impl Send for LogTarget {}
// SAFETY: as above (calls may run at once).
unsafe impl Sync for LogTarget {}

/// Sends the library's log lines (plugin messages among them) of `level <= max_level` to `fn`
/// with `user`; `fn` NULL: none, which is the default (the library prints nothing). Process-
/// wide: plugins log without a context.
///
/// # Safety
/// `fn` must be callable from any thread, at once from several, with `user`, until it is
/// replaced; it must not unwind (throw) into Luxon.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_set_log(
    r#fn: luxon_log_fn,
    user: *mut c_void,
    max_level: i32,
) -> luxon_status {
    guard("luxon_set_log", || {
        let Some(call) = r#fn else {
            set_log(None);
            return Ok(());
        };
        if !(0..=3).contains(&max_level) {
            return Err(Failure::invalid(format!(
                "max_level {max_level}: expected 0 (errors) to 3 (debug)"
            )));
        }
        let target = LogTarget {
            call,
            user,
            max_level,
        };
        set_log(Some(Box::new(move |level: Level, message: &str| {
            target.send(level, message)
        })));
        Ok(())
    })
}
