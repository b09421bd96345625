//! Volume ray casting (Stone 1998, ch. IV; Levoy 1988): along a ray, samples every `step` world
//! units are classified by a transfer function into a colour and an extinction (opacity per
//! unit length) and composited front to back, each sample covering its segment of the ray:
//! `alpha = 1 - exp(-sigma * dt)`, `C += T * alpha * colour`, `T *= 1 - alpha`. Marching stops at
//! the first surface (Sobierajski and Kaufman's volumetric ray tracing: the surface is shaded
//! and composited behind what the volume let through) and early when `T` falls below the ray's
//! cut-off. Overlapping volumes are sampled at the same points: extinctions add and colours mix
//! in proportion to them.
//!
//! Empty-space skipping: for each 8³ cell of index space the largest extinction the transfer
//! function gives over the values any sample in the cell can interpolate (the cell's brick and
//! the next one on each axis, a conservative bound) is precomputed; a sample in a cell whose
//! bound is 0 jumps to the first sample past the cell. Skipped samples would have added exactly
//! nothing, so images are bitwise identical with skipping on or off.

use crate::geometry::Clips;
use crate::math::{DVec3, Vec3A};
use crate::ray::Ray;
use crate::volume::{Brick, Volume, BRICK_SIZE, BRICK_VOXELS};
use luxon_formats::{Interpolation, VolumeRenderDesc};

/// The most rendered volumes a scene may have (a ray keeps them on the stack).
pub const MAX_RENDERED_VOLUMES: usize = 16;

/// A piecewise-linear transfer function over the window `[lo, lo + 1 / inv)`.
#[derive(Clone, Debug)]
pub struct Transfer {
    xs: Vec<f32>,
    /// Colour (linear RGB) and extinction at each point.
    rgba: Vec<[f32; 4]>,
    lo: f32,
    inv: f32,
}

impl Transfer {
    /// `points`: (x in [0, 1], increasing; colour; extinction); the window maps `range` to
    /// [0, 1].
    pub fn new(points: &[(f32, [f32; 3], f32)], range: (f32, f32)) -> Transfer {
        let width = range.1 - range.0;
        Transfer {
            xs: points.iter().map(|p| p.0).collect(),
            rgba: points
                .iter()
                .map(|p| [p.1[0], p.1[1], p.1[2], p.2])
                .collect(),
            lo: range.0,
            inv: if width > 0.0 { 1.0 / width } else { 0.0 },
        }
    }

    #[inline]
    fn x_of(&self, s: f32) -> f32 {
        ((s - self.lo) * self.inv).clamp(0.0, 1.0)
    }

    /// Colour and extinction at window position `x` (constant beyond the end points).
    #[inline]
    fn at_x(&self, x: f32) -> [f32; 4] {
        let n = self.xs.len();
        if x <= self.xs[0] {
            return self.rgba[0];
        }
        for i in 1..n {
            if x <= self.xs[i] {
                let (x0, x1) = (self.xs[i - 1], self.xs[i]);
                let f = (x - x0) / (x1 - x0);
                let (a, b) = (self.rgba[i - 1], self.rgba[i]);
                // A plain loop: `[0, 1, 2, 3].map` was left uninlined in some builds (7 % more
                // instructions per volume sample).
                let mut out = a;
                for (o, y) in out.iter_mut().zip(b) {
                    *o += (y - *o) * f;
                }
                return out;
            }
        }
        self.rgba[n - 1]
    }

    /// Colour and extinction of scalar `s`.
    #[inline]
    pub fn eval(&self, s: f32) -> [f32; 4] {
        self.at_x(self.x_of(s))
    }

    /// The largest extinction over scalars in `[s0, s1]` (exact: a piecewise-linear function
    /// peaks at an end or a control point).
    pub fn max_extinction(&self, s0: f32, s1: f32) -> f32 {
        let (x0, x1) = (self.x_of(s0), self.x_of(s1));
        let mut m = self.at_x(x0)[3].max(self.at_x(x1)[3]);
        for (x, c) in self.xs.iter().zip(&self.rgba) {
            if *x > x0 && *x < x1 {
                m = m.max(c[3]);
            }
        }
        m
    }
}

/// Gradient shading coefficients.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shading {
    pub(crate) ambient: f32,
    pub(crate) diffuse: f32,
    pub(crate) specular: f32,
    pub(crate) shininess: f32,
    pub(crate) shadows: bool,
}

/// A volume prepared for ray casting (render space, index-space transform, skipping cells).
#[derive(Clone, Debug)]
pub struct RenderVolume {
    /// Index into `Scene::volumes`.
    pub volume: usize,
    pub transfer: Transfer,
    /// World units between samples (after the render setting's multiplier).
    pub step: f32,
    nearest: bool,
    pub(crate) shading: Option<Shading>,
    /// Clip group (0: none).
    clip: u32,
    /// Crop box in render space.
    crop: Option<(Vec3A, Vec3A)>,
    /// index = rows · p + offset, for a render-space point p.
    rows: [Vec3A; 3],
    offset: Vec3A,
    /// Voxel-centre box (samples are clamped into it) and the volume's box, half a voxel
    /// wider, in index space.
    lo: Vec3A,
    hi: Vec3A,
    index_min: [i64; 3],
    index_max: [i64; 3],
    /// Largest extinction per skipping cell; cells cover index space `[8k, 8k + 8)`.
    cells: Vec<f32>,
    cell_min: [i64; 3],
    cell_dims: [i64; 3],
    /// The same as floats when every cell coordinate and table index is a whole f32 below
    /// 2^21 (then `cell_at` works in f32, exactly).
    cells_f32: Option<(Vec3A, Vec3A)>,
    /// Colour and extinction of every u8 code (the transfer function at its value), so that
    /// nearest-voxel samples of u8 bricks need no search.
    u8_rgba: Box<[[f32; 4]; 256]>,
    /// Nearest-voxel samples, every index of the box of a magnitude below 2^22: samples then
    /// find their voxel in f32 ([`Self::classify`]).
    nearest_small: bool,
}

/// What a ray's samples of one volume keep from one sample to the next: the brick they last
/// read (nearest-voxel samples only).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Reader<'a> {
    /// Brick coordinates, offset by a constant (`u32::MAX`: none read yet; no brick has it).
    key: [u32; 3],
    voxels: Voxels<'a>,
}

impl Default for Reader<'_> {
    fn default() -> Self {
        Reader {
            key: [u32::MAX; 3],
            voxels: Voxels::Rgba([0.0; 4]),
        }
    }
}

/// A brick as nearest-voxel samples read it.
#[derive(Clone, Copy, Debug)]
enum Voxels<'a> {
    /// Every voxel classifies as this (a constant brick, or none: the background).
    Rgba([f32; 4]),
    /// Codes classified through `RenderVolume::u8_rgba`.
    U8(&'a [u8; BRICK_VOXELS]),
    /// Values classified one by one.
    Values(&'a Brick),
}

/// A volume a ray crosses: its index-space ray and parameter interval.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Crossing {
    pub(crate) o: Vec3A,
    pub(crate) d: Vec3A,
    pub(crate) t0: f32,
    pub(crate) t1: f32,
}

impl RenderVolume {
    /// Prepares volume `index` of the scene for drawing with `desc`; `step_scale` is the render
    /// setting `volume_step`, `clip` the clip group (0: none).
    pub fn new(
        desc: &VolumeRenderDesc,
        volume: &Volume,
        index: usize,
        step_scale: f64,
        world_offset: DVec3,
        clip: u32,
    ) -> Result<RenderVolume, String> {
        let m = &volume.world_from_index;
        let col = |c: usize| DVec3::new(m[c], m[4 + c], m[8 + c]);
        let (c0, c1, c2) = (col(0), col(1), col(2));
        let det = c0.dot(c1.cross(c2));
        // Inverse of the 3x3 part: rows are the cross products of its columns over det.
        let inv = [c1.cross(c2) / det, c2.cross(c0) / det, c0.cross(c1) / det];
        let t = DVec3::new(m[3], m[7], m[11]);
        // index = inv · (p + world_offset - t)
        let shift = world_offset - t;
        let rows = inv.map(|r| Vec3A::from(r.as_vec3()));
        let offset = Vec3A::new(
            inv[0].dot(shift) as f32,
            inv[1].dot(shift) as f32,
            inv[2].dot(shift) as f32,
        );
        let smallest = c0.length().min(c1.length()).min(c2.length());
        let step = desc.step.unwrap_or(0.5 * smallest) * step_scale;
        if !(step > 0.0 && step.is_finite()) {
            return Err(format!("volume step {step} is not a positive number"));
        }
        let (vmin, vmax) = volume.min_max();
        let range = desc
            .transfer
            .range
            .map_or((vmin, vmax), |r| (r[0] as f32, r[1] as f32));
        let points: Vec<(f32, [f32; 3], f32)> = desc
            .transfer
            .points
            .iter()
            .map(|p| {
                (
                    p.x as f32,
                    p.color.map(|c| c as f32),
                    (p.opacity * desc.transfer.opacity) as f32,
                )
            })
            .collect();
        let transfer = Transfer::new(&points, range);
        let f = |a: [i64; 3]| Vec3A::new(a[0] as f32, a[1] as f32, a[2] as f32);
        let crop = desc.bounds.map(|(lo, hi)| {
            let r = |p: [f64; 3]| Vec3A::from((DVec3::from(p) - world_offset).as_vec3());
            (r(lo), r(hi))
        });
        let mut rv = RenderVolume {
            volume: index,
            transfer,
            step: step as f32,
            nearest: desc.interpolation == Interpolation::Nearest,
            shading: desc.shading.map(|s| Shading {
                ambient: s.ambient as f32,
                diffuse: s.diffuse as f32,
                specular: s.specular as f32,
                shininess: s.shininess as f32,
                shadows: s.shadows,
            }),
            clip,
            crop,
            rows,
            offset,
            lo: f(volume.index_min),
            hi: f(volume.index_max),
            index_min: volume.index_min,
            index_max: volume.index_max,
            cells: Vec::new(),
            cell_min: [0; 3],
            cell_dims: [0; 3],
            cells_f32: None,
            u8_rgba: Box::new([[0.0; 4]; 256]),
            nearest_small: desc.interpolation == Interpolation::Nearest
                && (0..3).all(|a| {
                    let limit = 1 << 22;
                    volume.index_min[a] > -limit && volume.index_max[a] < limit
                }),
        };
        let codes = volume.codes();
        *rv.u8_rgba = std::array::from_fn(|c| rv.transfer.eval(codes.u8(c as u8)));
        rv.build_cells(volume);
        Ok(rv)
    }

    /// The skipping table: per cell, the transfer function's largest extinction over the value
    /// range of the cell's brick and its successors on each axis.
    fn build_cells(&mut self, volume: &Volume) {
        let shift = BRICK_SIZE.trailing_zeros();
        let kmin = self.index_min.map(|c| (c - 1) >> shift);
        let kmax = self.index_max.map(|c| (c + 1) >> shift);
        let dims = [0, 1, 2].map(|a| kmax[a] - kmin[a] + 1);
        // Cells beyond a few million would cost more than they save: no skipping then.
        if dims.iter().product::<i64>() > 1 << 22 {
            return;
        }
        // Value range of every brick in kmin ..= kmax + 1.
        let bd = dims.map(|d| d + 1);
        let mut ranges = Vec::with_capacity((bd[0] * bd[1] * bd[2]) as usize);
        for z in 0..bd[2] {
            for y in 0..bd[1] {
                for x in 0..bd[0] {
                    let key = [kmin[0] + x, kmin[1] + y, kmin[2] + z];
                    ranges.push(match volume.brick(key) {
                        None => (volume.background, volume.background),
                        Some(b) => b.range(volume.codes()),
                    });
                }
            }
        }
        let mut cells = Vec::with_capacity((dims[0] * dims[1] * dims[2]) as usize);
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let (mut a, mut b) = (f32::INFINITY, f32::NEG_INFINITY);
                    for dz in 0..2 {
                        for dy in 0..2 {
                            for dx in 0..2 {
                                let i = ((z + dz) * bd[1] + y + dy) * bd[0] + x + dx;
                                let r = ranges[i as usize];
                                a = a.min(r.0);
                                b = b.max(r.1);
                            }
                        }
                    }
                    // Widened a little: interpolation rounds.
                    let pad = 1e-5 * (b - a).abs().max(a.abs()).max(b.abs()).max(1e-30);
                    cells.push(self.transfer.max_extinction(a - pad, b + pad));
                }
            }
        }
        self.cells = cells;
        self.cell_min = kmin;
        self.cell_dims = dims;
        let limit = 1 << 21;
        if (0..3).all(|a| kmin[a].abs() < limit && (kmin[a] + dims[a]).abs() < limit)
            && (self.cells.len() as i64) < limit
        {
            let f = |a: [i64; 3]| Vec3A::new(a[0] as f32, a[1] as f32, a[2] as f32);
            self.cells_f32 = Some((f(kmin), f(dims)));
        }
    }

    #[inline]
    fn to_index(&self, p: Vec3A) -> Vec3A {
        Vec3A::new(
            self.rows[0].dot(p),
            self.rows[1].dot(p),
            self.rows[2].dot(p),
        ) + self.offset
    }

    #[inline]
    fn dir_to_index(&self, d: Vec3A) -> Vec3A {
        Vec3A::new(
            self.rows[0].dot(d),
            self.rows[1].dot(d),
            self.rows[2].dot(d),
        )
    }

    /// Where `ray` is inside the volume (its box, crop box and clip group) within `[0, t_end)`.
    #[inline]
    pub(crate) fn crossing(&self, ray: &Ray, t_end: f32, clips: &Clips) -> Option<Crossing> {
        let o = self.to_index(ray.origin);
        let d = self.dir_to_index(ray.dir);
        let (mut t0, mut t1) = (0.0f32, t_end);
        slab(
            o,
            d,
            self.lo - Vec3A::splat(0.5),
            self.hi + Vec3A::splat(0.5),
            &mut t0,
            &mut t1,
        );
        if let Some((lo, hi)) = self.crop {
            slab(ray.origin, ray.dir, lo, hi, &mut t0, &mut t1);
        }
        if self.clip != 0 {
            // Kept: every plane's negative side (a clip group cuts what any plane points to).
            for (q, n) in &clips.groups[self.clip as usize - 1] {
                let dn = ray.dir.dot(*n);
                let s = (*q - ray.origin).dot(*n);
                if dn > 0.0 {
                    t1 = t1.min(s / dn);
                } else if dn < 0.0 {
                    t0 = t0.max(s / dn);
                } else if s < 0.0 {
                    return None;
                }
            }
        }
        (t0 < t1).then_some(Crossing { o, d, t0, t1 })
    }

    /// The scalar at index-space point `p` (clamped into the voxel-centre box).
    #[inline]
    pub(crate) fn sample(&self, vol: &Volume, p: Vec3A) -> f32 {
        let p = p.clamp(self.lo, self.hi);
        if self.nearest {
            let q = (p + Vec3A::splat(0.5)).floor();
            let ijk = [q.x as i64, q.y as i64, q.z as i64];
            let ijk = [0, 1, 2].map(|a| ijk[a].min(self.index_max[a]));
            return vol.value(ijk);
        }
        let f0 = p.floor();
        let f = p - f0;
        let i0 = [f0.x as i64, f0.y as i64, f0.z as i64];
        let i1 = [0, 1, 2].map(|a| (i0[a] + 1).min(self.index_max[a]));
        let shift = BRICK_SIZE.trailing_zeros();
        let key = i0.map(|c| c >> shift);
        let mut c = [0.0f32; 8];
        if (0..3).all(|a| i1[a] >> shift == key[a]) {
            // The common case: all eight voxels in one brick, one lookup.
            let m = BRICK_SIZE - 1;
            let at = |k: usize| {
                let x = if k & 1 == 0 { i0[0] } else { i1[0] };
                let y = if k & 2 == 0 { i0[1] } else { i1[1] };
                let z = if k & 4 == 0 { i0[2] } else { i1[2] };
                ((x & m) + ((y & m) << shift) + ((z & m) << (2 * shift))) as usize
            };
            // One match per sample, then a loop over the corners in the brick's format.
            match vol.brick(key) {
                None => return vol.background,
                Some(Brick::Constant(v)) => return *v,
                Some(Brick::F32(values)) => {
                    for (k, v) in c.iter_mut().enumerate() {
                        *v = values[at(k)];
                    }
                }
                Some(Brick::U8(values)) => {
                    let codes = vol.codes();
                    for (k, v) in c.iter_mut().enumerate() {
                        *v = codes.u8(values[at(k)]);
                    }
                }
                Some(Brick::U16(values)) => {
                    let codes = vol.codes();
                    for (k, v) in c.iter_mut().enumerate() {
                        *v = codes.u16(values[at(k)]);
                    }
                }
            }
        } else {
            for (k, v) in c.iter_mut().enumerate() {
                let x = if k & 1 == 0 { i0[0] } else { i1[0] };
                let y = if k & 2 == 0 { i0[1] } else { i1[1] };
                let z = if k & 4 == 0 { i0[2] } else { i1[2] };
                *v = vol.value([x, y, z]);
            }
        }
        let lx = |a: f32, b: f32| a + (b - a) * f.x;
        let (c00, c10) = (lx(c[0], c[1]), lx(c[2], c[3]));
        let (c01, c11) = (lx(c[4], c[5]), lx(c[6], c[7]));
        let ly = |a: f32, b: f32| a + (b - a) * f.y;
        let (a, b) = (ly(c00, c10), ly(c01, c11));
        a + (b - a) * f.z
    }

    /// Colour and extinction of the sample at index-space point `p`: the transfer function at
    /// [`Self::sample`]'s value, the same bits; nearest-voxel samples read through `reader`.
    #[inline(always)]
    pub(crate) fn classify<'a>(
        &self,
        vol: &'a Volume,
        p: Vec3A,
        reader: &mut Reader<'a>,
    ) -> [f32; 4] {
        if !self.nearest_small {
            return self.transfer.eval(self.sample(vol, p));
        }
        // The voxel `sample` picks. Every index here is a whole number of magnitude below 2^22,
        // so each step is exact (the integer arithmetic's result), and the index plus
        // 1.5 · 2^23 is an f32 whose low 23 bits are the index plus 2^22 (ulp 1 there): those
        // bits give the brick (above the low 3, offset by a constant) and the voxel in it.
        let p = p.clamp(self.lo, self.hi);
        let q = floor(p + Vec3A::splat(0.5)).min(self.hi);
        let bits = (q + Vec3A::splat(12_582_912.0))
            .to_array()
            .map(f32::to_bits);
        let key = bits.map(|b| b >> 3);
        if key != reader.key {
            reader.key = key;
            let brick = bits.map(|b| (i64::from(b & 0x7f_ffff) - (1 << 22)) >> 3);
            reader.voxels = match vol.brick(brick) {
                None => Voxels::Rgba(self.transfer.eval(vol.background)),
                Some(Brick::Constant(v)) => Voxels::Rgba(self.transfer.eval(*v)),
                Some(Brick::U8(codes)) => Voxels::U8(codes),
                Some(b) => Voxels::Values(b),
            };
        }
        let at = || (bits[0] & 7 | (bits[1] & 7) << 3 | (bits[2] & 7) << 6) as usize;
        match reader.voxels {
            Voxels::Rgba(rgba) => rgba,
            Voxels::U8(codes) => self.u8_rgba[usize::from(codes[at()])],
            Voxels::Values(b) => self.transfer.eval(b.value(at(), vol.codes())),
        }
    }

    /// Render-space gradient of the field at index-space point `p` (central differences one
    /// voxel apart).
    #[inline]
    pub(crate) fn gradient(&self, vol: &Volume, p: Vec3A) -> Vec3A {
        let g = Vec3A::new(
            self.sample(vol, p + Vec3A::X) - self.sample(vol, p - Vec3A::X),
            self.sample(vol, p + Vec3A::Y) - self.sample(vol, p - Vec3A::Y),
            self.sample(vol, p + Vec3A::Z) - self.sample(vol, p - Vec3A::Z),
        ) * 0.5;
        // d s / d p = (d index / d p)^T · (d s / d index).
        self.rows[0] * g.x + self.rows[1] * g.y + self.rows[2] * g.z
    }

    /// Whether the volume has a skipping table (without one nothing is skipped).
    #[inline]
    pub(crate) fn has_cells(&self) -> bool {
        !self.cells.is_empty()
    }

    /// The skipping cell of index-space point `p`, as whole-valued floats (`cell_at` takes
    /// them).
    #[inline]
    pub(crate) fn cell_key(p: Vec3A) -> Vec3A {
        floor(p * (1.0 / BRICK_SIZE as f32))
    }

    /// Cell `key`'s largest extinction and the ray parameter where the index-space ray `c`
    /// leaves it; `None` when the cell is outside the table (never skipped).
    #[inline]
    pub(crate) fn cell_at(&self, c: &Crossing, key: Vec3A) -> Option<(f32, f32)> {
        if self.cells.is_empty() {
            return None;
        }
        let size = BRICK_SIZE as f32;
        if let Some((min, dims)) = self.cells_f32 {
            // As below, in f32: every whole number here is exact.
            let r = key - min;
            if !(r.cmpge(Vec3A::ZERO) & r.cmplt(dims)).all() {
                return None;
            }
            let max = self.cells[((r.z * dims.y + r.y) * dims.x + r.x) as usize];
            let face = key + Vec3A::select(c.d.cmpgt(Vec3A::ZERO), Vec3A::ONE, Vec3A::ZERO);
            let t = (face * size - c.o) / c.d;
            let exit = Vec3A::select(c.d.cmpne(Vec3A::ZERO), t, Vec3A::INFINITY).min_element();
            return Some((max, exit));
        }
        let k = [key.x as i64, key.y as i64, key.z as i64];
        let r = [0, 1, 2].map(|a| k[a] - self.cell_min[a]);
        if (0..3).any(|a| r[a] < 0 || r[a] >= self.cell_dims[a]) {
            return None;
        }
        let d = self.cell_dims;
        let max = self.cells[((r[2] * d[1] + r[1]) * d[0] + r[0]) as usize];
        let mut exit = f32::INFINITY;
        for (a, &ka) in k.iter().enumerate() {
            let (o, dir) = (c.o[a], c.d[a]);
            if dir > 0.0 {
                exit = exit.min(((ka + 1) as f32 * size - o) / dir);
            } else if dir < 0.0 {
                exit = exit.min((ka as f32 * size - o) / dir);
            }
        }
        Some((max, exit))
    }
}

/// `v.floor()` lane by lane in one instruction each (glam's emulates it for SSE2), except that
/// `-0.0` stays `-0.0`: the same whole numbers wherever it is used.
#[inline(always)]
fn floor(v: Vec3A) -> Vec3A {
    Vec3A::new(v.x.floor(), v.y.floor(), v.z.floor())
}

/// Narrows `[t0, t1]` to where `o + t d` is inside the box `[lo, hi]`.
fn slab(o: Vec3A, d: Vec3A, lo: Vec3A, hi: Vec3A, t0: &mut f32, t1: &mut f32) {
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < lo[a] || o[a] > hi[a] {
                *t1 = f32::NEG_INFINITY;
            }
            continue;
        }
        let inv = 1.0 / d[a];
        let (mut n, mut f) = ((lo[a] - o[a]) * inv, (hi[a] - o[a]) * inv);
        if n > f {
            std::mem::swap(&mut n, &mut f);
        }
        *t0 = t0.max(n);
        *t1 = t1.min(f);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transfer_interpolates_and_bounds_exactly() {
        let t = Transfer::new(
            &[
                (0.0, [0.0; 3], 0.0),
                (0.5, [1.0, 0.5, 0.0], 4.0),
                (1.0, [1.0; 3], 1.0),
            ],
            (10.0, 20.0),
        );
        assert_eq!(t.eval(10.0), [0.0, 0.0, 0.0, 0.0]);
        assert_eq!(t.eval(12.5), [0.5, 0.25, 0.0, 2.0]);
        assert_eq!(t.eval(15.0)[3], 4.0);
        assert_eq!(t.eval(-100.0)[3], 0.0);
        assert_eq!(t.eval(100.0)[3], 1.0);
        // The peak inside the interval counts; an interval on the zero end does not.
        assert_eq!(t.max_extinction(11.0, 19.0), 4.0);
        assert_eq!(t.max_extinction(0.0, 10.0), 0.0);
        assert_eq!(t.max_extinction(17.5, 20.0), 2.5);
    }

    /// A volume over index box [-13, -5, -9] to [20, 14, 11] with u8 and f32 blocks, a
    /// constant tile and background elsewhere, drawn with `interpolation`.
    fn mixed(interpolation: Interpolation) -> (Volume, RenderVolume) {
        let mut b = crate::volume::VolumeBuilder::new("v", "test");
        let identity = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0.];
        b.begin(identity, 0.25, [-13, -5, -9], [20, 14, 11], "grid")
            .unwrap();
        let bytes: Vec<u8> = (0..17 * 9 * 10).map(|i| (i * 37 % 256) as u8).collect();
        b.add_dense_u8([-13, -5, -9], [17, 9, 10], &bytes, 255.0)
            .unwrap();
        let floats: Vec<f32> = (0..9 * 11 * 12).map(|i| (i % 23) as f32 / 22.0).collect();
        b.add_dense([5, 0, 0], [9, 11, 12], &floats).unwrap();
        b.add_tile([-8, 8, 0], [8, 6, 8], 0.75).unwrap();
        let vol = b.finish().unwrap();
        let point = |x: f64, opacity: f64| luxon_formats::TransferPoint {
            x,
            color: [x, 1.0 - x, 0.5],
            opacity,
        };
        let desc = VolumeRenderDesc {
            transfer: luxon_formats::TransferDesc {
                preset: None,
                points: vec![
                    point(0.0, 0.0),
                    point(0.3, 2.0),
                    point(0.7, 0.5),
                    point(1.0, 3.0),
                ],
                range: Some([0.0, 1.0]),
                opacity: 1.0,
            },
            step: None,
            interpolation,
            shading: None,
            clip: None,
            bounds: None,
        };
        let rv = RenderVolume::new(&desc, &vol, 0, 1.0, DVec3::ZERO, 0).unwrap();
        (vol, rv)
    }

    /// Points along lines through (and past) the box, as a ray's samples come.
    fn walks() -> Vec<Vec3A> {
        let mut seed = 12345u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        let mut out = Vec::new();
        for _ in 0..200 {
            let o = Vec3A::new(next(), next(), next()) * 50.0 - Vec3A::splat(20.0);
            let d = (Vec3A::new(next(), next(), next()) - Vec3A::splat(0.5)) * 1.5;
            out.extend((0..60).map(|i| o + i as f32 * d));
        }
        out
    }

    #[test]
    fn classify_gives_the_transfer_function_of_the_sample() {
        for interpolation in [Interpolation::Nearest, Interpolation::Trilinear] {
            let (vol, rv) = mixed(interpolation);
            assert_eq!(rv.nearest_small, interpolation == Interpolation::Nearest);
            let mut reader = Reader::default();
            for p in walks() {
                let want = rv.transfer.eval(rv.sample(&vol, p)).map(f32::to_bits);
                let got = rv.classify(&vol, p, &mut reader).map(f32::to_bits);
                assert_eq!(got, want, "{p}");
            }
        }
    }

    #[test]
    fn cells_in_f32_are_the_integer_cells() {
        let (_, rv) = mixed(Interpolation::Nearest);
        assert!(rv.cells_f32.is_some() && rv.has_cells());
        let mut wide = rv.clone();
        wide.cells_f32 = None;
        let points = walks();
        let mut some = 0;
        for w in points.chunks(60) {
            let c = Crossing {
                o: w[0],
                d: w[1] - w[0],
                t0: 0.0,
                t1: 60.0,
            };
            for (i, p) in w.iter().enumerate() {
                for p in [*p, c.o + (i as f32 + 0.5) * c.d] {
                    let key = RenderVolume::cell_key(p);
                    let got = rv.cell_at(&c, key);
                    assert_eq!(got, wide.cell_at(&c, key), "{p}");
                    some += usize::from(got.is_some());
                }
            }
        }
        assert!(some > 1000, "{some}");
    }

    #[test]
    fn slab_clips_to_the_box() {
        let (mut t0, mut t1) = (0.0, f32::INFINITY);
        slab(
            Vec3A::new(-5.0, 0.5, 0.5),
            Vec3A::X,
            Vec3A::ZERO,
            Vec3A::ONE,
            &mut t0,
            &mut t1,
        );
        assert_eq!((t0, t1), (5.0, 6.0));
        let (mut t0, mut t1) = (0.0, f32::INFINITY);
        slab(
            Vec3A::new(-5.0, 2.0, 0.5),
            Vec3A::X,
            Vec3A::ZERO,
            Vec3A::ONE,
            &mut t0,
            &mut t1,
        );
        assert!(t0 >= t1);
    }
}
