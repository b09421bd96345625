//! Renders and other threads: a cancel from another thread stops a render, other calls on a
//! scene that renders return BUSY at once, and a progress callback that returns non-zero
//! cancels.

mod common;

use common::capi::*;
use std::ffi::{c_void, CString};
use std::ptr::null_mut;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Counts calls into the `AtomicU64` behind `user`; never asks to stop.
unsafe extern "C" fn count(_: u64, _: u64, user: *mut c_void) -> i32 {
    // SAFETY: the tests pass a pointer to an AtomicU64 that outlives the render.
    unsafe { &*user.cast::<AtomicU64>() }.fetch_add(1, Ordering::SeqCst);
    0
}

/// Asks to stop at the first call.
unsafe extern "C" fn stop(_: u64, _: u64, _: *mut c_void) -> i32 {
    1
}

/// Holds a pointer for another thread: the tests keep what it points to alive across it.
#[derive(Clone, Copy)]
struct SendPtr(*mut c_void);
// SAFETY: the pointee (an AtomicU64) is Sync and outlives every thread given the pointer.
unsafe impl Send for SendPtr {}

#[test]
fn a_render_is_cancelled_from_another_thread_and_other_calls_are_busy() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    // Long enough to be running when the other thread acts, even on a fast machine.
    let scene = scene_ron(ctx, &ball_scene(256));
    let calls = AtomicU64::new(0);
    let user = SendPtr((&calls as *const AtomicU64).cast_mut().cast());
    // SAFETY: a callback callable from any thread, with a pointer that outlives the renders.
    unsafe {
        expect(
            (api.luxon_renderer_set_progress)(r, Some(count), user.0),
            OK,
            "",
        )
    };
    let done = AtomicBool::new(false);
    std::thread::scope(|s| {
        let render = s.spawn(|| {
            let mut px = vec![[0.0f32; 4]; 256 * 256];
            let t = target_f32(&mut px, 256, 256);
            let start = Instant::now();
            // SAFETY: a valid target over `px`, alive through the call.
            let status = unsafe { (api.luxon_render)(r, scene, &t, null_mut()) };
            done.store(true, Ordering::SeqCst);
            (status, last_error(), start.elapsed())
        });
        // Once pixels come in, the scene is busy for everyone else.
        while calls.load(Ordering::SeqCst) == 0 && !render.is_finished() {
            std::thread::yield_now();
        }
        // SAFETY: handles are plain numbers.
        let busy = unsafe { (api.luxon_scene_set_background)(scene, 0.0, 0.0, 0.0) };
        expect(
            busy,
            BUSY,
            &format!("luxon_scene {:#x} is being rendered", scene.id),
        );
        while !done.load(Ordering::SeqCst) {
            // SAFETY: as above.
            unsafe { expect((api.luxon_renderer_cancel)(r), OK, "") };
            std::thread::sleep(Duration::from_millis(5));
        }
        let (status, message, took) = render.join().unwrap();
        assert_eq!(
            (status, message.as_str()),
            (CANCELLED, "the render was cancelled")
        );
        assert!(
            took < Duration::from_secs(20),
            "a cancelled render took {took:?}"
        );
    });
    // The scene is free again, and the next render is whole.
    let mut px = vec![[0.0f32; 4]; 4];
    // SAFETY: valid handles, and a target over `px`.
    unsafe {
        expect(
            (api.luxon_renderer_set_progress)(r, None, null_mut()),
            OK,
            "",
        );
        let low = CString::new("(samples: 1)").unwrap();
        expect(
            (api.luxon_scene_set_render_ron)(scene, low.as_ptr()),
            OK,
            "",
        );
        let t = target_f32(&mut px, 2, 2);
        expect((api.luxon_render)(r, scene, &t, null_mut()), OK, "");
    }
    assert!(px.iter().all(|p| p[3] == 1.0), "{px:?}");
}

#[test]
fn a_progress_callback_that_returns_non_zero_cancels() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let scene = scene_ron(ctx, &ball_scene(4));
    let mut px = vec![[0.0f32; 4]; 64 * 64];
    // SAFETY: a callback callable from any thread; a target over `px`.
    unsafe {
        expect(
            (api.luxon_renderer_set_progress)(r, Some(stop), null_mut()),
            OK,
            "",
        );
        let t = target_f32(&mut px, 64, 64);
        expect(
            (api.luxon_render)(r, scene, &t, null_mut()),
            CANCELLED,
            "the render was cancelled",
        );
        let unfinished = px.iter().filter(|p| p[3] == 0.0).count();
        assert!(unfinished > 0, "every pixel was rendered");
        expect(
            (api.luxon_renderer_set_progress)(r, None, null_mut()),
            OK,
            "",
        );
        expect((api.luxon_render)(r, scene, &t, null_mut()), OK, "");
    }
    assert!(px.iter().all(|p| p[3] == 1.0));
}
