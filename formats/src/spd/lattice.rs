//! `lattice`: a cubic lattice of balls and rods.
//!
//! Balls (radius 1/4 of the cell) at the `(size+1)^3` points of a lattice of cell `1 / size`
//! filling the unit cube, each followed by the rods (radius 1/16 of the cell) to its neighbours
//! in +x, +y and +z, red, green and blue; a rod starts and ends 0.12375 cells from the centres
//! of the balls it joins. Size 12: 2197 balls and 6084 rods. Every object is written with its
//! material. Six lights, one beyond each face of the cube.

use std::io;

use super::{fill, view, Sink, BACKGROUND};

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    let n = size as f64;
    let cell = 1.0 / n;
    s.background(BACKGROUND)?;
    s.view(&super::View {
        angle: 60.0,
        ..view(
            [0.5 + 0.5 * cell, 1.0, 1.0 - 0.5 * cell],
            [0.5 + 0.5 * cell, -1.0, -1.0 - 0.5 * cell],
            [0.2, 1.0, 0.0],
            0.0,
        )
    })?;
    for l in [
        [2.0, 0.5, 0.5],
        [-1.0, 0.5, 0.5],
        [0.5, 2.0, 0.5],
        [0.5, -1.0, 0.5],
        [0.5, 0.5, 2.0],
        [0.5, 0.5, -1.0],
    ] {
        s.light(l)?;
    }
    let ball = fill([0.9; 3], 0.5, 0.5, 37.0, 0.0, 0.0);
    let rods = [
        fill([0.9, 0.1, 0.1], 0.99, 0.0, 0.0, 0.0, 0.0),
        fill([0.1, 0.9, 0.1], 0.99, 0.0, 0.0, 0.0, 0.0),
        fill([0.1, 0.1, 0.9], 0.99, 0.0, 0.0, 0.0, 0.0),
    ];
    let (ball_r, rod_r, gap) = (0.25 * cell, 0.0625 * cell, 0.12375 * cell);
    let at = |i: u32| i as f64 * cell;
    for i in 0..=size {
        for j in 0..=size {
            for k in 0..=size {
                let p = [at(i), at(j), at(k)];
                s.fill(&ball)?;
                s.sphere(p, ball_r)?;
                for (axis, index) in [i, j, k].into_iter().enumerate() {
                    if index == size {
                        continue;
                    }
                    let (mut a, mut b) = (p, p);
                    a[axis] += gap;
                    b[axis] = at(index + 1) - gap;
                    s.fill(&rods[axis])?;
                    s.cone(a, rod_r, b, rod_r)?;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn lattice_counts() {
        for size in [1u64, 2, 12] {
            let c = super::super::count("lattice", size as u32).unwrap();
            assert_eq!(c.spheres, (size + 1).pow(3), "size {size}");
            assert_eq!(c.cones, 3 * size * (size + 1).pow(2));
            assert_eq!(c.fills, c.spheres + c.cones);
        }
    }
}
