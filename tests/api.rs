//! The retained-scene API (`luxon::api`): its renders equal the library's one-shot path bit for
//! bit, a commit redoes only what changed, a moved camera keeps render space's origin, a
//! cancelled render does not spoil the next, and a render that faults leaves a scene that can
//! be rendered again.

mod common;

use common::*;
use luxon::api::{Color, Context, Plane, Renderer, RendererOptions, Scene, Target};
use luxon::Error;
use luxon_formats::SceneDesc;
use std::path::Path;

/// Small enough for a debug build on two cores.
const WIDTH: u32 = 64;

/// The golden images' scenes (tests/golden.rs), every shipped still.
const SCENES: &[&str] = &[
    "spheres",
    "glass",
    "mirrors",
    "shadows-glass",
    "antialiasing",
    "torus",
    "molecule",
    "textures",
    "lights",
    "ao-molecule",
    "solids",
    "cameras-dof",
    "cameras-orthographic",
    "cameras-fisheye",
    "cameras-stereo",
    "cameras-vr",
    "obj-mesh",
    "cutaway",
    "transparency",
    "transparency-vmd",
    "phantom",
    "vortex",
    "volume-geometry",
    "vdb-cloud",
];

fn small(d: &mut SceneDesc) {
    let aspect = d.render.height as f64 / d.render.width as f64;
    d.render.width = WIDTH;
    d.render.height = ((WIDTH as f64 * aspect).round() as u32).max(1);
}

fn context(desc: &SceneDesc, threads: usize) -> Context {
    api_context(desc, threads)
}

fn load(name: &str) -> SceneDesc {
    let path = root().join("scenes").join(format!("{name}.ron"));
    let mut desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    small(&mut desc);
    desc
}

fn render(r: &Renderer, scene: &mut Scene, w: u32, h: u32) -> Result<Vec<[f32; 4]>, Error> {
    api_render(r, scene, w, h)
}

#[test]
fn every_shipped_scene_renders_as_the_one_shot_path_does_on_1_and_2_threads() {
    for name in SCENES {
        let desc = load(name);
        let (w, h) = (desc.render.width, desc.render.height);
        let reg = registry(&desc);
        let built = luxon::Scene::build(&desc, &reg).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (fb, _) =
            luxon::render::render(&built, &|_, _| {}).unwrap_or_else(|e| panic!("{name}: {e}"));
        let want: Vec<u32> = fb.rgba.iter().map(|v| v.to_bits()).collect();
        for threads in [1, 2] {
            let ctx = context(&desc, threads);
            let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
            assert_eq!(r.threads(), threads);
            let mut scene = Scene::from_desc(&ctx, desc.clone()).unwrap();
            let got = render(&r, &mut scene, w, h).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(
                bits(&got) == want,
                "{name} on {threads} thread(s) differs from Scene::build + render::render"
            );
        }
    }
}

#[test]
fn load_and_a_renderer_of_its_own_give_the_same_image() {
    let desc = load("spheres");
    let ctx = context(&desc, 1);
    let (w, h) = (desc.render.width, desc.render.height);
    let own = Renderer::new(&ctx, RendererOptions { threads: Some(2) }).unwrap();
    assert_eq!(own.threads(), 2);
    let mut loaded = Scene::load(&ctx, &root().join("scenes/spheres.ron")).unwrap();
    let mut from_desc = Scene::from_desc(&ctx, desc).unwrap();
    // Loaded at its own size; the target decides.
    let a = render(&own, &mut loaded, w, h).unwrap();
    let shared = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let b = render(&shared, &mut from_desc, w, h).unwrap();
    assert!(bits(&a) == bits(&b));
}

#[test]
fn a_moved_camera_keeps_the_origin_of_the_first_commit() {
    let desc = load("spheres");
    let ctx = context(&desc, 2);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (w, h) = (desc.render.width, desc.render.height);
    let first = desc.camera.value.clone();
    let mut second = first.clone();
    second.position = [1.5, 1.0, -6.0];
    second.look_at = [0.3, 0.6, 0.2];

    let mut moved = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let before = render(&r, &mut moved, w, h).unwrap();
    moved.set_camera(second.clone()).unwrap();
    let report = moved.commit(&r).unwrap();
    assert_eq!(report.rebuilt, 0, "a camera move builds nothing");
    let after = render(&r, &mut moved, w, h).unwrap();
    assert!(bits(&before) != bits(&after), "the camera moved");

    let mut pinned = Scene::from_desc(&ctx, desc.clone()).unwrap();
    pinned.set_origin(Some(first.position)).unwrap();
    pinned.set_camera(second.clone()).unwrap();
    let fresh = render(&r, &mut pinned, w, h).unwrap();
    assert!(bits(&after) == bits(&fresh));

    // Re-centred on the second camera, the scene is built again (and may differ in the last
    // bits: coordinates are stored relative to another point).
    moved.set_origin(Some(second.position)).unwrap();
    assert_eq!(moved.commit(&r).unwrap().rebuilt, 1);
    let mut plain = desc;
    plain.camera.value = second;
    let mut plain = Scene::from_desc(&ctx, plain).unwrap();
    assert!(
        bits(&render(&r, &mut moved, w, h).unwrap())
            == bits(&render(&r, &mut plain, w, h).unwrap())
    );
}

#[test]
fn a_settings_only_commit_builds_no_bvh() {
    let desc = load("spheres");
    let ctx = context(&desc, 2);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (w, h) = (desc.render.width, desc.render.height);
    let mut scene = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let first = scene.commit(&r).unwrap();
    assert_eq!(first.rebuilt, 1);
    assert!(first.bvh_time > std::time::Duration::ZERO);
    assert_eq!(scene.commit(&r).unwrap().rebuilt, 0, "nothing changed");

    scene.set_render_ron("(samples: 1, max_depth: 3)").unwrap();
    scene.set_background([0.5, 0.1, 0.1]).unwrap();
    let report = scene.commit(&r).unwrap();
    assert_eq!(report.rebuilt, 0);
    assert_eq!(report.bvh_time, std::time::Duration::ZERO);
    let got = render(&r, &mut scene, w, h).unwrap();

    // The same settings from the start.
    let mut fresh = desc.clone();
    let settings = luxon_formats::fragment::render_settings("(samples: 1, max_depth: 3)").unwrap();
    fresh.render = luxon_formats::RenderDesc {
        width: w,
        height: h,
        outputs: fresh.render.outputs,
        parallel: fresh.render.parallel,
        ..settings
    };
    fresh.background = luxon_formats::BackgroundDesc::Color([0.5, 0.1, 0.1]);
    let mut fresh = Scene::from_desc(&ctx, fresh).unwrap();
    assert!(bits(&got) == bits(&render(&r, &mut fresh, w, h).unwrap()));

    // A setting the build reads builds again.
    scene
        .set_render_ron("(samples: 1, light_scale: 2)")
        .unwrap();
    assert_eq!(scene.commit(&r).unwrap().rebuilt, 1);
    // Bad values are refused with the text's position, and change nothing.
    let e = scene
        .set_render_ron("(samples: 0)")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("<render_settings>:1:11: `samples` is 0"),
        "{e}"
    );
    let e = scene
        .set_camera_ron("(positon: (0, 0, 1))")
        .unwrap_err()
        .to_string();
    assert!(e.contains("did you mean `position`"), "{e}");
}

#[test]
fn a_cancelled_render_leaves_the_next_one_complete() {
    let mut desc = load("spheres");
    desc.render.parallel.tile_size = 8;
    let ctx = context(&desc, 2);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (w, h) = (desc.render.width, desc.render.height);
    let mut scene = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let cancel = r.cancel_handle();
    let mut px = vec![[0u8; 4]; (w * h) as usize];
    let target = Target {
        width: w,
        height: h,
        color: Color::Rgba8Srgb(Plane::new(&mut px, w as usize)),
        depth: None,
    };
    // Cancelled as soon as the first pixels are done.
    let e = r
        .render_with(&mut scene, target, &|_, _| cancel.cancel())
        .unwrap_err();
    assert!(matches!(e, Error::Cancelled), "{e}");
    let again = render(&r, &mut scene, w, h).unwrap();
    let mut fresh = Scene::from_desc(&ctx, desc).unwrap();
    assert!(bits(&again) == bits(&render(&r, &mut fresh, w, h).unwrap()));
}

/// A scene with a custom object that panics when a ray reaches its box ([-1, 1]³) and a sphere
/// far from it; `look_at` aims the camera.
fn faulting_scene(dir: &Path, look_at: &str) -> SceneDesc {
    install_plugin(dir, "testplug_panics", "luxon_panics");
    let text = format!(
        "Scene(\n    plugin_path: [\"{}\"],\n    camera: (position: (0, 0, -5), look_at: {look_at}),\n    \
         objects: [(plugin: \"panic_intersect\"), (plugin: \"sphere\", params: (center: (0, 0, -12), radius: 1))],\n    \
         render: (width: 16, height: 16),\n)\n",
        dir.display()
    );
    let path = dir.join(format!("faults-{}.ron", look_at.len()));
    std::fs::write(&path, text).unwrap();
    luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_render_that_faults_is_an_error_and_the_next_commit_builds_again() {
    let dir = temp_dir("api-fault");
    let desc = faulting_scene(&dir, "(0, 0, 0)");
    let ctx = context(&desc, 2);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut scene = Scene::from_desc(&ctx, desc).unwrap();
    let e = render(&r, &mut scene, 16, 16).unwrap_err().to_string();
    assert!(e.contains("deliberate panic in intersect"), "{e}");
    assert!(scene.built().is_none(), "the faulted build is dropped");

    // Looking away from the faulting object, the scene renders again, built anew.
    scene
        .set_camera_ron("(position: (0, 0, -5), look_at: (0, 0, -12))")
        .unwrap();
    assert_eq!(scene.commit(&r).unwrap().rebuilt, 1);
    let got = render(&r, &mut scene, 16, 16).unwrap();
    let away = faulting_scene(&dir, "(0, 0, -12)");
    let mut fresh = Scene::from_desc(&ctx, away).unwrap();
    assert!(bits(&got) == bits(&render(&r, &mut fresh, 16, 16).unwrap()));
    assert!(got.iter().any(|p| p[0] > 0.0), "the sphere is seen");
}

#[test]
fn a_frozen_scene_consumes_its_imported_geometry_and_cannot_be_built_again() {
    let dir = temp_dir("api-frozen");
    let path = dir.join("ball.nff");
    std::fs::write(
        &path,
        "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 32 24\n\
         b 0.2 0.3 0.6\nl 4 -4 6\nf 0.9 0.2 0.2 0.6 0.4 30 0 0\ns 0 0 1 1\n",
    )
    .unwrap();
    let desc = luxon_formats::load(&path).unwrap();
    assert!(!desc.inline.is_empty());
    let ctx = context(&desc, 1);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut kept = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let mut frozen = Scene::from_desc_frozen(&ctx, desc).unwrap();
    let a = render(&r, &mut kept, 32, 24).unwrap();
    let b = render(&r, &mut frozen, 32, 24).unwrap();
    assert!(bits(&a) == bits(&b));
    assert!(frozen.desc().inline.is_empty(), "consumed");
    assert!(!kept.desc().inline.is_empty(), "kept");
    // A camera move needs no build; an origin change does, which only `kept` can do.
    frozen
        .set_camera_ron("(position: (1, -6, 2), look_at: (0, 0, 0.5), up: (0, 0, 1))")
        .unwrap();
    render(&r, &mut frozen, 32, 24).unwrap();
    frozen.set_origin(Some([0.0, 0.0, 0.0])).unwrap();
    let e = frozen.commit(&r).unwrap_err().to_string();
    assert!(e.contains("consumed at load"), "{e}");
    kept.set_origin(Some([0.0, 0.0, 0.0])).unwrap();
    assert_eq!(kept.commit(&r).unwrap().rebuilt, 1);
}

#[test]
fn write_image_writes_through_the_writer_plugins_whole() {
    let dir = temp_dir("api-write");
    let desc = load("spheres");
    let ctx = context(&desc, 1);
    let rgba: Vec<f32> = (0..6 * 4).map(|i| (i % 4) as f32 / 3.0).collect();
    let out = dir.join("tiny.png");
    luxon::api::write_image(&ctx, &out, &rgba, 3, 2).unwrap();
    let img = image::open(&out).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (3, 2));
    assert_eq!(img.get_pixel(0, 0).0[3], 255);
    let e = luxon::api::write_image(&ctx, &out, &rgba, 4, 2)
        .unwrap_err()
        .to_string();
    assert!(e.contains("expected 32"), "{e}");
    let e = luxon::api::write_image(&ctx, &dir.join("x.nope"), &rgba, 3, 2)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no writer for"), "{e}");
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "no temporary file is left: {names:?}");
}

#[test]
fn an_animated_scene_renders_its_frames_as_the_one_shot_path_does() {
    let desc = load("carousel");
    let (w, h) = (desc.render.width, desc.render.height);
    let reg = registry(&desc);
    let mut built = luxon::Scene::build(&desc, &reg).unwrap_or_else(|e| panic!("{e}"));
    built.set_frame(17).unwrap();
    let (fb, _) = luxon::render::render(&built, &|_, _| {}).unwrap();
    let want: Vec<u32> = fb.rgba.iter().map(|v| v.to_bits()).collect();

    let ctx = context(&desc, 2);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut scene = Scene::from_desc(&ctx, desc).unwrap();
    let first = render(&r, &mut scene, w, h).unwrap();
    scene.set_frame(17).unwrap();
    assert_eq!(scene.commit(&r).unwrap().rebuilt, 0);
    let got = render(&r, &mut scene, w, h).unwrap();
    assert!(bits(&got) == want);
    assert!(bits(&first) != want, "frame 0 differs from frame 17");
    // The animation places the camera.
    let e = scene
        .set_camera_ron("(position: (0, 0, 5))")
        .unwrap_err()
        .to_string();
    assert!(e.contains("animated"), "{e}");
}

#[test]
fn a_scene_renders_on_another_thread_with_a_shared_renderer() {
    let desc = load("spheres");
    let (w, h) = (desc.render.width, desc.render.height);
    let ctx = context(&desc, 2);
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut here = Scene::from_desc(&ctx, desc.clone()).unwrap();
    let want = render(&r, &mut here, w, h).unwrap();
    // A scene moves to another thread (`Send`); the renderer is shared (`Sync`).
    let there = Scene::from_desc(&ctx, desc).unwrap();
    let got = std::thread::scope(|s| {
        s.spawn(|| {
            let mut there = there;
            render(&r, &mut there, w, h).unwrap()
        })
        .join()
        .unwrap()
    });
    assert!(bits(&got) == bits(&want));
}
