//! The OBJ importer: triangulation, indices, normals, uvs, MTL materials, `meshes:` in RON.

use std::path::{Path, PathBuf};

use luxon_formats::obj::load_obj;
use luxon_formats::{load, InlineGeometry, SceneError};

mod common;
use common::TempDir;

fn temp_dir(name: &str) -> TempDir {
    TempDir::new(&format!("obj-{name}"))
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn only(g: &[InlineGeometry]) -> &InlineGeometry {
    assert_eq!(g.len(), 1, "{g:#?}");
    &g[0]
}

const QUAD: &str = "\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
f 1 2 3 4
";

#[test]
fn a_quad_becomes_two_triangles() {
    let dir = temp_dir("quad");
    let obj = load_obj(&write(&dir, "quad.obj", QUAD), None).unwrap();
    let g = only(&obj.geometry);
    assert_eq!(g.mesh.indices.len(), 2);
    assert_eq!(g.mesh.positions.len(), 4);
    assert!(g.material.is_none());
    assert!(obj.warnings.is_empty());
}

#[test]
fn vertex_colours_are_kept_per_vertex() {
    let dir = temp_dir("colours");
    let text = "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 0.5 -0.5 1\nf 1 2 3 4\n";
    let obj = load_obj(&write(&dir, "c.obj", text), None).unwrap();
    let g = only(&obj.geometry);
    assert_eq!(g.mesh.colors.len(), g.mesh.positions.len());
    // Each position keeps its colour (a negative component taken as 0).
    for (p, c) in g.mesh.positions.iter().zip(&g.mesh.colors) {
        let want = match [p[0], p[1]] {
            [0.0, 0.0] => [1.0, 0.0, 0.0],
            [1.0, 0.0] => [0.0, 1.0, 0.0],
            [1.0, 1.0] => [0.0, 0.0, 1.0],
            _ => [0.5, 0.0, 1.0],
        };
        assert_eq!(*c, want, "at {p:?}");
    }
    // Without colours, none.
    let plain = load_obj(&write(&dir, "q.obj", QUAD), None).unwrap();
    assert!(only(&plain.geometry).mesh.colors.is_empty());
}

#[test]
fn negative_indices_count_back_from_the_last_vertex() {
    let dir = temp_dir("neg");
    let text = "v 5 5 5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n";
    let obj = load_obj(&write(&dir, "neg.obj", text), None).unwrap();
    let m = &only(&obj.geometry).mesh;
    assert_eq!(m.indices.len(), 1);
    let tri: Vec<[f64; 3]> = m.indices[0]
        .iter()
        .map(|&i| m.positions[i as usize])
        .collect();
    assert_eq!(tri, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
}

#[test]
fn missing_normals_are_computed_unit_and_outward() {
    let dir = temp_dir("normals");
    // Counter-clockwise seen from +z: the front faces +z.
    let obj = load_obj(&write(&dir, "quad.obj", QUAD), None).unwrap();
    let m = &only(&obj.geometry).mesh;
    assert_eq!(m.normals.len(), m.positions.len());
    for n in &m.normals {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-12, "{n:?}");
        assert!((n[2] - 1.0).abs() < 1e-12, "{n:?}");
    }
}

#[test]
fn given_normals_and_uvs_are_kept_per_vertex() {
    let dir = temp_dir("uvs");
    let text = "\
v 0 0 0
v 1 0 0
v 0 1 0
vt 0 0
vt 1 0
vt 0 1
vn 0 0 -1
f 1/1/1 2/2/1 3/3/1
";
    let obj = load_obj(&write(&dir, "uv.obj", text), None).unwrap();
    let m = &only(&obj.geometry).mesh;
    assert_eq!(m.uvs.len(), m.positions.len());
    for (i, p) in m.positions.iter().enumerate() {
        assert_eq!(m.uvs[i], [p[0], p[1]]);
        assert_eq!(m.normals[i], [0.0, 0.0, -1.0]);
    }
}

#[test]
fn mtl_materials_are_mapped() {
    let dir = temp_dir("mtl");
    write(
        &dir,
        "lib.mtl",
        "newmtl gold\nKd 1 0.5 0.25\nKa 0.3 0.3 0.3\nKs 0.6 0.3 0.0\nNs 50\nd 0.75\nNi 1.5\n\
         newmtl glass\nKd 1 1 1\nTr 0.9\n",
    );
    let text = format!("mtllib lib.mtl\n{QUAD}usemtl gold\nf 1 2 3\nusemtl glass\nf 1 3 4\n");
    let obj = load_obj(&write(&dir, "thing.obj", &text), None).unwrap();
    assert!(obj.warnings.is_empty(), "{:?}", obj.warnings);
    let names: Vec<&str> = obj.materials.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["obj:thing:gold", "obj:thing:glass"]);
    let gold = &obj.materials[0].1.value;
    assert_eq!(gold.color, [1.0, 0.5, 0.25]);
    assert!((gold.ambient - 0.3).abs() < 1e-12);
    assert!((gold.specular - 0.3).abs() < 1e-12);
    assert_eq!(gold.shininess, 50.0);
    assert!((gold.transmit - 0.25).abs() < 1e-12);
    assert_eq!(gold.ior, 1.5);
    assert!((obj.materials[1].1.value.transmit - 0.9).abs() < 1e-12);
    // One mesh per material: the untextured quad, then gold, then glass.
    let used: Vec<Option<&str>> = obj
        .geometry
        .iter()
        .map(|g| g.material.as_ref().map(|m| m.value.as_str()))
        .collect();
    assert_eq!(
        used,
        [None, Some("obj:thing:gold"), Some("obj:thing:glass")]
    );
}

#[test]
fn a_missing_mtl_is_a_warning() {
    let dir = temp_dir("nomtl");
    let text = format!("mtllib gone.mtl\nusemtl red\n{QUAD}");
    let obj = load_obj(&write(&dir, "a.obj", &text), None).unwrap();
    assert_eq!(obj.warnings.len(), 1, "{:?}", obj.warnings);
    let w = obj.warnings[0].to_string();
    // At the `mtllib` line, naming the library and saying what happened.
    assert!(
        w.starts_with(&format!("{}:1:1: ", dir.join("a.obj").display())),
        "{w}"
    );
    assert!(w.contains("gone.mtl`: it does not exist"), "{w}");
    assert!(obj.materials.is_empty());
    assert!(only(&obj.geometry).material.is_none());
}

#[test]
fn load_makes_a_scene_looking_at_the_mesh() {
    let dir = temp_dir("scene");
    let scene = load(&write(&dir, "quad.OBJ", QUAD)).unwrap();
    assert_eq!(scene.inline.len(), 1);
    assert_eq!((scene.render.width, scene.render.height), (512, 512));
    assert_eq!(scene.lights.len(), 1);
    let c = &scene.camera.value;
    assert_eq!(c.look_at, [0.5, 0.5, 0.0]);
    assert!(c.position[2] < -1.0, "{:?}", c.position);
}

#[test]
fn parse_errors_name_file_and_line() {
    let dir = temp_dir("bad");
    let p = write(&dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n");
    let e = load_obj(&p, None).unwrap_err().to_string();
    assert!(e.contains("bad.obj:3:"), "{e}");
    let p = write(&dir, "oob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n");
    let e = load_obj(&p, None).unwrap_err().to_string();
    assert!(
        e.contains("oob.obj:5:") && e.contains("out of bounds"),
        "{e}"
    );
}

#[test]
fn meshes_in_a_ron_scene_land_in_inline() {
    let dir = temp_dir("ron");
    write(&dir, "lib.mtl", "newmtl red\nKd 1 0 0\n");
    std::fs::create_dir_all(dir.join("models")).unwrap();
    write(
        &dir,
        "models/quad.obj",
        &format!("mtllib ../lib.mtl\nusemtl red\n{QUAD}"),
    );
    let scene_text = r#"(
    camera: (position: (0, 0, -4), look_at: (0, 0, 0)),
    materials: { "gold": (color: (1, 0.8, 0.2)) },
    meshes: [
        (file: "models/quad.obj", material: "gold"),
        (file: "models/quad.obj"),
    ],
)"#;
    let path = write(&dir, "scene.ron", scene_text);
    let scene = load(&path).unwrap();
    assert_eq!(scene.inline.len(), 2);
    let m0 = scene.inline[0].material.as_ref().unwrap();
    assert_eq!(m0.value, "gold");
    assert_eq!(m0.at.line, 5);
    let m1 = scene.inline[1].material.as_ref().unwrap();
    assert_eq!(m1.value, "obj:quad:red");
    let (_, red) = scene
        .materials
        .iter()
        .find(|(n, _)| n == "obj:quad:red")
        .unwrap();
    assert_eq!(red.value.color, [1.0, 0.0, 0.0]);
    assert_eq!(scene.inline[0].mesh.indices.len(), 2);
}

#[test]
fn a_missing_mesh_file_is_reported_at_its_name() {
    let dir = temp_dir("ron-missing");
    let scene_text = "(\n    camera: (position: (0, 0, -4), look_at: (0, 0, 0)),\n    meshes: [(file: \"nope.obj\")],\n)";
    let path = write(&dir, "scene.ron", scene_text);
    let e = load(&path).unwrap_err();
    let at = e.origin().expect("a position").clone();
    assert_eq!((at.line, at.col), (3, 21), "{e}"); // the opening quote
    assert!(e.to_string().contains("nope.obj"), "{e}");

    let scene_text = "(\n    camera: (position: (0, 0, -4), look_at: (0, 0, 0)),\n    meshes: [(file: \"a.obj\", material: \"gld\")],\n)";
    let path = write(&dir, "scene2.ron", scene_text);
    let e = load(&path).unwrap_err();
    assert!(matches!(e, SceneError::At { .. }));
    assert!(e.to_string().contains("unknown material `gld`"), "{e}");
}

/// Faces of 1 or 2 corners are errors at their line, in the words NFF uses for polygons
/// (tobj would drop them silently).
#[test]
fn faces_with_fewer_than_three_corners_are_errors() {
    let dir = temp_dir("short");
    for (face, found) in [("f 1 2", 2), ("f 3", 1), ("f", 0)] {
        let p = write(&dir, "short.obj", &format!("{QUAD}\n{face}\n"));
        let e = load_obj(&p, None).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{}:7:1: a face needs at least 3 vertices, found {found}",
                p.display()
            )
        );
    }
}

/// Lines and points are OBJ, but Luxon draws neither: left out, with a warning per kind
/// that counts them.
#[test]
fn lines_and_points_are_left_out_with_a_warning() {
    let dir = temp_dir("lp");
    let p = write(&dir, "lp.obj", &format!("{QUAD}l 1 2\nl 2 3 4\np 1\n"));
    let obj = load_obj(&p, None).unwrap();
    assert_eq!(only(&obj.geometry).mesh.indices.len(), 2);
    let w: Vec<String> = obj.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        w,
        [
            format!(
                "{}:6:1: 2 line (`l`) statement(s), the first here: Luxon draws faces only, so \
                 they are left out",
                p.display()
            ),
            format!(
                "{}:8:1: 1 point (`p`) statement(s), the first here: Luxon draws faces only, so \
                 they are left out",
                p.display()
            ),
        ]
    );
}

/// A material defined twice: the last definition, in the first one's place, with a warning.
#[test]
fn a_material_defined_twice_takes_the_last_definition() {
    let dir = temp_dir("newmtl");
    write(
        &dir,
        "m.mtl",
        "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\nnewmtl red\nKd 0.7 0 0\nnewmtl red\nKd 0.5 0 0\n\
         newmtl blue\n",
    );
    let p = write(&dir, "m.obj", &format!("mtllib m.mtl\nusemtl red\n{QUAD}"));
    let obj = load_obj(&p, None).unwrap();
    let names: Vec<&str> = obj.materials.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["obj:m:red", "obj:m:blue"]);
    assert_eq!(obj.materials[0].1.value.color, [0.5, 0.0, 0.0]);
    assert_eq!(obj.warnings.len(), 1, "{:?}", obj.warnings);
    // One warning for all repeats.
    assert_eq!(
        obj.warnings[0].message,
        "material `red` is defined more than once in its material libraries; the last \
         definition is used (2 more repeated definitions)"
    );
}

/// In a RON scene's `meshes:`, the OBJ's warnings join the scene's, at the `file` string.
#[test]
fn mesh_warnings_are_the_scene_warnings() {
    let dir = temp_dir("meshwarn");
    write(&dir, "w.obj", &format!("mtllib gone.mtl\n{QUAD}"));
    let main = write(
        &dir,
        "main.ron",
        "Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), meshes: [(file: \"w.obj\")])",
    );
    let scene = load(&main).unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    assert_eq!((&**w.at.file, w.at.line, w.at.col), (main.as_path(), 1, 75));
    assert!(
        w.message.starts_with(&format!(
            "in mesh file {}:1: cannot use material library",
            dir.join("w.obj").display()
        )),
        "{w}"
    );
}
