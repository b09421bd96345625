//! Plugin failures give precise errors: missing, not a plugin, wrong ABI, wrong kind, bad
//! parameters, panics (at creation and while rendering).

mod common;

use common::*;
use luxon::Scene;
use std::path::Path;

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
    install_plugin(&dir, "testplug_bad_abi", "luxon_old");
    let e = build_error(&dir, r#"(plugin: "old_thing")"#);
    assert!(e.contains("no primitive plugin named `old_thing`"), "{e}");
    // A plugin built for the previous ABI, as every plugin built before the bump to 4 is.
    assert!(
        e.contains(
            "libluxon_old.so: built for plugin ABI 3 (luxon-plugin 0.3.0), but this Luxon uses \
             ABI 4 (luxon-plugin 0.4.0); rebuild it against luxon-plugin 0.4.0"
        ),
        "{e}"
    );
    assert_eq!(luxon_plugin::ABI_VERSION, 4);
}

#[test]
fn a_library_that_is_not_a_plugin_is_named() {
    let dir = temp_dir("notplugin");
    install_plugin(&dir, "testplug_not_a_plugin", "luxon_imposter");
    let e = build_error(&dir, r#"(plugin: "imposter")"#);
    assert!(
        e.contains("libluxon_imposter") && e.contains("not a Luxon plugin"),
        "{e}"
    );
}

#[test]
fn panic_in_create_becomes_an_error_naming_the_plugin() {
    let dir = temp_dir("panic-create");
    install_plugin(&dir, "testplug_panics", "luxon_panics");
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

/// A panic in custom geometry's `intersect` has no error sink to travel in: the SDK sends its
/// message through the host log, and the host puts it in the error with the object and its place.
#[test]
fn panic_while_intersecting_stops_the_render_with_an_error() {
    let dir = temp_dir("panic-intersect");
    install_plugin(&dir, "testplug_panics", "luxon_panics");
    let e = render_error(&dir, r#"(plugin: "panic_intersect")"#, "");
    let want = format!(
        "{}:6:15: object 0 (plugin `panic_intersect`) panicked while intersecting a ray: \
         deliberate panic in intersect",
        dir.join("scene.ron").display()
    );
    assert!(e.ends_with(&want), "{e}");
}

/// Builds a scene whose fourth line is `line`; returns the error message.
fn line4_error(dir: &Path, line: &str) -> String {
    let text = format!(
        "Scene(\n    plugin_path: [\"{}\"],\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    {line}\n)\n",
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

/// `file:4:col` of `needle` in a scene's fourth line `line` (see [`line4_error`]).
fn line4_at(dir: &Path, line: &str, needle: &str) -> String {
    let col = 5 + line.find(needle).unwrap();
    format!("{}:4:{col}", dir.join("scene.ron").display())
}

/// A value of the wrong type names its parameter, what the plugin's parameter table says it
/// takes and what the scene has, at the value.
#[test]
fn type_errors_in_params_name_the_parameter_what_was_expected_and_found() {
    let dir = temp_dir("param-types");
    install_plugin(&dir, "testplug_nan", "luxon_nan");
    let cases = [
        (
            r#"objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: "big"))],"#,
            "\"big\"",
            "plugin `sphere` (libluxon_shapes.so) failed: parameter `radius`: expected a number \
             > 0, found `\"big\"`",
        ),
        (
            r#"objects: [(plugin: "sphere", params: (center: (0, 0), radius: 1))],"#,
            "(0, 0)",
            "plugin `sphere` (libluxon_shapes.so) failed: parameter `center`: expected (x, y, z), \
             found 2 value(s) `(0, 0)`",
        ),
        (
            r#"textures: { "t": (plugin: "nan_texture", params: (color: "red")) },"#,
            "\"red\"",
            "plugin `nan_texture` (libluxon_nan.so) failed: parameter `color`: expected (r, g, b), \
             found `\"red\"`",
        ),
        (
            r#"textures: { "t": (plugin: "image", params: (file: "a.png", mapping: "planar")) },"#,
            "\"planar\"",
            "plugin `image` (libluxon_textures.so) failed: parameter `mapping`: expected one of \
             `uv`, `planar`, `cylindrical`, `spherical` (written without quotes), found \
             `\"planar\"`",
        ),
        // The plugin's own deserializer's words, with the parameter they are about.
        (
            r#"textures: { "t": (plugin: "checker", params: (scale: 2, even: "red")) },"#,
            "\"red\"",
            "plugin `checker` (libluxon_textures.so) failed: parameter `even`: unknown variant \
             `red` (expected one of: Constant, Checker, Blend, Gradient, Marble, Wood, Noise, \
             Image)",
        ),
    ];
    for (line, value, want) in cases {
        let e = line4_error(&dir, line);
        let at = line4_at(&dir, line, value);
        assert_eq!(e, format!("{at}: {want}"), "{line}");
    }
}

/// A plugin's own check on a value (`Error::invalid_at`, or any error whose message begins with
/// "parameter `name`") is reported at that parameter, not at the opening `(` of `params`.
#[test]
fn a_plugins_check_on_a_parameter_points_at_it() {
    let dir = temp_dir("param-check");
    let line = r#"objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: -1))],"#;
    let e = line4_error(&dir, line);
    assert_eq!(
        e,
        format!(
            "{}: plugin `sphere` (libluxon_shapes.so) failed: parameter `radius`: expected a \
             number > 0, found -1",
            line4_at(&dir, line, "radius")
        )
    );
    let line = r#"objects: [(plugin: "cone", params: (base: (0, 0, 0), base_radius: -2, apex: (0, 1, 0)))],"#;
    let e = line4_error(&dir, line);
    assert_eq!(
        e,
        format!(
            "{}: plugin `cone` (libluxon_shapes.so) failed: parameter `base_radius`: expected a \
             number >= 0, found -2",
            line4_at(&dir, line, "base_radius")
        )
    );
}

/// A writer that fails while writing the rendered image names the output, the plugin and its
/// message, at the output's place in the scene.
#[test]
fn a_writer_panic_names_the_output_and_carries_its_message() {
    let dir = temp_dir("panic-writer");
    install_plugin(&dir, "testplug_panics", "luxon_panics");
    let scene = dir.join("scene.ron");
    let text = format!(
        "Scene(\n    plugin_path: [\"{}\"],\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    render: (width: 4, height: 4, outputs: [(path: \"out.panicimg\")]),\n)\n",
        dir.display()
    );
    std::fs::write(&scene, &text).unwrap();
    let out = run(&["render", scene.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let col = 1 + text.lines().nth(3).unwrap().find("(path:").unwrap();
    let want = format!(
        "luxon: error: {}:4:{col}: output `{}`: plugin `panic_writer` (libluxon_panics.so) \
         panicked: deliberate panic writing a 4x4 image",
        scene.display(),
        dir.join("out.panicimg").display()
    );
    assert!(err.contains(&want), "{err}");
    assert!(!dir.join("out.panicimg").exists(), "{err}");
}

/// Places on the search path that give nothing say why: a directory that does not exist, a
/// library skipped for its name, a library that fails to load. `luxon plugins` lists them, and
/// so does the error of a lookup that misses.
#[test]
fn the_search_path_says_what_it_skipped_and_why() {
    let dir = temp_dir("search-notes");
    let misnamed = install_plugin(&dir, "testplug_panics", "zigzag");
    let broken = dir.join(format!(
        "{}luxon_broken{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    std::fs::write(&broken, "not a library").unwrap();
    std::fs::write(dir.join("notes.txt"), "not a library by its name either").unwrap();
    let missing = dir.join("no-such-dir");
    let path = std::env::join_paths([&dir, &missing]).unwrap();
    let name_note = format!(
        "skipped {}: not loaded: its name does not start with `libluxon_`; expected a file named \
         libluxon_NAME.so (rename it, or give the file itself in the plugin path)",
        misnamed.display()
    );
    let missing_note = format!(
        "skipped {}: no such file or directory; expected a directory of plugins or a plugin file",
        missing.display()
    );
    let r = luxon()
        .env("LUXON_PLUGIN_PATH", &path)
        .arg("plugins")
        .output()
        .unwrap();
    let listed = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(listed.contains(&name_note), "{listed}");
    assert!(listed.contains(&missing_note), "{listed}");
    assert!(
        listed.contains(&format!("skipped {}: ", broken.display())),
        "{listed}"
    );
    assert!(!listed.contains("notes.txt"), "{listed}");

    // The lookup that misses lists the same, after what was searched.
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        "Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), \
         textures: { \"s\": (plugin: \"zigzag\") }, render: (width: 4, height: 4))",
    )
    .unwrap();
    let out = dir.join("out.png");
    let r = luxon()
        .env("LUXON_PLUGIN_PATH", &path)
        .args([
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = stderr(&r);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("no texture plugin named `zigzag`"), "{err}");
    for note in [&name_note, &missing_note] {
        let reason = note.strip_prefix("skipped ").unwrap();
        assert!(err.contains(reason), "missing `{reason}` in {err}");
    }
    assert!(err.contains(&format!("{}: ", broken.display())), "{err}");
}

#[test]
fn panic_in_a_texture_stops_the_render_with_an_error() {
    let dir = temp_dir("panic-texture");
    install_plugin(&dir, "testplug_panics", "luxon_panics");
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
    install_plugin(&dir, "testplug_panics", "luxon_panics");
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
    let file = install_plugin(&dir, "testplug_panics", "whatever_name");
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
    install_plugin(&dir, "testplug_bad_abi", "luxon_old");
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
        "plugin ABI 4",
        "radius",
        "skipped",
        "built for plugin ABI 3 (luxon-plugin 0.3.0)",
    ] {
        assert!(s.contains(want), "missing `{want}` in:\n{s}");
    }
}

/// A library cut short (an interrupted copy) used to kill every run with SIGBUS inside `dlopen`,
/// even runs that never used it: now it is skipped with its reason, and the run goes on.
#[test]
fn a_truncated_library_on_the_search_path_is_skipped_by_name() {
    let dir = temp_dir("truncated");
    let lib = install_plugin(&dir, "luxon_shapes", "luxon_trunc");
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

/// The workspace's libraries carry name tables: finding them loads none, a lookup loads the
/// one library that provides the name, and `load_all` the rest.
#[test]
fn a_lookup_loads_only_the_library_that_provides_the_name() {
    use luxon::plugin::{PluginKind, Registry};
    let dir = temp_dir("lazy");
    install_plugin(&dir, "luxon_shapes", "luxon_myshapes");
    let r = Registry::discover(std::slice::from_ref(&dir));
    assert!(r.library_count() >= 4, "{}", r.library_count());
    assert!(r.loaded_libraries().is_empty());
    let sphere = r.get("sphere", PluginKind::Primitive).unwrap();
    let loaded = r.loaded_libraries();
    assert_eq!(loaded.len(), 1);
    // The first library on the search path provides it: the copy in `dir`.
    assert_eq!(
        loaded[0].0.path,
        dir.join("libluxon_myshapes.so").canonicalize().unwrap()
    );
    assert_eq!(r.library_of(sphere).name, "luxon-shapes");
    let png = r.writer_for_extension("PNG").unwrap().unwrap();
    assert_eq!(r.loaded_libraries().len(), 2);
    assert_eq!(r.library_of(png).name, "luxon-writers");
    // The names are known without loading: the other writers' extensions, a wrong kind.
    assert!(r.writer_extensions().contains(&"ppm".to_string()));
    assert!(r.get("png", PluginKind::Texture).is_err());
    assert_eq!(r.loaded_libraries().len(), 2);
    assert!(r.load_all().is_empty());
    assert_eq!(r.loaded_libraries().len(), r.library_count());
    // The copy's entries shadow the executable directory's shapes.
    let shadowed: Vec<_> = r
        .loaded_libraries()
        .into_iter()
        .filter(|(l, _)| l.name == "luxon-shapes")
        .map(|(_, e)| e.iter().all(|e| e.shadowed))
        .collect();
    assert!(shadowed.len() >= 2 && !shadowed[0], "{shadowed:?}");
    assert!(shadowed[1..].iter().all(|&s| s), "{shadowed:?}");
}

/// The bytes of a library's name table and where they are in its file.
fn name_table(lib: &Path) -> (Vec<u8>, usize) {
    let table = luxon::plugin::elf::check_library(lib)
        .unwrap()
        .names
        .expect("a name table");
    let file = std::fs::read(lib).unwrap();
    let at = file.windows(table.len()).position(|w| w == table).unwrap();
    (table, at)
}

/// A library whose table cannot be read is loaded at once to learn its names, as one built
/// before tables existed.
#[test]
fn a_library_with_a_damaged_name_table_is_loaded_at_once() {
    use luxon::plugin::{PluginKind, Registry};
    let dir = temp_dir("damaged-table");
    let lib = install_plugin(&dir, "luxon_shapes", "luxon_damaged");
    let (_, at) = name_table(&lib);
    let mut file = std::fs::read(&lib).unwrap();
    file[at] = b'X';
    std::fs::write(&lib, &file).unwrap();
    assert_eq!(
        luxon::plugin::elf::check_library(&lib)
            .unwrap()
            .names
            .unwrap()[0],
        b'X'
    );
    let r = Registry::discover(std::slice::from_ref(&dir));
    let loaded = r.loaded_libraries();
    assert_eq!(loaded.len(), 1);
    assert_eq!(loaded[0].0.path, lib.canonicalize().unwrap());
    let sphere = r.get("sphere", PluginKind::Primitive).unwrap();
    assert_eq!(r.library_of(sphere).path, lib.canonicalize().unwrap());
    assert!(r.problems.is_empty(), "{:?}", r.problems);
}

/// A table that lists a name the library does not declare (a file that does not match its
/// code): a lookup of that name is an error naming the name and the library.
#[test]
fn a_listed_name_the_library_does_not_declare_is_an_error_naming_both() {
    use luxon::plugin::{PluginKind, Registry};
    let dir = temp_dir("mismatched-table");
    let lib = install_plugin(&dir, "luxon_shapes", "luxon_mismatch");
    let (table, at) = name_table(&lib);
    let name = table.windows(6).position(|w| w == b"sphere").unwrap();
    let mut file = std::fs::read(&lib).unwrap();
    file[at + name + 5] = b'a';
    std::fs::write(&lib, &file).unwrap();
    let r = Registry::discover(std::slice::from_ref(&dir));
    assert!(r.loaded_libraries().is_empty());
    let e = r
        .get("sphera", PluginKind::Primitive)
        .unwrap_err()
        .to_string();
    let want = format!(
        "plugin `sphera` is provided by {}, which cannot be used: its name table lists \
         primitive `sphera`, but its declaration does not (it declares primitive `sphere`, \
         primitive `spheres`, ",
        lib.canonicalize().unwrap().display()
    );
    assert!(e.starts_with(&want), "{e}");
    assert!(
        e.ends_with("the library's file does not match its code"),
        "{e}"
    );
    // `luxon plugins` loads every library: it lists this one as skipped, with the reason.
    let failed = r.load_all();
    assert_eq!(failed.len(), 1, "{failed:?}");
    assert_eq!(failed[0].path, lib.canonicalize().unwrap());
    // The real sphere comes from the executable's directory.
    let sphere = r.get("sphere", PluginKind::Primitive).unwrap();
    assert_ne!(r.library_of(sphere).path, lib.canonicalize().unwrap());
}
