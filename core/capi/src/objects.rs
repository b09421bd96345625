//! Array objects and volumes of a scene, made from `luxon_array`s: spheres, cylinders, triangle
//! meshes (read in place at every commit and render) and volumes (copied into bricks when
//! committed).

use crate::arrays::{optional, required};
use crate::guard::guard;
use crate::handles::{luxon_array, luxon_object, luxon_scene};
use crate::scene::{part_handle, part_of, put_optional, with_scene, PartId, SceneState};
use crate::status::{luxon_status, Failure};
use crate::text::{optional_text, put, read_sized, Versioned};
use luxon_core::api::{Cylinders, MaterialId, Mesh, ObjectId, Radius, Spheres, VolumeGrid};
use std::ffi::c_char;
use std::mem::size_of;

/// Spheres read from arrays (`luxon_spheres_init` fills in the defaults).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct luxon_spheres {
    /// `sizeof(luxon_spheres)`.
    pub size: u32,
    /// Centres (LUXON_FLOAT32_VEC3 or LUXON_FLOAT64_VEC3), world coordinates.
    pub centers: luxon_array,
    /// One radius per centre (LUXON_FLOAT32 or LUXON_FLOAT64); `{0}`: `radius` for all.
    pub radii: luxon_array,
    pub radius: f64,
    /// Linear RGB per sphere (FLOAT32_VEC3 or FLOAT64_VEC3, replacing the material's colour);
    /// `{0}`: none.
    pub colors: luxon_array,
    /// The material's name; NULL: `default`.
    pub material: *const c_char,
}

/// Cylinders read from arrays (`luxon_cylinders_init` fills in the defaults).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct luxon_cylinders {
    /// `sizeof(luxon_cylinders)`.
    pub size: u32,
    /// Base and apex centres (FLOAT32_VEC3 or FLOAT64_VEC3), world coordinates.
    pub bases: luxon_array,
    pub apexes: luxon_array,
    /// One radius per cylinder (FLOAT32 or FLOAT64); `{0}`: `radius` for all.
    pub radii: luxon_array,
    pub radius: f64,
    /// Non-zero: closed by discs at both ends (default 1).
    pub caps: u32,
    /// The material's name; NULL: `default`.
    pub material: *const c_char,
}

/// A triangle mesh read from arrays (`luxon_mesh_init` fills in the defaults).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct luxon_mesh {
    /// `sizeof(luxon_mesh)`.
    pub size: u32,
    /// Vertex positions (FLOAT32_VEC3 or FLOAT64_VEC3), world coordinates.
    pub positions: luxon_array,
    /// Triangles' vertex indices (UINT32_VEC3 or UINT64_VEC3); `{0}`: every three positions
    /// make a triangle.
    pub indices: luxon_array,
    /// Per vertex, each optional (`{0}`): normals (FLOAT32_VEC3 or FLOAT64_VEC3), linear RGB
    /// colours (FLOAT32_VEC3 or FLOAT64_VEC3), texture coordinates (FLOAT32_VEC2).
    pub normals: luxon_array,
    pub colors: luxon_array,
    pub uvs: luxon_array,
    /// The material's name; NULL: `default`.
    pub material: *const c_char,
}

/// A volume from an array of scalars (`luxon_volume_init` fills in the defaults). Voxel
/// `(i, j, k)` is element `first + i*strides[0] + j*strides[1] + k*strides[2]` of `values` and
/// lies at world position `origin + (i*spacing[0], j*spacing[1], k*spacing[2])`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct luxon_volume {
    /// `sizeof(luxon_volume)`.
    pub size: u32,
    /// The voxels: LUXON_FLOAT32, LUXON_FLOAT64, LUXON_UINT8 or LUXON_UINT16.
    pub values: luxon_array,
    /// Voxels along x, y and z (each ≥ 1).
    pub dims: [u64; 3],
    /// In elements (negative: an axis runs backwards); all 0: x fastest, packed (a Fortran
    /// array `v(nx, ny, nz)`, a C array `v[nz][ny][nx]`).
    pub strides: [i64; 3],
    /// The element of voxel (0, 0, 0) (a view into a larger array, e.g. without halo cells).
    pub first: u64,
    pub origin: [f64; 3],
    /// Each finite and non-zero (default 1).
    pub spacing: [f64; 3],
    /// Non-zero (the default): integer voxels are divided by 255 (u8) or 65535 (u16).
    pub normalize: u32,
    /// The volume's name in messages; NULL: the object's.
    pub name: *const c_char,
    /// How it is drawn, as RON text (what follows `render:` in a scene file's volume, e.g.
    /// `(transfer: (preset: "viridis"))`); NULL: not drawn.
    pub render_ron: *const c_char,
}

impl Default for luxon_spheres {
    fn default() -> Self {
        luxon_spheres {
            size: size_of::<luxon_spheres>() as u32,
            centers: luxon_array::default(),
            radii: luxon_array::default(),
            radius: 1.0,
            colors: luxon_array::default(),
            material: std::ptr::null(),
        }
    }
}

impl Default for luxon_cylinders {
    fn default() -> Self {
        luxon_cylinders {
            size: size_of::<luxon_cylinders>() as u32,
            bases: luxon_array::default(),
            apexes: luxon_array::default(),
            radii: luxon_array::default(),
            radius: 1.0,
            caps: 1,
            material: std::ptr::null(),
        }
    }
}

impl Default for luxon_mesh {
    fn default() -> Self {
        luxon_mesh {
            size: size_of::<luxon_mesh>() as u32,
            positions: luxon_array::default(),
            indices: luxon_array::default(),
            normals: luxon_array::default(),
            colors: luxon_array::default(),
            uvs: luxon_array::default(),
            material: std::ptr::null(),
        }
    }
}

impl Default for luxon_volume {
    fn default() -> Self {
        luxon_volume {
            size: size_of::<luxon_volume>() as u32,
            values: luxon_array::default(),
            dims: [0; 3],
            strides: [0; 3],
            first: 0,
            origin: [0.0; 3],
            spacing: [1.0; 3],
            normalize: 1,
            name: std::ptr::null(),
            render_ron: std::ptr::null(),
        }
    }
}

impl Versioned for luxon_spheres {}
impl Versioned for luxon_cylinders {}
impl Versioned for luxon_mesh {}
impl Versioned for luxon_volume {}

/// Fills `spheres` with the defaults (and its `size`): no arrays, radius 1.
///
/// # Safety
/// `spheres` is valid for a write of a `luxon_spheres`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_spheres_init(spheres: *mut luxon_spheres) -> luxon_status {
    // SAFETY: writable (caller).
    guard("luxon_spheres_init", || unsafe {
        put(spheres, "spheres", luxon_spheres::default())
    })
}

/// Fills `cylinders` with the defaults (and its `size`): no arrays, radius 1, capped.
///
/// # Safety
/// `cylinders` is valid for a write of a `luxon_cylinders`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_cylinders_init(cylinders: *mut luxon_cylinders) -> luxon_status {
    // SAFETY: writable (caller).
    guard("luxon_cylinders_init", || unsafe {
        put(cylinders, "cylinders", luxon_cylinders::default())
    })
}

/// Fills `mesh` with the defaults (and its `size`): no arrays.
///
/// # Safety
/// `mesh` is valid for a write of a `luxon_mesh`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_mesh_init(mesh: *mut luxon_mesh) -> luxon_status {
    // SAFETY: writable (caller).
    guard("luxon_mesh_init", || unsafe {
        put(mesh, "mesh", luxon_mesh::default())
    })
}

/// Fills `volume` with the defaults (and its `size`): no array, x fastest, at the origin,
/// spacing 1, normalized, unnamed, not drawn.
///
/// # Safety
/// `volume` is valid for a write of a `luxon_volume`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_volume_init(volume: *mut luxon_volume) -> luxon_status {
    // SAFETY: writable (caller).
    guard("luxon_volume_init", || unsafe {
        put(volume, "volume", luxon_volume::default())
    })
}

/// The material named `name` (NULL: the default one).
///
/// # Safety
/// `name` is NULL or a valid string.
unsafe fn material(s: &SceneState, name: *const c_char) -> Result<Option<MaterialId>, Failure> {
    // SAFETY: the caller's promise.
    match unsafe { optional_text(name, "material") }? {
        None => Ok(None),
        Some(m) => s
            .scene
            .material(m)
            .map(Some)
            .ok_or_else(|| Failure::invalid(format!("the scene has no material named `{m}`"))),
    }
}

fn radius(radii: luxon_array, radius: f64, what: &str) -> Result<Radius, Failure> {
    Ok(match optional(radii, what)? {
        Some(a) => Radius::Each(a),
        None => Radius::Const(radius),
    })
}

/// # Safety
/// `d` is a valid `luxon_spheres` (its strings valid).
unsafe fn spheres(s: &SceneState, d: *const luxon_spheres) -> Result<Spheres, Failure> {
    // SAFETY: the caller's promise.
    let d = unsafe { read_sized(d, "spheres", size_of::<luxon_spheres>()) }?;
    Ok(Spheres {
        centers: required(d.centers, "centers")?,
        radius: radius(d.radii, d.radius, "radii")?,
        colors: optional(d.colors, "colors")?,
        // SAFETY: NULL or a valid string (caller).
        material: unsafe { material(s, d.material) }?,
    })
}

/// # Safety
/// `d` is a valid `luxon_cylinders` (its strings valid).
unsafe fn cylinders(s: &SceneState, d: *const luxon_cylinders) -> Result<Cylinders, Failure> {
    // SAFETY: the caller's promise.
    let d = unsafe { read_sized(d, "cylinders", size_of::<luxon_cylinders>()) }?;
    Ok(Cylinders {
        bases: required(d.bases, "bases")?,
        apexes: required(d.apexes, "apexes")?,
        radius: radius(d.radii, d.radius, "radii")?,
        caps: d.caps != 0,
        // SAFETY: NULL or a valid string (caller).
        material: unsafe { material(s, d.material) }?,
    })
}

/// # Safety
/// `d` is a valid `luxon_mesh` (its strings valid).
unsafe fn mesh(s: &SceneState, d: *const luxon_mesh) -> Result<Mesh, Failure> {
    // SAFETY: the caller's promise.
    let d = unsafe { read_sized(d, "mesh", size_of::<luxon_mesh>()) }?;
    Ok(Mesh {
        positions: required(d.positions, "positions")?,
        indices: optional(d.indices, "indices")?,
        normals: optional(d.normals, "normals")?,
        colors: optional(d.colors, "colors")?,
        uvs: optional(d.uvs, "uvs")?,
        // SAFETY: NULL or a valid string (caller).
        material: unsafe { material(s, d.material) }?,
    })
}

/// A grid and its look's RON text.
///
/// # Safety
/// `d` is a valid `luxon_volume` (its strings valid for `'a`).
unsafe fn volume<'a>(d: *const luxon_volume) -> Result<(VolumeGrid, Option<&'a str>), Failure> {
    // SAFETY: the caller's promise.
    let d = unsafe { read_sized(d, "volume", size_of::<luxon_volume>()) }?;
    // SAFETY: NULL or valid strings (caller).
    let (name, look) = unsafe {
        (
            optional_text(d.name, "name")?,
            optional_text(d.render_ron, "render_ron")?,
        )
    };
    let grid = VolumeGrid {
        values: required(d.values, "values")?,
        dims: d.dims,
        strides: (d.strides != [0; 3]).then_some(d.strides),
        first: d.first,
        origin: d.origin,
        spacing: d.spacing,
        normalize: d.normalize != 0,
        name: name.unwrap_or("").to_string(),
    };
    Ok((grid, look))
}

/// The array object or volume `object` names in `scene`.
fn object_of(object: luxon_object, scene: luxon_scene) -> Result<ObjectId, Failure> {
    match part_of(object, scene.id)? {
        PartId::Object(o) => Ok(o),
        PartId::Light(_) => Err(Failure::invalid(format!(
            "luxon_object {:#x} is a light, not an object",
            object.id
        ))),
    }
}

/// Adds `made`'s object to `scene` and writes its handle to `out` (NULL: not written).
///
/// # Safety
/// `out` is NULL or valid for a write.
unsafe fn add(
    scene: luxon_scene,
    out: *mut luxon_object,
    made: impl FnOnce(&mut SceneState) -> Result<ObjectId, Failure>,
) -> Result<(), Failure> {
    if !out.is_null() {
        // SAFETY: writable (caller); cleared first so a failure leaves {0}.
        unsafe { out.write(luxon_object::default()) };
    }
    let object = with_scene(scene, |s, _| {
        let id = made(s)?;
        part_handle(s, scene.id, PartId::Object(id))
    })?;
    // SAFETY: NULL or writable (caller).
    unsafe { put_optional(out, object) }
}

/// Adds spheres read from arrays (see `luxon_array_create_shared` for who owns the memory and
/// how long Luxon reads it). Element types are checked now; values (NaN, radius ≤ 0) at every
/// commit that reads them, naming the object and the sphere. After the arrays were marked
/// modified the next commit refits the object's BVH (builds it again when the count changed).
///
/// # Safety
/// `spheres` is a valid `luxon_spheres` (its `material` NULL or a valid string); `out` is NULL
/// or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_add_spheres(
    scene: luxon_scene,
    spheres: *const luxon_spheres,
    out: *mut luxon_object,
) -> luxon_status {
    guard("luxon_scene_add_spheres", || {
        // SAFETY: valid struct and out-pointer (caller).
        unsafe {
            add(scene, out, |s| {
                let d = self::spheres(s, spheres)?;
                Ok(s.scene.add_spheres(d)?)
            })
        }
    })
}

/// Gives the spheres `object` (from `luxon_scene_add_spheres`) new arrays: its BVH is built
/// again at the next commit; arrays it no longer uses are let go.
///
/// # Safety
/// As `luxon_scene_add_spheres`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_spheres(
    scene: luxon_scene,
    object: luxon_object,
    spheres: *const luxon_spheres,
) -> luxon_status {
    guard("luxon_scene_set_spheres", || {
        let id = object_of(object, scene)?;
        with_scene(scene, |s, _| {
            // SAFETY: a valid struct (caller).
            let d = unsafe { self::spheres(s, spheres) }?;
            Ok(s.scene.set_spheres(id, d)?)
        })
    })
}

/// Adds cylinders read from arrays (ownership: `luxon_array_create_shared`). Checked as
/// `luxon_scene_add_spheres` (a base at its apex is refused at commit).
///
/// # Safety
/// `cylinders` is a valid `luxon_cylinders` (its `material` NULL or a valid string); `out` is
/// NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_add_cylinders(
    scene: luxon_scene,
    cylinders: *const luxon_cylinders,
    out: *mut luxon_object,
) -> luxon_status {
    guard("luxon_scene_add_cylinders", || {
        // SAFETY: valid struct and out-pointer (caller).
        unsafe {
            add(scene, out, |s| {
                let d = self::cylinders(s, cylinders)?;
                Ok(s.scene.add_cylinders(d)?)
            })
        }
    })
}

/// Gives the cylinders `object` new arrays (as `luxon_scene_set_spheres`).
///
/// # Safety
/// As `luxon_scene_add_cylinders`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_cylinders(
    scene: luxon_scene,
    object: luxon_object,
    cylinders: *const luxon_cylinders,
) -> luxon_status {
    guard("luxon_scene_set_cylinders", || {
        let id = object_of(object, scene)?;
        with_scene(scene, |s, _| {
            // SAFETY: a valid struct (caller).
            let d = unsafe { self::cylinders(s, cylinders) }?;
            Ok(s.scene.set_cylinders(id, d)?)
        })
    })
}

/// Adds a triangle mesh read from arrays (ownership: `luxon_array_create_shared`). Element
/// types are checked now; at every commit that reads them, an index past the vertices or a
/// non-finite coordinate is refused, naming the object, the triangle and the vertex. Moved
/// vertices (marked modified) are refitted; changed indices build the object's BVH again.
///
/// # Safety
/// `mesh` is a valid `luxon_mesh` (its `material` NULL or a valid string); `out` is NULL or
/// valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_add_mesh(
    scene: luxon_scene,
    mesh: *const luxon_mesh,
    out: *mut luxon_object,
) -> luxon_status {
    guard("luxon_scene_add_mesh", || {
        // SAFETY: valid struct and out-pointer (caller).
        unsafe {
            add(scene, out, |s| {
                let d = self::mesh(s, mesh)?;
                Ok(s.scene.add_mesh(d)?)
            })
        }
    })
}

/// Gives the mesh `object` new arrays (as `luxon_scene_set_spheres`).
///
/// # Safety
/// As `luxon_scene_add_mesh`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_mesh(
    scene: luxon_scene,
    object: luxon_object,
    mesh: *const luxon_mesh,
) -> luxon_status {
    guard("luxon_scene_set_mesh", || {
        let id = object_of(object, scene)?;
        with_scene(scene, |s, _| {
            // SAFETY: a valid struct (caller).
            let d = unsafe { self::mesh(s, mesh) }?;
            Ok(s.scene.set_mesh(id, d)?)
        })
    })
}

/// Adds a volume from an array of scalars, drawn as `render_ron` says. The layout is checked
/// now (every voxel's element inside the array); the values are copied into Luxon's bricks at
/// the next commit (a NaN or infinite voxel is refused then, naming it) and again at each
/// commit after the array was marked modified (`luxon_commit_report.volumes_read`). The array
/// is read only during those commits: it may be written between them.
///
/// # Safety
/// `volume` is a valid `luxon_volume` (its strings NULL or valid); `out` is NULL or valid for
/// a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_add_volume(
    scene: luxon_scene,
    volume: *const luxon_volume,
    out: *mut luxon_object,
) -> luxon_status {
    guard("luxon_scene_add_volume", || {
        // SAFETY: a valid struct (caller).
        let (grid, look) = unsafe { self::volume(volume) }?;
        // SAFETY: NULL or writable (caller).
        unsafe {
            add(scene, out, |s| {
                Ok(match look {
                    Some(text) => s.scene.add_volume_ron(grid, text)?,
                    None => s.scene.add_volume(grid, None)?,
                })
            })
        }
    })
}

/// Gives the volume `object` a new grid and look: read again at the next commit.
///
/// # Safety
/// As `luxon_scene_add_volume`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_volume(
    scene: luxon_scene,
    object: luxon_object,
    volume: *const luxon_volume,
) -> luxon_status {
    guard("luxon_scene_set_volume", || {
        let id = object_of(object, scene)?;
        // SAFETY: a valid struct (caller).
        let (grid, look) = unsafe { self::volume(volume) }?;
        with_scene(scene, |s, _| {
            match look {
                Some(text) => s.scene.set_volume_ron(id, grid, text)?,
                None => s.scene.set_volume(id, grid, None)?,
            }
            Ok(())
        })
    })
}
