//! # NFF: Eric Haines' Neutral File Format (the SPD scenes)
//!
//! Reads `.nff` and `.nff.gz` (gzip is recognised by its magic bytes) into a [`SceneDesc`] whose
//! geometry is inline native data ([`InlineGeometry`]): spheres, open cones and triangle meshes,
//! grouped by material. Everything NFF.TXT defines is read:
//!
//! | entity | meaning | becomes |
//! |---|---|---|
//! | `v` + `from`, `at`, `up`, `angle`, `hither`, `resolution` lines | the view | camera, render size |
//! | `b r g b` | background colour | `background` |
//! | `l x y z [r g b]` | point light | a point light with shadows |
//! | `f r g b Kd Ks Shine T ior` | material of what follows | material `nff-N` |
//! | `c` base x y z r apex x y z r (one line or three) | open cone or cylinder | a cone, no caps |
//! | `s x y z r` | sphere | a sphere |
//! | `p N` + N lines `x y z` | polygon, convex or concave | triangles (fan or ear clipping) |
//! | `pp N` + N lines `x y z nx ny nz` | polygonal patch | triangles with vertex normals |
//! | `#` | comment to the end of the line | |
//!
//! ## How NFF maps to Luxon
//!
//! - **Materials** (NFF.TXT): colour (r, g, b); `Kd` the diffuse coefficient; `Ks` both the
//!   Phong highlight strength and the mirror reflectance; `Shine` the Phong exponent; `T` the
//!   transmittance, refracting with index `ior` (an index of 0, common in SPD files, means 1).
//!   NFF has no ambient term; like the SPD programs' own POV-Ray output, a purely diffuse
//!   material (`Ks` = `T` = 0) gets ambient `1 - Kd`, any other none. Identical `f` lines share
//!   one material; materials are named `nff-0`, `nff-1`... in order of first use. Objects
//!   before the first `f` get Luxon's default material.
//! - **Colours** are display values (NFF predates linear workflows; renderers of its time wrote
//!   them to the frame buffer as they were): they are converted from sRGB to linear, so that
//!   a fully lit matte surface and the background show the colours the file gives.
//! - **Lights** without a colour are white with intensity `1 / sqrt(number of lights)`, the
//!   brightness the SPD programs give them in every other output format; a colour given is
//!   used as it is.
//! - **Camera**: NFF's `angle` spans the centres of the outer pixels, so the image spans a
//!   slightly wider angle: `tan(fov / 2) = tan(angle / 2) * h / (h - 1)` (the vertical field
//!   of view; pixels are square, `aspect` is `w / h`). Right-handed: `right = (at - from) x up`.
//!   `hither` is read and ignored (Luxon has no near clipping plane).
//! - **Render settings**: `resolution` (default 512x512), 1 sample per pixel, ray depth 5
//!   (POV-Ray's default, which the SPD's POV-Ray files rely on); no outputs (`-o` gives them).
//! - Negative radii ("only the inside is visible") are made positive, with a warning: Luxon's
//!   spheres and cones are seen from both sides.
//!
//! ## Errors
//!
//! Every error names `file:line:col` and what was expected: unknown keywords (with a "did you
//! mean"), a wrong number of values on a line, bad numbers, NaN and infinities, polygons with
//! fewer than 3 vertices, a file that ends inside an entity, a missing or incomplete view.
//!
//! ## Warnings
//!
//! What NFF defines but Luxon renders differently is accepted with a warning (in the scene's
//! `warnings`; the first of each kind in a file, with a count of the others): negative sphere
//! and cone radii (drawn two-sided), and a polygon whose triangulation ran out of its time
//! budget (a self-intersecting or very irregular polygon of many thousand corners: the rest of
//! it becomes a fan from one corner, see `polygon`).
//!
//! ## Speed
//!
//! A reader thread reads (and decompresses) blocks of whole entities; each block is cut into
//! chunks at entity lines and the chunks are parsed in parallel (see `stream`). The material
//! in effect and line numbers are fixed up in file order afterwards. Numbers go through an
//! exact fast path; primitives go straight into per-material arrays (no allocation per
//! primitive).

mod lex;
mod parse;
pub(crate) mod polygon;
mod stream;

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use luxon_plugin::files::{open_regular, TextReader};

use crate::desc::{
    BackgroundDesc, CameraDesc, Highlight, LightDesc, MaterialDesc, Origin, Projection, RenderDesc,
    SceneDesc, Spanned,
};
use crate::error::{SceneError, Warning};
use crate::geometry::{InlineGeometry, InlineMesh};
use crate::input::{file_error, FileError, LoadOptions, NFF_MAX_LINE};
use parse::{ChunkError, ChunkOut, Directive, Fill, NoteKind, View};

/// What an NFF file held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NffStats {
    pub spheres: u64,
    pub cones: u64,
    /// `p` polygons.
    pub polygons: u64,
    /// `pp` patches.
    pub patches: u64,
    /// Triangles the polygons and patches became.
    pub triangles: u64,
    pub lights: u64,
    /// `f` lines.
    pub fills: u64,
    /// Distinct materials (identical `f` lines share one).
    pub materials: u64,
    /// Text lines.
    pub lines: u64,
}

impl std::ops::AddAssign for NffStats {
    fn add_assign(&mut self, o: NffStats) {
        self.spheres += o.spheres;
        self.cones += o.cones;
        self.polygons += o.polygons;
        self.patches += o.patches;
        self.triangles += o.triangles;
        self.lights += o.lights;
        self.fills += o.fills;
        self.materials += o.materials;
        self.lines += o.lines;
    }
}

/// A scene read from NFF and what it held.
#[derive(Clone, Debug)]
pub struct Imported {
    pub desc: SceneDesc,
    pub stats: NffStats,
}

/// True for names ending in `.nff` or `.nff.gz` (any case).
pub fn is_nff_path(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    name.ends_with(".nff") || name.ends_with(".nff.gz")
}

/// Loads an NFF file (plain or gzip).
pub fn load(path: &Path) -> Result<SceneDesc, SceneError> {
    import(path).map(|i| i.desc)
}

/// [`load`] within the limits of `options` (its geometry within `max_geometry`).
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<SceneDesc, SceneError> {
    import_with(path, options).map(|i| i.desc)
}

/// Loads an NFF file (plain or gzip) and counts what it held.
pub fn import(path: &Path) -> Result<Imported, SceneError> {
    import_with(path, &LoadOptions::default())
}

/// [`import`] within the limits of `options`: the geometry is counted as it is read, and an
/// error names the file as soon as it holds more than `max_geometry`.
pub fn import_with(path: &Path, options: &LoadOptions) -> Result<Imported, SceneError> {
    let reader = open(path)?;
    match reader {
        Opened::Plain(r) => import_limited(r, path, stream::BLOCK, options),
        Opened::Gzip(r) => import_limited(r, path, stream::BLOCK, options),
    }
}

/// An NFF file opened for reading: plain, or gzip (recognised by its magic bytes).
enum Opened {
    Plain(BufReader<File>),
    Gzip(flate2::read::MultiGzDecoder<BufReader<File>>),
}

/// What an NFF file must be, for messages.
const WHAT: &str = "an NFF scene file";

fn open(path: &Path) -> Result<Opened, SceneError> {
    let (file, _) = open_regular(path, u64::MAX).map_err(|e| file_error(e, path, WHAT))?;
    let mut reader = BufReader::with_capacity(1 << 16, file);
    let start = reader
        .fill_buf()
        .map_err(|e| file_error(FileError::from_io(e), path, WHAT))?;
    Ok(if start.starts_with(&[0x1f, 0x8b]) {
        Opened::Gzip(flate2::read::MultiGzDecoder::new(reader))
    } else {
        Opened::Plain(reader)
    })
}

/// The lines of an NFF file that are not geometry (the view, background, lights and `f`
/// materials), in file order. Parsing them gives the file's scene without its primitives: the
/// geometry cache stores those, built, and this text beside them.
pub fn skeleton(path: &Path) -> Result<String, SceneError> {
    const KEEP: [&str; 10] = [
        "v",
        "from",
        "at",
        "up",
        "angle",
        "hither",
        "resolution",
        "b",
        "l",
        "f",
    ];
    let mut text: Box<dyn BufRead> = match open(path)? {
        Opened::Plain(r) => Box::new(TextReader::new(r, NFF_MAX_LINE)),
        Opened::Gzip(r) => Box::new(TextReader::new(BufReader::new(r), NFF_MAX_LINE)),
    };
    let mut out = String::new();
    let mut line = Vec::new();
    loop {
        line.clear();
        let n = text
            .read_until(b'\n', &mut line)
            .map_err(|e| read_error(e, path))?;
        if n == 0 {
            break;
        }
        let first = line
            .split(|b| b.is_ascii_whitespace())
            .find(|w| !w.is_empty())
            .unwrap_or_default();
        if KEEP.iter().any(|k| k.as_bytes() == first) {
            out.push_str(&String::from_utf8_lossy(&line));
            if !out.ends_with('\n') {
                out.push('\n');
            }
        }
    }
    Ok(out)
}

/// A failure reading NFF text: at the line (and column) of a problem in the text (a line
/// without an end, binary data), else about the file.
fn read_error(e: std::io::Error, path: &Path) -> SceneError {
    match FileError::from_io(e) {
        FileError::Io(source) => SceneError::Io {
            path: path.to_path_buf(),
            source,
        },
        e => file_error(e, path, WHAT),
    }
}

/// Reads NFF text (not compressed) from `reader`; `path` names it in messages.
pub fn import_reader(reader: impl Read + Send, path: &Path) -> Result<Imported, SceneError> {
    import_reader_blocks(reader, path, stream::BLOCK)
}

/// `import_reader` with a chosen block size (tests use tiny blocks).
#[doc(hidden)]
pub fn import_reader_blocks(
    reader: impl Read + Send,
    path: &Path,
    block: usize,
) -> Result<Imported, SceneError> {
    import_limited(reader, path, block, &LoadOptions::default())
}

fn import_limited(
    reader: impl Read + Send,
    path: &Path,
    block: usize,
    options: &LoadOptions,
) -> Result<Imported, SceneError> {
    let mut a = Assembler::new(path, options);
    stream::parse_stream(
        TextReader::new(reader, NFF_MAX_LINE),
        block.max(1),
        |results| a.block(results),
        |e| read_error(e, path),
    )?;
    a.finish()
}

/// Parses NFF text held in memory; `path` names it in messages.
pub fn parse_str(text: &str, path: &Path) -> Result<Imported, SceneError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let options = LoadOptions::default();
    let mut a = Assembler::new(path, &options);
    let block = stream::Block {
        text: text.as_bytes().to_vec(),
        next: None,
    };
    a.block(stream::parse_block(&block))?;
    a.finish()
}

/// sRGB-encoded display value to linear.
fn linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_rgb(c: [f64; 3]) -> [f64; 3] {
    c.map(linear)
}

/// NFF's `f` as a Luxon material.
pub fn material_of_fill(f: [f64; 8]) -> MaterialDesc {
    let [r, g, b, kd, ks, shine, t, ior] = f;
    MaterialDesc {
        color: linear_rgb([r, g, b]),
        ambient: if ks == 0.0 && t == 0.0 {
            (1.0 - kd).max(0.0)
        } else {
            0.0
        },
        diffuse: kd,
        specular: ks,
        shininess: shine,
        highlight: Highlight::Phong,
        reflect: ks,
        transmit: t,
        ior: if ior > 0.0 { ior } else { 1.0 },
        ..MaterialDesc::default()
    }
}

/// The vertical field of view (degrees) of an image `height` pixels high whose outer pixel
/// centres are `angle` degrees apart.
pub fn fov_of_angle(angle: f64, height: u32) -> f64 {
    if height < 2 {
        return angle;
    }
    let h = height as f64;
    let half = (angle.to_radians() / 2.0).tan() * h / (h - 1.0);
    2.0 * half.atan().to_degrees()
}

type Rgb = [f64; 3];

/// Puts parsed chunks together in file order.
struct Assembler<'o> {
    file: Arc<PathBuf>,
    options: &'o LoadOptions,
    /// Bytes of geometry held (the arrays' capacities), within `options.max_geometry`.
    held: u64,
    /// Lines before the next chunk.
    line_base: u64,
    materials: Vec<(String, Spanned<MaterialDesc>)>,
    material_ids: HashMap<[u64; 8], usize>,
    /// The material in effect after the chunks so far.
    current: Option<usize>,
    inline: Vec<InlineGeometry>,
    view: Option<Spanned<View>>,
    background: Option<[f64; 3]>,
    /// Position and colour (`None`: white, sharing the brightness).
    lights: Vec<(Spanned<[f64; 3]>, Option<Rgb>)>,
    stats: NffStats,
    /// The first warning of each kind, and how many more of the kind there were.
    warnings: Vec<(Warning, u64)>,
    warning_of_kind: HashMap<NoteKind, usize>,
}

impl<'o> Assembler<'o> {
    fn new(path: &Path, options: &'o LoadOptions) -> Assembler<'o> {
        Assembler {
            file: Arc::new(path.to_path_buf()),
            options,
            held: 0,
            line_base: 0,
            materials: Vec::new(),
            material_ids: HashMap::new(),
            current: None,
            inline: Vec::new(),
            view: None,
            background: None,
            lights: Vec::new(),
            stats: NffStats::default(),
            warnings: Vec::new(),
            warning_of_kind: HashMap::new(),
        }
    }

    fn origin(&self, at: parse::Loc) -> Origin {
        Origin {
            file: self.file.clone(),
            line: u32::try_from(self.line_base + at.line as u64 + 1).unwrap_or(u32::MAX),
            col: at.col,
        }
    }

    fn block(&mut self, results: Vec<Result<ChunkOut, ChunkError>>) -> Result<(), SceneError> {
        for r in results {
            match r {
                Ok(chunk) => self.chunk(chunk)?,
                Err(e) => {
                    return Err(SceneError::At {
                        at: self.origin(e.at),
                        message: e.message,
                    })
                }
            }
        }
        Ok(())
    }

    fn chunk(&mut self, c: ChunkOut) -> Result<(), SceneError> {
        self.hold(&c)?;
        let ids: Vec<usize> = c
            .fills
            .iter()
            .map(|(f, at)| self.material(*f, *at))
            .collect();
        for (d, at) in c.directives {
            let origin = self.origin(at);
            match d {
                Directive::View(v) => {
                    self.view = Some(Spanned {
                        value: v,
                        at: origin,
                    })
                }
                Directive::Background(b) => self.background = Some(b),
                Directive::Light { position, color } => self.lights.push((
                    Spanned {
                        value: position,
                        at: origin,
                    },
                    color,
                )),
            }
        }
        for b in c.buckets {
            let material = b.material.map(|l| ids[l as usize]).or(self.current);
            let material = material.map(|m| Spanned {
                value: self.materials[m].0.clone(),
                at: self.materials[m].1.at.clone(),
            });
            self.inline.push(InlineGeometry {
                material,
                at: Some(self.origin(b.first)),
                clip: None,
                shadowless: false,
                spheres: b.spheres,
                cones: b.cones,
                discs: Vec::new(),
                planes: Vec::new(),
                mesh: InlineMesh {
                    positions: b.positions,
                    normals: b.normals,
                    indices: b.indices,
                    uvs: Vec::new(),
                    colors: Vec::new(),
                },
            });
        }
        if let Some(l) = c.end_fill {
            self.current = Some(ids[l as usize]);
        }
        for note in c.notes {
            match self.warning_of_kind.get(&note.kind) {
                Some(&i) => self.warnings[i].1 += 1,
                None => {
                    self.warning_of_kind.insert(note.kind, self.warnings.len());
                    let at = self.origin(note.at);
                    let warning = Warning {
                        at,
                        message: note.message,
                    };
                    self.warnings.push((warning, 0));
                }
            }
        }
        self.stats += c.stats;
        self.stats.lines += c.lines as u64;
        self.line_base += c.lines as u64;
        Ok(())
    }

    /// Counts a chunk's geometry (its arrays' capacities) against `max_geometry`.
    fn hold(&mut self, c: &ChunkOut) -> Result<(), SceneError> {
        fn held<T>(v: &Vec<T>) -> u64 {
            (v.capacity() * std::mem::size_of::<T>()) as u64
        }
        for b in &c.buckets {
            self.held += held(&b.spheres)
                + held(&b.cones)
                + held(&b.positions)
                + held(&b.normals)
                + held(&b.indices);
        }
        if self.held <= self.options.max_geometry {
            return Ok(());
        }
        let mut s = self.stats;
        s += c.stats;
        let what = format!(
            "its {} spheres, {} cones and {} triangles up to line {}",
            s.spheres,
            s.cones,
            s.triangles,
            self.line_base + c.lines as u64
        );
        Err(self.options.over_geometry(&self.file, &what, self.held))
    }

    fn material(&mut self, f: Fill, at: parse::Loc) -> usize {
        let key = f.map(f64::to_bits);
        if let Some(&i) = self.material_ids.get(&key) {
            return i;
        }
        let i = self.materials.len();
        let origin = self.origin(at);
        self.materials.push((
            format!("nff-{i}"),
            Spanned {
                value: material_of_fill(f),
                at: origin,
            },
        ));
        self.material_ids.insert(key, i);
        i
    }

    fn finish(mut self) -> Result<Imported, SceneError> {
        let Some(view) = self.view.take() else {
            return Err(SceneError::At {
                at: Origin {
                    file: self.file.clone(),
                    line: 1,
                    col: 1,
                },
                message: "the file has no `v` view; expected `v` followed by lines `from x y z`, \
                          `at x y z`, `up x y z`, `angle degrees`"
                    .into(),
            });
        };
        let v = &view.value;
        let (width, height) = v.resolution.unwrap_or((512, 512));
        let camera = Spanned {
            value: CameraDesc {
                position: v.from,
                look_at: v.at,
                up: v.up,
                projection: Projection::Perspective {
                    fov_deg: fov_of_angle(v.angle, height),
                },
                aspect: Some(width as f64 / height as f64),
                frustum: None,
                depth_of_field: None,
                stereo: None,
            },
            at: view.at.clone(),
        };
        let n = self.lights.len().max(1) as f64;
        let lights = self
            .lights
            .into_iter()
            .map(|(p, color)| Spanned {
                value: LightDesc::Point {
                    position: p.value,
                    color: color.map_or([1.0; 3], linear_rgb),
                    intensity: if color.is_some() { 1.0 } else { 1.0 / n.sqrt() },
                    attenuation: Default::default(),
                    shadows: true,
                },
                at: p.at,
            })
            .collect();
        self.stats.materials = self.materials.len() as u64;
        let desc = SceneDesc {
            source: self.file.as_ref().clone(),
            camera,
            background: BackgroundDesc::Color(linear_rgb(self.background.unwrap_or([0.0; 3]))),
            lights,
            fog: None,
            ambient_occlusion: None,
            textures: Vec::new(),
            materials: self.materials,
            clip_groups: Vec::new(),
            objects: Vec::new(),
            inline: self.inline,
            volumes: Vec::new(),
            render: RenderDesc {
                width,
                height,
                samples: 1,
                max_depth: 5,
                outputs: Vec::new(),
                ..RenderDesc::default()
            },
            animation: None,
            prototypes: Vec::new(),
            instances: Vec::new(),
            series: Vec::new(),
            plugin_path: Vec::new(),
            warnings: self
                .warnings
                .into_iter()
                .map(|(mut w, more)| {
                    if more > 0 {
                        w.message
                            .push_str(&format!(" ({more} more like it in this file)"));
                    }
                    w
                })
                .collect(),
        };
        Ok(Imported {
            desc,
            stats: self.stats,
        })
    }
}
