//! Rendering into the caller's buffers (`render::render_into` and `framebuffer::Target`): 8-bit
//! sRGB equal to the PNG writer's bytes, f32 equal to `render::render` bit for bit, row strides
//! that leave the padding alone, planes too small refused, depth, and cancelling from another
//! thread.

mod common;

use common::{registry, root, temp_dir};
use luxon::framebuffer::{Color, Plane, Target};
use luxon::plugin::Registry;
use luxon::render::{render, render_into};
use luxon::schedule::thread_pool;
use luxon::{Error, Scene};
use luxon_formats::{Decomposition, SceneDesc};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// A built scene and the plugins it was built with (the scene drops first).
struct Built {
    scene: Scene,
    _registry: Registry,
}

fn build(desc: &SceneDesc) -> Built {
    let registry = registry(desc);
    let scene = Scene::build(desc, &registry).unwrap_or_else(|e| panic!("{e}"));
    Built {
        scene,
        _registry: registry,
    }
}

/// `scenes/spheres.ron` at `w`×`h`.
fn spheres_desc(w: u32, h: u32) -> SceneDesc {
    let mut desc = luxon_formats::load(&root().join("scenes/spheres.ron")).unwrap();
    desc.render.width = w;
    desc.render.height = h;
    desc
}

fn text_desc(name: &str, ron: &str) -> SceneDesc {
    let path = temp_dir(name).join("scene.ron");
    std::fs::write(&path, ron).unwrap();
    luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn no_progress(_: u64, _: u64) {}

/// Renders into a tight linear RGBA f32 buffer (and depth, when asked).
fn render_f32(scene: &Scene, threads: usize, depth: bool) -> (Vec<[f32; 4]>, Vec<f32>) {
    let (w, h) = (scene.settings.width, scene.settings.height);
    let n = (w * h) as usize;
    let (mut rgba, mut z) = (vec![[f32::NAN; 4]; n], vec![f32::NAN; n]);
    let target = Target {
        width: w,
        height: h,
        color: Color::Rgba32fLinear(Plane::new(&mut rgba, w as usize)),
        depth: depth.then(|| Plane::new(&mut z, w as usize)),
    };
    let pool = thread_pool(threads).unwrap();
    render_into(scene, &pool, target, &AtomicBool::new(false), &no_progress)
        .unwrap_or_else(|e| panic!("{e}"));
    (rgba, z)
}

fn bits(rgba: &[[f32; 4]]) -> Vec<u32> {
    rgba.iter().flatten().map(|v| v.to_bits()).collect()
}

#[test]
fn rgba8_is_the_png_writers_bytes() {
    let mut desc = spheres_desc(48, 32);
    let dir = temp_dir("target-png");
    let mut png = desc.render.outputs[0].clone();
    png.path = dir.join("alpha.png");
    png.params = "(alpha: true)".into();
    desc.render.outputs = vec![png];
    let b = build(&desc);
    let (image, _) = render(&b.scene, &no_progress).unwrap();
    let outputs = luxon::output::resolve(&b.scene.outputs, &b._registry).unwrap();
    luxon::output::write_all(&outputs, &image, &b._registry, &dir).unwrap();
    let written = image::open(dir.join("alpha.png")).unwrap().to_rgba8();

    let mut rgba8 = vec![[0u8; 4]; 48 * 32];
    let target = Target {
        width: 48,
        height: 32,
        color: Color::Rgba8Srgb(Plane::new(&mut rgba8, 48)),
        depth: None,
    };
    let pool = thread_pool(2).unwrap();
    render_into(
        &b.scene,
        &pool,
        target,
        &AtomicBool::new(false),
        &no_progress,
    )
    .unwrap();
    assert_eq!(rgba8.concat(), written.into_raw());
    // Not a flat image: the formula is exercised across tones.
    let distinct: std::collections::BTreeSet<[u8; 4]> = rgba8.iter().copied().collect();
    assert!(distinct.len() > 100, "{} distinct pixels", distinct.len());
}

/// The 8-bit formula of the target is the PPM bytes' (`ppm::srgb8`) for colour, at every
/// 1/1024 step and beyond the ends.
#[test]
fn rgba8_colour_is_the_ppm_formula() {
    let values: Vec<f32> = (-8..=1100)
        .map(|i| i as f32 / 1024.0)
        .chain([f32::NAN, 7.0, f32::INFINITY])
        .collect();
    let rgba: Vec<f32> = values.iter().flat_map(|&v| [v, v, v, 1.0]).collect();
    let mut ppm = Vec::new();
    luxon::ppm::srgb8(&rgba, &mut ppm);
    for (i, &v) in values.iter().enumerate() {
        let px = luxon::framebuffer::rgba8([v, v, v, v]);
        assert_eq!(&px[..3], &ppm[3 * i..3 * i + 3], "{v}");
    }
}

#[test]
fn rgba_f32_equals_render_for_every_decomposition() {
    let mut desc = spheres_desc(48, 32);
    desc.render.parallel.tile_size = 8;
    let mut b = build(&desc);
    let (reference, _) = render(&b.scene, &no_progress).unwrap();
    let want: Vec<u32> = reference.rgba.iter().map(|v| v.to_bits()).collect();
    for how in [
        Decomposition::Dynamic,
        Decomposition::PixelCyclic,
        Decomposition::ScanlineCyclic,
        Decomposition::BlockCyclic,
    ] {
        b.scene.settings.decomposition = how;
        for threads in [1, 2] {
            let (rgba, _) = render_f32(&b.scene, threads, false);
            assert!(bits(&rgba) == want, "{how:?} on {threads} threads differs");
        }
    }
}

/// Every plane at a stride of 53 for a 48-wide image: the 5 pixels past each row keep their
/// sentinel, the image is the tight one.
#[test]
fn row_strides_leave_the_padding_untouched() {
    let b = build(&spheres_desc(48, 32));
    let (tight, tight_z) = render_f32(&b.scene, 2, true);
    let (w, h, stride) = (48usize, 32usize, 53usize);
    let len = (h - 1) * stride + w;
    let mut rgba8 = vec![[7u8; 4]; len];
    let mut rgba = vec![[-7.0f32; 4]; len];
    let mut z = vec![-7.0f32; len];
    let pool = thread_pool(2).unwrap();
    let never = AtomicBool::new(false);
    let t8 = Target {
        width: 48,
        height: 32,
        color: Color::Rgba8Srgb(Plane::new(&mut rgba8, stride)),
        depth: Some(Plane::new(&mut z, stride)),
    };
    render_into(&b.scene, &pool, t8, &never, &no_progress).unwrap();
    let t32 = Target {
        width: 48,
        height: 32,
        color: Color::Rgba32fLinear(Plane::new(&mut rgba, stride)),
        depth: None,
    };
    render_into(&b.scene, &pool, t32, &never, &no_progress).unwrap();
    for y in 0..h {
        for x in 0..stride {
            let i = y * stride + x;
            if x >= w {
                if i < len {
                    assert_eq!(rgba8[i], [7; 4], "padding ({x}, {y})");
                    assert_eq!(rgba[i], [-7.0; 4], "padding ({x}, {y})");
                    assert_eq!(z[i], -7.0, "padding ({x}, {y})");
                }
                continue;
            }
            let want = tight[y * w + x];
            assert_eq!(bits(&[rgba[i]]), bits(&[want]), "({x}, {y})");
            assert_eq!(rgba8[i], luxon::framebuffer::rgba8(want), "({x}, {y})");
            assert_eq!(z[i].to_bits(), tight_z[y * w + x].to_bits(), "({x}, {y})");
        }
    }
}

#[test]
fn planes_that_cannot_hold_the_image_are_refused_with_their_sizes() {
    let b = build(&spheres_desc(48, 32));
    let pool = thread_pool(1).unwrap();
    let never = AtomicBool::new(false);
    let refused = |target: Target| match render_into(&b.scene, &pool, target, &never, &no_progress)
    {
        Err(Error::Target(m)) => m,
        other => panic!("expected a target error, got {:?}", other.map(|_| ())),
    };
    // One element short of (32 − 1) · 53 + 48 = 1691.
    let mut short = vec![[0u8; 4]; 1690];
    let m = refused(Target {
        width: 48,
        height: 32,
        color: Color::Rgba8Srgb(Plane::new(&mut short, 53)),
        depth: None,
    });
    assert_eq!(
        m,
        "the RGBA8 plane holds 1690 pixels; a 48x32 image with a row stride of 53 needs 1691"
    );
    assert!(
        short.iter().all(|p| *p == [0; 4]),
        "a refused plane was written"
    );
    let mut rgba = vec![[0.0f32; 4]; 48 * 32];
    let mut z = vec![0.0f32; 48 * 32 - 1];
    let m = refused(Target {
        width: 48,
        height: 32,
        color: Color::Rgba32fLinear(Plane::new(&mut rgba, 48)),
        depth: Some(Plane::new(&mut z, 48)),
    });
    assert_eq!(
        m,
        "the depth plane holds 1535 pixels; a 48x32 image with a row stride of 48 needs 1536"
    );
    let m = refused(Target {
        width: 48,
        height: 32,
        color: Color::Rgba32fLinear(Plane::new(&mut rgba, 47)),
        depth: None,
    });
    assert_eq!(
        m,
        "the RGBA f32 plane's row stride is 47 pixels, less than the image width 48"
    );
    let m = refused(Target {
        width: 32,
        height: 48,
        color: Color::Rgba32fLinear(Plane::new(&mut rgba, 32)),
        depth: None,
    });
    assert_eq!(m, "the target is 32x48 pixels but the scene renders 48x32");
    let mut huge = vec![0.0f32; 4];
    let m = Target {
        width: 2,
        height: u32::MAX,
        color: Color::None,
        depth: Some(Plane::new(&mut huge, usize::MAX / 2)),
    }
    .check()
    .unwrap_err();
    assert!(m.contains("larger than memory"), "{m}");
}

/// A unit sphere 5 in front of the camera, seen by `projection`, 33×33, 4 samples.
fn sphere_scene(projection: &str) -> SceneDesc {
    text_desc(
        "target-depth",
        &format!(
            r#"Scene(
    camera: (position: (0, 0, 0), look_at: (0, 0, 1), {projection}),
    lights: [Point(position: (0, 3, -3), intensity: 1.0)],
    objects: [(plugin: "sphere", params: (center: (0, 0, 5), radius: 1))],
    render: (width: 33, height: 33, samples: 4),
)"#
        ),
    )
}

/// The nearest hit on the unit sphere at (0, 0, 5) of the centre pixel's camera rays (the
/// sample positions the colour uses), intersected here in f64.
fn centre_depth(scene: &Scene) -> f64 {
    let s = &scene.settings;
    let (cx, cy) = (s.width / 2, s.height / 2);
    (0..s.samples)
        .filter_map(|i| {
            let (jx, jy) = luxon::sampler::pixel_sample(cx, cy, i, s.samples, s.frame);
            let ray =
                scene
                    .camera
                    .primary(cx as f32 + jx, cy as f32 + jy, s.width, s.height, s.time)?;
            let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
            let oc = o - glam::DVec3::new(0.0, 0.0, 5.0);
            let (b, c) = (oc.dot(d), oc.length_squared() - 1.0);
            let disc = b * b - c;
            (disc >= 0.0).then(|| -b - disc.sqrt())
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn depth_is_the_distance_to_the_nearest_surface() {
    let b = build(&sphere_scene("fov: 20"));
    let (rgba_with, z) = render_f32(&b.scene, 2, true);
    let centre = z[16 * 33 + 16] as f64;
    let want = centre_depth(&b.scene);
    // 4 on the axis; the samples lie within half a pixel of it (10 θ² further at angle θ).
    assert!((want - 4.0).abs() < 1e-3, "{want}");
    assert!(
        (centre - want).abs() <= 1e-5,
        "centre {centre}, expected {want}"
    );
    for corner in [0, 32, 32 * 33, 33 * 33 - 1] {
        assert_eq!(z[corner], f32::INFINITY, "corner {corner}");
    }
    // Depth changes nothing in the colour.
    let (rgba_without, _) = render_f32(&b.scene, 2, false);
    assert!(bits(&rgba_with) == bits(&rgba_without));
    let (reference, _) = render(&b.scene, &no_progress).unwrap();
    let want: Vec<u32> = reference.rgba.iter().map(|v| v.to_bits()).collect();
    assert!(bits(&rgba_with) == want);
}

/// Orthographic rays start on the image plane: a plane 5 in front gives 5 everywhere.
#[test]
fn orthographic_depth_is_the_distance_from_the_image_plane() {
    let desc = text_desc(
        "target-ortho",
        r#"Scene(
    camera: (position: (0.3, -0.2, 0), look_at: (0.3, -0.2, 1), projection: Orthographic(height: 3)),
    lights: [Point(position: (0, 3, -3), intensity: 1.0)],
    objects: [(plugin: "plane", params: (point: (0, 0, 5), normal: (0, 0, -1)))],
    render: (width: 20, height: 16, samples: 4),
)"#,
    );
    let b = build(&desc);
    let (_, z) = render_f32(&b.scene, 2, true);
    for (i, d) in z.iter().enumerate() {
        assert!((d - 5.0).abs() <= 1e-5, "pixel {i}: {d}");
    }
    // Looking away from the plane: nothing is hit anywhere.
    let mut away = desc.clone();
    away.camera.value.look_at = [0.3, -0.2, -1.0];
    let b = build(&away);
    let (_, z) = render_f32(&b.scene, 1, true);
    assert!(z.iter().all(|d| *d == f32::INFINITY));
}

/// Cancelled from another thread once the first tiles are in: the render returns
/// `Error::Cancelled` within a second with pixels left out; the next render on the same pool is
/// whole and equal to a fresh one.
#[test]
fn a_render_cancelled_from_another_thread_stops_and_the_pool_renders_again() {
    // Long enough that the canceller, woken by the first tile, gets a core before the end even
    // on a busy machine; short enough for a debug build.
    let (w, h) = (320, 240);
    let mut desc = spheres_desc(w, h);
    desc.render.samples = 8;
    desc.render.parallel.tile_size = 8;
    let b = build(&desc);
    let total = (w * h) as usize;
    let pool = thread_pool(2).unwrap();
    let cancel = AtomicBool::new(false);
    let done = AtomicU64::new(0);
    let progress = |n: u64, _: u64| {
        done.fetch_max(n, Ordering::SeqCst);
    };
    let mut rgba = vec![[0.0f32; 4]; total];
    let (result, waited) = std::thread::scope(|s| {
        let canceller = s.spawn(|| {
            while done.load(Ordering::SeqCst) == 0 {
                std::thread::yield_now();
            }
            cancel.store(true, Ordering::SeqCst);
            Instant::now()
        });
        let target = Target {
            width: w,
            height: h,
            color: Color::Rgba32fLinear(Plane::new(&mut rgba, w as usize)),
            depth: None,
        };
        let result = render_into(&b.scene, &pool, target, &cancel, &progress);
        let returned = Instant::now();
        (result, returned - canceller.join().unwrap())
    });
    assert!(
        matches!(result, Err(Error::Cancelled)),
        "{:?}",
        result.map(|_| ())
    );
    assert!(
        waited < Duration::from_secs(1),
        "stopped {waited:?} after the cancel"
    );
    let rendered = done.load(Ordering::SeqCst);
    assert!(
        rendered < total as u64,
        "the cancel came too late to cut the render short: {rendered} of {total} pixels"
    );

    let (again, _) = render_f32(&b.scene, 2, false);
    let cancel = AtomicBool::new(false);
    let mut rgba = vec![[0.0f32; 4]; total];
    let target = Target {
        width: w,
        height: h,
        color: Color::Rgba32fLinear(Plane::new(&mut rgba, w as usize)),
        depth: None,
    };
    let stats = render_into(&b.scene, &pool, target, &cancel, &no_progress).unwrap();
    assert_eq!(stats.ranks[0].total().pixels, total as u64);
    assert!(bits(&rgba) == bits(&again));
    let (reference, _) = render(&b.scene, &no_progress).unwrap();
    let want: Vec<u32> = reference.rgba.iter().map(|v| v.to_bits()).collect();
    assert!(bits(&rgba) == want);
}

/// A unit that panics (here the caller's sink) ends the render with an error; the caller's
/// thread and the pool live on.
#[test]
fn a_panicking_unit_is_an_error_not_a_crash() {
    let b = build(&spheres_desc(16, 16));
    let pool = thread_pool(2).unwrap();
    let sink = |_: luxon::framebuffer::Chunk| panic!("deliberate panic in a sink");
    let r = luxon::schedule::render_local(
        &b.scene,
        &pool,
        luxon::schedule::RunOptions::default(),
        &sink,
    );
    match r {
        Err(Error::Plugin(m)) => {
            assert!(m.starts_with("internal error"), "{m}");
            assert!(m.contains("deliberate panic in a sink"), "{m}");
        }
        other => panic!("expected an error, got {:?}", other.map(|_| ())),
    }
    assert_eq!(pool.install(|| 6 * 7), 42);
}
