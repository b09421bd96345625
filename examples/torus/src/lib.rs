//! # luxon-torus: a torus, the example primitive plugin
//!
//! A complete custom-geometry plugin with its tests. This crate is built inside Luxon's
//! workspace (its `Cargo.toml` inherits the workspace's settings, and its tests use the
//! renderer), so a copy does not build elsewhere: to start a primitive of your own,
//! `luxon new-plugin NAME --kind primitive` writes a crate that builds anywhere, and this one
//! shows how far it can go. A primitive plugin is a `cdylib` depending on `luxon-plugin` and
//! `serde` only, and needs four things:
//!
//! 1. A params struct with `#[derive(serde::Deserialize)]` and `#[serde(deny_unknown_fields)]`:
//!    the scene's `params: (...)` arrive as RON text and are parsed into it (unknown or missing
//!    fields become errors pointing at the scene file).
//! 2. A type implementing [`Describe`] (name used by scenes, one-line description, parameter
//!    table shown by `luxon plugins`) and [`Primitive`], whose `create` validates the params
//!    (`luxon_plugin::finite`, range checks) and hands geometry to the host: `out.spheres`,
//!    `out.planes` or `out.mesh` when the shape can be expressed that way (the core intersects
//!    those itself, fastest), otherwise `out.custom(shape)`.
//! 3. For custom geometry, a type implementing [`CustomShape`] (`Send + Sync`: the host calls it
//!    from every render thread):
//!    - `count()`: number of primitives; each gets its own BVH leaf (a particle system would
//!      return one per particle and use the `index` argument below);
//!    - `bounds(index)`: a world-space box containing primitive `index`; tighter boxes mean
//!      fewer calls to `intersect`;
//!    - `intersect(index, ray)`: the nearest hit with `ray.tmin < t < ray.tmax`, its normal
//!      (world space, any length, any orientation) and texture coordinates. Rays are world
//!      space `f64` and their direction need not be unit length: `t` is in its units;
//!    - `occluded(index, ray)`: whether there is any such hit (shadow rays); the default calls
//!      `intersect`, override it when a cheaper answer exists.
//! 4. One `luxon_plugin::export!(library: "...", primitives: [...])` line.
//!
//! Panics in any of these are caught by the SDK and reported as errors naming the plugin.
//!
//! ## Build and use
//! ```text
//! cargo build --release -p luxon-torus          # -> target/release/libluxon_torus.so
//! target/release/luxon render scenes/torus.ron -o torus.png
//! ```
//! `luxon` finds the libraries beside its executable. A plugin built elsewhere is found
//! through `LUXON_PLUGIN_PATH=DIR luxon render scene.ron`, or a scene names the directory (or
//! the `.so` itself), relative to the scene file: `plugin_path: ["../target/release"]`.
//!
//! The library records the plugin ABI it was built for (ABI 3: `luxon-plugin` 0.3); Luxon
//! skips a library built for another and says so, naming both versions: rebuild it against the
//! SDK of the Luxon that loads it. A shape that builds big arrays (a tessellated mesh) should
//! allocate them with `ctx.alloc_vec`, which keeps to the memory budget the host gives the call
//! and turns a refused allocation into an error instead of an abort.
//!
//! ## `torus`
//! ```text
//! center: (x, y, z) = (0, 0, 0)  centre of the ring
//! axis: (x, y, z) = (0, 1, 0)  normal of the ring's plane, any non-zero length
//! major: f64 > 0  radius of the ring (centre to tube centre)
//! minor: f64 > 0, < major  radius of the tube
//! ```
//! Texture coordinates: `u` is the angle around the axis, `v` the angle around the tube, both
//! divided by 2π.
//!
//! ```text
//! objects: [
//!     (plugin: "torus", params: (center: (0, 1, 0), axis: (0, 1, 0), major: 1.0, minor: 0.3), material: "gold"),
//! ]
//! ```
//!
//! ## How the intersection works
//! The ray is moved into the torus frame (centre at the origin, axis = z, lengths in units of
//! the major radius R), where the surface is the zero set of the quartic
//! `f(p) = (|p|² + R² - r²)² - 4R²(x² + y²)`, negative inside the tube. The search interval is the
//! ray's `(tmin, tmax)` clipped to the bounding sphere and the slab `|z| <= r`. Along the ray `f`
//! is a quartic in `t` whose fourth derivative is a positive constant, so its third derivative
//! has one root, which splits the interval where the second derivative is monotone; its roots
//! split where the first derivative is monotone, and so on. On each monotone piece a root exists
//! exactly when the ends differ in sign and is found by safeguarded Newton iteration. This never
//! skips a pair of close roots (a grazing hit), which sampling-based searches can.

#![forbid(unsafe_code)]

use luxon_plugin::{
    finite, invalid, Aabb, Context, CustomShape, Describe, Error, Geometry, Hit, Primitive, Ray,
};
use serde::Deserialize;

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct TorusParams {
    #[serde(default)]
    pub center: [f64; 3],
    #[serde(default = "default_axis")]
    pub axis: [f64; 3],
    pub major: f64,
    pub minor: f64,
}

fn default_axis() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

pub struct TorusEntry;

impl Describe for TorusEntry {
    const NAME: &'static str = "torus";
    const DESCRIPTION: &'static str =
        "A torus (ring with a round tube), intersected as custom geometry; the example plugin.";
    const PARAMS: &'static str = "center: (x, y, z) = (0, 0, 0)  centre of the ring
axis: (x, y, z) = (0, 1, 0)  normal of the ring's plane, any non-zero length
major: f64 > 0  radius of the ring (centre to tube centre)
minor: f64 > 0, < major  radius of the tube";
}

impl Primitive for TorusEntry {
    type Params = TorusParams;
    fn create(p: TorusParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(Torus::new(&p)?)
    }
}

luxon_plugin::export!(library: "luxon-torus", primitives: [TorusEntry]);

// ------------------------------------------------------------------------------------------------
// Vector helpers
// ------------------------------------------------------------------------------------------------

type V3 = [f64; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn mul(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Unit vector, or `None` for zero; scales first so tiny or huge inputs do not under/overflow.
fn normalize(v: V3) -> Option<V3> {
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if m == 0.0 || !m.is_finite() {
        return None;
    }
    let w = mul(v, 1.0 / m);
    Some(mul(w, 1.0 / dot(w, w).sqrt()))
}

/// Two unit vectors completing `w` to a right-handed orthonormal frame, without a branch that
/// breaks down near any particular axis (Duff et al., "Building an orthonormal basis, revisited").
fn frame(w: V3) -> (V3, V3) {
    let sign = 1f64.copysign(w[2]);
    let a = -1.0 / (sign + w[2]);
    let b = w[0] * w[1] * a;
    (
        [1.0 + sign * w[0] * w[0] * a, sign * b, -sign * w[0]],
        [b, sign + w[1] * w[1] * a, -w[1]],
    )
}

// ------------------------------------------------------------------------------------------------
// The shape
// ------------------------------------------------------------------------------------------------

/// A validated torus, ready to intersect.
#[derive(Clone, Debug)]
pub struct Torus {
    center: V3,
    /// Orthonormal frame: `w` is the axis.
    u: V3,
    v: V3,
    w: V3,
    major: f64,
    minor: f64,
}

impl Torus {
    pub fn new(p: &TorusParams) -> Result<Torus, Error> {
        let center = finite("center", p.center)?;
        let w = normalize(finite("axis", p.axis)?)
            .ok_or_else(|| invalid("parameter `axis` has zero length"))?;
        let [major] = finite("major", [p.major])?;
        let [minor] = finite("minor", [p.minor])?;
        if major <= 0.0 {
            return Err(invalid(format!(
                "parameter `major` must be > 0, got {major}"
            )));
        }
        if minor <= 0.0 {
            return Err(invalid(format!(
                "parameter `minor` must be > 0, got {minor}"
            )));
        }
        if minor >= major {
            return Err(invalid(format!(
                "parameter `minor` ({minor}) must be less than `major` ({major}); \
                 a torus whose tube reaches the axis is not supported"
            )));
        }
        let (u, v) = frame(w);
        Ok(Torus {
            center,
            u,
            v,
            w,
            major,
            minor,
        })
    }

    /// World direction from the torus frame.
    fn to_world(&self, a: V3) -> V3 {
        add(add(mul(self.u, a[0]), mul(self.v, a[1])), mul(self.w, a[2]))
    }

    /// Nearest hit in `(ray.tmin, ray.tmax)`: its `t` and the point in the unit frame (R = 1).
    fn first_hit(&self, ray: &Ray) -> Option<(f64, V3)> {
        if !ray
            .origin
            .iter()
            .chain(&ray.direction)
            .all(|x| x.is_finite())
        {
            return None;
        }
        // The frame is orthonormal and both origin and direction are scaled by 1/R, so `t`
        // means the same here as in world space.
        let s = 1.0 / self.major;
        let rel = sub(ray.origin, self.center);
        let o = mul([dot(rel, self.u), dot(rel, self.v), dot(rel, self.w)], s);
        let d = mul(
            [
                dot(ray.direction, self.u),
                dot(ray.direction, self.v),
                dot(ray.direction, self.w),
            ],
            s,
        );
        let dd = dot(d, d);
        if dd == 0.0 || !dd.is_finite() {
            return None;
        }
        let r = self.minor * s;
        // Margin so that clipping never cuts off a root on the boundary (f > 0 there anyway).
        let pad = 1.0 + 1e-6;

        // Bounding sphere of radius 1 + r, via the closest approach for accuracy far away.
        let tc = -dot(o, d) / dd;
        let perp = add(o, mul(d, tc));
        let rho = (1.0 + r) * pad;
        let disc = rho * rho - dot(perp, perp);
        if disc < 0.0 {
            return None;
        }
        let half = (disc / dd).sqrt();
        let (mut a, mut b) = (tc - half, tc + half);

        // Slab |z| <= r.
        let h = r * pad;
        if d[2] == 0.0 {
            if o[2].abs() > h {
                return None;
            }
        } else {
            let (t1, t2) = ((-h - o[2]) / d[2], (h - o[2]) / d[2]);
            a = a.max(t1.min(t2));
            b = b.min(t1.max(t2));
        }
        a = a.max(ray.tmin);
        b = b.min(ray.tmax);
        // Empty, or NaN from an absurd ray.
        if a.partial_cmp(&b) != Some(std::cmp::Ordering::Less) {
            return None;
        }

        // Parametrise from `a` so the polynomial's argument stays small.
        let q = Quartic {
            p0: add(o, mul(d, a)),
            d,
            k: 1.0 - r * r,
            tol: 1e-15 / dd.sqrt(),
        };
        let len = b - a;
        let mut cuts = Points::new();
        cuts.push(0.0);
        cuts.extend(&q.roots(1, len));
        cuts.push(len);
        for seg in cuts.as_slice().windows(2) {
            let (lo, hi) = (seg[0], seg[1]);
            let (f_lo, f_hi) = (q.eval(lo)[0], q.eval(hi)[0]);
            if (f_lo > 0.0) != (f_hi > 0.0) {
                let x = q.refine(0, lo, hi, f_lo);
                let t = a + x;
                if t > ray.tmin && t < ray.tmax {
                    return Some((t, q.point(x)));
                }
            }
        }
        None
    }
}

impl CustomShape for Torus {
    fn count(&self) -> u64 {
        1
    }

    fn bounds(&self, _index: u64) -> Aabb {
        // The ring (a circle of radius R perpendicular to w) reaches R * sqrt(1 - w_i²) along
        // world axis i; the tube adds r in every direction.
        let mut min = [0.0; 3];
        let mut max = [0.0; 3];
        for i in 0..3 {
            let ring = self.major * (1.0 - self.w[i] * self.w[i]).max(0.0).sqrt();
            // Rounding margin.
            let half = (ring + self.minor) * (1.0 + 1e-9);
            min[i] = self.center[i] - half;
            max[i] = self.center[i] + half;
        }
        Aabb { min, max }
    }

    fn intersect(&self, _index: u64, ray: &Ray) -> Option<Hit> {
        let (t, p) = self.first_hit(ray)?;
        // Gradient of f in the unit frame (R = 1): 4 s p - 8 (x, y, 0), s = |p|² + 1 - r².
        let r = self.minor / self.major;
        let s = dot(p, p) + 1.0 - r * r;
        let grad = [
            4.0 * s * p[0] - 8.0 * p[0],
            4.0 * s * p[1] - 8.0 * p[1],
            4.0 * s * p[2],
        ];
        let normal = normalize(self.to_world(grad)).unwrap_or(self.w);
        let turn = |a: f64| {
            let x = a / std::f64::consts::TAU;
            (if x < 0.0 { x + 1.0 } else { x }) as f32
        };
        let ring = p[0].hypot(p[1]);
        Some(Hit {
            t,
            normal,
            uv: [turn(p[1].atan2(p[0])), turn(p[2].atan2(ring - 1.0))],
        })
    }

    fn occluded(&self, _index: u64, ray: &Ray) -> bool {
        self.first_hit(ray).is_some()
    }
}

// ------------------------------------------------------------------------------------------------
// Root finding
// ------------------------------------------------------------------------------------------------

/// f along the ray `p0 + x d` in the unit frame, with its derivatives in `x`.
struct Quartic {
    p0: V3,
    d: V3,
    /// 1 - r² (R = 1).
    k: f64,
    /// Absolute precision wanted in `x`: 1e-15 R of travel.
    tol: f64,
}

impl Quartic {
    fn point(&self, x: f64) -> V3 {
        add(self.p0, mul(self.d, x))
    }

    /// `[f, f', f'', f''']` at `x`. With s = |p|² + k and q = x² + y², f = s² - 4q; s and q are
    /// quadratics in `x` whose derivatives are cheap.
    fn eval(&self, x: f64) -> [f64; 4] {
        let (p, d) = (self.point(x), self.d);
        let s = dot(p, p) + self.k;
        let s1 = 2.0 * dot(p, d);
        let s2 = 2.0 * dot(d, d);
        let q = p[0] * p[0] + p[1] * p[1];
        let q1 = 2.0 * (p[0] * d[0] + p[1] * d[1]);
        let q2 = 2.0 * (d[0] * d[0] + d[1] * d[1]);
        [
            s * s - 4.0 * q,
            2.0 * s * s1 - 4.0 * q1,
            2.0 * s1 * s1 + 2.0 * s * s2 - 4.0 * q2,
            6.0 * s1 * s2,
        ]
    }

    /// The roots of derivative `level` (1..=3) in `(0, len)`, ascending.
    fn roots(&self, level: usize, len: f64) -> Points {
        let mut out = Points::new();
        if level == 3 {
            // f''' = 6 s' s'' vanishes only where s' = 2 p·d does: the closest approach.
            let x = -dot(self.p0, self.d) / dot(self.d, self.d);
            if x > 0.0 && x < len {
                out.push(x);
            }
            return out;
        }
        let mut cuts = Points::new();
        cuts.push(0.0);
        cuts.extend(&self.roots(level + 1, len));
        cuts.push(len);
        for seg in cuts.as_slice().windows(2) {
            let (lo, hi) = (seg[0], seg[1]);
            let (g_lo, g_hi) = (self.eval(lo)[level], self.eval(hi)[level]);
            if (g_lo > 0.0) != (g_hi > 0.0) {
                out.push(self.refine(level, lo, hi, g_lo));
            }
        }
        out
    }

    /// The root of derivative `level` in `[lo, hi]`, where it is monotone and changes sign
    /// (`g_lo` is its value at `lo`): Newton steps, falling back to bisection whenever a step
    /// leaves the bracket or does not shrink fast enough.
    fn refine(&self, level: usize, mut lo: f64, mut hi: f64, g_lo: f64) -> f64 {
        let lo_positive = g_lo > 0.0;
        let mut x = 0.5 * (lo + hi);
        let mut step_before = hi - lo;
        for _ in 0..100 {
            let e = self.eval(x);
            let g = e[level];
            if g == 0.0 {
                return x;
            }
            if (g > 0.0) == lo_positive {
                lo = x;
            } else {
                hi = x;
            }
            // `level` <= 2, so its derivative is in `e`.
            let dg = e[level + 1];
            let newton = x - g / dg;
            let step = (newton - x).abs();
            let next = if newton > lo && newton < hi && 2.0 * step <= step_before {
                step_before = step;
                newton
            } else {
                step_before = hi - lo;
                0.5 * (lo + hi)
            };
            if hi - lo <= self.tol || step_before <= self.tol || next == x {
                return next;
            }
            x = next;
        }
        x
    }
}

/// A fixed-capacity list of parameters along the ray (at most the 3 roots of a cubic plus the
/// two interval ends), so intersecting allocates nothing.
struct Points {
    items: [f64; 5],
    len: usize,
}

impl Points {
    fn new() -> Points {
        Points {
            items: [0.0; 5],
            len: 0,
        }
    }

    fn push(&mut self, x: f64) {
        self.items[self.len] = x;
        self.len += 1;
    }

    fn extend(&mut self, other: &Points) {
        for &x in other.as_slice() {
            self.push(x);
        }
    }

    fn as_slice(&self) -> &[f64] {
        &self.items[..self.len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn torus(center: V3, axis: V3, major: f64, minor: f64) -> Torus {
        Torus::new(&TorusParams {
            center,
            axis,
            major,
            minor,
        })
        .unwrap()
    }

    fn ray(origin: V3, direction: V3) -> Ray {
        Ray {
            origin,
            direction,
            tmin: 0.0,
            tmax: f64::INFINITY,
            time: 0.0,
        }
    }

    /// Signed distance to the surface, computed independently of the solver.
    fn distance(t: &Torus, world: V3) -> f64 {
        let rel = sub(world, t.center);
        let z = dot(rel, t.w);
        let ring = sub(rel, mul(t.w, z));
        let rho = dot(ring, ring).sqrt();
        (rho - t.major).hypot(z) - t.minor
    }

    /// Unit normal at a hit, and the outward direction from the tube's centre line.
    fn normal_and_outward(t: &Torus, world: V3, hit: &Hit) -> (V3, V3) {
        let rel = sub(world, t.center);
        let z = dot(rel, t.w);
        let ring = sub(rel, mul(t.w, z));
        let spine = mul(normalize(ring).unwrap(), t.major);
        (
            normalize(hit.normal).unwrap(),
            normalize(sub(rel, spine)).unwrap(),
        )
    }

    fn at(r: &Ray, t: f64) -> V3 {
        add(r.origin, mul(r.direction, t))
    }

    const Z: V3 = [0.0, 0.0, 1.0];

    #[test]
    fn params_from_ron_with_defaults() {
        let p: TorusParams = luxon_plugin::parse_params("(major: 2, minor: 0.5)").unwrap();
        assert_eq!((p.center, p.axis), ([0.0; 3], [0.0, 1.0, 0.0]));
        let t = Torus::new(&p).unwrap();
        assert_eq!(t.w, [0.0, 1.0, 0.0]);
        let e = luxon_plugin::parse_params::<TorusParams>("(major: 2, minr: 0.5)").unwrap_err();
        assert!(e.message.contains("did you mean `minor`"), "{}", e.message);
    }

    #[test]
    fn params_errors() {
        let e = |center, axis, major, minor| {
            Torus::new(&TorusParams {
                center,
                axis,
                major,
                minor,
            })
            .unwrap_err()
            .message
        };
        assert!(e([0.0; 3], [0.0; 3], 1.0, 0.5).contains("`axis` has zero length"));
        assert!(e([0.0; 3], Z, 0.0, 0.5).contains("`major` must be > 0"));
        assert!(e([0.0; 3], Z, 1.0, -0.5).contains("`minor` must be > 0"));
        assert!(e([0.0; 3], Z, 1.0, 1.0).contains("must be less than `major`"));
        assert!(e([f64::NAN, 0.0, 0.0], Z, 1.0, 0.5).contains("`center` must be finite"));
        assert!(e([0.0; 3], [0.0, f64::INFINITY, 0.0], 1.0, 0.5).contains("`axis` must be finite"));
        assert!(e([0.0; 3], Z, f64::INFINITY, 0.5).contains("`major` must be finite"));
    }

    #[test]
    fn ray_along_axis_through_hole_misses() {
        let t = torus([0.0; 3], Z, 1.0, 0.25);
        for dir in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]] {
            let r = ray([0.0, 0.0, -5.0 * dir[2]], dir);
            assert!(t.intersect(0, &r).is_none());
            assert!(!t.occluded(0, &r));
        }
        // Parallel to the axis but through the tube: hits the bottom of the tube.
        let r = ray([1.0, 0.0, -5.0], Z);
        let hit = t.intersect(0, &r).unwrap();
        assert!((hit.t - 4.75).abs() < 1e-12, "{}", hit.t);
    }

    #[test]
    fn ray_through_tube_hits_at_analytic_t() {
        let t = torus([0.0; 3], Z, 1.0, 0.25);
        let r = ray([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let hit = t.intersect(0, &r).unwrap();
        assert!((hit.t - 1.75).abs() < 1e-13, "{}", hit.t);
        let n = normalize(hit.normal).unwrap();
        assert!(dot(n, [-1.0, 0.0, 0.0]) > 1.0 - 1e-12, "{n:?}");
        assert!(t.occluded(0, &r));
        // A non-unit direction scales t.
        let r = ray([-3.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
        assert!((t.intersect(0, &r).unwrap().t - 0.875).abs() < 1e-13);
    }

    #[test]
    fn ray_from_inside_tube_hits_far_wall() {
        let t = torus([0.0; 3], Z, 1.0, 0.25);
        for (dir, expected) in [
            ([1.0, 0.0, 0.0], 0.25),
            ([0.0, 0.0, 1.0], 0.25),
            ([-1.0, 0.0, 0.0], 0.25),
        ] {
            let r = ray([-1.0, 0.0, 0.0], dir);
            let hit = t.intersect(0, &r).unwrap();
            assert!((hit.t - expected).abs() < 1e-13, "{dir:?}: {}", hit.t);
            let (n, out) = normal_and_outward(&t, at(&r, hit.t), &hit);
            assert!(dot(n, out) > 1.0 - 1e-12, "{n:?} vs {out:?}");
        }
    }

    #[test]
    fn tmin_and_tmax_exclude_hits() {
        let t = torus([0.0; 3], Z, 1.0, 0.25);
        let mut r = ray([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        // Hits along this ray: 1.75, 2.25, 3.75, 4.25.
        r.tmax = 1.7;
        assert!(t.intersect(0, &r).is_none());
        assert!(!t.occluded(0, &r));
        r.tmax = 1.75 - 1e-9;
        assert!(t.intersect(0, &r).is_none());
        // At the boundary rounding may go either way, but never outside the interval.
        r.tmax = 1.75;
        if let Some(h) = t.intersect(0, &r) {
            assert!(h.t < 1.75, "{}", h.t);
        }
        r.tmax = 1.8;
        assert!((t.intersect(0, &r).unwrap().t - 1.75).abs() < 1e-13);
        r.tmin = 1.8;
        r.tmax = f64::INFINITY;
        assert!((t.intersect(0, &r).unwrap().t - 2.25).abs() < 1e-13);
        r.tmin = 2.3;
        assert!((t.intersect(0, &r).unwrap().t - 3.75).abs() < 1e-13);
        r.tmin = 4.3;
        assert!(t.intersect(0, &r).is_none());
    }

    #[test]
    fn rotated_axis_and_offset_centre() {
        let c = [1.0, 2.0, 3.0];
        let axis = [1.0, 1.0, 1.0];
        let t = torus(c, axis, 2.0, 0.5);
        let w = normalize(axis).unwrap();
        let e = normalize([1.0, -1.0, 0.0]).unwrap();
        // In the ring's plane through the centre: enters the tube at distance R + r = 2.5.
        let r = ray(sub(c, mul(e, 6.0)), e);
        let hit = t.intersect(0, &r).unwrap();
        assert!((hit.t - 3.5).abs() < 1e-12, "{}", hit.t);
        assert!(dot(normalize(hit.normal).unwrap(), e) < -1.0 + 1e-12);
        // Along the axis: through the hole.
        assert!(t.intersect(0, &ray(sub(c, mul(w, 5.0)), w)).is_none());
        // Parallel to the axis through the tube centre line: hits at distance 5 - r.
        let r = ray(add(sub(c, mul(w, 5.0)), mul(e, 2.0)), w);
        let hit = t.intersect(0, &r).unwrap();
        assert!((hit.t - 4.5).abs() < 1e-12, "{}", hit.t);
        assert!(dot(normalize(hit.normal).unwrap(), w) < -1.0 + 1e-12);
        // The default axis is y.
        let t = torus(c, [0.0, 1.0, 0.0], 2.0, 0.5);
        let r = ray([1.0, 2.0, -10.0], Z);
        assert!((t.intersect(0, &r).unwrap().t - 10.5).abs() < 1e-12);
    }

    #[test]
    fn grazing_ray_tangent_to_top_of_tube_is_finite() {
        let t = torus([0.0; 3], Z, 1.0, 0.25);
        for dz in [0.0, 1e-15, -1e-15, 1e-9, -1e-9, 1e-6, -1e-6] {
            let r = ray([-3.0, 0.0, 0.25 + dz], [1.0, 0.0, 0.0]);
            let hit = t.intersect(0, &r);
            if dz < -1e-12 {
                let hit = hit.expect("a ray just below the top must hit");
                // Enters at x = -1 - sqrt(2 r dz) approximately.
                let expected = 2.0 - (0.5 * -dz).sqrt();
                assert!(
                    (hit.t - expected).abs() < 1e-6,
                    "{dz}: {} vs {expected}",
                    hit.t
                );
            }
            if dz > 1e-12 {
                assert!(hit.is_none(), "{dz}: {hit:?}");
            }
            if let Some(h) = hit {
                assert!(
                    h.t.is_finite() && h.normal.iter().all(|x| x.is_finite()),
                    "{h:?}"
                );
                assert!(h.uv.iter().all(|x| x.is_finite()));
                assert!((h.t - 2.0).abs() < 1e-3, "{dz}: {}", h.t);
                assert!(normalize(h.normal).unwrap()[2] > 0.99, "{h:?}");
            }
        }
        // Tangent to the outer equator.
        let r = ray([-3.0, 1.25, 0.0], [1.0, 0.0, 0.0]);
        if let Some(h) = t.intersect(0, &r) {
            assert!(h.t.is_finite() && (h.t - 3.0).abs() < 1e-3, "{h:?}");
        }
    }

    #[test]
    fn far_origin_keeps_precision() {
        let t = torus([0.0; 3], Z, 1.0, 0.25);
        let r = ray([-1e6, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let hit = t.intersect(0, &r).unwrap();
        assert!((hit.t - (1e6 - 1.25)).abs() < 1e-9, "{}", hit.t);
        // Large and tiny scales behave the same.
        for s in [1e-6, 1e6] {
            let t = torus([0.0; 3], Z, s, 0.25 * s);
            let r = ray([-3.0 * s, 0.0, 0.0], [1.0, 0.0, 0.0]);
            let hit = t.intersect(0, &r).unwrap();
            assert!((hit.t / s - 1.75).abs() < 1e-12, "{s}: {}", hit.t);
        }
    }

    #[test]
    fn uv_are_angles_over_two_pi() {
        let t = torus([0.0; 3], Z, 1.0, 0.25);
        // Outer equator at angle 90° around the axis: u = 1/4, v = 0.
        let hit = t
            .intersect(0, &ray([0.0, 3.0, 0.0], [0.0, -1.0, 0.0]))
            .unwrap();
        assert!(
            (hit.uv[0] - 0.25).abs() < 1e-6 && hit.uv[1].abs() < 1e-6,
            "{:?}",
            hit.uv
        );
        // Top of the tube at angle 180°: u = 1/2, v = 1/4.
        let hit = t
            .intersect(0, &ray([-1.0, 0.0, 3.0], [0.0, 0.0, -1.0]))
            .unwrap();
        assert!(
            (hit.uv[0] - 0.5).abs() < 1e-6 && (hit.uv[1] - 0.25).abs() < 1e-6,
            "{:?}",
            hit.uv
        );
    }

    /// Deterministic pseudo-random numbers in [0, 1).
    fn rng(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    fn random_torus_and_rays(seed: u64, rays: usize) -> (Torus, Vec<Ray>) {
        let mut s = seed;
        let mut g = |lo: f64, hi: f64| lo + (hi - lo) * rng(&mut s);
        let major = g(0.5, 3.0);
        let t = torus(
            [g(-2.0, 2.0), g(-2.0, 2.0), g(-2.0, 2.0)],
            [g(-1.0, 1.0), g(-1.0, 1.0), g(-1.0, 1.0)],
            major,
            major * g(0.05, 0.95),
        );
        let reach = t.major + t.minor;
        let rays = (0..rays)
            .map(|_| {
                let origin = add(
                    t.center,
                    [g(-3.0, 3.0), g(-3.0, 3.0), g(-3.0, 3.0)].map(|x| x * reach),
                );
                let target = add(
                    t.center,
                    [g(-1.0, 1.0), g(-1.0, 1.0), g(-1.0, 1.0)].map(|x| x * reach),
                );
                ray(origin, mul(sub(target, origin), g(0.2, 3.0)))
            })
            .collect();
        (t, rays)
    }

    #[test]
    fn hits_lie_on_surface_with_outward_unit_normals_inside_bounds() {
        let mut hits = 0;
        for seed in 0..40 {
            let (t, rays) = random_torus_and_rays(seed, 200);
            let b = t.bounds(0);
            let scale = t.major + t.minor;
            for r in &rays {
                let Some(hit) = t.intersect(0, r) else {
                    continue;
                };
                hits += 1;
                let p = at(r, hit.t);
                assert!(
                    distance(&t, p).abs() < 1e-12 * scale,
                    "{seed}: off by {}",
                    distance(&t, p)
                );
                let (n, out) = normal_and_outward(&t, p, &hit);
                assert!((dot(n, n).sqrt() - 1.0).abs() < 1e-12);
                assert!(dot(n, out) > 1.0 - 1e-9, "{seed}: {n:?} vs {out:?}");
                for i in 0..3 {
                    assert!(
                        b.min[i] <= p[i] && p[i] <= b.max[i],
                        "{seed}: {p:?} outside {b:?}"
                    );
                }
            }
        }
        assert!(hits > 1000, "{hits}");
    }

    /// Dense sampling of the distance along each ray must not find the surface before the
    /// solver's hit, nor an inside point the solver missed.
    #[test]
    fn agrees_with_dense_sampling() {
        for seed in 100..130 {
            let (t, rays) = random_torus_and_rays(seed, 100);
            let scale = t.major + t.minor;
            for r in &rays {
                let hit = t.intersect(0, r);
                assert_eq!(hit.is_some(), t.occluded(0, r));
                let len = dot(r.direction, r.direction).sqrt();
                let end = hit.map_or(8.0 * scale / len, |h| h.t);
                let n = 4000;
                let start_inside = distance(&t, r.origin) < 0.0;
                for i in 1..n {
                    let s = end * i as f64 / n as f64;
                    let d = distance(&t, at(r, s));
                    // Before the hit the ray stays on its starting side (within rounding).
                    if start_inside {
                        assert!(
                            d < 1e-9 * scale,
                            "{seed}: left the tube at {s} before {end}"
                        );
                    } else {
                        assert!(d > -1e-9 * scale, "{seed}: entered at {s} before {hit:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn bounds_are_tight_for_axis_aligned_torus() {
        let t = torus([1.0, 2.0, 3.0], Z, 2.0, 0.5);
        let b = t.bounds(0);
        let expect_min = [-1.5, -0.5, 2.5];
        let expect_max = [3.5, 4.5, 3.5];
        for i in 0..3 {
            assert!((b.min[i] - expect_min[i]).abs() < 1e-6, "{b:?}");
            assert!((b.max[i] - expect_max[i]).abs() < 1e-6, "{b:?}");
        }
        assert_eq!(t.count(), 1);
    }

    #[test]
    fn degenerate_rays_miss() {
        let t = torus([0.0; 3], Z, 1.0, 0.25);
        assert!(t.intersect(0, &ray([-3.0, 0.0, 0.0], [0.0; 3])).is_none());
        assert!(t
            .intersect(0, &ray([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]))
            .is_none());
        assert!(t
            .intersect(0, &ray([-3.0, 0.0, 0.0], [f64::INFINITY, 0.0, 0.0]))
            .is_none());
    }
}

/// Property tests as the host calls the torus: an f32 render-space ray widened to f64, the hit
/// kept in f32 with the host's error bound and left through the host's `luxon::ray::spawn`.
#[cfg(test)]
mod props {
    use super::*;
    use luxon::math::{gamma, Vec3A};
    use proptest::prelude::*;

    fn unit() -> impl Strategy<Value = Vec3A> {
        (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
            .prop_filter("not too short", |(x, y, z)| x * x + y * y + z * z > 0.01)
            .prop_map(|(x, y, z)| Vec3A::new(x, y, z).normalize())
    }

    fn host_ray(r: &luxon::ray::Ray) -> Ray {
        Ray {
            origin: r.origin.as_dvec3().into(),
            direction: r.dir.as_dvec3().into(),
            tmin: 0.0,
            tmax: f32::INFINITY as f64,
            time: 0.0,
        }
    }

    proptest! {
        // 512 cases, or `PROPTEST_CASES` (which `with_cases` would override) for longer runs.
        #![proptest_config(ProptestConfig::with_cases(
            std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(512)
        ))]

        /// The hit lies on the surface (relative to its magnitude in f32), the normal is unit
        /// once normalised, and a ray leaving outward (away from the tube's centre line) does
        /// not hit the torus again near its start: it can meet the far side of the ring, never
        /// the surface it leaves.
        #[test]
        fn hit_on_surface_and_no_self_hit(e in -3i32..=4, far in prop_oneof![Just(0.0f32), 1.0f32..1e4],
                                          at_dir in unit(), axis in unit(), minor in 0.05f64..0.9,
                                          from in unit(), jitter in unit(), leave in unit()) {
            let scale = 10f64.powi(e);
            let pos = far * at_dir;
            let t = Torus::new(&TorusParams {
                center: pos.as_dvec3().into(),
                axis: axis.as_dvec3().into(),
                major: scale,
                minor: minor * scale,
            }).unwrap();
            let o = pos + (4.0 * scale) as f32 * from;
            let target = pos + jitter * scale as f32;
            let r = luxon::ray::Ray::new(o, (target - o).normalize(), 0.0);
            let Some(h) = t.intersect(0, &host_ray(&r)) else { return Ok(()); };
            let p = r.at(h.t as f32);
            let pd: V3 = p.as_dvec3().into();
            let mag = pd.iter().fold(scale, |m, v| m.max(v.abs()));
            let d = tests_distance(&t, pd);
            prop_assert!(d.abs() <= mag / 65536.0, "{pd:?} is {d} off the surface");
            let n = luxon::math::DVec3::from(h.normal).normalize_or_zero().as_vec3();
            prop_assert!((n.length() - 1.0).abs() < 1e-5);
            // Outward from the tube.
            let rel = sub(pd, t.center);
            let z = dot(rel, t.w);
            let ring = sub(rel, mul(t.w, z));
            let spine = mul(normalize(ring).unwrap(), t.major);
            let out = Vec3A::from(luxon::math::DVec3::from(sub(rel, spine)).normalize().as_vec3());
            let n = if Vec3A::from(n).dot(out) < 0.0 { -Vec3A::from(n) } else { Vec3A::from(n) };
            let p_error = gamma(64) * (p.abs() + r.origin.abs());
            let mut dir = if leave.dot(n) < 0.0 { leave - 2.0 * leave.dot(n) * n } else { leave };
            dir = (dir + 0.05 * n).normalize();
            let spawned = luxon::ray::spawn(p, p_error, n, dir, 0.0);
            if let Some(again) = t.intersect(0, &host_ray(&spawned)) {
                prop_assert!(again.t > 1e-3 * t.minor, "left {pd:?} along {dir}, hit again at {}", again.t);
            }
        }
    }

    /// Signed distance to the surface, independent of the solver.
    fn tests_distance(t: &Torus, world: V3) -> f64 {
        let rel = sub(world, t.center);
        let z = dot(rel, t.w);
        let ring = sub(rel, mul(t.w, z));
        let rho = dot(ring, ring).sqrt();
        (rho - t.major).hypot(z) - t.minor
    }
}
