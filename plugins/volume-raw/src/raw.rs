//! The `raw` reader: checks its parameters, then streams the file (decompressing it when it is
//! gzip) and hands the host blocks of converted voxels; the format is described in the crate
//! doc.

use luxon_plugin::{finite, invalid, Context, Describe, Error, GridInfo, VolumeOut, VolumeReader};
use serde::{Deserialize, Deserializer};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
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

    /// The divisor of integer voxels: the format's largest value when normalising (so that
    /// `v / 255` is exactly what a reader of the file computes), else 1.
    fn divisor(&self) -> f32 {
        match (self.format, self.normalize) {
            (Format::U8, true) => 255.0,
            (Format::U16, true) => 65535.0,
            _ => 1.0,
        }
    }

    /// Converts `raw` (whole u16 voxels in the file's byte order) into native words.
    fn words(&self, raw: &[u8], out: &mut Vec<u16>) {
        out.clear();
        let big = self.endian == Endian::Big;
        out.extend(raw.chunks_exact(2).map(|c| {
            let b = [c[0], c[1]];
            if big {
                u16::from_be_bytes(b)
            } else {
                u16::from_le_bytes(b)
            }
        }));
    }

    /// Converts `raw` (whole f32 voxels in the file's byte order) into `out`.
    fn floats(&self, raw: &[u8], out: &mut Vec<f32>) {
        out.clear();
        let big = self.endian == Endian::Big;
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

    /// A dense block of bytes, voxel value `byte as f32 / divisor` (by default converted and
    /// given to [`dense`](Self::dense); the host keeps the bytes).
    fn dense_u8(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[u8],
        divisor: f32,
    ) -> Result<(), Error> {
        let values: Vec<f32> = values.iter().map(|&v| f32::from(v) / divisor).collect();
        self.dense(origin, dims, &values)
    }

    /// A dense block of `u16` (native byte order), voxel value `v as f32 / divisor`.
    fn dense_u16(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[u16],
        divisor: f32,
    ) -> Result<(), Error> {
        let values: Vec<f32> = values.iter().map(|&v| f32::from(v) / divisor).collect();
        self.dense(origin, dims, &values)
    }
}

impl Blocks for VolumeOut<'_> {
    fn begin(&mut self, info: &GridInfo) -> Result<(), Error> {
        VolumeOut::begin(self, info)
    }

    fn dense(&mut self, origin: [i64; 3], dims: [u64; 3], values: &[f32]) -> Result<(), Error> {
        VolumeOut::dense(self, origin, dims, values)
    }

    fn dense_u8(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[u8],
        divisor: f32,
    ) -> Result<(), Error> {
        VolumeOut::dense_u8(self, origin, dims, values, divisor)
    }

    fn dense_u16(
        &mut self,
        origin: [i64; 3],
        dims: [u64; 3],
        values: &[u16],
        divisor: f32,
    ) -> Result<(), Error> {
        VolumeOut::dense_u16(self, origin, dims, values, divisor)
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
        Err(self.size_error(path, &actual.to_string()))
    }

    fn size_error(&self, path: &Path, actual: &str) -> Error {
        let layout = &self.layout;
        invalid(format!(
            "`{}`: expected {} bytes for {} {} voxels plus a {}-byte header, the file has {actual}",
            path.display(),
            self.expected,
            dims_text(layout.dims),
            layout.format.name(),
            layout.header
        ))
    }

    /// Announces the grid and streams the voxels of `input` (the file's bytes, decompressed).
    fn decode(
        &self,
        name: String,
        input: &mut Input,
        out: &mut impl Blocks,
        sizes: Sizes,
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
        stream(input, &self.layout, out, sizes)?;
        input.at_end()
    }
}

/// The file's bytes (decompressed when it is gzip), read in order, with the size rules: a
/// stream that ends early or goes on too long is an error stating both sizes.
struct Input<'a> {
    reader: Box<dyn Read + Send + 'a>,
    path: &'a Path,
    checked: &'a Checked,
    gzip: bool,
    /// Bytes read so far.
    consumed: u64,
}

impl<'a> Input<'a> {
    fn new(
        source: impl Read + Send + 'a,
        gzip: bool,
        path: &'a Path,
        checked: &'a Checked,
    ) -> Self {
        let reader: Box<dyn Read + Send + 'a> = if gzip {
            Box::new(flate2::read::MultiGzDecoder::new(std::io::BufReader::new(
                source,
            )))
        } else {
            Box::new(source)
        };
        Input {
            reader,
            path,
            checked,
            gzip,
            consumed: 0,
        }
    }

    /// Fills `buf` with the next bytes.
    fn fill(&mut self, buf: &mut [u8]) -> Result<(), Error> {
        let mut got = 0;
        while got < buf.len() {
            match self.reader.read(&mut buf[got..]) {
                Ok(0) => return Err(self.wrong_size((self.consumed + got as u64).to_string())),
                Ok(n) => got += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(self.read_error(e)),
            }
        }
        self.consumed += got as u64;
        Ok(())
    }

    /// Reads and drops `n` bytes (the header).
    fn skip(&mut self, n: u64) -> Result<(), Error> {
        let mut scratch = vec![0u8; n.min(64 << 10) as usize];
        let mut left = n;
        while left > 0 {
            let k = left.min(scratch.len() as u64) as usize;
            self.fill(&mut scratch[..k])?;
            left -= k as u64;
        }
        Ok(())
    }

    /// After the last voxel: one more byte means the file is longer than the grid.
    fn at_end(&mut self) -> Result<(), Error> {
        let mut one = [0u8; 1];
        loop {
            match self.reader.read(&mut one) {
                Ok(0) => return Ok(()),
                Ok(_) => return Err(self.wrong_size("more".into())),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(self.read_error(e)),
            }
        }
    }

    fn read_error(&self, e: std::io::Error) -> Error {
        if self.gzip {
            invalid(format!(
                "`{}` is gzip-compressed but cannot be decompressed: {e}",
                self.path.display()
            ))
        } else {
            invalid(format!("error reading `{}`: {e}", self.path.display()))
        }
    }

    fn wrong_size(&self, actual: String) -> Error {
        if !self.gzip {
            // Checked before reading: the file changed while it was read.
            return self.checked.size_error(self.path, &actual);
        }
        let layout = &self.checked.layout;
        invalid(format!(
            "`{}` (gzip-compressed): expected {} decompressed bytes for {} {} voxels plus a \
             {}-byte header, it decompresses to {actual}",
            self.path.display(),
            self.checked.expected,
            dims_text(layout.dims),
            layout.format.name(),
            layout.header
        ))
    }
}

/// Reads a raw volume held in memory: `params` as in a scene (RON text; `file` only names the
/// grid and messages), `bytes` the file's content. The reader's whole parsing without the
/// plugin ABI or a file, for tools and fuzzing.
pub fn read_bytes(params: &str, bytes: &[u8], out: &mut impl Blocks) -> Result<(), Error> {
    read_bytes_in(params, bytes, out, Sizes::DEFAULT)
}

fn read_bytes_in(
    params: &str,
    bytes: &[u8],
    out: &mut impl Blocks,
    sizes: Sizes,
) -> Result<(), Error> {
    let p: RawParams = luxon_plugin::parse_params(params)?;
    let checked = Checked::new(&p)?;
    let path = Path::new(&p.file);
    let gzip = bytes.starts_with(&GZIP_MAGIC);
    if !gzip {
        checked.size(path, bytes.len() as u64)?;
    }
    let mut input = Input::new(bytes, gzip, path, &checked);
    checked.decode(p.file.clone(), &mut input, out, sizes)
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
        if !gzip {
            checked.size(&path, meta.len())?;
        }
        let mut input = Input::new(file, gzip, &path, &checked);
        checked.decode(name, &mut input, out, Sizes::within(ctx.memory_budget))
    }
}

/// How much is read and handed over at once (smaller in tests, to reach every case).
#[derive(Clone, Copy)]
struct Sizes {
    /// The most bytes of the file held at once: a slab of [`SLAB`] slices when it fits, else
    /// whole rows of one slice, else parts of one row (bricks then fill up over several blocks).
    slab_bytes: u64,
    /// The most voxels in one block handed to the host.
    block_voxels: u64,
}

impl Sizes {
    const DEFAULT: Sizes = Sizes {
        slab_bytes: 64 << 20,
        block_voxels: BLOCK_VOXELS,
    };

    /// The default sizes, with slabs of at most a quarter of the memory budget the host gave
    /// (0: none given): a tighter budget reads rows or parts of rows instead.
    fn within(memory_budget: u64) -> Sizes {
        let mut s = Sizes::DEFAULT;
        if memory_budget > 0 {
            s.slab_bytes = s.slab_bytes.min(memory_budget / 4);
        }
        s
    }
}

/// A buffer of `n` bytes, or an error naming what needed it (never an abort).
fn buffer(n: u64, what: impl FnOnce() -> String) -> Result<Vec<u8>, Error> {
    let mut v = Vec::new();
    usize::try_from(n)
        .ok()
        .and_then(|n| v.try_reserve_exact(n).ok().map(|()| n))
        .map(|n| {
            v.resize(n, 0);
            v
        })
        .ok_or_else(|| {
            invalid(format!(
                "{} needs {n} bytes, which do not fit in memory",
                what()
            ))
        })
}

/// Reads the voxels in file order, a piece at a time, and hands the host blocks of at most
/// `sizes.block_voxels` voxels. Nothing seeks, so gzip streams and plain files take one path,
/// and memory stays bounded whatever the file (or its decompression) claims.
fn stream(
    input: &mut Input,
    layout: &Layout,
    out: &mut impl Blocks,
    sizes: Sizes,
) -> Result<(), Error> {
    let Sizes {
        slab_bytes: max_slab,
        block_voxels,
    } = sizes;
    let [nx, ny, nz] = layout.dims;
    let bpv = layout.format.bytes();
    input.skip(layout.header)?;
    let path = input.path;
    let (mut floats, mut words) = (Vec::new(), Vec::new());
    let divisor = layout.divisor();
    // Integer voxels go to the host as they are (it stores them at their precision).
    let mut send = |raw: &[u8], origin: [u64; 3], dims: [u64; 3]| -> Result<(), Error> {
        let at = origin.map(|c| c as i64);
        match layout.format {
            Format::U8 => out.dense_u8(at, dims, raw, divisor),
            Format::U16 => {
                layout.words(raw, &mut words);
                out.dense_u16(at, dims, &words, divisor)
            }
            Format::F32 => {
                layout.floats(raw, &mut floats);
                check_finite(&floats, origin, dims, layout, path)?;
                out.dense(at, dims, &floats)
            }
        }
    };
    let slab_bytes = nx.saturating_mul(ny).saturating_mul(SLAB * bpv);
    if slab_bytes <= max_slab {
        let (bx, by) = block_size(layout.dims, block_voxels);
        let mut raw: Vec<u8> = Vec::new();
        // One slab buffer for the whole file (two when the next slab is read ahead): a fresh
        // one per slab was zeroed and, above malloc's mmap threshold, mapped and faulted in
        // again every time.
        let full = SLAB.min(nz);
        let slab_buffer = || {
            buffer(nx * ny * full * bpv, || {
                format!(
                    "a slab of {full} slices of {nx}x{ny} {} voxels",
                    layout.format.name()
                )
            })
        };
        let slabs = (0..nz).step_by(SLAB as usize).map(|z0| {
            let dz = SLAB.min(nz - z0);
            (z0, dz, (nx * ny * dz * bpv) as usize)
        });
        let mut each = |(z0, dz): (u64, u64), slab: &[u8]| -> Result<(), Error> {
            if bx == nx && by == ny {
                // One block is the whole slab, in file order already: no copy.
                return send(slab, [0, 0, z0], [nx, ny, dz]);
            }
            for y0 in (0..ny).step_by(by as usize) {
                let dy = by.min(ny - y0);
                for x0 in (0..nx).step_by(bx as usize) {
                    let dx = bx.min(nx - x0);
                    raw.clear();
                    for z in 0..dz {
                        for y in y0..y0 + dy {
                            let at = (((z * ny + y) * nx + x0) * bpv) as usize;
                            raw.extend_from_slice(&slab[at..at + (dx * bpv) as usize]);
                        }
                    }
                    send(&raw, [x0, y0, z0], [dx, dy, dz])?;
                }
            }
            Ok(())
        };
        if nz > SLAB && slab_bytes.saturating_mul(2) <= max_slab {
            read_ahead(input, slabs, [slab_buffer()?, slab_buffer()?], each)?;
        } else {
            let mut buf = slab_buffer()?;
            for (z0, dz, n) in slabs {
                input.fill(&mut buf[..n])?;
                each((z0, dz), &buf[..n])?;
            }
        }
    } else if nx <= block_voxels {
        // Rows of one slice (a multiple of 8 when more than 8 fit).
        let rows = block_voxels / nx;
        let rows = if rows >= 8 { rows / 8 * 8 } else { rows };
        let mut raw = Vec::new();
        for z in 0..nz {
            for y0 in (0..ny).step_by(rows as usize) {
                let dy = rows.min(ny - y0);
                raw.resize((nx * dy * bpv) as usize, 0);
                input.fill(&mut raw)?;
                send(&raw, [0, y0, z], [nx, dy, 1])?;
            }
        }
    } else {
        let mut raw = Vec::new();
        for z in 0..nz {
            for y in 0..ny {
                for x0 in (0..nx).step_by(block_voxels as usize) {
                    let dx = block_voxels.min(nx - x0);
                    raw.resize((dx * bpv) as usize, 0);
                    input.fill(&mut raw)?;
                    send(&raw, [x0, y, z], [dx, 1, 1])?;
                }
            }
        }
    }
    Ok(())
}

/// Reads the slabs `(z0, dz, bytes)` of `slabs` in order on a second thread, each into whichever
/// of `buffers` the host has done with, while `each` hands the one before to the host: the
/// file's reading (or decompression) overlaps the host's bricking. Slabs reach `each` in file
/// order, and the first error (reading or the host's) is returned.
fn read_ahead(
    input: &mut Input,
    slabs: impl Iterator<Item = (u64, u64, usize)> + Clone + Send,
    buffers: [Vec<u8>; 2],
    mut each: impl FnMut((u64, u64), &[u8]) -> Result<(), Error>,
) -> Result<(), Error> {
    use std::sync::mpsc::sync_channel;
    std::thread::scope(|s| {
        let (full_tx, full_rx) = sync_channel::<Result<Vec<u8>, Error>>(1);
        let (empty_tx, empty_rx) = sync_channel::<Vec<u8>>(2);
        for b in buffers {
            // The receiver lives until the reading thread ends, which needs a buffer first.
            let _ = empty_tx.send(b);
        }
        let sizes = slabs.clone().map(|(_, _, n)| n);
        s.spawn(move || {
            for n in sizes {
                // The host stopped (an error): nothing more to read.
                let Ok(mut b) = empty_rx.recv() else { return };
                let read = input.fill(&mut b[..n]).map(|()| b);
                let failed = read.is_err();
                if full_tx.send(read).is_err() || failed {
                    return;
                }
            }
        });
        for (z0, dz, n) in slabs {
            let b = full_rx
                .recv()
                .map_err(|_| invalid("the thread reading the volume file stopped"))??;
            each((z0, dz), &b[..n])?;
            // The reading thread may have stopped after its last slab.
            let _ = empty_tx.send(b);
        }
        Ok(())
    })
}

/// f32 files may hold NaN or infinities: the first one is an error naming its voxel and byte.
fn check_finite(
    values: &[f32],
    origin: [u64; 3],
    dims: [u64; 3],
    layout: &Layout,
    path: &Path,
) -> Result<(), Error> {
    let Some(i) = values.iter().position(|v| !v.is_finite()) else {
        return Ok(());
    };
    let [nx, ny, _] = layout.dims;
    let [dx, dy, _] = dims;
    let k = i as u64;
    let ijk = [
        origin[0] + k % dx,
        origin[1] + k / dx % dy,
        origin[2] + k / dx / dy,
    ];
    let offset = layout.header + ((ijk[2] * ny + ijk[1]) * nx + ijk[0]) * layout.format.bytes();
    Err(invalid(format!(
        "voxel ({}, {}, {}) of `{}` (byte {offset}) is {}; expected finite values",
        ijk[0],
        ijk[1],
        ijk[2],
        path.display(),
        values[i]
    )))
}

#[cfg(test)]
#[allow(unsafe_code)] // drives the reader through its C entry point, as the host does
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
        /// Format and divisor of each typed block.
        divisors: Vec<(u32, f32)>,
    }

    // The sink below stands in for the host's. The reader calls it during `read`, on the test's
    // thread and one call at a time (ABI contract), with the `ctx` put in the sink: the `Got`
    // that `read` owns and does not touch until the reader returns; every other pointer is
    // valid for the call.

    /// # Safety
    /// See the comment above.
    unsafe extern "C" fn begin(
        ctx: *mut c_void,
        desc: *const abi::VolumeDesc,
        _err: *const abi::ErrorSink,
    ) -> abi::Status {
        // SAFETY: see the comment above.
        let (g, d) = unsafe { (&mut *(ctx as *mut Got), &*desc) };
        g.begins += 1;
        g.world_from_index = d.world_from_index;
        g.background = d.background;
        assert_eq!(d.index_min, [0; 3]);
        g.index_max = d.index_max;
        // SAFETY: see the comment above.
        g.name = unsafe { d.grid_name.as_str() }.unwrap().to_string();
        let n: i64 = d.index_max.iter().map(|m| m + 1).product();
        g.values = vec![f32::NAN; n as usize];
        g.given = vec![0; n as usize];
        abi::STATUS_OK
    }

    impl Got {
        /// Stores a block's values (x fastest) in the dense copy.
        fn put(&mut self, o: [i64; 3], d: [u64; 3], value: impl Fn(usize) -> f32) {
            self.blocks.push((o, d));
            let [sx, sy, _] = self.index_max.map(|m| (m + 1) as usize);
            let mut i = 0;
            for z in 0..d[2] as usize {
                for y in 0..d[1] as usize {
                    for x in 0..d[0] as usize {
                        let at =
                            ((o[2] as usize + z) * sy + o[1] as usize + y) * sx + o[0] as usize + x;
                        self.values[at] = value(i);
                        self.given[at] += 1;
                        i += 1;
                    }
                }
            }
        }
    }

    /// # Safety
    /// See the comment above `begin`; `values` holds `dims[0] * dims[1] * dims[2]` values.
    unsafe extern "C" fn add_dense(
        ctx: *mut c_void,
        origin: *const [i64; 3],
        dims: *const [u64; 3],
        values: *const f32,
        _err: *const abi::ErrorSink,
    ) -> abi::Status {
        // SAFETY: see the comment above `begin`.
        let (g, o, d) = unsafe { (&mut *(ctx as *mut Got), *origin, *dims) };
        let n = (d[0] * d[1] * d[2]) as usize;
        // SAFETY: the reader's promise: `n` values, borrowed for the call.
        let v = unsafe { std::slice::from_raw_parts(values, n) };
        g.put(o, d, |i| v[i]);
        abi::STATUS_OK
    }

    /// # Safety
    /// See the comment above `begin`; `data` holds `len` bytes: `dims[0] * dims[1] * dims[2]`
    /// voxels of `format`, aligned for it.
    #[allow(clippy::too_many_arguments)]
    unsafe extern "C" fn add_dense_typed(
        ctx: *mut c_void,
        origin: *const [i64; 3],
        dims: *const [u64; 3],
        format: u32,
        data: *const u8,
        len: usize,
        divisor: f32,
        _err: *const abi::ErrorSink,
    ) -> abi::Status {
        // SAFETY: see the comment above `begin`.
        let (g, o, d) = unsafe { (&mut *(ctx as *mut Got), *origin, *dims) };
        let n = (d[0] * d[1] * d[2]) as usize;
        g.divisors.push((format, divisor));
        match format {
            abi::VOXEL_U8 => {
                assert_eq!(len, n);
                // SAFETY: the reader's promise: `n` bytes, borrowed for the call.
                let v = unsafe { std::slice::from_raw_parts(data, n) };
                g.put(o, d, |i| f32::from(v[i]) / divisor);
            }
            abi::VOXEL_U16 => {
                assert_eq!(len, 2 * n);
                // SAFETY: the reader's promise: `n` aligned u16, borrowed for the call.
                let v = unsafe { std::slice::from_raw_parts(data as *const u16, n) };
                g.put(o, d, |i| f32::from(v[i]) / divisor);
            }
            other => panic!("the raw reader sends f32 through `add_dense`, not format {other}"),
        }
        abi::STATUS_OK
    }

    /// # Safety
    /// Nothing to promise: it only panics (the raw reader must not call it).
    unsafe extern "C" fn add_tile(
        _ctx: *mut c_void,
        _origin: *const [i64; 3],
        _dims: *const [u64; 3],
        _value: f32,
        _err: *const abi::ErrorSink,
    ) -> abi::Status {
        panic!("the raw reader sends no tiles");
    }

    /// # Safety
    /// `ctx` is the message slot of the running `read`; `message` is readable for the call.
    unsafe extern "C" fn set_error(ctx: *mut c_void, message: abi::Str, _line: u32, _col: u32) {
        // SAFETY: the caller's promise; `read` does not touch the slot until the call returns.
        let (e, message) = unsafe { (&mut *(ctx as *mut Option<String>), message.as_str()) };
        *e = Some(message.unwrap().to_string());
    }

    /// Runs the reader through its C entry point, as the host does. A null call context means
    /// "scene directory `.`": the tests give absolute paths.
    fn read(params: &str) -> Result<Got, String> {
        let mut got = Got::default();
        let sink = abi::VolumeSink {
            ctx: &mut got as *mut Got as *mut c_void,
            begin,
            add_dense,
            add_dense_typed,
            add_tile,
        };
        let mut message: Option<String> = None;
        let err = abi::ErrorSink {
            ctx: &mut message as *mut Option<String> as *mut c_void,
            set: set_error,
        };
        // SAFETY: the calling contract: `params`, `sink` and `err` live across the call (a
        // null context is allowed), and `got` and `message` are only reached through them
        // until it returns.
        let status = unsafe {
            luxon_plugin::shim::volume_read::<Raw>(
                abi::Str::new(params),
                std::ptr::null(),
                &sink,
                &err,
            )
        };
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

    /// A fresh directory for one test, removed when dropped.
    struct TempDir(PathBuf);

    impl std::ops::Deref for TempDir {
        type Target = Path;

        fn deref(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn temp_dir(name: &str) -> TempDir {
        let d =
            std::env::temp_dir().join(format!("luxon-volume-raw-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        TempDir(d)
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
        // The bytes go to the host as they are, with the divisor that normalises them.
        assert_eq!(got.divisors, [(abi::VOXEL_U8, 255.0)]);

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
        assert_eq!(got.divisors, [(abi::VOXEL_U8, 1.0)]);
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
        assert_eq!(got.divisors, [(abi::VOXEL_U16, 1.0)]);
        let got = read(&format!(
            r#"(file: "{file}", dims: (4, 3, 2), format: "u16", endian: "big")"#
        ))
        .unwrap();
        assert_eq!(got.values[23], 23.0 * 2731.0 / 65535.0);
        assert_eq!(got.divisors, [(abi::VOXEL_U16, 65535.0)]);
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

    /// Every voxel of the grid, and how often each was given (checked once per voxel).
    #[derive(Default)]
    struct Grid {
        dims: [u64; 3],
        values: Vec<f32>,
        given: Vec<u8>,
        blocks: Vec<([i64; 3], [u64; 3])>,
    }

    impl Blocks for Grid {
        fn begin(&mut self, info: &GridInfo) -> Result<(), Error> {
            self.dims = info.index_max.map(|m| (m + 1) as u64);
            let n = self.dims.iter().product::<u64>() as usize;
            self.values = vec![f32::NAN; n];
            self.given = vec![0; n];
            Ok(())
        }
        fn dense(&mut self, o: [i64; 3], d: [u64; 3], values: &[f32]) -> Result<(), Error> {
            self.blocks.push((o, d));
            let [sx, sy, _] = self.dims;
            let mut i = 0;
            for z in 0..d[2] {
                for y in 0..d[1] {
                    for x in 0..d[0] {
                        let at = (((o[2] as u64 + z) * sy + o[1] as u64 + y) * sx + o[0] as u64 + x)
                            as usize;
                        self.values[at] = values[i];
                        self.given[at] += 1;
                        i += 1;
                    }
                }
            }
            Ok(())
        }
    }

    /// Slabs, rows of a slice and parts of rows (forced by small sizes) read the same voxels, from
    /// a plain file and from gzip (in two members), and each voxel exactly once.
    #[test]
    fn every_way_of_cutting_the_file_reads_the_same_voxels() {
        let dims = [37u64, 21, 19];
        let mut bytes = b"HDR".to_vec();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    bytes.push(pattern(x, y, z));
                }
            }
        }
        let mut zipped = gzip(&bytes[..1000]);
        zipped.extend(gzip(&bytes[1000..]));
        let params = r#"(file: "p.raw", dims: (37, 21, 19), header: 3, normalize: false)"#;
        let slice = 37 * 21;
        for (sizes, first_block) in [
            (Sizes::DEFAULT, [37, 21, 8]),
            (
                Sizes {
                    slab_bytes: slice * 8,
                    block_voxels: 37 * 64,
                },
                [37, 8, 8],
            ),
            (
                Sizes {
                    slab_bytes: slice * 4,
                    block_voxels: 300,
                },
                [37, 8, 1],
            ),
            (
                Sizes {
                    slab_bytes: slice * 4,
                    block_voxels: 100,
                },
                [37, 2, 1],
            ),
            (
                Sizes {
                    slab_bytes: 100,
                    block_voxels: 16,
                },
                [16, 1, 1],
            ),
        ] {
            for file in [&bytes, &zipped] {
                let mut got = Grid::default();
                read_bytes_in(params, file, &mut got, sizes).unwrap();
                assert!(got.given.iter().all(|&n| n == 1), "every voxel once");
                let want: Vec<f32> = bytes[3..].iter().map(|&b| f32::from(b)).collect();
                assert!(got.values == want, "values differ");
                assert_eq!(got.blocks[0], ([0, 0, 0], first_block));
                assert!(got
                    .blocks
                    .iter()
                    .all(|(_, d)| d[0] * d[1] * d[2] <= sizes.block_voxels));
            }
        }
    }

    /// A gzip stream that ends early or goes on is found while streaming, with the sizes.
    #[test]
    fn gzip_of_the_wrong_size_is_reported_while_streaming() {
        let params = r#"(file: "z.raw", dims: (16, 16, 16))"#;
        let e = read_bytes(params, &gzip(&[0u8; 4095]), &mut Grid::default()).unwrap_err();
        assert!(
            e.message.contains("expected 4096 decompressed bytes")
                && e.message.contains("decompresses to 4095"),
            "{}",
            e.message
        );
        let e = read_bytes(params, &gzip(&[0u8; 4097]), &mut Grid::default()).unwrap_err();
        assert!(e.message.contains("decompresses to more"), "{}", e.message);
        let mut broken = gzip(&[7u8; 4096]);
        let n = broken.len();
        broken[n - 8] ^= 0xff; // the CRC
        let e = read_bytes(params, &broken, &mut Grid::default()).unwrap_err();
        assert!(
            e.message.contains("cannot be decompressed"),
            "{}",
            e.message
        );
    }

    /// A host that refuses a block while the next slab is being read ahead: its error is the
    /// reader's, nothing after it reaches the host, and nothing hangs (plain and gzip).
    #[test]
    fn a_host_error_stops_the_read_ahead() {
        struct Refuses(Vec<[i64; 3]>);
        impl Blocks for Refuses {
            fn begin(&mut self, _: &GridInfo) -> Result<(), Error> {
                Ok(())
            }
            fn dense(&mut self, origin: [i64; 3], _: [u64; 3], _: &[f32]) -> Result<(), Error> {
                self.0.push(origin);
                if origin[2] == 8 {
                    return Err(invalid("the host refuses slab 8"));
                }
                Ok(())
            }
        }
        let bytes: Vec<u8> = (0..16 * 16 * 40).map(|i| i as u8).collect();
        let params = r#"(file: "h.raw", dims: (16, 16, 40))"#;
        for file in [bytes.clone(), gzip(&bytes)] {
            let mut host = Refuses(Vec::new());
            let e = read_bytes(params, &file, &mut host).unwrap_err();
            assert_eq!(e.message, "the host refuses slab 8");
            assert_eq!(host.0, [[0, 0, 0], [0, 0, 8]]);
        }
    }

    #[test]
    fn slabs_keep_to_a_quarter_of_the_memory_budget() {
        assert_eq!(Sizes::within(0).slab_bytes, 64 << 20);
        assert_eq!(Sizes::within(1 << 40).slab_bytes, 64 << 20);
        assert_eq!(Sizes::within(100 << 20).slab_bytes, 25 << 20);
        assert_eq!(Sizes::within(1).slab_bytes, 0);
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
