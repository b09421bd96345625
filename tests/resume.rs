//! Resumable sequences (the frame records beside the outputs and the claims): a run killed with
//! SIGKILL and run again ends with the frames of an uninterrupted run, byte for byte, and no
//! temporary file; a truncated frame, a changed scene and `--force` are rendered again; two
//! processes on the same outputs write each frame once.
#![cfg(unix)]

mod common;

use common::{luxon, stderr, temp_dir};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// 100 tiny frames (24x16, 1 sample): a ball crossing the picture.
const SCENE: &str = r#"Scene(
    camera: (position: (0, 0, 10), look_at: (0, 0, 0), projection: Orthographic(height: 2)),
    lights: [Directional(direction: (0, 0, -1), shadows: false)],
    materials: { "paint": (color: (1, 0.5, 0), ambient: 0.3, diffuse: 0.7) },
    objects: [(plugin: "sphere", name: "ball", params: (center: (0, 0, 0), radius: 0.4), material: "paint")],
    animation: (
        frames: (0, 99),
        objects: { "ball": (translate: (keys: [(0, (-1.5, 0, 0)), (99, (1.5, 0, 0))])) },
    ),
    render: (width: 24, height: 16, samples: 1, outputs: [(path: "out.ppm")]),
)
"#;

fn render(scene: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut c = luxon();
    c.arg("render")
        .arg(scene)
        .args(["--frames", "0..99", "-o"])
        .arg(out.join("f%03d.ppm"))
        .args(extra);
    if !extra.contains(&"--threads") {
        c.args(["--threads", "1"]);
    }
    c
}

fn finished(mut c: Command) -> Output {
    let o = c.output().expect("cannot run luxon");
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

/// The frame numbers a run says it wrote.
fn wrote(o: &Output) -> BTreeSet<u32> {
    stderr(o)
        .lines()
        .filter_map(|l| l.strip_prefix("luxon: wrote "))
        .map(|l| {
            let k = l.split("(frame ").nth(1).and_then(|r| r.split(',').next());
            k.and_then(|k| k.parse().ok())
                .unwrap_or_else(|| panic!("no frame in `{l}`"))
        })
        .collect()
}

/// The frames in `dir` (name, bytes); fails on any other file but the record directory.
fn frames(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().to_string();
        if name == ".f%03d.ppm.luxon-frames" {
            continue;
        }
        assert!(name.ends_with(".ppm") && !name.starts_with('.'), "{name}");
        v.push((name, std::fs::read(e.path()).unwrap()));
    }
    v.sort();
    v
}

/// Every file under `dir`, recursively.
fn all_files(dir: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            v.extend(all_files(&p));
        } else {
            v.push(p);
        }
    }
    v
}

fn records(dir: &Path) -> usize {
    std::fs::read_dir(dir.join(".f%03d.ppm.luxon-frames/done"))
        .map(|d| {
            d.flatten()
                .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
                .count()
        })
        .unwrap_or(0)
}

/// A small deterministic generator (the kill points are seeded).
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) % n
    }
}

#[test]
fn a_killed_sequence_resumes_to_the_same_frames() {
    let dir = temp_dir("resume");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let (a, b) = (dir.join("a"), dir.join("b"));
    let whole = finished(render(&scene, &a, &[]));
    assert_eq!(wrote(&whole), (0..100).collect());
    let want = frames(&a);
    assert_eq!(want.len(), 100);

    // Killed three times, each once it has recorded a few more frames and a seeded moment
    // later (anywhere in a frame: rendering, committing, recording).
    let mut rng = Lcg(19);
    let mut killed = 0;
    for _ in 0..3 {
        let target = records(&b) + 3 + rng.below(20) as usize;
        let mut child = render(&scene, &b, &[])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        while records(&b) < target && start.elapsed() < Duration::from_secs(30) {
            if child.try_wait().unwrap().is_some() {
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        std::thread::sleep(Duration::from_micros(rng.below(8000)));
        if child.try_wait().unwrap().is_none() {
            killed += 1;
        }
        child.kill().unwrap();
        child.wait().unwrap();
    }
    assert!(
        killed >= 2,
        "only {killed} of 3 runs were killed while rendering"
    );
    let last = finished(render(&scene, &b, &[]));
    let resumed = wrote(&last);
    assert!(
        !resumed.is_empty() && resumed.len() < 100,
        "the last run rendered {} frames",
        resumed.len()
    );
    assert!(
        stderr(&last).contains("frames are done already"),
        "{}",
        stderr(&last)
    );
    assert!(
        frames(&b) == want,
        "the resumed frames differ from the uninterrupted run's"
    );
    let temps: Vec<PathBuf> = all_files(&b)
        .into_iter()
        .filter(|p| p.to_string_lossy().ends_with(".luxon-tmp"))
        .collect();
    assert!(temps.is_empty(), "temporary files left: {temps:?}");

    // A truncated frame is rendered again, alone.
    let f50 = b.join("f050.ppm");
    let bytes = std::fs::read(&f50).unwrap();
    std::fs::write(&f50, &bytes[..bytes.len() / 2]).unwrap();
    let o = finished(render(&scene, &b, &[]));
    assert_eq!(wrote(&o), [50].into());
    assert_eq!(std::fs::read(&f50).unwrap(), bytes);
    // Nothing left to do: nothing rendered.
    let o = finished(render(&scene, &b, &[]));
    assert!(wrote(&o).is_empty(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("all 100 frames are done already"),
        "{}",
        stderr(&o)
    );

    // A changed material colour makes every frame stale; --force renders every frame.
    std::fs::write(
        &scene,
        SCENE.replace("color: (1, 0.5, 0)", "color: (0.2, 0.5, 1)"),
    )
    .unwrap();
    let o = finished(render(&scene, &b, &[]));
    assert_eq!(wrote(&o).len(), 100);
    assert!(frames(&b) != want);
    let o = finished(render(&scene, &b, &["--force"]));
    assert_eq!(wrote(&o).len(), 100);
    // The same scene and outputs named from another directory keep the frames.
    let o = luxon()
        .current_dir(&dir)
        .args([
            "render",
            "scene.ron",
            "--frames",
            "0..99",
            "-o",
            "b/f%03d.ppm",
        ])
        .output()
        .unwrap();
    assert!(o.status.success() && wrote(&o).is_empty(), "{}", stderr(&o));
    // A setting that changes no pixel keeps the frames.
    let o = finished(render(&scene, &b, &["--threads", "2", "--block-size", "5"]));
    assert!(wrote(&o).is_empty(), "{}", stderr(&o));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn two_processes_share_the_frames() {
    let dir = temp_dir("resume-two");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let c = dir.join("c");
    let spawn = || {
        render(&scene, &c, &[])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (p, q) = (spawn(), spawn());
    let (p, q) = (p.wait_with_output().unwrap(), q.wait_with_output().unwrap());
    assert!(
        p.status.success() && q.status.success(),
        "{}\n{}",
        stderr(&p),
        stderr(&q)
    );
    let (wp, wq) = (wrote(&p), wrote(&q));
    assert!(
        wp.is_disjoint(&wq),
        "frames written twice: {:?}",
        wp.intersection(&wq).collect::<Vec<_>>()
    );
    let all: BTreeSet<u32> = wp.union(&wq).copied().collect();
    assert_eq!(all, (0..100).collect());
    assert_eq!(frames(&c).len(), 100);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn records_that_cannot_be_kept_are_a_clear_error() {
    let dir = temp_dir("resume-unwritable");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    // A file where the record directory goes.
    std::fs::write(out.join(".f%03d.ppm.luxon-frames"), b"").unwrap();
    let o = render(&scene, &out, &[]).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("cannot keep the frame records in `")
            && err.contains(".f%03d.ppm.luxon-frames"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(wrote(&o).is_empty());
    let _ = std::fs::remove_dir_all(dir);
}
