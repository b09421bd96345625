//! `luxon plugins`: every plugin found and what it takes.

use luxon::plugin::{PluginKind, Registry};
use std::path::PathBuf;

pub fn run(extra: &[PathBuf]) {
    let registry = Registry::discover(extra);
    // Every library is loaded here, not only those a scene would use.
    let failed = registry.load_all();
    let loaded = registry.loaded_libraries();
    for (lib, entries) in &loaded {
        println!(
            "{} (library `{}`, plugin ABI {}, luxon-plugin {})",
            lib.path.display(),
            lib.name,
            lib.abi_version,
            lib.sdk_version
        );
        for e in entries.iter() {
            let ext = if e.kind == PluginKind::Writer {
                format!(" [.{}]", e.extensions.join(", ."))
            } else {
                String::new()
            };
            let shadow = if e.shadowed {
                " (shadowed by an earlier library)"
            } else {
                ""
            };
            println!("  {} `{}`{ext}{shadow}: {}", e.kind, e.name, e.description);
            for line in e.params_doc.lines() {
                println!("      {line}");
            }
        }
    }
    if loaded.is_empty() {
        println!("no plugins found");
    }
    // Files that could not be used, then places named on the search path that gave nothing.
    for p in registry
        .problems
        .iter()
        .chain(&failed)
        .chain(&registry.notes)
    {
        println!("skipped {p}");
    }
    let dirs: Vec<String> = registry
        .searched
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    println!("searched: {}", dirs.join(", "));
}
