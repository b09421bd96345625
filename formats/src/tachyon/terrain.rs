//! SCAPE: Tachyon's generated terrain, reproduced: midpoint subdivision of an m×n height grid
//! driven by Tachyon's own random sequence, then smooth triangles with central-difference
//! normals (Tachyon's `rt_landscape` and `rt_sheightfield`, as described in
//! `/work/notes/tachyon-mapping.md` §5.13).

use super::syntax::V3;

/// Tachyon's random sequence: `s ← 1099087573·s mod 2³²`, values `s / 2³²` in [0, 1).
struct Rand(u32);

impl Rand {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(1_099_087_573);
        f64::from(self.0) / 4_294_967_296.0
    }
}

/// Heights of an `m`×`n` grid (x fastest) over a `wx`×`wy` area.
fn heights(m: usize, n: usize, wx: f64, wy: f64) -> Vec<f64> {
    let mut h = vec![0.0; m * n];
    let mut rng = Rand((m * n) as u32);
    h[0] = rng.next();
    h[m - 1] = rng.next();
    h[m * (n - 1)] = rng.next();
    h[m - 1 + m * (n - 1)] = rng.next();
    let mut g = Grid {
        h,
        m,
        n,
        wx,
        wy,
        rng,
    };
    g.subdivide(0, 0, m - 1, n - 1);
    g.h
}

struct Grid {
    h: Vec<f64>,
    m: usize,
    n: usize,
    wx: f64,
    wy: f64,
    rng: Rand,
}

impl Grid {
    /// Sets point (x, y), if still 0, to the mean of (xa, ya) and (xb, yb) plus a random
    /// offset that grows with their distance, clamped to [0, m + n].
    fn adjust(
        &mut self,
        (xa, ya): (usize, usize),
        (x, y): (usize, usize),
        (xb, yb): (usize, usize),
    ) {
        let m = self.m;
        if self.h[x + m * y] != 0.0 {
            return;
        }
        let len = (self.wx * self.wx + self.wy * self.wy).sqrt();
        let d = (xa.abs_diff(xb) as f64 / m as f64) * self.wx
            + (ya.abs_diff(yb) as f64 / self.n as f64) * self.wy;
        let mean = (self.h[xa + m * ya] + self.h[xb + m * yb]) / 2.0;
        let v = mean + ((self.rng.next() - 0.5) * d / 4.0) * (len / 16.0);
        self.h[x + m * y] = v.clamp(0.0, (m + self.n) as f64);
    }

    fn subdivide(&mut self, x1: usize, y1: usize, x2: usize, y2: usize) {
        if x2 - x1 < 2 && y2 - y1 < 2 {
            return;
        }
        let (x, y) = ((x1 + x2) / 2, (y1 + y2) / 2);
        self.adjust((x1, y1), (x, y1), (x2, y1));
        self.adjust((x2, y1), (x2, y), (x2, y2));
        self.adjust((x1, y2), (x, y2), (x2, y2));
        self.adjust((x1, y1), (x1, y), (x1, y2));
        let m = self.m;
        if self.h[x + m * y] == 0.0 {
            self.h[x + m * y] = (self.h[x1 + m * y1]
                + self.h[x2 + m * y1]
                + self.h[x2 + m * y2]
                + self.h[x1 + m * y2])
                / 4.0;
        }
        self.subdivide(x1, y1, x, y);
        self.subdivide(x, y1, x2, y);
        self.subdivide(x, y, x2, y2);
        self.subdivide(x1, y, x, y2);
    }
}

/// The terrain in Tachyon's coordinates: vertices, normals and smooth triangles (two per
/// cell). Heights go along y; the grid spans `wx` along x and `wy` along z around `center`.
pub(super) fn scape(
    res: [u32; 2],
    scale: [f64; 2],
    center: V3,
) -> (Vec<V3>, Vec<V3>, Vec<[u32; 3]>) {
    let (m, n) = (res[0] as usize, res[1] as usize);
    let [wx, wy] = scale;
    let h = heights(m, n, wx, wy);
    let (xinc, yinc) = (wx / (m - 1) as f64, wy / (n - 1) as f64);
    let mut vertices = Vec::with_capacity(m * n);
    for y in 0..n {
        for x in 0..m {
            vertices.push([
                x as f64 * xinc + center[0] - wx / 2.0,
                h[x + m * y] + center[1],
                y as f64 * yinc + center[2] - wy / 2.0,
            ]);
        }
    }
    // Border normals point straight up; inner ones from central differences.
    let mut normals = vec![[0.0, 1.0, 0.0]; m * n];
    for y in 1..n.saturating_sub(1) {
        for x in 1..m.saturating_sub(1) {
            let a = x + m * y;
            let v = [
                -(h[a + 1] - h[a - 1]) / (2.0 * xinc),
                1.0,
                -(h[a + m] - h[a - m]) / (2.0 * yinc),
            ];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            normals[a] = v.map(|c| c / l);
        }
    }
    let mut triangles = Vec::with_capacity(2 * (m - 1) * (n - 1));
    for y in 0..n - 1 {
        for x in 0..m - 1 {
            let a = (x + m * y) as u32;
            let m = m as u32;
            triangles.push([a, a + 1 + m, a + 1]);
            triangles.push([a, a + m, a + 1 + m]);
        }
    }
    (vertices, normals, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_sequence_is_tachyons() {
        let mut r = Rand(1);
        assert_eq!(r.next(), 1_099_087_573.0 / 4_294_967_296.0);
        let expected = 1_099_087_573u64 * 1_099_087_573 % (1 << 32);
        assert_eq!(r.next(), expected as f64 / 4_294_967_296.0);
    }

    #[test]
    fn terrain_has_two_triangles_per_cell_and_bounded_heights() {
        let (v, n, t) = scape([10, 10], [5.0, 5.0], [0.0, -1.0, 0.0]);
        assert_eq!((v.len(), n.len(), t.len()), (100, 100, 162));
        for p in &v {
            assert!((-2.5..=2.5).contains(&p[0]) && (-2.5..=2.5).contains(&p[2]));
            assert!((-1.0..=19.0).contains(&p[1]));
        }
        // Not flat, and every interior point was set.
        assert!(v.iter().any(|p| p[1] > -0.9));
        assert!(n
            .iter()
            .all(|n| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-9));
    }
}
