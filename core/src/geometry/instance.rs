//! Shared instances: one copy of a prototype's geometry (a [`Group`] in the prototype's own
//! object space, with its own BVHs: the bottom level) traced through every instance of it by
//! moving the ray into object space, and a top level ([`TopLevel`]) over the instances'
//! render-space bounds. Memory is one prototype plus a few hundred bytes per instance; the
//! picture is the flat (baked) one's within rounding, not bit for bit: a ray moved into object
//! space meets the same surface at values that differ in the last bits.
//!
//! Precision: the object-space ray origin is computed in f64 from the render-space origin plus
//! the world offset (a scene far from the world origin keeps object-space precision); the
//! direction goes through the inverse linear part in f32 and is normalised (the shape tests
//! assume unit directions), its length scaling distances between the two spaces. Hit points go
//! back in f64, their error bounds grown by the transform's own rounding; normals go back by
//! the inverse transpose.

use super::group::Group;
use super::{Clips, Counters, Hit, Kind, Surface, NO_INSTANCE};
use crate::bvh::top::TopLevel;
use crate::bvh::BoxRay;
use crate::math::{gamma, next_down, next_up, Aabb, DVec3, Vec3A};
use crate::motion::bounds::swept_bounds;
use crate::ray::Ray;
use glam::{DAffine3, Mat3, Vec3};
use luxon_formats::ObjectTracks;
use std::borrow::Cow;

/// One placed copy of a bottom level.
#[derive(Clone, Debug)]
pub struct Instance {
    /// Index into [`Instances::blases`].
    pub blas: u32,
    pub motion: Motion,
}

/// How an instance's bottom level sits in render space.
#[derive(Clone, Debug)]
pub enum Motion {
    /// The bottom level is stored in render space: rays are used as they are.
    Identity,
    /// Fixed by a transform.
    Fixed(Box<Placement>),
    /// Keyed and blurred: placed at each ray's own time by its tracks (index into
    /// [`Instances`]' tracks), so it moves during the shutter.
    Keyed(u32),
}

/// A fixed transform, ready for rays and hit points both ways.
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    /// Ray origins (world coordinates, f64) into object space.
    object_from_world: DAffine3,
    /// Hit points (object space) into render space: world minus the world offset.
    render_from_object: DAffine3,
    /// The inverse linear part: directions into object space.
    dir_to_object: Mat3,
    /// The linear part: vectors (and error bounds) back to render space.
    linear: Mat3,
    /// The inverse transpose of the linear part: normals back to render space.
    normal: Mat3,
    /// The transform mirrors (negative determinant): a triangle's geometric normal, which is
    /// the cross product of its edges, turns with it.
    mirror: bool,
    /// Render-space units per object-space unit, inverted (1 / cbrt|det|): texture
    /// coordinates per unit length change by it.
    uv_per_unit: f32,
}

impl Placement {
    /// The placement of `world_from_object` (invertible) in render space, whose origin is at
    /// `world_offset` in the world.
    pub fn new(world_from_object: DAffine3, world_offset: DVec3) -> Placement {
        let l = world_from_object.matrix3;
        let det = l.determinant();
        let inverse = l.inverse();
        Placement {
            object_from_world: world_from_object.inverse(),
            render_from_object: DAffine3::from_translation(-world_offset) * world_from_object,
            dir_to_object: inverse.as_mat3(),
            linear: l.as_mat3(),
            normal: inverse.transpose().as_mat3(),
            mirror: det < 0.0,
            uv_per_unit: (1.0 / det.abs().cbrt()) as f32,
        }
    }

    /// A render-space point of object space, in f64.
    fn render_point(&self, p: DVec3) -> DVec3 {
        self.render_from_object.transform_point3(p)
    }

    /// The linear part with its entries made positive: how errors grow through it.
    fn abs_linear(&self) -> Mat3 {
        let l = &self.linear;
        Mat3::from_cols(l.x_axis.abs(), l.y_axis.abs(), l.z_axis.abs())
    }

    /// The rounding error of moving an object point no larger than `far` per component to
    /// render space (pbrt's transformed interval point: three products and sums per row, the
    /// translation) and rounding it to f32.
    fn move_error(&self, far: Vec3) -> Vec3 {
        let moved = self.abs_linear() * far;
        let shift = self.render_from_object.translation.abs().as_vec3();
        gamma(4) * (moved + shift) + (moved + shift) * f32::EPSILON
    }

    /// A surface found in object space, in render space.
    fn surface_to_render(&self, s: Surface, kind: Kind) -> Surface {
        let p = self.render_point(s.p.as_dvec3()).as_vec3();
        // The object point's own error carried over, and the move's.
        let p_error = self.abs_linear() * Vec3::from(s.p_error) + self.move_error(s.p.abs().into());
        let normal = |n: Vec3A| Vec3A::from(self.normal * Vec3::from(n)).normalize_or_zero();
        let mut ng = normal(s.ng);
        if self.mirror && kind == Kind::Triangle {
            ng = -ng;
        }
        let mut ns = normal(s.ns);
        if ns.dot(ng) < 0.0 {
            ns = -ns;
        }
        Surface {
            p: Vec3A::from(p),
            p_error: Vec3A::from(p_error),
            ng,
            ns,
            uv: s.uv,
            uv_scale: s.uv_scale * self.uv_per_unit,
            material: s.material,
            color: s.color,
            lift: Vec3A::from(self.linear * Vec3::from(s.lift)),
        }
    }
}

/// The shared instances of a scene: the bottom levels, the instances and the top level.
#[derive(Default)]
pub struct Instances {
    /// Bottom levels (built, in their own space).
    pub blases: Vec<Group>,
    pub list: Vec<Instance>,
    top: TopLevel,
    /// The world position of render space's origin.
    world_offset: DVec3,
    /// Prototypes cannot clip: every bottom level is traced with no clip groups.
    no_clips: Clips,
    /// The tracks of the keyed instances ([`Motion::Keyed`]).
    tracks: Vec<ObjectTracks>,
    /// The frame being rendered: a ray at (frame-relative) time τ sees the keyed instances
    /// where their tracks put them at `frame_time + τ`.
    frame_time: f64,
    /// The shutter (open, close), frames from `frame_time`: what the keyed instances' boxes
    /// cover.
    shutter: (f64, f64),
    /// Names the tracks, world offset and frame time the keyed placements come from (new with
    /// every change of them): the key of each thread's cache of placements ([`LAST`]).
    id: u64,
}

/// A fresh [`Instances::id`].
fn next_id() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// Slots of each thread's cache of keyed placements (instance k uses slot k mod `SLOTS`).
const SLOTS: usize = 8;

/// A keyed placement as computed: (instances id, instance, time bits) and the placement
/// (`None`: singular at that time).
type Cached = (u64, u32, u64, Option<Placement>);

thread_local! {
    /// The last keyed placements this thread computed. A camera sample's rays (primary,
    /// shadow, reflected, and its shading) share one time, so each meets the same placements:
    /// the same values the same function gives for the same time, computed once.
    static LAST: std::cell::RefCell<[Option<Cached>; SLOTS]> =
        const { std::cell::RefCell::new([const { None }; SLOTS]) };
}

impl Instances {
    /// The instances of `blases` (each built) in `list`, with their top level.
    pub fn new(blases: Vec<Group>, list: Vec<Instance>, world_offset: DVec3) -> Instances {
        let mut out = Instances {
            blases,
            list,
            top: TopLevel::default(),
            world_offset,
            no_clips: Clips::default(),
            tracks: Vec::new(),
            frame_time: 0.0,
            shutter: (0.0, 0.0),
            id: next_id(),
        };
        let bounds: Vec<Aabb> = out.list.iter().map(|i| out.bounds(i)).collect();
        out.top = TopLevel::build(&bounds);
        out
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Whether some instance moves during the shutter (is placed per ray).
    pub fn has_keyed(&self) -> bool {
        !self.tracks.is_empty()
    }

    /// How many instances are placed per ray.
    pub fn keyed_count(&self) -> usize {
        self.tracks.len()
    }

    /// Instance `i` moves by `tracks`, placed at each ray's time from now on (its box is set
    /// by the next [`Instances::set_time`]).
    pub fn key(&mut self, i: u32, tracks: ObjectTracks) {
        self.list[i as usize].motion = Motion::Keyed(self.tracks.len() as u32);
        self.tracks.push(tracks);
        self.id = next_id();
    }

    /// A new bottom level (built, in object space) with one instance moving by `tracks`.
    pub fn push_keyed(&mut self, blas: Group, tracks: ObjectTracks) {
        self.blases.push(blas);
        self.list.push(Instance {
            blas: self.blases.len() as u32 - 1,
            motion: Motion::Keyed(self.tracks.len() as u32),
        });
        self.tracks.push(tracks);
        self.id = next_id();
    }

    /// Goes to frame time `t` with the shutter `(open, close)` (frames from `t`): the keyed
    /// instances' boxes cover their motion over `[t + open, t + close]`, and the top level is
    /// rebuilt over every box (a function of `t` alone).
    pub fn set_time(&mut self, t: f64, shutter: (f64, f64)) {
        self.frame_time = t;
        self.shutter = shutter;
        self.id = next_id();
        let bounds: Vec<Aabb> = self.list.iter().map(|i| self.bounds(i)).collect();
        self.top = TopLevel::build(&bounds);
    }

    /// Where instance `inst` is for a ray at frame-relative time `time`: `None` for the
    /// identity (and for a keyed transform that is singular at that time, which holds
    /// nothing).
    #[inline]
    fn placement<'a>(&'a self, inst: &'a Instance, time: f32) -> Option<Cow<'a, Placement>> {
        match &inst.motion {
            Motion::Identity => None,
            Motion::Fixed(p) => Some(Cow::Borrowed(p)),
            Motion::Keyed(k) => {
                let t = self.frame_time + f64::from(time);
                let key = (self.id, *k, t.to_bits());
                let slot = *k as usize % SLOTS;
                let cached = LAST.with_borrow(|last| match &last[slot] {
                    Some((id, i, bits, p)) if (*id, *i, *bits) == key => Some(p.clone()),
                    _ => None,
                });
                let p = cached.unwrap_or_else(|| {
                    let m = crate::motion::Placement::at(&self.tracks[*k as usize], t);
                    let det = m.world_from_object.matrix3.determinant();
                    let p = (det.is_finite() && det != 0.0)
                        .then(|| Placement::new(m.world_from_object, self.world_offset));
                    LAST.with_borrow_mut(|last| {
                        last[slot] = Some((key.0, key.1, key.2, p.clone()))
                    });
                    p
                });
                p.map(Cow::Owned)
            }
        }
    }

    /// Moves instances (`(index, world_from_object)`, each invertible) and rebuilds the top
    /// level over every instance's new bounds (a rebuild, never a refit: the tree is a
    /// function of the placements alone).
    pub fn place(&mut self, moved: &[(u32, DAffine3)]) {
        for &(i, m) in moved {
            let p = Placement::new(m, self.world_offset);
            self.list[i as usize].motion = Motion::Fixed(Box::new(p));
        }
        let bounds: Vec<Aabb> = self.list.iter().map(|i| self.bounds(i)).collect();
        self.top = TopLevel::build(&bounds);
    }

    /// An instance's render-space box: its bottom level's box (infinite with a plane) with
    /// its eight corners moved in f64, rounded outward and widened by a few ulps, so rays that
    /// the object-space test could hit after rounding are never culled.
    pub fn bounds(&self, inst: &Instance) -> Aabb {
        let g = &self.blases[inst.blas as usize];
        if !g.planes.planes.is_empty() {
            return Aabb::new(Vec3A::splat(f32::NEG_INFINITY), Vec3A::splat(f32::INFINITY));
        }
        let boxes = [
            (g.spheres.is_empty(), g.spheres.bounds()),
            (g.triangles.is_empty(), g.triangles.set.bounds()),
            (g.cones.is_empty(), g.cones.bounds()),
            (g.discs.is_empty(), g.discs.bounds()),
        ];
        let b = boxes
            .iter()
            .filter(|(empty, _)| !empty)
            .fold(Aabb::EMPTY, |a, (_, b)| a.union(*b));
        if b.is_empty() {
            return b;
        }
        let (lo, hi) = match &inst.motion {
            Motion::Identity => return b,
            Motion::Fixed(p) => {
                let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                for k in 0..8 {
                    let pick = |i: usize| if k >> i & 1 == 0 { b.min[i] } else { b.max[i] };
                    let c = DVec3::new(pick(0) as f64, pick(1) as f64, pick(2) as f64);
                    let q = p.render_point(c);
                    (lo, hi) = (lo.min(q), hi.max(q));
                }
                (lo, hi)
            }
            Motion::Keyed(k) => {
                let object = (b.min.as_dvec3(), b.max.as_dvec3());
                let (t0, t1) = (
                    self.frame_time + self.shutter.0,
                    self.frame_time + self.shutter.1,
                );
                let (lo, hi) = swept_bounds(&self.tracks[*k as usize], object, t0, t1);
                (lo - self.world_offset, hi - self.world_offset)
            }
        };
        let pad = (hi - lo + lo.abs().max(hi.abs())) * 1e-6;
        let (lo, hi) = ((lo - pad).as_vec3(), (hi + pad).as_vec3());
        Aabb::new(
            Vec3A::from(lo.to_array().map(next_down)),
            Vec3A::from(hi.to_array().map(next_up)),
        )
    }

    /// `ray` in instance `inst`'s object space, with its direction unit length, and how much
    /// longer distances are there (t_object = t_render · scale).
    #[inline]
    pub fn object_ray(&self, inst: &Instance, ray: &Ray) -> Option<(Ray, f32)> {
        if let Motion::Identity = inst.motion {
            return Some((*ray, 1.0));
        }
        let p = self.placement(inst, ray.time)?;
        Some(self.moved_ray(&p, ray))
    }

    #[inline]
    fn moved_ray(&self, p: &Placement, ray: &Ray) -> (Ray, f32) {
        let o = p
            .object_from_world
            .transform_point3(ray.origin.as_dvec3() + self.world_offset);
        let d = p.dir_to_object * Vec3::from(ray.dir);
        let scale = d.length();
        let dir = Vec3A::from(d / scale);
        (Ray::new(Vec3A::from(o.as_vec3()), dir, ray.time), scale)
    }

    /// The closest hit of instance `k` before `t_max` (render-space distances), its `t` in
    /// render space and `instance` set.
    #[inline]
    pub fn hit_in(&self, k: u32, ray: &Ray, t_max: f32, c: &mut Counters) -> Option<Hit> {
        let inst = &self.list[k as usize];
        let (r, scale) = self.object_ray(inst, ray)?;
        let mut t_object = t_max * scale;
        let blas = &self.blases[inst.blas as usize];
        let mut h = blas.closest(&r, &mut t_object, &self.no_clips, c)?;
        // The division can round up to `t_max`: such a hit is not closer.
        let t = h.t / scale;
        if t >= t_max || t.is_nan() {
            return None;
        }
        h.t = t;
        h.instance = k;
        Some(h)
    }

    /// The closest hit before `t_max` (which it lowers) among the instances, if any: into `hit`.
    /// `boxes` is `ray` prepared for box tests.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: &mut f32,
        hit: &mut Option<Hit>,
        c: &mut Counters,
    ) {
        let mut found = None;
        *t_max = self.top.intersect(boxes, *t_max, |k, t_max| {
            let h = self.hit_in(k, ray, t_max, c)?;
            found = Some(h);
            Some(h.t)
        });
        if found.is_some() {
            *hit = found;
        }
    }

    /// Calls `on_hit(material, crossings)` for what the ray crosses in (0, t_max) in the
    /// instances until it returns true; returns whether it did.
    #[inline]
    pub fn any(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: f32,
        c: &mut Counters,
        on_hit: &mut impl FnMut(u32, u32) -> bool,
    ) -> bool {
        self.top.any(boxes, t_max, |k| {
            let inst = &self.list[k as usize];
            let Some((r, scale)) = self.object_ray(inst, ray) else {
                return false;
            };
            let blas = &self.blases[inst.blas as usize];
            blas.any(&r, t_max * scale, &self.no_clips, c, &mut *on_hit)
        })
    }

    /// The surface at a hit in an instance (`hit.instance`), in render space.
    pub fn surface(&self, hit: &Hit, ray: &Ray, textured: bool) -> Surface {
        let inst = &self.list[hit.instance as usize];
        let blas = &self.blases[inst.blas as usize];
        let mut h = *hit;
        h.instance = NO_INSTANCE;
        // The placement the hit was found through (a keyed one at the ray's time: the same
        // bits, the same function of the same time).
        let Some(p) = self.placement(inst, ray.time) else {
            return blas.surface(&h, ray, textured);
        };
        let (r, scale) = self.moved_ray(&p, ray);
        h.t = hit.t * scale;
        match p {
            // A triangle is shaded as its moved copy (the corners and vertex normals moved),
            // as baking would store it: interpolating moved normals is not moving the
            // interpolated one under a stretch, and a mirror turns the edges' cross product.
            p if hit.kind == Kind::Triangle => {
                let point = |v: Vec3| p.render_point(v.as_dvec3()).as_vec3();
                let normal = |n: Vec3| (p.normal * n).normalize_or_zero();
                let mut s = (blas.triangles).surface_moved(&h, textured, &point, &normal);
                // The object-space triangle the rays meet is the moved one within the
                // rounding of the move.
                let tri = blas.triangles.set.data[hit.index as usize].v;
                let far = tri.iter().fold(Vec3::ZERO, |m, v| m.max(v.abs()));
                s.p_error += Vec3A::from(p.move_error(far));
                s
            }
            p => p.surface_to_render(blas.surface(&h, &r, textured), hit.kind),
        }
    }

    /// Bytes held: the bottom levels' primitives and BVHs, the instances with their
    /// placements, and the top level.
    pub fn memory_bytes(&self) -> u64 {
        let blases: u64 = self.blases.iter().map(Group::memory_bytes).sum();
        let placements = self
            .list
            .iter()
            .filter(|i| matches!(i.motion, Motion::Fixed(_)))
            .count()
            * std::mem::size_of::<Placement>();
        let list = self.list.capacity() * std::mem::size_of::<Instance>();
        blases + (placements + list) as u64 + self.top.memory_bytes()
    }
}

/// The two levels against brute force: random prototypes (spheres, triangles, cones), random
/// affine instances and random rays; the top level must find the very hit (same `t` bits, same
/// instance and primitive) that testing every primitive of every instance through the same
/// object-space ray finds, and any-hit queries must agree with it.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::cone::Cone;
    use crate::geometry::set::Shape;
    use crate::geometry::sphere::Sphere;
    use crate::geometry::triangle::{Triangle, NO_ATTR};
    use glam::DMat3;
    use proptest::prelude::*;

    fn v3() -> impl Strategy<Value = Vec3> {
        (-2.0f32..2.0, -2.0f32..2.0, -2.0f32..2.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    type Parts = (Vec<Sphere>, Vec<Triangle>, Vec<Cone>);

    /// A prototype's parts: a few spheres, triangles and cones near its origin.
    fn prototype() -> impl Strategy<Value = Parts> {
        let sphere = (v3(), 0.05f32..0.8).prop_map(|(center, radius)| Sphere { center, radius });
        let triangle = (v3(), v3(), v3()).prop_map(|(a, b, c)| Triangle {
            v: [a, b, c],
            attr: NO_ATTR,
        });
        let cone = (v3(), v3(), 0.05f32..0.5, 0.0f32..0.5).prop_map(|(base, apex, rb, ra)| Cone {
            base,
            base_radius: rb,
            apex: base + apex + Vec3::splat(0.1),
            apex_radius: ra,
        });
        use proptest::collection::vec;
        (vec(sphere, 0..6), vec(triangle, 0..6), vec(cone, 0..6))
    }

    /// The bottom level of `parts`, built.
    fn group((s, t, c): &Parts) -> Group {
        let mut g = Group::default();
        for (i, x) in s.iter().enumerate() {
            g.spheres.push(*x, i as u32);
        }
        for (i, x) in t.iter().enumerate() {
            g.triangles.set.push(*x, i as u32);
        }
        for (i, x) in c.iter().enumerate() {
            g.cones.push(*x, i as u32);
        }
        g.spheres.build();
        g.triangles.set.build();
        g.cones.build();
        g
    }

    /// An invertible affine map: any linear part not too close to singular, any translation.
    fn affine() -> impl Strategy<Value = DAffine3> {
        let col = || (-1.5f64..1.5, -1.5f64..1.5, -1.5f64..1.5);
        (
            col(),
            col(),
            col(),
            (-8.0f64..8.0, -8.0f64..8.0, -8.0f64..8.0),
        )
            .prop_map(|(x, y, z, t)| {
                let m = DMat3::from_cols(x.into(), y.into(), z.into());
                DAffine3::from_mat3_translation(m, t.into())
            })
            .prop_filter("invertible", |a| a.matrix3.determinant().abs() > 0.05)
    }

    fn ray() -> impl Strategy<Value = Ray> {
        let dir = v3().prop_filter("a direction", |d| d.length() > 0.1);
        (v3(), dir)
            .prop_map(|(o, d)| Ray::new(Vec3A::from(o * 5.0), Vec3A::from(d.normalize()), 0.0))
    }

    /// (t, instance, kind, primitive) of the closest hit, testing everything, and whether
    /// another primitive is hit at that very `t` (then either may be reported: two identity
    /// instances of one prototype tie exactly).
    fn brute(inst: &Instances, ray: &Ray) -> Option<((u32, u32, Kind, u64), bool)> {
        let mut best: Option<(f32, u32, Kind, u64)> = None;
        let mut tied = false;
        for (k, i) in inst.list.iter().enumerate() {
            let Some((r, scale)) = inst.object_ray(i, ray) else {
                continue;
            };
            let g = &inst.blases[i.blas as usize];
            let mut consider = |t: Option<(f32, f32, f32)>, kind: Kind, p: usize| {
                let Some((t, _, _)) = t else { return };
                let t = t / scale;
                match best {
                    Some(b) if t == b.0 => tied = true,
                    Some(b) if t > b.0 => {}
                    _ => (best, tied) = (Some((t, k as u32, kind, p as u64)), false),
                }
            };
            for (p, s) in g.spheres.data.iter().enumerate() {
                consider(s.hit(&r, &Sphere::prep(&r), f32::INFINITY), Kind::Sphere, p);
            }
            for (p, s) in g.triangles.set.data.iter().enumerate() {
                consider(
                    s.hit(&r, &Triangle::prep(&r), f32::INFINITY),
                    Kind::Triangle,
                    p,
                );
            }
            for (p, s) in g.cones.data.iter().enumerate() {
                consider(s.hit(&r, &Cone::prep(&r), f32::INFINITY), Kind::Cone, p);
            }
        }
        best.map(|(t, k, kind, p)| ((t.to_bits(), k, kind, p), tied))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn the_top_level_finds_what_brute_force_finds(
            protos in proptest::collection::vec(prototype(), 1..4),
            placed in proptest::collection::vec((0usize..4, affine(), any::<bool>()), 1..50),
            rays in proptest::collection::vec((ray(), 0.5f32..30.0), 40),
        ) {
            let n = protos.len();
            let offset = DVec3::new(3.0, -2.0, 1.5);
            let list = placed
                .iter()
                .map(|(b, m, identity)| Instance {
                    blas: (b % n) as u32,
                    motion: if *identity {
                        Motion::Identity
                    } else {
                        Motion::Fixed(Box::new(Placement::new(*m, offset)))
                    },
                })
                .collect();
            let inst = Instances::new(protos.iter().map(group).collect(), list, offset);
            let mut c = Counters::default();
            for (ray, reach) in &rays {
                let mut t_max = f32::INFINITY;
                let mut hit = None;
                let boxes = BoxRay::new(ray.origin, ray.dir);
                inst.intersect(ray, &boxes, &mut t_max, &mut hit, &mut c);
                let got = hit.map(|h| (h.t.to_bits(), h.instance, h.kind, h.index));
                let want = brute(&inst, ray);
                match (got, want) {
                    (Some(g), Some((w, true))) => prop_assert_eq!(g.0, w.0),
                    (g, w) => prop_assert_eq!(g, w.map(|w| w.0)),
                }
                let blocked = inst.any(ray, &boxes, *reach, &mut c, &mut |_, _| true);
                let want = want.is_some_and(|(b, _)| f32::from_bits(b.0) < *reach);
                prop_assert_eq!(blocked, want);
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Moving instances (random keyed tracks) and rays at random times of the shutter:
        /// the top level over the swept boxes finds what testing every primitive of every
        /// instance, placed at the ray's time, finds.
        #[test]
        fn moving_instances_are_found_at_the_rays_time(
            protos in proptest::collection::vec(prototype(), 1..3),
            placed in proptest::collection::vec(
                (0usize..3, crate::motion::bounds::tests::tracks(), any::<bool>()), 1..16),
            frame in 0u32..8,
            shutter in prop_oneof![Just((0.0, 1.0)), Just((-0.25, 0.25)), Just((-2.0, 0.0))],
            rays in proptest::collection::vec((ray(), 0.0f32..1.0, 0.5f32..30.0), 60),
        ) {
            let n = protos.len();
            let offset = DVec3::new(3.0, -2.0, 1.5);
            let mut inst = Instances::new(
                protos.iter().map(group).collect(),
                placed.iter().map(|(b, _, _)| Instance { blas: (b % n) as u32, motion: Motion::Identity }).collect(),
                offset,
            );
            for (k, (_, tracks, keyed)) in placed.iter().enumerate() {
                if *keyed {
                    inst.key(k as u32, tracks.clone());
                }
            }
            inst.set_time(f64::from(frame), shutter);
            let mut c = Counters::default();
            for (ray, u, reach) in &rays {
                let time = shutter.0 as f32 + u * (shutter.1 - shutter.0) as f32;
                let ray = Ray::new(ray.origin, ray.dir, time);
                let mut t_max = f32::INFINITY;
                let mut hit = None;
                let boxes = BoxRay::new(ray.origin, ray.dir);
                inst.intersect(&ray, &boxes, &mut t_max, &mut hit, &mut c);
                let got = hit.map(|h| (h.t.to_bits(), h.instance, h.kind, h.index));
                let want = brute(&inst, &ray);
                match (got, want) {
                    (Some(g), Some((w, true))) => prop_assert_eq!(g.0, w.0),
                    (g, w) => prop_assert_eq!(g, w.map(|w| w.0)),
                }
                let blocked = inst.any(&ray, &boxes, *reach, &mut c, &mut |_, _| true);
                let want = want.is_some_and(|(b, _)| f32::from_bits(b.0) < *reach);
                prop_assert_eq!(blocked, want);
            }
        }
    }

    /// A hit point found through a transform lies on the moved surface, with its normal.
    #[test]
    fn surfaces_come_back_to_render_space() {
        let mut g = Group::default();
        g.spheres.push(
            Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            0,
        );
        g.spheres.build();
        // Stretched along x by 3 and moved to x = 100 in the world; render space starts at 90.
        let m = DAffine3::from_scale_rotation_translation(
            glam::DVec3::new(3.0, 1.0, 1.0),
            glam::DQuat::IDENTITY,
            glam::DVec3::new(100.0, 0.0, 0.0),
        );
        let offset = DVec3::new(90.0, 0.0, 0.0);
        let list = vec![Instance {
            blas: 0,
            motion: Motion::Fixed(Box::new(Placement::new(m, offset))),
        }];
        let inst = Instances::new(vec![g], list, offset);
        // Along -x from render x = 20 (world 110): the ellipsoid's end at world 103.
        let ray = Ray::new(Vec3A::new(20.0, 0.0, 0.0), -Vec3A::X, 0.0);
        let (mut t, mut hit) = (f32::INFINITY, None);
        let mut c = Counters::default();
        inst.intersect(
            &ray,
            &BoxRay::new(ray.origin, ray.dir),
            &mut t,
            &mut hit,
            &mut c,
        );
        let hit = hit.expect("a hit");
        assert!((hit.t - 7.0).abs() < 1e-5, "t = {}", hit.t);
        let s = inst.surface(&hit, &ray, false);
        assert!(
            (s.p - Vec3A::new(13.0, 0.0, 0.0)).length() < 1e-5,
            "{:?}",
            s.p
        );
        assert!((s.ng - Vec3A::X).length() < 1e-6, "{:?}", s.ng);
        assert!(s.p_error.max_element() > 0.0 && s.p_error.max_element() < 1e-4);
    }
}
