//! Building a [`Volume`] from what a reader sends: every check, and the cutting of blocks and
//! tiles into bricks (see the parent module for the rules).

use super::brick;
use super::charge::Charger;
use super::{local_index, Brick, BrickMap, Codes, Volume, BRICK_SHIFT, BRICK_SIZE, BRICK_VOXELS};
use super::{MAX_TABLE, MAX_VOXELS};
use crate::budget::Budget;
use std::sync::Arc;

/// Collects what a reader sends and checks it (the host side of `VolumeSink`).
pub struct VolumeBuilder {
    name: String,
    plugin: String,
    volume: Option<Volume>,
    /// Which voxels were given, for bricks that are only partly given so far (bit `i` of the
    /// 512-bit mask is voxel `i` of the brick). A stored brick without a mask is complete.
    partial: BrickMap<[u64; 8]>,
    /// Complete bricks of background voxels, which are not stored (`Given` remembers them so
    /// that a voxel given twice is still an error).
    skipped: Given,
    /// The first error; it stops the volume.
    failed: Option<String>,
    /// The divisor of each typed format's blocks, once one came (by `Format`).
    divisors: [Option<f32>; 3],
    /// The memory budget's account of what the volume stores.
    charger: Charger,
}

/// The voxel formats of typed dense blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    U8 = 0,
    U16 = 1,
    F32 = 2,
}

impl Format {
    fn name(self) -> &'static str {
        match self {
            Format::U8 => "u8",
            Format::U16 => "u16",
            Format::F32 => "f32",
        }
    }
}

/// What a block carries: voxels (x fastest) in one of the formats, or one value.
#[derive(Clone, Copy)]
enum Source<'a> {
    F32(&'a [f32]),
    U8(&'a [u8]),
    U16(&'a [u16]),
    Tile(f32),
}

impl Source<'_> {
    /// The value of voxel `i` of the block.
    #[inline]
    fn value(&self, i: usize, codes: &Codes) -> f32 {
        match self {
            Source::F32(v) => v[i],
            Source::U8(v) => codes.u8(v[i]),
            Source::U16(v) => codes.u16(v[i]),
            Source::Tile(v) => *v,
        }
    }

    /// Voxels in the block (`None` for a tile).
    fn len(&self) -> Option<usize> {
        match self {
            Source::F32(v) => Some(v.len()),
            Source::U8(v) => Some(v.len()),
            Source::U16(v) => Some(v.len()),
            Source::Tile(_) => None,
        }
    }
}

impl VolumeBuilder {
    /// A builder for the volume the scene calls `name`, read by plugin `plugin`.
    pub fn new(name: &str, plugin: &str) -> VolumeBuilder {
        VolumeBuilder {
            name: name.to_string(),
            plugin: plugin.to_string(),
            volume: None,
            partial: BrickMap::default(),
            skipped: Given::Set(BrickMap::default()),
            failed: None,
            divisors: [None; 3],
            charger: Charger::new(Arc::new(Budget::unlimited()), name),
        }
    }

    /// Charges what the volume stores to `budget` (by default, an unlimited one). Call it
    /// before the reader sends anything.
    pub fn charge_to(&mut self, budget: Arc<Budget>) {
        self.charger = Charger::new(budget, &self.name);
    }

    /// The budget the volume is charged to.
    pub fn budget(&self) -> &Budget {
        self.charger.budget()
    }

    /// Whether an error came from memory refused (by the budget or the system) rather than
    /// from the data, so a caller can report it as the budget's, not the volume's.
    pub fn out_of_memory(&self) -> bool {
        self.charger.was_refused()
    }

    /// Records the first error; later calls fail with it.
    pub fn fail(&mut self, message: &str) {
        if self.failed.is_none() {
            self.failed = Some(message.to_string());
        }
    }

    /// Keeps the first error of `result`.
    fn track(&mut self, result: Result<(), String>) -> Result<(), String> {
        if let Err(m) = &result {
            self.fail(m);
        }
        result
    }

    fn usable(&self) -> Result<(), String> {
        match &self.failed {
            Some(first) => Err(format!(
                "the volume was already rejected by an earlier error: {first}"
            )),
            None => Ok(()),
        }
    }

    /// Describes the grid; must come exactly once, before any data.
    pub fn begin(
        &mut self,
        world_from_index: [f64; 12],
        background: f32,
        index_min: [i64; 3],
        index_max: [i64; 3],
        grid_name: &str,
    ) -> Result<(), String> {
        self.usable()?;
        let r = self.begin_checked(
            world_from_index,
            background,
            index_min,
            index_max,
            grid_name,
        );
        self.track(r)
    }

    fn begin_checked(
        &mut self,
        world_from_index: [f64; 12],
        background: f32,
        index_min: [i64; 3],
        index_max: [i64; 3],
        grid_name: &str,
    ) -> Result<(), String> {
        if self.volume.is_some() {
            return Err("`begin` was called twice; a reader describes one grid per read".into());
        }
        if world_from_index.iter().any(|x| !x.is_finite()) {
            return Err(format!(
                "the grid's index-to-world transform has a non-finite entry: {world_from_index:?}"
            ));
        }
        let m = &world_from_index;
        let det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8])
            + m[2] * (m[4] * m[9] - m[5] * m[8]);
        if det == 0.0 || !det.is_finite() {
            return Err(format!(
                "the grid's index-to-world transform is not invertible (its 3x3 part has \
                 determinant {det}): {world_from_index:?}"
            ));
        }
        if !background.is_finite() {
            return Err(format!(
                "the grid's background value is {background}; expected a finite number"
            ));
        }
        if (0..3).any(|a| index_min[a] > index_max[a]) {
            return Err(format!(
                "the grid's index box {index_min:?} to {index_max:?} is empty; expected \
                 index_min <= index_max on every axis (both inclusive)"
            ));
        }
        let extent = box_extent(index_min, index_max);
        let voxels = extent
            .iter()
            .try_fold(1u128, |a, &e| a.checked_mul(e))
            .unwrap_or(u128::MAX);
        if voxels > u128::from(MAX_VOXELS) {
            return Err(format!(
                "the grid's index box {index_min:?} to {index_max:?} holds {} voxels; at most \
                 2^34 = {MAX_VOXELS} are supported",
                extent.map(|e| e.to_string()).join("x")
            ));
        }
        self.skipped = Given::new(index_min, index_max);
        self.volume = Some(Volume {
            name: self.name.clone(),
            grid_name: grid_name.to_string(),
            plugin: self.plugin.clone(),
            world_from_index,
            background,
            index_min,
            index_max,
            bricks: BrickMap::default(),
            store: Vec::new(),
            slots: BrickMap::default(),
            table: Vec::new(),
            table_min: [0; 3],
            table_dims: [0; 3],
            codes: Codes::default(),
            voxels: 0,
            range: None,
        });
        Ok(())
    }

    /// A dense block of `dims` voxels from `origin`, x fastest.
    pub fn add_dense(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[f32],
    ) -> Result<(), String> {
        self.usable()?;
        let r = self.add_checked(origin, dims, Source::F32(values));
        self.track(r)
    }

    /// A dense block of bytes: voxel value `byte as f32 / divisor` (one divisor for every u8
    /// block of the volume). Its bricks keep the bytes (see the module `brick`).
    pub fn add_dense_u8(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[u8],
        divisor: f32,
    ) -> Result<(), String> {
        self.usable()?;
        let r = self.check_divisor(Format::U8, divisor, origin, dims);
        self.track(r)?;
        if let Some(v) = self.volume.as_mut() {
            v.codes.set_u8_divisor(divisor);
        }
        let r = self.add_checked(origin, dims, Source::U8(values));
        self.track(r)
    }

    /// A dense block of `u16`: voxel value `v as f32 / divisor` (one divisor for every u16
    /// block of the volume). Its bricks keep the words.
    pub fn add_dense_u16(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[u16],
        divisor: f32,
    ) -> Result<(), String> {
        self.usable()?;
        let r = self.check_divisor(Format::U16, divisor, origin, dims);
        self.track(r)?;
        if let Some(v) = self.volume.as_mut() {
            v.codes.set_u16_divisor(divisor);
        }
        let r = self.add_checked(origin, dims, Source::U16(values));
        self.track(r)
    }

    /// A dense block of `f32` whose voxel values are `v / divisor` (`add_dense_typed` of the
    /// ABI with f32 data; divisor 1 is [`Self::add_dense`]).
    pub fn add_dense_f32(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[f32],
        divisor: f32,
    ) -> Result<(), String> {
        self.usable()?;
        let r = self.check_divisor(Format::F32, divisor, origin, dims);
        self.track(r)?;
        if divisor == 1.0 {
            return self.add_dense(origin, dims, values);
        }
        let values: Vec<f32> = values.iter().map(|&v| v / divisor).collect();
        self.add_dense(origin, dims, &values)
    }

    /// The divisor of a typed block: finite and positive, and the one this format's earlier
    /// blocks used.
    fn check_divisor(
        &mut self,
        format: Format,
        divisor: f32,
        origin: [i64; 3],
        dims: [u64; 3],
    ) -> Result<(), String> {
        let name = format.name();
        let what = format!(
            "dense block at {origin:?} of {}x{}x{} {name} voxels",
            dims[0], dims[1], dims[2]
        );
        if !(divisor.is_finite() && divisor > 0.0) {
            return Err(format!(
                "{what} has the divisor {divisor}; expected a finite number greater than 0"
            ));
        }
        let slot = &mut self.divisors[format as usize];
        match *slot {
            Some(d) if d.to_bits() != divisor.to_bits() => Err(format!(
                "{what} mixes divisors {d} and {divisor} for {name} blocks; expected one \
                 divisor per format for the whole volume"
            )),
            _ => {
                *slot = Some(divisor);
                Ok(())
            }
        }
    }

    /// A box of `dims` voxels from `origin`, all `value`.
    pub fn add_tile(&mut self, origin: [i64; 3], dims: [u64; 3], value: f32) -> Result<(), String> {
        self.usable()?;
        let r = self.add_checked(origin, dims, Source::Tile(value));
        self.track(r)
    }

    fn add_checked(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        source: Source,
    ) -> Result<(), String> {
        let what = block_name(&source, origin, dims);
        let call = match source {
            Source::F32(_) => "add_dense",
            Source::U8(_) | Source::U16(_) => "add_dense_typed",
            Source::Tile(_) => "add_tile",
        };
        let Some(volume) = self.volume.as_mut() else {
            return Err(format!(
                "{what}: `{call}` was called before `begin`; a reader must describe the grid first"
            ));
        };
        if dims.contains(&0) {
            return Err(format!(
                "{what} is empty; expected at least one voxel per axis"
            ));
        }
        let count = dims
            .iter()
            .try_fold(1u64, |a, &d| a.checked_mul(d))
            .ok_or_else(|| format!("{what} has too many voxels (the count overflows)"))?;
        // Inclusive last voxel, in i128 so that nothing overflows.
        let last = [0, 1, 2].map(|a| i128::from(origin[a]) + i128::from(dims[a]) - 1);
        if (0..3).any(|a| {
            i128::from(origin[a]) < i128::from(volume.index_min[a])
                || last[a] > i128::from(volume.index_max[a])
        }) {
            return Err(format!(
                "{what} reaches from {origin:?} to {last:?}, outside the grid's index box \
                 {:?} to {:?}",
                volume.index_min, volume.index_max
            ));
        }
        // Inside the box, so every coordinate fits i64 and `count` is at most MAX_VOXELS.
        let last = last.map(|c| c as i64);
        if let Some(len) = source.len() {
            if len as u64 != count {
                return Err(format!("{what} comes with {len} values"));
            }
        }
        let codes = &volume.codes;
        let non_finite = |i: usize| {
            let v = source.value(i, codes);
            let ijk = voxel_of(origin, dims, i);
            format!("{what} has the non-finite value {v} at voxel {ijk:?}; expected finite values")
        };
        let (lo, hi) = match source {
            Source::F32(values) => {
                let mut lo = f32::INFINITY;
                let mut hi = f32::NEG_INFINITY;
                for (i, &v) in values.iter().enumerate() {
                    if !v.is_finite() {
                        return Err(non_finite(i));
                    }
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                (lo, hi)
            }
            // Codes decode monotonically, so their extremes give the values' (and a value
            // that overflows to infinity, with a tiny divisor, is the largest).
            Source::U8(values) => {
                let (a, b) = min_max(values);
                (codes.u8(a), codes.u8(b))
            }
            Source::U16(values) => {
                let (a, b) = min_max(values);
                (codes.u16(a), codes.u16(b))
            }
            Source::Tile(v) => {
                if !v.is_finite() {
                    return Err(format!("{what} has the non-finite value {v}"));
                }
                (v, v)
            }
        };
        if !hi.is_finite() {
            let i = (0..count as usize)
                .find(|&i| !source.value(i, codes).is_finite())
                .unwrap_or(0);
            return Err(non_finite(i));
        }
        let sets = Sets {
            partial: &mut self.partial,
            skipped: &mut self.skipped,
            charger: &mut self.charger,
        };
        store(volume, sets, origin, dims, last, source, &what)?;
        volume.voxels += count;
        volume.range = Some(match volume.range {
            Some((a, b)) => (a.min(lo), b.max(hi)),
            None => (lo, hi),
        });
        Ok(())
    }

    /// The finished volume, or the first error. Dense bricks whose voxels all have one value
    /// (given or background) become constant bricks (complete bricks already are).
    pub fn finish(self) -> Result<Volume, String> {
        self.finish_or_refused().map_err(|(m, _)| m)
    }

    /// [`finish`](Self::finish), and with its error whether it came from memory refused (see
    /// [`out_of_memory`](Self::out_of_memory)), sealing's own charges included.
    pub fn finish_or_refused(mut self) -> Result<Volume, (String, bool)> {
        let refused = |b: &Self, m: String| (m, b.out_of_memory());
        if let Some(first) = self.failed.take() {
            let m = format!("ignored an error from the host and returned success: {first}");
            return Err(refused(&self, m));
        }
        let Some(mut volume) = self.volume.take() else {
            let m = "returned without reading a grid (it never called `begin` on the volume sink)";
            return Err(refused(&self, m.into()));
        };
        // Voxels nothing reached hold the background, so this keeps every value. Only bricks
        // still partly given can be dense and uniform: a complete one was tested when it was.
        let codes = &volume.codes;
        for key in self.partial.keys() {
            let Some(brick) = volume.bricks.get_mut(key) else {
                continue;
            };
            if let Some(v) = brick.uniform(codes) {
                self.charger.sub(brick.heap_bytes() as u64);
                *brick = Brick::Constant(v);
            }
        }
        if let Err(m) = volume.seal(&mut self.charger) {
            return Err(refused(&self, m));
        }
        self.charger.keep();
        Ok(volume)
    }
}

/// Voxels per axis of an inclusive index box (which must not be empty).
fn box_extent(min: [i64; 3], max: [i64; 3]) -> [u128; 3] {
    [0, 1, 2].map(|a| (i128::from(max[a]) - i128::from(min[a]) + 1) as u128)
}

fn block_name(source: &Source, origin: [i64; 3], dims: [u64; 3]) -> String {
    let kind = match source {
        Source::Tile(_) => "tile",
        _ => "dense block",
    };
    format!(
        "{kind} at {origin:?} of {}x{}x{} voxels",
        dims[0], dims[1], dims[2]
    )
}

/// Index of the voxel that is element `i` of a block (x fastest).
fn voxel_of(origin: [i64; 3], dims: [u64; 3], i: usize) -> [i128; 3] {
    let i = i as u64;
    let x = i % dims[0];
    let y = (i / dims[0]) % dims[1];
    let z = i / dims[0] / dims[1];
    [
        i128::from(origin[0]) + i128::from(x),
        i128::from(origin[1]) + i128::from(y),
        i128::from(origin[2]) + i128::from(z),
    ]
}

/// A set of brick coordinates: a bitmap over the index box's bricks when they are few enough
/// for a slot table (at most 2 MiB of bits), a hash set for sparse giants.
enum Given {
    Bits {
        min: [i64; 3],
        dims: [usize; 3],
        words: Vec<u64>,
    },
    Set(BrickMap<()>),
}

impl Given {
    fn new(index_min: [i64; 3], index_max: [i64; 3]) -> Given {
        let lo = index_min.map(|c| c >> BRICK_SHIFT);
        let hi = index_max.map(|c| c >> BRICK_SHIFT);
        let dims = [0, 1, 2].map(|a| (hi[a] - lo[a] + 1) as u64);
        let n = dims.iter().product::<u64>();
        if n > MAX_TABLE {
            return Given::Set(BrickMap::default());
        }
        Given::Bits {
            min: lo,
            dims: dims.map(|d| d as usize),
            words: vec![0; n.div_ceil(64) as usize],
        }
    }

    /// Bit index of `key`, a brick of the index box.
    fn bit(min: [i64; 3], dims: [usize; 3], key: [i64; 3]) -> usize {
        let r = [0, 1, 2].map(|a| (key[a] - min[a]) as usize);
        (r[2] * dims[1] + r[1]) * dims[0] + r[0]
    }

    fn contains(&self, key: [i64; 3]) -> bool {
        match self {
            Given::Bits { min, dims, words } => {
                let i = Given::bit(*min, *dims, key);
                words[i / 64] & (1 << (i % 64)) != 0
            }
            Given::Set(set) => set.contains_key(&key),
        }
    }

    fn insert(&mut self, key: [i64; 3]) {
        match self {
            Given::Bits { min, dims, words } => {
                let i = Given::bit(*min, *dims, key);
                words[i / 64] |= 1 << (i % 64);
            }
            Given::Set(set) => {
                set.insert(key, ());
            }
        }
    }
}

/// The builder's bookkeeping that `store` updates besides the volume.
struct Sets<'a> {
    partial: &'a mut BrickMap<[u64; 8]>,
    skipped: &'a mut Given,
    charger: &'a mut Charger,
}

/// The one value of a complete brick, if all its voxels hold the same bits (`-0.0` and `0.0`
/// differ: a collapsed brick must read exactly as the voxels given).
fn uniform(values: impl IntoIterator<Item = f32>) -> Option<f32> {
    let mut it = values.into_iter();
    let first = it.next()?;
    it.all(|v| v.to_bits() == first.to_bits()).then_some(first)
}

/// [`uniform`] of the voxels of `source` at `rows` (index ranges, the first not empty), row by
/// row: integer codes are compared as codes (equal codes decode to equal values), and only
/// when two differ are the values compared, as codes that differ may still decode to the same
/// value (a tiny divisor).
fn uniform_part(
    source: Source,
    codes: &Codes,
    rows: impl Iterator<Item = std::ops::Range<usize>> + Clone,
) -> Option<f32> {
    /// The one element of `s` at every index of `rows`.
    fn same<T: Copy + PartialEq>(
        s: &[T],
        mut rows: impl Iterator<Item = std::ops::Range<usize>> + Clone,
    ) -> Option<T> {
        let first = s[rows.clone().next()?.start];
        rows.all(|r| s[r].iter().all(|&c| c == first))
            .then_some(first)
    }
    let by_code = match source {
        Source::Tile(v) => return Some(v),
        Source::U8(s) => same(s, rows.clone()).map(|c| codes.u8(c)),
        Source::U16(s) => same(s, rows.clone()).map(|c| codes.u16(c)),
        // Values are compared by their bits.
        Source::F32(s) => {
            let bits = |v: &f32| v.to_bits();
            let first = s[rows.clone().next()?.start].to_bits();
            let mut rows = rows;
            return rows
                .all(|r| s[r].iter().map(bits).all(|b| b == first))
                .then_some(f32::from_bits(first));
        }
    };
    by_code.or_else(|| uniform(rows.flatten().map(|i| source.value(i, codes))))
}

/// Copies a whole brick's voxels from a u8 block of `dims` voxels whose voxel at the brick's
/// first corner is `s[at]` (row `y` of slice `z` of the brick, eight bytes, is
/// `s[at + (z * dims[1] + y) * dims[0]..]`), and says whether they all hold the same code.
fn copy_brick_u8(b: &mut [u8; BRICK_VOXELS], s: &[u8], at: usize, dims: [u64; 3]) -> bool {
    const N: usize = BRICK_SIZE as usize;
    let (dx, slab) = (dims[0] as usize, (dims[0] * dims[1]) as usize);
    let splat = u64::from(s[at]) * 0x0101_0101_0101_0101;
    let mut differ = 0;
    for (z, plane) in b.chunks_exact_mut(N * N).enumerate() {
        let s = &s[at + z * slab..];
        for (y, row) in plane.chunks_exact_mut(N).enumerate() {
            // One eight-byte word per row: copied, and compared with the first code.
            let mut word = [0; N];
            word.copy_from_slice(&s[y * dx..y * dx + N]);
            row.copy_from_slice(&word);
            differ |= u64::from_ne_bytes(word) ^ splat;
        }
    }
    differ == 0
}

/// Smallest and largest of a non-empty slice of codes.
fn min_max<T: Copy + Ord>(values: &[T]) -> (T, T) {
    let first = values[0];
    values
        .iter()
        .fold((first, first), |(a, b), &v| (a.min(v), b.max(v)))
}

/// Stores a complete brick whose voxels all hold `v`: nothing for the background, else a
/// constant brick (a dense brick it replaces gives its bytes back).
fn store_uniform(
    bricks: &mut BrickMap<Brick>,
    sets: (&mut Given, &mut Charger),
    background: f32,
    key: [i64; 3],
    v: f32,
) -> Result<(), String> {
    let (skipped, charger) = sets;
    let old = if v.to_bits() == background.to_bits() {
        skipped.insert(key);
        bricks.remove(&key)
    } else {
        if !bricks.contains_key(&key) {
            charger.room_for_one(bricks)?;
        }
        bricks.insert(key, Brick::Constant(v))
    };
    if let Some(old) = old {
        charger.sub(old.heap_bytes() as u64);
    }
    Ok(())
}

/// A new dense brick for data from `source`, charged: in the source's format, its voxels set to
/// the background when `partial` (so the format needs a code for it; otherwise f32).
fn new_brick(
    source: Source,
    background: f32,
    codes: &Codes,
    partial: bool,
    charger: &mut Charger,
) -> Result<Brick, String> {
    match source {
        Source::U8(_) => {
            let code = if partial {
                codes.u8_code(background)
            } else {
                Some(0)
            };
            if let Some(c) = code {
                return charger.brick(|| brick::array(c).map(Brick::U8), Brick::BYTES[0]);
            }
        }
        Source::U16(_) => {
            let code = if partial {
                codes.u16_code(background)
            } else {
                Some(0)
            };
            if let Some(c) = code {
                return charger.brick(|| brick::array(c).map(Brick::U16), Brick::BYTES[1]);
            }
        }
        Source::F32(_) | Source::Tile(_) => {}
    }
    charger.brick(|| brick::array(background).map(Brick::F32), Brick::BYTES[2])
}

/// Bits `from..from + n` of a 64-bit word (`n` in 1..=8).
#[inline]
fn run_bits(from: usize, n: usize) -> u64 {
    ((1u64 << n) - 1) << from
}

/// Cuts a checked block (inside the box, `last` its inclusive end) into bricks. A brick keeps
/// the format of the data that created it while later data has the same format (or is a tile
/// whose value has a code in it); other data first turns it into an f32 brick, which keeps
/// every value (the codes' values are f32s).
fn store(
    volume: &mut Volume,
    sets: Sets,
    origin: [i64; 3],
    dims: [u64; 3],
    last: [i64; 3],
    source: Source,
    what: &str,
) -> Result<(), String> {
    let first_key = origin.map(|c| c >> BRICK_SHIFT);
    let last_key = last.map(|c| c >> BRICK_SHIFT);
    let Sets {
        partial,
        skipped,
        charger,
    } = sets;
    let Volume {
        bricks,
        codes,
        background,
        ..
    } = volume;
    let (codes, background) = (&*codes, *background);
    // A tile's value as a code of u8 and u16 bricks, when it has one.
    let (tile_u8, tile_u16) = match source {
        Source::Tile(v) => (codes.u8_code(v), codes.u16_code(v)),
        _ => (None, None),
    };
    for bz in first_key[2]..=last_key[2] {
        for by in first_key[1]..=last_key[1] {
            for bx in first_key[0]..=last_key[0] {
                let key = [bx, by, bz];
                // The part of the block inside this brick, in voxel indices.
                let brick_lo = key.map(|k| k << BRICK_SHIFT);
                let lo = [0, 1, 2].map(|a| origin[a].max(brick_lo[a]));
                let hi = [0, 1, 2].map(|a| last[a].min(brick_lo[a] + BRICK_SIZE - 1));
                let whole =
                    (0..3).all(|a| lo[a] == brick_lo[a] && hi[a] == brick_lo[a] + BRICK_SIZE - 1);
                let existing = bricks.contains_key(&key);
                if (existing && !partial.contains_key(&key)) || skipped.contains(key) {
                    return Err(format!(
                        "{what} gives voxel {lo:?} again (it was given before); expected every \
                         voxel at most once"
                    ));
                }
                // Offset in a dense source of voxel (lo[0], y, z).
                let src_at = |y: i64, z: i64| {
                    (((z - origin[2]) as u64 * dims[1] + (y - origin[1]) as u64) * dims[0]
                        + (lo[0] - origin[0]) as u64) as usize
                };
                let n = (hi[0] - lo[0] + 1) as usize;
                if let (false, true, Source::U8(s)) = (existing, whole, source) {
                    // The common case of a u8 file (raw volumes): a whole new brick, copied
                    // once and tested as one contiguous array.
                    let mut b = [0; BRICK_VOXELS];
                    let all_equal = copy_brick_u8(&mut b, s, src_at(lo[1], lo[2]), dims);
                    if let Some(v) = codes.u8_uniform(&b, all_equal) {
                        store_uniform(bricks, (skipped, charger), background, key, v)?;
                    } else {
                        let brick =
                            charger.brick(|| brick::copy_of(&b).map(Brick::U8), Brick::BYTES[0])?;
                        charger.room_for_one(bricks)?;
                        bricks.insert(key, brick);
                    }
                    continue;
                }
                if !existing {
                    if whole {
                        let rows = (lo[2]..=hi[2])
                            .flat_map(|z| (lo[1]..=hi[1]).map(move |y| (y, z)))
                            .map(|(y, z)| src_at(y, z)..src_at(y, z) + n);
                        let one = uniform_part(source, codes, rows);
                        if let Some(v) = one {
                            store_uniform(bricks, (skipped, charger), background, key, v)?;
                            continue;
                        }
                    }
                    let brick = new_brick(source, background, codes, !whole, charger)?;
                    charger.room_for_one(bricks)?;
                    bricks.insert(key, brick);
                    if !whole {
                        partial.insert(key, [0; 8]);
                    }
                }
                let mask = partial.get_mut(&key);
                // Check the whole part first so a rejected block leaves the brick unchanged.
                if let Some(mask) = mask.as_deref() {
                    for z in lo[2]..=hi[2] {
                        for y in lo[1]..=hi[1] {
                            let bits = run_bits(local_index([lo[0], y, 0]), n);
                            if mask[(z - brick_lo[2]) as usize] & bits != 0 {
                                let x = (0..n as i64)
                                    .map(|d| lo[0] + d)
                                    .find(|&x| {
                                        mask[(z - brick_lo[2]) as usize]
                                            & (1 << local_index([x, y, 0]))
                                            != 0
                                    })
                                    .unwrap_or(lo[0]);
                                return Err(format!(
                                    "{what} gives voxel {:?} again (it was given before); \
                                     expected every voxel at most once",
                                    [x, y, z]
                                ));
                            }
                        }
                    }
                }
                let Some(brick) = bricks.get_mut(&key) else {
                    unreachable!("the brick was found or inserted above");
                };
                let keeps = match (&*brick, source) {
                    (Brick::F32(_), _)
                    | (Brick::U8(_), Source::U8(_))
                    | (Brick::U16(_), Source::U16(_)) => true,
                    (Brick::U8(_), Source::Tile(_)) => tile_u8.is_some(),
                    (Brick::U16(_), Source::Tile(_)) => tile_u16.is_some(),
                    _ => false,
                };
                if !keeps {
                    let more = Brick::BYTES[2] - brick.heap_bytes() as u64;
                    charger.add(more)?;
                    let Some(values) = brick.to_f32(codes) else {
                        charger.sub(more);
                        return Err(charger.refused(Brick::BYTES[2]));
                    };
                    *brick = Brick::F32(values);
                }
                for z in lo[2]..=hi[2] {
                    for y in lo[1]..=hi[1] {
                        let dst = local_index([lo[0], y, z]);
                        let at = src_at(y, z);
                        match (&mut *brick, source) {
                            (Brick::F32(b), Source::F32(s)) => {
                                b[dst..dst + n].copy_from_slice(&s[at..at + n]);
                            }
                            (Brick::F32(b), Source::Tile(v)) => b[dst..dst + n].fill(v),
                            (Brick::F32(b), _) => {
                                for k in 0..n {
                                    b[dst + k] = source.value(at + k, codes);
                                }
                            }
                            (Brick::U8(b), Source::U8(s)) => {
                                b[dst..dst + n].copy_from_slice(&s[at..at + n]);
                            }
                            (Brick::U8(b), Source::Tile(_)) => {
                                b[dst..dst + n].fill(tile_u8.unwrap_or_default());
                            }
                            (Brick::U16(b), Source::U16(s)) => {
                                b[dst..dst + n].copy_from_slice(&s[at..at + n]);
                            }
                            (Brick::U16(b), Source::Tile(_)) => {
                                b[dst..dst + n].fill(tile_u16.unwrap_or_default());
                            }
                            _ => unreachable!("a brick that cannot hold the data became f32"),
                        }
                    }
                }
                if let Some(mask) = mask {
                    for z in lo[2]..=hi[2] {
                        for y in lo[1]..=hi[1] {
                            mask[(z - brick_lo[2]) as usize] |=
                                run_bits(local_index([lo[0], y, 0]), n);
                        }
                    }
                    if mask.iter().all(|&w| w == u64::MAX) {
                        partial.remove(&key);
                        if let Some(v) = brick.uniform(codes) {
                            store_uniform(bricks, (skipped, charger), background, key, v)?;
                        }
                    }
                }
            }
        }
    }
    Ok(())
}
