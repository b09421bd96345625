//! The header compiles as C99 and as C++17 with every warning an error, and a C program linked
//! against libluxon (the shared library for C, the static one for C++) renders what the Rust
//! API renders, bit for bit: `tests/c/smoke.c` builds a scene through the calls and loads
//! `scenes/spheres.ron`, and writes its pixels for this test to compare.

mod common;

use common::{bits, ensure_built, profile_dir, render_f32, render_rgba8, root, rust_api, temp_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const W: u32 = 32;
const H: u32 = 24;

/// The compiler `var` names (`CC`, `CXX`) or `default`, if it runs.
fn compiler(var: &str, default: &str) -> Option<String> {
    let cc = std::env::var(var).unwrap_or_else(|_| default.to_string());
    let runs = Command::new(&cc).arg("--version").output();
    runs.is_ok_and(|o| o.status.success()).then_some(cc)
}

fn run(cmd: &mut Command) -> Output {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}):\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn floats(path: &Path) -> Vec<u32> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]).to_bits())
        .collect()
}

/// Runs the compiled smoke program; it must succeed and print nothing (the library prints
/// nothing of its own).
fn run_smoke(exe: &Path, out: &Path, plugin_path: Option<&Path>) {
    let scene = root().join("scenes/spheres.ron");
    let mut cmd = Command::new(exe);
    cmd.arg(&scene).arg(out).env_remove("LUXON_PLUGIN_PATH");
    if let Some(p) = plugin_path {
        cmd.env("LUXON_PLUGIN_PATH", p);
    }
    let o = run(&mut cmd);
    assert!(
        o.stdout.is_empty() && o.stderr.is_empty(),
        "{} printed:\n{}{}",
        exe.display(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// What the smoke program wrote equals the Rust API's renders of the same scenes.
fn check_pixels(out: &Path) {
    let (ctx, renderer) = rust_api();
    let mut code = common::smoke_scene(&ctx);
    let want = render_f32(&renderer, &mut code, W, H);
    assert_eq!(
        floats(&out.join("code.f32")),
        bits(&want),
        "RGBA f32 of the scene made in C"
    );
    let stride = W as usize + 8;
    let want8 = render_rgba8(&renderer, &mut code, W, H, stride, 0xAB);
    let got8 = std::fs::read(out.join("code.rgba8")).unwrap();
    assert_eq!(got8, want8.concat(), "RGBA8 of the scene made in C");

    let mut loaded = luxon_core::api::Scene::load(&ctx, &root().join("scenes/spheres.ron"))
        .unwrap_or_else(|e| panic!("{e}"));
    let want = render_f32(&renderer, &mut loaded, W, H);
    assert!(
        want.iter().any(|p| p[0] + p[1] + p[2] > 0.1),
        "a black image"
    );
    assert_eq!(
        floats(&out.join("loaded.f32")),
        bits(&want),
        "RGBA f32 of spheres.ron"
    );
}

/// A static library built with MPI needs the MPI library at link time: what OpenMPI's
/// `mpicc --showme:link` says (else `-lmpi`).
fn mpi_libs() -> Vec<String> {
    if !cfg!(feature = "mpi") {
        return Vec::new();
    }
    let shown = Command::new("mpicc").arg("--showme:link").output();
    match shown {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout)
            .split_whitespace()
            .map(str::to_string)
            .collect(),
        _ => vec!["-lmpi".to_string()],
    }
}

#[test]
fn c99_program_on_the_shared_library_renders_what_rust_renders() {
    let Some(cc) = compiler("CC", "cc") else {
        println!("note: no C compiler (cc or $CC) found; skipping the C99 test of luxon.h");
        return;
    };
    ensure_built();
    let lib = profile_dir();
    let dir = temp_dir("c99");
    let exe = dir.join("smoke");
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    run(Command::new(&cc)
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Wpedantic",
            "-Werror",
            "-I",
        ])
        .arg(here.join("include"))
        .arg(here.join("tests/c/smoke.c"))
        .arg("-o")
        .arg(&exe)
        .arg("-L")
        .arg(&lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(["-lluxon", "-lm"]));
    // No plugin path: the plugins are found beside libluxon.so.
    run_smoke(&exe, &dir, None);
    check_pixels(&dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cpp17_program_on_the_static_library_renders_what_rust_renders() {
    let Some(cxx) = compiler("CXX", "c++") else {
        println!("note: no C++ compiler (c++ or $CXX) found; skipping the C++17 test of luxon.h");
        return;
    };
    ensure_built();
    let lib = profile_dir();
    let dir = temp_dir("cpp17");
    let exe = dir.join("smoke");
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    run(Command::new(&cxx)
        .args([
            "-std=c++17",
            "-Wall",
            "-Wextra",
            "-Wpedantic",
            "-Werror",
            "-I",
        ])
        .arg(here.join("include"))
        .args(["-x", "c++"])
        .arg(here.join("tests/c/smoke.c"))
        .args(["-x", "none"])
        .arg(lib.join("libluxon.a"))
        .arg("-o")
        .arg(&exe)
        .args(mpi_libs())
        // What Rust's standard library needs from the system (`--print native-static-libs`).
        .args([
            "-lgcc_s",
            "-lutil",
            "-lrt",
            "-lpthread",
            "-lm",
            "-ldl",
            "-lc",
        ]));
    // Linked in, the library's directory is the program's: the plugins come by the path.
    run_smoke(&exe, &dir, Some(&lib));
    check_pixels(&dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_readme_example_compiles_and_runs() {
    let Some(cc) = compiler("CC", "cc") else {
        println!("note: no C compiler (cc or $CC) found; skipping the README's C example");
        return;
    };
    ensure_built();
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(here.join("README.md")).unwrap();
    let at = readme
        .find("<!-- compiled and run by tests/compile.rs -->")
        .unwrap();
    let start = readme[at..].find("```c\n").unwrap() + at + "```c\n".len();
    let end = readme[start..].find("```").unwrap() + start;
    let dir = temp_dir("readme");
    std::fs::write(dir.join("app.c"), &readme[start..end]).unwrap();
    let lib = profile_dir();
    let exe = dir.join("app");
    run(Command::new(&cc)
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Wpedantic",
            "-Werror",
            "-I",
        ])
        .arg(here.join("include"))
        .arg(dir.join("app.c"))
        .arg("-o")
        .arg(&exe)
        .arg("-L")
        .arg(&lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .arg("-lluxon"));
    let o = run(Command::new(&exe).env_remove("LUXON_PLUGIN_PATH"));
    assert!(
        o.stdout.is_empty() && o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
