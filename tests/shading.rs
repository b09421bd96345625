//! The shading model against values worked out by hand: one pixel through the image centre.

mod common;

use common::*;

/// Renders a 1x1 image (its single ray goes through the image centre) and returns its RGB.
fn centre(name: &str, scene: &str) -> [f32; 3] {
    let dir = temp_dir(name);
    let fb = render_text(&dir, scene, |d| {
        d.render.width = 1;
        d.render.height = 1;
    });
    let p = fb.pixel(0, 0);
    [p[0], p[1], p[2]]
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-4)
}

const HEAD_ON: &str = r#"Scene(
    camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 30),
    background: (0.2, 0.3, 0.4),
    lights: [Directional(direction: (0, 0, 1), intensity: 1.0, shadows: false)],
    materials: { "m": (color: (1, 0.5, 0.25), ambient: 0.1, diffuse: 0.6, specular: SPEC, shininess: 10) },
    objects: [(plugin: "sphere", params: (center: (0, 0, 5), radius: 1), material: "m")],
)"#;

#[test]
fn ambient_plus_lambert() {
    let c = centre("lambert", &HEAD_ON.replace("SPEC", "0.0"));
    assert!(close(c, [0.7, 0.35, 0.175]), "{c:?}");
}

#[test]
fn phong_highlight_adds_white() {
    let c = centre("phong", &HEAD_ON.replace("SPEC", "0.5"));
    assert!(close(c, [1.2, 0.85, 0.675]), "{c:?}");
}

#[test]
fn blinn_highlight_adds_white() {
    let scene = HEAD_ON
        .replace("SPEC", "0.5")
        .replace("shininess: 10", "shininess: 10, highlight: Blinn");
    let c = centre("blinn", &scene);
    assert!(close(c, [1.2, 0.85, 0.675]), "{c:?}");
}

#[test]
fn miss_shows_the_background() {
    let scene = HEAD_ON
        .replace("SPEC", "0.0")
        .replace("center: (0, 0, 5)", "center: (0, 5, 5)");
    assert!(close(centre("miss", &scene), [0.2, 0.3, 0.4]));
}

/// A gradient background, by direction (`Sphere`) and by where rays start (`OrthoPlane`):
/// the camera looks along +z, so its centre ray sees x = 0 (a quarter of the way from bottom
/// to top here), a mirror facing up-and-back sends it up (the top colour).
#[test]
fn gradient_backgrounds_follow_the_ray() {
    let scene = |bg: &str, objects: &str| {
        format!(
            r#"Scene(
    camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 30),
    background: {bg},
    materials: {{ "mirror": (color: (1, 1, 1), ambient: 0, diffuse: 0, reflect: 1) }},
    objects: [{objects}],
)"#
        )
    };
    let sky = "Gradient(kind: Sphere, up: (0, 2, 0), top: 1.5, bottom: -0.5, \
               top_color: (1, 0, 0), bottom_color: (0, 0, 1))";
    let c = centre("gradient", &scene(sky, ""));
    assert!(close(c, [0.25, 0.0, 0.75]), "{c:?}");
    let mirror = r#"(plugin: "plane", params: (point: (0, 0, 3), normal: (0, 1, -1)),
                     material: "mirror")"#;
    let c = centre("gradient-mirror", &scene(sky, mirror));
    assert!(close(c, [1.0, 0.0, 0.0]), "{c:?}");
    // By origin: the camera at y = 0 sees x = 0 whatever its direction; moved up by 0.5,
    // x = 1: half way.
    let plane = sky.replace("Sphere", "OrthoPlane");
    let c = centre("gradient-plane", &scene(&plane, ""));
    assert!(close(c, [0.25, 0.0, 0.75]), "{c:?}");
    let raised = scene(&plane, "").replace(
        "position: (0, 0, 0), look_at: (0, 0, 1)",
        "position: (0, 0.5, 0), look_at: (0, 0.5, 1)",
    );
    let c = centre("gradient-plane-up", &raised);
    assert!(close(c, [0.75, 0.0, 0.25]), "{c:?}");
}

/// Two parallel mirrors with the camera between them: each bounce adds the ambient term and
/// halves the rest; at the depth limit a ray sees the background.
fn mirrors(depth: u32, background: f32) -> [f32; 3] {
    let scene = format!(
        r#"Scene(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 30),
        background: ({background}, {background}, {background}),
        materials: {{ "mirror": (color: (1, 1, 1), ambient: 0.1, diffuse: 0, reflect: 0.5) }},
        objects: [
            (plugin: "plane", params: (point: (0, 0, 5), normal: (0, 0, -1)), material: "mirror"),
            (plugin: "plane", params: (point: (0, 0, -5), normal: (0, 0, 1)), material: "mirror"),
        ],
        render: (max_depth: {depth}, min_weight: 0),
    )"#
    );
    centre(&format!("mirrors-{depth}-{background}"), &scene)
}

#[test]
fn depth_limit_ends_in_the_background() {
    for depth in [0u32, 1, 3, 7] {
        for bg in [0.0f32, 1.0] {
            let expect: f32 = (0..=depth)
                .map(|k| 0.1 * 0.5f32.powi(k as i32))
                .sum::<f32>()
                + 0.5f32.powi(depth as i32 + 1) * bg;
            let c = mirrors(depth, bg);
            assert!(
                close(c, [expect; 3]),
                "depth {depth} bg {bg}: {c:?} vs {expect}"
            );
        }
    }
}

#[test]
fn deep_mirrors_finish() {
    // Deep recursion between mirrors must end (depth limit) without overflowing the stack.
    let c = mirrors(200, 0.0);
    assert!(close(c, [0.2; 3]), "{c:?}");
}

/// Camera between a floor and a light, looking down through nothing at the floor; a blocker
/// above the camera sits between the floor point and the light.
fn under(name: &str, blocker: &str, material: &str) -> [f32; 3] {
    let scene = format!(
        r#"Scene(
        camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov: 10),
        lights: [Directional(direction: (0, -1, 0), intensity: 1.0)],
        materials: {{
            "floor": (color: (1, 1, 1), ambient: 0, diffuse: 1),
            "blocker": {material},
        }},
        objects: [
            (plugin: "plane", params: (normal: (0, 1, 0)), material: "floor"),
            {blocker}
        ],
    )"#
    );
    centre(name, &scene)
}

const PANE: &str = r#"(plugin: "triangle", params: (vertices: ((-5, 2, -5), (5, 2, -5), (0, 2, 5))), material: "blocker"),"#;
const BALL: &str =
    r#"(plugin: "sphere", params: (center: (0, 3, 0), radius: 0.5), material: "blocker"),"#;
const TINTED: &str = r#"(color: (1, 0.5, 0.25), diffuse: 0, ambient: 0, transmit: 0.8, ior: 1.0)"#;

#[test]
fn shadow_through_a_pane_is_filtered_once() {
    let c = under("pane", PANE, TINTED);
    assert!(close(c, [0.8, 0.4, 0.2]), "{c:?}");
}

#[test]
fn shadow_through_a_ball_is_filtered_twice() {
    let c = under("ball", BALL, TINTED);
    assert!(close(c, [0.64, 0.16, 0.04]), "{c:?}");
}

#[test]
fn opaque_blocker_casts_a_black_shadow() {
    let c = under("opaque", BALL, "(color: (1, 1, 1))");
    assert!(close(c, [0.0; 3]), "{c:?}");
    let lit = under("nothing", "", "(color: (1, 1, 1))");
    assert!(close(lit, [1.0; 3]), "{lit:?}");
}

#[test]
fn clear_object_with_unit_ior_is_invisible() {
    let scene = r#"Scene(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 30),
        background: (0.2, 0.3, 0.4),
        materials: { "clear": (color: (1, 1, 1), ambient: 0, diffuse: 0, transmit: 1, ior: 1) },
        objects: [(plugin: "sphere", params: (center: (0, 0, 5), radius: 1), material: "clear")],
    )"#;
    assert!(close(centre("clear", scene), [0.2, 0.3, 0.4]));
}

#[test]
fn glass_ball_lens_inverts_what_is_behind_it() {
    // A glass ball acts as a lens: a red object seen above the axis through it shows up below.
    let scene = r#"Scene(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 12),
        background: (0, 0, 0),
        materials: {
            "glass": (color: (1, 1, 1), ambient: 0, diffuse: 0, transmit: 1, ior: 1.5),
            "red": (color: (1, 0, 0), ambient: 1, diffuse: 0),
        },
        objects: [
            (plugin: "sphere", params: (center: (0, 0, 10), radius: 1), material: "glass"),
            (plugin: "sphere", params: (center: (0, 2, 20), radius: 1.2), material: "red"),
        ],
    )"#;
    let dir = temp_dir("lens");
    let fb = render_text(&dir, scene, |d| {
        d.render.width = 41;
        d.render.height = 41;
    });
    let red_rows: Vec<u32> = (0..41)
        .filter(|&y| (0..41).any(|x| fb.pixel(x, y)[0] > 0.5))
        .collect();
    assert!(!red_rows.is_empty(), "the red ball is not visible at all");
    // Without the lens it would be in the top half (rows < 20); through it, in the bottom half.
    assert!(red_rows.iter().any(|&y| y > 20), "rows {red_rows:?}");
}

/// One or two panes between the camera and a blue background, in a given transparency mode.
fn panes(name: &str, mode: &str, tilt: f32, second: bool, extra: &str) -> [f32; 3] {
    // The pane spans x and the direction (0, cos, sin) of the tilt: its normal makes the angle
    // `tilt` with the view direction.
    let (y, z) = (tilt.to_radians().cos() * 5.0, tilt.to_radians().sin() * 5.0);
    let pane = |d: f32| {
        format!(
            r#"(plugin: "mesh", params: (positions: [(-5, {y0}, {z0}), (5, {y0}, {z0}), (5, {y1}, {z1}), (-5, {y1}, {z1})], indices: [(0, 1, 2), (0, 2, 3)]), material: "pane"),"#,
            y0 = -y,
            z0 = d - z,
            y1 = y,
            z1 = d + z
        )
    };
    let scene = format!(
        r#"Scene(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 20),
        background: (0, 0, 1),
        materials: {{ "pane": (color: (1, 0, 0), ambient: 1, diffuse: 0, transmit: 0.5, ior: 1) }},
        objects: [{}{}],
        render: (transparency: (mode: {mode}{extra})),
    )"#,
        pane(10.0),
        if second { pane(20.0) } else { String::new() }
    );
    centre(name, &scene)
}

#[test]
fn transparency_modes() {
    // Filter: ambient·opacity·base + transmit·base·behind = (0.5, 0, 0).
    let f = panes("t-filter", "Filter", 0.0, false, "");
    assert!(close(f, [0.5, 0.0, 0.0]), "{f:?}");
    // Post-multiplied (VMD): opacity·shaded + transmit·behind, unfiltered.
    let p = panes("t-post", "PostMultiplied", 0.0, false, "");
    assert!(close(p, [0.5, 0.0, 0.5]), "{p:?}");
    // Angle-modulated (Raster3D-style): head-on as Filter; seen at 60 degrees, t = 0.5^2.
    let a0 = panes("t-angle0", "AngleModulated", 0.0, false, "");
    assert!(close(a0, f), "{a0:?}");
    let a60 = panes("t-angle60", "AngleModulated", 60.0, false, "");
    assert!(close(a60, [0.75, 0.0, 0.0]), "{a60:?}");
}

#[test]
fn transparent_surface_limit_shows_the_next_one_opaque() {
    // Two panes, both half transparent: 0.5 + 0.5·(0.5 + 0.5·blue·red) = (0.75, 0, 0).
    let both = panes("t-two", "Filter", 0.0, true, "");
    assert!(close(both, [0.75, 0.0, 0.0]), "{both:?}");
    // Limit 1: the second pane is opaque: 0.5 + 0.5·red = (1.0, 0, 0).
    let limited = panes("t-limit", "Filter", 0.0, true, ", max_surfaces: 1");
    assert!(close(limited, [1.0, 0.0, 0.0]), "{limited:?}");
}

#[test]
fn tachyons_transparency_rules() {
    // Additive (Tachyon's TRANS_ORIG): the pane as if opaque + transmit·behind, unfiltered.
    let a = panes("t-additive", "Additive", 0.0, false, "");
    assert!(close(a, [1.0, 0.0, 0.5]), "{a:?}");
    // Raster3D head-on: opacity ¼(1 + cos(π·0.5·(−1)))² = ¼, so 0.75 of the blue comes through.
    let r = panes("t-r3d", "Additive", 0.0, false, ", angle: Raster3D");
    assert!(close(r, [1.0, 0.0, 0.75]), "{r:?}");
    // Post-multiplied: the same angle rule.
    let p = panes(
        "t-post-r3d",
        "PostMultiplied",
        0.0,
        false,
        ", angle: Raster3D",
    );
    assert!(close(p, [0.25, 0.0, 0.75]), "{p:?}");
    // Skip: past the limit the second pane is not there: red + 0.5·blue.
    let both = panes("t-add-two", "Additive", 0.0, true, "");
    assert!(close(both, [1.5, 0.0, 0.25]), "{both:?}");
    let skip = panes(
        "t-skip",
        "Additive",
        0.0,
        true,
        ", max_surfaces: 1, beyond_max: Skip",
    );
    assert!(close(skip, [1.0, 0.0, 0.5]), "{skip:?}");
    let none = panes(
        "t-skip0",
        "Additive",
        0.0,
        true,
        ", max_surfaces: 0, beyond_max: Skip",
    );
    assert!(close(none, [0.0, 0.0, 1.0]), "{none:?}");
}

/// `under`, with render settings.
fn under_with(name: &str, blocker: &str, material: &str, render: &str) -> [f32; 3] {
    let scene = format!(
        r#"Scene(
        camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov: 10),
        lights: [Directional(direction: (0, -1, 0), intensity: 1.0)],
        materials: {{
            "floor": (color: (1, 1, 1), ambient: 0, diffuse: 1),
            "blocker": {material},
        }},
        objects: [
            (plugin: "plane", params: (normal: (0, 1, 0)), material: "floor"),
            {blocker}
        ],
        render: ({render}),
    )"#
    );
    centre(name, &scene)
}

#[test]
fn shadows_through_transparency_grey_or_none() {
    let tinted = under_with("s-tinted", PANE, TINTED, "transparency: (shadows: Tinted)");
    assert!(close(tinted, [0.8, 0.4, 0.2]), "{tinted:?}");
    let grey = under_with("s-grey", BALL, TINTED, "transparency: (shadows: Untinted)");
    assert!(close(grey, [0.64; 3]), "{grey:?}");
    let off = under_with("s-off", BALL, TINTED, "transparency: (shadows: Off)");
    assert!(close(off, [1.0; 3]), "{off:?}");
    // Off spares only transparent surfaces.
    let opaque = under_with(
        "s-off-opaque",
        BALL,
        "(color: (1, 1, 1))",
        "transparency: (shadows: Off)",
    );
    assert!(close(opaque, [0.0; 3]), "{opaque:?}");
}

#[test]
fn objects_without_shadows() {
    let ball = BALL.replace(
        "material: \"blocker\")",
        "material: \"blocker\", shadows: false)",
    );
    let c = under("no-shadow", &ball, "(color: (1, 1, 1))");
    assert!(close(c, [1.0; 3]), "{c:?}");
}

#[test]
fn light_scale_scales_diffuse_and_highlights_not_ambient() {
    let scene = HEAD_ON
        .replace("SPEC", "0.5")
        .replace("objects:", "render: (light_scale: 0.5),\n    objects:");
    // 0.1·c + 0.5·(0.6·c + 0.5).
    let c = centre("light-scale", &scene);
    assert!(close(c, [0.65, 0.45, 0.35]), "{c:?}");
}

#[test]
fn surface_coloured_highlights() {
    let scene = HEAD_ON
        .replace("SPEC", "0.5")
        .replace("shininess: 10", "shininess: 10, highlight_color: Surface");
    // (0.1 + 0.6 + 0.5)·c.
    let c = centre("metal", &scene);
    assert!(close(c, [1.2, 0.6, 0.3]), "{c:?}");
}

#[test]
fn blinn_fast_highlight() {
    // Light from above-behind at 45°: N·L = cos 45°, x = N·H = cos 22.5°.
    let scene = HEAD_ON
        .replace("SPEC", "0.5")
        .replace("shininess: 10", "shininess: 10, highlight: BlinnFast")
        .replace("direction: (0, 0, 1)", "direction: (0, -1, 1)");
    let (nl, x) = (45f32.to_radians().cos(), 22.5f32.to_radians().cos());
    let h = 0.5 * x / (10.0 - 10.0 * x + x);
    let want = [1.0f32, 0.5, 0.25].map(|k| k * (0.1 + 0.6 * nl) + h);
    let c = centre("blinn-fast", &scene);
    assert!(close(c, want), "{c:?} {want:?}");
}

#[test]
fn fog_start_and_misses() {
    // The sphere's front is 4 from the eye; exponential fog starting there leaves it clear.
    let lit = centre("fog-none", &HEAD_ON.replace("SPEC", "0.0"));
    let fog = |mode: &str, extra: &str| {
        let scene = HEAD_ON.replace("SPEC", "0.0").replace(
            "objects:",
            &format!("fog: (mode: {mode}, color: (0, 1, 0){extra}),\n    objects:"),
        );
        centre("fog", &scene)
    };
    assert!(close(fog("Exp(density: 0.5, start: 4)", ""), lit));
    let v = (-0.5f32 * 2.0).exp();
    let want = [0, 1, 2].map(|k| lit[k] * v + [0.0, 1.0, 0.0][k] * (1.0 - v));
    let c = fog("Exp(density: 0.5, start: 2)", "");
    assert!(close(c, want), "{c:?} {want:?}");
    // A miss shows the fog colour with `misses`, the background without.
    let miss = |extra: &str| {
        let scene = HEAD_ON
            .replace("SPEC", "0.0")
            .replace("center: (0, 0, 5)", "center: (0, 5, 5)")
            .replace(
                "objects:",
                &format!("fog: (mode: Linear(start: 0, end: 10), color: (1, 0, 0){extra}),\n    objects:"),
            );
        centre("fog-miss", &scene)
    };
    assert!(close(miss(""), [0.2, 0.3, 0.4]));
    assert!(close(miss(", misses: true"), [1.0, 0.0, 0.0]));
}

#[test]
fn fog_on_every_ray_fogs_reflections_twice() {
    // A mirror 2 ahead sees a red emitter 4 behind it; linear fog over 10.
    let scene = |every: bool| {
        format!(
            r#"Scene(
            camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 30),
            background: (0, 0, 0),
            fog: (mode: Linear(start: 0, end: 10), color: (0, 0, 1), every_ray: {every}),
            materials: {{
                "mirror": (color: (0, 0, 0), ambient: 0, diffuse: 0, reflect: 1),
                "red": (color: (1, 0, 0), ambient: 1, diffuse: 0),
            }},
            objects: [
                (plugin: "plane", params: (point: (0, 0, 2), normal: (0, 0, -1)), material: "mirror"),
                (plugin: "plane", params: (point: (0, 0, -2), normal: (0, 0, 1)), material: "red"),
            ],
        )"#
        )
    };
    // Every ray: 0.8·(0.6·red + 0.4·blue) + 0.2·blue.
    let c = centre("fog-every", &scene(true));
    assert!(close(c, [0.48, 0.0, 0.52]), "{c:?}");
    // Camera rays only, on the mirror's own (black) shading: the reflection is unfogged.
    let c = centre("fog-camera", &scene(false));
    assert!(close(c, [1.0, 0.0, 0.2]), "{c:?}");
}
