//! Property tests of every native intersection routine, through the same calls a render makes
//! (`intersect`, then `surface`, then `ray::spawn`):
//!
//! - the hit point lies on the surface, within a bound relative to its magnitude;
//! - the geometric and shading normals are unit length;
//! - a ray spawned at the hit point and sent away from the surface (into the outward
//!   hemisphere of a convex shape, either side of a flat one) does not hit it again.
//!
//! Shapes and rays span scales from 1e-3 to 1e4 and positions up to 1e4 away from the origin.

use super::cone::Cone;
use super::disc::Disc;
use super::plane::Planes;
use super::set::{Set, Shape};
use super::sphere::Sphere;
use super::triangle::{MeshInput, Triangles};
use super::{Clips, Counters, Hit, Surface};
use crate::math::{DVec3, Vec3A};
use crate::ray::{spawn, Ray};
use glam::Vec3;
use proptest::prelude::*;

/// Relative tolerance for "on the surface": f32 carries 2^-24; points are re-projected or
/// interpolated with a few roundings, so 2^-16 of the magnitude is a generous, meaningful bound.
const ON_SURFACE: f64 = 1.0 / 65536.0;

/// 512 cases, or `PROPTEST_CASES` (which `with_cases` would override) for longer runs.
fn cases() -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES").ok();
    ProptestConfig::with_cases(cases.and_then(|v| v.parse().ok()).unwrap_or(512))
}

fn unit() -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("not too short", |(x, y, z)| x * x + y * y + z * z > 0.01)
        .prop_map(|(x, y, z)| Vec3A::new(x, y, z).normalize())
}

/// A length scale and a far-away position: the scene's size and where it sits.
fn placement() -> impl Strategy<Value = (f32, Vec3A)> {
    (-3i32..=4, prop_oneof![Just(0.0f32), 1.0f32..1e4], unit()).prop_map(|(e, far, dir)| {
        let scale = 10f32.powi(e);
        (scale, far * dir)
    })
}

/// Whether a shape of size `scale` at `pos` is resolved by f32 coordinates well enough that a
/// ray aimed at its inside (with the aim point rounded to f32) must hit it.
fn resolved(scale: f32, pos: Vec3A) -> bool {
    scale > 1e-3 * pos.abs().max_element()
}

/// A ray from a point about `4 * scale` from `target`, aimed at `target + jitter`.
fn ray_at(target: Vec3A, scale: f32, from: Vec3A, jitter: Vec3A) -> Ray {
    let o = target + 4.0 * scale * from;
    let aim = target + jitter * scale;
    Ray::new(o, (aim - o).normalize(), 0.0)
}

/// Closest hit of a one-primitive set.
fn first_hit<S: Shape>(set: &Set<S>, ray: &Ray) -> Option<Hit> {
    let (mut t, mut hit) = (f32::INFINITY, None);
    set.intersect(
        ray,
        &mut t,
        &mut hit,
        &Clips::default(),
        &mut Counters::default(),
    );
    hit
}

/// A direction in the hemisphere around `n` (or its opposite), not grazing: what a reflected
/// or refracted ray leaving the surface looks like.
fn away(n: Vec3A, d: Vec3A, side: f32) -> Vec3A {
    let n = n * side;
    let d = if d.dot(n) < 0.0 {
        d - 2.0 * d.dot(n) * n
    } else {
        d
    };
    (d + 0.05 * n).normalize()
}

fn check_normals(s: &Surface) -> Result<(), TestCaseError> {
    prop_assert!(
        (s.ng.length() - 1.0).abs() < 1e-5,
        "|ng| = {}",
        s.ng.length()
    );
    prop_assert!(
        (s.ns.length() - 1.0).abs() < 1e-5,
        "|ns| = {}",
        s.ns.length()
    );
    prop_assert!(s.p.is_finite() && s.p_error.is_finite());
    Ok(())
}

/// Checks the three properties of a hit on a one-primitive set. `distance(p)`: distance of a
/// point from the surface (f64); `size`: the shape's magnitude (added to |p| for the bound);
/// `convex`: leave only into the outward hemisphere of the normal (else either side).
// One place for the three properties; the arguments are what differs between the shapes.
#[allow(clippy::too_many_arguments)]
fn check_hit<S: Shape>(
    set: &Set<S>,
    ray: &Ray,
    surface: impl Fn(&Hit, &Ray) -> Surface,
    distance: impl Fn(DVec3) -> f64,
    size: f64,
    convex: bool,
    leave: Vec3A,
    must_hit: bool,
) -> Result<(), TestCaseError> {
    let Some(hit) = first_hit(set, ray) else {
        prop_assert!(!must_hit, "the ray missed");
        return Ok(());
    };
    let s = surface(&hit, ray);
    check_normals(&s)?;
    let p = s.p.as_dvec3();
    let bound = ON_SURFACE * (p.abs().max_element() + size);
    let dist = distance(p);
    prop_assert!(
        dist <= bound,
        "off the surface by {dist} (bound {bound}) at {p}"
    );
    for side in [1.0, -1.0] {
        if convex && side < 0.0 {
            continue;
        }
        let dir = away(s.ng, leave, side);
        let r = spawn(s.p, s.p_error, s.ng, dir, 0.0);
        let again = first_hit(set, &r);
        prop_assert!(
            again.is_none(),
            "a ray leaving {p} along {dir} hit the surface again at t = {:?}",
            again.map(|h| h.t)
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(cases())]

    #[test]
    fn sphere((scale, pos) in placement(), r in 0.1f32..2.0, from in unit(), jitter in unit(),
              leave in unit(), k in 0.0f32..1.2) {
        let radius = r * scale;
        let mut set = Set::<Sphere>::default();
        set.push(Sphere { center: pos.into(), radius }, 0);
        set.build();
        let ray = ray_at(pos, scale, from * (r + 1.0), jitter * k * r);
        let (c, rd) = (pos.as_dvec3(), radius as f64);
        check_hit(&set, &ray, |h, r| set.surface(h, r, true), |p| ((p - c).length() - rd).abs(),
                  rd + c.abs().max_element(), true, leave, k < 0.9 && resolved(scale, pos))?;
    }

    #[test]
    fn triangle((scale, pos) in placement(), a in unit(), b in unit(), c in unit(),
                from in unit(), w in (0.0f32..1.0, 0.0f32..1.0), leave in unit()) {
        let v = [pos + a * scale, pos + b * scale, pos + c * scale];
        let e1 = (v[1] - v[0]).as_dvec3();
        let e2 = (v[2] - v[0]).as_dvec3();
        let n = e1.cross(e2);
        prop_assume!(n.length() > 1e-3 * e1.length() * e2.length());
        let positions: Vec<f64> = v.iter().flat_map(|p| p.to_array().map(f64::from)).collect();
        let mut tris = Triangles::default();
        let mesh = MeshInput {
            positions: &positions, indices: &[0, 1, 2], normals: &[], colors: &[], uvs: &[],
        };
        prop_assert_eq!(tris.push_mesh(&mesh, DVec3::ZERO, 0).unwrap(), 0);
        tris.set.build();
        // Aim inside the triangle (barycentric weights folded into the triangle).
        let (mut u, mut t) = w;
        if u + t > 1.0 { (u, t) = (1.0 - u, 1.0 - t); }
        let target = v[0] + u * (v[1] - v[0]) + t * (v[2] - v[0]);
        let ray = ray_at(target, scale, from, Vec3A::ZERO);
        let (p0, nn) = (v[0].as_dvec3(), n.normalize());
        let size = v.iter().map(|p| p.abs().max_element()).fold(0.0, f32::max) as f64;
        let inside = u > 0.05 && t > 0.05 && u + t < 0.95 && ray.dir.as_dvec3().dot(nn).abs() > 0.05
            && resolved(scale, pos);
        check_hit(&tris.set, &ray, |h, _| tris.surface(h, true), |p| (p - p0).dot(nn).abs(), size,
                  false, leave, inside)?;
    }

    #[test]
    fn cone_and_cylinder((scale, pos) in placement(), axis in unit(), len in 0.2f32..3.0,
                         rb in 0.0f32..1.5, ra in 0.0f32..1.5, cylinder in any::<bool>(),
                         from in unit(), s in 0.0f32..1.0, around in unit(), leave in unit()) {
        prop_assume!(rb + ra > 0.1);
        let ra = if cylinder { rb.max(0.1) } else { ra };
        let rb = if cylinder { ra } else { rb };
        let cone = Cone {
            base: pos.into(), base_radius: rb * scale,
            apex: (pos + axis * len * scale).into(), apex_radius: ra * scale,
        };
        let mut set = Set::<Cone>::default();
        set.push(cone, 0);
        set.build();
        // Aim at a point of the surface: along the axis at s, out by the radius there.
        let q = (around - around.dot(axis) * axis).normalize_or_zero();
        prop_assume!(q != Vec3A::ZERO);
        let target = pos + axis * (s * len * scale) + q * ((rb + s * (ra - rb)) * scale);
        let ray = ray_at(target, scale, from, Vec3A::ZERO);
        let (b, a) = (cone.base.as_dvec3(), cone.apex.as_dvec3());
        let (rbd, rad) = (cone.base_radius as f64, cone.apex_radius as f64);
        let distance = |p: DVec3| {
            let h = (a - b).length();
            let w = (a - b) / h;
            let along = (p - b).dot(w);
            let radial = ((p - b) - along * w).length();
            let r = rbd + (rad - rbd) * along / h;
            // Distance to the slanted line, measured across it.
            (radial - r).abs() * h / (h * h + (rad - rbd).powi(2)).sqrt()
        };
        let size = (rbd.max(rad) + b.abs().max_element()).max(a.abs().max_element());
        check_hit(&set, &ray, |h, r| set.surface(h, r, true), distance, size, true, leave, false)?;
    }

    #[test]
    fn disc_and_ring((scale, pos) in placement(), n in unit(), inner in 0.0f32..0.8,
                     width in 0.1f32..2.0, from in unit(), jitter in unit(), leave in unit()) {
        let disc = Disc {
            center: pos.into(), normal: n.into(),
            inner: inner * scale, outer: (inner + width) * scale,
        };
        let mut set = Set::<Disc>::default();
        set.push(disc, 0);
        set.build();
        let ray = ray_at(pos, scale, from, jitter * (inner + width));
        let c = pos.as_dvec3();
        let nd = Vec3::from(n).as_dvec3();
        check_hit(&set, &ray, |h, r| set.surface(h, r, true), |p| (p - c).dot(nd).abs(),
                  c.abs().max_element() + (disc.outer as f64), false, leave, false)?;
    }

    #[test]
    fn plane((scale, pos) in placement(), n in unit(), from in unit(), jitter in unit(),
             leave in unit(), len in 0.5f64..100.0) {
        let mut planes = Planes::default();
        let nn = n.as_dvec3() * len;
        let p = pos.as_dvec3();
        planes.push_world(0, [p.x, p.y, p.z, nn.x, nn.y, nn.z], DVec3::ZERO, 0).unwrap();
        let ray = ray_at(pos, scale, from, jitter);
        let hit_of = |r: &Ray| {
            let (mut t, mut hit) = (f32::INFINITY, None);
            planes.intersect(r, &mut t, &mut hit, &Clips::default(), &mut Counters::default());
            hit
        };
        let Some(hit) = hit_of(&ray) else { return Ok(()); };
        let s = planes.surface(&hit, &ray, true);
        check_normals(&s)?;
        let pn = planes.planes[0].normal.as_dvec3();
        let point = planes.planes[0].point.as_dvec3();
        let q = s.p.as_dvec3();
        let bound = ON_SURFACE * (q.abs().max_element() + point.abs().max_element());
        prop_assert!((q - point).dot(pn).abs() <= bound, "off the plane at {q}");
        for side in [1.0, -1.0] {
            let dir = away(s.ng, leave, side);
            let again = hit_of(&spawn(s.p, s.p_error, s.ng, dir, 0.0));
            prop_assert!(again.is_none(), "left {q} along {dir} and hit the plane again");
        }
    }
}

/// Array objects: spheres and triangles read from arrays, moved and refitted, find exactly the
/// closest hit brute force finds (every element tested) for random rays.
mod arrays {
    use super::super::array_set::{ArraySet, MeshReader, RadiusRead, Reader, SphereReader};
    use super::super::set::Shape;
    use super::super::Counters;
    use crate::arrays::{Array, Pins, SharedVec};
    use crate::bvh::BoxRay;
    use crate::math::{DVec3, Vec3A};
    use crate::ray::Ray;
    use proptest::prelude::*;

    fn point() -> impl Strategy<Value = [f64; 3]> {
        [-5.0f64..5.0, -5.0f64..5.0, -5.0f64..5.0]
    }

    /// A closest hit's distance and element.
    type Found = Option<(f32, u64)>;

    /// The closest hit's (t, element) in the set, and by testing every element.
    fn both<R: Reader>(set: &ArraySet<R>, pins: &Pins, ray: &Ray) -> (Found, Found) {
        let mut hit = None;
        let mut t_max = f32::INFINITY;
        let boxes = BoxRay::new(ray.origin, ray.dir);
        set.intersect(
            pins,
            ray,
            &boxes,
            &mut t_max,
            &mut hit,
            &mut Counters::default(),
            1,
        );
        let found = hit.map(|h| (h.t, h.index));
        let prep = R::Shape::prep(ray);
        let mut brute: Found = None;
        for i in 0..set.reader.len(pins) {
            let Some(s) = set.reader.get(pins, i) else {
                continue;
            };
            if let Some((t, _, _)) = s.hit(ray, &prep, brute.map_or(f32::INFINITY, |b| b.0)) {
                brute = Some((t, i as u64));
            }
        }
        (found, brute)
    }

    proptest! {
        #![proptest_config(super::cases())]

        #[test]
        fn refitted_spheres_and_triangles_find_what_brute_force_finds(
            start in prop::collection::vec(point(), 3..120),
            steps in prop::collection::vec(point(), 120),
            rays in prop::collection::vec((point(), super::unit()), 20),
        ) {
            // Whole triangles: every three points make one.
            let n = start.len() / 3 * 3;
            let centers = SharedVec::new(start[..n].to_vec());
            let arrays = [Array::shared(&centers)];
            let offset = DVec3::new(0.5, -0.25, 1.0);
            let spheres = SphereReader { radius: RadiusRead::Const(0.4), colors: None, offset };
            let mesh = MeshReader { indices: None, normals: None, colors: None, uvs: None, offset };
            let (mut s, mut m) = {
                let pins = Pins::new(&arrays).unwrap();
                let s = ArraySet::build(spheres, &pins, 0).unwrap();
                let m = ArraySet::build(mesh, &pins, 0).unwrap();
                (s, m)
            };
            // Every point moves (up to 1.5 units): the trees are refitted, not rebuilt.
            for (p, d) in centers.write().iter_mut().zip(&steps) {
                for k in 0..3 {
                    p[k] += d[k] * 0.3;
                }
            }
            let pins = Pins::new(&arrays).unwrap();
            s.refit(&pins).unwrap();
            m.refit(&pins).unwrap();
            prop_assert_eq!(m.len(), n / 3);
            for (o, d) in &rays {
                let ray = Ray::new(Vec3A::from((DVec3::from(*o) * 1.5).as_vec3()), *d, 0.0);
                let (found, brute) = both(&s, &pins, &ray);
                prop_assert_eq!(found, brute);
                let (found, brute) = both(&m, &pins, &ray);
                prop_assert_eq!(found.map(|f| f.0), brute.map(|b| b.0));
            }
        }
    }
}
