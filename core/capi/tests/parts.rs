//! Textures, clip groups and plugin volumes through the C calls (`luxon_scene_set_texture`,
//! `luxon_scene_set_clip_group`, `luxon_scene_add_volume_plugin`): the same pictures, bit for
//! bit, as the Rust API's, and their failures as status codes with messages.

mod common;

use common::capi::*;
use common::rust_api;
use luxon_core::api::{Color, Plane, Renderer, Scene, Target};
use std::ffi::CString;
use std::ptr::{null, null_mut};

const W: u32 = 48;
const H: u32 = 32;
const CAMERA: &str = "(position: (0, 0, 5), look_at: (0, 0, 0), fov: 40)";
const LIGHT: &str = "Point(position: (2, 3, 6), intensity: 0.8)";
const STRIPES: &str = "(a: (0.9, 0.8, 0.1), b: (0.1, 0.1, 0.4), width: 0.3, filter: false)";
const FLAT: &str = "(texture: \"bands\", ambient: 1, diffuse: 0, specular: 0)";
const WALL: &str = "(point: (0, 0, 0), normal: (0, 0, 1))";
const BALL: &str = "(center: (0, 0, 1), radius: 1)";
const CUT: &str = "[(point: (0, 0, 1), normal: (1, 0, 0))]";
const LOOK: &str = "(transfer: (preset: \"hot\"), step: 0.05, clip: \"half\")";

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

/// The raw file of a 16³ blob of f32s, and the `raw` reader's parameters for it.
fn blob(dir: &std::path::Path) -> String {
    let n = 16usize;
    let mut bytes = Vec::new();
    for i in 0..n * n * n {
        let d = [i % n, i / n % n, i / (n * n)].map(|c| c as f32 - 7.5);
        bytes.extend(
            (-(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / 20.0)
                .exp()
                .to_le_bytes(),
        );
    }
    let file = dir.join("blob.raw");
    std::fs::write(&file, bytes).unwrap();
    format!(
        "(file: \"{}\", dims: ({n}, {n}, {n}), format: \"f32\", origin: (-1, -1, 1), \
         spacing: (0.125, 0.125, 0.125))",
        file.display()
    )
}

/// The same scene through the Rust API.
fn rust_picture(volume: &str) -> Vec<[f32; 4]> {
    let (ctx, r) = rust_api();
    let mut s = Scene::new(&ctx);
    let go = |e: Result<(), luxon_core::Error>| e.unwrap_or_else(|e| panic!("{e}"));
    go(s.set_camera_ron(CAMERA));
    go(s.add_light_ron(LIGHT).map(drop));
    go(s.set_texture("bands", "stripes", STRIPES));
    let wall = s.set_material_ron("wall", FLAT).unwrap();
    let half = s.set_clip_group_ron("half", CUT).unwrap();
    go(s.add_plugin_object("plane", WALL, Some(wall), None)
        .map(drop));
    go(s.add_plugin_object("sphere", BALL, None, Some(half))
        .map(drop));
    go(s.add_plugin_volume_ron("raw", volume, Some("blob"), LOOK)
        .map(drop));
    render(&r, &mut s)
}

fn render(r: &Renderer, s: &mut Scene) -> Vec<[f32; 4]> {
    let mut px = vec![[0.0f32; 4]; (W * H) as usize];
    let target = Target {
        width: W,
        height: H,
        color: Color::Rgba32fLinear(Plane::new(&mut px, W as usize)),
        depth: None,
    };
    r.render(s, target).unwrap_or_else(|e| panic!("{e}"));
    px
}

#[test]
fn textures_clip_groups_and_plugin_volumes_render_as_through_the_rust_api() {
    let api = capi();
    let dir = std::env::temp_dir().join(format!("luxon-capi-parts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let volume = blob(&dir);
    let ctx = context();
    let r = renderer(ctx);
    let mut scene = Handle::default();
    let mut px = vec![[0.0f32; 4]; (W * H) as usize];
    let target = target_f32(&mut px, W, H);
    let (bands, stripes, wall, flat) = (c("bands"), c("stripes"), c("wall"), c(FLAT));
    let (half, raw, params) = (c("half"), c("raw"), c(&volume));
    let mut object = Handle::default();
    // SAFETY: handles are plain numbers; strings, target and out-pointers valid or NULL where
    // the header allows it.
    unsafe {
        expect((api.luxon_scene_create)(ctx, &mut scene), OK, "");
        expect(
            (api.luxon_scene_set_camera_ron)(scene, c(CAMERA).as_ptr()),
            OK,
            "",
        );
        expect(
            (api.luxon_scene_add_light_ron)(scene, c(LIGHT).as_ptr(), null_mut()),
            OK,
            "",
        );

        // Textures: the plugin's parameter errors at once, pointing into them.
        let s = (api.luxon_scene_set_texture)(
            scene,
            bands.as_ptr(),
            stripes.as_ptr(),
            c("(width: 0)").as_ptr(),
        );
        expect(s, SCENE, "<texture>:1:");
        let s = (api.luxon_scene_set_texture)(scene, bands.as_ptr(), c("no-such").as_ptr(), null());
        expect(s, PLUGIN_NOT_FOUND, "");
        let s = (api.luxon_scene_set_texture)(scene, null(), stripes.as_ptr(), null());
        expect(s, INVALID_ARGUMENT, "");
        let s = (api.luxon_scene_set_material_ron)(scene, wall.as_ptr(), flat.as_ptr());
        expect(s, SCENE, "<material>:1:");
        assert!(last_error().contains("no texture named `bands`"));
        let s = (api.luxon_scene_set_texture)(
            scene,
            bands.as_ptr(),
            stripes.as_ptr(),
            c(STRIPES).as_ptr(),
        );
        expect(s, OK, "");
        expect(
            (api.luxon_scene_set_material_ron)(scene, wall.as_ptr(), flat.as_ptr()),
            OK,
            "",
        );

        // Clip groups.
        let zero = c("[(point: (0, 0, 0), normal: (0, 0, 0))]");
        let s = (api.luxon_scene_set_clip_group)(scene, half.as_ptr(), zero.as_ptr());
        expect(s, SCENE, "<clip_planes>:1:");
        assert!(last_error().contains("zero length"));
        expect(
            (api.luxon_scene_set_clip_group)(scene, half.as_ptr(), c(CUT).as_ptr()),
            OK,
            "",
        );
        let s = (api.luxon_scene_add_object)(
            scene,
            c("plane").as_ptr(),
            c(WALL).as_ptr(),
            wall.as_ptr(),
            null(),
            null_mut(),
        );
        expect(s, OK, "");
        let s = (api.luxon_scene_add_object)(
            scene,
            c("sphere").as_ptr(),
            c(BALL).as_ptr(),
            null(),
            half.as_ptr(),
            null_mut(),
        );
        expect(s, OK, "");

        // Volumes through their reader: refused when the reader is missing or the look names
        // a clip group the scene lacks.
        let s = (api.luxon_scene_add_volume_plugin)(
            scene,
            c("no-such").as_ptr(),
            params.as_ptr(),
            null(),
            null(),
            null_mut(),
        );
        expect(s, PLUGIN_NOT_FOUND, "");
        let nope = c("(transfer: (preset: \"hot\"), clip: \"nope\")");
        let s = (api.luxon_scene_add_volume_plugin)(
            scene,
            raw.as_ptr(),
            params.as_ptr(),
            null(),
            nope.as_ptr(),
            null_mut(),
        );
        expect(s, INVALID_ARGUMENT, "no clip group named `nope`");
        let s = (api.luxon_scene_add_volume_plugin)(
            scene,
            raw.as_ptr(),
            params.as_ptr(),
            c("blob").as_ptr(),
            c(LOOK).as_ptr(),
            &mut object,
        );
        expect(s, OK, "");

        expect((api.luxon_render)(r, scene, &target, null_mut()), OK, "");
    }
    let got: Vec<u32> = px.iter().flatten().map(|v| v.to_bits()).collect();
    let want: Vec<u32> = rust_picture(&volume)
        .iter()
        .flatten()
        .map(|v| v.to_bits())
        .collect();
    assert!(got == want, "differs from the Rust API's picture");

    // The volume removed by its handle: the picture changes, the scene builds again.
    // SAFETY: as above.
    unsafe {
        expect((api.luxon_scene_remove)(scene, object), OK, "");
        expect((api.luxon_render)(r, scene, &target, null_mut()), OK, "");
        expect((api.luxon_scene_release)(scene), OK, "");
        expect((api.luxon_renderer_release)(r), OK, "");
        expect((api.luxon_context_release)(ctx), OK, "");
    }
    let without: Vec<u32> = px.iter().flatten().map(|v| v.to_bits()).collect();
    assert!(without != got, "the volume is gone");
    std::fs::remove_dir_all(&dir).unwrap();
}
