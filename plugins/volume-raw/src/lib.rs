//! # luxon-volume-raw: raw voxel arrays for Luxon
//!
//! The `raw` volume reader (`raw.rs`; two procedural ones follow below): a headerless (or
//! fixed-header) array of `x * y * z` scalar voxels, x fastest, then y, then z, as written by
//! most scanners' export tools and used by classic volume-rendering data sets (the Chapel Hill
//! MRI head, the CT engine). Values become `f32`.
//!
//! ## Parameters
//!
//! | name        | type                         | default     | meaning |
//! |-------------|------------------------------|-------------|---------|
//! | `file`      | string                       | required    | the raw file, relative to the scene file's directory (or absolute) |
//! | `dims`      | `(x, y, z)`                  | required    | voxels along each axis, each at least 1 |
//! | `format`    | `"u8"`, `"u16"` or `"f32"`   | `"u8"`      | type of one voxel: unsigned 8 or 16 bits, or IEEE 754 single precision |
//! | `endian`    | `"little"` or `"big"`        | `"little"`  | byte order of `u16` and `f32` voxels (ignored for `u8`) |
//! | `header`    | whole number                 | `0`         | bytes to skip at the start of the file |
//! | `spacing`   | `(sx, sy, sz)`               | `(1, 1, 1)` | size of a voxel in world units along each axis, each non-zero (a negative one runs that axis backwards from `origin`: a mirrored grid) |
//! | `origin`    | `(x, y, z)`                  | `(0, 0, 0)` | world position of voxel `(0, 0, 0)` |
//! | `normalize` | bool                         | `true`      | map `u8` to [0, 1] by dividing by 255 and `u16` by dividing by 65535; `f32` values are always kept as they are |
//!
//! The file must hold exactly `header + x * y * z * bytes per voxel` bytes: anything else is an
//! error stating both sizes, so that wrong `dims` or `format` never read garbage.
//!
//! Voxel `(i, j, k)` is at world position `origin + (i * sx, j * sy, k * sz)` (the index box is
//! `(0, 0, 0)` to `dims - 1`; scale by `spacing`, then translate by `origin`). The background,
//! outside the array, is 0. The grid is named after the file.
//!
//! gzip-compressed files (such as `mri-head-256x256x109-u8.raw.gz`) are read transparently,
//! recognised by their magic bytes whatever their name; `header` and the size check apply to
//! the decompressed bytes (a stream that ends early or goes on is an error stating both sizes).
//!
//! Both kinds are streamed in file order: slabs of 8 z-slices (at most 64 MiB of the file; for
//! wider slices, rows of one slice or parts of a row) are read, converted and handed to the host
//! in blocks of about 1 Mi voxels, so the reader holds at most one slab whatever the file
//! claims. The host stores only what is not background, so an empty volume costs almost nothing.
//!
//! ## Procedural volumes
//!
//! Two more readers compute their grid instead of reading a file; both fill the cube [-1, 1]³
//! with `size`³ voxels (parameter `size`, default 64, 2 to 512):
//!
//! | name      | field |
//! |-----------|-------|
//! | `phantom` | a 3-D CT head phantom after Shepp and Logan: added ellipsoid densities (skull 1, brain 0.2, ventricles 0, small features 0.3) |
//! | `vortex`  | vorticity magnitude of two coaxial vortex rings with rippled Gaussian cores, at most 1 |
//!
//! ## Scene
//!
//! ```ron
//! volumes: [
//!     (
//!         plugin: "raw",
//!         name: "head",
//!         params: (
//!             file: "volumes/mri-head-256x256x109-u8.raw",
//!             dims: (256, 256, 109),
//!             format: "u8",
//!             spacing: (1, 1, 2),
//!             origin: (-128, -128, -109),
//!         ),
//!     ),
//! ],
//! ```

// No unsafe code; only the tests that call the reader's C entry point as the host does need it.
#![cfg_attr(not(test), forbid(unsafe_code))]
#![cfg_attr(test, deny(unsafe_code))]

mod procedural;
mod raw;

pub use procedural::{Phantom, Vortex};
pub use raw::{read_bytes, Blocks, Endian, Format, Raw, RawParams};

luxon_plugin::export!(library: "luxon-volume-raw", volume_readers: [Raw, Phantom, Vortex]);
