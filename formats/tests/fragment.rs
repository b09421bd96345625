//! Scene parts read from RON fragments (`fragment`) and printed as fragments (`print`): each
//! kind's good case, its errors at the fragment's own `<kind>:line:col`, and the round trip
//! of every camera, light, material, fog, ambient occlusion, clip group and render block of
//! the shipped scenes.

use std::path::{Path, PathBuf};

use luxon_formats::desc::*;
use luxon_formats::{fragment, print, SceneError};

/// The error's text, which must be there.
fn error<T: std::fmt::Debug>(r: Result<T, SceneError>) -> String {
    match r {
        Ok(v) => panic!("expected an error, got {v:?}"),
        Err(e) => e.to_string(),
    }
}

/// `message` starts with `at` and contains `says`.
fn is_at(message: &str, at: &str, says: &str) {
    assert!(
        message.starts_with(&format!("{at}: ")) && message.contains(says),
        "expected `{at}: ...{says}...`, got `{message}`"
    );
}

const CAMERA: &str = "(position: (0.0, 0.0, 5.0), look_at: (0.0, 0.0, 0.0), fov: 40.0)";

#[test]
fn a_camera_reads_and_its_errors_point_into_the_fragment() {
    let c = fragment::camera(CAMERA).unwrap();
    assert_eq!(c.position, [0.0, 0.0, 5.0]);
    assert_eq!(c.projection, Projection::Perspective { fov_deg: 40.0 });
    let e = error(fragment::camera(
        "(positon: (0.0, 0.0, 5.0), look_at: (0.0, 0.0, 0.0))",
    ));
    is_at(
        &e,
        "<camera>:1:2",
        "unknown field `positon` in `Camera`; did you mean `position`?",
    );
    let e = error(fragment::camera(
        "(position: (0.0, NaN, 5.0), look_at: (0.0, 0.0, 0.0))",
    ));
    is_at(&e, "<camera>:1:18", "NaN is not allowed here");
    let e = error(fragment::camera(
        "(position: (0.0, 0.0, 5.0), look_at: (0.0, 0.0, 0.0), fov: 190.0)",
    ));
    is_at(
        &e,
        "<camera>:1:60",
        "`fov` is 190.0; expected degrees between 0 and 180",
    );
    // Lines after the first keep their columns.
    let e = error(fragment::camera(
        "(position: (0.0, 0.0, 5.0),\n look_at: (0.0, 0.0, 0.0), fov: 190.0)",
    ));
    is_at(&e, "<camera>:2:33", "`fov` is 190.0");
    let e = error(fragment::camera(
        "(position: (0.0, 0.0, 5.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 0.0, 0.0))",
    ));
    is_at(&e, "<camera>:1:59", "the camera's `up` has zero length");
    let e = error(fragment::camera("(position: (0.0, 0.0, 5.0)"));
    is_at(&e, "<camera>:1:27", "missing field `look_at` in `Camera`");
}

#[test]
fn a_fragment_includes_nothing_and_is_one_value() {
    // A real scene file on disk: the fragment's source holds only the fragment.
    let real = scenes().join("spheres.ron");
    assert!(real.is_file());
    let text = format!("{CAMERA}, include: [{:?}]", real.display().to_string());
    let e = error(fragment::camera(&text));
    // At the path's string, just after `include: [`.
    let col = CAMERA.len() + ", include: [".len() + 1;
    is_at(
        &e,
        &format!("<camera>:1:{col}"),
        "cannot read included file",
    );
    let e = error(fragment::camera(&format!(
        "{CAMERA}, background: (1.0, 1.0, 1.0)"
    )));
    is_at(
        &e,
        "<camera>:1:1",
        "the camera fragment also sets `background`",
    );
    let e = error(fragment::camera(&format!(
        "{CAMERA}, lights: [Point(position: (1.0, 2.0, 3.0))]"
    )));
    is_at(&e, "<camera>:1:1", "also sets `lights`");
    let two = "Point(position: (1.0, 2.0, 3.0)), Point(position: (1.0, 2.0, 3.0))";
    is_at(
        &error(fragment::light(two)),
        "<light>:1:1",
        "expected one light",
    );
    let e = error(fragment::light(
        "Point(position: (1.0, 2.0, 3.0))], include: [\"x.ron\"], lights: [",
    ));
    is_at(&e, "<light>:1:56", "field `lights` is given twice");
}

#[test]
fn a_light_reads_and_its_errors_point_into_the_fragment() {
    let l = fragment::light("Point(position: (1.0, 2.0, 3.0), intensity: 2.0)").unwrap();
    match l {
        LightDesc::Point {
            position,
            intensity,
            ..
        } => assert_eq!((position, intensity), ([1.0, 2.0, 3.0], 2.0)),
        other => panic!("expected a point light, got {other:?}"),
    }
    let e = error(fragment::light("Point(positon: (1.0, 2.0, 3.0))"));
    is_at(
        &e,
        "<light>:1:7",
        "unknown field `positon` in `Point`; did you mean `position`?",
    );
    let e = error(fragment::light(
        "Point(position: (1.0, 2.0, 3.0), intensity: NaN)",
    ));
    is_at(&e, "<light>:1:45", "NaN is not allowed here");
    let e = error(fragment::light(
        "SphereLight(center: (1.0, 2.0, 3.0), radius: 1.0, samples: -4)",
    ));
    is_at(
        &e,
        "<light>:1:60",
        "`samples` is -4; expected a whole number from 1 to 4096",
    );
    let e = error(fragment::light(
        "Point(name: \"key\", position: (1.0, 2.0, 3.0))",
    ));
    is_at(&e, "<light>:1:13", "a light fragment takes no `name`");
    // A spot's cone: above 0, at most 179 degrees, said in plain numbers.
    let spot = |angle: &str| {
        error(fragment::light(&format!(
            "Spot(position: (0.0, 4.0, 0.0), direction: (0.0, -1.0, 0.0), angle: {angle})"
        )))
    };
    is_at(
        &spot("190"),
        "<light>:1:69",
        "`angle` is 190; expected a value from 0 to 179",
    );
    is_at(
        &spot("0"),
        "<light>:1:69",
        "`angle` is 0; expected a number greater than 0",
    );
}

#[test]
fn a_material_reads_and_its_errors_point_into_the_fragment() {
    let m =
        fragment::material("(color: (0.8, 0.2, 0.2), specular: 0.5, texture: \"wood\")").unwrap();
    assert_eq!(m.color, [0.8, 0.2, 0.2]);
    // The texture is the holding scene's to define; its position is in the fragment.
    let t = m.texture.unwrap();
    assert_eq!(t.value, "wood");
    assert_eq!((t.at.to_string()), "<material>:1:50");
    let e = error(fragment::material("(colour: (0.8, 0.2, 0.2))"));
    is_at(
        &e,
        "<material>:1:2",
        "unknown field `colour` in `Material`; did you mean `color`?",
    );
    let e = error(fragment::material("(color: (0.8, NaN, 0.2))"));
    is_at(&e, "<material>:1:15", "NaN is not allowed here");
    let e = error(fragment::material("(color: (0.8, 0.2, 0.2), ior: -1.0)"));
    is_at(
        &e,
        "<material>:1:31",
        "`ior` is -1.0; expected a number greater than 0",
    );
}

#[test]
fn fog_ambient_occlusion_and_clip_planes_read_with_their_errors() {
    let f = fragment::fog("(mode: Exp(density: 0.1), color: (0.5, 0.5, 0.5))").unwrap();
    assert_eq!(f.color, [0.5, 0.5, 0.5]);
    let e = error(fragment::fog("(mode: Exp(densty: 0.1))"));
    is_at(
        &e,
        "<fog>:1:12",
        "unknown field `densty` in `Exp`; did you mean `density`?",
    );
    let e = error(fragment::fog("(mode: Exp(density: -0.1))"));
    is_at(&e, "<fog>:1:21", "`density` is -0.1");
    let a = fragment::ambient_occlusion("(samples: 16, distance: 2.0)").unwrap();
    assert_eq!((a.samples, a.max_distance), (16, 2.0));
    let e = error(fragment::ambient_occlusion("(samples: -1)"));
    is_at(&e, "<ambient_occlusion>:1:11", "`samples` is -1");
    let e = error(fragment::ambient_occlusion("(sample: 16)"));
    is_at(&e, "<ambient_occlusion>:1:2", "did you mean `samples`?");
    let p = fragment::clip_planes("[(point: (0.0, 0.0, 0.0), normal: (0.0, 1.0, 0.0))]").unwrap();
    assert_eq!(p.len(), 1);
    assert_eq!(p[0].normal, [0.0, 1.0, 0.0]);
    let e = error(fragment::clip_planes(
        "[(point: (0.0, 0.0, 0.0), normal: (0.0, 0.0, 0.0))]",
    ));
    is_at(
        &e,
        "<clip_planes>:1:35",
        "the clip plane's `normal` has zero length",
    );
    let e = error(fragment::clip_planes(
        "[(pont: (0.0, 0.0, 0.0), normal: (0.0, 1.0, 0.0))]",
    ));
    is_at(&e, "<clip_planes>:1:3", "did you mean `point`?");
}

#[test]
fn render_settings_read_without_what_the_target_and_renderer_decide() {
    let r = fragment::render_settings("(samples: 4, max_depth: 8, adaptive: (threshold: 0.05))")
        .unwrap();
    assert_eq!((r.samples, r.max_depth), (4, 8));
    assert_eq!(r.adaptive.map(|a| a.threshold), Some(0.05));
    let e = error(fragment::render_settings("(samples: 4,\n width: 640)"));
    is_at(
        &e,
        "<render_settings>:2:9",
        "`width` is not a render setting of an embedded scene; the target's size decides it",
    );
    let e = error(fragment::render_settings("(outputs: [(path: \"a.png\")])"));
    is_at(
        &e,
        "<render_settings>:1:11",
        "`outputs` is not a render setting of an embedded scene; write images with write_image",
    );
    let e = error(fragment::render_settings("(parallel: (threads: 2))"));
    is_at(
        &e,
        "<render_settings>:1:12",
        "`parallel` is not a render setting",
    );
    let e = error(fragment::render_settings("(samples: -2)"));
    is_at(&e, "<render_settings>:1:11", "`samples` is -2");
    let e = error(fragment::render_settings("(sampels: 2)"));
    is_at(&e, "<render_settings>:1:2", "did you mean `samples`?");
    let m = fragment::check_render_settings(&RenderDesc {
        samples: 0,
        ..RenderDesc::default()
    })
    .unwrap_err();
    assert!(m.starts_with("`samples` is 0"), "{m}");
}

#[test]
fn a_volume_render_block_reads_with_its_errors() {
    let r =
        fragment::volume_render("(transfer: (preset: \"hot\"), step: 0.5, clip: \"cut\")").unwrap();
    assert_eq!(r.step, Some(0.5));
    // The clip group is the holding scene's to define; its position is in the fragment.
    assert_eq!(r.clip.unwrap().at.to_string(), "<volume_render>:1:46");
    let e = error(fragment::volume_render(
        "(transfer: (preset: \"hot\"), stepp: 0.5)",
    ));
    is_at(&e, "<volume_render>:1:29", "did you mean `step`?");
    let e = error(fragment::volume_render(
        "(transfer: (preset: \"hot\"), step: NaN)",
    ));
    is_at(&e, "<volume_render>:1:35", "NaN is not allowed here");
    let e = error(fragment::volume_render(
        "(transfer: (preset: \"hot\"), step: -1.0)",
    ));
    is_at(&e, "<volume_render>:1:35", "`step` is -1.0");
    let e = error(fragment::volume_render("(transfer: (preset: \"hott\"))"));
    is_at(
        &e,
        "<volume_render>:1:21",
        "unknown transfer-function preset `hott`; did you mean `hot`?",
    );
}

#[test]
fn typed_values_obey_the_fragments_rules() {
    let good = fragment::camera(CAMERA).unwrap();
    assert_eq!(fragment::check_camera(&good), Ok(()));
    let bad = |f: &dyn Fn(&mut CameraDesc)| {
        let mut c = good.clone();
        f(&mut c);
        fragment::check_camera(&c).unwrap_err()
    };
    let m = bad(&|c| c.projection = Projection::Perspective { fov_deg: 190.0 });
    assert!(m.starts_with("`fov` is 190.0; expected degrees"), "{m}");
    let m = bad(&|c| c.up = [0.0; 3]);
    assert!(m.starts_with("the camera's `up` has zero length"), "{m}");
    let m = bad(&|c| c.position[1] = f64::NAN);
    assert!(m.contains("NaN is not allowed here"), "{m}");
    // The same rule as the text: the fragment and the check agree.
    let text = "(position: (0.0, 0.0, 5.0), look_at: (0.0, 0.0, 0.0), fov: 190.0)";
    let from_text = match fragment::camera(text).unwrap_err() {
        SceneError::At { message, .. } => message,
        e => panic!("{e}"),
    };
    assert_eq!(
        bad(&|c| c.projection = Projection::Perspective { fov_deg: 190.0 }),
        from_text
    );

    let light = fragment::light("SphereLight(center: (1.0, 2.0, 3.0), radius: 1.0)").unwrap();
    assert_eq!(fragment::check_light(&light), Ok(()));
    let mut many = light.clone();
    if let LightDesc::Sphere { samples, .. } = &mut many {
        *samples = 100_000;
    }
    let m = fragment::check_light(&many).unwrap_err();
    assert!(
        m.starts_with("`samples` is 100000; expected a whole number"),
        "{m}"
    );

    let material = MaterialDesc::default();
    assert_eq!(fragment::check_material(&material), Ok(()));
    let m = fragment::check_material(&MaterialDesc {
        ior: -1.0,
        ..material
    })
    .unwrap_err();
    assert!(m.starts_with("`ior` is -1.0"), "{m}");

    let fog = fragment::fog("(mode: Linear(start: 1.0, end: 5.0))").unwrap();
    assert_eq!(fragment::check_fog(&fog), Ok(()));
    let ao = fragment::ambient_occlusion("(samples: 4)").unwrap();
    assert_eq!(fragment::check_ambient_occlusion(&ao), Ok(()));
    let m = fragment::check_ambient_occlusion(&AoDesc { samples: 0, ..ao }).unwrap_err();
    assert!(m.starts_with("`samples` is 0"), "{m}");
    let plane = ClipPlaneDesc {
        point: [0.0; 3],
        normal: [0.0; 3],
    };
    let m = fragment::check_clip_planes(&[plane]).unwrap_err();
    assert!(
        m.starts_with("the clip plane's `normal` has zero length"),
        "{m}"
    );
}

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// The material with its texture names' positions left out.
fn unplaced(mut m: MaterialDesc) -> MaterialDesc {
    for t in [
        &mut m.texture,
        &mut m.reflect_texture,
        &mut m.transmit_texture,
    ]
    .into_iter()
    .flatten()
    {
        t.at = Origin {
            file: PathBuf::new().into(),
            line: 0,
            col: 0,
        };
    }
    m
}

#[test]
fn every_part_of_every_shipped_scene_prints_and_reads_back() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenes())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    assert!(files.len() > 20, "found only {} scenes", files.len());
    let (mut lights, mut materials, mut others) = (0, 0, 0);
    for file in &files {
        let scene = luxon_formats::load(file).unwrap_or_else(|e| panic!("{e}"));
        let name = file.display();
        let c = &scene.camera.value;
        let text = print::camera(c);
        assert_eq!(&fragment::camera(&text).unwrap(), c, "{name}: {text}");
        assert_eq!(fragment::check_camera(c), Ok(()), "{name}");
        for l in &scene.lights {
            let text = print::light(&l.value);
            assert_eq!(fragment::light(&text).unwrap(), l.value, "{name}: {text}");
            lights += 1;
        }
        for (m_name, m) in &scene.materials {
            let text = print::material(&m.value);
            let back = fragment::material(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(
                unplaced(back),
                unplaced(m.value.clone()),
                "{name}: material {m_name}: {text}"
            );
            materials += 1;
        }
        if let Some(f) = &scene.fog {
            assert_eq!(&fragment::fog(&print::fog(f)).unwrap(), f, "{name}");
            others += 1;
        }
        if let Some(a) = &scene.ambient_occlusion {
            let back = fragment::ambient_occlusion(&print::ambient_occlusion(a)).unwrap();
            assert_eq!(&back, a, "{name}");
            others += 1;
        }
        for (_, planes) in &scene.clip_groups {
            let back = fragment::clip_planes(&print::clip_planes(&planes.value)).unwrap();
            assert_eq!(back, planes.value, "{name}");
            others += 1;
        }
        for v in &scene.volumes {
            let Some(r) = &v.value.render else { continue };
            let text = print::volume_render(&r.value);
            let mut back = fragment::volume_render(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(fragment::check_volume_render(&back), Ok(()), "{name}");
            back.clip = back.clip.map(|c| Spanned {
                value: c.value,
                at: r.value.clip.clone().unwrap().at,
            });
            assert_eq!(back, r.value, "{name}: {text}");
            others += 1;
        }
        let r = &scene.render;
        let text = print::render_settings(r);
        let back = fragment::render_settings(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        // What the embedded scene's target and renderer decide is not printed.
        let expected = RenderDesc {
            width: back.width,
            height: back.height,
            outputs: back.outputs.clone(),
            parallel: back.parallel.clone(),
            ..r.clone()
        };
        assert_eq!(back, expected, "{name}: {text}");
    }
    // The scenes hold each kind (so the loop above checked something of each).
    assert!(
        lights > 20 && materials > 20 && others > 2,
        "{lights} {materials} {others}"
    );
}
