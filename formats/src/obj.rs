//! # OBJ: Wavefront triangle meshes and their MTL materials (through `tobj`)
//!
//! [`load_obj`] reads a `.obj` file (and the `.mtl` files it names with `mtllib`) into inline
//! native geometry ([`InlineGeometry`]): one triangle mesh per OBJ object/group and material.
//!
//! - Faces with more than 3 vertices are triangulated (tobj's fan triangulation: n-gons in OBJ
//!   files are, by the format's convention, convex); negative (relative) indices are resolved.
//! - Positions, normals and texture coordinates are unified per vertex (a vertex is a distinct
//!   `v/vt/vn` triple), so `normals` and `uvs` are empty or have one entry per position.
//! - A mesh without (complete) normals gets smooth vertex normals: the area-weighted mean of the
//!   normals of the faces around each position (per mesh; vertices split by a texture seam
//!   share their normal). Faces are counter-clockwise seen from the front, as OBJ expects.
//! - MTL materials become [`MaterialDesc`]s named `obj:<file stem>:<mtl name>`: `Kd` the
//!   colour (diffuse 1), `Ka` and `Ks` the means of their RGB as `ambient` and `specular`,
//!   `Ns` the shininess, `d` (or `Tr`) the transmission `1 - d` (`Tr`), `Ni` the index of
//!   refraction. Colours are taken as linear. Textures are not read.
//! - A missing or broken `.mtl` file is a warning, not an error: its faces get Luxon's default
//!   material (so does `usemtl` of a name no `.mtl` file defines).
//! - Errors (missing file, bad numbers, bad faces, indices out of bounds) name the file and,
//!   where it can be found, the line.

use std::cell::RefCell;
use std::collections::HashMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::desc::{
    CameraDesc, LightDesc, MaterialDesc, Origin, Projection, RenderDesc, SceneDesc, Spanned,
};
use crate::error::SceneError;
use crate::geometry::{InlineGeometry, InlineMesh};

/// What an OBJ file held.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjImport {
    /// Materials of the MTL files, named `obj:<file stem>:<mtl name>`, in MTL order.
    pub materials: Vec<(String, Spanned<MaterialDesc>)>,
    /// One triangle mesh per OBJ object/group and material (empty ones left out).
    pub geometry: Vec<InlineGeometry>,
    /// Problems that did not stop the import (a missing `.mtl` file...), as sentences.
    pub warnings: Vec<String>,
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
    let file = ObjFile {
        path,
        at: at.as_ref(),
    };
    let Parsed {
        models,
        materials,
        mut warnings,
    } = file.parse()?;
    let origin = file.origin();
    let (names, materials) = named_materials(path, &materials, &origin);
    let geometry = models
        .into_iter()
        .filter_map(|model| mesh_of_model(model, &names, &origin, path, &mut warnings))
        .collect();
    Ok(ObjImport {
        materials,
        geometry,
        warnings,
    })
}

/// What tobj read: the models, the MTL materials and warnings about MTL files that could not
/// be read.
struct Parsed {
    models: Vec<tobj::Model>,
    materials: Vec<tobj::Material>,
    warnings: Vec<String>,
}

/// The OBJ file being read and where a scene names it (if one does): places its errors.
struct ObjFile<'a> {
    path: &'a Path,
    at: Option<&'a Origin>,
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

    /// An error at `line` of the OBJ file (0: no line known).
    fn fail(&self, line: u32, message: String) -> SceneError {
        match self.at {
            Some(at) => SceneError::at(
                at.clone(),
                if line > 0 {
                    format!("in mesh file {}:{line}: {message}", self.path.display())
                } else {
                    format!("mesh file `{}`: {message}", self.path.display())
                },
            ),
            None => SceneError::at(self.line_origin(line.max(1)), message),
        }
    }

    /// The file through tobj.
    fn parse(&self) -> Result<Parsed, SceneError> {
        let file = File::open(self.path).map_err(|e| match self.at {
            Some(_) => self.fail(
                0,
                format!("cannot read it: {e}; expected a Wavefront .obj file"),
            ),
            None => SceneError::Io {
                path: self.path.to_path_buf(),
                source: e,
            },
        })?;
        let mut reader = Counting {
            inner: BufReader::with_capacity(1 << 16, file),
            newlines: 0,
            last: b'\n',
        };
        let warnings = RefCell::new(Vec::new());
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
        // tobj 4.0.5 overflows on absurd face indices (`vt * 2 + 1`, found by fuzzing): faces
        // are checked first by our own scan (one more pass over the file), and a panic in tobj
        // all the same becomes an error.
        if let Some((line, detail)) = find_bad_face(self.path) {
            return Err(self.fail(line, detail));
        }
        let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            tobj::load_obj_buf(&mut reader, &options, |mtl: &Path| {
                let full = dir.join(mtl);
                match tobj::load_mtl(&full) {
                    Ok(r) => Ok(r),
                    Err(e) => {
                        let why = match e {
                            tobj::LoadError::OpenFileFailed => "cannot open it".to_string(),
                            e => format!("cannot read it ({e})"),
                        };
                        warnings.borrow_mut().push(format!(
                            "{}: material library `{}`: {why}; its materials are replaced by the \
                     default material",
                            self.path.display(),
                            full.display()
                        ));
                        Ok((Vec::new(), Default::default()))
                    }
                }
            })
        }))
        .map_err(|_| {
            let (line, detail) = find_bad_face(self.path).unwrap_or((
                0,
                "a face index is out of range; expected indices of defined vertices".to_string(),
            ));
            self.fail(line, detail)
        })?;
        let (models, materials) = loaded.map_err(|e| self.tobj_error(e, reader.line()))?;
        Ok(Parsed {
            models,
            materials: materials.unwrap_or_default(),
            warnings: warnings.into_inner(),
        })
    }

    /// tobj's error, found while reading line `line`, as ours.
    fn tobj_error(&self, e: tobj::LoadError, line: u32) -> SceneError {
        match e {
            tobj::LoadError::FaceVertexOutOfBounds
            | tobj::LoadError::FaceTexCoordOutOfBounds
            | tobj::LoadError::FaceNormalOutOfBounds
            | tobj::LoadError::FaceColorOutOfBounds => {
                // tobj finds these when a group ends: look for the face ourselves.
                let (line, detail) = find_bad_face(self.path).unwrap_or((0, e.to_string()));
                self.fail(line, detail)
            }
            tobj::LoadError::ReadError => self.fail(0, "cannot read it (not UTF-8 text?)".into()),
            e => self.fail(
                line,
                format!("{e}; expected OBJ statements such as `v x y z`, `f 1 2 3`"),
            ),
        }
    }
}

/// The MTL materials as Luxon materials named `obj:<file stem>:<mtl name>`, with those names
/// in MTL order (a model's `material_id` indexes them).
fn named_materials(
    path: &Path,
    materials: &[tobj::Material],
    origin: &Origin,
) -> (Vec<String>, Vec<(String, Spanned<MaterialDesc>)>) {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let names: Vec<String> = materials
        .iter()
        .map(|m| format!("obj:{stem}:{}", m.name))
        .collect();
    let out = materials
        .iter()
        .zip(&names)
        .map(|(m, name)| {
            (
                name.clone(),
                Spanned {
                    value: material_of_mtl(m),
                    at: origin.clone(),
                },
            )
        })
        .collect();
    (names, out)
}

/// One tobj model as a triangle mesh (`None`: it has no triangle), with smooth normals where
/// the file gives none or too few (the latter with a warning).
fn mesh_of_model(
    model: tobj::Model,
    names: &[String],
    origin: &Origin,
    path: &Path,
    warnings: &mut Vec<String>,
) -> Option<InlineGeometry> {
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
            warnings.push(format!(
                "{}: object `{}` gives normals for some vertices only; computed smooth \
                 normals for all",
                path.display(),
                model.name
            ));
        }
        smooth_normals(&positions, &indices)
    };
    let uvs = if m.texcoords.len() / 2 == positions.len() {
        m.texcoords.chunks_exact(2).map(|t| [t[0], t[1]]).collect()
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

/// The first face with an index out of range: (line, message).
fn find_bad_face(path: &Path) -> Option<(u32, String)> {
    let bytes = std::fs::read(path).ok()?;
    let text = String::from_utf8_lossy(&bytes);
    let (mut v, mut vt, mut vn) = (0i64, 0i64, 0i64);
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => v += 1,
            Some("vt") => vt += 1,
            Some("vn") => vn += 1,
            Some("f") => {
                for word in words {
                    for (k, part) in word.split('/').enumerate().take(3) {
                        if part.is_empty() {
                            continue;
                        }
                        let Ok(index) = part.parse::<i64>() else {
                            continue;
                        };
                        let (count, what) = match k {
                            0 => (v, "vertex"),
                            1 => (vt, "texture coordinate"),
                            _ => (vn, "normal"),
                        };
                        let resolved = if index < 0 { count + index + 1 } else { index };
                        if resolved < 1 || resolved > count {
                            return Some((
                                u32::try_from(i + 1).unwrap_or(u32::MAX),
                                format!(
                                    "face {what} index {index} is out of bounds; expected 1 to \
                                     {count} (or -1 to -{count}: relative to the last one) with \
                                     {count} defined so far"
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// Counts the lines a `BufRead` hands out, to place tobj's parse errors.
struct Counting<R> {
    inner: R,
    newlines: u64,
    last: u8,
}

impl<R: BufRead> Counting<R> {
    /// The line being read (the last one handed out).
    fn line(&self) -> u32 {
        let line = if self.last == b'\n' {
            self.newlines
        } else {
            self.newlines + 1
        };
        u32::try_from(line.max(1)).unwrap_or(u32::MAX)
    }

    fn count(&mut self, bytes: &[u8]) {
        self.newlines += bytes.iter().filter(|&&b| b == b'\n').count() as u64;
        if let Some(&b) = bytes.last() {
            self.last = b;
        }
    }
}

impl<R: BufRead> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count(&buf[..n]);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Counting<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }

    fn consume(&mut self, amt: usize) {
        if amt > 0 {
            // The buffer is already filled: this returns it without reading.
            if let Ok(buf) = self.inner.fill_buf() {
                let n = amt.min(buf.len());
                let consumed = buf[..n].to_vec();
                self.count(&consumed);
            }
        }
        self.inner.consume(amt);
    }
}

/// Loads an OBJ file as a whole scene: the mesh seen from the front (the -z side) by a camera
/// that fits its bounding box, one point light near the camera, 512x512. Warnings go to
/// standard error.
pub fn load(path: &Path) -> Result<SceneDesc, SceneError> {
    let import = load_obj(path, None)?;
    for w in &import.warnings {
        eprintln!("luxon: warning: {w}");
    }
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
        background: [0.0; 3],
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
        plugin_path: Vec::new(),
        warnings: Vec::new(),
    })
}
