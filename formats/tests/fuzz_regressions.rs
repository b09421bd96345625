//! Inputs the fuzz targets (tests/fuzz) once crashed on: each must now end in a clear error.

use luxon_formats::obj::load_obj;
use std::path::Path;

fn case(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz-cases")
        .join(name)
}

/// tobj 4.0.5 multiplies a texture-coordinate index without checking for overflow; this OBJ
/// (mangled faces, a stray non-UTF-8 byte) made it panic. Found by `cargo fuzz run obj`.
#[test]
fn obj_face_index_overflow_in_tobj_is_an_error() {
    let path = case("obj-tobj-index-overflow.obj");
    let e = load_obj(&path, None)
        .expect_err("a malformed OBJ")
        .to_string();
    assert!(e.contains("obj-tobj-index-overflow.obj"), "{e}");
    assert!(e.contains("index") || e.contains("cannot read"), "{e}");
}

/// The `include_graph` fuzz target's body (tests/fuzz), run here over its seeds and the
/// shipped scenes, so the normal test suite exercises it.
#[path = "../../tests/fuzz/include_graph_body.rs"]
mod include_graph;

#[test]
fn include_graph_target_over_its_seeds() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let seeds = root.join("tests/fuzz/seeds/include_graph");
    let mut inputs: Vec<std::path::PathBuf> = Vec::new();
    for dir in [
        seeds.clone(),
        root.join("scenes"),
        root.join("scenes/include"),
    ] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_file() {
                inputs.push(path);
            }
        }
    }
    assert!(inputs.len() > 20, "{inputs:?}");
    for path in &inputs {
        let data = std::fs::read(path).unwrap();
        // Ok or an error: the body itself asserts that no file was read twice.
        let _ = include_graph::run(&data);
    }
    let seed = |name: &str| include_graph::run(&std::fs::read(seeds.join(name)).unwrap());
    assert_eq!(seed("diamond").unwrap().lights.len(), 2);
    assert_eq!(seed("double-diamond").unwrap().lights.len(), 1);
    assert_eq!(
        seed("chain").unwrap().camera.value.position,
        [0.0, 0.0, -5.0]
    );
    let repeat = seed("repeat-in-list").unwrap();
    assert_eq!((repeat.lights.len(), repeat.warnings.len()), (1, 2));
    for cyclic in ["cycle", "self-include"] {
        let e = seed(cyclic).unwrap_err().to_string();
        assert!(e.contains("include cycle"), "{cyclic}: {e}");
    }
    let e = seed("missing-and-outside").unwrap_err().to_string();
    assert!(e.contains("cannot read included file `../f2.ron`"), "{e}");
}
