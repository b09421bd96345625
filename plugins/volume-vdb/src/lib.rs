//! # luxon-volume-vdb: OpenVDB files for Luxon
//!
//! One volume reader, `vdb`: a float or double grid of an OpenVDB `.vdb` file (smoke, clouds,
//! fire, level sets from Houdini, Blender, EmberGen or OpenVDB itself). The reader is our own
//! (see [`read_grid`], usable without the plugin machinery); it does not link OpenVDB.
//!
//! ## Parameters
//!
//! | name   | type   | default                  | meaning |
//! |--------|--------|--------------------------|---------|
//! | `file` | string | required                 | the `.vdb` file, relative to the scene file's directory (or absolute) |
//! | `grid` | string | the first float grid     | name of the grid to read; an unknown name is an error listing the file's grids |
//!
//! ## What is read
//!
//! - File format versions 222 to 224 (OpenVDB 3 to 12), with or without grid offsets.
//! - Grids of type `float` and `double` (double values become `f32`), saved at full precision
//!   or as half floats (`saveFloatAsHalf`), in OpenVDB's standard 5-4-3 tree.
//! - Every compression OpenVDB writes: blosc (LZ4 inside, byte shuffle), zip (zlib; tested on
//!   chunks only, as Debian's OpenVDB cannot write zip files) and none,
//!   each with or without active-mask compression, and every per-node way of storing inactive
//!   values (background, minus background, one or two other values with a selection mask, or
//!   all values). Inactive voxels keep the value OpenVDB gives them: a fog volume's background,
//!   a level set's plus or minus background.
//! - Leaves, tiles of the internal nodes (8³ and 128³) and of the root (4096³), active or not.
//!   Tiles that hold the background value and are inactive carry no information and are not
//!   sent; everything else reaches the host, so values match OpenVDB's voxel by voxel.
//! - Linear transforms: `UniformScaleMap`, `ScaleMap`, `TranslationMap`,
//!   `UniformScaleTranslateMap`, `ScaleTranslateMap`, `AffineMap` and `UnitaryMap` (rotations,
//!   shears). Voxel `(i, j, k)` is at the world position the map gives for `(i, j, k)`.
//! - Instanced grids (sharing another grid's tree with their own transform).
//!
//! Rejected with an error that says why: files that are not OpenVDB files (signature check),
//! other format versions, grids of any other type (`vec3s`, `bool`, `int32`, points...: the
//! error names the type), frustum transforms, blosc codecs other than LZ4 and bit shuffle, and
//! anything inconsistent in a corrupt or truncated file. The reader never panics and checks
//! every length against the bytes that remain before allocating.
//!
//! The host stores at most 2^34 voxels in a volume's index box, so a grid whose non-background
//! data spans more (e.g. a 4096³ root tile) is refused by the host with a message saying so.
//! The whole file is read into memory.
//!
//! ## Scene
//!
//! ```ron
//! volumes: [
//!     (
//!         plugin: "vdb",
//!         name: "cloud",
//!         params: (
//!             file: "volumes/cloud.vdb",
//!             grid: "density",
//!         ),
//!     ),
//! ],
//! ```
//!
//! `scenes/volumes/cloud.vdb` is a small cloud-like fog volume (48³, half floats) that
//! `scenes/vdb-cloud.ron` renders, gradient shaded and casting its shadow on a floor.
//!
//! ## Tested against OpenVDB
//!
//! The test fixtures (`tests/fixtures/`) are written by OpenVDB itself: `/usr/bin/python3
//! plugins/volume-vdb/tests/fixtures/make_fixtures.py --cloud scenes/volumes/cloud.vdb` (Debian's
//! `python3-openvdb`; `libopenvdb-dev` and `libboost-dev` for the double, uncompressed and
//! mask-less ones). The tests read every fixture voxel by voxel against the values OpenVDB
//! wrote, and every truncation, random corruption, wrong type and name.
//!
//! When `python3-openvdb` is installed (CI installs it), `tests/pyopenvdb_oracle.rs` also asks
//! OpenVDB itself, live, for every fixture's values and active flags on a lattice around its
//! active box and compares them with this reader: 18,309 voxels of 11 grids agree. Without
//! pyopenvdb it says it is skipped.
//!
//! ## Fuzzing
//!
//! The parser has a cargo-fuzz target (`plugins/volume-vdb/fuzz`, seeded with the test
//! fixtures):
//!
//! ```sh
//! mkdir -p /tmp/vdb-corpus && cp plugins/volume-vdb/tests/fixtures/*.vdb /tmp/vdb-corpus/
//! cargo +nightly fuzz run -s none vdb --fuzz-dir plugins/volume-vdb/fuzz /tmp/vdb-corpus \
//!     -- -runs=1000000 -rss_limit_mb=2048 -max_len=32768
//! ```
//!
//! (`-s none`: the crate has no `unsafe`, and without AddressSanitizer it runs ten times more
//! inputs; `-max_len=32768` keeps whole small fixtures. 1.19 million runs over three workers
//! found no crash; an input that ever crashes belongs in `tests/fixtures.rs` as a regression test.)

#![forbid(unsafe_code)]

mod blosc;
mod bytes;
mod file;
mod transform;
mod tree;
mod values;

pub use file::{list_grids, read_grid};
pub use values::half_to_f32;

use luxon_plugin::{export, invalid, Context, Describe, Error, GridInfo, VolumeOut, VolumeReader};
use serde::Deserialize;

/// Why a file could not be read.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum VdbError {
    #[error("not an OpenVDB file: {0}")]
    NotVdb(String),
    #[error(
        "OpenVDB file format version {0} is not supported; expected 222 to 224 (OpenVDB 3 to 12)"
    )]
    Version(u32),
    #[error(
        "the file is truncated: {what} at byte {offset} needs {needed} bytes, {remaining} remain"
    )]
    Truncated {
        offset: usize,
        what: String,
        needed: usize,
        remaining: usize,
    },
    #[error("corrupt file at byte {offset}: {message}")]
    Corrupt { offset: usize, message: String },
    #[error("{0}")]
    Unsupported(String),
    #[error("no grid named `{name}`: {listing}")]
    GridNotFound { name: String, listing: String },
    #[error("no float or double grid to read: {listing}")]
    NoScalarGrid { listing: String },
    #[error(
        "grid `{name}` has type {value_type} ({type_name}); only float and double grids can be \
         read as volumes"
    )]
    WrongType {
        name: String,
        value_type: String,
        type_name: String,
    },
}

/// A grid's name and type as the file lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct GridEntry {
    pub name: String,
    /// OpenVDB's tree type name, e.g. `Tree_float_5_4_3_HalfFloat`.
    pub type_name: String,
}

/// A float or double grid, values as `f32`.
#[derive(Clone, Debug)]
pub struct Grid {
    pub name: String,
    /// `"float"` or `"double"`.
    pub value_type: &'static str,
    /// Saved as half floats.
    pub half: bool,
    /// The `class` metadata: "fog volume", "level set", "unknown"...
    pub class: String,
    /// The transform's map type, e.g. `UniformScaleMap`.
    pub map: String,
    /// Row-major 3x4 affine map from voxel index to world space.
    pub world_from_index: [f64; 12],
    pub background: f32,
    pub leaves: Vec<Leaf>,
    /// Tiles that are active or hold a value other than the background.
    pub tiles: Vec<Tile>,
}

/// An 8³ leaf.
#[derive(Clone, Debug)]
pub struct Leaf {
    /// Index of voxel (0, 0, 0) of the leaf (a multiple of 8).
    pub origin: [i32; 3],
    /// Voxel `(x, y, z)` of the leaf is element `x + 8y + 64z`.
    pub values: Box<[f32; 512]>,
    /// Active flags, bit `x + 8y + 64z`.
    pub active: [u64; 8],
}

/// A constant cube of `size³` voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tile {
    pub origin: [i32; 3],
    /// Edge length: 8, 128 (internal node tiles) or 4096 (root tiles).
    pub size: u32,
    pub value: f32,
    pub active: bool,
}

impl Grid {
    /// The value and active flag of voxel `ijk`, as OpenVDB's accessor reports them.
    pub fn value(&self, ijk: [i32; 3]) -> (f32, bool) {
        for leaf in &self.leaves {
            if (0..3).all(|a| ijk[a] >= leaf.origin[a] && ijk[a] - leaf.origin[a] < 8) {
                let [x, y, z] = [0, 1, 2].map(|a| (ijk[a] - leaf.origin[a]) as usize);
                let i = x + 8 * y + 64 * z;
                return (leaf.values[i], leaf.active[i >> 6] >> (i & 63) & 1 != 0);
            }
        }
        for t in &self.tiles {
            if (0..3).all(|a| {
                let d = i64::from(ijk[a]) - i64::from(t.origin[a]);
                (0..i64::from(t.size)).contains(&d)
            }) {
                return (t.value, t.active);
            }
        }
        (self.background, false)
    }

    /// Number of active voxels (leaf voxels and tile voxels).
    pub fn active_voxel_count(&self) -> u64 {
        let leaves: u64 = self
            .leaves
            .iter()
            .map(|l| {
                l.active
                    .iter()
                    .map(|w| u64::from(w.count_ones()))
                    .sum::<u64>()
            })
            .sum();
        let tiles: u64 = self
            .tiles
            .iter()
            .filter(|t| t.active)
            .map(|t| u64::from(t.size).pow(3))
            .sum();
        leaves + tiles
    }

    /// Inclusive index box of everything the grid holds besides the background (leaves and
    /// tiles), `None` when it holds nothing.
    pub fn index_box(&self) -> Option<([i64; 3], [i64; 3])> {
        let boxes = self
            .leaves
            .iter()
            .map(|l| (l.origin, 8u32))
            .chain(self.tiles.iter().map(|t| (t.origin, t.size)));
        let mut out: Option<([i64; 3], [i64; 3])> = None;
        for (o, size) in boxes {
            let lo = o.map(i64::from);
            let hi = lo.map(|c| c + i64::from(size) - 1);
            out = Some(match out {
                None => (lo, hi),
                Some((a, b)) => (
                    [0, 1, 2].map(|i| a[i].min(lo[i])),
                    [0, 1, 2].map(|i| b[i].max(hi[i])),
                ),
            });
        }
        out
    }
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct VdbParams {
    file: String,
    #[serde(default)]
    grid: Option<String>,
}

/// The `vdb` volume reader.
pub struct Vdb;

impl Describe for Vdb {
    const NAME: &'static str = "vdb";
    const DESCRIPTION: &'static str =
        "A float or double grid of an OpenVDB file (blosc, zip or uncompressed; half floats).";
    const PARAMS: &'static str = "\
file: string = required  the .vdb file, relative to the scene file
grid: string = first float grid  name of the grid to read";
}

impl VolumeReader for Vdb {
    type Params = VdbParams;

    fn read(p: VdbParams, ctx: &Context, out: &mut VolumeOut) -> Result<(), Error> {
        if p.file.trim().is_empty() {
            return Err(invalid(
                "parameter `file` is empty; expected the path of a .vdb file",
            ));
        }
        let path = ctx.resolve(&p.file);
        let bytes = std::fs::read(&path).map_err(|e| {
            if e.kind() == std::io::ErrorKind::NotFound {
                invalid(format!("volume file `{}` does not exist", path.display()))
            } else {
                invalid(format!("cannot read volume file `{}`: {e}", path.display()))
            }
        })?;
        let grid = read_grid(&bytes, p.grid.as_deref())
            .map_err(|e| invalid(format!("`{}`: {e}", path.display())))?;
        drop(bytes);
        send(&grid, out)
    }
}

/// Hands a grid to the host: its description, then every leaf as a dense 8³ block and every
/// tile as a constant cube.
fn send(grid: &Grid, out: &mut VolumeOut) -> Result<(), Error> {
    let (index_min, index_max) = grid.index_box().unwrap_or(([0; 3], [0; 3]));
    out.begin(&GridInfo {
        world_from_index: grid.world_from_index,
        background: grid.background,
        index_min,
        index_max,
        name: grid.name.clone(),
    })?;
    for leaf in &grid.leaves {
        out.dense(leaf.origin.map(i64::from), [8; 3], &leaf.values[..])?;
    }
    for t in &grid.tiles {
        let s = u64::from(t.size);
        out.tile(t.origin.map(i64::from), [s; 3], t.value)?;
    }
    Ok(())
}

export!(library: "luxon-volume-vdb", volume_readers: [Vdb]);
