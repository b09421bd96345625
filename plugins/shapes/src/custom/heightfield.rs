//! `heightfield`: a terrain from a grid of heights, one primitive; a ray walks only the cells
//! it crosses (2-D DDA) and tests their two triangles.

use super::{at, in_range, slabs, usable};
use crate::params::{plain_some, positive};
use crate::vector::{cross, dot, scale, sub, V3};
use luxon_plugin::{
    finite, invalid, Aabb, Context, CustomShape, Describe, Error, Geometry, Hit, Primitive, Ray,
};
use serde::Deserialize;

/// Heights as rows or as one flat list.
#[derive(Deserialize, Debug, Clone)]
#[serde(
    untagged,
    expecting = "a list of rows `[[h, ...], ...]` or a flat list `[h, ...]` with `columns`"
)]
pub enum Heights {
    Rows(Vec<Vec<f64>>),
    Flat(Vec<f64>),
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct HeightfieldParams {
    #[serde(default)]
    pub origin: [f64; 2],
    pub size: [f64; 2],
    pub heights: Heights,
    #[serde(default, deserialize_with = "plain_some")]
    pub columns: Option<u64>,
}

/// A validated height grid: `nx` samples along x per row, `nz` rows along z.
#[derive(Clone, Debug)]
pub struct HeightGrid {
    origin: [f64; 2],
    size: [f64; 2],
    nx: usize,
    nz: usize,
    /// Row-major: `h[row * nx + column]`.
    h: Vec<f64>,
    low: f64,
    high: f64,
}

impl HeightGrid {
    pub fn new(p: &HeightfieldParams) -> Result<HeightGrid, Error> {
        let origin = finite("origin", p.origin)?;
        let size = [
            positive("size.0 (width)", p.size[0])?,
            positive("size.1 (depth)", p.size[1])?,
        ];
        let (nx, h) = match (&p.heights, p.columns) {
            (Heights::Rows(rows), None) => {
                let nx = rows.first().map_or(0, Vec::len);
                if let Some(i) = rows.iter().position(|r| r.len() != nx) {
                    return Err(invalid(format!(
                        "parameter `heights`: row {i} has {} heights but row 0 has {nx}; \
                         all rows must have the same length",
                        rows[i].len()
                    )));
                }
                (nx, rows.concat())
            }
            (Heights::Rows(_), Some(_)) => {
                return Err(invalid(
                    "parameter `columns` is only for a flat `heights` list; rows give their own",
                ))
            }
            (Heights::Flat(_), None) => {
                return Err(invalid(
                    "a flat `heights` list needs `columns` (heights per row)",
                ))
            }
            (Heights::Flat(flat), Some(columns)) => {
                let nx = usize::try_from(columns).unwrap_or(usize::MAX);
                if nx == 0 || flat.len() % nx != 0 {
                    return Err(invalid(format!(
                        "parameter `heights` has {} values, not a multiple of `columns` ({columns})",
                        flat.len()
                    )));
                }
                (nx, flat.clone())
            }
        };
        let nz = h.len().checked_div(nx).unwrap_or(0);
        if nx < 2 || nz < 2 {
            return Err(invalid(format!(
                "parameter `heights` is a {nx} x {nz} grid; expected at least 2 x 2"
            )));
        }
        for (n, &y) in h.iter().enumerate() {
            if !y.is_finite() {
                return Err(invalid(format!(
                    "parameter `heights` must be finite, got {y} at row {}, column {}",
                    n / nx,
                    n % nx
                )));
            }
        }
        let low = h.iter().copied().fold(f64::INFINITY, f64::min);
        let high = h.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Ok(HeightGrid {
            origin,
            size,
            nx,
            nz,
            h,
            low,
            high,
        })
    }

    fn corner(&self, i: usize, j: usize) -> V3 {
        [
            self.origin[0] + self.size[0] * (i as f64 / (self.nx - 1) as f64),
            self.h[j * self.nx + i],
            self.origin[1] + self.size[1] * (j as f64 / (self.nz - 1) as f64),
        ]
    }

    /// Nearest hit with one of cell `(i, j)`'s two triangles (split along the (i, j)-(i+1, j+1)
    /// diagonal).
    fn cell(&self, i: usize, j: usize, ray: &Ray) -> Option<(f64, V3)> {
        let p00 = self.corner(i, j);
        let p10 = self.corner(i + 1, j);
        let p11 = self.corner(i + 1, j + 1);
        let p01 = self.corner(i, j + 1);
        let mut best: Option<(f64, V3)> = None;
        for tri in [[p00, p10, p11], [p00, p11, p01]] {
            if let Some((t, n)) = triangle(tri, ray) {
                if best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, n));
                }
            }
        }
        best
    }
}

/// Möller–Trumbore with inclusive edges (a ray through a shared edge hits both triangles, so no
/// crack); the normal points up (+y). A ray in the triangle's plane misses.
fn triangle([p0, p1, p2]: [V3; 3], ray: &Ray) -> Option<(f64, V3)> {
    let e1 = sub(p1, p0);
    let e2 = sub(p2, p0);
    let pv = cross(ray.direction, e2);
    let det = dot(e1, pv);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = sub(ray.origin, p0);
    let u = dot(s, pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = cross(s, e1);
    let v = dot(ray.direction, qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = dot(e2, qv) * inv;
    if !in_range(ray, t) {
        return None;
    }
    let n = cross(e1, e2);
    Some((t, if n[1] < 0.0 { scale(n, -1.0) } else { n }))
}

impl CustomShape for HeightGrid {
    fn count(&self) -> u64 {
        1
    }

    fn bounds(&self, _index: u64) -> Aabb {
        Aabb {
            min: [self.origin[0], self.low, self.origin[1]],
            max: [
                self.origin[0] + self.size[0],
                self.high,
                self.origin[1] + self.size[1],
            ],
        }
    }

    fn intersect(&self, _index: u64, ray: &Ray) -> Option<Hit> {
        if !usable(ray) {
            return None;
        }
        let b = self.bounds(0);
        let (t0, _, t1, _) = slabs(b.min, b.max, ray)?;
        let ta = t0.max(ray.tmin);
        let tb = t1.min(ray.tmax);
        if ta > tb {
            return None;
        }
        // Grid coordinates: column index along x, row index along z, one unit per cell.
        let cells = [(self.nx - 1) as f64, (self.nz - 1) as f64];
        let g0 = [
            (ray.origin[0] - self.origin[0]) / self.size[0] * cells[0],
            (ray.origin[2] - self.origin[1]) / self.size[1] * cells[1],
        ];
        let dg = [
            ray.direction[0] / self.size[0] * cells[0],
            ray.direction[2] / self.size[1] * cells[1],
        ];
        // Cell of the first point inside the box (clamped: rounding may put it a hair outside).
        let last = [self.nx - 2, self.nz - 2];
        let mut cell = [0usize; 2];
        for k in 0..2 {
            let g = g0[k] + ta * dg[k];
            cell[k] = if g.is_finite() {
                (g.floor().max(0.0) as usize).min(last[k])
            } else {
                0
            };
        }
        // 2-D DDA: the t at which the ray crosses the next grid line on each axis.
        let next = |k: usize, c: usize| -> f64 {
            if dg[k] > 0.0 {
                ((c + 1) as f64 - g0[k]) / dg[k]
            } else if dg[k] < 0.0 {
                (c as f64 - g0[k]) / dg[k]
            } else {
                f64::INFINITY
            }
        };
        let mut cross_at = [next(0, cell[0]), next(1, cell[1])];
        loop {
            if let Some((t, normal)) = self.cell(cell[0], cell[1], ray) {
                let p = at(ray, t);
                let uv = [
                    ((p[0] - self.origin[0]) / self.size[0]) as f32,
                    ((p[2] - self.origin[1]) / self.size[1]) as f32,
                ];
                return Some(Hit { t, normal, uv });
            }
            let k = if cross_at[0] < cross_at[1] { 0 } else { 1 };
            if cross_at[k] > tb {
                return None;
            }
            if dg[k] > 0.0 {
                if cell[k] == last[k] {
                    return None;
                }
                cell[k] += 1;
            } else {
                if cell[k] == 0 {
                    return None;
                }
                cell[k] -= 1;
            }
            cross_at[k] = next(k, cell[k]);
        }
    }
}

pub struct Heightfield;

impl Describe for Heightfield {
    const NAME: &'static str = "heightfield";
    const DESCRIPTION: &'static str =
        "A terrain from a grid of heights (y up), two triangles per cell, one primitive.";
    const PARAMS: &'static str = "origin: (x, z) = (0, 0)  grid corner of row 0, column 0
size: (width, depth)  extent along x and z, both > 0
heights: [[f64, ...], ...]  rows along z of heights along x, at least 2 x 2 (or a flat list)
columns: u64 = none  heights per row, only with a flat `heights` list";
}

impl Primitive for Heightfield {
    type Params = HeightfieldParams;
    fn create(p: HeightfieldParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(HeightGrid::new(&p)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{assert_hit, close, close3, err, hit, ray};
    use crate::vector::normalize;
    use luxon_plugin::parse_params;

    fn grid(p: &str) -> HeightGrid {
        HeightGrid::new(&parse_params(p).unwrap()).unwrap()
    }

    /// 4 x 3 samples over [0, 3] x [0, 2]: one unit per cell, flat at 0 except a bump of 1 at
    /// column 1, row 1.
    fn bumpy() -> HeightGrid {
        grid("(size: (3, 2), heights: [[0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0]])")
    }

    #[test]
    fn heightfield_vertical_rays() {
        let g = bumpy();
        assert_hit(
            &g,
            &ray([2.5, 5.0, 0.5], [0.0, -1.0, 0.0]),
            5.0,
            [0.0, 1.0, 0.0],
        );
        // On the bump's peak.
        let (t, n) = hit(&g, &ray([1.0, 5.0, 1.0], [0.0, -2.0, 0.0])).unwrap();
        assert!(close(t, 2.0) && n[1] > 0.0);
        // Cell (0, 0), triangle (0,0)-(1,0)-(1,1) holds (0.75, 0.25): height there
        // 0 + 0.75*0 + ... plane through (0,0,0), (1,0,0), (1,1,1): y = z.
        let n = normalize([0.0, 1.0, -1.0]).unwrap();
        assert_hit(&g, &ray([0.75, 3.0, 0.25], [0.0, -1.0, 0.0]), 2.75, n);
        // The other triangle (0,0)-(1,1)-(0,1) holds (0.25, 0.75): plane y = x.
        let n = normalize([-1.0, 1.0, 0.0]).unwrap();
        assert_hit(&g, &ray([0.25, 3.0, 0.75], [0.0, -1.0, 0.0]), 2.75, n);
        // From below the surface upward (a "from inside" ray): hits the underside.
        assert_hit(
            &g,
            &ray([0.25, -1.0, 0.75], [0.0, 1.0, 0.0]),
            1.25,
            normalize([-1.0, 1.0, 0.0]).unwrap(),
        );
        // Outside the grid.
        assert!(g
            .intersect(0, &ray([3.5, 5.0, 0.5], [0.0, -1.0, 0.0]))
            .is_none());
    }

    #[test]
    fn heightfield_oblique_ray_walks_cells() {
        let g = bumpy();
        // Along z = 1 from x = -1 at height 0.5 going +x: flat until the bump; the rising face
        // of the bump between columns 0 and 1 (on the row-1 grid line) has y = x, so y = 0.5
        // at x = 0.5.
        let (t, n) = hit(&g, &ray([-1.0, 0.5, 1.0], [1.0, 0.0, 0.0])).unwrap();
        assert!(close(t, 1.5), "{t}");
        assert!(n[1] > 0.0 && n[0] < 0.0);
        // Same height from the far side: x from 4 going -x meets the falling face between
        // columns 1 and 2 (y = 2 - x) at x = 1.5.
        let (t, _) = hit(&g, &ray([4.0, 0.5, 1.0], [-1.0, 0.0, 0.0])).unwrap();
        assert!(close(t, 2.5), "{t}");
        // Above everything: miss. In the plane of the flat part (y = 0): flat cells are not hit
        // (a ray in a triangle's plane misses), but the sloped cell (0, 0) is, at x = 0.
        assert!(g
            .intersect(0, &ray([-1.0, 1.5, 1.0], [1.0, 0.0, 0.0]))
            .is_none());
        assert!(g
            .intersect(0, &ray([2.5, 0.0, 0.25], [1.0, 0.0, 0.0]))
            .is_none());
        let (t, _) = hit(&g, &ray([-1.0, 0.0, 0.25], [1.0, 0.0, 0.0])).unwrap();
        assert!(close(t, 1.0), "{t}");
        assert!(g
            .intersect(0, &ray([2.5, 0.0, -1.0], [0.0, 0.0, 1.0]))
            .is_none());
    }

    #[test]
    fn heightfield_rays_along_grid_lines() {
        let g = bumpy();
        // Down the grid line x = 2 (between cells), diagonally in z: plane y = 0 there except
        // nothing; aimed at the ground at z = 0.5.
        assert_hit(
            &g,
            &ray([2.0, 1.0, 1.5], [0.0, -1.0, -1.0]),
            1.0,
            [0.0, 1.0, 0.0],
        );
        // Exactly on a grid vertex column x = 1, z going +, height 0.5: meets the bump's side
        // on the shared edge x = 1 (y = z there) at z = 0.5.
        let (t, n) = hit(&g, &ray([1.0, 0.5, -1.0], [0.0, 0.0, 1.0])).unwrap();
        assert!(close(t, 1.5), "{t}");
        assert!(n[1] > 0.0 && n[2] < 0.0);
        // On the outer boundary x = 3 (last column).
        assert_hit(
            &g,
            &ray([3.0, 2.0, 1.0], [0.0, -1.0, 0.0]),
            2.0,
            [0.0, 1.0, 0.0],
        );
    }

    #[test]
    fn heightfield_matches_brute_force() {
        // A bumpy 9 x 7 grid with a flat list; compare the DDA against testing every triangle.
        let mut heights = Vec::new();
        for j in 0..7 {
            for i in 0..9 {
                heights.push(format!("{}", ((i * 7 + j * 3) % 5) as f64 * 0.3 - 0.5));
            }
        }
        let g = grid(&format!(
            "(origin: (-2, 1), size: (4, 3), heights: [{}], columns: 9)",
            heights.join(", ")
        ));
        assert_eq!((g.nx, g.nz), (9, 7));
        let brute = |r: &Ray| {
            let mut best: Option<f64> = None;
            for j in 0..6 {
                for i in 0..8 {
                    if let Some((t, _)) = g.cell(i, j, r) {
                        best = Some(best.map_or(t, |b: f64| b.min(t)));
                    }
                }
            }
            best
        };
        let mut hits = 0;
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let o = [rnd() * 8.0 - 4.0, rnd() * 3.0 - 1.0, rnd() * 6.0 - 2.0];
            let d = [rnd() * 2.0 - 1.0, rnd() * 2.0 - 1.2, rnd() * 2.0 - 1.0];
            let r = ray(o, d);
            let a = g.intersect(0, &r).map(|h| h.t);
            let b = brute(&r);
            match (a, b) {
                (Some(a), Some(b)) => {
                    assert!(close(a, b), "{a} vs {b} for {r:?}");
                    hits += 1;
                }
                (None, None) => {}
                _ => panic!("DDA {a:?} vs brute force {b:?} for {r:?}"),
            }
        }
        assert!(hits > 200, "only {hits} hits");
        let b = g.bounds(0);
        assert!(close3(b.min, [-2.0, -0.5, 1.0]) && close3(b.max, [2.0, 0.7, 4.0]));
    }

    #[test]
    fn heightfield_errors() {
        let bad = |p: &str| err(HeightGrid::new(&parse_params(p).unwrap()));
        assert!(bad("(size: (1, 1), heights: [[0, 0], [0]])").contains("row 1 has 1"));
        assert!(bad("(size: (1, 1), heights: [[0, 0]])").contains("at least 2 x 2"));
        assert!(bad("(size: (1, 1), heights: [[0], [0]])").contains("at least 2 x 2"));
        assert!(bad("(size: (0, 1), heights: [[0, 0], [0, 0]])").contains("width"));
        assert!(bad("(size: (1, 1), heights: [0, 0, 0, 0])").contains("needs `columns`"));
        assert!(bad("(size: (1, 1), heights: [0, 0, 0], columns: 2)").contains("multiple"));
        assert!(bad("(size: (1, 1), heights: [0, 0, 0, 0], columns: 0)").contains("multiple"));
        assert!(bad("(size: (1, 1), heights: [[0, 0], [0, 0]], columns: 2)").contains("only for"));
        let p = HeightfieldParams {
            origin: [0.0; 2],
            size: [1.0; 2],
            heights: Heights::Rows(vec![vec![0.0, f64::INFINITY], vec![0.0, 0.0]]),
            columns: None,
        };
        assert!(err(HeightGrid::new(&p)).contains("row 0, column 1"));
        let m = parse_params::<HeightfieldParams>("(size: (1, 1), heights: 3)").unwrap_err();
        assert!(m.message.contains("list of rows"), "{}", m.message);
    }
}
