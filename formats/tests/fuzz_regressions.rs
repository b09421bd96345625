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
