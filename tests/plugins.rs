//! Plugin failures give precise errors: missing, not a plugin, wrong ABI, wrong kind, bad
//! parameters, panics (at creation and while rendering).

mod common;

use common::*;
use luxon::Scene;
use std::path::{Path, PathBuf};

/// Copies a test plugin into `dir` under a name the scanner picks up.
fn install(dir: &Path, lib: &str, as_name: &str) -> PathBuf {
    ensure_plugins();
    let exe = std::env::current_exe().unwrap();
    let profile_dir = exe.parent().unwrap().parent().unwrap();
    let file = |n: &str| {
        format!(
            "{}{n}{}",
            std::env::consts::DLL_PREFIX,
            std::env::consts::DLL_SUFFIX
        )
    };
    let dst = dir.join(file(as_name));
    std::fs::copy(profile_dir.join(file(lib)), &dst).unwrap();
    dst
}

/// Builds a scene with one object line; returns the error message.
fn build_error(dir: &Path, object: &str) -> String {
    let text = format!(
        "Scene(\n    plugin_path: [\"{}\"],\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    objects: [\n        {object},\n    ],\n)\n",
        dir.display()
    );
    let path = dir.join("scene.ron");
    std::fs::write(&path, text).unwrap();
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    match Scene::build(&desc, &registry(&desc)) {
        Ok(_) => panic!("scene built, but an error was expected"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn unknown_plugin_suggests_and_lists_the_search_path() {
    let dir = temp_dir("unknown");
    let e = build_error(
        &dir,
        r#"(plugin: "sphre", params: (center: (0, 0, 0), radius: 1))"#,
    );
    assert!(
        e.contains("scene.ron:5:18: no primitive plugin named `sphre`, did you mean `sphere`?"),
        "{e}"
    );
    assert!(
        e.contains("did you mean `sphere`? Searched:") && e.contains(&dir.display().to_string()),
        "{e}"
    );
}

#[test]
fn wrong_kind_names_both_kinds() {
    let dir = temp_dir("kind");
    let e = build_error(&dir, r#"(plugin: "checker")"#);
    assert!(
        e.contains("scene.ron:5:18: plugin `checker` is a texture"),
        "{e}"
    );
    assert!(e.contains("but a primitive is expected"), "{e}");
}

#[test]
fn bad_parameter_is_reported_at_its_scene_position() {
    let dir = temp_dir("params");
    let e = build_error(
        &dir,
        r#"(plugin: "sphere", params: (center: (0, 0, 0), radus: 1))"#,
    );
    assert!(e.contains("scene.ron:5:56:"), "{e}");
    assert!(
        e.contains("plugin `sphere`") && e.contains("did you mean `radius`"),
        "{e}"
    );
    let e = build_error(
        &dir,
        r#"(plugin: "sphere", params: (center: (0, 0, 0), radius: -1))"#,
    );
    assert!(e.contains("scene.ron:5:") && e.contains("radius"), "{e}");
}

#[test]
fn wrong_abi_version_names_both_versions() {
    let dir = temp_dir("abi");
    install(&dir, "testplug_bad_abi", "luxon_old");
    let e = build_error(&dir, r#"(plugin: "old_thing")"#);
    assert!(e.contains("no primitive plugin named `old_thing`"), "{e}");
    // A plugin built for the previous ABI, as every plugin built before the bump to 2 is.
    assert!(
        e.contains(
            "libluxon_old.so: built for plugin ABI 1 (luxon-plugin 0.1.0), but this Luxon uses \
             ABI 2 (luxon-plugin 0.2.0); rebuild it against luxon-plugin 0.2.0"
        ),
        "{e}"
    );
    assert_eq!(luxon_plugin::ABI_VERSION, 2);
}

#[test]
fn a_library_that_is_not_a_plugin_is_named() {
    let dir = temp_dir("notplugin");
    install(&dir, "testplug_not_a_plugin", "luxon_imposter");
    let e = build_error(&dir, r#"(plugin: "imposter")"#);
    assert!(
        e.contains("libluxon_imposter") && e.contains("not a Luxon plugin"),
        "{e}"
    );
}

#[test]
fn panic_in_create_becomes_an_error_naming_the_plugin() {
    let dir = temp_dir("panic-create");
    install(&dir, "testplug_panics", "luxon_panics");
    let e = build_error(&dir, r#"(plugin: "panic_create")"#);
    assert!(
        e.contains("scene.ron:5:") && e.contains("plugin `panic_create`"),
        "{e}"
    );
    assert!(
        e.contains("panicked") && e.contains("deliberate panic in create"),
        "{e}"
    );
}

fn render_error(dir: &Path, objects: &str, extra: &str) -> String {
    let text = format!(
        "Scene(\n    plugin_path: [\"{}\"],\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    lights: [Point(position: (0, 5, -5))],\n    {extra}\n    objects: [{objects}],\n    render: (width: 16, height: 16),\n)\n",
        dir.display()
    );
    let path = dir.join("scene.ron");
    std::fs::write(&path, text).unwrap();
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let scene = Scene::build(&desc, &registry(&desc)).unwrap_or_else(|e| panic!("{e}"));
    match luxon::render::render(&scene, &|_, _| {}) {
        Ok(_) => panic!("render succeeded, but an error was expected"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn panic_while_intersecting_stops_the_render_with_an_error() {
    let dir = temp_dir("panic-intersect");
    install(&dir, "testplug_panics", "luxon_panics");
    let e = render_error(&dir, r#"(plugin: "panic_intersect")"#, "");
    assert!(
        e.contains("plugin `panic_intersect` panicked while intersecting"),
        "{e}"
    );
}

#[test]
fn panic_in_a_texture_stops_the_render_with_an_error() {
    let dir = temp_dir("panic-texture");
    install(&dir, "testplug_panics", "luxon_panics");
    let e = render_error(
        &dir,
        r#"(plugin: "sphere", params: (center: (0, 0, 0), radius: 1), material: "m")"#,
        r#"textures: { "t": (plugin: "panic_texture") }, materials: { "m": (texture: "t") },"#,
    );
    // The panic's message travels with the failure (plugin ABI 2), with the texture's place.
    assert!(
        e.ends_with(
            "scene.ron:5:22: texture `t` (plugin `panic_texture`) panicked during the render: \
             deliberate panic in texture eval"
        ),
        "{e}"
    );
}

/// A texture whose `try_eval` fails stops the render with one error: the texture's place,
/// name and plugin, and the plugin's own message.
#[test]
fn a_failing_texture_stops_the_render_with_its_message() {
    let dir = temp_dir("fail-texture");
    install(&dir, "testplug_panics", "luxon_panics");
    let e = render_error(
        &dir,
        r#"(plugin: "sphere", params: (center: (0, 0, 0), radius: 1), material: "m")"#,
        r#"textures: { "t": (plugin: "fail_texture") }, materials: { "m": (texture: "t") },"#,
    );
    let want = format!(
        "{}:5:22: texture `t` (plugin `fail_texture`) failed during the render: deliberate \
         failure: no value where x < 0",
        dir.join("scene.ron").display()
    );
    assert_eq!(e, want);
}

#[test]
fn a_plugin_file_named_in_plugin_path_is_loaded_whatever_its_name() {
    let dir = temp_dir("explicit");
    let file = install(&dir, "testplug_panics", "whatever_name");
    let text = format!(
        "Scene(plugin_path: [\"{}\"], camera: (position: (0, 0, -5), look_at: (0, 0, 0)), objects: [(plugin: \"panic_create\")])",
        file.display()
    );
    let path = dir.join("scene.ron");
    std::fs::write(&path, text).unwrap();
    let desc = luxon_formats::load(&path).unwrap();
    let e = Scene::build(&desc, &registry(&desc))
        .err()
        .expect("expected the plugin's panic")
        .to_string();
    assert!(e.contains("deliberate panic in create"), "{e}");
}

#[test]
fn plugins_command_lists_every_plugin_and_its_parameters() {
    let dir = temp_dir("list");
    install(&dir, "testplug_bad_abi", "luxon_old");
    let out = run(&["plugins", "--plugin-path", dir.to_str().unwrap()]);
    assert!(out.status.success());
    let s = String::from_utf8_lossy(&out.stdout);
    for want in [
        "primitive `sphere`",
        "primitive `mesh`",
        "primitive `torus`",
        "texture `checker`",
        "writer `png` [.png]",
        "writer `exr` [.exr]",
        "plugin ABI 2",
        "radius",
        "skipped",
        "built for plugin ABI 1 (luxon-plugin 0.1.0)",
    ] {
        assert!(s.contains(want), "missing `{want}` in:\n{s}");
    }
}

/// A library cut short (an interrupted copy) used to kill every run with SIGBUS inside `dlopen`,
/// even runs that never used it: now it is skipped with its reason, and the run goes on.
#[test]
fn a_truncated_library_on_the_search_path_is_skipped_by_name() {
    let dir = temp_dir("truncated");
    let lib = install(&dir, "luxon_shapes", "luxon_trunc");
    let full = std::fs::read(&lib).unwrap();
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        "Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), lights: [Point(position: (0, 5, -5))], \
         objects: [(plugin: \"sphere\", params: (center: (0, 0, 0), radius: 1))], \
         render: (width: 8, height: 8))",
    )
    .unwrap();
    let out = dir.join("out.png");
    for cut in [10, 1_000, 10_000, full.len() / 2, full.len() - 1] {
        std::fs::write(&lib, &full[..cut]).unwrap();
        let r = luxon()
            .env("LUXON_PLUGIN_PATH", &dir)
            .args([
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        let err = stderr(&r);
        assert_eq!(r.status.code(), Some(0), "cut at {cut}: {err}");
        assert!(
            err.contains(&format!(
                "luxon: warning: skipped plugin file {}: is ",
                lib.display()
            )) && err.contains("truncated"),
            "cut at {cut}: {err}"
        );
        let r = luxon()
            .env("LUXON_PLUGIN_PATH", &dir)
            .arg("plugins")
            .output()
            .unwrap();
        let listed = String::from_utf8_lossy(&r.stdout);
        assert_eq!(r.status.code(), Some(0), "cut at {cut}: {}", stderr(&r));
        assert!(
            listed.contains(&format!(
                "skipped {}: is a truncated ELF file: ",
                lib.display()
            )),
            "cut at {cut}: {listed}"
        );
        assert!(listed.contains("primitive `sphere`"), "{listed}");
    }
}

/// A FIFO or a directory named like a plugin is refused by its type (opening a FIFO would block).
#[cfg(unix)]
#[test]
fn special_files_named_like_plugins_are_refused_by_type() {
    let dir = temp_dir("special");
    let name = |n: &str| {
        dir.join(format!(
            "{}{n}{}",
            std::env::consts::DLL_PREFIX,
            std::env::consts::DLL_SUFFIX
        ))
    };
    let fifo = name("luxon_fifo");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    std::fs::create_dir(name("luxon_dir")).unwrap();
    let mut child = luxon()
        .env("LUXON_PLUGIN_PATH", &dir)
        .arg("plugins")
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() > 20 {
            let _ = child.kill();
            panic!("`luxon plugins` hung on a FIFO");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let r = child.wait_with_output().unwrap();
    let listed = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{listed}");
    assert!(
        listed.contains(&format!(
            "skipped {}: is a FIFO (named pipe); expected a plugin library (a regular file)",
            fifo.display()
        )),
        "{listed}"
    );
    assert!(
        listed.contains("luxon_dir") && listed.contains("is a directory"),
        "{listed}"
    );
}
