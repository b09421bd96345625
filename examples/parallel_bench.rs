//! Parallel scaling benchmark: renders an SPD-size sphereflake (Haines's "balls": 7,381
//! reflective spheres over a floor at size 4) with threads, MPI ranks and both, every
//! decomposition, and asynchronous against synchronous output, and prints median times,
//! speedups and parallel efficiencies as a Markdown table.
//!
//! ```sh
//! cargo build --release --features mpi
//! cargo run --release --features mpi --example parallel_bench -- [--runs 5] [--size 4] [--res 512x512] [--samples 4]
//! ```
//! `--no-mpi` skips the MPI rows (for a build without the `mpi` feature); `--scene-only FILE`
//! just writes the scene. Times are the render phase as `luxon render --stats` reports it (the
//! same scene build precedes it on every rank) and the wall time of the whole command.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

struct Args {
    runs: usize,
    size: u32,
    res: String,
    samples: u32,
    mpi: bool,
    scene_only: Option<PathBuf>,
}

fn args() -> Args {
    let mut a = Args {
        runs: 5,
        size: 4,
        res: "512x512".into(),
        samples: 4,
        mpi: true,
        scene_only: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let mut val = || it.next().unwrap_or_else(|| panic!("{k} needs a value"));
        match k.as_str() {
            "--runs" => a.runs = val().parse().expect("--runs N"),
            "--size" => a.size = val().parse().expect("--size N"),
            "--res" => a.res = val(),
            "--samples" => a.samples = val().parse().expect("--samples N"),
            "--no-mpi" => a.mpi = false,
            "--scene-only" => a.scene_only = Some(val().into()),
            _ => panic!("unknown argument {k}; see the comment at the top of parallel_bench.rs"),
        }
    }
    a
}

/// Unit vectors of an orthonormal frame around `d`.
fn frame(d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = if d[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = norm(cross(d, a));
    (u, cross(d, u))
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|v| v / l)
}

/// The sphereflake: a sphere with nine children a third its size, six around its equator
/// (relative to the direction it grows in) and three above, `depth` levels deep.
fn flake(c: [f64; 3], r: f64, dir: [f64; 3], depth: u32, out: &mut Vec<([f64; 3], f64)>) {
    out.push((c, r));
    if depth == 0 {
        return;
    }
    let (u, v) = frame(dir);
    let child = r / 3.0;
    let dirs = (0..9).map(|k| {
        let (elev, az) = if k < 6 {
            (0.0f64, k as f64 * std::f64::consts::PI / 3.0)
        } else {
            (
                std::f64::consts::PI / 3.0,
                (k - 6) as f64 * 2.0 * std::f64::consts::PI / 3.0 + std::f64::consts::PI / 6.0,
            )
        };
        let (ce, se, ca, sa) = (elev.cos(), elev.sin(), az.cos(), az.sin());
        norm([0, 1, 2].map(|i| ce * (ca * u[i] + sa * v[i]) + se * dir[i]))
    });
    for d in dirs.collect::<Vec<_>>() {
        let cc = [0, 1, 2].map(|i| c[i] + d[i] * (r + child));
        flake(cc, child, d, depth - 1, out);
    }
}

/// The scene's RON text and its number of spheres.
fn scene(size: u32) -> (String, usize) {
    let mut balls = Vec::new();
    flake([0.0, 0.0, 0.0], 0.5, [0.0, 0.0, 1.0], size, &mut balls);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "// SPD-style sphereflake, {} spheres (written by examples/parallel_bench.rs)",
        balls.len()
    );
    s.push_str(
        r#"Scene(
    camera: (position: (2.1, 1.3, 1.7), look_at: (0, 0, 0), up: (0, 0, 1), fov: 45),
    background: (0.078, 0.361, 0.753),
    lights: [
        Point(position: (4, 3, 2), intensity: 0.58),
        Point(position: (1, -4, 4), intensity: 0.58),
        Point(position: (-3, 1, 5), intensity: 0.58),
    ],
    materials: {
        "floor": (color: (1, 0.75, 0.33), ambient: 0, diffuse: 0.8),
        "ball": (color: (1, 0.9, 0.7), ambient: 0, diffuse: 0.5, specular: 0.5, shininess: 3, reflect: 0.5),
    },
    objects: [
        (plugin: "plane", params: (point: (0, 0, -0.5), normal: (0, 0, 1)), material: "floor"),
        (plugin: "spheres", material: "ball", params: (
            centers: ["#,
    );
    for (c, _) in &balls {
        let _ = write!(s, "({:.6}, {:.6}, {:.6}),", c[0], c[1], c[2]);
    }
    s.push_str("],\n            radii: [");
    for (_, r) in &balls {
        let _ = write!(s, "{r:.8},");
    }
    s.push_str(
        "],\n        )),\n    ],\n    render: (width: 512, height: 512, samples: 1, max_depth: 8, outputs: [(path: \"balls.png\")]),\n)\n",
    );
    (s, balls.len())
}

fn luxon_binary() -> PathBuf {
    let exe = std::env::current_exe().expect("current exe");
    // target/<profile>/examples/parallel_bench -> target/<profile>/luxon
    let bin = exe.parent().and_then(Path::parent).map(|d| d.join("luxon"));
    bin.filter(|b| b.exists())
        .expect("build the renderer first: cargo build --release --features mpi")
}

/// One configuration: how to launch, and the `luxon render` flags.
#[derive(Clone)]
struct Config {
    label: String,
    /// 0: run luxon directly, else under mpirun.
    ranks: usize,
    /// Render threads of all ranks together: the p of the efficiency.
    workers: usize,
    args: Vec<String>,
}

fn config(label: &str, ranks: usize, workers: usize, args: &str) -> Config {
    Config {
        label: label.into(),
        ranks,
        workers,
        args: args.split_whitespace().map(String::from).collect(),
    }
}

/// Seconds of one run: render and write (as `--stats` reports them), and wall time.
fn run_once(bin: &Path, scene: &Path, out: &Path, c: &Config, a: &Args) -> [f64; 3] {
    let mut cmd = if c.ranks > 0 {
        let mut m = Command::new("mpirun");
        m.args(["--oversubscribe", "--bind-to", "none", "-np"])
            .arg(c.ranks.to_string())
            .arg(bin);
        m
    } else {
        Command::new(bin)
    };
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .arg("render")
        .arg(scene)
        .args([
            "--stats",
            "--res",
            &a.res,
            "--samples",
            &a.samples.to_string(),
            "-o",
        ])
        .arg(out)
        .args(&c.args);
    let t = Instant::now();
    let o = cmd.output().expect("cannot run luxon");
    let wall = t.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{}: {err}", c.label);
    let seconds = |label: &str| -> f64 {
        err.lines()
            .find_map(|l| {
                l.trim()
                    .strip_prefix(label)?
                    .trim()
                    .strip_suffix(" s")?
                    .parse()
                    .ok()
            })
            .unwrap_or_else(|| panic!("no {label} time in {err}"))
    };
    [seconds("render"), seconds("write"), wall]
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn main() {
    let a = args();
    let (text, balls) = scene(a.size);
    if let Some(p) = &a.scene_only {
        std::fs::write(p, text).expect("cannot write the scene");
        return;
    }
    let dir = std::env::temp_dir().join(format!("luxon-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let scene = dir.join("balls.ron");
    std::fs::write(&scene, &text).expect("cannot write the scene");
    let bin = luxon_binary();

    let mut groups: Vec<(&str, Vec<Config>)> = vec![(
        "Threads",
        vec![
            config("1 thread", 0, 1, "--threads 1"),
            config("2 threads", 0, 2, "--threads 2"),
        ],
    )];
    if a.mpi {
        groups.push((
            "MPI and hybrid",
            vec![
                config("1 rank (mpi)", 1, 1, "--parallel mpi"),
                config("2 ranks (mpi)", 2, 2, "--parallel mpi"),
                config("hybrid 1 rank x 2 threads", 1, 2, "--parallel hybrid"),
                config("hybrid 2 ranks x 1 thread", 2, 2, "--parallel hybrid"),
            ],
        ));
    }
    let decomps = ["dynamic", "pixel-cyclic", "scanline-cyclic", "block-cyclic"];
    groups.push((
        "Decompositions, 2 threads",
        decomps
            .iter()
            .map(|d| config(d, 0, 2, &format!("--threads 2 --decomposition {d}")))
            .collect(),
    ));
    if a.mpi {
        groups.push((
            "Decompositions, 2 ranks",
            decomps
                .iter()
                .map(|d| config(d, 2, 2, &format!("--parallel mpi --decomposition {d}")))
                .collect(),
        ));
    }
    let outputs = [("PPM", "ppm"), ("PNG", "png")];
    let mut io = Vec::new();
    for (name, _) in outputs {
        for mode in ["async", "sync"] {
            io.push(config(
                &format!("{name}, {mode}"),
                0,
                2,
                &format!("--threads 2 --io {mode}"),
            ));
        }
    }
    groups.push(("Output, 2 threads", io));

    println!(
        "sphereflake size {} ({} spheres), {}, {} sample(s) per pixel, {} run(s) per row, medians; luxon: {}\n",
        a.size, balls, a.res, a.samples,
        a.runs,
        bin.display()
    );
    // Rounds visit every configuration once, so a change in the machine's load hits them all.
    let all: Vec<&Config> = groups.iter().flat_map(|g| &g.1).collect();
    let mut times: Vec<[Vec<f64>; 3]> = vec![Default::default(); all.len()];
    for round in 0..a.runs {
        eprintln!("round {} of {}", round + 1, a.runs);
        for (c, t) in all.iter().zip(&mut times) {
            let ext = if c.label.starts_with("PNG") {
                "png"
            } else {
                "ppm"
            };
            let one = run_once(&bin, &scene, &dir.join(format!("out.{ext}")), c, &a);
            for (v, x) in t.iter_mut().zip(one) {
                v.push(x);
            }
        }
    }
    let mut times = times.into_iter();
    let mut base = None;
    for (title, configs) in &groups {
        println!("### {title}\n");
        println!("| configuration | render s (median) | min | speedup | efficiency | efficiency of min | render / first row | write s | wall s |");
        println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
        let mut first_in_group = None;
        for c in configs {
            let [r, write, wall] = times.next().unwrap_or_default();
            let min = r.iter().copied().fold(f64::INFINITY, f64::min);
            let (r, write, wall) = (median(r), median(write), median(wall));
            let (t1, t1_min) = *base.get_or_insert((r, min));
            let speedup = t1 / r;
            let first = *first_in_group.get_or_insert(r);
            let p = c.workers as f64;
            println!(
                "| {} | {r:.3} | {min:.3} | {speedup:.2} | {:.1} % | {:.1} % | {:.3} | {write:.3} | {wall:.3} |",
                c.label,
                100.0 * speedup / p,
                100.0 * t1_min / min / p,
                r / first
            );
        }
        println!();
    }
    let _ = std::fs::remove_dir_all(&dir);
}
