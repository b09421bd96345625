//! The binary geometry cache of imported scenes (NFF): the native geometry after import and its
//! BVHs, plus the file's non-geometry lines (view, lights, materials), so a second render of a
//! large file skips parsing and the BVH build.
//!
//! File `NAME.luxcache` next to the source, or, when that directory is not writable, in
//! `$LUXON_CACHE_DIR`, `$XDG_CACHE_HOME/luxon` or `~/.cache/luxon` (named after a hash of the
//! source's full path). Written to a temporary file and renamed. Read through a memory map.
//!
//! Layout (little-endian): magic `LUXGEOC\0`, format version (u32), the luxon version that
//! wrote it, the source's size and modification time, the render-space origin, the payload's
//! length and checksum, then a checksum of all that header; the payload is u32 words in
//! sections (skeleton text, used materials, spheres, triangles with vertex attributes and
//! corners, cones; each set with its BVH nodes). A cache is used only when the magic, versions,
//! source size and time match and the cache is at least as new as the source ("stale"
//! otherwise: rebuilt silently); a checksum, length or structure that does not add up makes it
//! "corrupt": the caller warns and rebuilds it. Nothing read from a cache is trusted: every
//! index is checked, so a damaged file never crashes the renderer.

use crate::bvh::Bvh;
use crate::geometry::cone::{Cone, Cones};
use crate::geometry::set::Set;
use crate::geometry::sphere::{Sphere, Spheres};
use crate::geometry::triangle::{Triangle, Triangles, VertexAttr, NO_ATTR};
use crate::geometry::{clip_of, material_of};
use crate::math::DVec3;
use crate::scene::{Prebuilt, Scene};
use glam::Vec3;
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

const MAGIC: &[u8; 8] = b"LUXGEOC\0";
/// Raise when the layout changes, or when a new build makes better trees than the cached ones
/// (5: the SAH looks at all three axes).
pub const FORMAT_VERSION: u32 = 5;
const LUXON_VERSION: &str = env!("CARGO_PKG_VERSION");

/// A cache found valid for its source.
pub struct Cached {
    pub path: PathBuf,
    /// The source's non-geometry lines (see `luxon_formats::nff::skeleton`).
    pub skeleton: String,
    pub geometry: Prebuilt,
}

pub enum Lookup {
    Hit(Box<Cached>),
    /// No cache, or one for another version or an older source.
    Miss,
    /// A cache that claims to be current but does not read back: (file, why).
    Corrupt(PathBuf, String),
}

/// Where the cache of `source` may live, in the order they are tried.
pub fn locations(source: &Path) -> Vec<PathBuf> {
    let name = source
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "scene".into());
    let mut v = vec![source.with_file_name(format!("{name}.luxcache"))];
    let dir = std::env::var_os("LUXON_CACHE_DIR")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("XDG_CACHE_HOME").map(|d| PathBuf::from(d).join("luxon")))
        .or_else(|| std::env::var_os("HOME").map(|d| PathBuf::from(d).join(".cache/luxon")));
    if let Some(dir) = dir {
        let full = std::fs::canonicalize(source).unwrap_or_else(|_| source.to_path_buf());
        let key = full
            .to_string_lossy()
            .bytes()
            .fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
                (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
            });
        v.push(dir.join(format!("{key:016x}-{name}.luxcache")));
    }
    v
}

/// The source's identity: size, modification time (seconds, nanoseconds).
fn stamp(path: &Path) -> Option<(u64, i64, u32)> {
    let m = std::fs::metadata(path).ok()?;
    let t = m.modified().ok()?;
    let (secs, nanos) = match t.duration_since(UNIX_EPOCH) {
        Ok(d) => (d.as_secs() as i64, d.subsec_nanos()),
        Err(e) => (
            -(e.duration().as_secs() as i64),
            e.duration().subsec_nanos(),
        ),
    };
    Some((m.len(), secs, nanos))
}

/// Order-dependent 64-bit checksum of u32 words.
#[derive(Clone, Copy)]
struct Sum(u64);

impl Sum {
    fn new() -> Sum {
        Sum(0x9e37_79b9_7f4a_7c15)
    }

    #[inline(always)]
    fn add(&mut self, w: u32) {
        self.0 = (self.0.rotate_left(23) ^ w as u64).wrapping_mul(0xff51_afd7_ed55_8ccd);
    }
}

/// Words summed per block of this many bytes, the block sums then summed in order (so reading
/// checks a large cache in parallel).
const SUM_BLOCK: usize = 1 << 20;

fn sum_words(bytes: &[u8]) -> u64 {
    let mut s = Sum::new();
    for c in bytes.chunks_exact(4) {
        s.add(u32::from_le_bytes([c[0], c[1], c[2], c[3]]));
    }
    s.0
}

fn sum_bytes(bytes: &[u8]) -> u64 {
    sum_releasing(bytes, &|_, _| {})
}

/// `sum_bytes`, handing each block to `release` once summed.
fn sum_releasing(bytes: &[u8], release: &Release<'_>) -> u64 {
    use rayon::prelude::*;
    let blocks: Vec<u64> = bytes
        .par_chunks(SUM_BLOCK)
        .map(|block| {
            let s = sum_words(block);
            release(block.as_ptr() as usize, block.len());
            s
        })
        .collect();
    let mut s = Sum::new();
    for b in blocks {
        s.add(b as u32);
        s.add((b >> 32) as u32);
    }
    s.0
}

/// The header up to (not including) its own checksum.
fn header(stamp: (u64, i64, u32), offset: DVec3, words: u64, sum: u64) -> Vec<u8> {
    let mut h = Vec::new();
    h.extend_from_slice(MAGIC);
    h.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    h.extend_from_slice(&(LUXON_VERSION.len() as u32).to_le_bytes());
    h.extend_from_slice(LUXON_VERSION.as_bytes());
    while h.len() % 4 != 0 {
        h.push(0);
    }
    h.extend_from_slice(&stamp.0.to_le_bytes());
    h.extend_from_slice(&stamp.1.to_le_bytes());
    h.extend_from_slice(&stamp.2.to_le_bytes());
    for x in offset.to_array() {
        h.extend_from_slice(&x.to_le_bytes());
    }
    h.extend_from_slice(&words.to_le_bytes());
    h.extend_from_slice(&sum.to_le_bytes());
    h
}

/// Whether `scene` (built from `source`) can be cached: only imported native geometry.
pub fn cacheable(scene: &Scene, had_objects: bool) -> bool {
    !had_objects
        && scene.customs.is_empty()
        && scene.planes.planes.is_empty()
        && scene.discs.is_empty()
        && scene.clips.groups.is_empty()
        && scene.instances.is_empty()
}

/// Writes the cache of `source` (whose non-geometry lines are `skeleton`) for `scene`, to the
/// first location that accepts it; returns where.
pub fn write(source: &Path, skeleton: &str, scene: &Scene) -> std::io::Result<PathBuf> {
    let stamp = stamp(source).ok_or_else(|| std::io::Error::other("cannot stat the source"))?;
    let mut last = std::io::Error::other("no cache location");
    for path in locations(source) {
        if let Some(dir) = path.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        match write_to(&path, stamp, skeleton, scene) {
            Ok(()) => return Ok(path),
            Err(e) => last = e,
        }
    }
    Err(last)
}

/// Words to a file, summed as they go.
struct Out {
    file: std::io::BufWriter<std::fs::File>,
    buf: Vec<u8>,
    /// Sum of the current block and of the finished blocks' sums (see `sum_bytes`).
    block: Sum,
    sum: Sum,
    words: u64,
}

impl Out {
    #[inline(always)]
    fn w(&mut self, x: u32) {
        self.buf.extend_from_slice(&x.to_le_bytes());
        self.block.add(x);
        self.words += 1;
        if self.words.is_multiple_of((SUM_BLOCK / 4) as u64) {
            self.end_block();
        }
    }

    fn end_block(&mut self) {
        let b = std::mem::replace(&mut self.block, Sum::new()).0;
        self.sum.add(b as u32);
        self.sum.add((b >> 32) as u32);
    }

    fn f(&mut self, x: f32) {
        self.w(x.to_bits());
    }

    fn v3(&mut self, v: Vec3) {
        self.f(v.x);
        self.f(v.y);
        self.f(v.z);
    }

    fn len(&mut self, n: usize) {
        self.w(n as u32);
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if self.buf.len() >= 1 << 20 {
            self.file.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }

    fn set<S>(&mut self, set: &Set<S>, put: impl Fn(&mut Out, &S)) -> std::io::Result<()>
    where
        S: crate::geometry::set::Shape,
    {
        let (data, material, bvh) = set.parts();
        self.len(data.len());
        for s in data {
            put(self, s);
            self.flush()?;
        }
        for &m in material {
            self.w(m);
            self.flush()?;
        }
        let mut nodes = Vec::new();
        bvh.to_words(&mut |x| nodes.push(x));
        self.len(nodes.len());
        for x in nodes {
            self.w(x);
            self.flush()?;
        }
        Ok(())
    }
}

fn write_to(
    path: &Path,
    stamp: (u64, i64, u32),
    skeleton: &str,
    scene: &Scene,
) -> std::io::Result<()> {
    let mut tmp = crate::files::TempFile::create(path).map_err(|e| match e {
        crate::Error::Io { source, .. } => source,
        e => std::io::Error::other(e.to_string()),
    })?;
    // Removed on any error when `tmp` drops.
    let result = (|| {
        let file = tmp.file().try_clone()?;
        let head_len = header(stamp, scene.world_offset, 0, 0).len() + 8;
        let mut o = Out {
            file: std::io::BufWriter::new(file),
            buf: Vec::with_capacity(1 << 21),
            block: Sum::new(),
            sum: Sum::new(),
            words: 0,
        };
        o.file.write_all(&vec![0u8; head_len])?;
        let bytes = skeleton.as_bytes();
        o.len(bytes.len());
        for c in bytes.chunks(4) {
            let mut w = [0u8; 4];
            w[..c.len()].copy_from_slice(c);
            o.w(u32::from_le_bytes(w));
        }
        o.len(scene.used_materials.len());
        for &u in &scene.used_materials {
            o.w(u as u32);
        }
        o.w(scene.degenerate_triangles as u32);
        o.w((scene.degenerate_triangles >> 32) as u32);
        o.set(&scene.spheres, |o, s: &Sphere| {
            o.v3(s.center);
            o.f(s.radius);
        })?;
        o.set(&scene.triangles.set, |o, t: &Triangle| {
            t.v.iter().for_each(|v| o.v3(*v));
            o.w(t.attr);
        })?;
        let t = &scene.triangles;
        o.len(t.vertex_attrs.len());
        for a in &t.vertex_attrs {
            o.v3(a.n);
            o.v3(a.c);
            o.f(a.uv[0]);
            o.f(a.uv[1]);
            o.flush()?;
        }
        o.len(t.corners.len());
        for c in &t.corners {
            c.iter().for_each(|&i| o.w(i));
            o.flush()?;
        }
        o.set(&scene.cones, |o, c: &Cone| {
            o.v3(c.base);
            o.f(c.base_radius);
            o.v3(c.apex);
            o.f(c.apex_radius);
        })?;
        if !o.words.is_multiple_of((SUM_BLOCK / 4) as u64) {
            o.end_block();
        }
        let buf = std::mem::take(&mut o.buf);
        o.file.write_all(&buf)?;
        let mut head = header(stamp, scene.world_offset, o.words, o.sum.0);
        let hs = sum_bytes(&head);
        head.extend_from_slice(&hs.to_le_bytes());
        let mut file = o.file.into_inner().map_err(|e| e.into_error())?;
        file.rewind()?;
        file.write_all(&head)?;
        file.sync_all()
    })();
    result?;
    tmp.rename().map_err(|e| match e {
        crate::Error::Io { source, .. } => source,
        e => std::io::Error::other(e.to_string()),
    })
}

/// Looks for a current cache of `source`.
pub fn open(source: &Path) -> Lookup {
    let Some(stamp) = stamp(source) else {
        return Lookup::Miss;
    };
    let source_time = std::fs::metadata(source).and_then(|m| m.modified()).ok();
    for path in locations(source) {
        let Ok(file) = std::fs::File::open(&path) else {
            continue;
        };
        // "Newer than the source": a cache older than its source is stale whatever it says.
        let cache_time = file.metadata().and_then(|m| m.modified()).ok();
        if let (Some(c), Some(s)) = (cache_time, source_time) {
            if c < s {
                continue;
            }
        }
        // SAFETY: a file map is sound while nothing changes the file in place. Luxon never
        // does: a cache file is written whole under a temporary name and renamed over the old
        // one (`write`), which leaves the mapped file as it is. Another program writing into
        // a cache file is outside what a map can guard against; the bytes are only read through
        // bounds-checked slices and checked against their checksums, so such a change at worst
        // yields a rejected cache.
        let map = match unsafe { memmap2::Mmap::map(&file) } {
            Ok(m) => m,
            Err(_) => continue,
        };
        // Pages are given back as soon as they are checked or decoded, so the mapped file
        // does not sit in memory beside the arrays decoded from it.
        let base = map.as_ptr() as usize;
        let release = |at: usize, len: usize| {
            const PAGE: usize = 4096;
            let start = (at - base).next_multiple_of(PAGE);
            let end = (at - base + len) / PAGE * PAGE;
            if end > start {
                // SAFETY: a read-only map of a file that does not change (see above): pages
                // dropped here are read back from the file if touched again, so every slice into
                // them still sees the same bytes; the range lies inside the map (whole pages
                // within the `len` bytes at `at`, which the reader took from it).
                let _ = unsafe {
                    map.unchecked_advise_range(
                        memmap2::UncheckedAdvice::DontNeed,
                        start,
                        end - start,
                    )
                };
            }
        };
        match read(&map, stamp, &release) {
            Ok(Some((skeleton, geometry))) => {
                return Lookup::Hit(Box::new(Cached {
                    path,
                    skeleton,
                    geometry,
                }))
            }
            Ok(None) => continue,
            Err(why) => return Lookup::Corrupt(path, why),
        }
    }
    Lookup::Miss
}

/// Called with (address, length) of mapped bytes no longer needed.
type Release<'a> = dyn Fn(usize, usize) + Sync + 'a;

/// Little-endian reader over the mapped bytes; every read checked.
struct In<'a> {
    b: &'a [u8],
    at: usize,
    release: &'a Release<'a>,
}

impl<'a> In<'a> {
    fn bytes(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.b.len());
        let end = end.ok_or("the file is shorter than it says (truncated?)")?;
        let s = &self.b[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn w(&mut self) -> Result<u32, String> {
        let b = self.bytes(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn u64(&mut self) -> Result<u64, String> {
        Ok(self.w()? as u64 | (self.w()? as u64) << 32)
    }

    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_bits(self.u64()?))
    }

    /// `n` records of `k` words each, decoded by `f`.
    fn records<T: Send>(
        &mut self,
        n: usize,
        k: usize,
        f: impl Fn(&[u32]) -> T + Sync,
    ) -> Result<Vec<T>, String> {
        use rayon::prelude::*;
        let len = n.checked_mul(4 * k).ok_or("impossible length")?;
        let raw = self.bytes(len)?;
        let out = raw
            .par_chunks_exact(4 * k)
            .with_min_len(4096)
            .map(|c| {
                let mut words = [0u32; 16];
                for (w, b) in words.iter_mut().zip(c.chunks_exact(4)) {
                    *w = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                }
                f(&words[..k])
            })
            .collect();
        (self.release)(raw.as_ptr() as usize, raw.len());
        Ok(out)
    }

    fn len(&mut self) -> Result<usize, String> {
        Ok(self.w()? as usize)
    }
}

fn v3(w: &[u32]) -> Vec3 {
    Vec3::new(
        f32::from_bits(w[0]),
        f32::from_bits(w[1]),
        f32::from_bits(w[2]),
    )
}

/// Ok(None): a cache of another version or source (stale); Err: corrupt.
type Parsed = Result<Option<(String, Prebuilt)>, String>;

fn read<'a>(b: &'a [u8], stamp: (u64, i64, u32), release: &'a Release<'a>) -> Parsed {
    let mut r = In { b, at: 0, release };
    if r.bytes(8).ok() != Some(&MAGIC[..]) {
        return Err("not a luxon geometry cache".into());
    }
    if r.w()? != FORMAT_VERSION {
        return Ok(None);
    }
    let vlen = r.len()?;
    if vlen > 256 {
        return Err("bad header".into());
    }
    let version = r.bytes(vlen.div_ceil(4) * 4)?;
    if &version[..vlen] != LUXON_VERSION.as_bytes() {
        return Ok(None);
    }
    let size = r.u64()?;
    let secs = r.u64()? as i64;
    let nanos = r.w()?;
    let offset = DVec3::new(r.f64()?, r.f64()?, r.f64()?);
    let words = r.u64()?;
    let sum = r.u64()?;
    let head_end = r.at;
    if r.u64()? != sum_bytes(&b[..head_end]) {
        return Err("header checksum mismatch".into());
    }
    if (size, secs, nanos) != stamp {
        return Ok(None);
    }
    let payload_len = words
        .checked_mul(4)
        .filter(|&l| l == (b.len() - r.at) as u64)
        .ok_or("length does not match the header (truncated?)")?;
    if sum_releasing(&b[r.at..r.at + payload_len as usize], release) != sum {
        return Err("payload checksum mismatch".into());
    }

    let n = r.len()?;
    let text = r.bytes(n.div_ceil(4) * 4)?;
    let skeleton = String::from_utf8(text[..n].to_vec()).map_err(|_| "skeleton is not UTF-8")?;
    let n = r.len()?;
    let used = r.records(n, 1, |w| w[0] != 0)?;
    let degenerate = r.u64()?;
    let materials = used.len() as u32;
    let check_material = |m: &[u32]| {
        m.iter()
            .all(|&p| clip_of(p) == 0 && material_of(p) < materials)
    };

    let n = r.len()?;
    let data = r.records(n, 4, |w| Sphere {
        center: v3(w),
        radius: f32::from_bits(w[3]),
    })?;
    let spheres: Spheres = finish_set(&mut r, data, &check_material)?;

    let n = r.len()?;
    let data = r.records(n, 10, |w| Triangle {
        v: [v3(&w[0..3]), v3(&w[3..6]), v3(&w[6..9])],
        attr: w[9],
    })?;
    let set: Set<Triangle> = finish_set(&mut r, data, &check_material)?;
    let n = r.len()?;
    let vertex_attrs = r.records(n, 8, |w| VertexAttr {
        n: v3(&w[0..3]),
        c: v3(&w[3..6]),
        uv: [f32::from_bits(w[6]), f32::from_bits(w[7])],
    })?;
    let n = r.len()?;
    let corners = r.records(n, 3, |w| [w[0], w[1], w[2]])?;
    if corners
        .iter()
        .any(|c| c.iter().any(|&i| i as usize >= vertex_attrs.len()))
        || set
            .parts()
            .0
            .iter()
            .any(|t| t.attr != NO_ATTR && t.attr as usize >= corners.len())
    {
        return Err("a triangle's attributes are out of range".into());
    }
    let triangles = Triangles {
        set,
        vertex_attrs,
        corners,
    };

    let n = r.len()?;
    let data = r.records(n, 8, |w| Cone {
        base: v3(&w[0..3]),
        base_radius: f32::from_bits(w[3]),
        apex: v3(&w[4..7]),
        apex_radius: f32::from_bits(w[7]),
    })?;
    let cones: Cones = finish_set(&mut r, data, &check_material)?;
    if r.at != b.len() {
        return Err("trailing bytes".into());
    }
    Ok(Some((
        skeleton,
        Prebuilt {
            world_offset: offset,
            used,
            degenerate,
            spheres,
            triangles,
            cones,
        },
    )))
}

/// Reads a set's packed materials and BVH after its primitives.
fn finish_set<S: crate::geometry::set::Shape>(
    r: &mut In,
    data: Vec<S>,
    check_material: &dyn Fn(&[u32]) -> bool,
) -> Result<Set<S>, String> {
    let material = r.records(data.len(), 1, |w| w[0])?;
    if !check_material(&material) {
        return Err("a material index is out of range".into());
    }
    let k = r.len()?;
    let nodes = r.records(k, 1, |w| w[0])?;
    let bvh = Bvh::from_words(&nodes, data.len()).ok_or("a BVH node is out of range")?;
    Ok(Set::from_parts(data, material, bvh))
}
