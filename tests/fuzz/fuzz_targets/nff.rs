//! The NFF importer on arbitrary bytes: through a file (plain or gzip, chosen by the magic
//! bytes as for any `.nff.gz`), and in memory when the bytes are UTF-8 text.
#![no_main]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("luxon-fuzz-nff-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let path = dir().join("input.nff.gz");
    std::fs::write(&path, data).unwrap();
    let _ = luxon_formats::nff::import(&path);
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = luxon_formats::nff::parse_str(text, Path::new("input.nff"));
    }
});
