//! Test plugin: a handshake with the right magic but an ABI version no host supports. The host
//! must stop after reading `abi_version` and never touch `declaration` (null here).

use luxon_plugin::abi::{DeclareFn, HostTable, PluginHeader, Str, MAGIC};

struct Header(PluginHeader);
// SAFETY: immutable static data; the only pointers are to static strings or null.
unsafe impl Sync for Header {}

static HEADER: Header = Header(PluginHeader {
    magic: MAGIC,
    abi_version: 9999,
    sdk_version: Str::new(luxon_plugin::SDK_VERSION),
    declaration: std::ptr::null(),
});

#[no_mangle]
pub extern "C" fn luxon_plugin_declare(_host: *const HostTable) -> *const PluginHeader {
    &HEADER.0
}

// The symbol must keep the signature the host looks it up with.
const _: DeclareFn = luxon_plugin_declare;
