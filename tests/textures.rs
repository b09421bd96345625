//! Texture plugins through the host: ray footprints reach the textures (MIP mapping smooths a
//! receding floor) and textures drive reflectivity.

mod common;

use common::*;

/// Variance of the luminance of the rows just below the horizon.
fn far_floor_variance(filter: &str) -> f64 {
    let dir = temp_dir(&format!("mip-{filter}"));
    std::fs::copy(
        root().join("scenes/textures/card.png"),
        dir.join("card.png"),
    )
    .unwrap();
    let scene = format!(
        r#"Scene(
        camera: (position: (0, 1, 0), look_at: (0, 0.6, 10), fov: 30),
        background: (0, 0, 0),
        lights: [Directional(direction: (0, -1, 0), shadows: false)],
        textures: {{ "card": (plugin: "image", params: (file: "card.png", mapping: planar, scale: 0.5, filter: {filter})) }},
        materials: {{ "floor": (texture: "card", ambient: 0, diffuse: 1) }},
        objects: [(plugin: "plane", params: (normal: (0, 1, 0)), material: "floor")],
    )"#
    );
    let fb = render_text(&dir, &scene, |d| {
        d.render.width = 160;
        d.render.height = 120;
    });
    // The horizon is at the image centre (camera looks 2.3 degrees down over a 30 degree fov:
    // about row 69); sample the floor just below it.
    let mut v = Vec::new();
    for y in 72..80 {
        for x in 0..160 {
            let p = fb.pixel(x, y);
            v.push((p[0] + p[1] + p[2]) as f64 / 3.0);
        }
    }
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    assert!(mean > 0.05, "the floor is black near the horizon");
    v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / v.len() as f64
}

#[test]
fn mip_mapping_smooths_the_distance() {
    let nearest = far_floor_variance("nearest");
    let mip = far_floor_variance("mip");
    assert!(
        mip * 4.0 < nearest,
        "mip variance {mip} vs nearest {nearest}"
    );
}

#[test]
fn a_texture_drives_reflectivity() {
    // A mirror whose reflectivity comes from a checker: tiles alternate between reflecting the
    // red wall behind the camera and showing the dark base colour.
    let dir = temp_dir("reflect-texture");
    let scene = r#"Scene(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), fov: 40),
        background: (0, 0, 0),
        textures: { "tiles": (plugin: "checker", params: (scale: 0.5, even: 1.0, odd: 0.0)) },
        materials: {
            "mirror": (color: (0, 0, 0), ambient: 0, diffuse: 0, reflect: 1, reflect_texture: "tiles"),
            "red": (color: (1, 0, 0), ambient: 1, diffuse: 0),
        },
        objects: [
            (plugin: "plane", params: (point: (0, 0, 3), normal: (0, 0, -1)), material: "mirror"),
            (plugin: "plane", params: (point: (0, 0, -3), normal: (0, 0, 1)), material: "red"),
        ],
    )"#;
    let fb = render_text(&dir, scene, |d| {
        d.render.width = 64;
        d.render.height = 64;
    });
    let red = (0..64)
        .flat_map(|y| (0..64).map(move |x| (x, y)))
        .filter(|&(x, y)| fb.pixel(x, y)[0] > 0.9)
        .count();
    let black = (0..64)
        .flat_map(|y| (0..64).map(move |x| (x, y)))
        .filter(|&(x, y)| fb.pixel(x, y)[0] < 0.1)
        .count();
    assert!(
        red > 1000 && black > 1000,
        "red {red}, black {black} of 4096"
    );
}

/// An image that turns out not to decode (its header is fine, its data cut short) used to render
/// magenta with exit status 0, replacing the output; now the render fails with one error line
/// naming the texture and the decoder's reason, and the existing output stays as it was.
#[test]
fn a_truncated_image_fails_the_render_and_keeps_the_output() {
    let dir = temp_dir("truncated-texture");
    let img = image::RgbImage::from_fn(64, 64, |x, y| {
        image::Rgb([(x * 4) as u8, (y * 4) as u8, ((x * y) % 251) as u8])
    });
    img.save(dir.join("full.png")).unwrap();
    let bytes = std::fs::read(dir.join("full.png")).unwrap();
    std::fs::write(dir.join("half.png"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.join("out.png"), b"earlier image").unwrap();
    std::fs::write(
        dir.join("t.ron"),
        r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
    lights: [Point(position: (0, 5, -5))],
    textures: { "t": (plugin: "image", params: (file: "half.png", mapping: spherical, center: (0, 0, 0))) },
    materials: { "m": (texture: "t") },
    objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1), material: "m")],
    render: (width: 16, height: 16, outputs: [(path: "out.png")]),
)"#,
    )
    .unwrap();
    let out = run(&["render", dir.join("t.ron").to_str().unwrap()]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    // One error line: where the texture is, its name and plugin, and the decoder's reason.
    let half = dir.join("half.png");
    assert_eq!(
        e,
        format!(
            "luxon: error: {}:4:48: texture `t` (plugin `image`) failed during the render: \
             cannot decode image `{}`: unexpected end of file\n",
            dir.join("t.ron").display(),
            half.display()
        )
    );
    assert_eq!(
        std::fs::read(dir.join("out.png")).unwrap(),
        b"earlier image"
    );
}
