//! The camera grammar: projections, frustum, depth of field and stereo; defaults; every error at
//! its `line:col`.

use std::path::Path;

use luxon_formats::*;

/// Loads `(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0), {fields}),\n)`: the camera
/// is on line 2 and `fields` start at column 56.
fn load(fields: &str) -> Result<CameraDesc, SceneError> {
    let text = format!("(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0), {fields}),\n)");
    load_ron_str(&text, Path::new("dir/cam.ron")).map(|s| s.camera.value)
}

fn camera(fields: &str) -> CameraDesc {
    load(fields).unwrap_or_else(|e| panic!("{fields}: {e}"))
}

/// Column where `fields` start on line 2.
const COL: u32 = 56;

/// The error's position (line 2, column of `needle` in `fields`) and the message's key words.
#[track_caller]
fn check_error(fields: &str, needle: &str, words: &[&str]) {
    let error = load(fields).expect_err("the camera is invalid");
    let at = error.origin().expect("the error has a position").clone();
    let message = error.to_string();
    let col = COL + fields.find(needle).expect("needle in fields") as u32;
    assert_eq!((at.line, at.col), (2, col), "wrong position for: {message}");
    for word in words {
        assert!(message.contains(word), "`{word}` missing from: {message}");
    }
}

#[test]
fn projections_parse() {
    let p = |fields: &str| camera(fields).projection;
    assert_eq!(
        p("projection: Perspective(fov: 30)"),
        Projection::Perspective { fov_deg: 30.0 }
    );
    assert_eq!(
        p("projection: Perspective(zoom: 2)"),
        Projection::PerspectiveZoom { zoom: 2.0 }
    );
    assert_eq!(
        p("projection: Perspective()"),
        Projection::Perspective { fov_deg: 45.0 }
    );
    assert_eq!(
        p("projection: Orthographic(height: 4)"),
        Projection::Orthographic { height: 4.0 }
    );
    assert_eq!(
        p("projection: Fisheye(fov: 220)"),
        Projection::Fisheye { fov_deg: 220.0 }
    );
    assert_eq!(
        p("projection: Fisheye()"),
        Projection::Fisheye { fov_deg: 180.0 }
    );
    assert_eq!(
        p("projection: Equirectangular"),
        Projection::Equirectangular
    );
    // A window of the panorama, in degrees.
    let window =
        "projection: Equirectangular, frustum: (left: -90, right: 60, bottom: -30, top: 45)";
    assert_eq!(
        camera(window).frustum,
        Some(Frustum {
            left: -90.0,
            right: 60.0,
            bottom: -30.0,
            top: 45.0
        })
    );
    // The shorthand of the first scenes.
    assert_eq!(p("fov: 40"), Projection::Perspective { fov_deg: 40.0 });
    assert_eq!(p("zoom: 1.5"), Projection::PerspectiveZoom { zoom: 1.5 });
    assert_eq!(
        p("up: (0, 1, 0)"),
        Projection::Perspective { fov_deg: 45.0 }
    );
}

#[test]
fn defaults_come_from_the_look_at_distance() {
    // Distance 5: a 45° camera sees 2·5·tan(22.5°) at look_at.
    let Projection::Orthographic { height } = camera("projection: Orthographic()").projection
    else {
        panic!("not orthographic");
    };
    assert!((height - 10.0 * 22.5f64.to_radians().tan()).abs() < 1e-12);
    let c = camera("depth_of_field: (aperture: 0.1), stereo: ()");
    assert_eq!(
        c.depth_of_field,
        Some(DepthOfField {
            aperture: 0.1,
            focal_distance: 5.0
        })
    );
    assert_eq!(
        c.stereo,
        Some(Stereo {
            layout: StereoLayout::SideBySide,
            eye_separation: 5.0 / 30.0,
            convergence: 5.0
        })
    );
    let c = camera("fov: 40");
    assert_eq!((c.frustum, c.depth_of_field, c.stereo), (None, None, None));
}

#[test]
fn frustum_depth_of_field_and_stereo_parse() {
    let c = camera(
        "frustum: (left: -1, right: 0.5, bottom: -0.25, top: 0.75), \
         depth_of_field: (aperture: 0.2, focal_distance: 7), \
         stereo: (layout: OverUnder, eye_separation: 0.065, convergence: 3)",
    );
    assert_eq!(
        c.frustum,
        Some(Frustum {
            left: -1.0,
            right: 0.5,
            bottom: -0.25,
            top: 0.75
        })
    );
    assert_eq!(
        c.depth_of_field,
        Some(DepthOfField {
            aperture: 0.2,
            focal_distance: 7.0
        })
    );
    assert_eq!(
        c.stereo,
        Some(Stereo {
            layout: StereoLayout::OverUnder,
            eye_separation: 0.065,
            convergence: 3.0
        })
    );
    assert_eq!(c.projection, Projection::Perspective { fov_deg: 45.0 });
    let c = camera("projection: Orthographic(), frustum: (left: -2, right: 2, bottom: -1, top: 1)");
    assert_eq!(
        c.projection,
        Projection::Orthographic {
            height: 10.0 * 22.5f64.to_radians().tan()
        }
    );
    assert!(c.frustum.is_some());
    // Stereo and depth of field work with every projection.
    let c = camera(
        "projection: Equirectangular, stereo: (layout: OverUnder), depth_of_field: (aperture: 0)",
    );
    assert!(c.stereo.is_some() && c.depth_of_field.is_some());
}

#[test]
fn projection_errors() {
    check_error(
        "projection: Perspective(fov: 180)",
        "180",
        &["`fov` is 180", "between 0 and 180"],
    );
    check_error(
        "projection: Perspective(fov: 30, zoom: 2)",
        "2)",
        &["both `fov` and `zoom`"],
    );
    check_error(
        "projection: Perspective(zoom: -1)",
        "-1",
        &["`zoom` is -1", "greater than 0"],
    );
    check_error(
        "projection: Orthographic(height: 0)",
        "0)",
        &["`height` is 0", "greater than 0"],
    );
    check_error(
        "projection: Fisheye(fov: 361)",
        "361",
        &["`fov` is 361", "fisheye", "360"],
    );
    check_error("projection: Fisheye(fov: 0)", "0)", &["`fov` is 0"]);
    check_error(
        "fov: 40, projection: Orthographic(height: 2)",
        "40",
        &["both `projection` and `fov`", "inside the projection"],
    );
    check_error(
        "projection: Fisheye(fov: 90), zoom: 2",
        "2",
        &["both `projection` and `zoom`"],
    );
    check_error(
        "projection: Equirectangular, aspect: 2",
        "2",
        &["`aspect` has no effect", "Equirectangular"],
    );
    check_error(
        "projection: Fishey(fov: 90)",
        "Fishey",
        &["unknown variant `Fishey`", "did you mean `Fisheye`?"],
    );
}

#[test]
fn frustum_errors() {
    let f = "frustum: (left: 1, right: 1, bottom: 0, top: 1)";
    check_error(
        f,
        "1, b",
        &["`right` (1) is not greater than its `left` (1)"],
    );
    let f = "frustum: (left: 0, right: 1, bottom: 0.5, top: -1)";
    check_error(
        f,
        "-1",
        &["`top` (-1) is not greater than its `bottom` (0.5)"],
    );
    let f = "fov: 30, frustum: (left: 0, right: 1, bottom: 0, top: 1)";
    check_error(f, "(left", &["both `fov` and `frustum`"]);
    let f = "projection: Orthographic(height: 2), frustum: (left: 0, right: 1, bottom: 0, top: 1)";
    check_error(f, "(left", &["both `height` and `frustum`"]);
    let f = "aspect: 2, frustum: (left: 0, right: 1, bottom: 0, top: 1)";
    check_error(f, "2", &["both `aspect` and `frustum`"]);
    let f = "projection: Fisheye(), frustum: (left: 0, right: 1, bottom: 0, top: 1)";
    check_error(
        f,
        "(left",
        &["Perspective, Orthographic or Equirectangular", "Fisheye"],
    );
    let f = "frustum: (left: 0, right: 1, bottom: 0)";
    check_error(f, "(left", &["top"]);
}

#[test]
fn depth_of_field_and_stereo_errors() {
    check_error(
        "depth_of_field: (aperture: -0.1)",
        "-0.1",
        &["`aperture` is -0.1", "0 or more"],
    );
    check_error(
        "depth_of_field: (aperture: 0.1, focal_distance: 0)",
        "0)",
        &["`focal_distance` is 0", "greater than 0"],
    );
    check_error(
        "stereo: (eye_separation: -1)",
        "-1",
        &["`eye_separation` is -1", "0 or more"],
    );
    check_error(
        "stereo: (convergence: 0)",
        "0)",
        &["`convergence` is 0", "greater than 0"],
    );
    check_error(
        "stereo: (layout: SideBySid)",
        "SideBySid",
        &["did you mean `SideBySide`?"],
    );
    check_error(
        "stereo: (separation: 1)",
        "separation",
        &["unknown field `separation`", "`eye_separation`"],
    );
}
