//! `volumes: [...]`: parsing with positions, merging across includes, and its errors.

mod common;
use common::TempDir;

use std::path::{Path, PathBuf};

use luxon_formats::*;

const SCENE: &str = r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
    volumes: [
        (plugin: "raw", params: (file: "head.raw", dims: (256, 256, 109)), name: "head"),
        (name: "engine", plugin: "raw",
         params: (
            file: "engine.raw",
            dims: (256, 256, 110),
         )),
        (plugin: "vdb"),
    ],
)
"#;

fn at(o: &Origin) -> (u32, u32) {
    assert_eq!(*o.file, PathBuf::from("/scenes/vol.ron"));
    (o.line, o.col)
}

fn load(text: &str) -> SceneDesc {
    load_ron_str(text, Path::new("/scenes/vol.ron")).unwrap_or_else(|e| panic!("{e}"))
}

fn error_of(text: &str) -> (u32, u32, String) {
    let error = load_ron_str(text, Path::new("/scenes/vol.ron")).expect_err("the scene is invalid");
    let origin = error.origin().expect("the error has a position").clone();
    let message = error.to_string();
    let prefix = format!("/scenes/vol.ron:{}:{}: ", origin.line, origin.col);
    assert!(message.starts_with(&prefix), "{message}");
    (origin.line, origin.col, message[prefix.len()..].to_string())
}

#[track_caller]
fn check(found: (u32, u32, String), line: u32, col: u32, words: &[&str]) {
    let (l, c, message) = found;
    assert_eq!((l, c), (line, col), "wrong position for: {message}");
    for word in words {
        assert!(message.contains(word), "`{word}` missing from: {message}");
    }
}

/// `(camera...)` on line 2 and `body` from line 3.
fn scene_with(body: &str) -> String {
    format!("(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n{body}\n)")
}

#[test]
fn volumes_parse_with_positions_and_verbatim_params() {
    let scene = load(SCENE);
    assert_eq!(scene.volumes.len(), 3);

    let head = &scene.volumes[0];
    assert_eq!(at(&head.at), (4, 9));
    assert_eq!(head.value.call.plugin.value, "raw");
    assert_eq!(at(&head.value.call.plugin.at), (4, 18));
    assert_eq!(
        head.value.call.params,
        r#"(file: "head.raw", dims: (256, 256, 109))"#
    );
    assert_eq!(at(&head.value.call.params_at), (4, 33));
    let name = head.value.name.as_ref().unwrap();
    assert_eq!(name.value, "head");
    assert_eq!(at(&name.at), (4, 82));

    // Fields in any order; params over several lines keep their text and start position.
    let engine = &scene.volumes[1];
    assert_eq!(at(&engine.at), (5, 9));
    assert_eq!(engine.value.name.as_ref().unwrap().value, "engine");
    assert_eq!(
        engine.value.call.params,
        "(\n            file: \"engine.raw\",\n            dims: (256, 256, 110),\n         )"
    );
    assert_eq!(at(&engine.value.call.params_at), (6, 18));

    // No params: "()" at the entry; no name: None.
    let vdb = &scene.volumes[2].value;
    assert_eq!(vdb.call.plugin.value, "vdb");
    assert_eq!(vdb.call.params, "()");
    assert_eq!(at(&vdb.call.params_at), (10, 9));
    assert_eq!(vdb.name, None);
}

#[test]
fn volumes_are_optional() {
    let scene = load("(camera: (position: (0, 0, -1), look_at: (0, 0, 0)))");
    assert!(scene.volumes.is_empty());
    let scene = load("(camera: (position: (0, 0, -1), look_at: (0, 0, 0)), volumes: [])");
    assert!(scene.volumes.is_empty());
}

#[test]
fn unknown_field_in_a_volume() {
    let found = error_of(&scene_with(
        "    volumes: [(plugin: \"raw\", nme: \"head\")],",
    ));
    check(
        found,
        3,
        31,
        &[
            "unknown field `nme`",
            "in `Volume`",
            "did you mean `name`?",
            "`plugin`",
            "`params`",
        ],
    );
    // Render settings belong under `render:`, not on the volume itself.
    let found = error_of(&scene_with(
        "    volumes: [(plugin: \"raw\", transfer: (0, 1))],",
    ));
    check(
        found,
        3,
        31,
        &["unknown field `transfer`", "expected one of", "`name`"],
    );
}

#[test]
fn volume_plugin_is_required_and_not_empty() {
    let found = error_of(&scene_with("    volumes: [(name: \"head\")],"));
    check(found, 3, 15, &["missing field `plugin`", "`Volume`"]);
    let found = error_of(&scene_with("    volumes: [(plugin: \"\")],"));
    check(found, 3, 24, &["plugin name is empty", "\"raw\""]);
}

#[test]
fn volume_names_are_not_empty_and_unique() {
    let found = error_of(&scene_with(
        "    volumes: [(plugin: \"raw\", name: \" \")],",
    ));
    check(found, 3, 37, &["volume name is empty"]);
    let found = error_of(&scene_with(
        "    volumes: [\n        (plugin: \"raw\", name: \"head\"),\n        (plugin: \"raw\"),\n        (plugin: \"vdb\", name: \"head\"),\n    ],",
    ));
    check(
        found,
        6,
        31,
        &[
            "volume name `head` is already used at /scenes/vol.ron:4:31",
            "expected each volume name once",
        ],
    );
}

#[test]
fn wrong_type_for_volumes() {
    let found = error_of(&scene_with("    volumes: (plugin: \"raw\"),"));
    check(found, 3, 14, &["expected a list"]);
}

/// A fresh directory under the system temp dir, removed when dropped.
#[test]
fn volumes_merge_across_includes_in_order() {
    let dir = TempDir::new("merge");
    let data = dir.write(
        "data.ron",
        "(\n    volumes: [(plugin: \"raw\", params: (file: \"a.raw\"), name: \"a\")],\n)",
    );
    let main = dir.write(
        "main.ron",
        "(\n    include: [\"data.ron\"],\n    camera: (position: (0, 0, -1), look_at: (0, 0, 0)),\n    volumes: [(plugin: \"raw\", name: \"b\")],\n)",
    );
    let scene = luxon_formats::load(&main).unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<&str> = scene
        .volumes
        .iter()
        .map(|v| v.value.name.as_ref().unwrap().value.as_str())
        .collect();
    assert_eq!(names, ["a", "b"]);
    // Each keeps the position in its own file.
    let a = &scene.volumes[0];
    assert_eq!(*a.at.file, data);
    assert_eq!((a.at.line, a.at.col), (2, 15));
    assert_eq!(a.value.call.params, "(file: \"a.raw\")");
    assert_eq!(
        (a.value.call.params_at.line, a.value.call.params_at.col),
        (2, 39)
    );
    assert_eq!(*scene.volumes[1].at.file, main);

    // The same name in an included file and the including one is an error at the later one.
    dir.write(
        "main2.ron",
        "(\n    include: [\"data.ron\"],\n    camera: (position: (0, 0, -1), look_at: (0, 0, 0)),\n    volumes: [(plugin: \"raw\", name: \"a\")],\n)",
    );
    let e = luxon_formats::load(&dir.join("main2.ron")).unwrap_err();
    let at = e.origin().unwrap();
    assert_eq!(*at.file, dir.join("main2.ron"));
    assert_eq!((at.line, at.col), (4, 37));
    assert!(e.to_string().contains("already used at"), "{e}");
}

#[test]
fn render_settings_parse_with_defaults() {
    let scene = load(&scene_with(
        r#"    clip_groups: { "cut": [(point: (0, 0, 0), normal: (0, 0, 1))] },
    volumes: [
        (plugin: "raw", name: "a", render: (transfer: (preset: "ct-bone"))),
        (plugin: "raw", name: "b", render: (
            transfer: (points: [(x: 0, color: (0, 0, 0), opacity: 0), (x: 1, color: (1, 0.5, 0), opacity: 3)],
                       range: (10, 200), opacity: 2),
            step: 0.25, interpolation: Nearest, clip: "cut",
            shading: (specular: 0.5, shadows: true),
            bounds: (min: (-1, -1, -1), max: (1, 1, 0)),
        )),
        (plugin: "raw", name: "data"),
    ],
    render: (volume_step: 2, volume_skip: false),"#,
    ));
    let a = scene.volumes[0].value.render.as_ref().unwrap();
    assert_eq!(at(&a.at), (5, 44));
    let a = &a.value;
    assert_eq!(a.transfer.preset.as_deref(), Some("ct-bone"));
    assert!(a.transfer.points.len() >= 2);
    assert_eq!(a.transfer.range, None);
    assert_eq!(a.transfer.opacity, 1.0);
    assert_eq!(a.step, None);
    assert_eq!(a.interpolation, Interpolation::Trilinear);
    assert_eq!(a.shading, None);
    assert_eq!(a.clip, None);
    let b = &scene.volumes[1].value.render.as_ref().unwrap().value;
    assert_eq!(b.transfer.preset, None);
    assert_eq!(
        b.transfer.points[1],
        TransferPoint {
            x: 1.0,
            color: [1.0, 0.5, 0.0],
            opacity: 3.0
        }
    );
    assert_eq!(b.transfer.range, Some([10.0, 200.0]));
    assert_eq!(b.transfer.opacity, 2.0);
    assert_eq!(b.step, Some(0.25));
    assert_eq!(b.interpolation, Interpolation::Nearest);
    assert_eq!(b.clip.as_ref().unwrap().value, "cut");
    let sh = b.shading.unwrap();
    assert_eq!((sh.specular, sh.ambient, sh.shadows), (0.5, 0.3, true));
    assert_eq!(b.bounds, Some(([-1.0; 3], [1.0, 1.0, 0.0])));
    // No `render`: data only.
    assert_eq!(scene.volumes[2].value.render, None);
    assert_eq!(scene.render.volume_step, 2.0);
    assert!(!scene.render.volume_skip);
    let plain = load("(camera: (position: (0, 0, -1), look_at: (0, 0, 0)))");
    assert_eq!(
        (plain.render.volume_step, plain.render.volume_skip),
        (1.0, true)
    );
}

#[test]
fn every_preset_is_well_formed() {
    for (name, points) in TRANSFER_PRESETS {
        assert!(!points.is_empty(), "{name}");
        assert!(
            points.windows(2).all(|w| w[0].0 < w[1].0),
            "{name}: x increasing"
        );
        assert!(
            points
                .iter()
                .all(|p| (0.0..=1.0).contains(&p.0) && p.2 >= 0.0),
            "{name}"
        );
        let scene = load(&scene_with(&format!(
            "    volumes: [(plugin: \"raw\", render: (transfer: (preset: \"{name}\")))],"
        )));
        let t = &scene.volumes[0]
            .value
            .render
            .as_ref()
            .unwrap()
            .value
            .transfer;
        assert_eq!(t.points.len(), points.len());
    }
}

#[test]
fn render_setting_errors() {
    let v = |render: &str| {
        scene_with(&format!(
            "    volumes: [(plugin: \"raw\", render: {render})],"
        ))
    };
    // Column of `render:`'s value is 40.
    let found = error_of(&v(r#"(transfer: (preset: "ct-bones"))"#));
    check(
        found,
        3,
        59,
        &[
            "unknown transfer-function preset `ct-bones`",
            "did you mean `ct-bone`?",
            "`grayscale`",
        ],
    );
    let found = error_of(&v(r#"(transfer: (presets: "mri"))"#));
    check(
        found,
        3,
        51,
        &["unknown field `presets`", "did you mean `preset`?"],
    );
    let found = error_of(&v(r#"(transfer: ())"#));
    check(found, 3, 50, &["neither `preset` nor `points`", "mri"]);
    let found = error_of(&v(
        r#"(transfer: (preset: "mri", points: [(x: 0, color: (0, 0, 0), opacity: 1)]))"#,
    ));
    check(found, 3, 74, &["both `preset` and `points`"]);
    let found = error_of(&v(r#"(transfer: (points: []))"#));
    check(found, 3, 59, &["no points"]);
    let found = error_of(&v(
        r#"(transfer: (points: [(x: 0.5, color: (0, 0, 0), opacity: 1), (x: 0.5, color: (1, 1, 1), opacity: 1)]))"#,
    ));
    check(
        found,
        3,
        104,
        &[
            "`x` 0.5 does not follow the previous one (0.5)",
            "increasing",
        ],
    );
    let found = error_of(&v(
        r#"(transfer: (points: [(x: 1.5, color: (0, 0, 0), opacity: 1)]))"#,
    ));
    check(found, 3, 64, &["`x` is 1.5", "from 0 to 1"]);
    let found = error_of(&v(
        r#"(transfer: (points: [(x: 0, color: (0, -1, 0), opacity: 1)]))"#,
    ));
    check(found, 3, 78, &["negative component -1"]);
    let found = error_of(&v(
        r#"(transfer: (points: [(x: 0, color: (0, 0, 0), opacity: -2)]))"#,
    ));
    check(found, 3, 94, &["`opacity` is -2", "0 or more"]);
    let found = error_of(&v(r#"(transfer: (preset: "mri", range: (5, 5)))"#));
    check(found, 3, 77, &["`range` (5, 5) is empty", "low < high"]);
    let found = error_of(&v(r#"(transfer: (preset: "mri"), step: 0)"#));
    check(found, 3, 73, &["`step` is 0", "greater than 0"]);
    let found = error_of(&v(r#"(transfer: (preset: "mri"), interpolation: Cubic)"#));
    check(
        found,
        3,
        82,
        &["unknown variant `Cubic`", "`Nearest`", "`Trilinear`"],
    );
    let found = error_of(&v(
        r#"(transfer: (preset: "mri"), shading: (shininess: 0))"#,
    ));
    check(found, 3, 88, &["`shininess` is 0"]);
    let found = error_of(&v(
        r#"(transfer: (preset: "mri"), bounds: (min: (0, 0, 0), max: (1, 0, 1)))"#,
    ));
    check(found, 3, 101, &["crop box is empty", "axis 1"]);
    let found = error_of(&v(r#"(transfer: (preset: "mri"), clip: "cutt")"#));
    check(
        found,
        3,
        73,
        &["unknown clip group `cutt`", "none are defined"],
    );
    let found = error_of(&scene_with(
        "    clip_groups: { \"cut\": [(point: (0, 0, 0), normal: (0, 0, 1))] },\n    volumes: [(plugin: \"raw\", render: (transfer: (preset: \"mri\"), clip: \"cutt\"))],",
    ));
    check(
        found,
        4,
        73,
        &["unknown clip group `cutt`", "did you mean `cut`?"],
    );
    let found = error_of(&scene_with("    render: (volume_step: -1),"));
    check(found, 3, 27, &["`volume_step` is -1", "greater than 0"]);
}
