//! Shared by the integration tests: building the plugins, rendering scenes through the library,
//! running the `luxon` binary, and temporary directories.
#![allow(dead_code)]

#[cfg(unix)]
pub mod limits;

use luxon::plugin::Registry;
use luxon::{Framebuffer, Scene};
use luxon_formats::SceneDesc;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `cargo test` does not build the plugin cdylibs (nothing links them), so the tests build them
/// once, with the same profile, before anything needs them. Plain `cargo test` is then complete
/// and never runs against stale plugins.
pub fn ensure_plugins() {
    static BUILT: OnceLock<()> = OnceLock::new();
    BUILT.get_or_init(|| {
        let exe = std::env::current_exe().unwrap();
        let profile_dir = exe.parent().unwrap().parent().unwrap();
        let mut cmd = Command::new(env!("CARGO"));
        cmd.args(["build", "--workspace", "--lib", "--quiet"])
            .current_dir(root());
        if profile_dir.file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        let status = cmd.status().expect("cannot run cargo to build the plugins");
        assert!(status.success(), "building the plugins failed");
    });
}

/// Copies the test plugin `lib` (a crate of `tests/plugins`, e.g. `testplug_panics`) into `dir`
/// as the library of `as_name` (`luxon_panics`: found by the plugin scanner there), unless it
/// is there already: writing over a loaded library would change the code it runs.
pub fn install_plugin(dir: &Path, lib: &str, as_name: &str) -> PathBuf {
    ensure_plugins();
    let exe = std::env::current_exe().unwrap();
    let profile_dir = exe.parent().unwrap().parent().unwrap();
    let file = |n: &str| {
        format!(
            "{}{n}{}",
            std::env::consts::DLL_PREFIX,
            std::env::consts::DLL_SUFFIX
        )
    };
    let dst = dir.join(file(as_name));
    if !dst.exists() {
        std::fs::copy(profile_dir.join(file(lib)), &dst).unwrap();
    }
    dst
}

/// An API context on `threads` threads (0: every CPU) with the scene's plugin path.
pub fn api_context(desc: &SceneDesc, threads: usize) -> luxon::api::Context {
    ensure_plugins();
    luxon::api::Context::new(luxon::api::ContextOptions {
        plugin_path: desc.plugin_path.clone(),
        threads,
    })
    .unwrap_or_else(|e| panic!("{e}"))
}

/// Renders `scene` through the API into a linear RGBA f32 buffer of `w`×`h`.
pub fn api_render(
    r: &luxon::api::Renderer,
    scene: &mut luxon::api::Scene,
    w: u32,
    h: u32,
) -> Result<Vec<[f32; 4]>, luxon::Error> {
    use luxon::api::{Color, Plane, Target};
    let mut px = vec![[0.0f32; 4]; w as usize * h as usize];
    let target = Target {
        width: w,
        height: h,
        color: Color::Rgba32fLinear(Plane::new(&mut px, w as usize)),
        depth: None,
    };
    r.render(scene, target)?;
    Ok(px)
}

/// The bits of every channel of every pixel (for bitwise comparisons).
pub fn bits(px: &[[f32; 4]]) -> Vec<u32> {
    px.iter().flatten().map(|v| v.to_bits()).collect()
}

pub fn registry(desc: &SceneDesc) -> Registry {
    ensure_plugins();
    Registry::discover(&desc.plugin_path)
}

/// Loads a scene file, lets `edit` change its description, builds and renders it.
pub fn render_with(path: &Path, edit: impl FnOnce(&mut SceneDesc)) -> Framebuffer {
    let mut desc = luxon_formats::load(path).unwrap_or_else(|e| panic!("{e}"));
    edit(&mut desc);
    let reg = registry(&desc);
    let scene = Scene::build(&desc, &reg).unwrap_or_else(|e| panic!("{e}"));
    luxon::render::render(&scene, &|_, _| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// Renders RON text (written to a temporary scene file in `dir`).
pub fn render_text(dir: &Path, ron: &str, edit: impl FnOnce(&mut SceneDesc)) -> Framebuffer {
    let p = dir.join("scene.ron");
    std::fs::write(&p, ron).unwrap();
    render_with(&p, edit)
}

pub fn luxon() -> Command {
    ensure_plugins();
    Command::new(env!("CARGO_BIN_EXE_luxon"))
}

pub fn run(args: &[&str]) -> Output {
    luxon().args(args).output().expect("cannot run luxon")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// A fresh, empty directory for one test, under this process's own scratch directory.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = scratch_root().join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `$TMPDIR/luxon-tests/<pid>`. A test keeps its directory for inspection after it fails, so
/// nothing is removed at the end; instead the first call sweeps the directories of test
/// processes that have exited (hundreds of megabytes per full run otherwise pile up).
fn scratch_root() -> &'static Path {
    static ROOT: OnceLock<PathBuf> = OnceLock::new();
    ROOT.get_or_init(|| {
        let parent = std::env::temp_dir().join("luxon-tests");
        if let Ok(entries) = std::fs::read_dir(&parent) {
            for e in entries.flatten() {
                let pid = e.file_name().to_string_lossy().parse::<u32>();
                if matches!(pid, Ok(pid) if !process_alive(pid)) {
                    let _ = std::fs::remove_dir_all(e.path());
                }
            }
        }
        parent.join(std::process::id().to_string())
    })
}

/// Whether a process with this id exists; where that cannot be told, it is taken as alive so
/// that nothing of a running test is removed.
fn process_alive(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

/// 8-bit sRGB RGB, as the PNG writer stores it.
pub fn to_srgb8(fb: &Framebuffer) -> Vec<u8> {
    fb.rgba
        .chunks_exact(4)
        .flat_map(|p| [0, 1, 2].map(|k| (luxon_plugin::linear_to_srgb(p[k]) * 255.0 + 0.5) as u8))
        .collect()
}

/// Mean and maximum of |a - b| over 8-bit channels.
pub fn diff(a: &[u8], b: &[u8]) -> (f64, u8) {
    assert_eq!(a.len(), b.len());
    let mut sum = 0u64;
    let mut max = 0u8;
    for (x, y) in a.iter().zip(b) {
        let d = x.abs_diff(*y);
        sum += d as u64;
        max = max.max(d);
    }
    (sum as f64 / a.len() as f64, max)
}

/// Writes `scene.ron` with `volumes` (RON list items) into `dir` and loads it.
pub fn volume_scene(dir: &Path, volumes: &str) -> SceneDesc {
    let text = format!(
        "(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    volumes: [\n{volumes}\n    ],\n)\n"
    );
    let path = dir.join("scene.ron");
    std::fs::write(&path, text).unwrap();
    luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Reads volume `i` of the scene as `Scene::build` does.
pub fn read_volume_of(
    desc: &SceneDesc,
    reg: &Registry,
    i: usize,
) -> Result<luxon::volume::Volume, (luxon_formats::Origin, String)> {
    let v = &desc.volumes[i];
    let call = &v.value.call;
    let entry = reg
        .get(&call.plugin.value, luxon::plugin::PluginKind::VolumeReader)
        .unwrap_or_else(|e| panic!("{e}"));
    let name = match &v.value.name {
        Some(n) => n.value.clone(),
        None => format!("volume {i}"),
    };
    let dir = desc.source.parent().unwrap();
    let budget = std::sync::Arc::new(luxon::budget::Budget::unlimited());
    luxon::plugin::read_volume(
        reg,
        entry,
        &call.params,
        &call.params_at,
        dir,
        &name,
        &budget,
    )
}

/// Runs `cmd` (an `mpirun`, whose own `--timeout` should fire first) and kills it if it is still
/// running `limit` after the start: a hung job fails the test instead of hanging the suite.
#[allow(dead_code)]
pub fn run_with_deadline(
    cmd: &mut std::process::Command,
    limit: std::time::Duration,
    what: &str,
) -> (std::process::Output, std::time::Duration) {
    let start = std::time::Instant::now();
    let mut child = cmd.spawn().expect("cannot run mpirun (install OpenMPI)");
    while child.try_wait().expect("mpirun").is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{what} hung");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    (
        child.wait_with_output().expect("mpirun output"),
        start.elapsed(),
    )
}
