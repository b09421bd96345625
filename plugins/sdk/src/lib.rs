//! # luxon-plugin: write Luxon plugins as safe Rust
//!
//! A plugin library is a `cdylib` that depends on this crate only. Each thing it provides is a
//! type implementing [`Describe`] and one of [`Primitive`], [`Texture`], [`VolumeReader`] or
//! [`Writer`]; one [`export!`] line publishes them. The host finds the library by the names in
//! it, checks [`abi::ABI_VERSION`] before calling anything, and hands each instance its `params`
//! subtree from the scene as RON text, which this crate deserializes into the type's own
//! `#[derive(Deserialize)]` struct (use `#[serde(deny_unknown_fields)]` so typos are errors).
//! `luxon new-plugin NAME --kind primitive|texture|writer|volume` writes a crate of each kind
//! to start from.
//!
//! ```no_run
//! use luxon_plugin::*;
//!
//! #[derive(serde::Deserialize)]
//! #[serde(deny_unknown_fields)]
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
//! to write one. Its Rust examples are compiled as doctests here.
#![doc = include_str!("../../README.md")]

pub mod abi;
pub mod files;
pub mod names;
mod params;
pub mod srgb8;

use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

/// A texture's query, the one type of [`abi`] a texture plugin names.
pub use abi::TexQuery;
pub use abi::ABI_VERSION;
/// The serde this crate deserializes parameters with. Plugins depend on `serde` themselves
/// (see "Parameters" in the crate documentation); Cargo makes both the same crate.
pub use serde;

/// Version of this crate, sent in the handshake.
pub const SDK_VERSION: &str = env!("CARGO_PKG_VERSION");

/// An error a plugin reports; `line`/`col` (1-based, 0 = unknown) are positions in its params text.
#[derive(Debug, Clone, PartialEq)]
pub struct Error {
    /// What went wrong, in words for the scene's author (the host adds the plugin's name and
    /// the scene position).
    pub message: String,
    /// Line in the params text (1-based; 0: no position, the host points at `params`).
    pub line: u32,
    /// Column in that line (1-based; 0: no position).
    pub col: u32,
}

impl Error {
    /// An error without a position.
    pub fn new(message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
            line: 0,
            col: 0,
        }
    }

    /// An error about parameter `field`: "parameter `field`: {message}". Returned from a
    /// plugin's `create`/`read`/`write`, it is reported at that field in the scene file (the
    /// SDK finds `field:` in the params text it was given); a field the scene leaves out (its
    /// default was used) is reported at the start of the params. Any error without a position
    /// whose message begins with "parameter `name`" is placed the same way.
    ///
    /// ```
    /// let e = luxon_plugin::Error::invalid_at("width", "expected a number > 0, found -1");
    /// assert_eq!(e.message, "parameter `width`: expected a number > 0, found -1");
    /// ```
    pub fn invalid_at(field: &str, message: impl std::fmt::Display) -> Error {
        Error::new(format!("parameter `{field}`: {message}"))
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

/// Shorthand for [`Error::invalid_at`]: a failed check on parameter `field`, reported at it.
pub fn invalid_at(field: &str, message: impl std::fmt::Display) -> Error {
    Error::invalid_at(field, message)
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
    /// The name scenes use: `(plugin: "NAME", ...)`. Unique among the plugins of its kind on
    /// the search path (the first library found that provides it wins).
    const NAME: &'static str;
    /// One line: what it is.
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
    /// Bytes this call may allocate for what it produces or keeps (0: unknown, no limit
    /// given). Allocate big arrays with [`Context::alloc_vec`], which checks it.
    pub memory_budget: u64,
}

impl Default for Context {
    /// A context outside any scene (tests, tools): relative paths resolve against ".", and
    /// no memory budget is given.
    fn default() -> Context {
        Context {
            scene_dir: PathBuf::from("."),
            instance: String::new(),
            texture_cache_bytes: 0,
            threads: 1,
            memory_budget: 0,
        }
    }
}

impl Context {
    /// `path` relative to the scene file's directory (absolute paths are kept).
    pub fn resolve(&self, path: impl AsRef<Path>) -> PathBuf {
        self.scene_dir.join(path)
    }

    /// `n` copies of `value`, allocated within [`memory_budget`](Self::memory_budget) and
    /// without aborting when the system refuses: either is an error naming `what` (say "a
    /// slab of 8 slices of 1024x1024 u8 voxels") and the size it needs.
    pub fn alloc_vec<T: Clone>(&self, n: usize, value: T, what: &str) -> Result<Vec<T>, Error> {
        let bytes = (n as u64).saturating_mul(std::mem::size_of::<T>() as u64);
        let size = files::bytes(bytes);
        if self.memory_budget != 0 && bytes > self.memory_budget {
            return Err(Error::new(format!(
                "{what} needs {size}, more than the memory budget left for this plugin ({})",
                files::bytes(self.memory_budget)
            )));
        }
        let mut v = Vec::new();
        v.try_reserve_exact(n).map_err(|_| {
            Error::new(format!(
                "{what} needs {size}, which the system cannot allocate"
            ))
        })?;
        v.resize(n, value);
        Ok(v)
    }
}

// ------------------------------------------------------------------------------------------------
// Parameters
// ------------------------------------------------------------------------------------------------

/// Deserializes a params subtree given as RON text; positions in errors are relative to `text`.
pub fn parse_params<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, Error> {
    parse_documented_params(text, "")
}

/// [`parse_params`] for a plugin whose parameter table ([`Describe::PARAMS`]) is `doc`: a value
/// of the wrong type is reported naming its parameter, the type the table gives it and what the
/// text has there ("parameter `color`: expected (r, g, b), found `"red"`"). The SDK's entry
/// points parse with the plugin's own table.
pub fn parse_documented_params<T: serde::de::DeserializeOwned>(
    text: &str,
    doc: &str,
) -> Result<T, Error> {
    let text = if text.trim().is_empty() { "()" } else { text };
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .from_str::<T>(text)
        .map_err(|e| {
            let (line, col) = (e.span.start.line, e.span.start.col);
            let (message, (line, col)) = params::type_error(text, doc, &e.code, line, col)
                .unwrap_or_else(|| (describe_ron_error(&e.code), (line as u32, col as u32)));
            Error { message, line, col }
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
        // ron's own words point at its options, which a scene's author cannot set.
        ron::Error::ExceededRecursionLimit => {
            "values are nested more than 128 levels deep; expected at most 128 levels of brackets"
                .to_string()
        }
        other => other.to_string(),
    }
}

/// The candidate closest to `word` by edit distance, if it is close enough to be a likely typo:
/// at most `max(2, len / 3)` edits (len: `word`'s length in characters), and not a complete
/// rewrite of the word. The first of equally close candidates wins.
///
/// Luxon's one "did you mean" rule: plugin parameters and names here, scene files through
/// `luxon-formats` (which re-exports it).
pub fn suggest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let len = word.chars().count();
    let limit = (len / 3).max(2);
    let mut best: Option<(usize, &'a str)> = None;
    for candidate in candidates {
        let d = edit_distance(word, candidate);
        // Replacing every character is not a typo ("x" is not a misspelt "up").
        let whole = len.max(candidate.chars().count());
        if d <= limit && d < whole && !matches!(best, Some((b, _)) if b <= d) {
            best = Some((d, candidate));
        }
    }
    best.map(|(_, c)| c)
}

/// Levenshtein distance over chars.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitute = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

// ------------------------------------------------------------------------------------------------
// Primitives
// ------------------------------------------------------------------------------------------------

/// A primitive plugin: turns parameters into geometry.
pub trait Primitive: Describe {
    /// The scene's `params: (...)`, deserialized (see "Parameters" in the crate documentation).
    type Params: serde::de::DeserializeOwned;
    /// Called once per scene object naming the plugin: checks the parameters and hands the
    /// geometry to `out`. An error stops the scene from loading, naming the object.
    fn create(params: Self::Params, ctx: &Context, out: &mut Geometry) -> Result<(), Error>;
}

/// The host's geometry builder, seen from a plugin.
pub struct Geometry<'a> {
    sink: &'a abi::GeometrySink,
}

/// A triangle mesh to hand to the host. Optional arrays are empty or have one entry per vertex.
#[derive(Default, Clone, Debug)]
pub struct Mesh {
    /// Vertex positions in world space.
    pub positions: Vec<[f64; 3]>,
    /// Three indices into `positions` per triangle.
    pub indices: Vec<[u64; 3]>,
    /// Per-vertex normals, interpolated for smooth shading (empty: flat shading).
    pub normals: Vec<[f64; 3]>,
    /// Per-vertex linear RGB colours, interpolated and multiplied into the material's colour.
    pub colors: Vec<[f32; 3]>,
    /// Per-vertex texture coordinates, interpolated into [`TexQuery::uv`].
    pub uvs: Vec<[f32; 2]>,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The smallest corner (x, y, z), world space.
    pub min: [f64; 3],
    /// The largest corner.
    pub max: [f64; 3],
}

/// A ray as custom geometry sees it (world space, f64): see [`abi::RayF64`] for its fields.
pub type Ray = abi::RayF64;
/// A custom geometry hit: see [`abi::HitF64`] for its fields.
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

/// The SDK's error sink: keeps the message the host reports for one call.
///
/// # Safety
/// `ctx` is the `SinkError` of the running [`call_sink`]; `message` as in the ABI contract.
unsafe extern "C" fn sink_error_set(ctx: *mut c_void, message: abi::Str, line: u32, col: u32) {
    // SAFETY: the host calls this only through the `ErrorSink` of a running `call_sink`, whose
    // `ctx` points to that call's `SinkError`; nothing else touches it until the call returns.
    let slot = unsafe { &mut *(ctx as *mut SinkError) };
    // SAFETY: the host's `Str` is readable for this call (ABI contract); it is copied here.
    let message = unsafe { message.as_str() }
        .unwrap_or("(invalid UTF-8)")
        .to_string();
    slot.0 = Some(Error { message, line, col });
}

/// Runs one call into a host sink with an error sink of our own; the host's message on failure.
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

/// The signature of the sinks taking `count` records of f64 (spheres, planes, cones, discs).
type AddRecords = unsafe extern "C" fn(
    ctx: *mut c_void,
    data: *const f64,
    count: u64,
    err: *const abi::ErrorSink,
) -> abi::Status;

impl Geometry<'_> {
    /// Hands `records` to one of the sink's `add_*` functions.
    fn add<const N: usize>(&mut self, add: AddRecords, records: &[[f64; N]]) -> Result<(), Error> {
        let sink = self.sink;
        call_sink(|err| {
            // SAFETY: `add` is a function of `sink`, the host's table for the running `create`
            // (a `Geometry` exists only inside that call) and `sink.ctx` its own context;
            // `records` is `len` records of N contiguous f64, borrowed across the call; `err`
            // lives in `call_sink`.
            unsafe {
                add(
                    sink.ctx,
                    records.as_ptr() as *const f64,
                    records.len() as u64,
                    err,
                )
            }
        })
    }

    /// Spheres as `[x, y, z, radius]`.
    pub fn spheres(&mut self, spheres: &[[f64; 4]]) -> Result<(), Error> {
        self.add(self.sink.add_spheres, spheres)
    }

    /// Infinite planes as `[px, py, pz, nx, ny, nz]`.
    pub fn planes(&mut self, planes: &[[f64; 6]]) -> Result<(), Error> {
        self.add(self.sink.add_planes, planes)
    }

    /// Open cones as `[bx, by, bz, base_radius, ax, ay, az, apex_radius]`; equal radii make a
    /// cylinder. Caps are not included: add discs.
    pub fn cones(&mut self, cones: &[[f64; 8]]) -> Result<(), Error> {
        self.add(self.sink.add_cones, cones)
    }

    /// Discs or rings as `[cx, cy, cz, nx, ny, nz, inner_radius, outer_radius]`.
    pub fn discs(&mut self, discs: &[[f64; 8]]) -> Result<(), Error> {
        self.add(self.sink.add_discs, discs)
    }

    /// A triangle mesh; its optional arrays have one entry per vertex or none.
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
        let sink = self.sink;
        // SAFETY: `sink` is the host's table for the running `create` and `ctx` its own; every
        // array of `data` borrows `mesh` for the call with the length `MeshData` states (the
        // optional ones were checked to have one entry per vertex, or are null).
        call_sink(|err| unsafe { (sink.add_mesh)(sink.ctx, &data, err) })
    }

    /// Hands `shape` to the host, which owns it from now on.
    pub fn custom<S: CustomShape>(&mut self, shape: S) -> Result<(), Error> {
        let count = shape.count();
        let object = Box::into_raw(Box::new(Shape {
            shape,
            told: std::sync::atomic::AtomicBool::new(false),
        })) as *mut c_void;
        let geometry = abi::CustomGeometry {
            object,
            count,
            vtable: custom_vtable::<S>(),
        };
        let sink = self.sink;
        // The host takes ownership even when it reports an error (it destroys the object).
        // SAFETY: `sink` is the host's table for the running `create` and `ctx` its own;
        // `geometry` lives across the call, its object is a live `S` whose table is `S`'s.
        call_sink(|err| unsafe { (sink.add_custom)(sink.ctx, &geometry, err) })
    }
}

/// A custom shape as the host holds it: the plugin's shape, and whether the host has been told
/// of a panic in it.
struct Shape<S> {
    shape: S,
    told: std::sync::atomic::AtomicBool,
}

impl<S> Shape<S> {
    /// What a panic caught in `call` gives the host. Its calls have no error sink, so the first
    /// panic's message goes through the host log, on the thread of the call: "panicked in
    /// `intersect`: {message}" (a host that knows this convention adds it to the error that
    /// stops the render; an older one prints it as an error line). Later ones only return
    /// `status`.
    fn panicked<T>(&self, call: &str, p: Box<dyn std::any::Any + Send>, status: T) -> T {
        if !self.told.swap(true, std::sync::atomic::Ordering::Relaxed) {
            let message = shim::panic_message(p);
            let words = message.strip_prefix("panicked: ").unwrap_or(&message);
            let library = shim::LIBRARY.get().copied().unwrap_or("?");
            host_log(library, 0, &format!("panicked in `{call}`: {words}"));
        }
        status
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

// The functions of a custom shape's table. Their `object` is the `Box<Shape<S>>` that
// `Geometry::custom` leaked and handed to the host, which destroys it once, after every other
// call (ABI contract); `S: Sync`, so concurrent calls from the host's render threads are fine.

/// # Safety
/// `object` is a live `Shape<S>` from [`Geometry::custom`]; `min` and `max` are writable.
unsafe extern "C" fn custom_bounds<S: CustomShape>(
    object: *const c_void,
    index: u64,
    min: *mut [f64; 3],
    max: *mut [f64; 3],
) -> abi::Status {
    // SAFETY: see the comment above these functions.
    let shape = unsafe { &*(object as *const Shape<S>) };
    match catch_unwind(AssertUnwindSafe(|| shape.shape.bounds(index))) {
        Ok(b) => {
            // SAFETY: the host passes two writable `[f64; 3]` for the call (ABI contract).
            unsafe {
                *min = b.min;
                *max = b.max;
            }
            abi::STATUS_OK
        }
        Err(p) => shape.panicked("bounds", p, abi::STATUS_PANIC),
    }
}

/// # Safety
/// `object` is a live `Shape<S>` from [`Geometry::custom`]; `ray` is readable, `hit` writable.
unsafe extern "C" fn custom_intersect<S: CustomShape>(
    object: *const c_void,
    index: u64,
    ray: *const abi::RayF64,
    hit: *mut abi::HitF64,
) -> u32 {
    // SAFETY: see the comment above these functions; the host's ray is valid for the call.
    let (shape, ray) = unsafe { (&*(object as *const Shape<S>), &*ray) };
    match catch_unwind(AssertUnwindSafe(|| shape.shape.intersect(index, ray))) {
        Ok(Some(h)) => {
            // SAFETY: the host passes a writable `HitF64` for the call (ABI contract).
            unsafe { *hit = h };
            1
        }
        Ok(None) => 0,
        Err(p) => shape.panicked("intersect", p, abi::HIT_PANIC),
    }
}

/// # Safety
/// `object` is a live `Shape<S>` from [`Geometry::custom`]; `ray` is readable.
unsafe extern "C" fn custom_occluded<S: CustomShape>(
    object: *const c_void,
    index: u64,
    ray: *const abi::RayF64,
) -> u32 {
    // SAFETY: see the comment above these functions; the host's ray is valid for the call.
    let (shape, ray) = unsafe { (&*(object as *const Shape<S>), &*ray) };
    match catch_unwind(AssertUnwindSafe(|| shape.shape.occluded(index, ray))) {
        Ok(b) => u32::from(b),
        Err(p) => shape.panicked("occluded", p, abi::HIT_PANIC),
    }
}

/// # Safety
/// `object` is a live `Shape<S>` from [`Geometry::custom`], not used again after this call.
unsafe extern "C" fn custom_destroy<S: CustomShape>(object: *mut c_void) {
    // SAFETY: `object` came from `Box::into_raw` of a `Box<Shape<S>>` and the host destroys it
    // once, after every other call on it (see the comment above these functions).
    let shape = unsafe { Box::from_raw(object as *mut Shape<S>) };
    let _ = catch_unwind(AssertUnwindSafe(|| drop(shape)));
}

// ------------------------------------------------------------------------------------------------
// Textures
// ------------------------------------------------------------------------------------------------

/// A texture plugin: an instance created once, evaluated at every shading point (from many
/// threads at once, hence `Sync`).
pub trait Texture: Describe + Send + Sync + Sized + 'static {
    /// The texture's `params: (...)`, deserialized (see "Parameters" in the crate documentation).
    type Params: serde::de::DeserializeOwned;
    /// Called once per entry of the scene's `textures` naming the plugin. An error stops the
    /// scene from loading, naming the texture.
    fn create(params: Self::Params, ctx: &Context) -> Result<Self, Error>;
    /// Linear RGBA at the query point (see [`TexQuery`] for its fields). A material's colour
    /// takes red, green and blue (values above 1 are allowed); a reflect or transmit texture
    /// the mean of the three. The host does not use alpha: give 1, or what your own nested
    /// textures mix by.
    fn eval(&self, query: &abi::TexQuery) -> [f32; 4];
    /// What the host calls: [`eval`](Self::eval)'s value, or an error when no value can be
    /// given (an image that turns out not to decode). The host then stops the render with the
    /// error's message, naming the texture and its place in the scene, and the run fails (its
    /// outputs are left untouched). Override it only for textures that can fail; `eval` may
    /// then return a stand-in colour for callers that do not care.
    fn try_eval(&self, query: &abi::TexQuery) -> Result<[f32; 4], Error> {
        Ok(self.eval(query))
    }
    /// Which fields of the query `eval` reads (`abi::READS_*` bits), asked once after
    /// `create`: the host may leave the others 0 and skip working them out. The default, every
    /// field, is always correct; a texture that declares too few sees zeros.
    fn reads(&self) -> u32 {
        abi::READS_ALL
    }
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

// The functions of a texture instance's table. Their `object` is the `Box<T>` that
// `shim::texture_create` leaked into the host's `TextureObject`; the host destroys it once,
// after every other call (ABI contract); `T: Sync`, so concurrent `eval`s are fine.

/// # Safety
/// `object` is a live `T` from `shim::texture_create`; `query` is readable, `out` writable;
/// `err` is null or the host's error sink for this call.
unsafe extern "C" fn texture_eval<T: Texture>(
    object: *const c_void,
    query: *const abi::TexQuery,
    out: *mut [f32; 4],
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: see the comment above these functions; the host's query and error sink (or
    // null) are valid for the call.
    let (tex, q, err) = unsafe { (&*(object as *const T), &*query, err.as_ref()) };
    match catch_unwind(AssertUnwindSafe(|| tex.try_eval(q))) {
        Ok(Ok(c)) => {
            // SAFETY: the host passes a writable `[f32; 4]` for the call (ABI contract).
            unsafe { *out = c };
            abi::STATUS_OK
        }
        Ok(Err(e)) => {
            shim::report(err, &e);
            abi::STATUS_ERROR
        }
        Err(p) => {
            shim::report(err, &Error::new(shim::panic_message(p)));
            abi::STATUS_PANIC
        }
    }
}

/// # Safety
/// `object` is a live `T` from `shim::texture_create`, not used again after this call.
unsafe extern "C" fn texture_destroy<T: Texture>(object: *mut c_void) {
    // SAFETY: `object` came from `Box::into_raw` of a `Box<T>` and the host destroys it once,
    // after every other call on it (see the comment above these functions).
    let tex = unsafe { Box::from_raw(object as *mut T) };
    let _ = catch_unwind(AssertUnwindSafe(|| drop(tex)));
}

// ------------------------------------------------------------------------------------------------
// Volume readers
// ------------------------------------------------------------------------------------------------

/// A volume reader plugin: streams a scalar grid into the host.
pub trait VolumeReader: Describe {
    /// The volume's `params: (...)`, deserialized (see "Parameters" in the crate documentation).
    type Params: serde::de::DeserializeOwned;
    /// Called once per volume of the scene naming the plugin: describes the grid with
    /// [`VolumeOut::begin`], then sends its blocks and tiles. An error stops the scene from
    /// loading, naming the volume.
    fn read(params: Self::Params, ctx: &Context, out: &mut VolumeOut) -> Result<(), Error>;
}

/// Description of a grid, sent before its data (see [`abi::VolumeDesc`]).
#[derive(Clone, Debug)]
pub struct GridInfo {
    /// Row-major 3x4 affine map from voxel index to world space: voxel `(i, j, k)` is at
    /// `M · (i, j, k, 1)`.
    pub world_from_index: [f64; 12],
    /// The value outside every block and tile (where nothing was sent).
    pub background: f32,
    /// The smallest voxel index along each axis.
    pub index_min: [i64; 3],
    /// The largest voxel index along each axis (inclusive).
    pub index_max: [i64; 3],
    /// The grid's name, for messages and `luxon check`.
    pub name: String,
}

/// An error unless a block of `dims` voxels comes with `len` values.
fn check_count(dims: [u64; 3], len: usize) -> Result<(), Error> {
    let n = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d));
    if n != Some(len as u64) {
        return Err(Error::new(format!(
            "dense block of {dims:?} voxels given {len} values"
        )));
    }
    Ok(())
}

/// The host's volume builder, seen from a reader.
pub struct VolumeOut<'a> {
    sink: &'a abi::VolumeSink,
}

impl VolumeOut<'_> {
    /// Describes the grid; called once, before any block or tile.
    pub fn begin(&mut self, info: &GridInfo) -> Result<(), Error> {
        let desc = abi::VolumeDesc {
            world_from_index: info.world_from_index,
            background: info.background,
            index_min: info.index_min,
            index_max: info.index_max,
            grid_name: abi::Str::new(&info.name),
        };
        let sink = self.sink;
        // SAFETY: `sink` is the host's table for the running `read` (a `VolumeOut` exists only
        // inside it) and `ctx` its own; `desc` and its name live across the call.
        call_sink(|err| unsafe { (sink.begin)(sink.ctx, &desc, err) })
    }

    /// A dense block, x fastest; `values.len()` must be `dims[0] * dims[1] * dims[2]`.
    pub fn dense(&mut self, origin: [i64; 3], dims: [u64; 3], values: &[f32]) -> Result<(), Error> {
        check_count(dims, values.len())?;
        let sink = self.sink;
        // SAFETY: `sink` is the host's table for the running `read` and `ctx` its own; `values`
        // holds the `dims[0] * dims[1] * dims[2]` values the call reads (checked above).
        call_sink(|err| unsafe { (sink.add_dense)(sink.ctx, &origin, &dims, values.as_ptr(), err) })
    }

    /// A dense block of bytes, x fastest: voxel value `byte as f32 / divisor` (1 for the raw
    /// values, 255 to map them to [0, 1]). The host keeps it at a byte per voxel where it can,
    /// so a u8 file costs about its own size; a volume uses one divisor for all its u8 blocks.
    pub fn dense_u8(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[u8],
        divisor: f32,
    ) -> Result<(), Error> {
        check_count(dims, values.len())?;
        self.dense_typed(
            origin,
            dims,
            abi::VOXEL_U8,
            values.as_ptr(),
            values.len(),
            divisor,
        )
    }

    /// A dense block of `u16` (in the machine's byte order: swap a file's first), as
    /// [`dense_u8`](Self::dense_u8): value `v as f32 / divisor`, one divisor per volume.
    pub fn dense_u16(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[u16],
        divisor: f32,
    ) -> Result<(), Error> {
        check_count(dims, values.len())?;
        let data = values.as_ptr() as *const u8;
        self.dense_typed(
            origin,
            dims,
            abi::VOXEL_U16,
            data,
            values.len() * 2,
            divisor,
        )
    }

    /// `len` bytes at `data`: the voxels of a block checked by `check_count`, in `format`.
    fn dense_typed(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        format: u32,
        data: *const u8,
        len: usize,
        divisor: f32,
    ) -> Result<(), Error> {
        let sink = self.sink;
        // SAFETY: `sink` is the host's table for the running `read` and `ctx` its own; `data`
        // borrows the caller's slice of `len` bytes (aligned for its element type), which holds
        // the block's voxels in `format` (its count checked by the callers).
        call_sink(|err| unsafe {
            (sink.add_dense_typed)(sink.ctx, &origin, &dims, format, data, len, divisor, err)
        })
    }

    /// A box of `dims` voxels from index `origin`, all of `value` (a sparse format's
    /// constant tiles; cheaper than a dense block of one value).
    pub fn tile(&mut self, origin: [i64; 3], dims: [u64; 3], value: f32) -> Result<(), Error> {
        let sink = self.sink;
        // SAFETY: `sink` is the host's table for the running `read` and `ctx` its own.
        call_sink(|err| unsafe { (sink.add_tile)(sink.ctx, &origin, &dims, value, err) })
    }
}

// ------------------------------------------------------------------------------------------------
// Writers
// ------------------------------------------------------------------------------------------------

/// A finished image: linear RGBA f32, rows top to bottom.
pub struct Image<'a> {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width * height` pixels of four values each, red, green, blue and alpha, row by row
    /// from the top. Colours are linear (encode them for the format: [`linear_to_srgb`] for
    /// 8-bit sRGB) and may exceed 1; alpha is 1 (rendered pixels are opaque).
    pub rgba: &'a [f32],
}

/// An image writer plugin: encodes an image into bytes; the host writes them atomically.
pub trait Writer: Describe {
    /// Comma-separated file extensions, without dots, e.g. "ppm,pnm".
    const EXTENSIONS: &'static str;
    /// The output's `params: (...)`, deserialized (see "Parameters" in the crate
    /// documentation).
    type Params: serde::de::DeserializeOwned;
    /// Called once per output written (once per frame of an animation): encodes `image` into
    /// `out`, whose bytes become the file, written whole or not at all. An error fails the
    /// run with the message, and the file is not written.
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
        // SAFETY: the sink is the host's table for the running `write` (a `ByteOut` exists only
        // inside it) and `ctx` its own; `buf` is `len` bytes borrowed across the call.
        match unsafe { (self.0.write)(self.0.ctx, buf.as_ptr(), buf.len()) } {
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

/// Encodes the RGB of each linear RGBA pixel of `rgba` with `encode` (one channel at a time)
/// and hands `emit` the three samples with the pixel. A pixel whose colour has the same bits as
/// the one before it (a background, a flat region) gets that pixel's samples again instead of
/// being encoded anew: the same samples, without the transfer curve's `powf`.
pub fn encode_rgb<T: Copy>(
    rgba: &[f32],
    mut encode: impl FnMut(f32) -> T,
    mut emit: impl FnMut([T; 3], &[f32]),
) {
    let mut last: Option<([u32; 3], [T; 3])> = None;
    for px in rgba.chunks_exact(4) {
        let bits = [px[0].to_bits(), px[1].to_bits(), px[2].to_bits()];
        let rgb = match last {
            Some((b, rgb)) if b == bits => rgb,
            _ => {
                let rgb = [encode(px[0]), encode(px[1]), encode(px[2])];
                last = Some((bits, rgb));
                rgb
            }
        };
        emit(rgb, px);
    }
}

// ------------------------------------------------------------------------------------------------
// Entry point shims (used by `export!`; not for direct use)
// ------------------------------------------------------------------------------------------------

#[doc(hidden)]
pub mod shim {
    use super::*;
    use std::marker::PhantomData;

    pub(crate) fn report(err: Option<&abi::ErrorSink>, e: &Error) {
        if let Some(sink) = err {
            // SAFETY: `sink` is the host's error sink for the running call and `ctx` its own
            // (ABI contract); the message is borrowed across the call.
            unsafe { (sink.set)(sink.ctx, abi::Str::new(&e.message), e.line, e.col) };
        }
    }

    pub(crate) fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
        if let Some(s) = p.downcast_ref::<&str>() {
            format!("panicked: {s}")
        } else if let Some(s) = p.downcast_ref::<String>() {
            format!("panicked: {s}")
        } else {
            "panicked".to_string()
        }
    }

    fn context(ctx: Option<&abi::CallContext>) -> Context {
        match ctx {
            // SAFETY: the host's strings are readable for the running call (ABI contract);
            // they are copied here.
            Some(c) => unsafe {
                Context {
                    scene_dir: PathBuf::from(c.scene_dir.as_str().unwrap_or(".")),
                    instance: c.instance.as_str().unwrap_or("").to_string(),
                    texture_cache_bytes: c.texture_cache_bytes,
                    threads: c.threads,
                    memory_budget: c.memory_budget,
                }
            },
            None => Context::default(),
        }
    }

    /// Runs `f` with panics caught and errors sent to `err`.
    fn guarded(err: Option<&abi::ErrorSink>, f: impl FnOnce() -> Result<(), Error>) -> abi::Status {
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

    /// The params text of a call, or why it is unusable.
    fn text(text: Result<&str, std::str::Utf8Error>) -> Result<&str, Error> {
        text.map_err(|_| Error::new("params are not UTF-8"))
    }

    /// Parses the params of `D` and runs `f` with them; an error from `f` that names a
    /// parameter is placed at it in `text` (see [`Error::invalid_at`]).
    fn with_params<D: Describe, P: serde::de::DeserializeOwned>(
        text: Result<&str, std::str::Utf8Error>,
        f: impl FnOnce(P) -> Result<(), Error>,
    ) -> Result<(), Error> {
        let text = self::text(text)?;
        let p = parse_documented_params::<P>(text, D::PARAMS)?;
        f(p).map_err(|e| params::place(e, text))
    }

    /// [`abi::PrimitiveVTable::create`] for `P`.
    ///
    /// # Safety
    /// The ABI's calling contract (see [`abi`]): `text` readable; `ctx` and `err` null or
    /// valid; `sink` valid, all for the duration of the call.
    pub unsafe extern "C" fn primitive_create<P: Primitive>(
        text: abi::Str,
        ctx: *const abi::CallContext,
        sink: *const abi::GeometrySink,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        // SAFETY: the caller promises each pointer is null or valid for this call, and the
        // references do not outlive it (the closure runs before we return).
        let (text, ctx, sink, err) =
            unsafe { (text.as_str(), ctx.as_ref(), sink.as_ref(), err.as_ref()) };
        guarded(err, || {
            with_params::<P, P::Params>(text, |p| {
                let sink = sink.ok_or_else(|| Error::new("no geometry sink"))?;
                P::create(p, &context(ctx), &mut Geometry { sink })
            })
        })
    }

    /// [`abi::TextureVTable::create`] for `T`.
    ///
    /// # Safety
    /// The ABI's calling contract (see [`abi`]): `text` readable; `ctx` and `err` null or
    /// valid; `out` writable, all for the duration of the call.
    pub unsafe extern "C" fn texture_create<T: Texture>(
        text: abi::Str,
        ctx: *const abi::CallContext,
        out: *mut abi::TextureObject,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        // SAFETY: as in `primitive_create`; `out` is the host's slot, written only here.
        let (text, ctx, out, err) =
            unsafe { (text.as_str(), ctx.as_ref(), out.as_mut(), err.as_ref()) };
        guarded(err, || {
            let out = out.ok_or_else(|| Error::new("no place for the texture"))?;
            with_params::<T, T::Params>(text, |p| {
                let tex = T::create(p, &context(ctx))?;
                let reads = tex.reads();
                *out = abi::TextureObject {
                    object: Box::into_raw(Box::new(tex)) as *mut c_void,
                    vtable: texture_instance_vtable::<T>(),
                    reads,
                };
                Ok(())
            })
        })
    }

    /// [`abi::VolumeReaderVTable::read`] for `V`.
    ///
    /// # Safety
    /// The ABI's calling contract (see [`abi`]): `text` readable; `ctx` and `err` null or
    /// valid; `sink` valid, all for the duration of the call.
    pub unsafe extern "C" fn volume_read<V: VolumeReader>(
        text: abi::Str,
        ctx: *const abi::CallContext,
        sink: *const abi::VolumeSink,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        // SAFETY: as in `primitive_create`.
        let (text, ctx, sink, err) =
            unsafe { (text.as_str(), ctx.as_ref(), sink.as_ref(), err.as_ref()) };
        guarded(err, || {
            with_params::<V, V::Params>(text, |p| {
                let sink = sink.ok_or_else(|| Error::new("no volume sink"))?;
                V::read(p, &context(ctx), &mut VolumeOut { sink })
            })
        })
    }

    /// [`abi::WriterVTable::write`] for `W`.
    ///
    /// # Safety
    /// The ABI's calling contract (see [`abi`]): `text` readable; `ctx` and `err` null or
    /// valid; `image` (with its `width * height * 4` values) and `out` valid, all for the
    /// duration of the call.
    pub unsafe extern "C" fn writer_write<W: Writer>(
        text: abi::Str,
        ctx: *const abi::CallContext,
        image: *const abi::ImageView,
        out: *const abi::ByteSink,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        // SAFETY: as in `primitive_create`.
        let (text, ctx, view, out, err) = unsafe {
            (
                text.as_str(),
                ctx.as_ref(),
                image.as_ref(),
                out.as_ref(),
                err.as_ref(),
            )
        };
        guarded(err, || {
            with_params::<W, W::Params>(text, |p| {
                let view = view.ok_or_else(|| Error::new("no image"))?;
                let n = (view.width as usize)
                    .checked_mul(view.height as usize)
                    .and_then(|n| n.checked_mul(4))
                    .ok_or_else(|| Error::new("image too large"))?;
                let rgba = if n == 0 {
                    &[][..]
                } else if view.rgba.is_null() {
                    return Err(Error::new("no pixels"));
                } else {
                    // SAFETY: the host's image holds `width * height * 4` values, unchanged while
                    // the call runs (ABI contract), and the slice does not outlive the call.
                    unsafe { std::slice::from_raw_parts(view.rgba, n) }
                };
                let image = Image {
                    width: view.width,
                    height: view.height,
                    rgba,
                };
                let sink = out.ok_or_else(|| Error::new("no byte sink"))?;
                let mut w = ByteOut(sink);
                W::write(p, &context(ctx), &image, &mut w)
            })
        })
    }

    const fn entry<D: Describe>(
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

    // The entries of each kind, each with the table the host expects for that kind: a safe
    // function cannot pair a kind with another kind's table.

    /// The declaration entry of primitive `P`.
    pub const fn primitive_entry<P: Primitive>() -> abi::Entry {
        struct Table<P>(PhantomData<P>);
        impl<P: Primitive> Table<P> {
            const VTABLE: abi::PrimitiveVTable = abi::PrimitiveVTable {
                create: primitive_create::<P>,
            };
        }
        let vtable: &'static abi::PrimitiveVTable = &Table::<P>::VTABLE;
        entry::<P>(abi::KIND_PRIMITIVE, "", vtable as *const _ as *const c_void)
    }

    /// The declaration entry of texture `T`.
    pub const fn texture_entry<T: Texture>() -> abi::Entry {
        struct Table<T>(PhantomData<T>);
        impl<T: Texture> Table<T> {
            const VTABLE: abi::TextureVTable = abi::TextureVTable {
                create: texture_create::<T>,
            };
        }
        let vtable: &'static abi::TextureVTable = &Table::<T>::VTABLE;
        entry::<T>(abi::KIND_TEXTURE, "", vtable as *const _ as *const c_void)
    }

    /// The declaration entry of volume reader `V`.
    pub const fn volume_reader_entry<V: VolumeReader>() -> abi::Entry {
        struct Table<V>(PhantomData<V>);
        impl<V: VolumeReader> Table<V> {
            const VTABLE: abi::VolumeReaderVTable = abi::VolumeReaderVTable {
                read: volume_read::<V>,
            };
        }
        let vtable: &'static abi::VolumeReaderVTable = &Table::<V>::VTABLE;
        entry::<V>(
            abi::KIND_VOLUME_READER,
            "",
            vtable as *const _ as *const c_void,
        )
    }

    /// The declaration entry of writer `W`.
    pub const fn writer_entry<W: Writer>() -> abi::Entry {
        struct Table<W>(PhantomData<W>);
        impl<W: Writer> Table<W> {
            const VTABLE: abi::WriterVTable = abi::WriterVTable {
                write: writer_write::<W>,
            };
        }
        let vtable: &'static abi::WriterVTable = &Table::<W>::VTABLE;
        entry::<W>(
            abi::KIND_WRITER,
            W::EXTENSIONS,
            vtable as *const _ as *const c_void,
        )
    }

    /// The host's table, for `log`.
    pub(crate) static HOST: std::sync::OnceLock<&'static abi::HostTable> =
        std::sync::OnceLock::new();
    /// The library's name (`export!`'s), for log messages the SDK sends on its behalf.
    pub(crate) static LIBRARY: std::sync::OnceLock<&'static str> = std::sync::OnceLock::new();

    /// Called by the handshake. A cdylib has its own copy of std and so its own panic hook: the
    /// default one would print every caught panic (one per ray for a broken intersect). Ours
    /// sends the first panic's location through the host log and stays quiet after that; the
    /// message itself reaches the host as the call's error.
    ///
    /// # Safety
    /// `host` is null or points to a `HostTable` that stays valid and unchanged for the rest
    /// of the process (what the host promises in the handshake).
    pub unsafe fn init(host: *const abi::HostTable, library: &'static str) {
        // SAFETY: the caller's promise.
        let Some(host) = (unsafe { host.as_ref() }) else {
            return;
        };
        if HOST.set(host).is_err() {
            return;
        }
        let _ = LIBRARY.set(library);
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

    /// The static tables `export!` hands the host: the handshake's header, the declaration
    /// and the entry array. Only these can be wrapped (see [`SyncWrap`]).
    pub trait StaticTable: sealed::Sealed {}
    mod sealed {
        pub trait Sealed {}
    }
    impl sealed::Sealed for abi::PluginHeader {}
    impl StaticTable for abi::PluginHeader {}
    impl sealed::Sealed for abi::Declaration {}
    impl StaticTable for abi::Declaration {}
    impl sealed::Sealed for &'static [abi::Entry] {}
    impl StaticTable for &'static [abi::Entry] {}

    /// Makes the static tables of `export!` `Sync`, so they can be statics. Their raw pointers
    /// make them `!Sync` by default; for these types that is too cautious (see the `Sync` impl).
    pub struct SyncWrap<T: StaticTable>(pub T);

    // SAFETY: a `StaticTable` is plain data with no interior mutability: integers, function
    // pointers, and raw pointers (to string literals, the entry array, the vtables and the
    // declaration: all immutable statics). Sharing one between threads only lets them read
    // those values; reading through the raw pointers is unsafe code with its own contract
    // (the ABI's), which no more depends on the thread than a read of a static does.
    unsafe impl<T: StaticTable> Sync for SyncWrap<T> {}
}

/// Logs through the host (a plugin's own `log`/`println!` would bypass the host's output).
/// Level: 0 error, 1 warning, 2 info, 3 debug.
pub fn host_log(library: &str, level: u32, message: &str) {
    if let Some(host) = shim::HOST.get() {
        // SAFETY: the host's table stays valid for the process (`shim::init`'s contract), `log`
        // may be called from any thread, and both strings are borrowed across the call.
        unsafe { (host.log)(level, abi::Str::new(library), abi::Str::new(message)) };
    }
}

/// Publishes a library's plugins. Each list may be omitted.
///
/// ```text
/// export!(library: "luxon-shapes", primitives: [Sphere, Plane], textures: [], writers: []);
/// ```
///
/// The expansion holds the handshake (the library's one `#[no_mangle]` function) and its
/// static tables; its unsafe code is the SDK's, so a plugin crate can still
/// `#![forbid(unsafe_code)]` (the lint does not look into other crates' macros).
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
                $($($crate::shim::primitive_entry::<$prim>(),)*)?
                $($($crate::shim::texture_entry::<$tex>(),)*)?
                $($($crate::shim::volume_reader_entry::<$vol>(),)*)?
                $($($crate::shim::writer_entry::<$wr>(),)*)?
            ]);
            static DECLARATION: SyncWrap<abi::Declaration> = SyncWrap(abi::Declaration {
                library: abi::Str::new($lib),
                entries: ENTRIES.0.as_ptr(),
                entry_count: ENTRIES.0.len(),
            });
            // The same entries' names, read from the file by a host that loads only the
            // libraries a scene uses (see `names`).
            const ITEMS: &[$crate::names::Item] = &[
                $($($crate::names::Item::of::<$prim>(abi::KIND_PRIMITIVE, ""),)*)?
                $($($crate::names::Item::of::<$tex>(abi::KIND_TEXTURE, ""),)*)?
                $($($crate::names::Item::of::<$vol>(abi::KIND_VOLUME_READER, ""),)*)?
                $($($crate::names::Item::of::<$wr>(
                    abi::KIND_WRITER,
                    <$wr as $crate::Writer>::EXTENSIONS,
                ),)*)?
            ];
            // Placing a static in a named section is unsafe only if the section's other
            // contents clash; this one holds this table alone.
            #[unsafe(link_section = ".luxon_names")]
            #[used]
            static NAMES: [u8; $crate::names::table_len(ITEMS)] = $crate::names::table(ITEMS);
            static HEADER: SyncWrap<abi::PluginHeader> = SyncWrap(abi::PluginHeader {
                magic: abi::MAGIC,
                abi_version: abi::ABI_VERSION,
                sdk_version: abi::Str::new($crate::SDK_VERSION),
                declaration: &DECLARATION.0,
            });

            /// The handshake ([`abi::DeclareFn`]).
            ///
            /// # Safety
            /// `host` is null or the host's table, valid for the rest of the process.
            // Unmangled, which is unsafe only if the name clashes: the host looks the library's
            // one symbol of this name up (`export!` is used once per library).
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn luxon_plugin_declare(
                host: *const abi::HostTable,
            ) -> *const abi::PluginHeader {
                // SAFETY: the caller's promise, which is `init`'s contract.
                unsafe { $crate::shim::init(host, $lib) };
                // A use of the table, so that no linker drops its section as unreferenced.
                ::core::hint::black_box(&NAMES);
                &HEADER.0
            }
        };
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fails when the query's `time` is negative, panics when it is NaN.
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
        fn eval(&self, _: &abi::TexQuery) -> [f32; 4] {
            [0.5; 4]
        }
        fn try_eval(&self, q: &abi::TexQuery) -> Result<[f32; 4], Error> {
            assert!(!q.time.is_nan(), "a NaN time");
            if q.time < 0.0 {
                return Err(Error::new(format!("no value at time {}", q.time)));
            }
            Ok(self.eval(q))
        }
    }

    #[test]
    fn a_failed_texture_evaluation_returns_its_message() {
        let vt = texture_instance_vtable::<Picky>();
        let object = Box::into_raw(Box::new(Picky)) as *mut c_void;
        let mut out = [0.0f32; 4];
        let q = |time| abi::TexQuery {
            time,
            ..Default::default()
        };
        let mut slot = SinkError(None);
        let err = abi::ErrorSink {
            ctx: &mut slot as *mut SinkError as *mut c_void,
            set: sink_error_set,
        };
        // SAFETY: `object` is a live `Picky` made above for this table; queries, `out` and the
        // error sink (whose slot is only read between calls) live across each call; `destroy`
        // is the last use of `object`.
        unsafe {
            assert_eq!(
                (vt.eval)(object, &q(-1.0), &mut out, &err),
                abi::STATUS_ERROR
            );
            assert_eq!(out, [0.0; 4], "a failed evaluation writes no value");
            assert_eq!(slot.0.take().unwrap().message, "no value at time -1");
            assert_eq!((vt.eval)(object, &q(1.0), &mut out, &err), abi::STATUS_OK);
            assert_eq!(out, [0.5; 4]);
            assert!(slot.0.is_none());
            assert_eq!(
                (vt.eval)(object, &q(f32::NAN), &mut out, &err),
                abi::STATUS_PANIC
            );
            assert_eq!(slot.0.take().unwrap().message, "panicked: a NaN time");
            // Without an error sink the status still says what happened.
            assert_eq!(
                (vt.eval)(object, &q(-1.0), &mut out, std::ptr::null()),
                abi::STATUS_ERROR
            );
            (vt.destroy)(object);
        }
    }

    /// Keeps a table of 300 `u32` (1200 bytes).
    struct Hungry(#[allow(dead_code)] Vec<u32>);

    impl Describe for Hungry {
        const NAME: &'static str = "hungry";
        const DESCRIPTION: &'static str = "";
        const PARAMS: &'static str = "";
    }

    impl Texture for Hungry {
        type Params = ();
        fn create(_: (), ctx: &Context) -> Result<Self, Error> {
            Ok(Hungry(ctx.alloc_vec(300, 0u32, "the table")?))
        }
        fn eval(&self, _: &abi::TexQuery) -> [f32; 4] {
            [0.0; 4]
        }
    }

    #[test]
    fn the_call_contexts_memory_budget_reaches_the_plugin() {
        let create = |budget: u64| {
            let ctx = abi::CallContext {
                scene_dir: abi::Str::new("."),
                instance: abi::Str::new("t"),
                texture_cache_bytes: 0,
                threads: 1,
                memory_budget: budget,
            };
            let mut out = abi::TextureObject {
                object: std::ptr::null_mut(),
                vtable: std::ptr::null(),
                reads: abi::READS_ALL,
            };
            let mut slot = SinkError(None);
            let err = abi::ErrorSink {
                ctx: &mut slot as *mut SinkError as *mut c_void,
                set: sink_error_set,
            };
            // SAFETY: the calling contract: params, context, `out` and the error sink live
            // across the call; the object made is destroyed through its own table once.
            let status = unsafe {
                let s = shim::texture_create::<Hungry>(abi::Str::EMPTY, &ctx, &mut out, &err);
                if let Some(vt) = out.vtable.as_ref() {
                    (vt.destroy)(out.object);
                }
                s
            };
            (status, slot.0.map(|e| e.message))
        };
        assert_eq!(create(0), (abi::STATUS_OK, None));
        assert_eq!(create(1200), (abi::STATUS_OK, None));
        assert_eq!(
            create(1000),
            (
                abi::STATUS_ERROR,
                Some(
                    "the table needs 1.2 KiB, more than the memory budget left for this plugin \
                     (1000 bytes)"
                        .to_string()
                )
            )
        );
    }

    #[test]
    fn alloc_vec_keeps_to_the_budget_and_never_aborts() {
        let ctx = Context {
            memory_budget: 1000,
            ..Context::default()
        };
        assert_eq!(ctx.alloc_vec(250, 7u32, "four").unwrap(), vec![7u32; 250]);
        let e = ctx.alloc_vec(251, 0u32, "a row of 251 voxels").unwrap_err();
        assert_eq!(
            e.message,
            "a row of 251 voxels needs 1004 bytes, more than the memory budget left for this \
             plugin (1000 bytes)"
        );
        // No budget: only what the system refuses is an error (here: more than it can address).
        let e = Context::default()
            .alloc_vec(1usize << 60, 0u8, "everything")
            .unwrap_err();
        assert_eq!(
            e.message,
            "everything needs 1048576 TiB, which the system cannot allocate"
        );
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
    fn deep_nesting_is_explained_without_rons_options() {
        let text = format!("(v: {}1{})", "[".repeat(200), "]".repeat(200));
        let e = parse_params::<ron::Value>(&text).unwrap_err();
        assert_eq!(
            e.message,
            "values are nested more than 128 levels deep; expected at most 128 levels of brackets"
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
    fn distance_counts_edits() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("fov", "fov"), 0);
        assert_eq!(edit_distance("fvo", "fov"), 2);
    }

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(suggest("sphre", ["sphere", "plane"]), Some("sphere"));
        assert_eq!(suggest("xyzzy", ["sphere", "plane"]), None);
        assert_eq!(suggest("Pont", ["Point", "Directional"]), Some("Point"));
        assert_eq!(suggest("radus", ["center", "radius"]), Some("radius"));
        assert_eq!(suggest("glas", ["red", "glass", "floor"]), Some("glass"));
        assert_eq!(suggest("zzzzzz", ["red", "glass"]), None);
        assert_eq!(suggest("x", ["up"]), None);
        // Long words tolerate more edits: 12 / 3 = 4.
        assert_eq!(
            suggest("declmpositio", ["decomposition"]),
            Some("decomposition")
        );
        // The first of equally close candidates.
        assert_eq!(suggest("cat", ["bat", "cut"]), Some("bat"));
    }
}
