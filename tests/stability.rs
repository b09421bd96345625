//! Hard cases stay numerically stable: every test renders (or intersects) a case that breaks
//! naive ray tracers and checks both that no pixel is NaN or infinite and that the result is the
//! right one (compared with a reference rendering, a value worked out by hand, or a count).

mod common;
#[path = "common/leaks.rs"]
mod leaks;

use common::*;
use glam::DVec3;
use luxon::math::Vec3A;
use luxon::{Framebuffer, Scene};
use std::time::Instant;

/// Renders RON text through the library; also returns the render's counters.
fn render_counted(name: &str, ron: &str) -> (Framebuffer, luxon::geometry::Counters) {
    let dir = temp_dir(name);
    let path = dir.join("scene.ron");
    std::fs::write(&path, ron).unwrap();
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let scene = Scene::build(&desc, &registry(&desc)).unwrap_or_else(|e| panic!("{e}"));
    let (fb, stats) = luxon::render::render(&scene, &|_, _| {}).unwrap_or_else(|e| panic!("{e}"));
    (fb, stats.counters)
}

fn render(name: &str, ron: &str) -> Framebuffer {
    let (fb, c) = render_counted(name, ron);
    assert_eq!(c.nan_pixels, 0, "{name}: NaN pixels");
    assert!(
        fb.rgba.iter().all(|v| v.is_finite()),
        "{name}: a non-finite pixel"
    );
    fb
}

fn rgb(fb: &Framebuffer, x: u32, y: u32) -> [f32; 3] {
    let p = fb.pixel(x, y);
    [p[0], p[1], p[2]]
}

// ------------------------------------------------------------------------------------------------
// Scale and distance from the origin
// ------------------------------------------------------------------------------------------------

/// A small studio, every position mapped by `p -> p * s + o` and every length by `* s`:
/// a floor mesh and a back wall plane, a diffuse, a mirror and a glass sphere, a cone, a
/// ring, a shadow-casting point light.
fn studio(s: f64, o: [f64; 3]) -> String {
    let p =
        |x: f64, y: f64, z: f64| format!("({}, {}, {})", x * s + o[0], y * s + o[1], z * s + o[2]);
    let l = |v: f64| format!("{}", v * s);
    format!(
        r#"Scene(
    camera: (position: {cam}, look_at: {at}, fov: 40),
    background: (0.3, 0.4, 0.6),
    lights: [Point(position: {light}, intensity: 0.9)],
    materials: {{
        "floor": (color: (0.8, 0.8, 0.7), ambient: 0.1, diffuse: 0.9),
        "red": (color: (0.8, 0.2, 0.1), ambient: 0.1, diffuse: 0.8, specular: 0.4, shininess: 30),
        "mirror": (color: (0.9, 0.9, 0.9), ambient: 0.05, diffuse: 0.1, reflect: 0.8),
        "glass": (color: (1, 1, 1), ambient: 0, diffuse: 0, reflect: 0.05, transmit: 0.95, ior: 1.5),
    }},
    objects: [
        (plugin: "mesh", params: (positions: [{f0}, {f1}, {f2}, {f3}], indices: [(0, 1, 2), (0, 2, 3)]), material: "floor"),
        (plugin: "plane", params: (point: {wall}, normal: (0, 0, -1)), material: "floor"),
        (plugin: "sphere", params: (center: {s1}, radius: {r1}), material: "red"),
        (plugin: "sphere", params: (center: {s2}, radius: {r1}), material: "mirror"),
        (plugin: "sphere", params: (center: {s3}, radius: {r3}), material: "glass"),
        (plugin: "cone", params: (base: {c0}, apex: {c1}, base_radius: {cr}, apex_radius: 0), material: "red"),
    ],
    render: (width: 96, height: 64, samples: 1, max_depth: 6),
)"#,
        cam = p(0.0, 2.0, -7.0),
        at = p(0.0, 0.7, 0.0),
        light = p(-4.0, 6.0, -5.0),
        f0 = p(-6.0, 0.0, -6.0),
        f1 = p(-6.0, 0.0, 6.0),
        f2 = p(6.0, 0.0, 6.0),
        f3 = p(6.0, 0.0, -6.0),
        wall = p(0.0, 0.0, 5.0),
        s1 = p(-1.6, 1.0, 0.5),
        s2 = p(1.4, 1.0, 1.0),
        s3 = p(0.0, 0.6, -1.8),
        r1 = l(1.0),
        r3 = l(0.6),
        c0 = p(2.6, 0.0, -1.5),
        c1 = p(2.6, 1.5, -1.5),
        cr = l(0.5),
    )
}

/// Fraction of pixels whose 8-bit sRGB values differ by more than `tolerance` on any channel.
fn differing(a: &Framebuffer, b: &Framebuffer, tolerance: u8) -> f64 {
    let (a, b) = (to_srgb8(a), to_srgb8(b));
    let n = a
        .chunks_exact(3)
        .zip(b.chunks_exact(3))
        .filter(|(p, q)| p.iter().zip(*q).any(|(x, y)| x.abs_diff(*y) > tolerance))
        .count();
    n as f64 / (a.len() / 3) as f64
}

#[test]
fn tiny_and_far_scene_matches_the_unit_scene() {
    let unit = render("scale-unit", &studio(1.0, [0.0; 3]));
    // The picture is not trivial: lit floor, shadows, the spheres.
    let (mean, _) = diff(&to_srgb8(&unit), &vec![0; 96 * 64 * 3]);
    assert!(mean > 40.0, "the unit scene is too dark: {mean}");
    for (name, s, o) in [
        ("scale-tiny", 1e-4, [0.0; 3]),
        ("scale-far", 1.0, [1e6, -1e6, 1e6]),
        ("scale-tiny-far", 1e-4, [1e6, 1e6, -1e6]),
    ] {
        let fb = render(name, &studio(s, o));
        let (mean, max) = diff(&to_srgb8(&unit), &to_srgb8(&fb));
        let off = differing(&unit, &fb, 8);
        // Acne or speckle would darken scattered pixels by far more than 8/255; what remains
        // are a few silhouette pixels whose camera rays round differently.
        assert!(
            mean < 0.5 && off < 0.005,
            "{name}: mean |diff| {mean:.3}/255, max {max}, {:.2}% of pixels off by > 8/255",
            off * 100.0
        );
    }
}

// ------------------------------------------------------------------------------------------------
// Huge spheres
// ------------------------------------------------------------------------------------------------

#[test]
fn earth_sized_ground_seen_from_one_unit_above() {
    // Ground: a sphere of radius 6.4e6 whose top is at y = 0; the camera 1 unit above, level.
    // Light at 45° toward the camera: the ground's lit value is ambient + diffuse · cos 45° (the
    // surface curves by 1e-6 rad over the visible distance), and the ball's shadow falls toward
    // the camera where it can be seen.
    let scene = r#"Scene(
        camera: (position: (0, 1, 0), look_at: (0, 1, 10), fov: 60),
        background: (0, 0, 1),
        lights: [Directional(direction: (0, -1, -1), intensity: 1.0)],
        materials: {
            "ground": (color: (0.5, 0.8, 0.3), ambient: 0.2, diffuse: 0.8),
            "ball": (color: (1, 1, 1), ambient: 0.2, diffuse: 0.8),
        },
        objects: [
            (plugin: "sphere", params: (center: (0, -6.4e6, 0), radius: 6.4e6), material: "ground"),
            (plugin: "sphere", params: (center: (0, 0.5, 6), radius: 0.5), material: "ball"),
        ],
        render: (width: 64, height: 64),
    )"#;
    let fb = render("earth", scene);
    let lit = 0.2 + 0.8 * std::f32::consts::FRAC_1_SQRT_2;
    let ground = [0.5 * lit, 0.8 * lit, 0.3 * lit];
    let mut shadowed = 0;
    for y in 0..64 {
        for x in 0..64 {
            let c = rgb(&fb, x, y);
            if y < 31 {
                // Above the horizon (it dips by 3e-2 degrees: less than a pixel).
                if !(x > 24 && x < 40) {
                    assert_eq!(c, [0.0, 0.0, 1.0], "sky at ({x}, {y}): {c:?}");
                }
            } else if y > 33 && !(x > 20 && x < 44) {
                // Open ground, away from the ball and its shadow: exactly lit, no acne.
                for k in 0..3 {
                    assert!(
                        (c[k] - ground[k]).abs() < 1e-3,
                        "ground at ({x}, {y}): {c:?}"
                    );
                }
            } else if y > 33 && (c[1] - 0.2 * 0.8).abs() < 1e-3 {
                shadowed += 1;
            }
        }
    }
    // The ball's shadow directly below it is visible (ambient only).
    assert!(shadowed > 0, "no shadow under the ball");
}

// ------------------------------------------------------------------------------------------------
// Depth limit: parallel mirrors, total internal reflection
// ------------------------------------------------------------------------------------------------

/// A slab of glass between two parallel planes with the camera inside it looking along the slab
/// at a grazing angle: every reflection is total, the ray is trapped until the depth limit.
fn trapped(depth: u32) -> String {
    format!(
        r#"Scene(
        camera: (position: (0, 0, 0), look_at: (0, 0.1, 1), fov: 5),
        background: (1, 1, 1),
        materials: {{ "glass": (color: (1, 1, 1), ambient: 0, diffuse: 0, transmit: 1, ior: 1.5) }},
        objects: [
            (plugin: "plane", params: (point: (0, 1, 0), normal: (0, 1, 0)), material: "glass"),
            (plugin: "plane", params: (point: (0, -1, 0), normal: (0, -1, 0)), material: "glass"),
        ],
        render: (width: 8, height: 8, max_depth: {depth}, min_weight: 0),
    )"#
    )
}

#[test]
fn total_internal_reflection_ends_at_the_depth_limit() {
    for depth in [10u32, 40] {
        let start = Instant::now();
        let (fb, c) = render_counted(&format!("tir-{depth}"), &trapped(depth));
        let secs = start.elapsed().as_secs_f64();
        assert_eq!(c.nan_pixels, 0);
        // Every one of the 64 camera rays bounces exactly `depth` times (total reflection,
        // counted as refraction rays) and then sees the background... which it never reaches
        // inside the slab: the depth limit returns the background colour, times a weight of 1.
        assert_eq!(c.primary, 64);
        assert_eq!(
            c.refraction + c.reflection,
            64 * depth as u64,
            "depth {depth}"
        );
        for v in fb.rgba.chunks_exact(4) {
            assert!(v[..3].iter().all(|&x| (x - 1.0).abs() < 1e-5), "{v:?}");
        }
        assert!(secs < 60.0, "depth {depth} took {secs} s");
    }
}

#[test]
fn parallel_mirrors_end_at_the_depth_limit_in_bounded_time() {
    let scene = |depth: u32| {
        format!(
            r#"Scene(
            camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 20),
            materials: {{ "mirror": (color: (1, 1, 1), ambient: 0.1, diffuse: 0, reflect: 0.9) }},
            objects: [
                (plugin: "plane", params: (point: (0, 0, 5), normal: (0, 0, -1)), material: "mirror"),
                (plugin: "plane", params: (point: (0, 0, -5), normal: (0, 0, 1)), material: "mirror"),
            ],
            render: (width: 8, height: 8, max_depth: {depth}, min_weight: 0),
        )"#
        )
    };
    // 1024 is the largest max_depth a scene may ask for: the recursion must fit the stack.
    for depth in [20u32, 1024] {
        let (fb, c) = render_counted(&format!("mirrors-{depth}"), &scene(depth));
        assert_eq!(c.nan_pixels, 0);
        assert_eq!(c.reflection, 64 * depth as u64);
        // Each bounce adds ambient 0.1 and passes on 0.9 of the rest; the background is black.
        let expect: f32 = (0..=depth).map(|k| 0.1 * 0.9f32.powi(k as i32)).sum();
        for v in fb.rgba.chunks_exact(4) {
            assert!(
                (v[0] - expect).abs() < 1e-4,
                "depth {depth}: {v:?} vs {expect}"
            );
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Dielectrics, coincident surfaces, the camera inside an object
// ------------------------------------------------------------------------------------------------

/// A water ball with a glass ball inside (ior `glass`), clear and without reflections, in front
/// of a checker of coloured spheres.
fn nested(glass: Option<f64>) -> String {
    let (object, material) = match glass {
        Some(ior) => (
            r#"(plugin: "sphere", params: (center: (0, 0, 0), radius: 0.6), material: "glass"),"#
                .to_string(),
            format!(
                r#""glass": (color: (1, 1, 1), ambient: 0, diffuse: 0, transmit: 1, ior: {ior}),"#
            ),
        ),
        None => (String::new(), String::new()),
    };
    format!(
        r#"Scene(
        camera: (position: (0, 0, -6), look_at: (0, 0, 0), fov: 30),
        background: (0.2, 0.2, 0.2),
        lights: [Directional(direction: (0, 0, 1), intensity: 1.0, shadows: false)],
        materials: {{
            "water": (color: (1, 1, 1), ambient: 0, diffuse: 0, transmit: 1, ior: 1.33),
            {material}
            "red": (color: (1, 0, 0), ambient: 0.2, diffuse: 0.8),
            "green": (color: (0, 1, 0), ambient: 0.2, diffuse: 0.8),
        }},
        objects: [
            (plugin: "sphere", params: (center: (0, 0, 0), radius: 1.2), material: "water"),
            {object}
            (plugin: "sphere", params: (center: (-0.8, 0.3, 4), radius: 0.9), material: "red"),
            (plugin: "sphere", params: (center: (0.9, -0.4, 4), radius: 0.9), material: "green"),
        ],
        render: (width: 48, height: 48, max_depth: 8),
    )"#
    )
}

#[test]
fn glass_in_water_refracts_by_the_ratio_of_the_two() {
    let water = render("nested-water", &nested(None));
    // Glass with water's index inside water: no interface at all, so the same picture. A
    // renderer that took air (1.0) as the glass's outside would bend light there.
    let same = render("nested-same", &nested(Some(1.33)));
    let (mean, max) = diff(&to_srgb8(&water), &to_srgb8(&same));
    assert!(
        max <= 2,
        "invisible inner ball changed the picture: mean {mean}, max {max}"
    );
    // Real glass (1.5) does change it, but only inside the inner ball's outline.
    let glass = render("nested-glass", &nested(Some(1.5)));
    let (mean, _) = diff(&to_srgb8(&water), &to_srgb8(&glass));
    assert!(mean > 1.0, "glass in water changed nothing: {mean}");
    for (x, y) in [(0, 0), (47, 0), (0, 47), (47, 47), (2, 24)] {
        assert_eq!(
            rgb(&water, x, y),
            rgb(&glass, x, y),
            "outside the balls at ({x}, {y})"
        );
    }
}

#[test]
fn camera_inside_a_glass_ball_sees_straight_out() {
    // From the centre of a clear ball every camera ray meets its surface head on: nothing
    // bends, so the picture is the one without the ball. Leaving it without having entered
    // must use the ball's index on the inside.
    let scene = |ball: &str| {
        format!(
            r#"Scene(
            camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 40),
            background: (0.1, 0.1, 0.3),
            lights: [Point(position: (2, 3, -1), intensity: 1.0)],
            materials: {{
                "glass": (color: (1, 1, 1), ambient: 0, diffuse: 0, transmit: 1, ior: 1.5),
                "red": (color: (1, 0.2, 0.1), ambient: 0.2, diffuse: 0.8),
            }},
            objects: [
                {ball}
                (plugin: "sphere", params: (center: (0.5, 0, 5), radius: 1), material: "red"),
            ],
            render: (width: 32, height: 32),
        )"#
        )
    };
    let inside = render(
        "camera-inside",
        &scene(r#"(plugin: "sphere", params: (center: (0, 0, 0), radius: 2), material: "glass"),"#),
    );
    let free = render("camera-free", &scene(""));
    let (mean, max) = diff(&to_srgb8(&inside), &to_srgb8(&free));
    // Shadow rays through clear white glass are filtered by white: lighting is unchanged too.
    assert!(max <= 2, "mean {mean}, max {max}");
    assert!(rgb(&free, 16, 16)[0] > 0.3, "the red ball is in view");
}

#[test]
fn coincident_surfaces_do_not_shadow_each_other() {
    // A floor plane and a mesh quad in the same plane, two coincident spheres: whichever of
    // two coincident surfaces a ray hits, its shadow ray must not be stopped by the other one.
    let scene = r#"Scene(
        camera: (position: (0, 3, -6), look_at: (0, 0, 0), fov: 40),
        background: (0, 0, 0),
        lights: [Directional(direction: (0.3, -1, 0.2), intensity: 1.0)],
        materials: {
            "a": (color: (1, 1, 1), ambient: 0.1, diffuse: 0.9),
            "b": (color: (1, 1, 1), ambient: 0.1, diffuse: 0.9),
        },
        objects: [
            (plugin: "plane", params: (normal: (0, 1, 0)), material: "a"),
            (plugin: "mesh", params: (positions: [(-20, 0, -20), (-20, 0, 20), (20, 0, 20), (20, 0, -20)], indices: [(0, 1, 2), (0, 2, 3)]), material: "b"),
            (plugin: "sphere", params: (center: (3, 1, 2), radius: 1), material: "a"),
            (plugin: "sphere", params: (center: (3, 1, 2), radius: 1), material: "b"),
        ],
        render: (width: 64, height: 48),
    )"#;
    let fb = render("coincident", scene);
    let l = Vec3A::new(0.3, -1.0, 0.2).normalize();
    let lit = 0.1 + 0.9 * (-l).dot(Vec3A::Y);
    let mut floor = 0;
    for y in 26..48 {
        for x in 0..32 {
            // The left half of the lower image: open floor (the spheres and their shadow are
            // on the right).
            let c = rgb(&fb, x, y);
            assert!(
                (c[0] - lit).abs() < 1e-3,
                "floor at ({x}, {y}): {c:?} vs {lit}"
            );
            floor += 1;
        }
    }
    assert!(floor > 0);
}

// ------------------------------------------------------------------------------------------------
// Watertight triangles
// ------------------------------------------------------------------------------------------------

#[test]
fn rays_at_shared_edges_and_vertices_never_leak() {
    // 2 placements x 4 origins x 117,762 targets = 942,096 rays here (a few seconds in debug);
    // `cargo run --release --example watertight` casts 14 M with the same code.
    let mut total = 0;
    for (radius, center) in [(1.0, DVec3::ZERO), (1e-3, DVec3::new(1.0, -2.0, 0.5))] {
        let (positions, faces) = leaks::icosphere(4, radius, center);
        let (tris, verts) = leaks::build(&positions, &faces);
        let targets = leaks::targets(&verts, &faces, 15);
        let origins = leaks::origins(4, radius as f32, Vec3A::from(center.as_vec3()));
        let (rays, leaked) = leaks::count_leaks(&tris, &origins, &targets);
        assert_eq!(
            leaked, 0,
            "{leaked} of {rays} rays leaked at radius {radius}"
        );
        total += rays;
    }
    assert_eq!(total, 2 * 4 * (2562 + 7680 * 15));
}

// ------------------------------------------------------------------------------------------------
// A NaN never aborts a render
// ------------------------------------------------------------------------------------------------

fn nan_scene(dir: &std::path::Path) -> String {
    format!(
        r#"Scene(
        plugin_path: ["{}"],
        camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: 40),
        background: (0, 0, 1),
        lights: [Directional(direction: (0, 0, 1), intensity: 1.0)],
        textures: {{ "half": (plugin: "nan_texture", params: (color: (1, 0, 0))) }},
        materials: {{ "m": (texture: "half", ambient: 0.2, diffuse: 0.8) }},
        objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1.5), material: "m")],
        render: (width: 32, height: 32, outputs: [(path: "nan.png")]),
    )"#,
        dir.display()
    )
}

#[test]
fn a_nan_is_counted_reported_and_clamped() {
    let dir = temp_dir("nan-texture");
    install_plugin(&dir, "testplug_nan", "luxon_nan");
    let path = dir.join("scene.ron");
    std::fs::write(&path, nan_scene(&dir)).unwrap();
    let desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let scene = Scene::build(&desc, &registry(&desc)).unwrap_or_else(|e| panic!("{e}"));
    let (fb, stats) = luxon::render::render(&scene, &|_, _| {}).unwrap_or_else(|e| panic!("{e}"));
    // The sphere's half at world x < 0 is NaN: black. The camera looks along +z with y up,
    // so world +x is the image's left (right-handed) and the black half is on the right.
    let (mut black, mut red) = (0u64, 0u64);
    for y in 0..32 {
        for x in 0..32 {
            let c = rgb(&fb, x, y);
            assert!(c.iter().all(|v| v.is_finite()));
            if c == [0.0; 3] {
                black += 1;
                assert!(x >= 16, "black pixel on the left at ({x}, {y})");
            } else if c[1] == 0.0 && c[0] > 0.0 {
                red += 1;
                assert!(x < 16, "red pixel on the right at ({x}, {y})");
            }
        }
    }
    assert!(black > 50 && red > 50, "black {black}, red {red}");
    assert_eq!(stats.counters.nan_pixels, black);
    // Counted per plugin instance: the one texture, at least once per black pixel.
    let warnings = scene.nan_warnings(&stats.nan_sources);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(stats.nan_sources[0] >= black, "{:?}", stats.nan_sources);
    assert!(
        warnings[0].contains("texture `half` (plugin `nan_texture`) gave NaN"),
        "{warnings:?}"
    );
    // The command line finishes, writes the image and reports the count.
    let out = run(&["render", path.to_str().unwrap(), "--stats"]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(dir.join("nan.png").is_file());
    let line = err
        .lines()
        .find(|l| l.trim_start().starts_with("NaN pixels"))
        .unwrap_or_else(|| panic!("no NaN line in {err}"));
    assert_eq!(
        line.split_whitespace().last(),
        Some(black.to_string().as_str()),
        "{err}"
    );
    // The warning names the texture that gave the NaN, its plugin and its place in the scene,
    // with how many shading points it spoilt (at least one per black pixel).
    let text = nan_scene(&dir);
    let (row, line) = text
        .lines()
        .enumerate()
        .find(|(_, l)| l.contains("\"half\""))
        .unwrap();
    let at = format!(
        "{}:{}:{}",
        path.display(),
        row + 1,
        1 + line.find("(color").unwrap()
    );
    let head = format!(
        "luxon: warning: {at}: texture `half` (plugin `nan_texture`) gave NaN or infinite values \
         at "
    );
    let warning = err
        .lines()
        .find(|l| l.starts_with(&head))
        .unwrap_or_else(|| panic!("no `{head}` in {err}"));
    let count: u64 = warning[head.len()..]
        .split(' ')
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{warning}"));
    assert!(count >= black, "{warning}");
    assert!(
        warning.ends_with("shading point(s); expected finite RGBA"),
        "{warning}"
    );
}

/// Custom geometry answering hits at a NaN distance: the hits are misses (as before), and the
/// warning names the object, its plugin and its place.
#[test]
fn nan_hits_of_custom_geometry_are_counted_per_object() {
    let dir = temp_dir("nan-box");
    install_plugin(&dir, "testplug_nan", "luxon_nan");
    let path = dir.join("scene.ron");
    let text = format!(
        "Scene(\n    plugin_path: [\"{}\"],\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    objects: [(plugin: \"sphere\", params: (center: (3, 0, 0), radius: 0.5)), (plugin: \"nan_box\")],\n    render: (width: 8, height: 8, outputs: [(path: \"nan.png\")]),\n)\n",
        dir.display()
    );
    std::fs::write(&path, &text).unwrap();
    let out = run(&["render", path.to_str().unwrap()]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let col = 1 + text
        .lines()
        .nth(3)
        .unwrap()
        .find("(plugin: \"nan_box")
        .unwrap();
    let head = format!(
        "luxon: warning: {}:4:{col}: object 1 (plugin `nan_box`) answered ",
        path.display()
    );
    let warning = err
        .lines()
        .find(|l| l.starts_with(&head))
        .unwrap_or_else(|| panic!("no `{head}` in {err}"));
    assert!(
        warning.ends_with(
            "ray(s) with a hit at a NaN distance or normal; expected finite numbers (those hits \
             were taken as misses)"
        ),
        "{warning}"
    );
    // The primary rays through the middle of the image cross the box.
    let n: u64 = warning[head.len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(n > 0, "{warning}");
}

// ------------------------------------------------------------------------------------------------
// Degenerate input
// ------------------------------------------------------------------------------------------------

/// Whether `message` names `file:line:col`.
fn names_position(message: &str, file: &str) -> bool {
    message.match_indices(file).any(|(i, _)| {
        let rest = &message[i + file.len()..];
        let mut parts = rest.splitn(3, ':');
        parts.next() == Some("")
            && parts.next().is_some_and(|l| l.parse::<u32>().is_ok())
            && parts.next().is_some_and(|c| {
                c.split(':')
                    .next()
                    .is_some_and(|c| c.parse::<u32>().is_ok())
            })
    })
}

/// Loads and builds a scene file; Ok: the rendered image (checked for NaN), Err: the message.
fn outcome(path: &std::path::Path) -> Result<Framebuffer, String> {
    let desc = luxon_formats::load(path).map_err(|e| e.to_string())?;
    let scene = Scene::build(&desc, &registry(&desc)).map_err(|e| e.to_string())?;
    let (fb, stats) = luxon::render::render(&scene, &|_, _| {}).map_err(|e| e.to_string())?;
    assert_eq!(
        stats.counters.nan_pixels,
        0,
        "{}: NaN pixels",
        path.display()
    );
    assert!(fb.rgba.iter().all(|v| v.is_finite()));
    Ok(fb)
}

/// One object in front of the camera, on a black background; 16x16.
fn ron_with(object: &str) -> String {
    format!(
        r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0), fov: 40),
    lights: [Directional(direction: (0, 0, 1))],
    objects: [
        {object},
    ],
    render: (width: 16, height: 16),
)"#
    )
}

#[test]
fn degenerate_ron_geometry_is_rejected_with_its_position() {
    let dir = temp_dir("degenerate-ron");
    for (object, words) in [
        (
            r#"(plugin: "sphere", params: (center: (0, 0, 0), radius: 0))"#,
            "radius",
        ),
        (
            r#"(plugin: "spheres", params: (centers: [(0, 0, 0), (1, 0, 0)], radii: [1, 0]))"#,
            "0",
        ),
        (
            r#"(plugin: "plane", params: (normal: (0, 0, 0)))"#,
            "normal",
        ),
        (
            r#"(plugin: "triangle", params: (vertices: ((0, 0, 0), (1, 1, 1), (2, 2, 2))))"#,
            "collinear",
        ),
        (
            r#"(plugin: "triangle", params: (vertices: ((0, 0, 0), (0, 0, 0), (1, 0, 0))))"#,
            "collinear",
        ),
        (
            r#"(plugin: "triangle", params: (vertices: ((0, 0, 0), (1, 0, 0), (0, 1, 0)), normals: ((0, 0, 1), (0, 0, 0), (0, 0, 1))))"#,
            "normal",
        ),
        (
            r#"(plugin: "mesh", params: (positions: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], indices: [(0, 1, 2)], normals: [(0, 0, 0), (0, 0, 1), (0, 0, 1)]))"#,
            "normal",
        ),
        (
            r#"(plugin: "ring", params: (center: (0, 0, 0), normal: (0, 0, 1), inner: 1, outer: 1))"#,
            "outer",
        ),
        (
            r#"(plugin: "ring", params: (center: (0, 0, 0), normal: (0, 0, 0), outer: 1))"#,
            "normal",
        ),
        (
            r#"(plugin: "cone", params: (base: (0, 0, 0), apex: (0, 1, 0), base_radius: 0, apex_radius: 0))"#,
            "radi",
        ),
        (
            r#"(plugin: "cylinder", params: (base: (0, 0, 0), apex: (0, 0, 0), radius: 1))"#,
            "same",
        ),
        (
            r#"(plugin: "box", params: (min: (0, 0, 0), max: (1, 0, 1)))"#,
            "min",
        ),
        (
            r#"(plugin: "infinite_cylinder", params: (center: (0, 0, 0), axis: (0, 0, 0), radius: 1))"#,
            "axis",
        ),
    ] {
        let path = dir.join("scene.ron");
        std::fs::write(&path, ron_with(object)).unwrap();
        match outcome(&path) {
            Ok(_) => panic!("accepted {object}"),
            Err(e) => {
                assert!(names_position(&e, "scene.ron"), "no file:line:col in `{e}`");
                assert!(e.contains(words), "`{e}` does not mention {words}");
            }
        }
    }
}

#[test]
fn zero_area_triangles_and_repeated_vertices_are_dropped() {
    // A mesh whose good triangle covers the image centre, with a repeated-vertex and a
    // collinear triangle beside it: they are dropped, the rest renders.
    let dir = temp_dir("degenerate-mesh");
    let path = dir.join("scene.ron");
    std::fs::write(
        &path,
        ron_with(
            r#"(plugin: "mesh", params: (positions: [(-2, -2, 0), (2, -2, 0), (0, 2, 0), (5, 5, 0), (6, 6, 0), (7, 7, 0)],
                indices: [(0, 1, 2), (0, 0, 1), (3, 4, 5), (2, 2, 2)]))"#,
        ),
    )
    .unwrap();
    let fb = outcome(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(rgb(&fb, 8, 8)[0] > 0.1, "the good triangle is missing");
    assert_eq!(rgb(&fb, 0, 0), [0.0; 3]);
}

#[test]
fn degenerate_nff_input() {
    let dir = temp_dir("degenerate-nff");
    let view = "v\nfrom 0 0 -5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 16 16\nl 0 0 -10\nf 1 1 1 1 0 0 0 0\n";
    // Rejected, naming file:line:col.
    for (body, words) in [
        ("s 0 0 0 0\n", "radius"),
        ("c\n0 0 0 0\n0 1 0 0\n", "radi"),
        ("c\n0 0 0 1\n0 0 0 1\n", "same point"),
        ("p 2\n0 0 0\n1 0 0\n", "3"),
    ] {
        let path = dir.join("bad.nff");
        std::fs::write(&path, format!("{view}{body}")).unwrap();
        let e = outcome(&path)
            .err()
            .unwrap_or_else(|| panic!("accepted {body}"));
        assert!(names_position(&e, "bad.nff"), "no file:line:col in `{e}`");
        assert!(e.contains(words), "`{e}` does not mention {words}");
    }
    // Handled: polygons with repeated vertices or no area, normals of zero length; the good
    // triangle still renders.
    let body = "p 3\n-2 -2 0\n2 -2 0\n0 2 0\n\
                p 4\n5 5 0\n5 5 0\n6 6 0\n6 6 0\n\
                p 3\n1 1 0\n2 2 0\n3 3 0\n\
                pp 3\n-2 -2 0.5 0 0 0\n2 -2 0.5 0 0 0\n0 2 0.5 0 0 0\n";
    let path = dir.join("ok.nff");
    std::fs::write(&path, format!("{view}{body}")).unwrap();
    let fb = outcome(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(rgb(&fb, 8, 8)[0] > 0.1, "the good triangle is missing");
}

#[test]
fn degenerate_obj_input() {
    let dir = temp_dir("degenerate-obj");
    // Repeated vertices, a collinear face, zero-length normals: no NaN, the good face renders.
    let path = dir.join("mesh.obj");
    std::fs::write(
        &path,
        "v -2 -2 0\nv 2 -2 0\nv 0 2 0\nv 5 5 0\nv 6 6 0\nv 7 7 0\nvn 0 0 0\n\
         f 1//1 2//1 3//1\nf 1 1 2\nf 4 5 6\nf 3 3 3\n",
    )
    .unwrap();
    let fb = outcome(&path).unwrap_or_else(|e| panic!("{e}"));
    // The OBJ camera looks from -z at the mesh's box: its centre is the good face's.
    let lit = (0..fb.height)
        .flat_map(|y| (0..fb.width).map(move |x| (x, y)))
        .filter(|&(x, y)| rgb(&fb, x, y) != [0.0; 3])
        .count();
    assert!(lit > 100, "the good face is missing");
    // Only degenerate faces: an empty scene, not an error or a NaN.
    let path = dir.join("flat.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 1 1 1\n").unwrap();
    match outcome(&path) {
        Ok(_) => {}
        Err(e) => assert!(e.contains("flat.obj"), "{e}"),
    }
    // A face using a vertex that does not exist: an error naming the file and line.
    let path = dir.join("oob.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    let Err(e) = outcome(&path) else {
        panic!("accepted an out-of-range index");
    };
    assert!(names_position(&e, "oob.obj"), "{e}");
}
