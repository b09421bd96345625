//! Test library: a valid shared object without the Luxon handshake symbol. The host must
//! report it as "not a Luxon plugin" rather than crash.

// Unmangled, which is unsafe only if the name clashes: no other symbol is called this.
#[unsafe(no_mangle)]
pub extern "C" fn not_luxon() -> i32 {
    42
}
