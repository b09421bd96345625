//! # SPD: Eric Haines' Standard Procedural Databases, generated inside Luxon
//!
//! The scenes of "A Proposal for Standard Graphics Environments" (IEEE CG&A, November 1987),
//! and the three the SPD distribution (3.14) added later (`jacks`, `shells`, `sombrero`),
//! written from the published descriptions of what each scene holds and how it is built:
//!
//! | name | scene | size means | default |
//! |---|---|---|---|
//! | `balls` | sphereflake: a sphere with 9 spheres a third its size around it, recursively | recursion depth | 4 |
//! | `teapot` | Newell's teapot, 32 bicubic Bézier patches, on a checkerboard | patch subdivisions per side | 12 |
//! | `gears` | meshing gears with concave 144-sided faces, some glass | gears per axis (n³ gears) | 4 |
//! | `tetra` | Sierpinski tetrahedron | recursion depth | 5 |
//! | `rings` | pyramid of groups of six interlocked pentagonal rings | pyramid levels | 7 |
//! | `lattice` | a cubic lattice of balls joined by rods | cells per axis | 12 |
//! | `mount` | fractal mountain (midpoint subdivision) with four glass balls | subdivision depth | 6 |
//! | `tree` | a branching tree of cones and spheres | branching depth | 11 |
//! | `jacks` | recursive jacks: three cylinders with balls at the ends, eight half-size children | levels | 1 |
//! | `shells` | Pickover's seashell: a spiral of overlapping spheres | 180·2^size + 1 spheres | 5 |
//! | `sombrero` | the height field cos(2πρ)·e^-ρ as triangles | grid 32·2^(size-1) per side | 1 |
//!
//! Generators write to a [`Sink`]: [`generate`] streams NFF text exactly as the SPD programs
//! print it (`%g` numbers, a cone on one line), [`generate_ron`] a Luxon RON scene of the same
//! content, and [`count`] only counts. Nothing is held in memory but one primitive at a time
//! (the RON writer buffers at most 65,536 primitives per object), so `balls -s 6` (597,871
//! spheres, 0.2 s) and `teapot -s 153` (1.52 M polygons, 257 MB, 1.7 s) stream in a few MB.
//!
//! At the sizes of the SPD's reference files the output has the same primitives, in the same
//! order, as the SPD programs' (see `formats/tests/spd.rs`), except `mount`'s heights: the SPD
//! draws them from its own random number generator, which is not reproduced (the mountain has
//! the same structure, counts and statistics; see [`mount`]). No SPD output of `jacks`,
//! `shells` and `sombrero` is at hand: their counts and geometry are tested against the
//! construction their modules describe.

pub mod balls;
pub mod gears;
pub mod jacks;
pub mod lattice;
pub mod mount;
mod nff_out;
pub mod rings;
mod ron_out;
pub mod shells;
pub mod sombrero;
pub mod teapot;
pub mod tetra;
pub mod tree;

use std::io::{self, Write};

pub use nff_out::{push_g, NffWriter};
pub use ron_out::RonWriter;

/// Why a scene could not be generated.
#[derive(Debug, thiserror::Error)]
pub enum SpdError {
    #[error("unknown SPD scene `{name}`{}; expected one of: {}", .suggestion.map(|s| format!(", did you mean `{s}`?")).unwrap_or_default(), names().join(", "))]
    UnknownName {
        name: String,
        suggestion: Option<&'static str>,
    },
    #[error(
        "size {size} is out of range for `{name}`: expected {min}..={max} (default {default})"
    )]
    SizeOutOfRange {
        name: &'static str,
        size: u32,
        min: u32,
        max: u32,
        default: u32,
    },
    #[error(transparent)]
    Io(#[from] io::Error),
}

/// One SPD scene: its name, the sizes its generator accepts and the generator.
#[derive(Clone, Copy)]
pub struct SpdScene {
    pub name: &'static str,
    /// The SPD program's default size.
    pub default_size: u32,
    pub min_size: u32,
    pub max_size: u32,
    /// What the scene is, in a few words.
    pub about: &'static str,
    /// What the size means.
    pub size_means: &'static str,
    generate: fn(u32, &mut dyn Sink) -> io::Result<()>,
}

impl std::fmt::Debug for SpdScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpdScene")
            .field("name", &self.name)
            .field("default_size", &self.default_size)
            .field("min_size", &self.min_size)
            .field("max_size", &self.max_size)
            .finish()
    }
}

impl SpdScene {
    /// Runs the generator into `sink` (the size is not checked: see [`find`]).
    pub fn generate(&self, size: u32, sink: &mut dyn Sink) -> io::Result<()> {
        (self.generate)(size, sink)
    }
}

/// Every scene, by name.
pub const SCENES: &[SpdScene] = &[
    SpdScene {
        name: "balls",
        default_size: 4,
        min_size: 0,
        max_size: 8,
        about: "sphereflake: a sphere with 9 spheres a third its size around it, recursively",
        size_means: "recursion depth: (9^(size+1) - 1) / 8 spheres",
        generate: balls::generate,
    },
    SpdScene {
        name: "gears",
        default_size: 4,
        min_size: 1,
        max_size: 40,
        about: "meshing gears with concave 144-sided faces, some of glass",
        size_means: "gears per axis: size^3 gears of 146 polygons",
        generate: gears::generate,
    },
    SpdScene {
        name: "jacks",
        default_size: 1,
        min_size: 1,
        max_size: 8,
        about: "recursive jacks: cylinders with balls at their ends, eight half-size copies",
        size_means: "levels: (8^size - 1) / 7 jacks of 3 cylinders and 6 spheres",
        generate: jacks::generate,
    },
    SpdScene {
        name: "lattice",
        default_size: 12,
        min_size: 1,
        max_size: 200,
        about: "a cubic lattice of balls joined by rods",
        size_means: "cells per axis: (size+1)^3 spheres, 3 size (size+1)^2 cylinders",
        generate: lattice::generate,
    },
    SpdScene {
        name: "mount",
        default_size: 6,
        min_size: 0,
        max_size: 11,
        about: "fractal mountain with four glass balls",
        size_means: "subdivision depth: 2 * 4^size triangles",
        generate: mount::generate,
    },
    SpdScene {
        name: "rings",
        default_size: 7,
        min_size: 1,
        max_size: 60,
        about: "a pyramid of groups of six interlocked pentagonal rings",
        size_means: "pyramid levels: 30 * (1 + 4 + ... + size^2) cylinders and spheres",
        generate: rings::generate,
    },
    SpdScene {
        name: "shells",
        default_size: 5,
        min_size: 1,
        max_size: 16,
        about: "Pickover's seashell: a spiral of overlapping spheres",
        size_means: "angular steps: 180 * 2^size + 1 spheres",
        generate: shells::generate,
    },
    SpdScene {
        name: "sombrero",
        default_size: 1,
        min_size: 1,
        max_size: 8,
        about: "height field of a damped ripple (a sombrero) as triangles",
        size_means: "grid: w = 32 * 2^(size-1) samples per side, 2 (w-1)^2 triangles",
        generate: sombrero::generate,
    },
    SpdScene {
        name: "teapot",
        default_size: 12,
        min_size: 1,
        max_size: 1000,
        about: "Newell's teapot (32 bicubic Bezier patches) on a checkerboard",
        size_means:
            "subdivisions per patch side: 64 size^2 - 8 size patch triangles, size^2 squares",
        generate: teapot::generate,
    },
    SpdScene {
        name: "tetra",
        default_size: 5,
        min_size: 0,
        max_size: 11,
        about: "Sierpinski tetrahedron",
        size_means: "recursion depth: 4^(size+1) triangles",
        generate: tetra::generate,
    },
    SpdScene {
        name: "tree",
        default_size: 11,
        min_size: 0,
        max_size: 22,
        about: "a branching tree of cones and spheres",
        size_means: "branching depth: 2^(size+1) - 1 branches",
        generate: tree::generate,
    },
];

/// The scene names.
pub fn names() -> Vec<&'static str> {
    SCENES.iter().map(|s| s.name).collect()
}

/// The scene called `name` (exactly), or an error with a "did you mean".
pub fn scene(name: &str) -> Result<&'static SpdScene, SpdError> {
    SCENES
        .iter()
        .find(|s| s.name == name)
        .ok_or_else(|| SpdError::UnknownName {
            name: name.to_string(),
            suggestion: crate::error::suggest(&name.to_ascii_lowercase(), names()),
        })
}

/// The scene called `name` and the size to generate it at (`None`: its default), checked.
pub fn find(name: &str, size: Option<u32>) -> Result<(&'static SpdScene, u32), SpdError> {
    let s = scene(name)?;
    let size = size.unwrap_or(s.default_size);
    if size < s.min_size || size > s.max_size {
        return Err(SpdError::SizeOutOfRange {
            name: s.name,
            size,
            min: s.min_size,
            max: s.max_size,
            default: s.default_size,
        });
    }
    Ok((s, size))
}

/// Writes scene `name` at `size` as NFF text to `out`, as the SPD programs print it.
pub fn generate(name: &str, size: u32, out: &mut dyn Write) -> Result<(), SpdError> {
    let (scene, size) = find(name, Some(size))?;
    let mut w = NffWriter::new(out);
    scene.generate(size, &mut w)?;
    w.flush()?;
    Ok(())
}

/// Writes scene `name` at `size` as a Luxon RON scene to `out` (see [`RonWriter`]).
pub fn generate_ron(name: &str, size: u32, out: &mut dyn Write) -> Result<(), SpdError> {
    let (scene, size) = find(name, Some(size))?;
    ron_out::write(scene, size, out)?;
    Ok(())
}

/// The file formats scenes are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// NFF text, as the SPD programs print it.
    Nff,
    /// NFF text, gzip-compressed.
    NffGz,
    /// A Luxon RON scene of the same content.
    Ron,
}

impl OutputFormat {
    /// The format a file name asks for: `.nff`, `.nff.gz` or `.ron` (any case).
    pub fn of_path(path: &std::path::Path) -> Option<OutputFormat> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        if name.ends_with(".nff.gz") {
            Some(OutputFormat::NffGz)
        } else if name.ends_with(".nff") {
            Some(OutputFormat::Nff)
        } else if name.ends_with(".ron") {
            Some(OutputFormat::Ron)
        } else {
            None
        }
    }
}

/// Writes scene `name` at `size` to `out` in `format`; returns what it held.
pub fn generate_as(
    name: &str,
    size: u32,
    format: OutputFormat,
    out: &mut dyn Write,
) -> Result<Counts, SpdError> {
    let (scene, size) = find(name, Some(size))?;
    let nff = |out: &mut dyn Write| -> Result<Counts, SpdError> {
        let mut w = NffWriter::new(out);
        let mut tee = Tee {
            inner: &mut w,
            counts: Counts::default(),
        };
        scene.generate(size, &mut tee)?;
        let counts = tee.counts;
        w.flush()?;
        Ok(counts)
    };
    match format {
        OutputFormat::Nff => nff(out),
        OutputFormat::Ron => Ok(ron_out::write(scene, size, out)?),
        OutputFormat::NffGz => {
            let mut gz = flate2::write::GzEncoder::new(out, flate2::Compression::fast());
            let counts = nff(&mut gz)?;
            gz.finish()?;
            Ok(counts)
        }
    }
}

/// Passes everything on to `inner` and counts it.
struct Tee<'a> {
    inner: &'a mut dyn Sink,
    counts: Counts,
}

impl Sink for Tee<'_> {
    fn background(&mut self, rgb: [f64; 3]) -> io::Result<()> {
        self.inner.background(rgb)
    }
    fn view(&mut self, v: &View) -> io::Result<()> {
        self.inner.view(v)
    }
    fn light(&mut self, p: [f64; 3]) -> io::Result<()> {
        self.counts.light(p)?;
        self.inner.light(p)
    }
    fn fill(&mut self, f: &Fill) -> io::Result<()> {
        self.counts.fill(f)?;
        self.inner.fill(f)
    }
    fn sphere(&mut self, c: [f64; 3], r: f64) -> io::Result<()> {
        self.counts.sphere(c, r)?;
        self.inner.sphere(c, r)
    }
    fn cone(&mut self, b: [f64; 3], br: f64, a: [f64; 3], ar: f64) -> io::Result<()> {
        self.counts.cone(b, br, a, ar)?;
        self.inner.cone(b, br, a, ar)
    }
    fn polygon(&mut self, v: &[[f64; 3]]) -> io::Result<()> {
        self.counts.polygon(v)?;
        self.inner.polygon(v)
    }
    fn patch(&mut self, v: &[[f64; 3]], n: &[[f64; 3]]) -> io::Result<()> {
        self.counts.patch(v, n)?;
        self.inner.patch(v, n)
    }
}

/// What a scene holds, counted without writing it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub spheres: u64,
    pub cones: u64,
    /// `p` polygons.
    pub polygons: u64,
    /// `pp` patches (polygons with vertex normals).
    pub patches: u64,
    pub lights: u64,
    /// `f` lines.
    pub fills: u64,
}

impl Counts {
    /// Polygons of both kinds.
    pub fn all_polygons(&self) -> u64 {
        self.polygons + self.patches
    }
}

/// Counts what scene `name` holds at `size`.
pub fn count(name: &str, size: u32) -> Result<Counts, SpdError> {
    let (scene, size) = find(name, Some(size))?;
    let mut c = Counts::default();
    scene.generate(size, &mut c)?;
    Ok(c)
}

/// The view (NFF's `v` entity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub from: [f64; 3],
    pub at: [f64; 3],
    pub up: [f64; 3],
    /// Degrees between the centres of the outermost pixels.
    pub angle: f64,
    pub hither: f64,
    pub resolution: (u32, u32),
}

/// NFF's `f`: colour, Kd, Ks, Shine, T, index of refraction.
pub type Fill = [f64; 8];

/// An `f` material the way the SPD describes surfaces: the highlight is given as the angle
/// (degrees) from the mirror direction at which it falls to half its peak, turned into the
/// Phong exponent `ln(1/2) / ln(cos angle)` (an angle of 0: a mirror-sharp 100000).
pub fn fill(color: [f64; 3], kd: f64, ks: f64, half_angle: f64, t: f64, ior: f64) -> Fill {
    let shine = if half_angle > 0.0 {
        0.5f64.ln() / half_angle.to_radians().cos().ln()
    } else {
        100000.0
    };
    [color[0], color[1], color[2], kd, ks, shine, t, ior]
}

/// Receives a scene as the SPD programs emit it, in file order.
pub trait Sink {
    /// `b`: background colour.
    fn background(&mut self, rgb: [f64; 3]) -> io::Result<()>;
    /// `v`: the view.
    fn view(&mut self, view: &View) -> io::Result<()>;
    /// `l`: a point light without colour.
    fn light(&mut self, position: [f64; 3]) -> io::Result<()>;
    /// `f`: the material of what follows.
    fn fill(&mut self, fill: &Fill) -> io::Result<()>;
    /// `s`: a sphere.
    fn sphere(&mut self, center: [f64; 3], radius: f64) -> io::Result<()>;
    /// `c`: an open cone or cylinder.
    fn cone(&mut self, base: [f64; 3], base_r: f64, apex: [f64; 3], apex_r: f64) -> io::Result<()>;
    /// `p`: a planar polygon (convex or not).
    fn polygon(&mut self, vertices: &[[f64; 3]]) -> io::Result<()>;
    /// `pp`: a polygon with a normal per vertex.
    fn patch(&mut self, vertices: &[[f64; 3]], normals: &[[f64; 3]]) -> io::Result<()>;
}

impl Sink for Counts {
    fn background(&mut self, _: [f64; 3]) -> io::Result<()> {
        Ok(())
    }
    fn view(&mut self, _: &View) -> io::Result<()> {
        Ok(())
    }
    fn light(&mut self, _: [f64; 3]) -> io::Result<()> {
        self.lights += 1;
        Ok(())
    }
    fn fill(&mut self, _: &Fill) -> io::Result<()> {
        self.fills += 1;
        Ok(())
    }
    fn sphere(&mut self, _: [f64; 3], _: f64) -> io::Result<()> {
        self.spheres += 1;
        Ok(())
    }
    fn cone(&mut self, _: [f64; 3], _: f64, _: [f64; 3], _: f64) -> io::Result<()> {
        self.cones += 1;
        Ok(())
    }
    fn polygon(&mut self, _: &[[f64; 3]]) -> io::Result<()> {
        self.polygons += 1;
        Ok(())
    }
    fn patch(&mut self, _: &[[f64; 3]], _: &[[f64; 3]]) -> io::Result<()> {
        self.patches += 1;
        Ok(())
    }
}

/// The background every SPD scene uses.
pub(crate) const BACKGROUND: [f64; 3] = [0.078, 0.361, 0.753];

/// The usual SPD view: 45 degrees, 512x512.
pub(crate) fn view(from: [f64; 3], at: [f64; 3], up: [f64; 3], hither: f64) -> View {
    View {
        from,
        at,
        up,
        angle: 45.0,
        hither,
        resolution: (512, 512),
    }
}

// ------------------------------------------------------------------------------------------------
// Small vector helpers shared by the generators
// ------------------------------------------------------------------------------------------------

pub(crate) type V3 = [f64; 3];

pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn mul(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub(crate) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn length(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// A 3x3 matrix, rows first.
pub(crate) type M3 = [[f64; 3]; 3];

pub(crate) const IDENTITY: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

pub(crate) fn apply(m: &M3, v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

pub(crate) fn mat_mul(a: &M3, b: &M3) -> M3 {
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    r
}

/// Rotation by `angle` radians about the unit vector `axis` (right-handed).
pub(crate) fn rotation(axis: V3, angle: f64) -> M3 {
    let [x, y, z] = axis;
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// Everything a generator emits, kept for tests that look at the geometry.
#[cfg(test)]
#[derive(Default)]
pub(crate) struct Recorder {
    pub view: Option<View>,
    pub lights: Vec<V3>,
    pub fills: Vec<Fill>,
    pub spheres: Vec<(V3, f64)>,
    pub cones: Vec<(V3, f64, V3, f64)>,
    pub polygons: Vec<Vec<V3>>,
}

#[cfg(test)]
impl Recorder {
    /// Scene `name` at `size`, recorded.
    pub fn of(name: &str, size: u32) -> Recorder {
        let mut r = Recorder::default();
        scene(name).unwrap().generate(size, &mut r).unwrap();
        r
    }
}

#[cfg(test)]
impl Sink for Recorder {
    fn background(&mut self, _: [f64; 3]) -> io::Result<()> {
        Ok(())
    }
    fn view(&mut self, v: &View) -> io::Result<()> {
        self.view = Some(*v);
        Ok(())
    }
    fn light(&mut self, p: [f64; 3]) -> io::Result<()> {
        self.lights.push(p);
        Ok(())
    }
    fn fill(&mut self, f: &Fill) -> io::Result<()> {
        self.fills.push(*f);
        Ok(())
    }
    fn sphere(&mut self, c: [f64; 3], r: f64) -> io::Result<()> {
        self.spheres.push((c, r));
        Ok(())
    }
    fn cone(&mut self, b: [f64; 3], br: f64, a: [f64; 3], ar: f64) -> io::Result<()> {
        self.cones.push((b, br, a, ar));
        Ok(())
    }
    fn polygon(&mut self, v: &[[f64; 3]]) -> io::Result<()> {
        self.polygons.push(v.to_vec());
        Ok(())
    }
    fn patch(&mut self, v: &[[f64; 3]], _: &[[f64; 3]]) -> io::Result<()> {
        self.polygons.push(v.to_vec());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shine_from_half_angle() {
        let mut s = Vec::new();
        push_g(&mut s, fill([1.0; 3], 0.5, 0.5, 37.0, 0.0, 1.0)[5]);
        assert_eq!(std::str::from_utf8(&s).unwrap(), "3.0827");
        s.clear();
        push_g(&mut s, fill([1.0; 3], 0.5, 0.5, 30.0, 0.0, 1.0)[5]);
        assert_eq!(std::str::from_utf8(&s).unwrap(), "4.81884");
        assert_eq!(fill([1.0; 3], 1.0, 0.0, 0.0, 0.0, 0.0)[5], 100000.0);
    }

    #[test]
    fn unknown_names_and_sizes() {
        let e = find("bals", None).unwrap_err().to_string();
        assert!(e.contains("did you mean `balls`?"), "{e}");
        assert!(e.contains("balls, gears, jacks, lattice"), "{e}");
        let e = find("balls", Some(9)).unwrap_err().to_string();
        assert!(e.contains("expected 0..=8"), "{e}");
        assert_eq!(find("teapot", None).unwrap().1, 12);
    }
}
