//! Helpers the unit tests of every family share.

use crate::vector::{normalize, V3};
use luxon_plugin::{CustomShape, Error, Ray};

pub(crate) fn err<T: std::fmt::Debug>(r: Result<T, Error>) -> String {
    r.unwrap_err().message
}

pub(crate) fn assert_contains(message: &str, part: &str) {
    assert!(
        message.contains(part),
        "{message:?} does not contain {part:?}"
    );
}

/// A ray over `(0, ∞)`.
pub(crate) fn ray(origin: V3, direction: V3) -> Ray {
    Ray {
        origin,
        direction,
        tmin: 0.0,
        tmax: f64::INFINITY,
        time: 0.0,
    }
}

pub(crate) fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + b.abs())
}

pub(crate) fn close3(a: V3, b: V3) -> bool {
    (0..3).all(|k| close(a[k], b[k]))
}

/// Hit `t` and unit normal.
pub(crate) fn hit<S: CustomShape>(s: &S, r: &Ray) -> Option<(f64, V3)> {
    let h = s.intersect(0, r)?;
    assert!(h.t.is_finite() && h.normal.iter().all(|x| x.is_finite()));
    assert!(s.occluded(0, r));
    Some((h.t, normalize(h.normal).expect("zero normal")))
}

pub(crate) fn assert_hit<S: CustomShape>(s: &S, r: &Ray, t: f64, n: V3) {
    let (ht, hn) = hit(s, r).expect("expected a hit");
    assert!(close(ht, t), "t {ht} != {t}");
    assert!(close3(hn, n), "normal {hn:?} != {n:?}");
}
