//! Editing a retained scene by id (`luxon::api::Scene`): every edit, then a render, gives the
//! bits of a fresh scene built from the edited description; lights, materials, fog and ambient
//! occlusion change without a build; adding and removing objects builds once per commit;
//! removed and foreign ids are refused with their messages; a frozen scene refuses object
//! changes; a scene made from nothing renders as its `to_ron` text does.

mod common;

use common::*;
use luxon::api::{CommitReport, Context, ContextOptions, Renderer, RendererOptions, Scene};
use luxon::Error;
use luxon_formats::{fragment, SceneDesc};

const WIDTH: u32 = 48;

/// `scenes/spheres.ron`, small and with one sample (debug builds on two cores).
fn spheres() -> SceneDesc {
    let path = root().join("scenes/spheres.ron");
    let mut d = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    d.render.width = WIDTH;
    d.render.height = WIDTH * 2 / 3;
    d.render.samples = 1;
    d
}

fn context(desc: &SceneDesc) -> Context {
    api_context(desc, 2)
}

fn render(r: &Renderer, scene: &mut Scene, w: u32, h: u32) -> Result<Vec<u32>, Error> {
    api_render(r, scene, w, h).map(|px| bits(&px))
}

/// The edited scene's image, and whether a fresh scene of its description gives the same bits.
fn same_as_fresh(ctx: &Context, r: &Renderer, scene: &mut Scene) -> (Vec<u32>, bool) {
    let (w, h) = (WIDTH, WIDTH * 2 / 3);
    let got = render(r, scene, w, h).unwrap_or_else(|e| panic!("{e}"));
    let mut fresh = Scene::from_desc(ctx, scene.desc().clone()).unwrap();
    let want = render(r, &mut fresh, w, h).unwrap_or_else(|e| panic!("{e}"));
    let same = got == want;
    (got, same)
}

/// A commit that touched no geometry but took new shading.
fn shading_only(report: &CommitReport) {
    assert_eq!(report.rebuilt, 0, "{report:?}");
    assert_eq!(report.bvh_time, std::time::Duration::ZERO);
    assert!(report.shading, "{report:?}");
}

#[test]
fn light_edits_build_nothing_and_render_as_a_fresh_scene() {
    let desc = spheres();
    let ctx = context(&desc);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut scene = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let (before, _) = same_as_fresh(&ctx, &r, &mut scene);

    let ids = scene.lights();
    assert_eq!(ids.len(), 2, "the file's lights, in file order");
    scene
        .set_light_ron(ids[0], "Point(position: (-3, 6, -6), intensity: 1.1)")
        .unwrap();
    let added = scene
        .add_light_ron("Spot(position: (2, 5, -3), direction: (-0.3, -1, 0.5), angle: 40)")
        .unwrap();
    scene.remove_light(ids[1]).unwrap();
    shading_only(&scene.commit(&r).unwrap());
    let lights: Vec<_> = scene.desc().lights.iter().map(|l| &l.value).collect();
    let want = [
        fragment::light("Point(position: (-3, 6, -6), intensity: 1.1)").unwrap(),
        fragment::light("Spot(position: (2, 5, -3), direction: (-0.3, -1, 0.5), angle: 40)")
            .unwrap(),
    ];
    assert_eq!(lights, want.iter().collect::<Vec<_>>());
    assert_eq!(scene.lights(), vec![ids[0], added]);
    let (after, same) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(
        same,
        "edited lights differ from a fresh scene of the same description"
    );
    assert!(after != before, "the lights changed the image");

    // Removed and foreign ids are refused, and change nothing.
    let light = fragment::light("Point(position: (0, 5, 0))").unwrap();
    let e = scene.set_light(ids[1], light.clone()).unwrap_err();
    assert_eq!(e.to_string(), "light 1 was removed from this scene");
    let e = scene.remove_light(ids[1]).unwrap_err();
    assert_eq!(e.to_string(), "light 1 was removed from this scene");
    let other = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let e = scene.set_light(other.lights()[0], light).unwrap_err();
    assert_eq!(e.to_string(), "this light id belongs to another scene");
    // A new light takes the free slot under a new generation: the old id stays refused.
    let reused = scene.add_light_ron("Point(position: (0, 5, 0))").unwrap();
    assert_eq!(reused.to_string(), "light 1");
    assert!(scene.remove_light(ids[1]).is_err());
    scene.remove_light(reused).unwrap();
    // Bad text points into itself; a bad typed value says what it is.
    let e = scene
        .add_light_ron("Point(positon: (0, 5, 0))")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("<light>:1:7: unknown field `positon`"), "{e}");
    let mut bad = fragment::light("Point(position: (0, 5, 0))").unwrap();
    if let luxon_formats::LightDesc::Point { intensity, .. } = &mut bad {
        *intensity = f64::NAN;
    }
    let e = scene.add_light(bad).unwrap_err().to_string();
    assert!(e.starts_with("light: "), "{e}");
    assert_eq!(
        scene.lights(),
        vec![ids[0], added],
        "refused edits change nothing"
    );
    let (again, _) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(again == after);
}

#[test]
fn material_fog_and_occlusion_edits_build_nothing_and_render_as_a_fresh_scene() {
    let desc = spheres();
    let ctx = context(&desc);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut scene = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let (before, _) = same_as_fresh(&ctx, &r, &mut scene);

    let red = scene
        .set_material_ron(
            "red",
            "(color: (0.1, 0.7, 0.2), specular: 0.6, reflect: 0.3)",
        )
        .unwrap();
    assert_eq!(Some(red), scene.material("red"));
    shading_only(&scene.commit(&r).unwrap());
    let (recoloured, same) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(same, "a changed material differs from a fresh scene");
    assert!(recoloured != before);

    // A new material (no object uses it yet) needs no build either.
    let glow = scene
        .set_material_ron("glow", "(color: (1, 0.9, 0.5), ambient: 1)")
        .unwrap();
    assert_eq!(scene.material("glow"), Some(glow));
    shading_only(&scene.commit(&r).unwrap());
    let (_, same) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(same);

    scene
        .set_fog_ron("(mode: Exp(density: 0.08), color: (0.5, 0.5, 0.6))")
        .unwrap();
    scene
        .set_ambient_occlusion_ron("(samples: 4, distance: 2.0, intensity: 0.5)")
        .unwrap();
    shading_only(&scene.commit(&r).unwrap());
    let (fogged, same) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(same, "fog and occlusion differ from a fresh scene");
    assert!(fogged != recoloured);
    scene.set_fog(None).unwrap();
    scene.set_ambient_occlusion(None).unwrap();
    shading_only(&scene.commit(&r).unwrap());
    let (cleared, _) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(cleared == recoloured, "fog and occlusion removed");

    // Texture names must be the scene's; errors point into the text.
    let e = scene
        .set_material_ron("x", "(texture: \"nope\")")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("<material>:1:"), "{e}");
    assert!(e.ends_with("no texture named `nope`"), "{e}");
    let e = scene
        .set_material_ron("x", "(colour: (1, 1, 1))")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("<material>:1:2: unknown field `colour`"),
        "{e}"
    );
    let e = scene
        .set_fog_ron("(mode: Exp(density: -1))")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("<fog>:1:"), "{e}");
    assert!(
        scene.material("x").is_none(),
        "refused materials are not added"
    );
    // Another scene's material is refused where it is used.
    let other = Scene::from_desc(&ctx, desc).unwrap();
    let e = scene
        .add_plugin_object("sphere", "(radius: 1)", other.material("red"), None)
        .unwrap_err();
    assert_eq!(e.to_string(), "this material id belongs to another scene");
}

#[test]
fn object_changes_build_once_per_commit_and_render_as_a_fresh_scene() {
    let desc = spheres();
    let ctx = context(&desc);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut scene = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let (before, _) = same_as_fresh(&ctx, &r, &mut scene);
    let file_objects = scene.objects();
    assert_eq!(file_objects.len(), 4);

    // Two added and one of the file's removed: one build.
    let blue = scene.material("blue");
    let small = scene
        .add_plugin_object(
            "sphere",
            "(center: (0.6, 0.3, -2), radius: 0.3)",
            blue,
            None,
        )
        .unwrap();
    let big = scene
        .add_plugin_object(
            "sphere",
            "(center: (-0.8, 0.4, -2.2), radius: 0.4)",
            None,
            None,
        )
        .unwrap();
    scene.remove(file_objects[2]).unwrap();
    let report = scene.commit(&r).unwrap();
    assert_eq!(report.rebuilt, 1, "{report:?}");
    assert_eq!(scene.commit(&r).unwrap().rebuilt, 0, "nothing left to do");
    let (edited, same) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(same, "edited objects differ from a fresh scene");
    assert!(edited != before);
    let plugins: Vec<_> = scene
        .desc()
        .objects
        .iter()
        .map(|o| &o.value.call.params)
        .collect();
    assert_eq!(plugins.len(), 5);
    assert_eq!(plugins[3], "(center: (0.6, 0.3, -2), radius: 0.3)");

    // Removing one builds once more.
    scene.remove(big).unwrap();
    assert_eq!(scene.commit(&r).unwrap().rebuilt, 1);
    let (_, same) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(same);
    assert_eq!(
        scene.objects(),
        vec![file_objects[0], file_objects[1], file_objects[3], small]
    );
    let e = scene.remove(big).unwrap_err().to_string();
    assert_eq!(e, "object 5 was removed from this scene");
    let e = scene.remove(file_objects[2]).unwrap_err().to_string();
    assert_eq!(e, "object 2 was removed from this scene");
    let other = Scene::from_desc(&ctx, desc).unwrap();
    let e = scene.remove(other.objects()[0]).unwrap_err().to_string();
    assert_eq!(e, "this object id belongs to another scene");

    // The plugin reads the parameters at the commit: its error points into them.
    let e = scene
        .add_plugin_object("no-such-plugin", "()", None, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no-such-plugin"), "{e}");
    let bad = scene
        .add_plugin_object("sphere", "(radus: 1)", None, None)
        .unwrap();
    let e = scene.commit(&r).unwrap_err().to_string();
    assert!(e.starts_with(&format!("<{bad}>:1:2:")), "{e}");
    scene.remove(bad).unwrap();
    assert_eq!(scene.commit(&r).unwrap().rebuilt, 1);
    let (_, same) = same_as_fresh(&ctx, &r, &mut scene);
    assert!(same);
}

#[test]
fn a_scene_from_nothing_needs_a_camera_and_renders_as_its_ron_text() {
    let dir = temp_dir("api-edit-new");
    ensure_plugins();
    let ctx = Context::new(ContextOptions {
        threads: 2,
        ..Default::default()
    })
    .unwrap();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut scene = Scene::new(&ctx);
    let e = scene.commit(&r).unwrap_err().to_string();
    assert!(e.starts_with("this scene has no camera"), "{e}");

    scene
        .set_camera_ron("(position: (0, 1, -5), look_at: (0, 0.5, 0))")
        .unwrap();
    scene.set_background([0.2, 0.3, 0.5]).unwrap();
    scene
        .add_light_ron("Point(position: (-4, 6, -5), intensity: 0.9)")
        .unwrap();
    let red = scene
        .set_material_ron("red", "(color: (0.8, 0.1, 0.1), specular: 0.5)")
        .unwrap();
    scene
        .add_plugin_object(
            "sphere",
            "(center: (0, 0.8, 0), radius: 0.8)",
            Some(red),
            None,
        )
        .unwrap();
    scene
        .add_plugin_object("plane", "(point: (0, 0, 0), normal: (0, 1, 0))", None, None)
        .unwrap();
    let (w, h) = (32, 24);
    let got = render(&r, &mut scene, w, h).unwrap();
    assert!(
        got.iter().collect::<std::collections::HashSet<_>>().len() > 8,
        "not blank"
    );

    // The text `to_ron` writes is a scene file that renders the same bits.
    let text = scene.to_ron().unwrap();
    let path = dir.join("dump.ron");
    std::fs::write(&path, &text).unwrap();
    let mut loaded = Scene::load(&ctx, &path).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert!(render(&r, &mut loaded, w, h).unwrap() == got, "{text}");
}

#[test]
fn a_frozen_scene_refuses_object_changes_but_takes_lights() {
    let dir = temp_dir("api-edit-frozen");
    let path = dir.join("ball.nff");
    std::fs::write(
        &path,
        "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 32 24\n\
         b 0.2 0.3 0.6\nl 4 -4 6\nf 0.9 0.2 0.2 0.6 0.4 30 0 0\ns 0 0 1 1\n",
    )
    .unwrap();
    let desc = luxon_formats::load(&path).unwrap();
    let ctx = context(&desc);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut frozen = Scene::from_desc_frozen(&ctx, desc.clone()).unwrap();
    render(&r, &mut frozen, 32, 24).unwrap();
    let e = frozen
        .add_plugin_object("sphere", "(radius: 1)", None, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("objects cannot change: this scene's imported geometry was consumed at load"),
        "{e}"
    );
    frozen
        .add_light_ron("Point(position: (-4, -4, 6), intensity: 0.5)")
        .unwrap();
    shading_only(&frozen.commit(&r).unwrap());
    let got = render(&r, &mut frozen, 32, 24).unwrap();
    let mut kept = Scene::from_desc(&ctx, desc).unwrap();
    kept.add_light_ron("Point(position: (-4, -4, 6), intensity: 0.5)")
        .unwrap();
    assert!(render(&r, &mut kept, 32, 24).unwrap() == got);
}

#[test]
fn an_animated_scene_keeps_its_lights_in_place_and_its_frame_after_a_light_edit() {
    let path = root().join("scenes/carousel.ron");
    let mut desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    desc.render.samples = 1;
    let ctx = context(&desc);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut scene = Scene::from_desc(&ctx, desc).unwrap();
    let (w, h) = (24, 16);
    scene.set_frame(9).unwrap();
    render(&r, &mut scene, w, h).unwrap();
    let id = scene.lights()[0];
    let e = scene.remove_light(id).unwrap_err().to_string();
    assert!(e.starts_with("this scene is animated"), "{e}");
    let light = scene.desc().lights[0].value.clone();
    scene.set_light(id, light.clone()).unwrap();
    // The animation holds the lights: a build, back at frame 9.
    assert_eq!(scene.commit(&r).unwrap().rebuilt, 1);
    let got = render(&r, &mut scene, w, h).unwrap();
    let mut fresh = Scene::from_desc(&ctx, scene.desc().clone()).unwrap();
    fresh.set_frame(9).unwrap();
    assert!(render(&r, &mut fresh, w, h).unwrap() == got);
}
