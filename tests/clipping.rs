//! Clip groups cut objects away; what is behind a cut surface shows through it.

mod common;

use common::*;

fn render(name: &str, clip_normal: &str, fog: bool) -> luxon::Framebuffer {
    let dir = temp_dir(name);
    let scene = format!(
        r#"Scene(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 30),
        background: (0, 0, 1),
        {fog}
        clip_groups: {{ "cut": [(point: (0, 0, 5), normal: {clip_normal})] }},
        materials: {{ "red": (color: (1, 0, 0), ambient: 1, diffuse: 0) }},
        objects: [(plugin: "sphere", params: (center: (0, 0, 5), radius: 1), material: "red", clip: "cut")],
    )"#,
        fog = if fog {
            "fog: (mode: Exp(density: 0.1), color: (0, 0, 0)),"
        } else {
            ""
        }
    );
    render_text(&dir, &scene, |d| {
        d.render.width = 21;
        d.render.height = 21;
    })
}

#[test]
fn the_upper_half_is_cut_away() {
    let fb = render("clip-upper", "(0, 1, 0)", false);
    // Above the centre (y > 0 in the world): background; below: the sphere.
    assert_eq!(fb.pixel(10, 7)[..3], [0.0, 0.0, 1.0]);
    assert_eq!(fb.pixel(10, 13)[..3], [1.0, 0.0, 0.0]);
}

#[test]
fn a_cut_front_shows_the_inside_wall() {
    // Cutting the half facing the camera: the centre ray meets the far wall at t = 6, not the
    // front at t = 4; fog tells the distances apart.
    let whole = render("clip-none", "(0, 0, 1)", true).pixel(10, 10)[0];
    let cut = render("clip-front", "(0, 0, -1)", true).pixel(10, 10)[0];
    assert!(((whole - (-0.4f32).exp()).abs()) < 1e-4, "{whole}");
    assert!(((cut - (-0.6f32).exp()).abs()) < 1e-4, "{cut}");
}

#[test]
fn an_unknown_clip_group_is_an_error_with_a_suggestion() {
    let dir = temp_dir("clip-unknown");
    let p = dir.join("s.ron");
    std::fs::write(
        &p,
        r#"Scene(camera: (position: (0, 0, 0), look_at: (0, 0, 1)),
    clip_groups: { "slice": [(point: (0, 0, 0), normal: (1, 0, 0))] },
    objects: [(plugin: "sphere", params: (center: (0, 0, 5), radius: 1), clip: "slce")])"#,
    )
    .unwrap();
    let e = luxon_formats::load(&p).unwrap_err().to_string();
    assert!(
        e.contains("s.ron:3:80") && e.contains("did you mean `slice`"),
        "{e}"
    );
}
