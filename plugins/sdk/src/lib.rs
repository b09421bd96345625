//! # luxon-plugin: write Luxon plugins as safe Rust
//!
//! A plugin library is a `cdylib` that depends on this crate only. Each thing it provides is a
//! type implementing [`Describe`] and one of [`Primitive`], [`Texture`], [`VolumeReader`] or
//! [`Writer`]; one [`export!`] line publishes them. The host finds the library by the names in
//! it, checks [`abi::ABI_VERSION`] before calling anything, and hands each instance its `params`
//! subtree from the scene as RON text, which this crate deserializes into the type's own
//! `#[derive(Deserialize)]` struct (use `#[serde(deny_unknown_fields)]` so typos are errors).
//!
//! ```no_run
//! use luxon_plugin::*;
//!
//! #[derive(serde::Deserialize)]
//! #[serde(crate = "luxon_plugin::serde", deny_unknown_fields)]
//! struct BallParams { center: [f64; 3], radius: f64 }
//!
//! struct Ball;
//! impl Describe for Ball {
//!     const NAME: &'static str = "ball";
//!     const DESCRIPTION: &'static str = "A sphere.";
//!     const PARAMS: &'static str = "center: (x, y, z)\nradius: f64 > 0";
//! }
//! impl Primitive for Ball {
//!     type Params = BallParams;
//!     fn create(p: BallParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
//!         out.spheres(&[[p.center[0], p.center[1], p.center[2], p.radius]])
//!     }
//! }
//!
//! export!(library: "my-balls", primitives: [Ball]);
//! ```
//!
//! Panics inside any entry point are caught here and reported to the host as errors naming the
//! plugin; they never unwind across `extern "C"`.
//!
//! The rest of this page is the repository's `plugins/README.md`: the shipped plugins and how
//! to write one. Its Rust example is compiled as a doctest here.
#![doc = include_str!("../../README.md")]

pub mod abi;

use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

pub use abi::ABI_VERSION;
pub use serde;

/// Version of this crate, sent in the handshake.
pub const SDK_VERSION: &str = env!("CARGO_PKG_VERSION");

/// An error a plugin reports; `line`/`col` (1-based, 0 = unknown) are positions in its params text.
#[derive(Debug, Clone, PartialEq)]
pub struct Error {
    pub message: String,
    pub line: u32,
    pub col: u32,
}

impl Error {
    pub fn new(message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
            line: 0,
            col: 0,
        }
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Error {
        Error::new(e.to_string())
    }
}

/// Shorthand for a failed check on a parameter value.
pub fn invalid(message: impl Into<String>) -> Error {
    Error::new(message)
}

/// Rejects NaN and infinities with a message naming the parameter.
pub fn finite<const N: usize>(name: &str, v: [f64; N]) -> Result<[f64; N], Error> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(Error::new(format!(
            "parameter `{name}` must be finite, got {v:?}"
        )))
    }
}

/// Name, description and parameter table of a plugin entry (shown by `luxon plugins`).
pub trait Describe {
    const NAME: &'static str;
    const DESCRIPTION: &'static str;
    /// One `name: type = default  meaning` per line.
    const PARAMS: &'static str;
}

/// What a create/read/write call knows about where it was called from.
pub struct Context {
    /// Directory of the scene file: resolve relative paths against it.
    pub scene_dir: PathBuf,
    /// How the scene refers to this instance, for messages.
    pub instance: String,
    /// Memory budget for cached texture data in bytes (0: choose a default).
    pub texture_cache_bytes: u64,
    /// Threads that will call the instance concurrently.
    pub threads: u32,
}

impl Default for Context {
    /// A context outside any scene (tests, tools): relative paths resolve against ".".
    fn default() -> Context {
        Context {
            scene_dir: PathBuf::from("."),
            instance: String::new(),
            texture_cache_bytes: 0,
            threads: 1,
        }
    }
}

impl Context {
    /// `path` relative to the scene file's directory (absolute paths are kept).
    pub fn resolve(&self, path: impl AsRef<Path>) -> PathBuf {
        self.scene_dir.join(path)
    }
}

// ------------------------------------------------------------------------------------------------
// Parameters
// ------------------------------------------------------------------------------------------------

/// Deserializes a params subtree given as RON text; positions in errors are relative to `text`.
pub fn parse_params<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, Error> {
    let text = if text.trim().is_empty() { "()" } else { text };
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .from_str::<T>(text)
        .map_err(|e| {
            let message = describe_ron_error(&e.code);
            Error {
                message,
                line: e.span.start.line as u32,
                col: e.span.start.col as u32,
            }
        })
}

/// A RON error in words, with a "did you mean" for unknown fields.
pub fn describe_ron_error(code: &ron::Error) -> String {
    match code {
        ron::Error::NoSuchStructField {
            expected, found, ..
        } => {
            let mut msg = format!("unknown parameter `{found}`");
            if let Some(s) = suggest(found, expected.iter().copied()) {
                msg.push_str(&format!(", did you mean `{s}`?"));
            }
            msg.push_str(&format!(" (expected one of: {})", expected.join(", ")));
            msg
        }
        ron::Error::MissingStructField { field, .. } => {
            format!("missing parameter `{field}`")
        }
        other => other.to_string(),
    }
}

/// The candidate closest to `word` by edit distance, if it is close enough to be a likely typo.
pub fn suggest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        let d = edit_distance(word, c);
        if best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, c));
        }
    }
    best.filter(|(d, c)| *d <= 2.max(c.len() / 3))
        .map(|(_, c)| c)
}

/// Levenshtein distance over chars.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        cur[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

// ------------------------------------------------------------------------------------------------
// Primitives
// ------------------------------------------------------------------------------------------------

/// A primitive plugin: turns parameters into geometry.
pub trait Primitive: Describe {
    type Params: serde::de::DeserializeOwned;
    fn create(params: Self::Params, ctx: &Context, out: &mut Geometry) -> Result<(), Error>;
}

/// The host's geometry builder, seen from a plugin.
pub struct Geometry<'a> {
    sink: &'a abi::GeometrySink,
}

/// A triangle mesh to hand to the host. Optional arrays are empty or have one entry per vertex.
#[derive(Default, Clone, Debug)]
pub struct Mesh {
    pub positions: Vec<[f64; 3]>,
    pub indices: Vec<[u64; 3]>,
    pub normals: Vec<[f64; 3]>,
    pub colors: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// A ray as custom geometry sees it (world space, f64).
pub type Ray = abi::RayF64;
/// A custom geometry hit.
pub type Hit = abi::HitF64;

/// User geometry intersected by the plugin from inside the host's BVH.
pub trait CustomShape: Send + Sync + 'static {
    /// Number of primitives; each gets its own BVH leaf entry.
    fn count(&self) -> u64;
    fn bounds(&self, index: u64) -> Aabb;
    /// Nearest hit with `ray.tmin < t < ray.tmax`.
    fn intersect(&self, index: u64, ray: &Ray) -> Option<Hit>;
    /// Any hit with `ray.tmin < t < ray.tmax` (shadow rays); override when cheaper.
    fn occluded(&self, index: u64, ray: &Ray) -> bool {
        self.intersect(index, ray).is_some()
    }
}

struct SinkError(Option<Error>);

extern "C" fn sink_error_set(ctx: *mut c_void, message: abi::Str, line: u32, col: u32) {
    // SAFETY: ctx is the SinkError we created below for the duration of the call.
    let slot = unsafe { &mut *(ctx as *mut SinkError) };
    let message = unsafe { message.as_str() }
        .unwrap_or("(invalid UTF-8)")
        .to_string();
    slot.0 = Some(Error { message, line, col });
}

fn call_sink(f: impl FnOnce(&abi::ErrorSink) -> abi::Status) -> Result<(), Error> {
    let mut slot = SinkError(None);
    let err = abi::ErrorSink {
        ctx: &mut slot as *mut SinkError as *mut c_void,
        set: sink_error_set,
    };
    match f(&err) {
        abi::STATUS_OK => Ok(()),
        _ => Err(slot
            .0
            .unwrap_or_else(|| Error::new("the host rejected the data"))),
    }
}

impl Geometry<'_> {
    /// Spheres as `[x, y, z, radius]`.
    pub fn spheres(&mut self, spheres: &[[f64; 4]]) -> Result<(), Error> {
        call_sink(|err| {
            (self.sink.add_spheres)(
                self.sink.ctx,
                spheres.as_ptr() as *const f64,
                spheres.len() as u64,
                err,
            )
        })
    }

    /// Infinite planes as `[px, py, pz, nx, ny, nz]`.
    pub fn planes(&mut self, planes: &[[f64; 6]]) -> Result<(), Error> {
        call_sink(|err| {
            (self.sink.add_planes)(
                self.sink.ctx,
                planes.as_ptr() as *const f64,
                planes.len() as u64,
                err,
            )
        })
    }

    /// Open cones as `[bx, by, bz, base_radius, ax, ay, az, apex_radius]`; equal radii make a
    /// cylinder. Caps are not included: add discs.
    pub fn cones(&mut self, cones: &[[f64; 8]]) -> Result<(), Error> {
        call_sink(|err| {
            (self.sink.add_cones)(
                self.sink.ctx,
                cones.as_ptr() as *const f64,
                cones.len() as u64,
                err,
            )
        })
    }

    /// Discs or rings as `[cx, cy, cz, nx, ny, nz, inner_radius, outer_radius]`.
    pub fn discs(&mut self, discs: &[[f64; 8]]) -> Result<(), Error> {
        call_sink(|err| {
            (self.sink.add_discs)(
                self.sink.ctx,
                discs.as_ptr() as *const f64,
                discs.len() as u64,
                err,
            )
        })
    }

    pub fn mesh(&mut self, mesh: &Mesh) -> Result<(), Error> {
        let n = mesh.positions.len();
        for (what, len) in [
            ("normals", mesh.normals.len()),
            ("colors", mesh.colors.len()),
            ("uvs", mesh.uvs.len()),
        ] {
            if len != 0 && len != n {
                return Err(Error::new(format!(
                    "mesh has {n} vertices but {len} {what}; give one per vertex or none"
                )));
            }
        }
        fn opt<T>(v: &[T]) -> *const T {
            if v.is_empty() {
                std::ptr::null()
            } else {
                v.as_ptr()
            }
        }
        let data = abi::MeshData {
            positions: mesh.positions.as_ptr() as *const f64,
            vertex_count: n as u64,
            indices: mesh.indices.as_ptr() as *const u64,
            triangle_count: mesh.indices.len() as u64,
            normals: opt(&mesh.normals) as *const f64,
            colors: opt(&mesh.colors) as *const f32,
            uvs: opt(&mesh.uvs) as *const f32,
        };
        call_sink(|err| (self.sink.add_mesh)(self.sink.ctx, &data, err))
    }

    /// Hands `shape` to the host, which owns it from now on.
    pub fn custom<S: CustomShape>(&mut self, shape: S) -> Result<(), Error> {
        let count = shape.count();
        let object = Box::into_raw(Box::new(shape)) as *mut c_void;
        let geometry = abi::CustomGeometry {
            object,
            count,
            vtable: custom_vtable::<S>(),
        };
        // The host takes ownership even when it reports an error (it destroys the object).
        call_sink(|err| (self.sink.add_custom)(self.sink.ctx, &geometry, err))
    }
}

fn custom_vtable<S: CustomShape>() -> &'static abi::CustomVTable {
    struct Holder<S>(std::marker::PhantomData<S>);
    impl<S: CustomShape> Holder<S> {
        const VTABLE: abi::CustomVTable = abi::CustomVTable {
            bounds: custom_bounds::<S>,
            intersect: custom_intersect::<S>,
            occluded: custom_occluded::<S>,
            destroy: custom_destroy::<S>,
        };
    }
    &Holder::<S>::VTABLE
}

extern "C" fn custom_bounds<S: CustomShape>(
    object: *const c_void,
    index: u64,
    min: *mut [f64; 3],
    max: *mut [f64; 3],
) -> abi::Status {
    let shape = unsafe { &*(object as *const S) };
    match catch_unwind(AssertUnwindSafe(|| shape.bounds(index))) {
        Ok(b) => {
            unsafe {
                *min = b.min;
                *max = b.max;
            }
            abi::STATUS_OK
        }
        Err(_) => abi::STATUS_PANIC,
    }
}

extern "C" fn custom_intersect<S: CustomShape>(
    object: *const c_void,
    index: u64,
    ray: *const abi::RayF64,
    hit: *mut abi::HitF64,
) -> u32 {
    let shape = unsafe { &*(object as *const S) };
    let ray = unsafe { &*ray };
    match catch_unwind(AssertUnwindSafe(|| shape.intersect(index, ray))) {
        Ok(Some(h)) => {
            unsafe { *hit = h };
            1
        }
        Ok(None) => 0,
        Err(_) => abi::HIT_PANIC,
    }
}

extern "C" fn custom_occluded<S: CustomShape>(
    object: *const c_void,
    index: u64,
    ray: *const abi::RayF64,
) -> u32 {
    let shape = unsafe { &*(object as *const S) };
    let ray = unsafe { &*ray };
    match catch_unwind(AssertUnwindSafe(|| shape.occluded(index, ray))) {
        Ok(b) => u32::from(b),
        Err(_) => abi::HIT_PANIC,
    }
}

extern "C" fn custom_destroy<S: CustomShape>(object: *mut c_void) {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        drop(unsafe { Box::from_raw(object as *mut S) })
    }));
}

// ------------------------------------------------------------------------------------------------
// Textures
// ------------------------------------------------------------------------------------------------

/// A texture plugin: an instance created once, evaluated at every shading point (from many
/// threads at once, hence `Sync`).
pub trait Texture: Describe + Send + Sync + Sized + 'static {
    type Params: serde::de::DeserializeOwned;
    fn create(params: Self::Params, ctx: &Context) -> Result<Self, Error>;
    /// Linear RGBA at the query point. When no value can be given (an image that turns out not
    /// to decode), call [`texture_failed`] and return anything.
    fn eval(&self, query: &abi::TexQuery) -> [f32; 4];
}

thread_local! {
    /// Set by [`texture_failed`] during the `eval` call running on this thread.
    static EVAL_FAILED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Marks the texture evaluation running on this thread as failed: the host stops the render
/// with an error naming the texture, and the run fails (its outputs are left untouched). Log
/// the cause first, once, with [`host_log`] at level 0: plugin ABI 1 carries no message back
/// from `eval`, only its status ([`abi::STATUS_ERROR`]). Works from any depth of nested
/// textures.
pub fn texture_failed() {
    EVAL_FAILED.with(|f| f.set(true));
}

fn texture_instance_vtable<T: Texture>() -> &'static abi::TextureInstanceVTable {
    struct Holder<T>(std::marker::PhantomData<T>);
    impl<T: Texture> Holder<T> {
        const VTABLE: abi::TextureInstanceVTable = abi::TextureInstanceVTable {
            eval: texture_eval::<T>,
            destroy: texture_destroy::<T>,
        };
    }
    &Holder::<T>::VTABLE
}

extern "C" fn texture_eval<T: Texture>(
    object: *const c_void,
    query: *const abi::TexQuery,
    out: *mut [f32; 4],
) -> abi::Status {
    let tex = unsafe { &*(object as *const T) };
    let q = unsafe { &*query };
    EVAL_FAILED.with(|f| f.set(false));
    match catch_unwind(AssertUnwindSafe(|| tex.eval(q))) {
        Ok(_) if EVAL_FAILED.with(|f| f.replace(false)) => abi::STATUS_ERROR,
        Ok(c) => {
            unsafe { *out = c };
            abi::STATUS_OK
        }
        Err(_) => abi::STATUS_PANIC,
    }
}

extern "C" fn texture_destroy<T: Texture>(object: *mut c_void) {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        drop(unsafe { Box::from_raw(object as *mut T) })
    }));
}

// ------------------------------------------------------------------------------------------------
// Volume readers
// ------------------------------------------------------------------------------------------------

/// A volume reader plugin: streams a scalar grid into the host.
pub trait VolumeReader: Describe {
    type Params: serde::de::DeserializeOwned;
    fn read(params: Self::Params, ctx: &Context, out: &mut VolumeOut) -> Result<(), Error>;
}

/// Description of a grid, sent before its data.
#[derive(Clone, Debug)]
pub struct GridInfo {
    /// Row-major 3x4 affine map from voxel index to world space.
    pub world_from_index: [f64; 12],
    pub background: f32,
    pub index_min: [i64; 3],
    pub index_max: [i64; 3],
    pub name: String,
}

/// The host's volume builder, seen from a reader.
pub struct VolumeOut<'a> {
    sink: &'a abi::VolumeSink,
}

impl VolumeOut<'_> {
    pub fn begin(&mut self, info: &GridInfo) -> Result<(), Error> {
        let desc = abi::VolumeDesc {
            world_from_index: info.world_from_index,
            background: info.background,
            index_min: info.index_min,
            index_max: info.index_max,
            grid_name: abi::Str::new(&info.name),
        };
        call_sink(|err| (self.sink.begin)(self.sink.ctx, &desc, err))
    }

    /// A dense block, x fastest; `values.len()` must be `dims[0] * dims[1] * dims[2]`.
    pub fn dense(&mut self, origin: [i64; 3], dims: [u64; 3], values: &[f32]) -> Result<(), Error> {
        let n = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d));
        if n != Some(values.len() as u64) {
            return Err(Error::new(format!(
                "dense block of {dims:?} voxels given {} values",
                values.len()
            )));
        }
        call_sink(|err| (self.sink.add_dense)(self.sink.ctx, &origin, &dims, values.as_ptr(), err))
    }

    pub fn tile(&mut self, origin: [i64; 3], dims: [u64; 3], value: f32) -> Result<(), Error> {
        call_sink(|err| (self.sink.add_tile)(self.sink.ctx, &origin, &dims, value, err))
    }
}

// ------------------------------------------------------------------------------------------------
// Writers
// ------------------------------------------------------------------------------------------------

/// A finished image: linear RGBA f32, rows top to bottom.
pub struct Image<'a> {
    pub width: u32,
    pub height: u32,
    pub rgba: &'a [f32],
}

/// An image writer plugin: encodes an image into bytes; the host writes them atomically.
pub trait Writer: Describe {
    /// Comma-separated file extensions, without dots, e.g. "ppm,pnm".
    const EXTENSIONS: &'static str;
    type Params: serde::de::DeserializeOwned;
    fn write(
        params: Self::Params,
        ctx: &Context,
        image: &Image,
        out: &mut dyn std::io::Write,
    ) -> Result<(), Error>;
}

struct ByteOut<'a>(&'a abi::ByteSink);

impl std::io::Write for ByteOut<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match (self.0.write)(self.0.ctx, buf.as_ptr(), buf.len()) {
            abi::STATUS_OK => Ok(buf.len()),
            _ => Err(std::io::Error::other("the host could not take the bytes")),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Linear to sRGB transfer function (what 8-bit formats store).
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

// ------------------------------------------------------------------------------------------------
// Entry point shims (used by `export!`; not for direct use)
// ------------------------------------------------------------------------------------------------

#[doc(hidden)]
#[allow(clippy::not_unsafe_ptr_arg_deref)] // the host guarantees the pointers (ABI contract)
pub mod shim {
    use super::*;

    fn report(err: *const abi::ErrorSink, e: &Error) {
        if let Some(sink) = unsafe { err.as_ref() } {
            (sink.set)(sink.ctx, abi::Str::new(&e.message), e.line, e.col);
        }
    }

    fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
        if let Some(s) = p.downcast_ref::<&str>() {
            format!("panicked: {s}")
        } else if let Some(s) = p.downcast_ref::<String>() {
            format!("panicked: {s}")
        } else {
            "panicked".to_string()
        }
    }

    fn context(ctx: *const abi::CallContext) -> Context {
        match unsafe { ctx.as_ref() } {
            Some(c) => Context {
                scene_dir: PathBuf::from(unsafe { c.scene_dir.as_str() }.unwrap_or(".")),
                instance: unsafe { c.instance.as_str() }.unwrap_or("").to_string(),
                texture_cache_bytes: c.texture_cache_bytes,
                threads: c.threads,
            },
            None => Context::default(),
        }
    }

    /// Runs `f` with panics caught and errors sent to `err`.
    fn guarded(err: *const abi::ErrorSink, f: impl FnOnce() -> Result<(), Error>) -> abi::Status {
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(Ok(())) => abi::STATUS_OK,
            Ok(Err(e)) => {
                report(err, &e);
                abi::STATUS_ERROR
            }
            Err(p) => {
                report(err, &Error::new(panic_message(p)));
                abi::STATUS_PANIC
            }
        }
    }

    fn params<P: serde::de::DeserializeOwned>(text: abi::Str) -> Result<P, Error> {
        let text = unsafe { text.as_str() }.map_err(|_| Error::new("params are not UTF-8"))?;
        parse_params(text)
    }

    pub extern "C" fn primitive_create<P: Primitive>(
        text: abi::Str,
        ctx: *const abi::CallContext,
        sink: *const abi::GeometrySink,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        guarded(err, || {
            let p = params::<P::Params>(text)?;
            let sink = unsafe { sink.as_ref() }.ok_or_else(|| Error::new("no geometry sink"))?;
            P::create(p, &context(ctx), &mut Geometry { sink })
        })
    }

    pub extern "C" fn texture_create<T: Texture>(
        text: abi::Str,
        ctx: *const abi::CallContext,
        out: *mut abi::TextureObject,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        guarded(err, || {
            let p = params::<T::Params>(text)?;
            let tex = T::create(p, &context(ctx))?;
            let object = Box::into_raw(Box::new(tex)) as *mut c_void;
            unsafe {
                *out = abi::TextureObject {
                    object,
                    vtable: texture_instance_vtable::<T>(),
                }
            };
            Ok(())
        })
    }

    pub extern "C" fn volume_read<V: VolumeReader>(
        text: abi::Str,
        ctx: *const abi::CallContext,
        sink: *const abi::VolumeSink,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        guarded(err, || {
            let p = params::<V::Params>(text)?;
            let sink = unsafe { sink.as_ref() }.ok_or_else(|| Error::new("no volume sink"))?;
            V::read(p, &context(ctx), &mut VolumeOut { sink })
        })
    }

    pub extern "C" fn writer_write<W: Writer>(
        text: abi::Str,
        ctx: *const abi::CallContext,
        image: *const abi::ImageView,
        out: *const abi::ByteSink,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        guarded(err, || {
            let p = params::<W::Params>(text)?;
            let view = unsafe { image.as_ref() }.ok_or_else(|| Error::new("no image"))?;
            let n = view.width as usize * view.height as usize * 4;
            let rgba = if n == 0 {
                &[][..]
            } else {
                unsafe { std::slice::from_raw_parts(view.rgba, n) }
            };
            let image = Image {
                width: view.width,
                height: view.height,
                rgba,
            };
            let sink = unsafe { out.as_ref() }.ok_or_else(|| Error::new("no byte sink"))?;
            let mut w = ByteOut(sink);
            W::write(p, &context(ctx), &image, &mut w)
        })
    }

    pub const fn entry<D: Describe>(
        kind: u32,
        extensions: &'static str,
        vtable: *const c_void,
    ) -> abi::Entry {
        abi::Entry {
            kind,
            name: abi::Str::new(D::NAME),
            description: abi::Str::new(D::DESCRIPTION),
            params_doc: abi::Str::new(D::PARAMS),
            extensions: abi::Str::new(extensions),
            vtable,
        }
    }

    /// Holds the host table for `log`.
    pub static HOST: std::sync::OnceLock<usize> = std::sync::OnceLock::new();

    /// Called by the handshake. A cdylib has its own copy of std and so its own panic hook: the
    /// default one would print every caught panic (one per ray for a broken intersect). Ours
    /// sends the first panic's location through the host log and stays quiet after that; the
    /// message itself reaches the host as the call's error.
    pub fn init(host: *const abi::HostTable, library: &'static str) {
        if host.is_null() || HOST.set(host as usize).is_err() {
            return;
        }
        static REPORTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
        std::panic::set_hook(Box::new(move |info| {
            if !REPORTED.swap(true, std::sync::atomic::Ordering::Relaxed) {
                let at = info
                    .location()
                    .map(|l| format!(" at {}:{}", l.file(), l.line()))
                    .unwrap_or_default();
                host_log(library, 0, &format!("panicked{at}"));
            }
        }));
    }

    /// Wrapper making the static tables `Sync` (they hold raw pointers to other statics).
    pub struct SyncWrap<T>(pub T);
    unsafe impl<T> Sync for SyncWrap<T> {}
}

/// Logs through the host (a plugin's own `log`/`println!` would bypass the host's output).
/// Level: 0 error, 1 warning, 2 info, 3 debug.
pub fn host_log(library: &str, level: u32, message: &str) {
    if let Some(&ptr) = shim::HOST.get() {
        let host = unsafe { &*(ptr as *const abi::HostTable) };
        (host.log)(level, abi::Str::new(library), abi::Str::new(message));
    }
}

/// Publishes a library's plugins. Each list may be omitted.
///
/// ```text
/// export!(library: "luxon-shapes", primitives: [Sphere, Plane], textures: [], writers: []);
/// ```
#[macro_export]
macro_rules! export {
    (library: $lib:literal
        $(, primitives: [$($prim:ty),* $(,)?])?
        $(, textures: [$($tex:ty),* $(,)?])?
        $(, volume_readers: [$($vol:ty),* $(,)?])?
        $(, writers: [$($wr:ty),* $(,)?])?
        $(,)?
    ) => {
        const _: () = {
            use $crate::abi;
            use $crate::shim::SyncWrap;
            static ENTRIES: SyncWrap<&[abi::Entry]> = SyncWrap(&[
                $($($crate::shim::entry::<$prim>(
                    abi::KIND_PRIMITIVE,
                    "",
                    &abi::PrimitiveVTable { create: $crate::shim::primitive_create::<$prim> }
                        as *const abi::PrimitiveVTable as *const ::std::ffi::c_void,
                ),)*)?
                $($($crate::shim::entry::<$tex>(
                    abi::KIND_TEXTURE,
                    "",
                    &abi::TextureVTable { create: $crate::shim::texture_create::<$tex> }
                        as *const abi::TextureVTable as *const ::std::ffi::c_void,
                ),)*)?
                $($($crate::shim::entry::<$vol>(
                    abi::KIND_VOLUME_READER,
                    "",
                    &abi::VolumeReaderVTable { read: $crate::shim::volume_read::<$vol> }
                        as *const abi::VolumeReaderVTable as *const ::std::ffi::c_void,
                ),)*)?
                $($($crate::shim::entry::<$wr>(
                    abi::KIND_WRITER,
                    <$wr as $crate::Writer>::EXTENSIONS,
                    &abi::WriterVTable { write: $crate::shim::writer_write::<$wr> }
                        as *const abi::WriterVTable as *const ::std::ffi::c_void,
                ),)*)?
            ]);
            static DECLARATION: SyncWrap<abi::Declaration> = SyncWrap(abi::Declaration {
                library: abi::Str::new($lib),
                entries: ENTRIES.0.as_ptr(),
                entry_count: ENTRIES.0.len(),
            });
            static HEADER: SyncWrap<abi::PluginHeader> = SyncWrap(abi::PluginHeader {
                magic: abi::MAGIC,
                abi_version: abi::ABI_VERSION,
                sdk_version: abi::Str::new($crate::SDK_VERSION),
                declaration: &DECLARATION.0,
            });

            #[no_mangle]
            pub extern "C" fn luxon_plugin_declare(
                host: *const abi::HostTable,
            ) -> *const abi::PluginHeader {
                $crate::shim::init(host, $lib);
                &HEADER.0
            }
        };
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fails when the query's `time` is negative.
    struct Picky;

    impl Describe for Picky {
        const NAME: &'static str = "picky";
        const DESCRIPTION: &'static str = "";
        const PARAMS: &'static str = "";
    }

    impl Texture for Picky {
        type Params = ();
        fn create(_: (), _: &Context) -> Result<Self, Error> {
            Ok(Picky)
        }
        fn eval(&self, q: &abi::TexQuery) -> [f32; 4] {
            if q.time < 0.0 {
                texture_failed();
            }
            [0.5; 4]
        }
    }

    #[test]
    fn a_failed_texture_evaluation_returns_an_error_status_once() {
        let vt = texture_instance_vtable::<Picky>();
        let object = Box::into_raw(Box::new(Picky)) as *mut c_void;
        let mut out = [0.0f32; 4];
        let q = |time| abi::TexQuery {
            time,
            ..Default::default()
        };
        assert_eq!((vt.eval)(object, &q(-1.0), &mut out), abi::STATUS_ERROR);
        assert_eq!(out, [0.0; 4], "a failed evaluation writes no value");
        // The mark belongs to one evaluation only.
        assert_eq!((vt.eval)(object, &q(1.0), &mut out), abi::STATUS_OK);
        assert_eq!(out, [0.5; 4]);
        (vt.destroy)(object);
    }

    #[derive(serde::Deserialize, Debug, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct P {
        center: [f64; 3],
        radius: f64,
    }

    #[test]
    fn params_parse_and_integers_are_floats() {
        let p: P = parse_params("(center: (0, 1, 2), radius: 1)").unwrap();
        assert_eq!(
            p,
            P {
                center: [0.0, 1.0, 2.0],
                radius: 1.0
            }
        );
    }

    #[test]
    fn unknown_param_suggests_and_has_position() {
        let e = parse_params::<P>("(center: (0, 1, 2),\n radus: 1)").unwrap_err();
        assert!(e.message.contains("did you mean `radius`"), "{}", e.message);
        assert_eq!((e.line, e.col), (2, 2));
    }

    #[test]
    fn missing_param_is_named() {
        let e = parse_params::<P>("(center: (0, 1, 2))").unwrap_err();
        assert!(
            e.message.contains("missing parameter `radius`"),
            "{}",
            e.message
        );
    }

    #[test]
    fn suggestions() {
        assert_eq!(suggest("sphre", ["sphere", "plane"]), Some("sphere"));
        assert_eq!(suggest("xyzzy", ["sphere", "plane"]), None);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }
}
