//! Inline native geometry: what the NFF and OBJ importers (and a RON scene's `meshes:`) hand
//! the core directly. A million triangles must not round-trip through RON text to reach a
//! plugin, so an importer fills these arrays and the core stores them as it stores a primitive
//! plugin's output (same validation, same native types). World coordinates, f64.

use crate::origin::{Origin, Spanned};

/// A run of primitives sharing one material.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InlineGeometry {
    /// Material name; `None`: the built-in default material.
    pub material: Option<Spanned<String>>,
    /// Clip group name (the scene's `clip_groups`): the geometry is cut away on the far side of
    /// its planes; `None`: not clipped.
    pub clip: Option<Spanned<String>>,
    /// Where the geometry came from (first primitive), for messages.
    pub at: Option<Origin>,
    /// Casts no shadows: shadow and occlusion rays pass through it (a light's visible
    /// sphere).
    pub shadowless: bool,
    /// x, y, z, radius.
    pub spheres: Vec<[f64; 4]>,
    /// Open cones: base x, y, z, base radius, apex x, y, z, apex radius (equal radii: cylinder).
    pub cones: Vec<[f64; 8]>,
    /// Discs/rings: centre x, y, z, normal x, y, z, inner radius, outer radius.
    pub discs: Vec<[f64; 8]>,
    /// Infinite planes: point x, y, z, normal x, y, z.
    pub planes: Vec<[f64; 6]>,
    pub mesh: InlineMesh,
}

/// Triangles indexing shared vertices; `normals`, `uvs` and `colors` are empty or have one
/// entry per position.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InlineMesh {
    pub positions: Vec<[f64; 3]>,
    pub normals: Vec<[f64; 3]>,
    pub indices: Vec<[u64; 3]>,
    /// Texture coordinates (u, v).
    pub uvs: Vec<[f64; 2]>,
    /// Vertex colours (linear RGB, 0 or more): they multiply the material's colour, and are
    /// interpolated across each triangle.
    pub colors: Vec<[f64; 3]>,
}

impl InlineGeometry {
    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
            && self.cones.is_empty()
            && self.discs.is_empty()
            && self.planes.is_empty()
            && self.mesh.indices.is_empty()
    }

    /// Bytes its arrays hold (their capacities): what an import of it takes.
    pub fn bytes(&self) -> u64 {
        fn held<T>(v: &Vec<T>) -> u64 {
            (v.capacity() * std::mem::size_of::<T>()) as u64
        }
        let m = &self.mesh;
        held(&self.spheres)
            + held(&self.cones)
            + held(&self.discs)
            + held(&self.planes)
            + held(&m.positions)
            + held(&m.normals)
            + held(&m.indices)
            + held(&m.uvs)
            + held(&m.colors)
    }

    pub fn primitive_count(&self) -> usize {
        self.spheres.len()
            + self.cones.len()
            + self.discs.len()
            + self.planes.len()
            + self.mesh.indices.len()
    }
}
