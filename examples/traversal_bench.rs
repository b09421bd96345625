//! Traversal alone, with no shading, so BVH and primitive-test changes can be measured without
//! the rest of the renderer. Three sets of rays, each timed on its own:
//! - `primary`: the camera's rays through the pixel centres (`Scene::intersect`);
//! - `shadow`: from every primary hit to every point light (`Scene::transmittance`);
//! - `reflection`: the mirror direction at every primary hit (`Scene::intersect`).
//!
//! ```sh
//! cargo run --release --example traversal_bench -- teapot48.nff --passes 4 [--only shadow]
//! # instructions and cycles per ray: run under `perf stat -e instructions:u,cycles:u`, once
//! # with --passes 4 and once with --passes 0 (loading only), and divide the difference.
//! ```

use luxon::math::{reflect, Vec3A};
use luxon::ray::{spawn, spawn_to, Ray};
use luxon::scene::Light;
use luxon::{geometry::Counters, plugin::Registry, Scene};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let mut path = None;
    let mut passes = 4usize;
    let mut only = None;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--only" => only = args.next(),
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
    // Secondary rays leave the primary hits as the integrator spawns them.
    let mut c = Counters::default();
    let (mut shadow, mut reflection) = (Vec::new(), Vec::new());
    for r in &rays {
        let Some(hit) = scene.intersect(r, f32::INFINITY, &mut c) else {
            continue;
        };
        let s = scene.surface(&hit, r);
        let ng = if s.ng.dot(r.dir) < 0.0 { s.ng } else { -s.ng };
        let n = if s.ns.dot(ng) < 0.0 { -s.ns } else { s.ns };
        reflection.push(spawn(s.p, s.p_error, ng, reflect(r.dir, n), r.time));
        for light in &scene.lights {
            if let Light::Point { position, .. } = light {
                if n.dot(*position - s.p) > 0.0 {
                    shadow.push(spawn_to(s.p, s.p_error, ng, *position, r.time));
                }
            }
        }
    }
    let closest = |rays: &[Ray], c: &mut Counters| {
        rays.iter()
            .filter(|r| scene.intersect(r, f32::INFINITY, c).is_some())
            .count()
    };
    let blocked = |rays: &[(Ray, f32)], c: &mut Counters| {
        rays.iter()
            .filter(|(r, t)| scene.transmittance(r, *t, 0.0, c) == Vec3A::ZERO)
            .count()
    };
    type Cast<'a> = &'a dyn Fn(&mut Counters) -> usize;
    let sets: [(&str, usize, Cast); 3] = [
        ("primary", rays.len(), &|c| closest(&rays, c)),
        ("shadow", shadow.len(), &|c| blocked(&shadow, c)),
        ("reflection", reflection.len(), &|c| closest(&reflection, c)),
    ];
    for (name, count, cast) in sets {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let mut c = Counters::default();
        let (mut hits, mut times) = (0, Vec::new());
        for _ in 0..passes {
            let start = Instant::now();
            hits += cast(&mut c);
            times.push(start.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        let cast_total = (count * passes).max(1) as f64;
        print!(
            "{name}: {count} rays x {passes} passes, {:.1} % hit, {:.2} primitive tests per ray",
            100.0 * hits as f64 / cast_total,
            c.tests as f64 / cast_total
        );
        match times.get(times.len() / 2) {
            Some(m) => println!(
                ", median pass {:.1} ms, {:.1} ns per ray",
                m * 1e3,
                m * 1e9 / count.max(1) as f64
            ),
            None => println!(),
        }
    }
}

fn fail(what: &str) -> ! {
    eprintln!("traversal_bench: {what}");
    std::process::exit(2)
}
