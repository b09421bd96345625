//! What comes out besides pixels: commit reports, images written through the writer plugins, a
//! scene saved as RON (which renders the same), and log lines through the callback.

mod common;

use common::capi::*;
use common::{bits, temp_dir};
use std::ffi::{c_char, c_void, CStr, CString};
use std::ptr::null_mut;
use std::sync::Mutex;

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

#[test]
fn commit_reports_say_what_was_built() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let scene = scene_ron(ctx, &ball_scene(1));
    let mut report = CommitReport {
        size: std::mem::size_of::<CommitReport>() as u32,
        ..Default::default()
    };
    // SAFETY: valid handles and a report whose size is set.
    unsafe {
        expect((api.luxon_scene_commit)(scene, r, &mut report), OK, "");
        assert_eq!((report.rebuilt, report.shading), (1, 0));
        assert!(report.commit_seconds >= report.bvh_seconds);
        let light = c("Point(position: (4, 6, -5), intensity: 0.5)");
        expect(
            (api.luxon_scene_add_light_ron)(scene, light.as_ptr(), null_mut()),
            OK,
            "",
        );
        expect((api.luxon_scene_commit)(scene, r, &mut report), OK, "");
        assert_eq!((report.rebuilt, report.shading), (0, 1));
        // A report of an older, smaller version gets only its fields.
        let mut old = CommitReport {
            size: 8,
            shading: 77,
            ..Default::default()
        };
        expect((api.luxon_scene_commit)(scene, r, &mut old), OK, "");
        assert_eq!((old.size, old.rebuilt, old.shading), (8, 0, 77));
    }
}

#[test]
fn a_saved_scene_renders_as_the_scene_did_and_images_are_written() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let scene = scene_ron(ctx, &ball_scene(2));
    let dir = temp_dir("outputs");
    let (ron, ppm) = (dir.join("saved.ron"), dir.join("ball.ppm"));
    let mut first = vec![[0.0f32; 4]; 12 * 8];
    let mut second = vec![[0.0f32; 4]; 12 * 8];
    let mut saved = Handle::default();
    // SAFETY: valid handles, strings, targets over live buffers.
    unsafe {
        let light = c("Directional(direction: (1, -1, 1), intensity: 0.3)");
        expect(
            (api.luxon_scene_add_light_ron)(scene, light.as_ptr(), null_mut()),
            OK,
            "",
        );
        expect(
            (api.luxon_render)(r, scene, &target_f32(&mut first, 12, 8), null_mut()),
            OK,
            "",
        );
        let path = c(ron.to_str().unwrap());
        expect((api.luxon_scene_save_ron)(scene, path.as_ptr()), OK, "");
        expect(
            (api.luxon_scene_load)(ctx, path.as_ptr(), &mut saved),
            OK,
            "",
        );
        expect(
            (api.luxon_render)(r, saved, &target_f32(&mut second, 12, 8), null_mut()),
            OK,
            "",
        );
        assert_eq!(bits(&first), bits(&second));

        // Rows of 10 pixels (40 floats) in a buffer of 12.
        let padded: Vec<f32> = first
            .chunks(12)
            .flat_map(|row| row[..10].iter().flatten().copied().chain([0.0; 8]))
            .collect();
        let path = c(ppm.to_str().unwrap());
        let s = (api.luxon_write_image)(ctx, path.as_ptr(), padded.as_ptr(), 10, 8, 48);
        expect(s, OK, "");
        let bytes = std::fs::read(&ppm).unwrap();
        assert!(bytes.starts_with(b"P6\n10 8\n255\n"), "{:?}", &bytes[..12]);
        let bad = c(dir.join("x.nope").to_str().unwrap());
        let s = (api.luxon_write_image)(ctx, bad.as_ptr(), padded.as_ptr(), 10, 8, 48);
        assert_ne!(s, OK);
        assert!(last_error().contains("nope"), "{}", last_error());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

static LINES: Mutex<Vec<(i32, String)>> = Mutex::new(Vec::new());

unsafe extern "C" fn collect(level: i32, message: *const c_char, _: *mut c_void) {
    // SAFETY: the library passes a NUL-terminated message valid during the call.
    let text = unsafe { CStr::from_ptr(message) }
        .to_string_lossy()
        .into_owned();
    LINES.lock().unwrap().push((level, text));
}

#[test]
fn scene_warnings_reach_the_log_callback() {
    let api = capi();
    let ctx = context();
    let dir = temp_dir("log");
    let nff = dir.join("ball.nff");
    std::fs::write(
        &nff,
        "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 8 8\n\
         b 0.2 0.3 0.6\nl 4 -4 6\nf 0.9 0.2 0.2 0.6 0.4 30 0 0\ns 0 0 1 -1\n",
    )
    .unwrap();
    let path = c(nff.to_str().unwrap());
    let mut scene = Handle::default();
    // SAFETY: a callback callable from any thread (it locks), valid strings and pointers.
    unsafe {
        let s = (api.luxon_set_log)(Some(collect), null_mut(), 7);
        expect(
            s,
            INVALID_ARGUMENT,
            "max_level 7: expected 0 (errors) to 3 (debug)",
        );
        expect((api.luxon_set_log)(Some(collect), null_mut(), 1), OK, "");
        expect(
            (api.luxon_scene_load)(ctx, path.as_ptr(), &mut scene),
            OK,
            "",
        );
        expect((api.luxon_set_log)(None, null_mut(), 0), OK, "");
        expect((api.luxon_scene_release)(scene), OK, "");
        expect(
            (api.luxon_scene_load)(ctx, path.as_ptr(), &mut scene),
            OK,
            "",
        );
    }
    let lines = LINES.lock().unwrap();
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert_eq!(lines[0].0, 1);
    assert!(lines[0].1.contains("ball.nff:11:"), "{lines:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn effects_origin_and_objects_change_the_picture_and_back() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let scene = scene_ron(ctx, &ball_scene(1));
    let render = |px: &mut Vec<[f32; 4]>| {
        // SAFETY: valid handles and a target over `px`.
        let s = unsafe { (api.luxon_render)(r, scene, &target_f32(px, 8, 8), null_mut()) };
        expect(s, OK, "");
        bits(px)
    };
    let mut px = vec![[0.0f32; 4]; 64];
    let plain = render(&mut px);
    let mut objects = [Handle::default(); 4];
    let mut n = 0;
    // SAFETY: valid handles, strings, NULL where allowed, arrays of the sizes given.
    unsafe {
        let fog = c("(mode: Exp(density: 0.3), color: (0.5, 0.5, 0.5))");
        expect((api.luxon_scene_set_fog_ron)(scene, fog.as_ptr()), OK, "");
        assert_ne!(render(&mut px), plain);
        expect(
            (api.luxon_scene_set_fog_ron)(scene, std::ptr::null()),
            OK,
            "",
        );
        let ao = c("(samples: 4, distance: 2)");
        expect(
            (api.luxon_scene_set_ambient_occlusion_ron)(scene, ao.as_ptr()),
            OK,
            "",
        );
        assert_ne!(render(&mut px), plain);
        expect(
            (api.luxon_scene_set_ambient_occlusion_ron)(scene, std::ptr::null()),
            OK,
            "",
        );
        assert_eq!(render(&mut px), plain);
        // Render space's origin: NULL (the camera's) is where the scene started.
        expect(
            (api.luxon_scene_set_origin)(scene, std::ptr::null()),
            OK,
            "",
        );
        assert_eq!(render(&mut px), plain);
        let nan = [0.0, f64::NAN, 0.0];
        let s = (api.luxon_scene_set_origin)(scene, nan.as_ptr());
        expect(s, INVALID_ARGUMENT, "origin");

        // The file's two objects; without the ball the picture changes.
        expect(
            (api.luxon_scene_objects)(scene, objects.as_mut_ptr(), 4, &mut n),
            OK,
            "",
        );
        assert_eq!(n, 2);
        let mut again = [Handle::default(); 1];
        expect(
            (api.luxon_scene_objects)(scene, again.as_mut_ptr(), 1, &mut n),
            OK,
            "",
        );
        assert_eq!(
            (again[0], n),
            (objects[0], 2),
            "the same part, the same handle"
        );
        expect((api.luxon_scene_remove)(scene, objects[0]), OK, "");
        assert_ne!(render(&mut px), plain);
        expect(
            (api.luxon_scene_objects)(scene, std::ptr::null_mut(), 0, &mut n),
            OK,
            "",
        );
        assert_eq!(n, 1);
    }
}

#[test]
fn an_animated_scene_renders_its_frame_as_the_rust_api_does() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let path = common::root().join("scenes/carousel.ron");
    let text = c(path.to_str().unwrap());
    let (mut scene, mut px) = (Handle::default(), vec![[0.0f32; 4]; 16 * 12]);
    // SAFETY: valid handles, strings and a target over `px`.
    unsafe {
        expect(
            (api.luxon_scene_load)(ctx, text.as_ptr(), &mut scene),
            OK,
            "",
        );
        expect((api.luxon_scene_set_frame)(scene, 5), OK, "");
        expect(
            (api.luxon_render)(r, scene, &target_f32(&mut px, 16, 12), null_mut()),
            OK,
            "",
        );
        let still = scene_ron(ctx, &ball_scene(1));
        let s = (api.luxon_scene_set_frame)(still, 5);
        expect(s, INVALID_ARGUMENT, "frame 5: ");
        assert!(
            last_error().ends_with("has no `animation:`"),
            "{}",
            last_error()
        );
    }
    let (rust_ctx, rust_renderer) = common::rust_api();
    let mut want = luxon_core::api::Scene::load(&rust_ctx, &path).unwrap_or_else(|e| panic!("{e}"));
    want.set_frame(5).unwrap_or_else(|e| panic!("{e}"));
    let want = common::render_f32(&rust_renderer, &mut want, 16, 12);
    assert_eq!(bits(&px), bits(&want));
    let mut first =
        luxon_core::api::Scene::load(&rust_ctx, &path).unwrap_or_else(|e| panic!("{e}"));
    assert_ne!(
        bits(&common::render_f32(&rust_renderer, &mut first, 16, 12)),
        bits(&want)
    );
}
