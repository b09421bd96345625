//! The NFF importer on arbitrary bytes: streamed (gzip-decompressed first when the bytes start
//! with gzip's magic, as `nff::import` does for any file) in blocks of 4 KiB, so inputs span
//! several blocks and the block cutting is fuzzed too; and in memory when the bytes are UTF-8.
#![no_main]

use std::io::Read;
use std::path::Path;

use libfuzzer_sys::fuzz_target;
use luxon_formats::nff;

fn stream(reader: impl Read + Send) {
    // Ok or a SceneError: both fine; a panic, hang or runaway allocation is the bug.
    let _ = nff::import_reader_blocks(reader, Path::new("input.nff"), 4096);
}

fuzz_target!(|data: &[u8]| {
    if data.starts_with(&[0x1f, 0x8b]) {
        stream(flate2::read::MultiGzDecoder::new(data));
    } else {
        stream(data);
        if let Ok(text) = std::str::from_utf8(data) {
            let _ = nff::parse_str(text, Path::new("input.nff"));
        }
    }
});
