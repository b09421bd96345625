//! Spheres: 16 bytes each (centre + radius) plus a material index, in their own BVH.

use super::set::{Set, Shape, BLOCK};
use super::{material_of, Hit, Kind, Surface};
use crate::math::{gamma, Aabb, DVec3, Vec3A};
use crate::ray::Ray;
use glam::Vec3;

/// A sphere: 16 bytes (the molecular case stores millions).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}

pub type Spheres = Set<Sphere>;

/// Fills the lanes of a block past the last sphere (masked off).
const PAD: Sphere = Sphere {
    center: Vec3::ZERO,
    radius: 1.0,
};

/// The nearest root of a unit-direction ray against a sphere in (t_min, t_max), and how many
/// roots lie in (t_min, t_max). Solved in sphere-centred coordinates with the
/// cancellation-free form of the quadratic (Haines et al., Ray Tracing Gems ch. 7). A cheap f32
/// test rejects most misses (the line clear of the sphere); the rest are solved in f64 so that
/// a huge sphere seen from close by (an Earth-sized ground) keeps its precision: in f32,
/// |f|² − r² loses every digit when |f| ≈ r ≈ 1e6.
#[inline(always)]
pub fn intersect_sphere(
    s: &Sphere,
    o: Vec3A,
    d: Vec3A,
    t_min: f32,
    t_max: f32,
) -> (Option<f32>, u32) {
    intersect_sphere_in(s, o, d, t_min, t_max, false)
}

/// [`intersect_sphere`] for a sphere among `dense` ones ([`Sphere::dense`]), where a second
/// f32 test, the chord wholly outside (t_min, t_max) (`chord_outside`), turns away the
/// spheres behind the closest hit or behind the ray's origin before the f64 solve. The answer
/// is the same either way. Elsewhere it rarely rejects and only costs: run on every set,
/// balls4 took 1.6 % more instructions and ~4.6 % more time.
#[inline(always)]
pub fn intersect_sphere_in(
    s: &Sphere,
    o: Vec3A,
    d: Vec3A,
    t_min: f32,
    t_max: f32,
    dense: bool,
) -> (Option<f32>, u32) {
    let c = Vec3A::from(s.center);
    let r = s.radius;
    let f = o - c;
    let fd = f.dot(d);
    let l = f - fd * d;
    let r2 = r * r;
    let h = r2 - l.dot(l);
    if h < -r2 * 1e-4 {
        return (None, 0);
    }
    if dense && chord_outside(-fd, h, r, t_min, t_max) {
        return (None, 0);
    }
    solve_sphere(c, r, o, d, t_min, t_max)
}

/// Whether the ray's chord through the sphere, [tc - √h, tc + √h] (tc: the centre's distance
/// along the unit ray, h: r² less the line's squared distance from the centre, both in f32),
/// lies wholly past `t_max` or wholly before `t_min` (for `t_min <= t_max`), by margins that
/// make [`solve_sphere`]'s f64 roots round outside (t_min, t_max) whenever this says so:
/// `solve_sphere` would answer no, so it need not run. Overlapping spheres (a seashell, a
/// space-filling molecule) make many such tests: boxes entered before the closest hit whose
/// spheres lie behind it, and, for rays leaving a surface, the neighbours whose boxes hold the
/// ray's origin.
///
/// The f64 roots lie within |d|² - 1 times tc (about 1e-7 for a unit direction) of the exact
/// chord's ends. `tc` and `h` are within ~5e-7 (|tc| + 2r) and ~2e-6 r (|tc| + 2r) of their
/// exact values once the line meets the sphere (|l| <= 1.0001 r, so |f| <= |tc| + 1.0001 r);
/// the margins `e` and `e r` are 5 to 20 times those.
#[inline(always)]
fn chord_outside(tc: f32, h: f32, r: f32, t_min: f32, t_max: f32) -> bool {
    let e = 1e-5 * (tc.abs() + (r + r));
    // The gap between the chord's centre and the end of (t_min, t_max) on its side: the
    // chord lies past t_max only if its centre does, and before t_min only if its centre
    // does. An infinite t_max never has the centre past it.
    let gap = if tc > t_max { tc - t_max } else { t_min - tc } - e;
    gap > 0.0 && gap * gap > h + e * r
}

/// [`intersect_sphere`] past its f32 rejection (which `scene::few` also makes four spheres
/// at a time): the roots in f64.
#[inline(always)]
pub fn solve_sphere(
    c: Vec3A,
    r: f32,
    o: Vec3A,
    d: Vec3A,
    t_min: f32,
    t_max: f32,
) -> (Option<f32>, u32) {
    let f = o.as_dvec3() - c.as_dvec3();
    let d = d.as_dvec3();
    let r = r as f64;
    let b = -f.dot(d);
    let cc = f.dot(f) - r * r;
    // Outside (cc > 0) and moving away (b < 0): q < 0, so both roots below are negative and
    // neither lies past t_min >= 0. Answered first, without the discriminant, the square
    // root and the division (a shadow ray leaving the sphere it starts on).
    if cc > 0.0 && b < 0.0 && t_min >= 0.0 {
        return (None, 0);
    }
    let l = f + b * d;
    let disc = r * r - l.dot(l);
    if disc < 0.0 {
        return (None, 0);
    }
    let q = b + disc.sqrt().copysign(b);
    if q == 0.0 {
        return (None, 0);
    }
    let (mut t0, mut t1) = ((cc / q) as f32, q as f32);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    let in0 = t0 > t_min && t0 < t_max;
    let in1 = t1 > t_min && t1 < t_max;
    let n = u32::from(in0) + u32::from(in1);
    if in0 {
        (Some(t0), n)
    } else if in1 {
        (Some(t1), n)
    } else {
        (None, 0)
    }
}

impl Sphere {
    /// Sphere `i` of a batch given in world coordinates (x, y, z, radius), checked, in render
    /// space (`offset`: the world position of its origin).
    pub fn from_world(i: usize, s: [f64; 4], offset: DVec3) -> Result<Sphere, String> {
        if s.iter().any(|x| !x.is_finite()) {
            return Err(format!("sphere {i} has a non-finite value {s:?}"));
        }
        if s[3] <= 0.0 {
            return Err(format!(
                "sphere {i} has radius {}; expected a radius > 0",
                s[3]
            ));
        }
        Ok(Sphere {
            center: (DVec3::new(s[0], s[1], s[2]) - offset).as_vec3(),
            radius: s[3] as f32,
        })
    }
}

impl Shape for Sphere {
    const KIND: Kind = Kind::Sphere;
    type Prep = ();
    const DENSE_TESTS: bool = true;
    fn prep(_: &Ray) {}

    /// Spheres that overlap deeply and many at a time (one's centre inside the other): in leaf
    /// order (spatial neighbours), each overlaps at least three of the next seven on average,
    /// in a sample of every 16th. A seashell's spiral (6.9 of 7) or spheres stacked at the same
    /// points (Tachyon's gridtest.dat: 7.0) are dense; a space-filling DNA (dna.dat: 0.7) is not,
    /// nor are spheres that only touch (the sphereflake: 0). Dense sets' rays meet many spheres'
    /// boxes before their closest hit, and leave surfaces inside many boxes.
    fn dense(data: &[Sphere]) -> bool {
        let deep = |a: &Sphere, b: &Sphere| {
            let reach = a.radius.max(b.radius);
            a.center.distance_squared(b.center) < reach * reach
        };
        let (mut sampled, mut overlaps) = (0, 0);
        for i in (0..data.len()).step_by(16) {
            let next = &data[i + 1..data.len().min(i + BLOCK)];
            overlaps += next.iter().filter(|b| deep(&data[i], b)).count();
            sampled += 1;
        }
        sampled > 0 && overlaps >= 3 * sampled
    }

    /// The line and chord tests of [`intersect_sphere_in`], the same operations lane by lane
    /// (so the same decisions), over a block of spheres at once.
    #[inline(always)]
    fn block_may_hit(data: &[Sphere], start: usize, ray: &Ray, t_min: f32, t_max: f32) -> u32 {
        // A whole block copied at fixed places (the common case; the lanes are then loads and
        // shuffles), the last one of a set padded.
        let (block, n) = match data.get(start..start + BLOCK) {
            Some(b) => (
                <[Sphere; BLOCK]>::try_from(b).unwrap_or([PAD; BLOCK]),
                BLOCK,
            ),
            None => {
                let mut b = [PAD; BLOCK];
                let rest = &data[start..];
                b[..rest.len()].copy_from_slice(rest);
                (b, rest.len())
            }
        };
        let x = block.map(|s| s.center.x);
        let y = block.map(|s| s.center.y);
        let z = block.map(|s| s.center.z);
        let r = block.map(|s| s.radius);
        let (o, d) = (ray.origin, ray.dir);
        let mut mask = 0;
        for k in 0..BLOCK {
            let (fx, fy, fz) = (o.x - x[k], o.y - y[k], o.z - z[k]);
            // As glam's `dot`: (x + y) + z.
            let fd = (fx * d.x + fy * d.y) + fz * d.z;
            let (lx, ly, lz) = (fx - fd * d.x, fy - fd * d.y, fz - fd * d.z);
            let r2 = r[k] * r[k];
            let h = r2 - ((lx * lx + ly * ly) + lz * lz);
            // As the scalar test: a NaN is no clear miss.
            let clear_miss = h < -r2 * 1e-4;
            let may = !clear_miss && !chord_outside(-fd, h, r[k], t_min, t_max);
            mask |= u32::from(may) << k;
        }
        mask & ((1 << n) - 1)
    }

    fn bounds(&self) -> Aabb {
        let c = Vec3A::from(self.center);
        Aabb::new(c - self.radius, c + self.radius)
    }

    #[inline(always)]
    fn hit_after(&self, ray: &Ray, _: &(), t_min: f32, t_max: f32) -> Option<(f32, f32, f32)> {
        self.hit_after_in::<false>(ray, &(), t_min, t_max)
    }

    #[inline(always)]
    fn crossings(&self, ray: &Ray, _: &(), t_max: f32) -> u32 {
        self.crossings_in::<false>(ray, &(), t_max)
    }

    #[inline(always)]
    fn hit_after_in<const DENSE: bool>(
        &self,
        ray: &Ray,
        _: &(),
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, f32, f32)> {
        intersect_sphere_in(self, ray.origin, ray.dir, t_min, t_max, DENSE)
            .0
            .map(|t| (t, 0.0, 0.0))
    }

    #[inline(always)]
    fn crossings_in<const DENSE: bool>(&self, ray: &Ray, _: &(), t_max: f32) -> u32 {
        intersect_sphere_in(self, ray.origin, ray.dir, 0.0, t_max, DENSE).1
    }
}

impl Set<Sphere> {
    /// Validates and stores sphere `i` of a batch given in world coordinates.
    pub fn push_world(
        &mut self,
        i: usize,
        s: [f64; 4],
        offset: DVec3,
        material: u32,
    ) -> Result<(), String> {
        self.push(Sphere::from_world(i, s, offset)?, material);
        Ok(())
    }

    /// The surface at a hit; its texture coordinates only when `uv` asks (an `atan2` and an
    /// `acos`: no texture reads them on most spheres).
    pub fn surface(&self, hit: &Hit, ray: &Ray, uv: bool) -> Surface {
        let i = hit.index as usize;
        surface(self.data[i], hit.t, ray, uv, material_of(self.material[i]))
    }
}

/// The surface of sphere `s` hit at distance `t` along `ray`, of `material`; its texture
/// coordinates only when `uv` asks. Shared by the spheres stored here and those read from the
/// caller's arrays (`array_set`), so both shade alike.
#[inline]
pub fn surface(s: Sphere, t: f32, ray: &Ray, uv: bool, material: u32) -> Surface {
    let c = Vec3A::from(s.center);
    // Re-project onto the sphere: the error is then a few ulps of the coordinates. The
    // direction from the centre is taken in f64: for a sphere smaller than the f32 spacing
    // of its position, `ray.at(t) - c` can be exactly zero (a NaN normal).
    let rel = ray.origin.as_dvec3() - c.as_dvec3() + ray.dir.as_dvec3() * t as f64;
    let n = match rel.try_normalize() {
        Some(n) => Vec3A::from(n.as_vec3()),
        None => -ray.dir,
    };
    let pr = n * s.radius;
    let (p, p_error) = {
        let p_proj = c + pr;
        let e_proj = gamma(6) * (pr.abs() + c.abs());
        // Far from the centre of a huge sphere (an Earth-sized ground near the camera), the
        // re-projected point rounds to the f32 spacing at the centre's magnitude (0.5 at
        // 6.4e6): a shadow ray offset by that bound starts above small things on the
        // ground. The point along the ray is then far more precise: rounding of o + t·d
        // and of t to f32, plus the f64 solve's error (relative to the sphere's size).
        let p_ray = ray.at(t);
        let solve = 4.0 * f64::EPSILON as f32 * ((c - ray.origin).length() + s.radius);
        let e_ray = gamma(3) * (ray.origin.abs() + (t * ray.dir).abs()) + solve;
        if e_ray.max_element() < e_proj.max_element() {
            (p_ray, e_ray)
        } else {
            (p_proj, e_proj)
        }
    };
    let uv = if uv {
        let u = 0.5 + n.z.atan2(n.x) / std::f32::consts::TAU;
        let v = n.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        [u, v]
    } else {
        [0.0; 2]
    };
    Surface {
        // u spans 2πr, v spans πr: their geometric mean.
        uv_scale: 1.0 / (std::f32::consts::PI * std::f32::consts::SQRT_2 * s.radius),
        ..Surface::solid(p, p_error, n, uv, material)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::Lcg;
    use super::*;

    /// The chord test never changes the answer: `intersect_sphere` gives exactly what the line
    /// test and the f64 solve alone give, over spheres of radius 1e-3 to 1e3 up to 1e4 radii from
    /// the origin, for rays ending or starting (t_max, t_min) within 1e-9 to 1e-1 of either end
    /// of their chord, on either side; rays leaving the surface from just inside or outside,
    /// toward the centre or away; grazing rays. And the chord test turns many away.
    #[test]
    fn the_f32_tests_never_change_the_answer() {
        let mut rng = Lcg(2027);
        let (mut rays, mut outside, mut hits) = (0, 0, 0);
        for _ in 0..20_000 {
            let r = rng.log(-3.0, 3.0);
            let c = rng.unit() * r * rng.log(-1.0, 4.0) * rng.next();
            let s = Sphere {
                center: c.as_vec3(),
                radius: r as f32,
            };
            let c = s.center.as_dvec3();
            let rr = f64::from(s.radius);
            for kind in 0..5 {
                let n = rng.unit();
                let offset = rng.log(-9.0, -1.0) * if rng.next() < 0.5 { -1.0 } else { 1.0 };
                let surface = c + n * rr * (1.0 + offset);
                let (o, d) = match kind {
                    // From far away toward a point near the surface.
                    0 | 1 => {
                        let o = surface + rng.unit() * rr * rng.log(0.0, 4.0);
                        (o, (surface - o).normalize())
                    }
                    // Leaving a point near the surface, any way.
                    2 => (surface, rng.unit()),
                    // Grazing: tangent at a point just inside or outside.
                    3 => {
                        let t = n.any_orthonormal_vector();
                        (surface - t * rr * rng.log(-1.0, 3.0), t)
                    }
                    _ => (c + rng.unit() * rr * rng.log(-1.0, 2.0), rng.unit()),
                };
                let (o, d) = (Vec3A::from(o.as_vec3()), Vec3A::from(d.as_vec3()));
                let cf = Vec3A::from(s.center);
                let all = solve_sphere(cf, s.radius, o, d, f32::NEG_INFINITY, f32::INFINITY);
                // Ends near the chord's ends (the roots found over the whole line), or
                // anywhere.
                let (near, far) = match all {
                    (Some(t0), 2) => {
                        let f = cf - o;
                        (t0, 2.0 * f.dot(d) - t0)
                    }
                    _ => (rng.range(0.0, 10.0) as f32 * s.radius, s.radius),
                };
                let jitter = |t: f32, rng: &mut Lcg| {
                    let e = rng.log(-9.0, -1.0) * if rng.next() < 0.5 { -1.0 } else { 1.0 };
                    (f64::from(t) * (1.0 + e)) as f32
                };
                for (t_min, t_max) in [
                    (0.0, f32::INFINITY),
                    (0.0, jitter(near, &mut rng)),
                    (0.0, jitter(far, &mut rng)),
                    (jitter(near, &mut rng), f32::INFINITY),
                    (jitter(far, &mut rng), f32::INFINITY),
                    (jitter(near, &mut rng).max(0.0), jitter(far, &mut rng)),
                ] {
                    rays += 1;
                    // As without the chord test.
                    let want = intersect_sphere_in(&s, o, d, t_min, t_max, false);
                    assert_eq!(
                        intersect_sphere_in(&s, o, d, t_min, t_max, true),
                        want,
                        "{s:?} {o:?} {d:?} ({t_min}, {t_max})"
                    );
                    hits += usize::from(want.0.is_some());
                    let f = o - cf;
                    let l = f - f.dot(d) * d;
                    let h = s.radius * s.radius - l.dot(l);
                    outside += usize::from(
                        want.1 == 0 && chord_outside(-f.dot(d), h, s.radius, t_min, t_max),
                    );
                }
            }
        }
        assert!(hits > rays / 5, "{hits} of {rays} hit");
        assert!(
            outside > rays / 10,
            "{outside} of {rays} turned away by the chord"
        );
    }

    /// A block's cleared bit promises no root in (t_min, t_max), nor in any interval inside
    /// it; over overlapping spheres (a spiral, as in a seashell) and rays through them from
    /// outside and from their surfaces. Many bits are cleared, and the set bits are those the
    /// line test and the chord test each pass one sphere at a time.
    #[test]
    fn a_block_rules_out_only_spheres_without_roots() {
        let mut rng = Lcg(2028);
        let spiral: Vec<Sphere> = (0..60)
            .map(|k| {
                let a = k as f32 * 0.05;
                Sphere {
                    center: Vec3::new(a.cos() * (1.0 + a), a.sin() * (1.0 + a), 0.1 * a),
                    radius: 0.2 + 0.01 * k as f32,
                }
            })
            .collect();
        let (mut cleared, mut bits) = (0, 0);
        for _ in 0..3000 {
            let s = &spiral[(rng.next() * 60.0) as usize];
            let c = s.center.as_dvec3();
            let o = match rng.next() < 0.5 {
                true => c + rng.unit() * f64::from(s.radius) * (1.0 + rng.log(-7.0, -1.0)),
                false => c + rng.unit() * rng.log(0.5, 1.5),
            };
            let ray = Ray::new(
                Vec3A::from(o.as_vec3()),
                Vec3A::from(rng.unit().as_vec3()),
                0.0,
            );
            let t_max = [f32::INFINITY, rng.range(0.0, 3.0) as f32][usize::from(rng.next() < 0.5)];
            let start = (rng.next() * 60.0) as usize;
            let mask = Sphere::block_may_hit(&spiral, start, &ray, 0.0, t_max);
            for (k, s) in spiral[start..].iter().take(BLOCK).enumerate() {
                let (o, d) = (ray.origin, ray.dir);
                let f = o - Vec3A::from(s.center);
                let l = f - f.dot(d) * d;
                let h = s.radius * s.radius - l.dot(l);
                let clear_miss = h < -s.radius * s.radius * 1e-4;
                let scalar = !clear_miss && !chord_outside(-f.dot(d), h, s.radius, 0.0, t_max);
                assert_eq!(mask >> k & 1 != 0, scalar, "{s:?} {ray:?} {t_max}");
                bits += 1;
                if mask >> k & 1 == 0 {
                    cleared += 1;
                    let lo = rng.range(0.0, 1.0) as f32;
                    for (a, b) in [(0.0, t_max), (lo, t_max), (0.0, t_max.min(lo + 0.5))] {
                        assert_eq!(intersect_sphere_in(s, o, d, a, b, false), (None, 0));
                    }
                }
            }
            assert_eq!(mask >> spiral.len().saturating_sub(start).min(BLOCK), 0);
        }
        assert!(
            cleared > bits / 4 && bits - cleared > bits / 50,
            "{cleared} of {bits}"
        );
    }

    #[test]
    fn hits_from_outside_and_inside() {
        let s = &Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
        };
        let (t, n) = intersect_sphere(s, Vec3A::ZERO, Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!((t, n), (Some(4.0), 2));
        let (t, n) = intersect_sphere(s, Vec3A::new(0.0, 0.0, 5.0), Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!((t, n), (Some(1.0), 1));
        let (t, _) = intersect_sphere(s, Vec3A::ZERO, -Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!(t, None);
        let (t, _) = intersect_sphere(s, Vec3A::ZERO, Vec3A::Z, 0.0, 3.0);
        assert_eq!(t, None);
    }

    #[test]
    fn huge_far_sphere_has_no_cancellation() {
        // Earth-sized sphere, camera 1 unit above its surface looking straight down.
        let r = 6.4e6f32;
        let s = &Sphere {
            center: Vec3::new(0.0, -r, 0.0),
            radius: r,
        };
        let (t, _) = intersect_sphere(s, Vec3A::new(0.0, 1.0, 0.0), -Vec3A::Y, 0.0, f32::INFINITY);
        let t = t.unwrap();
        assert!((t - 1.0).abs() < 1e-6, "t = {t}");
    }
}
