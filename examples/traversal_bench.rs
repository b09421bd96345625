//! Closest-hit traversal alone: the camera's primary rays (one per pixel centre) cast through
//! `Scene::intersect`, with no shading, so BVH and primitive-test changes can be measured
//! without the rest of the renderer.
//!
//! ```sh
//! cargo run --release --example traversal_bench -- teapot48.nff --passes 4
//! # instructions and cycles per ray: run under `perf stat -e instructions:u,cycles:u`, once
//! # with --passes 4 and once with --passes 0 (loading only), and divide the difference.
//! ```

use luxon::{geometry::Counters, plugin::Registry, Scene};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let mut path = None;
    let mut passes = 4usize;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--passes" => {
                passes = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .unwrap_or_else(|| fail("--passes N"))
            }
            _ => path = Some(a),
        }
    }
    let path = path.unwrap_or_else(|| fail("a scene file"));
    let desc = luxon_formats::load(path.as_ref()).unwrap_or_else(|e| fail(&e.to_string()));
    let registry = Registry::discover(&desc.plugin_path);
    let scene = Scene::build(&desc, &registry).unwrap_or_else(|e| fail(&e.to_string()));
    let (w, h) = (scene.settings.width, scene.settings.height);
    let rays: Vec<_> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter_map(|(x, y)| {
            scene
                .camera
                .primary(x as f32 + 0.5, y as f32 + 0.5, w, h, 0.0)
        })
        .collect();
    let mut c = Counters::default();
    let (mut hits, mut times) = (0u64, Vec::new());
    for _ in 0..passes {
        let start = Instant::now();
        for r in &rays {
            hits += u64::from(scene.intersect(r, f32::INFINITY, &mut c).is_some());
        }
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let rays_cast = (rays.len() * passes) as f64;
    println!(
        "{} primary rays x {passes} passes: {hits} hits, {:.2} primitive tests per ray",
        rays.len(),
        c.tests as f64 / rays_cast.max(1.0)
    );
    if let Some(median) = times.get(times.len() / 2) {
        println!(
            "median pass {:.1} ms, {:.1} ns per ray",
            median * 1e3,
            median * 1e9 / rays.len().max(1) as f64
        );
    }
}

fn fail(what: &str) -> ! {
    eprintln!("traversal_bench: {what}");
    std::process::exit(2)
}
