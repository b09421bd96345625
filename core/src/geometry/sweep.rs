//! Time-sampled geometry under an open shutter (a `series:` blurred across its data frames):
//! spheres and mesh vertices given at a few steps of time, moving linearly from one step to
//! the next. Each segment between two steps is a set of its own whose primitives hold both
//! ends ([`Swept`]) and whose BVH boxes hold both (linear motion stays inside their union),
//! so a ray is tested only against the segment its time falls in, on the geometry blended at
//! that time. At a step's own time the blend is that step's geometry, bit for bit, tested and
//! shaded by the same functions as still geometry (`intersect_sphere`, `intersect_triangle`
//! and their `surface`s).
//!
//! Inside a segment's set, a ray's `time` is the blend factor u in [0, 1] (what `Shape::prep`
//! reads); [`Sweep`] maps a ray's frame-relative time to its segment and u.

use super::set::{Set, Shape};
use super::sphere::{self, intersect_sphere, Sphere};
use super::triangle::{self, intersect_triangle, TriRay, Triangle, VertexAttr, NO_ATTR};
use super::{material_of, Clips, Counters, Hit, Kind, Surface};
use crate::math::Aabb;
use crate::ray::Ray;
use glam::Vec3;

/// A primitive at the two ends of a segment of time.
#[derive(Clone, Copy, Debug)]
pub struct Swept<S> {
    pub a: S,
    pub b: S,
}

/// `a` and `b` blended by `u`: exactly `a` at 0 and `b` at 1.
#[inline(always)]
fn lerp(a: Vec3, b: Vec3, u: f32) -> Vec3 {
    if u == 0.0 {
        a
    } else if u == 1.0 {
        b
    } else {
        a * (1.0 - u) + b * u
    }
}

#[inline(always)]
fn lerp1(a: f32, b: f32, u: f32) -> f32 {
    if u == 0.0 {
        a
    } else if u == 1.0 {
        b
    } else {
        a * (1.0 - u) + b * u
    }
}

/// The union of two boxes, grown by a few ulps: a blend rounded in f32 may step past the
/// ends' boxes by its rounding.
fn padded(a: Aabb, b: Aabb) -> Aabb {
    let u = a.union(b);
    let pad = u.min.abs().max(u.max.abs()) * (4.0 * f32::EPSILON);
    Aabb::new(u.min - pad, u.max + pad)
}

impl Swept<Sphere> {
    /// The sphere at blend `u` (centre and radius).
    #[inline(always)]
    pub fn at(&self, u: f32) -> Sphere {
        Sphere {
            center: lerp(self.a.center, self.b.center, u),
            radius: lerp1(self.a.radius, self.b.radius, u),
        }
    }
}

impl Shape for Swept<Sphere> {
    const KIND: Kind = Kind::Sphere;
    /// The blend factor.
    type Prep = f32;

    fn prep(ray: &Ray) -> f32 {
        ray.time
    }

    fn bounds(&self) -> Aabb {
        padded(self.a.bounds(), self.b.bounds())
    }

    #[inline(always)]
    fn hit_after(&self, ray: &Ray, u: &f32, t_min: f32, t_max: f32) -> Option<(f32, f32, f32)> {
        intersect_sphere(&self.at(*u), ray.origin, ray.dir, t_min, t_max)
            .0
            .map(|t| (t, 0.0, 0.0))
    }

    #[inline(always)]
    fn crossings(&self, ray: &Ray, u: &f32, t_max: f32) -> u32 {
        intersect_sphere(&self.at(*u), ray.origin, ray.dir, 0.0, t_max).1
    }
}

impl Swept<Triangle> {
    /// The corners at blend `u`.
    #[inline(always)]
    pub fn at(&self, u: f32) -> [Vec3; 3] {
        [0, 1, 2].map(|k| lerp(self.a.v[k], self.b.v[k], u))
    }
}

impl Shape for Swept<Triangle> {
    const KIND: Kind = Kind::Triangle;
    /// The triangle test's set-up and the blend factor.
    type Prep = (TriRay, f32);

    fn prep(ray: &Ray) -> (TriRay, f32) {
        (TriRay::new(ray), ray.time)
    }

    fn bounds(&self) -> Aabb {
        padded(self.a.bounds(), self.b.bounds())
    }

    #[inline(always)]
    fn hit(&self, _: &Ray, (r, u): &(TriRay, f32), t_max: f32) -> Option<(f32, f32, f32)> {
        intersect_triangle(&self.at(*u), r, t_max)
    }

    #[inline(always)]
    fn hit_after(
        &self,
        _: &Ray,
        (r, u): &(TriRay, f32),
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, f32, f32)> {
        intersect_triangle(&self.at(*u), r, t_max).filter(|h| h.0 > t_min)
    }
}

/// A vertex's shading attributes at blend `u`: normals blended and made unit again (exact at
/// the ends, where they are stored unit), colours and uvs blended.
fn attr_at(a: VertexAttr, b: VertexAttr, u: f32) -> VertexAttr {
    if u == 0.0 {
        return a;
    }
    if u == 1.0 {
        return b;
    }
    VertexAttr {
        n: lerp(a.n, b.n, u).normalize_or_zero(),
        c: lerp(a.c, b.c, u),
        uv: [lerp1(a.uv[0], b.uv[0], u), lerp1(a.uv[1], b.uv[1], u)],
    }
}

/// Geometry given at steps of time, moving linearly between them (one series' data frames
/// during a frame's shutter).
#[derive(Default)]
pub struct Sweep {
    /// The steps' times, frames from the frame's time, increasing (two or more).
    pub times: Vec<f64>,
    /// Per segment (steps i and i + 1): its spheres.
    pub spheres: Vec<Set<Swept<Sphere>>>,
    /// Per segment: its triangles (`a.attr`: an index in `corners`, or `NO_ATTR`).
    pub triangles: Vec<Set<Swept<Triangle>>>,
    /// Per step: every vertex's shading attributes (meshes that have them, one after another).
    pub vertex_attrs: Vec<Vec<VertexAttr>>,
    /// For a triangle with attributes: its corners' indices in each step's `vertex_attrs`.
    pub corners: Vec<[u32; 3]>,
}

impl Sweep {
    /// An empty sweep over the steps at `times` (frames from the frame's time, increasing,
    /// two or more): a set of spheres and one of triangles per segment.
    pub fn new(times: Vec<f64>) -> Sweep {
        let segments = times.len().saturating_sub(1);
        Sweep {
            spheres: (0..segments).map(|_| Set::default()).collect(),
            triangles: (0..segments).map(|_| Set::default()).collect(),
            vertex_attrs: vec![Vec::new(); times.len()],
            corners: Vec::new(),
            times,
        }
    }

    pub fn len(&self) -> usize {
        let s: usize = self.spheres.iter().map(Set::len).sum();
        s + self.triangles.iter().map(Set::len).sum::<usize>()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bytes of the primitives, attributes and BVHs.
    pub fn bytes(&self) -> u64 {
        let sets: u64 = (self.spheres.iter())
            .map(|s| s.bytes() + s.bvh_bytes())
            .chain(self.triangles.iter().map(|s| s.bytes() + s.bvh_bytes()))
            .sum();
        let attrs: usize = self.vertex_attrs.iter().map(Vec::capacity).sum();
        sets + (attrs * std::mem::size_of::<VertexAttr>() + self.corners.capacity() * 12) as u64
    }

    pub fn build(&mut self) {
        self.spheres.iter_mut().for_each(Set::build);
        self.triangles.iter_mut().for_each(Set::build);
    }

    /// The segment a ray at frame-relative time `time` meets and its blend factor there:
    /// before the first step the first step holds, after the last the last. A step's own time
    /// is the start of the segment after it (u = 0; the last step: u = 1 of the last).
    #[inline]
    pub fn segment(&self, time: f32) -> (usize, f32) {
        let t = f64::from(time);
        let last = self.times.len() - 2;
        let i = self.times.partition_point(|&s| s <= t).saturating_sub(1);
        let i = i.min(last);
        let (t0, t1) = (self.times[i], self.times[i + 1]);
        let u = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        (i, u as f32)
    }

    /// The ray as a segment's sets read it: its time the blend factor.
    #[inline]
    fn local(&self, ray: &Ray) -> (usize, Ray) {
        let (i, u) = self.segment(ray.time);
        (i, Ray { time: u, ..*ray })
    }

    /// The closest hit before `t_max` (which it lowers), if any: spheres, then triangles.
    #[inline]
    pub fn closest(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        clips: &Clips,
        c: &mut Counters,
    ) -> Option<Hit> {
        let (i, local) = self.local(ray);
        let mut found = None;
        self.spheres[i].intersect(&local, t_max, &mut found, clips, c);
        self.triangles[i].intersect(&local, t_max, &mut found, clips, c);
        found
    }

    /// Calls `on_hit(material, crossings)` for what the ray crosses in (0, t_max) until it
    /// returns true; returns whether it did.
    #[inline]
    pub fn any(
        &self,
        ray: &Ray,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        on_hit: &mut impl FnMut(u32, u32) -> bool,
    ) -> bool {
        let (i, local) = self.local(ray);
        self.spheres[i].any(&local, t_max, clips, c, &mut *on_hit)
            || self.triangles[i].any(&local, t_max, clips, c, &mut *on_hit)
    }

    /// The surface at a hit `closest` found for `ray`, on the geometry at the ray's time.
    pub fn surface(&self, hit: &Hit, ray: &Ray, textured: bool) -> Surface {
        let (i, u) = self.segment(ray.time);
        let k = hit.index as usize;
        if hit.kind == Kind::Sphere {
            let set = &self.spheres[i];
            let m = material_of(set.material[k]);
            return sphere::surface(set.data[k].at(u), hit.t, ray, textured, m);
        }
        let set = &self.triangles[i];
        let tri = set.data[k];
        let a = tri.a.attr;
        let va = (a != NO_ATTR).then(|| {
            self.corners[a as usize].map(|v| {
                let v = v as usize;
                attr_at(self.vertex_attrs[i][v], self.vertex_attrs[i + 1][v], u)
            })
        });
        let m = material_of(set.material[k]);
        triangle::surface(tri.at(u), va, hit, textured, m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::triangle::{MeshInput, Triangles};
    use glam::DVec3;

    /// A small deterministic generator (xorshift), numbers in [0, 1).
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }

        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.next()
        }

        fn point(&mut self, r: f32) -> Vec3 {
            Vec3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
        }
    }

    const TIMES: [f64; 3] = [-1.0, 0.0, 0.5];

    /// Spheres wandering and growing over `TIMES`: per step, each sphere.
    fn sphere_steps(rng: &mut Random, n: usize) -> Vec<Vec<Sphere>> {
        let start: Vec<Sphere> = (0..n)
            .map(|_| Sphere {
                center: rng.point(3.0),
                radius: rng.range(0.05, 0.4),
            })
            .collect();
        let mut steps = vec![start];
        for _ in 1..TIMES.len() {
            let last = steps.last().unwrap();
            let next = (last.iter())
                .map(|s| Sphere {
                    center: s.center + rng.point(0.8),
                    radius: (s.radius * rng.range(0.5, 1.6)).max(0.02),
                })
                .collect();
            steps.push(next);
        }
        steps
    }

    /// Per step, positions and normals (flat x, y, z); and the shared indices.
    type MeshSteps = (Vec<(Vec<f64>, Vec<f64>)>, Vec<u64>);

    /// A grid mesh over 6x6 vertices whose vertices (and normals) move at each step: per
    /// step, positions and normals (flat x, y, z), and the shared indices.
    fn mesh_steps(rng: &mut Random) -> MeshSteps {
        let side = 6u64;
        let mut indices = Vec::new();
        for y in 0..side - 1 {
            for x in 0..side - 1 {
                let v = y * side + x;
                indices.extend([v, v + 1, v + side, v + 1, v + side + 1, v + side]);
            }
        }
        let mut steps = Vec::new();
        for s in 0..TIMES.len() {
            let (mut p, mut n) = (Vec::new(), Vec::new());
            for y in 0..side {
                for x in 0..side {
                    let wobble = rng.point(0.3);
                    let z = 0.5 * s as f32 + wobble.z;
                    p.extend([x as f32 * 0.6 - 1.5 + wobble.x, y as f32 * 0.6 - 1.5, z]);
                    let normal = (Vec3::Z + rng.point(0.5)).normalize();
                    n.extend(normal.to_array());
                }
            }
            let f64s = |v: Vec<f32>| v.into_iter().map(f64::from).collect();
            steps.push((f64s(p), f64s(n)));
        }
        (steps, indices)
    }

    /// The sweep over `spheres` and the mesh, as a series' data frames would store it.
    fn sweep_of(spheres: &[Vec<Sphere>], mesh: &MeshSteps) -> Sweep {
        let mut sweep = Sweep::new(TIMES.to_vec());
        let (steps, indices) = mesh;
        let ends: Vec<_> = (steps.iter())
            .map(|(p, n)| {
                let input = MeshInput {
                    positions: p,
                    indices,
                    normals: n,
                    colors: &[],
                    uvs: &[],
                };
                input.vertices(DVec3::ZERO).unwrap()
            })
            .collect();
        for (s, (_, attrs)) in ends.iter().enumerate() {
            sweep.vertex_attrs[s] = attrs.clone().unwrap();
        }
        for tri in indices.chunks_exact(3) {
            sweep
                .corners
                .push([tri[0], tri[1], tri[2]].map(|i| i as u32));
        }
        for s in 0..TIMES.len() - 1 {
            for (a, b) in spheres[s].iter().zip(&spheres[s + 1]) {
                sweep.spheres[s].push(Swept { a: *a, b: *b }, 1);
            }
            for (t, tri) in indices.chunks_exact(3).enumerate() {
                let a = triangle::corners(t, tri, &ends[s].0).unwrap();
                let b = triangle::corners(t, tri, &ends[s + 1].0).unwrap();
                let attr = t as u32;
                let swept = Swept {
                    a: Triangle { v: a, attr },
                    b: Triangle { v: b, attr },
                };
                sweep.triangles[s].push(swept, 2);
            }
        }
        sweep.build();
        sweep
    }

    #[test]
    fn a_rays_time_picks_its_segment_and_blend() {
        let sweep = Sweep::new(TIMES.to_vec());
        assert_eq!(sweep.segment(-1.0), (0, 0.0));
        assert_eq!(sweep.segment(-0.5), (0, 0.5));
        assert_eq!(sweep.segment(0.0), (1, 0.0));
        assert_eq!(sweep.segment(0.25), (1, 0.5));
        assert_eq!(sweep.segment(0.5), (1, 1.0));
        // Outside the steps the end holds.
        assert_eq!(sweep.segment(-3.0), (0, 0.0));
        assert_eq!(sweep.segment(2.0), (1, 1.0));
    }

    /// Random rays at random times against moving spheres and a deforming mesh: the BVH
    /// misses no hit a test of every primitive at the ray's time finds, at the same nearest
    /// distance, and the any-hit query agrees.
    #[test]
    fn brute_force_finds_no_hit_the_bvh_misses() {
        let mut rng = Random(0x9e37_79b9_7f4a_7c15);
        let spheres = sphere_steps(&mut rng, 60);
        let mesh = mesh_steps(&mut rng);
        let sweep = sweep_of(&spheres, &mesh);
        let (clips, mut c) = (Clips::default(), Counters::default());
        let (steps, indices) = &mesh;
        let verts = |s: usize| -> Vec<Vec3> {
            (steps[s].0.chunks_exact(3))
                .map(|p| DVec3::new(p[0], p[1], p[2]).as_vec3())
                .collect()
        };
        let verts: Vec<Vec<Vec3>> = (0..TIMES.len()).map(verts).collect();
        let (mut hits, mut triangle_hits) = (0, 0);
        for _ in 0..4000 {
            let o = rng.point(6.0);
            let d = (rng.point(2.0) - o * 0.3).normalize();
            let time = rng.range(-1.3, 0.8);
            let t_max = if rng.next() < 0.3 {
                rng.range(1.0, 8.0)
            } else {
                f32::INFINITY
            };
            let ray = Ray::new(o.into(), d.into(), time);
            let (s, u) = sweep.segment(time);
            let r = TriRay::new(&ray);
            let mut want: Option<(f32, Kind)> = None;
            let mut closer = |t: Option<f32>, kind| {
                if let Some(t) = t {
                    if want.is_none_or(|w| t < w.0) {
                        want = Some((t, kind));
                    }
                }
            };
            for (a, b) in spheres[s].iter().zip(&spheres[s + 1]) {
                let at = Swept { a: *a, b: *b }.at(u);
                closer(
                    intersect_sphere(&at, ray.origin, ray.dir, 0.0, t_max).0,
                    Kind::Sphere,
                );
            }
            for (t, tri) in indices.chunks_exact(3).enumerate() {
                let a = triangle::corners(t, tri, &verts[s]).unwrap();
                let b = triangle::corners(t, tri, &verts[s + 1]).unwrap();
                let v = Swept {
                    a: Triangle { v: a, attr: 0 },
                    b: Triangle { v: b, attr: 0 },
                }
                .at(u);
                closer(
                    intersect_triangle(&v, &r, t_max).map(|h| h.0),
                    Kind::Triangle,
                );
            }
            let mut tm = t_max;
            let got = sweep.closest(&ray, &mut tm, &clips, &mut c);
            assert_eq!(
                got.map(|h| (h.t.to_bits(), h.kind)),
                want.map(|w| (w.0.to_bits(), w.1)),
                "{ray:?}"
            );
            let any = sweep.any(&ray, t_max, &clips, &mut c, &mut |_, _| true);
            assert_eq!(any, want.is_some(), "{ray:?}");
            if let Some(h) = got {
                hits += 1;
                triangle_hits += usize::from(h.kind == Kind::Triangle);
                // Shading reads the geometry at the ray's time: the point lies on it.
                let surface = sweep.surface(&h, &ray, false);
                assert!((surface.p - ray.at(h.t)).length() < 1e-3, "{ray:?}");
            }
        }
        // Enough rays hit both kinds for the comparison to mean something.
        assert!(
            hits > 400 && triangle_hits > 100,
            "{hits} hits, {triangle_hits} on triangles"
        );
    }

    /// At a step's own time a ray meets the geometry of that step bit for bit: the same
    /// distances and surfaces as the step stored still.
    #[test]
    fn a_step_is_the_still_geometry_bitwise() {
        let mut rng = Random(0x2545_f491_4f6c_dd1d);
        let spheres = sphere_steps(&mut rng, 40);
        let mesh = mesh_steps(&mut rng);
        let sweep = sweep_of(&spheres, &mesh);
        let (clips, mut c) = (Clips::default(), Counters::default());
        for (s, &time) in TIMES.iter().enumerate() {
            let mut still = Set::default();
            for sphere in &spheres[s] {
                still.push(*sphere, 1);
            }
            still.build();
            let mut triangles = Triangles::default();
            let input = MeshInput {
                positions: &mesh.0[s].0,
                indices: &mesh.1,
                normals: &mesh.0[s].1,
                colors: &[],
                uvs: &[],
            };
            triangles.push_mesh(&input, DVec3::ZERO, 2).unwrap();
            triangles.set.build();
            let mut compared = 0;
            for _ in 0..1500 {
                let o = rng.point(6.0);
                let d = (rng.point(2.0) - o * 0.3).normalize();
                let ray = Ray::new(o.into(), d.into(), time as f32);
                let mut tm = f32::INFINITY;
                let mut want = None;
                still.intersect(&ray, &mut tm, &mut want, &clips, &mut c);
                triangles
                    .set
                    .intersect(&ray, &mut tm, &mut want, &clips, &mut c);
                let mut tm2 = f32::INFINITY;
                let got = sweep.closest(&ray, &mut tm2, &clips, &mut c);
                assert_eq!(got.map(|h| h.t.to_bits()), want.map(|h| h.t.to_bits()));
                let (Some(got), Some(want)) = (got, want) else {
                    continue;
                };
                let a = sweep.surface(&got, &ray, true);
                let b = match want.kind {
                    Kind::Sphere => still.surface(&want, &ray, true),
                    _ => triangles.surface(&want, true),
                };
                let bits = |s: &Surface| {
                    let v = [s.p, s.p_error, s.ng, s.ns, s.lift];
                    let mut out: Vec<u32> = v
                        .iter()
                        .flat_map(|v| v.to_array())
                        .map(f32::to_bits)
                        .collect();
                    out.extend(s.uv.map(f32::to_bits));
                    out.push(s.material);
                    out
                };
                assert_eq!(bits(&a), bits(&b), "step {s}, {ray:?}");
                compared += 1;
            }
            assert!(compared > 150, "step {s}: {compared} hits compared");
        }
    }
}
