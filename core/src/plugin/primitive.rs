//! Primitive plugins: `create` and the host side of `GeometrySink`, which stores what a plugin
//! adds (spheres, planes, cones, discs, meshes, custom geometry) in the scene's native sets.

use super::calls::{call_context, call_plugin, checked_len, fail, slice, wrong_kind};
use super::registry::{Entry, PluginKind, Registry, Table};
use crate::budget::{Budget, Use};
use crate::geometry::cone::Cones;
use crate::geometry::custom::{CustomObject, Customs};
use crate::geometry::disc::Discs;
use crate::geometry::plane::Planes;
use crate::geometry::sphere::Spheres;
use crate::geometry::triangle::{MeshInput, Triangles};
use crate::math::DVec3;
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

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
    /// When set, the geometry is recorded here as the plugin gives it instead of stored in the
    /// sets (an object that moves is stored anew for every frame, see `scene::frame`; a
    /// prototype is stored once per instance, see `scene::instances`).
    pub record: Option<&'a mut Recorded>,
    /// Charged for what is stored (or recorded), before it is stored.
    pub budget: &'a Budget,
    /// The object, for messages: "object 3 (plugin `mesh`, scene.ron:20:9)".
    pub object: String,
    /// The scene's name for the object ("object 3") and where it is, given to its custom
    /// geometry for the messages of the render.
    pub instance: String,
    pub at: Origin,
}

impl GeometryBuilder<'_> {
    /// "object 3 (plugin `mesh`, scene.ron:20:9): 40000000 triangles", for budget messages.
    fn describe(&self, n: usize, kind: &str) -> impl Fn() -> String {
        let object = self.object.clone();
        let kind = kind.to_string();
        move || format!("{object}: {n} {kind}")
    }
}

/// A plugin's geometry exactly as it gave it (f64 world coordinates), in the order it gave it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Recorded {
    pub spheres: Vec<[f64; 4]>,
    pub planes: Vec<[f64; 6]>,
    pub cones: Vec<[f64; 8]>,
    pub discs: Vec<[f64; 8]>,
    pub meshes: Vec<RecordedMesh>,
}

impl Recorded {
    /// Bytes held (capacities), what recording charged to the budget.
    pub fn bytes(&self) -> u64 {
        held(&self.spheres)
            + held(&self.planes)
            + held(&self.cones)
            + held(&self.discs)
            + held(&self.meshes)
            + self.meshes.iter().map(RecordedMesh::bytes).sum::<u64>()
    }
}

/// Bytes of `v`'s capacity.
fn held<T>(v: &Vec<T>) -> u64 {
    (v.capacity() * std::mem::size_of::<T>()) as u64
}

/// A mesh's arrays as [`MeshInput`] takes them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RecordedMesh {
    pub positions: Vec<f64>,
    pub indices: Vec<u64>,
    pub normals: Vec<f64>,
    pub colors: Vec<f32>,
    pub uvs: Vec<f32>,
}

impl RecordedMesh {
    /// Copies `m`, charging its arrays to `budget` before they are allocated.
    fn record(m: &MeshInput, budget: &Budget, what: &dyn Fn() -> String) -> Result<Self, String> {
        fn copy<T: Copy>(
            src: &[T],
            budget: &Budget,
            what: &dyn Fn() -> String,
        ) -> Result<Vec<T>, String> {
            let mut v = Vec::new();
            budget.grow(&mut v, src.len(), Use::Geometry, what)?;
            v.extend_from_slice(src);
            Ok(v)
        }
        Ok(RecordedMesh {
            positions: copy(m.positions, budget, what)?,
            indices: copy(m.indices, budget, what)?,
            normals: copy(m.normals, budget, what)?,
            colors: copy(m.colors, budget, what)?,
            uvs: copy(m.uvs, budget, what)?,
        })
    }

    fn bytes(&self) -> u64 {
        held(&self.positions)
            + held(&self.indices)
            + held(&self.normals)
            + held(&self.colors)
            + held(&self.uvs)
    }

    pub fn input(&self) -> MeshInput<'_> {
        MeshInput {
            positions: &self.positions,
            indices: &self.indices,
            normals: &self.normals,
            colors: &self.colors,
            uvs: &self.uvs,
        }
    }
}

// The host side of `GeometrySink`. The plugin calls these during `create_primitive`, on its
// thread and one at a time (ABI contract), with the `ctx` we put in the sink: our
// `GeometryBuilder`, which nothing else touches until `create` returns. Errors go to the
// plugin's `err`, null or valid for the call.

/// Runs one sink call: never unwinds into plugin frames, and reports failures to `err`.
///
/// # Safety
/// `ctx` is the `GeometryBuilder` of the running `create_primitive`, not otherwise borrowed
/// during the call; `err` is null or valid for the call.
unsafe fn guard(
    ctx: *mut c_void,
    err: *const abi::ErrorSink,
    f: impl FnOnce(&mut GeometryBuilder) -> Result<(), String>,
) -> abi::Status {
    // SAFETY: the caller's promise.
    let (b, err) = unsafe { (&mut *(ctx as *mut GeometryBuilder), err.as_ref()) };
    match catch_unwind(AssertUnwindSafe(|| f(b))) {
        Ok(Ok(())) => abi::STATUS_OK,
        Ok(Err(m)) => fail(err, &m),
        Err(_) => fail(err, "internal error in the host while storing geometry"),
    }
}

/// How a batch makes room for `n` records in its set, within the budget (the message names
/// what needed it).
type Reserve = fn(&mut GeometryBuilder, usize, &dyn Fn() -> String) -> Result<(), String>;

/// Stores a batch of `count` records of `N` f64 each through `push(builder, index, record)`,
/// after `reserve` made room for them.
///
/// # Safety
/// As for [`guard`]; `data` is null or points to `count * N` values.
unsafe fn add_batch<const N: usize>(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
    what: &str,
    reserve: Reserve,
    push: impl Fn(&mut GeometryBuilder, usize, [f64; N]) -> Result<(), String>,
) -> abi::Status {
    let store = |b: &mut GeometryBuilder| {
        // SAFETY: the caller's promise about `data` (the length is checked to fit memory).
        let v = unsafe { slice(data, checked_len(count, N as u64, what)?) };
        let describe = b.describe(v.len() / N, &format!("{what}s"));
        reserve(b, v.len() / N, &describe)?;
        for (i, r) in v.chunks_exact(N).enumerate() {
            push(b, i, r.try_into().expect("chunk of N"))?;
        }
        Ok(())
    };
    // SAFETY: the caller's promise.
    unsafe { guard(ctx, err, store) }
}

/// # Safety
/// See the comment above [`guard`].
unsafe extern "C" fn add_spheres(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: the caller keeps the ABI contract (see the comment above `guard`).
    unsafe {
        let reserve: Reserve = |b, n, what| match b.record.as_deref_mut() {
            Some(rec) => Ok(b.budget.grow(&mut rec.spheres, n, Use::Geometry, what)?),
            None => b.spheres.reserve(n, b.budget, what),
        };
        add_batch(
            ctx,
            data,
            count,
            err,
            "sphere",
            reserve,
            |b, i, r: [f64; 4]| match b.record.as_deref_mut() {
                Some(rec) => {
                    rec.spheres.push(r);
                    Ok(())
                }
                None => b.spheres.push_world(i, r, b.world_offset, b.material),
            },
        )
    }
}

/// # Safety
/// See the comment above [`guard`].
unsafe extern "C" fn add_planes(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: the caller keeps the ABI contract (see the comment above `guard`).
    unsafe {
        let reserve: Reserve = |b, n, what| match b.record.as_deref_mut() {
            Some(rec) => Ok(b.budget.grow(&mut rec.planes, n, Use::Geometry, what)?),
            None => b.planes.reserve(n, b.budget, what),
        };
        add_batch(
            ctx,
            data,
            count,
            err,
            "plane",
            reserve,
            |b, i, r: [f64; 6]| match b.record.as_deref_mut() {
                Some(rec) => {
                    rec.planes.push(r);
                    Ok(())
                }
                None => b.planes.push_world(i, r, b.world_offset, b.material),
            },
        )
    }
}

/// # Safety
/// See the comment above [`guard`].
unsafe extern "C" fn add_cones(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: the caller keeps the ABI contract (see the comment above `guard`).
    unsafe {
        let reserve: Reserve = |b, n, what| match b.record.as_deref_mut() {
            Some(rec) => Ok(b.budget.grow(&mut rec.cones, n, Use::Geometry, what)?),
            None => b.cones.reserve(n, b.budget, what),
        };
        add_batch(
            ctx,
            data,
            count,
            err,
            "cone",
            reserve,
            |b, i, r: [f64; 8]| match b.record.as_deref_mut() {
                Some(rec) => {
                    rec.cones.push(r);
                    Ok(())
                }
                None => b.cones.push_world(i, r, b.world_offset, b.material),
            },
        )
    }
}

/// # Safety
/// See the comment above [`guard`].
unsafe extern "C" fn add_discs(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: the caller keeps the ABI contract (see the comment above `guard`).
    unsafe {
        let reserve: Reserve = |b, n, what| match b.record.as_deref_mut() {
            Some(rec) => Ok(b.budget.grow(&mut rec.discs, n, Use::Geometry, what)?),
            None => b.discs.reserve(n, b.budget, what),
        };
        add_batch(
            ctx,
            data,
            count,
            err,
            "disc",
            reserve,
            |b, i, r: [f64; 8]| match b.record.as_deref_mut() {
                Some(rec) => {
                    rec.discs.push(r);
                    Ok(())
                }
                None => b.discs.push_world(i, r, b.world_offset, b.material),
            },
        )
    }
}

/// # Safety
/// See the comment above [`guard`]; `mesh` is null or valid, its arrays as `MeshData` says.
unsafe extern "C" fn add_mesh(
    ctx: *mut c_void,
    mesh: *const abi::MeshData,
    err: *const abi::ErrorSink,
) -> abi::Status {
    let store = |b: &mut GeometryBuilder| {
        // SAFETY: the caller's promise about `mesh`.
        let m = unsafe { mesh.as_ref() }.ok_or("no mesh data")?;
        let nv = checked_len(m.vertex_count, 1, "vertex")?;
        let optional = |p: bool, per: usize| if p { 0 } else { nv * per };
        // SAFETY: the plugin guarantees the arrays' lengths (ABI contract of MeshData),
        // checked here to fit memory; optional arrays are null or one entry per vertex.
        let input = unsafe {
            MeshInput {
                positions: slice(m.positions, checked_len(m.vertex_count, 3, "vertex")?),
                indices: slice(m.indices, checked_len(m.triangle_count, 3, "triangle")?),
                normals: slice(m.normals, optional(m.normals.is_null(), 3)),
                colors: slice(m.colors, optional(m.colors.is_null(), 3)),
                uvs: slice(m.uvs, optional(m.uvs.is_null(), 2)),
            }
        };
        let triangles = input.indices.len() / 3;
        let describe = b.describe(triangles, "triangles");
        if let Some(rec) = b.record.as_deref_mut() {
            b.budget
                .grow(&mut rec.meshes, 1, Use::Geometry, &describe)?;
            rec.meshes
                .push(RecordedMesh::record(&input, b.budget, &describe)?);
            return Ok(());
        }
        let attrs = !(input.normals.is_empty() && input.colors.is_empty() && input.uvs.is_empty());
        b.triangles
            .reserve_mesh(triangles, nv, attrs, b.budget, &describe)?;
        b.dropped += b.triangles.push_mesh(&input, b.world_offset, b.material)?;
        Ok(())
    };
    // SAFETY: the caller keeps the ABI contract (see the comment above `guard`).
    unsafe { guard(ctx, err, store) }
}

/// # Safety
/// See the comment above [`guard`]; `g` is null or valid, and passes its object to the host.
unsafe extern "C" fn add_custom(
    ctx: *mut c_void,
    g: *const abi::CustomGeometry,
    err: *const abi::ErrorSink,
) -> abi::Status {
    let store = |b: &mut GeometryBuilder| {
        // SAFETY: the caller's promise about `g`.
        let g = unsafe { g.as_ref() }.ok_or("no custom geometry")?;
        // SAFETY: a non-null table of custom geometry is a static of the library (ABI), which
        // is never unloaded.
        let Some(vtable) = (unsafe { g.vtable.as_ref() }) else {
            return Err("custom geometry without a function table".into());
        };
        let made_by = (b.instance.clone(), b.at.clone());
        // Own it first so it is destroyed even if we reject it.
        // SAFETY: the plugin hands over `object`, which `vtable` serves (ABI contract).
        let object =
            unsafe { CustomObject::new(g.object, vtable, b.plugin.clone(), g.count, made_by) };
        if b.record.is_some() {
            return Err(
                "custom geometry (drawn by its plugin) cannot be moved by animation keys or \
                 copied into instances; Luxon moves and copies spheres, planes, cones, discs and \
                 meshes"
                    .into(),
            );
        }
        if g.count > u32::MAX as u64 {
            return Err(format!(
                "custom geometry with {} primitives is too large",
                g.count
            ));
        }
        let describe = b.describe(object.count as usize, "custom primitives");
        b.customs
            .reserve(object.count as usize, b.budget, &describe)?;
        let o = b.customs.objects.len() as u32;
        for i in 0..object.count {
            b.customs.refs.push((o, i));
            b.customs.material.push(b.material);
        }
        b.customs.objects.push(object);
        Ok(())
    };
    // SAFETY: the caller keeps the ABI contract (see the comment above `guard`).
    unsafe { guard(ctx, err, store) }
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
    let Table::Primitive(vt) = entry.table else {
        return Err(wrong_kind(
            registry,
            entry,
            PluginKind::Primitive,
            params_at,
        ));
    };
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance, Some(builder.budget));
    call_plugin(registry, entry, params_at, |err| {
        // SAFETY: the calling contract: `params`, `ctx`, `sink` and `err` live across the
        // call; `sink.ctx` is `builder`, which this function borrows mutably and does not touch
        // until the plugin returns, and the callbacks only reach it through `ctx`.
        unsafe { (vt.create)(abi::Str::new(params), &ctx, &sink, err) }
    })
}
