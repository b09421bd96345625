//! Refitting a BVH against building it anew, on a cloud of moving spheres: the build (bounds
//! and `Bvh::build_with`) and the refit (bounds read through the leaf order and
//! `Bvh::refit`) of the same spheres after each has moved by a random step, timed in turn;
//! prints the medians, their ratio (issue 20 asks for at most 0.25 with 1 M spheres) and the
//! refitted tree's SAH cost over a fresh build's.
//!
//! ```sh
//! cargo run --release --example refit_bench -- [--count 1000000] [--runs 7] [--threads N]
//! ```

use luxon::bvh::{Bvh, REBUILD_RATIO};
use luxon::math::{Aabb, Vec3A};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let (mut count, mut runs, mut threads) = (1_000_000usize, 7usize, 0usize);
    while let Some(a) = args.next() {
        let mut value = |what: &str| -> usize {
            args.next()
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| fail(&format!("{what} N")))
        };
        match a.as_str() {
            "--count" => count = value("--count"),
            "--runs" => runs = value("--runs").max(1),
            "--threads" => threads = value("--threads"),
            _ => fail(&format!("unknown argument `{a}`")),
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap_or_else(|e| fail(&e.to_string()));
    pool.install(|| run(count, runs));
}

fn run(count: usize, runs: usize) {
    // Spheres in a cube, about as far apart as they are wide, moved by 5 % of their spacing.
    let side = (count as f32).cbrt();
    let radius = 0.25;
    let mut seed = 2024u32;
    let mut r = move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut centers: Vec<Vec3A> = (0..count)
        .map(|_| Vec3A::new(r(), r(), r()) * side)
        .collect();
    let bound = |c: Vec3A| Aabb::new(c - radius, c + radius);
    let (mut bvh, mut order) = Bvh::build_with(count, |i| bound(centers[i]));
    let (mut builds, mut refits, mut costs) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..runs {
        for c in centers.iter_mut() {
            *c += (Vec3A::new(r(), r(), r()) - 0.5) * 0.1;
        }
        let start = Instant::now();
        let refit_cost = bvh.refit(|i| bound(centers[order[i] as usize]));
        refits.push(start.elapsed().as_secs_f64());
        let start = Instant::now();
        let (fresh, fresh_order) = Bvh::build_with(count, |i| bound(centers[i]));
        builds.push(start.elapsed().as_secs_f64());
        costs.push(refit_cost / fresh.sah_cost());
        // The next step refits the fresh tree, so every step measures one step's movement.
        (bvh, order) = (fresh, fresh_order);
    }
    let (build, refit) = (median(&mut builds), median(&mut refits));
    println!(
        "{count} spheres, {} threads, {runs} runs: build {:.1} ms, refit {:.1} ms (medians), \
         refit / build = {:.3}; SAH cost refitted / fresh = {:.3} (rebuild above {REBUILD_RATIO})",
        rayon::current_num_threads(),
        build * 1e3,
        refit * 1e3,
        refit / build,
        median(&mut costs),
    );
}

fn median<T: Copy + PartialOrd>(v: &mut [T]) -> T {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    v[v.len() / 2]
}

fn fail(what: &str) -> ! {
    eprintln!("refit_bench: {what}");
    std::process::exit(2)
}
