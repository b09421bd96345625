//! The NFF importer: every entity, the mapping to Luxon, errors with exact `line:col`,
//! chunked parsing equal to one-piece parsing, gzip, and the shared SPD files' counts.

use std::io::Write;
use std::path::{Path, PathBuf};

use luxon_formats::nff::{self, Imported};
use luxon_formats::{BackgroundDesc, InlineGeometry, LightDesc, Projection, SceneDesc};

const VIEW: &str = "v\nfrom 0 -10 0\nat 0 0 0\nup 0 0 1\nangle 45\nhither 1\nresolution 64 48\n";

fn path() -> &'static Path {
    Path::new("dir/scene.nff")
}

fn parse(text: &str) -> Imported {
    nff::parse_str(text, path()).unwrap_or_else(|e| panic!("{e}"))
}

/// The error for `text`: (line, col, message without the `file:line:col: ` prefix).
fn error_of(text: &str) -> (u32, u32, String) {
    let e = nff::parse_str(text, path()).expect_err("the file is invalid");
    let at = e.origin().expect("the error has a position").clone();
    assert_eq!(*at.file, path());
    let message = e.to_string();
    let prefix = format!("dir/scene.nff:{}:{}: ", at.line, at.col);
    assert!(message.starts_with(&prefix), "{message}");
    // The same error, at the same place, whatever the blocks the text is read in.
    for block in [1, 7, 64] {
        let e2 = nff::import_reader_blocks(text.as_bytes(), path(), block)
            .expect_err("the file is invalid");
        assert_eq!(e2.to_string(), message, "read in blocks of {block} bytes");
    }
    (at.line, at.col, message[prefix.len()..].to_string())
}

#[track_caller]
fn check(found: (u32, u32, String), line: u32, col: u32, words: &[&str]) {
    let (l, c, message) = found;
    assert_eq!((l, c), (line, col), "wrong position for: {message}");
    for word in words {
        assert!(message.contains(word), "`{word}` missing from: {message}");
    }
}

fn triangles(desc: &SceneDesc) -> usize {
    desc.inline.iter().map(|g| g.mesh.indices.len()).sum()
}

fn all(desc: &SceneDesc) -> impl Iterator<Item = &InlineGeometry> {
    desc.inline.iter()
}

// ---- Entities ----

#[test]
fn view_maps_to_the_camera_and_render_settings() {
    let i = parse(VIEW);
    let d = &i.desc;
    let c = &d.camera.value;
    assert_eq!(c.position, [0.0, -10.0, 0.0]);
    assert_eq!(c.look_at, [0.0, 0.0, 0.0]);
    assert_eq!(c.up, [0.0, 0.0, 1.0]);
    assert_eq!((d.render.width, d.render.height), (64, 48));
    assert_eq!(c.aspect, Some(64.0 / 48.0));
    // 45 degrees between the centres of the outer pixel rows: the image is a little wider.
    let Projection::Perspective { fov_deg } = c.projection else {
        panic!("perspective expected")
    };
    let want = 2.0
        * ((22.5f64).to_radians().tan() * 48.0 / 47.0)
            .atan()
            .to_degrees();
    assert!((fov_deg - want).abs() < 1e-12, "{fov_deg} vs {want}");
    assert!(fov_deg > 45.0 && fov_deg < 46.0);
    assert_eq!((d.camera.at.line, d.camera.at.col), (1, 1));
    assert!(d.render.outputs.is_empty());
    assert_eq!(d.render.samples, 1);
    assert_eq!(d.render.max_depth, 5);
    // No background: black.
    assert_eq!(d.background, BackgroundDesc::Color([0.0; 3]));
}

#[test]
fn view_lines_in_any_order_hither_and_resolution_optional() {
    let i = parse("# a comment\n\nv\n  angle 30\nup 0 1 0\nat 1 2 3\nfrom 1 2 8\n");
    assert_eq!(i.desc.camera.value.position, [1.0, 2.0, 8.0]);
    assert_eq!((i.desc.render.width, i.desc.render.height), (512, 512));
    assert_eq!(i.desc.camera.at.line, 3);
}

#[test]
fn background_is_linear() {
    let i = parse(&format!("{VIEW}b 0.078 0.361 0.753\n"));
    let BackgroundDesc::Color(b) = i.desc.background else {
        panic!("not a colour: {:?}", i.desc.background);
    };
    // sRGB 0.361 is linear 0.1070...
    assert!((b[1] - 0.107156).abs() < 1e-6, "{b:?}");
    assert!((b[0] - 0.0069413).abs() < 1e-6, "{b:?}");
}

#[test]
fn lights_share_unit_brightness_unless_coloured() {
    let i = parse(&format!(
        "{VIEW}l 1 2 3\nl 4 5 6\nl 7 8 9\nl 0 0 9 1 0.5 0\n"
    ));
    let l = &i.desc.lights;
    assert_eq!(l.len(), 4);
    assert_eq!(i.stats.lights, 4);
    let LightDesc::Point {
        position,
        color,
        intensity,
        shadows,
        ..
    } = &l[0].value
    else {
        panic!("point light expected")
    };
    assert_eq!(*position, [1.0, 2.0, 3.0]);
    assert_eq!(*color, [1.0; 3]);
    assert!((intensity - 0.5).abs() < 1e-12, "1/sqrt(4)");
    assert!(shadows);
    assert_eq!((l[1].at.line, l[1].at.col), (9, 1));
    let LightDesc::Point {
        color, intensity, ..
    } = &l[3].value
    else {
        panic!("point light expected")
    };
    assert_eq!(*intensity, 1.0);
    assert_eq!(color[0], 1.0);
    assert!((color[1] - 0.21404).abs() < 1e-4);
}

#[test]
fn fill_maps_as_nff_txt_says() {
    let i = parse(&format!(
        "{VIEW}f 1 0.5 0 0.7 0.3 20 0.4 1.5\ns 0 0 0 1\nf 1 1 1 0.8 0 0 0 0\ns 0 0 3 1\n\
         f 1 0.5 0 0.7 0.3 20 0.4 1.5\ns 0 0 6 1\n"
    ));
    let m = &i.desc.materials;
    assert_eq!(m.len(), 2, "identical `f` lines share a material");
    assert_eq!(i.stats.fills, 3);
    assert_eq!(m[0].0, "nff-0");
    assert_eq!(m[1].0, "nff-1");
    let a = &m[0].1.value;
    assert_eq!(a.color[0], 1.0);
    assert!((a.color[1] - 0.21404).abs() < 1e-4, "sRGB to linear");
    assert_eq!(a.color[2], 0.0);
    assert_eq!((a.diffuse, a.specular, a.reflect), (0.7, 0.3, 0.3));
    assert_eq!((a.shininess, a.transmit, a.ior), (20.0, 0.4, 1.5));
    assert_eq!(a.ambient, 0.0, "not purely diffuse: no ambient");
    let b = &m[1].1.value;
    assert_eq!(b.ior, 1.0, "ior 0 means 1");
    assert!(
        (b.ambient - 0.2).abs() < 1e-12,
        "purely diffuse: ambient 1 - Kd"
    );
    assert_eq!((m[1].1.at.line, m[1].1.at.col), (10, 1));
    // Each sphere is in its material's group.
    let names: Vec<String> = all(&i.desc)
        .flat_map(|g| {
            let n = g.material.as_ref().unwrap().value.clone();
            g.spheres.iter().map(move |s| format!("{n}@{}", s[2]))
        })
        .collect();
    assert!(names.contains(&"nff-0@0".to_string()), "{names:?}");
    assert!(names.contains(&"nff-1@3".to_string()), "{names:?}");
    assert!(names.contains(&"nff-0@6".to_string()), "{names:?}");
}

#[test]
fn objects_before_any_fill_get_the_default_material() {
    let i = parse(&format!("{VIEW}s 0 0 0 1\n"));
    assert!(i.desc.inline[0].material.is_none());
}

#[test]
fn spheres_and_negative_radii() {
    let i = parse(&format!("{VIEW}s 1 2 3 0.5\ns 0 0 0 -2 # inside visible\n"));
    let s: Vec<[f64; 4]> = all(&i.desc).flat_map(|g| g.spheres.clone()).collect();
    assert_eq!(s, vec![[1.0, 2.0, 3.0, 0.5], [0.0, 0.0, 0.0, 2.0]]);
    let g = &i.desc.inline[0];
    let at = g.at.as_ref().unwrap();
    assert_eq!((at.line, at.col), (8, 1));
    // NFF's inside-only sphere: accepted (NFF defines it), drawn two-sided with a warning at
    // the radius, written as in the file.
    assert_eq!(i.desc.warnings.len(), 1, "{:?}", i.desc.warnings);
    let w = &i.desc.warnings[0];
    assert_eq!((w.at.line, w.at.col), (9, 9));
    assert_eq!(
        w.message,
        "sphere radius -2 is negative (NFF's inside-only sphere); Luxon's spheres are \
         two-sided, so it is drawn with radius 2"
    );
}

/// A warning per kind and file: the first one, with a count of the others.
#[test]
fn repeated_warnings_are_counted() {
    let mut text = VIEW.to_string();
    for k in 0..1000 {
        text.push_str(&format!("s {k} 0 0 -0.50\n"));
    }
    text.push_str("c 0 0 0 -1 0 0 1 -1\n");
    for block in [64, 1 << 20] {
        let i = nff::import_reader_blocks(text.as_bytes(), path(), block).unwrap();
        let w: Vec<String> = i.desc.warnings.iter().map(|w| w.to_string()).collect();
        assert_eq!(w.len(), 2, "{w:?}");
        assert_eq!(
            w[0],
            "dir/scene.nff:8:9: sphere radius -0.50 is negative (NFF's inside-only sphere); \
             Luxon's spheres are two-sided, so it is drawn with radius 0.50 (999 more like it in \
             this file)"
        );
        assert!(w[1].starts_with("dir/scene.nff:1008:9: cone radius -1 is negative"));
        assert!(w[1].ends_with("(1 more like it in this file)"), "{}", w[1]);
    }
}

#[test]
fn cones_one_line_and_two_line_forms() {
    // The SPD programs' one-line form, then NFF.TXT's two-line form, then a sphere that a
    // reader skipping two lines after every `c` would lose.
    let text = format!(
        "{VIEW}c 0 0 0 1 0 0 2 0.5\nc\n1 1 1 0.25\n1 1 3 0.25\nc\n\n  # base next\n2 0 0 -1\n2 0 1 -1\ns 5 5 5 1\n"
    );
    let i = parse(&text);
    let c: Vec<[f64; 8]> = all(&i.desc).flat_map(|g| g.cones.clone()).collect();
    assert_eq!(
        c,
        vec![
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0, 0.5],
            [1.0, 1.0, 1.0, 0.25, 1.0, 1.0, 3.0, 0.25],
            [2.0, 0.0, 0.0, 1.0, 2.0, 0.0, 1.0, 1.0],
        ]
    );
    assert_eq!(i.stats.cones, 3);
    assert_eq!(i.stats.spheres, 1);
    // No caps: nothing but cones and the sphere.
    assert_eq!(triangles(&i.desc), 0);
    assert!(all(&i.desc).all(|g| g.discs.is_empty()));
}

#[test]
fn polygons_and_patches() {
    let text = format!(
        "{VIEW}p 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\npp 3\n0 0 1 0 0 1\n1 0 1 0 0.5 1\n0 1 1 0 0 2\n"
    );
    let i = parse(&text);
    assert_eq!(
        (i.stats.polygons, i.stats.patches, i.stats.triangles),
        (1, 1, 3)
    );
    let plain = all(&i.desc).find(|g| g.mesh.normals.is_empty()).unwrap();
    assert_eq!(plain.mesh.positions.len(), 4);
    assert_eq!(plain.mesh.indices.len(), 2);
    let patch = all(&i.desc).find(|g| !g.mesh.normals.is_empty()).unwrap();
    assert_eq!(
        patch.mesh.positions,
        vec![[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]]
    );
    assert_eq!(
        patch.mesh.normals,
        vec![[0.0, 0.0, 1.0], [0.0, 0.5, 1.0], [0.0, 0.0, 2.0]]
    );
    assert_eq!(patch.mesh.indices, vec![[0, 1, 2]]);
    let at = patch.at.as_ref().unwrap();
    assert_eq!(
        (at.line, at.col),
        (13, 1),
        "a group is positioned at its first `pp`"
    );
}

#[test]
fn shared_vertices_are_stored_once() {
    // Two quads sharing an edge, then a patch triangle whose corner repeats with a different
    // normal: positions are shared only when the normal is the same too.
    let text = format!(
        "{VIEW}p 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\np 4\n1 0 0\n2 0 0\n2 1 0\n1 1 0\n\
         pp 3\n0 0 1 0 0 1\n1 0 1 0 0 1\n0 1 1 0 0 1\npp 3\n1 0 1 0 0 1\n1 1 1 0 0 1\n0 1 1 0 1 0\n"
    );
    let i = parse(&text);
    let plain = all(&i.desc).find(|g| g.mesh.normals.is_empty()).unwrap();
    assert_eq!(plain.mesh.positions.len(), 6);
    assert_eq!(plain.mesh.indices.len(), 4);
    let patch = all(&i.desc).find(|g| !g.mesh.normals.is_empty()).unwrap();
    assert_eq!(patch.mesh.positions.len(), 5, "(0 1 1) twice: two normals");
    assert_eq!(patch.mesh.indices, vec![[0, 1, 2], [1, 3, 4]]);
    assert_eq!(patch.mesh.normals[4], [0.0, 1.0, 0.0]);
}

/// Area of a triangle in 3-D.
fn area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0
}

fn point_in_polygon(p: &[[f64; 2]], q: [f64; 2]) -> bool {
    let mut inside = false;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        if (a[1] > q[1]) != (b[1] > q[1])
            && q[0] < a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
        {
            inside = !inside;
        }
    }
    inside
}

#[test]
fn concave_polygon_is_ear_clipped() {
    // A star with 5 notches in the plane x + y + z = 3 (seen in 2-D as (x, y)).
    let mut ring = Vec::new();
    for k in 0..10 {
        let a = k as f64 * std::f64::consts::PI / 5.0;
        let r = if k % 2 == 0 { 2.0 } else { 0.7 };
        ring.push([r * a.cos(), r * a.sin()]);
    }
    let mut text = format!("{VIEW}p 10\n");
    for q in &ring {
        text.push_str(&format!("{} {} {}\n", q[0], q[1], 3.0 - q[0] - q[1]));
    }
    let i = parse(&text);
    let g = &i.desc.inline[0];
    assert_eq!(g.mesh.indices.len(), 8, "n - 2 triangles");
    let p = &g.mesh.positions;
    let shoelace: f64 = (0..10)
        .map(|k| {
            let (a, b) = (ring[k], ring[(k + 1) % 10]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
        / 2.0;
    // Area in the tilted plane = projected area * |n| / |n_z| = shoelace * sqrt(3).
    let want = shoelace.abs() * 3f64.sqrt();
    let mut total = 0.0;
    for t in &g.mesh.indices {
        let [a, b, c] = t.map(|k| p[k as usize]);
        total += area(a, b, c);
        let centroid = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
        assert!(
            point_in_polygon(&ring, centroid),
            "triangle {t:?} lies outside the star"
        );
    }
    assert!((total - want).abs() < 1e-9, "area {total} vs {want}");
}

#[test]
fn comments_blank_lines_and_crlf() {
    let text = "# SPD\r\n\r\nv\r\nfrom 0 0 5 # eye\r\nat 0 0 0\r\nup 0 1 0\r\nangle 40\r\n\r\n# x\r\ns 0 0 0 1\r\n";
    let i = parse(text);
    assert_eq!(i.stats.spheres, 1);
    assert_eq!(i.stats.lines, 10);
}

// ---- Chunked reading ----

/// A file with many entities of every kind, materials changing often.
fn busy_file() -> String {
    let mut t = format!("{VIEW}b 0.1 0.2 0.3\nl 1 1 1\n");
    for k in 0..60 {
        let x = k as f64;
        if k % 7 == 0 {
            t.push_str(&format!(
                "f {} 0.5 0.5 0.8 0.2 10 0 0\n",
                (k % 3) as f64 / 2.0
            ));
        }
        match k % 5 {
            0 => t.push_str(&format!("s {x} 0 0 0.5\n")),
            1 => t.push_str(&format!("c\n{x} 0 0 0.2\n{x} 0 1 0.1\n")),
            2 => t.push_str(&format!(
                "p 5\n{x} 0 0\n{} 0 0\n{} 1 0\n{} 0.5 0\n{x} 1 0\n",
                x + 1.0,
                x + 1.0,
                x + 0.5
            )),
            3 => t.push_str(&format!(
                "pp 3\n{x} 0 2 0 0 1\n{} 0 2 0 0 1\n{x} 1 2 0 0 1\n",
                x + 1.0
            )),
            _ => t.push_str(&format!("c {x} 0 0 0.2 {x} 1 0 0.2\n# comment {k}\n\n")),
        }
    }
    t.push_str("l 5 5 5\n");
    t
}

/// Every primitive with its material name, in file order of the groups' contents.
fn flatten(d: &SceneDesc) -> Vec<String> {
    let mut out = Vec::new();
    for g in &d.inline {
        let m = g
            .material
            .as_ref()
            .map_or("default".to_string(), |m| m.value.clone());
        for s in &g.spheres {
            out.push(format!("{m} s {s:?}"));
        }
        for c in &g.cones {
            out.push(format!("{m} c {c:?}"));
        }
        for t in &g.mesh.indices {
            let v = t.map(|k| g.mesh.positions[k as usize]);
            let n = if g.mesh.normals.is_empty() {
                String::new()
            } else {
                format!("{:?}", t.map(|k| g.mesh.normals[k as usize]))
            };
            out.push(format!("{m} t {v:?} {n}"));
        }
    }
    out.sort();
    out
}

#[test]
fn blocks_of_any_size_give_the_same_scene() {
    let text = busy_file();
    let whole = parse(&text);
    let want = flatten(&whole.desc);
    assert_eq!(
        want.len() as u64,
        whole.stats.spheres + whole.stats.cones + whole.stats.triangles
    );
    for block in [1, 5, 33, 100, 1000, 1 << 20] {
        let i = nff::import_reader_blocks(text.as_bytes(), path(), block).unwrap();
        assert_eq!(flatten(&i.desc), want, "blocks of {block} bytes");
        assert_eq!(i.stats, whole.stats);
        assert_eq!(i.desc.materials, whole.desc.materials);
        assert_eq!(i.desc.lights, whole.desc.lights);
        assert_eq!(i.desc.camera, whole.desc.camera);
        assert_eq!(i.desc.background, whole.desc.background);
        // Group positions are file positions, whatever the blocks.
        for g in &i.desc.inline {
            let at = g.at.as_ref().unwrap();
            let line = text.lines().nth(at.line as usize - 1).unwrap();
            let word = line.split_whitespace().next().unwrap();
            assert!(
                ["s", "c", "p", "pp"].contains(&word),
                "group at {at}: {line}"
            );
        }
    }
}

#[test]
fn the_scene_does_not_depend_on_the_thread_count() {
    // About 3 MB: several parallel chunks.
    let mut text = busy_file();
    let body = text.split_once("l 1 1 1\n").unwrap().1.to_string();
    while text.len() < 3 << 20 {
        text.push_str(&body);
    }
    let with = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| parse(&text))
    };
    let one = with(1);
    assert!(one.desc.inline.len() > 3, "several chunks");
    for threads in [2, 3] {
        let many = with(threads);
        assert!(many.desc == one.desc, "{threads} threads");
        assert_eq!(many.stats, one.stats);
    }
}

// ---- Files ----

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("luxon-nff-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn gzip_and_extension_dispatch() {
    let dir = temp_dir("gz");
    let text = busy_file();
    let plain = dir.join("busy.NFF");
    std::fs::write(&plain, &text).unwrap();
    let gz = dir.join("busy.nff.GZ");
    let mut e = flate2::write::GzEncoder::new(
        std::fs::File::create(&gz).unwrap(),
        flate2::Compression::fast(),
    );
    e.write_all(text.as_bytes()).unwrap();
    e.finish().unwrap();
    let a = luxon_formats::load(&plain).unwrap_or_else(|e| panic!("{e}"));
    let b = luxon_formats::load(&gz).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(flatten(&a), flatten(&b));
    assert_eq!(a.source, plain);
    assert_eq!(b.source, gz);
    // Errors in a gzip file name the file and the line in the decompressed text.
    let bad = dir.join("bad.nff.gz");
    let mut e = flate2::write::GzEncoder::new(
        std::fs::File::create(&bad).unwrap(),
        flate2::Compression::fast(),
    );
    e.write_all(format!("{VIEW}s 1 2 3\n").as_bytes()).unwrap();
    e.finish().unwrap();
    let err = luxon_formats::load(&bad).unwrap_err().to_string();
    assert!(
        err.starts_with(&format!("{}:8:8: ", bad.display())),
        "{err}"
    );
    // A missing file is an I/O error naming it.
    let err = luxon_formats::load(&dir.join("none.nff"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("none.nff"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---- Errors: exact positions, what was expected ----

#[test]
fn unknown_keyword() {
    check(
        error_of(&format!("{VIEW}sphere 0 0 0 1\n")),
        8,
        1,
        &["unknown NFF keyword `sphere`", "expected"],
    );
    check(
        error_of(&format!("{VIEW}  pq 3\n")),
        8,
        3,
        &["`pq`", "did you mean"],
    );
    check(
        error_of("v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangel 40\n"),
        5,
        1,
        &["`angel`", "did you mean `angle`"],
    );
    check(
        error_of(&format!("{VIEW}s 0 0 0 1\nfrom 1 2 3\n")),
        9,
        1,
        &["`from` belongs in a `v` view"],
    );
}

#[test]
fn wrong_number_of_values() {
    check(
        error_of(&format!("{VIEW}s 1 2 3\n")),
        8,
        8,
        &["`s` sphere takes 4 numbers", "found 3"],
    );
    check(
        error_of(&format!("{VIEW}s 1 2 3 4 5\n")),
        8,
        11,
        &["takes 4 numbers", "found 5", "unexpected `5`"],
    );
    check(
        error_of(&format!("{VIEW}f 1 1 1 0.5 0.5 3\n")),
        8,
        18,
        &["`f` fill takes 8 numbers", "found 6"],
    );
    check(
        error_of(&format!("{VIEW}c 0 0 0 1 0 0 1\n")),
        8,
        3,
        &["`c` takes 8 numbers", "or none", "found 7"],
    );
    check(
        error_of(&format!("{VIEW}c\n0 0 0 1\n0 0 1\n")),
        10,
        6,
        &["cone apex takes 4 numbers", "found 3"],
    );
    check(
        error_of(&format!("{VIEW}l 1 2\n")),
        8,
        6,
        &["`l` light takes 3 numbers", "or 6", "found 2"],
    );
    check(
        error_of(&format!("{VIEW}p 3\n0 0 0\n1 0 0 5\n0 1 0\n")),
        10,
        7,
        &["`p` vertex takes 3 numbers", "found 4"],
    );
    check(
        error_of(&format!("{VIEW}pp 3\n0 0 0 0 0 1\n1 0 0\n0 1 0 0 0 1\n")),
        10,
        6,
        &["`pp` vertex takes 6 numbers", "found 3"],
    );
    check(
        error_of(&format!("{VIEW}b 1 1\n")),
        8,
        6,
        &["`b` background takes 3 numbers"],
    );
    check(
        error_of("v\nfrom 0 0 1\nat 0 0\n"),
        3,
        7,
        &["`at` takes 3 numbers", "found 2"],
    );
    check(
        error_of("v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 40\nresolution 512\n"),
        6,
        15,
        &["`resolution` takes 2"],
    );
    check(error_of("v 1\n"), 1, 3, &["`v` stands alone"]);
    check(
        error_of(&format!("{VIEW}p 3 0 0 0\n")),
        8,
        5,
        &["takes 1 number on its line", "vertex count"],
    );
    // More vertex lines than the count says.
    check(
        error_of(&format!("{VIEW}p 3\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n")),
        12,
        1,
        &["expected an NFF entity keyword", "found the number `1`"],
    );
}

#[test]
fn bad_numbers() {
    check(
        error_of(&format!("{VIEW}s 1 2x 3 4\n")),
        8,
        5,
        &["expected a number", "x y z radius", "found `2x`"],
    );
    check(
        error_of(&format!("{VIEW}p 3\n0 0 0\n1 0,5 0\n0 1 0\n")),
        10,
        3,
        &["expected a number", "found `0,5`"],
    );
    check(
        error_of(&format!("{VIEW}p three\n")),
        8,
        3,
        &["whole vertex count", "found `three`"],
    );
    check(
        error_of(&format!("{VIEW}p 3.5\n")),
        8,
        3,
        &["whole vertex count"],
    );
    check(
        error_of("v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 40\nresolution 512 0\n"),
        6,
        16,
        &["1..=65536", "height", "found `0`"],
    );
}

#[test]
fn nan_and_infinity() {
    check(
        error_of(&format!("{VIEW}s 1 nan 3 4\n")),
        8,
        5,
        &["finite number", "found `nan`", "NaN and infinities"],
    );
    check(
        error_of(&format!("{VIEW}p 3\n0 0 0\ninf 0 0\n0 1 0\n")),
        10,
        1,
        &["finite number", "found `inf`"],
    );
    check(
        error_of(&format!(
            "{VIEW}pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1e999\n"
        )),
        11,
        11,
        &["finite number", "found `1e999`"],
    );
    check(error_of("v\nfrom 0 0 NaN\n"), 2, 10, &["finite number"]);
}

#[test]
fn polygon_with_too_few_vertices() {
    check(
        error_of(&format!("{VIEW}p 2\n0 0 0\n1 0 0\n")),
        8,
        3,
        &["at least 3 vertices", "found 2"],
    );
    check(
        error_of(&format!("{VIEW}pp 0\n")),
        8,
        4,
        &["at least 3 vertices", "found 0"],
    );
}

#[test]
fn polygon_cut_short_by_the_next_entity() {
    check(
        error_of(&format!("{VIEW}p 4\n0 0 0\n1 0 0\n0 1 0\ns 0 0 0 1\n")),
        12,
        1,
        &["expected vertex 4 of 4", "x y z", "line 8", "found `s`"],
    );
}

#[test]
fn truncated_file() {
    check(
        error_of(&format!("{VIEW}p 4\n0 0 0\n1 0 0\n")),
        11,
        1,
        &["file ends early", "vertex 3 of 4"],
    );
    check(
        error_of(&format!("{VIEW}pp 3\n0 0 0 0 0 1")),
        9,
        12,
        &["file ends early", "vertex 2 of 3", "x y z nx ny nz"],
    );
    check(
        error_of(&format!("{VIEW}c\n0 0 0 1\n")),
        10,
        1,
        &["file ends early", "apex line"],
    );
}

#[test]
fn view_errors() {
    check(error_of("s 0 0 0 1\n"), 1, 1, &["no `v` view"]);
    check(
        error_of("v\nfrom 0 0 1\nat 0 0 0\nangle 40\ns 0 0 0 1\n"),
        1,
        1,
        &["lacks `up`"],
    );
    check(
        error_of("v\nfrom 0 0 1\nat 0 0 1\nup 0 1 0\nangle 40\n"),
        1,
        1,
        &["`from` and `at` are the same"],
    );
    check(
        error_of("v\nfrom 0 0 1\nat 0 0 0\nup 0 0 2\nangle 40\n"),
        4,
        4,
        &["parallel"],
    );
    check(
        error_of("v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 180\n"),
        5,
        7,
        &["(0, 180)"],
    );
    check(
        error_of("v\nfrom 0 0 1\nfrom 0 0 2\n"),
        3,
        1,
        &["`from` given twice"],
    );
}

#[test]
fn value_errors() {
    check(
        error_of(&format!("{VIEW}s 0 0 0 0\n")),
        8,
        9,
        &["radius is 0"],
    );
    check(
        error_of(&format!("{VIEW}c 0 0 0 0 0 0 1 0\n")),
        8,
        1,
        &["radii are both 0"],
    );
    check(
        error_of(&format!("{VIEW}c 1 1 1 1 1 1 1 2\n")),
        8,
        1,
        &["same point"],
    );
    check(
        error_of(&format!("{VIEW}f 1 1 1 -0.5 0 1 0 1\n")),
        8,
        9,
        &["Kd", ">= 0"],
    );
    check(
        error_of(&format!("{VIEW}l 0 0 0 1 -1 1\n")),
        8,
        11,
        &["negative"],
    );
}

#[test]
fn non_ascii_tokens_are_shown() {
    check(
        error_of(&format!("{VIEW}s 1 2 3 é\n")),
        8,
        9,
        &["found `é`"],
    );
    check(
        error_of(&format!("{VIEW}ßphere 1 2 3\n")),
        8,
        1,
        &["unknown NFF keyword `ßphere`"],
    );
}

// ---- The shared SPD files ----

fn shared() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/spd");
    d.is_dir().then_some(d)
}

#[test]
fn shared_spd_files_import_with_their_counts() {
    let Some(dir) = shared() else {
        eprintln!("note: ../shared/spd is absent; skipping the SPD file counts");
        return;
    };
    // (file, spheres, cones, polygons, patches, lights)
    let want: [(&str, u64, u64, u64, u64, u64); 11] = [
        ("balls4", 7381, 0, 1, 0, 3),
        ("balls5", 66430, 0, 1, 0, 3),
        ("gears", 0, 0, 9345, 0, 5),
        ("lattice", 2197, 6084, 0, 0, 6),
        ("mount", 4, 0, 8192, 0, 1),
        ("rings", 4200, 4200, 1, 0, 3),
        ("teapot6", 0, 0, 36, 2256, 2),
        ("teapot12", 0, 0, 144, 9120, 2),
        ("teapot48", 0, 0, 2304, 147072, 2),
        ("tetra", 0, 0, 4096, 0, 1),
        ("tree", 4095, 4095, 1, 0, 7),
    ];
    for (name, spheres, cones, polygons, patches, lights) in want {
        let path = dir.join(format!("{name}.nff.gz"));
        let i = nff::import(&path).unwrap_or_else(|e| panic!("{e}"));
        let s = i.stats;
        assert_eq!(
            (s.spheres, s.cones, s.polygons, s.patches, s.lights),
            (spheres, cones, polygons, patches, lights),
            "{name}"
        );
        let d = &i.desc;
        let stored: (u64, u64, u64) = (
            all(d).map(|g| g.spheres.len() as u64).sum(),
            all(d).map(|g| g.cones.len() as u64).sum(),
            triangles(d) as u64,
        );
        assert_eq!(stored, (spheres, cones, s.triangles), "{name}");
        assert_eq!((d.render.width, d.render.height), (512, 512), "{name}");
        assert_eq!(d.lights.len() as u64, lights);
        // Every material a group names exists.
        for g in all(d) {
            if let Some(m) = &g.material {
                assert!(
                    d.materials.iter().any(|(n, _)| n == &m.value),
                    "{name}: {}",
                    m.value
                );
            }
        }
    }
}

#[test]
fn shared_gears_are_concave_and_clipped() {
    let Some(dir) = shared() else {
        eprintln!("note: ../shared/spd is absent; skipping");
        return;
    };
    let i = nff::import(&dir.join("gears.nff.gz")).unwrap();
    // 9217 quads (2 triangles each) and 128 gear faces of 144 vertices (142 each).
    assert_eq!(i.stats.triangles, 9217 * 2 + 128 * 142);
}

/// One polygon of 100,000 corners at random angles (it intersects itself everywhere): the
/// ear search stops at its work budget and the rest becomes a fan, with a warning at the `p`.
/// (It took over a minute.)
#[test]
fn a_huge_tangled_polygon_falls_back_to_a_fan_with_a_warning() {
    let m = 100_000;
    let mut text = format!("{VIEW}f 1 1 1 1 0 0 0 1\n  p {m}\n");
    let mut state = 7u64;
    let mut unit = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..m {
        let a = unit() * std::f64::consts::TAU;
        let r = 1.0 + unit();
        text.push_str(&format!("{} 0 {}\n", r * a.cos(), r * a.sin()));
    }
    let i = parse(&text);
    assert_eq!(i.stats.triangles, m as u64 - 2);
    assert_eq!(i.desc.warnings.len(), 1, "{:?}", i.desc.warnings);
    let w = &i.desc.warnings[0];
    assert_eq!((w.at.line, w.at.col), (9, 3));
    assert!(
        w.message.starts_with(&format!(
            "`p` polygon of {m} vertices could not be cut into ears within its time budget"
        )),
        "{w}"
    );
    assert!(
        w.message.contains("triangles are a fan from one corner"),
        "{w}"
    );
}
