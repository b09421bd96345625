//! Primitives to Luxon geometry, mirrored into Luxon's world (z negated): inline arrays
//! grouped by material, clip group and smoothness; plugin objects for BOX and CYLINDER;
//! clip groups; SCALARVOL volumes through the `raw` reader.

use std::collections::HashMap;
use std::path::Path;

use super::ron::{float, string, vec3};
use super::syntax::V3;
use super::{mirror, Warnings};
use crate::desc::{
    ClipPlaneDesc, Interpolation, ObjectDesc, PluginCall, TransferDesc, TransferPoint,
    VolumeDescEntry, VolumeRenderDesc,
};
use crate::error::SceneError;
use crate::geometry::InlineGeometry;
use crate::origin::{Origin, Spanned};

type Result<T> = std::result::Result<T, SceneError>;

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn length(a: V3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Whether a triangle has an area (Tachyon drops those that do not).
fn has_area(v: &[V3; 3]) -> bool {
    length(cross(sub(v[1], v[0]), sub(v[2], v[0]))) > 0.0
}

/// Everything geometric the scene holds so far.
#[derive(Default)]
pub(super) struct Shapes {
    pub groups: Vec<InlineGeometry>,
    /// (material, clip group, smooth, colored, shadowless) → index into `groups`.
    index: HashMap<(String, Option<usize>, bool, bool, bool), usize>,
    pub objects: Vec<Spanned<ObjectDesc>>,
    pub volumes: Vec<Spanned<VolumeDescEntry>>,
    pub clip_groups: Vec<(String, Spanned<Vec<ClipPlaneDesc>>)>,
    /// The clip group in effect.
    clip: Option<usize>,
}

impl Shapes {
    /// The inline group for `material` in the clip group in effect: `smooth` meshes (with
    /// vertex normals), `colored` ones (with vertex colours) and the rest are kept apart, since
    /// a mesh has normals (colours) for all of its vertices or none.
    fn group(
        &mut self,
        material: &str,
        smooth: bool,
        colored: bool,
        at: &Origin,
    ) -> &mut InlineGeometry {
        self.group_of(material, (smooth, colored), false, at)
    }

    /// The inline group for `material`, casting shadows or not (`shadowless`).
    fn group_of(
        &mut self,
        material: &str,
        (smooth, colored): (bool, bool),
        shadowless: bool,
        at: &Origin,
    ) -> &mut InlineGeometry {
        let key = (material.to_string(), self.clip, smooth, colored, shadowless);
        let i = match self.index.get(&key) {
            Some(&i) => i,
            None => {
                let i = self.groups.len();
                let clip = self.clip_name(at);
                self.groups.push(InlineGeometry {
                    material: Some(Spanned {
                        value: material.to_string(),
                        at: at.clone(),
                    }),
                    at: Some(at.clone()),
                    clip,
                    shadowless,
                    ..InlineGeometry::default()
                });
                self.index.insert(key, i);
                i
            }
        };
        &mut self.groups[i]
    }

    fn clip_name(&self, at: &Origin) -> Option<Spanned<String>> {
        self.clip.map(|k| Spanned {
            value: self.clip_groups[k].0.clone(),
            at: at.clone(),
        })
    }

    /// `START_CLIPGROUP`: a plane `a x + b y + c z = d` cuts away the side where the left
    /// side is larger, i.e. the side its normal (a, b, c) points to. A new group replaces the
    /// one in effect (Tachyon does not nest them).
    pub fn start_clip(&mut self, planes: &[[f64; 4]], at: &Origin) -> Result<()> {
        let mut out = Vec::with_capacity(planes.len());
        for (i, p) in planes.iter().enumerate() {
            let normal = mirror([p[0], p[1], p[2]]);
            let l2 = normal.iter().map(|x| x * x).sum::<f64>();
            if l2 == 0.0 {
                return Err(SceneError::at(
                    at.clone(),
                    format!("clip plane {i} has a, b, c all 0; expected a plane normal"),
                ));
            }
            out.push(ClipPlaneDesc {
                point: normal.map(|x| x * p[3] / l2),
                normal,
            });
        }
        let name = format!("clip-{}", self.clip_groups.len());
        self.clip = Some(self.clip_groups.len());
        self.clip_groups.push((
            name,
            Spanned {
                value: out,
                at: at.clone(),
            },
        ));
        Ok(())
    }

    pub fn end_clip(&mut self) {
        self.clip = None;
    }

    /// A sphere (a negative radius is its absolute value; radius 0 draws nothing).
    pub fn sphere(&mut self, material: &str, center: V3, rad: f64, at: &Origin) {
        if rad != 0.0 {
            let c = mirror(center);
            self.group(material, false, false, at)
                .spheres
                .push([c[0], c[1], c[2], rad.abs()]);
        }
    }

    /// A light's visible sphere (RAD > 0): it casts no shadow, so neither its own light nor
    /// any other is blocked by it (`material`: the light's colour, unlit and unfogged).
    pub fn light_sphere(&mut self, material: &str, center: V3, rad: f64, at: &Origin) {
        let c = mirror(center);
        self.group_of(material, (false, false), true, at)
            .spheres
            .push([c[0], c[1], c[2], rad]);
    }

    /// An open cylinder from `base` to `apex`.
    pub fn cylinder(&mut self, material: &str, base: V3, apex: V3, rad: f64, at: &Origin) {
        if rad != 0.0 && base != apex {
            let (b, a, r) = (mirror(base), mirror(apex), rad.abs());
            self.group(material, false, false, at)
                .cones
                .push([b[0], b[1], b[2], r, a[0], a[1], a[2], r]);
        }
    }

    /// A sphere at every point and a cylinder between consecutive ones.
    pub fn polycylinder(&mut self, material: &str, points: &[V3], rad: f64, at: &Origin) {
        for (i, &p) in points.iter().enumerate() {
            self.sphere(material, p, rad, at);
            if i > 0 {
                self.cylinder(material, points[i - 1], p, rad, at);
            }
        }
    }

    /// A flat annulus (nothing when OUTER is not above INNER).
    pub fn ring(
        &mut self,
        material: &str,
        c: V3,
        n: V3,
        radii: [f64; 2],
        at: &Origin,
    ) -> Result<()> {
        if length(n) == 0.0 {
            return Err(SceneError::at(
                at.clone(),
                "RING NORMAL is (0, 0, 0); expected a direction",
            ));
        }
        let (inner, outer) = (radii[0].abs(), radii[1].abs());
        if outer > inner {
            let (c, n) = (mirror(c), mirror(n));
            self.group(material, false, false, at)
                .discs
                .push([c[0], c[1], c[2], n[0], n[1], n[2], inner, outer]);
        }
        Ok(())
    }

    pub fn plane(&mut self, material: &str, c: V3, n: V3, at: &Origin) -> Result<()> {
        if length(n) == 0.0 {
            return Err(SceneError::at(
                at.clone(),
                "PLANE NORMAL is (0, 0, 0); expected a direction",
            ));
        }
        let (c, n) = (mirror(c), mirror(n));
        self.group(material, false, false, at)
            .planes
            .push([c[0], c[1], c[2], n[0], n[1], n[2]]);
        Ok(())
    }

    /// A triangle, flat or with vertex normals, and with vertex colours or not. Mirroring
    /// reverses the winding, so v1 and v2 (and their normals and colours) swap places: the
    /// normals keep their side of the winding.
    pub fn triangle(
        &mut self,
        material: &str,
        v: [V3; 3],
        n: Option<[V3; 3]>,
        c: Option<[V3; 3]>,
        at: &Origin,
    ) {
        if !has_area(&v) {
            return;
        }
        let g = self.group(material, n.is_some(), c.is_some(), at);
        let mesh = &mut g.mesh;
        let base = mesh.positions.len() as u64;
        for k in [0, 2, 1] {
            mesh.positions.push(mirror(v[k]));
            if let Some(n) = n {
                mesh.normals.push(mirror(n[k]));
            }
            if let Some(c) = c {
                mesh.colors.push(c[k]);
            }
        }
        mesh.indices.push([base, base + 1, base + 2]);
    }

    /// Smooth triangles indexing `positions`, `normals` and, when given, `colors` (Tachyon
    /// coordinates): only the vertices used are stored, once each.
    pub fn mesh(
        &mut self,
        material: &str,
        positions: &[V3],
        normals: &[V3],
        colors: Option<&[V3]>,
        triangles: &[[u32; 3]],
        at: &Origin,
    ) {
        let g = self.group(material, true, colors.is_some(), at);
        let mesh = &mut g.mesh;
        let mut stored: HashMap<u32, u64> = HashMap::new();
        for t in triangles {
            let v = t.map(|i| positions[i as usize]);
            if !has_area(&v) {
                continue;
            }
            let mut index = |i: u32| {
                *stored.entry(i).or_insert_with(|| {
                    mesh.positions.push(mirror(positions[i as usize]));
                    mesh.normals.push(mirror(normals[i as usize]));
                    if let Some(c) = colors {
                        mesh.colors.push(c[i as usize]);
                    }
                    mesh.positions.len() as u64 - 1
                })
            };
            let tri = [index(t[0]), index(t[2]), index(t[1])];
            mesh.indices.push(tri);
        }
    }

    fn object(&mut self, plugin: &str, params: String, material: &str, at: &Origin) {
        let clip = self.clip_name(at);
        self.objects.push(Spanned {
            value: ObjectDesc {
                call: PluginCall {
                    plugin: Spanned {
                        value: plugin.to_string(),
                        at: at.clone(),
                    },
                    params,
                    params_at: at.clone(),
                },
                material: Some(Spanned {
                    value: material.to_string(),
                    at: at.clone(),
                }),
                clip,
                shadows: true,
            },
            at: at.clone(),
        });
    }

    /// An axis-aligned box (corners in any order; a box without volume draws nothing).
    pub fn boxed(&mut self, material: &str, a: V3, b: V3, at: &Origin, warnings: &mut Warnings) {
        let (a, b) = (mirror(a), mirror(b));
        let lo = [0, 1, 2].map(|k| a[k].min(b[k]));
        let hi = [0, 1, 2].map(|k| a[k].max(b[k]));
        if (0..3).any(|k| lo[k] == hi[k]) {
            warnings.push(Spanned {
                value: "BOX has no thickness along an axis; it is left out".into(),
                at: at.clone(),
            });
            return;
        }
        self.object(
            "box",
            format!("(min: {}, max: {})", vec3(lo), vec3(hi)),
            material,
            at,
        );
    }

    /// An infinite cylinder (Tachyon's CYLINDER).
    pub fn infinite_cylinder(
        &mut self,
        material: &str,
        c: V3,
        axis: V3,
        rad: f64,
        at: &Origin,
    ) -> Result<()> {
        if length(axis) == 0.0 {
            return Err(SceneError::at(
                at.clone(),
                "CYLINDER AXIS is (0, 0, 0); expected a direction",
            ));
        }
        if rad != 0.0 {
            self.object(
                "infinite_cylinder",
                format!(
                    "(center: {}, axis: {}, radius: {})",
                    vec3(mirror(c)),
                    vec3(mirror(axis)),
                    float(rad.abs())
                ),
                material,
                at,
            );
        }
        Ok(())
    }

    /// SCALARVOL: the raw file's bytes (x fastest) through the `raw` reader, voxel (0, 0, 0) at
    /// MIN and the last at MAX, drawn by emission and absorption with Tachyon's colour ramp;
    /// `density` is the texture's OPACITY; `slices` the z slices read ([`volume_slices`]).
    #[allow(clippy::too_many_arguments)]
    pub fn volume(
        &mut self,
        min: V3,
        max: V3,
        dim: [u32; 3],
        path: &Path,
        slices: u32,
        density: f64,
        at: &Origin,
    ) -> Result<()> {
        let extent = sub(max, min);
        if extent.contains(&0.0) {
            return Err(SceneError::at(
                at.clone(),
                "SCALARVOL: MIN and MAX are equal on an axis; expected a box with volume",
            ));
        }
        let spacing = [0, 1, 2].map(|k| {
            let n = f64::from(dim[k].max(2) - 1);
            extent[k] / n
        });
        // Mirroring z turns the z spacing negative: the raw reader takes any non-zero one.
        let spacing = mirror(spacing);
        let origin = mirror(min);
        let params = format!(
            "(file: {}, dims: ({}, {}, {slices}), format: \"u8\", spacing: {}, origin: {})",
            string(&path.to_string_lossy()),
            dim[0],
            dim[1],
            vec3(spacing),
            vec3(origin)
        );
        let (a, b) = (mirror(min), mirror(max));
        let lo = [0, 1, 2].map(|k| a[k].min(b[k]));
        let hi = [0, 1, 2].map(|k| a[k].max(b[k]));
        let diagonal = length(extent);
        let cells = dim
            .iter()
            .map(|&n| f64::from(n).powi(2))
            .sum::<f64>()
            .sqrt();
        // Tachyon adds opacity (OPACITY / |dim|)·s per step of |MAX - MIN| / |dim|: an
        // extinction of OPACITY·s / |MAX - MIN| per unit length, s = voxel / 255.
        let k = density / diagonal;
        let point = |x: f64, color: V3| TransferPoint {
            x,
            color,
            opacity: k * x,
        };
        let transfer = TransferDesc {
            preset: None,
            points: vec![
                point(0.0, [0.0, 0.0, 0.0]),
                point(0.25, [1.0, 0.0, 0.0]),
                point(0.75, [1.0, 1.0, 0.0]),
                point(1.0, [1.0, 1.0, 1.0]),
            ],
            range: Some([0.0, 1.0]),
            opacity: 1.0,
        };
        let clip = self.clip_name(at);
        self.volumes.push(Spanned {
            value: VolumeDescEntry {
                call: PluginCall {
                    plugin: Spanned {
                        value: "raw".into(),
                        at: at.clone(),
                    },
                    params,
                    params_at: at.clone(),
                },
                name: None,
                render: Some(Spanned {
                    value: VolumeRenderDesc {
                        transfer,
                        step: Some(diagonal / cells),
                        interpolation: Interpolation::Nearest,
                        shading: None,
                        clip,
                        bounds: (slices != dim[2]).then_some((lo, hi)),
                    },
                    at: at.clone(),
                }),
            },
            at: at.clone(),
        });
        Ok(())
    }
}

/// How many z slices of a volume file to read: Tachyon reads the first nx·ny·nz bytes, so a
/// file with whole extra slices is read whole and cropped to the box (`voltest.dat` reads 100
/// of 109 slices); any other size is an error message.
pub(super) fn volume_slices(path: &Path, dim: [u32; 3]) -> std::result::Result<u32, String> {
    let slice = u64::from(dim[0]) * u64::from(dim[1]);
    let needed = slice * u64::from(dim[2]);
    let len = std::fs::metadata(path)
        .map_err(|e| format!("volume file {}: {e}", path.display()))?
        .len();
    if len == needed {
        Ok(dim[2])
    } else if len > needed && len % slice == 0 && len / slice <= u64::from(u32::MAX) {
        Ok((len / slice) as u32)
    } else {
        Err(format!(
            "volume file {} has {len} bytes; DIM {} {} {} needs {needed} (or whole extra slices)",
            path.display(),
            dim[0],
            dim[1],
            dim[2]
        ))
    }
}

/// TPOLYFILE's transform of a vertex: scaled by SCALE, then multiplied by Tachyon's matrix of
/// ROT (degrees; not a rotation when ROT.y ≠ 0: its bottom-left entry is +sin y), then moved
/// by CENTER.
pub(super) fn tpoly_vertex(v: V3, scale: V3, rot: V3, center: V3) -> V3 {
    // Tachyon's own value of π here (its degree conversion), not `std`'s.
    #[allow(clippy::approx_constant)]
    const PI: f64 = 3.1415926;
    let r = rot.map(|a| a * PI / 180.0);
    let (sx, cx) = r[0].sin_cos();
    let (sy, cy) = r[1].sin_cos();
    let (sz, cz) = r[2].sin_cos();
    let m = [
        [cy * cz, sx * sy * cz - cx * sz, sx * sz + cx * cz * sy],
        [cy * sz, cx * cz + sx * sy * sz, cx * sy * sz - sx * cz],
        [sy, sx * cy, cx * cy],
    ];
    let p = [v[0] * scale[0], v[1] * scale[1], v[2] * scale[2]];
    [0, 1, 2].map(|i| m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + center[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tpoly_rot_y_swaps_x_and_z() {
        // Measured: ROT 0 90 0 puts a triangle at x = 5 at z = +5, and one at z = 5 at x = +5.
        let p = tpoly_vertex([5.0, 0.0, 0.0], [1.0; 3], [0.0, 90.0, 0.0], [0.0; 3]);
        assert!((p[2] - 5.0).abs() < 1e-6 && p[0].abs() < 1e-6, "{p:?}");
        let q = tpoly_vertex([0.0, 0.0, 5.0], [1.0; 3], [0.0, 90.0, 0.0], [0.0; 3]);
        assert!((q[0] - 5.0).abs() < 1e-6 && q[2].abs() < 1e-6, "{q:?}");
    }
}
