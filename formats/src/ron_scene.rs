//! The RON scene format: one file through ron and the span scanner, then its includes, merged.

use std::path::{Path, PathBuf};

use ron::extensions::Extensions;

use crate::convert::{MeshRef, Part};
use crate::desc::SceneDesc;
use crate::error::{quoted_list, unknown_name, SceneError};
use crate::obj::{is_obj_path, load_obj};
use crate::raw;
use crate::ron_error::ron_error;
use crate::scanner::scan;
use crate::spans::SourceMap;
use crate::validate::{references, Checker};

/// Loads a scene from RON text; `path` names it in messages and anchors relative paths.
pub fn load_ron_str(text: &str, path: &Path) -> Result<SceneDesc, SceneError> {
    let mut chain = vec![Visit {
        key: identity(path),
        shown: path.to_path_buf(),
    }];
    let mut part = load_part(text.to_string(), path, &mut chain)?;
    let origin = SourceMap::new(path.to_path_buf(), String::new()).origin_at(1, 1);
    let camera = part.camera.ok_or_else(|| {
        SceneError::at(
            origin,
            "the scene has no camera; expected `camera: (position: ..., look_at: ...)`",
        )
    })?;
    let mut render = part.render.unwrap_or_default();
    render.outputs = part.outputs;
    let meshes = std::mem::take(&mut part.meshes);
    let mut scene = SceneDesc {
        source: path.to_path_buf(),
        camera,
        background: part.background.unwrap_or([0.0; 3]),
        lights: part.lights,
        fog: part.fog,
        ambient_occlusion: part.ambient_occlusion,
        textures: part.textures,
        materials: part.materials,
        clip_groups: part.clip_groups,
        objects: part.objects,
        inline: Vec::new(),
        volumes: part.volumes,
        render,
        plugin_path: part.plugin_path,
        warnings: Vec::new(),
    };
    references(&scene)?;
    add_meshes(&mut scene, meshes)?;
    Ok(scene)
}

/// Reads the `meshes:` files into `inline` geometry (and their materials, unless the entry
/// names one), in file order; warnings go to standard error.
fn add_meshes(scene: &mut SceneDesc, meshes: Vec<MeshRef>) -> Result<(), SceneError> {
    for mesh in &meshes {
        if let Some(material) = &mesh.material {
            if !scene.materials.iter().any(|(n, _)| *n == material.value) {
                let names = scene.materials.iter().map(|(n, _)| n.as_str());
                let message = unknown_name("material", &material.value, "", names);
                return Err(SceneError::at(material.at.clone(), message));
            }
        }
    }
    for mesh in meshes {
        if !is_obj_path(&mesh.file.value) {
            return Err(SceneError::at(
                mesh.file.at,
                format!(
                    "unsupported mesh file `{}`; expected a Wavefront `.obj` file",
                    mesh.file.value.display()
                ),
            ));
        }
        let import = load_obj(&mesh.file.value, Some(mesh.file.at.clone()))?;
        for w in &import.warnings {
            eprintln!("luxon: warning: {}: {w}", mesh.file.at);
        }
        match mesh.material {
            Some(material) => {
                for mut g in import.geometry {
                    g.material = Some(material.clone());
                    scene.inline.push(g);
                }
            }
            None => {
                upsert(&mut scene.materials, import.materials);
                scene.inline.extend(import.geometry);
            }
        }
    }
    Ok(())
}

/// A file on the include chain: `key` to compare, `shown` for messages.
struct Visit {
    key: PathBuf,
    shown: PathBuf,
}

fn identity(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

/// One file and, before it, everything it includes.
fn load_part(text: String, path: &Path, chain: &mut Vec<Visit>) -> Result<Part, SceneError> {
    let src = SourceMap::new(path.to_path_buf(), text);
    let options = ron::Options::default().with_default_extension(Extensions::IMPLICIT_SOME);
    let scene: raw::Scene = options
        .from_str(&src.text)
        .map_err(|e| ron_error(&e, &src))?;
    let root = scan(&src.text).map_err(|e| SceneError::at(src.origin(e.at), e.message))?;
    let check = Checker { src: &src };
    check.finite_numbers(&root)?;
    let includes = scene.include.clone();
    let own = check.part(scene, &root)?;

    let dir = path.parent().unwrap_or(Path::new(""));
    let mut merged = Part::default();
    for (i, include) in includes.iter().enumerate() {
        let node = root
            .field("include")
            .and_then(|n| n.item(i))
            .unwrap_or(&root);
        let at = check.origin(node);
        let file = dir.join(include);
        let key = identity(&file);
        if chain.iter().any(|v| v.key == key) {
            let names: Vec<String> = chain
                .iter()
                .map(|v| v.shown.display().to_string())
                .chain([file.display().to_string()])
                .collect();
            return Err(SceneError::at(
                at,
                format!(
                    "include cycle: {}; expected included files not to include each other back",
                    names.join(" -> ")
                ),
            ));
        }
        let text = std::fs::read_to_string(&file).map_err(|e| {
            SceneError::at(
                at.clone(),
                format!(
                    "cannot read included file `{}`: {e}; expected a scene file path relative to `{}`",
                    file.display(),
                    path.display()
                ),
            )
        })?;
        chain.push(Visit {
            key,
            shown: file.clone(),
        });
        let part = load_part(text, &file, chain)?;
        chain.pop();
        merged.absorb(part);
    }
    merged.absorb(own);
    Ok(merged)
}

impl Part {
    /// Adds a later part: lists append, names are replaced in place, singles are overridden.
    fn absorb(&mut self, later: Part) {
        if later.camera.is_some() {
            self.camera = later.camera;
        }
        if later.background.is_some() {
            self.background = later.background;
        }
        if later.fog.is_some() {
            self.fog = later.fog;
        }
        if later.ambient_occlusion.is_some() {
            self.ambient_occlusion = later.ambient_occlusion;
        }
        if later.render.is_some() {
            self.render = later.render;
        }
        self.lights.extend(later.lights);
        self.objects.extend(later.objects);
        self.volumes.extend(later.volumes);
        self.meshes.extend(later.meshes);
        // Outputs belong to the file that renders: an including file that names any replaces
        // those of its includes (including a scene must not also write that scene's image).
        if !later.outputs.is_empty() {
            self.outputs = later.outputs;
        }
        self.plugin_path.extend(later.plugin_path);
        upsert(&mut self.textures, later.textures);
        upsert(&mut self.materials, later.materials);
        upsert(&mut self.clip_groups, later.clip_groups);
    }
}

/// Later definitions replace earlier ones of the same name, keeping the first one's place.
fn upsert<T>(into: &mut Vec<(String, T)>, later: Vec<(String, T)>) {
    for (name, value) in later {
        match into.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => slot.1 = value,
            None => into.push((name, value)),
        }
    }
}

/// Extensions this crate reads, for messages.
pub(crate) fn supported_extensions() -> String {
    quoted_list([".ron"])
}
