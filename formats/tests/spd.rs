//! The SPD generators against the SPD programs' own output (`../shared/spd/*.nff.gz`, when the
//! directory exists): every primitive, in order, with coordinates equal within 1e-4; the same
//! materials, lights and view. `mount`'s heights come from the SPD's random number generator,
//! which is not reproduced: there the heights are only reported, everything else must match.

use std::io::Read;
use std::path::PathBuf;

use luxon_formats::spd;

const TOLERANCE: f64 = 1e-4;

fn shared() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/spd");
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "note: {} not found; skipping the comparison with the SPD's reference files",
            dir.display()
        );
        None
    }
}

/// One NFF entity, its numbers flattened (a polygon's vertices one after the other).
#[derive(Debug)]
struct Entity {
    kind: String,
    /// Number of vertices of `p` and `pp`.
    vertices: usize,
    values: Vec<f64>,
    text: String,
}

/// A minimal NFF reader for SPD output: one entity per line but `v` (6 lines) and polygons.
fn parse(text: &str) -> Vec<Entity> {
    let mut lines = text.lines();
    let mut out = Vec::new();
    let nums = |s: &str| -> Vec<f64> {
        s.split_whitespace()
            .map(|t| {
                t.parse()
                    .unwrap_or_else(|_| panic!("bad number `{t}` in `{s}`"))
            })
            .collect()
    };
    while let Some(line) = lines.next() {
        let mut it = line.split_whitespace();
        let Some(kind) = it.next() else { continue };
        let rest = line.trim_start()[kind.len()..].trim();
        let mut e = Entity {
            kind: kind.to_string(),
            vertices: 0,
            values: Vec::new(),
            text: line.to_string(),
        };
        match kind {
            "v" => {
                for _ in 0..6 {
                    let l = lines.next().expect("view ends early");
                    let mut t = l.split_whitespace();
                    t.next();
                    e.values.extend(t.map(|x| x.parse::<f64>().unwrap()));
                    e.text.push('\n');
                    e.text.push_str(l);
                }
            }
            "p" | "pp" => {
                e.vertices = rest.parse().unwrap();
                for _ in 0..e.vertices {
                    let l = lines.next().expect("polygon ends early");
                    e.values.extend(nums(l));
                    e.text.push('\n');
                    e.text.push_str(l);
                }
            }
            "#" => continue,
            _ => e.values = nums(rest),
        }
        out.push(e);
    }
    out
}

fn reference(dir: &std::path::Path, file: &str) -> String {
    let f = std::fs::File::open(dir.join(file)).unwrap();
    let mut text = String::new();
    flate2::read::MultiGzDecoder::new(f)
        .read_to_string(&mut text)
        .unwrap();
    text
}

fn generated(name: &str, size: u32) -> String {
    let mut out = Vec::new();
    spd::generate(name, size, &mut out).unwrap();
    String::from_utf8(out).unwrap()
}

fn counts(e: &[Entity]) -> Vec<(String, usize, usize)> {
    let mut c: Vec<(String, usize, usize)> = Vec::new();
    for x in e {
        match c
            .iter_mut()
            .find(|(k, v, _)| *k == x.kind && *v == x.vertices)
        {
            Some(entry) => entry.2 += 1,
            None => c.push((x.kind.clone(), x.vertices, 1)),
        }
    }
    c.sort();
    c
}

/// Compares entity by entity; `free_z` leaves the third coordinate of polygon vertices free
/// and returns the largest difference seen there.
fn compare(label: &str, mine: &[Entity], theirs: &[Entity], free_z: bool) -> f64 {
    assert_eq!(counts(mine), counts(theirs), "{label}: primitives per kind");
    assert_eq!(mine.len(), theirs.len(), "{label}: entities");
    let (mut same_text, mut z_diff) = (0usize, 0f64);
    for (i, (a, b)) in mine.iter().zip(theirs).enumerate() {
        assert_eq!(
            (&a.kind, a.vertices, a.values.len()),
            (&b.kind, b.vertices, b.values.len()),
            "{label}: entity {i} differs in kind:\n  mine:   {}\n  theirs: {}",
            a.text,
            b.text
        );
        let stride = if a.kind == "pp" { 6 } else { 3 };
        for (k, (x, y)) in a.values.iter().zip(&b.values).enumerate() {
            if free_z && a.kind == "p" && k % stride == 2 {
                z_diff = z_diff.max((x - y).abs());
                continue;
            }
            assert!(
                (x - y).abs() <= TOLERANCE,
                "{label}: entity {i} ({}), value {k}: {x} vs {y}\n  mine:   {}\n  theirs: {}",
                a.kind,
                a.text,
                b.text
            );
        }
        same_text += usize::from(a.text == b.text);
    }
    eprintln!(
        "{label}: {} entities match within {TOLERANCE}; {same_text} of them textually identical",
        mine.len()
    );
    z_diff
}

fn check(file: &str, name: &str, size: u32) {
    let Some(dir) = shared() else { return };
    let theirs = parse(&reference(&dir, file));
    let mine = parse(&generated(name, size));
    compare(
        &format!("{name} -s {size} vs {file}"),
        &mine,
        &theirs,
        false,
    );
}

#[test]
fn balls4() {
    check("balls4.nff.gz", "balls", 4);
}

#[test]
fn balls5() {
    check("balls5.nff.gz", "balls", 5);
}

#[test]
fn teapot6() {
    check("teapot6.nff.gz", "teapot", 6);
}

#[test]
fn teapot12() {
    check("teapot12.nff.gz", "teapot", 12);
}

#[test]
fn teapot48() {
    check("teapot48.nff.gz", "teapot", 48);
}

#[test]
fn gears() {
    check("gears.nff.gz", "gears", 4);
}

#[test]
fn tetra() {
    check("tetra.nff.gz", "tetra", 5);
}

#[test]
fn rings() {
    check("rings.nff.gz", "rings", 7);
}

#[test]
fn lattice() {
    check("lattice.nff.gz", "lattice", 12);
}

#[test]
fn tree() {
    check("tree.nff.gz", "tree", 11);
}

/// Everything but the mountain's heights (the SPD's random numbers) matches.
#[test]
fn mount() {
    let Some(dir) = shared() else { return };
    let theirs = parse(&reference(&dir, "mount.nff.gz"));
    let mine = parse(&generated("mount", 6));
    let z = compare("mount -s 6 vs mount.nff.gz", &mine, &theirs, true);
    eprintln!("mount: heights differ by up to {z:.3} (different random numbers)");
    // Same kind of mountain: the heights span a similar range.
    let range = |e: &[Entity]| {
        let z: Vec<f64> = e
            .iter()
            .filter(|e| e.kind == "p")
            .flat_map(|e| e.values.chunks(3).map(|v| v[2]).collect::<Vec<_>>())
            .collect();
        let (lo, hi) = z
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        hi - lo
    };
    let (a, b) = (range(&mine), range(&theirs));
    assert!(a > 0.5 * b && a < 2.0 * b, "height ranges {a} vs {b}");
}

/// The defaults are the sizes of the reference files and, for the databases without one, the
/// SPD programs' own defaults.
#[test]
fn default_sizes() {
    for (name, size) in [
        ("jacks", 1),
        ("shells", 5),
        ("sombrero", 1),
        ("balls", 4),
        ("gears", 4),
        ("tetra", 5),
        ("rings", 7),
        ("lattice", 12),
        ("mount", 6),
        ("tree", 11),
    ] {
        assert_eq!(spd::find(name, None).unwrap().1, size, "{name}");
    }
}

/// What the README promises for the sizes that are generated, not shipped.
#[test]
fn counts_of_large_sizes() {
    assert_eq!(spd::count("balls", 6).unwrap().spheres, 597_871);
    let t = spd::count("teapot", 153).unwrap();
    assert_eq!(t.all_polygons(), 1_520_361);
}

/// The RON version describes the same scene: it loads, with the same camera, lights,
/// materials and amount of geometry as the NFF version read by the NFF importer.
#[test]
fn ron_matches_nff() {
    let dir = std::env::temp_dir().join(format!("luxon-spd-ron-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, size) in [
        ("gears", 1),
        ("lattice", 2),
        ("teapot", 3),
        ("balls", 2),
        ("tree", 3),
        ("jacks", 2),
        ("shells", 1),
        ("sombrero", 1),
    ] {
        let mut ron = Vec::new();
        spd::generate_ron(name, size, &mut ron).unwrap();
        let ron_path = dir.join(format!("{name}.ron"));
        std::fs::write(&ron_path, &ron).unwrap();
        let from_ron = luxon_formats::load(&ron_path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let nff_path = dir.join(format!("{name}.nff"));
        std::fs::write(&nff_path, generated(name, size)).unwrap();
        let from_nff = luxon_formats::load(&nff_path).unwrap();

        let (a, b) = (&from_ron.camera.value, &from_nff.camera.value);
        assert_eq!(
            (a.position, a.look_at, a.up),
            (b.position, b.look_at, b.up),
            "{name}"
        );
        assert_eq!(
            format!("{:?}", a.projection),
            format!("{:?}", b.projection),
            "{name}"
        );
        assert_eq!(from_ron.lights.len(), from_nff.lights.len(), "{name}");
        for (l, m) in from_ron.lights.iter().zip(&from_nff.lights) {
            assert_eq!(l.value, m.value, "{name}");
        }
        let mats = |d: &luxon_formats::SceneDesc| -> Vec<_> {
            d.materials.iter().map(|(_, m)| m.value.clone()).collect()
        };
        assert_eq!(mats(&from_ron), mats(&from_nff), "{name}");
        assert_eq!(from_ron.background, from_nff.background, "{name}");
        assert_eq!(
            (from_ron.render.width, from_ron.render.height),
            (from_nff.render.width, from_nff.render.height)
        );
        // Geometry: spheres and cones are objects of their own; count through the NFF side.
        let c = spd::count(name, size).unwrap();
        let plugins = |p: &str| {
            from_ron
                .objects
                .iter()
                .filter(|o| o.value.call.plugin.value == p)
                .count() as u64
        };
        assert_eq!(plugins("cone"), c.cones, "{name}");
        assert_eq!(plugins("spheres") > 0, c.spheres > 0, "{name}");
        assert_eq!(plugins("mesh") > 0, c.all_polygons() > 0, "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The databases without a reference file start with the SPD programs' settings: background,
/// view, light and material (the Phong exponent from the highlight's half angle).
#[test]
fn later_databases_settings() {
    for (name, head) in [
        (
            "jacks",
            "b 0.2 0.05 0.2\nv\nfrom 0 0 -8\nat 0 0 0\nup 0 1 0\nangle 25\nhither 0.001\n\
             resolution 256 256\nl -10 3 -20\nf 0.737 0.561 0.561 0.7 0.7 11.1434 0 1\nc ",
        ),
        (
            "shells",
            "b 0.078 0.361 0.753\nv\nfrom -6 -60 35\nat 0 8 -15\nup 0 0 1\nangle 45\n\
             hither 0.5\nresolution 512 512\nl -100 -100 100\nf 1 0.8 0.4 0.8 0.2 45.2776 0 1\ns ",
        ),
        (
            "sombrero",
            "b 0.078 0.361 0.753\nv\nfrom 0 5 -8\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\n\
             resolution 512 512\nl 10 10 -10\nf 1 0.1 0.1 0.8 0 2.60078 0 1\np 3\n",
        ),
    ] {
        let size = spd::find(name, None).unwrap().1;
        let text = generated(name, size);
        assert!(
            text.starts_with(head),
            "{name}:\n{}",
            &text[..head.len() + 80]
        );
    }
}
