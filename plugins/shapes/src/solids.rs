//! Boxes, infinite cylinders, clipped quadrics and heightfields: custom geometry the plugin
//! intersects itself in `f64` (the host only stores their bounds in its BVH).

use crate::{finite, invalid, positive, sub};
use luxon_plugin::{Aabb, Context, CustomShape, Describe, Error, Geometry, Hit, Primitive, Ray};
use serde::Deserialize;

type V3 = [f64; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn mul(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn at(ray: &Ray, t: f64) -> V3 {
    add(ray.origin, mul(ray.direction, t))
}

/// Unit vector, or `None` for zero; scales first so tiny or huge inputs do not under/overflow.
fn unit(v: V3) -> Option<V3> {
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if m == 0.0 || !m.is_finite() {
        return None;
    }
    let w = mul(v, 1.0 / m);
    Some(mul(w, 1.0 / dot(w, w).sqrt()))
}

/// Two unit vectors completing the unit `w` to a right-handed orthonormal frame (the branchless
/// construction of Duff et al., "Building an orthonormal basis, revisited").
fn frame(w: V3) -> (V3, V3) {
    let sign = 1f64.copysign(w[2]);
    let a = -1.0 / (sign + w[2]);
    let b = w[0] * w[1] * a;
    (
        [1.0 + sign * w[0] * w[0] * a, sign * b, -sign * w[0]],
        [b, sign + w[1] * w[1] * a, -w[1]],
    )
}

/// Rays the shapes can work with: finite origin, finite non-zero direction.
fn usable(ray: &Ray) -> bool {
    ray.origin
        .iter()
        .chain(&ray.direction)
        .all(|x| x.is_finite())
        && ray.direction.iter().any(|&x| x != 0.0)
}

fn in_range(ray: &Ray, t: f64) -> bool {
    ray.tmin < t && t < ray.tmax
}

/// `min` and `max` of a box, finite, with `min < max` on every axis.
fn check_box(min: V3, max: V3) -> Result<(V3, V3), Error> {
    let min = finite("min", min)?;
    let max = finite("max", max)?;
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        if min[k] >= max[k] {
            return Err(invalid(format!(
                "`min` must be smaller than `max` on every axis; on {axis}: min {} >= max {}",
                min[k], max[k]
            )));
        }
    }
    Ok((min, max))
}

/// Where the ray's line is inside the closed box: `(t_enter, enter_axis, t_leave, leave_axis)`.
///
/// A direction component of exactly 0 is not divided by: the ray is then inside that slab for
/// every `t` when its origin lies in the closed interval (a face plane included) and outside for
/// every `t` otherwise, so no NaN (0/0, inf - inf) can arise. Needs a usable ray.
fn slabs(min: V3, max: V3, ray: &Ray) -> Option<(f64, usize, f64, usize)> {
    let (mut t0, mut a0, mut t1, mut a1) = (f64::NEG_INFINITY, 0, f64::INFINITY, 0);
    for k in 0..3 {
        let (o, d) = (ray.origin[k], ray.direction[k]);
        if d == 0.0 {
            if o < min[k] || o > max[k] {
                return None;
            }
            continue;
        }
        let (mut near, mut far) = ((min[k] - o) / d, (max[k] - o) / d);
        if d < 0.0 {
            std::mem::swap(&mut near, &mut far);
        }
        if near > t0 {
            (t0, a0) = (near, k);
        }
        if far < t1 {
            (t1, a1) = (far, k);
        }
    }
    (t0 <= t1).then_some((t0, a0, t1, a1))
}

/// Roots of `a u² + b u + c = 0` in increasing order, by the cancellation-free form
/// `q = -(b + sign(b) √disc) / 2`, `u = q / a`, `u = c / q`. A zero `a` leaves the linear root.
fn quadratic(a: f64, b: f64, c: f64) -> ([f64; 2], usize) {
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 || !disc.is_finite() {
        return ([0.0; 2], 0);
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    if q == 0.0 {
        // b = 0 and disc = 0: with a != 0 also c = 0, a double root at 0.
        return if a != 0.0 {
            ([0.0; 2], 1)
        } else {
            ([0.0; 2], 0)
        };
    }
    let (r1, r2) = (q / a, c / q);
    match (r1.is_finite(), r2.is_finite()) {
        (true, true) => ([r1.min(r2), r1.max(r2)], 2),
        (true, false) => ([r1, 0.0], 1),
        (false, true) => ([r2, 0.0], 1),
        (false, false) => ([0.0; 2], 0),
    }
}

/// Turns as a texture coordinate in [0, 1).
fn turn(angle: f64) -> f32 {
    let u = angle / std::f64::consts::TAU;
    (if u < 0.0 { u + 1.0 } else { u }) as f32
}

fn plain<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    T::deserialize(d).map(Some)
}

// ------------------------------------------------------------------------------------------------
// box
// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct BoxParams {
    pub min: V3,
    pub max: V3,
}

/// A validated axis-aligned box.
#[derive(Clone, Debug)]
pub struct Cuboid {
    min: V3,
    max: V3,
}

impl Cuboid {
    pub fn new(p: &BoxParams) -> Result<Cuboid, Error> {
        let (min, max) = check_box(p.min, p.max)?;
        Ok(Cuboid { min, max })
    }

    fn face_hit(&self, ray: &Ray, t: f64, axis: usize, outward: f64) -> Hit {
        let mut normal = [0.0; 3];
        normal[axis] = outward;
        let p = at(ray, t);
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        let rel = |k: usize| ((p[k] - self.min[k]) / (self.max[k] - self.min[k])).clamp(0.0, 1.0);
        Hit {
            t,
            normal,
            uv: [rel(a) as f32, rel(b) as f32],
        }
    }
}

impl CustomShape for Cuboid {
    fn count(&self) -> u64 {
        1
    }

    fn bounds(&self, _index: u64) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }

    fn intersect(&self, _index: u64, ray: &Ray) -> Option<Hit> {
        if !usable(ray) {
            return None;
        }
        let (t0, a0, t1, a1) = slabs(self.min, self.max, ray)?;
        if in_range(ray, t0) {
            // Entering: the face faces against the ray.
            Some(self.face_hit(ray, t0, a0, -ray.direction[a0].signum()))
        } else if in_range(ray, t1) {
            // From inside: the far face, normal still outward.
            Some(self.face_hit(ray, t1, a1, ray.direction[a1].signum()))
        } else {
            None
        }
    }
}

pub struct BoxEntry;

impl Describe for BoxEntry {
    const NAME: &'static str = "box";
    const DESCRIPTION: &'static str = "An axis-aligned box (Tachyon's box), custom geometry.";
    const PARAMS: &'static str = "min: (x, y, z)  lowest corner
max: (x, y, z)  highest corner, > min on every axis";
}

impl Primitive for BoxEntry {
    type Params = BoxParams;
    fn create(p: BoxParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(Cuboid::new(&p)?)
    }
}

// ------------------------------------------------------------------------------------------------
// infinite_cylinder
// ------------------------------------------------------------------------------------------------

fn default_extent() -> f64 {
    1e6
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct InfiniteCylinderParams {
    pub center: V3,
    pub axis: V3,
    pub radius: f64,
    #[serde(default = "default_extent")]
    pub extent: f64,
}

/// A validated cylinder around a line, cut at `extent` along the axis on both sides.
#[derive(Clone, Debug)]
pub struct LineCylinder {
    center: V3,
    u: V3,
    v: V3,
    w: V3,
    radius: f64,
    extent: f64,
}

impl LineCylinder {
    pub fn new(p: &InfiniteCylinderParams) -> Result<LineCylinder, Error> {
        let center = finite("center", p.center)?;
        let w = unit(finite("axis", p.axis)?)
            .ok_or_else(|| invalid("parameter `axis` has zero length"))?;
        let radius = positive("radius", p.radius)?;
        let extent = positive("extent", p.extent)?;
        let (u, v) = frame(w);
        Ok(LineCylinder {
            center,
            u,
            v,
            w,
            radius,
            extent,
        })
    }
}

impl CustomShape for LineCylinder {
    fn count(&self) -> u64 {
        1
    }

    fn bounds(&self, _index: u64) -> Aabb {
        // Box of the two end discs: along world axis k the axis contributes e |w_k| and a disc
        // of radius r perpendicular to w contributes r √(1 - w_k²).
        let mut min = [0.0; 3];
        let mut max = [0.0; 3];
        for k in 0..3 {
            let half = self.extent * self.w[k].abs()
                + self.radius * (1.0 - self.w[k] * self.w[k]).max(0.0).sqrt();
            min[k] = self.center[k] - half;
            max[k] = self.center[k] + half;
        }
        Aabb { min, max }
    }

    fn intersect(&self, _index: u64, ray: &Ray) -> Option<Hit> {
        if !usable(ray) {
            return None;
        }
        let rel = sub(ray.origin, self.center);
        let d = ray.direction;
        let o = [dot(rel, self.u), dot(rel, self.v), dot(rel, self.w)];
        let d = [dot(d, self.u), dot(d, self.v), dot(d, self.w)];
        let a = d[0] * d[0] + d[1] * d[1];
        if a == 0.0 {
            // Parallel to the axis: never crosses the surface.
            return None;
        }
        let b = 2.0 * (o[0] * d[0] + o[1] * d[1]);
        let c = o[0] * o[0] + o[1] * o[1] - self.radius * self.radius;
        let (roots, n) = quadratic(a, b, c);
        for &t in &roots[..n] {
            if !in_range(ray, t) {
                continue;
            }
            let p = add(o, mul(d, t));
            if p[2].abs() > self.extent {
                continue;
            }
            return Some(Hit {
                t,
                normal: add(mul(self.u, p[0]), mul(self.v, p[1])),
                uv: [
                    turn(p[1].atan2(p[0])),
                    ((p[2] + self.extent) / (2.0 * self.extent)) as f32,
                ],
            });
        }
        None
    }
}

pub struct InfiniteCylinder;

impl Describe for InfiniteCylinder {
    const NAME: &'static str = "infinite_cylinder";
    const DESCRIPTION: &'static str =
        "A cylinder around a line (Tachyon's cylinder), cut far away at `extent`.";
    const PARAMS: &'static str = "center: (x, y, z)  a point on the axis
axis: (x, y, z)  axis direction, any non-zero length
radius: f64 > 0  radius
extent: f64 > 0 = 1e6  half-length kept on each side of `center` (the bounds need an end)";
}

impl Primitive for InfiniteCylinder {
    type Params = InfiniteCylinderParams;
    fn create(p: InfiniteCylinderParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(LineCylinder::new(&p)?)
    }
}

// ------------------------------------------------------------------------------------------------
// quadric
// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct QuadricParams {
    pub coefficients: [f64; 10],
    pub min: V3,
    pub max: V3,
}

/// A validated quadric surface clipped to a box.
#[derive(Clone, Debug)]
pub struct ClippedQuadric {
    /// a..j of `a x² + b y² + c z² + d xy + e xz + f yz + g x + h y + i z + j`.
    k: [f64; 10],
    min: V3,
    max: V3,
}

impl ClippedQuadric {
    pub fn new(p: &QuadricParams) -> Result<ClippedQuadric, Error> {
        let k = finite("coefficients", p.coefficients)?;
        if k[..9].iter().all(|&x| x == 0.0) {
            return Err(invalid(
                "parameter `coefficients`: the first nine (a to i) are all 0, so there is no \
                 surface; give at least one non-zero term in x, y or z",
            ));
        }
        let (min, max) = check_box(p.min, p.max)?;
        Ok(ClippedQuadric { k, min, max })
    }

    fn value(&self, p: V3) -> f64 {
        let [a, b, c, d, e, f, g, h, i, j] = self.k;
        let [x, y, z] = p;
        x * (a * x + d * y + e * z + g) + y * (b * y + f * z + h) + z * (c * z + i) + j
    }

    fn gradient(&self, p: V3) -> V3 {
        let [a, b, c, d, e, f, g, h, i, _] = self.k;
        let [x, y, z] = p;
        [
            2.0 * a * x + d * y + e * z + g,
            2.0 * b * y + d * x + f * z + h,
            2.0 * c * z + e * x + f * y + i,
        ]
    }

    /// The second-order part alone (the quadratic coefficient along a direction).
    fn second_order(&self, v: V3) -> f64 {
        let [a, b, c, d, e, f, ..] = self.k;
        let [x, y, z] = v;
        a * x * x + b * y * y + c * z * z + d * x * y + e * x * z + f * y * z
    }
}

impl CustomShape for ClippedQuadric {
    fn count(&self) -> u64 {
        1
    }

    fn bounds(&self, _index: u64) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }

    fn intersect(&self, _index: u64, ray: &Ray) -> Option<Hit> {
        if !usable(ray) {
            return None;
        }
        let (t0, _, t1, _) = slabs(self.min, self.max, ray)?;
        // Expand around a point on the ray where it enters the box, so the coefficients are
        // computed at box scale even when the ray starts far away: t = t0 + s.
        let base = at(ray, t0);
        let dir = ray.direction;
        let a = self.second_order(dir);
        let b = dot(self.gradient(base), dir);
        let c = self.value(base);
        let (roots, n) = quadratic(a, b, c);
        for &s in &roots[..n] {
            let t = t0 + s;
            // Inside the box is decided on t so a root on a face is not lost to rounding.
            if t < t0 || t > t1 || !in_range(ray, t) {
                continue;
            }
            let g = self.gradient(at(ray, t));
            // At a singular point (a cone's apex) the gradient vanishes: face the ray.
            let normal = if g.iter().all(|&x| x == 0.0) {
                mul(dir, -1.0)
            } else {
                g
            };
            return Some(Hit {
                t,
                normal,
                uv: [0.0; 2],
            });
        }
        None
    }
}

pub struct Quadric;

impl Describe for Quadric {
    const NAME: &'static str = "quadric";
    const DESCRIPTION: &'static str =
        "A general second-order surface (Tachyon's quadric) clipped to a box.";
    const PARAMS: &'static str = "coefficients: (a, b, c, d, e, f, g, h, i, j)  a x² + b y² + c z² + d xy + e xz + f yz + g x + h y + i z + j = 0
min: (x, y, z)  lowest corner of the clipping box
max: (x, y, z)  highest corner, > min on every axis";
}

impl Primitive for Quadric {
    type Params = QuadricParams;
    fn create(p: QuadricParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(ClippedQuadric::new(&p)?)
    }
}

// ------------------------------------------------------------------------------------------------
// heightfield
// ------------------------------------------------------------------------------------------------

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
    #[serde(default, deserialize_with = "plain")]
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
    Some((t, if n[1] < 0.0 { mul(n, -1.0) } else { n }))
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
    use luxon_plugin::parse_params;

    fn ray(origin: V3, direction: V3) -> Ray {
        Ray {
            origin,
            direction,
            tmin: 0.0,
            tmax: f64::INFINITY,
            time: 0.0,
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-9 * (1.0 + b.abs())
    }

    fn close3(a: V3, b: V3) -> bool {
        (0..3).all(|k| close(a[k], b[k]))
    }

    /// Hit `t` and unit normal.
    fn hit<S: CustomShape>(s: &S, r: &Ray) -> Option<(f64, V3)> {
        let h = s.intersect(0, r)?;
        assert!(h.t.is_finite() && h.normal.iter().all(|x| x.is_finite()));
        assert!(s.occluded(0, r));
        Some((h.t, unit(h.normal).expect("zero normal")))
    }

    fn assert_hit<S: CustomShape>(s: &S, r: &Ray, t: f64, n: V3) {
        let (ht, hn) = hit(s, r).expect("expected a hit");
        assert!(close(ht, t), "t {ht} != {t}");
        assert!(close3(hn, n), "normal {hn:?} != {n:?}");
    }

    fn err<T: std::fmt::Debug>(r: Result<T, Error>) -> String {
        r.unwrap_err().message
    }

    // -------------------------------------------------------------------------------- box

    fn unit_box() -> Cuboid {
        Cuboid::new(&parse_params("(min: (-1, -1, -1), max: (1, 1, 1))").unwrap()).unwrap()
    }

    #[test]
    fn box_hits_the_near_face_with_its_normal() {
        let b = unit_box();
        assert_hit(
            &b,
            &ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]),
            4.0,
            [0.0, 0.0, -1.0],
        );
        assert_hit(
            &b,
            &ray([5.0, 0.5, 0.2], [-2.0, 0.0, 0.0]),
            2.0,
            [1.0, 0.0, 0.0],
        );
        assert_hit(
            &b,
            &ray([0.3, 3.0, 0.2], [0.0, -1.0, 0.0]),
            2.0,
            [0.0, 1.0, 0.0],
        );
        // Oblique, through the top face at (0.5, 1, 0).
        assert_hit(
            &b,
            &ray([-0.5, 2.0, 0.0], [1.0, -1.0, 0.0]),
            1.0,
            [0.0, 1.0, 0.0],
        );
        assert_eq!(b.bounds(0).max, [1.0; 3]);
    }

    #[test]
    fn box_from_inside_hits_the_far_face() {
        let b = unit_box();
        assert_hit(&b, &ray([0.0; 3], [0.0, 0.0, 1.0]), 1.0, [0.0, 0.0, 1.0]);
        assert_hit(
            &b,
            &ray([0.5, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            1.5,
            [-1.0, 0.0, 0.0],
        );
    }

    #[test]
    fn box_misses_and_respects_the_ray_interval() {
        let b = unit_box();
        assert!(b
            .intersect(0, &ray([0.0, 2.0, -5.0], [0.0, 0.0, 1.0]))
            .is_none());
        assert!(b
            .intersect(0, &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]))
            .is_none());
        assert!(b
            .intersect(0, &ray([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]))
            .is_none());
        let mut short = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
        short.tmax = 3.9;
        assert!(b.intersect(0, &short).is_none());
        short.tmax = 6.5;
        short.tmin = 4.0; // t = 4 is excluded: the far face is next.
        assert_hit(&b, &short, 6.0, [0.0, 0.0, 1.0]);
    }

    #[test]
    fn box_parallel_rays_give_no_nan() {
        let b = unit_box();
        // Parallel to the x and y faces, inside those slabs.
        assert_hit(
            &b,
            &ray([0.2, -0.3, -5.0], [0.0, 0.0, 1.0]),
            4.0,
            [0.0, 0.0, -1.0],
        );
        // Parallel to the x faces, outside their slab.
        assert!(b
            .intersect(0, &ray([1.5, 0.0, -5.0], [0.0, 0.0, 1.0]))
            .is_none());
        // Exactly in the face plane y = 1: touches the box, enters through x = -1.
        assert_hit(
            &b,
            &ray([-3.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
            2.0,
            [-1.0, 0.0, 0.0],
        );
        // Along an edge (in two face planes at once).
        assert_hit(
            &b,
            &ray([-3.0, 1.0, 1.0], [1.0, 0.0, 0.0]),
            2.0,
            [-1.0, 0.0, 0.0],
        );
        // Tiny direction components do not produce NaN either.
        let h = b
            .intersect(0, &ray([0.0, 0.0, -5.0], [1e-320, -1e-320, 1.0]))
            .unwrap();
        assert!(close(h.t, 4.0));
    }

    #[test]
    fn box_grazing_a_corner_touches() {
        let b = unit_box();
        // The line x + y = 2 in the z = 0 plane touches the corner (1, 1) only.
        let (t, _) = hit(&b, &ray([0.0, 2.0, 0.0], [1.0, -1.0, 0.0])).unwrap();
        assert!(close(t, 1.0));
    }

    #[test]
    fn box_errors() {
        let p: BoxParams = parse_params("(min: (0, 0, 0), max: (1, 0, 1))").unwrap();
        let m = err(Cuboid::new(&p));
        assert!(
            m.contains("smaller than `max`") && m.contains("on y"),
            "{m}"
        );
        let p = BoxParams {
            min: [f64::NAN, 0.0, 0.0],
            max: [1.0; 3],
        };
        assert!(err(Cuboid::new(&p)).contains("`min` must be finite"));
        assert!(parse_params::<BoxParams>("(min: (0, 0, 0))").is_err());
    }

    // -------------------------------------------------------------------------------- infinite_cylinder

    fn z_cylinder(extent: &str) -> LineCylinder {
        let p = format!("(center: (1, 2, 0), axis: (0, 0, 3), radius: 0.5{extent})");
        LineCylinder::new(&parse_params(&p).unwrap()).unwrap()
    }

    #[test]
    fn cylinder_hits_outside_and_inside() {
        let c = z_cylinder("");
        assert_hit(
            &c,
            &ray([5.0, 2.0, 7.0], [-1.0, 0.0, 0.0]),
            3.5,
            [1.0, 0.0, 0.0],
        );
        // From the axis: the wall ahead, normal outward.
        assert_hit(
            &c,
            &ray([1.0, 2.0, 0.0], [0.0, -2.0, 0.0]),
            0.25,
            [0.0, -1.0, 0.0],
        );
        // Oblique: x hits 1.5 at t = 2 (z is irrelevant).
        assert_hit(
            &c,
            &ray([3.5, 2.0, 0.0], [-1.0, 0.0, 4.0]),
            2.0,
            [1.0, 0.0, 0.0],
        );
        let h = c
            .intersect(0, &ray([5.0, 2.0, 0.0], [-1.0, 0.0, 0.0]))
            .unwrap();
        assert!(close(h.uv[0] as f64, 0.0) && close(h.uv[1] as f64, 0.5));
    }

    #[test]
    fn cylinder_tangent_parallel_and_miss() {
        let c = z_cylinder("");
        // Tangent at (1.5, 2, 0): touches once.
        assert_hit(
            &c,
            &ray([1.5, -3.0, 0.0], [0.0, 1.0, 0.0]),
            5.0,
            [1.0, 0.0, 0.0],
        );
        assert!(c
            .intersect(0, &ray([1.6, -3.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
        // Parallel to the axis, inside or outside: no crossing.
        assert!(c
            .intersect(0, &ray([1.0, 2.0, 0.0], [0.0, 0.0, 1.0]))
            .is_none());
        assert!(c
            .intersect(0, &ray([3.0, 2.0, 0.0], [0.0, 0.0, -1.0]))
            .is_none());
        assert!(c
            .intersect(0, &ray([5.0, 2.0, 0.0], [1.0, 0.0, 0.0]))
            .is_none());
    }

    #[test]
    fn cylinder_extent_cuts_and_bounds() {
        let c = z_cylinder(", extent: 2");
        assert!(c
            .intersect(0, &ray([5.0, 2.0, 2.5], [-1.0, 0.0, 0.0]))
            .is_none());
        assert!(c
            .intersect(0, &ray([5.0, 2.0, 1.5], [-1.0, 0.0, 0.0]))
            .is_some());
        let b = c.bounds(0);
        assert!(close3(b.min, [0.5, 1.5, -2.0]) && close3(b.max, [1.5, 2.5, 2.0]));
        // A diagonal axis: the box holds both end discs.
        let d = LineCylinder::new(
            &parse_params("(center: (0, 0, 0), axis: (1, 1, 0), radius: 1, extent: 1)").unwrap(),
        )
        .unwrap();
        let half = 0.5f64.sqrt() + 0.5f64.sqrt();
        let b = d.bounds(0);
        assert!(close3(b.max, [half, half, 1.0]));
        assert!(close3(b.min, [-half, -half, -1.0]));
        // The default keeps the cylinder practically infinite.
        assert!(close(z_cylinder("").bounds(0).max[2], 1e6));
    }

    #[test]
    fn cylinder_errors() {
        let bad = |p: &str| err(LineCylinder::new(&parse_params(p).unwrap()));
        assert!(bad("(center: (0, 0, 0), axis: (0, 0, 0), radius: 1)").contains("zero length"));
        assert!(bad("(center: (0, 0, 0), axis: (0, 1, 0), radius: 0)").contains("`radius`"));
        assert!(
            bad("(center: (0, 0, 0), axis: (0, 1, 0), radius: 1, extent: -1)").contains("`extent`")
        );
    }

    // -------------------------------------------------------------------------------- quadric

    fn quadric(k: &str, min: &str, max: &str) -> ClippedQuadric {
        let p = format!("(coefficients: {k}, min: {min}, max: {max})");
        ClippedQuadric::new(&parse_params(&p).unwrap()).unwrap()
    }

    #[test]
    fn quadric_sphere() {
        let s = quadric(
            "(1, 1, 1, 0, 0, 0, 0, 0, 0, -1)",
            "(-2, -2, -2)",
            "(2, 2, 2)",
        );
        assert_hit(
            &s,
            &ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]),
            4.0,
            [0.0, 0.0, -1.0],
        );
        // Far away: the expansion at the box keeps it accurate.
        assert_hit(
            &s,
            &ray([0.0, 0.0, -1e9], [0.0, 0.0, 1.0]),
            1e9 - 1.0,
            [0.0, 0.0, -1.0],
        );
        // From inside: the far side.
        assert_hit(&s, &ray([0.0; 3], [0.0, 2.0, 0.0]), 0.5, [0.0, 1.0, 0.0]);
        // Tangent at (1, 0, 0).
        assert_hit(
            &s,
            &ray([1.0, -3.0, 0.0], [0.0, 1.0, 0.0]),
            3.0,
            [1.0, 0.0, 0.0],
        );
        assert!(s
            .intersect(0, &ray([1.1, -3.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
        assert!(s
            .intersect(0, &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]))
            .is_none());
    }

    #[test]
    fn quadric_clipping_tries_both_roots() {
        // Upper half of the unit sphere only.
        let s = quadric(
            "(1, 1, 1, 0, 0, 0, 0, 0, 0, -1)",
            "(-2, 0, -2)",
            "(2, 2, 2)",
        );
        // From below: the first root (y = -1) is clipped, the second (y = 1) wins; the normal is
        // the gradient, outward.
        assert_hit(
            &s,
            &ray([0.0, -5.0, 0.0], [0.0, 1.0, 0.0]),
            6.0,
            [0.0, 1.0, 0.0],
        );
        // Both roots clipped.
        let low = quadric(
            "(1, 1, 1, 0, 0, 0, 0, 0, 0, -1)",
            "(-2, -0.5, -2)",
            "(2, 0.5, 2)",
        );
        assert!(low
            .intersect(0, &ray([0.0, -5.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
        // A ray missing the box entirely.
        assert!(s
            .intersect(0, &ray([5.0, -5.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
    }

    #[test]
    fn quadric_cylinder() {
        // x² + y² = 1 for |z| <= 1.
        let c = quadric(
            "(1, 1, 0, 0, 0, 0, 0, 0, 0, -1)",
            "(-2, -2, -1)",
            "(2, 2, 1)",
        );
        assert_hit(
            &c,
            &ray([3.0, 0.0, 0.5], [-1.0, 0.0, 0.0]),
            2.0,
            [1.0, 0.0, 0.0],
        );
        // Along the axis: A = 0 and the equation has no root.
        assert!(c
            .intersect(0, &ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]))
            .is_none());
        // Beyond the clipped end.
        assert!(c
            .intersect(0, &ray([3.0, 0.0, 1.5], [-1.0, 0.0, 0.0]))
            .is_none());
        // From inside.
        assert_hit(&c, &ray([0.0; 3], [0.0, -1.0, 0.0]), 1.0, [0.0, -1.0, 0.0]);
    }

    #[test]
    fn quadric_paraboloid() {
        // y = x² + z²: x² + z² - y = 0; a vertical ray meets it once (linear case).
        let p = quadric(
            "(1, 0, 1, 0, 0, 0, 0, -1, 0, 0)",
            "(-2, -1, -2)",
            "(2, 4, 2)",
        );
        let n = unit([2.0, -1.0, 0.0]).unwrap();
        assert_hit(&p, &ray([1.0, 10.0, 0.0], [0.0, -1.0, 0.0]), 9.0, n);
        // Its inside is y > x² + z²: from the vertex region upward nothing is hit before the
        // box top; a horizontal ray at y = 1 hits x = -1 first.
        assert_hit(
            &p,
            &ray([-3.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
            2.0,
            unit([-2.0, -1.0, 0.0]).unwrap(),
        );
        assert!(p
            .intersect(0, &ray([0.0, 1.0, 0.0], [0.0, 1.0, 0.0]))
            .is_none());
    }

    #[test]
    fn quadric_hyperboloid_clipped() {
        // One sheet: x² + y² - z² = 1, for |z| <= 1 (waist radius 1, rim radius √2).
        let h = quadric(
            "(1, 1, -1, 0, 0, 0, 0, 0, 0, -1)",
            "(-3, -3, -1)",
            "(3, 3, 1)",
        );
        // At the waist.
        assert_hit(
            &h,
            &ray([5.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            4.0,
            [1.0, 0.0, 0.0],
        );
        // At z = 1 the radius is √2; the gradient (2x, 0, -2z) there is (2√2, 0, -2).
        let r2 = 2f64.sqrt();
        let n = unit([2.0 * r2, 0.0, -2.0]).unwrap();
        assert_hit(&h, &ray([5.0, 0.0, 1.0], [-1.0, 0.0, 0.0]), 5.0 - r2, n);
        // Along the axis it never meets the surface; past the clip neither.
        assert!(h
            .intersect(0, &ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]))
            .is_none());
        assert!(h
            .intersect(0, &ray([5.0, 0.0, 1.5], [-1.0, 0.0, 0.0]))
            .is_none());
        // A ray along an asymptote direction (A = 0): x = 1 + s, z = s hits where
        // (1+s)² - s² = 1, s = 0, i.e. the linear root.
        assert_hit(
            &h,
            &ray([0.5, 0.0, -0.5], [1.0, 0.0, 1.0]),
            0.5,
            [1.0, 0.0, 0.0],
        );
    }

    #[test]
    fn quadric_errors() {
        let bad = |p: &str| err(ClippedQuadric::new(&parse_params(p).unwrap()));
        let m =
            bad("(coefficients: (0, 0, 0, 0, 0, 0, 0, 0, 0, 1), min: (0, 0, 0), max: (1, 1, 1))");
        assert!(m.contains("no surface"), "{m}");
        let m =
            bad("(coefficients: (1, 1, 1, 0, 0, 0, 0, 0, 0, 1), min: (0, 0, 0), max: (1, 1, -1))");
        assert!(m.contains("on z"), "{m}");
        assert!(parse_params::<QuadricParams>(
            "(coefficients: (1, 1, 1), min: (0, 0, 0), max: (1, 1, 1))"
        )
        .is_err());
    }

    // -------------------------------------------------------------------------------- heightfield

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
        let n = unit([0.0, 1.0, -1.0]).unwrap();
        assert_hit(&g, &ray([0.75, 3.0, 0.25], [0.0, -1.0, 0.0]), 2.75, n);
        // The other triangle (0,0)-(1,1)-(0,1) holds (0.25, 0.75): plane y = x.
        let n = unit([-1.0, 1.0, 0.0]).unwrap();
        assert_hit(&g, &ray([0.25, 3.0, 0.75], [0.0, -1.0, 0.0]), 2.75, n);
        // From below the surface upward (a "from inside" ray): hits the underside.
        assert_hit(
            &g,
            &ray([0.25, -1.0, 0.75], [0.0, 1.0, 0.0]),
            1.25,
            unit([-1.0, 1.0, 0.0]).unwrap(),
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
