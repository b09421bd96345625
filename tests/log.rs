//! The library prints nothing: plugin messages go to the log sink its user installs (none by
//! default), and a whole load, build, render and write through the library leaves stdout and
//! stderr empty. The `luxon` command's own sink is checked in tests/cli.rs.

mod common;

use common::temp_dir;
use luxon::error::{set_log, Level};
use luxon::Scene;
use std::process::Command;
use std::sync::{Arc, Mutex};

/// A mesh with one zero-area triangle: the `mesh` plugin drops it and logs a warning.
const SCENE: &str = r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: 40),
    lights: [Point(position: (0, 5, -5), intensity: 1.0)],
    objects: [
        (plugin: "mesh", params: (positions: [(-1, -1, 0), (1, -1, 0), (0, 1, 0)], indices: [(0, 1, 2), (0, 1, 1)])),
        (plugin: "sphere", params: (center: (1, 1, 1), radius: 0.5)),
    ],
    render: (width: 16, height: 12, samples: 1, outputs: [(path: "out.png")]),
)"#;

const DROPPED: &str = "dropped 1 of 2 triangles with zero area";

/// Loads, builds, renders and writes [`SCENE`] through the library in `dir`.
fn render_scene(dir: &std::path::Path) {
    let path = dir.join("scene.ron");
    std::fs::write(&path, SCENE).unwrap();
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let registry = common::registry(&desc);
    let scene = Scene::build(&desc, &registry).unwrap_or_else(|e| panic!("{e}"));
    let (image, _) = luxon::render::render(&scene, &|_, _| {}).unwrap_or_else(|e| panic!("{e}"));
    let outputs = luxon::output::resolve(&scene.outputs, &registry).unwrap();
    luxon::output::write_all(&outputs, &image, &registry, dir).unwrap();
    assert!(dir.join("out.png").is_file());
}

#[test]
fn a_plugin_log_line_reaches_the_sink_at_its_level() {
    let lines = Arc::new(Mutex::new(Vec::<(Level, String)>::new()));
    let into = lines.clone();
    set_log(Some(Box::new(move |level, m| {
        into.lock().unwrap().push((level, m.to_string()))
    })));
    render_scene(&temp_dir("log-sink"));
    set_log(None);
    let lines = lines.lock().unwrap().clone();
    let dropped: Vec<_> = lines.iter().filter(|(_, m)| m.contains(DROPPED)).collect();
    assert_eq!(dropped.len(), 1, "{lines:?}");
    let (level, message) = dropped[0];
    assert_eq!(*level, Level::Warning, "{message}");
    assert!(message.starts_with("luxon-shapes: mesh "), "{message}");
}

/// Runs [`render_scene`] in a child process (this test again, told so by the environment) with
/// no sink installed: its stderr must be empty and its stdout only the test harness's lines.
#[test]
fn the_library_prints_nothing() {
    if std::env::var_os("LUXON_TEST_PRINTS_NOTHING").is_some() {
        render_scene(&temp_dir("prints-nothing-child"));
        return;
    }
    common::ensure_plugins();
    let out = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "the_library_prints_nothing", "--nocapture"])
        .args(["--test-threads", "1"])
        .env("LUXON_TEST_PRINTS_NOTHING", "1")
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("test the_library_prints_nothing ... ok"),
        "the child did not run the test:\n{stdout}"
    );
    assert_eq!(stderr, "", "the library printed to stderr");
    let printed: Vec<&str> = stdout
        .lines()
        .filter(|l| !(l.is_empty() || l.starts_with("running ") || l.starts_with("test ")))
        .collect();
    assert!(
        printed.is_empty(),
        "the library printed to stdout: {printed:?}"
    );
}
