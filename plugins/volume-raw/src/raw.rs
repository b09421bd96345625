//! The `raw` reader: checks its parameters, then reads (or, gzip-compressed, decompresses) the
//! file and hands the host slabs of converted voxels; the format is described in the crate doc.

use luxon_plugin::{finite, invalid, Context, Describe, Error, GridInfo, VolumeOut, VolumeReader};
use serde::{Deserialize, Deserializer};
use std::fs::File;
use std::io::{Cursor, Read, Seek, SeekFrom};
use std::path::Path;

/// The first bytes of every gzip stream.
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// The most voxels read and converted at once (one dense block handed to the host).
const BLOCK_VOXELS: u64 = 1 << 20;

/// Thickness of a slab in z-slices (the host's brick size, so blocks fill whole bricks).
const SLAB: u64 = 8;

/// Type of one voxel in the file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Format {
    #[default]
    U8,
    U16,
    F32,
}

impl Format {
    const NAMES: &'static str = "\"u8\", \"u16\", \"f32\"";

    fn bytes(self) -> u64 {
        match self {
            Format::U8 => 1,
            Format::U16 => 2,
            Format::F32 => 4,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Format::U8 => "u8",
            Format::U16 => "u16",
            Format::F32 => "f32",
        }
    }
}

impl<'de> Deserialize<'de> for Format {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        match s.as_str() {
            "u8" => Ok(Format::U8),
            "u16" => Ok(Format::U16),
            "f32" => Ok(Format::F32),
            other => Err(serde::de::Error::custom(format!(
                "unknown format \"{other}\"; expected one of {}",
                Format::NAMES
            ))),
        }
    }
}

/// Byte order of multi-byte voxels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Endian {
    #[default]
    Little,
    Big,
}

impl<'de> Deserialize<'de> for Endian {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        match s.as_str() {
            "little" => Ok(Endian::Little),
            "big" => Ok(Endian::Big),
            other => Err(serde::de::Error::custom(format!(
                "unknown endian \"{other}\"; expected one of \"little\", \"big\""
            ))),
        }
    }
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct RawParams {
    file: String,
    dims: [u64; 3],
    #[serde(default)]
    format: Format,
    #[serde(default)]
    endian: Endian,
    #[serde(default)]
    header: u64,
    #[serde(default = "ones")]
    spacing: [f64; 3],
    #[serde(default)]
    origin: [f64; 3],
    #[serde(default = "yes")]
    normalize: bool,
}

fn ones() -> [f64; 3] {
    [1.0; 3]
}

fn yes() -> bool {
    true
}

/// The `raw` volume reader.
pub struct Raw;

impl Describe for Raw {
    const NAME: &'static str = "raw";
    const DESCRIPTION: &'static str =
        "A raw array of u8, u16 or f32 voxels, x fastest; gzip-compressed files are read too.";
    const PARAMS: &'static str = "\
file: string = required  the raw file (or gzip of it), relative to the scene file
dims: (x, y, z) = required  voxels along each axis, each >= 1
format: \"u8\" | \"u16\" | \"f32\" = \"u8\"  type of one voxel
endian: \"little\" | \"big\" = \"little\"  byte order of u16 and f32 voxels
header: u64 = 0  bytes to skip at the start of the file
spacing: (sx, sy, sz) = (1, 1, 1)  voxel step in world units, each non-zero (negative: the axis runs backwards)
origin: (x, y, z) = (0, 0, 0)  world position of voxel (0, 0, 0)
normalize: bool = true  u8 / 255 and u16 / 65535 into [0, 1] (f32 kept)";
}

/// "256x256x109".
fn dims_text(d: [u64; 3]) -> String {
    format!("{}x{}x{}", d[0], d[1], d[2])
}

/// Checked parameters: the file's expected size and the grid.
struct Layout {
    dims: [u64; 3],
    format: Format,
    endian: Endian,
    header: u64,
    normalize: bool,
}

impl Layout {
    fn new(p: &RawParams) -> Result<(Layout, u64), Error> {
        let d = p.dims;
        if d.contains(&0) {
            return Err(invalid(format!(
                "parameter `dims` must be at least 1 on every axis, got ({}, {}, {})",
                d[0], d[1], d[2]
            )));
        }
        // The largest index, dims - 1, must fit the host's i64 indices.
        if d.iter().any(|&n| n - 1 > i64::MAX as u64) {
            return Err(invalid(format!(
                "parameter `dims` ({}) is too large for voxel indices",
                dims_text(d)
            )));
        }
        let overflow = || {
            invalid(format!(
                "parameter `dims` is too large: the size of {} {} voxels plus a {}-byte header \
                 overflows 64 bits",
                dims_text(d),
                p.format.name(),
                p.header
            ))
        };
        let size = d[0]
            .checked_mul(d[1])
            .and_then(|n| n.checked_mul(d[2]))
            .and_then(|n| n.checked_mul(p.format.bytes()))
            .and_then(|n| n.checked_add(p.header))
            .ok_or_else(overflow)?;
        let layout = Layout {
            dims: d,
            format: p.format,
            endian: p.endian,
            header: p.header,
            normalize: p.normalize,
        };
        Ok((layout, size))
    }

    /// Converts `raw` (whole voxels of this format) into `out` (normalising by division, so that
    /// `v / 255` is exactly what a reader of the file computes).
    fn convert(&self, raw: &[u8], out: &mut Vec<f32>) {
        out.clear();
        let big = self.endian == Endian::Big;
        match self.format {
            Format::U8 => {
                let scale = if self.normalize { 255.0 } else { 1.0 };
                out.extend(raw.iter().map(|&b| f32::from(b) / scale));
            }
            Format::U16 => {
                let scale = if self.normalize { 65535.0 } else { 1.0 };
                out.extend(raw.chunks_exact(2).map(|c| {
                    let b = [c[0], c[1]];
                    let v = if big {
                        u16::from_be_bytes(b)
                    } else {
                        u16::from_le_bytes(b)
                    };
                    f32::from(v) / scale
                }));
            }
            Format::F32 => {
                out.extend(raw.chunks_exact(4).map(|c| {
                    let b = [c[0], c[1], c[2], c[3]];
                    if big {
                        f32::from_be_bytes(b)
                    } else {
                        f32::from_le_bytes(b)
                    }
                }));
            }
        }
    }
}

/// Block edge lengths `(x, y)` for slabs of [`SLAB`] z-slices, so that a block holds at most
/// `budget` voxels (at least 8x8x8): whole slices when they fit, else whole rows, else parts of
/// rows. Multiples of 8, so blocks fill the host's bricks.
fn block_size(dims: [u64; 3], budget: u64) -> (u64, u64) {
    let [nx, ny, _] = dims;
    let round = |n: u64| (n / 8 * 8).max(8);
    if nx.saturating_mul(SLAB * 8) <= budget {
        let rows = round(budget / (nx * SLAB));
        (nx, ny.min(rows))
    } else {
        (nx.min(round(budget / (SLAB * 8))), ny.min(8))
    }
}

fn open_error(path: &Path, e: std::io::Error) -> Error {
    if e.kind() == std::io::ErrorKind::NotFound {
        let mut gz = path.as_os_str().to_owned();
        gz.push(".gz");
        let hint = if Path::new(&gz).is_file() {
            format!(
                "; `{}` does: name that file (compressed files are read as they are)",
                Path::new(&gz).display()
            )
        } else {
            String::new()
        };
        invalid(format!(
            "volume file `{}` does not exist{hint}",
            path.display()
        ))
    } else {
        invalid(format!("cannot open volume file `{}`: {e}", path.display()))
    }
}

/// Where decoded blocks go: the host (through the plugin ABI) or, for tools, tests and the
/// fuzz targets, anything else.
pub trait Blocks {
    fn begin(&mut self, info: &GridInfo) -> Result<(), Error>;
    /// A dense block, x fastest.
    fn dense(&mut self, origin: [i64; 3], dims: [u64; 3], values: &[f32]) -> Result<(), Error>;
}

impl Blocks for VolumeOut<'_> {
    fn begin(&mut self, info: &GridInfo) -> Result<(), Error> {
        VolumeOut::begin(self, info)
    }

    fn dense(&mut self, origin: [i64; 3], dims: [u64; 3], values: &[f32]) -> Result<(), Error> {
        VolumeOut::dense(self, origin, dims, values)
    }
}

/// Parameters checked, without the file: its expected size and the grid's map.
struct Checked {
    layout: Layout,
    expected: u64,
    spacing: [f64; 3],
    origin: [f64; 3],
}

impl Checked {
    fn new(p: &RawParams) -> Result<Checked, Error> {
        let (layout, expected) = Layout::new(p)?;
        let spacing = finite("spacing", p.spacing)?;
        // A negative step mirrors its axis (Tachyon scenes, mirrored into Luxon's world).
        if spacing.contains(&0.0) {
            return Err(invalid(format!(
                "parameter `spacing` must not be 0 on any axis, got {spacing:?}"
            )));
        }
        let origin = finite("origin", p.origin)?;
        if p.file.trim().is_empty() {
            return Err(invalid(
                "parameter `file` is empty; expected the path of a raw file",
            ));
        }
        Ok(Checked {
            layout,
            expected,
            spacing,
            origin,
        })
    }

    /// The size error, or nothing when `actual` is the expected size.
    fn size(&self, path: &Path, actual: u64) -> Result<(), Error> {
        if actual == self.expected {
            return Ok(());
        }
        let layout = &self.layout;
        Err(invalid(format!(
            "`{}`: expected {} bytes for {} {} voxels plus a {}-byte header, the file has {actual}",
            path.display(),
            self.expected,
            dims_text(layout.dims),
            layout.format.name(),
            layout.header
        )))
    }

    /// The decompressed bytes of a gzip stream, which must be exactly the expected size
    /// (checked without ever holding more than one byte beyond it).
    fn gunzip(&self, source: impl Read, path: &Path) -> Result<Vec<u8>, Error> {
        let (layout, expected) = (&self.layout, self.expected);
        let mut bytes = Vec::new();
        flate2::read::MultiGzDecoder::new(std::io::BufReader::new(source))
            .take(expected.saturating_add(1))
            .read_to_end(&mut bytes)
            .map_err(|e| {
                invalid(format!(
                    "`{}` is gzip-compressed but cannot be decompressed: {e}",
                    path.display()
                ))
            })?;
        if bytes.len() as u64 != expected {
            let actual = if bytes.len() as u64 > expected {
                "more".to_string()
            } else {
                bytes.len().to_string()
            };
            return Err(invalid(format!(
                "`{}` (gzip-compressed): expected {expected} decompressed bytes for {} {} voxels \
                 plus a {}-byte header, it decompresses to {actual}",
                path.display(),
                dims_text(layout.dims),
                layout.format.name(),
                layout.header
            )));
        }
        Ok(bytes)
    }

    /// Announces the grid and streams the voxels of `source` (of the expected size).
    fn decode(
        &self,
        name: String,
        source: &mut (impl Read + Seek),
        path: &Path,
        out: &mut impl Blocks,
        budget: u64,
    ) -> Result<(), Error> {
        let (spacing, origin) = (self.spacing, self.origin);
        out.begin(&GridInfo {
            world_from_index: [
                spacing[0], 0.0, 0.0, origin[0], //
                0.0, spacing[1], 0.0, origin[1], //
                0.0, 0.0, spacing[2], origin[2],
            ],
            background: 0.0,
            index_min: [0; 3],
            index_max: self.layout.dims.map(|n| (n - 1) as i64),
            name,
        })?;
        stream(source, path, &self.layout, out, budget)
    }
}

/// Reads a raw volume held in memory: `params` as in a scene (RON text; `file` only names the
/// grid and messages), `bytes` the file's content. The reader's whole parsing without the
/// plugin ABI or a file, for tools and fuzzing.
pub fn read_bytes(params: &str, bytes: &[u8], out: &mut impl Blocks) -> Result<(), Error> {
    let p: RawParams = luxon_plugin::parse_params(params)?;
    let checked = Checked::new(&p)?;
    let path = Path::new(&p.file);
    if bytes.starts_with(&GZIP_MAGIC) {
        let unzipped = checked.gunzip(bytes, path)?;
        return checked.decode(
            p.file.clone(),
            &mut Cursor::new(unzipped),
            path,
            out,
            BLOCK_VOXELS,
        );
    }
    checked.size(path, bytes.len() as u64)?;
    checked.decode(
        p.file.clone(),
        &mut Cursor::new(bytes),
        path,
        out,
        BLOCK_VOXELS,
    )
}

impl VolumeReader for Raw {
    type Params = RawParams;

    fn read(p: RawParams, ctx: &Context, out: &mut VolumeOut) -> Result<(), Error> {
        let checked = Checked::new(&p)?;
        let path = ctx.resolve(&p.file);
        let mut file = File::open(&path).map_err(|e| open_error(&path, e))?;
        let meta = file
            .metadata()
            .map_err(|e| invalid(format!("cannot read `{}`: {e}", path.display())))?;
        if meta.is_dir() {
            return Err(invalid(format!(
                "volume file `{}` is a directory; expected a raw file",
                path.display()
            )));
        }
        let mut magic = [0u8; 2];
        let gzip = file.read_exact(&mut magic).is_ok() && magic == GZIP_MAGIC;
        file.seek(SeekFrom::Start(0))
            .map_err(|e| invalid(format!("cannot read `{}`: {e}", path.display())))?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_else(|| p.file.clone());
        if gzip {
            let bytes = checked.gunzip(&mut file, &path)?;
            checked.decode(name, &mut Cursor::new(bytes), &path, out, BLOCK_VOXELS)
        } else {
            checked.size(&path, meta.len())?;
            checked.decode(name, &mut file, &path, out, BLOCK_VOXELS)
        }
    }
}

/// Reads the voxels block by block and hands each to the host.
fn stream(
    file: &mut (impl Read + Seek),
    path: &Path,
    layout: &Layout,
    out: &mut impl Blocks,
    budget: u64,
) -> Result<(), Error> {
    let [nx, ny, nz] = layout.dims;
    let bpv = layout.format.bytes();
    let (bx, by) = block_size(layout.dims, budget);
    let mut raw: Vec<u8> = Vec::new();
    let mut values: Vec<f32> = Vec::new();
    let mut position = u64::MAX;
    let read_error =
        |e: std::io::Error| invalid(format!("error reading `{}`: {e}", path.display()));
    for z0 in (0..nz).step_by(SLAB as usize) {
        let dz = SLAB.min(nz - z0);
        for y0 in (0..ny).step_by(by as usize) {
            let dy = by.min(ny - y0);
            for x0 in (0..nx).step_by(bx as usize) {
                let dx = bx.min(nx - x0);
                // At most `budget` voxels (or 8x8x8), so these fit in memory and usize.
                raw.resize((dx * dy * dz * bpv) as usize, 0);
                // Contiguous runs in the file: whole slices' rows at once when a block spans
                // full rows, one row part at a time otherwise.
                let (run, runs_per_slice) = if dx == nx { (dx * dy, 1) } else { (dx, dy) };
                let run_bytes = (run * bpv) as usize;
                let mut chunks = raw.chunks_exact_mut(run_bytes);
                for z in z0..z0 + dz {
                    for r in 0..runs_per_slice {
                        let y = y0 + if runs_per_slice == 1 { 0 } else { r };
                        let offset = layout.header + ((z * ny + y) * nx + x0) * bpv;
                        if position != offset {
                            file.seek(SeekFrom::Start(offset)).map_err(read_error)?;
                        }
                        let chunk = chunks.next().expect("the buffer holds every run");
                        file.read_exact(chunk).map_err(read_error)?;
                        position = offset + run_bytes as u64;
                    }
                }
                layout.convert(&raw, &mut values);
                if layout.format == Format::F32 {
                    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                        let i = i as u64;
                        let ijk = [x0 + i % dx, y0 + i / dx % dy, z0 + i / dx / dy];
                        let offset = layout.header + ((ijk[2] * ny + ijk[1]) * nx + ijk[0]) * bpv;
                        return Err(invalid(format!(
                            "voxel ({}, {}, {}) of `{}` (byte {offset}) is {}; expected finite \
                             values",
                            ijk[0],
                            ijk[1],
                            ijk[2],
                            path.display(),
                            values[i as usize]
                        )));
                    }
                }
                out.dense([x0 as i64, y0 as i64, z0 as i64], [dx, dy, dz], &values)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use luxon_plugin::abi;
    use std::ffi::c_void;
    use std::path::PathBuf;

    /// What the reader sent, as the host would see it.
    #[derive(Default, Debug)]
    struct Got {
        begins: u32,
        world_from_index: [f64; 12],
        background: f32,
        index_max: [i64; 3],
        name: String,
        /// Dense copy of the grid (x fastest), filled from the blocks.
        values: Vec<f32>,
        /// Times each voxel was given.
        given: Vec<u32>,
        blocks: Vec<([i64; 3], [u64; 3])>,
    }

    extern "C" fn begin(
        ctx: *mut c_void,
        desc: *const abi::VolumeDesc,
        _err: *const abi::ErrorSink,
    ) -> abi::Status {
        let g = unsafe { &mut *(ctx as *mut Got) };
        let d = unsafe { &*desc };
        g.begins += 1;
        g.world_from_index = d.world_from_index;
        g.background = d.background;
        assert_eq!(d.index_min, [0; 3]);
        g.index_max = d.index_max;
        g.name = unsafe { d.grid_name.as_str() }.unwrap().to_string();
        let n: i64 = d.index_max.iter().map(|m| m + 1).product();
        g.values = vec![f32::NAN; n as usize];
        g.given = vec![0; n as usize];
        abi::STATUS_OK
    }

    extern "C" fn add_dense(
        ctx: *mut c_void,
        origin: *const [i64; 3],
        dims: *const [u64; 3],
        values: *const f32,
        _err: *const abi::ErrorSink,
    ) -> abi::Status {
        let g = unsafe { &mut *(ctx as *mut Got) };
        let (o, d) = unsafe { (*origin, *dims) };
        g.blocks.push((o, d));
        let n = (d[0] * d[1] * d[2]) as usize;
        let v = unsafe { std::slice::from_raw_parts(values, n) };
        let [sx, sy, _] = g.index_max.map(|m| (m + 1) as usize);
        let mut i = 0;
        for z in 0..d[2] as usize {
            for y in 0..d[1] as usize {
                for x in 0..d[0] as usize {
                    let at =
                        ((o[2] as usize + z) * sy + o[1] as usize + y) * sx + o[0] as usize + x;
                    g.values[at] = v[i];
                    g.given[at] += 1;
                    i += 1;
                }
            }
        }
        abi::STATUS_OK
    }

    extern "C" fn add_tile(
        _ctx: *mut c_void,
        _origin: *const [i64; 3],
        _dims: *const [u64; 3],
        _value: f32,
        _err: *const abi::ErrorSink,
    ) -> abi::Status {
        panic!("the raw reader sends no tiles");
    }

    extern "C" fn set_error(ctx: *mut c_void, message: abi::Str, _line: u32, _col: u32) {
        let e = unsafe { &mut *(ctx as *mut Option<String>) };
        *e = Some(unsafe { message.as_str() }.unwrap().to_string());
    }

    /// Runs the reader through its C entry point, as the host does. A null call context means
    /// "scene directory `.`": the tests give absolute paths.
    fn read(params: &str) -> Result<Got, String> {
        let mut got = Got::default();
        let sink = abi::VolumeSink {
            ctx: &mut got as *mut Got as *mut c_void,
            begin,
            add_dense,
            add_tile,
        };
        let mut message: Option<String> = None;
        let err = abi::ErrorSink {
            ctx: &mut message as *mut Option<String> as *mut c_void,
            set: set_error,
        };
        let status = luxon_plugin::shim::volume_read::<Raw>(
            abi::Str::new(params),
            std::ptr::null(),
            &sink,
            &err,
        );
        match status {
            abi::STATUS_OK => {
                assert_eq!(got.begins, 1);
                assert!(
                    got.given.iter().all(|&n| n == 1),
                    "every voxel exactly once"
                );
                Ok(got)
            }
            _ => Err(message.unwrap_or_default()),
        }
    }

    /// A fresh directory for one test.
    fn temp_dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("luxon-volume-raw-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn write(dir: &Path, name: &str, bytes: &[u8]) -> String {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p.to_str().unwrap().to_string()
    }

    #[test]
    fn u8_normalised_with_spacing_and_origin() {
        let dir = temp_dir("u8");
        let bytes: Vec<u8> = (0..3 * 2 * 2).map(|i| (i * 20) as u8).collect();
        let file = write(&dir, "small.raw", &bytes);
        let got = read(&format!(
            r#"(file: "{file}", dims: (3, 2, 2), spacing: (0.5, 2, 3), origin: (1, -1, 10))"#
        ))
        .unwrap();
        assert_eq!(got.index_max, [2, 1, 1]);
        assert_eq!(
            got.world_from_index,
            [0.5, 0., 0., 1., 0., 2., 0., -1., 0., 0., 3., 10.]
        );
        assert_eq!(got.background, 0.0);
        assert_eq!(got.name, "small.raw");
        let want: Vec<f32> = bytes.iter().map(|&b| b as f32 / 255.0).collect();
        assert_eq!(got.values, want);

        // A negative step runs the axis backwards from `origin`.
        let got = read(&format!(
            r#"(file: "{file}", dims: (3, 2, 2), spacing: (0.5, 2, -3), origin: (1, -1, 10))"#
        ))
        .unwrap();
        assert_eq!(
            got.world_from_index,
            [0.5, 0., 0., 1., 0., 2., 0., -1., 0., 0., -3., 10.]
        );

        let got = read(&format!(
            r#"(file: "{file}", dims: (3, 2, 2), normalize: false)"#
        ))
        .unwrap();
        assert_eq!(got.values[11], 220.0);
        assert_eq!(
            got.world_from_index,
            [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0.]
        );
    }

    #[test]
    fn u16_big_endian() {
        let dir = temp_dir("u16");
        let words: Vec<u16> = (0..4 * 3 * 2).map(|i| i * 2731).collect();
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_be_bytes()).collect();
        let file = write(&dir, "be.raw", &bytes);
        let got = read(&format!(
            r#"(file: "{file}", dims: (4, 3, 2), format: "u16", endian: "big", normalize: false)"#
        ))
        .unwrap();
        let want: Vec<f32> = words.iter().map(|&w| w as f32).collect();
        assert_eq!(got.values, want);
        let got = read(&format!(
            r#"(file: "{file}", dims: (4, 3, 2), format: "u16", endian: "big")"#
        ))
        .unwrap();
        assert_eq!(got.values[23], 23.0 * 2731.0 / 65535.0);
        // Read as little-endian, the same bytes mean something else.
        let got = read(&format!(
            r#"(file: "{file}", dims: (4, 3, 2), format: "u16")"#
        ))
        .unwrap();
        assert_eq!(
            got.values[1],
            u16::from_le_bytes(2731u16.to_be_bytes()) as f32 / 65535.0
        );
    }

    #[test]
    fn f32_with_header_skip_both_byte_orders() {
        let dir = temp_dir("f32");
        let values: Vec<f32> = (0..2 * 2 * 3).map(|i| i as f32 * -1.5 + 0.25).collect();
        let mut le = b"HEADER!".to_vec();
        le.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        let file = write(&dir, "le.raw", &le);
        let got = read(&format!(
            r#"(file: "{file}", dims: (2, 2, 3), format: "f32", header: 7)"#
        ))
        .unwrap();
        // f32 values are kept, normalize or not.
        assert_eq!(got.values, values);
        let mut be = vec![0u8; 16];
        be.extend(values.iter().flat_map(|v| v.to_be_bytes()));
        let file = write(&dir, "be.raw", &be);
        let got = read(&format!(
            r#"(file: "{file}", dims: (2, 2, 3), format: "f32", endian: "big", header: 16, normalize: false)"#
        ))
        .unwrap();
        assert_eq!(got.values, values);
    }

    #[test]
    fn non_finite_f32_is_reported_with_its_voxel() {
        let dir = temp_dir("nan");
        let mut values = [1.0f32; 2 * 3 * 2];
        values[2 * 3 + 2 + 1] = f32::NAN; // voxel (1, 1, 1)
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let file = write(&dir, "nan.raw", &bytes);
        let e = read(&format!(
            r#"(file: "{file}", dims: (2, 3, 2), format: "f32")"#
        ))
        .unwrap_err();
        assert!(e.contains("voxel (1, 1, 1)") && e.contains("NaN"), "{e}");
    }

    #[test]
    fn size_mismatch_says_both_sizes() {
        let dir = temp_dir("size");
        let file = write(&dir, "short.raw", &[0u8; 1000]);
        let e = read(&format!(r#"(file: "{file}", dims: (256, 256, 109))"#)).unwrap_err();
        assert_eq!(
            e,
            format!(
                "`{file}`: expected 7143424 bytes for 256x256x109 u8 voxels plus a 0-byte \
                 header, the file has 1000"
            )
        );
        let e = read(&format!(
            r#"(file: "{file}", dims: (10, 10, 5), format: "u16", header: 2)"#
        ))
        .unwrap_err();
        assert!(
            e.contains("expected 1002 bytes for 10x10x5 u16 voxels plus a 2-byte header, the file has 1000"),
            "{e}"
        );
        // A broken gzip file is recognised and named as such.
        let file = write(&dir, "head.raw.gz", &[0x1f, 0x8b, 8, 0, 0, 0]);
        let e = read(&format!(r#"(file: "{file}", dims: (2, 2, 2))"#)).unwrap_err();
        assert!(
            e.contains("gzip-compressed") && e.contains("cannot be decompressed"),
            "{e}"
        );
    }

    fn gzip(bytes: &[u8]) -> Vec<u8> {
        use std::io::Write;
        let mut z = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        z.write_all(bytes).unwrap();
        z.finish().unwrap()
    }

    #[test]
    fn gzip_files_are_read_transparently_and_size_checked() {
        let dir = temp_dir("gzip");
        let bytes: Vec<u8> = (0..4 * 3 * 2).map(|i| i as u8 * 10).collect();
        let file = write(&dir, "small.raw.gz", &gzip(&bytes));
        let got = read(&format!(
            r#"(file: "{file}", dims: (4, 3, 2), normalize: false)"#
        ))
        .unwrap();
        let want: Vec<f32> = bytes.iter().map(|&b| f32::from(b)).collect();
        assert_eq!(got.values, want);
        // With a header, and under a name without `.gz`.
        let mut with_header = vec![9u8; 3];
        with_header.extend(&bytes);
        let file = write(&dir, "plain-name.raw", &gzip(&with_header));
        let got = read(&format!(
            r#"(file: "{file}", dims: (4, 3, 2), header: 3, normalize: false)"#
        ))
        .unwrap();
        assert_eq!(got.values, want);
        let e = read(&format!(r#"(file: "{file}", dims: (4, 3, 3))"#)).unwrap_err();
        assert!(
            e.contains("expected 36 decompressed bytes") && e.contains("decompresses to 27"),
            "{e}"
        );
        let e = read(&format!(r#"(file: "{file}", dims: (2, 3, 2))"#)).unwrap_err();
        assert!(e.contains("decompresses to more"), "{e}");
    }

    #[test]
    fn missing_file_names_the_resolved_path() {
        let dir = temp_dir("missing");
        let path = dir.join("nope.raw");
        let e = read(&format!(r#"(file: "{}", dims: (1, 1, 1))"#, path.display())).unwrap_err();
        assert_eq!(
            e,
            format!("volume file `{}` does not exist", path.display())
        );
        write(&dir, "nope.raw.gz", &[0x1f, 0x8b]);
        let e = read(&format!(r#"(file: "{}", dims: (1, 1, 1))"#, path.display())).unwrap_err();
        assert!(e.contains("nope.raw.gz` does: name that file"), "{e}");
        // Relative paths resolve against the scene directory (`.` without a call context).
        let e = read(r#"(file: "rel/x.raw", dims: (1, 1, 1))"#).unwrap_err();
        assert!(e.contains("`./rel/x.raw` does not exist"), "{e}");
    }

    #[test]
    fn bad_parameters() {
        let e = read(r#"(file: "x.raw", dims: (1, 1, 1), format: "u32")"#).unwrap_err();
        assert!(
            e.contains("unknown format \"u32\"; expected one of \"u8\", \"u16\", \"f32\""),
            "{e}"
        );
        let e = read(r#"(file: "x.raw", dims: (1, 1, 1), endian: "middle")"#).unwrap_err();
        assert!(e.contains("expected one of \"little\", \"big\""), "{e}");
        let e = read(r#"(file: "x.raw", dims: (4, 0, 1))"#).unwrap_err();
        assert!(e.contains("`dims` must be at least 1"), "{e}");
        let e = read(r#"(file: "x.raw", dims: (4294967296, 4294967296, 2))"#).unwrap_err();
        assert!(e.contains("overflows"), "{e}");
        let e = read(r#"(file: "x.raw", dims: (1, 1, 1), spacing: (1, 0, 1))"#).unwrap_err();
        assert!(e.contains("`spacing` must not be 0"), "{e}");
        let e = read(r#"(file: "x.raw", dims: (1, 1, 1), gzip: true)"#).unwrap_err();
        assert!(e.contains("unknown parameter `gzip`"), "{e}");
        let e = read(r#"(dims: (1, 1, 1))"#).unwrap_err();
        assert!(e.contains("missing parameter `file`"), "{e}");
    }

    /// A recognisable u8 value per voxel.
    fn pattern(x: u64, y: u64, z: u64) -> u8 {
        ((x * 7 + y * 13 + z * 29) % 251) as u8
    }

    fn check_pattern(name: &str, dims: [u64; 3]) -> Got {
        let dir = temp_dir(name);
        let mut bytes = Vec::new();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    bytes.push(pattern(x, y, z));
                }
            }
        }
        let file = write(&dir, "big.raw", &bytes);
        let got = read(&format!(
            r#"(file: "{file}", dims: ({}, {}, {}), normalize: false)"#,
            dims[0], dims[1], dims[2]
        ))
        .unwrap();
        let want: Vec<f32> = bytes.iter().map(|&b| b as f32).collect();
        assert!(got.values == want, "values differ");
        let _ = std::fs::remove_dir_all(&dir);
        got
    }

    #[test]
    fn whole_slabs_of_eight_slices() {
        let got = check_pattern("slabs", [20, 6, 17]);
        assert_eq!(
            got.blocks,
            [
                ([0, 0, 0], [20, 6, 8]),
                ([0, 0, 8], [20, 6, 8]),
                ([0, 0, 16], [20, 6, 1])
            ]
        );
    }

    #[test]
    fn wide_slices_are_split_into_rows_and_row_parts() {
        // 512 x 8 slices of 8: 32768 voxels per slice row block, 256 rows per block.
        let got = check_pattern("rows", [512, 300, 9]);
        assert!(
            got.blocks.contains(&([0, 256, 8], [512, 44, 1])),
            "{:?}",
            got.blocks
        );
        assert!(got
            .blocks
            .iter()
            .all(|(_, d)| d[0] * d[1] * d[2] <= BLOCK_VOXELS));
        let got = check_pattern("parts", [20000, 9, 9]);
        assert!(
            got.blocks.contains(&([16384, 8, 8], [3616, 1, 1])),
            "{:?}",
            got.blocks
        );
        assert!(got
            .blocks
            .iter()
            .all(|(_, d)| d[0] * d[1] * d[2] <= BLOCK_VOXELS));
    }

    /// Collects what `read_bytes` hands over.
    #[derive(Default)]
    struct Collect {
        info: Option<GridInfo>,
        values: Vec<f32>,
    }

    impl Blocks for Collect {
        fn begin(&mut self, info: &GridInfo) -> Result<(), Error> {
            self.info = Some(info.clone());
            Ok(())
        }
        fn dense(&mut self, _: [i64; 3], _: [u64; 3], values: &[f32]) -> Result<(), Error> {
            self.values.extend_from_slice(values);
            Ok(())
        }
    }

    #[test]
    fn read_bytes_decodes_without_a_file_or_the_abi() {
        let params = r#"(file: "b.raw", dims: (3, 1, 1), format: "u16", endian: "big", header: 2)"#;
        let bytes = [b'H', b'D', 0, 0, 0x80, 0x00, 0xff, 0xff];
        let mut got = Collect::default();
        read_bytes(params, &bytes, &mut got).unwrap();
        assert_eq!(got.info.unwrap().index_max, [2, 0, 0]);
        assert_eq!(got.values, [0.0, 32768.0 / 65535.0, 1.0]);
        // The same checks as for a file: size, parameters.
        let e = read_bytes(params, &bytes[..7], &mut Collect::default()).unwrap_err();
        assert!(
            e.message.contains("expected 8 bytes") && e.message.contains("has 7"),
            "{}",
            e.message
        );
        let e = read_bytes(
            "(file: \"x\", dims: (0, 1, 1))",
            &[],
            &mut Collect::default(),
        );
        assert!(e.unwrap_err().message.contains("at least 1"));
        let e = read_bytes("(dims: (1, 1, 1))", &[0], &mut Collect::default());
        assert!(e.unwrap_err().message.contains("missing parameter `file`"));
    }

    #[test]
    fn block_sizes_respect_the_budget() {
        assert_eq!(block_size([256, 256, 109], 1 << 20), (256, 256));
        assert_eq!(block_size([1024, 1024, 8], 1 << 20), (1024, 128));
        assert_eq!(block_size([100_000, 3, 3], 1 << 20), (16384, 3));
        assert_eq!(block_size([u64::MAX, 1, 1], 1 << 20), (16384, 1));
        assert_eq!(block_size([3, 5, 2], 100), (3, 5));
    }

    #[test]
    fn params_doc_lines_have_the_usual_shape() {
        for line in Raw::PARAMS.lines() {
            assert!(line.contains(": ") && line.contains(" = "), "{line}");
        }
    }
}
