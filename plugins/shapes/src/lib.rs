//! # luxon-shapes: the geometric primitives
//!
//! Turns scene parameters into geometry: native primitives the core stores and intersects
//! itself (spheres, infinite planes, triangle meshes, cones and discs) and custom geometry this
//! plugin intersects. Entries:
//!
//! | entry      | makes                                          |
//! |------------|------------------------------------------------|
//! | `sphere`   | one sphere                                     |
//! | `spheres`  | many spheres in one object (molecules, points) |
//! | `plane`    | one infinite plane                             |
//! | `triangle` | one triangle                                   |
//! | `mesh`     | an inline triangle mesh                        |
//! | `cylinder` | a finite cylinder, capped or open              |
//! | `cone`     | a cone or truncated cone (NFF's `c`)           |
//! | `ring`     | a flat ring or disc                            |
//! | `polycylinder` | cylinders with sphere joints (bonds, tubes) |
//! | `box`      | an axis-aligned box                            |
//! | `infinite_cylinder` | a cylinder around a line (Tachyon's `cylinder`) |
//! | `quadric`  | a second-order surface clipped to a box        |
//! | `heightfield` | a terrain from a grid of heights            |
//!
//! The last four are custom geometry: the host keeps their bounds in its BVH and the plugin
//! intersects them in `f64`.
//!
//! One file per family: `spheres.rs`, `planes.rs`, `triangles.rs` (`triangle`, `mesh`) and
//! `cones.rs` (`cylinder`, `cone`, `ring`, `polycylinder`) build native primitives; `custom/`
//! holds the four custom shapes, one file each, and their property tests (`custom/props.rs`).
//! A new primitive is a `Describe` + `Primitive` pair in its family's file (or a new one), its
//! section below and its name in `export!`.
//!
//! Vectors are RON tuples: `(x, y, z)`. Every number must be finite. Indices in error messages
//! (triangle numbers, `normals[4]`, ...) start at 0, like the `indices` of a mesh.
//!
//! ## `sphere`
//! ```text
//! center: (x, y, z)  centre of the sphere
//! radius: f64 > 0  radius
//! ```
//!
//! ## `spheres`
//! ```text
//! centers: [(x, y, z), ...]  sphere centres, at least one
//! radius: f64 > 0 = none  radius shared by every sphere (give this or `radii`)
//! radii: [f64 > 0, ...] = none  one radius per centre (give this or `radius`)
//! ```
//!
//! ## `plane`
//! ```text
//! point: (x, y, z) = (0, 0, 0)  a point on the plane
//! normal: (x, y, z)  plane normal, any non-zero length
//! ```
//!
//! ## `triangle`
//! ```text
//! vertices: ((x, y, z), (x, y, z), (x, y, z))  corners, not collinear
//! normals: ((x, y, z), (x, y, z), (x, y, z)) = none  shading normal per corner, non-zero
//! colors: ((r, g, b), (r, g, b), (r, g, b)) = none  linear RGB per corner, >= 0
//! ```
//!
//! ## `mesh`
//! ```text
//! positions: [(x, y, z), ...]  vertex positions
//! indices: [(i, j, k), ...]  triangles as 0-based vertex indices
//! normals: [(x, y, z), ...] = none  one shading normal per vertex, non-zero
//! colors: [(r, g, b), ...] = none  one linear RGB colour per vertex, >= 0
//! uvs: [(u, v), ...] = none  one texture coordinate per vertex
//! ```
//! Triangles of zero area (repeated or collinear corners) are dropped with a warning; a mesh
//! left with no triangle is an error.
//!
//! ## `cylinder`
//! ```text
//! base: (x, y, z)  centre of one end
//! apex: (x, y, z)  centre of the other end
//! radius: f64 > 0  radius
//! caps: bool = true  close both ends with discs
//! ```
//!
//! ## `cone`
//! ```text
//! base: (x, y, z)  centre of the base
//! base_radius: f64 >= 0  radius at the base
//! apex: (x, y, z)  centre of the apex end
//! apex_radius: f64 >= 0 = 0  radius at the apex (0: pointed)
//! caps: bool = true  close the ends that have a radius with discs
//! ```
//!
//! ## `ring`
//! ```text
//! center: (x, y, z)  centre
//! normal: (x, y, z)  normal, any non-zero length
//! inner: f64 >= 0 = 0  radius of the hole
//! outer: f64 > inner  outer radius
//! ```
//!
//! ## `polycylinder`
//! ```text
//! points: [(x, y, z), ...]  at least two points along the chain
//! radius: f64 > 0  radius of the tube
//! ```
//!
//! ## `box`
//! ```text
//! min: (x, y, z)  lowest corner
//! max: (x, y, z)  highest corner, > min on every axis
//! ```
//! The normal is that of the face hit, outward; a ray starting inside hits the far face. Rays
//! parallel to faces are handled without division by zero. A ray lying exactly in a face plane
//! (or along an edge) counts as touching the closed box: it hits where it enters through a
//! perpendicular face, and a ray grazing an edge or corner hits there.
//! ```text
//! (plugin: "box", params: (min: (-1, 0, -1), max: (1, 2, 1)), material: "crate"),
//! ```
//!
//! ## `infinite_cylinder`
//! ```text
//! center: (x, y, z)  a point on the axis
//! axis: (x, y, z)  axis direction, any non-zero length
//! radius: f64 > 0  radius
//! extent: f64 > 0 = 1e6  half-length kept on each side of `center` (the bounds need an end)
//! ```
//! The host's BVH needs finite bounds, so the cylinder ends `extent` from `center` along the
//! axis on both sides (open ends; hits beyond are discarded). The default looks infinite in any
//! scene of ordinary size; give the real reach of the scene for a tighter box. A ray parallel to
//! the axis never hits it; a tangent ray touches it once. `uv`: angle around the axis over 2π,
//! and the position along the axis from -extent (0) to +extent (1).
//! ```text
//! (plugin: "infinite_cylinder", params: (center: (0, 0, 0), axis: (0, 1, 0), radius: 0.2, extent: 50)),
//! ```
//!
//! ## `quadric`
//! ```text
//! coefficients: (a, b, c, d, e, f, g, h, i, j)  a x² + b y² + c z² + d xy + e xz + f yz + g x + h y + i z + j = 0
//! min: (x, y, z)  lowest corner of the clipping box
//! max: (x, y, z)  highest corner, > min on every axis
//! ```
//! Only the part of the surface inside the (closed) box exists: of the two roots along a ray the
//! nearer one inside the box wins, so a clipped surface is open and seen from both sides. The
//! normal is the gradient (at a singular point such as a cone's apex it faces the ray). At least
//! one of `a` to `i` must be non-zero.
//! ```text
//! // a unit sphere, and a paraboloid bowl y = x² + z² cut at y = 1
//! (plugin: "quadric", params: (coefficients: (1, 1, 1, 0, 0, 0, 0, 0, 0, -1), min: (-1, -1, -1), max: (1, 1, 1))),
//! (plugin: "quadric", params: (coefficients: (1, 0, 1, 0, 0, 0, 0, -1, 0, 0), min: (-1, 0, -1), max: (1, 1, 1))),
//! ```
//!
//! ## `heightfield`
//! ```text
//! origin: (x, z) = (0, 0)  grid corner of row 0, column 0
//! size: (width, depth)  extent along x and z, both > 0
//! heights: [[f64, ...], ...]  rows along z of heights along x, at least 2 x 2 (or a flat list)
//! columns: u64 = none  heights per row, only with a flat `heights` list
//! ```
//! y is up. `heights[row][column]` sits at `x = origin.0 + width * column / (columns - 1)`,
//! `z = origin.1 + depth * row / (rows - 1)`. Each cell is two flat triangles split along the
//! diagonal from (column, row) to (column + 1, row + 1); normals are per triangle and point up.
//! The grid is one primitive: a ray walks only the cells it crosses (2-D DDA). A ray lying in the
//! plane of a flat cell does not hit that cell. `uv` is the position over the grid, 0 to 1.
//! ```text
//! (plugin: "heightfield", params: (origin: (-5, -5), size: (10, 10), heights: [[0, 0.2, 0], [0.1, 1.5, 0.3], [0, 0.4, 0]]), material: "grass"),
//! (plugin: "heightfield", params: (size: (4, 2), heights: [0, 1, 1, 0, 0, 2, 2, 0], columns: 4)),
//! ```
//!
//! ## Scene snippet
//! ```text
//! objects: [
//!     (plugin: "sphere", params: (center: (0, 1, 0), radius: 1), material: "red"),
//!     (plugin: "spheres", params: (centers: [(0, 0, 0), (1.2, 0, 0)], radii: [0.7, 0.5])),
//!     (plugin: "plane", params: (normal: (0, 1, 0)), material: "floor"),
//!     (plugin: "triangle", params: (vertices: ((0, 0, 0), (1, 0, 0), (0, 1, 0)))),
//!     (plugin: "mesh", params: (
//!         positions: [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
//!         indices: [(0, 1, 2), (0, 2, 3)],
//!         uvs: [(0, 0), (1, 0), (1, 1), (0, 1)],
//!     )),
//! ]
//! ```

#![forbid(unsafe_code)]

mod cones;
mod custom;
mod params;
mod planes;
mod spheres;
#[cfg(test)]
mod testing;
mod triangles;
mod vector;

pub use cones::{Cone, Cylinder, Polycylinder, Ring};
pub use custom::{BoxEntry, Heightfield, InfiniteCylinder, Quadric};
pub use planes::Plane;
pub use spheres::{Sphere, Spheres};
pub use triangles::{MeshEntry, Triangle};

/// The library name in messages sent through the host's log.
const LIBRARY: &str = "luxon-shapes";

luxon_plugin::export!(
    library: "luxon-shapes",
    primitives: [
        Sphere, Spheres, Plane, Triangle, MeshEntry, Cylinder, Cone, Ring, Polycylinder,
        BoxEntry, InfiniteCylinder, Quadric, Heightfield,
    ],
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spheres::SphereParams;
    use crate::testing::assert_contains;
    use crate::triangles::MeshParams;
    use luxon_plugin::{parse_params, Describe};

    #[test]
    fn unknown_parameter_is_rejected_with_suggestion() {
        let e = parse_params::<SphereParams>("(center: (0, 0, 0), radus: 1)").unwrap_err();
        assert_contains(&e.message, "did you mean `radius`");
        let e = parse_params::<MeshParams>("(positions: [], indices: [], normal: [])").unwrap_err();
        assert_contains(&e.message, "did you mean `normals`");
    }

    /// The crate doc must show every entry's table exactly as `luxon plugins` prints it.
    #[test]
    fn crate_doc_lists_every_param_table() {
        let doc: String = include_str!("lib.rs")
            .lines()
            .filter_map(|l| l.strip_prefix("//! "))
            .collect::<Vec<_>>()
            .join("\n");
        for (name, table) in [
            (Sphere::NAME, Sphere::PARAMS),
            (Spheres::NAME, Spheres::PARAMS),
            (Plane::NAME, Plane::PARAMS),
            (Triangle::NAME, Triangle::PARAMS),
            (MeshEntry::NAME, MeshEntry::PARAMS),
            (Cylinder::NAME, Cylinder::PARAMS),
            (Cone::NAME, Cone::PARAMS),
            (Ring::NAME, Ring::PARAMS),
            (Polycylinder::NAME, Polycylinder::PARAMS),
            (BoxEntry::NAME, BoxEntry::PARAMS),
            (InfiniteCylinder::NAME, InfiniteCylinder::PARAMS),
            (Quadric::NAME, Quadric::PARAMS),
            (Heightfield::NAME, Heightfield::PARAMS),
        ] {
            let section = format!("## `{name}`\n```text\n{table}\n```");
            assert!(
                doc.contains(&section),
                "crate doc lacks the table of `{name}`:\n{section}"
            );
        }
    }
}
