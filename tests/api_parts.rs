//! Textures, clip groups and plugin volumes defined from code (`luxon::api::Scene`): each
//! renders bit for bit as the same part written in a scene file, a replaced one takes effect
//! at the next commit (which builds the scene again), and bad ones are refused when given,
//! with the messages of scene files pointing into the text.

mod common;

use common::*;
use luxon::api::{Context, ContextOptions, Renderer, RendererOptions, Scene};
use std::path::Path;

const W: u32 = 64;
const H: u32 = 48;

fn context() -> Context {
    ensure_plugins();
    Context::new(ContextOptions {
        threads: 2,
        ..Default::default()
    })
    .unwrap()
}

fn render(r: &Renderer, s: &mut Scene) -> Vec<u32> {
    bits(&api_render(r, s, W, H).unwrap_or_else(|e| panic!("{e}")))
}

/// The picture of a fresh scene made from `s`'s description.
fn fresh(ctx: &Context, r: &Renderer, s: &Scene) -> Vec<u32> {
    render(r, &mut Scene::from_desc(ctx, s.desc().clone()).unwrap())
}

const CAMERA: &str = "(position: (0, 0, 5), look_at: (0, 0, 0), fov: 40)";
/// Lit by ambient light only: a pixel is its texture's colour, so stripes are two values.
const FLAT: &str = "(texture: \"bands\", ambient: 1, diffuse: 0, specular: 0)";
const WALL: &str = "(point: (0, 0, 0), normal: (0, 0, 1))";

/// A scene file of the camera, a wall facing it and `parts` (RON fields).
fn scene_file(dir: &Path, name: &str, parts: &str) -> std::path::PathBuf {
    let text = format!(
        "Scene(camera: {CAMERA}, background: (0.2, 0.3, 0.5), \
         lights: [Point(position: (2, 3, 6), intensity: 0.8)], {parts} \
         render: (width: {W}, height: {H}))"
    );
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The distinct values along the middle row, and how many runs of equal pixels it has.
fn row_runs(px: &[u32]) -> (usize, usize) {
    let row: Vec<&[u32]> = px[(H / 2 * W * 4) as usize..((H / 2 + 1) * W * 4) as usize]
        .chunks(4)
        .collect();
    let mut values = row.clone();
    values.sort();
    values.dedup();
    let runs = 1 + row.windows(2).filter(|p| p[0] != p[1]).count();
    (values.len(), runs)
}

#[test]
fn a_texture_from_code_renders_as_in_a_scene_file_and_a_new_one_takes_effect() {
    let dir = temp_dir("api-parts-texture");
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let stripes = "(a: (0.9, 0.8, 0.1), b: (0.1, 0.1, 0.4), width: 0.4, filter: false)";

    let mut s = Scene::new(&ctx);
    s.set_camera_ron(CAMERA).unwrap();
    s.set_background([0.2, 0.3, 0.5]).unwrap();
    s.add_light_ron("Point(position: (2, 3, 6), intensity: 0.8)")
        .unwrap();
    // A material cannot name a texture the scene does not have.
    let e = s.set_material_ron("wall", FLAT).unwrap_err().to_string();
    assert!(e.contains("no texture named `bands`"), "{e}");
    s.set_texture("bands", "stripes", stripes).unwrap();
    let wall = s.set_material_ron("wall", FLAT).unwrap();
    s.add_plugin_object("plane", WALL, Some(wall), None)
        .unwrap();
    let got = render(&r, &mut s);

    // Stripes across x: along the middle row two colours, one run per stripe in view.
    let (values, runs) = row_runs(&got);
    assert_eq!(values, 2, "two colours along the row");
    assert!(runs >= 8, "{runs} runs: expected a stripe every few pixels");

    let file = scene_file(
        &dir,
        "stripes.ron",
        &format!(
            "textures: {{\"bands\": (plugin: \"stripes\", params: {stripes})}}, \
             materials: {{\"wall\": {FLAT}}}, \
             objects: [(plugin: \"plane\", params: {WALL}, material: \"wall\")],"
        ),
    );
    let mut loaded = Scene::load(&ctx, &file).unwrap();
    assert!(
        render(&r, &mut loaded) == got,
        "differs from the scene file"
    );

    // Replaced (by RON text): the next commit builds the scene again and shows it.
    s.set_texture_ron(
        "bands",
        "(plugin: \"stripes\", params: (a: (0.9, 0.8, 0.1), b: (0.1, 0.1, 0.4), \
         width: 0.2, filter: false))",
    )
    .unwrap();
    assert_eq!(s.commit(&r).unwrap().rebuilt, 1);
    let finer = render(&r, &mut s);
    let (values, finer_runs) = row_runs(&finer);
    assert_eq!(values, 2);
    assert!(finer_runs > runs + 4, "{finer_runs} runs after {runs}");
    assert!(finer == fresh(&ctx, &r, &s), "differs from a fresh scene");
    assert_eq!(s.desc().textures.len(), 1, "replaced, not added");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_textures_are_refused_when_given_pointing_into_their_text() {
    let ctx = context();
    let mut s = Scene::new(&ctx);
    let err = |r: Result<(), luxon::Error>| r.unwrap_err().to_string();

    // The plugin reads its parameters at once: its message points into them.
    let e = err(s.set_texture_ron("t", "(plugin: \"stripes\", params: (widht: 0.1))"));
    assert!(e.starts_with("<texture>:1:30: "), "{e}");
    assert!(e.contains("widht"), "{e}");
    let e = err(s.set_texture("t", "stripes", "(width: -1)"));
    assert!(e.starts_with("<texture>:1:"), "{e}");
    assert!(e.contains("width"), "{e}");
    // The fragment's own errors, as the other fragments give them.
    let e = err(s.set_texture_ron("t", "(plugin: \"stripes\", parms: ())"));
    assert!(e.starts_with("<texture>:1:21: "), "{e}");
    let e = err(s.set_texture_ron("t", "(plugin: \"stripes\"), lights: []"));
    assert!(e.starts_with("<texture>:"), "{e}");
    // A plugin that is missing, or of another kind.
    let e = err(s.set_texture("t", "no-such-texture", "()"));
    assert!(e.contains("no-such-texture"), "{e}");
    let e = err(s.set_texture("t", "sphere", "()"));
    assert!(e.contains("sphere"), "{e}");
    let e = err(s.set_texture("", "stripes", "()"));
    assert!(e.contains("name"), "{e}");
    assert!(s.desc().textures.is_empty(), "nothing refused was kept");
}

#[test]
fn clip_groups_from_code_cut_as_in_a_scene_file() {
    let dir = temp_dir("api-parts-clip");
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let ball = "(center: (0, 0, 0), radius: 1.2)";
    let cut = "[(point: (0, 0, 0), normal: (1, 0, 0))]";

    let mut s = Scene::load(&ctx, &scene_file(&dir, "bare.ron", "")).unwrap();
    let whole = {
        let mut w = Scene::load(&ctx, &scene_file(&dir, "whole.ron", "")).unwrap();
        w.add_plugin_object("sphere", ball, None, None).unwrap();
        render(&r, &mut w)
    };
    let group = s.set_clip_group_ron("half", cut).unwrap();
    assert_eq!(s.clip_group("half"), Some(group));
    s.add_plugin_object("sphere", ball, None, Some(group))
        .unwrap();
    let got = render(&r, &mut s);
    assert!(got != whole, "the cut shows");
    let file = scene_file(
        &dir,
        "clip.ron",
        &format!(
            "clip_groups: {{\"half\": {cut}}}, \
             objects: [(plugin: \"sphere\", params: {ball}, clip: \"half\")],"
        ),
    );
    assert!(render(&r, &mut Scene::load(&ctx, &file).unwrap()) == got);

    // New planes: the same id, the other half cut, a build at the next commit.
    let typed =
        luxon_formats::fragment::clip_planes("[(point: (0, 0, 0), normal: (-1, 0, 0))]").unwrap();
    assert_eq!(s.set_clip_group("half", typed).unwrap(), group);
    assert_eq!(s.commit(&r).unwrap().rebuilt, 1);
    let other = render(&r, &mut s);
    assert!(other != got && other != whole);
    assert!(other == fresh(&ctx, &r, &s));

    let e = s
        .set_clip_group_ron("bad", "[(point: (0, 0, 0), normal: (0, 0, 0))]")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("<clip_planes>:1:"), "{e}");
    let zero = luxon_formats::ClipPlaneDesc {
        point: [0.0; 3],
        normal: [0.0; 3],
    };
    let e = s.set_clip_group("bad", vec![zero]).unwrap_err().to_string();
    assert!(e.starts_with("clip group `bad`: "), "{e}");
    assert!(e.contains("zero length"), "{e}");
    assert!(s.clip_group("bad").is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plugin_volumes_from_code_render_as_in_a_scene_file_and_can_be_removed() {
    let dir = temp_dir("api-parts-volume");
    let n = 16usize;
    let mut bytes = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let d = [i, j, k].map(|c| c as f32 - 7.5);
                let v = (-(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / 20.0).exp();
                bytes.extend(v.to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join("blob.raw"), bytes).unwrap();
    let params = format!(
        "(file: \"{}\", dims: ({n}, {n}, {n}), format: \"f32\", origin: (-1, -1, -1), \
         spacing: (0.125, 0.125, 0.125))",
        dir.join("blob.raw").display()
    );
    let look = "(transfer: (preset: \"hot\"), step: 0.05)";
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();

    let bare = scene_file(&dir, "bare.ron", "");
    let mut s = Scene::load(&ctx, &bare).unwrap();
    let empty = render(&r, &mut s);
    let blob = s
        .add_plugin_volume_ron("raw", &params, Some("blob"), look)
        .unwrap();
    let ball = s
        .add_plugin_object("sphere", "(center: (0, 0, -3), radius: 1)", None, None)
        .unwrap();
    let got = render(&r, &mut s);
    let file = scene_file(
        &dir,
        "volume.ron",
        &format!(
            "volumes: [(plugin: \"raw\", name: \"blob\", params: {params}, render: {look})], \
             objects: [(plugin: \"sphere\", params: (center: (0, 0, -3), radius: 1))],"
        ),
    );
    assert!(render(&r, &mut Scene::load(&ctx, &file).unwrap()) == got);
    assert!(got != empty, "the volume shows");

    // Refused: a taken name, a reader that is missing, a clip group the scene lacks.
    let e = s.add_plugin_volume("raw", &params, Some("blob"), None);
    assert!(e.unwrap_err().to_string().contains("named `blob` already"));
    let e = s.add_plugin_volume("no-such-reader", "()", None, None);
    assert!(e.unwrap_err().to_string().contains("no-such-reader"));
    let clipped = "(transfer: (preset: \"hot\"), clip: \"nope\")";
    let e = s.add_plugin_volume_ron("raw", &params, None, clipped);
    assert!(e
        .unwrap_err()
        .to_string()
        .contains("no clip group named `nope`"));
    // A reader's error at the commit points into the parameters, named by the id.
    let broken = s
        .add_plugin_volume("raw", "(dims: (2, 2, 2))", None, None)
        .unwrap();
    let e = s.commit(&r).unwrap_err().to_string();
    assert!(e.starts_with(&format!("<{broken}>:1:")), "{e}");
    s.remove(broken).unwrap();

    // Removing the volume leaves the sphere; removing both leaves the bare scene.
    s.remove(blob).unwrap();
    assert!(s.desc().volumes.is_empty() && s.desc().objects.len() == 1);
    assert_eq!(s.objects(), vec![ball]);
    let sphere_only = render(&r, &mut s);
    assert!(sphere_only != got && sphere_only == fresh(&ctx, &r, &s));
    s.remove(ball).unwrap();
    assert!(render(&r, &mut s) == empty);
    std::fs::remove_dir_all(&dir).unwrap();
}
