//! `shells`: Pickover's seashell, a spiral of overlapping spheres.
//!
//! Clifford Pickover's construction (IEEE CG&A, November 1989) as the SPD's `shells` program
//! (Eric Haines) builds it: for `i` from `-2 steps / 3` to `steps / 3`, with
//! `steps = 180 * 2^size`, a sphere at angle `t = 18 pi i / steps` (nine turns, from -12 pi to
//! 6 pi), distance `r = exp(0.15 t)` from the axis, centre `(r sin t, r cos t, -2 r)` and radius
//! `r`: each sphere overlaps its neighbours, most are tiny, the last few large (the SPD calls it
//! "a realistic yet pathological database"). One golden material, one light, the SPD's sky
//! blue background.
//!
//! Counts: the loop includes both ends, so `180 * 2^size + 1` spheres and nothing else
//! (size 5, the default: 5,761). The table in the header of the SPD's `shells.c` (3.14) says
//! `180 * 2^size` spheres and one square; the program itself writes one sphere more and no
//! square, and this generator follows the program.

use std::f64::consts::PI;
use std::io;

use super::{fill, view, Sink, BACKGROUND};

/// Growth exponent `a` of `r = exp(a t)`.
const A: f64 = 0.15;
/// Height per unit of distance from the axis (the SPD's `beta`).
const BETA: f64 = -2.0;

/// The number of angular steps (`steps`) at `size`.
fn steps(size: u32) -> i64 {
    180 << size
}

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    s.background(BACKGROUND)?;
    s.view(&view(
        [-6.0, -60.0, 35.0],
        [0.0, 8.0, -15.0],
        [0.0, 0.0, 1.0],
        0.5,
    ))?;
    s.light([-100.0, -100.0, 100.0])?;
    s.fill(&fill([1.0, 0.8, 0.4], 0.8, 0.2, 10.0, 0.0, 1.0))?;
    let steps = steps(size);
    // C's integer division: both bounds are exact since steps is a multiple of 3.
    for i in (-steps * 2 / 3)..=(steps / 3) {
        let t = 3.0 * 6.0 * PI * i as f64 / steps as f64;
        let r = (A * t).exp();
        s.sphere([r * t.sin(), r * t.cos(), BETA * r], r)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn sphere_counts() {
        for (size, n) in [(1, 361), (2, 721), (5, 5761), (10, 184_321)] {
            let c = super::super::count("shells", size).unwrap();
            assert_eq!(c.spheres, n, "size {size}");
            assert_eq!(c.spheres, (180u64 << size) + 1);
            assert_eq!((c.polygons, c.cones, c.lights, c.fills), (0, 0, 1, 1));
        }
    }

    /// The spiral grows outwards and downwards: the first sphere is tiny, the last is the
    /// largest, every centre lies at `-2 r` on its distance `r` from the axis.
    #[test]
    fn spiral_geometry() {
        use std::f64::consts::PI;
        let s = super::super::Recorder::of("shells", 5).spheres;
        let (first, last) = (s[0], s[s.len() - 1]);
        assert!((first.1 - (-0.15 * 12.0 * PI).exp()).abs() < 1e-12);
        assert!((last.1 - (0.15 * 6.0 * PI).exp()).abs() < 1e-9);
        for w in s.windows(2) {
            assert!(w[1].1 > w[0].1, "radii grow");
        }
        for (c, r) in &s {
            assert!(((c[0] * c[0] + c[1] * c[1]).sqrt() - r).abs() < 1e-9);
            assert!((c[2] + 2.0 * r).abs() < 1e-12);
        }
    }
}
