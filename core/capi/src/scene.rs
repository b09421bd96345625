//! Scenes: made empty, loaded, changed piece by piece, committed, written out as RON.

use crate::context::CONTEXTS;
use crate::guard::guard;
use crate::handles::{
    luxon_context, luxon_object, luxon_renderer, luxon_scene, Entry, Kind, Table,
};
use crate::renderer::RENDERERS;
use crate::status::{
    luxon_status, Failure, LUXON_ERROR_BUSY, LUXON_ERROR_INVALID_HANDLE,
    LUXON_ERROR_PLUGIN_NOT_FOUND,
};
use crate::text::{optional_text, put, put_sized, read_sized, text, Versioned};
use luxon_core::api::{Context, LightId, ObjectId, Scene};
use luxon_core::plugin::{LookupError, PluginKind};
use luxon_core::Error;
use luxon_formats::{Attenuation, CameraDesc, LightDesc, MaterialDesc, Projection};
use std::ffi::c_char;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, TryLockError};

pub(crate) static SCENES: Table<SceneEntry> = Table::new(Kind::Scene);
pub(crate) static PARTS: Table<Part> = Table::new(Kind::Object);

/// A scene handle's entry: the scene and the handles of its parts behind one lock, and the
/// flag that makes other calls return BUSY instead of waiting while it renders or commits.
pub(crate) struct SceneEntry {
    state: Mutex<SceneState>,
    busy: AtomicBool,
    /// The context the scene was made in (its plugins, for lookups).
    context: Arc<Entry<Context>>,
}

pub(crate) struct SceneState {
    pub scene: Scene,
    /// The `luxon_object` handles given out for this scene's parts.
    parts: Vec<(u64, PartId)>,
}

/// What a `luxon_object` names: a part of one scene.
pub(crate) struct Part {
    scene: u64,
    id: PartId,
}

#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum PartId {
    Light(LightId),
    Object(ObjectId),
}

/// The scene's state, locked for a call; the busy flag is cleared when it drops (if the call
/// set it).
pub(crate) struct Locked<'a> {
    pub state: MutexGuard<'a, SceneState>,
    busy: Option<&'a AtomicBool>,
}

impl Drop for Locked<'_> {
    fn drop(&mut self) {
        if let Some(b) = self.busy {
            b.store(false, Ordering::SeqCst);
        }
    }
}

impl SceneEntry {
    /// Fails with PLUGIN_NOT_FOUND when the scene's context has no plugin `name` of `kind`
    /// (one of another kind is left for the scene to refuse, naming its kind).
    fn plugin_found(&self, name: &str, kind: PluginKind) -> Result<(), Failure> {
        match self.context.value.registry().get(name, kind) {
            Err(e @ LookupError::NotFound { .. }) => {
                Err(Failure::new(LUXON_ERROR_PLUGIN_NOT_FOUND, e.to_string()))
            }
            _ => Ok(()),
        }
    }

    /// Locks the scene for a call. While another thread renders or commits it (`busy`), the
    /// call fails with BUSY at once; a short call on another thread is waited for. `long`
    /// marks this call busy (a render or a commit).
    pub(crate) fn lock(&self, id: u64, long: bool) -> Result<Locked<'_>, Failure> {
        loop {
            match self.state.try_lock() {
                Ok(state) => {
                    if long {
                        self.busy.store(true, Ordering::SeqCst);
                    }
                    return Ok(Locked {
                        state,
                        busy: long.then_some(&self.busy),
                    });
                }
                Err(TryLockError::Poisoned(_)) => {
                    return Err(Failure::new(
                        LUXON_ERROR_INVALID_HANDLE,
                        format!(
                            "luxon_scene {id:#x} is unusable after an internal error; release it"
                        ),
                    ))
                }
                Err(TryLockError::WouldBlock) if self.busy.load(Ordering::SeqCst) => {
                    return Err(Failure::new(
                        LUXON_ERROR_BUSY,
                        format!(
                            "luxon_scene {id:#x} is being rendered or committed on another \
                             thread; nothing was done"
                        ),
                    ))
                }
                Err(TryLockError::WouldBlock) => std::thread::yield_now(),
            }
        }
    }
}

/// Runs `f` on the scene `scene` names, locked (see [`SceneEntry::lock`]).
pub(crate) fn with_scene<T>(
    scene: luxon_scene,
    f: impl FnOnce(&mut SceneState, &SceneEntry) -> Result<T, Failure>,
) -> Result<T, Failure> {
    let entry = SCENES.get(scene.id)?;
    let mut locked = entry.value.lock(scene.id, false)?;
    f(&mut locked.state, &entry.value)
}

fn new_scene(
    context: luxon_context,
    out: *mut luxon_scene,
    make: impl FnOnce(&Context) -> Result<Scene, Error>,
) -> Result<(), Failure> {
    // SAFETY: `out` is NULL or writable (every caller's contract); cleared first so a failure
    // leaves {0}.
    unsafe { put(out, "out", luxon_scene::default()) }?;
    let ctx = CONTEXTS.get(context.id)?;
    let scene = make(&ctx.value)?;
    let id = SCENES.insert(SceneEntry {
        state: Mutex::new(SceneState {
            scene,
            parts: Vec::new(),
        }),
        busy: AtomicBool::new(false),
        context: ctx,
    })?;
    // SAFETY: as above.
    unsafe { put(out, "out", luxon_scene { id }) }
}

/// An empty scene: no camera (give it one before rendering), no lights, no objects, the
/// default material, a black background, the default render settings.
///
/// # Safety
/// `out` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_create(
    context: luxon_context,
    out: *mut luxon_scene,
) -> luxon_status {
    guard("luxon_scene_create", || {
        new_scene(context, out, |ctx| Ok(Scene::new(ctx)))
    })
}

/// Loads a scene file of any format Luxon reads (RON, NFF, OBJ, Tachyon...). Its warnings go
/// to the log callback.
///
/// # Safety
/// `path` is a valid string; `out` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_load(
    context: luxon_context,
    path: *const c_char,
    out: *mut luxon_scene,
) -> luxon_status {
    guard("luxon_scene_load", || {
        // SAFETY: a valid string (caller).
        let path = unsafe { text(path, "path") }?;
        new_scene(context, out, |ctx| Scene::load(ctx, Path::new(path)))
    })
}

/// A scene from RON scene text (what a `.ron` scene file holds). `name` (NULL: `<scene>`)
/// names it in messages and anchors relative paths (its directory; none: the working
/// directory).
///
/// # Safety
/// `ron` is a valid string, `name` NULL or one; `out` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_load_ron(
    context: luxon_context,
    ron: *const c_char,
    name: *const c_char,
    out: *mut luxon_scene,
) -> luxon_status {
    guard("luxon_scene_load_ron", || {
        // SAFETY: valid strings (caller).
        let (ron, name) = unsafe { (text(ron, "ron")?, optional_text(name, "name")?) };
        let name = Path::new(name.unwrap_or("<scene>"));
        new_scene(context, out, |ctx| {
            let desc = ctx.install(|| luxon_formats::load_ron_str(ron, name))?;
            for w in &desc.warnings {
                luxon_core::error::log(luxon_core::error::Level::Warning, &w.to_string());
            }
            Scene::from_desc(ctx, desc)
        })
    })
}

/// Releases a scene and the `luxon_object` handles of its parts. A render of it running on
/// another thread finishes first (the scene goes when it ends).
#[unsafe(no_mangle)]
pub extern "C" fn luxon_scene_release(scene: luxon_scene) -> luxon_status {
    guard("luxon_scene_release", || {
        let entry = SCENES.release(scene.id)?;
        // Its part handles go with it (a poisoned lock still holds their ids).
        let parts = match entry.value.state.lock() {
            Ok(mut s) => std::mem::take(&mut s.parts),
            Err(poisoned) => std::mem::take(&mut poisoned.into_inner().parts),
        };
        for (id, _) in parts {
            let _ = PARTS.release(id);
        }
        Ok(())
    })
}

/// The camera from RON text, e.g. `(position: (0, 0, 5), look_at: (0, 0, 0), fov: 40)`
/// (a scene file's `camera:`); errors point into the text as `<camera>:line:col`.
///
/// # Safety
/// `ron` is a valid string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_camera_ron(
    scene: luxon_scene,
    ron: *const c_char,
) -> luxon_status {
    guard("luxon_scene_set_camera_ron", || {
        // SAFETY: a valid string (caller).
        let ron = unsafe { text(ron, "ron") }?;
        with_scene(scene, |s, _| Ok(s.scene.set_camera_ron(ron)?))
    })
}

/// Reads 3 doubles at `p` (named `what`).
///
/// # Safety
/// `p` is NULL or valid for reads of 3 doubles.
unsafe fn vec3(p: *const f64, what: &str) -> Result<[f64; 3], Failure> {
    if p.is_null() {
        return Err(Failure::invalid(format!("`{what}` is NULL")));
    }
    // SAFETY: 3 readable doubles (caller); unaligned reads allow any caller layout.
    Ok(unsafe {
        [
            p.read_unaligned(),
            p.add(1).read_unaligned(),
            p.add(2).read_unaligned(),
        ]
    })
}

/// A perspective camera at `position` (3 doubles) looking at `look_at` with `up` upwards and
/// a vertical field of view of `fov_deg` degrees (in (0, 180)).
///
/// # Safety
/// `position`, `look_at` and `up` are each valid for reads of 3 doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_camera_view(
    scene: luxon_scene,
    position: *const f64,
    look_at: *const f64,
    up: *const f64,
    fov_deg: f64,
) -> luxon_status {
    guard("luxon_scene_set_camera_view", || {
        // SAFETY: 3 readable doubles each (caller).
        let camera = unsafe {
            CameraDesc {
                position: vec3(position, "position")?,
                look_at: vec3(look_at, "look_at")?,
                up: vec3(up, "up")?,
                projection: Projection::Perspective { fov_deg },
                aspect: None,
                frustum: None,
                depth_of_field: None,
                stereo: None,
            }
        };
        with_scene(scene, |s, _| Ok(s.scene.set_camera(camera)?))
    })
}

/// Render space's origin in world coordinates (3 doubles); NULL: the camera's position at the
/// first commit. Fixed at the first commit; changing it later builds the scene again. Call it
/// when the camera moves far (10^4 times the data's size) from where it was at the first
/// commit: precision near the camera follows its distance to the origin.
///
/// # Safety
/// `origin` is NULL or valid for reads of 3 doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_origin(
    scene: luxon_scene,
    origin: *const f64,
) -> luxon_status {
    guard("luxon_scene_set_origin", || {
        let origin = match origin.is_null() {
            true => None,
            // SAFETY: 3 readable doubles (caller).
            false => Some(unsafe { vec3(origin, "origin") }?),
        };
        with_scene(scene, |s, _| Ok(s.scene.set_origin(origin)?))
    })
}

/// The colour of rays that hit nothing (linear RGB, each finite and ≥ 0).
#[unsafe(no_mangle)]
pub extern "C" fn luxon_scene_set_background(
    scene: luxon_scene,
    r: f64,
    g: f64,
    b: f64,
) -> luxon_status {
    guard("luxon_scene_set_background", || {
        with_scene(scene, |s, _| Ok(s.scene.set_background([r, g, b])?))
    })
}

/// Puts an animated scene (a scene file with `animation:`) at frame `frame` at the next commit:
/// its camera, lights, keyed objects and colours. A scene without an animation refuses it.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_scene_set_frame(scene: luxon_scene, frame: u32) -> luxon_status {
    guard("luxon_scene_set_frame", || {
        with_scene(scene, |s, _| Ok(s.scene.set_frame(frame)?))
    })
}

/// The render settings from RON text, e.g. `(samples: 4, max_depth: 8)` (a scene file's
/// `render:`, without `width`, `height`, `outputs` and `parallel`: the target gives the size,
/// `luxon_write_image` writes files); errors point into the text as `<render_settings>:line:col`.
///
/// # Safety
/// `ron` is a valid string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_render_ron(
    scene: luxon_scene,
    ron: *const c_char,
) -> luxon_status {
    guard("luxon_scene_set_render_ron", || {
        // SAFETY: a valid string (caller).
        let ron = unsafe { text(ron, "ron") }?;
        with_scene(scene, |s, _| Ok(s.scene.set_render_ron(ron)?))
    })
}

/// Fog from RON text, e.g. `(mode: Exp(density: 0.1), color: (0.5, 0.5, 0.5))`; NULL: none.
/// Errors point into the text as `<fog>:line:col`.
///
/// # Safety
/// `ron` is NULL or a valid string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_fog_ron(
    scene: luxon_scene,
    ron: *const c_char,
) -> luxon_status {
    guard("luxon_scene_set_fog_ron", || {
        // SAFETY: NULL or a valid string (caller).
        let ron = unsafe { optional_text(ron, "ron") }?;
        with_scene(scene, |s, _| match ron {
            Some(t) => Ok(s.scene.set_fog_ron(t)?),
            None => Ok(s.scene.set_fog(None)?),
        })
    })
}

/// Ambient occlusion from RON text, e.g. `(samples: 16, distance: 2)`; NULL: none.
/// Errors point into the text as `<ambient_occlusion>:line:col`.
///
/// # Safety
/// `ron` is NULL or a valid string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_ambient_occlusion_ron(
    scene: luxon_scene,
    ron: *const c_char,
) -> luxon_status {
    guard("luxon_scene_set_ambient_occlusion_ron", || {
        // SAFETY: NULL or a valid string (caller).
        let ron = unsafe { optional_text(ron, "ron") }?;
        with_scene(scene, |s, _| match ron {
            Some(t) => Ok(s.scene.set_ambient_occlusion_ron(t)?),
            None => Ok(s.scene.set_ambient_occlusion(None)?),
        })
    })
}

/// The handle of a part, made on first use (the same part gets the same handle).
pub(crate) fn part_handle(
    s: &mut SceneState,
    scene: u64,
    id: PartId,
) -> Result<luxon_object, Failure> {
    if let Some((h, _)) = s.parts.iter().find(|(_, p)| *p == id) {
        return Ok(luxon_object { id: *h });
    }
    let h = PARTS.insert(Part { scene, id })?;
    s.parts.push((h, id));
    Ok(luxon_object { id: h })
}

/// The part `object` names, which must be `scene`'s.
pub(crate) fn part_of(object: luxon_object, scene: u64) -> Result<PartId, Failure> {
    let part = PARTS.get(object.id)?;
    if part.value.scene != scene {
        return Err(Failure::new(
            LUXON_ERROR_INVALID_HANDLE,
            format!(
                "luxon_object {:#x} belongs to luxon_scene {:#x}, not to {scene:#x}",
                object.id, part.value.scene
            ),
        ));
    }
    Ok(part.value.id)
}

/// Adds a light from RON text, e.g. `Point(position: (1, 2, 3), intensity: 2)` (an entry of a
/// scene file's `lights:`); errors point into the text as `<light>:line:col`.
///
/// # Safety
/// `ron` is a valid string; `out` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_add_light_ron(
    scene: luxon_scene,
    ron: *const c_char,
    out: *mut luxon_object,
) -> luxon_status {
    guard("luxon_scene_add_light_ron", || {
        // SAFETY: a valid string (caller).
        let ron = unsafe { text(ron, "ron") }?;
        let light = with_scene(scene, |s, _| {
            let id = s.scene.add_light_ron(ron)?;
            part_handle(s, scene.id, PartId::Light(id))
        })?;
        // SAFETY: NULL or writable (caller).
        unsafe { put_optional(out, light) }
    })
}

/// A point light (`luxon_point_light_init` fills in the defaults).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct luxon_point_light {
    /// `sizeof(luxon_point_light)`.
    pub size: u32,
    /// Non-zero: the light casts shadows (default 1).
    pub shadows: u32,
    pub position: [f64; 3],
    /// Linear RGB (default white).
    pub color: [f64; 3],
    /// Default 1.
    pub intensity: f64,
}

impl Default for luxon_point_light {
    fn default() -> Self {
        luxon_point_light {
            size: std::mem::size_of::<luxon_point_light>() as u32,
            shadows: 1,
            position: [0.0; 3],
            color: [1.0; 3],
            intensity: 1.0,
        }
    }
}

impl Versioned for luxon_point_light {}

/// Fills `light` with the defaults (and its `size`).
///
/// # Safety
/// `light` is valid for a write of a `luxon_point_light`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_point_light_init(light: *mut luxon_point_light) -> luxon_status {
    // SAFETY: writable (caller).
    guard("luxon_point_light_init", || unsafe {
        put(light, "light", luxon_point_light::default())
    })
}

/// Adds a point light (no attenuation with distance).
///
/// # Safety
/// `light` is a valid `luxon_point_light`; `out` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_add_point_light(
    scene: luxon_scene,
    light: *const luxon_point_light,
    out: *mut luxon_object,
) -> luxon_status {
    guard("luxon_scene_add_point_light", || {
        // SAFETY: a valid struct (caller).
        let l = unsafe { read_sized(light, "light", std::mem::size_of::<luxon_point_light>()) }?;
        let desc = LightDesc::Point {
            position: l.position,
            color: l.color,
            intensity: l.intensity,
            shadows: l.shadows != 0,
            attenuation: Attenuation::default(),
        };
        let light = with_scene(scene, |s, _| {
            let id = s.scene.add_light(desc)?;
            part_handle(s, scene.id, PartId::Light(id))
        })?;
        // SAFETY: NULL or writable (caller).
        unsafe { put_optional(out, light) }
    })
}

/// Changes a light from RON text (as `luxon_scene_add_light_ron`).
///
/// # Safety
/// `ron` is a valid string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_light_ron(
    scene: luxon_scene,
    light: luxon_object,
    ron: *const c_char,
) -> luxon_status {
    guard("luxon_scene_set_light_ron", || {
        // SAFETY: a valid string (caller).
        let ron = unsafe { text(ron, "ron") }?;
        let PartId::Light(id) = part_of(light, scene.id)? else {
            return Err(Failure::invalid(format!(
                "luxon_object {:#x} is an object, not a light",
                light.id
            )));
        };
        with_scene(scene, |s, _| Ok(s.scene.set_light_ron(id, ron)?))
    })
}

/// A material (`luxon_material_init` fills in the defaults: a scene file's `(...)`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct luxon_material {
    /// `sizeof(luxon_material)`.
    pub size: u32,
    /// Linear RGB base colour.
    pub color: [f64; 3],
    pub ambient: f64,
    pub diffuse: f64,
    pub specular: f64,
    /// Highlight exponent (> 0).
    pub shininess: f64,
    /// Mirror reflection coefficient.
    pub reflect: f64,
    /// Fraction of light passing through (0: opaque).
    pub transmit: f64,
    /// Index of refraction (1: no bending).
    pub ior: f64,
}

impl Default for luxon_material {
    fn default() -> Self {
        let d = MaterialDesc::default();
        luxon_material {
            size: std::mem::size_of::<luxon_material>() as u32,
            color: d.color,
            ambient: d.ambient,
            diffuse: d.diffuse,
            specular: d.specular,
            shininess: d.shininess,
            reflect: d.reflect,
            transmit: d.transmit,
            ior: d.ior,
        }
    }
}

impl Versioned for luxon_material {}

/// Fills `material` with the defaults (and its `size`).
///
/// # Safety
/// `material` is valid for a write of a `luxon_material`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_material_init(material: *mut luxon_material) -> luxon_status {
    // SAFETY: writable (caller).
    guard("luxon_material_init", || unsafe {
        put(material, "material", luxon_material::default())
    })
}

/// Defines the material `name` or changes it (its other properties: the defaults). Materials
/// are never removed; `default` is the material of objects that name none.
///
/// # Safety
/// `name` is a valid string; `material` a valid `luxon_material`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_material(
    scene: luxon_scene,
    name: *const c_char,
    material: *const luxon_material,
) -> luxon_status {
    guard("luxon_scene_set_material", || {
        // SAFETY: a valid string and struct (caller).
        let (name, m) = unsafe {
            (
                text(name, "name")?,
                read_sized(material, "material", std::mem::size_of::<luxon_material>())?,
            )
        };
        let desc = MaterialDesc {
            color: m.color,
            ambient: m.ambient,
            diffuse: m.diffuse,
            specular: m.specular,
            shininess: m.shininess,
            reflect: m.reflect,
            transmit: m.transmit,
            ior: m.ior,
            ..MaterialDesc::default()
        };
        with_scene(scene, |s, _| {
            s.scene
                .set_material(name, desc)
                .map(drop)
                .map_err(Into::into)
        })
    })
}

/// Defines the material `name` or changes it, from RON text, e.g.
/// `(color: (0.8, 0.2, 0.2), specular: 0.5)`; errors point into the text as
/// `<material>:line:col`.
///
/// # Safety
/// `name` and `ron` are valid strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_material_ron(
    scene: luxon_scene,
    name: *const c_char,
    ron: *const c_char,
) -> luxon_status {
    guard("luxon_scene_set_material_ron", || {
        // SAFETY: valid strings (caller).
        let (name, ron) = unsafe { (text(name, "name")?, text(ron, "ron")?) };
        with_scene(scene, |s, _| {
            s.scene
                .set_material_ron(name, ron)
                .map(drop)
                .map_err(Into::into)
        })
    })
}

/// Defines the texture `name` made by the texture plugin `plugin` (e.g. `checker`, `image`,
/// `stripes`) from its parameters in RON (`params_ron`, e.g. `(width: 0.1)`; NULL: `()`), or
/// replaces it; materials name it in their `texture` (`luxon_scene_set_material_ron`). The
/// plugin reads the parameters now: its errors come from this call, pointing into them as
/// `<texture>:line:col` (LUXON_ERROR_SCENE). Textures are never removed; the next commit
/// builds the scene again (array objects keep their trees).
///
/// # Safety
/// `name` and `plugin` are valid strings, `params_ron` NULL or a valid string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_texture(
    scene: luxon_scene,
    name: *const c_char,
    plugin: *const c_char,
    params_ron: *const c_char,
) -> luxon_status {
    guard("luxon_scene_set_texture", || {
        // SAFETY: valid strings or NULL where allowed (caller).
        let (name, plugin, params) = unsafe {
            (
                text(name, "name")?,
                text(plugin, "plugin")?,
                optional_text(params_ron, "params_ron")?,
            )
        };
        with_scene(scene, |s, entry| {
            entry.plugin_found(plugin, PluginKind::Texture)?;
            let params = params.unwrap_or("()");
            Ok(s.scene.set_texture(name, plugin, params)?)
        })
    })
}

/// Defines the clip group `name` or replaces its planes, from RON text: the list a scene
/// file's `clip_groups` holds, e.g. `[(point: (0, 0, 0), normal: (0, 1, 0))]` (an object or
/// volume cut by the group loses what lies on the side a plane's normal points to). Errors
/// point into the text as `<clip_planes>:line:col`. Objects name the group in
/// `luxon_scene_add_object`, volumes in their render settings (`clip: "name"`). Clip groups
/// are never removed; the next commit builds the scene again.
///
/// # Safety
/// `name` and `planes_ron` are valid strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_set_clip_group(
    scene: luxon_scene,
    name: *const c_char,
    planes_ron: *const c_char,
) -> luxon_status {
    guard("luxon_scene_set_clip_group", || {
        // SAFETY: valid strings (caller).
        let (name, planes) = unsafe { (text(name, "name")?, text(planes_ron, "planes_ron")?) };
        with_scene(scene, |s, _| {
            s.scene
                .set_clip_group_ron(name, planes)
                .map(drop)
                .map_err(Into::into)
        })
    })
}

/// Adds a volume read by the volume reader plugin `plugin` (`raw`, `vdb`, as scene files name
/// them) from its parameters in RON (`params_ron`, e.g. `(file: "head.raw", dims: (256, 256,
/// 109))`; relative paths start at the working directory, or a loaded scene's directory),
/// called `name` (NULL: unnamed) and drawn as `render_ron` says (what follows `render:` in a
/// scene file's volume, e.g. `(transfer: (preset: "viridis"))`; NULL: data only, not drawn).
/// The plugin reads the file at the next commit; its errors point into the parameters as
/// `<object N>:line:col`. Adding or removing one (`luxon_scene_remove`) builds the scene
/// again at the next commit.
///
/// # Safety
/// `plugin` and `params_ron` are valid strings, `name` and `render_ron` NULL or valid
/// strings; `out` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_add_volume_plugin(
    scene: luxon_scene,
    plugin: *const c_char,
    params_ron: *const c_char,
    name: *const c_char,
    render_ron: *const c_char,
    out: *mut luxon_object,
) -> luxon_status {
    guard("luxon_scene_add_volume_plugin", || {
        // SAFETY: valid strings or NULL where allowed (caller).
        let (plugin, params, name, look) = unsafe {
            (
                text(plugin, "plugin")?,
                text(params_ron, "params_ron")?,
                optional_text(name, "name")?,
                optional_text(render_ron, "render_ron")?,
            )
        };
        let object = with_scene(scene, |s, entry| {
            entry.plugin_found(plugin, PluginKind::VolumeReader)?;
            let id = match look {
                Some(look) => s.scene.add_plugin_volume_ron(plugin, params, name, look)?,
                None => s.scene.add_plugin_volume(plugin, params, name, None)?,
            };
            part_handle(s, scene.id, PartId::Object(id))
        })?;
        // SAFETY: NULL or writable (caller).
        unsafe { put_optional(out, object) }
    })
}

/// Adds an object made by the primitive plugin `plugin` (e.g. `sphere`, `plane`, from
/// luxon-shapes) from its parameters in RON (`params_ron`, e.g.
/// `(center: (0, 1, 0), radius: 0.5)`), of the material named `material` (NULL: `default`),
/// cut by the clip group `clip_group` (NULL: none). The plugin reads the parameters at the next
/// commit; its errors point into them as `<object N>:line:col`. Every commit after objects
/// were added or removed builds the scene again, once: plugin objects are for what does not
/// change every step.
///
/// # Safety
/// `plugin` and `params_ron` are valid strings, `material` and `clip_group` NULL or valid
/// strings; `out` is NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_add_object(
    scene: luxon_scene,
    plugin: *const c_char,
    params_ron: *const c_char,
    material: *const c_char,
    clip_group: *const c_char,
    out: *mut luxon_object,
) -> luxon_status {
    guard("luxon_scene_add_object", || {
        // SAFETY: valid strings or NULL where allowed (caller).
        let (plugin, params, material, clip) = unsafe {
            (
                text(plugin, "plugin")?,
                text(params_ron, "params_ron")?,
                optional_text(material, "material")?,
                optional_text(clip_group, "clip_group")?,
            )
        };
        let object = with_scene(scene, |s, entry| {
            entry.plugin_found(plugin, PluginKind::Primitive)?;
            let material = match material {
                None => None,
                Some(m) => Some(s.scene.material(m).ok_or_else(|| {
                    Failure::invalid(format!("the scene has no material named `{m}`"))
                })?),
            };
            let clip = match clip {
                None => None,
                Some(c) => Some(s.scene.clip_group(c).ok_or_else(|| {
                    Failure::invalid(format!("the scene has no clip group named `{c}`"))
                })?),
            };
            let id = s.scene.add_plugin_object(plugin, params, material, clip)?;
            part_handle(s, scene.id, PartId::Object(id))
        })?;
        // SAFETY: NULL or writable (caller).
        unsafe { put_optional(out, object) }
    })
}

/// Removes a light or an object from the scene; its handle is invalid from then on.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_scene_remove(scene: luxon_scene, part: luxon_object) -> luxon_status {
    guard("luxon_scene_remove", || {
        let id = part_of(part, scene.id)?;
        with_scene(scene, |s, _| {
            match id {
                PartId::Light(l) => s.scene.remove_light(l)?,
                PartId::Object(o) => s.scene.remove(o)?,
            }
            s.parts.retain(|(h, _)| *h != part.id);
            PARTS.release(part.id).map(drop)
        })
    })
}

/// Writes handles of the scene's lights (a loaded scene's: in file order) into `out`, up to
/// `capacity` of them, and their number to `count`. `out` may be NULL when `capacity` is 0
/// (to ask for the number).
///
/// # Safety
/// `out` is valid for writes of `capacity` handles (or `capacity` is 0); `count` is valid for a
/// write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_lights(
    scene: luxon_scene,
    out: *mut luxon_object,
    capacity: usize,
    count: *mut usize,
) -> luxon_status {
    guard("luxon_scene_lights", || {
        let parts = with_scene(scene, |s, _| {
            let ids = s.scene.lights();
            ids.into_iter()
                .map(|l| part_handle(s, scene.id, PartId::Light(l)))
                .collect::<Result<Vec<_>, _>>()
        })?;
        // SAFETY: as the caller guarantees.
        unsafe { put_list(&parts, out, capacity, count) }
    })
}

/// Writes handles of the scene's objects (a loaded scene's: in file order; imported geometry
/// has none) as `luxon_scene_lights` does.
///
/// # Safety
/// As `luxon_scene_lights`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_objects(
    scene: luxon_scene,
    out: *mut luxon_object,
    capacity: usize,
    count: *mut usize,
) -> luxon_status {
    guard("luxon_scene_objects", || {
        let parts = with_scene(scene, |s, _| {
            let ids = s.scene.objects();
            ids.into_iter()
                .map(|o| part_handle(s, scene.id, PartId::Object(o)))
                .collect::<Result<Vec<_>, _>>()
        })?;
        // SAFETY: as the caller guarantees.
        unsafe { put_list(&parts, out, capacity, count) }
    })
}

/// Writes `parts` into the caller's array, as far as it goes, and their number.
///
/// # Safety
/// `out` is valid for writes of `capacity` handles (or `capacity` is 0); `count` is NULL or
/// valid for a write.
unsafe fn put_list(
    parts: &[luxon_object],
    out: *mut luxon_object,
    capacity: usize,
    count: *mut usize,
) -> Result<(), Failure> {
    if capacity > 0 && out.is_null() {
        return Err(Failure::invalid("`out` is NULL and `capacity` is not 0"));
    }
    for (i, p) in parts.iter().take(capacity).enumerate() {
        // SAFETY: i < capacity, so within the caller's array.
        unsafe { out.add(i).write(*p) };
    }
    // SAFETY: NULL or writable (caller).
    unsafe { put(count, "count", parts.len()) }
}

/// Writes through an out-pointer the caller may leave NULL.
///
/// # Safety
/// `out` is NULL or valid for a write of a `T`.
pub(crate) unsafe fn put_optional<T>(out: *mut T, value: T) -> Result<(), Failure> {
    if !out.is_null() {
        // SAFETY: not NULL, so writable (this function's contract).
        unsafe { out.write(value) };
    }
    Ok(())
}

/// What a commit did (`luxon_scene_commit`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct luxon_commit_report {
    /// `sizeof(luxon_commit_report)`.
    pub size: u32,
    /// Geometry builds: 1 when the commit built the scene (its BVHs), plus one per array object
    /// whose BVH it built; 0 when it only took new settings,
    /// camera, background, lights, materials, fog or ambient occlusion.
    pub rebuilt: u32,
    /// 1 when it took new lights, materials, fog or ambient occlusion without a build.
    pub shading: u32,
    /// Seconds spent building BVHs.
    pub bvh_seconds: f64,
    /// Seconds the whole commit took.
    pub commit_seconds: f64,
    /// Array objects whose BVHs were refitted (their arrays marked modified, counts unchanged).
    pub refitted: u32,
    /// Array objects refitted whose trees had become too costly, so built again (also in
    /// `rebuilt`, which counts every array object built besides the scene's 1).
    pub degraded: u32,
    /// Volumes read from their arrays (new, set again, or marked modified).
    pub volumes_read: u32,
}

impl Versioned for luxon_commit_report {}

/// Brings the scene's built form up to date on `renderer`'s threads, redoing only what the
/// changes since the last commit need (every render commits first; committing ahead separates
/// the build's time from the render's). `report` may be NULL; its `size` must be set.
///
/// # Safety
/// `report` is NULL or a `luxon_commit_report` whose `size` is set, writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_commit(
    scene: luxon_scene,
    renderer: luxon_renderer,
    report: *mut luxon_commit_report,
) -> luxon_status {
    guard("luxon_scene_commit", || {
        let r = RENDERERS.get(renderer.id)?;
        let entry = SCENES.get(scene.id)?;
        let mut locked = entry.value.lock(scene.id, true)?;
        let done = locked.state.scene.commit(&r.value.renderer)?;
        let out = luxon_commit_report {
            size: 0,
            rebuilt: done.rebuilt,
            shading: u32::from(done.shading),
            bvh_seconds: done.bvh_time.as_secs_f64(),
            commit_seconds: done.commit_time.as_secs_f64(),
            refitted: done.refitted,
            degraded: done.degraded,
            volumes_read: done.volumes_read,
        };
        // SAFETY: NULL or writable as far as its size says (caller).
        unsafe { put_sized(report, &out) };
        Ok(())
    })
}

/// Writes the scene as a RON scene file at `path` (for a bug report, or to render it with the
/// `luxon` command).
///
/// # Safety
/// `path` is a valid string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_scene_save_ron(
    scene: luxon_scene,
    path: *const c_char,
) -> luxon_status {
    guard("luxon_scene_save_ron", || {
        // SAFETY: a valid string (caller).
        let path = unsafe { text(path, "path") }?;
        let ron = with_scene(scene, |s, _| Ok(s.scene.to_ron()?))?;
        std::fs::write(path, ron).map_err(|source| {
            Failure::from(Error::Io {
                path: path.into(),
                source,
            })
        })
    })
}
