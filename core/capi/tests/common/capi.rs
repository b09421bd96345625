//! libluxon.so loaded as a C program links it: its functions by their exported names, its
//! structs as the header declares them (tests/compile.rs checks the header itself).

use super::{ensure_built, profile_dir};
use libloading::Library;
use std::ffi::{c_char, c_void, CStr};
use std::sync::OnceLock;

/// Any handle (`luxon_scene`, `luxon_renderer`...: one `uint64_t` passed by value).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Handle {
    pub id: u64,
}

#[repr(C)]
pub struct ContextOptions {
    pub size: u32,
    pub threads: u32,
    pub plugin_path: *const c_char,
}

#[repr(C)]
#[derive(Clone, Copy)]
pub struct TargetDesc {
    pub size: u32,
    pub width: u32,
    pub height: u32,
    pub format: i32,
    pub pixels: *mut c_void,
    pub row_bytes: usize,
    pub depth: *mut f32,
    pub depth_row_bytes: usize,
}

#[repr(C)]
#[derive(Default)]
pub struct CommitReport {
    pub size: u32,
    pub rebuilt: u32,
    pub shading: u32,
    pub bvh_seconds: f64,
    pub commit_seconds: f64,
}

pub type LogFn = Option<unsafe extern "C" fn(i32, *const c_char, *mut c_void)>;

pub type ProgressFn = Option<unsafe extern "C" fn(u64, u64, *mut c_void) -> i32>;

pub const OK: i32 = 0;
pub const INVALID_ARGUMENT: i32 = 1;
pub const INVALID_HANDLE: i32 = 2;
pub const SCENE: i32 = 3;
pub const PLUGIN_NOT_FOUND: i32 = 4;
pub const IO: i32 = 6;
pub const CANCELLED: i32 = 7;
pub const BUSY: i32 = 8;
pub const UNSUPPORTED: i32 = 9;
pub const MPI: i32 = 10;
pub const PANIC: i32 = 11;
pub const RGBA8: i32 = 1;
pub const RGBA32F: i32 = 2;

macro_rules! functions {
    ($($name:ident($($ty:ty),*) -> $ret:ty;)*) => {
        /// The library's functions.
        pub struct Capi {
            _lib: Library,
            $(pub $name: unsafe extern "C" fn($($ty),*) -> $ret,)*
        }

        impl Capi {
            fn load(lib: Library) -> Capi {
                $(
                    let symbol = concat!(stringify!($name), "\0").as_bytes();
                    // SAFETY: the header declares the function with this signature.
                    let $name = unsafe {
                        *lib.get::<unsafe extern "C" fn($($ty),*) -> $ret>(symbol)
                            .unwrap_or_else(|e| panic!("{}: {e}", stringify!($name)))
                    };
                )*
                Capi { _lib: lib, $($name,)* }
            }
        }
    };
}

functions! {
    luxon_api_version() -> u32;
    luxon_version_string() -> *const c_char;
    luxon_version(*mut u32, *mut u32, *mut u32) -> ();
    luxon_plugin_abi_version() -> u32;
    luxon_has_mpi() -> bool;
    luxon_last_error() -> *const c_char;
    luxon_last_error_copy(*mut c_char, usize) -> usize;
    luxon_context_create(*const ContextOptions, *mut Handle) -> i32;
    luxon_context_release(Handle) -> i32;
    luxon_scene_create(Handle, *mut Handle) -> i32;
    luxon_scene_load(Handle, *const c_char, *mut Handle) -> i32;
    luxon_scene_load_ron(Handle, *const c_char, *const c_char, *mut Handle) -> i32;
    luxon_scene_release(Handle) -> i32;
    luxon_scene_set_camera_ron(Handle, *const c_char) -> i32;
    luxon_scene_set_background(Handle, f64, f64, f64) -> i32;
    luxon_scene_set_render_ron(Handle, *const c_char) -> i32;
    luxon_scene_add_light_ron(Handle, *const c_char, *mut Handle) -> i32;
    luxon_scene_add_object(Handle, *const c_char, *const c_char, *const c_char, *const c_char, *mut Handle) -> i32;
    luxon_scene_remove(Handle, Handle) -> i32;
    luxon_scene_commit(Handle, Handle, *mut CommitReport) -> i32;
    luxon_renderer_create(Handle, u32, *mut Handle) -> i32;
    luxon_renderer_release(Handle) -> i32;
    luxon_renderer_cancel(Handle) -> i32;
    luxon_renderer_set_progress(Handle, ProgressFn, *mut c_void) -> i32;
    luxon_renderer_set_mpi_comm_f(Handle, i32) -> i32;
    luxon_render(Handle, Handle, *const TargetDesc, *mut c_void) -> i32;
    luxon_write_image(Handle, *const c_char, *const f32, u32, u32, usize) -> i32;
    luxon_scene_save_ron(Handle, *const c_char) -> i32;
    luxon_scene_set_fog_ron(Handle, *const c_char) -> i32;
    luxon_scene_set_ambient_occlusion_ron(Handle, *const c_char) -> i32;
    luxon_scene_set_origin(Handle, *const f64) -> i32;
    luxon_scene_set_frame(Handle, u32) -> i32;
    luxon_scene_objects(Handle, *mut Handle, usize, *mut usize) -> i32;
    luxon_set_log(LogFn, *mut c_void, i32) -> i32;
    luxon_scene_set_material_ron(Handle, *const c_char, *const c_char) -> i32;
    luxon_scene_set_texture(Handle, *const c_char, *const c_char, *const c_char) -> i32;
    luxon_scene_set_clip_group(Handle, *const c_char, *const c_char) -> i32;
    luxon_scene_add_volume_plugin(Handle, *const c_char, *const c_char, *const c_char, *const c_char, *mut Handle) -> i32;
}

/// The library, loaded once per test process.
pub fn capi() -> &'static Capi {
    static LIB: OnceLock<Capi> = OnceLock::new();
    LIB.get_or_init(|| {
        ensure_built();
        let path = profile_dir().join(format!(
            "{}luxon{}",
            std::env::consts::DLL_PREFIX,
            std::env::consts::DLL_SUFFIX
        ));
        // SAFETY: libluxon's initialisers are Rust's (none of its own); it stays loaded for
        // the process (held by the static).
        let lib = unsafe { Library::new(&path) }.unwrap_or_else(|e| panic!("{e}"));
        Capi::load(lib)
    })
}

/// This thread's last error, as text.
pub fn last_error() -> String {
    // SAFETY: luxon_last_error returns a valid NUL-terminated string, never NULL.
    unsafe { CStr::from_ptr((capi().luxon_last_error)()) }
        .to_string_lossy()
        .into_owned()
}

/// Asserts `status` is `want` and the last error starts with `prefix`.
#[track_caller]
pub fn expect(status: i32, want: i32, prefix: &str) {
    let message = last_error();
    assert_eq!(
        (status, message.starts_with(prefix)),
        (want, true),
        "{message}"
    );
}

/// A context on 2 threads with the default plugin path.
pub fn context() -> Handle {
    let options = ContextOptions {
        size: std::mem::size_of::<ContextOptions>() as u32,
        threads: 2,
        plugin_path: std::ptr::null(),
    };
    let mut ctx = Handle::default();
    // SAFETY: valid options and out-pointer.
    let s = unsafe { (capi().luxon_context_create)(&options, &mut ctx) };
    expect(s, OK, "");
    ctx
}

/// A renderer on the context's pool.
pub fn renderer(ctx: Handle) -> Handle {
    let mut r = Handle::default();
    // SAFETY: a valid out-pointer.
    let s = unsafe { (capi().luxon_renderer_create)(ctx, 0, &mut r) };
    expect(s, OK, "");
    r
}

/// A scene from RON scene text.
pub fn scene_ron(ctx: Handle, ron: &str) -> Handle {
    let text = std::ffi::CString::new(ron).unwrap();
    let mut scene = Handle::default();
    // SAFETY: valid strings (name NULL) and out-pointer.
    let s =
        unsafe { (capi().luxon_scene_load_ron)(ctx, text.as_ptr(), std::ptr::null(), &mut scene) };
    expect(s, OK, "");
    scene
}

/// A packed RGBA f32 target over `px`.
pub fn target_f32(px: &mut [[f32; 4]], w: u32, h: u32) -> TargetDesc {
    TargetDesc {
        size: std::mem::size_of::<TargetDesc>() as u32,
        width: w,
        height: h,
        format: RGBA32F,
        pixels: px.as_mut_ptr().cast(),
        row_bytes: 0,
        depth: std::ptr::null_mut(),
        depth_row_bytes: 0,
    }
}

/// A small scene: a sphere on a plane under a light, `samples` per pixel.
pub fn ball_scene(samples: u32) -> String {
    format!(
        "Scene(camera: (position: (0, 1, -5), look_at: (0, 0.5, 0)), \
         lights: [Point(position: (-4, 6, -5))], \
         objects: [(plugin: \"sphere\", params: (center: (0, 0.8, 0), radius: 0.8)), \
         (plugin: \"plane\", params: (point: (0, 0, 0), normal: (0, 1, 0)))], \
         render: (width: 8, height: 8, samples: {samples}))"
    )
}
