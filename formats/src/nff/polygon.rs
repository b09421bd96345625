//! Polygons into triangles: a fan for convex polygons, ear clipping in the polygon's plane for
//! concave ones (the SPD gears are 144-gons with notches; a fan from one vertex would cover the
//! notches). No allocation per polygon: the scratch buffers are reused.
//!
//! Time: polygons of up to 2,048 corners get the best-ear triangulation, O(m²). Larger ones
//! cut the first ear found going round the polygon (each round cuts about every other corner,
//! so the triangles stay compact), looking for vertices inside a candidate ear only in the
//! cells of a grid of the reflex vertices that the ear overlaps: the same answer as looking at
//! all of them, in far less time. A self-intersecting or very irregular polygon can still need
//! O(m²) steps: the work is counted, and past a budget of `32 m log2 m` steps (about a second
//! for 100,000 corners) the rest of the polygon becomes a fan from one corner, which the caller
//! reports as a warning (a fan may cover area outside the polygon).

/// Reused buffers of the triangulator.
#[derive(Default)]
pub(crate) struct Triangulator {
    /// 2-D vertices in the plane, counter-clockwise.
    pts: Vec<[f64; 2]>,
    /// Indices of the polygon's distinct vertices (consecutive duplicates removed).
    keep: Vec<u32>,
    prev: Vec<u32>,
    next: Vec<u32>,
    reflex: Vec<bool>,
    /// Per corner: `Some(diagonal length²)` when it is an ear.
    ear: Vec<Option<f64>>,
    /// The grid of reflex vertices of large polygons (`first_ears`), and the corners it was
    /// built over.
    grid: Grid,
    ring: Vec<[f64; 2]>,
    /// Steps of the ear search so far (large polygons), against `budget`.
    work: u64,
    budget: u64,
    /// Tests: the ear test without the grid and no budget (the oracle for the grid's).
    #[cfg(test)]
    plain: bool,
}

/// How a polygon was triangulated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Outcome {
    /// Triangles that came from the fan fallback after the work budget ran out (0: none).
    pub fan: usize,
}

/// Reflex vertices bucketed in a uniform `size x size` grid over the polygon's bounding box,
/// so that a triangle's test looks only at the vertices in the cells it overlaps. A vertex is
/// taken out when it is cut off or turns convex, so every entry is a live reflex vertex.
#[derive(Default)]
struct Grid {
    size: usize,
    min: [f64; 2],
    /// Cells per unit along x and y.
    scale: [f64; 2],
    cells: Vec<Vec<u32>>,
    /// Per vertex: its cell and its place there (`NONE`: not in the grid).
    cell_of: Vec<u32>,
    slot: Vec<u32>,
    /// Vertices in the grid.
    live: usize,
}

const NONE: u32 = u32::MAX;

impl Grid {
    /// An empty grid over `pts` with about 4 points per cell, for vertex indices below `n`.
    fn reset(&mut self, pts: &[[f64; 2]], n: usize) {
        let m = pts.len();
        self.size = ((m as f64 / 4.0).sqrt().ceil() as usize).max(1);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in pts {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        self.min = lo;
        self.scale = [0, 1].map(|k| {
            let extent = hi[k] - lo[k];
            if extent > 0.0 {
                self.size as f64 / extent
            } else {
                0.0
            }
        });
        let cells = self.size * self.size;
        self.cells.truncate(cells);
        for c in &mut self.cells {
            c.clear();
        }
        self.cells.resize_with(cells, Vec::new);
        self.cell_of.clear();
        self.cell_of.resize(n, NONE);
        self.slot.clear();
        self.slot.resize(n, NONE);
        self.live = 0;
    }

    /// The cell column or row of coordinate `v` along axis `k`. Monotone in `v`, so the
    /// cells of a box's corners bound the cells of every point in the box.
    fn cell(&self, v: f64, k: usize) -> usize {
        // `as` saturates: below the box gives 0.
        (((v - self.min[k]) * self.scale[k]) as usize).min(self.size - 1)
    }

    /// The columns of row `y` that triangle `t` may overlap, within `lo..=hi` (the columns of
    /// its bounding box). The row's band is widened by a hundredth of a row and the span by a
    /// column on each side, so that rounding never leaves out a cell a point of the triangle
    /// falls in. Empty (`lo > hi`) when the triangle misses the row.
    fn row_span(&self, y: usize, t: [[f64; 2]; 3], lo: usize, hi: usize) -> (usize, usize) {
        if self.scale[1] == 0.0 {
            return (lo, hi);
        }
        let h = 1.0 / self.scale[1];
        let y0 = self.min[1] + (y as f64 - 0.01) * h;
        let y1 = self.min[1] + (y as f64 + 1.01) * h;
        let mut x_min = f64::INFINITY;
        let mut x_max = f64::NEG_INFINITY;
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            if (y0..=y1).contains(&p[1]) {
                x_min = x_min.min(p[0]);
                x_max = x_max.max(p[0]);
            }
            for band in [y0, y1] {
                if p[1] != q[1] && (p[1] - band) * (q[1] - band) <= 0.0 {
                    let x = p[0] + (band - p[1]) / (q[1] - p[1]) * (q[0] - p[0]);
                    x_min = x_min.min(x);
                    x_max = x_max.max(x);
                }
            }
        }
        if x_min > x_max {
            return (1, 0);
        }
        let a = self.cell(x_min, 0).saturating_sub(1).max(lo);
        let b = (self.cell(x_max, 0) + 1).min(hi);
        (a, b)
    }

    /// Puts vertex `i` at `p` in the grid (if it is not there).
    fn add(&mut self, i: usize, p: [f64; 2]) {
        if self.slot[i] == NONE {
            let c = self.cell(p[1], 1) * self.size + self.cell(p[0], 0);
            self.cell_of[i] = c as u32;
            self.slot[i] = self.cells[c].len() as u32;
            self.cells[c].push(i as u32);
            self.live += 1;
        }
    }

    /// Takes vertex `i` out of the grid (if it is there).
    fn remove(&mut self, i: usize) {
        let slot = self.slot[i];
        if slot != NONE {
            let cell = &mut self.cells[self.cell_of[i] as usize];
            cell.swap_remove(slot as usize);
            if let Some(&moved) = cell.get(slot as usize) {
                self.slot[moved as usize] = slot;
            }
            self.slot[i] = NONE;
            self.live -= 1;
        }
    }
}

/// Polygons up to this many corners get the best-ear triangulation.
const BEST_EAR_MAX: usize = 2048;

/// Newell's normal of a polygon (not normalised; zero when it has no area).
pub(crate) fn newell_normal(v: &[[f64; 3]]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for (i, a) in v.iter().enumerate() {
        let b = &v[(i + 1) % v.len()];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    n
}

#[inline]
fn cross2(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

impl Triangulator {
    /// Appends triangles (indices into `v`, wound as the polygon is) covering polygon `v`.
    /// Degenerate polygons (no area) get a fan: its triangles have no area either, and the
    /// renderer drops those.
    pub fn triangulate(&mut self, v: &[[f64; 3]], out: &mut Vec<[u32; 3]>) -> Outcome {
        self.triangulate_up_to(v, out, BEST_EAR_MAX)
    }

    /// `triangulate`, cutting best ears in concave polygons of at most `best_ears` corners.
    fn triangulate_up_to(
        &mut self,
        v: &[[f64; 3]],
        out: &mut Vec<[u32; 3]>,
        best_ears: usize,
    ) -> Outcome {
        let n = v.len();
        if n < 3 {
            return Outcome::default();
        }
        if n == 3 {
            out.push([0, 1, 2]);
            return Outcome::default();
        }
        // Distinct vertices only: a repeated vertex makes a zero-length edge.
        self.keep.clear();
        for i in 0..n {
            let last = self.keep.last().map(|&k| v[k as usize]);
            if last != Some(v[i]) {
                self.keep.push(i as u32);
            }
        }
        while self.keep.len() > 1
            && v[self.keep[0] as usize] == v[*self.keep.last().unwrap() as usize]
        {
            self.keep.pop();
        }
        let normal = newell_normal(v);
        let m = self.keep.len();
        if m < 3 || normal == [0.0; 3] {
            fan(n, out);
            return Outcome::default();
        }
        // Project onto the plane that drops the normal's largest axis, keeping orientation:
        // the polygon is counter-clockwise seen from its normal, so it stays counter-clockwise.
        let a = normal.map(f64::abs);
        let (ax, ay, flip) = if a[0] >= a[1] && a[0] >= a[2] {
            (1, 2, normal[0] < 0.0)
        } else if a[1] >= a[2] {
            (2, 0, normal[1] < 0.0)
        } else {
            (0, 1, normal[2] < 0.0)
        };
        self.pts.clear();
        for &k in &self.keep {
            let p = v[k as usize];
            self.pts
                .push(if flip { [p[ay], p[ax]] } else { [p[ax], p[ay]] });
        }
        // Convex (no reflex corner): a fan is exact.
        self.reflex.clear();
        let mut any_reflex = false;
        for i in 0..m {
            let c = cross2(
                self.pts[(i + m - 1) % m],
                self.pts[i],
                self.pts[(i + 1) % m],
            );
            any_reflex |= c < 0.0;
            self.reflex.push(c < 0.0);
        }
        if !any_reflex {
            for i in 1..m - 1 {
                out.push([self.keep[0], self.keep[i], self.keep[i + 1]]);
            }
            return Outcome::default();
        }
        self.ear_clip(out, best_ears)
    }

    /// Cuts, each time, the ear with the shortest closing diagonal: the triangles come out
    /// compact (a gear's teeth first, then its disc halved and halved again) instead of the
    /// long slivers that cutting the first ear found leaves, which overlap in the BVH (the
    /// SPD gears took 13.8 ray/triangle tests per ray with slivers). O(m²); larger polygons
    /// take the first ear found.
    fn ear_clip(&mut self, out: &mut Vec<[u32; 3]>, best_ears: usize) -> Outcome {
        let m = self.pts.len();
        if m > best_ears {
            return self.first_ears(out);
        }
        self.prev.clear();
        self.next.clear();
        for i in 0..m {
            self.prev.push(((i + m - 1) % m) as u32);
            self.next.push(((i + 1) % m) as u32);
        }
        self.ear.clear();
        for i in 0..m {
            let e = self.ear_key(i);
            self.ear.push(e);
        }
        let mut left = m;
        let mut start = 0usize;
        while left > 3 {
            let mut best: Option<(f64, usize)> = None;
            let mut k = start;
            loop {
                if let Some(key) = self.ear[k] {
                    if best.is_none_or(|(b, _)| key < b) {
                        best = Some((key, k));
                    }
                }
                k = self.next[k] as usize;
                if k == start {
                    break;
                }
            }
            // No ear: not simple (or rounding hides its ears); cut the flattest convex corner.
            let cut = best.map_or_else(|| self.fallback_corner(start), |(_, k)| k);
            let (p, nx) = (self.prev[cut] as usize, self.next[cut] as usize);
            out.push([self.keep[p], self.keep[cut], self.keep[nx]]);
            self.next[p] = nx as u32;
            self.prev[nx] = p as u32;
            left -= 1;
            for k in [p, nx] {
                let c = cross2(
                    self.pts[self.prev[k] as usize],
                    self.pts[k],
                    self.pts[self.next[k] as usize],
                );
                self.reflex[k] = c < 0.0;
            }
            for k in [p, nx] {
                self.ear[k] = self.ear_key(k);
            }
            start = p;
        }
        let (p, nx) = (self.prev[start] as usize, self.next[start] as usize);
        out.push([self.keep[p], self.keep[start], self.keep[nx]]);
        Outcome::default()
    }

    /// For an ear at corner `i`: the squared length of the diagonal that cuts it off.
    fn ear_key(&self, i: usize) -> Option<f64> {
        let (p, nx) = (self.prev[i] as usize, self.next[i] as usize);
        if self.reflex[i] || !self.no_point_inside(p, i, nx) {
            return None;
        }
        let (a, b) = (self.pts[p], self.pts[nx]);
        Some((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2))
    }

    /// Ear clipping that cuts the first ear it meets and goes on past the ear's far corner
    /// (so that a round cuts about every other corner), with the grid's ear test, within the
    /// work budget (past it, the rest is a fan).
    fn first_ears(&mut self, out: &mut Vec<[u32; 3]>) -> Outcome {
        let m = self.pts.len();
        self.prev.clear();
        self.next.clear();
        for i in 0..m {
            self.prev.push(((i + m - 1) % m) as u32);
            self.next.push(((i + 1) % m) as u32);
        }
        self.fill_grid(0);
        // The grid is built again, coarser, each time the polygon has lost half its corners:
        // its cells stay about as large as the ears being cut.
        let mut rebuild_at = m / 2;
        self.work = 0;
        self.budget = work_budget(m);
        #[cfg(test)]
        if self.plain {
            self.budget = u64::MAX;
        }
        let mut left = m;
        let mut i = 0usize;
        // Corners looked at since the last ear was cut: a full round without an ear means the
        // polygon is not simple (or rounding hides its ears); cut the flattest convex corner.
        let mut misses = 0usize;
        while left > 3 {
            if self.work > self.budget {
                return Outcome {
                    fan: self.fan_rest(i, left, out),
                };
            }
            if left <= rebuild_at {
                self.fill_grid(i);
                self.work += left as u64;
                rebuild_at = left / 2;
            }
            self.work += 1;
            let (p, nx) = (self.prev[i] as usize, self.next[i] as usize);
            let is_ear = !self.reflex[i] && self.ear_test(p, i, nx);
            if is_ear || misses > left {
                let cut = if is_ear { i } else { self.fallback_corner(i) };
                let (p, nx) = (self.prev[cut] as usize, self.next[cut] as usize);
                out.push([self.keep[p], self.keep[cut], self.keep[nx]]);
                self.next[p] = nx as u32;
                self.prev[nx] = p as u32;
                self.grid.remove(cut);
                left -= 1;
                misses = 0;
                for k in [p, nx] {
                    let c = cross2(
                        self.pts[self.prev[k] as usize],
                        self.pts[k],
                        self.pts[self.next[k] as usize],
                    );
                    self.reflex[k] = c < 0.0;
                    // A corner can turn reflex too, after a cut that was not an ear.
                    if self.reflex[k] {
                        self.grid.add(k, self.pts[k]);
                    } else {
                        self.grid.remove(k);
                    }
                }
                i = self.next[nx] as usize;
            } else {
                misses += 1;
                i = nx;
            }
        }
        let (p, nx) = (self.prev[i] as usize, self.next[i] as usize);
        out.push([self.keep[p], self.keep[i], self.keep[nx]]);
        Outcome::default()
    }

    /// A new grid over the corners left (the ring through corner `from`), holding its reflex
    /// corners.
    fn fill_grid(&mut self, from: usize) {
        self.ring.clear();
        let mut k = from;
        loop {
            self.ring.push(self.pts[k]);
            k = self.next[k] as usize;
            if k == from {
                break;
            }
        }
        self.grid.reset(&self.ring, self.pts.len());
        let mut k = from;
        loop {
            if self.reflex[k] {
                self.grid.add(k, self.pts[k]);
            }
            k = self.next[k] as usize;
            if k == from {
                break;
            }
        }
    }

    /// The remaining `left` corners as a fan from corner `i`; the number of triangles.
    fn fan_rest(&self, i: usize, left: usize, out: &mut Vec<[u32; 3]>) -> usize {
        let mut k = self.next[i] as usize;
        while self.next[k] as usize != i {
            let nx = self.next[k] as usize;
            out.push([self.keep[i], self.keep[k], self.keep[nx]]);
            k = nx;
        }
        left - 2
    }

    /// Whether the corner (a, b, c) is an ear: through the grid (the plain scan in tests that
    /// ask for it).
    fn ear_test(&mut self, a: usize, b: usize, c: usize) -> bool {
        #[cfg(test)]
        if self.plain {
            return self.no_point_inside(a, b, c);
        }
        self.no_point_inside_grid(a, b, c)
    }

    /// `no_point_inside`, looking only at the reflex vertices in the grid cells that the
    /// triangle's bounding box overlaps (bounds included: a vertex on the box is found).
    /// Counts its steps as work.
    fn no_point_inside_grid(&mut self, a: usize, b: usize, c: usize) -> bool {
        let (pa, pb, pc) = (self.pts[a], self.pts[b], self.pts[c]);
        if cross2(pa, pb, pc) <= 0.0 {
            return false;
        }
        let g = &self.grid;
        if g.live == 0 {
            return true;
        }
        let lo = [0, 1].map(|k| g.cell(pa[k].min(pb[k]).min(pc[k]), k));
        let hi = [0, 1].map(|k| g.cell(pa[k].max(pb[k]).max(pc[k]), k));
        let mut work = 0u64;
        let mut clear = true;
        'cells: for y in lo[1]..=hi[1] {
            let (x0, x1) = g.row_span(y, [pa, pb, pc], lo[0], hi[0]);
            for x in x0..=x1 {
                let cell = &g.cells[y * g.size + x];
                work += 1 + cell.len() as u64;
                for &k in cell {
                    let k = k as usize;
                    if k != a && k != b && k != c && inside_or_on(pa, pb, pc, self.pts[k]) {
                        clear = false;
                        break 'cells;
                    }
                }
            }
        }
        self.work += work;
        clear
    }

    /// True when no other remaining vertex lies inside or on triangle (a, b, c).
    fn no_point_inside(&self, a: usize, b: usize, c: usize) -> bool {
        let (pa, pb, pc) = (self.pts[a], self.pts[b], self.pts[c]);
        if cross2(pa, pb, pc) <= 0.0 {
            return false;
        }
        let mut k = self.next[c] as usize;
        while k != a {
            // Only reflex vertices can be inside a convex corner's triangle.
            if self.reflex[k] && inside_or_on(pa, pb, pc, self.pts[k]) {
                return false;
            }
            k = self.next[k] as usize;
        }
        true
    }

    /// The remaining corner with the largest convex turn, starting the search at `from`.
    fn fallback_corner(&mut self, from: usize) -> usize {
        let mut best = from;
        let mut best_c = f64::NEG_INFINITY;
        let mut k = from;
        loop {
            self.work += 1;
            let c = cross2(
                self.pts[self.prev[k] as usize],
                self.pts[k],
                self.pts[self.next[k] as usize],
            );
            if c > best_c {
                best_c = c;
                best = k;
            }
            k = self.next[k] as usize;
            if k == from {
                return best;
            }
        }
    }
}

/// Whether `q`, a point other than the corners, lies inside or on triangle (a, b, c)
/// (counter-clockwise).
#[inline]
fn inside_or_on(pa: [f64; 2], pb: [f64; 2], pc: [f64; 2], q: [f64; 2]) -> bool {
    q != pa
        && q != pb
        && q != pc
        && cross2(pa, pb, q) >= 0.0
        && cross2(pb, pc, q) >= 0.0
        && cross2(pc, pa, q) >= 0.0
}

/// The work the ear search of a polygon of `m` corners may do: `32 m ceil(log2 m)` steps
/// (54 million for 100,000 corners, about a second).
fn work_budget(m: usize) -> u64 {
    let m = m as u64;
    32 * m * u64::from(m.next_power_of_two().trailing_zeros().max(1))
}

fn fan(n: usize, out: &mut Vec<[u32; 3]>) {
    for i in 1..n - 1 {
        out.push([0, i as u32, i as u32 + 1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area2(p: &[[f64; 2]]) -> f64 {
        (0..p.len())
            .map(|i| {
                let (a, b) = (p[i], p[(i + 1) % p.len()]);
                a[0] * b[1] - a[1] * b[0]
            })
            .sum::<f64>()
            / 2.0
    }

    /// Even-odd point in polygon.
    fn inside(p: &[[f64; 2]], q: [f64; 2]) -> bool {
        let mut c = false;
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            if (a[1] > q[1]) != (b[1] > q[1]) {
                let x = a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if q[0] < x {
                    c = !c;
                }
            }
        }
        c
    }

    /// Triangulates a planar polygon given in 2-D (placed in a tilted plane in 3-D) and checks
    /// the cover: the triangle areas add up to the polygon's, each triangle keeps the polygon's
    /// winding, and every triangle's centroid and edge midpoints lie inside the polygon.
    fn check_cover(p2: &[[f64; 2]]) -> Vec<[u32; 3]> {
        let lift = |q: [f64; 2]| [q[0], 0.3 * q[0] + 0.2 * q[1], q[1] + 5.0];
        let v: Vec<[f64; 3]> = p2.iter().map(|&q| lift(q)).collect();
        let mut t = Triangulator::default();
        let mut out = Vec::new();
        t.triangulate(&v, &mut out);
        assert_eq!(out.len(), p2.len() - 2, "n - 2 triangles");
        let total = area2(p2);
        let mut sum = 0.0;
        for tri in &out {
            let q = tri.map(|i| p2[i as usize]);
            let a = area2(&q);
            assert!(
                a * total > 0.0,
                "triangle {tri:?} is wound against the polygon"
            );
            sum += a;
            let c = [
                (q[0][0] + q[1][0] + q[2][0]) / 3.0,
                (q[0][1] + q[1][1] + q[2][1]) / 3.0,
            ];
            assert!(inside(p2, c), "centroid of {tri:?} is outside the polygon");
        }
        assert!(
            (sum - total).abs() < 1e-9 * total.abs().max(1.0),
            "area {sum} != {total}"
        );
        out
    }

    #[test]
    fn triangle_and_convex_fan() {
        check_cover(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        check_cover(&[[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 2.0], [0.0, 1.0]]);
        // Clockwise too.
        check_cover(&[[0.0, 1.0], [1.0, 2.0], [2.0, 1.0], [2.0, 0.0], [0.0, 0.0]]);
    }

    #[test]
    fn gears_are_cut_into_compact_triangles() {
        // A 36-tooth gear outline (144 corners, like the SPD gears).
        let gear: Vec<[f64; 2]> = (0..144)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 144.0;
                let r = if (i / 2) % 2 == 0 { 1.0 } else { 0.85 };
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        let best = check_cover(&gear);
        let longest = |tris: &[[u32; 3]]| -> f64 {
            tris.iter()
                .map(|t| {
                    (0..3)
                        .map(|k| {
                            let (a, b) = (gear[t[k] as usize], gear[t[(k + 1) % 3] as usize]);
                            (a[0] - b[0]).hypot(a[1] - b[1])
                        })
                        .fold(0.0, f64::max)
                })
                .sum()
        };
        // The same polygon cut by the large polygons' method: the first ear found, going
        // round the polygon (not back at the same corner, which grows a fan of slivers).
        let v: Vec<[f64; 3]> = gear.iter().map(|q| [q[0], q[1], 0.0]).collect();
        let mut first = Vec::new();
        Triangulator::default().triangulate_up_to(&v, &mut first, 0);
        assert_eq!(first.len(), best.len());
        // The longest edge of a triangle is about a quarter of the gear's diameter on average
        // (slivers, cut always next to the last ear, averaged over a half).
        let n = best.len() as f64;
        let (b, f) = (longest(&best) / n, longest(&first) / n);
        assert!(
            b < 0.3 && f < 0.3,
            "mean longest edges: best ears {b}, first ears {f}"
        );
    }

    #[test]
    fn concave_polygons_are_ear_clipped() {
        // An L and an arrow head, both windings.
        let l = [
            [0.0, 0.0],
            [3.0, 0.0],
            [3.0, 1.0],
            [1.0, 1.0],
            [1.0, 3.0],
            [0.0, 3.0],
        ];
        check_cover(&l);
        let mut r = l;
        r.reverse();
        check_cover(&r);
        check_cover(&[[0.0, 0.0], [2.0, 1.0], [4.0, 0.0], [2.0, 3.0]]);
        // A concave quad whose fan from vertex 0 would leave the polygon.
        check_cover(&[[1.0, 1.0], [0.0, 3.0], [-1.0, 0.0], [3.0, 0.0]]);
    }

    #[test]
    fn gear_like_polygon() {
        // 36 teeth: 144 vertices alternating between two radii in pairs, like an SPD gear.
        let mut p = Vec::new();
        for k in 0..144 {
            let a = k as f64 / 144.0 * std::f64::consts::TAU;
            let r = if (k / 2) % 2 == 0 { 1.0 } else { 0.8 };
            p.push([r * a.cos(), r * a.sin()]);
        }
        check_cover(&p);
        // A fan from vertex 0 would not do: some of its triangles leave the polygon.
        let outside = (1..143).any(|i| {
            let q = [p[0], p[i], p[i + 1]];
            let c = [
                (q[0][0] + q[1][0] + q[2][0]) / 3.0,
                (q[0][1] + q[1][1] + q[2][1]) / 3.0,
            ];
            !inside(&p, c)
        });
        assert!(outside);
    }

    #[test]
    fn comb_with_collinear_vertices() {
        // A comb with collinear points along its spine.
        let mut p = vec![[0.0, 0.0]];
        for k in 0..10 {
            let x = k as f64;
            p.push([x + 0.5, 0.0]);
            p.push([x + 1.0, 0.0]);
        }
        p.push([10.0, 2.0]);
        for k in (0..10).rev() {
            let x = k as f64;
            p.push([x + 0.75, 2.0]);
            p.push([x + 0.5, 1.0]);
            p.push([x + 0.25, 2.0]);
        }
        p.push([0.0, 2.0]);
        check_cover(&p);
    }

    /// xorshift64*: test polygons the same on every run.
    struct Rng(u64);

    impl Rng {
        fn unit(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A star-shaped (simple) polygon: corners at even angles, radii from `radius`.
    fn star(m: usize, mut radius: impl FnMut(usize) -> f64) -> Vec<[f64; 3]> {
        (0..m)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / m as f64;
                let r = radius(i);
                [r * a.cos(), r * a.sin(), 0.0]
            })
            .collect()
    }

    /// A comb of `teeth` teeth of random depths (simple, with many reflex corners).
    fn comb(teeth: usize, rng: &mut Rng) -> Vec<[f64; 3]> {
        let mut p = vec![[0.0, 0.0, 0.0], [teeth as f64, 0.0, 0.0]];
        for k in (0..teeth).rev() {
            let x = k as f64;
            p.push([x + 0.9, 2.0, 0.0]);
            p.push([x + 0.5, 1.0 + 0.9 * rng.unit(), 0.0]);
            p.push([x + 0.1, 2.0, 0.0]);
        }
        p
    }

    /// Corners at random angles and radii: it intersects itself everywhere.
    fn tangle(m: usize, rng: &mut Rng) -> Vec<[f64; 3]> {
        (0..m)
            .map(|_| {
                let a = rng.unit() * std::f64::consts::TAU;
                let r = 1.0 + rng.unit();
                [r * a.cos(), 0.0, r * a.sin()]
            })
            .collect()
    }

    fn cut(v: &[[f64; 3]], plain: bool) -> (Vec<[u32; 3]>, Outcome, u64) {
        let mut t = Triangulator {
            plain,
            ..Triangulator::default()
        };
        let mut out = Vec::new();
        let outcome = t.triangulate(v, &mut out);
        (out, outcome, t.work)
    }

    /// The grid changes where the ear test looks, not its answer: large polygons get the
    /// same triangles as with the full scan (up to where the budget stops a tangle).
    #[test]
    fn the_grid_finds_the_same_ears_as_the_full_scan() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut polygons = Vec::new();
        for m in [3000, 5000, 8000] {
            polygons.push(star(m, |i| if i % 2 == 0 { 1.0 } else { 0.8 }));
            polygons.push(star(m, |_| 0.5 + 0.5 * rng.unit()));
            polygons.push(comb(m / 3, &mut rng));
        }
        for (k, v) in polygons.iter().enumerate() {
            let (grid, outcome, _) = cut(v, false);
            let (plain, _, _) = cut(v, true);
            assert_eq!(outcome.fan, 0, "polygon {k}");
            assert!(grid == plain, "polygon {k} of {} corners", v.len());
        }
        let v = tangle(2500, &mut rng);
        let (grid, outcome, _) = cut(&v, false);
        let (plain, _, _) = cut(&v, true);
        let ears = grid.len() - outcome.fan;
        assert_eq!(grid[..ears], plain[..ears]);
    }

    /// A tangle of 100,000 corners stops at the work budget and ends in a fan; a simple star
    /// of as many corners needs a small multiple of its size and no fan.
    #[test]
    fn work_is_bounded_by_the_budget() {
        let m = 100_000;
        let v = tangle(m, &mut Rng(7));
        let (out, outcome, work) = cut(&v, false);
        assert_eq!(out.len(), m - 2);
        assert!(outcome.fan > 0);
        // The budget is checked between ear tests: one more step (an ear test over the whole
        // grid, a fallback corner search, a grid rebuild) may pass it.
        assert!(work <= work_budget(m) + 4 * m as u64, "{work}");
        for v in [
            star(m, |i| if i % 2 == 0 { 1.0 } else { 0.8 }),
            comb(m / 3, &mut Rng(11)),
        ] {
            let (out, outcome, work) = cut(&v, false);
            assert_eq!(out.len(), v.len() - 2);
            assert_eq!(outcome.fan, 0);
            // About 70 (star) and 135 (comb) steps per corner, of 544 allowed.
            assert!(work <= 160 * v.len() as u64, "{work}");
        }
    }

    #[test]
    fn duplicates_and_degenerate_polygons_do_not_panic() {
        let mut t = Triangulator::default();
        let mut out = Vec::new();
        let d = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
        ];
        t.triangulate(&d, &mut out);
        assert!(!out.is_empty());
        out.clear();
        let line = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
        ];
        t.triangulate(&line, &mut out);
        assert_eq!(out.len(), 2);
        // A bow tie (not simple) still terminates with n - 2 triangles.
        out.clear();
        let bow = [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 2.0, 0.0],
        ];
        t.triangulate(&bow, &mut out);
        assert!(out.len() <= 3);
    }
}
