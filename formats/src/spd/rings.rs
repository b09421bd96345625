//! `rings`: a pyramid of interlocked pentagonal rings.
//!
//! A group is six pentagonal rings sharing a centre, each a chain of five spheres joined by
//! five cylinders (tube radius 0.07412, corner radius 1 / 1.07412), in the six planes
//! perpendicular to the five-fold axes of an icosahedron: the first ring lies in the xy plane
//! (corners from +x counter-clockwise), the five others are tilted 63.43 degrees from it about
//! horizontal axes 72 degrees apart, each starting at the corner on the xy plane. The six rings
//! are red, green, blue, cyan, magenta and yellow. Groups are stacked in a square pyramid
//! receding from the viewer: level `k` (0..size) is a `(k+1) x (k+1)` grid of groups 2 apart
//! in x and z, at depth `(k+1) d` with `d = 1 / sin(22.5 degrees)`, so size 7 is
//! 1 + 4 + ... + 49 = 140 groups, 4200 cylinders and 4200 spheres. The eye is at depth `-d`,
//! looking along +y; a white wall one level beyond the pyramid closes the view, 1% wider than
//! the 45-degree view at its distance.
//!
//! A ring is written corner by corner: the cylinder from the corner back to the previous one,
//! then the sphere at the corner.

use std::io;

use super::{add, cross, fill, mul, view, Sink, BACKGROUND, V3};

const TUBE: f64 = 0.07412;

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    let d = 1.0 / (std::f64::consts::PI / 8.0).sin();
    s.background(BACKGROUND)?;
    s.view(&view(
        [-1.0, -d, 0.5],
        [-1.0, 1.0 - d, 0.5],
        [0.0, 0.0, 1.0],
        1.0,
    ))?;
    for l in [[3.0, -d, 3.0], [-4.0, -d, 1.0], [2.0, -d, -4.0]] {
        s.light(l)?;
    }
    // The wall: at the next level's depth, 1% wider than the view there.
    let wall_y = (size as f64 + 1.0) * d;
    let half = 1.01 * (wall_y + d) * (std::f64::consts::PI / 8.0).tan();
    s.fill(&fill([1.0; 3], 1.0, 0.0, 0.0, 0.0, 0.0))?;
    s.polygon(&[
        [-1.0 + half, wall_y, 0.5 + half],
        [-1.0 - half, wall_y, 0.5 + half],
        [-1.0 - half, wall_y, 0.5 - half],
        [-1.0 + half, wall_y, 0.5 - half],
    ])?;
    let rings = ring_axes();
    let colors = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
    ];
    let radius = 1.0 / (1.0 + TUBE);
    for level in 0..size as i64 {
        let y = (level + 1) as f64 * d;
        for zi in 0..=level {
            for xi in 0..=level {
                let c = [(2 * xi - level) as f64, y, (2 * zi - level) as f64];
                for ((v0, w), color) in rings.iter().zip(colors) {
                    s.fill(&fill(color, 0.5, 0.2, 37.0, 0.0, 0.0))?;
                    let corner = |k: usize| {
                        let a = (72.0 * k as f64).to_radians();
                        add(c, mul(add(mul(*v0, a.cos()), mul(*w, a.sin())), radius))
                    };
                    for k in 0..5 {
                        let (p, prev) = (corner(k), corner((k + 4) % 5));
                        s.cone(p, TUBE, prev, TUBE)?;
                        s.sphere(p, TUBE)?;
                    }
                }
            }
        }
    }
    Ok(())
}

/// For each of the six rings, the unit vectors to its first corner and a quarter turn on.
fn ring_axes() -> [(V3, V3); 6] {
    let mut r = [([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]); 6];
    let (h, z) = (2.0 / 5f64.sqrt(), 1.0 / 5f64.sqrt());
    for (i, ring) in r.iter_mut().enumerate().skip(1) {
        let az = (72.0 * i as f64 - 126.0).to_radians();
        let normal = [h * az.cos(), h * az.sin(), z];
        let v0 = [-az.sin(), az.cos(), 0.0];
        *ring = (v0, cross(normal, v0));
    }
    r
}

#[cfg(test)]
mod tests {
    #[test]
    fn ring_counts() {
        for (size, groups) in [(1u64, 1u64), (2, 5), (7, 140)] {
            let c = super::super::count("rings", size as u32).unwrap();
            assert_eq!(c.cones, groups * 30, "size {size}");
            assert_eq!(c.spheres, groups * 30);
            assert_eq!(c.polygons, 1);
        }
    }
}
