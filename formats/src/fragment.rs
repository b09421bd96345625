//! Parts of a scene read from RON fragments — the text a scene file writes after `camera:`,
//! inside `lights: [...]`, after a material's name... — for values that come from code or
//! from C strings rather than from a scene file. One rule set, no drift: each fragment is
//! wrapped into a minimal scene text and read by the RON loader itself (its parser and every
//! check of its reading stage), so a fragment is accepted or refused exactly as the same text
//! in a scene file. [`crate::print`] writes fragments; `check_*` print a typed value and read
//! it back, so typed values obey the same rules as text.
//!
//! Kinds: [`camera`], [`light`], [`material`], [`texture`], [`fog`], [`ambient_occlusion`],
//! [`render_settings`], [`clip_planes`], [`volume_render`].
//!
//! - The file name in messages is the kind in angle brackets, and columns on the fragment's
//!   first line are its own: ``<light>:1:7: unknown field `positon` in `Point`; did you mean
//!   `position`? ...``.
//! - The loader reads from an in-memory source that holds only the fragment: `include` fails.
//! - A fragment is one value: text that closes the wrapper and adds other parts of a scene
//!   (`(...), lights: [...]`) is refused.
//! - Render settings refuse `width`, `height`, `outputs` and `parallel`: an embedded scene's
//!   target and renderer decide them.
//! - A material's texture names and a volume's clip group are not looked up: the scene that
//!   holds them defines those names (so fragments are read by the loader's reading stage, before the scene-wide
//!   checks of names).

use std::path::Path;

use crate::convert::Part;
use crate::desc::{
    AoDesc, CameraDesc, ClipPlaneDesc, FogDesc, LightDesc, MaterialDesc, Origin, PluginCall,
    RenderDesc, VolumeRenderDesc,
};
use crate::error::SceneError;
use crate::includes::resolve;
use crate::input::{file_error, LoadOptions, MemorySource, Source};
use crate::print::{self, NOT_RENDER_SETTINGS};
use crate::scanner::scan;
use crate::spans::SourceMap;

/// A kind of fragment: its name in messages and the scene text around it.
struct Kind {
    name: &'static str,
    /// Scene text before the fragment, on the first line (ASCII: its length is its columns).
    before: &'static str,
    after: &'static str,
}

const CAMERA: Kind = Kind {
    name: "camera",
    before: "Scene(camera: ",
    after: ")",
};
const LIGHT: Kind = Kind {
    name: "light",
    before: "Scene(lights: [",
    after: "])",
};
const MATERIAL: Kind = Kind {
    name: "material",
    before: "Scene(materials: {\"m\": ",
    after: "})",
};
const TEXTURE: Kind = Kind {
    name: "texture",
    before: "Scene(textures: {\"t\": ",
    after: "})",
};
const FOG: Kind = Kind {
    name: "fog",
    before: "Scene(fog: ",
    after: ")",
};
const AMBIENT_OCCLUSION: Kind = Kind {
    name: "ambient_occlusion",
    before: "Scene(ambient_occlusion: ",
    after: ")",
};
const RENDER_SETTINGS: Kind = Kind {
    name: "render_settings",
    before: "Scene(render: ",
    after: ")",
};
const VOLUME_RENDER: Kind = Kind {
    name: "volume_render",
    // The plugin is not loaded here: the reading stage takes any name.
    before: "Scene(volumes: [(plugin: \"volume\", params: (), render: ",
    after: ")])",
};
const CLIP_PLANES: Kind = Kind {
    name: "clip_planes",
    before: "Scene(clip_groups: {\"g\": ",
    after: "})",
};

/// A camera: `(position: (0.0, 0.0, 5.0), look_at: (0.0, 0.0, 0.0), fov: 40.0)`.
pub fn camera(text: &str) -> Result<CameraDesc, SceneError> {
    let (mut part, at) = read(&CAMERA, text)?;
    let camera = part.camera.take();
    only(&CAMERA, part, at.clone())?;
    camera.map(|c| c.value).ok_or_else(|| missing(&CAMERA, at))
}

/// A light: `Point(position: (1.0, 2.0, 3.0), intensity: 2.0)`, `Spot(...)`, ... A `name`
/// is refused: names belong to the scene that holds the light (its animation keys them).
pub fn light(text: &str) -> Result<LightDesc, SceneError> {
    let (mut part, at) = read(&LIGHT, text)?;
    if let Some((_, name)) = part.light_names.first() {
        let mut at = name.at.clone();
        shift(&mut at, &LIGHT);
        return Err(SceneError::at(
            at,
            "a light fragment takes no `name`; the scene that holds the light names it",
        ));
    }
    let mut lights = std::mem::take(&mut part.lights);
    only(&LIGHT, part, at.clone())?;
    match (lights.pop(), lights.is_empty()) {
        (Some(l), true) => Ok(l.value),
        _ => Err(missing(&LIGHT, at)),
    }
}

/// A material: `(color: (0.8, 0.2, 0.2), specular: 0.5, texture: "wood")`. Texture names
/// are taken as written (see the module documentation); their positions are in the fragment.
pub fn material(text: &str) -> Result<MaterialDesc, SceneError> {
    let (mut part, at) = read(&MATERIAL, text)?;
    let mut materials = std::mem::take(&mut part.materials);
    only(&MATERIAL, part, at.clone())?;
    let Some((_, m)) = materials.pop() else {
        return Err(missing(&MATERIAL, at));
    };
    let mut m = m.value;
    for t in [
        &mut m.texture,
        &mut m.reflect_texture,
        &mut m.transmit_texture,
    ]
    .into_iter()
    .flatten()
    {
        shift(&mut t.at, &MATERIAL);
    }
    Ok(m)
}

/// A texture: `(plugin: "stripes", params: (width: 0.1))`, as a scene file's `textures`
/// map holds one after its name (`plugin` left out: `checker`). The plugin is not looked up
/// and its parameters not read (the scene that holds the texture does both); their position
/// (`params_at`) is in the fragment's own columns, so the plugin's errors point into it.
pub fn texture(text: &str) -> Result<PluginCall, SceneError> {
    let (mut part, at) = read(&TEXTURE, text)?;
    let mut textures = std::mem::take(&mut part.textures);
    only(&TEXTURE, part, at.clone())?;
    match (textures.pop(), textures.is_empty()) {
        (Some((_, t)), true) => {
            let mut call = t.value;
            shift(&mut call.plugin.at, &TEXTURE);
            shift(&mut call.params_at, &TEXTURE);
            Ok(call)
        }
        _ => Err(missing(&TEXTURE, at)),
    }
}

/// Fog: `(mode: Exp(density: 0.1), color: (0.5, 0.5, 0.5))`.
pub fn fog(text: &str) -> Result<FogDesc, SceneError> {
    let (mut part, at) = read(&FOG, text)?;
    let fog = part.fog.take();
    only(&FOG, part, at.clone())?;
    fog.ok_or_else(|| missing(&FOG, at))
}

/// Ambient occlusion: `(samples: 16, distance: 2.0)`.
pub fn ambient_occlusion(text: &str) -> Result<AoDesc, SceneError> {
    let (mut part, at) = read(&AMBIENT_OCCLUSION, text)?;
    let ao = part.ambient_occlusion.take();
    only(&AMBIENT_OCCLUSION, part, at.clone())?;
    ao.ok_or_else(|| missing(&AMBIENT_OCCLUSION, at))
}

/// A clip group's planes: `[(point: (0.0, 0.0, 0.0), normal: (0.0, 1.0, 0.0))]`.
pub fn clip_planes(text: &str) -> Result<Vec<ClipPlaneDesc>, SceneError> {
    let (mut part, at) = read(&CLIP_PLANES, text)?;
    let mut groups = std::mem::take(&mut part.clip_groups);
    only(&CLIP_PLANES, part, at.clone())?;
    match groups.pop() {
        Some((_, planes)) => Ok(planes.value),
        None => Err(missing(&CLIP_PLANES, at)),
    }
}

/// Render settings: `(samples: 4, max_depth: 8, adaptive: (threshold: 0.05))`. An embedded
/// scene's target and renderer decide `width`, `height`, `outputs` and `parallel`: they are
/// refused (the result holds their defaults).
pub fn render_settings(text: &str) -> Result<RenderDesc, SceneError> {
    let (mut part, at) = read(&RENDER_SETTINGS, text)?;
    let render = part.render.take();
    // `outputs` are kept apart from the rest of `render` (refused below).
    part.outputs.clear();
    only(&RENDER_SETTINGS, part, at.clone())?;
    // The text is valid RON (it was read): where it writes a refused field, in its own columns.
    let root = scan(text).map_err(|e| SceneError::at(at.clone(), e.message))?;
    let src = SourceMap::new(at.file.to_path_buf(), text.to_string());
    for (name, why) in NOT_RENDER_SETTINGS {
        if let Some(node) = root.raw_field(name) {
            return Err(SceneError::at(
                src.origin(node.start),
                format!("`{name}` is not a render setting of an embedded scene; {why}"),
            ));
        }
    }
    render.ok_or_else(|| missing(&RENDER_SETTINGS, at))
}

/// How a volume is drawn: `(transfer: (preset: "viridis"), step: 0.5)`. A clip group name is
/// taken as written (the scene that holds the volume defines its groups).
pub fn volume_render(text: &str) -> Result<VolumeRenderDesc, SceneError> {
    let (mut part, at) = read(&VOLUME_RENDER, text)?;
    let mut volumes = std::mem::take(&mut part.volumes);
    only(&VOLUME_RENDER, part, at.clone())?;
    let render = match (volumes.pop(), volumes.is_empty()) {
        (Some(v), true) => v.value.render,
        _ => None,
    };
    let mut r = render.ok_or_else(|| missing(&VOLUME_RENDER, at))?.value;
    if let Some(clip) = &mut r.clip {
        shift(&mut clip.at, &VOLUME_RENDER);
    }
    Ok(r)
}

/// Checks a camera as [`camera`] checks its text: `Err` holds the message (without a
/// position, which would point into the printed text).
pub fn check_camera(c: &CameraDesc) -> Result<(), String> {
    checked(camera(&print::camera(c)))
}

/// Checks a light as [`light`] checks its text.
pub fn check_light(l: &LightDesc) -> Result<(), String> {
    checked(light(&print::light(l)))
}

/// Checks a material as [`material`] checks its text.
pub fn check_material(m: &MaterialDesc) -> Result<(), String> {
    checked(material(&print::material(m)))
}

/// Checks fog as [`fog`] checks its text.
pub fn check_fog(f: &FogDesc) -> Result<(), String> {
    checked(fog(&print::fog(f)))
}

/// Checks ambient occlusion as [`ambient_occlusion`] checks its text.
pub fn check_ambient_occlusion(a: &AoDesc) -> Result<(), String> {
    checked(ambient_occlusion(&print::ambient_occlusion(a)))
}

/// Checks render settings as [`render_settings`] checks their text (the fields it refuses are
/// not printed, so not checked).
pub fn check_render_settings(r: &RenderDesc) -> Result<(), String> {
    checked(render_settings(&print::render_settings(r)))
}

/// Checks a volume's render block as [`volume_render`] checks its text.
pub fn check_volume_render(r: &VolumeRenderDesc) -> Result<(), String> {
    checked(volume_render(&print::volume_render(r)))
}

/// Checks clip planes as [`clip_planes`] checks their text.
pub fn check_clip_planes(planes: &[ClipPlaneDesc]) -> Result<(), String> {
    checked(clip_planes(&print::clip_planes(planes)))
}

fn checked<T>(read: Result<T, SceneError>) -> Result<(), String> {
    match read {
        Ok(_) => Ok(()),
        Err(SceneError::At { message, .. }) => Err(message),
        Err(e) => Err(e.to_string()),
    }
}

/// Reads the fragment wrapped as a scene: the part it makes, and the fragment's start.
fn read(kind: &Kind, text: &str) -> Result<(Part, Origin), SceneError> {
    let name = format!("<{}>", kind.name);
    let path = Path::new(&name);
    let mut source = MemorySource::new();
    source.insert(path, format!("{}{text}{}", kind.before, kind.after));
    let options = LoadOptions::default();
    let wrapped = source
        .read(path, options.max_scene_bytes)
        .map_err(|e| file_error(e, path, "a fragment"))?;
    let read = wrapped.len() as u64;
    // No warnings can come: they are about includes, which the source cannot give.
    let merged = resolve(wrapped, path, &mut source, &options, read).map_err(|e| match e {
        SceneError::At { mut at, message } => {
            shift(&mut at, kind);
            SceneError::At { at, message }
        }
        e => e,
    })?;
    let at = Origin {
        file: path.to_path_buf().into(),
        line: 1,
        col: 1,
    };
    Ok((merged.part, at))
}

/// Moves a position in the wrapped text to the fragment's own columns.
fn shift(at: &mut Origin, kind: &Kind) {
    if at.line == 1 {
        at.col = at.col.saturating_sub(kind.before.len() as u32).max(1);
    }
}

/// Refuses a fragment that gave more than its own part (text that closed the wrapper).
fn only(kind: &Kind, part: Part, at: Origin) -> Result<(), SceneError> {
    // Every field by name: a part added to the scene format is refused here too.
    let Part {
        camera,
        background,
        lights,
        fog,
        ambient_occlusion,
        textures,
        materials,
        clip_groups,
        objects,
        volumes,
        meshes,
        render,
        outputs,
        plugin_path,
        animation,
        prototypes,
        instances,
        series,
        light_names: _,
        object_names: _,
        instance_names: _,
        render_clock: _,
    } = part;
    let extra = [
        ("camera", camera.is_some()),
        ("background", background.is_some()),
        ("lights", !lights.is_empty()),
        ("fog", fog.is_some()),
        ("ambient_occlusion", ambient_occlusion.is_some()),
        ("textures", !textures.is_empty()),
        ("materials", !materials.is_empty()),
        ("clip_groups", !clip_groups.is_empty()),
        ("objects", !objects.is_empty()),
        ("volumes", !volumes.is_empty()),
        ("meshes", !meshes.is_empty()),
        ("render", render.is_some()),
        ("outputs", !outputs.is_empty()),
        ("plugin_path", !plugin_path.is_empty()),
        ("animation", animation.is_some()),
        ("prototypes", !prototypes.is_empty()),
        ("instances", !instances.is_empty()),
        ("series", !series.is_empty()),
    ];
    match extra.iter().find(|(_, set)| *set) {
        Some((field, _)) => Err(SceneError::at(
            at,
            format!(
                "the {} fragment also sets `{field}`; expected one {} and nothing after it",
                kind.name, kind.name
            ),
        )),
        None => Ok(()),
    }
}

fn missing(kind: &Kind, at: Origin) -> SceneError {
    SceneError::at(at, format!("expected one {}", kind.name))
}
