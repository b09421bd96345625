//! Threads of the API: a context's pool is the only one a load, build and render use (rayon's
//! global pool, which would start one unnamed thread per CPU, is never reached), its threads
//! sleep between renders, and dropping the context and renderer ends them. One test in its own binary, so no other test's
//! threads are counted.
#![cfg(target_os = "linux")]

mod common;

use common::*;
use luxon::api::{Color, Context, ContextOptions, Plane, Renderer, RendererOptions, Scene, Target};
use std::time::{Duration, Instant};

/// The names of this process's threads.
fn threads() -> Vec<String> {
    std::fs::read_dir("/proc/self/task")
        .unwrap()
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("comm")).ok())
        .map(|n| n.trim().to_string())
        .collect()
}

/// User and system CPU time (clock ticks) of the threads named `luxon-render-*`.
fn pool_ticks() -> u64 {
    let mut sum = 0;
    for t in std::fs::read_dir("/proc/self/task").unwrap().flatten() {
        let comm = std::fs::read_to_string(t.path().join("comm")).unwrap_or_default();
        if !comm.starts_with("luxon-render-") {
            continue;
        }
        let stat = std::fs::read_to_string(t.path().join("stat")).unwrap_or_default();
        // Fields after the name (which may hold spaces): state is field 3, utime 14, stime 15.
        let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
        let f: Vec<u64> = rest
            .split_whitespace()
            .skip(11)
            .take(2)
            .map(|v| v.parse().unwrap())
            .collect();
        sum += f.iter().sum::<u64>();
    }
    sum
}

#[test]
fn a_context_pool_is_the_only_one_used_sleeps_when_idle_and_ends_with_it() {
    ensure_plugins();
    let before = threads();
    let path = root().join("scenes/spheres.ron");
    let ctx = Context::new(ContextOptions {
        threads: 2,
        ..Default::default()
    })
    .unwrap();
    let renderer = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    // Plugins create the objects; the BVHs are built (over enough spheres to run in parallel
    // if they were not stored by plugins) and the image rendered.
    let mut scene = Scene::load(&ctx, &path).unwrap();
    let (w, h) = (96, 64);
    let mut px = vec![[0u8; 4]; w * h];
    let target = Target {
        width: w as u32,
        height: h as u32,
        color: Color::Rgba8Srgb(Plane::new(&mut px, w)),
        depth: None,
    };
    renderer.render(&mut scene, target).unwrap();
    // An NFF file: parsed in parallel, and 10,000 spheres are enough for a parallel BVH build.
    let dir = temp_dir("api-threads");
    let nff = dir.join("many.nff");
    let mut text = String::from(
        "v\nfrom 0 -150 40\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.1\nresolution 32 24\n\
         b 0.1 0.1 0.1\nl 0 -100 100\nf 0.9 0.2 0.2 0.6 0.4 30 0 0\n",
    );
    for i in 0..10_000 {
        let (x, y) = ((i % 100) as f64 - 50.0, (i / 100) as f64 - 50.0);
        text.push_str(&format!("s {x} {y} 0 0.4\n"));
    }
    std::fs::write(&nff, text).unwrap();
    let mut many = Scene::load(&ctx, &nff).unwrap();
    let mut px = vec![[0u8; 4]; 32 * 24];
    let target = Target {
        width: 32,
        height: 24,
        color: Color::Rgba8Srgb(Plane::new(&mut px, 32)),
        depth: None,
    };
    renderer.render(&mut many, target).unwrap();
    assert!(px.iter().any(|p| p[0] > 50), "the spheres are seen");
    let during = threads();
    let mut new = during.clone();
    for t in &before {
        if let Some(i) = new.iter().position(|n| n == t) {
            new.remove(i);
        }
    }
    assert_eq!(new.len(), 2, "new threads: {new:?}");
    assert!(
        new.iter().all(|n| n.starts_with("luxon-render-")),
        "only the context's pool: {new:?}"
    );

    // Idle, the pool's threads sleep: once the last render's workers have gone to sleep, a
    // second passes with (nearly) no CPU time spent by them.
    std::thread::sleep(Duration::from_millis(300));
    let busy = pool_ticks();
    std::thread::sleep(Duration::from_secs(1));
    let idle = pool_ticks() - busy;
    assert!(
        idle <= 2,
        "the idle pool used {idle} clock ticks in a second"
    );

    drop(scene);
    drop(many);
    drop(renderer);
    drop(ctx);
    // Rayon ends its threads after the pool is dropped, not before `drop` returns.
    let start = Instant::now();
    while threads().len() > before.len() && start.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(threads().len(), before.len(), "{:?}", threads());
}
