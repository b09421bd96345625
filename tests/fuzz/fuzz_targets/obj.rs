//! The OBJ importer (tobj and Luxon's mesh building) on arbitrary bytes. The file lives alone
//! in a private temporary directory: every `mtllib` it names is missing.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("luxon-fuzz-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let path = dir().join("input.obj");
    std::fs::write(&path, data).unwrap();
    let _ = luxon_formats::obj::load_obj(&path, None);
});
