//! The RON scene format: the root file and its includes (see `includes`) merged, then the
//! `meshes:` it names.

use std::path::Path;

use crate::animation::resolve_animation;
use crate::desc::{MeshFile, SceneDesc};
use crate::error::{quoted_list, unknown_name, SceneError};
use crate::geometry::InlineGeometry;
use crate::includes::{resolve, upsert, Names};
use crate::input::{file_error, DiskSource, LoadOptions, Source};
use crate::instances::resolve_instances;
use crate::obj::{is_obj_path, load_obj_with};
use crate::series::resolve_series;
use crate::spans::SourceMap;
use crate::validate::references;

/// Loads a scene from RON text; `path` names it in messages and anchors relative paths.
/// Included files are read from disk, within the default [`LoadOptions`].
pub fn load_ron_str(text: &str, path: &Path) -> Result<SceneDesc, SceneError> {
    let options = LoadOptions::default();
    // As read from a file: without a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    load_root(text.to_string(), path, &mut DiskSource, &options)
}

/// Loads the RON scene at `path`, reading it and its includes through `source` (files in
/// memory, for tests and fuzzing; [`DiskSource`] for the disk).
pub fn load_ron_with(
    source: &mut dyn Source,
    path: &Path,
    options: &LoadOptions,
) -> Result<SceneDesc, SceneError> {
    let text = source
        .read(path, options.max_scene_bytes)
        .map_err(|e| file_error(e, path, "a scene file"))?;
    load_root(text, path, source, options)
}

fn load_root(
    text: String,
    path: &Path,
    source: &mut dyn Source,
    options: &LoadOptions,
) -> Result<SceneDesc, SceneError> {
    let read = text.len() as u64;
    let merged = resolve(text, path, source, options, read)?;
    let mut part = merged.part;
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
    if let (Some(_), Some(at)) = (&part.animation, &part.render_clock) {
        return Err(SceneError::at(
            at.clone(),
            "`frame` and `time` cannot be set in a scene with `animation:`; its frames are \
             chosen by `animation: (frames: ...)` or `--frames`",
        ));
    }
    let mut scene = SceneDesc {
        source: path.to_path_buf(),
        camera,
        background: part.background.unwrap_or_default(),
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
        warnings: merged.warnings,
        animation: part.animation,
        prototypes: part.prototypes,
        instances: part.instances,
        series: part.series,
    };
    references(&scene)?;
    resolve_instances(&scene, &part.object_names, &part.instance_names)?;
    resolve_series(&scene)?;
    resolve_animation(
        &mut scene,
        &part.light_names,
        &part.object_names,
        &part.instance_names,
    )?;
    add_meshes(&mut scene, meshes, options)?;
    Ok(scene)
}

/// Reads the `meshes:` files into `inline` geometry (and their materials, unless the entry
/// names one), in file order, then the prototypes' into theirs, and their warnings into the
/// scene's. All of them together within `options.max_geometry`.
fn add_meshes(
    scene: &mut SceneDesc,
    meshes: Vec<MeshFile>,
    options: &LoadOptions,
) -> Result<(), SceneError> {
    let mut names: Names = scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, (n, _))| (n.clone(), i))
        .collect();
    for mesh in &meshes {
        if let Some(material) = &mesh.material {
            if !names.contains_key(&material.value) {
                let names = scene.materials.iter().map(|(n, _)| n.as_str());
                let message = unknown_name("material", &material.value, "", names);
                return Err(SceneError::at(material.at.clone(), message));
            }
        }
    }
    for mesh in meshes {
        let groups = read_mesh(scene, &mut names, mesh, options)?;
        scene.inline.extend(groups);
    }
    // Then the prototypes' meshes, in the prototypes' own coordinates.
    for p in 0..scene.prototypes.len() {
        let files = std::mem::take(&mut scene.prototypes[p].1.value.mesh_files);
        for mesh in files {
            let groups = read_mesh(scene, &mut names, mesh, options)?;
            scene.prototypes[p].1.value.inline.extend(groups);
        }
    }
    Ok(())
}

/// Reads one mesh file: its groups, each with the entry's material, else with the file's own
/// (added to the scene's materials, `names` indexing them).
fn read_mesh(
    scene: &mut SceneDesc,
    names: &mut Names,
    mesh: MeshFile,
    options: &LoadOptions,
) -> Result<Vec<InlineGeometry>, SceneError> {
    if !is_obj_path(&mesh.file.value) {
        return Err(SceneError::at(
            mesh.file.at,
            format!(
                "unsupported mesh file `{}`; expected a Wavefront `.obj` file",
                mesh.file.value.display()
            ),
        ));
    }
    let prototypes = scene.prototypes.iter().flat_map(|(_, p)| &p.value.inline);
    let held: u64 = scene
        .inline
        .iter()
        .chain(prototypes)
        .map(InlineGeometry::bytes)
        .sum();
    let left = LoadOptions {
        max_geometry: options.max_geometry.saturating_sub(held),
        ..options.clone()
    };
    let mut import = load_obj_with(&mesh.file.value, Some(mesh.file.at.clone()), &left)?;
    scene.warnings.extend(import.warnings);
    match mesh.material {
        Some(material) => {
            for g in &mut import.geometry {
                g.material = Some(material.clone());
            }
        }
        None => upsert(&mut scene.materials, names, import.materials),
    }
    Ok(import.geometry)
}

/// Extensions this crate reads, for messages.
pub(crate) fn supported_extensions() -> String {
    quoted_list([".ron"])
}
