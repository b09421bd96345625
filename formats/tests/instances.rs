//! `prototypes:` and `instances:`: what they read (objects, transforms, material overrides,
//! names), how they merge with `include`, and every error at its `line:col`.

mod common;

use std::path::Path;

use luxon_formats::*;

/// Line 2: a camera; line 3: materials; line 4: a named object. The body given to `scene`
/// starts on line 5.
const HEAD: &str = r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: 40),
    materials: { "red": (color: (1, 0, 0)), "glass": (color: (0, 0, 1)) },
    objects: [(plugin: "sphere", name: "ball", params: ())],
"#;

/// A prototype on line 5, for bodies that only add instances (from line 6).
const GEAR: &str = r#"    prototypes: { "gear": (objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1), material: "red"), (plugin: "cylinder", params: ())]), "empty": (objects: []) },
"#;

fn load(body: &str) -> Result<SceneDesc, SceneError> {
    load_ron_str(&format!("{HEAD}{body}\n)"), Path::new("a.ron"))
}

fn scene(body: &str) -> SceneDesc {
    load(body).unwrap_or_else(|e| panic!("{e}"))
}

/// Checks that the error is at the first `needle` on line `line` of the scene text and that
/// its message holds `words`.
#[track_caller]
fn check(body: &str, line: u32, needle: &str, words: &[&str]) {
    let e = load(body).expect_err("the scene is invalid");
    common::assert_error_at(&format!("{HEAD}{body}"), &e, line, needle, words);
}

#[test]
fn prototypes_and_instances_are_read_with_their_transforms() {
    let s = scene(&format!(
        r#"{GEAR}    instances: [
        (prototype: "gear"),
        (prototype: "gear", name: "g1", world_from_object: (translate: (2, 0, 0), rotate: (axis: (0, 0, 2), degrees: 15), scale: (0.5, 0.5, 0.5)), material: "glass"),
        (prototype: "gear", world_from_object: (matrix: ((1, 0, 0, 4), (0, 1, 0, 0), (0, 0, 1, 0)))),
    ],"#
    ));
    assert_eq!(s.prototypes.len(), 2);
    let (name, gear) = &s.prototypes[0];
    assert_eq!(name, "gear");
    assert_eq!(gear.value.objects.len(), 2);
    assert_eq!(gear.value.objects[0].value.call.plugin.value, "sphere");
    assert_eq!(
        gear.value.objects[0].value.material.as_ref().unwrap().value,
        "red"
    );
    let i: Vec<&InstanceDesc> = s.instances.iter().map(|i| &i.value).collect();
    assert_eq!(i.len(), 3);
    assert_eq!(i[0].world_from_object.value, TransformDesc::IDENTITY);
    assert_eq!(i[0].name, None);
    assert_eq!(i[1].name.as_ref().unwrap().value, "g1");
    assert_eq!(i[1].material.as_ref().unwrap().value, "glass");
    assert_eq!(
        i[1].world_from_object.value,
        TransformDesc::Trs {
            translate: [2.0, 0.0, 0.0],
            rotate: Some(RotationDesc {
                axis: [0.0, 0.0, 1.0],
                degrees: 15.0
            }),
            scale: [0.5; 3],
        }
    );
    assert_eq!(
        i[2].world_from_object.value,
        TransformDesc::Matrix([
            [1.0, 0.0, 0.0, 4.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0]
        ])
    );
    // Where things are: the instance and its transform.
    assert_eq!((s.instances[1].at.line, s.instances[1].at.col), (8, 9));
    assert_eq!(i[1].world_from_object.at.line, 8);
}

#[test]
fn unknown_prototypes_are_named_with_a_suggestion() {
    check(
        &format!("{GEAR}    instances: [(prototype: \"gaer\")],"),
        6,
        "\"gaer\"",
        &[
            "unknown prototype `gaer`; did you mean `gear`?",
            "expected one of `gear`, `empty`",
        ],
    );
}

#[test]
fn an_instance_of_an_empty_prototype_is_an_error() {
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\"), (prototype: \"empty\")],"),
        6,
        "\"empty\"",
        &["prototype `empty` (at a.ron:5:", "has no objects"],
    );
    // An empty prototype nothing places is fine.
    scene(&format!("{GEAR}    instances: [(prototype: \"gear\")],"));
}

#[test]
fn transforms_must_be_invertible() {
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\", world_from_object: (matrix: ((1, 0, 0, 0), (2, 0, 0, 0), (0, 0, 1, 0))))],"),
        6,
        "((1, 0",
        &["the `matrix` is singular", "expected an invertible transform"],
    );
    check(
        &format!(
            "{GEAR}    instances: [(prototype: \"gear\", world_from_object: (scale: (1, 0, 1)))],"
        ),
        6,
        "0, 1)))",
        &["`scale` has a zero component"],
    );
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\", world_from_object: (rotate: (axis: (0, 0, 0), degrees: 5)))],"),
        6,
        "(0, 0, 0)",
        &["the rotation's `axis` has zero length"],
    );
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\", world_from_object: (translate: (1, 0, 0), matrix: ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0))))],"),
        6,
        "((1, 0, 0, 0)",
        &["give either `matrix` or `translate`/`rotate`/`scale`, not both"],
    );
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\", world_from_object: (translate: (NaN, 0, 0)))],"),
        6,
        "NaN",
        &["NaN is not allowed here; expected a finite number"],
    );
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\", world_from_object: (matrix: ((1e200, 0, 0, 0), (0, 1e200, 0, 0), (0, 0, 1e200, 0))))],"),
        6,
        "((1e200",
        &["the `matrix` is singular (its 3x3 part has determinant inf)"],
    );
}

#[test]
fn prototypes_hold_objects_only() {
    check(
        r#"    prototypes: { "p": (objects: [], lights: []) },"#,
        5,
        "lights",
        &["unknown field `lights`", "`objects`, `meshes`"],
    );
    check(
        r#"    prototypes: { "p": (instances: []) },"#,
        5,
        "instances",
        &["unknown field `instances`"],
    );
    check(
        r#"    prototypes: { "p": (objects: [(plugin: "sphere", params: (), clip: "c")]) },"#,
        5,
        "\"c\"",
        &["objects of a prototype cannot use clip groups"],
    );
    check(
        r#"    prototypes: { "p": (objects: [(plugin: "sphere", name: "n", params: ())]) },"#,
        5,
        "\"n\"",
        &["objects of a prototype cannot be named"],
    );
    check(
        r#"    prototypes: { "p": (objects: []), "p": (objects: []) },"#,
        5,
        "\"p\": (objects: []) }",
        &["prototype `p` is defined twice in this file"],
    );
}

#[test]
fn materials_and_names_are_checked() {
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\", material: \"glas\")],"),
        6,
        "\"glas\"",
        &["unknown material `glas`; did you mean `glass`?"],
    );
    check(
        r#"    prototypes: { "p": (objects: [(plugin: "sphere", params: (), material: "rde")]) },"#,
        5,
        "\"rde\"",
        &["unknown material `rde`; did you mean `red`?"],
    );
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\", name: \"g\"), (prototype: \"gear\", name: \"g\")],"),
        6,
        "\"g\")]",
        &["the instance name `g` is already used at a.ron:6:"],
    );
    check(
        &format!("{GEAR}    instances: [(prototype: \"gear\", name: \"ball\")],"),
        6,
        "\"ball\"",
        &["the instance name `ball` is already used at a.ron:4:"],
    );
}

#[test]
fn includes_merge_prototypes_by_name_and_append_instances() {
    let mut source = MemorySource::new();
    source.insert(
        "lib.ron",
        r#"(prototypes: { "p": (objects: [(plugin: "sphere", params: ())]), "q": (objects: [(plugin: "sphere", params: ())]) },
           instances: [(prototype: "p", name: "first")])"#,
    );
    source.insert(
        "main.ron",
        r#"(include: ["lib.ron"],
           camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
           prototypes: { "p": (objects: [(plugin: "cylinder", params: ()), (plugin: "sphere", params: ())]) },
           instances: [(prototype: "q"), (prototype: "p")])"#,
    );
    let s = load_ron_with(&mut source, Path::new("main.ron"), &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<(&str, usize)> = s
        .prototypes
        .iter()
        .map(|(n, p)| (n.as_str(), p.value.objects.len()))
        .collect();
    // The later `p` replaces the included one in its place.
    assert_eq!(names, [("p", 2), ("q", 1)]);
    let order: Vec<&str> = s
        .instances
        .iter()
        .map(|i| i.value.prototype.value.as_str())
        .collect();
    assert_eq!(order, ["p", "q", "p"]);
}

#[test]
fn keyed_instances_are_found_by_name() {
    let s = scene(&format!(
        r#"{GEAR}    instances: [(prototype: "gear", name: "g0"), (prototype: "gear", name: "g1")],
    animation: (frames: (0, 9), objects: {{ "g1": (translate: (keys: [(0, (0, 0, 0)), (9, (1, 0, 0))])), "ball": (scale: (keys: [(0, (1, 1, 1))])) }}),"#
    ));
    let a = s.animation.unwrap().value;
    assert_eq!(a.instances.len(), 1);
    assert_eq!(
        (a.instances[0].object, a.instances[0].name.value.as_str()),
        (1, "g1")
    );
    assert_eq!(a.objects.len(), 1);
    assert_eq!(a.objects[0].name.value, "ball");
    check(
        &format!(
            r#"{GEAR}    instances: [(prototype: "gear", name: "g0")],
    animation: (frames: (0, 9), objects: {{ "g9": (scale: (keys: [(0, (1, 1, 1))])) }}),"#
        ),
        7,
        "\"g9\"",
        &[
            "unknown object `g9`",
            "did you mean `g0`?",
            "expected one of `ball`, `g0`",
        ],
    );
}

#[test]
fn convert_writes_them_back() {
    let s = scene(&format!(
        r#"{GEAR}    instances: [
        (prototype: "gear", name: "g1", world_from_object: (rotate: (axis: (1, 2, 3), degrees: 15), scale: (2, 2, 2)), material: "glass"),
        (prototype: "gear", world_from_object: (matrix: ((0.1, 0, 0, 4), (0, 1, 0, 0), (0, 0, 1, 0)))),
    ],"#
    ));
    let text = to_ron(&s, Path::new("")).unwrap();
    assert!(
        text.contains("    prototypes: {\n        \"gear\": (objects: [\n"),
        "{text}"
    );
    let back = load_ron_str(&text, Path::new("b.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"));
    let values = |d: &SceneDesc| {
        let i: Vec<(String, TransformDesc, Option<String>, Option<String>)> = d
            .instances
            .iter()
            .map(|i| {
                let i = &i.value;
                (
                    i.prototype.value.clone(),
                    i.world_from_object.value,
                    i.name.as_ref().map(|n| n.value.clone()),
                    i.material.as_ref().map(|m| m.value.clone()),
                )
            })
            .collect();
        let p: Vec<(String, Vec<(String, String)>)> = d
            .prototypes
            .iter()
            .map(|(n, p)| {
                let o = p.value.objects.iter();
                let o = o.map(|o| {
                    (
                        o.value.call.plugin.value.clone(),
                        o.value.call.params.clone(),
                    )
                });
                (n.clone(), o.collect())
            })
            .collect();
        (i, p)
    };
    assert_eq!(values(&back), values(&s));
}

#[test]
fn prototype_meshes_are_read_after_merging() {
    let dir = std::env::temp_dir().join(format!("luxon-fmt-inst-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("tri.obj"),
        "mtllib tri.mtl\nusemtl shiny\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(dir.join("tri.mtl"), "newmtl shiny\nKd 0.5 0.5 0.5\n").unwrap();
    let path = dir.join("s.ron");
    let text = |mesh: &str| {
        format!(
            "Scene(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    materials: {{ \"red\": (color: (1, 0, 0)) }},\n    prototypes: {{ \"t\": (meshes: [{mesh}]) }},\n    instances: [(prototype: \"t\")],\n)\n"
        )
    };
    let s = load_ron_str(&text(r#"(file: "tri.obj")"#), &path).unwrap_or_else(|e| panic!("{e}"));
    let p = &s.prototypes[0].1.value;
    assert!(p.mesh_files.is_empty() && s.inline.is_empty());
    assert_eq!(p.inline.len(), 1);
    assert_eq!(p.inline[0].mesh.indices.len(), 1);
    // The file's own material joins the scene's.
    let own = &p.inline[0].material.as_ref().unwrap().value;
    assert_eq!(own, "obj:tri:shiny");
    assert!(s.materials.iter().any(|(n, _)| n == own));
    let s = load_ron_str(&text(r#"(file: "tri.obj", material: "red")"#), &path).unwrap();
    assert_eq!(
        s.prototypes[0].1.value.inline[0]
            .material
            .as_ref()
            .unwrap()
            .value,
        "red"
    );
    let e = load_ron_str(&text(r#"(file: "tri.obj", material: "rd")"#), &path).unwrap_err();
    assert!(
        e.to_string()
            .contains("s.ron:4:62: unknown material `rd`; did you mean `red`?"),
        "{e}"
    );
    let e = load_ron_str(&text(r#"(file: "missing.obj")"#), &path).unwrap_err();
    assert!(e.to_string().contains("s.ron:4:41:"), "{e}");
    let e = load_ron_str(&text(r#"(file: "")"#), &path).unwrap_err();
    assert!(
        e.to_string()
            .contains("s.ron:4:41: the mesh file name is empty"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn instancing_is_a_render_setting_written_back_when_not_auto() {
    assert_eq!(scene("").render.instancing, Instancing::Auto);
    for (text, want) in [
        ("Auto", Instancing::Auto),
        ("Bake", Instancing::Bake),
        ("Share", Instancing::Share),
    ] {
        let s = scene(&format!("    render: (instancing: {text}),"));
        assert_eq!(s.render.instancing, want);
        let ron = to_ron(&s, Path::new("")).unwrap();
        assert_eq!(
            ron.contains("instancing:"),
            want != Instancing::Auto,
            "{ron}"
        );
        let back = load_ron_str(&ron, Path::new("b.ron")).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back.render.instancing, want);
    }
    check(
        "    render: (instancing: Shared),",
        5,
        "Shared",
        &["Auto", "Bake", "Share"],
    );
}
