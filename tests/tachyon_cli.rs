//! `luxon tachyon`: Tachyon's command line as VMD and scripts use it: VMD's own command lines
//! on a scene as VMD exports it (and on VMD's export in Debian's examples), the files written
//! and their names (single images, camera-file sequences with Tachyon's end-of-file quirk,
//! several scenes), formats chosen by `-format` holding Tachyon's values (uncompressed Targa,
//! no sRGB curve), and one-line errors.

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

/// A single image is written without `fsync` (as Tachyon writes) but still atomically: into a
/// temporary file renamed over the target, never into the existing file, and nothing left
/// behind. A second name for the old file (a hard link) keeps the old bytes; writing in place
/// would change them.
#[test]
fn a_single_image_still_replaces_its_target_atomically() {
    let dir = setup("atomic");
    for (target, args) in [
        ("outfile.tga", &["s.dat"][..]),
        ("x.ppm", &["s.dat", "-format", "PPM", "-o", "x.ppm"][..]),
    ] {
        std::fs::write(dir.join(target), b"old").unwrap();
        let keep = dir.join("keep");
        std::fs::hard_link(dir.join(target), &keep).unwrap();
        ok(&tachyon(&dir, args));
        assert_eq!(
            std::fs::read(&keep).unwrap(),
            b"old",
            "{target} written in place"
        );
        let new = std::fs::read(dir.join(target)).unwrap();
        assert!(new.len() > 24 * 16 * 3, "{target}: {} bytes", new.len());
        std::fs::remove_file(&keep).unwrap();
    }
    assert_eq!(
        files(&dir),
        ["outfile.tga", "s.dat", "x.ppm"],
        "temporary files left"
    );
    // A scene that fails leaves the target as it was.
    std::fs::write(dir.join("bad.dat"), "BEGIN_SCENE RESOLUTION 8 8 SPHERE\n").unwrap();
    let before = std::fs::read(dir.join("outfile.tga")).unwrap();
    error(&tachyon(&dir, &["bad.dat"]));
    assert_eq!(std::fs::read(dir.join("outfile.tga")).unwrap(), before);
    assert_eq!(files(&dir), ["bad.dat", "outfile.tga", "s.dat", "x.ppm"]);
}

/// A scene as VMD 1.9 exports it: its header, mixed-case keywords, `Shader_Mode` with
/// `Trans_VMD` and `Fog_VMD`, `Raydepth 50`, directional lights, inline textures with `Phong
/// Plastic`, a translucent sphere, `FCylinder`, `VCSTri` and a `VertexArray` strip.
const VMD_SCENE: &str = "# \n\
# Molecular graphics exported from VMD 1.9.3\n\
# http://www.ks.uiuc.edu/Research/vmd/\n\
# Requires Tachyon version 0.99.0 or newer\n\
# \n\
# Default tachyon rendering command for this scene:\n\
#   tachyon  -aasamples 12 %s -format TARGA -o %s.tga\n\
# \n\
Begin_Scene\nResolution 40 30\n\
Shader_Mode Full\n  Trans_VMD\n  Fog_VMD\nEnd_Shader_Mode\n\
#  Cam\nCamera\n  Projection Perspective\n  Zoom 0.666667\n  Aspectratio 1\n  Antialiasing 12\n\
  Raydepth 50\n  Center  0 0 -4\n  Viewdir 0 0 1\n  Updir   0 1 0\nEnd_Camera\n\
Directional_Light Direction 0.1 -0.1 1 Color 1 1 1\n\
Directional_Light Direction -1 -2 0.5 Color 1 1 1\n\n\
Background 0.05 0.05 0.1\n\
Fog Linear Start 0.5 End 12 Density 0.3 Color 0.05 0.05 0.1\n\n\
# MoleculeID: 0 ReprID: 0 Beginning VDW\n\
Sphere \n  Center -1 0.2 0.3\n  Rad 0.8\n\
Texture Ambient 0 Diffuse 0.65 Specular 0 Opacity 1\n\
   Phong Plastic 0.5 Phong_size 40 Color 0.25 0.75 0.75 TexFunc 0\n\n\
Sphere \n  Center 0.9 -0.2 0.5\n  Rad 0.7\n\
Texture Ambient 0 Diffuse 0.65 Specular 0 Opacity 0.5\n\
   Phong Plastic 0.5 Phong_size 40 Color 1 0.3 0.2 TexFunc 0\n\n\
FCylinder\n  Base -1 0.2 0.3\n  Apex 0.9 -0.2 0.5\n  Rad 0.2\n\
Texture Ambient 0 Diffuse 0.65 Specular 0 Opacity 1\n\
   Phong Plastic 0.5 Phong_size 40 Color 0.9 0.9 0.9 TexFunc 0\n\n\
VCSTri V0 -2 -1.5 1 V1 2 -1.5 1 V2 0 -1.5 -1\n  N0 0 1 0 N1 0 1 0 N2 0 1 0\n\
  C0 1 0 0 C1 0 1 0 C2 0 0 1\n\
Ambient 0 Diffuse 0.65 Specular 0 Opacity 1\n  Phong Plastic 0.5 Phong_size 40 VCST\n\n\
VertexArray  Numverts 4\nCoords\n-2 -1 2\n-2 1.5 2\n2 -1 2\n2 1.5 2\n\
Normals\n0 0 -1\n0 0 -1\n0 0 -1\n0 0 -1\n\
Texture\n  Ambient 0 Diffuse 0.65 Specular 0 Opacity 1\n\
  Phong Plastic 0.5 Phong_size 40 Color 0.8 0.8 0.3 TexFunc 0\n\n\
TriStrip 4\n0 1 2 3 \nEnd_VertexArray\nEnd_Scene \n";

/// `bytes` as Tachyon writes a Targa: uncompressed 24-bit, top row first, `w`x`h`; its pixels.
fn targa(bytes: &[u8], w: u32, h: u32) -> image::RgbImage {
    assert_eq!(bytes[2], 2, "image type: uncompressed true colour");
    let size = |k: usize| u32::from(u16::from_le_bytes([bytes[k], bytes[k + 1]]));
    assert_eq!((size(12), size(14)), (w, h));
    assert_eq!(
        (bytes[16], bytes[17] & 0x20),
        (24, 0x20),
        "24 bits, top row first"
    );
    assert_eq!(bytes.len(), 18 + (w * h * 3) as usize);
    image::load_from_memory_with_format(bytes, image::ImageFormat::Tga)
        .unwrap()
        .to_rgb8()
}

/// A scene's picture as `luxon tachyon` must write it: the framebuffer of the scene (with
/// `samples`) truncated to 8 bits as Tachyon writes, without the sRGB curve.
fn expected(scene: &Path, samples: u32) -> Vec<u8> {
    let fb = render_with(scene, |d| d.render.samples = samples);
    fb.rgba
        .chunks_exact(4)
        .flat_map(|p| [0, 1, 2].map(|k| (p[k].clamp(0.0, 1.0) * 255.0).floor() as u8))
        .collect()
}

#[test]
fn vmds_command_lines_render() {
    let dir = setup("vmd");
    std::fs::write(dir.join("vmdscene.dat"), VMD_SCENE).unwrap();
    // VMD 1.9's render command, `%s` replaced by the scene file's name.
    let o = tachyon(
        &dir,
        &[
            "-aasamples",
            "12",
            "vmdscene.dat",
            "-format",
            "TARGA",
            "-o",
            "vmdscene.dat.tga",
        ],
    );
    let out = ok(&o);
    assert!(out.contains("Ray Tracing Time:"), "{out}");
    // The vertex colours are drawn: nothing to warn about.
    assert!(!stderr(&o).contains("VCSTRI"), "{}", stderr(&o));
    let tga = std::fs::read(dir.join("vmdscene.dat.tga")).unwrap();
    let img = targa(&tga, 40, 30);
    assert_eq!(img.as_raw(), &expected(&dir.join("vmdscene.dat"), 13));
    // A picture, not a blank: the cyan sphere, the red one and the wall, on a dark background.
    let colours: std::collections::HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(colours.len() > 100, "{} colours", colours.len());
    let cyan = img
        .pixels()
        .filter(|p| p[2] > 80 && p[0] < p[2] / 2)
        .count();
    // Under Tachyon's shading rules the red sphere is dim: red well above green and blue.
    let red = img
        .pixels()
        .filter(|p| p[0] > 50 && p[0] > p[1] + 20 && p[0] > p[2] + 20)
        .count();
    assert!(cyan > 15 && red > 8, "cyan {cyan}, red {red}");
    assert_eq!(
        img.get_pixel(0, 0).0,
        [12, 12, 25],
        "the background, as Tachyon writes it"
    );

    // VMD 1.8.6's command (janbadoutput.dat's header gives it) with what users add.
    ok(&tachyon(
        &dir,
        &[
            "-aasamples",
            "4",
            "-trans_vmd",
            "-mediumshade",
            "vmdscene.dat",
            "-format",
            "TARGA",
            "-o",
            "vmdscene.dat.tga",
            "-res",
            "48",
            "32",
            "-numthreads",
            "2",
            "-trans_max_surfaces",
            "1",
        ],
    ));
    let small = targa(
        &std::fs::read(dir.join("vmdscene.dat.tga")).unwrap(),
        48,
        32,
    );
    assert_ne!(small.get_pixel(24, 16).0, [12, 12, 25]);
    ok(&tachyon(
        &dir,
        &[
            "-auto_skylight",
            "0.7",
            "-skylight_samples",
            "4",
            "vmdscene.dat",
            "-format",
            "PNG",
            "-o",
            "ao.png",
        ],
    ));
    let ao = image::open(dir.join("ao.png")).unwrap().to_rgb8();
    assert_eq!(ao.dimensions(), (40, 30));
    assert_ne!(ao.as_raw(), img.as_raw());

    // The same command line on the small test scene: 1 + 12 samples per pixel.
    ok(&tachyon(
        &dir,
        &[
            "-aasamples",
            "12",
            "s.dat",
            "-format",
            "TARGA",
            "-o",
            "s.dat.tga",
        ],
    ));
    let s = targa(&std::fs::read(dir.join("s.dat.tga")).unwrap(), 24, 16);
    assert_eq!(s.as_raw(), &expected(&dir.join("s.dat"), 13));
    assert_ne!(s.as_raw(), &expected(&dir.join("s.dat"), 1));
}

/// Mid-tone colours come out with Tachyon's values: written as they are (no sRGB curve),
/// truncated; with `tachyon-nox` installed, the same file as Tachyon's.
#[test]
fn images_hold_tachyons_values() {
    let dir = setup("tones");
    let unlit =
        |c: &str| format!("TEXTURE AMBIENT 1 DIFFUSE 0 SPECULAR 0 OPACITY 1 COLOR {c} TEXFUNC 0");
    let scene = format!(
        "BEGIN_SCENE RESOLUTION 32 24\nBACKGROUND 0.3 0.6 0.2\n\
         SPHERE CENTER -0.6 0 5 RAD 0.8 {}\nSPHERE CENTER 0.9 0.2 5 RAD 0.6 {}\nEND_SCENE\n",
        unlit("0.5 0.25 0.1"),
        unlit("0.9 0.7 0.05")
    );
    std::fs::write(dir.join("tones.dat"), scene).unwrap();
    ok(&tachyon(
        &dir,
        &["tones.dat", "-format", "PPM", "-o", "luxon.ppm"],
    ));
    let ours = std::fs::read(dir.join("luxon.ppm")).unwrap();
    let header = b"P6\n32 24\n255\n";
    assert!(ours.starts_with(header));
    let px: Vec<&[u8]> = ours[header.len()..].chunks_exact(3).collect();
    // floor(255 c): the background, then the centres of the two spheres.
    assert_eq!(px[0], [76, 153, 51]);
    assert_eq!(px[12 * 32 + 11], [127, 63, 25]);
    assert_eq!(px[11 * 32 + 22], [229, 178, 12]);
    // -normalize and -gamma on a background of (0.5, 0.25, 0.1): tachyon-nox writes
    // (255, 95, 0) and (255, 163, 0).
    std::fs::write(
        dir.join("flat.dat"),
        "BEGIN_SCENE RESOLUTION 4 4 BACKGROUND 0.5 0.25 0.1 END_SCENE",
    )
    .unwrap();
    for (option, rgb) in [
        (&["-normalize"][..], [255, 95, 0]),
        (&["-gamma", "2.2"][..], [255, 163, 0]),
    ] {
        let mut args = vec!["flat.dat", "-format", "PPM", "-o", "flat.ppm"];
        args.extend(option);
        let o = tachyon(&dir, &args);
        ok(&o);
        assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
        let ppm = std::fs::read(dir.join("flat.ppm")).unwrap();
        assert_eq!(ppm[ppm.len() - 3..], rgb, "{option:?}");
    }
    let Ok(run) = std::process::Command::new("tachyon-nox")
        .current_dir(&dir)
        .args(["tones.dat", "-format", "PPM", "-o", "tachyon.ppm"])
        .output()
    else {
        eprintln!("note: tachyon-nox is not installed; not compared with Tachyon's file");
        return;
    };
    assert!(run.status.success());
    let theirs = std::fs::read(dir.join("tachyon.ppm")).unwrap();
    assert_eq!(ours.len(), theirs.len());
    // Pixels whose sample point lies on an edge may fall either way in f32: a handful.
    let differ = ours
        .chunks_exact(3)
        .zip(theirs.chunks_exact(3))
        .filter(|(a, b)| a != b);
    assert!(
        differ.count() <= 2,
        "more than 2 pixels differ from Tachyon's"
    );
}

/// VMD 1.8.6's own export in Debian's examples, with the command line its header suggests, run
/// in a copy of the scene's directory as VMD runs Tachyon.
#[test]
fn vmds_example_renders_with_its_own_command_line() {
    let src = Path::new("/usr/share/doc/tachyon/examples/scenes/janbadoutput.dat");
    if !src.is_file() {
        eprintln!("note: Debian's tachyon-doc is not installed; janbadoutput.dat not rendered");
        return;
    }
    let dir = temp_dir("tcli-janbad");
    std::fs::copy(src, dir.join("janbadoutput.dat")).unwrap();
    let header = std::fs::read_to_string(src).unwrap();
    let line = "tachyon  -aasamples 4 -trans_vmd -mediumshade %s -format TARGA -o %s.tga";
    assert!(header.contains(line));
    let args: Vec<String> = line
        .split_whitespace()
        .skip(1)
        .map(|w| w.replace("%s", "janbadoutput.dat"))
        .collect();
    let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    ok(&tachyon(&dir, &args));
    let img = targa(
        &std::fs::read(dir.join("janbadoutput.dat.tga")).unwrap(),
        514,
        247,
    );
    // A white background and the pink molecular surface.
    assert_eq!(img.get_pixel(0, 0).0, [255, 255, 255]);
    let pink = img
        .pixels()
        .filter(|p| p[0] > 180 && p[2] > 150 && u16::from(p[1]) + 30 < u16::from(p[0]))
        .count();
    assert!(pink > 3000, "{pink} pink pixels");
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

/// A light with a radius is also a sphere that casts no shadow: `luxon render` of the `.dat`
/// (which takes the imported geometry out of the scene while building) lights the scene exactly
/// as the same light without its sphere, where the sphere is out of view.
#[test]
fn light_spheres_do_not_shadow_their_own_light() {
    let dir = temp_dir("tcli-lightsphere");
    let scene = |rad: &str| {
        SCENE
            .replace(
                "LIGHT CENTER 4 5 -6 RAD 0",
                &format!("LIGHT CENTER 4 5 -6 RAD {rad}"),
            )
            .replace("CENTER 0 0 -6 VIEWDIR", "CENTER 0 0 -5 VIEWDIR")
    };
    let mut images = Vec::new();
    for rad in ["0", "0.2"] {
        let (dat, png) = (
            dir.join(format!("l{rad}.dat")),
            dir.join(format!("l{rad}.png")),
        );
        std::fs::write(&dat, scene(rad)).unwrap();
        let o = run(&["render", dat.to_str().unwrap(), "-o", png.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        images.push(image::open(&png).unwrap().to_rgb8());
    }
    let lit = images[0]
        .pixels()
        .map(|p| p.0[0].max(p.0[1]).max(p.0[2]))
        .max();
    assert!(lit > Some(150), "the lit scene is dark: {lit:?}");
    assert!(
        images[0] == images[1],
        "the light's sphere shadows the scene"
    );
}
