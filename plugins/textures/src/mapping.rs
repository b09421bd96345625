//! How a shading point becomes texture coordinates: a mapping gives `(u, v)`, then the 2-D
//! placement (`scale`, `rotate`, `offset`) gives the image coordinates `(s, t)` (see
//! `mipmap.rs` for where texels sit in `(s, t)`).
//!
//! Projected mappings work in a frame around `center`: `w` is `axis` (normalised); `e1` is the
//! world x axis made perpendicular to `w` (the world z axis when `axis` is along x); `e2 = w × e1`.
//! With the default axis (0, 1, 0) that is `e1 = +x`, `e2 = -z`. For `d = p - center`:
//!
//! | mapping | u | v |
//! |---|---|---|
//! | `uv` | the mesh's `u` | the mesh's `v` |
//! | `planar` | `d · e1` | `d · e2` (the plane through `center` perpendicular to `axis`; world units) |
//! | `cylindrical` | `atan2(d · e2, d · e1) / 2π`, in [0, 1) | `d · w` (height along the axis, world units) |
//! | `spherical` | the same longitude | `0.5 + asin(d̂ · w) / π`: 0 at the south pole, 1 at the north |
//!
//! The placement maps `(u, v)` to `(s, t) = R(-rotate) · ((u, v) - offset) / scale`: the image is
//! scaled by `scale`, turned by `rotate` degrees (counter-clockwise) and moved to `offset`, in
//! `(u, v)` units: one copy of the image covers `scale` world units under `planar` mapping. A
//! negative scale mirrors the image along that direction (Tachyon's image maps need it).

use crate::params::{direction, Factors};
use luxon_plugin::abi::TexQuery;
use luxon_plugin::{finite, Error};
use serde::Deserialize;
use std::f64::consts::{PI, TAU};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum Kind {
    #[default]
    #[serde(rename = "uv", alias = "Uv", alias = "UV")]
    Uv,
    #[serde(rename = "planar", alias = "Planar")]
    Planar,
    #[serde(rename = "cylindrical", alias = "Cylindrical")]
    Cylindrical,
    #[serde(rename = "spherical", alias = "Spherical")]
    Spherical,
}

/// A mapping with its frame and the 2-D placement.
#[derive(Clone, Debug)]
pub struct Mapping {
    kind: Kind,
    center: [f64; 3],
    w: [f64; 3],
    e1: [f64; 3],
    e2: [f64; 3],
    scale: [f64; 2],
    /// cos and sin of `-rotate`.
    rot: (f64, f64),
    offset: [f64; 2],
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    a.map(|x| x / l)
}

/// Where a lookup lands and how wide it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lookup {
    pub s: f64,
    pub t: f64,
    /// Footprint in `(s, t)` units along s and along t (0: a point).
    pub ds: f64,
    pub dt: f64,
}

impl Mapping {
    pub fn new(
        kind: Kind,
        center: [f64; 3],
        axis: [f64; 3],
        scale: Factors<2>,
        rotate: f64,
        offset: [f64; 2],
    ) -> Result<Mapping, Error> {
        let center = finite("center", center)?;
        let w = direction("axis", axis)?;
        let [rotate] = finite("rotate", [rotate])?;
        let offset = finite("offset", offset)?;
        let scale = scale.nonzero("scale")?;
        let x = [1.0, 0.0, 0.0];
        // World x made perpendicular to the axis; world z when the axis is (nearly) along x.
        let reference = if dot(x, w).abs() > 0.999 {
            [0.0, 0.0, 1.0]
        } else {
            x
        };
        let k = dot(reference, w);
        let e1 = normalize([
            reference[0] - k * w[0],
            reference[1] - k * w[1],
            reference[2] - k * w[2],
        ]);
        let e2 = cross(w, e1);
        let (sin, cos) = (-rotate).to_radians().sin_cos();
        Ok(Mapping {
            kind,
            center,
            w,
            e1,
            e2,
            scale,
            rot: (cos, sin),
            offset,
        })
    }

    /// `(u, v)` and the footprint's size in `(u, v)` units along u and v (0 without
    /// `FOOTPRINT`: only MIP filtering reads it, and its `hypot` is not free).
    fn uv<const FOOTPRINT: bool>(&self, q: &TexQuery) -> (f64, f64, f64, f64) {
        if self.kind == Kind::Uv {
            let f = q.uv_footprint.max(0.0) as f64;
            return (q.uv[0] as f64, q.uv[1] as f64, f, f);
        }
        let d = [
            q.p[0] - self.center[0],
            q.p[1] - self.center[1],
            q.p[2] - self.center[2],
        ];
        let (a, b, h) = (dot(d, self.e1), dot(d, self.e2), dot(d, self.w));
        let fp = q.footprint.max(0.0) as f64;
        let longitude = || {
            let u = b.atan2(a) / TAU;
            if u < 0.0 {
                u + 1.0
            } else {
                u
            }
        };
        match self.kind {
            Kind::Uv | Kind::Planar => (a, b, fp, fp),
            Kind::Cylindrical if !FOOTPRINT => (longitude(), h, 0.0, 0.0),
            Kind::Cylindrical => {
                // An arc of length fp at distance r from the axis spans fp / (2π r) in u.
                let r = a.hypot(b);
                (longitude(), h, fp / (TAU * r), fp)
            }
            Kind::Spherical => {
                let r = dot(d, d).sqrt();
                let lat = (h / r).clamp(-1.0, 1.0).asin();
                if !FOOTPRINT {
                    return (longitude(), 0.5 + lat / PI, 0.0, 0.0);
                }
                let ring = a.hypot(b);
                (
                    longitude(),
                    0.5 + lat / PI,
                    fp / (TAU * ring),
                    fp / (PI * r),
                )
            }
        }
    }

    /// Image coordinates and footprint for a query. Degenerate points (on the axis, at the
    /// centre) give infinite footprints (the coarsest level) rather than NaN.
    pub fn lookup(&self, q: &TexQuery) -> Lookup {
        self.resolve::<true>(q)
    }

    /// What the mapping projects from (uv: the surface's coordinates; else the point).
    pub fn kind(&self) -> Kind {
        self.kind
    }

    /// How far the query's point is from the projection's centre (world units).
    pub fn radius(&self, q: &TexQuery) -> f64 {
        let d: [f64; 3] = std::array::from_fn(|i| q.p[i] - self.center[i]);
        dot(d, d).sqrt()
    }

    /// Image coordinates `(s, t)` alone, as [`Self::lookup`] gives them (for the filters that
    /// read no footprint).
    pub fn point(&self, q: &TexQuery) -> (f64, f64) {
        let l = self.resolve::<false>(q);
        (l.s, l.t)
    }

    /// [`Self::lookup`]; the footprint is left 0 without `FOOTPRINT`.
    #[inline(always)]
    fn resolve<const FOOTPRINT: bool>(&self, q: &TexQuery) -> Lookup {
        let (u, v, du, dv) = self.uv::<FOOTPRINT>(q);
        let (u, v) = (u - self.offset[0], v - self.offset[1]);
        let (c, s) = self.rot;
        let (ru, rv) = (c * u - s * v, s * u + c * v);
        let clean = |x: f64| if x.is_nan() { 0.0 } else { x };
        let fix = |x: f64| if x.is_nan() { f64::INFINITY } else { x };
        let (s, t) = (clean(ru / self.scale[0]), clean(rv / self.scale[1]));
        if !FOOTPRINT {
            return Lookup {
                s,
                t,
                ds: 0.0,
                dt: 0.0,
            };
        }
        Lookup {
            s,
            t,
            ds: fix(du / self.scale[0].abs()),
            dt: fix(dv / self.scale[1].abs()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(p: [f64; 3]) -> TexQuery {
        TexQuery {
            p,
            ..Default::default()
        }
    }

    fn m(kind: Kind) -> Mapping {
        Mapping::new(
            kind,
            [0.0; 3],
            [0.0, 1.0, 0.0],
            Factors([1.0; 2]),
            0.0,
            [0.0; 2],
        )
        .unwrap()
    }

    fn near(l: Lookup, s: f64, t: f64) -> bool {
        (l.s - s).abs() < 1e-12 && (l.t - t).abs() < 1e-12
    }

    #[test]
    fn the_point_alone_is_the_lookups_point_bit_for_bit() {
        let kinds = [Kind::Uv, Kind::Planar, Kind::Cylindrical, Kind::Spherical];
        for (n, kind) in kinds.into_iter().enumerate() {
            let mp = Mapping::new(
                kind,
                [0.3, -1.0, 2.0],
                [0.2, 1.0, -0.4],
                Factors([0.7, -1.3]),
                25.0,
                [0.1, 0.2],
            )
            .unwrap();
            for k in 0..200 {
                let f = (k * 7 + n) as f64;
                let q = TexQuery {
                    p: [f.sin() * 5.0, (f * 0.37).cos() * 3.0, f * 0.01 - 1.0],
                    uv: [(f * 0.13).sin() as f32, (f * 0.07).cos() as f32],
                    footprint: 0.01,
                    uv_footprint: 0.002,
                    ..Default::default()
                };
                let (full, (s, t)) = (mp.lookup(&q), mp.point(&q));
                assert_eq!(
                    (full.s.to_bits(), full.t.to_bits()),
                    (s.to_bits(), t.to_bits())
                );
            }
            // The centre itself (NaN cleaned to 0 in both).
            let q = TexQuery {
                p: [0.3, -1.0, 2.0],
                ..Default::default()
            };
            let full = mp.lookup(&q);
            assert_eq!((full.s, full.t), mp.point(&q), "{kind:?}");
        }
    }

    #[test]
    fn frame_of_the_default_axis() {
        let mp = m(Kind::Planar);
        assert_eq!(mp.e1, [1.0, 0.0, 0.0]);
        assert_eq!(mp.e2, [0.0, 0.0, -1.0]);
        // Along x, the reference switches to z.
        let mx = Mapping::new(
            Kind::Planar,
            [0.0; 3],
            [2.0, 0.0, 0.0],
            Factors([1.0; 2]),
            0.0,
            [0.0; 2],
        )
        .unwrap();
        assert_eq!(mx.e1, [0.0, 0.0, 1.0]);
        assert_eq!(mx.e2, [0.0, -1.0, 0.0]);
    }

    #[test]
    fn uv_mapping_uses_the_mesh_coordinates() {
        let mp = m(Kind::Uv);
        let l = mp.lookup(&TexQuery {
            uv: [0.25, 0.75],
            uv_footprint: 0.125,
            footprint: 9.0,
            ..Default::default()
        });
        assert_eq!(
            l,
            Lookup {
                s: 0.25,
                t: 0.75,
                ds: 0.125,
                dt: 0.125
            }
        );
    }

    #[test]
    fn planar_cylindrical_spherical_known_points() {
        let p = m(Kind::Planar);
        assert!(near(p.lookup(&q([0.25, 7.0, -0.75])), 0.25, 0.75));
        let c = m(Kind::Cylindrical);
        assert!(near(c.lookup(&q([1.0, 0.5, 0.0])), 0.0, 0.5));
        assert!(near(c.lookup(&q([0.0, 0.5, -1.0])), 0.25, 0.5));
        assert!(near(c.lookup(&q([-2.0, -1.0, 0.0])), 0.5, -1.0));
        assert!(near(c.lookup(&q([0.0, 0.0, 3.0])), 0.75, 0.0));
        let s = m(Kind::Spherical);
        assert!(near(s.lookup(&q([1.0, 0.0, 0.0])), 0.0, 0.5));
        assert!(near(s.lookup(&q([0.0, 0.0, -1.0])), 0.25, 0.5));
        assert!((s.lookup(&q([0.0, 2.0, 0.0])).t - 1.0).abs() < 1e-12);
        assert!(s.lookup(&q([0.0, -1.0, 0.0])).t.abs() < 1e-12);
        // 45° north: v = 0.75.
        assert!(near(s.lookup(&q([1.0, 1.0, 0.0])), 0.0, 0.75));
        // A centre moves the frame.
        let moved = Mapping::new(
            Kind::Spherical,
            [5.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            Factors([1.0; 2]),
            0.0,
            [0.0; 2],
        )
        .unwrap();
        assert!(near(moved.lookup(&q([5.0, 0.0, -1.0])), 0.25, 0.5));
    }

    #[test]
    fn placement_scales_rotates_and_offsets() {
        let p = Mapping::new(
            Kind::Planar,
            [0.0; 3],
            [0.0, 1.0, 0.0],
            Factors([2.0, 4.0]),
            0.0,
            [1.0, 0.0],
        )
        .unwrap();
        // u = 3 -> (3 - 1) / 2 = 1; v = 2 -> 2 / 4 = 0.5.
        assert!(near(p.lookup(&q([3.0, 0.0, -2.0])), 1.0, 0.5));
        // Rotating the image 90° counter-clockwise: the point (0, 1) in (u, v) reads image (1, 0).
        let r = Mapping::new(
            Kind::Planar,
            [0.0; 3],
            [0.0, 1.0, 0.0],
            Factors([1.0; 2]),
            90.0,
            [0.0; 2],
        )
        .unwrap();
        assert!(near(r.lookup(&q([0.0, 0.0, -1.0])), 1.0, 0.0));
        // A negative scale mirrors: v = 2 -> 2 / -4 = -0.5; the footprint stays positive.
        let m = Mapping::new(
            Kind::Planar,
            [0.0; 3],
            [0.0, 1.0, 0.0],
            Factors([2.0, -4.0]),
            0.0,
            [0.0; 2],
        )
        .unwrap();
        let l = m.lookup(&TexQuery {
            p: [2.0, 0.0, -2.0],
            footprint: 1.0,
            ..Default::default()
        });
        assert!(near(l, 1.0, -0.5));
        assert_eq!((l.ds, l.dt), (0.5, 0.25));
    }

    #[test]
    fn footprints_in_texture_units() {
        let foot = |mp: &Mapping, p: [f64; 3]| {
            let l = mp.lookup(&TexQuery {
                p,
                footprint: 0.5,
                ..Default::default()
            });
            (l.ds, l.dt)
        };
        let planar = Mapping::new(
            Kind::Planar,
            [0.0; 3],
            [0.0, 1.0, 0.0],
            Factors([2.0, 0.5]),
            0.0,
            [0.0; 2],
        )
        .unwrap();
        assert_eq!(foot(&planar, [1.0, 0.0, 1.0]), (0.25, 1.0));
        let cyl = m(Kind::Cylindrical);
        let (ds, dt) = foot(&cyl, [2.0, 0.0, 0.0]);
        assert!((ds - 0.5 / (TAU * 2.0)).abs() < 1e-12 && dt == 0.5);
        let sph = m(Kind::Spherical);
        let (ds, dt) = foot(&sph, [2.0, 0.0, 0.0]);
        assert!((ds - 0.5 / (TAU * 2.0)).abs() < 1e-12 && (dt - 0.5 / (PI * 2.0)).abs() < 1e-12);
        // On the axis the longitude is undefined: the footprint is infinite (coarsest level).
        let (ds, _) = foot(&cyl, [0.0, 1.0, 0.0]);
        assert!(ds.is_infinite());
        let l = sph.lookup(&q([0.0; 3]));
        assert!(l.s.is_finite() && l.t.is_finite());
    }

    #[test]
    fn bad_params() {
        let e = Mapping::new(
            Kind::Planar,
            [0.0; 3],
            [0.0; 3],
            Factors([1.0; 2]),
            0.0,
            [0.0; 2],
        )
        .unwrap_err();
        assert!(e.message.contains("`axis`"), "{}", e.message);
        let e = Mapping::new(
            Kind::Planar,
            [0.0; 3],
            [0.0, 1.0, 0.0],
            Factors([0.0, 1.0]),
            0.0,
            [0.0; 2],
        )
        .unwrap_err();
        assert!(e.message.contains("`scale`"), "{}", e.message);
        let e = Mapping::new(
            Kind::Planar,
            [f64::NAN, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            Factors([1.0; 2]),
            0.0,
            [0.0; 2],
        )
        .unwrap_err();
        assert!(e.message.contains("`center`"), "{}", e.message);
    }
}
