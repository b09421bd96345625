//! `luxon tachyon`: Tachyon's command line as VMD and scripts use it: the files written and
//! their names (single images, camera-file sequences with Tachyon's end-of-file quirk,
//! several scenes), formats chosen by `-format`, and one-line errors.

mod common;

use common::*;
use std::path::Path;
use std::process::Output;

/// Two spheres, a light and a floor; 24x16 unless `-res` says otherwise.
const SCENE: &str = "BEGIN_SCENE RESOLUTION 24 16\n\
    CAMERA ZOOM 1 ASPECTRATIO 1 ANTIALIASING 0 RAYDEPTH 4 CENTER 0 0 -6 VIEWDIR 0 0 1 \
    UPDIR 0 1 0 END_CAMERA\n\
    LIGHT CENTER 4 5 -6 RAD 0 COLOR 1 1 1\n\
    SPHERE CENTER -1 0 0 RAD 1 TEXTURE AMBIENT 0.1 DIFFUSE 0.8 SPECULAR 0 OPACITY 1 \
    COLOR 1 0.2 0.2 TEXFUNC 0\n\
    SPHERE CENTER 1.2 0 0.5 RAD 1 TEXTURE AMBIENT 0.1 DIFFUSE 0.8 SPECULAR 0.3 OPACITY 1 \
    COLOR 0.2 0.4 1 TEXFUNC 0\n\
    PLANE CENTER 0 -1 0 NORMAL 0 1 0 TEXTURE AMBIENT 0.1 DIFFUSE 0.8 SPECULAR 0 OPACITY 1 \
    COLOR 0.8 0.8 0.8 TEXFUNC 0\n\
    END_SCENE\n";

/// Runs `luxon tachyon ARGS` in `dir`.
fn tachyon(dir: &Path, args: &[&str]) -> Output {
    luxon()
        .current_dir(dir)
        .arg("tachyon")
        .args(args)
        .output()
        .expect("cannot run luxon")
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", stderr(o));
    String::from_utf8_lossy(&o.stdout).to_string()
}

fn error(o: &Output) -> String {
    assert_eq!(o.status.code(), Some(1), "{}", stderr(o));
    let e = stderr(o);
    assert_eq!(e.lines().count(), 1, "not one line: {e}");
    e
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

fn setup(name: &str) -> std::path::PathBuf {
    let dir = temp_dir(&format!("tcli-{name}"));
    std::fs::write(dir.join("s.dat"), SCENE).unwrap();
    dir
}

#[test]
fn a_single_image_is_written_under_tachyons_names_in_its_format() {
    let dir = setup("single");
    let out = ok(&tachyon(&dir, &["s.dat"]));
    assert!(out.contains("Ray Tracing Time:"), "{out}");
    let tga = image::open(dir.join("outfile.tga")).unwrap().to_rgb8();
    assert_eq!(tga.dimensions(), (24, 16));
    // -o is used verbatim: the format, not the extension, chooses the writer.
    ok(&tachyon(&dir, &["-o", "x.png", "s.dat", "-res", "12", "8"]));
    let x = std::fs::read(dir.join("x.png")).unwrap();
    let tga12 = image::load_from_memory_with_format(&x, image::ImageFormat::Tga)
        .unwrap()
        .to_rgb8();
    assert_eq!(tga12.dimensions(), (12, 8));
    ok(&tachyon(&dir, &["s.dat", "-format", "PNG"]));
    let png = image::open(dir.join("outfile.png")).unwrap().to_rgb8();
    assert_eq!(
        png.as_raw(),
        tga.as_raw(),
        "PNG and TGA hold the same pixels"
    );
    ok(&tachyon(&dir, &["s.dat", "-format", "bmp"]));
    assert_eq!(&std::fs::read(dir.join("outfile.bmp")).unwrap()[..2], b"BM");
    ok(&tachyon(&dir, &["s.dat", "-format", "PPM48"]));
    let ppm = std::fs::read(dir.join("outfile.ppm")).unwrap();
    assert!(ppm.starts_with(b"P6\n24 16\n65535\n"));
    ok(&tachyon(&dir, &["s.dat", "-format", "JPEG"]));
    assert!(dir.join("outfile.jpg").is_file());
    // -nosave renders and writes nothing.
    let before = files(&dir);
    ok(&tachyon(&dir, &["s.dat", "-nosave", "-o", "none.tga"]));
    assert_eq!(files(&dir), before);
}

#[test]
fn vmds_command_line_renders() {
    let dir = setup("vmd");
    let out = ok(&tachyon(
        &dir,
        &[
            "-aasamples",
            "4",
            "-trans_vmd",
            "-mediumshade",
            "s.dat",
            "-format",
            "TARGA",
            "-o",
            "s.dat.tga",
        ],
    ));
    assert!(out.contains("Scene Parsing Time:"), "{out}");
    assert!(dir.join("s.dat.tga").is_file());
}

#[test]
fn a_camera_file_renders_its_frames_with_tachyons_names() {
    let dir = setup("camfile");
    // Two frames and a final newline: Tachyon renders the last one twice (3 frames).
    std::fs::write(
        dir.join("path.cam"),
        "0 0 1  0 1 0  0 0 -6\n0.2 0.1 1  0 1 0  0 0 -6\n",
    )
    .unwrap();
    let out = ok(&tachyon(
        &dir,
        &["s.dat", "-camfile", "path.cam", "-format", "PPM"],
    ));
    assert!(out.contains("Completed animation of 3 frames"), "{out}");
    assert_eq!(out.matches("Rendering Frame to cam.").count(), 3, "{out}");
    let read = |n: &str| std::fs::read(dir.join(n)).unwrap();
    let frames: Vec<Vec<u8>> = (0..3).map(|k| read(&format!("cam.{k:04}.ppm"))).collect();
    assert_ne!(frames[0], frames[1]);
    assert_eq!(frames[1], frames[2], "the repeated last frame");
    // Frame 0 is the scene's own camera: the same image as a single render.
    ok(&tachyon(
        &dir,
        &["s.dat", "-format", "PPM", "-o", "single.ppm"],
    ));
    assert_eq!(frames[0], read("single.ppm"));
    // Frame 1 equals the scene rendered with that view direction.
    let turned = SCENE.replace("VIEWDIR 0 0 1", "VIEWDIR 0.2 0.1 1");
    std::fs::write(dir.join("turned.dat"), turned).unwrap();
    ok(&tachyon(
        &dir,
        &["turned.dat", "-format", "PPM", "-o", "turned.ppm"],
    ));
    assert_eq!(frames[1], read("turned.ppm"));

    // With -o: a %0Nd pattern numbers the frames; a plain name gets the number before its
    // extension, with a warning.
    ok(&tachyon(
        &dir,
        &["s.dat", "-camfile", "path.cam", "-o", "f%02d.tga"],
    ));
    for k in 0..3 {
        assert!(dir.join(format!("f{k:02}.tga")).is_file());
    }
    let o = tachyon(&dir, &["s.dat", "-camfile", "path.cam", "-o", "movie.tga"]);
    ok(&o);
    assert!(stderr(&o).contains("writing movie.0000.tga, movie.0001.tga, ..."));
    for k in 0..3 {
        assert!(dir.join(format!("movie.{k:04}.tga")).is_file());
    }
    // -nosave: every frame rendered, none written.
    let before = files(&dir);
    let out = ok(&tachyon(
        &dir,
        &["s.dat", "-camfile", "path.cam", "-nosave"],
    ));
    assert!(out.contains("Completed animation of 3 frames"));
    assert_eq!(files(&dir), before);
}

#[test]
fn camera_file_errors_name_the_frame_and_place() {
    let dir = setup("camfile-errors");
    std::fs::write(
        dir.join("bad.cam"),
        "0 0 1 0 1 0 0 0 -6\n0 0 0 0 1 0 0 0 -6",
    )
    .unwrap();
    let e = error(&tachyon(&dir, &["s.dat", "-camfile", "bad.cam"]));
    assert!(
        e.contains("bad.cam:2:1: frame 1 (cam.0001.tga): VIEWDIR is (0, 0, 0)"),
        "{e}"
    );
    std::fs::write(dir.join("short.cam"), "0 0 1 0 1 0 0 0").unwrap();
    let e = error(&tachyon(&dir, &["s.dat", "-camfile", "short.cam"]));
    assert!(e.contains("short.cam:1:1: frame 1 is incomplete"), "{e}");
    let e = error(&tachyon(&dir, &["s.dat", "-camfile", "missing.cam"]));
    assert!(
        e.contains("-camfile missing.cam: cannot read the camera file"),
        "{e}"
    );
}

#[test]
fn several_scenes_are_numbered() {
    let dir = setup("several");
    std::fs::write(dir.join("t.dat"), SCENE).unwrap();
    let out = ok(&tachyon(&dir, &["s.dat", "t.dat", "-format", "PNG"]));
    assert!(out.contains("Rendering 2 scene files."));
    assert!(dir.join("outfile.0000.png").is_file() && dir.join("outfile.0001.png").is_file());
}

#[test]
fn command_line_errors_are_one_line() {
    let dir = setup("errors");
    for (args, fragment) in [
        (
            &["s.dat", "-aasampels", "4"][..],
            "unknown option `-aasampels`; did you mean `-aasamples`?",
        ),
        (
            &["s.dat", "-format", "PSD48"][..],
            "Luxon cannot write this format; expected one of TARGA, BMP, PPM, PPM48, PNG, JPEG",
        ),
        (
            &["s.dat", "-res", "64"][..],
            "-res expects two values (width height)",
        ),
        (&["-aasamples", "4"][..], "no scene file"),
        (&["missing.dat"][..], "missing.dat"),
        (&["s.nff"][..], "render NFF scenes with `luxon render`"),
        (
            &["s.dat", "-camfile", "a.cam", "-o", "f%s.tga"][..],
            "`%s` is not a frame-number conversion",
        ),
    ] {
        let e = error(&tachyon(&dir, args));
        assert!(e.starts_with("luxon: error: "), "{e}");
        assert!(e.contains(fragment), "{args:?}: {e}");
    }
    assert!(!dir.join("outfile.tga").exists());
}

#[test]
fn help_version_and_warnings() {
    let dir = setup("help");
    let out = ok(&tachyon(&dir, &["-help"]));
    assert!(
        out.contains("-camfile") && out.contains("-trans_vmd"),
        "{out}"
    );
    assert!(ok(&tachyon(&dir, &["-version"])).starts_with("0.99"));
    // An option Luxon ignores is warned about once, and the render goes on.
    let o = tachyon(&dir, &["s.dat", "-nobounding", "-nobounding", "-nosave"]);
    ok(&o);
    let e = stderr(&o);
    assert_eq!(e.matches("-nobounding is not supported").count(), 1, "{e}");
}
