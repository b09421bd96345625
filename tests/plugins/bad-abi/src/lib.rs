//! Test plugin: the handshake of a plugin built for plugin ABI 3 with luxon-plugin 0.3.0 (the
//! version before the current one: its `TexQuery` had no `distance`), which the host must
//! refuse. The header's leading fields keep their layout in every ABI version, so this is what
//! such a library really declares; the host must stop after reading `abi_version` and never
//! touch `declaration` (null here).

use luxon_plugin::abi::{DeclareFn, HostTable, PluginHeader, Str, MAGIC};

/// The header as a static (spelled out by hand: this library does not use `export!`).
struct Header(PluginHeader);
// SAFETY: immutable static data without interior mutability; its only pointers are to a static
// string and null, so threads sharing it can only read the same values.
unsafe impl Sync for Header {}

static HEADER: Header = Header(PluginHeader {
    magic: MAGIC,
    abi_version: 3,
    sdk_version: Str::new("0.3.0"),
    declaration: std::ptr::null(),
});

// Unmangled, which is unsafe only if the name clashes: the library's one symbol of this name
// (no SDK `export!` here).
#[unsafe(no_mangle)]
pub extern "C" fn luxon_plugin_declare(_host: *const HostTable) -> *const PluginHeader {
    &HEADER.0
}

// The symbol must keep the signature the host looks it up with.
const _: DeclareFn = luxon_plugin_declare;
