//! Shared by the C API's tests: building libluxon (and the plugins) with the test's profile,
//! and renders of the same scenes through the Rust API to compare with.
#![allow(dead_code)]

use luxon_core::api::{Color, Context, ContextOptions, Plane, Renderer, Scene, Target};
use luxon_formats::{Attenuation, CameraDesc, LightDesc, MaterialDesc, Projection};
use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The workspace's root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh scratch directory for test `name` of this process.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("luxon-capi-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A finished command's status and output, for an assertion's message.
pub fn report(o: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// `target/<profile>`, where libluxon and the plugins are.
pub fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().unwrap().parent().unwrap().to_path_buf()
}

/// `cargo test` builds neither libluxon.so/.a nor the plugins (nothing links them): built
/// once here with the test's profile, so the tests never run against stale ones.
pub fn ensure_built() {
    static BUILT: OnceLock<()> = OnceLock::new();
    BUILT.get_or_init(|| {
        let mut cmd = Command::new(env!("CARGO"));
        cmd.args(["build", "--workspace", "--lib", "--quiet"])
            .current_dir(root());
        if profile_dir().file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        // The library the tests load is built as this test was (with MPI or not).
        if cfg!(feature = "mpi") {
            cmd.args(["--features", "mpi"]);
        }
        let status = cmd.status().expect("cannot run cargo to build libluxon");
        assert!(status.success(), "building libluxon and the plugins failed");
    });
}

/// A Rust API context and renderer (one thread: images do not depend on the count).
pub fn rust_api() -> (Context, Renderer) {
    ensure_built();
    let ctx = Context::new(ContextOptions {
        threads: 1,
        ..Default::default()
    })
    .unwrap_or_else(|e| panic!("{e}"));
    let renderer = Renderer::new(&ctx, Default::default()).unwrap_or_else(|e| panic!("{e}"));
    (ctx, renderer)
}

/// The scene `tests/c/smoke.c` builds through the C calls, built through the Rust API.
pub fn smoke_scene(ctx: &Context) -> Scene {
    let mut s = Scene::new(ctx);
    let camera = CameraDesc {
        position: [0.0, 0.5, -5.0],
        look_at: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        projection: Projection::Perspective { fov_deg: 40.0 },
        aspect: None,
        frustum: None,
        depth_of_field: None,
        stereo: None,
    };
    let light = LightDesc::Point {
        position: [-4.0, 6.0, -5.0],
        color: [1.0; 3],
        intensity: 1.0,
        shadows: true,
        attenuation: Attenuation::default(),
    };
    let red = MaterialDesc {
        color: [0.8, 0.1, 0.1],
        specular: 0.5,
        ..MaterialDesc::default()
    };
    let go = |r: Result<(), luxon_core::Error>| r.unwrap_or_else(|e| panic!("{e}"));
    go(s.set_camera(camera));
    go(s.set_background([0.1, 0.2, 0.4]));
    go(s.add_light(light).map(drop));
    let red = s.set_material("red", red).unwrap_or_else(|e| panic!("{e}"));
    let params = "(center: (0, 0, 0), radius: 1)";
    go(s.add_plugin_object("sphere", params, Some(red), None)
        .map(drop));
    go(s.set_render_ron("(samples: 1)"));
    s
}

/// Renders `scene` into packed linear RGBA f32.
pub fn render_f32(r: &Renderer, scene: &mut Scene, w: u32, h: u32) -> Vec<[f32; 4]> {
    let mut px = vec![[0.0f32; 4]; (w * h) as usize];
    let target = Target {
        width: w,
        height: h,
        color: Color::Rgba32fLinear(Plane::new(&mut px, w as usize)),
        depth: None,
    };
    r.render(scene, target).unwrap_or_else(|e| panic!("{e}"));
    px
}

/// Renders `scene` into RGBA8 rows of `stride` pixels, filled with `fill` before.
pub fn render_rgba8(
    r: &Renderer,
    scene: &mut Scene,
    w: u32,
    h: u32,
    stride: usize,
    fill: u8,
) -> Vec<[u8; 4]> {
    let mut px = vec![[fill; 4]; stride * h as usize];
    let target = Target {
        width: w,
        height: h,
        color: Color::Rgba8Srgb(Plane::new(&mut px, stride)),
        depth: None,
    };
    r.render(scene, target).unwrap_or_else(|e| panic!("{e}"));
    px
}

/// The bits of every float (for bitwise comparisons).
pub fn bits(px: &[[f32; 4]]) -> Vec<u32> {
    px.iter().flatten().map(|v| v.to_bits()).collect()
}
pub mod capi;
