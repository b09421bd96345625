//! Watertightness of the triangle intersection through the BVH: rays from inside a closed mesh
//! aimed exactly at its vertices and at points of its shared edges must all hit it. Shared by
//! `tests/stability.rs` (a count that stays fast in debug) and `examples/watertight.rs` (10 M+).
#![allow(dead_code)]

use glam::DVec3;
use luxon::geometry::triangle::{MeshInput, Triangles};
use luxon::geometry::{Clips, Counters};
use luxon::math::Vec3A;
use luxon::ray::Ray;
use rayon::prelude::*;

/// A closed icosphere (subdivided icosahedron) of radius `radius` around `center`:
/// positions and triangles, every edge shared by exactly two triangles.
pub fn icosphere(levels: u32, radius: f64, center: DVec3) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from(*p).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(f.len() * 4);
        let mut middle = |a: u32, b: u32, v: &mut Vec<DVec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) / 2.0).normalize());
                v.len() as u32 - 1
            })
        };
        for [a, b, c] in f {
            let (ab, bc, ca) = (
                middle(a, b, &mut v),
                middle(b, c, &mut v),
                middle(c, a, &mut v),
            );
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    (v.into_iter().map(|p| center + p * radius).collect(), f)
}

/// The mesh in a triangle BVH, and its vertices as stored (f32).
pub fn build(positions: &[DVec3], faces: &[[u32; 3]]) -> (Triangles, Vec<Vec3A>) {
    let flat: Vec<f64> = positions.iter().flat_map(|p| p.to_array()).collect();
    let indices: Vec<u64> = faces.iter().flatten().map(|&i| i as u64).collect();
    let mut tris = Triangles::default();
    let mesh = MeshInput {
        positions: &flat,
        indices: &indices,
        normals: &[],
        colors: &[],
        uvs: &[],
    };
    let dropped = tris.push_mesh(&mesh, DVec3::ZERO, 0).unwrap();
    assert_eq!(dropped, 0);
    tris.set.build();
    let stored = positions.iter().map(|p| Vec3A::from(p.as_vec3())).collect();
    (tris, stored)
}

/// Every target of one origin: the vertices, then `per_edge` points along every edge
/// (`v0 + k/(per_edge+1) · (v1 - v0)` in f32, on the edge to within its rounding).
pub fn targets(verts: &[Vec3A], faces: &[[u32; 3]], per_edge: u32) -> Vec<Vec3A> {
    let mut edges: Vec<(u32, u32)> = faces
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let mut out = verts.to_vec();
    for (a, b) in edges {
        let (p, q) = (verts[a as usize], verts[b as usize]);
        for k in 1..=per_edge {
            let s = k as f32 / (per_edge + 1) as f32;
            out.push(p + s * (q - p));
        }
    }
    out
}

/// Deterministic origins inside the unit ball around `center` scaled by `radius` (at most half
/// the radius out, so every origin is well inside the mesh).
pub fn origins(n: usize, radius: f32, center: Vec3A) -> Vec<Vec3A> {
    let mut s = 0x9E37_79B9u32;
    let mut r = || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s as f32 / u32::MAX as f32 * 2.0 - 1.0
    };
    (0..n)
        .map(|_| loop {
            let p = Vec3A::new(r(), r(), r());
            if p.length() < 1.0 {
                break center + p * (0.5 * radius);
            }
        })
        .collect()
}

/// Rays cast and rays that found no triangle (leaks), over all origins × targets, in parallel.
pub fn count_leaks(tris: &Triangles, origins: &[Vec3A], targets: &[Vec3A]) -> (u64, u64) {
    let clips = Clips::default();
    origins
        .par_iter()
        .map(|&o| {
            let mut c = Counters::default();
            let mut leaks = 0u64;
            for &p in targets {
                let ray = Ray::new(o, (p - o).normalize(), 0.0);
                let (mut t, mut hit) = (f32::INFINITY, None);
                tris.set.intersect(&ray, &mut t, &mut hit, &clips, &mut c);
                if hit.is_none() {
                    leaks += 1;
                }
            }
            (targets.len() as u64, leaks)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}
