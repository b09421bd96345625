//! `luxon sweep`: the report files, error falling with samples, the texture filter override
//! and clear errors for bad `--vary`; a frame of an animated scene (`--frame`, `--shutter`).

mod common;

use common::*;
use luxon::sweep::{Curve, Options};
use std::path::Path;

fn sweep(args: &[&str], dir: &Path) -> std::process::Output {
    let scene = root().join("scenes/antialiasing.ron");
    let mut all = vec![
        "sweep",
        scene.to_str().unwrap(),
        "--res",
        "40x30",
        "--runs",
        "1",
        "--reference-samples",
        "64",
        "-o",
        dir.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    run(&all)
}

#[test]
fn writes_the_report_and_error_falls_with_samples() {
    let dir = temp_dir("sweep-report");
    let o = sweep(
        &["--vary", "samples=1,4,16", "--vary", "adaptive=off,0.1:2"],
        &dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(
        csv.lines().next().unwrap(),
        "parameter,value,time_s,rays,samples_per_pixel,rmse,psnr_db,ssim"
    );
    let keys: Vec<(&str, &str)> = rows.iter().map(|r| (r[0], r[1])).collect();
    assert_eq!(
        keys,
        [
            ("samples", "1"),
            ("samples", "4"),
            ("samples", "16"),
            ("adaptive", "off"),
            ("adaptive", "0.1:2")
        ]
    );
    let rays: Vec<u64> = rows.iter().map(|r| r[3].parse().unwrap()).collect();
    let rmse: Vec<f64> = rows.iter().map(|r| r[5].parse().unwrap()).collect();
    assert_eq!(&rays[..3], &[1200, 4800, 19200]);
    assert!(rmse[0] > rmse[1] && rmse[1] > rmse[2], "{rmse:?}");
    assert!(rmse[2] > 0.0 && rmse[0] < 0.5);
    // The scene's 16 samples: adaptive off equals samples=16; adaptive uses 16 as its base.
    assert_eq!(rows[3][5], rows[2][5]);
    assert!(rays[4] > rays[3]);
    let ssim: Vec<f64> = rows.iter().map(|r| r[7].parse().unwrap()).collect();
    assert!(ssim[0] < ssim[2] && ssim[2] <= 1.0);

    let md = std::fs::read_to_string(dir.join("sweep.md")).unwrap();
    assert!(
        md.contains("| samples | 16 |") && md.contains("| adaptive | 0.1:2 |"),
        "{md}"
    );
    assert!(md.contains("64 uniform samples per pixel"));
    let svg = std::fs::read_to_string(dir.join("sweep.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("samples") && svg.contains("adaptive"));
    assert!(svg.matches("<circle").count() >= 5);
    // Contact sheet: 3 columns, 2 curves + the reference; 40x30 thumbnails, 6 px gaps.
    let sheet = image::open(dir.join("contact.png")).unwrap().to_rgb8();
    assert_eq!(sheet.dimensions(), (3 * 40 + 4 * 6, 3 * 30 + 4 * 6));
    assert!(
        sheet.pixels().any(|p| p.0[0] < 50),
        "the sheet shows the images"
    );
    for f in ["samples-1.png", "adaptive-0.1-2.png", "reference.png"] {
        let img = image::open(dir.join(f)).unwrap();
        assert_eq!((img.width(), img.height()), (40, 30), "{f}");
    }
    // A supplied reference: comparing samples=64 with itself gives no error.
    let dir2 = temp_dir("sweep-supplied");
    let o = sweep(
        &[
            "--vary",
            "samples=64",
            "--reference",
            dir.join("reference.png").to_str().unwrap(),
        ],
        &dir2,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(dir2.join("sweep.csv")).unwrap();
    assert!(csv.contains("samples,64,"), "{csv}");
    assert!(
        csv.lines()
            .nth(1)
            .unwrap()
            .ends_with(",0.000000,inf,1.0000"),
        "{csv}"
    );
}

#[test]
fn bad_vary_and_reference_are_clear_errors() {
    let dir = temp_dir("sweep-errors");
    let cases: [(&[&str], &str); 7] = [
        (&["--vary", "samples"], "expected PARAMETER=VALUE"),
        (&["--vary", "sample=1,4"], "did you mean `samples`"),
        (&["--vary", "samples=1,,4"], "empty value"),
        (
            &["--vary", "max_depth=deep"],
            "`deep` is not a whole number",
        ),
        (&["--vary", "volume_step=0.1"], "draws no volume"),
        (&["--vary", "texture_filter=nearest"], "no image textures"),
        (
            &[
                "--vary",
                "samples=1",
                "--reference",
                "scenes/textures/card.png",
            ],
            "but the scene renders 40x30",
        ),
    ];
    for (args, expected) in cases {
        let o = sweep(args, &dir);
        let err = stderr(&o);
        assert!(!o.status.success(), "{args:?}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
    assert!(!dir.join("sweep.csv").exists());
}

#[test]
fn texture_filter_rewrites_the_image_textures() {
    let dir = temp_dir("sweep-filter");
    std::fs::copy(
        root().join("scenes/textures/card.png"),
        dir.join("card.png"),
    )
    .unwrap();
    let path = dir.join("scene.ron");
    std::fs::write(
        &path,
        r#"Scene(
        camera: (position: (0, 1, 0), look_at: (0, 0.6, 10), fov: 30),
        lights: [Directional(direction: (0, -1, 0), shadows: false)],
        textures: {
            "card": (plugin: "image", params: (file: "card.png", mapping: planar, scale: 0.5)),
            "tree": (plugin: "checker", params: (scale: 2, even: Image(file: "card.png", mapping: planar, filter: mip), odd: (0, 0, 0))),
        },
        materials: { "floor": (texture: "card", ambient: 0, diffuse: 1), "box": (texture: "tree") },
        objects: [
            (plugin: "plane", params: (normal: (0, 1, 0)), material: "floor"),
            (plugin: "sphere", params: (center: (1, 1, 6), radius: 0.5), material: "box"),
        ],
        render: (width: 32, height: 24, samples: 1),
    )"#,
    )
    .unwrap();
    let desc = luxon_formats::load(&path).unwrap();
    let reg = registry(&desc);
    let options = Options {
        curves: vec!["texture_filter=nearest,bilinear,mip"
            .parse::<Curve>()
            .unwrap()],
        reference: None,
        reference_samples: Some(16),
        runs: 1,
        frame: None,
    };
    let s = luxon::sweep::run(&desc, &reg, &options, &|_| {}).unwrap();
    assert_eq!(s.rows.len(), 3);
    assert_ne!(
        s.rows[0].rgb, s.rows[1].rgb,
        "nearest and bilinear look alike"
    );
    assert_ne!(s.rows[1].rgb, s.rows[2].rgb, "bilinear and mip look alike");
    assert!(s.rows.iter().all(|r| r.rmse > 0.0 && r.rmse < 0.3));
}

#[test]
fn volume_step_sweep_error_falls_with_the_step() {
    let dir = temp_dir("sweep-volume-step");
    let scene = root().join("scenes/vortex.ron");
    let o = run(&[
        "sweep",
        scene.to_str().unwrap(),
        "--res",
        "32x32",
        "--runs",
        "1",
        "--vary",
        "volume_step=4,2,1",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let values: Vec<&str> = rows.iter().map(|r| r[1]).collect();
    assert_eq!(values, ["4", "2", "1"]);
    // The reference is the finest step: coarser steps are further from it.
    let rmse: Vec<f64> = rows.iter().map(|r| r[5].parse().unwrap()).collect();
    assert!(rmse[0] > rmse[1] && rmse[1] > rmse[2], "{rmse:?}");
}

/// `Options::frame` sweeps that frame of an animated scene: the rows are the frame as
/// `set_frame` gives it (here a blurred one), not the scene's first frame.
#[test]
fn a_frame_of_an_animation_is_swept() {
    let mut desc = luxon_formats::load(&root().join("scenes/bouncing-ball.ron")).unwrap();
    desc.render.width = 24;
    desc.render.height = 16;
    let reg = registry(&desc);
    let sweep_at = |frame| {
        let options = Options {
            curves: vec!["samples=2".parse::<Curve>().unwrap()],
            reference: None,
            reference_samples: Some(4),
            runs: 1,
            frame,
        };
        luxon::sweep::run(&desc, &reg, &options, &|_| {}).unwrap()
    };
    let mut d = desc.clone();
    d.render.samples = 2;
    let mut scene = luxon::Scene::build(&d, &reg).unwrap();
    scene.set_frame(15).unwrap();
    let (fb, _) = luxon::render::render(&scene, &|_, _| {}).unwrap();
    let at15 = sweep_at(Some(15));
    assert_eq!(at15.rows[0].rgb, luxon::sweep::to_rgb8(&fb));
    assert_ne!(sweep_at(None).rows[0].rgb, at15.rows[0].rgb);
}

/// `--frame` and `--shutter` on the command line, and their errors.
#[test]
fn frame_and_shutter_options() {
    let dir = temp_dir("sweep-frame");
    let ball = root().join("scenes/bouncing-ball.ron");
    let args = |extra: &[&str]| {
        let mut a = vec![
            "sweep",
            ball.to_str().unwrap(),
            "--res",
            "24x16",
            "--runs",
            "1",
            "--reference-samples",
            "4",
            "--vary",
            "samples=1,2",
            "-o",
            dir.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    let o = args(&["--frame", "15", "--shutter", "off"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("sweep.csv").is_file());
    for (extra, expected) in [
        (&["--frame", "48"][..], "the scene's frames are 0 to 47"),
        (&["--shutter", "3"][..], "--shutter 3: expected LENGTH"),
    ] {
        let o = args(extra);
        assert!(!o.status.success(), "{extra:?}");
        assert!(stderr(&o).contains(expected), "{extra:?}: {}", stderr(&o));
    }
    let o = sweep(&["--vary", "samples=1", "--frame", "2"], &dir);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("has no `animation:`"), "{}", stderr(&o));
}
