//! `animation:`: what it reads (frames, fps, shutter, tracks of the camera, lights, materials
//! and named objects), how it merges with `include`, and every error at its `line:col`.

mod common;

use std::path::Path;

use luxon_formats::*;

/// Line 2: a camera; line 3: two named lights; line 4: materials; line 5: two objects, one
/// named. The body given to `scene` starts on line 6.
const HEAD: &str = r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: 40),
    lights: [Point(name: "key", position: (1, 2, 3)), Directional(name: "sun", direction: (0, -1, 0))],
    materials: { "red": (color: (1, 0, 0)), "blue": (color: (0, 0, 1)) },
    objects: [(plugin: "sphere", name: "ball", params: ()), (plugin: "sphere", params: ())],
"#;

fn load(body: &str) -> Result<SceneDesc, SceneError> {
    load_ron_str(&format!("{HEAD}{body}\n)"), Path::new("a.ron"))
}

fn animation(body: &str) -> AnimationDesc {
    let scene = load(body).unwrap_or_else(|e| panic!("{e}"));
    scene.animation.expect("the scene is animated").value
}

/// Checks that the error is at the first `needle` on line `line` of the scene text and that
/// its message holds `words`.
#[track_caller]
fn check(body: &str, line: u32, needle: &str, words: &[&str]) {
    let e = load(body).expect_err("the scene is invalid");
    common::assert_error_at(&format!("{HEAD}{body}"), &e, line, needle, words);
}

#[test]
fn a_still_scene_has_no_animation() {
    assert_eq!(load("").unwrap().animation, None);
}

#[test]
fn reads_frames_fps_shutter_and_every_kind_of_track() {
    let a = animation(
        r#"    animation: (
        frames: (0, 47), fps: 30, shutter: (length: 0.5, at: Start),
        camera: (
            position: (keys: [(0, (0, 0, -5)), (24, (5, 0, 0)), (47.5, (0, 0, 5))], interpolation: CatmullRom),
            look_at: (keys: [(0, (0, 1, 0))]),
            up: (keys: [(0, (0, 1, 0)), (10, (1, 1, 0))]),
            fov: (keys: [(0, 40), (47, 20)]),
        ),
        lights: { "key": (intensity: (keys: [(0, 1), (10, 0)]), color: (keys: [(0, (1, 1, 1))])),
                  "sun": (direction: (keys: [(0, (0, -1, 0)), (5, (1, -1, 0))])) },
        materials: { "red": (color: (keys: [(0, (1, 0, 0)), (47, (0, 1, 0))])) },
        objects: { "ball": (translate: (keys: [(0, (0, 0, 0)), (12, (0, 2, 0))]),
                            rotate: (keys: [(0, (axis: (0, 0, 2), degrees: 0)), (47, (axis: (0, 0, 1), degrees: 360))]),
                            scale: (keys: [(3, (1, 1, 1)), (4, (2, 2, 2))])) },
    ),"#,
    );
    assert_eq!((a.first, a.last, a.fps), (0, 47, 30.0));
    let shutter = a.shutter.unwrap().value;
    assert_eq!(shutter.at, ShutterAt::Start);
    assert_eq!(shutter.interval(), (0.0, 0.5));
    let position = a.camera.position.unwrap();
    assert_eq!(position.interpolation, Interpolate::CatmullRom);
    let frames: Vec<f64> = position.keys.iter().map(|k| k.frame).collect();
    assert_eq!(frames, [0.0, 24.0, 47.5]);
    assert_eq!(position.keys[1].value, [5.0, 0.0, 0.0]);
    assert_eq!((position.keys[1].at.line, position.keys[1].at.col), (9, 49));
    assert_eq!(a.camera.fov.unwrap().interpolation, Interpolate::Linear);
    assert!(a.camera.focal_distance.is_none());
    assert_eq!(a.lights.len(), 2);
    assert_eq!((a.lights[0].light, a.lights[1].light), (0, 1));
    assert!(a.lights[1].direction.is_some() && a.lights[1].position.is_none());
    assert_eq!(a.materials[0].material.value, "red");
    let ball = &a.objects[0];
    assert_eq!((ball.object, ball.name.value.as_str()), (0, "ball"));
    let rotate = ball.rotate.as_ref().unwrap();
    // Axes are made unit length, so keys about one axis compare equal.
    assert_eq!(rotate.keys[0].value.axis, [0.0, 0.0, 1.0]);
    assert_eq!(rotate.keys[0].value.axis, rotate.keys[1].value.axis);
    assert_eq!(rotate.keys[1].value.degrees, 360.0);
}

#[test]
fn defaults_are_24_fps_and_no_shutter_and_the_centre() {
    let a = animation("    animation: (frames: (5, 5), shutter: (length: 1)),");
    assert_eq!((a.first, a.last, a.fps), (5, 5, 24.0));
    assert_eq!(a.shutter.unwrap().value.interval(), (-0.5, 0.5));
    let a = animation("    animation: (frames: (0, 1)),");
    assert!(a.shutter.is_none() && a.camera.is_empty() && a.objects.is_empty());
}

#[test]
fn the_frame_range_must_be_whole_and_not_empty() {
    check(
        "    animation: (frames: (48, 0)),",
        6,
        "(48, 0)",
        &["the frame range 48..0 is empty", "first <= last"],
    );
    let whole = ["whole number from 0 to 4294967295"];
    check("    animation: (frames: (0, 1.5)),", 6, "1.5", &whole);
    check(
        "    animation: (frames: (-1, 3)),",
        6,
        "-1",
        &["`frames` is -1"],
    );
    check(
        "    animation: (frames: (0, 3), fps: 0),",
        6,
        "0),",
        &["`fps` is 0"],
    );
    check(
        "    animation: (frames: (0, 3), shutter: (length: 3)),",
        6,
        "3))",
        &["`length` is 3", "from 0 to 2"],
    );
    check(
        "    animation: (fps: 3),",
        6,
        "(fps",
        &["missing field `frames`"],
    );
}

#[test]
fn keys_must_increase() {
    let body = r#"    animation: (frames: (0, 9), camera: (
        position: (keys: [(0, (0, 0, -5)), (36, (1, 0, -5)), (24, (2, 0, -5))]),
    )),"#;
    check(
        body,
        7,
        "24,",
        &[
            "key frames must increase: frame 24 comes after frame 36",
            "`camera.position`",
        ],
    );
    let body = r#"    animation: (frames: (0, 9), lights: {
        "key": (intensity: (keys: [(0, 1), (12, 2), (12, 3)])),
    }),"#;
    check(
        body,
        7,
        "12, 3",
        &[
            "frame 12 is keyed twice",
            "`lights.key.intensity`",
            "first at 7:45",
        ],
    );
    let body = "    animation: (frames: (0, 9), materials: { \"red\": (color: (keys: [])) }),";
    check(body, 6, "[]", &["the track has no keys"]);
}

#[test]
fn a_property_that_cannot_animate_is_named() {
    check(
        "    animation: (frames: (0, 9), camera: (aspect: (keys: [(0, 1)]))),",
        6,
        "aspect",
        &[
            "the camera's `aspect` cannot be animated",
            "expected one of `position`, `look_at`, `up`, `fov`, `focal_distance`",
        ],
    );
    check(
        "    animation: (frames: (0, 9), camera: (positon: (keys: [(0, (1, 2, 3))]))),",
        6,
        "positon",
        &["`positon` cannot be animated", "did you mean `position`?"],
    );
    check(
        "    animation: (frames: (0, 9), lights: { \"key\": (samples: (keys: [(0, 4)])) }),",
        6,
        "samples",
        &["a light's `samples` cannot be animated"],
    );
    check(
        "    animation: (frames: (0, 9), materials: { \"red\": (specular: (keys: [(0, 1)])) }),",
        6,
        "specular",
        &["a material's `specular` cannot be animated", "`color`"],
    );
    check(
        "    animation: (frames: (0, 9), objects: { \"ball\": (radius: (keys: [(0, 1)])) }),",
        6,
        "radius",
        &["an object's `radius` cannot be animated", "`translate`"],
    );
    // The light's kind decides, after merging.
    check(
        "    animation: (frames: (0, 9), lights: { \"sun\": (position: (keys: [(0, (1, 2, 3))])) }),",
        6,
        "(keys",
        &[
            "light `sun` is Directional: it has no `position` to animate",
            "`direction`, `intensity`, `color`",
        ],
    );
    check(
        "    animation: (frames: (0, 9), lights: { \"key\": (direction: (keys: [(0, (1, 2, 3))])) }),",
        6,
        "(keys",
        &["light `key` is Point: it has no `direction`"],
    );
}

#[test]
fn values_are_checked_at_the_value() {
    check(
        "    animation: (frames: (0, 9), materials: { \"red\": (color: (keys: [(0, (1, -0.5, 0))])) }),",
        6,
        "-0.5",
        &["negative component -0.5"],
    );
    check(
        "    animation: (frames: (0, 9), camera: (fov: (keys: [(0, 40), (9, 180)]))),",
        6,
        "180",
        &["`camera.fov` is 180", "between 0 and 180"],
    );
    check(
        "    animation: (frames: (0, 9), lights: { \"key\": (intensity: (keys: [(0, -1)])) }),",
        6,
        "-1",
        &["`lights.key.intensity` is -1"],
    );
    check(
        "    animation: (frames: (0, 9), objects: { \"ball\": (scale: (keys: [(0, (1, 0, 1))])) }),",
        6,
        "0, 1))",
        &["`objects.ball.scale` has a zero component"],
    );
    check(
        "    animation: (frames: (0, 9), objects: { \"ball\": (rotate: (keys: [(0, (axis: (0, 0, 0), degrees: 5))])) }),",
        6,
        "(0, 0, 0)",
        &["the rotation's `axis` has zero length"],
    );
    check(
        "    animation: (frames: (0, 9), camera: (fov: (keys: [(0, (1, 2, 3))]))),",
        6,
        "(1, 2, 3)",
        &["expected a number"],
    );
}

#[test]
fn a_long_turn_between_different_axes_is_refused() {
    let body = r#"    animation: (frames: (0, 9), objects: { "ball": (rotate: (keys: [
        (0, (axis: (0, 0, 1), degrees: 0)),
        (9, (axis: (1, 0, 0), degrees: 270)),
    ])) }),"#;
    check(
        body,
        8,
        "270",
        &[
            "turn about different axes",
            "270 degrees is reached as -90 degrees",
        ],
    );
    // About one axis a long turn is fine: the angle itself is interpolated.
    let a = animation(
        r#"    animation: (frames: (0, 9), objects: { "ball": (rotate: (keys: [
        (0, (axis: (1, 0, 0), degrees: 0)), (9, (axis: (2, 0, 0), degrees: 270))])) }),"#,
    );
    assert_eq!(a.objects[0].rotate.as_ref().unwrap().keys.len(), 2);
}

#[test]
fn names_are_resolved_after_merging() {
    check(
        "    animation: (frames: (0, 9), lights: { \"kye\": (intensity: (keys: [(0, 1)])) }),",
        6,
        "\"kye\"",
        &["unknown light `kye`", "did you mean `key`?", "`key`, `sun`"],
    );
    check(
        "    animation: (frames: (0, 9), materials: { \"green\": (color: (keys: [(0, (0, 1, 0))])) }),",
        6,
        "\"green\"",
        &["unknown material `green`", "`red`, `blue`"],
    );
    check(
        "    animation: (frames: (0, 9), objects: { \"bal\": (translate: (keys: [(0, (0, 1, 0))])) }),",
        6,
        "\"bal\"",
        &["unknown object `bal`", "did you mean `ball`?"],
    );
    check(
        "    animation: (frames: (0, 9), objects: { \"ball\": (), \"ball\": () }),",
        6,
        "\"ball\": () }",
        &["object `ball` is keyed twice", "first at 6:44"],
    );
    let text = "(camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n lights: [Point(name: \" \", position: (0, 0, 0))])";
    let e = load_ron_str(text, Path::new("n.ron")).expect_err("an empty name");
    assert!(
        e.to_string()
            .starts_with("n.ron:2:23: the light name is empty"),
        "{e}"
    );
}

/// A scene of its own camera (line 1) and animation (line 2): the error's line and column.
fn camera_error(camera: &str, animation: &str) -> (u32, u32, String) {
    let text = format!("(camera: {camera},\nanimation: {animation})");
    let e = load_ron_str(&text, Path::new("c.ron")).expect_err("invalid");
    let at = e.origin().unwrap().clone();
    (at.line, at.col, e.to_string())
}

#[test]
fn camera_tracks_need_the_camera_they_change() {
    let (line, col, message) = camera_error(
        "(position: (0, 0, -5), look_at: (0, 0, 0), zoom: 2)",
        "(frames: (0, 9), camera: (fov: (keys: [(0, 30)])))",
    );
    assert_eq!((line, col), (2, 43), "{message}");
    assert!(message.contains("`fov` keys need a perspective camera sized by `fov`"));
    let (line, col, message) = camera_error(
        "(position: (0, 0, -5), look_at: (0, 0, 0))",
        "(frames: (0, 9), camera: (focal_distance: (keys: [(0, 3)])))",
    );
    assert_eq!((line, col), (2, 54), "{message}");
    assert!(message.contains("`focal_distance` keys need the camera's `depth_of_field`"));
    let text =
        "(camera: (position: (0, 0, -5), look_at: (0, 0, 0), depth_of_field: (aperture: 0.1)),
        animation: (frames: (0, 9), camera: (focal_distance: (keys: [(0, 3)]))))";
    let scene = load_ron_str(text, Path::new("c.ron")).unwrap();
    assert!(scene
        .animation
        .unwrap()
        .value
        .camera
        .focal_distance
        .is_some());
}

#[test]
fn frame_and_time_belong_to_the_animation() {
    check(
        "    render: (frame: 3),\n    animation: (frames: (0, 9)),",
        6,
        "3)",
        &["`frame` and `time` cannot be set in a scene with `animation:`"],
    );
    // Without animation they stay what they were.
    let scene = load("    render: (frame: 3, time: 0.5),").unwrap();
    assert_eq!((scene.render.frame, scene.render.time), (3, 0.5));
}

#[test]
fn an_including_file_animates_what_it_includes() {
    let mut files = MemorySource::new();
    files.insert(
        "dir/base.ron",
        r#"(camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
            lights: [Point(name: "a", position: (0, 1, 0)), Point(name: "b", position: (0, 2, 0))],
            objects: [(plugin: "sphere", name: "one"), (plugin: "sphere", name: "two")],
            animation: (frames: (0, 1)))"#,
    );
    files.insert(
        "dir/top.ron",
        r#"(include: ["base.ron"],
            lights: [Point(name: "c", position: (0, 3, 0))],
            objects: [(plugin: "sphere"), (plugin: "sphere", name: "three")],
            animation: (frames: (2, 8),
                lights: { "c": (intensity: (keys: [(0, 1)])), "a": (intensity: (keys: [(0, 2)])) },
                objects: { "three": (translate: (keys: [(0, (1, 0, 0))])), "two": () }))"#,
    );
    let scene = load_ron_with(
        &mut files,
        Path::new("dir/top.ron"),
        &LoadOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // The last file's animation wins; names index the merged lists.
    let a = scene.animation.unwrap().value;
    assert_eq!((a.first, a.last), (2, 8));
    assert_eq!((a.lights[0].light, a.lights[1].light), (2, 0));
    assert_eq!((a.objects[0].object, a.objects[1].object), (3, 1));

    // A name is given once in the whole scene.
    files.insert(
        "dir/top.ron",
        r#"(include: ["base.ron"],
            objects: [(plugin: "sphere", name: "two")])"#,
    );
    let e = load_ron_with(
        &mut files,
        Path::new("dir/top.ron"),
        &LoadOptions::default(),
    )
    .expect_err("two objects named `two`");
    assert_eq!(
        e.to_string(),
        "dir/top.ron:2:48: the object name `two` is already used at dir/base.ron:3:81; \
         expected each object name once"
    );
}
