//! `triangle` and `mesh`: native triangle meshes the core intersects itself, with optional
//! per-vertex shading normals, colours and texture coordinates.

use crate::params::plain_some;
use crate::vector::{cross, length, max_abs, normalize, scale, sub};
use crate::LIBRARY;
use luxon_plugin::{finite, invalid, Context, Describe, Error, Geometry, Mesh, Primitive};
use serde::Deserialize;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{assert_contains, err};
    use luxon_plugin::parse_params;

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
}
