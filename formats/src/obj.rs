//! # OBJ: Wavefront triangle meshes and their MTL materials (through `tobj`)
//!
//! [`load_obj`] reads a `.obj` file (and the `.mtl` files it names with `mtllib`) into inline
//! native geometry ([`InlineGeometry`]): one triangle mesh per OBJ object/group and material.
//!
//! - Faces with more than 3 vertices are triangulated (tobj's fan triangulation: n-gons in OBJ
//!   files are, by the format's convention, convex); negative (relative) indices are resolved.
//! - Positions, normals and texture coordinates are unified per vertex (a vertex is a distinct
//!   `v/vt/vn` triple), so `normals` and `uvs` are empty or have one entry per position.
//! - Vertex colours (`v x y z r g b`, as MeshLab and others write them) become the mesh's
//!   `colors`, which multiply the material's colour (negative components are taken as 0).
//! - A mesh without (complete) normals gets smooth vertex normals: the area-weighted mean of the
//!   normals of the faces around each position (per mesh; vertices split by a texture seam
//!   share their normal). Faces are counter-clockwise seen from the front, as OBJ expects.
//! - MTL materials become [`MaterialDesc`]s named `obj:<file stem>:<mtl name>`: `Kd` the
//!   colour (diffuse 1), `Ka` and `Ks` the means of their RGB as `ambient` and `specular`,
//!   `Ns` the shininess, `d` (or `Tr`) the transmission `1 - d` (`Tr`), `Ni` the index of
//!   refraction. Colours are taken as linear. Textures are not read.
//! - A missing or broken `.mtl` file is a warning, not an error: its faces get Luxon's default
//!   material (so does `usemtl` of a name no `.mtl` file defines). A material defined twice
//!   takes its last definition, with a warning.
//! - Lines (`l`) and points (`p`) are left out with a warning that counts them: Luxon draws
//!   faces only.
//! - Errors (missing file, not a regular file, not text, bad numbers, faces with fewer than 3
//!   corners or indices out of bounds) name the file and, where it can be found, the line.
//!   Warnings go to the import's (and the scene's) `warnings`.

use std::cell::RefCell;
use std::collections::HashMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use luxon_plugin::files::{open_regular, TextReader};

use crate::desc::{
    BackgroundDesc, CameraDesc, LightDesc, MaterialDesc, Origin, Projection, RenderDesc, SceneDesc,
    Spanned,
};
use crate::error::{shown, SceneError, Warning};
use crate::geometry::{InlineGeometry, InlineMesh};
use crate::input::{file_error, FileError, LoadOptions, MTL_MAX_BYTES, OBJ_MAX_LINE};

/// What an OBJ file held.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjImport {
    /// Materials of the MTL files, named `obj:<file stem>:<mtl name>`, in MTL order.
    pub materials: Vec<(String, Spanned<MaterialDesc>)>,
    /// One triangle mesh per OBJ object/group and material (empty ones left out).
    pub geometry: Vec<InlineGeometry>,
    /// Problems that did not stop the import (a missing `.mtl` file...).
    pub warnings: Vec<Warning>,
}

/// True for names ending in `.obj` (any case).
pub fn is_obj_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// Reads an OBJ file and its MTL files. `at`: where a scene names the file; errors are then
/// reported there (naming the OBJ file and line in the message) and the geometry and
/// materials carry it as their origin. Without it, the OBJ file itself is the origin.
pub fn load_obj(path: &Path, at: Option<Origin>) -> Result<ObjImport, SceneError> {
    load_obj_with(path, at, &LoadOptions::default())
}

/// [`load_obj`] within the limits of `options`: a file whose geometry would take more than
/// `max_geometry` (estimated from its statements before it is read into meshes) is an error
/// naming it.
pub fn load_obj_with(
    path: &Path,
    at: Option<Origin>,
    options: &LoadOptions,
) -> Result<ObjImport, SceneError> {
    let file = ObjFile {
        path,
        at: at.as_ref(),
        options,
    };
    let Parsed {
        models,
        materials,
        mut warnings,
    } = file.parse()?;
    let (names, materials) = named_materials(&file, &materials, &mut warnings);
    let geometry = models
        .into_iter()
        .filter_map(|model| mesh_of_model(model, &names, &file, &mut warnings))
        .collect();
    Ok(ObjImport {
        materials,
        geometry,
        warnings,
    })
}

/// What tobj read: the models, the MTL materials and warnings (MTL files that could not be
/// read, statements Luxon does not draw).
struct Parsed {
    models: Vec<tobj::Model>,
    materials: Vec<tobj::Material>,
    warnings: Vec<Warning>,
}

/// The OBJ file being read and where a scene names it (if one does): places its errors.
struct ObjFile<'a> {
    path: &'a Path,
    at: Option<&'a Origin>,
    options: &'a LoadOptions,
}

impl ObjFile<'_> {
    /// Line `line` of the OBJ file itself.
    fn line_origin(&self, line: u32) -> Origin {
        Origin {
            file: Arc::new(self.path.to_path_buf()),
            line,
            col: 1,
        }
    }

    /// What the imported geometry and materials name as their origin.
    fn origin(&self) -> Origin {
        self.at.cloned().unwrap_or_else(|| self.line_origin(1))
    }

    /// Where a problem at `line` of the OBJ file (0: no line known) is reported, and the
    /// message saying so: at the scene's mention of the file, naming the line, if a scene
    /// names it; else at the line.
    fn place(&self, line: u32, message: String) -> (Origin, String) {
        match self.at {
            Some(at) => (
                at.clone(),
                if line > 0 {
                    format!("in mesh file {}:{line}: {message}", self.path.display())
                } else {
                    format!("mesh file `{}`: {message}", self.path.display())
                },
            ),
            None => (self.line_origin(line.max(1)), message),
        }
    }

    /// An error at `line` of the OBJ file (0: no line known).
    fn fail(&self, line: u32, message: String) -> SceneError {
        let (at, message) = self.place(line, message);
        SceneError::at(at, message)
    }

    /// A warning at `line` of the OBJ file (0: no line known).
    fn warn(&self, line: u32, message: String) -> Warning {
        let (at, message) = self.place(line, message);
        Warning { at, message }
    }

    /// The file could not be read (as a whole, or at a line of its text).
    fn unreadable(&self, e: FileError) -> SceneError {
        match (self.at, e.position()) {
            (None, _) => file_error(e, self.path, "a Wavefront .obj file"),
            (Some(_), Some((line, _))) => {
                self.fail(to_u32(line), e.explain("a Wavefront .obj file"))
            }
            (Some(at), None) => SceneError::at(
                at.clone(),
                format!(
                    "mesh file {}",
                    e.sentence(self.path, "a Wavefront .obj file")
                ),
            ),
        }
    }

    /// The file as text, line by line: a regular file, lines of bounded length.
    fn open(&self) -> Result<TextReader<BufReader<File>>, SceneError> {
        let (file, _) = open_regular(self.path, u64::MAX).map_err(|e| self.unreadable(e))?;
        Ok(TextReader::new(
            BufReader::with_capacity(1 << 16, file),
            OBJ_MAX_LINE,
        ))
    }

    /// The file through tobj, after our own pass over it (`prescan`).
    fn parse(&self) -> Result<Parsed, SceneError> {
        let scan = self.prescan()?;
        let needs = scan.import_bytes();
        if needs > self.options.max_geometry {
            let what = format!(
                "its {} vertices and {} triangles",
                scan.positions, scan.triangles
            );
            return Err(self.options.over_geometry(self.path, &what, needs));
        }
        let mut reader = WithoutLines::new(self.open()?);
        let warnings = RefCell::new(scan.warnings);
        let dir = self.path.parent().unwrap_or(Path::new("")).to_path_buf();
        // The update fills the fields tobj's optional features (merging, reordering) add.
        #[allow(clippy::needless_update)]
        let options = tobj::LoadOptions {
            single_index: true,
            triangulate: true,
            ignore_points: true,
            ignore_lines: true,
            ..Default::default()
        };
        // tobj 4.0.5 overflows on absurd face indices (`vt * 2 + 1`, found by fuzzing): the
        // prescan rejects those first, and a panic in tobj all the same becomes an error.
        let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            tobj::load_obj_buf(&mut reader, &options, |mtl: &Path| {
                let line = scan
                    .mtllibs
                    .iter()
                    .find(|(name, _)| Path::new(name) == mtl)
                    .map_or(0, |(_, line)| *line);
                let full = dir.join(mtl);
                Ok(read_mtl(&full).unwrap_or_else(|why| {
                    warnings.borrow_mut().push(self.warn(
                        line,
                        format!(
                            "cannot use material library `{}`: {why}; its materials are \
                             replaced by the default material",
                            full.display()
                        ),
                    ));
                    (Vec::new(), Default::default())
                }))
            })
        }))
        .map_err(|_| {
            self.fail(
                0,
                "a face index is out of range; expected indices of defined vertices".to_string(),
            )
        })?;
        let (models, materials) = loaded.map_err(|e| self.tobj_error(e, reader.line))?;
        Ok(Parsed {
            models,
            materials: materials.unwrap_or_default(),
            warnings: warnings.into_inner(),
        })
    }

    /// tobj's error, found while reading line `line`, as ours.
    fn tobj_error(&self, e: tobj::LoadError, line: u64) -> SceneError {
        // `line` counts from 1; 0 (nothing read yet) means no line is known.
        let line = to_u32(line);
        match e {
            tobj::LoadError::ReadError => {
                self.fail(line, "cannot read it (not UTF-8 text?)".into())
            }
            e => self.fail(
                line,
                format!("{e}; expected OBJ statements such as `v x y z`, `f 1 2 3`"),
            ),
        }
    }

    /// One pass over the file before tobj's: the first face tobj would mishandle (an index
    /// out of range, which tobj reports without a line or overflows on; fewer than 3
    /// corners, which tobj drops silently) is an error at its line, and so is a line that is
    /// not text; `l` and `p` statements (lines and points, which Luxon does not draw) are
    /// counted for a warning; `mtllib` lines are noted to place warnings about them.
    fn prescan(&self) -> Result<Prescan, SceneError> {
        let mut reader = self.open()?;
        let mut out = Prescan::default();
        let (mut v, mut vt, mut vn) = (0i64, 0i64, 0i64);
        let mut ignored: [(u64, u32); 2] = [(0, 0); 2];
        let mut bytes = Vec::new();
        for line in 1u32.. {
            bytes.clear();
            let n = reader
                .read_until(b'\n', &mut bytes)
                .map_err(|e| self.unreadable(FileError::from_io(e)))?;
            if n == 0 {
                break;
            }
            let Ok(text) = std::str::from_utf8(&bytes) else {
                return Err(self.fail(line, "cannot read it: the line is not UTF-8 text".into()));
            };
            let mut words = text.split_whitespace();
            match words.next() {
                Some("v") => v += 1,
                Some("vt") => vt += 1,
                Some("vn") => vn += 1,
                Some("f") => {
                    let corners = bad_face(words, [v, vt, vn]).map_err(|e| self.fail(line, e))?;
                    out.corners += corners;
                    out.triangles += corners - 2;
                }
                Some(k @ ("l" | "p")) => {
                    let slot = &mut ignored[usize::from(k == "p")];
                    if slot.0 == 0 {
                        slot.1 = line;
                    }
                    slot.0 += 1;
                }
                Some("mtllib") => {
                    // The name as tobj takes it: the rest of the line after the first space.
                    let name = text.split_once(' ').unwrap_or_default().1.trim();
                    out.mtllibs.push((name.to_string(), line));
                }
                _ => {}
            }
        }
        for ((count, line), what) in ignored.into_iter().zip(["line (`l`)", "point (`p`)"]) {
            if count > 0 {
                out.warnings.push(self.warn(
                    line,
                    format!(
                        "{count} {what} statement(s), the first here: Luxon draws faces only, \
                         so they are left out"
                    ),
                ));
            }
        }
        [out.positions, out.uvs, out.normals] = [v, vt, vn].map(|n| n as u64);
        Ok(out)
    }
}

/// The OBJ text as tobj reads it, a line at a time, with `l` statements blanked: tobj takes a
/// polyline of 3 or more points for a face, and Luxon draws no lines (they are counted for a
/// warning by the prescan). Counts the lines handed out.
struct WithoutLines<R> {
    inner: R,
    buf: Vec<u8>,
    pos: usize,
    /// The line in `buf` (1-based; 0 before the first).
    line: u64,
}

impl<R: BufRead> WithoutLines<R> {
    fn new(inner: R) -> WithoutLines<R> {
        WithoutLines {
            inner,
            buf: Vec::new(),
            pos: 0,
            line: 0,
        }
    }
}

impl<R: BufRead> Read for WithoutLines<R> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let n = {
            let buf = self.fill_buf()?;
            let n = buf.len().min(out.len());
            out[..n].copy_from_slice(&buf[..n]);
            n
        };
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for WithoutLines<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if self.pos == self.buf.len() {
            self.buf.clear();
            self.pos = 0;
            if self.inner.read_until(b'\n', &mut self.buf)? > 0 {
                self.line += 1;
                let first = self
                    .buf
                    .split(u8::is_ascii_whitespace)
                    .find(|w| !w.is_empty());
                if first == Some(b"l") {
                    let newline = self.buf.ends_with(b"\n");
                    self.buf.clear();
                    if newline {
                        self.buf.push(b'\n');
                    }
                }
            }
        }
        Ok(&self.buf[self.pos..])
    }

    fn consume(&mut self, amt: usize) {
        self.pos = (self.pos + amt).min(self.buf.len());
    }
}

/// What the prescan found besides errors.
#[derive(Default)]
struct Prescan {
    /// `mtllib` names and their lines.
    mtllibs: Vec<(String, u32)>,
    warnings: Vec<Warning>,
    /// `v`, `vt` and `vn` statements.
    positions: u64,
    uvs: u64,
    normals: u64,
    /// Corners of the faces, and the triangles they become.
    corners: u64,
    triangles: u64,
}

impl Prescan {
    /// Bytes the import takes at its peak, estimated from the statements (tobj gives no way
    /// to bound its allocations, so this is checked before it runs): tobj's tables of what the
    /// file defines (f64) and of its faces' corners; the meshes it builds (a vertex per
    /// distinct corner: usually about one per position, which is what is counted), with the
    /// index map that builds them; and the inline geometry they become.
    fn import_bytes(&self) -> u64 {
        let (v, t) = (self.positions, self.triangles);
        let tables = 24 * v + 16 * self.uvs + 24 * self.normals + 24 * self.corners;
        let meshes = v * (24 + 24 + 16 + 48) + 12 * t;
        let inline = v * (24 + 24 + 16) + 24 * t;
        tables.saturating_add(meshes).saturating_add(inline)
    }
}

/// What is wrong with a face (the words after `f`), given the counts of vertices, texture
/// coordinates and normals defined so far.
/// `Ok`: its number of corners.
fn bad_face<'a>(words: impl Iterator<Item = &'a str>, counts: [i64; 3]) -> Result<u64, String> {
    let mut corners = 0;
    for word in words {
        corners += 1;
        for (k, part) in word.split('/').enumerate().take(3) {
            let Ok(index) = part.parse::<i64>() else {
                continue;
            };
            let count = counts[k];
            let what = ["vertex", "texture coordinate", "normal"][k];
            let resolved = if index < 0 { count + index + 1 } else { index };
            if resolved < 1 || resolved > count {
                return Err(format!(
                    "face {what} index {index} is out of bounds; expected 1 to {count} (or -1 \
                     to -{count}: relative to the last one) with {count} defined so far"
                ));
            }
        }
    }
    if corners < 3 {
        return Err(format!("a face needs at least 3 vertices, found {corners}"));
    }
    Ok(corners)
}

/// An MTL file's materials, or why it cannot be used.
fn read_mtl(path: &Path) -> Result<(Vec<tobj::Material>, HashMap<String, usize>), String> {
    let text =
        luxon_plugin::files::read_text(path, MTL_MAX_BYTES).map_err(|e| format!("it {e}"))?;
    let mut reader = TextReader::new(text.as_bytes(), OBJ_MAX_LINE);
    tobj::load_mtl_buf(&mut reader).map_err(|e| format!("it cannot be read ({e})"))
}

fn to_u32(n: u64) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// The MTL materials as Luxon materials named `obj:<file stem>:<mtl name>`, in MTL order,
/// and per MTL material its name (a model's `material_id` indexes them). A name defined
/// twice (in one library or two) keeps its first place and takes the last definition, with
/// a warning.
fn named_materials(
    file: &ObjFile,
    materials: &[tobj::Material],
    warnings: &mut Vec<Warning>,
) -> (Vec<String>, Vec<(String, Spanned<MaterialDesc>)>) {
    let stem = file
        .path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let origin = file.origin();
    let names: Vec<String> = materials
        .iter()
        .map(|m| format!("obj:{stem}:{}", m.name))
        .collect();
    let mut out: Vec<(String, Spanned<MaterialDesc>)> = Vec::new();
    let mut place: HashMap<&str, usize> = HashMap::new();
    // The first name defined again, and how many more definitions repeat a name.
    let mut repeated: Option<(&str, usize)> = None;
    for (m, name) in materials.iter().zip(&names) {
        let material = Spanned {
            value: material_of_mtl(m),
            at: origin.clone(),
        };
        match place.get(name.as_str()) {
            Some(&i) => {
                repeated.get_or_insert((&m.name, 0)).1 += 1;
                out[i].1 = material;
            }
            None => {
                place.insert(name, out.len());
                out.push((name.clone(), material));
            }
        }
    }
    if let Some((name, count)) = repeated {
        let more = match count {
            1 => String::new(),
            n => format!(" ({} more repeated definitions)", n - 1),
        };
        warnings.push(file.warn(
            0,
            format!(
                "material `{}` is defined more than once in its material libraries; the last \
                 definition is used{more}",
                shown(name)
            ),
        ));
    }
    (names, out)
}

/// One tobj model as a triangle mesh (`None`: it has no triangle), with smooth normals where
/// the file gives none or too few (the latter with a warning).
fn mesh_of_model(
    model: tobj::Model,
    names: &[String],
    file: &ObjFile,
    warnings: &mut Vec<Warning>,
) -> Option<InlineGeometry> {
    let origin = &file.origin();
    let m = model.mesh;
    if m.indices.len() < 3 {
        return None;
    }
    let positions: Vec<[f64; 3]> = m
        .positions
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    let indices: Vec<[u64; 3]> = m
        .indices
        .chunks_exact(3)
        .map(|t| [t[0] as u64, t[1] as u64, t[2] as u64])
        .collect();
    let normals = if m.normals.len() == m.positions.len() {
        m.normals
            .chunks_exact(3)
            .map(|n| [n[0], n[1], n[2]])
            .collect()
    } else {
        if !m.normals.is_empty() {
            warnings.push(file.warn(
                0,
                format!(
                    "object `{}` gives normals for some vertices only; computed smooth \
                     normals for all",
                    shown(&model.name)
                ),
            ));
        }
        smooth_normals(&positions, &indices)
    };
    let uvs = if m.texcoords.len() / 2 == positions.len() {
        m.texcoords.chunks_exact(2).map(|t| [t[0], t[1]]).collect()
    } else {
        Vec::new()
    };
    // `v x y z r g b`: colours of all vertices or none (tobj keeps them only then).
    let colors = if m.vertex_color.len() == m.positions.len() {
        m.vertex_color
            .chunks_exact(3)
            .map(|c| [c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)])
            .collect()
    } else {
        Vec::new()
    };
    let material = m.material_id.and_then(|i| names.get(i)).map(|n| Spanned {
        value: n.clone(),
        at: origin.clone(),
    });
    Some(InlineGeometry {
        material,
        at: Some(origin.clone()),
        mesh: InlineMesh {
            positions,
            normals,
            indices,
            uvs,
            colors,
        },
        ..InlineGeometry::default()
    })
}

/// An MTL material as a Luxon material.
pub fn material_of_mtl(m: &tobj::Material) -> MaterialDesc {
    let d = MaterialDesc::default();
    let mean = |c: [f64; 3]| ((c[0] + c[1] + c[2]) / 3.0).clamp(0.0, 1.0);
    let transmit = match (m.dissolve, m.unknown_param.get("Tr")) {
        (Some(d), _) => 1.0 - d,
        (None, Some(tr)) => tr.trim().parse::<f64>().unwrap_or(0.0),
        (None, None) => 0.0,
    };
    MaterialDesc {
        color: m.diffuse.map_or(d.color, |c| c.map(|x| x.max(0.0))),
        ambient: m.ambient.map_or(d.ambient, mean),
        diffuse: 1.0,
        specular: m.specular.map_or(d.specular, mean),
        shininess: m
            .shininess
            .filter(|s| s.is_finite() && *s > 0.0)
            .unwrap_or(d.shininess),
        transmit: if transmit.is_finite() {
            transmit.clamp(0.0, 1.0)
        } else {
            0.0
        },
        ior: m
            .optical_density
            .filter(|n| n.is_finite() && *n > 0.0)
            .unwrap_or(1.0),
        ..d
    }
}

/// Area-weighted smooth normals, accumulated per distinct position (so that vertices split by
/// texture seams get the same normal). A position on degenerate faces only gets +z.
fn smooth_normals(positions: &[[f64; 3]], indices: &[[u64; 3]]) -> Vec<[f64; 3]> {
    let mut slot_of: HashMap<[u64; 3], usize> = HashMap::new();
    let slots: Vec<usize> = positions
        .iter()
        .map(|p| {
            let n = slot_of.len();
            *slot_of.entry(p.map(f64::to_bits)).or_insert(n)
        })
        .collect();
    let mut sums = vec![[0.0f64; 3]; slot_of.len()];
    for t in indices {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let u = sub(b, a);
        let v = sub(c, a);
        // |u x v| is twice the area: the weighting.
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        for i in t {
            let s = &mut sums[slots[*i as usize]];
            for k in 0..3 {
                s[k] += n[k];
            }
        }
    }
    slots
        .iter()
        .map(|&s| {
            let n = sums[s];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                n.map(|x| x / len)
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Loads an OBJ file as a whole scene: the mesh seen from the front (the -z side) by a camera
/// that fits its bounding box, one point light near the camera, 512x512. Warnings go to the
/// scene's `warnings`.
pub fn load(path: &Path) -> Result<SceneDesc, SceneError> {
    load_with(path, &LoadOptions::default())
}

/// [`load`] within the limits of `options`.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<SceneDesc, SceneError> {
    let import = load_obj_with(path, None, options)?;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for g in &import.geometry {
        for p in &g.mesh.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    if lo[0] > hi[0] {
        lo = [-1.0; 3];
        hi = [1.0; 3];
    }
    let center = [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2.0);
    let half = [0, 1, 2].map(|k| (hi[k] - lo[k]) / 2.0);
    let radius = (half[0] * half[0] + half[1] * half[1] + half[2] * half[2])
        .sqrt()
        .max(1e-6);
    let fov_deg: f64 = 40.0;
    // The bounding sphere fits the view with a margin.
    let distance = 1.1 * radius / (fov_deg.to_radians() / 2.0).sin();
    let position = [center[0], center[1], center[2] - distance];
    let at = Origin {
        file: Arc::new(path.to_path_buf()),
        line: 1,
        col: 1,
    };
    let light = [
        position[0] + 0.5 * distance,
        position[1] + 0.5 * distance,
        position[2],
    ];
    let width = 512;
    let height = 512;
    Ok(SceneDesc {
        source: PathBuf::from(path),
        camera: Spanned {
            value: CameraDesc {
                position,
                look_at: center,
                up: [0.0, 1.0, 0.0],
                projection: Projection::Perspective { fov_deg },
                aspect: None,
                frustum: None,
                depth_of_field: None,
                stereo: None,
            },
            at: at.clone(),
        },
        background: BackgroundDesc::default(),
        lights: vec![Spanned {
            value: LightDesc::Point {
                position: light,
                color: [1.0; 3],
                intensity: 1.0,
                shadows: true,
                attenuation: Default::default(),
            },
            at,
        }],
        fog: None,
        ambient_occlusion: None,
        textures: Vec::new(),
        materials: import.materials,
        clip_groups: Vec::new(),
        objects: Vec::new(),
        inline: import.geometry,
        volumes: Vec::new(),
        render: RenderDesc {
            width,
            height,
            ..RenderDesc::default()
        },
        animation: None,
        prototypes: Vec::new(),
        instances: Vec::new(),
        series: Vec::new(),
        plugin_path: Vec::new(),
        warnings: import.warnings,
    })
}
