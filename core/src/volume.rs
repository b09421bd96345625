//! Volumes: scalar grids read by volume-reader plugins, stored sparsely as bricks.
//!
//! A reader describes its grid once (`begin`: index-to-world transform, background value and the
//! inclusive index box), then hands over dense blocks and constant tiles anywhere inside that
//! box, in any order and of any size. The host cuts them into bricks of 8³ voxels, each stored
//! either as 512 values or as a single constant, so that dense raw files and sparse VDB-style
//! trees (leaves and tiles) fit the same structure. Voxels no block or tile gave read as the
//! background value.
//!
//! A brick is collapsed as soon as it is complete: one whose voxels all hold one value becomes a
//! constant brick, and one whose voxels all hold the background is not stored at all (it reads
//! as the background anyway). So memory follows the data's content, not the grid's size: an
//! empty 1024³ grid costs its slot table (8 MiB), not the 4 GiB of its voxels.
//!
//! Everything a reader sends is checked before it is stored: `begin` exactly once and before any
//! data, finite numbers only, an invertible transform, blocks inside the index box, no voxel
//! given twice, and an index box of at most [`MAX_VOXELS`] voxels (checked before anything is
//! allocated). The first error stops the volume: later calls fail, and the read fails even if
//! the plugin ignores the error.
//!
//! The readers are plugins (`plugins/volume-raw`, `plugins/volume-vdb`); how volumes are drawn:
//! the module `volume_render`; what a scene writes (transfer functions, steps, shading): in
//! the Volumes section of `formats/README.md`.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Edge length of a brick in voxels.
pub const BRICK_SIZE: i64 = 8;
const BRICK_SHIFT: u32 = 3;
/// Voxels in a brick.
pub const BRICK_VOXELS: usize = 512;
/// The largest index box a volume may declare, in voxels (2^34: 64 GiB of dense f32 data).
pub const MAX_VOXELS: u64 = 1 << 34;

/// The storage of one 8³ brick; voxel `(x, y, z)` of the brick is element `x + 8y + 64z`.
#[derive(Clone, Debug, PartialEq)]
pub enum Brick {
    /// Every voxel has this value.
    Constant(f32),
    /// One value per voxel, x fastest (voxels no data reached hold the background).
    Dense(Box<[f32; BRICK_VOXELS]>),
}

/// A fast hasher for brick coordinates (three `i64`s), which are not attacker-controlled in a
/// way that matters here: the default SipHash would dominate voxel lookups.
#[derive(Default)]
struct BrickHasher(u64);

impl BrickHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(23) ^ word).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
}

impl Hasher for BrickHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u64(&mut self, n: u64) {
        self.add(n);
    }

    #[inline]
    fn write_i64(&mut self, n: i64) {
        self.add(n as u64);
    }

    #[inline]
    fn write_usize(&mut self, n: usize) {
        self.add(n as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        // Fold the well-mixed high bits into the low ones the table indexes with.
        self.0 ^ (self.0 >> 29)
    }
}

type BrickMap<T> = HashMap<[i64; 3], T, BuildHasherDefault<BrickHasher>>;

/// A scalar grid read by a volume-reader plugin.
#[derive(Clone, Debug)]
pub struct Volume {
    /// The scene's name for the volume (its `name`, or "volume N" when it has none).
    pub name: String,
    /// The name the reader gives the grid (e.g. a VDB grid name or a file name).
    pub grid_name: String,
    /// The reader plugin.
    pub plugin: String,
    /// Row-major 3x4 affine map from voxel index space to world space (finite, invertible).
    pub world_from_index: [f64; 12],
    /// Value of every voxel no block or tile gave, and outside the index box.
    pub background: f32,
    /// Inclusive index-space bounds of the data (`index_min <= index_max` on every axis).
    pub index_min: [i64; 3],
    pub index_max: [i64; 3],
    /// Bricks while the volume is being read; empty once finished (see `store`).
    bricks: BrickMap<Brick>,
    /// The finished bricks, found through `slots` (by brick coordinate) or `table`.
    store: Vec<Brick>,
    slots: BrickMap<u32>,
    /// Dense slot table over the brick coordinates of the index box (`NO_BRICK`: none), for
    /// lookups without hashing in the renderer's inner loops; empty when that box has more
    /// than `MAX_TABLE` bricks (sparse giants are looked up by hash).
    table: Vec<u32>,
    table_min: [i64; 3],
    table_dims: [usize; 3],
    /// Voxels given by the reader.
    voxels: u64,
    /// Smallest and largest value given, `None` when no voxel was.
    range: Option<(f32, f32)>,
}

const NO_BRICK: u32 = u32::MAX;
/// The most bricks a dense slot table may have (64 MiB of slots).
const MAX_TABLE: u64 = 1 << 24;

impl Volume {
    /// The value at voxel `ijk`: the background where the reader gave nothing.
    #[inline]
    pub fn value(&self, ijk: [i64; 3]) -> f32 {
        let key = ijk.map(|c| c >> BRICK_SHIFT);
        match self.brick(key) {
            None => self.background,
            Some(Brick::Constant(v)) => *v,
            Some(Brick::Dense(values)) => values[local_index(ijk)],
        }
    }

    /// Moves the bricks read into their final storage and builds the slot table.
    fn seal(&mut self) {
        let mut all: Vec<([i64; 3], Brick)> =
            std::mem::take(&mut self.bricks).into_iter().collect();
        all.sort_unstable_by_key(|(k, _)| *k);
        self.store.reserve_exact(all.len());
        for (key, brick) in all {
            self.slots.insert(key, self.store.len() as u32);
            self.store.push(brick);
        }
        let lo = self.index_min.map(|c| c >> BRICK_SHIFT);
        let hi = self.index_max.map(|c| c >> BRICK_SHIFT);
        let dims = [0, 1, 2].map(|a| (hi[a] - lo[a] + 1) as u64);
        if dims.iter().product::<u64>() <= MAX_TABLE {
            let dims = dims.map(|d| d as usize);
            let mut table = vec![NO_BRICK; dims[0] * dims[1] * dims[2]];
            for (key, &slot) in &self.slots {
                let r = [0, 1, 2].map(|a| (key[a] - lo[a]) as usize);
                table[(r[2] * dims[1] + r[1]) * dims[0] + r[0]] = slot;
            }
            self.table = table;
            self.table_min = lo;
            self.table_dims = dims;
        }
    }

    /// Number of voxels the reader gave (in dense blocks and tiles), not counting background.
    pub fn voxel_count(&self) -> u64 {
        self.voxels
    }

    /// Smallest and largest value over the voxels the reader gave; `(background, background)`
    /// when it gave none.
    pub fn min_max(&self) -> (f32, f32) {
        self.range.unwrap_or((self.background, self.background))
    }

    /// Bytes held by the volume's storage: the brick table and the dense bricks (approximate:
    /// the table's control bytes and the allocator's overhead are not counted).
    pub fn memory_bytes(&self) -> usize {
        let dense = self
            .store
            .iter()
            .filter(|b| matches!(b, Brick::Dense(_)))
            .count();
        std::mem::size_of::<Volume>()
            + self.store.capacity() * std::mem::size_of::<Brick>()
            + self.slots.capacity() * std::mem::size_of::<([i64; 3], u32)>()
            + self.table.capacity() * 4
            + dense * std::mem::size_of::<[f32; BRICK_VOXELS]>()
            + self.name.capacity()
            + self.grid_name.capacity()
            + self.plugin.capacity()
    }

    /// Number of (dense, constant) bricks stored (bricks of background voxels are not).
    pub fn brick_counts(&self) -> (usize, usize) {
        let dense = self
            .store
            .iter()
            .filter(|b| matches!(b, Brick::Dense(_)))
            .count();
        (dense, self.store.len() - dense)
    }

    /// The brick with brick coordinate `key` (voxel `ijk` lies in brick `ijk >> 3`, i.e.
    /// `floor(ijk / 8)`), if it is stored: `None` reads as the background (no data reached the
    /// brick, or all of its voxels were given the background value).
    #[inline]
    pub fn brick(&self, key: [i64; 3]) -> Option<&Brick> {
        if !self.table.is_empty() {
            let d = self.table_dims;
            let r = [0, 1, 2].map(|a| key[a].wrapping_sub(self.table_min[a]) as u64);
            if r[0] >= d[0] as u64 || r[1] >= d[1] as u64 || r[2] >= d[2] as u64 {
                return None;
            }
            let slot = self.table[(r[2] as usize * d[1] + r[1] as usize) * d[0] + r[0] as usize];
            return (slot != NO_BRICK).then(|| &self.store[slot as usize]);
        }
        self.slots.get(&key).map(|&s| &self.store[s as usize])
    }

    /// Every stored brick with its brick coordinate, in no particular order; bricks that read
    /// as the background are omitted.
    pub fn bricks(&self) -> impl Iterator<Item = ([i64; 3], &Brick)> {
        self.slots
            .iter()
            .map(|(k, &s)| (*k, &self.store[s as usize]))
    }

    /// A point in (continuous) index space mapped to world space.
    pub fn index_to_world(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.world_from_index;
        [0, 1, 2]
            .map(|r| m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3])
    }
}

/// Position of voxel `ijk` inside its brick.
#[inline]
fn local_index(ijk: [i64; 3]) -> usize {
    let mask = BRICK_SIZE - 1;
    ((ijk[0] & mask) + ((ijk[1] & mask) << BRICK_SHIFT) + ((ijk[2] & mask) << (2 * BRICK_SHIFT)))
        as usize
}

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
}

/// What a block carries.
#[derive(Clone, Copy)]
enum Source<'a> {
    Dense(&'a [f32]),
    Tile(f32),
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
        }
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
        let r = self.add_checked(origin, dims, Source::Dense(values));
        self.track(r)
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
            Source::Dense(_) => "add_dense",
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
        let (lo, hi) = match source {
            Source::Dense(values) => {
                if values.len() as u64 != count {
                    return Err(format!("{what} comes with {} values", values.len()));
                }
                let mut lo = f32::INFINITY;
                let mut hi = f32::NEG_INFINITY;
                for (i, &v) in values.iter().enumerate() {
                    if !v.is_finite() {
                        let ijk = voxel_of(origin, dims, i);
                        return Err(format!(
                            "{what} has the non-finite value {v} at voxel {ijk:?}; expected \
                             finite values"
                        ));
                    }
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                (lo, hi)
            }
            Source::Tile(v) => {
                if !v.is_finite() {
                    return Err(format!("{what} has the non-finite value {v}"));
                }
                (v, v)
            }
        };
        let sets = Sets {
            partial: &mut self.partial,
            skipped: &mut self.skipped,
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
        if let Some(first) = self.failed {
            return Err(format!(
                "ignored an error from the host and returned success: {first}"
            ));
        }
        let Some(mut volume) = self.volume else {
            return Err(
                "returned without reading a grid (it never called `begin` on the volume sink)"
                    .into(),
            );
        };
        // Voxels nothing reached hold the background, so this keeps every value.
        for brick in volume.bricks.values_mut() {
            if let Brick::Dense(values) = brick {
                let first = values[0];
                if values.iter().all(|&v| v == first) {
                    *brick = Brick::Constant(first);
                }
            }
        }
        volume.seal();
        Ok(volume)
    }
}

/// Voxels per axis of an inclusive index box (which must not be empty).
fn box_extent(min: [i64; 3], max: [i64; 3]) -> [u128; 3] {
    [0, 1, 2].map(|a| (i128::from(max[a]) - i128::from(min[a]) + 1) as u128)
}

fn block_name(source: &Source, origin: [i64; 3], dims: [u64; 3]) -> String {
    let kind = match source {
        Source::Dense(_) => "dense block",
        Source::Tile(_) => "tile",
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
}

/// The one value of a complete brick, if all its voxels hold the same bits (`-0.0` and `0.0`
/// differ: a collapsed brick must read exactly as the voxels given).
fn uniform(values: impl IntoIterator<Item = f32>) -> Option<f32> {
    let mut it = values.into_iter();
    let first = it.next()?;
    it.all(|v| v.to_bits() == first.to_bits()).then_some(first)
}

/// Stores a complete brick whose voxels all hold `v`: nothing for the background, else a
/// constant brick.
fn store_uniform(volume: &mut Volume, skipped: &mut Given, key: [i64; 3], v: f32) {
    if v.to_bits() == volume.background.to_bits() {
        volume.bricks.remove(&key);
        skipped.insert(key);
    } else {
        volume.bricks.insert(key, Brick::Constant(v));
    }
}

/// Bits `from..from + n` of a 64-bit word (`n` in 1..=8).
#[inline]
fn run_bits(from: usize, n: usize) -> u64 {
    ((1u64 << n) - 1) << from
}

/// Cuts a checked block (inside the box, `last` its inclusive end) into bricks.
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
    let Sets { partial, skipped } = sets;
    let background = volume.background;
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
                let existing = volume.bricks.contains_key(&key);
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
                if !existing {
                    if whole {
                        let one = match source {
                            Source::Tile(v) => Some(v),
                            Source::Dense(src) => uniform(
                                (lo[2]..=hi[2])
                                    .flat_map(|z| (lo[1]..=hi[1]).map(move |y| (y, z)))
                                    .flat_map(|(y, z)| src[src_at(y, z)..src_at(y, z) + n].iter())
                                    .copied(),
                            ),
                        };
                        if let Some(v) = one {
                            store_uniform(volume, skipped, key, v);
                            continue;
                        }
                    } else {
                        partial.insert(key, [0; 8]);
                    }
                    volume
                        .bricks
                        .insert(key, Brick::Dense(Box::new([background; BRICK_VOXELS])));
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
                let Some(Brick::Dense(values)) = volume.bricks.get_mut(&key) else {
                    unreachable!("a brick given in part is dense");
                };
                for z in lo[2]..=hi[2] {
                    for y in lo[1]..=hi[1] {
                        let dst = local_index([lo[0], y, z]);
                        let run = &mut values[dst..dst + n];
                        match source {
                            Source::Tile(v) => run.fill(v),
                            Source::Dense(src) => {
                                let at = src_at(y, z);
                                run.copy_from_slice(&src[at..at + n]);
                            }
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
                        if let Some(v) = uniform(values.iter().copied()) {
                            store_uniform(volume, skipped, key, v);
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const IDENTITY: [f64; 12] = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0.];

    fn builder(min: [i64; 3], max: [i64; 3]) -> VolumeBuilder {
        let mut b = VolumeBuilder::new("v", "test");
        b.begin(IDENTITY, -1.0, min, max, "grid").unwrap();
        b
    }

    #[test]
    fn dense_blocks_across_bricks_and_negative_indices() {
        let mut b = builder([-10, -3, -9], [20, 20, 20]);
        // A 13x5x11 block straddling brick boundaries on every axis, value = linear index.
        let origin = [-6, -3, -9];
        let dims = [13u64, 5, 11];
        let values: Vec<f32> = (0..13 * 5 * 11).map(|i| i as f32).collect();
        b.add_dense(origin, dims, &values).unwrap();
        let v = b.finish().unwrap();
        for z in 0..11 {
            for y in 0..5 {
                for x in 0..13 {
                    let ijk = [origin[0] + x, origin[1] + y, origin[2] + z];
                    assert_eq!(v.value(ijk), ((z * 5 + y) * 13 + x) as f32, "{ijk:?}");
                }
            }
        }
        assert_eq!(v.value([-7, -3, -9]), -1.0);
        assert_eq!(v.value([7, 0, 0]), -1.0);
        assert_eq!(v.value([1000, 0, 0]), -1.0);
        assert_eq!(v.voxel_count(), 13 * 5 * 11);
        assert_eq!(v.min_max(), (0.0, (13 * 5 * 11 - 1) as f32));
    }

    #[test]
    fn tiles_become_constant_bricks_and_partial_tiles_dense() {
        let mut b = builder([0, 0, 0], [63, 63, 63]);
        b.add_tile([0, 0, 0], [16, 16, 8], 2.5).unwrap();
        b.add_tile([16, 0, 0], [3, 1, 1], 4.0).unwrap();
        let v = b.finish().unwrap();
        assert_eq!(v.brick_counts(), (1, 4));
        assert_eq!(v.brick([1, 1, 0]), Some(&Brick::Constant(2.5)));
        assert_eq!(v.value([15, 15, 7]), 2.5);
        assert_eq!(v.value([18, 0, 0]), 4.0);
        assert_eq!(v.value([19, 0, 0]), -1.0);
        assert_eq!(v.voxel_count(), 16 * 16 * 8 + 3);
        assert_eq!(v.min_max(), (2.5, 4.0));
    }

    #[test]
    fn uniform_complete_dense_bricks_are_compacted() {
        let mut b = builder([0, 0, 0], [15, 7, 7]);
        let mut values = vec![0.0f32; 16 * 8 * 8];
        values[8] = 1.0; // in the second brick
        b.add_dense([0, 0, 0], [16, 8, 8], &values).unwrap();
        let v = b.finish().unwrap();
        assert_eq!(v.brick([0, 0, 0]), Some(&Brick::Constant(0.0)));
        assert!(matches!(v.brick([1, 0, 0]), Some(Brick::Dense(_))));
        assert_eq!(v.value([8, 0, 0]), 1.0);
        assert!(v.memory_bytes() >= 2048);
    }

    #[test]
    fn background_bricks_are_not_stored_and_uniform_ones_are_constant() {
        // 4x4x8 bricks: the lower half (z < 32) all background, the upper half all 0.5, sent
        // as dense blocks of one slice of bricks each.
        let fill = || {
            let mut b = builder([0, 0, 0], [31, 31, 63]);
            for z in (0..64).step_by(8) {
                let v = if z < 32 { -1.0 } else { 0.5 };
                b.add_dense([0, 0, z], [32, 32, 8], &vec![v; 32 * 32 * 8])
                    .unwrap();
            }
            b
        };
        let e = fill().add_tile([3, 4, 5], [1, 1, 1], 2.0).unwrap_err();
        assert!(e.contains("voxel [3, 4, 5] again"), "{e}");
        let v = fill().finish().unwrap();
        assert_eq!(v.brick_counts(), (0, 64));
        assert_eq!(v.brick([0, 0, 0]), None);
        assert!(v.memory_bytes() < 64 * 2048, "{}", v.memory_bytes());
        for (ijk, want) in [([0, 0, 0], -1.0), ([31, 31, 31], -1.0), ([0, 0, 32], 0.5)] {
            assert_eq!(v.value(ijk), want, "{ijk:?}");
        }
        assert_eq!(v.voxel_count(), 32 * 32 * 64);
        assert_eq!(v.min_max(), (-1.0, 0.5));
    }

    #[test]
    fn a_brick_completed_in_parts_collapses_when_complete() {
        let fill = || {
            let mut b = builder([0, 0, 0], [15, 7, 7]);
            for z in 0..8 {
                b.add_dense([0, 0, z], [16, 8, 1], &[-1.0; 128]).unwrap();
            }
            b
        };
        let e = fill().add_dense([9, 1, 1], [1, 1, 1], &[-1.0]).unwrap_err();
        assert!(e.contains("voxel [9, 1, 1] again"), "{e}");
        let v = fill().finish().unwrap();
        assert_eq!(v.brick_counts(), (0, 0));
        assert_eq!(v.value([9, 1, 1]), -1.0);
    }

    #[test]
    fn negative_zero_is_not_the_background_zero() {
        let mut b = VolumeBuilder::new("v", "test");
        b.begin(IDENTITY, 0.0, [0; 3], [7; 3], "g").unwrap();
        b.add_dense([0; 3], [8; 3], &[-0.0; 512]).unwrap();
        let v = b.finish().unwrap();
        assert_eq!(v.brick_counts(), (0, 1));
        assert!(v.value([1, 2, 3]).is_sign_negative());
    }

    #[test]
    fn a_brick_filled_in_parts_is_complete() {
        let mut b = builder([0, 0, 0], [7, 7, 7]);
        for z in 0..8 {
            b.add_tile([0, 0, z], [8, 8, 1], 3.0).unwrap();
        }
        let e = b.add_tile([1, 2, 3], [1, 1, 1], 3.0).unwrap_err();
        assert!(e.contains("again"), "{e}");
    }

    #[test]
    fn rejections() {
        let mut b = VolumeBuilder::new("v", "test");
        let e = b.add_dense([0; 3], [1; 3], &[0.0]).unwrap_err();
        assert!(e.contains("before `begin`"), "{e}");
        // The first error sticks.
        let e = b.begin(IDENTITY, 0.0, [0; 3], [1; 3], "g").unwrap_err();
        assert!(e.contains("already rejected"), "{e}");
        assert!(b.finish().unwrap_err().contains("before `begin`"));

        let mut b = builder([0; 3], [9; 3]);
        let e = b.begin(IDENTITY, 0.0, [0; 3], [1; 3], "g").unwrap_err();
        assert!(e.contains("twice"), "{e}");

        let fresh = || builder([0; 3], [9; 3]);
        let e = fresh()
            .add_dense([5, 5, 5], [2, 2, 6], &[0.0; 24])
            .unwrap_err();
        assert!(
            e.contains("dense block at [5, 5, 5] of 2x2x6 voxels") && e.contains("outside"),
            "{e}"
        );
        let e = fresh().add_tile([-1, 0, 0], [1, 1, 1], 0.0).unwrap_err();
        assert!(
            e.contains("tile at [-1, 0, 0]") && e.contains("outside"),
            "{e}"
        );
        let e = fresh()
            .add_tile([0, 0, 0], [u64::MAX, u64::MAX, 2], 0.0)
            .unwrap_err();
        assert!(e.contains("overflows"), "{e}");
        let e = fresh().add_tile([0, 0, 0], [0, 1, 1], 0.0).unwrap_err();
        assert!(e.contains("empty"), "{e}");
        let e = fresh()
            .add_dense([0, 0, 0], [2, 1, 1], &[0.0, f32::NAN])
            .unwrap_err();
        assert!(e.contains("non-finite") && e.contains("[1, 0, 0]"), "{e}");
        let e = fresh().add_dense([0, 0, 0], [2, 1, 1], &[0.0]).unwrap_err();
        assert!(e.contains("1 values"), "{e}");
        let mut b = fresh();
        b.add_tile([0, 0, 0], [3, 3, 3], 1.0).unwrap();
        let e = b.add_dense([2, 2, 2], [1, 1, 1], &[1.0]).unwrap_err();
        assert!(e.contains("voxel [2, 2, 2] again"), "{e}");

        let mut b = VolumeBuilder::new("v", "test");
        let mut m = IDENTITY;
        m[5] = f64::NAN;
        assert!(b
            .begin(m, 0.0, [0; 3], [1; 3], "g")
            .unwrap_err()
            .contains("non-finite"));
        let mut b = VolumeBuilder::new("v", "test");
        m[5] = 0.0;
        assert!(b
            .begin(m, 0.0, [0; 3], [1; 3], "g")
            .unwrap_err()
            .contains("invertible"));
        let mut b = VolumeBuilder::new("v", "test");
        let e = b
            .begin(IDENTITY, f32::INFINITY, [0; 3], [1; 3], "g")
            .unwrap_err();
        assert!(e.contains("background"), "{e}");
        let mut b = VolumeBuilder::new("v", "test");
        let e = b
            .begin(IDENTITY, 0.0, [0, 0, 5], [1, 1, 4], "g")
            .unwrap_err();
        assert!(e.contains("empty"), "{e}");
        let mut b = VolumeBuilder::new("v", "test");
        let e = b
            .begin(IDENTITY, 0.0, [i64::MIN; 3], [i64::MAX; 3], "g")
            .unwrap_err();
        assert!(e.contains("at most 2^34"), "{e}");
        let mut b = VolumeBuilder::new("v", "test");
        // Exactly 2^34 voxels is fine (nothing is allocated for it).
        b.begin(IDENTITY, 0.0, [0; 3], [2047, 2047, 4095], "g")
            .unwrap();
        let mut b = VolumeBuilder::new("v", "test");
        assert!(b
            .begin(IDENTITY, 0.0, [0; 3], [2047, 2047, 4096], "g")
            .is_err());
    }

    #[test]
    fn index_to_world_applies_the_affine_map() {
        let mut b = VolumeBuilder::new("v", "test");
        let m = [2., 0., 0., 1., 0., 3., 0., 2., 0., 0., 4., 3.];
        b.begin(m, 0.0, [0; 3], [1; 3], "g").unwrap();
        let v = b.finish().unwrap();
        assert_eq!(v.index_to_world([1.0, 1.0, 1.0]), [3.0, 5.0, 7.0]);
        assert_eq!(v.voxel_count(), 0);
        assert_eq!(v.min_max(), (0.0, 0.0));
    }
}
