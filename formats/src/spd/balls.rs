//! `balls`: the sphereflake.
//!
//! A sphere of radius 1/2 at the origin carries nine spheres a third its radius, touching it:
//! three "upper" ones 54.74 degrees above its equator (the angle of a cube's diagonal, so the
//! three sit like the corners of a cube around its axis) at azimuths 45, 165 and 285 degrees,
//! and six on the equator, 30 degrees either side of each upper one. Every child repeats the
//! pattern around its own axis (the direction from its parent), `size` levels deep: a sphere
//! and (9^(size+1) - 1) / 8 - 1 descendants (size 4: 7381 spheres). The frame of a child is the
//! parent's pattern turned by the shortest rotation that takes the z axis to the child's
//! direction (a half turn about y for straight down). The flake stands on a 24x24 square
//! floor under three lights.

use std::io;

use super::{add, fill, length, mul, rotation, view, Sink, BACKGROUND, IDENTITY, M3, V3};

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    s.background(BACKGROUND)?;
    s.view(&view([2.1, 1.3, 1.7], [0.0; 3], [0.0, 0.0, 1.0], 0.01))?;
    for l in [[4.0, 3.0, 2.0], [1.0, -4.0, 4.0], [-3.0, 1.0, 5.0]] {
        s.light(l)?;
    }
    s.fill(&fill([1.0, 0.75, 0.33], 0.8, 0.0, 0.0, 0.0, 1.0))?;
    s.polygon(&[
        [12.0, 12.0, -0.5],
        [-12.0, 12.0, -0.5],
        [-12.0, -12.0, -0.5],
        [12.0, -12.0, -0.5],
    ])?;
    s.fill(&fill([1.0, 0.9, 0.7], 0.5, 0.5, 37.0, 0.0, 1.0))?;
    let dirs = directions();
    flake(s, &dirs, [0.0; 3], 0.5, &IDENTITY, size)
}

/// The nine child directions around the z axis.
fn directions() -> [V3; 9] {
    let (sin_up, cos_up) = ((2.0f64 / 3.0).sqrt(), (1.0f64 / 3.0).sqrt());
    let mut d = [[0.0; 3]; 9];
    for i in 0..3 {
        let a = (45.0 + 120.0 * i as f64).to_radians();
        d[3 * i] = [cos_up * a.cos(), cos_up * a.sin(), sin_up];
        for (k, side) in [-30.0f64, 30.0].into_iter().enumerate() {
            let b = a + side.to_radians();
            d[3 * i + 1 + k] = [b.cos(), b.sin(), 0.0];
        }
    }
    d
}

/// The shortest rotation taking +z to the unit vector `d`.
fn frame(d: V3) -> M3 {
    let axis = [-d[1], d[0], 0.0];
    let s = length(axis);
    if s < 1e-9 {
        return if d[2] > 0.0 {
            IDENTITY
        } else {
            [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]
        };
    }
    rotation(mul(axis, 1.0 / s), s.atan2(d[2]))
}

fn flake(s: &mut dyn Sink, dirs: &[V3; 9], c: V3, r: f64, m: &M3, depth: u32) -> io::Result<()> {
    s.sphere(c, r)?;
    if depth == 0 {
        return Ok(());
    }
    for d in dirs {
        let w = super::apply(m, *d);
        flake(
            s,
            dirs,
            add(c, mul(w, r * 4.0 / 3.0)),
            r / 3.0,
            &frame(w),
            depth - 1,
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn sphere_counts() {
        for (size, n) in [(0, 1), (1, 10), (4, 7381), (5, 66430), (6, 597871)] {
            let c = super::super::count("balls", size).unwrap();
            assert_eq!(c.spheres, n, "size {size}");
            assert_eq!(c.spheres, (9u64.pow(size + 1) - 1) / 8);
            assert_eq!((c.polygons, c.lights), (1, 3));
        }
    }
}
