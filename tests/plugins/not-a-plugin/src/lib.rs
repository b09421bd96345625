//! Test library: a valid shared object without the Luxon handshake symbol. The host must
//! report it as "not a Luxon plugin" rather than crash.

// SAFETY: a name no other symbol in the process uses.
#[unsafe(no_mangle)]
pub extern "C" fn not_luxon() -> i32 {
    42
}
