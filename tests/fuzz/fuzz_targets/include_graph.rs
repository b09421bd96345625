//! The include resolver on graphs of up to 16 in-memory RON files (see
//! `../include_graph_body.rs`): cycles, diamonds, repeats and chains, without the disk.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../include_graph_body.rs"]
mod body;

fuzz_target!(|data: &[u8]| {
    // Ok or a SceneError: both fine; a panic (a file read twice), hang or runaway allocation
    // is the bug.
    let _ = body::run(data);
});
