//! The README's molecule walkthrough renders as the README says it does.

mod common;

use common::*;

/// The `ron` block after the README's "tested by tests/readme.rs" marker.
fn readme_scene() -> String {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let at = readme
        .find("<!-- tested by tests/readme.rs")
        .expect("marker in README.md");
    let start = readme[at..].find("```ron\n").unwrap() + at + "```ron\n".len();
    let end = readme[start..].find("```").unwrap() + start;
    readme[start..end].to_string()
}

fn brightness(fb: &luxon::Framebuffer) -> f32 {
    let mut sum = 0.0;
    for y in 0..fb.height {
        for x in 0..fb.width {
            let p = fb.pixel(x, y);
            assert!(p.iter().all(|v| v.is_finite()));
            sum += p[0] + p[1] + p[2];
        }
    }
    sum / (3 * fb.width * fb.height) as f32
}

#[test]
fn molecule_walkthrough_renders_with_occlusion_and_transparency() {
    let dir = temp_dir("readme-molecule");
    let scene = readme_scene();
    let small = |d: &mut luxon_formats::SceneDesc| {
        d.render.width = 96;
        d.render.height = 60;
        d.render.samples = 1;
    };
    let with_ao = render_text(&dir, &scene, small);
    let without_ao = render_text(&dir, &scene, |d| {
        small(d);
        d.ambient_occlusion = None;
    });
    // Not a flat picture: the molecule stands out from the white background.
    let px = to_srgb8(&with_ao);
    let (min, max) = (px.iter().min().unwrap(), px.iter().max().unwrap());
    assert!(max - min > 100, "flat image: {min}..{max}");
    // Occlusion is the main light here: without it (and with the full direct light it scales
    // down) the picture changes.
    let (a, b) = (brightness(&with_ao), brightness(&without_ao));
    assert!(
        (a - b).abs() > 0.02,
        "occlusion changed nothing: {a} vs {b}"
    );
}
