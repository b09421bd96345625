//! What in-situ rendering costs (issue 20's measured items), each as medians on a shared
//! machine:
//!
//! - `cloud`: a diffusing cloud of 200 k spheres over 100 steps; at every 10th step the ray
//!   throughput (primary and shadow rays, 256² view) of the refitted tree, with the automatic
//!   rebuild rule (cost above [`REBUILD_RATIO`] × the cost at build) and without it, against a
//!   tree freshly built on the same positions. (Refit against build time: `refit_bench`.)
//! - `memory`: 10 M spheres published through the API from a shared array and from a copy, each
//!   in a process of its own: resident memory beyond the data and the BVH.
//! - `idle`: a 3-D heat stencil on 2 threads alone, and with a context, a renderer and a
//!   committed scene idle in the process; runs alternate, each in a process of its own.
//! - `lj`: the per-step costs of the Lennard-Jones example (`insitu_lj`).
//!
//! ```sh
//! cargo run --release --example insitu_bench -- [--quick] [--only cloud|memory|idle|lj]
//! ```

#[path = "lj.rs"]
#[allow(dead_code)]
mod lj;

use luxon::api::{Context, ContextOptions, Radius, Renderer, RendererOptions, Scene, Spheres};
use luxon::arrays::{Array, SharedVec};
use luxon::bvh::{Bvh, REBUILD_RATIO};
use luxon::math::{Aabb, Vec3A};
use rayon::prelude::*;
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--child") {
        return child(&args[1..]);
    }
    let quick = args.iter().any(|a| a == "--quick");
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1).cloned());
    let want = |name: &str| only.as_deref().is_none_or(|o| o == name);
    println!(
        "insitu_bench on {} CPUs{}",
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        if quick { " (--quick)" } else { "" }
    );
    if want("cloud") {
        cloud(if quick { 50_000 } else { 200_000 });
    }
    if want("memory") {
        memory(if quick { 1_000_000 } else { 10_000_000 });
    }
    if want("idle") {
        idle(if quick { 3 } else { 7 });
    }
    if want("lj") {
        lj_overhead(quick);
    }
}

/// A deterministic stream of numbers.
struct Lcg(u64);

impl Lcg {
    fn uniform(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 40) as f32 + 0.5) / (1u64 << 24) as f32
    }

    /// A standard normal number (Box–Muller).
    fn normal(&mut self) -> f32 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f32::consts::TAU * v).cos()
    }
}

const RADIUS: f32 = 0.3;

fn bound(c: Vec3A) -> Aabb {
    Aabb::new(c - RADIUS, c + RADIUS)
}

/// The distance along a unit `dir` from `o` to the sphere at `c`, if it is hit before `t_max`.
#[inline]
fn hit(o: Vec3A, dir: Vec3A, c: Vec3A, t_max: f32) -> Option<f32> {
    let oc = o - c;
    let b = oc.dot(dir);
    let disc = b * b - (oc.dot(oc) - RADIUS * RADIUS);
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t > 1e-4 && t < t_max).then_some(t)
}

/// A tree over the spheres with its leaf order.
struct Tree {
    bvh: Bvh,
    order: Vec<u64>,
    cost_at_build: f32,
}

impl Tree {
    fn build(c: &[Vec3A]) -> Tree {
        let (bvh, order) = Bvh::build_with(c.len(), |i| bound(c[i]));
        let cost_at_build = bvh.sah_cost();
        Tree {
            bvh,
            order,
            cost_at_build,
        }
    }

    /// Refits to `c`; returns the cost over the cost at build.
    fn refit(&mut self, c: &[Vec3A]) -> f32 {
        let order = &self.order;
        self.bvh.refit(|i| bound(c[order[i] as usize])) / self.cost_at_build
    }

    /// Primary rays through a 256² view and shadow rays from their hits toward a light, once;
    /// returns the time, the rays, the primary hits (to check trees agree) and the sphere
    /// tests (the work, free of the machine's noise).
    fn cast(&self, c: &[Vec3A], side: f32) -> (Duration, Cast) {
        const W: usize = 256;
        let center = Vec3A::splat(side / 2.0);
        let eye = center + Vec3A::new(0.35, 0.45, -1.0).normalize() * side * 1.6;
        let light = center + Vec3A::new(-1.0, 2.0, -1.5) * side;
        let forward = (center - eye).normalize();
        let right = forward.cross(Vec3A::Y).normalize();
        let up = right.cross(forward);
        let start = Instant::now();
        let cast = {
            (0..W * W)
                .into_par_iter()
                .with_min_len(256)
                .map(|p| {
                    let mut tests = 0;
                    let (x, y) = ((p % W) as f32, (p / W) as f32);
                    let (u, v) = ((x + 0.5) / W as f32 - 0.5, 0.5 - (y + 0.5) / W as f32);
                    let dir = (forward + (right * u + up * v) * 0.7).normalize();
                    let order = &self.order;
                    let t = self.bvh.intersect(eye, dir, f32::INFINITY, |i, t_max| {
                        tests += 1;
                        hit(eye, dir, c[order[i] as usize], t_max)
                    });
                    if !t.is_finite() {
                        return Cast {
                            rays: 1,
                            hits: 0,
                            tests,
                        };
                    }
                    let at = eye + dir * t;
                    let to = light - at;
                    let (len, d) = (to.length(), to.normalize());
                    let _ = self.bvh.any(at, d, len, |i| {
                        tests += 1;
                        hit(at, d, c[order[i] as usize], len).is_some()
                    });
                    Cast {
                        rays: 2,
                        hits: 1,
                        tests,
                    }
                })
                .reduce(Cast::default, |a, b| Cast {
                    rays: a.rays + b.rays,
                    hits: a.hits + b.hits,
                    tests: a.tests + b.tests,
                })
        };
        (start.elapsed(), cast)
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Cast {
    rays: u64,
    hits: u64,
    tests: u64,
}

fn cloud(n: usize) {
    let side = (n as f32).cbrt();
    let mut r = Lcg(7);
    let mut c: Vec<Vec3A> = (0..n)
        .map(|_| Vec3A::new(r.uniform(), r.uniform(), r.uniform()) * side)
        .collect();
    let mut plain = Tree::build(&c);
    let mut ruled = Tree::build(&c);
    let (mut rebuilds, mut worst, mut worst_work) = (0, f64::INFINITY, f64::INFINITY);
    println!(
        "\n## cloud: {n} spheres (radius {RADIUS}, mean spacing 1) diffusing by 0.05 per step \
         and axis, {} threads; rays/s of primary + shadow rays on a 256² view",
        rayon::current_num_threads()
    );
    println!(
        "| step | SAH refit/fresh | fresh: rays/s, tests/ray | refit only: rays/s vs fresh \
         (tests) | with the rule: vs fresh (tests) | rebuilds so far |"
    );
    println!("|---:|---:|---:|---:|---:|---:|");
    for step in 0..=100 {
        if step > 0 {
            for p in c.iter_mut() {
                *p += Vec3A::new(r.normal(), r.normal(), r.normal()) * 0.05;
            }
            plain.refit(&c);
            if ruled.refit(&c) > REBUILD_RATIO {
                ruled = Tree::build(&c);
                rebuilds += 1;
            }
        }
        if step % 10 != 0 {
            continue;
        }
        let fresh = Tree::build(&c);
        // Passes alternate between the trees, so the machine's moods hit all three alike.
        let mut times = [Vec::new(), Vec::new(), Vec::new()];
        let mut casts = [Cast::default(); 3];
        for _ in 0..5 {
            for (k, tree) in [&fresh, &plain, &ruled].into_iter().enumerate() {
                let (t, cast) = tree.cast(&c, side);
                times[k].push(t);
                casts[k] = cast;
            }
        }
        assert!(
            casts[1].hits == casts[0].hits && casts[2].hits == casts[0].hits,
            "trees disagree"
        );
        let mut rate = |k: usize| casts[k].rays as f64 / median(&mut times[k]).as_secs_f64();
        let (f, p, q) = (rate(0), rate(1), rate(2));
        let per_ray = |k: usize| casts[k].tests as f64 / casts[k].rays as f64;
        let sah = plain.bvh.sah_cost() / fresh.bvh.sah_cost();
        worst = worst.min(q / f);
        worst_work = worst_work.min(per_ray(0) / per_ray(2));
        println!(
            "| {step} | {sah:.3} | {:.2} M, {:.1} | {:.0} % ({:.0} %) | {:.0} % ({:.0} %) | \
             {rebuilds} |",
            f / 1e6,
            per_ray(0),
            100.0 * p / f,
            100.0 * per_ray(0) / per_ray(1),
            100.0 * q / f,
            100.0 * per_ray(0) / per_ray(2),
        );
    }
    println!(
        "a fresh build's rays/s (tests per ray) are the 100 % line; with the rule the worst \
         point is {:.0} % ({:.0} % in tests per ray; target ≥ 70 %)",
        100.0 * worst,
        100.0 * worst_work
    );
}

/// `VmRSS` of this process in bytes.
fn rss() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(0, |kb| kb * 1024)
}

fn memory(n: usize) {
    println!(
        "\n## memory: {n} spheres (f64 centres, {} MB) published from a shared array and from \
         a copy, a process each",
        n * 24 / 1_000_000
    );
    println!(
        "| mode | resident before (data, Luxon loaded) | after add + commit | BVH + leaf order \
         in use | added beyond the BVH |"
    );
    println!("|---|---:|---:|---:|---:|");
    for mode in ["shared", "copy"] {
        let o = Command::new(std::env::current_exe().unwrap())
            .args(["--child", "memory", mode, &n.to_string()])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout);
        if !o.status.success() {
            println!(
                "| {mode} | failed: {} |",
                String::from_utf8_lossy(&o.stderr).trim()
            );
            continue;
        }
        let v: Vec<f64> = text
            .split_whitespace()
            .filter_map(|w| w.parse().ok())
            .collect();
        let mb = |b: f64| b / 1e6;
        println!(
            "| {mode} | {:.1} MB | {:.1} MB | {:.1} MB | {:.1} MB |",
            mb(v[0]),
            mb(v[1]),
            mb(v[2]),
            mb(v[1] - v[0] - v[2])
        );
    }
}

/// Children: `memory shared|copy N`, `idle alone|luxon SECONDS`.
fn child(args: &[String]) {
    match args {
        [what, mode, n] if what == "memory" => memory_child(mode == "copy", n.parse().unwrap()),
        [what, mode, reps] if what == "idle" => idle_child(mode == "luxon", reps.parse().unwrap()),
        _ => panic!("bad child arguments {args:?}"),
    }
}

fn memory_child(copy: bool, n: usize) {
    // As the luxon binary does: freed build buffers go back to the system.
    // SAFETY: mallopt only sets a parameter of glibc's allocator; no other thread runs yet.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
    let mut r = Lcg(3);
    let side = (n as f32).cbrt();
    let data = SharedVec::new(
        (0..n)
            .map(|_| [r.uniform(), r.uniform(), r.uniform()].map(|x| f64::from(x * side)))
            .collect::<Vec<[f64; 3]>>(),
    );
    let ctx = Context::new(ContextOptions {
        threads: 2,
        ..Default::default()
    })
    .unwrap();
    let renderer = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut scene = Scene::new(&ctx);
    scene
        .set_camera_ron("(position: (0, 0, -50), look_at: (0, 0, 0))")
        .unwrap();
    let before = rss();
    let centers = match copy {
        true => Array::copy(&data.read()).unwrap(),
        false => Array::shared(&data),
    };
    scene
        .add_spheres(Spheres::new(centers, Radius::Const(0.3)))
        .unwrap();
    scene.commit(&renderer).unwrap();
    let after = rss();
    let tree: u64 = scene
        .built()
        .map_or(0, |b| b.objects.list().iter().map(|o| o.bytes()).sum());
    println!("{before} {after} {tree}");
}

/// A 3-D heat stencil on a 96³ grid, `reps` sweeps on the current pool.
fn stencil(reps: usize) -> Duration {
    const N: usize = 96;
    let mut u = vec![0.0f64; N * N * N];
    let mut next = u.clone();
    u[N * N * N / 2 + N * N / 2 + N / 2] = 1.0;
    let start = Instant::now();
    for _ in 0..reps {
        next.par_chunks_mut(N * N)
            .enumerate()
            .for_each(|(k, plane)| {
                if k == 0 || k == N - 1 {
                    return;
                }
                for j in 1..N - 1 {
                    for i in 1..N - 1 {
                        let at = (k * N + j) * N + i;
                        let sum = u[at - 1]
                            + u[at + 1]
                            + u[at - N]
                            + u[at + N]
                            + u[at - N * N]
                            + u[at + N * N];
                        plane[j * N + i] = u[at] + 0.15 * (sum - 6.0 * u[at]);
                    }
                }
            });
        std::mem::swap(&mut u, &mut next);
    }
    std::hint::black_box(&u);
    start.elapsed()
}

fn idle_child(luxon: bool, reps: usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    // Luxon loaded and ready, but idle: a context, a renderer and a committed scene.
    let _kept = luxon.then(|| {
        let ctx = Context::new(ContextOptions {
            threads: 2,
            ..Default::default()
        })
        .unwrap();
        let renderer = Renderer::new(&ctx, RendererOptions::default()).unwrap();
        let mut scene = Scene::new(&ctx);
        scene
            .set_camera_ron("(position: (0, 0, -10), look_at: (0, 0, 0))")
            .unwrap();
        let centers = Array::from_vec(vec![[0.0f64; 3], [1.0, 0.0, 0.0]]);
        scene
            .add_spheres(Spheres::new(centers, Radius::Const(0.3)))
            .unwrap();
        scene.commit(&renderer).unwrap();
        (ctx, renderer, scene)
    });
    let t = pool.install(|| stencil(reps));
    println!("{}", t.as_secs_f64());
}

fn idle(runs: usize) {
    // About 2 s a run on this machine.
    let reps = 200;
    let (mut alone, mut with) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        for (mode, into) in [("alone", &mut alone), ("luxon", &mut with)] {
            let o = Command::new(std::env::current_exe().unwrap())
                .args(["--child", "idle", mode, &reps.to_string()])
                .output()
                .unwrap();
            let s: f64 = String::from_utf8_lossy(&o.stdout).trim().parse().unwrap();
            into.push(Duration::from_secs_f64(s));
        }
    }
    let (a, w) = (median(&mut alone), median(&mut with));
    println!(
        "\n## idle: a 96³ heat stencil, {reps} sweeps on 2 threads, {runs} alternating runs: \
         alone {:.3} s, with an idle Luxon (context, renderer, committed scene; 2 threads) \
         {:.3} s (medians): ratio {:.3} (target ≤ 1.02)",
        a.as_secs_f64(),
        w.as_secs_f64(),
        w.as_secs_f64() / a.as_secs_f64()
    );
}

fn lj_overhead(quick: bool) {
    let out = std::env::temp_dir().join(format!("luxon-insitu-bench-{}", std::process::id()));
    let mut plugin_path = Vec::new();
    if let Some(dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().and_then(|d| d.parent()).map(PathBuf::from))
    {
        plugin_path.push(dir);
    }
    let config = lj::Config {
        particles: if quick { 1000 } else { 4000 },
        steps: if quick { 50 } else { 200 },
        every: 10,
        size: 512,
        threads: 2,
        out: out.clone(),
        plugin_path,
        verbose: false,
    };
    let r = lj::run(&config).unwrap_or_else(|e| panic!("insitu_lj: {e}"));
    let _ = std::fs::remove_dir_all(&out);
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let (sim, commit, render) = (
        lj::median(&r.step_times),
        lj::median(r.commit_times.get(1..).unwrap_or_default()),
        lj::median(&r.render_times),
    );
    let rebuilds: u32 = r.commits[1..].iter().map(|c| c.degraded).sum();
    println!(
        "\n## lj: {} particles, {} steps, a 512² frame every {} steps, 2 threads: sim {:.2} \
         ms/step, commit {:.2} ms ({} refits, {rebuilds} of them rebuilt by the rule), render \
         {:.1} ms/frame (medians); rendering costs {:.0} % of the simulation's time; {} bytes \
         copied",
        config.particles,
        config.steps,
        config.every,
        ms(sim),
        ms(commit),
        r.commits.len() - 1,
        ms(render),
        100.0 * ms(commit + render) / (ms(sim) * config.every as f64),
        r.copied_bytes
    );
}

fn median(v: &mut [Duration]) -> Duration {
    v.sort();
    v.get(v.len() / 2).copied().unwrap_or_default()
}
