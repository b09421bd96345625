//! `luxon spd`: generating SPD scenes from the command line, in every output format, and its
//! errors.

mod common;

use common::*;

fn no_temp_files_in(dir: &std::path::Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().to_string();
        assert!(!name.ends_with(".tmp"), "temporary file {name} left behind");
    }
}

#[test]
fn writes_nff_that_luxon_reads() {
    let dir = temp_dir("spd-nff");
    let f = dir.join("balls2.nff");
    let out = run(&["spd", "balls", "--size", "2", "-o", f.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("91 spheres, 1 polygon"),
        "{}",
        stderr(&out)
    );
    let text = std::fs::read_to_string(&f).unwrap();
    assert!(
        text.starts_with("b 0.078 0.361 0.753\nv\nfrom 2.1 1.3 1.7\n"),
        "{text}"
    );
    assert_eq!(text.lines().filter(|l| l.starts_with("s ")).count(), 91);
    no_temp_files_in(&dir);
    let check = run(&["check", f.to_str().unwrap()]);
    assert!(check.status.success(), "{}", stderr(&check));
}

#[test]
fn default_size_and_gzip() {
    let dir = temp_dir("spd-gz");
    let f = dir.join("tetra.nff.gz");
    let out = run(&["spd", "tetra", "-o", f.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("tetra -s 5: 4096 polygons"),
        "{}",
        stderr(&out)
    );
    let bytes = std::fs::read(&f).unwrap();
    assert_eq!(&bytes[..2], &[0x1f, 0x8b], "not gzip");
    let check = run(&["check", f.to_str().unwrap()]);
    assert!(check.status.success(), "{}", stderr(&check));
}

#[test]
fn writes_ron_scenes_that_load() {
    let dir = temp_dir("spd-ron");
    for (name, size) in [
        ("gears", "1"),
        ("lattice", "2"),
        ("teapot", "2"),
        ("mount", "2"),
    ] {
        let f = dir.join(format!("{name}.ron"));
        let out = run(&["spd", name, "-s", size, "-o", f.to_str().unwrap()]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let text = std::fs::read_to_string(&f).unwrap();
        assert!(text.contains("Scene("), "{name}");
        let check = run(&["check", f.to_str().unwrap()]);
        assert!(check.status.success(), "{name}: {}", stderr(&check));
    }
    no_temp_files_in(&dir);
}

#[test]
fn lists_the_scenes() {
    let out = run(&["spd"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    for name in [
        "balls", "gears", "jacks", "lattice", "mount", "rings", "shells", "sombrero", "teapot",
        "tetra", "tree",
    ] {
        assert!(text.contains(name), "{name} missing from\n{text}");
    }
}

#[test]
fn one_line_errors() {
    let dir = temp_dir("spd-errors");
    let f = dir.join("x.nff");
    let f = f.to_str().unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["spd", "bals", "-o", f], "did you mean `balls`?"),
        (&["spd", "balls", "-s", "9", "-o", f], "expected 0..=8"),
        (
            &["spd", "tree", "-o", "x.obj"],
            "expected a name ending in .nff, .nff.gz or .ron",
        ),
        (&["spd", "tree"], "needs -o FILE"),
    ];
    for (args, expected) in cases {
        let out = run(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let e = stderr(&out);
        assert!(e.starts_with("luxon: error: "), "{e}");
        assert!(e.contains(expected), "{args:?}: {e}");
        assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    }
    let e = stderr(&run(&["spd", "teapt", "-o", f]));
    assert!(
        e.contains(
            "balls, gears, jacks, lattice, mount, rings, shells, sombrero, teapot, tetra, tree"
        ),
        "{e}"
    );
    assert!(!std::path::Path::new(f).exists());
}

/// A scene name, what `luxon spd` reports writing, and whether a linear RGB pixel has the
/// object's colour.
type Case = (&'static str, &'static str, fn([f32; 3]) -> bool);

/// The SPD databases added after 1987 (`jacks`, `shells`, `sombrero`): written by `luxon spd` at
/// their default sizes with the published counts, read back, and rendered small into a picture
/// that shows the object (not only background) in its own colour.
#[test]
fn later_databases_generate_and_render() {
    let dir = temp_dir("spd-later");
    let cases: [Case; 3] = [
        // Pink jacks on dark purple.
        ("jacks", "jacks -s 1: 6 spheres, 3 cones", |p| {
            p[0] > 0.1 && p[0] > 1.2 * p[2]
        }),
        // Golden spheres on sky blue.
        ("shells", "shells -s 5: 5761 spheres", |p| {
            p[0] > 0.1 && p[0] > 1.5 * p[2]
        }),
        // A red surface on sky blue.
        ("sombrero", "sombrero -s 1: 1922 polygons", |p| {
            p[0] > 0.05 && p[0] > 3.0 * p[1]
        }),
    ];
    for (name, counts, own_colour) in cases {
        let f = dir.join(format!("{name}.nff"));
        let out = run(&["spd", name, "-o", f.to_str().unwrap()]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        assert!(stderr(&out).contains(counts), "{name}: {}", stderr(&out));
        let fb = render_with(&f, |d| {
            d.render.width = 96;
            d.render.height = 96;
        });
        let pixels: Vec<[f32; 3]> = fb
            .rgba
            .chunks_exact(4)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        let object = pixels.iter().filter(|p| own_colour(**p)).count();
        let share = object as f64 / pixels.len() as f64;
        assert!(
            (0.02..0.95).contains(&share),
            "{name}: {:.1} % of the picture in the object's colour",
            100.0 * share
        );
    }
}

/// Generating twice gives the same bytes.
#[test]
fn later_databases_are_deterministic() {
    let dir = temp_dir("spd-later-det");
    for name in ["jacks", "shells", "sombrero"] {
        let (a, b) = (
            dir.join(format!("{name}-a.nff")),
            dir.join(format!("{name}-b.nff")),
        );
        for f in [&a, &b] {
            let out = run(&["spd", name, "-s", "2", "-o", f.to_str().unwrap()]);
            assert!(out.status.success(), "{name}: {}", stderr(&out));
        }
        assert_eq!(
            std::fs::read(&a).unwrap(),
            std::fs::read(&b).unwrap(),
            "{name}"
        );
    }
}
