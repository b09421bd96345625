//! Light kinds, attenuation, fog and ambient occlusion against values worked out by hand.

mod common;

use common::*;

/// A 1x1 render: the ray goes through the image centre.
fn centre(name: &str, scene: &str) -> [f32; 3] {
    let dir = temp_dir(name);
    let fb = render_text(&dir, scene, |d| {
        d.render.width = 1;
        d.render.height = 1;
    });
    let p = fb.pixel(0, 0);
    [p[0], p[1], p[2]]
}

fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() < tol)
}

/// Looking straight down at a white floor (ambient 0, diffuse 1) from (0, 1, 0).
fn floor(name: &str, lights: &str, extra: &str) -> [f32; 3] {
    let scene = format!(
        r#"Scene(
        camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov: 10),
        lights: [{lights}],
        materials: {{ "floor": (color: (1, 1, 1), ambient: 0, diffuse: 1) }},
        objects: [(plugin: "plane", params: (normal: (0, 1, 0)), material: "floor")],
        {extra}
    )"#
    );
    centre(name, &scene)
}

#[test]
fn point_light_attenuation() {
    let c = floor(
        "atten",
        "Point(position: (0, 4, 0), attenuation: (1, 0, 1))",
        "",
    );
    assert!(close(c, [1.0 / 17.0; 3], 1e-5), "{c:?}");
}

#[test]
fn spot_light_cone_and_falloff() {
    let inside = floor(
        "spot-in",
        "Spot(position: (0, 4, 0), direction: (0, -1, 0), angle: 40, falloff: 10)",
        "",
    );
    assert!(close(inside, [1.0; 3], 1e-5), "{inside:?}");
    // Aimed 30 degrees away: the floor point is outside the 20-degree half-angle.
    let outside = floor(
        "spot-out",
        "Spot(position: (0, 4, 0), direction: (0.577, -1, 0), angle: 40, falloff: 10)",
        "",
    );
    assert!(close(outside, [0.0; 3], 1e-6), "{outside:?}");
    // Aimed 17.5 degrees away: in the middle of the fall-off band (15..20 degrees): smoothstep(0.5).
    let t = 17.5f32.to_radians().tan();
    let edge = floor(
        "spot-edge",
        &format!("Spot(position: (0, 4, 0), direction: ({t}, -1, 0), angle: 40, falloff: 10)"),
        "",
    );
    assert!(edge[0] > 0.2 && edge[0] < 0.8, "{edge:?}");
}

#[test]
fn area_lights_are_unoccluded_averages() {
    // Unoccluded, a sphere light straight above lights the floor about like a point light.
    let s = floor(
        "sphere-light",
        "SphereLight(center: (0, 4, 0), radius: 0.5, samples: 16)",
        "",
    );
    assert!(s[0] > 0.95 && s[0] <= 1.0, "{s:?}");
    // A rectangle light shines to the side of edge1 × edge2: x × z = -y faces the floor,
    // z × x = +y faces away from it.
    let down = floor(
        "rect-down",
        "RectLight(corner: (-0.5, 4, -0.5), edge1: (1, 0, 0), edge2: (0, 0, 1), samples: 9)",
        "",
    );
    let up = floor(
        "rect-up",
        "RectLight(corner: (-0.5, 4, -0.5), edge1: (0, 0, 1), edge2: (1, 0, 0), samples: 9)",
        "",
    );
    assert!(down[0] > 0.9 && up[0] == 0.0, "{down:?} {up:?}");
}

#[test]
fn soft_shadow_penumbra_is_between_light_and_dark() {
    // A blocker edge right under the middle of a sphere light: half the light is hidden.
    let blocker = r#"objects: [(plugin: "mesh", params: (positions: [(0, 2, -5), (5, 2, -5), (5, 2, 5), (0, 2, 5)], indices: [(0, 1, 2), (0, 2, 3)]))],"#;
    let scene = format!(
        r#"Scene(
        camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov: 10),
        lights: [SphereLight(center: (0, 4, 0), radius: 1.0, samples: 64)],
        materials: {{ "floor": (color: (1, 1, 1), ambient: 0, diffuse: 1) }},
        {blocker}
    )"#
    )
    .replace("objects: [(plugin: \"mesh\"", "objects: [(plugin: \"plane\", params: (normal: (0, 1, 0)), material: \"floor\"), (plugin: \"mesh\"");
    let c = centre("penumbra", &scene);
    assert!(c[0] > 0.3 && c[0] < 0.7, "{c:?}");
}

#[test]
fn exponential_fog_blends_toward_its_colour() {
    // Straight down 1 unit; fog density 0.5: visibility e^-0.5.
    let lit = floor(
        "fog",
        "Directional(direction: (0, -1, 0))",
        "fog: (mode: Exp(density: 0.5), color: (0, 0, 1)),",
    );
    let v = (-0.5f32).exp();
    assert!(close(lit, [v, v, v + (1.0 - v)], 1e-5), "{lit:?}");
    let linear = floor(
        "fog-linear",
        "Directional(direction: (0, -1, 0))",
        "fog: (mode: Linear(start: 0.5, end: 1.5), color: (0, 0, 0)),",
    );
    assert!(close(linear, [0.5; 3], 1e-5), "{linear:?}");
}

#[test]
fn ambient_occlusion_sees_the_open_sky_and_transparent_covers_by_opacity() {
    let open = floor(
        "ao-open",
        "",
        "ambient_occlusion: (samples: 64, distance: 10, color: (1, 1, 1)),",
    );
    assert!(close(open, [1.0; 3], 1e-5), "{open:?}");
    let cover = |name: &str, m: &str| {
        let scene = format!(
            r#"Scene(
            camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov: 10),
            ambient_occlusion: (samples: 64, distance: 100),
            materials: {{ "floor": (color: (1, 1, 1), ambient: 0, diffuse: 1), "cover": {m} }},
            objects: [
                (plugin: "plane", params: (normal: (0, 1, 0)), material: "floor"),
                (plugin: "plane", params: (point: (0, 2, 0), normal: (0, -1, 0)), material: "cover"),
            ],
        )"#
        );
        centre(name, &scene)
    };
    let opaque = cover("ao-opaque", "(color: (1, 1, 1))");
    assert!(close(opaque, [0.0; 3], 1e-6), "{opaque:?}");
    let glass = cover("ao-glass", "(color: (1, 1, 1), transmit: 0.5, ior: 1.0)");
    assert!(close(glass, [0.5; 3], 1e-4), "{glass:?}");
}

#[test]
fn ambient_occlusion_scales_direct_light_like_vmd_aodirect() {
    // Open sky (AO term = intensity) plus a point light straight above (direct = 1 before scaling).
    let c = floor(
        "ao-direct",
        "Point(position: (0, 4, 0))",
        "ambient_occlusion: (samples: 16, distance: 10, intensity: 0.25, direct: 0.5),",
    );
    assert!(close(c, [0.25 + 0.5; 3], 1e-5), "{c:?}");
    // Without occlusion, `direct` does not apply: the light alone gives 1.
    let plain = floor("ao-direct-off", "Point(position: (0, 4, 0))", "");
    assert!(close(plain, [1.0; 3], 1e-5), "{plain:?}");
}

#[test]
fn a_scene_of_cylinders_alone_casts_shadows() {
    // The floor is a wide cylinder's top cap (a disc), the blocker a rod (a cone) between it
    // and the light, out of the camera's view: nothing but cones and discs in the scene.
    let scene = |rod: &str| {
        format!(
            r#"Scene(
            camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov: 10),
            lights: [Point(position: (2, 2, 0), color: (1, 1, 1))],
            materials: {{ "floor": (color: (1, 1, 1), ambient: 0, diffuse: 1) }},
            objects: [
                (plugin: "cylinder", params: (base: (0, -1, 0), apex: (0, 0, 0), radius: 10), material: "floor"),
                {rod}
            ],
        )"#
        )
    };
    let rod = r#"(plugin: "cylinder", params: (base: (0.5, 0.5, -1), apex: (0.5, 0.5, 1), radius: 0.1), material: "floor"),"#;
    let lit = centre("cyl-lit", &scene(""));
    let shadowed = centre("cyl-shadow", &scene(rod));
    assert!(lit[0] > 0.2, "the floor is lit without the rod: {lit:?}");
    assert!(shadowed[0] < 0.01, "the rod's shadow: {shadowed:?}");
}
