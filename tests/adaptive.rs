//! Adaptive supersampling on whole scenes: flat regions cost the base samples, edges more,
//! `--stats` counts every ray, and the image converges to the uniform high-sample one.

mod common;

use common::*;
use luxon::Scene;
use luxon_formats::{AdaptiveDesc, SceneDesc};

fn adaptive(threshold: f64, max_depth: u32) -> Option<AdaptiveDesc> {
    Some(AdaptiveDesc {
        threshold,
        max_depth,
    })
}

/// Renders with `edit`; returns the 8-bit image and the primary rays cast.
fn render(path: &std::path::Path, edit: impl FnOnce(&mut SceneDesc)) -> (Vec<u8>, u64) {
    let mut desc = luxon_formats::load(path).unwrap();
    edit(&mut desc);
    let reg = registry(&desc);
    let scene = Scene::build(&desc, &reg).unwrap();
    let (fb, stats) = luxon::render::render(&scene, &|_, _| {}).unwrap();
    (to_srgb8(&fb), stats.counters.primary)
}

fn rmse(a: &[u8], b: &[u8]) -> f64 {
    luxon::metrics::rmse(a, b)
}

#[test]
fn a_flat_image_gets_exactly_the_base_samples() {
    let dir = temp_dir("adaptive-flat");
    let p = dir.join("flat.ron");
    std::fs::write(
        &p,
        r#"Scene(
            camera: (position: (0, 0, -3), look_at: (0, 0, 0), fov: 40),
            background: (0.2, 0.3, 0.4),
            materials: { "flat": (color: (0.8, 0.5, 0.1), ambient: 1, diffuse: 0) },
            objects: [(plugin: "plane", params: (point: (0, 0, 1), normal: (0, 0, -1)), material: "flat")],
        )"#,
    )
    .unwrap();
    for (samples, base) in [(1, 4), (16, 16)] {
        let (img, primary) = render(&p, |d| {
            d.render.width = 20;
            d.render.height = 10;
            d.render.samples = samples;
            d.render.adaptive = adaptive(0.0, 4);
        });
        assert_eq!(primary, 200 * base, "samples {samples}");
        assert!(img.chunks(3).all(|px| px == &img[..3] && px[0] > 150));
    }
}

/// The thin bars and disc of `scenes/antialiasing.ron` without its checker floor: geometric
/// edges on a flat background (sub-pixel texture is adaptive sampling's blind spot: four equal
/// samples in a pixel never split it).
fn edges(d: &mut SceneDesc, samples: u32, a: Option<AdaptiveDesc>) {
    d.objects.remove(0);
    d.render.width = 64;
    d.render.height = 48;
    d.render.samples = samples;
    d.render.adaptive = a;
}

#[test]
fn edges_get_more_samples_and_converge_to_the_uniform_image() {
    let scene = root().join("scenes/antialiasing.ron");
    let pixels = 64 * 48;
    let (reference, _) = render(&scene, |d| edges(d, 1024, None));
    let uniform = |n| render(&scene, |d| edges(d, n, None));
    let adapt = |n, t, depth| render(&scene, |d| edges(d, n, adaptive(t, depth)));
    let e = |img: &[u8]| rmse(img, &reference);
    let (u4, r4) = uniform(4);
    let (u16, _) = uniform(16);
    let (a4, ra4) = adapt(4, 0.05, 2);
    assert_eq!(r4, 4 * pixels);
    // More than the base where the picture has edges, far fewer than splitting everywhere.
    assert!(ra4 > r4 && ra4 < 2 * r4, "{ra4}");
    assert!(
        e(&a4) < 0.85 * e(&u4),
        "adaptive {} vs 4 samples {}",
        e(&a4),
        e(&u4)
    );
    // On a base of 16, about as many rays as 16 uniform samples and clearly less error.
    let (a16, ra16) = adapt(16, 0.05, 2);
    assert!(ra16 < 2 * 16 * pixels, "{ra16}");
    assert!(
        e(&a16) < 0.9 * e(&u16),
        "adaptive {} vs 16 samples {}",
        e(&a16),
        e(&u16)
    );
    // More base samples and depth: the uniform high-sample image.
    let (a64, _) = adapt(64, 0.02, 2);
    assert!(e(&a64) < e(&a16) && e(&a64) < 0.004, "{}", e(&a64));
}

#[test]
fn stats_count_adaptive_rays_and_bad_flags_are_refused() {
    let dir = temp_dir("adaptive-cli");
    let out = dir.join("a.png");
    let o = run(&[
        "render",
        root().join("scenes/antialiasing.ron").to_str().unwrap(),
        "--res",
        "40x30",
        "--samples",
        "4",
        "--adaptive",
        "0.05:2",
        "--stats",
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("adaptive         threshold 0.05, max depth 2: 4 base sample(s) per pixel"),
        "{err}"
    );
    let primary: u64 = err
        .lines()
        .find_map(|l| l.trim().strip_prefix("primary"))
        .and_then(|v| v.trim().parse().ok())
        .expect("a primary ray count");
    assert!(primary > 4 * 1200 && primary < 64 * 1200, "{primary}");
    for bad in ["0.05:9", "much", "-1"] {
        let flag = format!("--adaptive={bad}");
        let o = run(&[
            "render",
            root().join("scenes/antialiasing.ron").to_str().unwrap(),
            &flag,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success());
        assert!(stderr(&o).contains("--adaptive"), "{}", stderr(&o));
    }
}

/// The sampling pattern itself: the shipped ball-and-stick molecule rendered adaptively must
/// match its committed picture (so a change of positions, splitting or averaging shows up here;
/// bless with `LUXON_BLESS=1 cargo test --test adaptive` after looking at the new picture).
#[test]
fn ball_and_stick_matches_its_adaptive_golden_image() {
    let fb = render_with(&root().join("scenes/ball-and-stick.ron"), |d| {
        d.render.width = 128;
        d.render.height = 96;
        d.render.samples = 4;
        d.render.adaptive = adaptive(0.05, 2);
    });
    let got = to_srgb8(&fb);
    let golden = root().join("tests/golden/ball-and-stick-adaptive.png");
    if std::env::var_os("LUXON_BLESS").is_some() {
        image::save_buffer(&golden, &got, fb.width, fb.height, image::ColorType::Rgb8).unwrap();
        return;
    }
    let want = image::open(&golden)
        .unwrap_or_else(|e| panic!("{}: {e} (bless with LUXON_BLESS=1)", golden.display()))
        .to_rgb8();
    assert_eq!((want.width(), want.height()), (fb.width, fb.height));
    let (mean, max) = diff(&got, want.as_raw());
    // Same machine: identical. Elsewhere, libm's last bits may differ a little at edges.
    assert!(mean < 0.5 && max < 64, "mean diff {mean:.3}, max {max}");
    // Not a flat picture: the molecule is there, bright atoms on a dark background.
    assert!(got.iter().any(|&c| c > 200) && got.iter().any(|&c| c < 90));
}
