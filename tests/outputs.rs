//! Outputs are all or nothing: checked before the render, written to temporary files, renamed
//! together; a failure or a signal leaves every existing file as it was, and temporary files of
//! dead processes are removed by the next run that writes there.
#![cfg(unix)]

mod common;

use common::*;
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

/// A scene whose render must fail: its sphere's texture panics when evaluated (the test plugin
/// `panic_texture`, copied into `dir`). An output error reported instead proves the outputs
/// were checked before rendering.
fn failing_scene(dir: &Path, outputs: &str) -> PathBuf {
    install_plugin(dir, "testplug_panics", "luxon_panics");
    let scene = dir.join("fails.ron");
    std::fs::write(
        &scene,
        format!(
            "Scene(\n    plugin_path: [\"{}\"],\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    \
             textures: {{ \"t\": (plugin: \"panic_texture\") }},\n    materials: {{ \"m\": (texture: \"t\") }},\n    \
             objects: [(plugin: \"sphere\", params: (center: (0, 0, 0), radius: 1), material: \"m\")],\n    \
             render: (width: 16, height: 16, outputs: [{outputs}]),\n)\n",
            dir.display()
        ),
    )
    .unwrap();
    scene
}

/// The names in `dir` that are temporary files.
fn temps(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".luxon-tmp") || n.ends_with(".tmp"))
        .collect()
}

#[cfg(target_os = "linux")]
#[test]
fn an_unwritable_output_fails_before_rendering_and_touches_no_other() {
    let dir = temp_dir("outputs-proc");
    let good = dir.join("good.png");
    std::fs::write(&good, b"precious").unwrap();
    let scene = failing_scene(&dir, "");
    let out = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        good.to_str().unwrap(),
        "-o",
        "/proc/x.png",
    ]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("cannot write output `/proc/x.png`") && !e.contains("panic"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1, "{e}");
    assert_eq!(std::fs::read(&good).unwrap(), b"precious");
    assert!(temps(&dir).is_empty(), "{:?}", temps(&dir));
}

#[test]
fn a_writer_s_bad_parameter_fails_before_rendering_at_its_position() {
    let dir = temp_dir("outputs-params");
    let first = dir.join("g2.png");
    std::fs::write(&first, b"precious").unwrap();
    let scene = failing_scene(
        &dir,
        r#"(path: "g2.png"), (path: "b.png", params: (bits: 7))"#,
    );
    let out = run(&["render", scene.to_str().unwrap()]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("fails.ron:7:") && e.contains("expected 8 or 16") && !e.contains("panic"),
        "{e}"
    );
    assert_eq!(std::fs::read(&first).unwrap(), b"precious");
    assert!(!dir.join("b.png").exists());
    assert!(temps(&dir).is_empty(), "{:?}", temps(&dir));
}

#[test]
fn a_failed_render_replaces_no_output() {
    let dir = temp_dir("outputs-failed-render");
    let scene = failing_scene(&dir, r#"(path: "a.png"), (path: "b.ppm")"#);
    std::fs::write(dir.join("a.png"), b"old a").unwrap();
    let out = run(&["render", scene.to_str().unwrap()]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("panicked"), "{e}");
    assert_eq!(std::fs::read(dir.join("a.png")).unwrap(), b"old a");
    assert!(!dir.join("b.ppm").exists());
    assert!(temps(&dir).is_empty(), "{:?}", temps(&dir));
}

#[test]
fn an_output_that_is_a_directory_or_given_twice_is_refused() {
    let dir = temp_dir("outputs-dir");
    std::fs::create_dir(dir.join("d.png")).unwrap();
    let scene = root().join("scenes").join("spheres.ron");
    let d = dir.join("d.png");
    let out = run(&[
        "render",
        scene.to_str().unwrap(),
        "--res",
        "4x4",
        "-o",
        d.to_str().unwrap(),
    ]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("it is a directory; expected a file path"), "{e}");
    let a = dir.join("a.png");
    let out = run(&[
        "render",
        scene.to_str().unwrap(),
        "--res",
        "4x4",
        "-o",
        a.to_str().unwrap(),
        "-o",
        a.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("is given twice"), "{}", stderr(&out));
    assert!(!a.exists());
}

#[test]
fn temporary_files_of_dead_processes_are_removed_and_live_ones_kept() {
    let dir = temp_dir("outputs-stale");
    let target = dir.join("out.ppm");
    // Nobody holds its lock: its process is dead.
    std::fs::write(dir.join(".out.ppm.999999.luxon-tmp"), b"stale").unwrap();
    // The name of older versions, with a pid above any pid_max.
    std::fs::write(dir.join(".out.ppm.4194304.tmp"), b"stale").unwrap();
    // A live writer (this test process) holds its lock.
    let live = luxon::files::TempFile::create(&dir.join("other.ppm")).unwrap();
    let scene = root().join("scenes").join("spheres.ron");
    let out = run(&[
        "render",
        scene.to_str().unwrap(),
        "--res",
        "8x6",
        "-o",
        target.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(target.is_file());
    let left = temps(&dir);
    let live_name = live
        .path()
        .file_name()
        .unwrap()
        .to_string_lossy()
        .to_string();
    assert_eq!(left, [live_name], "{left:?}");
}

/// Starts a render slow enough to be interrupted (1 thread, many samples) of `out.ppm` and
/// `out.png` in `dir`, and waits until its temporary files exist.
fn slow_render(dir: &Path) -> Child {
    let scene = root().join("scenes").join("spheres.ron");
    let child = luxon()
        .args([
            "render",
            scene.to_str().unwrap(),
            "--res",
            "1200x900",
            "--samples",
            "64",
            "--threads",
            "1",
            "-o",
        ])
        .arg(dir.join("out.ppm"))
        .arg("-o")
        .arg(dir.join("out.png"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while temps(dir).len() < 2 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no temporary files appeared"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    child
}

fn signal(child: &Child, sig: libc::c_int) {
    // SAFETY: sends a signal to our own child process.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, sig) }, 0);
}

#[test]
fn sigterm_removes_this_run_s_temporary_files_and_exits_143() {
    let dir = temp_dir("outputs-sigterm");
    std::fs::write(dir.join("out.ppm"), b"old").unwrap();
    let child = slow_render(&dir);
    signal(&child, libc::SIGTERM);
    let out = child.wait_with_output().unwrap();
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(143), "{e}");
    assert!(e.contains("luxon: error: interrupted by SIGTERM"), "{e}");
    assert!(temps(&dir).is_empty(), "{:?}", temps(&dir));
    assert_eq!(std::fs::read(dir.join("out.ppm")).unwrap(), b"old");
    assert!(!dir.join("out.png").exists());
}

#[test]
fn a_run_killed_with_sigkill_is_cleaned_up_by_the_next() {
    let dir = temp_dir("outputs-sigkill");
    let mut child = slow_render(&dir);
    signal(&child, libc::SIGKILL);
    child.wait().unwrap();
    assert_eq!(temps(&dir).len(), 2);
    let scene = root().join("scenes").join("spheres.ron");
    let target = dir.join("out.ppm");
    let out = run(&[
        "render",
        scene.to_str().unwrap(),
        "--res",
        "8x6",
        "-o",
        target.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(temps(&dir).is_empty(), "{:?}", temps(&dir));
}

/// A writer that fails on the real image (JPEG allows at most 65535 pixels a side), after an
/// earlier output was already complete: neither file is replaced.
#[test]
fn an_encoding_error_after_the_render_replaces_no_output() {
    let dir = temp_dir("outputs-encode");
    ensure_plugins();
    let registry = luxon::plugin::Registry::discover(&[]);
    std::fs::write(dir.join("a.png"), b"old a").unwrap();
    let descs: Vec<luxon_formats::OutputDesc> = ["a.png", "b.jpg"]
        .iter()
        .map(|n| luxon_formats::OutputDesc {
            path: dir.join(n),
            plugin: None,
            params: "()".into(),
            params_at: luxon_formats::Origin {
                file: std::sync::Arc::new(PathBuf::from("test")),
                line: 1,
                col: 1,
            },
        })
        .collect();
    let outputs = luxon::output::resolve(&descs, &registry).unwrap();
    let fb = luxon::Framebuffer::new(65536, 1);
    let e = luxon::output::write_all(&outputs, &fb, &registry, &dir)
        .expect_err("a JPEG 65536 pixels wide cannot be written");
    assert!(e.to_string().contains("jpeg"), "{e}");
    assert_eq!(std::fs::read(dir.join("a.png")).unwrap(), b"old a");
    assert!(!dir.join("b.jpg").exists());
    assert!(temps(&dir).is_empty(), "{:?}", temps(&dir));
}
