//! A series' data frames during one frame's open shutter, stored as a [`Sweep`]: each
//! segment between two data frames holds every sphere (centre and radius) and every triangle
//! at both ends. The data frames must hold the same things: as many atoms, and meshes with the
//! same triangles over as many vertices (only where the vertices are changes).

use super::series::with_mesh_input;
use crate::budget::{Budget, Use};
use crate::geometry::sphere::Sphere;
use crate::geometry::sweep::{Sweep, Swept};
use crate::geometry::triangle::{corners, Triangle, VertexAttr, NO_ATTR};
use crate::math::DVec3;
use glam::Vec3;
use luxon_formats::{InlineGeometry, SeriesFrame};
use std::sync::Arc;

/// The sweep over `steps` (time, data frame; two or more, in time order) of a series whose
/// styles have the packed `materials`, in render space (`offset`: the world position of its
/// origin), charged to `budget` as it grows. An error names the data files.
pub(super) fn sweep(
    steps: &[(f64, Arc<SeriesFrame>)],
    materials: &[u32],
    offset: DVec3,
    budget: &Budget,
) -> Result<Sweep, String> {
    let mut sweep = Sweep::new(steps.iter().map(|s| s.0).collect());
    let first = &steps[0].1;
    let file = |f: &SeriesFrame| format!("`{}`", f.file.display());
    for (_, f) in &steps[1..] {
        let same = |what: &str, a: usize, b: usize| {
            if a == b {
                return Ok(());
            }
            Err(format!(
                "{} has {b} {what} but {} has {a}; a series blurred across its data frames \
                 (an open shutter) needs the same {what} in each",
                file(f),
                file(first)
            ))
        };
        same("atoms", first.spheres.len(), f.spheres.len())?;
        same("meshes", first.meshes.len(), f.meshes.len())?;
        for (a, b) in first.meshes.iter().zip(&f.meshes) {
            same("vertices", a.mesh.positions.len(), b.mesh.positions.len())?;
            if a.mesh.indices != b.mesh.indices {
                return Err(format!(
                    "{} joins its vertices into other triangles than {}; a series blurred \
                     across its data frames (an open shutter) needs the same triangles in each",
                    file(f),
                    file(first)
                ));
            }
        }
    }
    spheres(&mut sweep, steps, materials, offset, budget)?;
    let m = materials.first().copied().unwrap_or(0);
    for g in 0..first.meshes.len() {
        let meshes: Vec<&InlineGeometry> = steps.iter().map(|(_, f)| &f.meshes[g]).collect();
        mesh(&mut sweep, &meshes, steps, offset, m, budget)?;
    }
    Ok(sweep)
}

/// Every segment's spheres: each atom at both ends, of the material of its style at the
/// segment's start.
fn spheres(
    sweep: &mut Sweep,
    steps: &[(f64, Arc<SeriesFrame>)],
    materials: &[u32],
    offset: DVec3,
    budget: &Budget,
) -> Result<(), String> {
    let n = steps[0].1.spheres.len();
    let what = move || format!("{n} moving spheres");
    for (s, pair) in steps.windows(2).enumerate() {
        let (a, b) = (&pair[0].1, &pair[1].1);
        let set = &mut sweep.spheres[s];
        set.reserve(n, budget, &what)?;
        for (i, ((style, sa), (_, sb))) in a.spheres.iter().zip(&b.spheres).enumerate() {
            let end = |f: &SeriesFrame, s| {
                Sphere::from_world(i, s, offset).map_err(|m| format!("`{}`: {m}", f.file.display()))
            };
            let swept = Swept {
                a: end(a, *sa)?,
                b: end(b, *sb)?,
            };
            let m = materials.get(*style as usize).copied().unwrap_or(0);
            set.push(swept, m);
        }
    }
    Ok(())
}

/// One mesh of every step (`meshes`, same triangles) into every segment's triangles: a
/// triangle is left out of a segment only where it has no area at both ends.
fn mesh(
    sweep: &mut Sweep,
    meshes: &[&InlineGeometry],
    steps: &[(f64, Arc<SeriesFrame>)],
    offset: DVec3,
    material: u32,
    budget: &Budget,
) -> Result<(), String> {
    let mut ends: Vec<(Vec<Vec3>, Option<Vec<VertexAttr>>)> = Vec::new();
    for (g, (_, f)) in meshes.iter().zip(steps) {
        let end = with_mesh_input(g, |input| input.vertices(offset))
            .map_err(|e| format!("`{}`: {e}", f.file.display()))?;
        if end.1.is_some() != ends.first().map_or(end.1.is_some(), |e| e.1.is_some()) {
            return Err(format!(
                "`{}` and `{}` differ in whether vertices have normals, colours or uvs; a \
                 series blurred across its data frames needs the same in each",
                steps[0].1.file.display(),
                f.file.display()
            ));
        }
        ends.push(end);
    }
    let indices = &meshes[0].mesh.indices;
    let triangles = indices.len();
    let what = move || format!("{triangles} moving triangles");
    // Corners index each step's attributes alike (the same vertices in every step).
    let mut first_corner = None;
    if ends[0].1.is_some() {
        let base = sweep.vertex_attrs[0].len();
        let nv = ends[0].0.len();
        if base + nv > NO_ATTR as usize || sweep.corners.len() + triangles >= NO_ATTR as usize {
            return Err("too many vertices with normals, colours or uvs in one series".into());
        }
        for (s, (_, attrs)) in ends.iter().enumerate() {
            let list = &mut sweep.vertex_attrs[s];
            budget
                .grow(list, nv, Use::Geometry, what)
                .map_err(|e| e.0)?;
            list.extend(attrs.iter().flatten().copied());
        }
        budget
            .grow(&mut sweep.corners, triangles, Use::Geometry, what)
            .map_err(|e| e.0)?;
        first_corner = Some(sweep.corners.len());
        sweep
            .corners
            .extend((indices.iter()).map(|tri| tri.map(|i| (base as u64 + i) as u32)));
    }
    for (s, pair) in ends.windows(2).enumerate() {
        let set = &mut sweep.triangles[s];
        set.reserve(triangles, budget, &what)?;
        for (t, tri) in indices.iter().enumerate() {
            let a = corners(t, &tri[..], &pair[0].0)?;
            let b = corners(t, &tri[..], &pair[1].0)?;
            let flat = |v: [Vec3; 3]| (v[1] - v[0]).cross(v[2] - v[0]) == Vec3::ZERO;
            if flat(a) && flat(b) {
                continue;
            }
            let attr = first_corner.map_or(NO_ATTR, |c| (c + t) as u32);
            set.push(
                Swept {
                    a: Triangle { v: a, attr },
                    b: Triangle { v: b, attr },
                },
                material,
            );
        }
    }
    Ok(())
}
