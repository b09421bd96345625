//! The array objects a retained scene reads from the caller's arrays ([`crate::arrays`]):
//! [`Spheres`] for now, each checked for its arrays' element types when added and for its
//! elements' values at every commit that reads them.

use super::ids::MaterialId;
use crate::arrays::{Array, Elem};
use crate::error::Error;

/// The radius of every sphere, or one per sphere.
#[derive(Clone, Debug)]
pub enum Radius {
    Const(f64),
    /// f32 or f64, one per centre.
    Each(Array),
}

/// Spheres read in place: centres (f32x3 or f64x3, world coordinates), radii, optional linear
/// RGB colours (f32x3 or f64x3, ≥ 0; they replace the material's colour), of `material` (`None`:
/// the default one). Added by [`super::Scene::add_spheres`].
#[derive(Clone, Debug)]
pub struct Spheres {
    pub centers: Array,
    pub radius: Radius,
    pub colors: Option<Array>,
    pub material: Option<MaterialId>,
}

impl Spheres {
    /// Spheres of the default material, without colours.
    pub fn new(centers: Array, radius: Radius) -> Spheres {
        Spheres {
            centers,
            radius,
            colors: None,
            material: None,
        }
    }
}

/// Cylinders read in place: base and apex centres (f32x3 or f64x3, world coordinates), radii,
/// closed at both ends by discs when `caps` (as the `cylinder` plugin makes them), of
/// `material` (`None`: the default one). Added by [`super::Scene::add_cylinders`].
#[derive(Clone, Debug)]
pub struct Cylinders {
    pub bases: Array,
    pub apexes: Array,
    pub radius: Radius,
    pub caps: bool,
    pub material: Option<MaterialId>,
}

impl Cylinders {
    /// Capped cylinders of the default material.
    pub fn new(bases: Array, apexes: Array, radius: Radius) -> Cylinders {
        Cylinders {
            bases,
            apexes,
            radius,
            caps: true,
            material: None,
        }
    }
}

/// A triangle mesh read in place: vertex positions (f32x3 or f64x3, world coordinates),
/// triangles as vertex index triples (u32x3 or u64x3; `None`: every three positions make
/// one), and optional per-vertex normals (f32x3 or f64x3, any non-zero length), linear RGB
/// colours (f32x3 or f64x3; they replace the material's colour) and texture coordinates
/// (f32x2), of `material` (`None`: the default one). Added by [`super::Scene::add_mesh`].
/// Triangles of zero area are kept (and never hit): a triangle keeps its number whatever its
/// vertices do.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub positions: Array,
    pub indices: Option<Array>,
    pub normals: Option<Array>,
    pub colors: Option<Array>,
    pub uvs: Option<Array>,
    pub material: Option<MaterialId>,
}

impl Mesh {
    /// A mesh of the default material, without vertex attributes.
    pub fn new(positions: Array, indices: Option<Array>) -> Mesh {
        Mesh {
            positions,
            indices,
            normals: None,
            colors: None,
            uvs: None,
            material: None,
        }
    }
}

/// Refuses an array whose elements are not of one of the types `allowed`.
pub(super) fn expect_elem(what: &str, a: &Array, allowed: &[Elem]) -> Result<(), Error> {
    if allowed.contains(&a.elem()) {
        return Ok(());
    }
    let names: Vec<&str> = allowed.iter().map(|e| e.name()).collect();
    Err(Error::Api(format!(
        "{what}: an array of {} elements; expected {}",
        a.elem(),
        names.join(" or ")
    )))
}

/// Vectors of three numbers (positions, colours).
pub(super) const VEC3: &[Elem] = &[Elem::F32x3, Elem::F64x3];
/// Triangles' vertex indices.
pub(super) const INDEX3: &[Elem] = &[Elem::U32x3, Elem::U64x3];
/// Texture coordinates.
pub(super) const UV: &[Elem] = &[Elem::F32x2];
/// Real numbers (radii).
pub(super) const REAL: &[Elem] = &[Elem::F32, Elem::F64];

/// A scalar grid read from an array (f32, f64, u8 or u16), copied into Luxon's bricks at every
/// commit that finds it changed (a volume is never read in place: sampling and empty-space
/// skipping need bricks). Voxel `(i, j, k)` is element `first + i·sx + j·sy + k·sz` of `values`
/// (`strides` `[sx, sy, sz]` in elements; `None`: x fastest, packed, as a Fortran array
/// `v(nx, ny, nz)` or a C array `v[nz][ny][nx]`; negative strides run an axis backwards) and
/// lies at world position `origin + (i·spacing.x, j·spacing.y, k·spacing.z)`, as the `raw`
/// volume reader places its voxels. Integer voxels are divided by 255 (u8) or 65535 (u16)
/// when `normalize`, as `raw` does by default. Added by [`super::Scene::add_volume`].
#[derive(Clone, Debug)]
pub struct VolumeGrid {
    pub values: Array,
    /// Voxels along x, y and z (each ≥ 1).
    pub dims: [u64; 3],
    pub strides: Option<[i64; 3]>,
    /// The element of voxel (0, 0, 0) (a view into a larger array starts past 0).
    pub first: u64,
    pub origin: [f64; 3],
    /// Each finite and non-zero (a negative one mirrors its axis).
    pub spacing: [f64; 3],
    pub normalize: bool,
    /// The scene's name for the volume (its messages use it); empty: the object's id.
    pub name: String,
}

impl VolumeGrid {
    /// A grid of `dims` voxels, x fastest, at the world origin with unit spacing.
    pub fn new(values: Array, dims: [u64; 3]) -> VolumeGrid {
        VolumeGrid {
            values,
            dims,
            strides: None,
            first: 0,
            origin: [0.0; 3],
            spacing: [1.0; 3],
            normalize: true,
            name: String::new(),
        }
    }
}

/// A grid's voxel values.
pub(super) const VOXEL: &[Elem] = &[Elem::F32, Elem::F64, Elem::U8, Elem::U16];
