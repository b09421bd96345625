//! `luxon new-plugin`: a crate of every kind, written outside the repository (inside another
//! workspace's directory, which its own `[workspace]` table keeps it out of), builds against
//! this checkout's SDK with the README's command and renders its scene with the README's
//! command. The crates share one target directory under the workspace's, so their
//! dependencies compile once, and are built offline.

mod common;

use common::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const KINDS: [&str; 4] = ["primitive", "texture", "writer", "volume"];

/// Where the generated crates are built: beside the workspace's own profiles.
fn target_dir() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .unwrap()
        .join("plugin-templates")
}

fn ok(what: &str, o: &Output) {
    assert!(
        o.status.success(),
        "{what} failed\nstdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stdout),
        stderr(o)
    );
}

/// The plugin's name for `kind` (distinct from every shipped plugin).
fn name(kind: &str) -> String {
    format!("tmpl-{kind}")
}

/// Distinct colours of an 8-bit RGB picture.
fn colours(px: &[u8]) -> usize {
    let mut v: Vec<&[u8]> = px.chunks_exact(3).collect();
    v.sort();
    v.dedup();
    v.len()
}

/// The width, height and RGB floats of a PFM file (as the writer template writes it: RGB,
/// little-endian, rows from the bottom).
fn read_pfm(bytes: &[u8]) -> (usize, usize, Vec<f32>) {
    let mut header = bytes.splitn(4, |&b| b == b'\n');
    assert_eq!(header.next(), Some(&b"PF"[..]));
    let size = std::str::from_utf8(header.next().unwrap()).unwrap();
    let (w, h) = size.split_once(' ').unwrap();
    let (w, h): (usize, usize) = (w.parse().unwrap(), h.parse().unwrap());
    assert_eq!(header.next(), Some(&b"-1.0"[..]));
    let data = header.next().unwrap();
    assert_eq!(data.len(), w * h * 12, "PFM data size");
    let values = data
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    (w, h, values)
}

#[test]
fn every_kind_builds_outside_the_repository_and_renders() {
    let dir = temp_dir("templates");
    assert!(
        !dir.starts_with(root()),
        "{} is inside the repository",
        dir.display()
    );
    // Another project's workspace around the crates.
    std::fs::write(dir.join("Cargo.toml"), "[workspace]\nmembers = []\n").unwrap();
    let sdk = root().join("plugins/sdk");
    for kind in KINDS {
        let crate_dir = dir.join(kind);
        let o = run(&[
            "new-plugin",
            &name(kind),
            "--kind",
            kind,
            "--dir",
            crate_dir.to_str().unwrap(),
            "--sdk",
            sdk.to_str().unwrap(),
        ]);
        ok("luxon new-plugin", &o);
        assert!(
            stderr(&o).contains("cargo build --release"),
            "{}",
            stderr(&o)
        );
        let manifest = std::fs::read_to_string(crate_dir.join("Cargo.toml")).unwrap();
        assert!(
            manifest.contains(&format!(
                "luxon-plugin = {{ path = \"{}\" }}",
                sdk.display()
            )),
            "{manifest}"
        );
        let readme = std::fs::read_to_string(crate_dir.join("README.md")).unwrap();
        assert!(readme.contains("\ncargo build --release\n"), "{readme}");
        // The generated code is formatted as rustfmt would.
        let fmt = Command::new(env!("CARGO"))
            .args(["fmt", "--check", "--manifest-path"])
            .arg(crate_dir.join("Cargo.toml"))
            .output()
            .unwrap();
        ok(&format!("cargo fmt --check of the {kind} template"), &fmt);
    }

    // The README's build command, offline, into the shared target directory.
    for kind in KINDS {
        let o = Command::new(env!("CARGO"))
            .args(["build", "--release", "--offline", "--quiet"])
            .current_dir(dir.join(kind))
            .env("CARGO_TARGET_DIR", target_dir())
            .output()
            .unwrap();
        ok(&format!("cargo build of the {kind} template"), &o);
    }
    let plugins = target_dir().join("release");
    let luxon_in = |kind: &str| {
        let mut c = luxon();
        c.current_dir(dir.join(kind))
            .env("LUXON_PLUGIN_PATH", &plugins);
        c
    };

    // Each plugin is found under its name and kind.
    let o = luxon_in("texture").arg("plugins").output().unwrap();
    ok("luxon plugins", &o);
    let listing = String::from_utf8_lossy(&o.stdout);
    for (kind, shown) in KINDS
        .iter()
        .zip(["primitive", "texture", "writer", "volume reader"])
    {
        assert!(
            listing.contains(&format!("  {shown} `{}`", name(kind))),
            "{kind}: {listing}"
        );
    }

    // The README's render command: a picture with something in it.
    for kind in ["primitive", "texture", "volume"] {
        let o = luxon_in(kind)
            .args(["render", "scene.ron", "-o", "x.png"])
            .output()
            .unwrap();
        ok(&format!("rendering the {kind} template's scene"), &o);
        let png = image::open(dir.join(kind).join("x.png")).unwrap().to_rgb8();
        let n = colours(png.as_raw());
        assert!(n > 100, "{kind}: the picture has only {n} colours");
        if kind != "volume" {
            let lit = png.as_raw().iter().filter(|&&v| v > 40).count();
            assert!(lit > png.as_raw().len() / 2, "{kind}: the picture is dark");
        }
    }
    // The volume shows: its centre is brighter than the background.
    let png = image::open(dir.join("volume/x.png")).unwrap().to_rgb8();
    let centre = png.get_pixel(png.width() / 2, png.height() / 2);
    let corner = png.get_pixel(2, 2);
    assert!(
        centre[0] > corner[0] + 100,
        "centre {centre:?}, corner {corner:?}"
    );

    // The writer writes the file the extension chose, and the scene's own output.
    let o = luxon_in("writer")
        .args(["render", "scene.ron", "-o", "x.pfm"])
        .output()
        .unwrap();
    ok("rendering the writer template's scene", &o);
    let o = luxon_in("writer")
        .args(["render", "scene.ron"])
        .output()
        .unwrap();
    ok(
        "rendering the writer template's scene to its own output",
        &o,
    );
    let x = std::fs::read(dir.join("writer/x.pfm")).unwrap();
    let own = std::fs::read(dir.join("writer").join(format!("{}.pfm", name("writer")))).unwrap();
    assert_eq!(x, own, "the same picture either way");
    let (w, h, rgb) = read_pfm(&x);
    assert_eq!((w, h), (320, 240));
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    // Rows from the bottom: the first is the floor, the last the sky (the background).
    let sky = |px: &[f32]| {
        px.iter()
            .zip([0.6, 0.7, 0.85])
            .all(|(v, s)| (v - s).abs() < 1e-5)
    };
    assert!(
        sky(&rgb[(h - 1) * w * 3..][..3]),
        "the top row is not the sky"
    );
    assert!(!sky(&rgb[..3]), "the bottom row is not the floor");
    let distinct = {
        let mut v: Vec<[u32; 3]> = rgb
            .chunks_exact(3)
            .map(|c| [c[0].to_bits(), c[1].to_bits(), c[2].to_bits()])
            .collect();
        v.sort();
        v.dedup();
        v.len()
    };
    assert!(distinct > 100, "the PFM has only {distinct} colours");
}

#[test]
fn new_plugin_refuses_a_bad_name_and_a_directory_in_use() {
    let dir = temp_dir("new-plugin-errors");
    let o = run(&["new-plugin", "My Plugin", "--kind", "texture", "--dir", "x"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("plugin name `My Plugin` does not start with a lowercase letter"),
        "{}",
        stderr(&o)
    );
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let o = run(&[
        "new-plugin",
        "dots",
        "--kind",
        "texture",
        "--dir",
        dir.to_str().unwrap(),
        "--sdk",
        "0.2",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains(&format!(
            "{}: the directory exists and is not empty",
            dir.display()
        )),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("Cargo.toml").exists());
    let o = run(&["new-plugin", "dots", "--kind", "shader"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("'shader'"), "{}", stderr(&o));
}

#[test]
fn help_shows_the_commands_that_follow() {
    let o = run(&["help", "new-plugin"]);
    ok("luxon help new-plugin", &o);
    let help = String::from_utf8_lossy(&o.stdout);
    for line in [
        "--kind <KIND>",
        "cargo build --release",
        "LUXON_PLUGIN_PATH=target/release luxon render scene.ron -o x.png",
    ] {
        assert!(help.contains(line), "{help}");
    }
    let o = run(&["help"]);
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("new-plugin"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
}
