//! Time-sampled data (`series:`): each frame shows the spheres of its `.xyz` data frame (or the
//! triangles of its `.obj`) where the file puts them, `per_frame` skips data frames, a frame is
//! the same bits alone or after others, and a missing data file fails the frames showing it,
//! the others being written; `luxon check` reports missing files.

mod common;

use common::{registry, run, stderr, temp_dir};
use luxon::{Framebuffer, Scene};
use std::path::{Path, PathBuf};

/// Orthographic, 64x32 pixels over x in [-2, 2], y in [-1, 1] (16 pixels per unit), black
/// background; flat colours (ambient only). `SERIES` is replaced by the series list.
const SCENE: &str = r#"Scene(
    camera: (position: (0, 0, 10), look_at: (0, 0, 0), projection: Orthographic(height: 2)),
    lights: [Directional(direction: (0, 0, -1), shadows: false)],
    materials: {
        "red": (color: (1, 0, 0), ambient: 1, diffuse: 0),
        "blue": (color: (0, 0, 1), ambient: 1, diffuse: 0),
    },
    series: [SERIES],
    animation: (frames: (0, 2)),
    render: (width: 64, height: 32, outputs: [(path: "out.ppm")]),
)
"#;

const ATOMS: &str = r#"(name: "water", files: "traj/w_%03d.xyz", atoms: { "O": (radius: 0.3, material: "red"), "H": (radius: 0.2, material: "blue") })"#;

/// An `.xyz` data frame with one O atom at (x, y, 0) and one H atom at (x, y - 0.6, 0).
fn xyz(x: f64, y: f64) -> String {
    format!("2\nO and H\nO {x} {y} 0\nH {x} {} 0\n", y - 0.6)
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(&p, text).unwrap();
    p
}

fn scene_file(dir: &Path, series: &str) -> PathBuf {
    write(dir, "scene.ron", &SCENE.replace("SERIES", series))
}

fn build(path: &Path) -> Scene {
    let desc = luxon_formats::load(path).unwrap_or_else(|e| panic!("{e}"));
    Scene::build(&desc, &registry(&desc)).unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Scene) -> Framebuffer {
    luxon::render::render(scene, &|_, _| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// Linear RGB at world point (x, y) of the 64x32 view.
fn at(fb: &Framebuffer, x: f64, y: f64) -> [f32; 3] {
    let px = ((x + 2.0) * 16.0) as u32;
    let py = ((1.0 - y) * 16.0) as u32;
    let i = 4 * (py * fb.width + px) as usize;
    [fb.rgba[i], fb.rgba[i + 1], fb.rgba[i + 2]]
}

const RED: [f32; 3] = [1.0, 0.0, 0.0];
const BLUE: [f32; 3] = [0.0, 0.0, 1.0];
const BLACK: [f32; 3] = [0.0; 3];

#[track_caller]
fn near(a: [f32; 3], b: [f32; 3]) {
    let d = (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f32::max);
    assert!(d < 1e-3, "{a:?} is not {b:?}");
}

/// Each frame shows an O atom (red) at `xs[k]`, y 0.4, and an H atom (blue) below it, and
/// nothing where the other frames' atoms are.
#[track_caller]
fn shows_atoms_at(frames: &[Framebuffer], xs: &[f64]) {
    for (k, fb) in frames.iter().enumerate() {
        near(at(fb, xs[k], 0.4), RED);
        near(at(fb, xs[k], -0.2), BLUE);
        for (j, &x) in xs.iter().enumerate() {
            if x != xs[k] {
                near(at(fb, x, 0.4), BLACK);
                assert_ne!(j, k);
            }
        }
    }
}

#[test]
fn each_frame_shows_the_atoms_of_its_data_file() {
    let dir = temp_dir("series-xyz");
    let xs = [-1.2, 0.0, 1.2];
    for (d, x) in xs.iter().enumerate() {
        write(&dir, &format!("traj/w_{d:03}.xyz"), &xyz(*x, 0.4));
    }
    let mut scene = build(&scene_file(&dir, ATOMS));
    let mut frames = Vec::new();
    for k in 0..3 {
        scene.set_frame(k).unwrap();
        frames.push(render(&scene));
    }
    shows_atoms_at(&frames, &xs);
    // The last frame holds after the range; the radius of a fifth column applies.
    write(&dir, "traj/w_002.xyz", "1\nbig\nO 1.2 0.4 0 0.9\n");
    let mut scene = build(&scene_file(&dir, ATOMS));
    scene.set_frame(7).unwrap();
    let fb = render(&scene);
    near(at(&fb, 1.2, -0.3), RED);
    near(at(&fb, 1.2 - 0.8, 0.4), RED);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn per_frame_two_shows_every_other_data_frame() {
    let dir = temp_dir("series-per-frame");
    let xs = [-1.5, -0.75, 0.0, 0.75, 1.5];
    for (d, x) in xs.iter().enumerate() {
        write(&dir, &format!("traj/w_{d:03}.xyz"), &xyz(*x, 0.4));
    }
    let series = ATOMS.replace("(name: \"water\",", "(name: \"water\", per_frame: 2,");
    let mut scene = build(&scene_file(&dir, &series));
    let mut frames = Vec::new();
    for k in 0..3 {
        scene.set_frame(k).unwrap();
        frames.push(render(&scene));
    }
    // Data frames 0, 2 and 4.
    shows_atoms_at(&frames, &[-1.5, 0.0, 1.5]);
    for fb in &frames {
        near(at(fb, -0.75, 0.4), BLACK);
        near(at(fb, 0.75, 0.4), BLACK);
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_frame_alone_is_the_same_bits_as_after_the_others() {
    let dir = temp_dir("series-bitwise");
    for (d, x) in [-1.2, 0.1, 1.3].iter().enumerate() {
        write(
            &dir,
            &format!("traj/w_{d:03}.xyz"),
            &xyz(*x, 0.3 - 0.1 * d as f64),
        );
    }
    let path = scene_file(&dir, ATOMS);
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("width: 64, height: 32", "width: 64, height: 32, samples: 4")
        .replace("diffuse: 0", "diffuse: 0.8");
    std::fs::write(&path, text).unwrap();
    let mut sequence = build(&path);
    let mut after = Vec::new();
    for k in [0, 1, 2, 1] {
        sequence.set_frame(k).unwrap();
        after.push(render(&sequence).rgba);
    }
    assert_ne!(after[0], after[1]);
    for k in 0..3u32 {
        let mut alone = build(&path);
        alone.set_frame(k).unwrap();
        let fresh = render(&alone).rgba;
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
        assert!(
            bits(&fresh) == bits(&after[k as usize]),
            "frame {k} alone differs from the sequence's"
        );
    }
    // Frame 1 again, after frame 2: the same bits.
    assert_eq!(after[3], after[1]);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn an_obj_series_shows_one_mesh_per_frame() {
    let dir = temp_dir("series-obj");
    // A square of side 0.5 with its lower left corner at (x, -0.25).
    for (d, x) in [-1.5f64, 1.0].iter().enumerate() {
        let (a, b) = (x, x + 0.5);
        write(
            &dir,
            &format!("mesh/m{d}.obj"),
            &format!("v {a} -0.25 0\nv {b} -0.25 0\nv {b} 0.25 0\nv {a} 0.25 0\nf 1 2 3 4\n"),
        );
    }
    let series = r#"(name: "sheet", files: "mesh/m#.obj", material: "blue")"#;
    let mut scene = build(&scene_file(&dir, series));
    scene.set_frame(0).unwrap();
    let first = render(&scene);
    scene.set_frame(1).unwrap();
    let second = render(&scene);
    near(at(&first, -1.25, 0.0), BLUE);
    near(at(&first, 1.25, 0.0), BLACK);
    near(at(&second, 1.25, 0.0), BLUE);
    near(at(&second, -1.25, 0.0), BLACK);
    // Frame 2 has no file: an error naming it and the frame.
    let e = scene.set_frame(2).unwrap_err().to_string();
    assert!(e.contains("series `sheet`, frame 2: data file"), "{e}");
    assert!(e.contains("m2.obj` does not exist"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// The image files of `dir` by name.
fn images(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| !n.ends_with(".luxon-frames"))
        .collect();
    v.sort();
    v
}

#[test]
fn a_missing_data_file_fails_its_frame_only() {
    let dir = temp_dir("series-missing");
    write(&dir, "traj/w_000.xyz", &xyz(-1.2, 0.4));
    write(&dir, "traj/w_002.xyz", &xyz(1.2, 0.4));
    let scene = scene_file(&dir, ATOMS);
    let s = scene.to_str().unwrap();
    let out = dir.join("out");
    let o = run(&["render", s, "-o", out.join("f%d.png").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("luxon: error: frame 1: ") && err.contains("w_001.xyz` does not exist"),
        "{err}"
    );
    assert!(err.contains("series `water`, frame 1"), "{err}");
    assert!(
        err.contains("1 of 3 frames failed (1); the other frames are written"),
        "{err}"
    );
    assert_eq!(images(&out), ["f0.png", "f2.png"]);
    // Frame 2 shows its atoms (decoded from the PNG written).
    let png = image::open(out.join("f2.png")).unwrap().to_rgb8();
    let px = |x: f64, y: f64| {
        let p = png.get_pixel(((x + 2.0) * 16.0) as u32, ((1.0 - y) * 16.0) as u32);
        p.0
    };
    assert_eq!(px(1.2, 0.4), [255, 0, 0]);
    assert_eq!(px(1.2, -0.2), [0, 0, 255]);
    assert_eq!(px(-1.2, 0.4), [0, 0, 0]);
    // A missing first frame fails that frame, not the build.
    std::fs::rename(dir.join("traj/w_000.xyz"), dir.join("traj/w_001.xyz")).unwrap();
    let o = run(&[
        "render",
        s,
        "--force",
        "-o",
        out.join("g%d.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("1 of 3 frames failed (0)"),
        "{}",
        stderr(&o)
    );
    assert!(out.join("g1.png").exists() && out.join("g2.png").exists());
    // `luxon check` names the missing file and the frame.
    let o = run(&["check", s]);
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &stderr(&o);
    assert!(
        text.contains("series `water`: 1 of 3 data files are missing (first: ")
            && text.contains("w_000.xyz, frame 0)"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_shipped_trajectory_renders_its_four_data_frames() {
    let path = common::root().join("scenes/trajectory/water.ron");
    let mut scene = build(&path);
    let mut frames = Vec::new();
    for k in 0..4 {
        scene.set_frame(k).unwrap();
        frames.push(render(&scene));
    }
    for (k, fb) in frames.iter().enumerate() {
        // The oxygen (red) sits at the origin, seen near the middle of the picture.
        let (w, h) = (fb.width, fb.height);
        let i = 4 * ((h / 2 + 5) * w + w / 2) as usize;
        let c = &fb.rgba[i..i + 3];
        assert!(c[0] > 0.3 && c[1] < 0.2 && c[2] < 0.2, "frame {k}: {c:?}");
        let white = fb
            .rgba
            .chunks(4)
            .filter(|p| p[0] > 0.5 && p[1] > 0.5)
            .count();
        assert!(white > 100, "frame {k}: hydrogen pixels {white}");
    }
    for k in 1..4 {
        assert_ne!(
            frames[k].rgba,
            frames[k - 1].rgba,
            "frames {k} and {}",
            k - 1
        );
    }
}

/// `SCENE` with a shutter (`shutter`: its RON) and `samples` per pixel.
fn blurred_scene(dir: &Path, series: &str, shutter: &str, samples: u32) -> PathBuf {
    let text = SCENE
        .replace("SERIES", series)
        .replace(
            "animation: (frames: (0, 2))",
            &format!("animation: (frames: (0, 2), shutter: {shutter})"),
        )
        .replace(
            "width: 64, height: 32,",
            &format!("width: 64, height: 32, samples: {samples},"),
        );
    write(dir, "scene.ron", &text)
}

fn bits(fb: &Framebuffer) -> Vec<u32> {
    fb.rgba.iter().map(|v| v.to_bits()).collect()
}

/// Under an open shutter the atoms move from one data frame to the next during the frame:
/// smeared along their path (neither sharp nor black), the same bits on any number of
/// threads and tiles; a shutter of no length is the still frame bit for bit.
#[test]
fn a_blurred_series_moves_between_its_data_frames() {
    let dir = temp_dir("series-blur");
    for (d, x) in [-1.0, 0.0, 1.0].iter().enumerate() {
        write(&dir, &format!("traj/w_{d:03}.xyz"), &xyz(*x, 0.4));
    }
    // Open for the whole frame from its start: frame 0 moves the atoms from x -1 to 0.
    let path = blurred_scene(&dir, ATOMS, "(length: 1, at: Start)", 64);
    let mut scene = build(&path);
    assert!(scene.features.motion_blur);
    scene.set_frame(0).unwrap();
    let fb = render(&scene);
    // The O atom's centre passes every x in [-1, 0]: partly covered there, not at its ends'
    // far sides.
    for x in [-0.75, -0.5, -0.25] {
        let [r, g, b] = at(&fb, x, 0.4);
        assert!(
            r > 0.2 && r < 0.9 && g == 0.0 && b < 0.05,
            "x {x}: {:?}",
            [r, g, b]
        );
    }
    near(at(&fb, 0.5, 0.4), BLACK);
    near(at(&fb, -1.5, 0.4), BLACK);
    // Threads and tiles do not change a bit.
    let mut images = Vec::new();
    for (threads, tile) in [(1, 16), (2, 16), (2, 5)] {
        let mut desc = luxon_formats::load(&path).unwrap();
        desc.render.parallel.threads = Some(threads);
        desc.render.parallel.tile_size = tile;
        let mut scene = Scene::build(&desc, &registry(&desc)).unwrap();
        scene.set_frame(1).unwrap();
        images.push(bits(&render(&scene)));
    }
    assert_eq!(images[0], images[1]);
    assert_eq!(images[0], images[2]);
    // A shutter of no length: the still frames' bits.
    let zero = build(&blurred_scene(&dir, ATOMS, "(length: 0)", 64));
    let mut still = luxon_formats::load(&path).unwrap();
    still.animation.as_mut().unwrap().value.shutter = None;
    let mut still = Scene::build(&still, &registry(&still)).unwrap();
    let mut zero = zero;
    for k in 0..3 {
        zero.set_frame(k).unwrap();
        still.set_frame(k).unwrap();
        assert_eq!(bits(&render(&zero)), bits(&render(&still)), "frame {k}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A deforming `.obj` series: the square grows from one data frame to the next, so the band
/// it sweeps is partly covered; a data frame joining other triangles is refused.
#[test]
fn a_blurred_obj_series_deforms_between_its_data_frames() {
    let dir = temp_dir("series-blur-obj");
    for (d, b) in [-0.5f64, 0.5, 1.5].iter().enumerate() {
        write(
            &dir,
            &format!("mesh/m{d}.obj"),
            &format!("v -1 -0.25 0\nv {b} -0.25 0\nv {b} 0.25 0\nv -1 0.25 0\nf 1 2 3 4\n"),
        );
    }
    let series = r#"(name: "sheet", files: "mesh/m#.obj", material: "blue")"#;
    let path = blurred_scene(&dir, series, "(length: 1, at: Start)", 64);
    let mut scene = build(&path);
    scene.set_frame(0).unwrap();
    let fb = render(&scene);
    near(at(&fb, -0.75, 0.0), BLUE);
    let [r, g, b] = at(&fb, 0.0, 0.0);
    assert!(
        r == 0.0 && g == 0.0 && b > 0.2 && b < 0.8,
        "{:?}",
        [r, g, b]
    );
    near(at(&fb, 0.75, 0.0), BLACK);
    // Other triangles in the next data frame: an error naming both files and the frame.
    write(
        &dir,
        "mesh/m1.obj",
        "v -1 -0.25 0\nv 0.5 -0.25 0\nv 0.5 0.25 0\nv -1 0.25 0\nf 1 2 4\nf 2 3 4\n",
    );
    // (A scene keeps the data frames it read: a fresh one reads the edit.)
    let e = build(&path).set_frame(0).unwrap_err().to_string();
    assert!(e.contains("series `sheet`, frame 0: "), "{e}");
    assert!(
        e.contains("m1.obj` joins its vertices into other triangles than"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// Under an open shutter a frame needs the data frames its shutter spans: a missing one fails
/// the frame, naming the file and the frame; a data frame with other atoms is refused.
#[test]
fn a_blurred_frame_needs_every_data_frame_its_shutter_spans() {
    let dir = temp_dir("series-blur-missing");
    write(&dir, "traj/w_000.xyz", &xyz(-1.0, 0.4));
    write(&dir, "traj/w_002.xyz", &xyz(1.0, 0.4));
    // Centred on the frame: frame 0 reaches half-way to data frame 1.
    let path = blurred_scene(&dir, ATOMS, "(length: 1)", 4);
    let desc = luxon_formats::load(&path).unwrap();
    let mut scene = Scene::build(&desc, &registry(&desc)).unwrap();
    let e = scene.set_frame(0).unwrap_err().to_string();
    assert!(e.contains("series `water`, frame 0: data file"), "{e}");
    assert!(e.contains("w_001.xyz` does not exist"), "{e}");
    write(&dir, "traj/w_001.xyz", "1\nonly O\nO 0 0.4 0\n");
    let e = scene.set_frame(0).unwrap_err().to_string();
    assert!(e.contains("w_001.xyz` has 1 atoms but `"), "{e}");
    assert!(e.contains("w_000.xyz` has 2"), "{e}");
    write(&dir, "traj/w_001.xyz", &xyz(0.0, 0.4));
    build(&path).set_frame(0).unwrap();
    let _ = std::fs::remove_dir_all(dir);
}

/// The frame numbers a run says it wrote.
fn wrote(o: &std::process::Output) -> Vec<u32> {
    let mut v: Vec<u32> = stderr(o)
        .lines()
        .filter_map(|l| l.strip_prefix("luxon: wrote "))
        .filter_map(|l| l.split("(frame ").nth(1)?.split(',').next()?.parse().ok())
        .collect();
    v.sort();
    v
}

/// A resumed sequence renders again the frames whose data files changed, and only those:
/// each frame's record covers the data frames it reads (under an open shutter, those its
/// shutter spans).
#[test]
fn an_edited_data_file_makes_the_frames_reading_it_stale() {
    let dir = temp_dir("series-resume");
    for (d, x) in [-1.0, 0.0, 1.0].iter().enumerate() {
        write(&dir, &format!("traj/w_{d:03}.xyz"), &xyz(*x, 0.4));
    }
    let out = dir.join("out");
    let pattern = out.join("f%d.ppm");
    let render = |scene: &Path| {
        let o = run(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            pattern.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        wrote(&o)
    };
    // Sharp frames: frame k reads data frame k.
    let sharp = scene_file(&dir, ATOMS);
    assert_eq!(render(&sharp), [0, 1, 2]);
    assert_eq!(render(&sharp), [] as [u32; 0]);
    write(&dir, "traj/w_001.xyz", &xyz(0.25, 0.4));
    assert_eq!(render(&sharp), [1]);
    // Centred shutter of one frame: frame 0 reads data frames 0 and 1, frame 1 all three,
    // frame 2 the last two.
    let blurred = blurred_scene(&dir, ATOMS, "(length: 1)", 1);
    assert_eq!(render(&blurred), [0, 1, 2]);
    write(&dir, "traj/w_000.xyz", &xyz(-0.75, 0.4));
    assert_eq!(render(&blurred), [0, 1]);
    write(&dir, "traj/w_002.xyz", &xyz(0.75, 0.4));
    assert_eq!(render(&blurred), [1, 2]);
    let _ = std::fs::remove_dir_all(dir);
}
