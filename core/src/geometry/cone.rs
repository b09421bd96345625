//! Open cones and cylinders between two end discs (base centre + radius, apex centre + radius):
//! 32 bytes each, in their own BVH. Molecular bonds and the SPD's `c` primitives are these.

use super::set::{Set, Shape};
use super::{material_of, Hit, Kind, Surface};
use crate::math::{gamma, Aabb, DVec3, Vec3A};
use crate::ray::Ray;
use glam::{Vec3, Vec3Swizzles};

/// An open cone or cylinder: base centre and radius, apex centre and radius (32 bytes).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Cone {
    pub base: Vec3,
    pub base_radius: f32,
    pub apex: Vec3,
    pub apex_radius: f32,
}

pub type Cones = Set<Cone>;

/// Bounds of a disc of radius `r` around `c` with unit normal `w`: per axis r·√(1 − wᵢ²).
pub fn disc_bounds(c: Vec3A, w: Vec3A, r: f32) -> Aabb {
    let q = (Vec3A::ONE - w * w).max(Vec3A::ZERO);
    let e = r * Vec3A::new(q.x.sqrt(), q.y.sqrt(), q.z.sqrt());
    Aabb::new(c - e, c + e)
}

/// Whether the line of a ray (origin `o`, direction `d`) can meet cylinder `c` (equal radii):
/// false only when the line passes farther from the axis line than the radius by more than
/// every rounding error of this f32 test and of the f64 test in [`exact_roots`], so a `false`
/// is never a root that test would find. A handful of vector operations and one square root,
/// against the exact test's two square roots and up to six divisions in f64: most cylinders a
/// ray is tested against are ones whose (axis-aligned, mostly empty) box it only crosses.
///
/// With the axis `ax = apex - base` and `oc = o - base`, the line's distance from the axis
/// line is |oc · n| / |n| for n = d × ax. Rounding bounds (u = 2^-24, first order): each
/// computed n_i errs by at most 3u·m_i, with m_i = |d_j ax_k| + |d_k ax_j| (rounded `ax`, two
/// products, a difference), so |n| ≤ length(n') + 5u·Σm_i (with the length's own rounding);
/// the dot product oc·n errs by at most 7u·Σ|oc_i| m_i. The code allows 8u and 16u. The f64
/// test can report a root for a line up to about sqrt(60·2^-53)·|oc| ≈ 1e-7·|oc| beyond the
/// radius (the rounding of its discriminant, of size |oc|²|rd|²); the margin allows
/// 1e-6·|oc|₁. The last term covers underflow. An overflow or a NaN makes a side infinite or
/// NaN, which keeps the cylinder.
#[inline(always)]
fn may_hit_cylinder(c: &Cone, o: Vec3A, d: Vec3A) -> bool {
    const U: f32 = f32::EPSILON * 0.5;
    let b = Vec3A::from(c.base);
    let ax = Vec3A::from(c.apex) - b;
    let oc = o - b;
    let n = d.cross(ax);
    let (da, aa) = (d.abs(), ax.abs());
    let m = da.yzx() * aa.zxy() + da.zxy() * aa.yzx();
    let oc_abs = oc.abs();
    let n_max = n.length() + 8.0 * U * m.element_sum();
    let slack =
        16.0 * U * oc_abs.dot(m) + (c.base_radius + 1e-6 * oc_abs.element_sum()) * n_max + 1e-30;
    oc.dot(n).abs().partial_cmp(&slack) != Some(std::cmp::Ordering::Greater)
}

/// The roots of the cone's quadric along the ray that lie on the finite, correct-nappe part of
/// the surface within (0, t_max), nearest first; solved in f64. A cylinder the ray's line
/// passes clear of is rejected first by a cheap f32 test ([`may_hit_cylinder`]).
#[inline(always)]
fn cone_roots(c: &Cone, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> ([f64; 2], usize) {
    if c.base_radius == c.apex_radius && !may_hit_cylinder(c, o, d) {
        return ([0.0; 2], 0);
    }
    exact_roots(c, o, d, t_min, t_max)
}

/// [`cone_roots`] without the f32 rejection.
#[inline(always)]
fn exact_roots(c: &Cone, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> ([f64; 2], usize) {
    let b = c.base.as_dvec3();
    let a = c.apex.as_dvec3();
    let (rb, ra) = (c.base_radius as f64, c.apex_radius as f64);
    let ba = a - b;
    let h = ba.length();
    let w = ba / h;
    let k = (ra - rb) / h;
    let oc = o.as_dvec3() - b;
    let d = d.as_dvec3();
    let so = oc.dot(w);
    let sd = d.dot(w);
    let ro = oc - so * w;
    let rd = d - sd * w;
    let m = rb + k * so;
    let n = k * sd;
    let qa = rd.dot(rd) - n * n;
    let qb = ro.dot(rd) - m * n;
    let qc = ro.dot(ro) - m * m;
    let mut roots = [0.0f64; 2];
    let mut count = 0;
    let mut consider = |t: f64| {
        if t > t_min as f64 && t < t_max as f64 {
            let s = so + t * sd;
            if (0.0..=h).contains(&s) && m + n * t >= 0.0 {
                roots[count] = t;
                count += 1;
            }
        }
    };
    if qa.abs() < 1e-12 * (rd.dot(rd) + n * n).max(1e-300) {
        // Ray parallel to a line of the cone: one root.
        if qb != 0.0 {
            consider(-qc / (2.0 * qb));
        }
    } else {
        let disc = qb * qb - qa * qc;
        if disc < 0.0 {
            return (roots, 0);
        }
        let q = -(qb + disc.sqrt().copysign(qb));
        let (mut t0, mut t1) = (q / qa, if q != 0.0 { qc / q } else { q / qa });
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        consider(t0);
        if t1 != t0 {
            consider(t1);
        }
    }
    (roots, count)
}

impl Shape for Cone {
    const KIND: Kind = Kind::Cone;
    type Prep = ();
    fn prep(_: &Ray) {}

    fn bounds(&self) -> Aabb {
        let (b, a) = (Vec3A::from(self.base), Vec3A::from(self.apex));
        let w = (a - b).normalize();
        disc_bounds(b, w, self.base_radius).union(disc_bounds(a, w, self.apex_radius))
    }

    #[inline(always)]
    fn hit_after(&self, ray: &Ray, _: &(), t_min: f32, t_max: f32) -> Option<(f32, f32, f32)> {
        let (r, n) = cone_roots(self, ray.origin, ray.dir, t_min, t_max);
        let t = r[0] as f32;
        (n > 0 && t > t_min && t < t_max).then_some((t, 0.0, 0.0))
    }

    #[inline(always)]
    fn crossings(&self, ray: &Ray, _: &(), t_max: f32) -> u32 {
        cone_roots(self, ray.origin, ray.dir, 0.0, t_max).1 as u32
    }
}

impl Set<Cone> {
    /// Validates and stores cone `i` of a batch given in world coordinates.
    pub fn push_world(
        &mut self,
        i: usize,
        c: [f64; 8],
        offset: DVec3,
        material: u32,
    ) -> Result<(), String> {
        if c.iter().any(|v| !v.is_finite()) {
            return Err(format!("cone {i} has a non-finite value {c:?}"));
        }
        if c[3] < 0.0 || c[7] < 0.0 || (c[3] == 0.0 && c[7] == 0.0) {
            return Err(format!(
                "cone {i} has radii {} and {}; expected radii >= 0, not both 0",
                c[3], c[7]
            ));
        }
        let base = (DVec3::new(c[0], c[1], c[2]) - offset).as_vec3();
        let apex = (DVec3::new(c[4], c[5], c[6]) - offset).as_vec3();
        if base == apex {
            return Err(format!(
                "cone {i} has the same base and apex centre; expected a length > 0"
            ));
        }
        self.push(
            Cone {
                base,
                base_radius: c[3] as f32,
                apex,
                apex_radius: c[7] as f32,
            },
            material,
        );
        Ok(())
    }

    /// The surface at a hit; its texture coordinates only when `uv` asks.
    pub fn surface(&self, hit: &Hit, ray: &Ray, uv: bool) -> Surface {
        let i = hit.index as usize;
        surface(&self.data[i], hit.t, ray, uv, material_of(self.material[i]))
    }
}

/// The surface of cone `c` hit at distance `t` along `ray`, of `material`; its texture
/// coordinates only when `uv` asks. Shared with the cylinders read from the caller's arrays.
#[inline]
pub fn surface(c: &Cone, t: f32, ray: &Ray, uv: bool, material: u32) -> Surface {
    let (b, a) = (Vec3A::from(c.base), Vec3A::from(c.apex));
    let h = (a - b).length();
    let w = (a - b) / h;
    let k = (c.apex_radius - c.base_radius) / h;
    let p = ray.at(t);
    let s = (p - b).dot(w);
    let ortho = crate::math::orthogonal(w);
    let q = ((p - b) - s * w).normalize_or_zero();
    let q = if q == Vec3A::ZERO { ortho } else { q };
    let n = (q - k * w).normalize();
    let r_max = c.base_radius.max(c.apex_radius);
    let p_error = gamma(16) * (p.abs() + b.abs().max(a.abs()) + Vec3A::splat(r_max));
    let uv = if uv {
        let u = 0.5 + q.dot(w.cross(ortho)).atan2(q.dot(ortho)) / std::f32::consts::TAU;
        [u, (s / h).clamp(0.0, 1.0)]
    } else {
        [0.0; 2]
    };
    Surface::solid(p, p_error, n, uv, material)
}

#[cfg(test)]
mod tests {
    use super::super::testing::Lcg;
    use super::*;

    const CYL: Cone = Cone {
        base: Vec3::ZERO,
        base_radius: 1.0,
        apex: Vec3::new(0.0, 0.0, 4.0),
        apex_radius: 1.0,
    };

    #[test]
    fn cylinder_hit_from_outside_inside_and_along_the_axis() {
        let (r, n) = cone_roots(
            &CYL,
            Vec3A::new(-5.0, 0.0, 2.0),
            Vec3A::X,
            0.0,
            f32::INFINITY,
        );
        assert_eq!(n, 2);
        assert!((r[0] - 4.0).abs() < 1e-9 && (r[1] - 6.0).abs() < 1e-9);
        let (r, n) = cone_roots(
            &CYL,
            Vec3A::new(0.0, 0.0, 2.0),
            Vec3A::X,
            0.0,
            f32::INFINITY,
        );
        assert_eq!((n, r[0]), (1, 1.0));
        // Along the axis through the open ends: no hit.
        let (_, n) = cone_roots(
            &CYL,
            Vec3A::new(0.0, 0.0, -1.0),
            Vec3A::Z,
            0.0,
            f32::INFINITY,
        );
        assert_eq!(n, 0);
        // Beyond the ends: no hit.
        let (_, n) = cone_roots(
            &CYL,
            Vec3A::new(-5.0, 0.0, 5.0),
            Vec3A::X,
            0.0,
            f32::INFINITY,
        );
        assert_eq!(n, 0);
    }

    #[test]
    fn cone_hits_only_its_own_nappe() {
        // Pointed cone: radius 1 at z=0, 0 at z=1.
        let cone = Cone {
            base: Vec3::ZERO,
            base_radius: 1.0,
            apex: Vec3::Z,
            apex_radius: 0.0,
        };
        let (r, n) = cone_roots(
            &cone,
            Vec3A::new(-5.0, 0.0, 0.5),
            Vec3A::X,
            0.0,
            f32::INFINITY,
        );
        assert_eq!(n, 2);
        assert!((r[0] - 4.5).abs() < 1e-6, "{r:?}");
        // Through the mirrored nappe above the apex: nothing.
        let (_, n) = cone_roots(
            &cone,
            Vec3A::new(-5.0, 0.0, 1.5),
            Vec3A::X,
            0.0,
            f32::INFINITY,
        );
        assert_eq!(n, 0);
    }

    /// The f32 rejection never turns away a line on which the exact test finds a root, over
    /// cylinders of every scale (radii from 1e-6 to 1e3 of their scale, lengths from 1e-2 to
    /// 1e2, far from the origin or not) and rays of every sort: grazing the surface tangentially
    /// from just inside to just outside (radial offsets from 1e-9 to 1e-1 of the radius), along
    /// the axis or nearly, from inside, from far away, and at random. And it turns away many,
    /// so the comparison means something.
    #[test]
    fn the_cheap_rejection_never_drops_a_root_of_the_exact_test() {
        let mut rng = Lcg(2026);
        let (mut rays, mut rejected, mut hits, mut grazing_hits) = (0, 0, 0, 0);
        for _ in 0..20_000 {
            let scale = rng.log(-3.0, 3.0);
            let base = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ) * scale
                * rng.log(0.0, 2.0);
            let w = rng.unit();
            let len = scale * rng.log(-2.0, 2.0);
            let r = scale * rng.log(-6.0, 3.0);
            let cyl = Cone {
                base: base.as_vec3(),
                base_radius: r as f32,
                apex: (base + w * len).as_vec3(),
                apex_radius: r as f32,
            };
            if cyl.base == cyl.apex {
                continue;
            }
            // The axis as stored, and two directions across it.
            let (b, a) = (cyl.base.as_dvec3(), cyl.apex.as_dvec3());
            let w = (a - b).normalize();
            let u = w.any_orthonormal_vector();
            let v = w.cross(u);
            for kind in 0..6 {
                let phi = rng.range(0.0, std::f64::consts::TAU);
                let radial = u * phi.cos() + v * phi.sin();
                let tangent = v * phi.cos() - u * phi.sin();
                let s = (a - b).length() * rng.range(-0.2, 1.2);
                let offset = rng.log(-9.0, -1.0) * if rng.next() < 0.5 { -1.0 } else { 1.0 };
                let (o, d) = match kind {
                    // Tangent to the surface at a point just inside or outside it.
                    0 | 1 => {
                        let p = b + w * s + radial * r * (1.0 + offset);
                        let d = (tangent + w * rng.range(-3.0, 3.0)).normalize();
                        (p - d * scale * rng.log(-2.0, 3.0), d)
                    }
                    // Along the axis, exactly or nearly, just inside or outside the surface.
                    2 => {
                        let tilt = if rng.next() < 0.3 {
                            0.0
                        } else {
                            rng.log(-9.0, -2.0)
                        };
                        let d = (w + radial * tilt).normalize();
                        (b + radial * r * (1.0 + offset) - w * scale, d)
                    }
                    // From inside, in any direction.
                    3 => (b + w * s + radial * r * rng.range(0.0, 0.99), rng.unit()),
                    // From far away toward a point near the surface.
                    4 => {
                        let target = b + w * s + radial * r * (1.0 + offset);
                        let o = target + rng.unit() * scale * rng.log(2.0, 4.0);
                        (o, (target - o).normalize())
                    }
                    // Anywhere near, any direction.
                    _ => (
                        b + rng.unit() * (scale + r) * rng.range(0.0, 3.0),
                        rng.unit(),
                    ),
                };
                let (o, d) = (Vec3A::from(o.as_vec3()), Vec3A::from(d.as_vec3()));
                let found = exact_roots(&cyl, o, d, f32::NEG_INFINITY, f32::INFINITY).1;
                rays += 1;
                hits += usize::from(found > 0);
                grazing_hits += usize::from(found > 0 && kind < 3 && offset > 0.0);
                if !may_hit_cylinder(&cyl, o, d) {
                    rejected += 1;
                    assert_eq!(found, 0, "{cyl:?} {o:?} {d:?}");
                    assert_eq!(cone_roots(&cyl, o, d, 0.0, f32::INFINITY).1, 0);
                }
            }
        }
        // Most rays here are near misses within the margin; still a good part is turned away.
        assert!(hits > rays / 5, "{hits} of {rays} hit");
        let misses = rays - hits;
        assert!(
            rejected > misses / 5,
            "{rejected} of {misses} misses rejected"
        );
        // Lines just outside the surface that the exact test still finds (rounding, or a
        // tangent line's slant): the margin keeps them all.
        assert!(grazing_hits > 100, "{grazing_hits} grazing hits");
    }

    /// Lines clear of a cylinder of ordinary proportions are turned away by the f32 test
    /// alone, down to 1 % of the radius outside, seen from 100 radii away.
    #[test]
    fn the_cheap_rejection_turns_away_clear_misses() {
        for (gap, rejected) in [(1.01, true), (1.5, true), (0.99, false), (0.0, false)] {
            for z in [-1.0, 2.0, 5.0] {
                let o = Vec3A::new(-100.0, gap, z);
                let d = Vec3A::new(1.0, 0.0, 0.3).normalize();
                assert_eq!(may_hit_cylinder(&CYL, o, d), !rejected, "{gap} {z}");
            }
        }
    }

    #[test]
    fn normals_point_outward() {
        let mut cones = Cones::default();
        cones
            .push_world(0, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0], DVec3::ZERO, 0)
            .unwrap();
        let ray = Ray::new(Vec3A::new(-5.0, 0.0, 0.5), Vec3A::X, 0.0);
        let s = cones.surface(&Hit::new(4.5, Kind::Cone, 0), &ray, true);
        let want = Vec3A::new(-1.0, 0.0, 1.0).normalize();
        assert!((s.ng - want).length() < 1e-5, "{:?}", s.ng);
    }

    #[test]
    fn bad_cones_are_rejected() {
        let mut c = Cones::default();
        assert!(c.push_world(0, [0.0; 8], DVec3::ZERO, 0).is_err());
        assert!(c
            .push_world(0, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], DVec3::ZERO, 0)
            .is_err());
        assert!(c
            .push_world(0, [0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 1.0], DVec3::ZERO, 0)
            .is_err());
        assert!(c
            .push_world(
                0,
                [f64::NAN, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0],
                DVec3::ZERO,
                0
            )
            .is_err());
    }
}
