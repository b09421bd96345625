//! Storing recorded geometry (a primitive plugin's output, in f64 object coordinates) moved by
//! a transform: for keyed objects at each frame (`frame`) and for baked instances once
//! (`instances`). Points go through `world_from_object`, normals through its inverse
//! transpose, radii by its scale (uniform only: a sphere stays a sphere), all in f64, and are
//! then stored like any plugin's output, so a moved copy holds exactly what the same
//! geometry written out at its place would.

use crate::budget::{Budget, Use};
use crate::geometry::cone::Cones;
use crate::geometry::disc::Discs;
use crate::geometry::group::Group;
use crate::geometry::plane::Planes;
use crate::geometry::sphere::Spheres;
use crate::geometry::triangle::{MeshInput, Triangles};
use crate::math::DVec3;
use crate::motion::Placement;
use crate::plugin::primitive::Recorded;
use std::sync::Arc;

/// The native sets moved geometry goes into.
pub(super) struct Sets<'a> {
    pub spheres: &'a mut Spheres,
    pub triangles: &'a mut Triangles,
    pub planes: &'a mut Planes,
    pub cones: &'a mut Cones,
    pub discs: &'a mut Discs,
}

impl Sets<'_> {
    /// The same sets for a shorter borrow (one `place` of many).
    pub(super) fn reborrow(&mut self) -> Sets<'_> {
        Sets {
            spheres: &mut *self.spheres,
            triangles: &mut *self.triangles,
            planes: &mut *self.planes,
            cones: &mut *self.cones,
            discs: &mut *self.discs,
        }
    }
}

impl Group {
    pub(super) fn sets(&mut self) -> Sets<'_> {
        Sets {
            spheres: &mut self.spheres,
            triangles: &mut self.triangles,
            planes: &mut self.planes,
            cones: &mut self.cones,
            discs: &mut self.discs,
        }
    }
}

/// Stores `g` moved by `p` into `sets` (through the sets' own checks), charging its arrays
/// to `budget` before they grow; returns the zero-area triangles dropped.
pub(super) fn place(
    g: &Recorded,
    p: &Placement,
    offset: DVec3,
    material: u32,
    group: Sets,
    budget: &Arc<Budget>,
) -> Result<u64, String> {
    let m = p.world_from_object.matrix3;
    let det = m.determinant();
    if !(det.is_finite() && det != 0.0) {
        return Err("its transform is singular (a scale of 0?)".into());
    }
    let round = !(g.spheres.is_empty() && g.cones.is_empty() && g.discs.is_empty());
    let s = match (p.uniform_scale(), round) {
        (Some(s), _) => s,
        (None, false) => 1.0,
        (None, true) => {
            let s = m.x_axis.length();
            return Err(format!(
                "its scale is not the same on every axis (x is {s}), and it holds \
                 spheres, cones or discs, which keep their shape only under a uniform scale"
            ));
        }
    };
    let xyz = |r: &[f64], i: usize| p.point([r[i], r[i + 1], r[i + 2]]);
    let normal = |r: &[f64], i: usize| p.normal([r[i], r[i + 1], r[i + 2]]);
    let count = |n: usize, kind: &'static str| move || format!("{n} {kind}");
    let (ns, np, nc, nd) = (
        g.spheres.len(),
        g.planes.len(),
        g.cones.len(),
        g.discs.len(),
    );
    group.spheres.reserve(ns, budget, &count(ns, "spheres"))?;
    group.planes.reserve(np, budget, &count(np, "planes"))?;
    group.cones.reserve(nc, budget, &count(nc, "cones"))?;
    group.discs.reserve(nd, budget, &count(nd, "discs"))?;
    for (i, r) in g.spheres.iter().enumerate() {
        let c = xyz(r, 0);
        group
            .spheres
            .push_world(i, [c[0], c[1], c[2], r[3] * s], offset, material)?;
    }
    for (i, r) in g.planes.iter().enumerate() {
        let (q, n) = (xyz(r, 0), normal(r, 3));
        group
            .planes
            .push_world(i, [q[0], q[1], q[2], n[0], n[1], n[2]], offset, material)?;
    }
    for (i, r) in g.cones.iter().enumerate() {
        let (b, a) = (xyz(r, 0), xyz(r, 4));
        let cone = [b[0], b[1], b[2], r[3] * s, a[0], a[1], a[2], r[7] * s];
        group.cones.push_world(i, cone, offset, material)?;
    }
    for (i, r) in g.discs.iter().enumerate() {
        let (c, n) = (xyz(r, 0), normal(r, 3));
        let disc = [c[0], c[1], c[2], n[0], n[1], n[2], r[6] * s, r[7] * s];
        group.discs.push_world(i, disc, offset, material)?;
    }
    let mut dropped = 0;
    for mesh in &g.meshes {
        let triangles = mesh.indices.len() / 3;
        let what = count(triangles, "triangles");
        let attrs = !(mesh.normals.is_empty() && mesh.colors.is_empty() && mesh.uvs.is_empty());
        let vertices = mesh.positions.len() / 3;
        group
            .triangles
            .reserve_mesh(triangles, vertices, attrs, budget, &what)?;
        // The moved positions and normals, charged while they are stored.
        let moved = |from: &[f64], f: &dyn Fn(&[f64], usize) -> [f64; 3]| {
            let (mut to, charge) = budget.alloc_vec(Use::Geometry, from.len(), 0.0, what)?;
            for (a, b) in to.chunks_exact_mut(3).zip(from.chunks_exact(3)) {
                a.copy_from_slice(&f(b, 0));
            }
            Ok::<_, String>((to, charge))
        };
        let (positions, _p) = moved(&mesh.positions, &xyz)?;
        let (normals, _n) = moved(&mesh.normals, &normal)?;
        let input = MeshInput {
            positions: &positions,
            normals: &normals,
            ..mesh.input()
        };
        dropped += group.triangles.push_mesh(&input, offset, material)?;
    }
    Ok(dropped)
}
