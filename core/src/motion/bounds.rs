//! Boxes that hold a keyed object over an interval of time (motion blur's shutter): every
//! point of the object at every time in the interval lies inside, so a BVH over these boxes
//! never culls a ray that meets the object at the ray's own time. Conservative, in f64; the
//! caller rounds outward when it stores them in f32.
//!
//! `world_from_object = translate · rotate · scale`, so a point p of the object box is at
//! `T(t) + R(t)·S(t)·p`. Each part is bounded on its own and the bounds added (a Minkowski sum
//! of boxes): the translation by the hull of the curve's control points, the scale the same
//! way per axis, and the rotation exactly where it holds still over the interval; a rotation
//! whose keys all turn about one axis by the box turned through the angle's range a few degrees
//! at a time (grown by how far an arc strays from its chord), any other by the ball its
//! largest scaled corner distance sweeps.

use super::keys::{quaternion, rotation, value};
use glam::{DQuat, DVec3};
use luxon_formats::{Interpolate, Key, ObjectTracks, Track};

/// A box in f64: (low corner, high corner).
pub type DBox = (DVec3, DVec3);

/// The box holding `object` (a box in object space) placed by `tracks` at every time of
/// `[t0, t1]` (frames, `t0 <= t1`).
pub fn swept_bounds(tracks: &ObjectTracks, object: DBox, t0: f64, t1: f64) -> DBox {
    let (tlo, thi) = match &tracks.translate {
        Some(t) => hull(t, t0, t1),
        None => (DVec3::ZERO, DVec3::ZERO),
    };
    let (slo, shi) = match &tracks.scale {
        Some(s) => hull(s, t0, t1),
        None => (DVec3::ONE, DVec3::ONE),
    };
    let (lo, hi) = object;
    let still = tracks.rotate.as_ref().map_or(Some(DQuat::IDENTITY), |r| {
        holds(r, t0, t1).then(|| rotation(r, t0))
    });
    // The scaled box: per axis the products of the scale's and the box's ends.
    let mut a = DVec3::ZERO;
    let mut b = DVec3::ZERO;
    for i in 0..3 {
        let p = [
            slo[i] * lo[i],
            slo[i] * hi[i],
            shi[i] * lo[i],
            shi[i] * hi[i],
        ];
        a[i] = p.iter().copied().fold(f64::INFINITY, f64::min);
        b[i] = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    }
    let turning = || {
        let r = tracks.rotate.as_ref()?;
        turned_about_axis(r, (a, b), t0, t1)
    };
    let (rlo, rhi) = match still {
        Some(q) => corners_turned(q, (a, b)),
        None => turning().unwrap_or_else(|| {
            let far = slo.abs().max(shi.abs()) * lo.abs().max(hi.abs());
            let r = far.length();
            (DVec3::splat(-r), DVec3::splat(r))
        }),
    };
    let (lo, hi) = (tlo + rlo, thi + rhi);
    // The evaluation's own rounding (slerp, the pyramid, the product) is far below this.
    let pad = (hi - lo + lo.abs().max(hi.abs())) * 1e-9;
    (lo - pad, hi + pad)
}

/// The box of the box `b` turned by `q`: its eight corners turned.
fn corners_turned(q: DQuat, (lo, hi): DBox) -> DBox {
    let mut out = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for k in 0..8 {
        let pick = |i: usize| if k >> i & 1 == 0 { lo[i] } else { hi[i] };
        let c = q * DVec3::new(pick(0), pick(1), pick(2));
        out = (out.0.min(c), out.1.max(c));
    }
    out
}

/// The box holding `b` turned over `[t0, t1]` by a rotation track whose keys all turn about
/// one axis (its angle then interpolated as a number, see `keys::rotation`): the box turned
/// at angles at most `STEP` degrees apart over the angle's range (from `hull`, which holds a
/// Catmull-Rom overshoot), grown by the most an arc between two of them strays from its chord
/// (the sagitta at the box's farthest corner). `None`: keys about several axes, or a range of
/// a whole turn or more.
fn turned_about_axis(
    r: &Track<luxon_formats::RotationDesc>,
    b: DBox,
    t0: f64,
    t1: f64,
) -> Option<DBox> {
    const STEP: f64 = 5.0;
    let axis = r.keys[0].value.axis;
    if r.keys.iter().any(|k| k.value.axis != axis) {
        return None;
    }
    let angles = Track {
        keys: (r.keys.iter())
            .map(|k| Key {
                frame: k.frame,
                value: [k.value.degrees, 0.0, 0.0],
                at: k.at.clone(),
            })
            .collect(),
        interpolation: r.interpolation,
        at: r.at.clone(),
    };
    let (lo, hi) = hull(&angles, t0, t1);
    let (a0, a1) = (lo.x, hi.x);
    // A full turn (or a NaN span) is bounded by the loose sphere instead.
    if a1 - a0 >= 360.0 || (a1 - a0).is_nan() {
        return None;
    }
    let n = ((a1 - a0) / STEP).ceil().max(1.0);
    let mut out = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for j in 0..=n as u32 {
        let degrees = a0 + (a1 - a0) * f64::from(j) / n;
        let q = quaternion(&luxon_formats::RotationDesc { axis, degrees });
        let c = corners_turned(q, b);
        out = (out.0.min(c.0), out.1.max(c.1));
    }
    let half_step = ((a1 - a0) / n).to_radians() * 0.5;
    let sagitta = b.0.abs().max(b.1.abs()).length() * (1.0 - half_step.cos());
    Some((out.0 - sagitta, out.1 + sagitta))
}

/// Whether a rotation track holds one rotation over `[t0, t1]`: the interval lies outside
/// the keys' span, or every key turns the same way.
fn holds(r: &Track<luxon_formats::RotationDesc>, t0: f64, t1: f64) -> bool {
    let keys = &r.keys;
    let (first, last) = (keys[0].frame, keys[keys.len() - 1].frame);
    if t1 <= first || t0 >= last {
        return true;
    }
    let q0 = quaternion(&keys[0].value);
    keys.iter().all(|k| quaternion(&k.value) == q0)
}

/// Per axis, the range of a vector track over `[t0, t1]`: its values at both ends, the keys
/// inside, and the control points of every Catmull-Rom segment the interval meets (its cubic
/// Bézier points, whose hull holds the curve).
pub fn hull(track: &Track<[f64; 3]>, t0: f64, t1: f64) -> DBox {
    let mut lo = DVec3::from(value(track, t0));
    let mut hi = lo;
    let mut add = |p: DVec3| {
        lo = lo.min(p);
        hi = hi.max(p);
    };
    add(DVec3::from(value(track, t1)));
    let keys = &track.keys;
    for i in 0..keys.len().saturating_sub(1) {
        let (a, b) = (keys[i].frame, keys[i + 1].frame);
        if b <= t0 || a >= t1 {
            continue;
        }
        for p in controls(keys, i, track.interpolation) {
            add(p);
        }
    }
    for k in keys.iter().filter(|k| k.frame > t0 && k.frame < t1) {
        add(DVec3::from(k.value));
    }
    (lo, hi)
}

/// The control points of segment `i` (keys `i`, `i + 1`).
fn controls(keys: &[Key<[f64; 3]>], i: usize, how: Interpolate) -> Vec<DVec3> {
    let p = |k: &Key<[f64; 3]>| DVec3::from(k.value);
    let (t1, t2) = (keys[i].frame, keys[i + 1].frame);
    let (p1, p2) = (p(&keys[i]), p(&keys[i + 1]));
    if how == Interpolate::Linear {
        // Straight between keys: the values at the interval's ends (added by the caller) and
        // the keys inside it bound the path.
        return vec![];
    }
    // The neighbours, with the phantom keys of `keys::around` at the ends.
    let (t0, p0) = match i.checked_sub(1) {
        Some(h) => (keys[h].frame, p(&keys[h])),
        None => (2.0 * t1 - t2, 2.0 * p1 - p2),
    };
    let (t3, p3) = match keys.get(i + 2) {
        Some(k) => (k.frame, p(k)),
        None => (2.0 * t2 - t1, 2.0 * p2 - p1),
    };
    // The Barry–Goldman curve is the cubic Hermite with these tangents (per frame).
    let m1 = (p1 - p0) / (t1 - t0) - (p2 - p0) / (t2 - t0) + (p2 - p1) / (t2 - t1);
    let m2 = (p2 - p1) / (t2 - t1) - (p3 - p1) / (t3 - t1) + (p3 - p2) / (t3 - t2);
    let d = (t2 - t1) / 3.0;
    vec![p1, p1 + m1 * d, p2 - m2 * d, p2]
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::motion::keys::tests::{at, track};
    use crate::motion::Placement;
    use luxon_formats::{RotationDesc, Spanned};
    use proptest::prelude::*;

    fn v3(r: f64) -> impl Strategy<Value = [f64; 3]> {
        [-r..r, -r..r, -r..r]
    }

    fn how() -> impl Strategy<Value = Interpolate> {
        prop_oneof![Just(Interpolate::Linear), Just(Interpolate::CatmullRom)]
    }

    /// Key frames: increasing, 1 to 5 of them, some closely and some widely spaced.
    fn frames() -> impl Strategy<Value = Vec<f64>> {
        proptest::collection::vec(0.05f64..4.0, 1..6).prop_map(|gaps| {
            gaps.iter()
                .scan(-2.0, |t, g| {
                    *t += g;
                    Some(*t)
                })
                .collect()
        })
    }

    /// Random keyed tracks: each of translate (within ±5), rotate (about z or any axis, up to
    /// ±400°) and scale (0.2 to 2 per axis) present or not, Linear or Catmull-Rom.
    pub(crate) fn tracks() -> impl Strategy<Value = ObjectTracks> {
        let vec_track = |r: f64| {
            (frames(), how()).prop_flat_map(move |(f, how)| {
                proptest::collection::vec(v3(r), f.len())
                    .prop_map(move |v| track(f.iter().copied().zip(v).collect(), how))
            })
        };
        let scale = (frames(), how()).prop_flat_map(|(f, how)| {
            proptest::collection::vec([0.2f64..2.0, 0.2f64..2.0, 0.2f64..2.0], f.len())
                .prop_map(move |v| track(f.iter().copied().zip(v).collect(), how))
        });
        let axis = prop_oneof![
            Just([0.0, 0.0, 1.0]),
            v3(1.0).prop_filter("an axis", |a| DVec3::from(*a).length() > 0.1)
        ]
        .prop_map(|a| DVec3::from(a).normalize().to_array());
        let rot = (frames(), how()).prop_flat_map(move |(f, how)| {
            proptest::collection::vec((axis.clone(), -400.0f64..400.0), f.len()).prop_map(
                move |v| {
                    let keys = f.iter().copied().zip(v);
                    let keys = keys.map(|(t, (axis, degrees))| (t, RotationDesc { axis, degrees }));
                    track(keys.collect(), how)
                },
            )
        });
        (
            proptest::option::of(vec_track(5.0)),
            proptest::option::of(rot),
            proptest::option::of(scale),
        )
            .prop_map(|(translate, rotate, scale)| ObjectTracks {
                object: 0,
                name: Spanned {
                    value: "o".into(),
                    at: at(),
                },
                translate,
                rotate,
                scale,
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        /// Every corner of the object box, at 200 times in the interval, is inside.
        #[test]
        fn the_swept_box_holds_the_object_at_every_time(
            tracks in tracks(),
            lo in v3(2.0),
            size in [0.0f64..2.0, 0.0f64..2.0, 0.0f64..2.0],
            t0 in -3.0f64..12.0,
            len in 0.0f64..2.0,
        ) {
            let lo = DVec3::from(lo);
            let hi = lo + DVec3::from(size);
            let t1 = t0 + len;
            let (blo, bhi) = swept_bounds(&tracks, (lo, hi), t0, t1);
            for s in 0..=200 {
                let t = t0 + len * s as f64 / 200.0;
                let p = Placement::at(&tracks, t);
                for k in 0..8 {
                    let pick = |i: usize| if k >> i & 1 == 0 { lo[i] } else { hi[i] };
                    let q = DVec3::from(p.point([pick(0), pick(1), pick(2)]));
                    prop_assert!(
                        q.cmpge(blo).all() && q.cmple(bhi).all(),
                        "{q:?} outside {blo:?}..{bhi:?} at {t}"
                    );
                }
            }
        }
    }

    /// A turn about one axis is bounded by the turned box, not the ball around it: a bar
    /// along x turning 4 degrees about y stays thin in y and z.
    #[test]
    fn a_small_turn_about_one_axis_stays_close() {
        let turn = |degrees| RotationDesc {
            axis: [0.0, 1.0, 0.0],
            degrees,
        };
        let tracks = ObjectTracks {
            object: 0,
            name: Spanned {
                value: "o".into(),
                at: at(),
            },
            translate: None,
            rotate: Some(track(
                vec![(0.0, turn(0.0)), (48.0, turn(360.0))],
                Interpolate::Linear,
            )),
            scale: None,
        };
        let bar = (DVec3::new(-1.3, -0.15, -0.15), DVec3::new(1.3, 0.15, 0.15));
        let (lo, hi) = swept_bounds(&tracks, bar, 4.75, 5.25);
        assert!(hi.y < 0.151 && lo.y > -0.151, "{lo:?} {hi:?}");
        // sin(40°) · 1.3 plus the bar's half-width, about 0.95: far inside the 1.3 ball.
        assert!(hi.z < 1.0 && lo.z > -1.0, "{lo:?} {hi:?}");
        assert!(hi.x <= 1.31 && lo.x >= -1.31, "{lo:?} {hi:?}");
    }

    /// A translation alone is bounded tightly: its path's ends for a line.
    #[test]
    fn a_straight_move_is_bounded_by_its_ends() {
        let tracks = ObjectTracks {
            object: 0,
            name: Spanned {
                value: "o".into(),
                at: at(),
            },
            translate: Some(track(
                vec![(0.0, [-1.0, 0.0, 0.0]), (1.0, [1.0, 0.0, 0.0])],
                Interpolate::Linear,
            )),
            rotate: None,
            scale: None,
        };
        let b = (DVec3::splat(-0.5), DVec3::splat(0.5));
        let (lo, hi) = swept_bounds(&tracks, b, 0.25, 0.75);
        assert!((lo - DVec3::new(-1.0, -0.5, -0.5)).abs().max_element() < 1e-6);
        assert!((hi - DVec3::new(1.0, 0.5, 0.5)).abs().max_element() < 1e-6);
    }
}
