//! The `luxon` command as a user meets it: outputs, exit codes, one-line errors.

mod common;

use common::*;

fn scene(name: &str) -> String {
    root().join("scenes").join(name).display().to_string()
}

#[test]
fn render_writes_every_format_by_extension() {
    let dir = temp_dir("formats");
    let outs: Vec<String> = ["png", "jpg", "ppm", "tga", "exr"]
        .iter()
        .map(|e| dir.join(format!("out.{e}")).display().to_string())
        .collect();
    let mut args = vec![
        "render",
        &*Box::leak(scene("spheres.ron").into_boxed_str()),
        "--res",
        "64x40",
    ];
    for o in &outs {
        args.extend(["-o", o.as_str()]);
    }
    let out = run(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    for o in &outs[..4] {
        let img = image::open(o)
            .unwrap_or_else(|e| panic!("{o}: {e}"))
            .to_rgb8();
        assert_eq!((img.width(), img.height()), (64, 40));
        let first = img.get_pixel(0, 0);
        assert!(img.pixels().any(|p| p != first), "{o} is one flat colour");
    }
    let exr = std::fs::read(&outs[4]).unwrap();
    assert_eq!(&exr[..4], &[0x76, 0x2f, 0x31, 0x01], "not an OpenEXR file");
}

#[test]
fn stats_print_rays_per_kind() {
    let dir = temp_dir("stats");
    let o = dir.join("g.png");
    let out = run(&[
        "render",
        &scene("glass.ron"),
        "-o",
        o.to_str().unwrap(),
        "--res",
        "48x32",
        "--stats",
        "--threads",
        "2",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let e = stderr(&out);
    let count = |label: &str| -> u64 {
        let line = e
            .lines()
            .find(|l| l.trim_start().starts_with(label))
            .unwrap_or_else(|| panic!("no `{label}` in {e}"));
        line.split_whitespace()
            .nth(if label == "intersection" { 2 } else { 1 })
            .unwrap()
            .parse()
            .unwrap()
    };
    assert_eq!(count("primary"), 48 * 32 * 4);
    assert!(count("shadow") > 0 && count("reflection") > 0 && count("refraction") > 0);
    assert!(count("intersection") > count("primary"));
    assert!(e.contains("threads          2"), "{e}");
    assert!(
        e.contains("BVH build") && e.contains("NaN pixels       0"),
        "{e}"
    );
}

#[test]
fn unused_effects_cast_no_rays() {
    // The antialiasing scene has no shadows (its light casts none), no mirrors and no glass.
    let dir = temp_dir("effects");
    let o = dir.join("a.png");
    let out = run(&[
        "render",
        &scene("antialiasing.ron"),
        "-o",
        o.to_str().unwrap(),
        "--res",
        "32x24",
        "--stats",
    ]);
    let e = stderr(&out);
    for kind in ["shadow", "reflection", "refraction"] {
        let line = e
            .lines()
            .find(|l| l.trim_start().starts_with(kind))
            .unwrap();
        assert!(line.trim_end().ends_with(" 0"), "{line}");
    }
}

#[test]
fn check_describes_the_scene_without_rendering() {
    let out = run(&["check", &scene("torus.ron")]);
    assert!(out.status.success(), "{}", stderr(&out));
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(
        s.contains("2 torus")
            && s.contains("2 custom")
            && s.contains("effects    shadows, reflection, textures, antialiasing"),
        "{s}"
    );
    assert!(!root().join("out/torus-should-not-exist.png").exists());
}

#[test]
fn scene_errors_are_one_line_with_file_line_col() {
    let dir = temp_dir("syntax");
    let p = dir.join("bad.ron");
    std::fs::write(&p, "Scene(\n  camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n  objects: [(plugin: \"sphere\", params: (center: (0, 0, 0), radius: 1), materal: \"x\")],\n)\n").unwrap();
    let out = run(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        dir.join("x.png").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let e = stderr(&out);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(
        e.starts_with(&format!("luxon: error: {}:3:", p.display())),
        "{e}"
    );
    assert!(e.contains("did you mean `material`"), "{e}");
}

#[test]
fn unknown_output_extension_lists_the_known_ones() {
    let dir = temp_dir("ext");
    let out = run(&[
        "render",
        &scene("spheres.ron"),
        "-o",
        dir.join("x.xyz").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let e = stderr(&out);
    assert!(
        e.contains("no writer for") && e.contains(".png") && e.contains(".exr"),
        "{e}"
    );
}

#[test]
fn a_failed_write_leaves_the_existing_file_untouched() {
    let dir = temp_dir("atomic");
    let target = dir.join("keep.png");
    std::fs::write(&target, b"precious").unwrap();
    let p = dir.join("s.ron");
    std::fs::write(
        &p,
        r#"Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
            objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1))],
            render: (width: 8, height: 8, outputs: [(path: "keep.png", params: (bits: 12))]))"#,
    )
    .unwrap();
    let out = run(&["render", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("expected 8 or 16"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read(&target).unwrap(), b"precious");
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        2,
        "a temporary file was left behind"
    );
}

#[test]
fn missing_scene_and_bad_arguments() {
    let out = run(&["render", "/nonexistent/scene.ron", "-o", "x.png"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("/nonexistent/scene.ron"),
        "{}",
        stderr(&out)
    );
    let out = run(&["render", &scene("spheres.ron"), "--res", "0x10"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("out of range"), "{}", stderr(&out));
}

#[test]
fn empty_scene_renders_the_background() {
    let dir = temp_dir("empty");
    let p = dir.join("empty.ron");
    std::fs::write(
        &p,
        "Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), background: (0.2, 0.4, 0.6))",
    )
    .unwrap();
    let o = dir.join("e.png");
    let out = run(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        o.to_str().unwrap(),
        "--res",
        "8x8",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(&o).unwrap().to_rgb8();
    let px = img.get_pixel(3, 3).0;
    let want = [0.2f32, 0.4, 0.6].map(|v| (luxon_plugin::linear_to_srgb(v) * 255.0 + 0.5) as u8);
    assert_eq!(px, want);
}

#[test]
fn renders_an_obj_file_with_its_mtl_colour() {
    let dir = temp_dir("obj");
    // A cube; its MTL makes it teal. No normals in the file: they are computed.
    let mut obj = String::from("mtllib cube.mtl\nusemtl teal\n");
    for z in [-1, 1] {
        for y in [-1, 1] {
            for x in [-1, 1] {
                obj.push_str(&format!("v {x} {y} {z}\n"));
            }
        }
    }
    for f in [
        "1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6",
    ] {
        obj.push_str(&format!("f {f}\n"));
    }
    std::fs::write(dir.join("cube.obj"), obj).unwrap();
    std::fs::write(dir.join("cube.mtl"), "newmtl teal\nKd 0.1 0.6 0.6\n").unwrap();
    let out = dir.join("cube.png");
    let o = run(&[
        "render",
        dir.join("cube.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--res",
        "32x32",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let px = image::open(&out).unwrap().to_rgb8().get_pixel(16, 16).0;
    assert!(
        px[1] > px[0] + 40 && px[2] > px[0] + 40,
        "centre pixel {px:?} is not teal"
    );
}

#[test]
fn shading_switches_change_what_is_traced() {
    let dir = temp_dir("shade");
    let o = dir.join("s.png");
    let count = |args: &[&str], kind: &str| -> u64 {
        let mut all = vec![
            "render",
            &*Box::leak(scene("spheres.ron").into_boxed_str()),
            "-o",
            o.to_str().unwrap(),
            "--res",
            "48x32",
            "--stats",
        ];
        all.extend_from_slice(args);
        let out = run(&all);
        assert!(out.status.success(), "{}", stderr(&out));
        let e = stderr(&out);
        let line = e
            .lines()
            .find(|l| l.trim_start().starts_with(kind))
            .unwrap_or_else(|| panic!("no {kind} in {e}"));
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    assert!(count(&[], "shadow") > 0 && count(&[], "reflection") > 0);
    assert_eq!(count(&["--shade", "medium"], "shadow"), 0);
    assert!(count(&["--shade", "medium"], "reflection") > 0);
    assert_eq!(count(&["--shade", "low"], "reflection"), 0);
    assert_eq!(count(&["--no-shadows"], "shadow"), 0);
    assert_eq!(count(&["--max-depth", "0"], "reflection"), 0);
    assert_eq!(count(&[], "occlusion"), 0);
    assert!(count(&["--ao", "4"], "occlusion") > 0);
}

/// Command-line errors are one `luxon: error:` line with status 1, like every other error;
/// help and version print with status 0.
#[test]
fn command_line_errors_are_one_line_and_exit_1() {
    for (args, want) in [
        (
            &["render", "--samples", "x", "s.ron"][..],
            "luxon: error: invalid value 'x' for '--samples",
        ),
        (&["rendr"][..], "did you mean `render`?"),
        (&["render"][..], "<SCENE>"),
    ] {
        let out = run(args);
        let e = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{args:?}: {e}");
        assert!(
            e.contains(want) && e.starts_with("luxon: error: "),
            "{args:?}: {e}"
        );
    }
    for args in [&["--help"][..], &["--version"], &["render", "--help"]] {
        let out = run(args);
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        assert!(!out.stdout.is_empty(), "{args:?}");
    }
}

/// Plugin messages reach stderr through the sink the command installs (the library prints
/// nothing by itself: tests/log.rs), one `luxon: warning:` line each.
#[test]
fn plugin_log_lines_are_printed_by_render() {
    let dir = temp_dir("plugin-log");
    let ron = dir.join("mesh.ron");
    std::fs::write(
        &ron,
        r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: 40),
    objects: [(plugin: "mesh", params: (positions: [(-1, -1, 0), (1, -1, 0), (0, 1, 0)], indices: [(0, 1, 2), (2, 2, 0)]))],
)"#,
    )
    .unwrap();
    let png = dir.join("mesh.png");
    let out = run(&[
        "render",
        ron.to_str().unwrap(),
        "--res",
        "8x8",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let e = stderr(&out);
    let lines: Vec<&str> = e.lines().filter(|l| l.contains("zero area")).collect();
    assert_eq!(
        lines,
        ["luxon: warning: luxon-shapes: mesh object 0: dropped 1 of 2 triangles with zero area"],
        "{e}"
    );
}

#[test]
fn loader_warnings_are_printed_by_render_and_check() {
    let dir = temp_dir("loader-warnings");
    // An OBJ polyline is defined by the format but not drawn: a warning, not an error.
    let obj = dir.join("lines.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2 3\n").unwrap();
    let png = dir.join("lines.png");
    for args in [
        vec!["check", obj.to_str().unwrap()],
        vec![
            "render",
            obj.to_str().unwrap(),
            "--res",
            "16x16",
            "-o",
            png.to_str().unwrap(),
        ],
    ] {
        let out = run(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        let e = stderr(&out);
        let line = e
            .lines()
            .find(|l| l.starts_with("luxon: warning: ") && l.contains("lines.obj:5:"))
            .unwrap_or_else(|| panic!("no warning at lines.obj:5 in:\n{e}"));
        assert!(line.contains("`l`"), "{line}");
    }
}
