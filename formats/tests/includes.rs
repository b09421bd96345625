//! `include`: merge order, nesting, relative paths, cycles, missing files, error positions.

mod common;
use common::TempDir;

use std::path::Path;

use luxon_formats::*;

/// A fresh directory under the system temp dir, removed when dropped.
fn intensities(scene: &SceneDesc) -> Vec<f64> {
    scene
        .lights
        .iter()
        .map(|l| match l.value {
            LightDesc::Point { intensity, .. }
            | LightDesc::Directional { intensity, .. }
            | LightDesc::Spot { intensity, .. }
            | LightDesc::Sphere { intensity, .. }
            | LightDesc::Rect { intensity, .. } => intensity,
        })
        .collect()
}

#[test]
fn includes_merge_in_order() {
    let dir = TempDir::new("merge");
    dir.write(
        "a.ron",
        r#"Scene(
    plugin_path: ["plugins-a"],
    camera: (position: (0, 0, -1), look_at: (0, 0, 0)),
    background: (1, 0, 0),
    lights: [Point(position: (0, 0, 0), intensity: 1)],
    materials: { "m": (ior: 1.1), "n": (ior: 1.2) },
    textures: { "t": (plugin: "from-a") },
    objects: [(plugin: "a")],
    render: (width: 10, outputs: [(path: "a.png")]),
)"#,
    );
    dir.write(
        "b.ron",
        r#"(
    include: ["sub/c.ron"],
    lights: [Point(position: (0, 0, 0), intensity: 2)],
    materials: { "m": (ior: 1.3) },
    render: (width: 20, outputs: [(path: "b.png")]),
)"#,
    );
    dir.write(
        "sub/c.ron",
        r#"(
    plugin_path: ["plugins-c"],
    lights: [Point(position: (0, 0, 0), intensity: 3)],
    materials: { "c": () },
    objects: [(plugin: "c")],
    render: (outputs: [(path: "c.png")]),
)"#,
    );
    let main = dir.write(
        "main.ron",
        r#"Scene(
    include: ["a.ron", "b.ron"],
    plugin_path: ["plugins-main"],
    lights: [Point(position: (0, 0, 0), intensity: 4)],
    materials: { "n": (ior: 1.4), "z": () },
    textures: { "t": (plugin: "from-main") },
    objects: [(plugin: "main", material: "c")],
)"#,
    );
    let scene = load(&main).unwrap();
    let d: &Path = &dir;

    // Lists: included files first (depth first, in include order), then this file.
    assert_eq!(intensities(&scene), [1.0, 3.0, 2.0, 4.0]);
    let plugins: Vec<&str> = scene
        .objects
        .iter()
        .map(|o| o.value.call.plugin.value.as_str())
        .collect();
    assert_eq!(plugins, ["a", "c", "main"]);
    assert_eq!(
        scene.plugin_path,
        [
            d.join("plugins-a"),
            d.join("sub").join("plugins-c"),
            d.join("plugins-main")
        ]
    );
    let outputs: Vec<&Path> = scene
        .render
        .outputs
        .iter()
        .map(|o| o.path.as_path())
        .collect();
    // Outputs: the last file in merge order that names any (b.png replaces c.png and a.png).
    assert_eq!(outputs, [d.join("b.png")]);

    // Maps: later definitions win, in the place of the first definition.
    let materials: Vec<(&str, f64)> = scene
        .materials
        .iter()
        .map(|(n, m)| (n.as_str(), m.value.ior))
        .collect();
    assert_eq!(materials, [("m", 1.3), ("n", 1.4), ("c", 1.0), ("z", 1.0)]);
    assert_eq!(*scene.materials[0].1.at.file, d.join("b.ron"));
    assert_eq!(scene.textures.len(), 1);
    assert_eq!(scene.textures[0].1.value.plugin.value, "from-main");

    // Singles: from the including file when it gives them, else from the last include that does.
    assert_eq!(*scene.camera.at.file, d.join("a.ron"));
    assert_eq!(scene.background, BackgroundDesc::Color([1.0, 0.0, 0.0]));
    assert_eq!(scene.render.width, 20);
    assert_eq!(scene.source, main);
}

#[test]
fn positions_in_included_content_name_that_file() {
    let dir = TempDir::new("positions");
    dir.write(
        "common.ron",
        "(\n    objects: [\n        (plugin: \"sphere\", params: (radius: 2)),\n    ],\n)",
    );
    let main = dir.write(
        "main.ron",
        "(\n    include: [\"common.ron\"],\n    camera: (position: (0, 0, -1), look_at: (0, 0, 0)),\n)",
    );
    let scene = load(&main).unwrap();
    let sphere = &scene.objects[0];
    assert_eq!(*sphere.at.file, dir.join("common.ron"));
    assert_eq!((sphere.at.line, sphere.at.col), (3, 9));
    assert_eq!(sphere.value.call.params, "(radius: 2)");
    assert_eq!(
        (
            sphere.value.call.params_at.line,
            sphere.value.call.params_at.col
        ),
        (3, 36)
    );
    assert_eq!(*scene.camera.at.file, main);

    // An error inside an included file names it.
    dir.write(
        "common.ron",
        "(\n    objects: [\n        (plugin: \"sphere\", params: (radius: NaN)),\n    ],\n)",
    );
    let error = load(&main).unwrap_err();
    let at = error.origin().unwrap();
    assert_eq!(*at.file, dir.join("common.ron"));
    assert_eq!((at.line, at.col), (3, 45));
    let prefix = format!(
        "{}:3:45: NaN is not allowed",
        dir.join("common.ron").display()
    );
    assert!(error.to_string().starts_with(&prefix), "{error}");

    // ron's own errors too.
    dir.write(
        "common.ron",
        "(\n    lights: [Pont(position: (0, 0, 0))],\n)",
    );
    let error = load(&main).unwrap_err();
    let at = error.origin().unwrap();
    assert_eq!(
        (&**at.file, at.line, at.col),
        (dir.join("common.ron").as_path(), 2, 14)
    );
    assert!(
        error.to_string().contains("did you mean `Point`?"),
        "{error}"
    );
}

#[test]
fn names_defined_in_the_including_file_resolve_in_included_content() {
    let dir = TempDir::new("names");
    dir.write(
        "objects.ron",
        "(objects: [(plugin: \"sphere\", material: \"gold\")])",
    );
    let main = dir.write(
        "main.ron",
        "(include: [\"objects.ron\"], camera: (position: (0, 0, -1), look_at: (0, 0, 0)), \
         materials: {\"gold\": ()})",
    );
    assert_eq!(load(&main).unwrap().objects.len(), 1);

    dir.write(
        "objects.ron",
        "(objects: [(plugin: \"sphere\", material: \"gould\")])",
    );
    let error = load(&main).unwrap_err();
    let at = error.origin().unwrap();
    assert_eq!(
        (&**at.file, at.line, at.col),
        (dir.join("objects.ron").as_path(), 1, 41)
    );
    assert!(
        error.to_string().contains("did you mean `gold`?"),
        "{error}"
    );
}

#[test]
fn include_cycle_is_an_error_naming_the_chain() {
    let dir = TempDir::new("cycle");
    let main = dir.write(
        "main.ron",
        "(\n    include: [\"a.ron\"],\n    camera: (position: (0, 0, -1), look_at: (0, 0, 0)),\n)",
    );
    dir.write("a.ron", "(include: [\"b.ron\"])");
    dir.write("b.ron", "(\n  include: [\n    \"main.ron\",\n  ],\n)");
    let error = load(&main).unwrap_err();
    let at = error.origin().unwrap();
    assert_eq!(
        (&**at.file, at.line, at.col),
        (dir.join("b.ron").as_path(), 3, 5)
    );
    let message = error.to_string();
    assert!(message.contains("include cycle"), "{message}");
    let chain = format!(
        "{} -> {} -> {} -> {}",
        main.display(),
        dir.join("a.ron").display(),
        dir.join("b.ron").display(),
        dir.join("main.ron").display()
    );
    assert!(message.contains(&chain), "{message}");

    // A file including itself.
    dir.write("a.ron", "(include: [\"./a.ron\"])");
    let error = load(&main).unwrap_err();
    let at = error.origin().unwrap();
    assert_eq!(
        (&**at.file, at.line, at.col),
        (dir.join("a.ron").as_path(), 1, 12)
    );
    assert!(error.to_string().contains("include cycle"), "{error}");
}

/// Include-once: a file reached again through another file (a diamond) is merged once, where
/// it is first reached, without a warning; it is not a cycle.
#[test]
fn a_file_included_twice_is_merged_once_where_first_reached() {
    let dir = TempDir::new("diamond");
    dir.write(
        "l.ron",
        "(lights: [Point(position: (0, 0, 0), intensity: 3)])",
    );
    dir.write(
        "a.ron",
        "(include: [\"l.ron\"], lights: [Point(position: (0, 0, 0), intensity: 1)])",
    );
    let main = dir.write(
        "main.ron",
        "(include: [\"a.ron\", \"l.ron\"], lights: [Point(position: (0, 0, 0), intensity: 2)], \
         camera: (position: (0, 0, -1), look_at: (0, 0, 0)))",
    );
    let scene = load(&main).unwrap();
    // l (inside a), a, main: the second mention of l adds nothing.
    assert_eq!(intensities(&scene), [3.0, 1.0, 2.0]);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

/// The same file twice in one `include` list is a slip: merged once, with a warning at the
/// second mention naming the first.
#[test]
fn a_file_listed_twice_in_one_include_list_is_merged_once_with_a_warning() {
    let dir = TempDir::new("twice");
    dir.write("l.ron", "(lights: [Point(position: (0, 0, 0))])");
    let main = dir.write(
        "main.ron",
        "(include: [\"l.ron\", \"./l.ron\"], camera: (position: (0, 0, -1), look_at: (0, 0, 0)))",
    );
    let scene = load(&main).unwrap();
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    assert_eq!((&**w.at.file, w.at.line, w.at.col), (main.as_path(), 1, 21));
    assert!(w.message.contains("already included at 1:12"), "{w}");
}

#[test]
fn missing_include_is_reported_at_its_string() {
    let dir = TempDir::new("missing");
    let main = dir.write(
        "main.ron",
        "(\n    include: [\"common.ron\", \"nope.ron\"],\n    camera: (position: (0, 0, -1), look_at: (0, 0, 0)),\n)",
    );
    dir.write("common.ron", "()");
    let error = load(&main).unwrap_err();
    let at = error.origin().unwrap();
    assert_eq!((&**at.file, at.line, at.col), (main.as_path(), 2, 29));
    let message = error.to_string();
    assert!(message.contains("cannot read included file"), "{message}");
    assert!(message.contains("nope.ron"), "{message}");
}

#[test]
fn missing_camera_after_merging_is_reported_at_the_main_file() {
    let dir = TempDir::new("nocamera");
    dir.write("a.ron", "(lights: [])");
    let main = dir.write("main.ron", "\n\n(include: [\"a.ron\"])");
    let error = load(&main).unwrap_err();
    let at = error.origin().unwrap();
    assert_eq!((&**at.file, at.line, at.col), (main.as_path(), 1, 1));
    assert!(
        error.to_string().contains("the scene has no camera"),
        "{error}"
    );

    // A camera from an include is enough.
    dir.write(
        "a.ron",
        "(camera: (position: (0, 0, -1), look_at: (0, 0, 0)))",
    );
    assert!(load(&main).is_ok());
}

/// A chain of 3,000 files, each including the next, loads on a thread with a 256 KiB stack:
/// the resolver walks the chain in a list, not by recursion (3,000 levels once overflowed the
/// main thread's 8 MiB stack).
#[test]
fn a_long_include_chain_needs_no_stack() {
    let dir = TempDir::new("chain");
    let n = 3000;
    for i in 0..n {
        dir.write(
            &format!("c{i}.ron"),
            format!("(include: [\"c{}.ron\"])", i + 1),
        );
    }
    dir.write(
        &format!("c{n}.ron"),
        "(camera: (position: (0, 0, -7), look_at: (0, 0, 0)))",
    );
    let root = dir.join("c0.ron");
    let scene = std::thread::Builder::new()
        .stack_size(256 << 10)
        .spawn(move || load(&root).map(|s| s.camera.value.position))
        .unwrap()
        .join()
        .expect("the load must not overflow its stack");
    assert_eq!(scene.unwrap(), [0.0, 0.0, -7.0]);
}

/// Includes nest at most `MAX_INCLUDE_DEPTH` files deep: deeper is an error at the include
/// string that goes too far, naming both ends of the chain.
#[test]
fn includes_deeper_than_the_limit_are_an_error_naming_the_chain() {
    let mut source = MemorySource::new();
    let n = MAX_INCLUDE_DEPTH + 5;
    for i in 0..n {
        source.insert(
            format!("c{i}.ron"),
            format!("(include: [\"c{}.ron\"])", i + 1),
        );
    }
    source.insert(
        format!("c{n}.ron"),
        "(camera: (position: (0, 0, -7), look_at: (0, 0, 0)))",
    );
    let e = load_ron_with(&mut source, Path::new("c0.ron"), &LoadOptions::default()).unwrap_err();
    let last = MAX_INCLUDE_DEPTH - 1;
    let at = e.origin().unwrap();
    assert_eq!(
        (at.file.display().to_string(), at.line, at.col),
        (format!("c{last}.ron"), 1, 12)
    );
    assert_eq!(
        e.to_string(),
        format!(
            "c{last}.ron:1:12: includes nest deeper than {MAX_INCLUDE_DEPTH} files (c0.ron -> \
             c1.ron -> c2.ron -> … -> c{}.ron -> c{last}.ron -> c{}.ron); expected a shallower \
             include chain",
            last - 1,
            last + 1
        )
    );
}

/// 30 files, each including the next twice (and once more through a third file): 2^29 paths
/// through the graph, but every file is read and parsed once and merged once.
#[test]
fn an_include_diamond_reads_each_file_once() {
    let n = 30;
    let mut source = MemorySource::new();
    for i in 0..n {
        source.insert(
            format!("scenes/d{i}.ron"),
            format!(
                "(include: [\"d{}.ron\", \"sub/../d{}.ron\", \"e{i}.ron\"])",
                i + 1,
                i + 1
            ),
        );
        source.insert(
            format!("scenes/e{i}.ron"),
            format!("(include: [\"d{}.ron\"])", i + 1),
        );
    }
    source.insert(
        format!("scenes/d{n}.ron"),
        "(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), lights: [Point(position: (0, 0, 0))])",
    );
    let scene = load_ron_with(
        &mut source,
        Path::new("scenes/d0.ron"),
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(scene.lights.len(), 1);
    for i in 0..=n {
        assert_eq!(source.reads(format!("scenes/d{i}.ron")), 1, "d{i}.ron");
    }
    assert_eq!(source.total_reads(), 2 * n + 1);
    // One warning per file that lists the same file twice; none for the diamonds.
    assert_eq!(scene.warnings.len(), n, "{:?}", scene.warnings);
}

/// The same on disk: it finishes (it took hours when every path was followed).
#[test]
fn an_include_diamond_on_disk_loads() {
    let dir = TempDir::new("diamond30");
    let n = 30;
    for i in 0..n {
        dir.write(
            &format!("d{i}.ron"),
            format!("(include: [\"d{}.ron\", \"d{}.ron\"])", i + 1, i + 1),
        );
    }
    dir.write(
        &format!("d{n}.ron"),
        "(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), lights: [Point(position: (0, 0, 0))])",
    );
    let scene = load(&dir.join("d0.ron")).unwrap();
    assert_eq!(scene.lights.len(), 1);
}

/// Cycles in memory too, with `.` and `..` resolved by name.
#[test]
fn include_cycles_through_relative_paths_are_found() {
    let mut source = MemorySource::new();
    source.insert("a/main.ron", "(include: [\"../b/x.ron\"])");
    source.insert("b/x.ron", "(include: [\"./../a/main.ron\"])");
    let e = load_ron_with(
        &mut source,
        Path::new("a/main.ron"),
        &LoadOptions::default(),
    )
    .unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("include cycle: a/main.ron -> a/../b/x.ron -> a/../b/./../a/main.ron"),
        "{message}"
    );
}

/// All scene files of one load together hold at most `max_scene_bytes`.
#[test]
fn scene_text_is_capped_per_load() {
    let main = "(include: [\"big.ron\"], camera: (position: (0, 0, -5), look_at: (0, 0, 0)))";
    let mut source = MemorySource::new();
    source.insert("main.ron", main);
    source.insert("big.ron", format!("({})", " ".repeat(200)));
    let options = LoadOptions {
        max_scene_bytes: 250,
        ..LoadOptions::default()
    };
    let e = load_ron_with(&mut source, Path::new("main.ron"), &options).unwrap_err();
    let at = e.origin().unwrap();
    assert_eq!((at.line, at.col), (1, 12));
    assert!(
        e.to_string().ends_with(&format!(
            "cannot include `big.ron`: it is 202 bytes; the scene files of one load may hold at \
             most 250 bytes together, and {} bytes are read already",
            main.len()
        )),
        "{e}"
    );
    // The main file alone.
    let options = LoadOptions {
        max_scene_bytes: 50,
        ..LoadOptions::default()
    };
    let e = load_ron_with(&mut source, Path::new("main.ron"), &options).unwrap_err();
    assert!(e.origin().is_none());
    assert_eq!(
        e.to_string(),
        format!(
            "`main.ron` is {} bytes; a scene file may be at most 50 bytes",
            main.len()
        )
    );
}
