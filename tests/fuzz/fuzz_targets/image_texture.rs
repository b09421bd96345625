//! Image texture files (PNG streamed or whole, JPEG, TGA, PNM, OpenEXR) decoded within a 64 MiB
//! cap (see `../image_texture_body.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../image_texture_body.rs"]
mod body;

fuzz_target!(|data: &[u8]| {
    // Ok or an error message: both fine; a panic (the cap or the plan broken), hang or runaway
    // allocation is the bug.
    let _ = body::run(data);
});
