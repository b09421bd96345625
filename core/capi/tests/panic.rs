//! A panic inside an entry point (made with `LUXON_TEST_PANIC=<function>`) comes back as
//! LUXON_ERROR_PANIC naming the function; the process lives on, the scene the call held is
//! unusable but can be released, and everything else keeps working. One test in its own
//! binary: it sets an environment variable the library reads on every call.

mod common;

use common::bits;
use common::capi::*;
use std::ptr::null_mut;

#[test]
fn a_panic_becomes_a_status_and_poisons_only_what_the_call_held() {
    let api = capi();
    let ctx = context();
    let r = renderer(ctx);
    let (victim, bystander) = (
        scene_ron(ctx, &ball_scene(1)),
        scene_ron(ctx, &ball_scene(1)),
    );
    let mut before = vec![[0.0f32; 4]; 16];
    let mut after = vec![[0.0f32; 4]; 16];
    // SAFETY: for every call below, valid handles and targets over live buffers.
    unsafe {
        let t = target_f32(&mut before, 4, 4);
        expect((api.luxon_render)(r, bystander, &t, null_mut()), OK, "");

        std::env::set_var("LUXON_TEST_PANIC", "luxon_scene_commit");
        let s = (api.luxon_scene_commit)(victim, r, null_mut());
        std::env::remove_var("LUXON_TEST_PANIC");
        expect(
            s,
            PANIC,
            "internal error in luxon_scene_commit (a bug in Luxon; please report it): panic \
             injected by LUXON_TEST_PANIC at ",
        );
        assert!(last_error().contains("guard.rs:"), "{}", last_error());

        // The scene is unusable; the renderer (also held) too; both can be released.
        let s = (api.luxon_scene_set_background)(victim, 0.0, 0.0, 0.0);
        expect(
            s,
            INVALID_HANDLE,
            &format!(
                "luxon_scene {:#x} is unusable after an internal error; release it",
                victim.id
            ),
        );
        let s = (api.luxon_renderer_cancel)(r);
        expect(s, INVALID_HANDLE, "luxon_renderer");
        expect((api.luxon_scene_release)(victim), OK, "");
        expect((api.luxon_renderer_release)(r), OK, "");

        // The other scene renders as before on a new renderer.
        let r = renderer(ctx);
        let t = target_f32(&mut after, 4, 4);
        expect((api.luxon_render)(r, bystander, &t, null_mut()), OK, "");
        assert_eq!(bits(&before), bits(&after));
        expect((api.luxon_scene_release)(bystander), OK, "");
        expect((api.luxon_renderer_release)(r), OK, "");
        expect((api.luxon_context_release)(ctx), OK, "");
    }
}
