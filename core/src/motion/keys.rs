//! Keyed values at any time: linear and Catmull-Rom interpolation of numbers and vectors, and
//! of rotations (about one axis by their angle; about several by quaternion slerp, never by
//! blending matrices).
//!
//! Time is in frames. Before the first key and after the last the value holds (Blender's
//! constant extrapolation); at a key's own frame the value is that key's, bit for bit.
//!
//! Catmull-Rom is the non-uniform kind, parameterised by the key times (so keys 6 frames apart
//! keep their timing next to keys 24 apart), evaluated by the Barry–Goldman pyramid of three
//! levels of linear blends. At the ends a phantom key mirrors the second key through the first
//! (`2·P0 − P1` at `2·t0 − t1`), so the curve starts without a kink and nothing divides by zero.
//! With rotations the same pyramid runs on quaternions with slerp in place of the linear blend.

use glam::{DQuat, DVec3};
use luxon_formats::{Interpolate, Key, RotationDesc, Track};

/// A value that blends along a line: `lerp(a, b, u) = a + u·(b − a)`, for any `u` (the outer
/// levels of the Catmull-Rom pyramid extrapolate).
pub trait Blend: Copy {
    fn lerp(a: Self, b: Self, u: f64) -> Self;
}

impl Blend for f64 {
    #[inline]
    fn lerp(a: f64, b: f64, u: f64) -> f64 {
        a + u * (b - a)
    }
}

impl Blend for [f64; 3] {
    #[inline]
    fn lerp(a: [f64; 3], b: [f64; 3], u: f64) -> [f64; 3] {
        [0, 1, 2].map(|i| f64::lerp(a[i], b[i], u))
    }
}

/// Where a time falls among a track's keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Span {
    /// At key `i`'s frame, or outside the keys on key `i`'s side: key `i`'s value.
    Hold(usize),
    /// Strictly between keys `i` and `i + 1`.
    Between(usize),
}

fn span<T>(keys: &[Key<T>], t: f64) -> Span {
    let after = keys.partition_point(|k| k.frame <= t);
    if after == 0 {
        Span::Hold(0)
    } else if after == keys.len() || keys[after - 1].frame == t {
        Span::Hold(after - 1)
    } else {
        Span::Between(after - 1)
    }
}

/// The four points of segment `i` (keys `i` and `i + 1`) for Catmull-Rom: the keys around it,
/// with phantoms mirrored through the end keys where the track ends.
fn around<K, T: Copy>(
    keys: &[Key<K>],
    i: usize,
    value: impl Fn(&Key<K>) -> T,
    lerp: &impl Fn(T, T, f64) -> T,
) -> ([f64; 4], [T; 4]) {
    let (t1, t2) = (keys[i].frame, keys[i + 1].frame);
    let (p1, p2) = (value(&keys[i]), value(&keys[i + 1]));
    let (t0, p0) = match i.checked_sub(1) {
        Some(h) => (keys[h].frame, value(&keys[h])),
        None => (f64::lerp(t2, t1, 2.0), lerp(p2, p1, 2.0)),
    };
    let (t3, p3) = match keys.get(i + 2) {
        Some(k) => (k.frame, value(k)),
        None => (f64::lerp(t1, t2, 2.0), lerp(p1, p2, 2.0)),
    };
    ([t0, t1, t2, t3], [p0, p1, p2, p3])
}

/// The Barry–Goldman pyramid: the Catmull-Rom curve through `p` at times `ts`, at `t` in
/// `[ts[1], ts[2]]`, built from the blend `lerp` alone.
fn pyramid<T: Copy>(ts: [f64; 4], p: [T; 4], t: f64, lerp: &impl Fn(T, T, f64) -> T) -> T {
    let u = |a: usize, b: usize| (t - ts[a]) / (ts[b] - ts[a]);
    let a1 = lerp(p[0], p[1], u(0, 1));
    let a2 = lerp(p[1], p[2], u(1, 2));
    let a3 = lerp(p[2], p[3], u(2, 3));
    let b1 = lerp(a1, a2, u(0, 2));
    let b2 = lerp(a2, a3, u(1, 3));
    lerp(b1, b2, u(1, 2))
}

/// The track's value at time `t` (frames).
pub fn value<T: Blend>(track: &Track<T>, t: f64) -> T {
    sample(&track.keys, track.interpolation, t, |k| k.value, &T::lerp)
}

fn sample<K, T: Copy>(
    keys: &[Key<K>],
    interpolation: Interpolate,
    t: f64,
    value: impl Fn(&Key<K>) -> T,
    lerp: &impl Fn(T, T, f64) -> T,
) -> T {
    match span(keys, t) {
        Span::Hold(i) => value(&keys[i]),
        Span::Between(i) => match interpolation {
            Interpolate::Linear => {
                let (a, b) = (&keys[i], &keys[i + 1]);
                lerp(value(a), value(b), (t - a.frame) / (b.frame - a.frame))
            }
            Interpolate::CatmullRom => {
                let (ts, p) = around(keys, i, value, lerp);
                pyramid(ts, p, t, lerp)
            }
        },
    }
}

/// The rotation a key gives.
pub fn quaternion(r: &RotationDesc) -> DQuat {
    DQuat::from_axis_angle(DVec3::from(r.axis), r.degrees.to_radians())
}

/// A rotation track's value at time `t`. Where every key a segment uses turns about the same
/// axis, its angle is interpolated as a number (so 0° to 360° between two keys is one whole
/// turn, which no quaternion path can be: q and −q are the same rotation); otherwise the keys'
/// quaternions are joined by slerp along the shorter arc (Linear) or by the spherical
/// Catmull-Rom pyramid (CatmullRom).
pub fn rotation(track: &Track<RotationDesc>, t: f64) -> DQuat {
    let keys = &track.keys;
    let i = match span(keys, t) {
        Span::Hold(i) => return quaternion(&keys[i].value),
        Span::Between(i) => i,
    };
    let used = match track.interpolation {
        Interpolate::Linear => i..i + 2,
        Interpolate::CatmullRom => i.saturating_sub(1)..(i + 3).min(keys.len()),
    };
    let axis = keys[i].value.axis;
    if keys[used].iter().all(|k| k.value.axis == axis) {
        let degrees = sample(
            keys,
            track.interpolation,
            t,
            |k| k.value.degrees,
            &f64::lerp,
        );
        return quaternion(&RotationDesc { axis, degrees });
    }
    sample(
        keys,
        track.interpolation,
        t,
        |k| quaternion(&k.value),
        &slerp,
    )
    .normalize()
}

/// The rotation `u` of the way from `a` to `b` along the shorter great arc, for any `u`
/// (beyond [0, 1] it goes on along the same arc): `a · exp(u · log(a⁻¹ b))`.
pub fn slerp(a: DQuat, b: DQuat, u: f64) -> DQuat {
    let mut d = a.conjugate() * b;
    if d.w < 0.0 {
        // −d is the same rotation the short way round.
        d = -d;
    }
    (a * exp(log(d) * u)).normalize()
}

/// The logarithm of a unit quaternion: its axis times half its angle.
fn log(q: DQuat) -> DVec3 {
    let v = DVec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-300 {
        return v;
    }
    v * (s.atan2(q.w) / s)
}

/// The unit quaternion whose logarithm is `v`.
fn exp(v: DVec3) -> DQuat {
    let phi = v.length();
    if phi < 1e-300 {
        return DQuat::IDENTITY;
    }
    let s = phi.sin() / phi;
    DQuat::from_xyzw(v.x * s, v.y * s, v.z * s, phi.cos())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use luxon_formats::Origin;
    use std::path::PathBuf;
    use std::sync::Arc;

    pub(crate) fn at() -> Origin {
        Origin {
            file: Arc::new(PathBuf::from("t.ron")),
            line: 1,
            col: 1,
        }
    }

    pub(crate) fn track<T>(keys: Vec<(f64, T)>, interpolation: Interpolate) -> Track<T> {
        Track {
            keys: keys
                .into_iter()
                .map(|(frame, value)| Key {
                    frame,
                    value,
                    at: at(),
                })
                .collect(),
            interpolation,
            at: at(),
        }
    }

    fn rot(axis: [f64; 3], degrees: f64) -> RotationDesc {
        let a = DVec3::from(axis).normalize();
        RotationDesc {
            axis: a.to_array(),
            degrees,
        }
    }

    /// The angle of the rotation taking `a` to `b`, in degrees.
    fn angle(a: DQuat, b: DQuat) -> f64 {
        let d = a.conjugate() * b;
        // atan2 keeps its precision near 0, where acos(w) would not.
        (2.0 * DVec3::new(d.x, d.y, d.z).length().atan2(d.w.abs())).to_degrees()
    }

    /// A little pseudo-random generator (tests only).
    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    const KEYS: [(f64, f64); 5] = [
        (0.0, 1.0),
        (3.0, -2.0),
        (4.5, 7.25),
        (10.0, 0.5),
        (24.0, 3.0),
    ];

    #[test]
    fn keys_are_reached_exactly_and_hold_outside() {
        for interpolation in [Interpolate::Linear, Interpolate::CatmullRom] {
            let tr = track(KEYS.to_vec(), interpolation);
            for (f, v) in KEYS {
                assert_eq!(
                    value(&tr, f).to_bits(),
                    v.to_bits(),
                    "{interpolation:?} at {f}"
                );
            }
            assert_eq!(value(&tr, -5.0), 1.0);
            assert_eq!(value(&tr, 1e9), 3.0);
            let one = track(vec![(7.0, [1.0, 2.0, 3.0])], interpolation);
            assert_eq!(value(&one, -1.0), [1.0, 2.0, 3.0]);
            assert_eq!(value(&one, 100.0), [1.0, 2.0, 3.0]);
        }
    }

    #[test]
    fn linear_is_the_straight_line_between_keys() {
        let tr = track(KEYS.to_vec(), Interpolate::Linear);
        assert_eq!(value(&tr, 1.5), -0.5);
        assert_eq!(value(&tr, 17.0), 1.75);
    }

    #[test]
    fn catmull_rom_keeps_points_on_a_line_on_the_line() {
        // Values linear in time at uneven key times: the curve is that line.
        let line = |t: f64| 2.0 - 0.75 * t;
        let times = [0.0, 1.0, 5.0, 6.5, 20.0];
        let tr = track(
            times.iter().map(|&t| (t, line(t))).collect(),
            Interpolate::CatmullRom,
        );
        let mut t: f64 = -1.0;
        while t < 21.0 {
            let want = line(t.clamp(0.0, 20.0));
            assert!((value(&tr, t) - want).abs() < 1e-12, "at {t}");
            t += 0.37;
        }
    }

    #[test]
    fn catmull_rom_is_smooth_across_keys_and_not_linear() {
        let tr = track(KEYS.to_vec(), Interpolate::CatmullRom);
        let h = 1e-6;
        for (f, _) in &KEYS[1..4] {
            let left = (value(&tr, *f) - value(&tr, f - h)) / h;
            let right = (value(&tr, f + h) - value(&tr, *f)) / h;
            assert!(
                (left - right).abs() < 1e-4 * (1.0 + left.abs()),
                "kink at {f}: {left} vs {right}"
            );
        }
        // A curve, not the polyline: between keys 1 and 2 it differs from the chord.
        let linear = track(KEYS.to_vec(), Interpolate::Linear);
        assert!((value(&tr, 3.75) - value(&linear, 3.75)).abs() > 0.1);
    }

    #[test]
    fn catmull_rom_ends_follow_the_first_and_last_segment() {
        // With the mirrored phantom keys, the end tangent is the chord of the end segment:
        // three keys on a parabola leave the first key along that chord.
        let tr = track(
            vec![(0.0, 0.0), (1.0, 1.0), (2.0, 4.0)],
            Interpolate::CatmullRom,
        );
        let h = 1e-7;
        let slope = (value(&tr, h) - value(&tr, 0.0)) / h;
        assert!((slope - 1.0).abs() < 1e-5, "{slope}");
        let slope = (value(&tr, 2.0) - value(&tr, 2.0 - h)) / h;
        assert!((slope - 3.0).abs() < 1e-5, "{slope}");
    }

    #[test]
    fn one_axis_turns_by_its_angle_even_past_half_a_turn() {
        let tr = track(
            vec![
                (0.0, rot([0.0, 0.0, 1.0], 0.0)),
                (4.0, rot([0.0, 0.0, 1.0], 360.0)),
            ],
            Interpolate::Linear,
        );
        let q = rotation(&tr, 1.0);
        let x = q * DVec3::X;
        assert!((x - DVec3::Y).length() < 1e-12, "{x}");
        let x = rotation(&tr, 3.0) * DVec3::X;
        assert!((x + DVec3::Y).length() < 1e-12, "{x}");
    }

    #[test]
    fn slerp_takes_the_shorter_arc_at_a_steady_rate() {
        let a = quaternion(&rot([1.0, 0.0, 0.0], 0.0));
        // 300° about y is 60° the other way.
        let b = quaternion(&rot([0.0, 1.0, 0.0], 300.0));
        assert!((angle(a, b) - 60.0).abs() < 1e-9);
        let mut last = a;
        for k in 1..=10 {
            let q = slerp(a, b, k as f64 / 10.0);
            assert!((q.length() - 1.0).abs() < 1e-12);
            assert!((angle(last, q) - 6.0).abs() < 1e-9, "step {k}");
            last = q;
        }
        assert!(angle(last, b) < 1e-9);
        // And against −b (the same rotation), the same path.
        let q = slerp(a, -b, 0.5);
        assert!(angle(q, slerp(a, b, 0.5)) < 1e-9);
    }

    #[test]
    fn keys_about_different_axes_are_joined_by_slerp() {
        let tr = track(
            vec![
                (0.0, rot([1.0, 0.0, 0.0], 90.0)),
                (10.0, rot([0.0, 1.0, 0.0], 90.0)),
            ],
            Interpolate::Linear,
        );
        let (a, b) = (rotation(&tr, 0.0), rotation(&tr, 10.0));
        let total = angle(a, b);
        for k in 1..10 {
            let q = rotation(&tr, k as f64);
            assert!((angle(a, q) - total * k as f64 / 10.0).abs() < 1e-9);
            assert!((angle(q, b) - total * (10 - k) as f64 / 10.0).abs() < 1e-9);
        }
    }

    #[test]
    fn spherical_catmull_rom_passes_through_its_keys_smoothly() {
        let keys = vec![
            (0.0, rot([1.0, 0.0, 0.0], 30.0)),
            (5.0, rot([0.0, 1.0, 0.0], 80.0)),
            (7.0, rot([1.0, 1.0, 1.0], -45.0)),
            (15.0, rot([0.0, 0.0, 1.0], 120.0)),
        ];
        let tr = track(keys.clone(), Interpolate::CatmullRom);
        for (f, r) in &keys {
            assert!(angle(rotation(&tr, *f), quaternion(r)) < 1e-9, "key at {f}");
        }
        // Angular velocity continuous across the inner keys.
        let h = 1e-5;
        for f in [5.0, 7.0] {
            let before = angle(rotation(&tr, f - h), rotation(&tr, f)) / h;
            let after = angle(rotation(&tr, f), rotation(&tr, f + h)) / h;
            assert!(
                (before - after).abs() < 1e-3 * before.max(1.0),
                "{before} {after}"
            );
        }
    }

    #[test]
    fn rotations_never_shear_or_scale() {
        let keys = vec![
            (0.0, rot([1.0, 2.0, 3.0], 10.0)),
            (3.0, rot([0.0, 1.0, 0.0], 170.0)),
            (4.0, rot([-1.0, 0.5, 0.0], -120.0)),
            (9.0, rot([0.0, 0.0, 1.0], 60.0)),
        ];
        for interpolation in [Interpolate::Linear, Interpolate::CatmullRom] {
            let tr = track(keys.clone(), interpolation);
            let mut seed = 7;
            for _ in 0..1000 {
                let t = -1.0 + 11.0 * lcg(&mut seed);
                let m = glam::DMat3::from_quat(rotation(&tr, t));
                let e = (m * m.transpose() - glam::DMat3::IDENTITY).abs();
                let worst = e
                    .x_axis
                    .max_element()
                    .max(e.y_axis.max_element())
                    .max(e.z_axis.max_element());
                assert!(worst < 1e-12, "at {t}: {worst}");
                assert!((m.determinant() - 1.0).abs() < 1e-12);
            }
        }
    }
}
