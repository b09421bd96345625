//! Version queries.

use crate::guard::guard_value;
use std::ffi::c_char;

/// The version of this header's API: `luxon_api_version()` returns the version the library
/// was built with, so a program can check it loaded the library it was compiled for. Raised
/// whenever a function or struct changes or is added.
pub const LUXON_API_VERSION: u32 = 2;

/// `LUXON_API_VERSION` of the header the library was built with.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_api_version() -> u32 {
    guard_value("luxon_api_version", LUXON_API_VERSION, || LUXON_API_VERSION)
}

/// Luxon's version as text, e.g. "0.1.0" (static, never NULL).
#[unsafe(no_mangle)]
pub extern "C" fn luxon_version_string() -> *const c_char {
    const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "\0");
    guard_value("luxon_version_string", VERSION.as_ptr().cast(), || {
        VERSION.as_ptr().cast()
    })
}

/// Luxon's version as numbers; any pointer may be NULL.
///
/// # Safety
/// Each pointer is NULL or valid for a write of a `uint32_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_version(major: *mut u32, minor: *mut u32, patch: *mut u32) {
    let parse = |s: &str| s.parse().unwrap_or(0);
    let numbers = [
        parse(env!("CARGO_PKG_VERSION_MAJOR")),
        parse(env!("CARGO_PKG_VERSION_MINOR")),
        parse(env!("CARGO_PKG_VERSION_PATCH")),
    ];
    guard_value("luxon_version", (), || {
        for (p, v) in [major, minor, patch].into_iter().zip(numbers) {
            if !p.is_null() {
                // SAFETY: not NULL, and writable as the caller guarantees.
                unsafe { p.write(v) };
            }
        }
    })
}

/// The plugin ABI version this library loads plugins of (plugins of another are skipped).
#[unsafe(no_mangle)]
pub extern "C" fn luxon_plugin_abi_version() -> u32 {
    let v = luxon_plugin::ABI_VERSION;
    guard_value("luxon_plugin_abi_version", v, || v)
}

/// Whether the library was built with MPI (the `mpi` feature).
#[unsafe(no_mangle)]
pub extern "C" fn luxon_has_mpi() -> bool {
    let built = cfg!(feature = "mpi");
    guard_value("luxon_has_mpi", built, || built)
}
