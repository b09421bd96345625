//! Every error class: exact `line:col` and the key words of the message.

use std::path::Path;

use luxon_formats::load_ron_str;

/// A valid camera on line 2 of every scene below.
const CAMERA: &str = "    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),";

/// Loads `(\n{CAMERA}\n{body}\n)`: `body` starts on line 3.
fn scene_error(body: &str) -> (u32, u32, String) {
    error_of(&format!("(\n{CAMERA}\n{body}\n)"))
}

fn error_of(text: &str) -> (u32, u32, String) {
    let error = load_ron_str(text, Path::new("dir/bad.ron")).expect_err("the scene is invalid");
    let at = error.origin().expect("the error has a position").clone();
    assert_eq!(*at.file, Path::new("dir/bad.ron"));
    let message = error.to_string();
    let prefix = format!("dir/bad.ron:{}:{}: ", at.line, at.col);
    assert!(message.starts_with(&prefix), "{message}");
    (at.line, at.col, message[prefix.len()..].to_string())
}

#[track_caller]
fn check(found: (u32, u32, String), line: u32, col: u32, words: &[&str]) {
    let (l, c, message) = found;
    assert_eq!((l, c), (line, col), "wrong position for: {message}");
    for word in words {
        assert!(message.contains(word), "`{word}` missing from: {message}");
    }
}

// ---- What ron reports, reworded ----

#[test]
fn syntax_error_missing_comma() {
    let found = scene_error("    lights: [Point(position: (1, 2, 3)) Point(position: (1, 2, 3))],");
    check(found, 3, 41, &["expected `,`"]);
}

#[test]
fn unknown_field_suggests_the_closest() {
    let found = error_of("(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fvo: 40),\n)");
    check(
        found,
        2,
        56,
        &[
            "unknown field `fvo`",
            "did you mean `fov`?",
            "`zoom`",
            "`look_at`",
        ],
    );
    let found = scene_error("    materials: { \"m\": (shinyness: 3) },");
    check(
        found,
        3,
        24,
        &[
            "unknown field `shinyness`",
            "did you mean `shininess`?",
            "`ior`",
        ],
    );
}

#[test]
fn unknown_field_without_close_name_lists_fields() {
    let found = scene_error("    render: (quality: 3),");
    check(
        found,
        3,
        14,
        &["unknown field `quality`", "expected one of", "`width`"],
    );
    assert!(!found_contains_did_you_mean(scene_error(
        "    render: (quality: 3),"
    )));
}

fn found_contains_did_you_mean(found: (u32, u32, String)) -> bool {
    found.2.contains("did you mean")
}

#[test]
fn unknown_light_variant_suggests_point() {
    let found = scene_error("    lights: [\n        Pont(position: (1, 2, 3)),\n    ],");
    check(
        found,
        4,
        9,
        &[
            "unknown variant `Pont`",
            "did you mean `Point`?",
            "`Directional`",
        ],
    );
}

#[test]
fn unknown_enum_values() {
    let found = scene_error("    materials: { \"m\": (highlight: Blin) },");
    check(
        found,
        3,
        35,
        &["`Blin`", "did you mean `Blinn`?", "`Phong`"],
    );
    let found = scene_error("    render: (parallel: (decomposition: Dynamik)),");
    check(
        found,
        3,
        40,
        &["`Dynamik`", "did you mean `Dynamic`?", "`BlockCyclic`"],
    );
}

#[test]
fn wrong_top_level_name() {
    let found = error_of("Scen(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n)");
    check(
        found,
        1,
        1,
        &["`Scen(`", "expected `Scene(`", "did you mean `Scene`?"],
    );
}

#[test]
fn missing_and_duplicate_fields() {
    let found = scene_error("    objects: [(material: \"m\")],");
    check(found, 3, 15, &["missing field `plugin`", "`Object`"]);
    let found =
        error_of("(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: 4, fov: 5),\n)");
    check(found, 2, 64, &["`fov`", "twice"]);
}

#[test]
fn wrong_types() {
    let found =
        error_of("(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: \"wide\"),\n)");
    check(found, 2, 61, &["expected a number"]);
    let found = error_of("(\n    camera: (position: (0, 0, -5), look_at: (0, 0)),\n)");
    check(
        found,
        2,
        45,
        &["found 2 numbers", "expected 3", "(x, y, z)"],
    );
}

// ---- Numbers ----

#[test]
fn nan_inside_params() {
    let found = scene_error(
        "    objects: [\n        (plugin: \"sphere\", params: (center: (0, NaN, 0), radius: 1)),\n    ],",
    );
    check(
        found,
        4,
        49,
        &["NaN is not allowed here; expected a finite number"],
    );
}

#[test]
fn infinities_anywhere() {
    let found = error_of("(\n    camera: (position: (0, 0, -inf), look_at: (0, 0, 0)),\n)");
    check(found, 2, 31, &["-inf is not allowed here", "finite number"]);
    let found = scene_error("    background: (1e999, 0, 0),");
    check(found, 3, 18, &["1e999", "finite number"]);
}

// ---- Camera ----

fn camera_error(fields: &str) -> (u32, u32, String) {
    error_of(&format!("(\n    camera: ({fields}),\n)"))
}

#[test]
fn camera_position_equals_look_at() {
    let found = camera_error("position: (1, 2, 3), look_at: (1, 2, 3)");
    check(
        found,
        2,
        44,
        &["`look_at` equals its `position`", "expected"],
    );
}

#[test]
fn camera_zero_up_vector() {
    let found = camera_error("position: (0, 0, -5), look_at: (0, 0, 0), up: (0, 0, 0)");
    check(
        found,
        2,
        60,
        &["`up` has zero length", "expected a direction"],
    );
}

#[test]
fn camera_up_parallel_to_view() {
    // Looking straight down with the default up (0, 1, 0): reported at the camera.
    let found = camera_error("position: (0, 5, 0), look_at: (0, 0, 0)");
    check(
        found,
        2,
        13,
        &["`up` (0, 1, 0) (the default) is parallel", "view direction"],
    );
    let found = camera_error("position: (0, 0, -5), look_at: (0, 0, 0), up: (0, 0, 2)");
    check(found, 2, 60, &["parallel"]);
}

#[test]
fn camera_fov_zoom_aspect() {
    let found = camera_error("position: (0, 0, -5), look_at: (0, 0, 0), fov: 180");
    check(found, 2, 61, &["`fov` is 180", "between 0 and 180"]);
    let found = camera_error("position: (0, 0, -5), look_at: (0, 0, 0), fov: 0");
    check(found, 2, 61, &["`fov` is 0"]);
    let found = camera_error("position: (0, 0, -5), look_at: (0, 0, 0), zoom: 0");
    check(found, 2, 62, &["`zoom` is 0", "greater than 0"]);
    let found = camera_error("position: (0, 0, -5), look_at: (0, 0, 0), fov: 30, zoom: 2");
    check(found, 2, 71, &["both `fov` and `zoom`", "only one"]);
    let found = camera_error("position: (0, 0, -5), look_at: (0, 0, 0), aspect: -1");
    check(found, 2, 64, &["`aspect` is -1", "greater than 0"]);
}

#[test]
fn missing_camera_is_reported_at_the_start() {
    let found = error_of("// no camera\n(\n    lights: [],\n)");
    check(
        found,
        1,
        1,
        &[
            "no camera",
            "expected `camera: (position: ..., look_at: ...)`",
        ],
    );
}

// ---- Lights ----

#[test]
fn light_errors() {
    let found = scene_error("    lights: [Point(position: (0, 0, 0), intensity: -1)],");
    check(found, 3, 52, &["`intensity` is -1", "0 or more"]);
    let found = scene_error("    lights: [Point(position: (0, 0, 0), color: (1, -0.5, 1))],");
    check(found, 3, 52, &["`color`", "-0.5", "0 or more"]);
    let found = scene_error("    lights: [Directional(direction: (0, 0, 0))],");
    check(found, 3, 37, &["`direction` has zero length", "non-zero"]);
}

#[test]
fn ambient_occlusion_errors() {
    let found = scene_error("    ambient_occlusion: (samples: 8, direct: -0.5),");
    check(found, 3, 45, &["`direct` is -0.5", "0 or more"]);
    let found = scene_error("    ambient_occlusion: (samples: 0),");
    check(found, 3, 34, &["`samples` is 0"]);
}

#[test]
fn fog_errors() {
    let found = scene_error("    fog: (mode: Exp(density: 0.1, start: -1), every_ray: true),");
    check(found, 3, 42, &["`start` is -1", "0"]);
    let found = scene_error("    fog: (mode: Exp2(density: 0.1), misses: 1),");
    check(found, 3, 45, &["expected `true` or `false`"]);
}

// ---- Materials ----

#[test]
fn material_coefficients() {
    let cases = [
        ("specular: -0.1", "`specular` is -0.1"),
        ("reflect: 1.5", "`reflect` is 1.5"),
        ("transmit: 2", "`transmit` is 2"),
        ("shininess: 0", "`shininess` is 0"),
        ("ior: 0", "`ior` is 0"),
        ("ambient: -1", "`ambient` is -1"),
        ("color: (0.5, 0.5, -2)", "-2"),
        ("outline: 1.5", "`outline` is 1.5"),
        ("outline_width: -0.5", "`outline_width` is -0.5"),
    ];
    for (field, words) in cases {
        let body = format!("    materials: {{ \"m\": ({field}) }},");
        let value = field.find(": ").unwrap() + 2;
        let mut col = 24 + value as u32;
        if field.starts_with("color") {
            col += 11; // the third component
        }
        check(scene_error(&body), 3, col, &[words, "expected"]);
    }
}

#[test]
fn material_texture_must_be_defined() {
    let found = scene_error(
        "    textures: { \"checks\": (plugin: \"checker\") },\n    materials: { \"m\": (texture: \"chekcs\") },",
    );
    check(
        found,
        4,
        33,
        &[
            "unknown texture `chekcs`",
            "did you mean `checks`?",
            "`checks`",
        ],
    );
}

// ---- Objects ----

#[test]
fn object_material_must_be_defined() {
    let body = "    materials: { \"red\": (), \"glass\": () },\n    objects: [\n        (plugin: \"sphere\", material: \"glas\"),\n    ],";
    let found = scene_error(body);
    check(
        found,
        5,
        38,
        &[
            "unknown material `glas`",
            "did you mean `glass`?",
            "`red`, `glass`",
        ],
    );
    let found = scene_error("    objects: [(plugin: \"sphere\", material: \"steel\")],");
    check(
        found,
        3,
        44,
        &["unknown material `steel`", "none are defined"],
    );
}

#[test]
fn empty_plugin_names() {
    let found = scene_error("    objects: [(plugin: \"\")],");
    check(found, 3, 24, &["plugin name is empty", "expected"]);
    let found = scene_error("    textures: { \"t\": (plugin: \" \") },");
    check(found, 3, 31, &["plugin name is empty"]);
    let found = scene_error("    render: (outputs: [(path: \"a.png\", plugin: \"\")]),");
    check(found, 3, 48, &["plugin name is empty"]);
}

// ---- Render ----

fn render_error(fields: &str) -> (u32, u32, String) {
    scene_error(&format!("    render: ({fields}),"))
}

#[test]
fn resolution_zero() {
    check(
        render_error("width: 0"),
        3,
        21,
        &["`width` is 0", "whole number from 1 to 65536"],
    );
    check(
        render_error("width: 8, height: 0"),
        3,
        32,
        &["`height` is 0"],
    );
}

#[test]
fn resolution_limits() {
    check(
        render_error("height: 70000"),
        3,
        22,
        &["`height` is 70000", "65536"],
    );
    check(
        render_error("width: 1.5"),
        3,
        21,
        &["`width` is 1.5", "whole number"],
    );
    check(render_error("width: -1"), 3, 21, &["`width` is -1"]);
    check(
        render_error("width: 65536, height: 65536"),
        3,
        21,
        &["absurdly large", "4294967296", "at most 268435456"],
    );
}

#[test]
fn adaptive_settings() {
    check(
        render_error("adaptive: (threshold: -1)"),
        3,
        36,
        &["`threshold` is -1", "at least 0"],
    );
    check(
        render_error("adaptive: (threshold: 0.1, max_depth: 9)"),
        3,
        52,
        &["`max_depth` is 9", "0 to 6"],
    );
    let (_, _, m) = render_error("adaptive: (threshold: 0.1, depth: 2)");
    assert!(m.contains("depth"), "{m}");
    let (_, _, m) = render_error("adaptive: (max_depth: 2)");
    assert!(m.contains("threshold"), "{m}");
}

#[test]
fn tachyon_shading_settings() {
    check(
        render_error("light_scale: -1"),
        3,
        27,
        &["`light_scale` is -1", "0"],
    );
    check(
        render_error("transparency: (mode: AngleModulated, angle: Raster3D)"),
        3,
        58,
        &["`angle`", "AngleModulated", "expected one of them"],
    );
    check(
        render_error("transparency: (mode: Filter, scale_reflection: true)"),
        3,
        61,
        &["`scale_reflection`", "PostMultiplied"],
    );
    let (_, _, m) = render_error("transparency: (beyond_max: Hidden)");
    assert!(m.contains("Skip"), "{m}");
    let (_, _, m) = render_error("tachyon: (threshold: true)");
    assert!(m.contains("light_threshold"), "{m}");
}

#[test]
fn render_limits() {
    check(
        render_error("samples: 0"),
        3,
        23,
        &["`samples` is 0", "1 to 65536"],
    );
    check(
        render_error("max_depth: 2000"),
        3,
        25,
        &["`max_depth` is 2000", "0 to 1024"],
    );
    check(
        render_error("min_weight: 1"),
        3,
        26,
        &["`min_weight` is 1", "less than 1"],
    );
    check(
        render_error("min_weight: -0.5"),
        3,
        26,
        &["`min_weight` is -0.5"],
    );
    check(
        render_error("parallel: (tile_size: 0)"),
        3,
        36,
        &["`tile_size` is 0", "1 to 4096"],
    );
    check(
        render_error("parallel: (threads: 5000)"),
        3,
        34,
        &["`threads` is 5000", "1 to 4096"],
    );
}

#[test]
fn frame_groups() {
    // Reported at the group size inside `Groups(...)`, or at the unknown name.
    check(
        render_error("parallel: (frames: Groups(0))"),
        3,
        40,
        &["`Groups` is 0", "1 to 65536"],
    );
    check(
        render_error("parallel: (frames: Groups(1.5))"),
        3,
        40,
        &["`Groups` is 1.5", "whole number"],
    );
    check(
        render_error("parallel: (frames: Hole)"),
        3,
        33,
        &["unknown variant `Hole`", "`Whole`", "`Shared`"],
    );
}

// ---- Hostile and careless input ----

/// ron's recursion limit, in words for a scene's author (not ron's options).
#[test]
fn values_nested_too_deeply() {
    let deep = format!(
        "    objects: [(plugin: \"x\", params: (v: {}1{}))],",
        "[".repeat(200),
        "]".repeat(200)
    );
    let (line, _, message) = scene_error(&deep);
    assert_eq!(line, 3);
    assert_eq!(
        message,
        "values are nested more than 128 levels deep; expected at most 128 levels of brackets"
    );
}

/// A name defined twice in one file is a slip: an error at the second key, naming the first.
#[test]
fn a_name_defined_twice_in_one_file() {
    for (map, what) in [
        ("materials", "material"),
        ("textures", "texture"),
        ("clip_groups", "clip group"),
    ] {
        let value = match map {
            "materials" => "(ior: 1.5)",
            "textures" => "(plugin: \"checker\")",
            _ => "[]",
        };
        let found = scene_error(&format!(
            "    {map}: {{\n        \"m\": {value},\n        \"n\": {value},\n        \"m\": {value},\n    }},"
        ));
        check(
            found,
            6,
            9,
            &[&format!(
                "{what} `m` is defined twice in this file (first at 4:9); expected each name \
                 once (a file that includes this one may redefine it)"
            )],
        );
    }
}

/// Numbers in messages as written: 2^64 - 1 is not 18446744073709552000.
#[test]
fn values_are_quoted_as_written() {
    let found = scene_error("    render: (width: 18446744073709551615),");
    check(
        found,
        3,
        21,
        &["`width` is 18446744073709551615; expected a whole number from 1 to 65536"],
    );
    let found = scene_error("    render: (samples: 1e30),");
    check(found, 3, 23, &["`samples` is 1e30;"]);
    let found = scene_error("    materials: { \"m\": (color: (1, -0.50, 0)) },");
    check(found, 3, 35, &["negative component -0.50;"]);
}

/// Names from the file are echoed with their control characters escaped.
#[test]
fn echoed_names_cannot_drive_the_terminal() {
    let found = scene_error(
        "    materials: { \"\\u{1b}[31m\": () },\n    objects: [(plugin: \"sphere\", material: \"\\u{1b}[32m\")],",
    );
    let (_, _, message) = &found;
    assert!(!message.chars().any(char::is_control), "{message:?}");
    check(
        found,
        4,
        44,
        &[
            "unknown material `\\u{1b}[32m`",
            "expected one of `\\u{1b}[31m`",
        ],
    );
}

// ---- Memory sizes (`render: (memory: ..., texture_cache: ...)`) ----

#[test]
fn memory_sizes_parse_with_binary_units_or_as_percentages() {
    use luxon_formats::{parse_memory_size, MemorySize};
    for (text, bytes) in [
        ("6 GiB", 6u64 << 30),
        ("512M", 512 << 20),
        ("1.5G", 3 << 29),
        ("64 kb", 64 << 10),
        ("2T", 2 << 40),
        ("100 B", 100),
    ] {
        assert_eq!(
            parse_memory_size(text),
            Ok(MemorySize::Bytes(bytes)),
            "{text}"
        );
    }
    assert_eq!(parse_memory_size("50%"), Ok(MemorySize::Percent(50.0)));
    // Written back as a scene writes them, they read back the same.
    for m in [
        MemorySize::Bytes(6 << 30),
        MemorySize::Bytes(3 << 29),
        MemorySize::Bytes(100),
        MemorySize::Percent(12.5),
    ] {
        assert_eq!(parse_memory_size(&m.to_string()), Ok(m), "{m}");
    }
    assert_eq!(MemorySize::Bytes(3 << 29).to_string(), "1536 MiB");
    for (text, why) in [
        ("1.5 X", "`X` is not a unit"),
        ("1024", "no unit"),
        ("G", "does not start with a number"),
        ("-1G", "does not start with a number"),
        ("0M", "at least 1 byte"),
        ("0%", "above 0 and at most 100"),
        ("150%", "above 0 and at most 100"),
        ("99999999T", "below 8 EiB"),
    ] {
        let e = parse_memory_size(text).unwrap_err();
        assert!(e.contains(why), "{text}: {e}");
    }
}

#[test]
fn a_memory_size_without_a_unit_is_an_error_at_its_value() {
    let found = scene_error("    render: (width: 8, memory: \"1.5 X\"),");
    check(
        found,
        3,
        32,
        &["`memory` is \"1.5 X\": `X` is not a unit; expected a size such as 512M"],
    );
    let found = scene_error("    render: (texture_cache: \"25%\"),");
    check(
        found,
        3,
        29,
        &["`texture_cache` is \"25%\"", "not a percentage"],
    );
    let desc = load_ron_str(
        &format!("(\n{CAMERA}\n    render: (memory: \"50%\", texture_cache: \"1 GiB\"),\n)"),
        Path::new("ok.ron"),
    )
    .unwrap();
    assert_eq!(
        desc.render.memory,
        Some(luxon_formats::MemorySize::Percent(50.0))
    );
    assert_eq!(desc.render.texture_cache, Some(1 << 30));
}

// ---- Background ----

#[test]
fn gradient_background_errors_are_at_the_value() {
    // An unknown field, a misspelt kind, a missing field, a zero `up`, a negative colour, a
    // struct that is not a `Gradient`, a colour of two components.
    let g = "kind: Sphere, top: 1, bottom: -1, top_color: (1, 1, 1), bottom_color: (0, 0, 0)";
    let found = scene_error(&format!(
        "    background: Gradient({g}, colour: (1, 0, 0)),"
    ));
    check(
        found,
        3,
        107,
        &["unknown field `colour` in `Gradient`", "`top_color`"],
    );
    let found = scene_error(
        "    background: Gradient(kind: Sphre, top: 1, bottom: 0, top_color: (1, 1, 1), \
         bottom_color: (0, 0, 0)),",
    );
    check(
        found,
        3,
        32,
        &["Sphre", "did you mean `Sphere`?", "`OrthoPlane`"],
    );
    let found = scene_error("    background: Gradient(kind: OrthoPlane, top: 1, bottom: 0),");
    check(found, 3, 17, &["missing field `top_color` in `Gradient`"]);
    let found = scene_error(&format!("    background: Gradient({g}, up: (0, 0, 0)),"));
    check(
        found,
        3,
        111,
        &["`up` is (0, 0, 0)", "expected a direction"],
    );
    let found = scene_error(
        "    background: Gradient(kind: Sphere, top: 1, bottom: 0, top_color: (1, -1, 1), \
         bottom_color: (0, 0, 0)),",
    );
    check(found, 3, 74, &["`top_color` has a negative component -1"]);
    let found = scene_error(&format!("    background: Sky({g}),"));
    check(found, 3, 17, &["`background: Sky(...)`", "Gradient(kind:"]);
    let found = scene_error("    background: (1, 0),");
    check(found, 3, 17, &["found 2 numbers; expected 3"]);
}
