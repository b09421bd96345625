//! Property tests of the custom-geometry intersection routines (box, quadric, infinite
//! cylinder, heightfield), called as the host calls them: an f32 render-space ray widened to
//! f64, the hit point taken back to f32 with the host's error bound and left through the
//! host's own `luxon::ray::spawn`.
//!
//! - the hit point lies on the surface, within a bound relative to its magnitude and within
//!   the host's error bound along the normal (the offset spawned rays start at);
//! - the normal is finite and non-zero, and unit length once the host normalises it;
//! - a ray leaving the hit point into the outward hemisphere of a convex shape never hits it
//!   again; a ray leaving a heightfield upward hits it again only where it really crosses
//!   another facet (a concave fold may be arbitrarily close), never on the plane it left (acne).
//!
//! Also: rays exactly parallel to the box's faces and lying in a face's plane (division by
//! zero in the slab test).

use super::boxes::Cuboid;
use super::heightfield::HeightGrid;
use super::infinite_cylinder::LineCylinder;
use super::quadric::ClippedQuadric;
use luxon::math::{gamma, DVec3, Vec3A};
use luxon_plugin::{parse_params, CustomShape, Hit, Ray};
use proptest::prelude::*;

type V3 = [f64; 3];

/// Relative tolerance for "on the surface" (the host keeps hit points in f32).
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

/// A length scale and a position up to 1e4 from the origin.
fn placement() -> impl Strategy<Value = (f64, Vec3A)> {
    (-3i32..=4, prop_oneof![Just(0.0f32), 1.0f32..1e4], unit())
        .prop_map(|(e, far, dir)| (10f64.powi(e), far * dir))
}

/// The f64 ray the host hands a plugin for an f32 render-space ray.
fn host_ray(r: &luxon::ray::Ray) -> Ray {
    Ray {
        origin: r.origin.as_dvec3().into(),
        direction: r.dir.as_dvec3().into(),
        tmin: 0.0,
        tmax: f32::INFINITY as f64,
        time: 0.0,
    }
}

fn aimed(target: Vec3A, scale: f64, from: Vec3A) -> luxon::ray::Ray {
    let o = target + (4.0 * scale) as f32 * from;
    luxon::ray::Ray::new(o, (target - o).normalize(), 0.0)
}

/// The hit as the host keeps it: f32 point, its error bound, the unit normal.
fn host_surface(r: &luxon::ray::Ray, h: &Hit) -> (Vec3A, Vec3A, Vec3A) {
    let p = r.at(h.t as f32);
    let p_error = gamma(64) * (p.abs() + r.origin.abs());
    let n = DVec3::from(h.normal).normalize_or_zero().as_vec3();
    (p, p_error, Vec3A::from(n))
}

/// A direction in the hemisphere of `n`, not grazing.
fn away(n: Vec3A, d: Vec3A) -> Vec3A {
    let d = if d.dot(n) < 0.0 {
        d - 2.0 * d.dot(n) * n
    } else {
        d
    };
    (d + 0.05 * n).normalize()
}

/// What `check` saw: the first hit, the ray that left it (as the plugin gets it) and that ray's
/// hit, if any.
struct Leaving {
    hit: Hit,
    ray: Ray,
    again: Option<Hit>,
}

/// Checks a hit of `shape` for the ray; `distance(p)`: distance of a point from the surface;
/// `outward(p, n)`: the normal turned outward; `may_rehit(ray, again)`: whether the ray leaving
/// the surface may have that hit (`|_, _| false`: never hits the shape again).
fn check<S: CustomShape>(
    shape: &S,
    r: &luxon::ray::Ray,
    distance: impl Fn(V3) -> f64,
    size: f64,
    outward: impl Fn(V3, Vec3A) -> Vec3A,
    leave: Vec3A,
    may_rehit: impl Fn(&Ray, &Hit) -> bool,
) -> Result<Option<Leaving>, TestCaseError> {
    let Some(h) = shape.intersect(0, &host_ray(r)) else {
        return Ok(None);
    };
    prop_assert!(h.t.is_finite() && h.normal.iter().all(|v| v.is_finite()));
    let (p, p_error, n) = host_surface(r, &h);
    prop_assert!((n.length() - 1.0).abs() < 1e-5, "normal {:?}", h.normal);
    let pd: V3 = p.as_dvec3().into();
    let mag = pd.iter().fold(size, |m, v| m.max(v.abs()));
    let dist = distance(pd);
    prop_assert!(dist <= ON_SURFACE * mag, "{pd:?} is {dist} off the surface");
    // The host spawns rays this far off along the normal: the surface must lie within it.
    let bound = n.abs().dot(p_error) as f64;
    prop_assert!(
        dist <= bound,
        "{pd:?} is {dist} off the surface, beyond its error bound {bound}"
    );
    let n = outward(pd, n);
    let dir = away(n, leave);
    let spawned = host_ray(&luxon::ray::spawn(p, p_error, n, dir, 0.0));
    let again = shape.intersect(0, &spawned);
    if let Some(again) = &again {
        prop_assert!(
            may_rehit(&spawned, again),
            "left {pd:?} along {dir} and hit the surface again at t = {} (normal {:?})",
            again.t,
            again.normal
        );
    }
    Ok(Some(Leaving {
        hit: h,
        ray: spawned,
        again,
    }))
}

fn v3(v: Vec3A) -> V3 {
    v.as_dvec3().into()
}

fn text(v: V3) -> String {
    format!("({:?}, {:?}, {:?})", v[0], v[1], v[2])
}

proptest! {
    #![proptest_config(cases())]

    #[test]
    fn box_faces((scale, pos) in placement(), half in (0.1f64..2.0, 0.1f64..2.0, 0.1f64..2.0),
                 from in unit(), jitter in unit(), leave in unit()) {
        let c = v3(pos);
        let h = [half.0 * scale, half.1 * scale, half.2 * scale];
        let (min, max) = ([c[0] - h[0], c[1] - h[1], c[2] - h[2]], [c[0] + h[0], c[1] + h[1], c[2] + h[2]]);
        let b = Cuboid::new(&parse_params(&format!("(min: {}, max: {})", text(min), text(max))).unwrap()).unwrap();
        let r = aimed(pos + jitter * (2.0 * scale) as f32, scale, from);
        let distance = |p: V3| {
            // Distance to the nearest face plane, for a point on the box's boundary.
            (0..3).map(|k| (p[k] - min[k]).abs().min((p[k] - max[k]).abs())).fold(f64::MAX, f64::min)
        };
        let size = c.iter().map(|v| v.abs()).fold(0.0, f64::max) + h.iter().fold(0.0, |m: f64, v| m.max(*v));
        check(&b, &r, distance, size, |_, n| n, leave, |_, _| false)?;
    }

    #[test]
    fn infinite_cylinder((scale, pos) in placement(), axis in unit(), radius in 0.1f64..2.0,
                         from in unit(), jitter in unit(), leave in unit()) {
        let (c, w) = (v3(pos), v3(axis));
        let r0 = radius * scale;
        let cyl = LineCylinder::new(&parse_params(&format!(
            "(center: {}, axis: {}, radius: {r0:?})", text(c), text(w))).unwrap()).unwrap();
        let r = aimed(pos + jitter * (2.0 * radius * scale) as f32, scale * (1.0 + radius), from);
        let radial = |p: V3| {
            let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            let along = d[0] * w[0] + d[1] * w[1] + d[2] * w[2];
            [d[0] - along * w[0], d[1] - along * w[1], d[2] - along * w[2]]
        };
        let distance = |p: V3| {
            let q = radial(p);
            ((q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() - r0).abs()
        };
        let size = c.iter().map(|v| v.abs()).fold(r0, f64::max);
        // Outward: away from the axis.
        let outward = |p: V3, n: Vec3A| {
            let q = radial(p);
            if n.as_dvec3().dot(q.into()) < 0.0 { -n } else { n }
        };
        check(&cyl, &r, distance, size, outward, leave, |_, _| false)?;
    }

    #[test]
    fn convex_quadrics((scale, pos) in placement(), axes in (0.2f64..2.0, 0.2f64..2.0, 0.2f64..2.0),
                       paraboloid in any::<bool>(), from in unit(), jitter in unit(), leave in unit()) {
        quadric_case(scale, pos, axes, paraboloid, from, jitter, leave)?;
    }

    #[test]
    fn heightfield((scale, pos) in placement(), n in 2usize..8,
                   heights in proptest::collection::vec(-1.0f64..1.0, 64),
                   from in unit(), jitter in (0.0f32..1.0, 0.0f32..1.0), leave in unit()) {
        heightfield_case(scale, pos, n, &heights, from, jitter, leave)?;
    }
}

/// The quadric property for one input: an ellipsoid (x/a)² + (y/b)² + (z/c)² = 1, or a
/// paraboloid (x/a)² + (z/c)² = y/b, with axes `axes * scale` around `pos`, in a clipping box
/// that holds all of the ellipsoid; a ray aimed near `pos` from the direction `from`.
fn quadric_case(
    scale: f64,
    pos: Vec3A,
    axes: (f64, f64, f64),
    paraboloid: bool,
    from: Vec3A,
    jitter: Vec3A,
    leave: Vec3A,
) -> Result<Option<Leaving>, TestCaseError> {
    let c = v3(pos);
    let (a, b, cc) = (axes.0 * scale, axes.1 * scale, axes.2 * scale);
    let (ka, kb, kc) = (1.0 / (a * a), 1.0 / (b * b), 1.0 / (cc * cc));
    #[rustfmt::skip]
    let k: [f64; 10] = if paraboloid {
        // ka (x - cx)² + kc (z - cz)² - (y - cy) / b
        [ka, 0.0, kc, 0.0, 0.0, 0.0, -2.0 * ka * c[0], -1.0 / b, -2.0 * kc * c[2],
         ka * c[0] * c[0] + kc * c[2] * c[2] + c[1] / b]
    } else {
        [ka, kb, kc, 0.0, 0.0, 0.0, -2.0 * ka * c[0], -2.0 * kb * c[1], -2.0 * kc * c[2],
         ka * c[0] * c[0] + kb * c[1] * c[1] + kc * c[2] * c[2] - 1.0]
    };
    let m = 2.5 * scale;
    let (min, max) = (
        [c[0] - m, c[1] - m, c[2] - m],
        [c[0] + m, c[1] + m, c[2] + m],
    );
    let coefficients = k
        .iter()
        .map(|v| format!("{v:?}"))
        .collect::<Vec<_>>()
        .join(", ");
    let q = ClippedQuadric::new(
        &parse_params(&format!(
            "(coefficients: ({coefficients}), min: {}, max: {})",
            text(min),
            text(max)
        ))
        .unwrap(),
    )
    .unwrap();
    let r = aimed(pos + jitter * scale as f32, 2.0 * scale, from);
    // The exact distance, in coordinates relative to the centre (not |f| / |∇f|: a shape
    // smaller than f32's spacing at its position may have its hit rounded to the centre,
    // where ∇f = 0).
    let distance = |p: V3| {
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        if paraboloid {
            quadric_distance(d, [ka, 0.0, kc], [0.0, -1.0 / b, 0.0], 0.0)
        } else {
            quadric_distance(d, [ka, kb, kc], [0.0; 3], -1.0)
        }
    };
    // Only hits inside the clipping box count; the box's faces cut the paraboloid open,
    // so leaving outward from near a cut may still cross the surface: skip those.
    let inner = |p: V3| (0..3).all(|k| p[k] > min[k] + 0.2 * m && p[k] < max[k] - 0.2 * m);
    let outward = |p: V3, n: Vec3A| {
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let g = if paraboloid {
            [2.0 * ka * d[0], -1.0 / b, 2.0 * kc * d[2]]
        } else {
            [2.0 * ka * d[0], 2.0 * kb * d[1], 2.0 * kc * d[2]]
        };
        // g = 0 at the centre, where only a shape far smaller than the spawn offset (~100 f32
        // steps) can have its hit rounded to: every side leads out of it.
        if n.as_dvec3().dot(g.into()) < 0.0 {
            -n
        } else {
            n
        }
    };
    let size = c.iter().map(|v| v.abs()).fold(m, f64::max);
    let Some(h) = q.intersect(0, &host_ray(&r)) else {
        return Ok(None);
    };
    let p: V3 = r.at(h.t as f32).as_dvec3().into();
    let cut_nearby = !inner(p);
    check(&q, &r, distance, size, outward, leave, |_, _| cut_nearby)
}

/// Distance from `d` to the surface `f(x) = Σ k_i x_i² + l_i x_i + c0 = 0` (`k_i >= 0`, not all
/// 0; `f` takes both signs), as the maximum over `μ` of the Lagrangian dual
/// `φ(μ) = min_x |x - d|² + μ f(x)`: exact for one quadratic constraint (the S-lemma), concave,
/// with `φ'(μ) = f(x(μ))` at the minimiser `x_i(μ) = (d_i - μ l_i / 2) / (1 + μ k_i)`, defined
/// for `1 + μ k_i > 0`. No gradient in a denominator, so the centre of an ellipsoid is fine (its
/// maximum is then at the end of that range, which bisection approaches).
fn quadric_distance(d: V3, k: V3, l: V3, c0: f64) -> f64 {
    let x = |mu: f64| -> Option<V3> {
        let w = [0, 1, 2].map(|i| 1.0 + mu * k[i]);
        w.iter()
            .all(|&w| w > 0.0)
            .then(|| [0, 1, 2].map(|i| (d[i] - 0.5 * mu * l[i]) / w[i]))
    };
    let f = |x: V3| (0..3).map(|i| x[i] * (k[i] * x[i] + l[i])).sum::<f64>() + c0;
    let k_max = k.iter().fold(0.0, |m: f64, &v| m.max(v));
    // The maximum lies in [lo, hi]: x is undefined below lo, and φ'(hi) <= 0.
    let mut lo = -1.0 / k_max;
    let mut hi = 1.0 / k_max;
    while x(hi).is_some_and(|x| f(x) > 0.0) {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        match x(mid) {
            Some(x) if f(x) <= 0.0 => hi = mid,
            _ => lo = mid,
        }
    }
    let x = x(hi).expect("1 + hi k_i > 0");
    let phi = DVec3::from(x).distance_squared(d.into()) + hi * f(x);
    phi.max(0.0).sqrt()
}

/// f64 rounding of a point's distance from a plane, relative to the coordinates involved
/// (weighted by the normal): millions of times f64's epsilon, so exact hits always pass, yet ~4000 times
/// below the host's spawn offset (`gamma(64)` ≈ 3.8e-6 of the same magnitudes), so a point of
/// the plane a spawned ray started on never passes as lying on it.
const ROUNDING: f64 = 1e-9;

/// Slack, in grid cells, for "inside a triangle's footprint": the hit's position along a
/// grazing ray is far less exact than its distance from the plane. It cannot admit a point off
/// the surface: the plane test decides that.
const FOOTPRINT: f64 = 1e-6;

/// The heightfield of the property test: `n` × `n` heights `pos.y + heights[j * 8 + i] * scale`
/// (row `j` along z, column `i` along x) over a square of side `4 scale` with corner `pos`.
struct Terrain {
    o: V3,
    n: usize,
    size: f64,
    h: Vec<Vec<f64>>,
    grid: HeightGrid,
}

impl Terrain {
    fn new(scale: f64, pos: Vec3A, n: usize, heights: &[f64]) -> Terrain {
        let size = 4.0 * scale;
        let o = v3(pos);
        let h: Vec<Vec<f64>> = (0..n)
            .map(|j| (0..n).map(|i| o[1] + heights[j * 8 + i] * scale).collect())
            .collect();
        let rows = h
            .iter()
            .map(|r| {
                let r = r.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>();
                format!("[{}]", r.join(", "))
            })
            .collect::<Vec<_>>()
            .join(", ");
        let params = format!(
            "(origin: ({:?}, {:?}), size: ({size:?}, {size:?}), heights: [{rows}])",
            o[0], o[2]
        );
        let grid = HeightGrid::new(&parse_params(&params).unwrap()).unwrap();
        Terrain {
            o,
            n,
            size,
            h,
            grid,
        }
    }

    /// Grid coordinates (column, row) of a point's footprint, one unit per cell.
    fn grid_xz(&self, p: V3) -> (f64, f64) {
        let cell = self.size / (self.n - 1) as f64;
        ((p[0] - self.o[0]) / cell, (p[2] - self.o[2]) / cell)
    }

    /// Vertical distance to the surface above or below `p`.
    fn distance(&self, p: V3) -> f64 {
        let (n, h) = (self.n, &self.h);
        let (gx, gz) = self.grid_xz(p);
        let (gx, gz) = (gx.clamp(0.0, (n - 1) as f64), gz.clamp(0.0, (n - 1) as f64));
        let (i, j) = (
            (gx.floor() as usize).min(n - 2),
            (gz.floor() as usize).min(n - 2),
        );
        let (fx, fz) = (gx - i as f64, gz - j as f64);
        let (h00, h10, h11, h01) = (h[j][i], h[j][i + 1], h[j + 1][i + 1], h[j + 1][i]);
        let y = if fx >= fz {
            h00 + fx * (h10 - h00) + fz * (h11 - h10)
        } else {
            h00 + fz * (h01 - h00) + fx * (h11 - h01)
        };
        (p[1] - y).abs()
    }

    /// Corner (column `i`, row `j`), placed as the plugin places it.
    fn corner(&self, i: usize, j: usize) -> V3 {
        let at = |k: usize| self.size * (k as f64 / (self.n - 1) as f64);
        [self.o[0] + at(i), self.h[j][i], self.o[2] + at(j)]
    }

    /// Triangle `k` of cell `(i, j)`, split along the (i, j)-(i+1, j+1) diagonal: 0 is the half
    /// with `fx >= fz`, 1 the other; ordered so that `(b - a) × (c - a)` points up.
    fn triangle(&self, i: usize, j: usize, k: usize) -> [V3; 3] {
        let (a, c) = (self.corner(i, j), self.corner(i + 1, j + 1));
        if k == 0 {
            [a, c, self.corner(i + 1, j)]
        } else {
            [a, self.corner(i, j + 1), c]
        }
    }

    /// The facet `(i, j, k)` (cell and triangle) that holds the point `q` of a ray from `from`
    /// and has a normal parallel to `normal`: `q` within rounding of its plane and within
    /// `FOOTPRINT` of its footprint. `None`: `q` is not a point of such a facet.
    fn facet_at(&self, q: V3, from: V3, normal: V3) -> Option<(usize, usize, usize)> {
        let (gx, gz) = self.grid_xz(q);
        let (q, from, normal) = (DVec3::from(q), DVec3::from(from), DVec3::from(normal));
        for j in 0..self.n - 1 {
            for i in 0..self.n - 1 {
                for k in 0..2 {
                    let (fx, fz) = (gx - i as f64, gz - j as f64);
                    // Triangle 0: 0 <= fz <= fx <= 1; triangle 1: 0 <= fx <= fz <= 1.
                    let (lo, hi) = if k == 0 { (fz, fx) } else { (fx, fz) };
                    if lo < -FOOTPRINT || lo > hi + FOOTPRINT || hi > 1.0 + FOOTPRINT {
                        continue;
                    }
                    let [a, b, c] = self.triangle(i, j, k).map(DVec3::from);
                    let m = (b - a).cross(c - a);
                    // Only picks the facet: random neighbours' normals differ by far more,
                    // and equal normals on one plane are the same surface.
                    if m.cross(normal).length() > 1e-6 * m.length() * normal.length() {
                        continue;
                    }
                    let m = m / m.length();
                    let scale = (m.abs() * (q.abs() + a.abs() + from.abs())).element_sum();
                    if m.dot(q - a).abs() <= ROUNDING * scale {
                        return Some((i, j, k));
                    }
                }
            }
        }
        None
    }
}

fn at(r: &Ray, t: f64) -> V3 {
    [0, 1, 2].map(|k| r.origin[k] + t * r.direction[k])
}

/// The heightfield property for one input: a ray from above hits it, and the ray leaving the
/// hit point upward meets the surface again only where it really crosses another facet. (The
/// surface is not convex: across a concave fold, a facet next to the start can lie in the way
/// at any distance, however short; but the leaving ray starts above the start facet's plane and
/// moves away from it, so it can never meet that plane.)
fn heightfield_case(
    scale: f64,
    pos: Vec3A,
    n: usize,
    heights: &[f64],
    from: Vec3A,
    jitter: (f32, f32),
    leave: Vec3A,
) -> Result<(Terrain, Option<Leaving>), TestCaseError> {
    let terrain = Terrain::new(scale, pos, n, heights);
    let size = terrain.size;
    let target = pos + Vec3A::new(jitter.0 * size as f32, 0.0, jitter.1 * size as f32);
    let mut from = from;
    from.y = from.y.abs() + 0.2; // from above, where the light and camera usually are
    let r = aimed(target, 2.0 * size, from.normalize());
    let extent = terrain.o.iter().map(|v| v.abs()).fold(size, f64::max);
    let real = |ray: &Ray, again: &Hit| {
        terrain
            .facet_at(at(ray, again.t), ray.origin, again.normal)
            .is_some()
    };
    let leaving = check(
        &terrain.grid,
        &r,
        |p| terrain.distance(p),
        extent,
        |_, n| n,
        leave,
        real,
    )?;
    Ok((terrain, leaving))
}

/// Rays exactly parallel to a box's faces, inside a face's plane, or along an edge: no NaN,
/// and the hit the geometry dictates.
#[test]
fn box_rays_parallel_to_faces() {
    let b = Cuboid::new(&parse_params("(min: (0, 0, 0), max: (1, 1, 1))").unwrap()).unwrap();
    let ray = |o: V3, d: V3| Ray {
        origin: o,
        direction: d,
        tmin: 0.0,
        tmax: f64::INFINITY,
        time: 0.0,
    };
    for (o, d, t) in [
        // In the plane of the bottom face, +x: enters through the x = 0 face at t = 1.
        ([-1.0, 0.0, 0.5], [1.0, 0.0, 0.0], Some(1.0)),
        ([-1.0, 0.0, 0.5], [1.0, -0.0, -0.0], Some(1.0)),
        // Along an edge.
        ([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], Some(1.0)),
        ([2.0, 1.0, 1.0], [-1.0, 0.0, 0.0], Some(1.0)),
        // Parallel, just outside.
        ([-1.0, -1e-12, 0.5], [1.0, 0.0, 0.0], None),
        ([-1.0, 0.5, 1.0 + 1e-12], [1.0, 0.0, 0.0], None),
        // Inside, parallel to two face pairs: leaves through the third.
        ([0.5, 0.5, 0.5], [0.0, 0.0, -1.0], Some(0.5)),
    ] {
        let h = b.intersect(0, &ray(o, d));
        assert_eq!(h.map(|h| h.t), t, "{o:?} {d:?}");
        if let Some(h) = h {
            assert!(h.normal.iter().all(|v| v.is_finite()) && h.normal != [0.0; 3]);
            assert!(h.uv.iter().all(|v| v.is_finite()));
        }
    }
}

/// The case proptest once shrank a failure to (also in `proptest-regressions/props.txt`): a hit
/// 6.7e-4 from a concave fold. The ray leaving it really crosses the neighbouring facet at
/// t ≈ 9.9e-4; a hit of the start facet there would be acne and is refused.
#[test]
fn heightfield_leaving_across_a_concave_fold() {
    let mut heights = [0.0; 64];
    heights[10] = -0.9847626778304014; // row 1, column 2: the bottom of the fold
    heights[18] = 0.40490939841966794;
    heights[19] = 0.5482355574828219;
    let (terrain, leaving) = heightfield_case(
        1.0,
        Vec3A::ZERO,
        5,
        &heights,
        Vec3A::new(-0.5304499, 0.6761686, -0.51129144),
        (0.46018103, 0.34107244),
        Vec3A::new(-0.96751004, -0.2518868, -0.021847842),
    )
    .unwrap();
    let Leaving { hit, ray, again } = leaving.expect("the ray hits the heightfield");
    // Started on cell (2, 1)'s triangle (2, 1)-(3, 2)-(2, 2), just east of the fold x = 2 ...
    let start = ray.origin;
    assert!(start[0] > 2.0 && start[0] < 2.001, "{start:?}");
    assert_eq!(terrain.facet_at(start, start, hit.normal), None); // lifted off its plane
    let [a, b, c] = terrain.triangle(2, 1, 1);
    let [a, b, c] = [a, b, c].map(DVec3::from);
    let m = (b - a).cross(c - a);
    assert!(m.dot(DVec3::from(start) - a) > 0.0 && m.dot(ray.direction.into()) > 0.0);
    // ... whose plane the western neighbour rises above: the fold is concave.
    assert!(m.dot(DVec3::from(terrain.corner(1, 1)) - a) > 0.5 * m.length());
    // The ray heads west and down into cell (1, 1)'s triangle (1, 1)-(2, 2)-(2, 1).
    let again = again.expect("the leaving ray crosses the neighbouring facet");
    assert!(
        (again.t - 9.886492139770e-4).abs() < 1e-15,
        "t = {}",
        again.t
    );
    let q = at(&ray, again.t);
    assert_eq!(terrain.facet_at(q, start, again.normal), Some((1, 1, 0)));
    assert!(q[0] < 2.0);
    // The same point as a hit of the start facet is not on it: the check has teeth.
    assert_eq!(terrain.facet_at(q, start, hit.normal), None);
}

/// `quadric_distance` against closed forms, including the centre of an ellipsoid (the nearest
/// points are the ends of its shortest axis) and points on a paraboloid's axis.
#[test]
fn quadric_distance_is_exact() {
    let ellipsoid = |d: V3, r: V3| quadric_distance(d, r.map(|r| 1.0 / (r * r)), [0.0; 3], -1.0);
    let close = |got: f64, want: f64| (got - want).abs() <= 1e-12 * want.max(1.0);
    for (d, want) in [
        ([0.0, 0.0, 0.0], 2.0),
        ([3.0, 0.0, 0.0], 1.0),
        ([0.0, 0.0, 9.0], 7.0),
        // Off-centre on a longer axis: nearest at y = 0.5 · 9 / (9 - 4), z² = 4 (1 - y² / 9).
        ([0.0, 0.5, 0.0], 3.8f64.sqrt()),
        ([1e-300, 0.0, 0.0], 2.0),
        ([0.0, 3.0 * 0.6, 2.0 * 0.8], 0.0), // on the surface
    ] {
        let got = ellipsoid(d, [4.0, 3.0, 2.0]);
        assert!(close(got, want), "{d:?}: {got} != {want}");
    }
    // A sphere: | |d| - r |, at any scale.
    for (s, d) in [(1e-4, [1e-4, -2e-4, 0.5e-4]), (1e4, [3e4, 1e4, -2e4])] {
        let got = ellipsoid(d, [s; 3]);
        let want = (DVec3::from(d).length() - s).abs();
        assert!((got - want).abs() <= 1e-12 * s, "{got} != {want}");
    }
    // y = x² + z²: from (0, h, 0), the apex while h <= 1/2 (the radius of curvature there),
    // else the circle where 2 x² = 2 h - 1, at distance √(h - 1/4).
    let paraboloid = |d: V3| quadric_distance(d, [1.0, 0.0, 1.0], [0.0, -1.0, 0.0], 0.0);
    for (h, want) in [
        (-2.0, 2.0f64),
        (0.25, 0.25),
        (0.5, 0.5),
        (3.0, 2.75f64.sqrt()),
    ] {
        let got = paraboloid([0.0, h, 0.0]);
        assert!(close(got, want), "h = {h}: {got} != {want}");
    }
}

/// The case proptest once shrank a failure to (also in `proptest-regressions/props.txt`): a
/// sphere of radius 2e-4 around (3217.5, -3742.8, 5472.8), where f32's spacing is 2.4e-4 in x
/// and y and 4.9e-4 in z. The plugin's f64 hit lies on the surface, and rounding it to f32
/// lands on the centre: 2e-4 off, far inside its error bound (0.025 to 0.042 per axis) but
/// where ∇f = 0, so the old first-order distance |f| / |∇f| was infinite.
#[test]
fn quadric_smaller_than_f32_spacing() {
    let (scale, pos) = (0.001, Vec3A::new(3217.4993, -3742.8179, 5472.7993));
    let (from, jitter) = (
        Vec3A::new(0.5031121, 0.26987594, 0.82100254),
        Vec3A::new(0.5730141, 0.3569052, 0.737749),
    );
    let leaving = quadric_case(scale, pos, (0.2, 0.2, 0.2), false, from, jitter, Vec3A::Z);
    let Leaving { hit, ray, again } = leaving.unwrap().expect("the ray hits the sphere");
    let r = aimed(pos + jitter * scale as f32, 2.0 * scale, from);
    // The f64 hit: on the sphere to within the rounding of the coefficients, which hold
    // |centre|² / r² ≈ 1.4e15 (spacing 0.25, over |∇f| = 2 / r: 2.5e-5 in radius).
    let exact = DVec3::from(at(&host_ray(&r), hit.t)) - DVec3::from(v3(pos));
    assert!((exact.length() - 2e-4).abs() < 2.5e-5, "{exact:?}");
    // The host's point is the centre, 2e-4 from the surface, inside its error bound.
    let (p, p_error, n) = host_surface(&r, &hit);
    assert_eq!(p, pos);
    assert!(p_error.min_element() > 100.0 * 2e-4, "{p_error:?}");
    assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-6);
    // The spawned ray starts well outside and does not come back.
    let o = DVec3::from(ray.origin) - DVec3::from(v3(pos));
    assert!(o.length() > 100.0 * 2e-4, "{o:?}");
    assert!(again.is_none());
}
