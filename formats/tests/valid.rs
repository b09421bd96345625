//! A full valid scene loads into the expected `SceneDesc`, positions and params text included.

use std::path::{Path, PathBuf};

use luxon_formats::Attenuation;
use luxon_formats::*;

const SCENE: &str = r#"// A comment
Scene(
    plugin_path: ["../target/release", "/opt/luxon/plugins"],
    camera: (
        position: (0, 2, -6),
        look_at: (0, 0, 0),
        fov: 40,
        aspect: 1.5,
    ),
    background: (0.05, 0.05, 0.1),
    lights: [
        Point(position: (5, 5, -5), color: (1, 1, 1), intensity: 1.0, shadows: true),
        Directional(direction: (-1, -1, 1), intensity: 0.5),
    ],
    textures: {
        "checks": (plugin: "checker", params: (scale: 0.5, even: (1,1,1))),
    },
    materials: {
        "red": (color: (0.8, 0.1, 0.1), specular: 0.5, shininess: 40, highlight: Blinn),
        "glass": (color: (1, 1, 1), diffuse: 0.0, ambient: 0, specular: 0.8, reflect: 0.05, transmit: 0.95, ior: 1.5),
        "floor": (texture: "checks"),
    },
    objects: [
        (plugin: "sphere", params: (center: (0, 1, 0), radius: 1.0), material: "glass"),
        (plugin: "plane", params: (point: (0, 0, 0), /* up */ normal: (0, 1, 0)), material: "floor"),
        (plugin: "torus"),
    ],
    render: (
        width: 640, height: 480, samples: 4, max_depth: 8, min_weight: 0.002, frame: 3, time: 0.5,
        outputs: [ (path: "out.png"), (path: "/tmp/out.exr", plugin: "exr", params: (half: true)) ],
        parallel: (mode: Threads, threads: 2, decomposition: BlockCyclic, tile_size: 32, io: Sync),
    ),
)
"#;

fn load_scene() -> SceneDesc {
    load_ron_str(SCENE, Path::new("/scenes/demo.ron")).expect("the scene is valid")
}

fn at(o: &Origin) -> (u32, u32) {
    assert_eq!(*o.file, PathBuf::from("/scenes/demo.ron"));
    (o.line, o.col)
}

#[test]
fn camera_background_and_lights() {
    let scene = load_scene();
    assert_eq!(scene.source, PathBuf::from("/scenes/demo.ron"));
    assert_eq!(at(&scene.camera.at), (4, 13));
    let camera = &scene.camera.value;
    assert_eq!(camera.position, [0.0, 2.0, -6.0]);
    assert_eq!(camera.look_at, [0.0; 3]);
    assert_eq!(camera.up, [0.0, 1.0, 0.0]);
    assert_eq!(camera.projection, Projection::Perspective { fov_deg: 40.0 });
    assert_eq!(camera.aspect, Some(1.5));
    assert_eq!(scene.background, BackgroundDesc::Color([0.05, 0.05, 0.1]));

    assert_eq!(scene.lights.len(), 2);
    assert_eq!(at(&scene.lights[0].at), (12, 9));
    assert_eq!(
        scene.lights[1].value,
        LightDesc::Directional {
            direction: [-1.0, -1.0, 1.0],
            color: [1.0; 3],
            intensity: 0.5,
            shadows: true,
        }
    );
    assert_eq!(at(&scene.lights[1].at), (13, 9));
}

#[test]
fn textures_and_materials() {
    let scene = load_scene();
    let (name, checks) = &scene.textures[0];
    assert_eq!(name, "checks");
    assert_eq!(at(&checks.at), (16, 9));
    assert_eq!(checks.value.plugin.value, "checker");
    assert_eq!(at(&checks.value.plugin.at), (16, 28));
    assert_eq!(checks.value.params, "(scale: 0.5, even: (1,1,1))");
    assert_eq!(at(&checks.value.params_at), (16, 47));

    let names: Vec<&str> = scene.materials.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["red", "glass", "floor"]);
    let red = &scene.materials[0].1.value;
    assert_eq!(red.color, [0.8, 0.1, 0.1]);
    assert_eq!(red.highlight, Highlight::Blinn);
    assert_eq!(red.shininess, 40.0);
    assert_eq!(red.ambient, MaterialDesc::default().ambient);
    let glass = &scene.materials[1].1.value;
    assert_eq!((glass.transmit, glass.ior, glass.diffuse), (0.95, 1.5, 0.0));
    let floor = &scene.materials[2].1;
    assert_eq!(at(&floor.at), (21, 9));
    let texture = floor.value.texture.as_ref().unwrap();
    assert_eq!(texture.value, "checks");
    assert_eq!(at(&texture.at), (21, 28));
    assert_eq!(floor.value.color, MaterialDesc::default().color);
}

#[test]
fn objects_keep_params_verbatim() {
    let scene = load_scene();
    assert_eq!(scene.objects.len(), 3);
    let plane = &scene.objects[1];
    assert_eq!(at(&plane.at), (25, 9));
    assert_eq!(plane.value.call.plugin.value, "plane");
    assert_eq!(at(&plane.value.call.plugin.at), (25, 18));
    assert_eq!(
        plane.value.call.params,
        "(point: (0, 0, 0), /* up */ normal: (0, 1, 0))"
    );
    assert_eq!(at(&plane.value.call.params_at), (25, 35));
    let material = plane.value.material.as_ref().unwrap();
    assert_eq!(material.value, "floor");
    assert_eq!(at(&material.at), (25, 93));

    // No params: "()" at the entry; no material: None.
    let torus = &scene.objects[2].value;
    assert_eq!(torus.call.params, "()");
    assert_eq!(at(&torus.call.params_at), (26, 9));
    assert_eq!(torus.material, None);
}

#[test]
fn render_outputs_and_paths() {
    let scene = load_scene();
    let r = &scene.render;
    assert_eq!(
        (r.width, r.height, r.samples, r.max_depth),
        (640, 480, 4, 8)
    );
    assert_eq!((r.min_weight, r.frame, r.time), (0.002, 3, 0.5));
    assert_eq!(r.adaptive, None);
    assert_eq!(
        r.parallel,
        ParallelDesc {
            mode: ParallelMode::Threads,
            threads: Some(2),
            decomposition: Decomposition::BlockCyclic,
            tile_size: 32,
            io: OutputIo::Sync,
            frames: FrameGroups::Auto,
        }
    );
    assert_eq!(r.outputs.len(), 2);
    assert_eq!(r.outputs[0].path, PathBuf::from("/scenes/out.png"));
    assert_eq!(r.outputs[0].plugin, None);
    assert_eq!(r.outputs[0].params, "()");
    assert_eq!(r.outputs[1].path, PathBuf::from("/tmp/out.exr"));
    assert_eq!(r.outputs[1].plugin.as_ref().unwrap().value, "exr");
    assert_eq!(r.outputs[1].params, "(half: true)");
    assert_eq!(at(&r.outputs[1].params_at), (30, 85));
    assert_eq!(
        scene.plugin_path,
        [
            PathBuf::from("/scenes/../target/release"),
            PathBuf::from("/opt/luxon/plugins")
        ]
    );
}

#[test]
fn defaults_fill_what_is_left_out() {
    let text = "(camera: (position: (0, 0, -1), look_at: (0, 0, 0), zoom: 2))";
    let scene = load_ron_str(text, Path::new("min.ron")).unwrap();
    assert_eq!(
        scene.camera.value.projection,
        Projection::PerspectiveZoom { zoom: 2.0 }
    );
    assert_eq!(scene.camera.value.aspect, None);
    assert_eq!(scene.background, BackgroundDesc::Color([0.0; 3]));
    assert_eq!(scene.render, RenderDesc::default());
    assert!(scene.lights.is_empty() && scene.objects.is_empty());

    let text = "Scene(camera: (position: (0, 0, -1), look_at: (0, 0, 0)), \
                lights: [Point(position: (1, 2, 3))])";
    let scene = load_ron_str(text, Path::new("min.ron")).unwrap();
    assert_eq!(
        scene.camera.value.projection,
        Projection::Perspective { fov_deg: 45.0 }
    );
    assert_eq!(
        scene.lights[0].value,
        LightDesc::Point {
            position: [1.0, 2.0, 3.0],
            color: [1.0; 3],
            intensity: 1.0,
            shadows: true,
            attenuation: Attenuation::default(),
        }
    );
}

#[test]
fn load_reads_files_and_rejects_other_formats() {
    let dir = std::env::temp_dir().join(format!("luxon-formats-load-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("demo.ron");
    std::fs::write(&file, SCENE).unwrap();
    let scene = load(&file).unwrap();
    assert_eq!(scene.render.outputs[0].path, dir.join("out.png"));
    assert_eq!(*scene.objects[0].at.file, file);

    let error = load(&dir.join("model.xyz")).unwrap_err();
    assert!(error.origin().is_none());
    let message = error.to_string();
    assert!(
        message.contains("`.nff`") && message.contains("`.ron`"),
        "{message}"
    );

    let error = load(&dir.join("missing.ron")).unwrap_err();
    assert!(matches!(error, SceneError::File { .. }), "{error}");
    assert!(error.origin().is_none());
    assert!(error
        .to_string()
        .ends_with("missing.ron` does not exist; expected a scene file"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn adaptive_supersampling_settings() {
    let scene = |render: &str| {
        load_ron_str(
            &format!(
                "Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), render: ({render}))"
            ),
            Path::new("/scenes/a.ron"),
        )
        .expect("valid")
        .render
        .adaptive
    };
    assert_eq!(
        scene("adaptive: (threshold: 0.05, max_depth: 4)"),
        Some(AdaptiveDesc {
            threshold: 0.05,
            max_depth: 4
        })
    );
    // The depth defaults to 3.
    assert_eq!(
        scene("samples: 16, adaptive: (threshold: 0)"),
        Some(AdaptiveDesc {
            threshold: 0.0,
            max_depth: 3
        })
    );
}

#[test]
fn gradient_backgrounds() {
    let load = |bg: &str| {
        let text =
            format!("(camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n background: {bg})");
        load_ron_str(&text, Path::new("g.ron"))
            .unwrap_or_else(|e| panic!("{e}"))
            .background
    };
    assert_eq!(
        load(
            "Gradient(kind: OrthoPlane, up: (0, 0, 2), top: 3, bottom: -1, top_color: (1, 1, 1), \
             bottom_color: (0, 0, 0.5))"
        ),
        BackgroundDesc::Gradient(GradientDesc {
            kind: GradientKind::OrthoPlane,
            up: [0.0, 0.0, 2.0],
            top: 3.0,
            bottom: -1.0,
            top_color: [1.0; 3],
            bottom_color: [0.0, 0.0, 0.5],
        })
    );
    // `up` defaults to +y; the name may be left out, as for any RON struct; top = bottom is
    // a sharp horizon.
    let BackgroundDesc::Gradient(g) =
        load("(kind: Sphere, top: 0, bottom: 0, top_color: (1, 0, 0), bottom_color: (0, 0, 1))")
    else {
        panic!("not a gradient");
    };
    assert_eq!(
        (g.kind, g.up, g.top),
        (GradientKind::Sphere, [0.0, 1.0, 0.0], 0.0)
    );
    // The colour keeps its syntax.
    assert_eq!(
        load("(0.5, 0.25, 1)"),
        BackgroundDesc::Color([0.5, 0.25, 1.0])
    );
}

/// `parallel: (frames: ...)`: each spelling, its default, and the text `to_ron` writes back.
#[test]
fn frame_groups_parse_and_round_trip() {
    let cases = [
        ("", FrameGroups::Auto),
        (", frames: Whole", FrameGroups::Whole),
        (", frames: Groups(2)", FrameGroups::Groups(2)),
        (", frames: Shared", FrameGroups::Shared),
    ];
    for (text, want) in cases {
        let scene = format!(
            "(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), \
             render: (parallel: (mode: Mpi{text})))"
        );
        let desc = load_ron_str(&scene, Path::new("/scenes/f.ron")).unwrap();
        assert_eq!(desc.render.parallel.frames, want, "{text}");
        let written = to_ron(&desc, Path::new("/scenes")).unwrap();
        let again = load_ron_str(&written, Path::new("/scenes/f.ron")).unwrap();
        assert_eq!(again.render.parallel.frames, want, "{written}");
    }
}

#[test]
fn frame_group_sizes() {
    use FrameGroups::*;
    // Auto: whole frames when every rank can have one, else every rank on every frame.
    assert_eq!(Auto.group_size(48, 2), 1);
    assert_eq!(Auto.group_size(2, 2), 1);
    assert_eq!(Auto.group_size(3, 4), 4);
    assert_eq!(Whole.group_size(1, 4), 1);
    assert_eq!(Shared.group_size(48, 3), 3);
    assert_eq!(Groups(2).group_size(48, 3), 2);
    // More than the ranks: one group of all.
    assert_eq!(Groups(8).group_size(48, 3), 3);
    assert_eq!(Whole.group_size(5, 0), 1);
}
