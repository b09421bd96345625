//! Baked against shared instances on a big case: `--copies` copies of a mesh of `--grid`² × 2
//! triangles (a bumpy square, written as an OBJ file), built with `instancing: Bake` or `Share`
//! and rendered once. Prints the build time, the memory the scene holds (what the build
//! charged to the memory budget: geometry and BVHs), the process's peak resident memory
//! (VmHWM: run each mode in its own process), and the render time per ray.
//!
//! ```sh
//! cargo build --release
//! cargo run --release --example instances_bench -- --mode share --copies 1000 --grid 100
//! cargo run --release --example instances_bench -- --mode bake --copies 1000 --grid 100
//! ```

use luxon::budget::Use;
use luxon::{plugin::Registry, Scene};
use std::fmt::Write as _;
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let (mut copies, mut grid, mut mode, mut res) = (1000usize, 100usize, String::new(), 256u32);
    let mut threads = 0u32;
    while let Some(a) = args.next() {
        let mut value = |what: &str| -> String {
            args.next()
                .unwrap_or_else(|| fail(&format!("{what} needs a value")))
        };
        let number = |s: String, what: &str| -> usize {
            s.parse()
                .unwrap_or_else(|_| fail(&format!("{what}: expected a number")))
        };
        match a.as_str() {
            "--copies" => copies = number(value("--copies"), "--copies"),
            "--grid" => grid = number(value("--grid"), "--grid").max(1),
            "--res" => res = number(value("--res"), "--res").max(8) as u32,
            "--threads" => threads = number(value("--threads"), "--threads") as u32,
            "--mode" => mode = value("--mode"),
            _ => fail(&format!("unknown argument `{a}`")),
        }
    }
    let how = match mode.as_str() {
        "bake" => "Bake",
        "share" => "Share",
        _ => fail("--mode bake|share"),
    };
    let dir = std::env::temp_dir().join(format!("luxon-instances-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| fail(&e.to_string()));
    std::fs::write(dir.join("grid.obj"), mesh(grid)).unwrap_or_else(|e| fail(&e.to_string()));
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene(copies, how, res, threads))
        .unwrap_or_else(|e| fail(&e.to_string()));
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| fail(&e.to_string()));
    let registry = Registry::discover(&desc.plugin_path);
    let start = Instant::now();
    let scene = Scene::build(&desc, &registry).unwrap_or_else(|e| fail(&e.to_string()));
    let build = start.elapsed();
    let held = scene.budget.used(Use::Geometry) + scene.budget.used(Use::Bvh);
    let (fb, stats) =
        luxon::render::render(&scene, &|_, _| {}).unwrap_or_else(|e| fail(&e.to_string()));
    let rays = stats.counters.rays();
    let ns = stats.render_time.as_secs_f64() * 1e9 * stats.threads as f64 / rays as f64;
    let lit = fb.rgba.chunks(4).filter(|p| p[0] > 0.05).count();
    println!(
        "{how}: {copies} copies of {} triangles; triangles stored {}, shared instances {}",
        2 * grid * grid,
        scene.triangles.len()
            + scene
                .instances
                .blases
                .iter()
                .map(|b| b.triangles.len())
                .sum::<usize>(),
        scene.instances.list.len()
    );
    println!(
        "build {:.1} ms; scene holds {:.1} MiB (geometry and BVHs); peak RSS {} MiB",
        build.as_secs_f64() * 1e3,
        held as f64 / (1u64 << 20) as f64,
        peak_rss_kib() / 1024
    );
    println!(
        "render {res}x{res}: {:.1} ms on {} threads, {rays} rays, {ns:.0} ns per ray per thread \
         ({lit} lit pixels)",
        stats.render_time.as_secs_f64() * 1e3,
        stats.threads
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A `n` × `n` grid of quads over the unit square, gently bumped: 2n² triangles.
fn mesh(n: usize) -> String {
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (i as f64 / n as f64, j as f64 / n as f64);
            let y = 0.08 * (x * 11.0).sin() * (z * 9.0).cos();
            let _ = writeln!(s, "v {x} {y} {z}");
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
            let _ = writeln!(s, "f {a} {b} {c}\nf {a} {c} {d}");
        }
    }
    s
}

/// The copies on a square field, each turned, seen from above at an angle.
fn scene(copies: usize, how: &str, res: u32, threads: u32) -> String {
    let side = (copies as f64).sqrt().ceil() as usize;
    let half = side as f64 * 0.75;
    let mut s = format!(
        "Scene(\n    camera: (position: (0, {}, {}), look_at: (0, 0, 0), fov: 50),\n    lights: [Directional(direction: (-1, -2, 1))],\n    materials: {{ \"m\": (color: (0.8, 0.7, 0.5), specular: 0.4) }},\n    prototypes: {{ \"grid\": (meshes: [(file: \"grid.obj\", material: \"m\")]) }},\n    instances: [\n",
        half * 1.6,
        -half * 1.8
    );
    for k in 0..copies {
        let (x, z) = (
            (k % side) as f64 * 1.5 - half,
            (k / side) as f64 * 1.5 - half,
        );
        let _ = writeln!(
            s,
            "        (prototype: \"grid\", world_from_object: (translate: ({x}, 0, {z}), rotate: (axis: (0, 1, 0), degrees: {}))),",
            (k * 37) % 360
        );
    }
    let threads = if threads > 0 {
        format!(", parallel: (threads: {threads})")
    } else {
        String::new()
    };
    let _ = write!(
        s,
        "    ],\n    render: (width: {res}, height: {res}, instancing: {how}{threads}),\n)\n"
    );
    s
}

/// The process's peak resident memory (VmHWM), in KiB; 0 where /proc does not tell.
fn peak_rss_kib() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

fn fail(message: &str) -> ! {
    eprintln!("instances_bench: {message}");
    std::process::exit(2)
}
