//! The RON files of one load: each read and parsed once, merged in include order.
//!
//! The rules of `include` (a list of paths relative to the including file):
//!
//! - A file's includes are merged before the file's own content, in list order, each with its
//!   own includes before it (a depth-first walk, each file merged after what it includes).
//!   Lists (lights, objects, instances, volumes, meshes, plugin paths) are concatenated;
//!   named maps (textures, materials, clip groups, prototypes) let a later definition replace an earlier one of the
//!   same name in its place; single settings (camera, background, fog, ambient occlusion,
//!   render, animation) are taken from the last file that gives them. Outputs belong to the file that
//!   renders: an including file that names any replaces those of its includes.
//! - **Each file is merged once per load** (like `#pragma once`), where it is first reached.
//!   Includes have no parameters or transforms, so a second copy would only double lights
//!   and stack coincident objects. A file reached again through another file (two includes
//!   sharing `studio.ron`: a diamond) is skipped without a word; the same file listed twice
//!   in one `include` list is skipped with a warning at the second mention.
//! - A file that includes itself, directly or through others, is an error naming the chain.
//! - Includes may nest up to [`MAX_DEPTH`] files deep. The walk keeps its path in a list,
//!   not on the call stack, so depth costs no stack.
//! - All files of one load together may hold at most `LoadOptions::max_scene_bytes`.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use luxon_plugin::files::bytes;
use ron::extensions::Extensions;

use crate::animation::ItemNames;
use crate::convert::Part;
use crate::desc::Origin;
use crate::error::{SceneError, Warning};
use crate::input::{file_error, FileError, LoadOptions, Source};
use crate::raw;
use crate::ron_error::ron_error;
use crate::scanner::scan;
use crate::spans::SourceMap;
use crate::validate::Checker;

/// The deepest include nesting accepted (files on one chain).
pub const MAX_DEPTH: usize = 10_000;

/// The merged content of a root file and everything it includes.
pub(crate) struct Merged {
    pub part: Part,
    pub warnings: Vec<Warning>,
}

/// Parts merged so far, with where each name is in the named maps (so that merging is
/// linear in the number of names, however many files define them).
#[derive(Default)]
struct Accumulator {
    part: Part,
    textures: Names,
    materials: Names,
    clip_groups: Names,
    prototypes: Names,
}

/// Name to its place in a list of named definitions.
pub(crate) type Names = HashMap<String, usize>;

/// A file being merged: its own content, and its includes, merged one by one before it.
struct Frame {
    /// Its identity (`Source::key`).
    key: PathBuf,
    /// Its path as reached, for messages.
    shown: PathBuf,
    own: Part,
    includes: Vec<(PathBuf, Origin)>,
    /// The next include to merge.
    next: usize,
    /// The files its list named so far, and where.
    listed: HashMap<PathBuf, Origin>,
}

/// Reads `root` (whose text is given) and everything it includes through `source`. `read`:
/// bytes of scene text already read in this load (the root's).
pub(crate) fn resolve(
    text: String,
    root: &Path,
    source: &mut dyn Source,
    options: &LoadOptions,
    mut read: u64,
) -> Result<Merged, SceneError> {
    let mut warnings = Vec::new();
    let mut merged = Accumulator::default();
    let mut done: HashSet<PathBuf> = HashSet::new();
    let mut on_stack: HashSet<PathBuf> = HashSet::new();
    let key = source.key(root);
    on_stack.insert(key.clone());
    let mut stack = vec![frame(text, root, key)?];
    while let Some(top) = stack.last_mut() {
        let Some((file, at)) = top.includes.get(top.next).cloned() else {
            // All its includes are merged: the file's own content comes after them.
            if let Some(finished) = stack.pop() {
                on_stack.remove(&finished.key);
                done.insert(finished.key);
                merged.absorb(finished.own);
            }
            continue;
        };
        top.next += 1;
        let key = source.key(&file);
        if let Some(first) = top.listed.get(&key) {
            warnings.push(Warning {
                at,
                message: format!(
                    "`{}` is already included at {}:{}; a file is merged once, so this \
                     mention is skipped",
                    file.display(),
                    first.line,
                    first.col
                ),
            });
            continue;
        }
        top.listed.insert(key.clone(), at.clone());
        let including = top.shown.clone();
        if on_stack.contains(&key) {
            let names: Vec<String> = stack
                .iter()
                .map(|f| f.shown.display().to_string())
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
        if done.contains(&key) {
            // Merged already, where it was first reached.
            continue;
        }
        if stack.len() >= MAX_DEPTH {
            return Err(SceneError::at(at, too_deep(&stack, &file)));
        }
        let max = options.max_scene_bytes.saturating_sub(read);
        let text = source
            .read(&file, max)
            .map_err(|e| include_error(e, &file, &including, &at, read, options))?;
        read += text.len() as u64;
        on_stack.insert(key.clone());
        stack.push(frame(text, &file, key)?);
    }
    Ok(Merged {
        part: merged.part,
        warnings,
    })
}

/// Parses one file: its own content and its include list, each path resolved against the
/// file's directory and placed at its string.
fn frame(text: String, path: &Path, key: PathBuf) -> Result<Frame, SceneError> {
    let src = SourceMap::new(path.to_path_buf(), text);
    let options = ron::Options::default().with_default_extension(Extensions::IMPLICIT_SOME);
    let scene: raw::Scene = options
        .from_str(&src.text)
        .map_err(|e| ron_error(&e, &src))?;
    let root = scan(&src.text).map_err(|e| SceneError::at(src.origin(e.at), e.message))?;
    let check = Checker { src: &src };
    check.finite_numbers(&root)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let includes = scene
        .include
        .iter()
        .enumerate()
        .map(|(i, include)| {
            let node = root
                .field("include")
                .and_then(|n| n.item(i))
                .unwrap_or(&root);
            (dir.join(include), check.origin(node))
        })
        .collect();
    let own = check.part(scene, &root)?;
    Ok(Frame {
        key,
        shown: path.to_path_buf(),
        own,
        includes,
        next: 0,
        listed: HashMap::new(),
    })
}

/// An included file that could not be read: at the include string, or at the problem in
/// the file's text.
fn include_error(
    e: FileError,
    file: &Path,
    including: &Path,
    at: &Origin,
    read: u64,
    options: &LoadOptions,
) -> SceneError {
    if e.position().is_some() {
        return file_error(e, file, "a scene file");
    }
    let f = file.display();
    let message = match e {
        FileError::Missing | FileError::Io(_) => format!(
            "cannot read included file `{f}`: it {e}; expected a scene file path relative to `{}`",
            including.display()
        ),
        FileError::TooLarge { size, .. } => format!(
            "cannot include `{f}`: it is {}; the scene files of one load may hold at most {} \
             together, and {} are read already",
            bytes(size),
            bytes(options.max_scene_bytes),
            bytes(read)
        ),
        e => format!("cannot include `{f}`: it {}", e.explain("a scene file")),
    };
    SceneError::at(at.clone(), message)
}

/// The message for a chain of includes deeper than `MAX_DEPTH`, naming its ends.
fn too_deep(stack: &[Frame], file: &Path) -> String {
    let names: Vec<String> = stack
        .iter()
        .map(|f| f.shown.display().to_string())
        .chain([file.display().to_string()])
        .collect();
    let chain = if names.len() > 6 {
        format!(
            "{} -> … -> {}",
            names[..3].join(" -> "),
            names[names.len() - 3..].join(" -> ")
        )
    } else {
        names.join(" -> ")
    };
    format!(
        "includes nest deeper than {MAX_DEPTH} files ({chain}); expected a shallower include chain"
    )
}

impl Accumulator {
    /// Adds a later part: lists append, names are replaced in place, singles are overridden.
    fn absorb(&mut self, later: Part) {
        let part = &mut self.part;
        if later.camera.is_some() {
            part.camera = later.camera;
        }
        if later.background.is_some() {
            part.background = later.background;
        }
        if later.fog.is_some() {
            part.fog = later.fog;
        }
        if later.ambient_occlusion.is_some() {
            part.ambient_occlusion = later.ambient_occlusion;
        }
        if later.render.is_some() {
            part.render = later.render;
            part.render_clock = later.render_clock;
        }
        if later.animation.is_some() {
            part.animation = later.animation;
        }
        // Names follow their lights and objects to their places in the merged lists.
        let (lights, objects) = (part.lights.len(), part.objects.len());
        let shift = |names: ItemNames, by: usize| names.into_iter().map(move |(i, n)| (i + by, n));
        part.light_names.extend(shift(later.light_names, lights));
        part.object_names.extend(shift(later.object_names, objects));
        let instances = part.instances.len();
        part.instance_names
            .extend(shift(later.instance_names, instances));
        part.instances.extend(later.instances);
        part.series.extend(later.series);
        upsert(&mut part.prototypes, &mut self.prototypes, later.prototypes);
        part.lights.extend(later.lights);
        part.objects.extend(later.objects);
        part.volumes.extend(later.volumes);
        part.meshes.extend(later.meshes);
        // Outputs belong to the file that renders: an including file that names any replaces
        // those of its includes (including a scene must not also write that scene's image).
        if !later.outputs.is_empty() {
            part.outputs = later.outputs;
        }
        part.plugin_path.extend(later.plugin_path);
        upsert(&mut part.textures, &mut self.textures, later.textures);
        upsert(&mut part.materials, &mut self.materials, later.materials);
        upsert(
            &mut part.clip_groups,
            &mut self.clip_groups,
            later.clip_groups,
        );
    }
}

/// Later definitions replace earlier ones of the same name, keeping the first one's place.
/// `names` indexes `into`.
pub(crate) fn upsert<T>(into: &mut Vec<(String, T)>, names: &mut Names, later: Vec<(String, T)>) {
    for (name, value) in later {
        match names.get(&name) {
            Some(&i) => into[i].1 = value,
            None => {
                names.insert(name.clone(), into.len());
                into.push((name, value));
            }
        }
    }
}
