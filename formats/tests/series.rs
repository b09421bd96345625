//! `series:`: time-sampled data files by pattern. What an entry reads (pattern, `first`,
//! `per_frame`, atoms or a mesh material), which data frame each movie frame shows, and every
//! error at its `line:col`, in the scene or in the data file (missing, short, bad number,
//! unknown element), naming the series and the frame.

mod common;

use std::path::{Path, PathBuf};

use luxon_formats::*;

/// Line 2: a camera; line 3: materials; line 4: the animation. The body starts on line 5.
const HEAD: &str = r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: 40),
    materials: { "red": (color: (1, 0, 0)), "white": (color: (1, 1, 1)) },
    animation: (frames: (10, 14)),
"#;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("luxon-series-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn load_in(dir: &Path, head: &str, body: &str) -> Result<SceneDesc, SceneError> {
    load_ron_str(&format!("{head}{body}\n)"), &dir.join("a.ron"))
}

fn load(body: &str) -> Result<SceneDesc, SceneError> {
    load_ron_str(&format!("{HEAD}{body}\n)"), Path::new("a.ron"))
}

#[track_caller]
fn check(body: &str, line: u32, needle: &str, words: &[&str]) {
    let e = load(body).expect_err("the scene is invalid");
    common::assert_error_at(&format!("{HEAD}{body}"), &e, line, needle, words);
}

#[test]
fn entries_are_read_with_their_patterns_and_styles() {
    let s = load(
        r#"    series: [
        (name: "water", files: "traj/t_%04d.xyz", first: 3, per_frame: 2, atoms: { "O": (radius: 0.6, material: "red"), "H": (radius: 0.3) }, default_atom: (radius: 0.5, material: "white")),
        (name: "cloth", files: "cloth/c_##.obj", material: "white"),
    ],"#,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.series.len(), 2);
    let w = &s.series[0].value;
    assert_eq!(w.name.value, "water");
    assert_eq!((w.first, w.per_frame), (3, 2));
    assert_eq!(w.path(7), Path::new("traj/t_0007.xyz"));
    let SeriesKind::Atoms { atoms, default } = &w.kind else {
        panic!("atoms expected: {:?}", w.kind);
    };
    assert_eq!(atoms.len(), 2);
    assert_eq!(atoms[0].0, "O");
    assert_eq!(atoms[0].1.radius, 0.6);
    assert_eq!(atoms[0].1.material.as_ref().unwrap().value, "red");
    assert_eq!(atoms[1].1.material, None);
    assert_eq!(default.as_ref().unwrap().radius, 0.5);
    // Movie frames 10..14: data frames 3, 5, 7, 9, 11; outside the range they hold.
    let range = (10, 14);
    let shown: Vec<u32> = (8..=16).map(|k| w.data_frame(k, range)).collect();
    assert_eq!(shown, [3, 3, 3, 5, 7, 9, 11, 11, 11]);
    let c = &s.series[1].value;
    assert_eq!(c.path(4), Path::new("cloth/c_04.obj"));
    assert_eq!((c.first, c.per_frame), (0, 1));
    let SeriesKind::Mesh { material } = &c.kind else {
        panic!("a mesh expected");
    };
    assert_eq!(material.as_ref().unwrap().value, "white");
    // Written back by `luxon convert`'s writer, and read again the same.
    let text = to_ron(&s, Path::new(".")).unwrap();
    let again = load_ron_str(&text, Path::new("a.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(again.series.len(), 2);
    for (a, b) in again.series.iter().zip(&s.series) {
        assert_eq!(a.value.pattern, b.value.pattern);
        assert_eq!(a.value.kind.clone(), strip(&b.value.kind, &a.value.kind));
        assert_eq!(
            (a.value.first, a.value.per_frame),
            (b.value.first, b.value.per_frame)
        );
    }
}

/// `b` with the positions of `a` (positions differ between the two texts).
fn strip(b: &SeriesKind, a: &SeriesKind) -> SeriesKind {
    let at = |m: &Option<Spanned<String>>, like: &Option<Spanned<String>>| match (m, like) {
        (Some(m), Some(l)) => Some(Spanned {
            value: m.value.clone(),
            at: l.at.clone(),
        }),
        (m, _) => m.clone(),
    };
    match (b, a) {
        (
            SeriesKind::Atoms { atoms, default },
            SeriesKind::Atoms {
                atoms: la,
                default: ld,
            },
        ) => SeriesKind::Atoms {
            atoms: atoms
                .iter()
                .zip(la)
                .map(|((n, s), (_, l))| {
                    let material = at(&s.material, &l.material);
                    (
                        n.clone(),
                        AtomStyle {
                            material,
                            ..s.clone()
                        },
                    )
                })
                .collect(),
            default: default.as_ref().zip(ld.as_ref()).map(|(d, l)| AtomStyle {
                material: at(&d.material, &l.material),
                ..d.clone()
            }),
        },
        (SeriesKind::Mesh { material }, SeriesKind::Mesh { material: l }) => SeriesKind::Mesh {
            material: at(material, l),
        },
        _ => b.clone(),
    }
}

#[test]
fn pattern_errors_point_at_the_files_string() {
    let s = |files: &str| {
        format!(r#"    series: [(name: "w", files: "{files}", default_atom: (radius: 1))],"#)
    };
    check(
        &s("traj.xyz"),
        5,
        "\"traj.xyz\"",
        &[
            "the file pattern `traj.xyz` has no frame number",
            "expected %d, %04d or ####",
        ],
    );
    check(&s("t%04d_%d.xyz"), 5, "\"t%04d", &["has two frame numbers"]);
    check(
        &s("t%5d.xyz"),
        5,
        "\"t%5d",
        &["`%5d` in `t%5d.xyz` is not a frame number"],
    );
    check(
        &s("t%04d.pdb"),
        5,
        "\"t%04d.pdb",
        &["unsupported data file pattern", "`.xyz`", "`.obj`"],
    );
}

#[test]
fn entry_errors_point_at_their_value() {
    check(
        r#"    series: [(name: "w", files: "t%d.xyz", per_frame: 0, default_atom: (radius: 1))],"#,
        5,
        "0,",
        &["`per_frame` is 0; expected a whole number from 1"],
    );
    check(
        r#"    series: [(name: "w", files: "t%d.xyz", first: 1.5, default_atom: (radius: 1))],"#,
        5,
        "1.5",
        &["`first` is 1.5"],
    );
    check(
        r#"    series: [(name: "w", files: "t%d.xyz", atoms: { "O": (radius: -1) })],"#,
        5,
        "-1",
        &["`radius` is -1; expected a number greater than 0"],
    );
    check(
        r#"    series: [(name: "w", files: "t%d.xyz", atoms: { "O": (radius: 1, material: "blue") })],"#,
        5,
        "\"blue\"",
        &["unknown material `blue`"],
    );
    check(
        r#"    series: [(name: "w", files: "t%d.xyz")],"#,
        5,
        "(name",
        &["needs `atoms`", "or `default_atom`"],
    );
    check(
        r#"    series: [(name: "w", files: "t%d.xyz", material: "red", default_atom: (radius: 1))],"#,
        5,
        "\"red\"",
        &["`material` is for `.obj` series"],
    );
    check(
        r#"    series: [(name: "m", files: "t%d.obj", atoms: { "O": (radius: 1) })],"#,
        5,
        "{ \"O\"",
        &["`atoms` is for `.xyz` series"],
    );
    check(
        r#"    series: [(name: "w", files: "a%d.xyz", default_atom: (radius: 1)), (name: "w", files: "b%d.obj")],"#,
        5,
        "\"w\", files: \"b",
        &["the series name `w` is already used at a.ron:5:"],
    );
    check(
        r#"    series: [(name: "w", files: "t%d.xyz", first: 4294967290, per_frame: 2, default_atom: (radius: 1))],"#,
        5,
        "\"t%d",
        &["would show data frame 4294967298"],
    );
    // Without an animation there is no frame to choose data by.
    let e = load_in(
        Path::new(""),
        "Scene(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n",
        r#"    series: [(name: "w", files: "t%d.xyz", default_atom: (radius: 1))],"#,
    )
    .expect_err("no animation");
    assert!(
        e.to_string()
            .starts_with("a.ron:3:14: `series:` needs an `animation:` block"),
        "{e}"
    );
}

/// Data files of one series in `dir`: the scene and its `series` loaded.
fn trajectory(dir: &Path, files: &[(&str, &str)]) -> SeriesDesc {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let s = load_in(
        dir,
        HEAD,
        r#"    series: [(name: "water", files: "w_%03d.xyz", atoms: { "O": (radius: 0.6), "H": (radius: 0.3) })],"#,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    s.series[0].value.clone()
}

#[test]
fn data_files_are_read_and_their_errors_name_file_frame_and_place() {
    let dir = temp_dir("errors");
    let s = trajectory(
        &dir,
        &[
            ("w_000.xyz", "2\nframe 0\nO 0 0 0\nH 1 2 3 0.25\n"),
            ("w_001.xyz", "3\nshort\nO 0 0 0\nH 1 2 3\n"),
            ("w_002.xyz", "1\nbad\nO 0 1.2.3 0\n"),
            ("w_003.xyz", "1\nunknown\n  Na 0 0 0\n"),
        ],
    );
    let o = LoadOptions::default();
    let f = load_frame(&s, 0, 10, &o).unwrap();
    assert_eq!(
        f.spheres,
        vec![(0, [0.0, 0.0, 0.0, 0.6]), (1, [1.0, 2.0, 3.0, 0.25])]
    );
    assert_eq!(f.file, dir.join("w_000.xyz"));
    let err = |d: u32, k: u32| load_frame(&s, d, k, &o).unwrap_err().to_string();
    let file = |d: u32| dir.join(format!("w_{d:03}.xyz")).display().to_string();
    let e = err(1, 11);
    assert_eq!(
        e,
        format!(
            "{}:5:1: series `water`, frame 11: the file ends after 2 of 3 atoms; expected 3 \
             atom lines (line 1 says 3)",
            file(1)
        )
    );
    let e = err(2, 12);
    assert!(
        e.starts_with(&format!(
            "{}:3:5: series `water`, frame 12: `1.2.3` is not a number; expected `element x y \
             z [radius]`",
            file(2)
        )),
        "{e}"
    );
    let e = err(3, 13);
    assert!(
        e.starts_with(&format!(
            "{}:3:3: series `water`, frame 13: element `Na` has no entry in `atoms` and there \
             is no `default_atom`; expected one of `O`, `H`",
            file(3)
        )),
        "{e}"
    );
    // A missing file is reported at the scene's `files` pattern (line 5, col of the string).
    let e = err(4, 14);
    let at = format!("{}:5:", dir.join("a.ron").display());
    assert!(e.starts_with(&at), "{e}");
    assert!(
        e.contains(&format!(
            "series `water`, frame 14: data file `{}` does not exist; expected one file per \
             data frame (pattern `w_%03d.xyz`, data frame 4)",
            file(4)
        )),
        "{e}"
    );
    // Movie frames 10..14 need data frames 0..4: one missing, named with the first frame
    // showing it.
    let (total, missing) = missing_files(&s, (10, 14));
    assert_eq!(total, 5);
    assert_eq!(missing, vec![(14, dir.join("w_004.xyz"))]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn obj_series_read_one_mesh_per_data_frame() {
    let dir = temp_dir("obj");
    std::fs::write(
        dir.join("m_7.obj"),
        "mtllib none.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(dir.join("m_8.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 x\n").unwrap();
    let s = load_in(
        &dir,
        HEAD,
        r#"    series: [(name: "m", files: "m_%d.obj", first: 7, material: "red")],"#,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let s = &s.series[0].value;
    let f = load_frame(s, 7, 10, &LoadOptions::default()).unwrap();
    assert_eq!(f.meshes.len(), 1);
    assert_eq!(f.meshes[0].mesh.indices, vec![[0, 1, 2]]);
    assert_eq!(f.meshes[0].material, None, "the series' material applies");
    let e = load_frame(s, 8, 11, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("{}:3:", dir.join("m_8.obj").display())),
        "{e}"
    );
    assert!(e.contains("series `m`, frame 11: "), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
