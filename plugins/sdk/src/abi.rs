//! THE plugin ABI, all of it, in this one file.
//!
//! Only `#[repr(C)]` plain data and `extern "C"` function pointers cross the boundary. Strings and
//! slices are borrowed pointer + length pairs that live for the duration of the call; memory is
//! freed by the side that allocated it. Enumerations travel as `u32` so that a bad value from the
//! other side is an error, not undefined behaviour.
//!
//! Handshake: the library exports [`DECLARE_SYMBOL`], an `unsafe extern "C" fn(*const HostTable)
//! -> *const PluginHeader`. The host reads the header's `magic`, `abi_version` and
//! `sdk_version` (for its messages) and stops there when the magic or the version does not
//! match: these three keep their layout in every ABI version; everything after them may change.
//!
//! # The calling contract
//!
//! Every function pointer is an `unsafe extern "C" fn`: it takes raw pointers whose validity
//! only its caller can promise, and the promise is the same for all of them.
//! - A pointer argument is non-null, aligned and points to a live value of its type (for a
//!   data pointer with a count: that many values) for the duration of the call, unless the
//!   field's documentation allows null. Nothing else writes to what it points to during the
//!   call; the callee writes only through its out-pointers (`*mut` arguments).
//! - A `ctx` argument is the `ctx` stored next to the function in the same table.
//! - An `object` argument is one the same library created (in a [`CustomGeometry`] or
//!   [`TextureObject`]) and has not destroyed; `destroy` is called once, with no other call on
//!   the object running or following.
//! - A [`Str`] points to `len` readable bytes (or is null with `len` 0); that they are UTF-8 is
//!   checked by the receiver, not promised.
//! - Borrowed pointers are not kept after the call returns (ownership passes only where a field
//!   says so).
//! - A callee never unwinds across the boundary: panics are caught on the side they happen.
//! - Threads: the host's sinks ([`ErrorSink`], [`GeometrySink`], [`VolumeSink`], [`ByteSink`])
//!   are called only on the thread running the call they were passed to, one call at a time;
//!   [`HostTable::log`] from any thread. A plugin's objects ([`CustomVTable`],
//!   [`TextureInstanceVTable`]) take `intersect`/`occluded`/`bounds` and `eval` calls from
//!   several threads at once (they must be thread-safe), and `destroy` from any thread.
//!
//! Any change to a type or a function signature in this file must bump [`ABI_VERSION`]: the
//! version protects compiled plugins, so the rule is about what the machine code sees. Marking a
//! function pointer `unsafe` (or removing the mark) is not such a change: `unsafe extern "C" fn`
//! and `extern "C" fn` have the same calling convention and representation, so a plugin built
//! before such a change loads and runs unchanged after it.

use std::ffi::c_void;

/// Bumped on every incompatible change to this file. Version 2 added
/// [`CallContext::memory_budget`], [`VolumeSink::add_dense_typed`] and the error sink of
/// [`TextureInstanceVTable::eval`]; version 3 [`TextureObject::reads`]; version 4
/// [`TexQuery::distance`].
pub const ABI_VERSION: u32 = 4;
/// First eight bytes of every [`PluginHeader`].
pub const MAGIC: [u8; 8] = *b"LUXONPLG";
/// The one symbol a plugin library exports (NUL-terminated for `dlsym`).
pub const DECLARE_SYMBOL: &[u8] = b"luxon_plugin_declare\0";

/// The signature of [`DECLARE_SYMBOL`].
pub type DeclareFn = unsafe extern "C" fn(host: *const HostTable) -> *const PluginHeader;

/// Borrowed UTF-8 text.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct Str {
    /// The first byte (null when `len` is 0).
    pub ptr: *const u8,
    /// Length in bytes.
    pub len: usize,
}

impl Str {
    pub const EMPTY: Str = Str {
        ptr: std::ptr::null(),
        len: 0,
    };

    pub const fn new(s: &str) -> Str {
        Str {
            ptr: s.as_ptr(),
            len: s.len(),
        }
    }

    /// The text, or an error when it is not UTF-8. A null or empty `Str` is `""`.
    ///
    /// # Safety
    /// Unless `ptr` is null or `len` is 0, `ptr` must point to `len` initialised bytes of one
    /// allocation that stay valid and unmodified for the lifetime `'a`.
    pub unsafe fn as_str<'a>(&self) -> Result<&'a str, std::str::Utf8Error> {
        if self.ptr.is_null() || self.len == 0 {
            return Ok("");
        }
        // SAFETY: non-null and non-empty here, so the caller promised `len` readable bytes at
        // `ptr`, unmodified for `'a`.
        std::str::from_utf8(unsafe { std::slice::from_raw_parts(self.ptr, self.len) })
    }
}

/// Result of every call across the boundary.
pub type Status = u32;
pub const STATUS_OK: Status = 0;
/// The callee reported an error through the [`ErrorSink`].
pub const STATUS_ERROR: Status = 1;
/// The callee panicked; the panic was caught on its side and its message sent to the sink.
pub const STATUS_PANIC: Status = 2;

/// Plugin kinds (`Entry::kind`).
pub const KIND_PRIMITIVE: u32 = 1;
pub const KIND_TEXTURE: u32 = 2;
pub const KIND_VOLUME_READER: u32 = 3;
pub const KIND_WRITER: u32 = 4;

/// What the host offers every plugin (given in the handshake, valid for the process lifetime).
/// A cdylib has its own statics, so logging goes through here rather than a `log` facade.
#[repr(C)]
pub struct HostTable {
    /// The host's [`ABI_VERSION`].
    pub abi_version: u32,
    /// level: 0 error, 1 warning, 2 info, 3 debug. Callable from any thread.
    ///
    /// One convention rides on it: an error (level 0) beginning "panicked in `" (as in
    /// "panicked in `intersect`: {message}"), sent on the thread of a [`CustomVTable`] call that
    /// then returns [`HIT_PANIC`] or [`STATUS_PANIC`], is that panic's message. The host adds it
    /// to the error that stops the render instead of printing it (a host that predates the
    /// convention prints it as an error line, which still reads well).
    pub log: unsafe extern "C" fn(level: u32, plugin: Str, message: Str),
}

/// Returned by the handshake; lives for the process lifetime (a static in the plugin).
#[repr(C)]
pub struct PluginHeader {
    /// [`MAGIC`].
    pub magic: [u8; 8],
    /// The [`ABI_VERSION`] the plugin was built for.
    pub abi_version: u32,
    /// Version of the `luxon-plugin` crate the plugin was built with, e.g. "0.2.0".
    pub sdk_version: Str,
    /// Only read when `magic` and `abi_version` match (the fields above this one never move).
    pub declaration: *const Declaration,
}

#[repr(C)]
pub struct Declaration {
    /// The library's own name, e.g. "luxon-shapes"; used in messages.
    pub library: Str,
    /// The library's entries: `entry_count` of them, a static array.
    pub entries: *const Entry,
    /// How many entries.
    pub entry_count: usize,
}

/// One named thing a library provides.
#[repr(C)]
pub struct Entry {
    /// What the entry is: [`KIND_PRIMITIVE`], [`KIND_TEXTURE`], [`KIND_VOLUME_READER`] or
    /// [`KIND_WRITER`].
    pub kind: u32,
    /// The name a scene uses: `(plugin: "sphere", ...)`.
    pub name: Str,
    /// One line: what it is (shown by `luxon plugins`).
    pub description: Str,
    /// The parameter table, one `name: type = default  description` per line.
    pub params_doc: Str,
    /// Writers: comma-separated file extensions without dots ("ppm,pnm"); empty otherwise.
    pub extensions: Str,
    /// Points to the table for `kind`: [`PrimitiveVTable`], [`TextureVTable`],
    /// [`VolumeReaderVTable`] or [`WriterVTable`], a static of the library.
    pub vtable: *const c_void,
}

/// Where a plugin reports an error. `line`/`col` are 1-based positions inside the params text it
/// was given (0 when the error has no position); the host maps them to the scene file.
#[repr(C)]
pub struct ErrorSink {
    /// The host's state for this call, passed back to `set`.
    pub ctx: *mut c_void,
    /// Records the error: its message (copied by the host) and position.
    pub set: unsafe extern "C" fn(ctx: *mut c_void, message: Str, line: u32, col: u32),
}

/// What every create/read/write call receives besides its params.
#[repr(C)]
pub struct CallContext {
    /// Directory of the scene file that named the plugin: relative paths resolve against it.
    pub scene_dir: Str,
    /// The scene's name for this instance (the object's index or the texture's name), for messages.
    pub instance: Str,
    /// Memory budget for cached texture data, bytes (render settings; 0 = the plugin's default).
    pub texture_cache_bytes: u64,
    /// Threads that will call the instance concurrently.
    pub threads: u32,
    /// Bytes this call may allocate for what it produces or keeps (a mesh, decoded texels, a
    /// buffer of voxels): an allocation beyond it should be refused with an error naming what
    /// needed it. 0 means unknown (no budget is given: allocate what the data needs). The
    /// host counts what it receives against its own budget anyway.
    pub memory_budget: u64,
}

// ---------------------------------------------------------------------------------------------
// Primitives: a plugin turns its parameters into native geometry (spheres, planes, triangle
// meshes) that the core stores compactly and intersects inline, and/or custom geometry that the
// core calls through `CustomVTable` from inside the same BVH.
// ---------------------------------------------------------------------------------------------

#[repr(C)]
pub struct PrimitiveVTable {
    /// `ctx` may be null (a context outside any scene); `err` may be null (errors are then
    /// only reported by the status).
    pub create: unsafe extern "C" fn(
        params: Str,
        ctx: *const CallContext,
        sink: *const GeometrySink,
        err: *const ErrorSink,
    ) -> Status,
}

/// A triangle mesh handed to the host. All pointers are borrowed for the call; optional arrays
/// are null when absent, otherwise they have one entry per vertex.
#[repr(C)]
pub struct MeshData {
    /// x, y, z per vertex.
    pub positions: *const f64,
    /// Vertices in `positions` (and in each optional array).
    pub vertex_count: u64,
    /// Three vertex indices per triangle.
    pub indices: *const u64,
    /// Triangles in `indices`.
    pub triangle_count: u64,
    /// x, y, z per vertex, or null.
    pub normals: *const f64,
    /// r, g, b per vertex, or null.
    pub colors: *const f32,
    /// u, v per vertex, or null.
    pub uvs: *const f32,
}

/// A ray in world space, double precision: the points `origin + t * direction` with
/// `tmin < t < tmax`. Custom geometry sees it as [`Ray`](crate::Ray).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RayF64 {
    /// Where the ray starts, in world space (the host has already moved it off the surface it
    /// leaves, so a hit at `t` just above `tmin` is a real one).
    pub origin: [f64; 3],
    /// Its direction, in world space; not necessarily of unit length, so `t` counts in units of
    /// its length, not of distance.
    pub direction: [f64; 3],
    /// Hits at or before this `t` do not count (0 for the rays the host traces).
    pub tmin: f64,
    /// Hits at or beyond this `t` do not count: the nearest hit found so far, or the distance
    /// to the light for a shadow ray.
    pub tmax: f64,
    /// The ray's time within the frame's shutter (the scene's `render.time`, or a sample of
    /// the shutter interval under motion blur), for shapes that move.
    pub time: f64,
}

/// A custom primitive's answer to `intersect` (the SDK's [`Hit`](crate::Hit)).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct HitF64 {
    /// Where along the ray: the hit point is `origin + t * direction`, with
    /// `tmin < t < tmax` (the host drops other answers).
    pub t: f64,
    /// Geometric normal in world space, any length, any orientation (the host normalises it
    /// and turns it toward the ray; a zero normal drops the hit). It is also the shading
    /// normal: custom geometry is shaded flat by its true normal.
    pub normal: [f64; 3],
    /// Texture coordinates of the hit, passed on to textures as [`TexQuery::uv`]. Give
    /// `[0, 0]` when the shape has none.
    pub uv: [f32; 2],
}

/// Custom geometry: `count` primitives the host puts in its BVH.
/// `intersect`/`occluded` return 1 for a hit, 0 for none, and [`STATUS_PANIC`] + 1 (= 3) when the
/// plugin panicked (the host then stops the render with an error naming the plugin). These calls
/// have no [`ErrorSink`]: a panic's message may be sent through [`HostTable::log`] first (see
/// there).
#[repr(C)]
pub struct CustomVTable {
    /// Writes the world-space box of primitive `index` (`0..count`) to `min` and `max`.
    pub bounds: unsafe extern "C" fn(
        object: *const c_void,
        index: u64,
        min: *mut [f64; 3],
        max: *mut [f64; 3],
    ) -> Status,
    /// The nearest hit of the ray with primitive `index` with `tmin < t < tmax`, written to
    /// `hit`.
    pub intersect: unsafe extern "C" fn(
        object: *const c_void,
        index: u64,
        ray: *const RayF64,
        hit: *mut HitF64,
    ) -> u32,
    /// Whether the ray hits primitive `index` anywhere with `tmin < t < tmax` (shadow rays).
    pub occluded:
        unsafe extern "C" fn(object: *const c_void, index: u64, ray: *const RayF64) -> u32,
    /// Called once by the host when it no longer needs the object.
    pub destroy: unsafe extern "C" fn(object: *mut c_void),
}

/// Return value of `intersect`/`occluded` when the plugin panicked.
pub const HIT_PANIC: u32 = 3;

#[repr(C)]
pub struct CustomGeometry {
    /// The plugin's object, passed to every function of `vtable`.
    pub object: *mut c_void,
    /// Primitives in the object, each with its own BVH leaf (`index` `0..count`).
    pub count: u64,
    /// A table that stays valid while the library is loaded (a static).
    pub vtable: *const CustomVTable,
}

/// The host's geometry builder. Each call copies what it is given; it returns [`STATUS_ERROR`] and
/// fills `err` when the data is unusable (NaN, bad index...).
#[repr(C)]
pub struct GeometrySink {
    /// The host's builder for this call, passed back to every function.
    pub ctx: *mut c_void,
    /// `count` spheres as x, y, z, radius.
    pub add_spheres: unsafe extern "C" fn(
        ctx: *mut c_void,
        data: *const f64,
        count: u64,
        err: *const ErrorSink,
    ) -> Status,
    /// `count` infinite planes as point x, y, z then normal x, y, z.
    pub add_planes: unsafe extern "C" fn(
        ctx: *mut c_void,
        data: *const f64,
        count: u64,
        err: *const ErrorSink,
    ) -> Status,
    /// `count` open cones as base x, y, z, base radius, apex x, y, z, apex radius (equal radii:
    /// a cylinder; one radius may be 0: a pointed cone). No caps: add discs for them.
    pub add_cones: unsafe extern "C" fn(
        ctx: *mut c_void,
        data: *const f64,
        count: u64,
        err: *const ErrorSink,
    ) -> Status,
    /// `count` discs (rings) as centre x, y, z, normal x, y, z, inner radius, outer radius.
    pub add_discs: unsafe extern "C" fn(
        ctx: *mut c_void,
        data: *const f64,
        count: u64,
        err: *const ErrorSink,
    ) -> Status,
    /// A triangle mesh (see [`MeshData`]).
    pub add_mesh: unsafe extern "C" fn(
        ctx: *mut c_void,
        mesh: *const MeshData,
        err: *const ErrorSink,
    ) -> Status,
    /// Ownership of `geometry.object` passes to the host, which calls `destroy` when done.
    pub add_custom: unsafe extern "C" fn(
        ctx: *mut c_void,
        geometry: *const CustomGeometry,
        err: *const ErrorSink,
    ) -> Status,
}

// ---------------------------------------------------------------------------------------------
// Textures: an instance evaluated per shading point.
// ---------------------------------------------------------------------------------------------

#[repr(C)]
pub struct TextureVTable {
    /// On success fills `out` with an object the host later destroys through its table.
    /// `ctx` and `err` may be null (as for [`PrimitiveVTable::create`]).
    pub create: unsafe extern "C" fn(
        params: Str,
        ctx: *const CallContext,
        out: *mut TextureObject,
        err: *const ErrorSink,
    ) -> Status,
}

#[repr(C)]
pub struct TextureObject {
    /// The plugin's object, passed to every function of `vtable`.
    pub object: *mut c_void,
    /// A table that stays valid while the library is loaded (a static).
    pub vtable: *const TextureInstanceVTable,
    /// Which fields of [`TexQuery`] the object's `eval` reads: `READS_*` bits
    /// ([`READS_ALL`] when unsure). The host may skip working out the others (it leaves them
    /// 0): a sphere's `uv` costs an `atan2` and an `acos` that a projected image never reads.
    pub reads: u32,
}

/// [`TextureObject::reads`]: the hit point [`TexQuery::p`].
pub const READS_POINT: u32 = 1;
/// [`TextureObject::reads`]: the shading normal [`TexQuery::n`].
pub const READS_NORMAL: u32 = 1 << 1;
/// [`TextureObject::reads`]: the texture coordinates [`TexQuery::uv`] and
/// [`TexQuery::uv_footprint`].
pub const READS_UV: u32 = 1 << 2;
/// [`TextureObject::reads`]: the world footprint [`TexQuery::footprint`].
pub const READS_FOOTPRINT: u32 = 1 << 3;
/// [`TextureObject::reads`]: the ray's time [`TexQuery::time`].
pub const READS_TIME: u32 = 1 << 4;
/// [`TextureObject::reads`]: how far the ray travelled [`TexQuery::distance`].
pub const READS_DISTANCE: u32 = 1 << 5;
/// [`TextureObject::reads`]: every field.
pub const READS_ALL: u32 =
    READS_POINT | READS_NORMAL | READS_UV | READS_FOOTPRINT | READS_TIME | READS_DISTANCE;

/// Where and how a texture is looked up: one shading point (the SDK re-exports it at its
/// root: `luxon_plugin::TexQuery`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct TexQuery {
    /// The hit point in world space (double precision, so solid textures stay sharp far from
    /// the origin).
    pub p: [f64; 3],
    /// The shading normal at `p`: unit length, turned toward the viewer (the interpolated
    /// normal of a smooth mesh, else the geometric one).
    pub n: [f32; 3],
    /// The surface's texture coordinates at `p`: spheres give longitude and latitude in [0, 1]
    /// (`u` around the y axis, `v` from the top), planes the distances along two directions in
    /// the plane (world units), meshes their per-vertex uvs interpolated (or `[0, 0]`), custom
    /// shapes what their `intersect` returned; cylinders, cones and discs their own.
    pub uv: [f32; 2],
    /// How wide the pixel's share of the scene is at `p`, in world units: rays are traced as
    /// thin cones, about a pixel wide at the camera (an orthographic camera's pixel, or 0 at a
    /// pinhole) and widening by the angle of one pixel per unit of distance, including the
    /// path through mirrors and glass before it. A texture with detail finer than this should
    /// average over a box of this width around `p` rather than return the value at `p`, or it
    /// aliases (moiré, sparkle). It is measured across the ray, not along a slanted surface.
    pub footprint: f32,
    /// The same footprint in `uv` units: measured on spheres and on meshes with uvs, 0 on
    /// other surfaces (planes, cylinders and cones, discs, custom shapes); image textures
    /// under uv mapping choose their MIP level from it.
    pub uv_footprint: f32,
    /// The ray's time within the frame's shutter, for textures that change over time.
    pub time: f32,
    /// How far light travels from `p` to the camera along this path, in world units: the
    /// camera ray's length plus every mirror and glass segment before it (an orthographic
    /// camera's rays start on its image plane). Tachyon's image maps blur with it.
    pub distance: f32,
}

#[repr(C)]
pub struct TextureInstanceVTable {
    /// Writes linear RGBA into `out`; returns [`STATUS_PANIC`] when the plugin panicked and
    /// [`STATUS_ERROR`] when it could give no value (an image that turns out not to decode),
    /// in both cases with the reason sent to `err` (which may be null). The host then stops
    /// the render with that message.
    pub eval: unsafe extern "C" fn(
        object: *const c_void,
        query: *const TexQuery,
        out: *mut [f32; 4],
        err: *const ErrorSink,
    ) -> Status,
    /// Called once by the host when it no longer needs the object.
    pub destroy: unsafe extern "C" fn(object: *mut c_void),
}

// ---------------------------------------------------------------------------------------------
// Volume readers: a reader streams a scalar grid into the host as dense blocks and constant
// tiles (sparse formats such as OpenVDB hand over their leaves and tiles as they are).
// ---------------------------------------------------------------------------------------------

#[repr(C)]
pub struct VolumeReaderVTable {
    /// `ctx` and `err` may be null (as for [`PrimitiveVTable::create`]).
    pub read: unsafe extern "C" fn(
        params: Str,
        ctx: *const CallContext,
        sink: *const VolumeSink,
        err: *const ErrorSink,
    ) -> Status,
}

/// A grid's description, sent by `begin` before its data (the SDK's
/// [`GridInfo`](crate::GridInfo)).
#[repr(C)]
pub struct VolumeDesc {
    /// Row-major 3x4 affine map from voxel index space to world space: voxel `(i, j, k)` is at
    /// `M · (i, j, k, 1)`.
    pub world_from_index: [f64; 12],
    /// Value outside every block and tile.
    pub background: f32,
    /// Inclusive index-space bounds of the data: the smallest index along each axis...
    pub index_min: [i64; 3],
    /// ... and the largest (inclusive). Blocks and tiles must lie within these bounds.
    pub index_max: [i64; 3],
    /// The grid's name, for messages and `luxon check`.
    pub grid_name: Str,
}

/// Voxel formats of [`VolumeSink::add_dense_typed`].
pub const VOXEL_U8: u32 = 1;
/// Native-endian `u16`.
pub const VOXEL_U16: u32 = 2;
pub const VOXEL_F32: u32 = 3;

#[repr(C)]
pub struct VolumeSink {
    /// The host's volume for this call, passed back to every function.
    pub ctx: *mut c_void,
    /// Called once, before any block or tile.
    pub begin: unsafe extern "C" fn(
        ctx: *mut c_void,
        desc: *const VolumeDesc,
        err: *const ErrorSink,
    ) -> Status,
    /// A dense block of `dims[0]*dims[1]*dims[2]` values, x fastest, starting at index `origin`.
    pub add_dense: unsafe extern "C" fn(
        ctx: *mut c_void,
        origin: *const [i64; 3],
        dims: *const [u64; 3],
        values: *const f32,
        err: *const ErrorSink,
    ) -> Status,
    /// A dense block as [`add_dense`](Self::add_dense), of voxels in `format` ([`VOXEL_U8`],
    /// [`VOXEL_U16`] or [`VOXEL_F32`]): `data` holds `len` bytes, exactly
    /// `dims[0]*dims[1]*dims[2]` voxels of that format (`u16` and `f32` in the machine's byte
    /// order, `data` aligned for the type). Voxel value = `raw as f32 / divisor`, computed in
    /// f32 (`divisor` finite and > 0; 1 for the raw values). Integer formats let the host store
    /// the data at its own precision (a u8 volume costs a byte per voxel), so a volume must
    /// use one divisor per format.
    pub add_dense_typed: unsafe extern "C" fn(
        ctx: *mut c_void,
        origin: *const [i64; 3],
        dims: *const [u64; 3],
        format: u32,
        data: *const u8,
        len: usize,
        divisor: f32,
        err: *const ErrorSink,
    ) -> Status,
    /// A constant box of `dims` voxels starting at `origin`.
    pub add_tile: unsafe extern "C" fn(
        ctx: *mut c_void,
        origin: *const [i64; 3],
        dims: *const [u64; 3],
        value: f32,
        err: *const ErrorSink,
    ) -> Status,
}

// ---------------------------------------------------------------------------------------------
// Writers: encode a finished image into bytes; the host writes them atomically.
// ---------------------------------------------------------------------------------------------

#[repr(C)]
pub struct WriterVTable {
    /// `ctx` and `err` may be null (as for [`PrimitiveVTable::create`]).
    pub write: unsafe extern "C" fn(
        params: Str,
        ctx: *const CallContext,
        image: *const ImageView,
        out: *const ByteSink,
        err: *const ErrorSink,
    ) -> Status,
}

/// A finished image: linear (not gamma-encoded) RGBA f32, rows top to bottom (the SDK's
/// [`Image`](crate::Image)).
#[repr(C)]
pub struct ImageView {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width * height * 4` values (may be null when that is 0).
    pub rgba: *const f32,
}

#[repr(C)]
pub struct ByteSink {
    /// The host's buffer for this call, passed back to `write`.
    pub ctx: *mut c_void,
    /// Appends `len` bytes from `data` to the file's contents.
    pub write: unsafe extern "C" fn(ctx: *mut c_void, data: *const u8, len: usize) -> Status,
}
