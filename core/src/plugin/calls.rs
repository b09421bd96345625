//! Calling into plugins: the host side of the sinks, and errors mapped back to the scene file.

use super::registry::{Entry, Registry};
use crate::geometry::custom::CustomObject;
use crate::geometry::plane::Plane;
use crate::geometry::triangle::{VertexAttr, NO_ATTR};
use crate::geometry::{custom::Customs, plane::Planes, sphere::Spheres, triangle::Triangles};
use crate::math::{DVec3, Vec3A};
use glam::Vec3;
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
    }
}

/// Where a primitive plugin's geometry goes. Coordinates arrive in f64 world space and are
/// stored re-centred on `world_offset` in f32.
pub struct GeometryBuilder<'a> {
    pub spheres: &'a mut Spheres,
    pub triangles: &'a mut Triangles,
    pub planes: &'a mut Planes,
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

extern "C" fn add_spheres(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    guard(err, || {
        let b = builder(ctx);
        let v = unsafe { slice(data, checked_len(count, 4, "sphere")?) };
        for (i, s) in v.chunks_exact(4).enumerate() {
            if s.iter().any(|x| !x.is_finite()) {
                return Err(format!("sphere {i} has a non-finite value {s:?}"));
            }
            if s[3] <= 0.0 {
                return Err(format!(
                    "sphere {i} has radius {}; expected a radius > 0",
                    s[3]
                ));
            }
            let c = (DVec3::new(s[0], s[1], s[2]) - b.world_offset).as_vec3();
            b.spheres.push([c.x, c.y, c.z, s[3] as f32], b.material);
        }
        Ok(())
    })
}

extern "C" fn add_planes(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    guard(err, || {
        let b = builder(ctx);
        let v = unsafe { slice(data, checked_len(count, 6, "plane")?) };
        for (i, p) in v.chunks_exact(6).enumerate() {
            if p.iter().any(|x| !x.is_finite()) {
                return Err(format!("plane {i} has a non-finite value {p:?}"));
            }
            let n = DVec3::new(p[3], p[4], p[5]);
            if n.length() == 0.0 {
                return Err(format!("plane {i} has a zero-length normal"));
            }
            let point = (DVec3::new(p[0], p[1], p[2]) - b.world_offset).as_vec3();
            b.planes.planes.push(Plane {
                point: point.into(),
                normal: Vec3A::from(n.normalize().as_vec3()),
                material: b.material,
            });
        }
        Ok(())
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
        let pos = unsafe { slice(m.positions, checked_len(m.vertex_count, 3, "vertex")?) };
        let idx = unsafe { slice(m.indices, checked_len(m.triangle_count, 3, "triangle")?) };
        let normals = unsafe { slice(m.normals, if m.normals.is_null() { 0 } else { nv * 3 }) };
        let colors = unsafe { slice(m.colors, if m.colors.is_null() { 0 } else { nv * 3 }) };
        let uvs = unsafe { slice(m.uvs, if m.uvs.is_null() { 0 } else { nv * 2 }) };
        if let Some(i) = pos.iter().position(|x| !x.is_finite()) {
            return Err(format!("vertex {} has a non-finite coordinate", i / 3));
        }
        if normals.iter().any(|x| !x.is_finite())
            || colors.iter().any(|x| !x.is_finite())
            || uvs.iter().any(|x| !x.is_finite())
        {
            return Err("mesh has a non-finite normal, colour or uv".into());
        }
        let verts: Vec<Vec3> = pos
            .chunks_exact(3)
            .map(|p| (DVec3::new(p[0], p[1], p[2]) - b.world_offset).as_vec3())
            .collect();
        let has_attr = !normals.is_empty() || !colors.is_empty() || !uvs.is_empty();
        let attr_of = |v: usize| VertexAttr {
            n: if normals.is_empty() {
                Vec3::ZERO
            } else {
                DVec3::new(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2])
                    .normalize_or_zero()
                    .as_vec3()
            },
            c: if colors.is_empty() {
                Vec3::splat(-1.0)
            } else {
                Vec3::new(colors[3 * v], colors[3 * v + 1], colors[3 * v + 2])
            },
            uv: if uvs.is_empty() {
                [0.0; 2]
            } else {
                [uvs[2 * v], uvs[2 * v + 1]]
            },
        };
        for (t, tri) in idx.chunks_exact(3).enumerate() {
            let mut v = [Vec3::ZERO; 3];
            for k in 0..3 {
                let i = tri[k];
                if i >= nv as u64 {
                    return Err(format!(
                        "triangle {t} uses vertex {i}, but the mesh has {nv} vertices"
                    ));
                }
                v[k] = verts[i as usize];
            }
            // Zero-area triangles (after rounding) can never be hit and have no normal.
            if (v[1] - v[0]).cross(v[2] - v[0]) == Vec3::ZERO {
                b.dropped += 1;
                continue;
            }
            b.triangles.verts.push(v);
            b.triangles.material.push(b.material);
            if has_attr {
                b.triangles.attr.push(b.triangles.attrs.len() as u32);
                b.triangles.attrs.push([
                    attr_of(tri[0] as usize),
                    attr_of(tri[1] as usize),
                    attr_of(tri[2] as usize),
                ]);
            } else {
                b.triangles.attr.push(NO_ATTR);
            }
        }
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
