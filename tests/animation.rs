//! Animated scenes: what each frame shows (keyed objects moving and turning, a material's
//! colour, a light's intensity, the camera), that a frame is the same bits whether rendered
//! alone, in a sequence, after other frames or on other thread counts, the `--frames` driver
//! (names, steps, failed frames) and the build's refusals.

mod common;

use common::{registry, run, stderr, temp_dir};
use luxon::{Framebuffer, Scene};
use std::path::{Path, PathBuf};

/// Orthographic, 64x32 pixels over x in [-2, 2], y in [-1, 1] (16 pixels per unit), black
/// background. `ball` moves right and turns from red to blue, `lit` is lit by `sun`, whose
/// intensity falls, and `bar` turns a quarter turn about z; frames 0 to 2.
const SCENE: &str = r#"Scene(
    camera: (position: (0, 0, 10), look_at: (0, 0, 0), projection: Orthographic(height: 2)),
    lights: [Directional(name: "sun", direction: (0, 0, -1), shadows: false)],
    materials: {
        "paint": (color: (1, 0, 0), ambient: 1, diffuse: 0),
        "matte": (color: (1, 1, 1), ambient: 0, diffuse: 1),
        "green": (color: (0, 1, 0), ambient: 1, diffuse: 0),
    },
    objects: [
        (plugin: "sphere", name: "ball", params: (center: (0, 0, 0), radius: 0.35), material: "paint"),
        (plugin: "sphere", name: "lit", params: (center: (-1.2, 0.5, 0), radius: 0.35), material: "matte"),
        (plugin: "cylinder", name: "bar", params: (base: (-0.45, 0, 0), apex: (0.45, 0, 0), radius: 0.08), material: "green"),
    ],
    animation: (
        frames: (0, 2),
        lights: { "sun": (intensity: (keys: [(0, 1), (2, 0.2)])) },
        materials: { "paint": (color: (keys: [(0, (1, 0, 0)), (2, (0, 0, 1))])) },
        objects: {
            "ball": (translate: (keys: [(0, (-1.2, -0.5, 0)), (2, (0.4, -0.5, 0))])),
            "bar": (translate: (keys: [(0, (1.2, 0.3, 0))]),
                    rotate: (keys: [(0, (axis: (0, 0, 1), degrees: 0)), (2, (axis: (0, 0, 1), degrees: 90))])),
        },
    ),
    render: (width: 64, height: 32, outputs: [(path: "out.ppm")]),
)
"#;

fn write_scene(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("scene.ron");
    std::fs::write(&p, text).unwrap();
    p
}

fn build(text: &str, dir: &Path) -> Scene {
    let path = write_scene(dir, text);
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    Scene::build(&desc, &registry(&desc)).unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Scene) -> Framebuffer {
    luxon::render::render(scene, &|_, _| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// Linear RGB at pixel (x, y).
fn px(fb: &Framebuffer, x: u32, y: u32) -> [f32; 3] {
    let i = 4 * (y * fb.width + x) as usize;
    [fb.rgba[i], fb.rgba[i + 1], fb.rgba[i + 2]]
}

#[track_caller]
fn near(a: [f32; 3], b: [f32; 3]) {
    let d = (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f32::max);
    assert!(d < 1e-3, "{a:?} is not {b:?}");
}

const BLACK: [f32; 3] = [0.0; 3];

#[test]
fn each_frame_shows_its_keyed_values() {
    let dir = temp_dir("anim-values");
    let mut scene = build(SCENE, &dir);
    let mut frames = Vec::new();
    for k in 0..3 {
        scene.set_frame(k).unwrap();
        frames.push(render(&scene));
    }
    // The ball at x = -1.2, -0.4, 0.4 (pixels 12.8, 25.6, 38.4) on row 24; red, purple, blue.
    for (k, fb) in frames.iter().enumerate() {
        let colour = [1.0 - 0.5 * k as f32, 0.0, 0.5 * k as f32];
        for (j, x) in [12, 25, 38].into_iter().enumerate() {
            near(px(fb, x, 24), if j == k { colour } else { BLACK });
        }
    }
    // `lit` faces the light: it dims with the intensity, 1 then 0.6 then 0.2.
    let full = px(&frames[0], 12, 8)[0];
    assert!(full > 0.9, "{full}");
    for (k, fb) in frames.iter().enumerate() {
        let i = 1.0 - 0.4 * k as f32;
        near(px(fb, 12, 8), [full * i; 3]);
    }
    // The bar turns from along x (a point 0.35 right of its centre) to along y (0.35 above).
    let green = [0.0, 1.0, 0.0];
    near(px(&frames[0], 56, 11), green);
    near(px(&frames[0], 51, 5), BLACK);
    near(px(&frames[2], 56, 11), BLACK);
    near(px(&frames[2], 51, 5), green);
    // Halfway, 45 degrees: both points are off the bar, the diagonal is on it.
    near(px(&frames[1], 56, 11), BLACK);
    near(px(&frames[1], 55, 7), green);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_frame_is_the_same_whatever_came_before() {
    let dir = temp_dir("anim-pure");
    let mut scene = build(SCENE, &dir);
    // The build leaves the scene at its first frame.
    let built = render(&scene);
    scene.set_frame(0).unwrap();
    assert_eq!(render(&scene).rgba, built.rgba);
    scene.set_frame(2).unwrap();
    let two = render(&scene);
    assert_ne!(two.rgba, built.rgba);
    for before in [[0, 1], [40, 7], [2, 2]] {
        for k in before {
            scene.set_frame(k).unwrap();
        }
        scene.set_frame(2).unwrap();
        assert_eq!(render(&scene).rgba, two.rgba, "after frames {before:?}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn frames_outside_the_range_hold_the_ends() {
    let dir = temp_dir("anim-hold");
    let mut scene = build(SCENE, &dir);
    scene.set_frame(2).unwrap();
    let last = render(&scene);
    scene.set_frame(1000).unwrap();
    assert_eq!(render(&scene).rgba, last.rgba);
    assert_eq!(scene.settings.frame, 1000);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_camera_follows_its_keys() {
    let dir = temp_dir("anim-camera");
    // The camera slides one unit right: the sphere at the origin moves 16 pixels left. The
    // world offset is the camera at the first frame, so frame 2 is still rendered near it.
    let text = SCENE.replace(
        "        frames: (0, 2),",
        "        frames: (0, 2),
        camera: (position: (keys: [(0, (0, 0, 10)), (2, (1, 0, 10))]),
                 look_at: (keys: [(0, (0, 0, 0)), (2, (1, 0, 0))])),",
    );
    let mut scene = build(&text, &dir);
    assert_eq!(scene.world_offset.to_array(), [0.0, 0.0, 10.0]);
    scene.set_frame(2).unwrap();
    let fb = render(&scene);
    // The ball (at x = 0.4 now) appears at 38.4 - 16 = 22.4.
    near(px(&fb, 22, 24), [0.0, 0.0, 1.0]);
    near(px(&fb, 38, 24), BLACK);
    let _ = std::fs::remove_dir_all(dir);
}

/// The P6 files of `dir`, by name (not the hidden directory of frame records).
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| !e.file_name().to_string_lossy().ends_with(".luxon-frames"))
        .map(|e| {
            (
                e.file_name().to_string_lossy().to_string(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn a_frame_alone_equals_the_same_frame_of_a_sequence() {
    let dir = temp_dir("anim-cli");
    let scene = write_scene(
        &dir,
        &SCENE.replace("width: 64, height: 32", "width: 96, height: 48, samples: 4"),
    );
    let s = scene.to_str().unwrap();
    let seq = dir.join("seq");
    let o = run(&[
        "render",
        s,
        "--frames",
        "0..2",
        "--threads",
        "1",
        "-o",
        seq.join("f%d.ppm").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("f2.ppm (frame 2, 3 of 3"), "{err}");
    let seq_files = files(&seq);
    let names: Vec<&str> = seq_files.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["f0.ppm", "f1.ppm", "f2.ppm"]);
    // The frames differ from each other, and are not black.
    assert_ne!(seq_files[0].1, seq_files[1].1);
    assert_ne!(seq_files[1].1, seq_files[2].1);
    for (name, bytes) in &seq_files {
        let lit = bytes
            .iter()
            .rev()
            .take(96 * 48 * 3)
            .filter(|&&b| b > 50)
            .count();
        assert!(lit > 200, "{name} is nearly black ({lit} bright values)");
    }
    for (k, in_sequence) in seq_files.iter().enumerate() {
        let alone = dir.join(format!("alone{k}"));
        let o = run(&[
            "render",
            s,
            "--frames",
            &k.to_string(),
            "--threads",
            "3",
            "--block-size",
            "5",
            "-o",
            alone.join("f%d.ppm").to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let got = files(&alone);
        assert_eq!(got.len(), 1);
        assert_eq!(
            &got[0], in_sequence,
            "frame {k} alone differs from the sequence's"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn steps_and_appended_numbers() {
    let dir = temp_dir("anim-names");
    let scene = write_scene(&dir, SCENE);
    let s = scene.to_str().unwrap();
    let out = dir.join("out");
    // No number in the name: appended, padded to the digits of the last frame (12).
    let o = run(&[
        "render",
        s,
        "--frames",
        "0..12",
        "--step",
        "4",
        "-o",
        out.join("anim.ppm").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<String> = files(&out).into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        ["anim00.ppm", "anim04.ppm", "anim08.ppm", "anim12.ppm"]
    );
    // The scene's own range and `####`, and the scene's outputs without -o.
    let o = run(&["render", s, "-o", out.join("g####.ppm").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("g0002.ppm").exists() && !out.join("g0003.ppm").exists());
    // One frame and a plain name: the name as given.
    let o = run(&["render", s, "--frames", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("out.ppm").exists());
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn command_line_mistakes_are_one_line_errors() {
    let dir = temp_dir("anim-usage");
    let scene = write_scene(&dir, SCENE);
    let s = scene.to_str().unwrap();
    let o = run(&["render", s, "--frames", "5..2"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("the first frame is after the last; expected A..B with A <= B"),
        "{}",
        stderr(&o)
    );
    let o = run(&["render", s, "--step", "0"]);
    assert!(
        stderr(&o).contains("--step 0: expected 1 or more"),
        "{}",
        stderr(&o)
    );
    let still = dir.join("still.ron");
    std::fs::write(
        &still,
        "Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), render: (outputs: [(path: \"s.ppm\")]))",
    )
    .unwrap();
    let o = run(&["render", still.to_str().unwrap(), "--frames", "0..3"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("still.ron has no `animation:`; --frames needs one"),
        "{}",
        stderr(&o)
    );
    let o = run(&["render", still.to_str().unwrap(), "--force"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("still.ron has no `animation:`; --force needs one"),
        "{}",
        stderr(&o)
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_failed_frame_is_named_and_the_others_are_written() {
    let dir = temp_dir("anim-fail");
    // At frame 1 the camera looks at its own position.
    let text = SCENE.replace(
        "        frames: (0, 2),",
        "        frames: (0, 2),
        camera: (look_at: (keys: [(0, (0, 0, 0)), (2, (0, 0, 20))])),",
    );
    let scene = write_scene(&dir, &text);
    let out = dir.join("out");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.join("f%d.ppm").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("luxon: error: frame 1: ")
            && err.contains("the camera's `look_at` equals its `position`"),
        "{err}"
    );
    assert!(
        err.contains("1 of 3 frames failed (1); the other frames are written"),
        "{err}"
    );
    let names: Vec<String> = files(&out).into_iter().map(|(n, _)| n).collect();
    assert_eq!(names, ["f0.ppm", "f2.ppm"]);
    let _ = std::fs::remove_dir_all(dir);
}

fn build_error(text: &str, name: &str) -> String {
    let dir = temp_dir(name);
    let path = write_scene(&dir, text);
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let e = Scene::build(&desc, &registry(&desc))
        .err()
        .expect("the build fails");
    let _ = std::fs::remove_dir_all(dir);
    e.to_string()
}

#[test]
fn what_cannot_be_moved_is_refused_at_the_build() {
    // A sphere scaled differently along its axes would be an ellipsoid.
    let text = SCENE.replace(
        "\"ball\": (translate:",
        "\"ball\": (scale: (keys: [(0, (1, 1, 1)), (1, (1, 2, 1))]), translate:",
    );
    let e = build_error(&text, "anim-scale");
    assert!(
        e.contains("scene.ron:19:54: object `ball` holds spheres, cones or discs"),
        "{e}"
    );
    assert!(e.contains("scales by (1, 2, 1)"), "{e}");
    // Custom geometry is intersected by its plugin, which the host cannot move.
    let text = SCENE.replace(
        "(plugin: \"cylinder\", name: \"bar\", params: (base: (-0.45, 0, 0), apex: (0.45, 0, 0), radius: 0.08)",
        "(plugin: \"box\", name: \"bar\", params: (min: (0, 0, 0), max: (1, 1, 1))",
    );
    let e = build_error(&text, "anim-custom");
    assert!(
        e.contains("custom geometry (drawn by its plugin) cannot be moved"),
        "{e}"
    );
    // A keyed object in a clip group cannot be blurred (instances do not clip).
    let text = SCENE
        .replace("frames: (0, 2),", "frames: (0, 2), shutter: (length: 0.5),")
        .replace(
            "radius: 0.35), material: \"paint\")",
            "radius: 0.35), material: \"paint\", clip: \"cut\")",
        )
        .replace(
            "render: (",
            "clip_groups: { \"cut\": [(point: (5, 0, 0), normal: (1, 0, 0))] },\n    render: (",
        );
    let e = build_error(&text, "anim-shutter-clip");
    assert!(e.contains("object `ball` is keyed and clipped"), "{e}");
    // Shutters build, with motion blur on (a shutter of no length too: it samples +0.0).
    for length in ["0", "0.5"] {
        let text = SCENE.replace(
            "frames: (0, 2),",
            &format!("frames: (0, 2), shutter: (length: {length}),"),
        );
        let dir = temp_dir("anim-shutter");
        assert!(build(&text, &dir).features.motion_blur);
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// The animation walkthrough (scenes/README.md): its scene loads (as a file of `scenes/`), animates what
/// it says, and renders a frame that is not black.
#[test]
fn readme_walkthrough_scene_renders() {
    let readme = std::fs::read_to_string(common::root().join("scenes/README.md")).unwrap();
    let at = readme
        .find("<!-- tested by tests/animation.rs")
        .expect("marker in scenes/README.md");
    let start = readme[at..].find("```ron\n").unwrap() + at + "```ron\n".len();
    let end = readme[start..].find("```").unwrap() + start;
    let path = common::root().join("scenes/readme-animation.ron");
    let mut desc =
        luxon_formats::load_ron_str(&readme[start..end], &path).unwrap_or_else(|e| panic!("{e}"));
    desc.render.width = 64;
    desc.render.height = 48;
    desc.render.samples = 1;
    let a = &desc.animation.as_ref().expect("animated").value;
    assert_eq!((a.first, a.last), (0, 47));
    assert!(a.camera.position.is_some() && a.lights.len() == 1 && a.objects.len() == 1);
    let mut scene = Scene::build(&desc, &registry(&desc)).unwrap_or_else(|e| panic!("{e}"));
    let first = render(&scene);
    scene.set_frame(12).unwrap();
    let later = render(&scene);
    assert_ne!(first.rgba, later.rgba);
    let bright = later
        .rgba
        .chunks_exact(4)
        .filter(|p| p[0] + p[1] + p[2] > 0.3)
        .count();
    assert!(
        bright > 64 * 48 / 2,
        "frame 12 is dark: {bright} bright pixels"
    );
}

/// The keyed objects' geometry (recorded at the build, placed anew at every frame, with its
/// BVHs) is charged to the memory budget: the charges stay the same from frame to frame (each
/// frame's group gives back the last one's), and a frame whose objects do not fit is an error
/// that leaves the scene at the frame it was.
#[test]
fn keyed_objects_are_charged_to_the_memory_budget() {
    use luxon::budget::{Budget, Use};
    use std::sync::Arc;
    let dir = temp_dir("anim-budget");
    let path = write_scene(&dir, SCENE);
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let budget = Arc::new(Budget::new(1 << 30, "a test".into(), None));
    let mut scene = Scene::build_with(&desc, &registry(&desc), budget.clone())
        .unwrap_or_else(|e| panic!("{e}"));
    let held = (budget.used(Use::Geometry), budget.used(Use::Bvh));
    // All the scene's objects are keyed: its geometry is what was recorded and frame 0's.
    assert!(
        scene.moving.len() >= 3 && held.0 > 0 && held.1 > 0,
        "{held:?}"
    );
    for k in [1, 2, 0, 2] {
        scene.set_frame(k).unwrap();
        assert_eq!((budget.used(Use::Geometry), budget.used(Use::Bvh)), held);
    }
    let two = render(&scene);
    // With nothing left, the next frame's objects do not fit.
    let rest = budget.remaining();
    budget
        .reserve(Use::Image, rest, || "a test".into())
        .unwrap();
    let e = scene.set_frame(1).expect_err("over budget").to_string();
    assert!(e.contains("frame 1") && e.contains("memory budget"), "{e}");
    assert_eq!(scene.settings.frame, 2);
    assert_eq!((budget.used(Use::Geometry), budget.used(Use::Bvh)), held);
    budget.release(Use::Image, rest);
    assert_eq!(render(&scene).rgba, two.rgba);
    scene.set_frame(1).unwrap();
    drop(scene);
    // What the scene keeps for good stays charged; the frame's group is given back.
    assert!(budget.used(Use::Geometry) < held.0 && budget.used(Use::Bvh) < held.1);
    let _ = std::fs::remove_dir_all(dir);
}

/// A keyed colour of a transparent material tints its shadows too (`shadows: Tinted`), and
/// the material's copy for objects that cast no shadow takes the colour but stays shadowless.
#[test]
fn a_keyed_colour_tints_the_shadows_of_its_material() {
    let dir = temp_dir("anim-tint");
    let text = SCENE
        .replace(
            "\"paint\": (color: (1, 0, 0), ambient: 1, diffuse: 0)",
            "\"paint\": (color: (1, 0, 0), ambient: 1, diffuse: 0, transmit: 0.5)",
        )
        .replace(
            "material: \"matte\"),",
            "material: \"matte\"),\n        (plugin: \"sphere\", params: (center: (1.5, -0.5, 0), radius: 0.2), material: \"paint\", shadows: false),",
        );
    let mut scene = build(&text, &dir);
    let paint = scene
        .material_names
        .iter()
        .position(|n| n == "paint")
        .unwrap();
    for (k, colour) in [
        (0, [1.0, 0.0, 0.0]),
        (1, [0.5, 0.0, 0.5]),
        (2, [0.0, 0.0, 1.0]),
    ] {
        scene.set_frame(k).unwrap();
        let c = luxon::math::Vec3A::from(colour);
        let m = &scene.materials[paint];
        assert_eq!((m.color, m.shadow), (c, Some(0.5 * c)), "frame {k}");
        // The copies that cast no shadow follow the named materials.
        let copies: Vec<_> = scene.materials[scene.material_names.len()..]
            .iter()
            .filter(|m| m.transmit == 0.5)
            .map(|m| (m.color, m.shadow))
            .collect();
        assert_eq!(copies, [(c, Some(luxon::math::Vec3A::ONE))], "frame {k}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_preview_animates_the_frames_as_apng_and_gif() {
    let dir = temp_dir("anim-preview");
    let scene = write_scene(&dir, SCENE);
    let s = scene.to_str().unwrap();
    let out = dir.join("out");
    let apng = dir.join("p.png");
    let o = run(&[
        "render",
        s,
        "--frames",
        "0..3",
        "--preview",
        apng.to_str().unwrap(),
        "-o",
        out.join("f%d.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("(a preview of 4 frames)"),
        "{}",
        stderr(&o)
    );
    // An animated PNG of 4 frames of the frames' size (64 wide: under 320, kept).
    let mut reader =
        png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&apng).unwrap()))
            .read_info()
            .unwrap();
    let control = reader.info().animation_control().expect("an animated PNG");
    assert_eq!(control.num_frames, 4);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let mut decoded = Vec::new();
    for _ in 0..4 {
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (64, 32));
        decoded.push(buf[..info.buffer_size()].to_vec());
    }
    // Each frame of the preview is the frame written (RGBA of the PNG).
    for (k, d) in decoded.iter().enumerate() {
        let frame = image::open(out.join(format!("f{k}.png")))
            .unwrap()
            .to_rgba8();
        assert_eq!(d, frame.as_raw(), "preview frame {k}");
    }
    // A GIF of the same frames (the frames are done: only the preview is written).
    let gif = dir.join("p.gif");
    let o = run(&[
        "render",
        s,
        "--frames",
        "0..3",
        "--preview",
        gif.to_str().unwrap(),
        "-o",
        out.join("f%d.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    use image::AnimationDecoder;
    let file = std::io::BufReader::new(std::fs::File::open(&gif).unwrap());
    let frames = image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
    assert_eq!(frames.len(), 4);
    assert_eq!(frames[0].buffer().dimensions(), (64, 32));
    assert_ne!(frames[0].buffer(), frames[3].buffer());
    // Outputs it cannot read back are refused before rendering.
    let o = run(&[
        "render",
        s,
        "--preview",
        gif.to_str().unwrap(),
        "-o",
        out.join("g%d.exr").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("needs a frame output it can read back"),
        "{}",
        stderr(&o)
    );
    assert!(!out.join("g0.exr").exists());
    let _ = std::fs::remove_dir_all(dir);
}
