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
        "balls", "gears", "lattice", "mount", "rings", "teapot", "tetra", "tree",
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
        e.contains("balls, gears, lattice, mount, rings, teapot, tetra, tree"),
        "{e}"
    );
    assert!(!std::path::Path::new(f).exists());
}
