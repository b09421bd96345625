//! Property tests of the custom-geometry intersection routines (box, quadric, infinite
//! cylinder, heightfield), called as the host calls them: an f32 render-space ray widened to
//! f64, the hit point taken back to f32 with the host's error bound and left through the
//! host's own `luxon::ray::spawn`.
//!
//! - the hit point lies on the surface, within a bound relative to its magnitude;
//! - the normal is finite and non-zero, and unit length once the host normalises it;
//! - a ray leaving the hit point into the outward hemisphere of a convex shape never hits it
//!   again; leaving a heightfield upward never hits it again near the start (no acne).
//!
//! Also: rays exactly parallel to the box's faces and lying in a face's plane (division by
//! zero in the slab test).

use super::solids::{ClippedQuadric, Cuboid, HeightGrid, LineCylinder};
use luxon::math::{gamma, Vec3A};
use luxon_plugin::{parse_params, CustomShape, Hit, Ray};
use proptest::prelude::*;

type V3 = [f64; 3];

/// Relative tolerance for "on the surface" (the host keeps hit points in f32).
const ON_SURFACE: f64 = 1.0 / 65536.0;

fn cases() -> ProptestConfig {
    ProptestConfig::with_cases(512)
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
    let n = luxon::math::DVec3::from(h.normal)
        .normalize_or_zero()
        .as_vec3();
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

/// Checks a hit of `shape` for the ray; `distance(p)`: distance of a point from the surface;
/// `outward(p, n)`: the normal turned outward; `rehit_after`: the nearest a ray leaving the
/// surface may hit it again (infinity: never).
fn check<S: CustomShape>(
    shape: &S,
    r: &luxon::ray::Ray,
    distance: impl Fn(V3) -> f64,
    size: f64,
    outward: impl Fn(V3, Vec3A) -> Vec3A,
    leave: Vec3A,
    rehit_after: f64,
) -> Result<(), TestCaseError> {
    let Some(h) = shape.intersect(0, &host_ray(r)) else {
        return Ok(());
    };
    prop_assert!(h.t.is_finite() && h.normal.iter().all(|v| v.is_finite()));
    let (p, p_error, n) = host_surface(r, &h);
    prop_assert!((n.length() - 1.0).abs() < 1e-5, "normal {:?}", h.normal);
    let pd: V3 = p.as_dvec3().into();
    let mag = pd.iter().fold(size, |m, v| m.max(v.abs()));
    let dist = distance(pd);
    prop_assert!(dist <= ON_SURFACE * mag, "{pd:?} is {dist} off the surface");
    let n = outward(pd, n);
    let dir = away(n, leave);
    let spawned = luxon::ray::spawn(p, p_error, n, dir, 0.0);
    if let Some(again) = shape.intersect(0, &host_ray(&spawned)) {
        prop_assert!(
            again.t >= rehit_after,
            "left {pd:?} along {dir} and hit the surface again at t = {}",
            again.t
        );
    }
    Ok(())
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
        check(&b, &r, distance, size, |_, n| n, leave, f64::INFINITY)?;
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
        check(&cyl, &r, distance, size, outward, leave, f64::INFINITY)?;
    }

    #[test]
    fn convex_quadrics((scale, pos) in placement(), axes in (0.2f64..2.0, 0.2f64..2.0, 0.2f64..2.0),
                       paraboloid in any::<bool>(), from in unit(), jitter in unit(), leave in unit()) {
        // An ellipsoid (x/a)² + (y/b)² + (z/c)² = 1, or a paraboloid (x/a)² + (z/c)² = y/b,
        // around `pos`, in a clipping box that holds all of the ellipsoid.
        let c = v3(pos);
        let (a, b, cc) = (axes.0 * scale, axes.1 * scale, axes.2 * scale);
        let (ka, kb, kc) = (1.0 / (a * a), 1.0 / (b * b), 1.0 / (cc * cc));
        let k: [f64; 10] = if paraboloid {
            // ka (x - cx)² + kc (z - cz)² - (y - cy) / b
            [ka, 0.0, kc, 0.0, 0.0, 0.0, -2.0 * ka * c[0], -1.0 / b, -2.0 * kc * c[2],
             ka * c[0] * c[0] + kc * c[2] * c[2] + c[1] / b]
        } else {
            [ka, kb, kc, 0.0, 0.0, 0.0, -2.0 * ka * c[0], -2.0 * kb * c[1], -2.0 * kc * c[2],
             ka * c[0] * c[0] + kb * c[1] * c[1] + kc * c[2] * c[2] - 1.0]
        };
        let m = 2.5 * scale;
        let (min, max) = ([c[0] - m, c[1] - m, c[2] - m], [c[0] + m, c[1] + m, c[2] + m]);
        let coefficients = k.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(", ");
        let q = ClippedQuadric::new(&parse_params(&format!(
            "(coefficients: ({coefficients}), min: {}, max: {})", text(min), text(max))).unwrap()).unwrap();
        let r = aimed(pos + jitter * scale as f32, 2.0 * scale, from);
        // First-order distance |f| / |∇f|, in coordinates relative to the centre.
        let distance = |p: V3| {
            let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            let (f, g) = if paraboloid {
                (ka * d[0] * d[0] + kc * d[2] * d[2] - d[1] / b,
                 [2.0 * ka * d[0], -1.0 / b, 2.0 * kc * d[2]])
            } else {
                (ka * d[0] * d[0] + kb * d[1] * d[1] + kc * d[2] * d[2] - 1.0,
                 [2.0 * ka * d[0], 2.0 * kb * d[1], 2.0 * kc * d[2]])
            };
            f.abs() / (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
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
            if n.as_dvec3().dot(g.into()) < 0.0 { -n } else { n }
        };
        let size = c.iter().map(|v| v.abs()).fold(m, f64::max);
        if let Some(h) = q.intersect(0, &host_ray(&r)) {
            let p: V3 = r.at(h.t as f32).as_dvec3().into();
            let rehit = if inner(p) { f64::INFINITY } else { 0.0 };
            check(&q, &r, distance, size, outward, leave, rehit)?;
        }
    }

    #[test]
    fn heightfield((scale, pos) in placement(), n in 2usize..8,
                   heights in proptest::collection::vec(-1.0f64..1.0, 64),
                   from in unit(), jitter in (0.0f32..1.0, 0.0f32..1.0), leave in unit()) {
        let size = 4.0 * scale;
        let o = v3(pos);
        let h: Vec<Vec<f64>> = (0..n)
            .map(|j| (0..n).map(|i| o[1] + heights[j * 8 + i] * scale).collect())
            .collect();
        let rows = h.iter()
            .map(|r| format!("[{}]", r.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(", ")))
            .collect::<Vec<_>>().join(", ");
        let g = HeightGrid::new(&parse_params(&format!(
            "(origin: ({:?}, {:?}), size: ({size:?}, {size:?}), heights: [{rows}])", o[0], o[2])).unwrap()).unwrap();
        let target = pos + Vec3A::new(jitter.0 * size as f32, 0.0, jitter.1 * size as f32);
        let mut from = from;
        from.y = from.y.abs() + 0.2; // from above, where the light and camera usually are
        let r = aimed(target, 2.0 * size, from.normalize());
        let cell = size / (n - 1) as f64;
        // Vertical distance to the cell's triangle (split along the (i, j)-(i+1, j+1) diagonal).
        let distance = |p: V3| {
            let gx = ((p[0] - o[0]) / cell).clamp(0.0, (n - 1) as f64);
            let gz = ((p[2] - o[2]) / cell).clamp(0.0, (n - 1) as f64);
            let (i, j) = ((gx.floor() as usize).min(n - 2), (gz.floor() as usize).min(n - 2));
            let (fx, fz) = (gx - i as f64, gz - j as f64);
            let (h00, h10, h11, h01) = (h[j][i], h[j][i + 1], h[j + 1][i + 1], h[j + 1][i]);
            let y = if fx >= fz {
                h00 + fx * (h10 - h00) + fz * (h11 - h10)
            } else {
                h00 + fz * (h01 - h00) + fx * (h11 - h01)
            };
            (p[1] - y).abs()
        };
        let extent = o.iter().map(|v| v.abs()).fold(size, f64::max);
        // Leaving upward may meet a higher hill, but never the surface it starts on.
        check(&g, &r, distance, extent, |_, n| n, leave, 1e-3 * scale)?;
    }
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
