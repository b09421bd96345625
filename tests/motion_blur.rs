//! Motion blur: a sphere moving across the shutter matches the analytic box-filtered profile,
//! a shutter of no length is the still frame bit for bit, the blurred image is the same on
//! one and two threads, and the camera moves during the shutter when its track does.

mod common;

use common::{registry, temp_dir};
use luxon::{Framebuffer, Scene};
use luxon_formats::SceneDesc;
use std::path::Path;

/// Orthographic, 64x4 pixels over x in [-2, 2], y in [-0.125, 0.125] (16 pixels per unit):
/// a white sphere of radius 0.4 (ambient 1, nothing else) moving along x from -0.5 to 0.5
/// over frame 0's shutter, which is open for the whole frame from its start.
const PROFILE: &str = r#"Scene(
    camera: (position: (0, 0, 10), look_at: (0, 0, 0), projection: Orthographic(height: 0.25)),
    lights: [Directional(direction: (0, 0, -1), shadows: false)],
    materials: { "white": (color: (1, 1, 1), ambient: 1, diffuse: 0, specular: 0) },
    objects: [
        (plugin: "sphere", name: "ball", params: (center: (0, 0, 0), radius: 0.4), material: "white"),
    ],
    animation: (
        frames: (0, 1),
        shutter: (length: 1, at: Start),
        objects: { "ball": (translate: (keys: [(0, (-0.5, 0, 0)), (1, (0.5, 0, 0))])) },
    ),
    render: (width: 64, height: 4, samples: 1024, outputs: [(path: "out.ppm")]),
)
"#;

fn load(dir: &Path, text: &str) -> SceneDesc {
    let p = dir.join("scene.ron");
    std::fs::write(&p, text).unwrap();
    luxon_formats::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

fn render(desc: &SceneDesc, frame: u32) -> Framebuffer {
    let mut scene = Scene::build(desc, &registry(desc)).unwrap_or_else(|e| panic!("{e}"));
    scene.set_frame(frame).unwrap_or_else(|e| panic!("{e}"));
    luxon::render::render(&scene, &|_, _| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// The fraction of the shutter during which point (x, y) lies in the moving disc: the
/// overlap of the centre's positions that cover it, [x − w, x + w], with its path [−0.5, 0.5].
fn covered(x: f64, y: f64) -> f64 {
    let r = 0.4f64;
    if y.abs() >= r {
        return 0.0;
    }
    let w = (r * r - y * y).sqrt();
    ((x + w).min(0.5) - (x - w).max(-0.5)).max(0.0)
}

/// The box-filtered profile: each pixel's average of `covered` over a 64x64 grid in it.
fn analytic(width: u32, height: u32) -> Vec<f64> {
    let unit = 16.0;
    let (x0, y0) = (-2.0, 0.125);
    let mut out = Vec::new();
    for py in 0..height {
        for px in 0..width {
            let mut sum = 0.0;
            for j in 0..64 {
                for i in 0..64 {
                    let x = x0 + (f64::from(px) + (f64::from(i) + 0.5) / 64.0) / unit;
                    let y = y0 - (f64::from(py) + (f64::from(j) + 0.5) / 64.0) / unit;
                    sum += covered(x, y);
                }
            }
            out.push(sum / 4096.0);
        }
    }
    out
}

fn mean_error(fb: &Framebuffer, want: &[f64]) -> f64 {
    let got = fb.rgba.chunks(4).map(|p| f64::from(p[0]));
    got.zip(want).map(|(g, w)| (g - w).abs()).sum::<f64>() / want.len() as f64
}

#[test]
fn a_moving_sphere_matches_the_analytic_profile() {
    let dir = temp_dir("blur-profile");
    let desc = load(&dir, PROFILE);
    let want = analytic(64, 4);
    let blurred = render(&desc, 0);
    let e = mean_error(&blurred, &want);
    eprintln!("blurred profile: mean absolute error {e}");
    assert!(e <= 0.01, "mean absolute error {e}");
    // Without the shutter the sphere stands at the frame's time: far from the profile.
    let mut still = desc.clone();
    still.animation.as_mut().unwrap().value.shutter = None;
    let e = mean_error(&render(&still, 0), &want);
    eprintln!("still frame against the profile: {e}");
    assert!(e >= 0.05, "the still frame is {e} from the blurred profile");
    let _ = std::fs::remove_dir_all(dir);
}

/// The same sphere moving as time-sampled data: two `.xyz` data frames, at x −0.5 and 0.5,
/// blended at each ray's time, match the profile too.
#[test]
fn a_moving_series_sphere_matches_the_analytic_profile() {
    let dir = temp_dir("blur-profile-series");
    for (d, x) in [-0.5, 0.5].iter().enumerate() {
        std::fs::write(
            dir.join(format!("ball{d}.xyz")),
            format!("1\nball\nC {x} 0 0\n"),
        )
        .unwrap();
    }
    let text = PROFILE
        .replace(
            r#"(plugin: "sphere", name: "ball", params: (center: (0, 0, 0), radius: 0.4), material: "white"),"#,
            "",
        )
        .replace(
            r#"objects: { "ball": (translate: (keys: [(0, (-0.5, 0, 0)), (1, (0.5, 0, 0))])) },"#,
            "",
        )
        .replace(
            "animation: (",
            r#"series: [(name: "ball", files: "ball%d.xyz", default_atom: (radius: 0.4, material: "white"))],
    animation: ("#,
        );
    let desc = load(&dir, &text);
    assert!(desc.objects.is_empty() && desc.series.len() == 1);
    let want = analytic(64, 4);
    let e = mean_error(&render(&desc, 0), &want);
    eprintln!("blurred series profile: mean absolute error {e}");
    assert!(e <= 0.01, "mean absolute error {e}");
    let mut still = desc.clone();
    still.animation.as_mut().unwrap().value.shutter = None;
    let e = mean_error(&render(&still, 0), &want);
    assert!(e >= 0.05, "the still frame is {e} from the blurred profile");
    let _ = std::fs::remove_dir_all(dir);
}

/// A perspective scene with a bouncing ball (keyed object), a turning shared instance and a
/// camera that moves, 4 samples per pixel.
const SCENE: &str = r#"Scene(
    camera: (position: (0, 1, -6), look_at: (0, 0.5, 0), fov: 40),
    lights: [Point(position: (3, 5, -4), intensity: 0.9)],
    materials: {
        "red": (color: (0.9, 0.1, 0.1), specular: 0.4, shininess: 40),
        "blue": (color: (0.2, 0.3, 0.9), reflect: 0.2),
    },
    objects: [
        (plugin: "plane", params: (normal: (0, 1, 0))),
        (plugin: "sphere", name: "ball", params: (center: (0, 0, 0), radius: 0.5), material: "red"),
    ],
    prototypes: {
        "bar": (objects: [(plugin: "cylinder", params: (base: (-0.8, 0, 0), apex: (0.8, 0, 0), radius: 0.15), material: "blue")]),
    },
    instances: [(prototype: "bar", name: "spinner", world_from_object: (translate: (1.5, 1.2, 0)))],
    animation: (
        frames: (0, 12),
        shutter: (length: 0.5),
        camera: (position: (keys: [(0, (0, 1, -6)), (12, (1, 1.5, -6))])),
        objects: {
            "ball": (translate: (keys: [(0, (-1, 0.5, 0)), (6, (-1, 2, 0)), (12, (-1, 0.5, 0))], interpolation: CatmullRom)),
            "spinner": (translate: (keys: [(0, (1.5, 1.2, 0))]),
                        rotate: (keys: [(0, (axis: (0, 0, 1), degrees: 0)), (12, (axis: (0, 0, 1), degrees: 720))])),
        },
    ),
    render: (width: 48, height: 32, samples: 4, outputs: [(path: "out.ppm")]),
)
"#;

fn bits(fb: &Framebuffer) -> Vec<u32> {
    fb.rgba.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn a_shutter_of_no_length_is_the_still_frame_bitwise() {
    let dir = temp_dir("blur-zero");
    let desc = load(&dir, SCENE);
    let with = |length: Option<f64>, instancing: &str| {
        let mut d = desc.clone();
        d.render.instancing = match instancing {
            "share" => luxon_formats::Instancing::Share,
            _ => luxon_formats::Instancing::Auto,
        };
        let a = &mut d.animation.as_mut().unwrap().value;
        match length {
            Some(l) => a.shutter.as_mut().unwrap().value.length = l,
            None => a.shutter = None,
        }
        d
    };
    for instancing in ["auto", "share"] {
        let zero = with(Some(0.0), instancing);
        let scene = Scene::build(&zero, &registry(&zero)).unwrap();
        assert!(
            scene.features.motion_blur,
            "a shutter of no length samples time"
        );
        let still = bits(&render(&with(None, instancing), 5));
        assert_eq!(bits(&render(&zero, 5)), still, "{instancing}");
        let open = bits(&render(&with(Some(0.5), instancing), 5));
        assert_ne!(open, still, "{instancing}: an open shutter blurs");
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn blurred_frames_are_the_same_on_one_and_two_threads() {
    let dir = temp_dir("blur-threads");
    let desc = load(&dir, SCENE);
    let mut images = Vec::new();
    for (threads, tile) in [(1, 16), (2, 16), (2, 7)] {
        let mut d = desc.clone();
        d.render.parallel.threads = Some(threads);
        d.render.parallel.tile_size = tile;
        let scene = Scene::build(&d, &registry(&d)).unwrap();
        assert!(scene.features.motion_blur);
        images.push(bits(&render(&d, 3)));
    }
    assert_eq!(images[0], images[1]);
    assert_eq!(images[0], images[2]);
    // Frame 3 rendered after other frames is frame 3 rendered alone.
    let mut scene = Scene::build(&desc, &registry(&desc)).unwrap();
    for k in [7, 1, 3] {
        scene.set_frame(k).unwrap();
    }
    let after = luxon::render::render(&scene, &|_, _| {}).unwrap().0;
    assert_eq!(bits(&after), images[0]);
    let _ = std::fs::remove_dir_all(dir);
}

/// What moves is placed per ray: the keyed object and instance as moving instances, the
/// camera when its track changes during the shutter; a scene whose keys hold still samples
/// no time.
#[test]
fn what_moves_is_evaluated_at_the_rays_time() {
    let dir = temp_dir("blur-what");
    let desc = load(&dir, SCENE);
    let scene = Scene::build(&desc, &registry(&desc)).unwrap();
    assert_eq!(scene.instances.keyed_count(), 2);
    assert!(scene.camera_moves);
    assert_eq!(scene.settings.shutter, Some((-0.25, 0.25)));
    // Keys that hold one value move nothing: no time is sampled, the image is the still one.
    let text = SCENE
        .replace("(12, (1, 1.5, -6))", "(12, (0, 1, -6))")
        .replace("(6, (-1, 2, 0)), (12, (-1, 0.5, 0))", "(12, (-1, 0.5, 0))")
        .replace(
            "(12, (axis: (0, 0, 1), degrees: 720))",
            "(12, (axis: (0, 0, 1), degrees: 0))",
        );
    let held = load(&dir, &text);
    let scene = Scene::build(&held, &registry(&held)).unwrap();
    assert!(!scene.features.motion_blur);
    assert_eq!(scene.settings.shutter, None);
    let _ = std::fs::remove_dir_all(dir);
}

/// `--shutter` overrides the scene's: `check` shows it, `off` turns motion blur off, a length
/// outside 0 to 2 or an unknown placement is a usage error naming the form.
#[test]
fn the_shutter_option_overrides_the_scene() {
    let dir = temp_dir("blur-cli");
    let path = dir.join("scene.ron");
    std::fs::write(&path, SCENE).unwrap();
    let p = path.to_str().unwrap();
    let o = common::run(&["check", p, "--shutter", "1.5:end"]);
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{}", common::stderr(&o));
    assert!(out.contains("shutter 1.5 frame End"), "{out}");
    assert!(out.contains("motion blur"), "{out}");
    let o = common::run(&["check", p, "--shutter", "off"]);
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success() && !out.contains("motion blur"), "{out}");
    for bad in ["3", "0.5:middle", "x"] {
        let o = common::run(&["check", p, "--shutter", bad]);
        assert!(!o.status.success());
        assert!(
            common::stderr(&o).contains("expected LENGTH[:start|centre|end]"),
            "{}",
            common::stderr(&o)
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}
