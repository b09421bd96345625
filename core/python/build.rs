//! With the `bundle-plugins` feature (the wheel build, see pyproject.toml): builds Luxon's plugin
//! crates (in the extension's profile) and copies their libraries into `python/luxon/plugins/`, which maturin
//! packs into the wheel and the module searches. Without it (`cargo build --workspace`,
//! clippy, tests) this does nothing.
//!
//! The plugins are separate `cdylib`s that a cargo build of this crate does not make, and a
//! wheel must carry them to work after `pip install ./core/python` on a fresh clone. They are
//! built in a target directory of their own: the outer build holds the lock of the workspace's.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The plugin crates a scene file can name without a plugin path (the `cargo build` defaults
/// less the examples and the test fixtures).
const PLUGINS: [(&str, &str); 5] = [
    ("luxon-shapes", "luxon_shapes"),
    ("luxon-textures", "luxon_textures"),
    ("luxon-writers", "luxon_writers"),
    ("luxon-volume-raw", "luxon_volume_raw"),
    ("luxon-volume-vdb", "luxon_volume_vdb"),
];

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_BUNDLE_PLUGINS").is_none() {
        return;
    }
    let here = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let root = here.join("../..");
    for dir in ["plugins", "formats", "Cargo.lock"] {
        println!("cargo:rerun-if-changed={}", root.join(dir).display());
    }
    let target = std::env::var("TARGET").expect("set by cargo");
    let target_dir = root.join("target/python-plugins");
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    // The plugins are built as the extension is: release for a wheel, dev when maturin is
    // asked for `--profile dev` (as .ci/run does).
    let profile = std::env::var("PROFILE").expect("set by cargo");
    let mut cmd = Command::new(cargo);
    cmd.current_dir(&root)
        .args(["build", "--target", &target, "--target-dir"])
        .arg(&target_dir);
    if profile == "release" {
        cmd.arg("--release");
    }
    for (package, _) in PLUGINS {
        cmd.args(["-p", package]);
    }
    // The outer build's settings for this crate are not the plugins' (their flags come from
    // the workspace's .cargo/config.toml, as in `cargo build`).
    for var in [
        "CARGO_TARGET_DIR",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_BUILD_TARGET",
    ] {
        cmd.env_remove(var);
    }
    let status = cmd.status().expect("cargo runs");
    assert!(status.success(), "building the plugins failed: {status}");

    let built = target_dir.join(&target).join(&profile);
    let into = here.join("python/luxon/plugins");
    std::fs::create_dir_all(&into).expect("the package's plugins directory can be made");
    for (_, lib) in PLUGINS {
        let name = format!(
            "{}{lib}{}",
            std::env::consts::DLL_PREFIX,
            std::env::consts::DLL_SUFFIX
        );
        copy(&built.join(&name), &into.join(&name));
    }
}

fn copy(from: &Path, to: &Path) {
    if let Err(e) = std::fs::copy(from, to) {
        panic!("copying {} to {}: {e}", from.display(), to.display());
    }
}
