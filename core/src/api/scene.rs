//! [`Scene`]: a retained scene, its description kept and its built form redone at each commit
//! only as far as the changes since the last one need.

use super::ids::{self, scene_serial, ClipId, LightId, MaterialId, ObjectId, Slots};
use super::objects::{
    expect_elem, Cylinders, Mesh, Radius, Spheres, VolumeGrid, INDEX3, REAL, UV, VEC3,
};
use super::volumes;
use super::{Context, Renderer};
use crate::arrays::{Array, Pins};
use crate::budget::{Budget, Charge};
use crate::error::Error;
use crate::geometry::array_set::{CylinderReader, MeshReader, RadiusRead, SphereReader};
use crate::geometry::objects::{Object, Objects, Outcome, Spec, MAX_OBJECTS};
use crate::math::DVec3;
use crate::plugin::texture::create_texture;
use crate::plugin::{PluginKind, Registry};
use crate::scene::update::ArrayVolume;
use crate::scene::{shadowless_groups, Prebuilt, Scene as Built};
use crate::volume::Volume;
use luxon_formats::{
    fragment, AoDesc, BackgroundDesc, CameraDesc, ClipPlaneDesc, FogDesc, LightDesc, MaterialDesc,
    ObjectDesc, Origin, PluginCall, Projection, RenderDesc, SceneDesc, Spanned, VolumeDescEntry,
    VolumeRenderDesc,
};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What a commit did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CommitReport {
    /// Geometry builds: 1 when the commit built the scene (its plugin objects and imported
    /// geometry stored and their BVHs built), plus one per array object whose BVH it built
    /// (new, given new arrays or counts, or degraded); 0 when it only took new settings,
    /// camera, background, lights, materials, fog or ambient occlusion, or refitted.
    pub rebuilt: u32,
    /// Array objects whose content changed but not their counts: their BVHs were refitted.
    pub refitted: u32,
    /// Array objects refitted whose tree's cost then exceeded [`crate::bvh::REBUILD_RATIO`] times its cost
    /// when built, so built again (also counted in `rebuilt`).
    pub degraded: u32,
    /// The largest ratio of a refitted tree's cost to its cost when built (0: no refit).
    pub worst_ratio: f32,
    /// Volumes read from their arrays into bricks: new ones, those given a new grid or look
    /// ([`Scene::set_volume`]), and those whose values changed (marked modified).
    pub volumes_read: u32,
    /// The commit took new lights, materials, fog or ambient occlusion into the built scene
    /// without building it again (no geometry touched).
    pub shading: bool,
    /// Time spent building BVHs.
    pub bvh_time: Duration,
    /// Time the whole commit took.
    pub commit_time: Duration,
}

/// A scene kept between renders: its description (what it was loaded or built from, with the
/// changes made since) and its built form, redone by [`Scene::commit`] (which every render
/// runs) only where the changes need it. Changing the camera, the background, the render
/// settings that touch no geometry, the lights, fog or ambient occlusion, or a material costs
/// microseconds; adding or removing an object, changing render space's origin, or the settings
/// the build reads (`transparency`, `light_scale`, `volume_step`, `memory`, `texture_cache`),
/// builds the scene again — once per commit, however many changes it takes. (A new material
/// name in a scene where some objects cast no shadow builds it again too: the materials of
/// those objects' copies are renumbered.) In an animated scene, whose animation holds the
/// lights and materials it keys, a change of lights or materials builds it again and puts it
/// back at its frame.
///
/// Lights and objects have ids ([`LightId`], [`ObjectId`]): a scene loaded from a file gives
/// them to its own in file order ([`Scene::lights`], [`Scene::objects`]). A removed part's id,
/// or another scene's, is refused with an error that says so. Materials, textures and clip
/// groups are named and never removed ([`MaterialId`], [`ClipId`]).
///
/// Render space's origin (the world point coordinates are stored relative to, in f32) is fixed
/// at the first commit: [`Scene::set_origin`]'s point when given, else the camera's position
/// then. A camera that moves later keeps it, so its images are those of a scene built with that
/// origin. Call `set_origin` when the camera leaves the data far behind (by some 10⁴ times the
/// data's size): precision near the camera follows the distance to the origin.
///
/// A render that fails because a plugin panicked (or a bug in Luxon) leaves the built form
/// unusable; it is dropped, and the next commit builds the scene again from its description
/// (plugin objects created anew). A scene whose imported geometry was consumed at load
/// ([`Scene::from_desc_frozen`], [`Scene::from_prebuilt`]) cannot be built again and says so.
pub struct Scene {
    // Dropped before the registry whose plugins its objects belong to.
    built: Option<Built>,
    desc: SceneDesc,
    registry: Arc<Registry>,
    /// The budget of the first build (a caller's, [`Scene::set_budget`]); later builds get a
    /// fresh one from the render settings (a build's charges stay with its budget).
    budget: Option<Arc<Budget>>,
    /// A geometry cache's geometry, taken by the first build.
    prebuilt: Option<Prebuilt>,
    /// The first build takes the imported geometry out of the description.
    frozen: bool,
    /// Why the scene cannot be built again, once its imported geometry is gone.
    consumed: Option<&'static str>,
    origin: Option<DVec3>,
    /// The image size of the next render.
    size: (u32, u32),
    /// What the next commit must redo.
    dirty: Dirty,
    /// An animated scene's frame to put it at, at the next commit.
    frame: Option<u32>,
    /// The frame the built scene was last put at (put back after a build).
    at_frame: Option<u32>,
    /// This scene's serial, in its ids.
    serial: u32,
    lights: Slots<ids::Light>,
    objects: Slots<ids::Object>,
    /// Per object, in the order of `objects`: a plugin object (the description's `objects`,
    /// in the same order), an array object's description or a volume grid's.
    parts: Vec<Part>,
    /// The key and generation of each volume read from an array that the built scene holds,
    /// in order (its last volumes).
    volumes_built: Vec<(u64, u64)>,
    /// What each of those volumes' bricks are charged to the built scene's memory budget.
    volume_charges: Vec<Charge>,
    /// The materials of the imported groups that cast no shadow (the build's copies of them
    /// depend on it), taken before a frozen scene's groups are consumed.
    shadowless: Vec<Option<Spanned<String>>>,
    /// [`Scene::new`]'s scene has no camera until one is set.
    has_camera: bool,
}

/// What an object id stands for.
#[derive(Clone)]
enum Part {
    Plugin,
    /// A volume read by a volume reader plugin: an entry of the description's `volumes`,
    /// after those the scene was loaded with (which have no ids).
    PluginVolume,
    Array(ArrayObject),
    // Boxed: a grid and its look are large, and plugin objects many.
    Volume(Box<VolumeObject>),
}

impl Part {
    fn plugin_volume(&self) -> bool {
        matches!(self, Part::PluginVolume)
    }

    fn array(&self) -> Option<&ArrayObject> {
        match self {
            Part::Array(a) => Some(a),
            _ => None,
        }
    }

    fn volume(&self) -> Option<&VolumeObject> {
        match self {
            Part::Volume(v) => Some(v),
            _ => None,
        }
    }
}

/// A volume read from an array, as the caller described it.
#[derive(Clone)]
struct VolumeObject {
    /// Changes when the object is given a new grid or look: it is then read again.
    key: u64,
    /// `object 2 (volume)`.
    label: String,
    /// The volume's name (the grid's, or the object's id).
    name: String,
    grid: VolumeGrid,
    look: Option<VolumeRenderDesc>,
}

/// A volume object and the name its grid gives it.
struct Named {
    object: VolumeObject,
    name: Option<String>,
}

/// An array object as the caller described it.
#[derive(Clone)]
struct ArrayObject {
    /// Changes when the object is given new arrays: its built form is then built again.
    key: u64,
    /// `object 2 (spheres)`.
    label: String,
    arrays: Vec<Array>,
    spec: Spec,
    material: u32,
}

/// A radius as a reader takes it (a radius array joins `arrays`); `whose`: `spheres'`.
fn radius_read(whose: &str, r: Radius, arrays: &mut Vec<Array>) -> Result<RadiusRead, Error> {
    match r {
        Radius::Const(r) => {
            if !(r.is_finite() && r > 0.0) {
                return Err(Error::Api(format!(
                    "{whose} radius {r}; expected a radius > 0"
                )));
            }
            Ok(RadiusRead::Const(r))
        }
        Radius::Each(a) => {
            expect_elem(&format!("{whose} radii"), &a, REAL)?;
            arrays.push(a);
            Ok(RadiusRead::Each(arrays.len() - 1))
        }
    }
}

/// An array object's arrays, reader and material.
type ArrayParts = (Vec<Array>, Spec, u32);

fn array_key() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Volumes read from arrays by their keys and generations, with their budget charges.
type ReadVolumes = HashMap<(u64, u64), (Volume, Charge)>;

/// The keys and generations of the volumes a commit put in the built scene, and their charges.
type PutVolumes = (Vec<(u64, u64)>, Vec<Charge>);

/// What the next commit must redo besides the camera and settings.
#[derive(Clone, Copy, Debug, Default)]
struct Dirty {
    /// Everything (origin, budget or a setting the build reads changed; objects; a fault).
    build: bool,
    lights: bool,
    materials: bool,
    /// Fog and ambient occlusion.
    effects: bool,
}

/// Where a part added from code is "written": `<kind>:1:1`, as the fragments' messages say.
fn origin(name: &str) -> Origin {
    Origin {
        file: Arc::new(PathBuf::from(name)),
        line: 1,
        col: 1,
    }
}

const FROZEN: &str = "this scene's imported geometry was consumed at load \
    (Scene::from_desc_frozen) and it cannot be built again; load it with Scene::load to change it";
const PREBUILT: &str = "this scene's geometry came from a geometry cache and was consumed \
    (Scene::from_prebuilt); it cannot be built again; load it with Scene::load to change it";

impl Scene {
    /// An empty scene: no camera (a commit is refused until [`Scene::set_camera`] gives one),
    /// no lights, objects or materials but the default one, a black background and the
    /// default render settings. Relative paths in plugin parameters start at the working
    /// directory.
    pub fn new(ctx: &Context) -> Scene {
        // A placeholder, never rendered: `has_camera` is false until one is set.
        let camera = CameraDesc {
            position: [0.0; 3],
            look_at: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            projection: Projection::Perspective { fov_deg: 40.0 },
            aspect: None,
            frustum: None,
            depth_of_field: None,
            stereo: None,
        };
        let desc = SceneDesc {
            source: PathBuf::from("<scene>"),
            camera: Spanned {
                value: camera,
                at: origin("<camera>"),
            },
            background: BackgroundDesc::default(),
            lights: Vec::new(),
            fog: None,
            ambient_occlusion: None,
            textures: Vec::new(),
            materials: Vec::new(),
            clip_groups: Vec::new(),
            objects: Vec::new(),
            prototypes: Default::default(),
            instances: Vec::new(),
            series: Vec::new(),
            inline: Vec::new(),
            volumes: Vec::new(),
            render: RenderDesc::default(),
            plugin_path: Vec::new(),
            warnings: Vec::new(),
            animation: None,
        };
        let mut s = Scene::with_desc(ctx, desc);
        s.has_camera = false;
        s
    }

    /// Loads a scene file of any format Luxon reads (on the context's pool). The loader's
    /// warnings go to the log sink ([`crate::error::set_log`]).
    pub fn load(ctx: &Context, path: &Path) -> Result<Scene, Error> {
        let desc = ctx.install(|| luxon_formats::load(path))?;
        for w in &desc.warnings {
            crate::error::log(crate::error::Level::Warning, &w.to_string());
        }
        Scene::from_desc(ctx, desc)
    }

    /// A scene from its description; imported geometry stays in it (so the scene can be built
    /// again after a change).
    pub fn from_desc(ctx: &Context, desc: SceneDesc) -> Result<Scene, Error> {
        Ok(Scene::with_desc(ctx, desc))
    }

    fn with_desc(ctx: &Context, desc: SceneDesc) -> Scene {
        let serial = scene_serial();
        Scene {
            built: None,
            size: (desc.render.width, desc.render.height),
            lights: Slots::new(serial, desc.lights.len()),
            objects: Slots::new(serial, desc.objects.len()),
            parts: vec![Part::Plugin; desc.objects.len()],
            volumes_built: Vec::new(),
            volume_charges: Vec::new(),
            shadowless: shadowless_groups(&desc),
            desc,
            registry: ctx.registry.clone(),
            budget: None,
            prebuilt: None,
            frozen: false,
            consumed: None,
            origin: None,
            dirty: Dirty {
                build: true,
                ..Dirty::default()
            },
            frame: None,
            at_frame: None,
            serial,
            has_camera: true,
        }
    }

    /// A scene whose imported geometry (NFF, OBJ...) the first commit takes out of the
    /// description, freeing each group once it is stored: a large import is never held twice.
    /// Such a scene cannot be built again (changes that need a build are refused).
    pub fn from_desc_frozen(ctx: &Context, desc: SceneDesc) -> Result<Scene, Error> {
        let mut s = Scene::from_desc(ctx, desc)?;
        s.frozen = true;
        Ok(s)
    }

    /// A scene whose native geometry and BVHs come from a geometry cache (`desc` holds the rest
    /// of the scene and no imported geometry). It cannot be built again.
    pub fn from_prebuilt(
        ctx: &Context,
        desc: SceneDesc,
        geometry: Prebuilt,
    ) -> Result<Scene, Error> {
        let mut s = Scene::from_desc(ctx, desc)?;
        s.prebuilt = Some(geometry);
        Ok(s)
    }

    /// The description as it is now (imported geometry gone once consumed).
    pub fn desc(&self) -> &SceneDesc {
        &self.desc
    }

    /// The built scene of the last commit, if any: for its statistics, settings and queries.
    pub fn built(&self) -> Option<&Built> {
        self.built.as_ref()
    }

    /// The memory budget the next build counts against (by default the render settings' own,
    /// [`Budget::for_render`]). Builds the scene again.
    pub fn set_budget(&mut self, budget: Arc<Budget>) {
        self.budget = Some(budget);
        self.dirty.build = true;
    }

    /// The camera (checked by the scene files' rules). An animated scene's camera is its
    /// animation's.
    pub fn set_camera(&mut self, camera: CameraDesc) -> Result<(), Error> {
        self.camera_not_animated()?;
        fragment::check_camera(&camera).map_err(|m| Error::Api(format!("camera: {m}")))?;
        self.desc.camera.value = camera;
        self.has_camera = true;
        Ok(())
    }

    /// The camera from RON text, e.g. `(position: (0, 0, 5), look_at: (0, 0, 0))`; errors
    /// point into the text as `<camera>:line:col`.
    pub fn set_camera_ron(&mut self, text: &str) -> Result<(), Error> {
        self.camera_not_animated()?;
        let camera = fragment::camera(text)?;
        self.set_camera(camera)
    }

    fn camera_not_animated(&self) -> Result<(), Error> {
        match self.desc.animation {
            Some(_) => Err(Error::Api(
                "this scene is animated: its frame places the camera (Scene::set_frame)".into(),
            )),
            None => Ok(()),
        }
    }

    /// The render settings (checked by the scene files' rules). The image size is the
    /// target's, and `outputs` and `parallel` are not an embedded scene's: those of `render`
    /// are ignored.
    pub fn set_render(&mut self, render: RenderDesc) -> Result<(), Error> {
        fragment::check_render_settings(&render)
            .map_err(|m| Error::Api(format!("render settings: {m}")))?;
        let old = &self.desc.render;
        let rebuild = old.transparency != render.transparency
            || old.volume_step != render.volume_step
            || old.light_scale != render.light_scale
            || old.memory != render.memory
            || old.texture_cache != render.texture_cache;
        let r = &mut self.desc.render;
        *r = RenderDesc {
            width: r.width,
            height: r.height,
            outputs: std::mem::take(&mut r.outputs),
            parallel: r.parallel.clone(),
            ..render
        };
        self.dirty.build |= rebuild;
        Ok(())
    }

    /// The render settings from RON text, e.g. `(samples: 4, max_depth: 8)` (see
    /// [`Scene::set_render`]); errors point into the text as `<render_settings>:line:col`.
    pub fn set_render_ron(&mut self, text: &str) -> Result<(), Error> {
        let render = fragment::render_settings(text)?;
        self.set_render(render)
    }

    /// The colour of rays that hit nothing (linear RGB, each finite and ≥ 0).
    pub fn set_background(&mut self, rgb: [f64; 3]) -> Result<(), Error> {
        if rgb.iter().any(|c| !c.is_finite() || *c < 0.0) {
            return Err(Error::Api(format!(
                "background {rgb:?}: expected finite components ≥ 0"
            )));
        }
        self.desc.background = BackgroundDesc::Color(rgb);
        Ok(())
    }

    /// Render space's origin in world coordinates; `None`: the camera's position at the next
    /// build. Fixed at the first commit; changing it later builds the scene again.
    pub fn set_origin(&mut self, world: Option<[f64; 3]>) -> Result<(), Error> {
        if let Some(p) = world {
            if p.iter().any(|c| !c.is_finite()) {
                return Err(Error::Api(format!(
                    "origin {p:?}: expected finite coordinates"
                )));
            }
        }
        let origin = world.map(DVec3::from);
        if self.built.is_some() && origin != self.origin {
            self.dirty.build = true;
        }
        self.origin = origin;
        Ok(())
    }

    /// Puts an animated scene at frame `k` at the next commit (camera, lights, keyed objects
    /// and colours); the commit fails, leaving the scene as it was, if the frame cannot be set.
    pub fn set_frame(&mut self, k: u32) -> Result<(), Error> {
        if self.desc.animation.is_none() {
            return Err(Error::Api(format!(
                "frame {k}: {} has no `animation:`",
                self.desc.source.display()
            )));
        }
        self.frame = Some(k);
        Ok(())
    }

    /// The scene's lights, in its order (a loaded scene's: file order).
    pub fn lights(&self) -> Vec<LightId> {
        self.lights.ids()
    }

    /// Adds a light (checked by the scene files' rules) after the others.
    pub fn add_light(&mut self, light: LightDesc) -> Result<LightId, Error> {
        fragment::check_light(&light).map_err(|m| Error::Api(format!("light: {m}")))?;
        self.desc.lights.push(Spanned {
            value: light,
            at: origin("<light>"),
        });
        self.dirty.lights = true;
        Ok(self.lights.insert())
    }

    /// Adds a light from RON text, e.g. `Point(position: (1, 2, 3), intensity: 2)`; errors
    /// point into the text as `<light>:line:col`.
    pub fn add_light_ron(&mut self, text: &str) -> Result<LightId, Error> {
        let light = fragment::light(text)?;
        self.add_light(light)
    }

    /// Changes a light (checked by the scene files' rules).
    pub fn set_light(&mut self, id: LightId, light: LightDesc) -> Result<(), Error> {
        let i = self.lights.position(id)?;
        fragment::check_light(&light).map_err(|m| Error::Api(format!("light: {m}")))?;
        self.desc.lights[i] = Spanned {
            value: light,
            at: origin("<light>"),
        };
        self.dirty.lights = true;
        Ok(())
    }

    /// [`Scene::set_light`] from RON text.
    pub fn set_light_ron(&mut self, id: LightId, text: &str) -> Result<(), Error> {
        self.lights.position(id)?;
        let light = fragment::light(text)?;
        self.set_light(id, light)
    }

    /// Removes a light; its id is refused from now on. An animated scene's lights cannot be
    /// removed (its animation refers to them by their place).
    pub fn remove_light(&mut self, id: LightId) -> Result<(), Error> {
        self.lights.position(id)?;
        self.not_animated("lights")?;
        let i = self.lights.remove(id)?;
        self.desc.lights.remove(i);
        self.dirty.lights = true;
        Ok(())
    }

    fn not_animated(&self, what: &str) -> Result<(), Error> {
        match self.desc.animation {
            Some(_) => Err(Error::Api(format!(
                "this scene is animated and its animation refers to {what} by their place in \
                 the scene: they can be added and changed, not removed"
            ))),
            None => Ok(()),
        }
    }

    /// The material named `name` (`default`: the default one), if the scene has it.
    pub fn material(&self, name: &str) -> Option<MaterialId> {
        let index = self.material_names().iter().position(|n| *n == name)?;
        Some(MaterialId {
            scene: self.serial,
            index: index as u32,
        })
    }

    /// The materials' names by number, as the build numbers them: `default`, then the
    /// scene's in the order they were first defined.
    fn material_names(&self) -> Vec<&str> {
        let mut names = vec!["default"];
        for (n, _) in &self.desc.materials {
            if !names.contains(&n.as_str()) {
                names.push(n);
            }
        }
        names
    }

    fn material_name(&self, id: MaterialId) -> Result<String, Error> {
        if id.scene != self.serial {
            return Err(Error::Api(
                "this material id belongs to another scene".into(),
            ));
        }
        let names = self.material_names();
        let name = names
            .get(id.index as usize)
            .ok_or_else(|| Error::Api(format!("material {} is not in this scene", id.index)))?;
        Ok(name.to_string())
    }

    /// Defines the material `name` (checked by the scene files' rules) or changes it; its
    /// textures must be the scene's. Materials are never removed. (`default` is the material
    /// of objects that name none.)
    pub fn set_material(&mut self, name: &str, m: MaterialDesc) -> Result<MaterialId, Error> {
        fragment::check_material(&m).map_err(|e| Error::Api(format!("material `{name}`: {e}")))?;
        for t in [&m.texture, &m.reflect_texture, &m.transmit_texture]
            .into_iter()
            .flatten()
        {
            if !self.desc.textures.iter().any(|(n, _)| *n == t.value) {
                return Err(Error::at(&t.at, format!("no texture named `{}`", t.value)));
            }
        }
        let new = self.material(name).is_none();
        // A new name renumbers the copies that cast no shadow, which a consumed scene's
        // geometry refers to and cannot be stored again.
        let copies = self
            .built
            .as_ref()
            .is_some_and(|b| b.materials.len() > b.material_names.len());
        if let Some(why) = self.consumed.filter(|_| new && copies) {
            return Err(Error::Api(format!(
                "material `{name}` is new and would renumber the materials of objects that \
                 cast no shadow; {why}"
            )));
        }
        let value = Spanned {
            value: m,
            at: origin("<material>"),
        };
        // Later definitions of a name replace earlier ones: every one becomes the new one.
        let mut found = false;
        for (_, d) in self.desc.materials.iter_mut().filter(|(n, _)| n == name) {
            *d = value.clone();
            found = true;
        }
        if !found {
            self.desc.materials.push((name.to_string(), value));
        }
        self.dirty.materials = true;
        self.material(name)
            .ok_or_else(|| Error::Api(format!("material `{name}` was not defined")))
    }

    /// [`Scene::set_material`] from RON text, e.g. `(color: (0.8, 0.2, 0.2), specular: 0.5)`;
    /// errors point into the text as `<material>:line:col`.
    pub fn set_material_ron(&mut self, name: &str, text: &str) -> Result<MaterialId, Error> {
        let m = fragment::material(text)?;
        self.set_material(name, m)
    }

    /// Defines the texture `name` made by the texture plugin `plugin` (`checker`, `image`,
    /// `stripes`... or one of your own) from its parameters (RON text, as after `params:` in
    /// a scene file), or replaces it; materials refer to it by name
    /// ([`MaterialDesc::texture`]). The plugin is found and reads the parameters now, so its
    /// errors come from this call, pointing into them as `<texture>:line:col`. Textures are
    /// never removed. The next commit builds the scene again (a texture is part of the build;
    /// array objects keep their trees).
    pub fn set_texture(&mut self, name: &str, plugin: &str, params_ron: &str) -> Result<(), Error> {
        let at = origin("<texture>");
        let call = PluginCall {
            plugin: Spanned {
                value: plugin.to_string(),
                at: at.clone(),
            },
            params: params_ron.to_string(),
            params_at: at,
        };
        self.put_texture(name, call)
    }

    /// [`Scene::set_texture`] from RON text, as a scene file's `textures` map holds one after
    /// its name: `(plugin: "stripes", params: (width: 0.1))`; errors point into the text as
    /// `<texture>:line:col` (the plugin's too).
    pub fn set_texture_ron(&mut self, name: &str, text: &str) -> Result<(), Error> {
        let call = fragment::texture(text)?;
        self.put_texture(name, call)
    }

    fn put_texture(&mut self, name: &str, call: PluginCall) -> Result<(), Error> {
        if name.is_empty() {
            return Err(Error::Api("a texture needs a name".into()));
        }
        self.can_build(&format!("texture `{name}`"))?;
        let entry = self
            .registry
            .get(&call.plugin.value, PluginKind::Texture)
            .map_err(|e| Error::at(&call.plugin.at, e.to_string()))?;
        // Made once and dropped, so that a bad parameter is this call's error, not a later
        // commit's (the build makes the scene's own instance, within its budget).
        let dir = self.desc.source.parent().unwrap_or(Path::new(""));
        let budget = Budget::unlimited();
        create_texture(
            &self.registry,
            entry,
            &call.params,
            &call.params_at,
            dir,
            name,
            &budget,
        )
        .map_err(|(at, m)| Error::at(&at, m))?;
        let value = Spanned {
            at: call.params_at.clone(),
            value: call,
        };
        match self.desc.textures.iter_mut().find(|(n, _)| n == name) {
            Some((_, t)) => *t = value,
            None => self.desc.textures.push((name.to_string(), value)),
        }
        self.dirty.build = true;
        Ok(())
    }

    /// Refuses a change that needs a build in a scene that cannot be built again.
    fn can_build(&self, what: &str) -> Result<(), Error> {
        match self.consumed {
            Some(why) => Err(Error::Api(format!("{what} cannot change: {why}"))),
            None => Ok(()),
        }
    }

    /// Defines the clip group `name` (checked by the scene files' rules: at least one plane,
    /// each a finite point and a non-zero normal) or replaces its planes. Objects and volumes
    /// cut by it lose what lies on the side any of its planes' normals points to. Clip groups are never removed. The
    /// next commit builds the scene again.
    pub fn set_clip_group(
        &mut self,
        name: &str,
        planes: Vec<ClipPlaneDesc>,
    ) -> Result<ClipId, Error> {
        if name.is_empty() {
            return Err(Error::Api("a clip group needs a name".into()));
        }
        fragment::check_clip_planes(&planes)
            .map_err(|m| Error::Api(format!("clip group `{name}`: {m}")))?;
        self.can_build(&format!("clip group `{name}`"))?;
        let value = Spanned {
            value: planes,
            at: origin("<clip_planes>"),
        };
        match self.desc.clip_groups.iter_mut().find(|(n, _)| n == name) {
            Some((_, g)) => *g = value,
            None => self.desc.clip_groups.push((name.to_string(), value)),
        }
        self.dirty.build = true;
        self.clip_group(name)
            .ok_or_else(|| Error::Api(format!("clip group `{name}` was not defined")))
    }

    /// [`Scene::set_clip_group`] from RON text, the list a scene file's `clip_groups` map
    /// holds after the name: `[(point: (0, 0, 0), normal: (0, 1, 0))]`; errors point into the
    /// text as `<clip_planes>:line:col`.
    pub fn set_clip_group_ron(&mut self, name: &str, text: &str) -> Result<ClipId, Error> {
        let planes = fragment::clip_planes(text)?;
        self.set_clip_group(name, planes)
    }

    /// The clip group named `name`, if the scene has it.
    pub fn clip_group(&self, name: &str) -> Option<ClipId> {
        let index = self.desc.clip_groups.iter().position(|(n, _)| n == name)?;
        Some(ClipId {
            scene: self.serial,
            index: index as u32,
        })
    }

    fn clip_name(&self, id: ClipId) -> Result<String, Error> {
        if id.scene != self.serial {
            return Err(Error::Api(
                "this clip group id belongs to another scene".into(),
            ));
        }
        match self.desc.clip_groups.get(id.index as usize) {
            Some((n, _)) => Ok(n.clone()),
            None => Err(Error::Api(format!(
                "clip group {} is not in this scene",
                id.index
            ))),
        }
    }

    /// Fog (checked by the scene files' rules); `None`: none.
    pub fn set_fog(&mut self, fog: Option<FogDesc>) -> Result<(), Error> {
        if let Some(f) = &fog {
            fragment::check_fog(f).map_err(|m| Error::Api(format!("fog: {m}")))?;
        }
        self.desc.fog = fog;
        self.dirty.effects = true;
        Ok(())
    }

    /// Fog from RON text, e.g. `(mode: Exp(density: 0.1), color: (0.5, 0.5, 0.5))`; errors
    /// point into the text as `<fog>:line:col`.
    pub fn set_fog_ron(&mut self, text: &str) -> Result<(), Error> {
        let fog = fragment::fog(text)?;
        self.set_fog(Some(fog))
    }

    /// Ambient occlusion (checked by the scene files' rules); `None`: none.
    pub fn set_ambient_occlusion(&mut self, ao: Option<AoDesc>) -> Result<(), Error> {
        if let Some(a) = &ao {
            fragment::check_ambient_occlusion(a)
                .map_err(|m| Error::Api(format!("ambient occlusion: {m}")))?;
        }
        self.desc.ambient_occlusion = ao;
        self.dirty.effects = true;
        Ok(())
    }

    /// Ambient occlusion from RON text, e.g. `(samples: 16, distance: 2)`; errors point
    /// into the text as `<ambient_occlusion>:line:col`.
    pub fn set_ambient_occlusion_ron(&mut self, text: &str) -> Result<(), Error> {
        let ao = fragment::ambient_occlusion(text)?;
        self.set_ambient_occlusion(Some(ao))
    }

    /// The scene's objects, in its order (a loaded scene's: file order; imported geometry,
    /// which has no ids, comes after them).
    pub fn objects(&self) -> Vec<ObjectId> {
        self.objects.ids()
    }

    /// Adds an object made by the primitive plugin `plugin` from its parameters (RON text, as
    /// after `params:` in a scene file), of `material` (`None`: the default) and cut by `clip`.
    /// The plugin reads the parameters at the next commit: its errors point into them as
    /// `<object N>:line:col` (N: the id's number), and the object stays until removed. Every
    /// commit after objects were added or removed builds the scene again, once: plugin
    /// objects are for what does not change every step.
    pub fn add_plugin_object(
        &mut self,
        plugin: &str,
        params_ron: &str,
        material: Option<MaterialId>,
        clip: Option<ClipId>,
    ) -> Result<ObjectId, Error> {
        self.objects_can_change()?;
        self.registry
            .get(plugin, PluginKind::Primitive)
            .map_err(|e| Error::Api(e.to_string()))?;
        let material = material.map(|m| self.material_name(m)).transpose()?;
        let clip = clip.map(|c| self.clip_name(c)).transpose()?;
        let id = self.objects.insert();
        let at = origin(&format!("<{id}>"));
        let named = |value: String| Spanned {
            value,
            at: at.clone(),
        };
        let object = ObjectDesc {
            call: PluginCall {
                plugin: named(plugin.to_string()),
                params: params_ron.to_string(),
                params_at: at.clone(),
            },
            material: material.map(named),
            clip: clip.map(named),
            shadows: true,
        };
        self.desc.objects.push(Spanned { value: object, at });
        self.parts.push(Part::Plugin);
        self.dirty.build = true;
        Ok(id)
    }

    /// Removes an object; its id is refused from now on. The next commit builds the scene
    /// again. An animated scene's objects cannot be removed (its animation refers to them by
    /// their place).
    pub fn remove(&mut self, id: ObjectId) -> Result<(), Error> {
        let i = self.objects.position(id)?;
        match self.parts[i] {
            Part::Plugin => {
                self.objects_can_change()?;
                self.not_animated("objects")?;
            }
            Part::PluginVolume => self.objects_can_change()?,
            Part::Array(_) | Part::Volume(_) => {
                // Dropped from the built scene at the next commit, no build.
                self.objects.remove(id)?;
                self.parts.remove(i);
                return Ok(());
            }
        }
        let i = self.objects.remove(id)?;
        let part = self.parts.remove(i);
        let before = |kind: fn(&Part) -> bool| self.parts[..i].iter().filter(|p| kind(p)).count();
        match part {
            Part::PluginVolume => {
                // The scene's own volumes come first, then those added, in the parts' order.
                let added = self.parts.iter().filter(|p| p.plugin_volume()).count() + 1;
                let first = self.desc.volumes.len() - added;
                self.desc
                    .volumes
                    .remove(first + before(Part::plugin_volume));
            }
            _ => {
                let k = before(|p| matches!(p, Part::Plugin));
                self.desc.objects.remove(k);
            }
        }
        self.dirty.build = true;
        Ok(())
    }

    /// Adds a volume read by the volume reader plugin `plugin` (`raw`, `vdb`... as a scene
    /// file's `volumes` name them) from its parameters (RON text, as after `params:`), called
    /// `name` (`None`: by its place among the volumes, as a scene file's unnamed ones) and drawn
    /// as `look` says (`None`: data only, not drawn). The plugin reads the file at the next
    /// commit: its errors point into the parameters as `<object N>:line:col` (N: the id's
    /// number). Adding or removing one builds the scene again at the next commit.
    pub fn add_plugin_volume(
        &mut self,
        plugin: &str,
        params_ron: &str,
        name: Option<&str>,
        look: Option<VolumeRenderDesc>,
    ) -> Result<ObjectId, Error> {
        self.objects_can_change()?;
        self.registry
            .get(plugin, PluginKind::VolumeReader)
            .map_err(|e| Error::Api(e.to_string()))?;
        if let Some(n) = name {
            if n.trim().is_empty() {
                return Err(Error::Api(
                    "the volume name is empty; expected a name such as \"head\" (or None)".into(),
                ));
            }
            let taken = (self.desc.volumes.iter())
                .any(|v| v.value.name.as_ref().is_some_and(|t| t.value == n));
            if taken {
                return Err(Error::Api(format!(
                    "the scene has a volume named `{n}` already"
                )));
            }
        }
        if let Some(l) = &look {
            fragment::check_volume_render(l)
                .map_err(|m| Error::Api(format!("volume render settings: {m}")))?;
            if let Some(c) = &l.clip {
                if self.clip_group(&c.value).is_none() {
                    return Err(Error::Api(format!("no clip group named `{}`", c.value)));
                }
            }
        }
        let id = self.objects.insert();
        let at = origin(&format!("<{id}>"));
        let named = |value: String| Spanned {
            value,
            at: at.clone(),
        };
        let entry = VolumeDescEntry {
            call: PluginCall {
                plugin: named(plugin.to_string()),
                params: params_ron.to_string(),
                params_at: at.clone(),
            },
            name: name.map(|n| named(n.to_string())),
            render: look.map(|l| Spanned {
                value: l,
                at: at.clone(),
            }),
        };
        self.desc.volumes.push(Spanned { value: entry, at });
        self.parts.push(Part::PluginVolume);
        self.dirty.build = true;
        Ok(id)
    }

    /// [`Scene::add_plugin_volume`] drawn as RON text says (what follows `render:` in a scene
    /// file's volume, see [`Scene::add_volume_ron`]).
    pub fn add_plugin_volume_ron(
        &mut self,
        plugin: &str,
        params_ron: &str,
        name: Option<&str>,
        look_ron: &str,
    ) -> Result<ObjectId, Error> {
        let look = fragment::volume_render(look_ron)?;
        self.add_plugin_volume(plugin, params_ron, name, Some(look))
    }

    /// Adds spheres read from arrays (in place, or Luxon's copy: see [`crate::arrays`]). The
    /// element types are checked now; the values at every commit that reads them (a NaN
    /// centre or a radius ≤ 0 is refused, naming the object and the sphere). A commit after
    /// their content changed refits the object's BVH; after their count changed, or
    /// [`Scene::set_spheres`] gave other arrays, it builds it again.
    pub fn add_spheres(&mut self, s: Spheres) -> Result<ObjectId, Error> {
        let parts = self.spheres_parts(s)?;
        self.add_array(parts)
    }

    /// Gives array object `id` (added by [`Scene::add_spheres`]) new spheres: its BVH is
    /// built again at the next commit.
    pub fn set_spheres(&mut self, id: ObjectId, s: Spheres) -> Result<(), Error> {
        let parts = self.spheres_parts(s)?;
        self.set_array(id, parts)
    }

    /// Adds a triangle mesh read from arrays (in place, or Luxon's copy: see
    /// [`crate::arrays`]). The element types are checked now; the values at every commit that
    /// reads them (an index past the vertices, a non-finite coordinate, are refused naming the
    /// object, the triangle and the vertex). A commit after the vertices' content changed
    /// refits the object's BVH; after the indices changed (content or count), or the vertex
    /// count, or [`Scene::set_mesh`] gave other arrays, it builds it again.
    pub fn add_mesh(&mut self, m: Mesh) -> Result<ObjectId, Error> {
        let parts = self.mesh_parts(m)?;
        self.add_array(parts)
    }

    /// Gives array object `id` (added by [`Scene::add_mesh`]) a new mesh: its BVH is built
    /// again at the next commit.
    pub fn set_mesh(&mut self, id: ObjectId, m: Mesh) -> Result<(), Error> {
        let parts = self.mesh_parts(m)?;
        self.set_array(id, parts)
    }

    /// Adds cylinders read from arrays (in place, or Luxon's copy: see [`crate::arrays`]),
    /// capped as [`Cylinders::caps`] says. The element types are checked now; the values at
    /// every commit that reads them (a NaN coordinate, a radius ≤ 0 or a base at its apex are
    /// refused, naming the object and the cylinder). A commit after their content changed
    /// refits the object's BVHs; after their count changed, or [`Scene::set_cylinders`] gave
    /// other arrays, it builds them again.
    pub fn add_cylinders(&mut self, c: Cylinders) -> Result<ObjectId, Error> {
        let parts = self.cylinders_parts(c)?;
        self.add_array(parts)
    }

    /// Gives array object `id` (added by [`Scene::add_cylinders`]) new cylinders: its BVHs
    /// are built again at the next commit.
    pub fn set_cylinders(&mut self, id: ObjectId, c: Cylinders) -> Result<(), Error> {
        let parts = self.cylinders_parts(c)?;
        self.set_array(id, parts)
    }

    fn cylinders_parts(&self, c: Cylinders) -> Result<ArrayParts, Error> {
        expect_elem("cylinders' bases", &c.bases, VEC3)?;
        expect_elem("cylinders' apexes", &c.apexes, VEC3)?;
        let mut arrays = vec![c.bases, c.apexes];
        let radius = radius_read("cylinders'", c.radius, &mut arrays)?;
        let reader = CylinderReader {
            radius,
            offset: Default::default(),
        };
        let material = self.material_index(c.material)?;
        Ok((
            arrays,
            Spec::Cylinders {
                reader,
                caps: c.caps,
            },
            material,
        ))
    }

    fn add_array(&mut self, (arrays, spec, material): ArrayParts) -> Result<ObjectId, Error> {
        if self.parts.iter().filter_map(Part::array).count() >= MAX_OBJECTS {
            return Err(Error::Api(format!(
                "a scene holds at most {MAX_OBJECTS} array objects"
            )));
        }
        let id = self.objects.insert();
        self.parts.push(Part::Array(ArrayObject {
            key: array_key(),
            label: format!("{id} ({})", spec.kind()),
            arrays,
            spec,
            material,
        }));
        Ok(id)
    }

    fn set_array(
        &mut self,
        id: ObjectId,
        (arrays, spec, material): ArrayParts,
    ) -> Result<(), Error> {
        let i = self.objects.position(id)?;
        let kind = spec.kind();
        if !matches!(&self.parts[i], Part::Array(a) if a.spec.kind() == kind) {
            return Err(Error::Api(format!("{id} is not an array object of {kind}")));
        }
        self.parts[i] = Part::Array(ArrayObject {
            key: array_key(),
            label: format!("{id} ({kind})"),
            arrays,
            spec,
            material,
        });
        Ok(())
    }

    /// Adds a volume read from an array, drawn as `look` says (`None`: data only, not drawn),
    /// the settings a scene file gives a volume after `render:`. The grid's layout and element
    /// type are checked now; its values are copied into bricks at the next commit (a NaN or
    /// infinite voxel is refused then, naming it), and again at every commit after they were
    /// marked modified ([`crate::arrays::Array::mark_modified`], or a
    /// [`crate::arrays::SharedVec`] write): [`CommitReport::volumes_read`] counts these reads.
    /// Between commits the array may be written freely (a volume is never read in place). No
    /// BVH is built for it.
    pub fn add_volume(
        &mut self,
        grid: VolumeGrid,
        look: Option<VolumeRenderDesc>,
    ) -> Result<ObjectId, Error> {
        let v = self.volume_object(grid, look)?;
        let id = self.objects.insert();
        self.parts.push(Part::Volume(Box::new(VolumeObject {
            label: format!("{id} (volume)"),
            name: v.name.unwrap_or_else(|| id.to_string()),
            ..v.object
        })));
        Ok(id)
    }

    /// [`Scene::add_volume`] drawn as RON text says, e.g. `(transfer: (preset: "viridis"),
    /// step: 0.05)` (what follows `render:` in a scene file's volume); errors point into the
    /// text as `<volume_render>:line:col`.
    pub fn add_volume_ron(&mut self, grid: VolumeGrid, look_ron: &str) -> Result<ObjectId, Error> {
        let look = fragment::volume_render(look_ron)?;
        self.add_volume(grid, Some(look))
    }

    /// Gives volume `id` (added by [`Scene::add_volume`]) a new grid and look: read again at
    /// the next commit.
    pub fn set_volume(
        &mut self,
        id: ObjectId,
        grid: VolumeGrid,
        look: Option<VolumeRenderDesc>,
    ) -> Result<(), Error> {
        let i = self.objects.position(id)?;
        if !matches!(self.parts[i], Part::Volume(_)) {
            return Err(Error::Api(format!("{id} is not a volume")));
        }
        let v = self.volume_object(grid, look)?;
        self.parts[i] = Part::Volume(Box::new(VolumeObject {
            label: format!("{id} (volume)"),
            name: v.name.unwrap_or_else(|| id.to_string()),
            ..v.object
        }));
        Ok(())
    }

    /// [`Scene::set_volume`] with its look as RON text (see [`Scene::add_volume_ron`]).
    pub fn set_volume_ron(
        &mut self,
        id: ObjectId,
        grid: VolumeGrid,
        look_ron: &str,
    ) -> Result<(), Error> {
        self.objects.position(id)?;
        let look = fragment::volume_render(look_ron)?;
        self.set_volume(id, grid, Some(look))
    }

    /// A volume object (its label to be set) and its grid's name if it has one.
    fn volume_object(
        &self,
        grid: VolumeGrid,
        look: Option<VolumeRenderDesc>,
    ) -> Result<Named, Error> {
        let name = (!grid.name.is_empty()).then(|| grid.name.clone());
        let called = name.as_deref().unwrap_or("(unnamed)");
        volumes::check(&grid, &format!("volume grid `{called}`"))?;
        if let Some(l) = &look {
            fragment::check_volume_render(l)
                .map_err(|m| Error::Api(format!("volume `{called}`'s render settings: {m}")))?;
            if let Some(c) = &l.clip {
                if !self.desc.clip_groups.iter().any(|(n, _)| *n == c.value) {
                    return Err(Error::Api(format!("no clip group named `{}`", c.value)));
                }
            }
        }
        let object = VolumeObject {
            key: array_key(),
            label: String::new(),
            name: String::new(),
            grid,
            look,
        };
        Ok(Named { object, name })
    }

    fn material_index(&self, m: Option<MaterialId>) -> Result<u32, Error> {
        match m {
            Some(m) => {
                self.material_name(m)?;
                Ok(m.index)
            }
            None => Ok(0),
        }
    }

    fn mesh_parts(&self, m: Mesh) -> Result<ArrayParts, Error> {
        expect_elem("mesh positions", &m.positions, VEC3)?;
        let mut arrays = vec![m.positions];
        let mut slot = |what: &str, a: Option<Array>, allowed| -> Result<Option<usize>, Error> {
            let Some(a) = a else { return Ok(None) };
            expect_elem(what, &a, allowed)?;
            arrays.push(a);
            Ok(Some(arrays.len() - 1))
        };
        let reader = MeshReader {
            indices: slot("mesh indices", m.indices, INDEX3)?,
            normals: slot("mesh normals", m.normals, VEC3)?,
            colors: slot("mesh colours", m.colors, VEC3)?,
            uvs: slot("mesh uvs", m.uvs, UV)?,
            offset: Default::default(),
        };
        let material = self.material_index(m.material)?;
        Ok((arrays, Spec::Mesh(reader), material))
    }

    fn spheres_parts(&self, s: Spheres) -> Result<ArrayParts, Error> {
        expect_elem("spheres' centres", &s.centers, VEC3)?;
        let mut arrays = vec![s.centers];
        let radius = radius_read("spheres'", s.radius, &mut arrays)?;
        let colors = match s.colors {
            Some(a) => {
                expect_elem("spheres' colours", &a, VEC3)?;
                arrays.push(a);
                Some(arrays.len() - 1)
            }
            None => None,
        };
        let material = self.material_index(s.material)?;
        let reader = SphereReader {
            radius,
            colors,
            offset: Default::default(),
        };
        Ok((arrays, Spec::Spheres(reader), material))
    }

    fn objects_can_change(&self) -> Result<(), Error> {
        match self.consumed {
            Some(why) => Err(Error::Api(format!("objects cannot change: {why}"))),
            None => Ok(()),
        }
    }

    /// The description as a RON scene (what `luxon convert` writes), for a bug report or to
    /// render it with the command line: paths relative to the scene file's directory when it
    /// has one. A frozen scene's imported geometry is not in it once consumed. A scene with
    /// array objects or volumes from arrays is refused (their data live in the caller's
    /// arrays, which a scene file cannot refer to): remove them first.
    pub fn to_ron(&self) -> Result<String, Error> {
        let ids = self.objects.ids();
        let from_arrays = self.parts.iter().zip(&ids).find_map(|(p, id)| match p {
            Part::Plugin | Part::PluginVolume => None,
            Part::Array(a) => Some(a.label.clone()),
            Part::Volume(_) => Some(format!("{id} (volume)")),
        });
        if let Some(label) = from_arrays {
            return Err(Error::Api(format!(
                "{label} is read from arrays and cannot be written as RON (a scene file refers \
                 to no caller's memory); remove the objects made from arrays to write the rest"
            )));
        }
        let base = self.desc.source.parent().unwrap_or(Path::new("."));
        luxon_formats::print::scene(&self.desc, base).map_err(Error::Api)
    }

    /// The image size of the next commit (a render sets it to its target's).
    pub(super) fn set_size(&mut self, width: u32, height: u32) {
        self.size = (width, height);
    }

    /// Brings the built scene up to date with the description, on `on`'s pool: a build when
    /// there is none yet or it is out of date (objects, origin, the settings a build reads),
    /// else only what changed among the settings, camera, background, lights, materials, fog
    /// and ambient occlusion. A scene without a camera ([`Scene::new`]) is refused.
    ///
    /// Array objects are read (their arrays pinned: writers wait) during the commit only, and
    /// their BVHs refitted or built again as [`CommitReport`] tells; volumes from arrays are
    /// read when new or changed.
    pub fn commit(&mut self, on: &Renderer) -> Result<CommitReport, Error> {
        let report = self.commit_pinned(on);
        self.unpin();
        report
    }

    /// [`Scene::commit`], leaving the array objects' arrays pinned for a render: call
    /// [`Scene::unpin`] after it.
    pub(super) fn commit_pinned(&mut self, on: &Renderer) -> Result<CommitReport, Error> {
        let t0 = Instant::now();
        // Pinned on this thread first: one that is writing an array is refused here (on the
        // pool's threads its pin would wait for itself), and no write starts meanwhile.
        let held = self
            .parts
            .iter()
            .filter_map(Part::array)
            .map(|a| Pins::new(&a.arrays))
            .collect::<Result<Vec<Pins>, Error>>()?;
        // Volumes are read during the commit only: their pins go with it.
        let grids = self
            .parts
            .iter()
            .filter_map(Part::volume)
            .map(|v| Pins::new(std::slice::from_ref(&v.grid.values)))
            .collect::<Result<Vec<Pins>, Error>>()?;
        let report = on.pool.install(|| self.commit_here(&grids));
        drop(grids);
        drop(held);
        let mut report = report?;
        report.commit_time = t0.elapsed();
        Ok(report)
    }

    /// Releases the array objects' arrays (after a render): the caller may write them.
    pub(super) fn unpin(&mut self) {
        if let Some(b) = self.built.as_mut() {
            b.objects.unpin();
        }
    }

    /// Brings the built array objects up to date with their descriptions (in the built
    /// scene's render space): kept, refitted or built again, as `report` then says.
    fn commit_arrays(
        parts: &[Part],
        previous: Vec<Object>,
        built: &mut Built,
        render: &RenderDesc,
        report: &mut CommitReport,
    ) -> Result<(), Error> {
        if previous.is_empty() && parts.iter().all(|p| p.array().is_none()) {
            return Ok(());
        }
        let t0 = Instant::now();
        let offset = built.world_offset;
        let budget = built.budget.clone();
        let mut previous: HashMap<u64, Object> = previous.into_iter().map(|o| (o.key, o)).collect();
        let mut list = Vec::new();
        for a in parts.iter().filter_map(Part::array) {
            let (object, outcome) = match previous.remove(&a.key) {
                Some(o) => o.update(offset, &budget)?,
                None => {
                    let (arrays, spec) = (a.arrays.clone(), a.spec);
                    let label = a.label.clone();
                    let o = Object::build(a.key, label, arrays, spec, a.material, offset, &budget)?;
                    (o, Outcome::Built)
                }
            };
            match outcome {
                Outcome::Kept => {}
                Outcome::Built => report.rebuilt += 1,
                Outcome::Refitted(r) => {
                    report.refitted += 1;
                    report.worst_ratio = report.worst_ratio.max(r);
                }
                Outcome::Degraded(r) => {
                    report.rebuilt += 1;
                    report.degraded += 1;
                    report.worst_ratio = report.worst_ratio.max(r);
                }
            }
            list.push(object);
        }
        // Objects removed since are dropped here (their arrays released).
        drop(previous);
        report.bvh_time += t0.elapsed();
        built.set_objects(Objects::new(list), render);
        Ok(())
    }

    /// Puts the volumes read from arrays into the built scene (which holds none of them now):
    /// each read from `grids` (its pinned values, in the order of the volumes in `parts`)
    /// unless `previous` has it read at the same generation. Their bricks are charged to the
    /// built scene's memory budget (a volume that does not fit is refused). Returns their keys
    /// and generations, and their charges, in order.
    fn commit_volumes(
        parts: &[Part],
        grids: &[Pins],
        mut previous: ReadVolumes,
        desc: &SceneDesc,
        built: &mut Built,
        report: &mut CommitReport,
    ) -> Result<PutVolumes, Error> {
        let mut list = Vec::new();
        let mut keys = Vec::new();
        let mut charges = Vec::new();
        let budget = built.budget.clone();
        for (v, pins) in parts.iter().filter_map(Part::volume).zip(grids) {
            let key = (v.key, pins.generation(0));
            let (volume, charge) = match previous.remove(&key) {
                Some((volume, charge)) => {
                    let name = &v.name;
                    let charge = charge.move_to(&budget, || format!("volume `{name}`"))?;
                    (volume, charge)
                }
                None => {
                    report.volumes_read += 1;
                    let named = |e| match e {
                        Error::Api(m) => Error::Api(format!("{}: {m}", v.label)),
                        e => e,
                    };
                    volumes::read(&v.grid, &v.name, pins.view(0), &budget).map_err(named)?
                }
            };
            charges.push(charge);
            let clip = match v.look.as_ref().and_then(|l| l.clip.as_ref()) {
                Some(c) => {
                    let i = desc.clip_groups.iter().position(|(n, _)| *n == c.value);
                    i.map(|i| i as u32 + 1).ok_or_else(|| {
                        Error::Api(format!("{}: no clip group named `{}`", v.label, c.value))
                    })?
                }
                None => 0,
            };
            list.push(ArrayVolume {
                volume,
                look: v.look.as_ref(),
                clip,
                label: &v.label,
            });
            keys.push(key);
        }
        // Volumes removed since are dropped here.
        drop(previous);
        built.set_array_volumes(list, &desc.render)?;
        Ok((keys, charges))
    }

    fn commit_here(&mut self, grids: &[Pins]) -> Result<CommitReport, Error> {
        if !self.has_camera {
            return Err(Error::Api(
                "this scene has no camera; give it one with Scene::set_camera before \
                 rendering"
                    .into(),
            ));
        }
        let mut report = CommitReport::default();
        let d = &mut self.dirty;
        if self.desc.animation.is_some() && (d.lights || d.materials) {
            // The animation holds the lights and materials it keys: built again with them.
            d.build = true;
        }
        if let (Some(built), false, true) = (self.built.as_mut(), d.build, d.materials) {
            match built.update_materials(&self.desc, &self.shadowless)? {
                true => report.shading = true,
                false => d.build = true,
            }
            d.materials = false;
        }
        // The array objects outlive a build of the rest (their trees are kept).
        let previous = match self.built.as_mut() {
            Some(b) => b.objects.take(),
            None => Vec::new(),
        };
        // So do the volumes read from arrays, taken out when they or the build change.
        let generations: Vec<(u64, u64)> = (self.parts.iter().filter_map(Part::volume))
            .zip(grids)
            .map(|(v, p)| (v.key, p.generation(0)))
            .collect();
        let building = self.built.is_none() || self.dirty.build;
        let volumes_change = building || generations != self.volumes_built;
        let mut previous_volumes = HashMap::new();
        if let (true, Some(b)) = (volumes_change, self.built.as_mut()) {
            let keys = std::mem::take(&mut self.volumes_built);
            let charges = std::mem::take(&mut self.volume_charges);
            let volumes = b.take_array_volumes().into_iter().zip(charges);
            previous_volumes = keys.into_iter().zip(volumes).collect();
        }
        if self.built.is_none() || self.dirty.build {
            if let Some(why) = self.consumed {
                return Err(Error::Api(why.into()));
            }
            // The old build goes first: two are never held at once.
            self.built = None;
            let budget = self
                .budget
                .take()
                .unwrap_or_else(|| Arc::new(Budget::for_render(&self.desc.render, None, 1)));
            let prebuilt = self.prebuilt.take();
            if prebuilt.is_some() {
                self.consumed = Some(PREBUILT);
            } else if self.frozen && !self.desc.inline.is_empty() {
                self.consumed = Some(FROZEN);
            }
            let built = Built::build_retained(
                &mut self.desc,
                self.frozen,
                prebuilt,
                self.origin,
                &self.registry,
                budget,
            )?;
            self.origin = Some(built.world_offset);
            report.rebuilt = 1;
            report.bvh_time = built.bvh_time;
            self.built = Some(built);
            self.dirty = Dirty::default();
            // A new build starts at the first frame: back to the frame it was at.
            self.frame = self.frame.or(self.at_frame);
        }
        let Some(built) = self.built.as_mut() else {
            return Err(Error::Api("the scene is not built".into()));
        };
        Scene::commit_arrays(&self.parts, previous, built, &self.desc.render, &mut report)?;
        if volumes_change {
            (self.volumes_built, self.volume_charges) = Scene::commit_volumes(
                &self.parts,
                grids,
                previous_volumes,
                &self.desc,
                built,
                &mut report,
            )?;
        }
        if self.dirty.lights {
            built.update_lights(&self.desc);
            self.dirty.lights = false;
            report.shading = true;
        }
        if self.dirty.effects {
            built.update_effects(&self.desc);
            self.dirty.effects = false;
            report.shading = true;
        }
        let (w, h) = self.size;
        built.update_view(&self.desc, w, h)?;
        if let Some(k) = self.frame.take() {
            built.set_frame(k)?;
            self.at_frame = Some(k);
        }
        Ok(report)
    }

    /// The built scene, for a render right after a commit.
    pub(super) fn committed(&self) -> Result<&Built, Error> {
        self.built
            .as_ref()
            .ok_or_else(|| Error::Api("the scene is not built".into()))
    }

    /// After a render failed: a raised fault (a plugin's or Luxon's panic) makes the built
    /// scene unusable, so it is dropped and the next commit builds it again.
    pub(super) fn after_failure(&mut self) {
        if self
            .built
            .as_ref()
            .is_some_and(|b| b.customs.fault.is_raised())
        {
            self.built = None;
            self.dirty.build = true;
        }
    }
}
