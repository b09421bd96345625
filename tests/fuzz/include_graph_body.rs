//! The include resolver on a graph of in-memory RON files: the input, split at NUL bytes, is
//! `f0.ron`, `f1.ron`, ... (at most 16 files); `f0.ron` is loaded. Every file must be read at
//! most once, whatever the includes (cycles, diamonds, repeats, deep chains). Shared by the
//! `include_graph` fuzz target and the test that runs it over the seeds
//! (`formats/tests/fuzz_regressions.rs`).

use std::path::Path;

use luxon_formats::{load_ron_with, LoadOptions, MemorySource, SceneDesc, SceneError};

/// Loads the graph held in `data`; panics if a file was read twice.
pub fn run(data: &[u8]) -> Result<SceneDesc, SceneError> {
    let mut source = MemorySource::new();
    let files: Vec<&[u8]> = data.split(|&b| b == 0).take(16).collect();
    for (i, text) in files.iter().enumerate() {
        source.insert(format!("f{i}.ron"), text.to_vec());
    }
    // A small cap keeps the fuzzer's memory bounded.
    let options = LoadOptions {
        max_scene_bytes: 1 << 20,
        ..LoadOptions::default()
    };
    let result = load_ron_with(&mut source, Path::new("f0.ron"), &options);
    for i in 0..files.len() {
        let reads = source.reads(format!("f{i}.ron"));
        assert!(reads <= 1, "f{i}.ron was read {reads} times");
    }
    result
}
