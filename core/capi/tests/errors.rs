//! Every failure is a status code with a message, never a crash: NULL, released and mixed-up
//! handles, bad arguments, scene errors, and the per-thread last error.

mod common;

use common::capi::*;
use std::ffi::{c_char, CString};
use std::ptr::{null, null_mut};

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

#[test]
fn null_released_and_mixed_up_handles_are_refused() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let mut scene = Handle::default();
    // SAFETY: for every call below, handles are plain numbers, pointers valid or NULL where the
    // header allows it.
    unsafe {
        let s = (api.luxon_scene_set_background)(Handle::default(), 0.0, 0.0, 0.0);
        expect(s, INVALID_HANDLE, "the luxon_scene is null");
        expect((api.luxon_scene_create)(ctx, &mut scene), OK, "");
        expect(
            (api.luxon_scene_set_background)(scene, 0.1, 0.1, 0.1),
            OK,
            "",
        );
        // A scene where a renderer is expected, and a number that is no handle.
        let s = (api.luxon_renderer_cancel)(scene);
        expect(
            s,
            INVALID_HANDLE,
            "this handle is a luxon_scene, expected a luxon_renderer",
        );
        let s = (api.luxon_renderer_cancel)(Handle { id: 0x1234 });
        expect(
            s,
            INVALID_HANDLE,
            "0x1234 is not a Luxon handle; expected a luxon_renderer",
        );
        let s = (api.luxon_scene_release)(Handle { id: scene.id + 7 });
        expect(s, INVALID_HANDLE, "luxon_scene");
        assert!(last_error().ends_with("was released (or never created)"));
        // Released: every use and a second release are refused.
        expect((api.luxon_scene_release)(scene), OK, "");
        let s = (api.luxon_scene_set_background)(scene, 0.0, 0.0, 0.0);
        expect(
            s,
            INVALID_HANDLE,
            &format!("luxon_scene {:#x} was released", scene.id),
        );
        expect(
            (api.luxon_scene_release)(scene),
            INVALID_HANDLE,
            "luxon_scene",
        );
        // A new scene may take the slot again, under another id: the old one stays dead.
        let mut again = Handle::default();
        expect((api.luxon_scene_create)(ctx, &mut again), OK, "");
        assert_ne!(again, scene);
        expect(
            (api.luxon_scene_set_background)(scene, 0.0, 0.0, 0.0),
            INVALID_HANDLE,
            "",
        );
        expect(
            (api.luxon_scene_set_background)(again, 0.0, 0.0, 0.0),
            OK,
            "",
        );

        // A light of one scene used with another, and after its removal.
        let mut light = Handle::default();
        let ron = c("Point(position: (0, 5, 0))");
        expect(
            (api.luxon_scene_add_light_ron)(again, ron.as_ptr(), &mut light),
            OK,
            "",
        );
        let mut other = Handle::default();
        expect((api.luxon_scene_create)(ctx, &mut other), OK, "");
        let s = (api.luxon_scene_remove)(other, light);
        expect(
            s,
            INVALID_HANDLE,
            &format!("luxon_object {:#x} belongs to", light.id),
        );
        expect((api.luxon_scene_remove)(again, light), OK, "");
        expect(
            (api.luxon_scene_remove)(again, light),
            INVALID_HANDLE,
            "luxon_object",
        );
        // Releasing a scene releases its parts' handles.
        expect(
            (api.luxon_scene_add_light_ron)(other, ron.as_ptr(), &mut light),
            OK,
            "",
        );
        expect((api.luxon_scene_release)(other), OK, "");
        expect(
            (api.luxon_scene_remove)(again, light),
            INVALID_HANDLE,
            "luxon_object",
        );

        // The context goes first; its scene and renderer still work.
        expect((api.luxon_context_release)(ctx), OK, "");
        expect(
            (api.luxon_scene_set_background)(again, 0.2, 0.2, 0.2),
            OK,
            "",
        );
        expect((api.luxon_scene_release)(again), OK, "");
        expect((api.luxon_renderer_release)(r), OK, "");
    }
}

#[test]
fn bad_arguments_are_refused_with_what_is_wrong() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let scene = scene_ron(ctx, &ball_scene(1));
    let mut px = vec![[0.0f32; 4]; 16];
    // SAFETY: for every call below, handles are plain numbers; pointers are valid or NULL, and
    // where a target's planes are said to be larger than they are, the call refuses before
    // touching them (which is what is tested).
    unsafe {
        let s = (api.luxon_scene_create)(ctx, null_mut());
        expect(s, INVALID_ARGUMENT, "`out` is NULL");
        let s = (api.luxon_scene_set_camera_ron)(scene, null());
        expect(s, INVALID_ARGUMENT, "`ron` is NULL");
        let bad = [b'(' as c_char, 0xFFu8 as c_char, 0];
        let s = (api.luxon_scene_set_camera_ron)(scene, bad.as_ptr());
        expect(s, INVALID_ARGUMENT, "`ron` is not UTF-8 text (byte 1 of 2)");
        let s = (api.luxon_scene_set_background)(scene, -1.0, 0.0, f64::NAN);
        expect(s, INVALID_ARGUMENT, "background");

        let good = target_f32(&mut px, 4, 4);
        let cases: [(TargetDesc, &str); 7] = [
            (TargetDesc { size: 0, ..good }, "`target->size` is 0"),
            (
                TargetDesc { format: 7, ..good },
                "pixel format 7 is not one of",
            ),
            (TargetDesc { width: 0, ..good }, "the target is 0x4 pixels"),
            (
                TargetDesc {
                    row_bytes: 12,
                    ..good
                },
                "the pixels plane's row_bytes 12 is not a multiple",
            ),
            (
                TargetDesc {
                    row_bytes: 32,
                    ..good
                },
                "the RGBA f32 plane's row stride is 2 pixels",
            ),
            (
                TargetDesc {
                    height: u32::MAX,
                    row_bytes: (usize::MAX / 2) & !15,
                    ..good
                },
                "the pixels plane of a 4x4294967295 image",
            ),
            (
                TargetDesc {
                    pixels: good.pixels.cast::<u8>().add(1).cast(),
                    ..good
                },
                "`target->pixels` is not aligned",
            ),
        ];
        for (t, message) in cases {
            let s = (api.luxon_render)(r, scene, &t, null_mut());
            expect(s, INVALID_ARGUMENT, message);
        }
        // Depth over the colour plane would be written twice at once.
        let overlap = TargetDesc {
            depth: good.pixels.cast(),
            ..good
        };
        let s = (api.luxon_render)(r, scene, &overlap, null_mut());
        expect(s, INVALID_ARGUMENT, "the pixels and depth planes overlap");
        expect((api.luxon_render)(r, scene, &good, null_mut()), OK, "");

        let path = c("/nonexistent/x.png");
        let rgba = [0.5f32; 16];
        let s = (api.luxon_write_image)(ctx, path.as_ptr(), rgba.as_ptr(), 2, 2, 4);
        expect(
            s,
            INVALID_ARGUMENT,
            "row_floats 4 is less than a row of 2 RGBA pixels (8 floats)",
        );
        let s = (api.luxon_write_image)(ctx, path.as_ptr(), null(), 2, 2, 0);
        expect(s, INVALID_ARGUMENT, "`rgba` is NULL");
    }
}

#[test]
fn scene_errors_say_where() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let mut scene = Handle::default();
    // SAFETY: for every call below, valid strings and pointers, or NULL where allowed.
    unsafe {
        expect((api.luxon_scene_create)(ctx, &mut scene), OK, "");
        let ron = c("Point(positon: (0, 0, 5))");
        let s = (api.luxon_scene_add_light_ron)(scene, ron.as_ptr(), null_mut());
        expect(s, SCENE, "<light>:1:7: unknown field `positon`");
        let ron = c("(samples: -2)");
        let s = (api.luxon_scene_set_render_ron)(scene, ron.as_ptr());
        expect(s, SCENE, "<render_settings>:1:");
        // No camera yet: a commit is refused (the scene is not rendered black).
        let s = (api.luxon_scene_commit)(scene, r, null_mut());
        expect(s, INVALID_ARGUMENT, "this scene has no camera");
        let (plugin, params) = (c("spheer"), c("()"));
        let s = (api.luxon_scene_add_object)(
            scene,
            plugin.as_ptr(),
            params.as_ptr(),
            null(),
            null(),
            null_mut(),
        );
        expect(s, PLUGIN_NOT_FOUND, "");
        assert!(
            last_error().contains("did you mean `sphere`"),
            "{}",
            last_error()
        );
        let (plugin, material) = (c("sphere"), c("chrome"));
        let s = (api.luxon_scene_add_object)(
            scene,
            plugin.as_ptr(),
            params.as_ptr(),
            material.as_ptr(),
            null(),
            null_mut(),
        );
        expect(
            s,
            INVALID_ARGUMENT,
            "the scene has no material named `chrome`",
        );
        // The plugin reads its parameters at the commit, and its error points into them.
        let camera = c("(position: (0, 0, -5), look_at: (0, 0, 0))");
        expect(
            (api.luxon_scene_set_camera_ron)(scene, camera.as_ptr()),
            OK,
            "",
        );
        let params = c("(center: (0, 0, 0), radus: 1)");
        let s = (api.luxon_scene_add_object)(
            scene,
            plugin.as_ptr(),
            params.as_ptr(),
            null(),
            null(),
            null_mut(),
        );
        expect(s, OK, "");
        let s = (api.luxon_scene_commit)(scene, r, null_mut());
        expect(s, SCENE, "<object 0>:");
        let path = c("/nonexistent/scene.ron");
        let mut loaded = Handle::default();
        let s = (api.luxon_scene_load)(ctx, path.as_ptr(), &mut loaded);
        expect(s, IO, "");
        assert_eq!(
            loaded,
            Handle::default(),
            "a failed load leaves the null handle"
        );
    }
}

#[test]
fn the_last_error_is_per_thread_and_cleared_by_a_success() {
    let api = capi();
    let threads: Vec<_> = (0..4)
        .map(|i| {
            std::thread::spawn(move || {
                for _ in 0..50 {
                    // SAFETY: handles are plain numbers.
                    let s = unsafe { (api.luxon_renderer_cancel)(Handle { id: 0x1000 + i }) };
                    expect(
                        s,
                        INVALID_HANDLE,
                        &format!("{:#x} is not a Luxon handle", 0x1000 + i),
                    );
                }
            })
        })
        .collect();
    for t in threads {
        t.join().unwrap();
    }
    let ctx = context();
    // SAFETY: handles are plain numbers.
    unsafe {
        expect(
            (api.luxon_scene_release)(Handle::default()),
            INVALID_HANDLE,
            "the luxon_scene is null",
        );
        assert_eq!((api.luxon_api_version)(), 2);
        assert_eq!(last_error(), "");
        (api.luxon_scene_release)(Handle::default());
        expect((api.luxon_context_release)(ctx), OK, "");
        assert_eq!(last_error(), "");
    }
}

#[test]
fn the_last_error_copy_cuts_at_a_character() {
    let api = capi();
    let ctx = context();
    let mut scene = Handle::default();
    // SAFETY: valid strings, buffers of the lengths given, NULL with length 0.
    unsafe {
        expect((api.luxon_scene_create)(ctx, &mut scene), OK, "");
        // A material name with a 2-byte character, echoed in the message.
        let (plugin, params, material) = (c("sphere"), c("()"), c("é"));
        (api.luxon_scene_add_object)(
            scene,
            plugin.as_ptr(),
            params.as_ptr(),
            material.as_ptr(),
            null(),
            null_mut(),
        );
        let message = last_error();
        assert_eq!(message, "the scene has no material named `é`");
        let len = (api.luxon_last_error_copy)(null_mut(), 0);
        assert_eq!(len, message.len());
        let cut = message.find('é').unwrap();
        // Room for the text before 'é' and one of its two bytes: the 'é' is left out whole.
        let mut buf = vec![0x55 as c_char; cut + 2];
        assert_eq!(
            (api.luxon_last_error_copy)(buf.as_mut_ptr(), buf.len()),
            len
        );
        let got = std::ffi::CStr::from_ptr(buf.as_ptr()).to_str().unwrap();
        assert_eq!(got, &message[..cut]);
        let mut buf = vec![0 as c_char; len + 1];
        (api.luxon_last_error_copy)(buf.as_mut_ptr(), buf.len());
        assert_eq!(
            std::ffi::CStr::from_ptr(buf.as_ptr()).to_str().unwrap(),
            message
        );
    }
}

#[test]
fn versions_are_the_crates() {
    let api = capi();
    let mut v = [u32::MAX; 3];
    // SAFETY: the version string is static and NUL-terminated; the pointers are writable.
    unsafe {
        assert_eq!((api.luxon_api_version)(), 2);
        let text = std::ffi::CStr::from_ptr((api.luxon_version_string)());
        assert_eq!(text.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
        (api.luxon_version)(&mut v[0], &mut v[1], &mut v[2]);
        (api.luxon_version)(null_mut(), null_mut(), null_mut());
        assert_eq!((api.luxon_plugin_abi_version)(), luxon_plugin::ABI_VERSION);
        // With `--features mpi` the library is built with MPI (and says so), else without.
        assert_eq!((api.luxon_has_mpi)(), cfg!(feature = "mpi"));
    }
    let want: Vec<u32> = env!("CARGO_PKG_VERSION")
        .split('.')
        .map(|n| n.parse().unwrap())
        .collect();
    assert_eq!(v.to_vec(), want);
}
