//! `gears`: a block of meshing gears.
//!
//! `size` layers of `size x size` gears (size 4: 64) over a square floor. Each gear is a prism:
//! a top and a bottom face, both concave 144-sided polygons, joined by 144 side quadrilaterals.
//! A gear has 36 teeth; along one tooth period of 10 degrees its outline runs on the tip
//! circle from -1.9 to 1.9 degrees, slopes down to the root circle at 3 degrees, follows it to
//! 7 degrees and climbs back to the tip at 8.1. Neighbours are turned half a tooth against each
//! other (by the parity of their grid position) so their teeth interlock. With
//! `u = 1 / (19 size + 1)` the tip radius is `19.9 u`, the root radius `18 u`, the centres
//! `38 u` apart and the outer centres `20 u` inside the square [-1, 1]; layer `k` spans
//! z = `1 - k / size` down by `0.4 / size`.
//!
//! Every gear has its own fully bright colour and finish. The SPD's rule is not published; this
//! one reproduces its output exactly (found by reading the colours of its 64 gears): each
//! component takes one of seven levels `k` as `(r + 0.07) / (max + 0.07)`, the levels varying
//! linearly modulo 7 across the grid (see `material`); the gears where
//! `col + 3 row + 4 layer` is a multiple of 5 are clear plastic (T 0.8, index 1.1), the rest
//! matte.
//!
//! The faces are written top first (counter-clockwise seen from above, starting at the first
//! tip corner), then the sides, then the bottom (clockwise from above: the outline reversed).

use std::io;

use super::{fill, view, Sink, BACKGROUND, V3};

const TEETH: usize = 36;
/// One tooth: (angle in degrees within its 10-degree period, on the tip circle?).
const TOOTH: [(f64, bool); 4] = [(-1.9, true), (1.9, true), (3.0, false), (7.0, false)];

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    s.background(BACKGROUND)?;
    s.view(&view([-1.1, -2.1, 2.6], [0.0; 3], [0.0, 0.0, 1.0], 1.0))?;
    for l in [
        [2.0, 4.0, 4.0],
        [-2.0, 4.0, 3.0],
        [2.0, -2.5, 2.5],
        [-1.0, -4.0, 2.0],
        [-1.111, -2.121, 2.626],
    ] {
        s.light(l)?;
    }
    s.fill(&fill([1.0, 0.85, 0.7], 0.3, 0.6, 37.0, 0.0, 0.0))?;
    s.polygon(&[
        [2.0, 2.0, 0.0],
        [-2.0, 2.0, 0.0],
        [-2.0, -2.0, 0.0],
        [2.0, -2.0, 0.0],
    ])?;
    let n = size as usize;
    let u = 1.0 / (19.0 * size as f64 + 1.0);
    let (tip, root) = (19.9 * u, 18.0 * u);
    let centre = |i: usize| -1.0 + (20.0 + 38.0 * i as f64) * u;
    let mut top = vec![[0.0; 3]; TEETH * 4];
    let mut bottom = vec![[0.0; 3]; TEETH * 4];
    for layer in 0..n {
        let z_top = 1.0 - layer as f64 / size as f64;
        let z_bottom = z_top - 0.4 / size as f64;
        for row in 0..n {
            for col in 0..n {
                s.fill(&material(layer, row, col))?;
                let (cx, cy) = (centre(col), centre(row));
                let phase = if (layer + row + col) % 2 == 1 {
                    5.0
                } else {
                    0.0
                };
                for t in 0..TEETH {
                    for (k, &(a, on_tip)) in TOOTH.iter().enumerate() {
                        let a = (10.0 * t as f64 + a + phase).to_radians();
                        let r = if on_tip { tip } else { root };
                        let (x, y) = (cx + r * a.cos(), cy + r * a.sin());
                        top[4 * t + k] = [x, y, z_top];
                        bottom[4 * t + k] = [x, y, z_bottom];
                    }
                }
                s.polygon(&top)?;
                let m = top.len();
                for i in 0..m {
                    let j = (i + 1) % m;
                    s.polygon(&[top[i], bottom[i], bottom[j], top[j]])?;
                }
                let reversed: Vec<V3> = (0..m).map(|k| bottom[(m + 1 - k) % m]).collect();
                s.polygon(&reversed)?;
            }
        }
    }
    Ok(())
}

/// The colour and finish of the gear in `layer` (from the top), `row` (y) and `col` (x):
/// levels `(5 + col + 3 row + 5 layer, 3 + 3 col + 2 row + 6 layer, 2 + 4 col + 2 row + 6 layer)`
/// modulo 7.
fn material(layer: usize, row: usize, col: usize) -> super::Fill {
    let level = |c: usize, a: usize, b: usize, d: usize| (c + a * col + b * row + d * layer) % 7;
    let raw = [level(5, 1, 3, 5), level(3, 3, 2, 6), level(2, 4, 2, 6)];
    let max = *raw.iter().max().unwrap() as f64;
    let color = raw.map(|v| (v as f64 + 0.07) / (max + 0.07));
    if (col + 3 * row + 4 * layer).is_multiple_of(5) {
        fill(color, 0.2, 0.0, 0.0, 0.8, 1.1)
    } else {
        fill(color, 1.0, 0.0, 0.0, 0.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn polygon_counts() {
        for size in [1u64, 4, 5] {
            let c = super::super::count("gears", size as u32).unwrap();
            assert_eq!(c.polygons, 1 + size * size * size * 146, "size {size}");
            assert_eq!(c.fills, 1 + size * size * size);
        }
    }
}
