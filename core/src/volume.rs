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

mod brick;
mod builder;
mod charge;

pub use brick::{Brick, Codes};
pub use builder::{Format, VolumeBuilder};

use crate::budget::try_vec;
use charge::{entry_bytes, Charger};

/// Edge length of a brick in voxels.
pub const BRICK_SIZE: i64 = 8;
const BRICK_SHIFT: u32 = 3;
/// Voxels in a brick.
pub const BRICK_VOXELS: usize = 512;
/// The largest index box a volume may declare, in voxels (2^34: 64 GiB of dense f32 data).
pub const MAX_VOXELS: u64 = 1 << 34;

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
    /// The values of the codes of u8 and u16 bricks.
    codes: Codes,
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
            Some(b) => b.value(local_index(ijk), &self.codes),
        }
    }

    /// How the codes of the volume's u8 and u16 bricks become values.
    #[inline]
    pub fn codes(&self) -> &Codes {
        &self.codes
    }

    /// Moves the bricks read into their final storage and builds the slot table, charging
    /// both first (and giving back the map the bricks were read into).
    fn seal(&mut self, charger: &mut Charger) -> Result<(), String> {
        let n = self.bricks.len();
        let lo = self.index_min.map(|c| c >> BRICK_SHIFT);
        let hi = self.index_max.map(|c| c >> BRICK_SHIFT);
        let dims = [0, 1, 2].map(|a| (hi[a] - lo[a] + 1) as u64);
        let cells = dims.iter().product::<u64>();
        let table_len = if cells <= MAX_TABLE {
            cells as usize
        } else {
            0
        };
        let sorting = (n * std::mem::size_of::<([i64; 3], Brick)>()) as u64;
        let sealed = (n * std::mem::size_of::<Brick>()) as u64
            + n as u64 * entry_bytes::<u32>() * 8 / 7
            + table_len as u64 * 4;
        charger.add(sorting + sealed)?;
        let mut all: Vec<([i64; 3], Brick)> = Vec::new();
        let ok = all.try_reserve_exact(n).is_ok()
            && self.store.try_reserve_exact(n).is_ok()
            && self.slots.try_reserve(n).is_ok();
        if !ok {
            return Err(charger.refused(sorting + sealed));
        }
        let map_bytes = self.bricks.capacity() as u64 * entry_bytes::<Brick>();
        all.extend(std::mem::take(&mut self.bricks));
        charger.sub(map_bytes);
        if table_len > 0 {
            let dims = dims.map(|d| d as usize);
            let cell = |key: [i64; 3]| {
                let r = [0, 1, 2].map(|a| (key[a] - lo[a]) as usize);
                (r[2] * dims[1] + r[1]) * dims[0] + r[0]
            };
            let mut table = try_vec(table_len, NO_BRICK)
                .ok_or_else(|| charger.refused(table_len as u64 * 4))?;
            // The table first holds each brick's place in `all`; walking its cells in the keys'
            // order (x, then y, then z) stores the bricks as sorting them would, without a sort.
            for (i, (key, _)) in all.iter().enumerate() {
                table[cell(*key)] = i as u32;
            }
            for x in 0..dims[0] {
                for y in 0..dims[1] {
                    for z in 0..dims[2] {
                        let c = (z * dims[1] + y) * dims[0] + x;
                        let i = table[c];
                        if i == NO_BRICK {
                            continue;
                        }
                        let (key, brick) = &mut all[i as usize];
                        let slot = self.store.len() as u32;
                        self.slots.insert(*key, slot);
                        self.store
                            .push(std::mem::replace(brick, Brick::Constant(0.0)));
                        table[c] = slot;
                    }
                }
            }
            drop(all);
            charger.sub(sorting);
            self.table = table;
            self.table_min = lo;
            self.table_dims = dims;
            return Ok(());
        }
        all.sort_unstable_by_key(|(k, _)| *k);
        for (key, brick) in all {
            self.slots.insert(key, self.store.len() as u32);
            self.store.push(brick);
        }
        charger.sub(sorting);
        Ok(())
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

    /// Bytes held by the volume's storage: the brick table and the dense bricks at their
    /// precision (approximate: the table's control bytes and the allocator's overhead are not
    /// counted).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Volume>()
            + self.store.capacity() * std::mem::size_of::<Brick>()
            + self.slots.capacity() * std::mem::size_of::<([i64; 3], u32)>()
            + self.table.capacity() * 4
            + self.store.iter().map(Brick::heap_bytes).sum::<usize>()
            + std::mem::size_of::<[f32; 256]>()
            + self.name.capacity()
            + self.grid_name.capacity()
            + self.plugin.capacity()
    }

    /// Number of (dense, constant) bricks stored (bricks of background voxels are not).
    pub fn brick_counts(&self) -> (usize, usize) {
        let dense = self.store.iter().filter(|b| b.is_dense()).count();
        (dense, self.store.len() - dense)
    }

    /// Number of dense bricks stored as u8, u16 and f32.
    pub fn dense_counts(&self) -> [usize; 3] {
        let mut n = [0; 3];
        for b in &self.store {
            match b {
                Brick::Constant(_) => {}
                Brick::U8(_) => n[0] += 1,
                Brick::U16(_) => n[1] += 1,
                Brick::F32(_) => n[2] += 1,
            }
        }
        n
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

    /// Sealing with a slot table stores the bricks in their keys' order (what the sort gave
    /// before the table walk replaced it), and the table and the map find the same bricks.
    #[test]
    fn sealed_bricks_are_stored_in_key_order() {
        let mut b = builder([-16, -8, 0], [23, 15, 31]);
        // Blocks given in a scrambled order, each brick a different value, some left out.
        let mut keys = Vec::new();
        for x in -2..3i64 {
            for y in -1..2i64 {
                for z in 0..4i64 {
                    if (x + y + z) % 3 != 0 {
                        keys.push([x, y, z]);
                    }
                }
            }
        }
        keys.sort_by_key(|k| (k[2] * 7 + k[0] * 3 + k[1]).rem_euclid(11));
        for k in &keys {
            let mut values = vec![0.0f32; 512];
            values[0] = (k[0] * 100 + k[1] * 10 + k[2]) as f32;
            b.add_dense(k.map(|c| c * 8), [8, 8, 8], &values).unwrap();
        }
        let v = b.finish().unwrap();
        assert!(!v.table.is_empty());
        let mut by_slot: Vec<([i64; 3], u32)> = v.slots.iter().map(|(k, &s)| (*k, s)).collect();
        by_slot.sort_by_key(|&(_, s)| s);
        let stored: Vec<[i64; 3]> = by_slot.iter().map(|&(k, _)| k).collect();
        keys.sort();
        assert_eq!(stored, keys);
        for (k, s) in by_slot {
            assert!(std::ptr::eq(v.brick(k).unwrap(), &v.store[s as usize]));
            let want = (k[0] * 100 + k[1] * 10 + k[2]) as f32;
            assert_eq!(v.value(k.map(|c| c * 8)), want, "{k:?}");
        }
        assert_eq!(v.brick([0, 0, 0]), None);
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
        assert!(matches!(v.brick([1, 0, 0]), Some(Brick::F32(_))));
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
    fn memory_refusals_are_told_apart_from_bad_data() {
        // A dense brick (8³ f32) does not fit a 1000-byte budget.
        let mut b = VolumeBuilder::new("v", "test");
        b.charge_to(std::sync::Arc::new(crate::budget::Budget::new(
            1000,
            "test".into(),
            None,
        )));
        b.begin(IDENTITY, 0.0, [0; 3], [7; 3], "g").unwrap();
        assert!(!b.out_of_memory());
        let e = b.add_dense([0; 3], [8; 3], &[0.5; 512]).unwrap_err();
        assert!(e.contains("memory budget"), "{e}");
        assert!(b.out_of_memory());
        let (_, refused) = b.finish_or_refused().unwrap_err();
        assert!(refused);

        // A voxel outside the grid's box is the data's fault, with memory to spare.
        let mut b = builder([0; 3], [3; 3]);
        b.add_dense([2; 3], [4; 3], &[0.5; 64]).unwrap_err();
        assert!(!b.out_of_memory());
        let (_, refused) = b.finish_or_refused().unwrap_err();
        assert!(!refused);
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

    /// Whether every voxel of `v` in `0..n` on each axis reads `want(ijk)` (same bits).
    fn reads(v: &Volume, n: i64, want: impl Fn([i64; 3]) -> f32) {
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let ijk = [x, y, z];
                    assert_eq!(v.value(ijk).to_bits(), want(ijk).to_bits(), "{ijk:?}");
                }
            }
        }
    }

    fn byte(ijk: [i64; 3]) -> u8 {
        (ijk[0] * 7 + ijk[1] * 31 + ijk[2] * 101) as u8
    }

    #[test]
    fn u8_and_u16_blocks_are_kept_at_their_precision() {
        // Background 0 has the code 0, so partial bricks stay u8 too.
        let mut b = VolumeBuilder::new("v", "test");
        b.begin(IDENTITY, 0.0, [0; 3], [11; 3], "g").unwrap();
        let bytes: Vec<u8> = (0..12 * 12 * 12)
            .map(|i| byte([i % 12, i / 12 % 12, i / 144]))
            .collect();
        b.add_dense_u8([0; 3], [12; 3], &bytes, 255.0).unwrap();
        let v = b.finish().unwrap();
        assert_eq!(v.dense_counts(), [8, 0, 0]);
        reads(&v, 12, |ijk| f32::from(byte(ijk)) / 255.0);
        assert_eq!(v.min_max(), (0.0, 1.0));
        // A byte per voxel: 8 bricks of 512 bytes, not 2 KiB each.
        assert!(v.memory_bytes() < 8 * 2048, "{}", v.memory_bytes());

        let mut b = VolumeBuilder::new("w", "test");
        b.begin(IDENTITY, 0.0, [0; 3], [7; 3], "g").unwrap();
        let words: Vec<u16> = (0..512).map(|i| i * 100).collect();
        b.add_dense_u16([0; 3], [8; 3], &words, 65535.0).unwrap();
        let v = b.finish().unwrap();
        assert_eq!(v.dense_counts(), [0, 1, 0]);
        reads(&v, 8, |ijk| f32::from(words[local_index(ijk)]) / 65535.0);
    }

    #[test]
    fn a_brick_without_a_code_for_the_background_or_given_other_data_becomes_f32() {
        // Background -1 has no u8 code: a partial u8 brick starts as f32, a whole one is u8.
        let mut b = builder([0; 3], [15, 7, 7]);
        b.add_dense_u8(
            [0; 3],
            [8, 8, 8],
            &[3; 511].iter().chain(&[4]).copied().collect::<Vec<_>>(),
            1.0,
        )
        .unwrap();
        b.add_dense_u8([8, 0, 0], [2, 2, 2], &[5; 8], 1.0).unwrap();
        let v = b.finish().unwrap();
        assert_eq!(v.dense_counts(), [1, 0, 1]);
        assert_eq!((v.value([7, 7, 7]), v.value([9, 1, 1])), (4.0, 5.0));
        assert_eq!(v.value([10, 0, 0]), -1.0);

        // Another format or a value without a code promotes a u8 brick, keeping its values;
        // a tile whose value has a code does not.
        let fill = |last: &dyn Fn(&mut VolumeBuilder)| {
            let mut b = VolumeBuilder::new("v", "test");
            b.begin(IDENTITY, 0.0, [0; 3], [7; 3], "g").unwrap();
            b.add_dense_u8([0; 3], [8, 8, 4], &[200; 256], 255.0)
                .unwrap();
            b.add_tile([0, 0, 4], [8, 8, 2], 10.0 / 255.0).unwrap();
            last(&mut b);
            b.finish().unwrap()
        };
        let v = fill(&|_| {});
        assert_eq!(v.dense_counts(), [1, 0, 0]);
        let bg = |ijk: [i64; 3]| match ijk[2] {
            0..4 => 200.0 / 255.0,
            4..6 => 10.0 / 255.0,
            _ => 0.0,
        };
        reads(&v, 8, bg);
        let v = fill(&|b| b.add_tile([0, 0, 6], [8, 8, 1], 0.3).unwrap());
        assert_eq!(v.dense_counts(), [0, 0, 1]);
        reads(&v, 8, |ijk| if ijk[2] == 6 { 0.3 } else { bg(ijk) });
        let v = fill(&|b| b.add_dense([0, 0, 7], [8, 8, 1], &[0.25; 64]).unwrap());
        assert_eq!(v.dense_counts(), [0, 0, 1]);
        reads(&v, 8, |ijk| if ijk[2] == 7 { 0.25 } else { bg(ijk) });
        let v = fill(&|b| {
            b.add_dense_u16([0, 0, 7], [8, 8, 1], &[9; 64], 3.0)
                .unwrap()
        });
        assert_eq!(v.dense_counts(), [0, 0, 1]);
        reads(&v, 8, |ijk| if ijk[2] == 7 { 3.0 } else { bg(ijk) });
    }

    #[test]
    fn typed_bricks_collapse_and_check_their_values() {
        // Complete u8 bricks of one code are constants; of the background's, nothing.
        let mut b = VolumeBuilder::new("v", "test");
        b.begin(IDENTITY, 0.0, [0; 3], [15, 7, 7], "g").unwrap();
        let mut bytes = vec![0u8; 16 * 8 * 8];
        for (i, c) in bytes.iter_mut().enumerate() {
            if i % 16 >= 8 {
                *c = 51;
            }
        }
        for z in 0..8 {
            b.add_dense_u8(
                [0, 0, z],
                [16, 8, 1],
                &bytes[z as usize * 128..][..128],
                255.0,
            )
            .unwrap();
        }
        let v = b.finish().unwrap();
        assert_eq!(v.brick([0, 0, 0]), None);
        assert_eq!(v.brick([1, 0, 0]), Some(&Brick::Constant(0.2)));

        // A divisor so small that a code's value overflows is a non-finite value.
        let mut b = builder([0; 3], [7; 3]);
        let e = b
            .add_dense_u16([0; 3], [2, 1, 1], &[0, 60000], 1e-35)
            .unwrap_err();
        assert!(e.contains("non-finite value inf at voxel [1, 0, 0]"), "{e}");
    }

    /// A block not aligned to bricks: its whole bricks (copied and tested as one array) and its
    /// partial ones read back every voxel; whole bricks of one code become constants (or
    /// nothing, for the background's), in any position of the block.
    #[test]
    fn whole_u8_bricks_of_an_unaligned_block_read_back() {
        let (origin, dims) = ([3i64, 0, 5], [21u64, 16, 11]);
        let mut b = VolumeBuilder::new("v", "test");
        b.begin(IDENTITY, 0.0, [0; 3], [31, 15, 15], "g").unwrap();
        let at = |i: usize| {
            let (x, y, z) = (
                i as u64 % dims[0],
                i as u64 / dims[0] % dims[1],
                i as u64 / 336,
            );
            [x, y, z].map(|c| c as i64)
        };
        // Brick [1, 0, 1] (x 8..15, z 8..15) all 9; brick [1, 1, 1] all 0 (the background);
        // the rest a pattern.
        let code = |ijk: [i64; 3]| match (ijk[0] >> 3, ijk[1] >> 3, ijk[2] >> 3) {
            (1, 0, 1) => 9,
            (1, 1, 1) => 0,
            _ => byte(ijk) | 1,
        };
        let bytes: Vec<u8> = (0..(21 * 16 * 11))
            .map(|i| code([0, 1, 2].map(|a| at(i)[a] + origin[a])))
            .collect();
        b.add_dense_u8(origin, dims, &bytes, 2.0).unwrap();
        let v = b.finish().unwrap();
        assert_eq!(v.brick([1, 0, 1]), Some(&Brick::Constant(4.5)));
        assert_eq!(v.brick([1, 1, 1]), None);
        for (i, &c) in bytes.iter().enumerate() {
            let ijk = [0, 1, 2].map(|a| at(i)[a] + origin[a]);
            assert_eq!(
                v.value(ijk).to_bits(),
                (f32::from(c) / 2.0).to_bits(),
                "{ijk:?}"
            );
        }
        assert_eq!(v.value([0, 0, 0]), 0.0);
        // Whole bricks: x 8..=23, y 0..=15, z 8..=15 (four, two of them collapsed); partial:
        // the eight others the block reaches, kept as u8 (the background has a code).
        assert_eq!(v.dense_counts(), [2 + 8, 0, 0]);
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
