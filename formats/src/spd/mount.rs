//! `mount`: a fractal mountain with four glass balls.
//!
//! The mountain is Fournier, Fussell and Carpenter's midpoint subdivision of triangles: the
//! square [-1, 1]² at height 0, cut along its diagonal from (-1, -1) to (1, 1) into two
//! triangles, is subdivided `size` times, every triangle into four through the midpoints of its
//! edges; each new midpoint is raised from the mean of its edge's ends by a Gaussian random
//! amount whose spread is proportional to the edge length (a fractal of dimension 2: the
//! spread halves with every level). The result is the `2^size x 2^size` grid, every cell
//! written as two triangles (lower-right first) in the order the subdivision reaches them
//! (quarters of every square counter-clockwise from the lower left): 2 * 4^size triangles
//! (size 6: 8192). Above it float four glass balls of radius 0.17,
//! touching, stacked as a tetrahedron (one on top) around (-0.8, 0.8, 1).
//!
//! **Not the SPD's mountain.** The SPD draws the displacements from its own random number
//! generator, which is not reproduced here: the grid, the triangles, their order and count,
//! the balls, materials, light and view are the SPD's, but the heights are Luxon's own
//! (deterministic) random mountain of the same statistics (displacement spread 0.26 times the
//! edge length, as measured on the SPD's output). Each displacement is a hash of the midpoint's
//! position, so a larger size refines the same mountain.

use std::io;

use super::{fill, view, Sink, BACKGROUND};

/// Standard deviation of a midpoint's displacement per unit of edge length.
const ROUGHNESS: f64 = 0.26;

/// Picks Luxon's mountain among the possible ones: one with a summit about as high as the
/// SPD's (0.93), clear of the glass balls.
const SALT: u64 = 52;

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    s.background(BACKGROUND)?;
    s.view(&view([-1.6, 1.6, 1.7], [0.0; 3], [0.0, 0.0, 1.0], 0.01))?;
    s.light([-100.0, -100.0, 100.0])?;
    s.fill(&fill([1.0; 3], 0.1, 0.1, 6.7, 0.9, 1.5))?;
    balls(s)?;
    s.fill(&fill([0.5, 0.45, 0.35], 1.0, 0.0, 0.0, 0.0, 0.0))?;
    let n = 1usize << size;
    let z = heights(size);
    let p = |i: usize, j: usize| {
        let w = |k: usize| -1.0 + 2.0 * k as f64 / n as f64;
        [w(i), w(j), z[j * (n + 1) + i]]
    };
    cells(s, &p, 0, 0, n)?;
    Ok(())
}

/// The cells of the square of side `side` at (i, j) as the recursion reaches them: quarters
/// counter-clockwise from the lower left; a cell is two triangles, the lower right first.
fn cells(
    s: &mut dyn Sink,
    p: &dyn Fn(usize, usize) -> [f64; 3],
    i: usize,
    j: usize,
    side: usize,
) -> io::Result<()> {
    if side == 1 {
        s.polygon(&[p(i, j), p(i + 1, j), p(i + 1, j + 1)])?;
        return s.polygon(&[p(i + 1, j + 1), p(i, j + 1), p(i, j)]);
    }
    let h = side / 2;
    for (di, dj) in [(0, 0), (h, 0), (h, h), (0, h)] {
        cells(s, p, i + di, j + dj, h)?;
    }
    Ok(())
}

/// Four touching balls of radius 0.17 as a tetrahedron with one corner up, centred on
/// (-0.8, 0.8, 1): the top one first, then the lower ones at azimuths -45, 75 and 195 degrees.
fn balls(s: &mut dyn Sink) -> io::Result<()> {
    let r = 0.17;
    let (cx, cy, cz) = (-0.8, 0.8, 1.0);
    let circum = 2.0 * r * 6f64.sqrt() / 4.0;
    s.sphere([cx, cy, cz + circum], r)?;
    let out = circum * (8.0f64 / 9.0).sqrt();
    for az in [-45.0f64, 75.0, 195.0] {
        let a = az.to_radians();
        s.sphere(
            [cx + out * a.cos(), cy + out * a.sin(), cz - circum / 3.0],
            r,
        )?;
    }
    Ok(())
}

/// Heights of the `(2^size + 1)²` grid points, row by row (y), by midpoint subdivision.
fn heights(size: u32) -> Vec<f64> {
    let n = 1usize << size;
    let mut z = vec![0.0; (n + 1) * (n + 1)];
    let at = |i: usize, j: usize| j * (n + 1) + i;
    let mut step = n;
    while step > 1 {
        // Edge length in world units of the axis-parallel edges at this level.
        let spread = ROUGHNESS * 2.0 * step as f64 / n as f64;
        let raise = |z: &mut Vec<f64>, (i0, j0): (usize, usize), (i1, j1): (usize, usize)| {
            let (mi, mj) = ((i0 + i1) / 2, (j0 + j1) / 2);
            let mean = 0.5 * (z[at(i0, j0)] + z[at(i1, j1)]);
            z[at(mi, mj)] = mean + spread * gaussian(mi, mj, size);
        };
        for j in (0..=n).step_by(step) {
            for i in (0..n).step_by(step) {
                raise(&mut z, (i, j), (i + step, j));
                raise(&mut z, (j, i), (j, i + step));
            }
        }
        for j in (0..n).step_by(step) {
            for i in (0..n).step_by(step) {
                raise(&mut z, (i, j), (i + step, j + step));
            }
        }
        step /= 2;
    }
    z
}

/// A standard normal deviate that depends only on the grid point's position (in units of a
/// 2^-24 grid, whatever the size): Box-Muller over two hashed uniforms.
fn gaussian(i: usize, j: usize, size: u32) -> f64 {
    let shift = 24 - size.min(24);
    let key = ((i as u64) << shift) | (((j as u64) << shift) << 32);
    let a = splitmix(key ^ SALT);
    let b = splitmix(a);
    let u1 = ((a >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let u2 = (b >> 11) as f64 / (1u64 << 53) as f64;
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

fn splitmix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

#[cfg(test)]
mod tests {
    #[test]
    fn triangle_counts() {
        for size in [0u32, 1, 6] {
            let c = super::super::count("mount", size).unwrap();
            assert_eq!(c.polygons, 2 * 4u64.pow(size), "size {size}");
            assert_eq!(c.spheres, 4);
        }
    }

    #[test]
    fn larger_sizes_refine_the_same_mountain() {
        let (a, b) = (super::heights(3), super::heights(5));
        for j in 0..=8 {
            for i in 0..=8 {
                assert_eq!(a[j * 9 + i], b[(4 * j) * 33 + 4 * i]);
            }
        }
    }
}
