//! Calling into plugins: the host side of the sinks, and errors mapped back to the scene file.

use super::registry::{Entry, PluginKind, Registry};
use crate::geometry::cone::Cones;
use crate::geometry::custom::CustomObject;
use crate::geometry::disc::Discs;
use crate::geometry::triangle::MeshInput;
use crate::geometry::{custom::Customs, plane::Planes, sphere::Spheres, triangle::Triangles};
use crate::math::DVec3;
use crate::volume::VolumeBuilder;
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

/// An error reported by a plugin, with its position inside the params text.
struct Reported {
    message: Option<String>,
    line: u32,
    col: u32,
}

extern "C" fn set_error(ctx: *mut c_void, message: abi::Str, line: u32, col: u32) {
    // SAFETY: ctx is the `Reported` owned by `call_plugin` for the duration of the call.
    let r = unsafe { &mut *(ctx as *mut Reported) };
    r.message = Some(
        unsafe { message.as_str() }
            .unwrap_or("(invalid UTF-8)")
            .to_string(),
    );
    r.line = line;
    r.col = col;
}

/// Maps a position inside params text that starts at `start` to the scene file.
pub fn offset_origin(start: &Origin, line: u32, col: u32) -> Origin {
    if line == 0 {
        return start.clone();
    }
    Origin {
        file: start.file.clone(),
        line: start.line + line - 1,
        col: if line == 1 {
            start.col + col.max(1) - 1
        } else {
            col
        },
    }
}

/// Runs one plugin call with an error sink; returns the message and its scene position on error.
pub fn call_plugin(
    registry: &Registry,
    entry: &Entry,
    params_at: &Origin,
    f: impl FnOnce(&abi::ErrorSink) -> abi::Status,
) -> Result<(), (Origin, String)> {
    let mut reported = Reported {
        message: None,
        line: 0,
        col: 0,
    };
    let sink = abi::ErrorSink {
        ctx: &mut reported as *mut Reported as *mut c_void,
        set: set_error,
    };
    let status = f(&sink);
    if status == abi::STATUS_OK {
        return Ok(());
    }
    let lib = registry.library_of(entry);
    let file = lib
        .path
        .file_name()
        .map(|f| f.to_string_lossy().to_string())
        .unwrap_or_default();
    let what = if status == abi::STATUS_PANIC {
        "panicked"
    } else {
        "failed"
    };
    let detail = reported.message.unwrap_or_else(|| "no message".into());
    let detail = detail
        .strip_prefix("panicked: ")
        .unwrap_or(&detail)
        .to_string();
    Err((
        offset_origin(params_at, reported.line, reported.col),
        format!("plugin `{}` ({file}) {what}: {detail}", entry.name),
    ))
}

pub fn call_context<'a>(scene_dir: &'a str, instance: &'a str) -> abi::CallContext {
    abi::CallContext {
        scene_dir: abi::Str::new(scene_dir),
        instance: abi::Str::new(instance),
        texture_cache_bytes: 0,
        threads: rayon::current_num_threads() as u32,
    }
}

/// Where a primitive plugin's geometry goes. Coordinates arrive in f64 world space and are
/// stored re-centred on `world_offset` in f32.
pub struct GeometryBuilder<'a> {
    pub spheres: &'a mut Spheres,
    pub triangles: &'a mut Triangles,
    pub planes: &'a mut Planes,
    pub cones: &'a mut Cones,
    pub discs: &'a mut Discs,
    pub customs: &'a mut Customs,
    pub material: u32,
    pub world_offset: DVec3,
    pub plugin: String,
    /// Degenerate triangles dropped.
    pub dropped: u64,
}

fn fail(err: *const abi::ErrorSink, msg: &str) -> abi::Status {
    if let Some(e) = unsafe { err.as_ref() } {
        (e.set)(e.ctx, abi::Str::new(msg), 0, 0);
    }
    abi::STATUS_ERROR
}

/// Host callbacks must never unwind into plugin frames.
fn guard(err: *const abi::ErrorSink, f: impl FnOnce() -> Result<(), String>) -> abi::Status {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => abi::STATUS_OK,
        Ok(Err(m)) => fail(err, &m),
        Err(_) => fail(err, "internal error in the host while storing geometry"),
    }
}

fn builder<'a>(ctx: *mut c_void) -> &'a mut GeometryBuilder<'a> {
    // SAFETY: ctx is the builder passed in `GeometrySink::ctx` for the duration of create().
    unsafe { &mut *(ctx as *mut GeometryBuilder) }
}

unsafe fn slice<'a, T>(ptr: *const T, len: usize) -> &'a [T] {
    if len == 0 || ptr.is_null() {
        &[]
    } else {
        std::slice::from_raw_parts(ptr, len)
    }
}

fn checked_len(count: u64, per: u64, what: &str) -> Result<usize, String> {
    count
        .checked_mul(per)
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| format!("{what} count {count} is too large"))
}

/// Stores a batch of `count` records of `N` f64 each through `push(builder, index, record)`.
fn add_batch<const N: usize>(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
    what: &str,
    push: impl Fn(&mut GeometryBuilder, usize, [f64; N]) -> Result<(), String>,
) -> abi::Status {
    guard(err, || {
        let b = builder(ctx);
        // SAFETY: the plugin passes `count` records of N values (ABI contract).
        let v = unsafe { slice(data, checked_len(count, N as u64, what)?) };
        for (i, r) in v.chunks_exact(N).enumerate() {
            push(b, i, r.try_into().expect("chunk of N"))?;
        }
        Ok(())
    })
}

extern "C" fn add_spheres(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    add_batch(ctx, data, count, err, "sphere", |b, i, r: [f64; 4]| {
        b.spheres.push_world(i, r, b.world_offset, b.material)
    })
}

extern "C" fn add_planes(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    add_batch(ctx, data, count, err, "plane", |b, i, r: [f64; 6]| {
        b.planes.push_world(i, r, b.world_offset, b.material)
    })
}

extern "C" fn add_cones(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    add_batch(ctx, data, count, err, "cone", |b, i, r: [f64; 8]| {
        b.cones.push_world(i, r, b.world_offset, b.material)
    })
}

extern "C" fn add_discs(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    add_batch(ctx, data, count, err, "disc", |b, i, r: [f64; 8]| {
        b.discs.push_world(i, r, b.world_offset, b.material)
    })
}

extern "C" fn add_mesh(
    ctx: *mut c_void,
    mesh: *const abi::MeshData,
    err: *const abi::ErrorSink,
) -> abi::Status {
    guard(err, || {
        let b = builder(ctx);
        let m = unsafe { mesh.as_ref() }.ok_or("no mesh data")?;
        let nv = checked_len(m.vertex_count, 1, "vertex")?;
        let optional = |p: bool, per: usize| if p { 0 } else { nv * per };
        // SAFETY: the plugin guarantees the arrays' lengths (ABI contract of MeshData).
        let input = unsafe {
            MeshInput {
                positions: slice(m.positions, checked_len(m.vertex_count, 3, "vertex")?),
                indices: slice(m.indices, checked_len(m.triangle_count, 3, "triangle")?),
                normals: slice(m.normals, optional(m.normals.is_null(), 3)),
                colors: slice(m.colors, optional(m.colors.is_null(), 3)),
                uvs: slice(m.uvs, optional(m.uvs.is_null(), 2)),
            }
        };
        b.dropped += b.triangles.push_mesh(&input, b.world_offset, b.material)?;
        Ok(())
    })
}

extern "C" fn add_custom(
    ctx: *mut c_void,
    g: *const abi::CustomGeometry,
    err: *const abi::ErrorSink,
) -> abi::Status {
    guard(err, || {
        let b = builder(ctx);
        let g = unsafe { g.as_ref() }.ok_or("no custom geometry")?;
        if g.vtable.is_null() {
            return Err("custom geometry without a function table".into());
        }
        // Own it first so it is destroyed even if we reject it.
        let object = CustomObject {
            object: g.object,
            vtable: g.vtable,
            plugin: b.plugin.clone(),
            count: g.count,
        };
        if g.count > u32::MAX as u64 {
            return Err(format!(
                "custom geometry with {} primitives is too large",
                g.count
            ));
        }
        let o = b.customs.objects.len() as u32;
        for i in 0..object.count {
            b.customs.refs.push((o, i));
            b.customs.material.push(b.material);
        }
        b.customs.objects.push(object);
        Ok(())
    })
}

/// Runs a primitive plugin's `create` into `builder`.
pub fn create_primitive(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    instance: &str,
    builder: &mut GeometryBuilder,
) -> Result<(), (Origin, String)> {
    let sink = abi::GeometrySink {
        ctx: builder as *mut GeometryBuilder as *mut c_void,
        add_spheres,
        add_planes,
        add_cones,
        add_discs,
        add_mesh,
        add_custom,
    };
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance);
    // SAFETY: the entry is a primitive, so its vtable is a PrimitiveVTable.
    let vt = unsafe { &*(entry.vtable as *const abi::PrimitiveVTable) };
    call_plugin(registry, entry, params_at, |err| {
        (vt.create)(abi::Str::new(params), &ctx, &sink, err)
    })
}

/// A texture instance created by a plugin; destroyed through it on drop.
pub struct TextureInstance {
    object: *mut c_void,
    vtable: *const abi::TextureInstanceVTable,
    pub plugin: String,
}

// SAFETY: the SDK requires textures to be Send + Sync.
unsafe impl Send for TextureInstance {}
unsafe impl Sync for TextureInstance {}

impl TextureInstance {
    /// Linear RGBA, or `None` when the plugin panicked.
    #[inline]
    pub fn eval(&self, q: &abi::TexQuery) -> Option<[f32; 4]> {
        let mut out = [0.0f32; 4];
        // SAFETY: valid table of a loaded plugin.
        let s = unsafe { ((*self.vtable).eval)(self.object, q, &mut out) };
        (s == abi::STATUS_OK).then_some(out)
    }
}

impl Drop for TextureInstance {
    fn drop(&mut self) {
        // SAFETY: created by this plugin, destroyed once.
        unsafe { ((*self.vtable).destroy)(self.object) };
    }
}

pub fn create_texture(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    instance: &str,
) -> Result<TextureInstance, (Origin, String)> {
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance);
    let mut out = abi::TextureObject {
        object: std::ptr::null_mut(),
        vtable: std::ptr::null(),
    };
    // SAFETY: the entry is a texture, so its vtable is a TextureVTable.
    let vt = unsafe { &*(entry.vtable as *const abi::TextureVTable) };
    call_plugin(registry, entry, params_at, |err| {
        (vt.create)(abi::Str::new(params), &ctx, &mut out, err)
    })?;
    if out.vtable.is_null() {
        return Err((
            params_at.clone(),
            format!("plugin `{}` returned no texture", entry.name),
        ));
    }
    Ok(TextureInstance {
        object: out.object,
        vtable: out.vtable,
        plugin: entry.name.clone(),
    })
}

extern "C" fn collect_bytes(ctx: *mut c_void, data: *const u8, len: usize) -> abi::Status {
    // SAFETY: ctx is the Vec owned by `encode_image` for the duration of the call.
    let v = unsafe { &mut *(ctx as *mut Vec<u8>) };
    match catch_unwind(AssertUnwindSafe(|| {
        v.extend_from_slice(unsafe { slice(data, len) })
    })) {
        Ok(()) => abi::STATUS_OK,
        Err(_) => abi::STATUS_ERROR,
    }
}

/// Encodes an image with a writer plugin into bytes.
#[allow(clippy::too_many_arguments)]
pub fn encode_image(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    width: u32,
    height: u32,
    rgba: &[f32],
) -> Result<Vec<u8>, (Origin, String)> {
    let mut bytes: Vec<u8> = Vec::new();
    let sink = abi::ByteSink {
        ctx: &mut bytes as *mut Vec<u8> as *mut c_void,
        write: collect_bytes,
    };
    let image = abi::ImageView {
        width,
        height,
        rgba: rgba.as_ptr(),
    };
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, "");
    // SAFETY: the entry is a writer, so its vtable is a WriterVTable.
    let vt = unsafe { &*(entry.vtable as *const abi::WriterVTable) };
    call_plugin(registry, entry, params_at, |err| {
        (vt.write)(abi::Str::new(params), &ctx, &image, &sink, err)
    })?;
    Ok(bytes)
}

// ------------------------------------------------------------------------------------------------
// Volume readers: the host side of `VolumeSink`. Storage and checks live in `crate::volume`.
// ------------------------------------------------------------------------------------------------

/// "plugin `name` (library file)", as messages name a plugin.
pub fn plugin_label(registry: &Registry, entry: &Entry) -> String {
    let file = registry
        .library_of(entry)
        .path
        .file_name()
        .map(|f| f.to_string_lossy().to_string())
        .unwrap_or_default();
    format!("plugin `{}` ({file})", entry.name)
}

/// Runs one volume sink callback: never unwinds, and any failure (a panic included) stops the
/// volume so the read fails even if the plugin ignores the error.
fn volume_call(
    ctx: *mut c_void,
    err: *const abi::ErrorSink,
    f: impl FnOnce(&mut VolumeBuilder) -> Result<(), String>,
) -> abi::Status {
    if ctx.is_null() {
        return fail(err, "the volume sink has no context");
    }
    // SAFETY: ctx is the builder passed in `VolumeSink::ctx` for the duration of read().
    let b = unsafe { &mut *(ctx as *mut VolumeBuilder) };
    let message = match catch_unwind(AssertUnwindSafe(|| f(&mut *b))) {
        Ok(Ok(())) => return abi::STATUS_OK,
        Ok(Err(m)) => m,
        Err(_) => {
            let m = "internal error in the host while storing volume data";
            let _ = catch_unwind(AssertUnwindSafe(|| b.fail(m)));
            m.to_string()
        }
    };
    fail(err, &message)
}

extern "C" fn volume_begin(
    ctx: *mut c_void,
    desc: *const abi::VolumeDesc,
    err: *const abi::ErrorSink,
) -> abi::Status {
    volume_call(ctx, err, |b| {
        let Some(d) = (unsafe { desc.as_ref() }) else {
            let m = "`begin` was given no grid description";
            b.fail(m);
            return Err(m.into());
        };
        let Ok(name) = (unsafe { d.grid_name.as_str() }) else {
            let m = "the grid name is not valid UTF-8";
            b.fail(m);
            return Err(m.into());
        };
        b.begin(
            d.world_from_index,
            d.background,
            d.index_min,
            d.index_max,
            name,
        )
    })
}

extern "C" fn volume_add_dense(
    ctx: *mut c_void,
    origin: *const [i64; 3],
    dims: *const [u64; 3],
    values: *const f32,
    err: *const abi::ErrorSink,
) -> abi::Status {
    volume_call(ctx, err, |b| {
        let (Some(&origin), Some(&dims)) = (unsafe { origin.as_ref() }, unsafe { dims.as_ref() })
        else {
            let m = "`add_dense` was given a null origin or size";
            b.fail(m);
            return Err(m.into());
        };
        // The builder checks the size against the grid; here it only has to be addressable.
        let n = dims
            .iter()
            .try_fold(1u64, |a, &d| a.checked_mul(d))
            .and_then(|n| usize::try_from(n).ok())
            .filter(|&n| n <= usize::MAX / std::mem::size_of::<f32>());
        let Some(n) = n else {
            let m = format!(
                "dense block at {origin:?} of {}x{}x{} voxels has too many voxels (the count \
                 overflows)",
                dims[0], dims[1], dims[2]
            );
            b.fail(&m);
            return Err(m);
        };
        if values.is_null() && n > 0 {
            let m = format!("dense block at {origin:?} was given no values (a null pointer)");
            b.fail(&m);
            return Err(m);
        }
        // Borrowed for the call (ABI contract); `n` values, x fastest.
        let values = unsafe { slice(values, n) };
        b.add_dense(origin, dims, values)
    })
}

extern "C" fn volume_add_tile(
    ctx: *mut c_void,
    origin: *const [i64; 3],
    dims: *const [u64; 3],
    value: f32,
    err: *const abi::ErrorSink,
) -> abi::Status {
    volume_call(ctx, err, |b| {
        let (Some(&origin), Some(&dims)) = (unsafe { origin.as_ref() }, unsafe { dims.as_ref() })
        else {
            let m = "`add_tile` was given a null origin or size";
            b.fail(m);
            return Err(m.into());
        };
        b.add_tile(origin, dims, value)
    })
}

/// Runs a volume-reader plugin's `read` into `builder` (which must be fresh). `entry` must be a
/// volume reader.
#[allow(clippy::too_many_arguments)]
pub fn read_volume_into(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    instance: &str,
    builder: &mut VolumeBuilder,
) -> Result<(), (Origin, String)> {
    if entry.kind != PluginKind::VolumeReader {
        return Err((
            params_at.clone(),
            format!(
                "{} is a {}, but a volume reader is expected here",
                plugin_label(registry, entry),
                entry.kind
            ),
        ));
    }
    let sink = abi::VolumeSink {
        ctx: builder as *mut VolumeBuilder as *mut c_void,
        begin: volume_begin,
        add_dense: volume_add_dense,
        add_tile: volume_add_tile,
    };
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance);
    // SAFETY: the entry is a volume reader (checked above), so its vtable is a
    // VolumeReaderVTable.
    let vt = unsafe { &*(entry.vtable as *const abi::VolumeReaderVTable) };
    call_plugin(registry, entry, params_at, |err| {
        (vt.read)(abi::Str::new(params), &ctx, &sink, err)
    })
}
