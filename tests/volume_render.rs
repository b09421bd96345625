//! Volume ray casting against analytic answers: transmittance exp(-σL) through a constant box
//! (nearest and trilinear), step-size convergence, early termination, empty-space skipping
//! (bitwise the same image), a surface inside a volume and its shadow, overlapping volumes,
//! a clip plane halving a volume, no NaN with everything on.

mod common;
use common::*;

use luxon::geometry::Counters;
use luxon::{Framebuffer, Scene};
use std::path::Path;

/// Builds and renders scene text written into `dir`; the image and the counters.
fn render(dir: &Path, ron: &str) -> (Framebuffer, Counters) {
    let path = dir.join("scene.ron");
    std::fs::write(&path, ron).unwrap();
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let reg = registry(&desc);
    let scene = Scene::build(&desc, &reg).unwrap_or_else(|e| panic!("{e}"));
    let (fb, stats) = luxon::render::render(&scene, &|_, _| {}).unwrap_or_else(|e| panic!("{e}"));
    (fb, stats.counters)
}

/// Writes an n³ f32 grid with `f(i, j, k)` as `name`.
fn grid(dir: &Path, name: &str, n: usize, f: impl Fn(usize, usize, usize) -> f32) {
    let mut bytes = Vec::with_capacity(n * n * n * 4);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                bytes.extend(f(i, j, k).to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join(name), bytes).unwrap();
}

/// An orthographic camera looking down -z at the unit square around the z axis, a white
/// background, 8x8 pixels, no cut-off; `body` adds volumes, objects...
fn scene(body: &str) -> String {
    format!(
        "(
    camera: (position: (0, 0, 10), look_at: (0, 0, 0), up: (0, 1, 0), projection: Orthographic(height: 1)),
    background: (1, 1, 1),
{body}
)"
    )
}

fn render_settings(extra: &str) -> String {
    format!("    render: (width: 8, height: 8, min_weight: 0, {extra}),")
}

/// A 16³ volume of value 1 with voxels 0.1 apart centred on the origin: a box 1.6 wide
/// (voxel centres ±0.75, plus half a voxel) of constant extinction `sigma` and colour black.
fn constant_box(file: &str, sigma: f64, extra: &str) -> String {
    format!(
        "        (plugin: \"raw\", params: (file: \"{file}\", dims: (16, 16, 16), format: \"f32\", spacing: (0.1, 0.1, 0.1), origin: (-0.75, -0.75, -0.75)),
         render: (transfer: (points: [(x: 0, color: (0, 0, 0), opacity: {sigma})]){extra})),"
    )
}

fn pixels(fb: &Framebuffer) -> impl Iterator<Item = [f32; 3]> + '_ {
    fb.rgba.chunks_exact(4).map(|p| [p[0], p[1], p[2]])
}

#[test]
fn constant_box_transmittance_is_exp_minus_sigma_l() {
    let dir = temp_dir("vr-constant");
    grid(&dir, "one.raw", 16, |_, _, _| 1.0);
    let (sigma, length) = (1.5f64, 1.6f64);
    let want = (-sigma * length).exp() as f32;
    for interp in ["Nearest", "Trilinear"] {
        for step in ["0.05", "0.13", "0.7"] {
            let text = scene(&format!(
                "    volumes: [\n{}\n    ],\n{}",
                constant_box(
                    "one.raw",
                    sigma,
                    &format!(", interpolation: {interp}, step: {step}")
                ),
                render_settings("")
            ));
            let (fb, c) = render(&dir, &text);
            assert!(c.volume_samples > 0);
            for p in pixels(&fb) {
                for v in p {
                    // A constant field is integrated exactly whatever the step.
                    assert!(
                        (v - want).abs() < 2e-5,
                        "{interp}, step {step}: {v} instead of exp(-σL) = {want}"
                    );
                }
            }
        }
    }
}

#[test]
fn step_size_converges_to_the_exact_optical_depth() {
    let dir = temp_dir("vr-converge");
    // Values rise linearly along z from 0 (k = 0) to 1 (k = 15); the extinction has two
    // narrow peaks (triangles of area 0.6 each in x), which coarse steps miss or overcount.
    grid(&dir, "ramp.raw", 16, |_, _, k| k as f32 / 15.0);
    let p = |x: f64, o: f64| format!("(x: {x}, color: (0, 0, 0), opacity: {o})");
    let points = format!(
        "[{}, {}, {}, {}, {}, {}, {}]",
        p(0.0, 0.0),
        p(0.1, 0.0),
        p(0.2, 6.0),
        p(0.3, 0.0),
        p(0.5, 0.0),
        p(0.6, 6.0),
        p(0.7, 0.0)
    );
    // Along z: 1.5 units between the first and last voxel centres, where x runs linearly from 0
    // to 1 (integral of the function over x: 1.2); the half voxels at the ends add nothing.
    let tau: f64 = 1.2 * 1.5;
    let want = (-tau).exp() as f32;
    let mut errors = Vec::new();
    for step in [0.4, 0.2, 0.1, 0.05, 0.0125] {
        let text = scene(&format!(
            "    volumes: [(plugin: \"raw\", params: (file: \"ramp.raw\", dims: (16, 16, 16), format: \"f32\", spacing: (0.1, 0.1, 0.1), origin: (-0.75, -0.75, -0.75)),
         render: (transfer: (points: {points}, range: (0, 1)), step: {step}))],\n{}",
            render_settings("")
        ));
        let (fb, _) = render(&dir, &text);
        let v = fb.rgba[4 * 27];
        errors.push((v - want).abs());
    }
    assert!(
        errors[0] > 1e-3,
        "the coarsest step must show an error: {errors:?}"
    );
    // The midpoint rule is exact between kinks, so the error need not shrink at every halving,
    // but it shrinks overall and ends small.
    assert!(
        errors[2..].iter().all(|&e| e < errors[0]) && errors[4] < errors[0] / 10.0,
        "errors must shrink with the step: {errors:?}"
    );
    assert!(errors[4] < 2e-4, "finest step: {errors:?} (want {want})");
}

#[test]
fn early_termination_stops_in_an_opaque_volume() {
    let dir = temp_dir("vr-early");
    grid(&dir, "one.raw", 16, |_, _, _| 1.0);
    let body = |min_weight: &str| {
        scene(&format!(
            "    volumes: [\n{}\n    ],\n    render: (width: 8, height: 8, min_weight: {min_weight}),",
            constant_box("one.raw", 40.0, ", step: 0.01")
        ))
    };
    let (full, all) = render(&dir, &body("0"));
    let (cut, early) = render(&dir, &body("0.002"));
    // 160 samples per ray without a cut-off; with it, until T < 0.002: ln(500) / (40 * 0.01)
    // ≈ 16 samples.
    // (1.6 / 0.01 rounds up to 161 segments in f32.)
    assert!(
        (64 * 160..=64 * 161).contains(&all.volume_samples),
        "{}",
        all.volume_samples
    );
    assert!(
        early.volume_samples <= 64 * 17,
        "early termination took {} samples",
        early.volume_samples
    );
    for (a, b) in pixels(&full).zip(pixels(&cut)) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() <= 0.002, "{a:?} vs {b:?}");
        }
    }
}

/// Renders a shipped scene small with empty-space skipping on or off.
fn shipped(name: &str, skip: bool) -> (Framebuffer, Counters) {
    let path = root().join("scenes").join(format!("{name}.ron"));
    let mut desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    desc.render.width = 64;
    desc.render.height = 64;
    desc.render.volume_skip = skip;
    let reg = registry(&desc);
    let scene = Scene::build(&desc, &reg).unwrap_or_else(|e| panic!("{e}"));
    let (fb, stats) = luxon::render::render(&scene, &|_, _| {}).unwrap_or_else(|e| panic!("{e}"));
    (fb, stats.counters)
}

#[test]
fn empty_space_skipping_gives_the_same_image_bitwise() {
    for name in ["vortex", "phantom", "volume-geometry"] {
        let (with, c_with) = shipped(name, true);
        let (without, c_without) = shipped(name, false);
        assert!(
            with.rgba.iter().any(|&v| v > 0.05),
            "{name}: image is black"
        );
        assert!(
            with.rgba
                .iter()
                .zip(&without.rgba)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{name}: skipping changed the image"
        );
        // The phantom inside the geometry scene fills its grid: nothing to skip there.
        assert!(
            name == "volume-geometry" || c_with.volume_samples < c_without.volume_samples,
            "{name}: skipping took {} samples, not skipping {}",
            c_with.volume_samples,
            c_without.volume_samples
        );
    }
}

#[test]
fn a_surface_inside_a_volume_and_its_shadow_are_attenuated() {
    let dir = temp_dir("vr-surface");
    grid(&dir, "one.raw", 16, |_, _, _| 1.0);
    let sigma = 0.8f64;
    // An unlit white plane (ambient 1) at z = 0.2 inside the box: the camera sees it through
    // 0.8 - 0.2 = 0.6 units of the volume.
    let text = scene(&format!(
        "    materials: {{ \"white\": (color: (1, 1, 1), ambient: 1, diffuse: 0) }},
    objects: [(plugin: \"plane\", params: (point: (0, 0, 0.2), normal: (0, 0, 1)), material: \"white\")],
    volumes: [\n{}\n    ],\n{}",
        constant_box("one.raw", sigma, ", step: 0.05"),
        render_settings("")
    ));
    let (fb, _) = render(&dir, &text);
    let want = (-sigma * 0.6).exp() as f32;
    for p in pixels(&fb) {
        assert!((p[0] - want).abs() < 1e-5, "{} vs {want}", p[0]);
    }
    // A diffuse plane at z = 0.2 lit from straight above: the light crosses the same 0.6 units
    // on its way down, the view on its way up: exp(-2σ·0.6).
    let text = scene(&format!(
        "    lights: [Directional(direction: (0, 0, -1))],
    materials: {{ \"white\": (color: (1, 1, 1), ambient: 0, diffuse: 1) }},
    objects: [(plugin: \"plane\", params: (point: (0, 0, 0.2), normal: (0, 0, 1)), material: \"white\")],
    volumes: [\n{}\n    ],\n{}",
        constant_box("one.raw", sigma, ", step: 0.05"),
        render_settings("")
    ));
    let (fb, c) = render(&dir, &text);
    assert!(c.shadow > 0);
    let want = (-2.0 * sigma * 0.6).exp() as f32;
    for p in pixels(&fb) {
        assert!((p[0] - want).abs() < 1e-4, "{} vs {want}", p[0]);
    }
}

#[test]
fn overlapping_volumes_add_their_extinctions() {
    let dir = temp_dir("vr-overlap");
    grid(&dir, "one.raw", 16, |_, _, _| 1.0);
    // The second box is the first moved 0.8 down: they overlap over z in [-0.05, 0.8 - 0.8]...
    // along the ray: box 1 covers z in [-0.8, 0.8], box 2 [-1.6, 0]; both over [-0.8, 0].
    let second = "        (plugin: \"raw\", params: (file: \"one.raw\", dims: (16, 16, 16), format: \"f32\", spacing: (0.1, 0.1, 0.1), origin: (-0.75, -0.75, -1.55)),
         render: (transfer: (points: [(x: 0, color: (0, 0, 0), opacity: 0.5)]), step: 0.01)),";
    let text = scene(&format!(
        "    volumes: [\n{}\n{second}\n    ],\n{}",
        constant_box("one.raw", 1.0, ", step: 0.01"),
        render_settings("")
    ));
    let (fb, _) = render(&dir, &text);
    let want = (-(1.0 * 1.6 + 0.5 * 1.6f64)).exp() as f32;
    for p in pixels(&fb) {
        assert!((p[0] - want).abs() < 1e-4, "{} vs {want}", p[0]);
    }
}

#[test]
fn a_clip_plane_halves_a_volume_and_a_crop_box_bounds_it() {
    let dir = temp_dir("vr-clip");
    grid(&dir, "one.raw", 16, |_, _, _| 1.0);
    let sigma = 1.0f64;
    // Cut away z > 0: half the box remains.
    let text = scene(&format!(
        "    clip_groups: {{ \"top\": [(point: (0, 0, 0), normal: (0, 0, 1))] }},
    volumes: [\n{}\n    ],\n{}",
        constant_box("one.raw", sigma, ", step: 0.05, clip: \"top\""),
        render_settings("")
    ));
    let (fb, _) = render(&dir, &text);
    let want = (-sigma * 0.8).exp() as f32;
    for p in pixels(&fb) {
        assert!((p[0] - want).abs() < 1e-5, "clip: {} vs {want}", p[0]);
    }
    // A crop box 0.3 deep.
    let text = scene(&format!(
        "    volumes: [\n{}\n    ],\n{}",
        constant_box(
            "one.raw",
            sigma,
            ", step: 0.05, bounds: (min: (-5, -5, -0.1), max: (5, 5, 0.2))"
        ),
        render_settings("")
    ));
    let (fb, _) = render(&dir, &text);
    let want = (-sigma * 0.3).exp() as f32;
    for p in pixels(&fb) {
        assert!((p[0] - want).abs() < 1e-5, "crop: {} vs {want}", p[0]);
    }
}

#[test]
fn a_volume_without_render_settings_is_not_drawn() {
    let dir = temp_dir("vr-data-only");
    grid(&dir, "one.raw", 16, |_, _, _| 1.0);
    let text = scene(&format!(
        "    volumes: [(plugin: \"raw\", params: (file: \"one.raw\", dims: (16, 16, 16), format: \"f32\"))],\n{}",
        render_settings("")
    ));
    let path = dir.join("scene.ron");
    std::fs::write(&path, &text).unwrap();
    let desc = luxon_formats::load(&path).unwrap();
    let scene = Scene::build(&desc, &registry(&desc)).unwrap();
    assert!(!scene.features.volumes);
    assert_eq!(scene.volumes.len(), 1);
    let (fb, c) = render(&dir, &text);
    assert_eq!(c.volume_samples, 0);
    assert!(fb.rgba.chunks_exact(4).all(|p| p[..3] == [1.0, 1.0, 1.0]));
}

#[test]
fn shaded_volume_with_shadows_and_geometry_has_no_nan() {
    let dir = temp_dir("vr-nan");
    // A sharp sphere of density 1 (gradients from nothing to everything), the camera inside
    // the grid, shadows through volume and geometry, a light inside the volume.
    grid(&dir, "ball.raw", 16, |i, j, k| {
        let d = [i, j, k].map(|c| c as f32 - 7.5);
        f32::from(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < 25.0)
    });
    let text = "(
    camera: (position: (0.7, 0.1, 0.5), look_at: (0, 0, 0), up: (0, 0, 1), fov: 90),
    background: (0.2, 0.3, 0.4),
    lights: [Point(position: (0, 0, 0.1)), Directional(direction: (0, 0, -1)), SphereLight(center: (3, 3, 3), radius: 0.5, samples: 2)],
    objects: [(plugin: \"sphere\", params: (center: (0, 0, 0), radius: 0.2))],
    volumes: [(plugin: \"raw\", params: (file: \"ball.raw\", dims: (16, 16, 16), format: \"f32\", spacing: (0.1, 0.1, 0.1), origin: (-0.75, -0.75, -0.75)),
               render: (transfer: (preset: \"cool-warm\", opacity: 5), shading: (shadows: true)))],
    render: (width: 24, height: 24),
)";
    let (fb, c) = render(&dir, text);
    assert_eq!(c.nan_pixels, 0);
    assert!(fb.rgba.iter().all(|v| v.is_finite()));
    assert!(c.volume_samples > 0 && c.shadow > 0);
}
