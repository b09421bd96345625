//! `sombrero`: the "hat function" height field, as triangles.
//!
//! The SPD's height-field example (Alexander Enzmann, sizes by Eduard Schwan), from its
//! description: a `w x w` grid of heights, `w = 32 * 2^(size-1)`, samples of the damped ripple
//! `cos(2 pi rho) exp(-rho)` (`rho` the distance from the origin; the SPD's pi is 3.14159265358)
//! at `x, y = -4 + 8 k / w` (so the last sample is one step short of 4; the SPD steps by
//! adding the increment and keeps heights in single precision, as here). The field is laid
//! over the square `[-4, 4]` in x and z with `w - 1` cells per side, height `y = -3 + h` (the
//! SPD's height fields rise along y); every cell is cut along its diagonal into two triangles,
//! `(i, j), (i+1, j+1), (i, j+1)` and `(i, j), (i+1, j), (i+1, j+1)`, row `i` along z, column
//! `j` along x, rows first. Shiny red, one light, seen from (0, 5, -8) with z up, 40 degrees.
//!
//! Counts (the SPD's `sombrero.c` 3.14 gives the grid per size: 32x32, 64x64, 128x128,
//! 256x256 for sizes 1 to 4): `2 (w - 1)^2` triangles, size 1 (the SPD's default) 1,922, size
//! 2 7,938, size 3 32,258, size 4 130,050. Two rows of heights are held at a time.

use std::io;

use super::{fill, Sink, View, BACKGROUND};

/// The SPD's value of pi in this program (kept: it is what the SPD's heights are made of).
#[allow(clippy::approx_constant)]
const PI_SPD: f64 = 3.14159265358;

/// Samples per side at `size`.
pub fn width(size: u32) -> usize {
    32 << (size - 1)
}

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    s.background(BACKGROUND)?;
    s.view(&View {
        from: [0.0, 5.0, -8.0],
        at: [0.0; 3],
        up: [0.0, 0.0, 1.0],
        angle: 40.0,
        hither: 0.01,
        resolution: (512, 512),
    })?;
    s.light([10.0, 10.0, -10.0])?;
    s.fill(&fill([1.0, 0.1, 0.1], 0.8, 0.0, 40.0, 0.0, 1.0))?;
    let w = width(size);
    let (x0, y0, z0) = (-4.0, -3.0, -4.0);
    let step = 8.0 / (w - 1) as f64;
    let vertex = |i: usize, j: usize, h: f32| {
        [
            x0 + j as f64 * step,
            y0 + f64::from(h),
            z0 + i as f64 * step,
        ]
    };
    let mut rows = Rows::new(w);
    let mut this = rows.next_row();
    for i in 0..w - 1 {
        let next = rows.next_row();
        for j in 0..w - 1 {
            let corner = vertex(i, j, this[j]);
            let across = vertex(i + 1, j + 1, next[j + 1]);
            s.polygon(&[corner, across, vertex(i, j + 1, this[j + 1])])?;
            s.polygon(&[corner, vertex(i + 1, j, next[j]), across])?;
        }
        this = next;
    }
    Ok(())
}

/// The height samples, one row (constant y of the sampling) at a time.
struct Rows {
    w: usize,
    /// Sampling coordinate of the next row, advanced by adding the step as the SPD does.
    y: f64,
    delta: f64,
}

impl Rows {
    fn new(w: usize) -> Rows {
        Rows {
            w,
            y: -4.0,
            delta: 8.0 / w as f64,
        }
    }

    fn next_row(&mut self) -> Vec<f32> {
        let mut row = Vec::with_capacity(self.w);
        let mut x = -4.0;
        for _ in 0..self.w {
            row.push(height(x, self.y));
            x += self.delta;
        }
        self.y += self.delta;
        row
    }
}

/// The damped ripple at `(x, y)`, in single precision like the SPD's height field.
fn height(x: f64, y: f64) -> f32 {
    let rho = (x * x + y * y).sqrt();
    (3.0 * (2.0 * PI_SPD * rho).cos() * (-rho).exp() / 3.0) as f32
}

#[cfg(test)]
mod tests {
    use super::super::{count, Recorder};

    #[test]
    fn triangle_counts() {
        for (size, w, n) in [(1, 32, 1922u64), (2, 64, 7938), (3, 128, 32_258)] {
            assert_eq!(super::width(size), w);
            let c = count("sombrero", size).unwrap();
            assert_eq!(c.polygons, n, "size {size}");
            assert_eq!(c.polygons, 2 * (w as u64 - 1).pow(2));
            assert_eq!((c.spheres, c.cones, c.lights, c.fills), (0, 0, 1, 1));
        }
    }

    /// The grid covers [-4, 4] in x and z; heights stay within -3 +- 1, the crown (1 at the
    /// centre) near the middle, and every triangle is a half cell.
    #[test]
    fn field_geometry() {
        let r = Recorder::of("sombrero", 1);
        let all: Vec<[f64; 3]> = r.polygons.iter().flatten().copied().collect();
        let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
        for v in &all {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        assert_eq!((lo[0], hi[0], lo[2], hi[2]), (-4.0, 4.0, -4.0, 4.0));
        assert!(lo[1] > -4.0 && hi[1] <= -2.0, "{lo:?} {hi:?}");
        assert!(hi[1] > -2.01, "the crown reaches almost 1: {hi:?}");
        let top = all
            .iter()
            .fold(all[0], |a, &v| if v[1] > a[1] { v } else { a });
        assert!(top[0].abs() < 0.3 && top[2].abs() < 0.3, "crown at {top:?}");
        let cell = 8.0 / 31.0;
        for p in &r.polygons {
            assert_eq!(p.len(), 3);
            let (dx, dz) = ((p[1][0] - p[0][0]).abs(), (p[1][2] - p[0][2]).abs());
            assert!(dx <= cell + 1e-12 && dz <= cell + 1e-12 && dz > 0.0);
        }
    }
}
