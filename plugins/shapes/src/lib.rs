//! # luxon-shapes: the native primitives
//!
//! Turns scene parameters into the geometry the core stores and intersects itself (spheres,
//! infinite planes, triangle meshes). Entries:
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

pub(crate) use luxon_plugin::{
    finite, invalid, Context, Describe, Error, Geometry, Mesh, Primitive,
};
use serde::Deserialize;

const LIBRARY: &str = "luxon-shapes";

/// Lets an optional parameter be written as a plain value (`radius: 1`): without RON's
/// `implicit_some` extension an `Option` field would demand `Some(1)`.
fn plain_some<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    T::deserialize(d).map(Some)
}

// ------------------------------------------------------------------------------------------------
// Vector helpers
// ------------------------------------------------------------------------------------------------

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn length(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

pub(crate) fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn max_abs(a: [f64; 3]) -> f64 {
    a[0].abs().max(a[1].abs()).max(a[2].abs())
}

/// Unit vector, or `None` for a zero vector. Scales first so that tiny or huge (finite) inputs
/// neither underflow nor overflow.
fn normalize(v: [f64; 3]) -> Option<[f64; 3]> {
    let m = max_abs(v);
    if m == 0.0 || !m.is_finite() {
        return None;
    }
    let w = scale(v, 1.0 / m);
    Some(scale(w, 1.0 / length(w)))
}

/// True when the corners are repeated or collinear, judged by the sine of the angle at `a`
/// (relative, so the scene's units do not matter).
fn zero_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let (e1, e2) = (sub(b, a), sub(c, a));
    let m = max_abs(e1).max(max_abs(e2));
    if m == 0.0 {
        return true;
    }
    let (e1, e2) = (scale(e1, 1.0 / m), scale(e2, 1.0 / m));
    length(cross(e1, e2)) <= 1e-12 * length(e1) * length(e2)
}

pub(crate) fn positive(name: &str, x: f64) -> Result<f64, Error> {
    let [x] = finite(name, [x])?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(invalid(format!("parameter `{name}` must be > 0, got {x}")))
    }
}

/// A finite, non-negative colour, narrowed to what the host stores.
fn color(name: &str, c: [f64; 3]) -> Result<[f32; 3], Error> {
    let c = finite(name, c)?;
    if c.iter().any(|&x| x < 0.0) {
        return Err(invalid(format!(
            "parameter `{name}` must not be negative, got {c:?}"
        )));
    }
    let n = c.map(|x| x as f32);
    if n.iter().all(|x| x.is_finite()) {
        Ok(n)
    } else {
        Err(invalid(format!(
            "parameter `{name}` is too large, got {c:?}"
        )))
    }
}

fn uv(name: &str, v: [f64; 2]) -> Result<[f32; 2], Error> {
    let v = finite(name, v)?;
    let n = v.map(|x| x as f32);
    if n.iter().all(|x| x.is_finite()) {
        Ok(n)
    } else {
        Err(invalid(format!(
            "parameter `{name}` is too large, got {v:?}"
        )))
    }
}

/// A unit shading normal; `label` is how messages name it ("normal 4").
fn shading_normal(name: &str, label: &str, n: [f64; 3]) -> Result<[f64; 3], Error> {
    normalize(finite(name, n)?).ok_or_else(|| invalid(format!("{label} has zero length")))
}

// ------------------------------------------------------------------------------------------------
// sphere
// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct SphereParams {
    pub center: [f64; 3],
    pub radius: f64,
}

/// The sphere as the host takes it: `[x, y, z, radius]`.
pub fn sphere(p: &SphereParams) -> Result<[f64; 4], Error> {
    let [x, y, z] = finite("center", p.center)?;
    Ok([x, y, z, positive("radius", p.radius)?])
}

pub struct Sphere;

impl Describe for Sphere {
    const NAME: &'static str = "sphere";
    const DESCRIPTION: &'static str = "A sphere.";
    const PARAMS: &'static str = "center: (x, y, z)  centre of the sphere
radius: f64 > 0  radius";
}

impl Primitive for Sphere {
    type Params = SphereParams;
    fn create(p: SphereParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.spheres(&[sphere(&p)?])
    }
}

// ------------------------------------------------------------------------------------------------
// spheres
// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct SpheresParams {
    pub centers: Vec<[f64; 3]>,
    #[serde(default, deserialize_with = "plain_some")]
    pub radius: Option<f64>,
    #[serde(default, deserialize_with = "plain_some")]
    pub radii: Option<Vec<f64>>,
}

pub fn spheres(p: &SpheresParams) -> Result<Vec<[f64; 4]>, Error> {
    if p.centers.is_empty() {
        return Err(invalid(
            "parameter `centers` is empty; give at least one centre",
        ));
    }
    let n = p.centers.len();
    let radii: Vec<f64> = match (p.radius, &p.radii) {
        (Some(r), None) => vec![positive("radius", r)?; n],
        (None, Some(radii)) => {
            if radii.len() != n {
                return Err(invalid(format!(
                    "parameter `radii` has {} entries but `centers` has {n}; give one radius per centre",
                    radii.len()
                )));
            }
            let check = |(i, &r): (usize, &f64)| positive(&format!("radii[{i}]"), r);
            radii
                .iter()
                .enumerate()
                .map(check)
                .collect::<Result<_, _>>()?
        }
        (Some(_), Some(_)) => {
            return Err(invalid(
                "give either `radius` (shared) or `radii` (one per centre), not both",
            ))
        }
        (None, None) => {
            return Err(invalid(
                "missing parameter `radius` (shared) or `radii` (one per centre)",
            ))
        }
    };
    let mut out = Vec::with_capacity(n);
    for (i, (&c, r)) in p.centers.iter().zip(radii).enumerate() {
        let [x, y, z] = finite(&format!("centers[{i}]"), c)?;
        out.push([x, y, z, r]);
    }
    Ok(out)
}

pub struct Spheres;

impl Describe for Spheres {
    const NAME: &'static str = "spheres";
    const DESCRIPTION: &'static str =
        "Many spheres in one object, with a shared radius or one radius each (molecules, point sets).";
    const PARAMS: &'static str = "centers: [(x, y, z), ...]  sphere centres, at least one
radius: f64 > 0 = none  radius shared by every sphere (give this or `radii`)
radii: [f64 > 0, ...] = none  one radius per centre (give this or `radius`)";
}

impl Primitive for Spheres {
    type Params = SpheresParams;
    fn create(p: SpheresParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.spheres(&spheres(&p)?)
    }
}

// ------------------------------------------------------------------------------------------------
// plane
// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct PlaneParams {
    #[serde(default)]
    pub point: [f64; 3],
    pub normal: [f64; 3],
}

/// The plane as the host takes it: point then unit normal.
pub fn plane(p: &PlaneParams) -> Result<[f64; 6], Error> {
    let [px, py, pz] = finite("point", p.point)?;
    let [nx, ny, nz] = normalize(finite("normal", p.normal)?)
        .ok_or_else(|| invalid("parameter `normal` has zero length"))?;
    Ok([px, py, pz, nx, ny, nz])
}

pub struct Plane;

impl Describe for Plane {
    const NAME: &'static str = "plane";
    const DESCRIPTION: &'static str = "An infinite plane through a point.";
    const PARAMS: &'static str = "point: (x, y, z) = (0, 0, 0)  a point on the plane
normal: (x, y, z)  plane normal, any non-zero length";
}

impl Primitive for Plane {
    type Params = PlaneParams;
    fn create(p: PlaneParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.planes(&[plane(&p)?])
    }
}

// ------------------------------------------------------------------------------------------------
// triangle
// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct TriangleParams {
    pub vertices: [[f64; 3]; 3],
    #[serde(default, deserialize_with = "plain_some")]
    pub normals: Option<[[f64; 3]; 3]>,
    #[serde(default, deserialize_with = "plain_some")]
    pub colors: Option<[[f64; 3]; 3]>,
}

/// A one-triangle mesh.
pub fn triangle(p: &TriangleParams) -> Result<Mesh, Error> {
    let mut positions = Vec::with_capacity(3);
    for (i, &v) in p.vertices.iter().enumerate() {
        positions.push(finite(&format!("vertices[{i}]"), v)?);
    }
    if zero_area(positions[0], positions[1], positions[2]) {
        return Err(invalid(format!(
            "triangle has zero area (vertices {:?}, {:?}, {:?} are repeated or collinear)",
            positions[0], positions[1], positions[2]
        )));
    }
    let mut mesh = Mesh {
        positions,
        indices: vec![[0, 1, 2]],
        ..Mesh::default()
    };
    if let Some(normals) = &p.normals {
        for (i, &n) in normals.iter().enumerate() {
            let name = format!("normals[{i}]");
            mesh.normals
                .push(shading_normal(&name, &format!("normal {i}"), n)?);
        }
    }
    if let Some(colors) = &p.colors {
        for (i, &c) in colors.iter().enumerate() {
            mesh.colors.push(color(&format!("colors[{i}]"), c)?);
        }
    }
    Ok(mesh)
}

pub struct Triangle;

impl Describe for Triangle {
    const NAME: &'static str = "triangle";
    const DESCRIPTION: &'static str =
        "One triangle, with optional per-corner shading normals and colours.";
    const PARAMS: &'static str =
        "vertices: ((x, y, z), (x, y, z), (x, y, z))  corners, not collinear
normals: ((x, y, z), (x, y, z), (x, y, z)) = none  shading normal per corner, non-zero
colors: ((r, g, b), (r, g, b), (r, g, b)) = none  linear RGB per corner, >= 0";
}

impl Primitive for Triangle {
    type Params = TriangleParams;
    fn create(p: TriangleParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.mesh(&triangle(&p)?)
    }
}

// ------------------------------------------------------------------------------------------------
// mesh
// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct MeshParams {
    pub positions: Vec<[f64; 3]>,
    pub indices: Vec<[u64; 3]>,
    #[serde(default)]
    pub normals: Vec<[f64; 3]>,
    #[serde(default)]
    pub colors: Vec<[f64; 3]>,
    #[serde(default)]
    pub uvs: Vec<[f64; 2]>,
}

/// A validated mesh and how many zero-area triangles were dropped from it.
#[derive(Debug)]
pub struct BuiltMesh {
    pub mesh: Mesh,
    pub dropped: usize,
}

pub fn mesh(p: &MeshParams) -> Result<BuiltMesh, Error> {
    let n = p.positions.len();
    if n == 0 {
        return Err(invalid(
            "mesh is empty: parameter `positions` has no vertices",
        ));
    }
    if p.indices.is_empty() {
        return Err(invalid(
            "mesh is empty: parameter `indices` has no triangles",
        ));
    }
    for (name, len) in [
        ("normals", p.normals.len()),
        ("colors", p.colors.len()),
        ("uvs", p.uvs.len()),
    ] {
        if len != 0 && len != n {
            return Err(invalid(format!(
                "parameter `{name}` has {len} entries but `positions` has {n}; give one per vertex or none"
            )));
        }
    }

    let mut positions = Vec::with_capacity(n);
    for (i, &v) in p.positions.iter().enumerate() {
        positions.push(finite(&format!("positions[{i}]"), v)?);
    }
    let mut indices = Vec::with_capacity(p.indices.len());
    let mut dropped = 0;
    for (t, tri) in p.indices.iter().enumerate() {
        for &i in tri {
            if i >= n as u64 {
                return Err(invalid(format!(
                    "triangle {t} refers to vertex {i}, but there are only {n} positions (indices start at 0)"
                )));
            }
        }
        let [a, b, c] = tri.map(|i| positions[i as usize]);
        if zero_area(a, b, c) {
            dropped += 1;
        } else {
            indices.push(*tri);
        }
    }
    if indices.is_empty() {
        return Err(invalid(format!(
            "mesh has no usable triangle: all {dropped} have zero area"
        )));
    }

    let mut normals = Vec::with_capacity(p.normals.len());
    for (i, &v) in p.normals.iter().enumerate() {
        normals.push(shading_normal(
            &format!("normals[{i}]"),
            &format!("normal {i}"),
            v,
        )?);
    }
    let mut colors = Vec::with_capacity(p.colors.len());
    for (i, &c) in p.colors.iter().enumerate() {
        colors.push(color(&format!("colors[{i}]"), c)?);
    }
    let mut uvs = Vec::with_capacity(p.uvs.len());
    for (i, &v) in p.uvs.iter().enumerate() {
        uvs.push(uv(&format!("uvs[{i}]"), v)?);
    }
    Ok(BuiltMesh {
        mesh: Mesh {
            positions,
            indices,
            normals,
            colors,
            uvs,
        },
        dropped,
    })
}

pub struct MeshEntry;

impl Describe for MeshEntry {
    const NAME: &'static str = "mesh";
    const DESCRIPTION: &'static str =
        "A triangle mesh given inline, with optional per-vertex normals, colours and UVs.";
    const PARAMS: &'static str = "positions: [(x, y, z), ...]  vertex positions
indices: [(i, j, k), ...]  triangles as 0-based vertex indices
normals: [(x, y, z), ...] = none  one shading normal per vertex, non-zero
colors: [(r, g, b), ...] = none  one linear RGB colour per vertex, >= 0
uvs: [(u, v), ...] = none  one texture coordinate per vertex";
}

impl Primitive for MeshEntry {
    type Params = MeshParams;
    fn create(p: MeshParams, ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        let built = mesh(&p)?;
        if built.dropped > 0 {
            let total = p.indices.len();
            let msg = format!(
                "mesh {}: dropped {} of {total} triangles with zero area",
                ctx.instance, built.dropped
            );
            luxon_plugin::host_log(LIBRARY, 1, &msg);
        }
        out.mesh(&built.mesh)
    }
}

mod cones;
pub use cones::{Cone, Cylinder, Polycylinder, Ring};
mod solids;

#[cfg(test)]
mod props;
pub use solids::{BoxEntry, Heightfield, InfiniteCylinder, Quadric};

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
    use luxon_plugin::parse_params;

    fn err<T: std::fmt::Debug>(r: Result<T, Error>) -> String {
        r.unwrap_err().message
    }

    fn assert_contains(message: &str, part: &str) {
        assert!(
            message.contains(part),
            "{message:?} does not contain {part:?}"
        );
    }

    #[test]
    fn sphere_from_ron() {
        let p: SphereParams = parse_params("(center: (1, 2, 3), radius: 0.5)").unwrap();
        assert_eq!(sphere(&p).unwrap(), [1.0, 2.0, 3.0, 0.5]);
    }

    #[test]
    fn sphere_errors() {
        let p = |center, radius| SphereParams { center, radius };
        assert_contains(
            &err(sphere(&p([0.0; 3], 0.0))),
            "`radius` must be > 0, got 0",
        );
        assert_contains(&err(sphere(&p([0.0; 3], -1.0))), "`radius` must be > 0");
        assert_contains(
            &err(sphere(&p([0.0; 3], f64::INFINITY))),
            "`radius` must be finite",
        );
        assert_contains(
            &err(sphere(&p([0.0, f64::NAN, 0.0], 1.0))),
            "`center` must be finite",
        );
    }

    #[test]
    fn unknown_parameter_is_rejected_with_suggestion() {
        let e = parse_params::<SphereParams>("(center: (0, 0, 0), radus: 1)").unwrap_err();
        assert_contains(&e.message, "did you mean `radius`");
        let e = parse_params::<MeshParams>("(positions: [], indices: [], normal: [])").unwrap_err();
        assert_contains(&e.message, "did you mean `normals`");
    }

    #[test]
    fn spheres_shared_radius_and_radii() {
        let p: SpheresParams =
            parse_params("(centers: [(0, 0, 0), (1, 0, 0)], radius: 0.5)").unwrap();
        assert_eq!(
            spheres(&p).unwrap(),
            vec![[0.0, 0.0, 0.0, 0.5], [1.0, 0.0, 0.0, 0.5]]
        );
        let p: SpheresParams =
            parse_params("(centers: [(0, 0, 0), (1, 0, 0)], radii: [0.25, 2])").unwrap();
        assert_eq!(
            spheres(&p).unwrap(),
            vec![[0.0, 0.0, 0.0, 0.25], [1.0, 0.0, 0.0, 2.0]]
        );
    }

    #[test]
    fn spheres_errors() {
        let e = |text: &str| err(spheres(&parse_params::<SpheresParams>(text).unwrap()));
        assert_contains(&e("(centers: [], radius: 1)"), "`centers` is empty");
        assert_contains(&e("(centers: [(0, 0, 0)])"), "missing parameter `radius`");
        assert_contains(
            &e("(centers: [(0, 0, 0)], radius: 1, radii: [1])"),
            "not both",
        );
        assert_contains(
            &e("(centers: [(0, 0, 0), (1, 1, 1)], radii: [1])"),
            "`radii` has 1 entries but `centers` has 2",
        );
        assert_contains(
            &e("(centers: [(0, 0, 0), (1, 1, 1)], radii: [1, 0])"),
            "`radii[1]` must be > 0",
        );
        assert_contains(
            &e("(centers: [(0, 0, 0)], radius: -2)"),
            "`radius` must be > 0",
        );
        let p = SpheresParams {
            centers: vec![[0.0; 3], [f64::NAN, 0.0, 0.0]],
            radius: Some(1.0),
            radii: None,
        };
        assert_contains(&err(spheres(&p)), "`centers[1]` must be finite");
    }

    #[test]
    fn plane_default_point_and_unit_normal() {
        let p: PlaneParams = parse_params("(normal: (0, 2, 0))").unwrap();
        assert_eq!(plane(&p).unwrap(), [0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let p: PlaneParams =
            parse_params("(point: (1, 2, 3), normal: (1e-300, 0, 1e-300))").unwrap();
        let [_, _, _, nx, ny, nz] = plane(&p).unwrap();
        let h = 0.5f64.sqrt();
        assert!((nx - h).abs() < 1e-15 && ny == 0.0 && (nz - h).abs() < 1e-15);
    }

    #[test]
    fn plane_errors() {
        let p = PlaneParams {
            point: [0.0; 3],
            normal: [0.0; 3],
        };
        assert_contains(&err(plane(&p)), "`normal` has zero length");
        let p = PlaneParams {
            point: [f64::NEG_INFINITY, 0.0, 0.0],
            normal: [0.0, 1.0, 0.0],
        };
        assert_contains(&err(plane(&p)), "`point` must be finite");
        let p = PlaneParams {
            point: [0.0; 3],
            normal: [0.0, f64::NAN, 1.0],
        };
        assert_contains(&err(plane(&p)), "`normal` must be finite");
    }

    #[test]
    fn triangle_with_normals_and_colors() {
        let p: TriangleParams = parse_params(
            "(vertices: ((0, 0, 0), (1, 0, 0), (0, 1, 0)),
              normals: ((0, 0, 2), (0, 0, 1), (0, 3, 4)),
              colors: ((1, 0, 0), (0, 1, 0), (0, 0, 1)))",
        )
        .unwrap();
        let m = triangle(&p).unwrap();
        assert_eq!(
            m.positions,
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        );
        assert_eq!(m.indices, vec![[0, 1, 2]]);
        let expected = [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.6, 0.8]];
        for (n, e) in m.normals.iter().zip(expected) {
            assert!(length(sub(*n, e)) < 1e-15, "{n:?} != {e:?}");
        }
        assert_eq!(m.colors[2], [0.0, 0.0, 1.0]);
        assert!(m.uvs.is_empty());

        let p: TriangleParams =
            parse_params("(vertices: ((0, 0, 0), (1, 0, 0), (0, 1, 0)))").unwrap();
        let m = triangle(&p).unwrap();
        assert!(m.normals.is_empty() && m.colors.is_empty());
    }

    #[test]
    fn triangle_errors() {
        let t = |text: &str| err(triangle(&parse_params::<TriangleParams>(text).unwrap()));
        assert_contains(
            &t("(vertices: ((0, 0, 0), (1, 1, 1), (2, 2, 2)))"),
            "triangle has zero area (vertices [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]",
        );
        assert_contains(
            &t("(vertices: ((0.1, 0.2, 0.3), (0.1, 0.2, 0.3), (0, 1, 0)))"),
            "triangle has zero area",
        );
        // Collinear but not exactly representable.
        assert_contains(
            &t("(vertices: ((0.1, 0.2, 0.3), (0.2, 0.4, 0.6), (0.3, 0.6, 0.9)))"),
            "triangle has zero area",
        );
        assert_contains(
            &t("(vertices: ((0, 0, 0), (1, 0, 0), (0, 1, 0)), normals: ((0, 0, 1), (0, 0, 0), (0, 0, 1)))"),
            "normal 1 has zero length",
        );
        assert_contains(
            &t("(vertices: ((0, 0, 0), (1, 0, 0), (0, 1, 0)), colors: ((1, 1, 1), (1, 1, 1), (0, -1, 0)))"),
            "`colors[2]` must not be negative",
        );
        let p = TriangleParams {
            vertices: [[0.0; 3], [1.0, f64::NAN, 0.0], [0.0, 1.0, 0.0]],
            normals: None,
            colors: None,
        };
        assert_contains(&err(triangle(&p)), "`vertices[1]` must be finite");
    }

    #[test]
    fn tiny_and_far_triangles_are_not_zero_area() {
        let p = TriangleParams {
            vertices: [
                [1e6, 1e6, 1e6],
                [1e6 + 1e-3, 1e6, 1e6],
                [1e6, 1e6 + 1e-3, 1e6],
            ],
            normals: None,
            colors: None,
        };
        assert!(triangle(&p).is_ok());
        let p = TriangleParams {
            vertices: [[0.0; 3], [1e-200, 0.0, 0.0], [0.0, 1e-200, 0.0]],
            normals: None,
            colors: None,
        };
        assert!(triangle(&p).is_ok());
    }

    const QUAD: &str = "positions: [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
        indices: [(0, 1, 2), (0, 2, 3)]";

    fn parse_mesh(extra: &str) -> MeshParams {
        parse_params(&format!("({QUAD}, {extra})")).unwrap()
    }

    #[test]
    fn mesh_with_all_attributes() {
        let p = parse_mesh(
            "normals: [(0, 0, 1), (0, 0, 2), (0, 0, 3), (0, 0, 4)],
             colors: [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)],
             uvs: [(0, 0), (1, 0), (1, 1), (0, 1)]",
        );
        let built = mesh(&p).unwrap();
        assert_eq!(built.dropped, 0);
        let m = built.mesh;
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(m.normals.iter().all(|&n| n == [0.0, 0.0, 1.0]));
        assert_eq!(m.colors[3], [1.0, 1.0, 1.0]);
        assert_eq!(m.uvs[2], [1.0, 1.0]);
    }

    #[test]
    fn mesh_drops_zero_area_triangles() {
        let p: MeshParams = parse_params(
            "(positions: [(0, 0, 0), (1, 0, 0), (1, 1, 0), (2, 0, 0)],
              indices: [(0, 1, 2), (0, 0, 1), (0, 1, 3), (1, 2, 0)])",
        )
        .unwrap();
        let built = mesh(&p).unwrap();
        assert_eq!(built.dropped, 2);
        assert_eq!(built.mesh.indices, vec![[0, 1, 2], [1, 2, 0]]);
    }

    #[test]
    fn mesh_errors() {
        let m = |text: &str| err(mesh(&parse_params::<MeshParams>(text).unwrap()));
        assert_contains(
            &m("(positions: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], indices: [(0, 1, 2), (2, 1, 3)])"),
            "triangle 1 refers to vertex 3, but there are only 3 positions",
        );
        assert_contains(&m("(positions: [], indices: [])"), "mesh is empty");
        assert_contains(
            &m("(positions: [(0, 0, 0)], indices: [])"),
            "`indices` has no triangles",
        );
        assert_contains(
            &m("(positions: [(0, 0, 0), (1, 1, 1), (2, 2, 2)], indices: [(0, 1, 2), (0, 0, 0)])"),
            "all 2 have zero area",
        );
        let e = |extra: &str| err(mesh(&parse_mesh(extra)));
        assert_contains(
            &e("normals: [(0, 0, 1)]"),
            "`normals` has 1 entries but `positions` has 4",
        );
        assert_contains(&e("colors: [(0, 0, 1)]"), "`colors` has 1 entries");
        assert_contains(
            &e("uvs: [(0, 0), (0, 0), (0, 0), (0, 0), (0, 0)]"),
            "`uvs` has 5 entries",
        );
        assert_contains(
            &e("normals: [(0, 0, 1), (0, 0, 1), (0, 0, 1), (0, 0, 0)]"),
            "normal 3 has zero length",
        );
        assert_contains(
            &e("colors: [(0, 0, 1), (0, 0, 1), (0, 0, 1), (1e39, 0, 0)]"),
            "`colors[3]` is too large",
        );
        let mut p = parse_mesh("");
        p.positions[2][1] = f64::INFINITY;
        assert_contains(&err(mesh(&p)), "`positions[2]` must be finite");
        let mut p = parse_mesh("uvs: [(0, 0), (1, 0), (1, 1), (0, 1)]");
        p.uvs[1][0] = f64::NAN;
        assert_contains(&err(mesh(&p)), "`uvs[1]` must be finite");
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
