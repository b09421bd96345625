//! Triangles: three vertices each (intersection needs nothing else), optional per-vertex
//! attributes kept apart and read only when shading: each mesh's vertex attributes are stored
//! once and its triangles index them (12 bytes per triangle instead of three copies, 96 bytes).

use super::set::{Set, Shape};
use super::{material_of, Hit, Kind, Surface};
use crate::budget::{Budget, Use};
use crate::math::{gamma, Aabb, Vec3A};
use crate::ray::Ray;
use glam::{DVec3, Vec3};

/// Shading attributes of one vertex.
#[derive(Clone, Copy, Debug, Default)]
pub struct VertexAttr {
    /// Unit normal, or zero when the mesh has none.
    pub n: Vec3,
    /// Colour, or negative when the mesh has none.
    pub c: Vec3,
    pub uv: [f32; 2],
}

pub const NO_ATTR: u32 = u32::MAX;

/// A triangle: its three vertices (all the intersection test reads) and the index of its
/// corners in `Triangles::corners`, or `NO_ATTR`.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    pub v: [Vec3; 3],
    pub attr: u32,
}

#[derive(Default)]
pub struct Triangles {
    pub set: Set<Triangle>,
    /// Per-vertex shading attributes of every mesh that has them, meshes one after another.
    pub vertex_attrs: Vec<VertexAttr>,
    /// For a triangle with attributes: the indices of its three corners in `vertex_attrs`.
    pub corners: Vec<[u32; 3]>,
}

/// What a ray precomputes once for the watertight test (Woop, Benthin & Wald 2013): the axis
/// along which it travels most and the shear that maps it onto +z; the origin is kept in that
/// axis order so the test reads each vertex coordinate straight from memory.
#[derive(Clone, Copy)]
pub struct TriRay {
    /// Coordinate indices (x', y', z'), each in 0..3.
    k: [usize; 3],
    /// The origin in (x', y', z') order.
    o: [f32; 3],
    s: [f32; 3],
}

impl TriRay {
    #[inline]
    pub fn new(ray: &Ray) -> TriRay {
        let d: [f32; 3] = ray.dir.into();
        let a = d.map(f32::abs);
        let kz = if a[0] > a[1] && a[0] > a[2] {
            0
        } else if a[1] > a[2] {
            1
        } else {
            2
        };
        // The next two axes in cyclic order; swapped for a negative z' to keep the winding so
        // the sign test below means the same for every ray.
        const NEXT: [[usize; 2]; 3] = [[1, 2], [2, 0], [0, 1]];
        let [mut kx, mut ky] = NEXT[kz];
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let o: [f32; 3] = ray.origin.into();
        TriRay {
            k: [kx, ky, kz],
            o: [o[kx], o[ky], o[kz]],
            // One vector division, lane for lane the three scalar ones.
            s: (Vec3A::new(d[kx], d[ky], 1.0) / Vec3A::splat(d[kz])).into(),
        }
    }

    /// Coordinate `k[i]` of `v`.
    #[inline(always)]
    fn coord(&self, v: &Vec3, i: usize) -> f32 {
        let v: &[f32; 3] = v.as_ref();
        // SAFETY: `k` is private and only `new` sets it, to axes from `NEXT` and `kz`, all in
        // 0..3, the length of `v` (`self.k[i]` itself is bounds-checked).
        unsafe { *v.get_unchecked(self.k[i]) }
    }
}

/// Watertight ray/triangle test: rays through shared edges and vertices hit exactly one of the
/// triangles that meet there. Returns (t, b1, b2) with t in (0, t_max).
#[inline(always)]
pub fn intersect_triangle(v: &[Vec3; 3], r: &TriRay, t_max: f32) -> Option<(f32, f32, f32)> {
    let [sx, sy, sz] = r.s;
    let [ox, oy, oz] = r.o;
    // Each vertex relative to the origin, sheared so the ray runs along +z.
    let shear = |p: &Vec3| {
        let z = r.coord(p, 2) - oz;
        (r.coord(p, 0) - ox - sx * z, r.coord(p, 1) - oy - sy * z, z)
    };
    let (ax, ay, az) = shear(&v[0]);
    let (bx, by, bz) = shear(&v[1]);
    let (cx, cy, cz) = shear(&v[2]);
    let mut u = cx * by - cy * bx;
    let mut vv = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || vv == 0.0 || w == 0.0 {
        // On an edge in f32: decide in f64 so neighbours agree.
        let (ax, ay, bx, by, cx, cy) = (
            ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
        );
        u = (cx * by - cy * bx) as f32;
        vv = (ax * cy - ay * cx) as f32;
        w = (bx * ay - by * ax) as f32;
    }
    if (u < 0.0 || vv < 0.0 || w < 0.0) && (u > 0.0 || vv > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + vv + w;
    if det == 0.0 {
        return None;
    }
    let z = [sz * az, sz * bz, sz * cz];
    let t_scaled = u * z[0] + vv * z[1] + w * z[2];
    if det > 0.0 {
        if t_scaled <= 0.0 || t_scaled >= t_max * det {
            return None;
        }
    } else if t_scaled >= 0.0 || t_scaled <= t_max * det {
        return None;
    }
    let inv = 1.0 / det;
    let t = t_scaled * inv;
    // A hit closer than the rounding error of t could be the surface a ray just left: reject
    // it (the bound of Pharr, Jakob & Humphreys, PBR 3rd ed., 3.9.6). Only computed for hits.
    let max_z = z.map(f32::abs).into_iter().fold(0.0, f32::max);
    let max_x = ax.abs().max(bx.abs()).max(cx.abs());
    let max_y = ay.abs().max(by.abs()).max(cy.abs());
    let delta_z = gamma(3) * max_z;
    let delta_x = gamma(5) * (max_x + max_z);
    let delta_y = gamma(5) * (max_y + max_z);
    let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let max_e = u.abs().max(vv.abs()).max(w.abs());
    let delta_t = 3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv.abs();
    if t <= delta_t {
        return None;
    }
    Some((t, vv * inv, w * inv))
}

/// A mesh as plugins and importers give it: flat f64/f32 arrays, optional ones empty.
pub struct MeshInput<'a> {
    /// x, y, z per vertex.
    pub positions: &'a [f64],
    /// Three vertex indices per triangle.
    pub indices: &'a [u64],
    /// x, y, z per vertex, or empty.
    pub normals: &'a [f64],
    /// r, g, b per vertex, or empty.
    pub colors: &'a [f32],
    /// u, v per vertex, or empty.
    pub uvs: &'a [f32],
}

impl MeshInput<'_> {
    /// The mesh's vertices in render space (`offset`: the world position of its origin) and,
    /// when it has normals, colours or uvs, their shading attributes (unit or zero normals),
    /// after checking the arrays' lengths and that every value is finite.
    #[allow(clippy::type_complexity)]
    pub fn vertices(&self, offset: DVec3) -> Result<(Vec<Vec3>, Option<Vec<VertexAttr>>), String> {
        let m = self;
        let nv = m.positions.len() / 3;
        if !m.positions.len().is_multiple_of(3) || !m.indices.len().is_multiple_of(3) {
            return Err("mesh arrays are not whole vertices or triangles".into());
        }
        for (what, len, per) in [
            ("normals", m.normals.len(), 3),
            ("colors", m.colors.len(), 3),
            ("uvs", m.uvs.len(), 2),
        ] {
            if len != 0 && len != nv * per {
                return Err(format!("mesh has {nv} vertices but {} {what}", len / per));
            }
        }
        if let Some(i) = m.positions.iter().position(|x| !x.is_finite()) {
            return Err(format!("vertex {} has a non-finite coordinate", i / 3));
        }
        if m.normals.iter().any(|x| !x.is_finite())
            || m.colors.iter().any(|x| !x.is_finite())
            || m.uvs.iter().any(|x| !x.is_finite())
        {
            return Err("mesh has a non-finite normal, colour or uv".into());
        }
        let verts: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|p| (DVec3::new(p[0], p[1], p[2]) - offset).as_vec3())
            .collect();
        let has_attr = !m.normals.is_empty() || !m.colors.is_empty() || !m.uvs.is_empty();
        let attr_of = |v: usize| VertexAttr {
            n: if m.normals.is_empty() {
                Vec3::ZERO
            } else {
                DVec3::new(m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2])
                    .normalize_or_zero()
                    .as_vec3()
            },
            c: if m.colors.is_empty() {
                Vec3::splat(-1.0)
            } else {
                Vec3::new(m.colors[3 * v], m.colors[3 * v + 1], m.colors[3 * v + 2])
            },
            uv: if m.uvs.is_empty() {
                [0.0; 2]
            } else {
                [m.uvs[2 * v], m.uvs[2 * v + 1]]
            },
        };
        Ok((verts, has_attr.then(|| (0..nv).map(attr_of).collect())))
    }
}

/// The corners of triangle `t` (vertex indices `tri`) among `verts`, each index checked.
pub fn corners(t: usize, tri: &[u64], verts: &[Vec3]) -> Result<[Vec3; 3], String> {
    let mut v = [Vec3::ZERO; 3];
    for k in 0..3 {
        let i = tri[k];
        let Some(p) = verts.get(i as usize) else {
            return Err(format!(
                "triangle {t} uses vertex {i}, but the mesh has {} vertices",
                verts.len()
            ));
        };
        v[k] = *p;
    }
    Ok(v)
}

impl Shape for Triangle {
    const KIND: Kind = Kind::Triangle;
    type Prep = TriRay;

    fn prep(ray: &Ray) -> TriRay {
        TriRay::new(ray)
    }

    fn bounds(&self) -> Aabb {
        let a = Vec3A::from(self.v[0]);
        Aabb::new(a, a)
            .grow(self.v[1].into())
            .grow(self.v[2].into())
    }

    #[inline(always)]
    fn hit(&self, _: &Ray, prep: &TriRay, t_max: f32) -> Option<(f32, f32, f32)> {
        intersect_triangle(&self.v, prep, t_max)
    }

    #[inline(always)]
    fn hit_after(&self, _: &Ray, prep: &TriRay, t_min: f32, t_max: f32) -> Option<(f32, f32, f32)> {
        intersect_triangle(&self.v, prep, t_max).filter(|h| h.0 > t_min)
    }
}

impl Triangles {
    pub fn len(&self) -> usize {
        self.set.len()
    }

    pub fn is_empty(&self) -> bool {
        self.set.is_empty()
    }

    /// Validates and stores a mesh given in world coordinates; returns how many zero-area
    /// triangles were dropped (they can never be hit and have no normal).
    /// Bytes of the triangles, their materials and shading attributes (capacities).
    pub fn bytes(&self) -> u64 {
        self.set.bytes()
            + (self.vertex_attrs.capacity() * std::mem::size_of::<VertexAttr>()
                + self.corners.capacity() * 12) as u64
    }

    /// Room for a mesh of `triangles` triangles over `vertices` vertices, charged to `budget`
    /// (see `Set::reserve`); `attrs`: the mesh has normals, colours or uvs.
    pub fn reserve_mesh(
        &mut self,
        triangles: usize,
        vertices: usize,
        attrs: bool,
        budget: &Budget,
        what: &dyn Fn() -> String,
    ) -> Result<(), String> {
        self.set.reserve(triangles, budget, what)?;
        if attrs {
            budget.grow(&mut self.vertex_attrs, vertices, Use::Geometry, what)?;
            budget.grow(&mut self.corners, triangles, Use::Geometry, what)?;
        }
        Ok(())
    }

    pub fn push_mesh(
        &mut self,
        m: &MeshInput,
        offset: DVec3,
        material: u32,
    ) -> Result<u64, String> {
        let (verts, attrs) = m.vertices(offset)?;
        let nv = verts.len();
        let base = self.vertex_attrs.len();
        let has_attr = attrs.is_some();
        if let Some(attrs) = attrs {
            if base + nv > NO_ATTR as usize {
                return Err("too many vertices with normals, colours or uvs in one scene".into());
            }
            self.vertex_attrs.extend(attrs);
        }
        let mut dropped = 0;
        self.set.data.reserve(m.indices.len() / 3);
        self.set.material.reserve(m.indices.len() / 3);
        for (t, tri) in m.indices.chunks_exact(3).enumerate() {
            let v = corners(t, tri, &verts)?;
            if (v[1] - v[0]).cross(v[2] - v[0]) == Vec3::ZERO {
                dropped += 1;
                continue;
            }
            let attr = if has_attr {
                if self.corners.len() >= NO_ATTR as usize {
                    return Err("too many triangles with normals, colours or uvs".into());
                }
                self.corners
                    .push([tri[0], tri[1], tri[2]].map(|i| (base as u64 + i) as u32));
                self.corners.len() as u32 - 1
            } else {
                NO_ATTR
            };
            self.set.push(Triangle { v, attr }, material);
        }
        Ok(dropped)
    }

    /// Starts loading the vertex attributes `surface` will read for triangle `i`: called for
    /// each closer hit found during traversal, which goes on while they arrive.
    #[inline(always)]
    pub fn prefetch_shading(&self, i: usize) {
        let a = self.set.data[i].attr;
        if a == NO_ATTR {
            return;
        }
        if let Some(corner) = self.corners.get(a as usize) {
            for &v in corner {
                if let Some(va) = self.vertex_attrs.get(v as usize) {
                    prefetch(va);
                }
            }
        }
    }

    /// `textured`: the scene looks textures up, so the uvs and their scale are needed.
    pub fn surface(&self, hit: &Hit, textured: bool) -> Surface {
        let i = hit.index as usize;
        let Triangle { v, attr: a } = self.set.data[i];
        let va =
            (a != NO_ATTR).then(|| self.corners[a as usize].map(|i| self.vertex_attrs[i as usize]));
        surface(v, va, hit, textured, material_of(self.set.material[i]))
    }

    /// The surface at a hit on triangle `hit.index` as it is after moving its corners by
    /// `point` and its vertex normals by `normal` (which returns unit or zero normals): a shared
    /// instance's triangle, shaded as its flat copy would be (interpolated moved normals, the
    /// geometric normal from the moved edges).
    pub fn surface_moved(
        &self,
        hit: &Hit,
        textured: bool,
        point: &dyn Fn(Vec3) -> Vec3,
        normal: &dyn Fn(Vec3) -> Vec3,
    ) -> Surface {
        let i = hit.index as usize;
        let Triangle { v, attr: a } = self.set.data[i];
        let va = (a != NO_ATTR).then(|| {
            self.corners[a as usize].map(|i| {
                let va = self.vertex_attrs[i as usize];
                VertexAttr {
                    n: normal(va.n),
                    ..va
                }
            })
        });
        surface(
            v.map(point),
            va,
            hit,
            textured,
            material_of(self.set.material[i]),
        )
    }
}

/// The surface of the triangle with vertices `v` (and vertex attributes `va`, when its mesh
/// has them) at `hit`, of `material`; `textured`: the scene looks textures up, so the uvs and
/// their scale are needed. Shared by the stored meshes and those read from the caller's arrays
/// (`array_set`), so both shade alike.
#[inline(always)]
pub fn surface(
    v: [Vec3; 3],
    va: Option<[VertexAttr; 3]>,
    hit: &Hit,
    textured: bool,
    material: u32,
) -> Surface {
    let (b1, b2) = (hit.b1, hit.b2);
    let b0 = 1.0 - b1 - b2;
    let (p0, p1, p2) = (Vec3A::from(v[0]), Vec3A::from(v[1]), Vec3A::from(v[2]));
    let p = b0 * p0 + b1 * p1 + b2 * p2;
    let p_error = gamma(7) * ((b0 * p0).abs() + (b1 * p1).abs() + (b2 * p2).abs());
    // Normal in f64: thin triangles lose the direction of the cross product in f32.
    let e1 = DVec3::from(v[1]) - DVec3::from(v[0]);
    let e2 = DVec3::from(v[2]) - DVec3::from(v[0]);
    let ng = Vec3A::from(e1.cross(e2).normalize_or_zero().as_vec3());
    let mut s = Surface {
        p,
        p_error,
        ng,
        ns: ng,
        uv: [b1, b2],
        material,
        color: None,
        uv_scale: 0.0,
        lift: Vec3A::ZERO,
    };
    if let Some(va) = va {
        if va[0].n != Vec3::ZERO {
            let n =
                b0 * Vec3A::from(va[0].n) + b1 * Vec3A::from(va[1].n) + b2 * Vec3A::from(va[2].n);
            let n = n.normalize_or_zero();
            if n != Vec3A::ZERO {
                let side = if n.dot(ng) < 0.0 { -1.0 } else { 1.0 };
                s.ns = side * n;
                s.lift = terminator_lift(p, [p0, p1, p2], [b0, b1, b2], &va, side);
            }
        }
        if va[0].c.x >= 0.0 {
            s.color = Some(
                b0 * Vec3A::from(va[0].c) + b1 * Vec3A::from(va[1].c) + b2 * Vec3A::from(va[2].c),
            );
        }
        if !textured {
            return s;
        }
        let uv = |k: usize| b0 * va[0].uv[k] + b1 * va[1].uv[k] + b2 * va[2].uv[k];
        s.uv = [uv(0), uv(1)];
        let (d1, d2) = (
            [va[1].uv[0] - va[0].uv[0], va[1].uv[1] - va[0].uv[1]],
            [va[2].uv[0] - va[0].uv[0], va[2].uv[1] - va[0].uv[1]],
        );
        let uv_area = (d1[0] * d2[1] - d1[1] * d2[0]).abs();
        let world_area = e1.cross(e2).length() as f32;
        if world_area > 0.0 {
            s.uv_scale = (uv_area / world_area).sqrt();
        }
    }
    s
}

/// Hanika's shadow-terminator fix ("Hacking the shadow terminator", Ray Tracing Gems II): the
/// offset from `p` to the barycentric blend of `p` projected onto each vertex's tangent plane,
/// for the planes `p` lies below. Zero on concave parts and on flat facets. Vertex normals are
/// stored unit length or zero (`push_mesh` normalizes them), so they are used as they are.
fn terminator_lift(p: Vec3A, v: [Vec3A; 3], b: [f32; 3], va: &[VertexAttr; 3], side: f32) -> Vec3A {
    let mut lift = Vec3A::ZERO;
    for k in 0..3 {
        let n = side * Vec3A::from(va[k].n);
        let below = (p - v[k]).dot(n).min(0.0);
        lift -= b[k] * below * n;
    }
    lift
}

/// Asks for the cache line holding `x`; a hint only.
#[inline(always)]
fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of the x86_64 baseline, and a prefetch is a hint: it reads nothing
    // the program sees and cannot fault, whatever the address.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
            (x as *const T).cast(),
        )
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3A::from(o), Vec3A::from(d).normalize(), 0.0)
    }

    #[test]
    fn terminator_lift_moves_facet_points_onto_the_smooth_sphere() {
        // A facet of a unit sphere with the sphere's normals at its corners.
        let v = [Vec3A::X, Vec3A::Y, Vec3A::Z];
        let va = v.map(|p| VertexAttr {
            n: p.into(),
            c: Vec3::splat(-1.0),
            uv: [0.0; 2],
        });
        let b = [1.0 / 3.0; 3];
        let p = (v[0] + v[1] + v[2]) / 3.0;
        let lifted = p + terminator_lift(p, v, b, &va, 1.0);
        // The facet's centre is at 0.577 from the centre; lifted, it is far closer to 1.
        assert!((p.length() - 0.577).abs() < 1e-3);
        assert!(
            lifted.length() > 0.95 && lifted.length() <= 1.0 + 1e-6,
            "{lifted}"
        );
        // Corners do not move; normals flipped to the other side (the inside) do not lift.
        assert_eq!(
            terminator_lift(v[0], v, [1.0, 0.0, 0.0], &va, 1.0),
            Vec3A::ZERO
        );
        assert_eq!(terminator_lift(p, v, b, &va, -1.0), Vec3A::ZERO);
        // A flat facet (all normals equal to the facet's) does not lift either.
        let flat = [VertexAttr {
            n: Vec3::ONE.normalize(),
            ..va[0]
        }; 3];
        assert!(terminator_lift(p, v, b, &flat, 1.0).length() < 1e-6);
    }

    #[test]
    fn hit_and_barycentrics() {
        let v = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let r = ray([0.25, 0.25, 0.0], [0.0, 0.0, 1.0]);
        let (t, b1, b2) = intersect_triangle(&v, &TriRay::new(&r), f32::INFINITY).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (b1 - 0.25).abs() < 1e-6 && (b2 - 0.25).abs() < 1e-6);
        // Both windings hit; behind the origin does not.
        let v2 = [v[0], v[2], v[1]];
        assert!(intersect_triangle(&v2, &TriRay::new(&r), f32::INFINITY).is_some());
        let back = ray([0.25, 0.25, 2.0], [0.0, 0.0, 1.0]);
        assert!(intersect_triangle(&v, &TriRay::new(&back), f32::INFINITY).is_none());
    }

    #[test]
    fn shared_edge_is_watertight() {
        // Two triangles sharing the diagonal of a square; rays exactly on the diagonal.
        let a = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
        ];
        let b = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        for k in 1..1000 {
            let x = k as f32 / 1000.0;
            let r = ray([x, x, 0.0], [0.0, 0.0, 1.0]);
            let tr = TriRay::new(&r);
            let hits = intersect_triangle(&a, &tr, f32::INFINITY).is_some() as u32
                + intersect_triangle(&b, &tr, f32::INFINITY).is_some() as u32;
            assert!(hits >= 1, "ray through the shared edge at {x} leaked");
        }
    }

    #[test]
    fn parallel_ray_misses() {
        let v = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let r = ray([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        assert!(intersect_triangle(&v, &TriRay::new(&r), f32::INFINITY).is_none());
    }
}
