//! Building a [`Scene`] from its description, in the stages [`Scene::build_from`] runs in order:
//! textures, volumes, materials, clip groups, render volumes, objects (plugins, then imported
//! geometry, then baked instances, then a cache's prebuilt geometry), BVHs, lights, and the
//! effects the scene calls for; an animated scene then goes to its first frame (keyed objects
//! and instances are recorded, not stored, see `frame`). A new kind of scene content gets a
//! stage of its own here.

use super::frame::{self, Animation, Keyed};
use super::instances::{self, PrototypeUse};
use super::place::Sets;
use super::series::SeriesSet;
use super::{
    AngleRule, Ao, Casters, Fade, Features, Few, Fog, Light, Material, Scene, Settings, Sky,
};
use crate::budget::{Budget, Use};
use crate::bvh::BUILD_BYTES_PER_PRIM;
use crate::camera::Camera;
use crate::error::Error;
use crate::geometry::cone::Cones;
use crate::geometry::custom::Customs;
use crate::geometry::disc::Discs;
use crate::geometry::instance::Instances;
use crate::geometry::plane::Planes;
use crate::geometry::sphere::Spheres;
use crate::geometry::triangle::{MeshInput, Triangles};
use crate::geometry::{pack, Clips, MAX_CLIP_GROUPS, MAX_MATERIALS};
use crate::math::{DVec3, Vec3A};
use crate::plugin::primitive::{create_primitive, GeometryBuilder, Recorded};
use crate::plugin::texture::{create_texture, TextureInstance};
use crate::plugin::{read_volume, PluginKind, Registry};
use crate::volume::Volume;
use crate::volume_render::{RenderVolume, MAX_RENDERED_VOLUMES};
use luxon_formats::{
    AoDesc, BackgroundDesc, FogDesc, HighlightColor, InlineGeometry, LightDesc, ObjectTracks,
    RenderDesc, SceneDesc, Spanned, SpotFade, TransparencyAngle, TransparencyDesc,
    TransparencyMode, TransparentShadows,
};
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// A scene's native geometry with its BVHs built, as a geometry cache gives it back
/// ([`crate::cache`]).
pub struct Prebuilt {
    pub world_offset: DVec3,
    /// Per material of the scene (index 0: the default): whether any primitive uses it.
    pub used: Vec<bool>,
    pub degenerate: u64,
    pub spheres: Spheres,
    pub triangles: Triangles,
    pub cones: Cones,
}

/// Imported geometry groups, handed over one at a time.
type Inline<'g> = Box<dyn Iterator<Item = Cow<'g, InlineGeometry>> + 'g>;

impl Scene {
    /// Resolves plugins, instantiates every object and builds the BVHs, within the scene's
    /// memory budget (its `render: (memory: ...)`, else the machine's default).
    pub fn build(desc: &SceneDesc, registry: &Registry) -> Result<Scene, Error> {
        let budget = Budget::for_render(&desc.render, None, 1);
        Scene::build_with(desc, registry, Arc::new(budget))
    }

    /// `build` within `budget`.
    pub fn build_with(
        desc: &SceneDesc,
        registry: &Registry,
        budget: Arc<Budget>,
    ) -> Result<Scene, Error> {
        let groups = desc.inline.iter().map(Cow::Borrowed);
        let shadowless = shadowless_groups(desc);
        Scene::build_from(desc, Box::new(groups), shadowless, None, registry, budget)
    }

    /// Builds with the native geometry and BVHs of a geometry cache (`desc` holds the rest of
    /// the scene and no inline geometry).
    pub fn build_prebuilt(
        desc: &SceneDesc,
        geometry: Prebuilt,
        registry: &Registry,
        budget: Arc<Budget>,
    ) -> Result<Scene, Error> {
        let none = Box::new(std::iter::empty());
        Scene::build_from(desc, none, Vec::new(), Some(geometry), registry, budget)
    }

    /// Like `build_with`, but takes the imported geometry (`desc.inline`) out of `desc` and
    /// frees each group once it is stored, so a large import is not held twice while the BVHs
    /// are built and the image rendered.
    pub fn build_taking_geometry(
        desc: &mut SceneDesc,
        registry: &Registry,
        budget: Arc<Budget>,
    ) -> Result<Scene, Error> {
        // Which groups cast no shadow is needed before they are taken: their materials get a
        // shadowless copy in the palette.
        let shadowless = shadowless_groups(desc);
        let groups = std::mem::take(&mut desc.inline).into_iter().map(Cow::Owned);
        Scene::build_from(desc, Box::new(groups), shadowless, None, registry, budget)
    }

    /// One full build of a retained scene ([`crate::api::Scene`]): `build_with`, or
    /// `build_taking_geometry` when `take_geometry`, or `build_prebuilt` when `prebuilt` is
    /// given; render space's origin at `origin` when given (else the camera, as always).
    pub(crate) fn build_retained(
        desc: &mut SceneDesc,
        take_geometry: bool,
        prebuilt: Option<Prebuilt>,
        origin: Option<DVec3>,
        registry: &Registry,
        budget: Arc<Budget>,
    ) -> Result<Scene, Error> {
        let shadowless = shadowless_groups(desc);
        let taken = match take_geometry {
            true => std::mem::take(&mut desc.inline),
            false => Vec::new(),
        };
        let desc = &*desc;
        let inline: Inline = match take_geometry {
            true => Box::new(taken.into_iter().map(Cow::Owned)),
            false => Box::new(desc.inline.iter().map(Cow::Borrowed)),
        };
        let b = Build::at(desc, registry, budget, origin);
        Scene::build_stages(b, desc, inline, shadowless, prebuilt)
    }

    /// The build, stage after stage (errors are reported in this order too).
    fn build_from(
        desc: &SceneDesc,
        inline: Inline,
        shadowless: Vec<Option<Spanned<String>>>,
        prebuilt: Option<Prebuilt>,
        registry: &Registry,
        budget: Arc<Budget>,
    ) -> Result<Scene, Error> {
        let b = Build::new(desc, registry, budget);
        Scene::build_stages(b, desc, inline, shadowless, prebuilt)
    }

    /// The stages of `build_from`, with render space's origin already chosen (`b.world_offset`).
    fn build_stages(
        b: Build,
        desc: &SceneDesc,
        inline: Inline,
        shadowless: Vec<Option<Spanned<String>>>,
        prebuilt: Option<Prebuilt>,
    ) -> Result<Scene, Error> {
        let t0 = Instant::now();
        let (textures, texture_names) = b.textures()?;
        let volumes = b.volumes()?;
        let palette = Build::materials(desc, &texture_names, &textures, &shadowless)?;
        let clips = b.clips()?;
        let render_volumes = b.render_volumes(&volumes)?;
        let mut stored = Stored::new(b.world_offset, palette.materials.len());
        b.objects(&palette, &mut stored)?;
        b.imported(inline, &palette, &mut stored)?;
        let prototypes = b.instances(&palette, &mut stored)?;
        let Palette {
            materials,
            names: material_names,
            shadowless: shadowless_copies,
        } = palette;
        let native_built = prebuilt.is_some();
        if let Some(p) = prebuilt {
            stored.take_prebuilt(p, b.world_offset)?;
            let held = stored.geometry_bytes();
            b.budget.reserve(Use::Geometry, held, || {
                "the geometry read from the geometry cache".into()
            })?;
        }
        let plugin_time = t0.elapsed();

        let t1 = Instant::now();
        stored.build_bvhs(!native_built, &b.budget)?;
        let bvh_time = t1.elapsed();

        let lights = b.lights();
        let (fog, ao) = Build::effects(&desc.fog, &desc.ambient_occlusion);
        // Series data arrive frame by frame: their materials count as used from the start.
        let series = SeriesSet::new(desc, &mut |name| {
            let m = material_index(&material_names, name)?;
            stored.used[m] = true;
            Ok(m)
        })?;
        let has_geometry = stored.has_geometry() || !series.is_empty();
        let features = features(
            &desc.render,
            &materials,
            &stored.used,
            has_geometry,
            &lights,
            &fog,
            &ao,
            &render_volumes,
        );
        let r = &desc.render;
        // The eye sits at render space's origin unless a retained scene fixed it elsewhere.
        let eye = (DVec3::from(desc.camera.value.position) - b.world_offset).as_vec3();
        let eye = match b.origin_given {
            false => Vec3A::ZERO,
            true => Vec3A::from(eye),
        };
        let camera = Camera::new(&desc.camera.value, eye, r.width, r.height);
        let keyed = std::mem::take(&mut stored.keyed);
        let shared = std::mem::take(&mut stored.shared);
        let mut scene = Scene {
            source: desc.source.clone(),
            camera: camera.clone(),
            primary_width: camera.footprint().0,
            pixel_spread: camera.footprint().1,
            background: background(&desc.background),
            sky: sky(&desc.background, b.world_offset),
            lights,
            fog,
            ao,
            materials,
            material_names,
            textures,
            texture_names,
            spheres: stored.spheres,
            triangles: stored.triangles,
            planes: stored.planes,
            cones: stored.cones,
            discs: stored.discs,
            customs: stored.customs,
            clips,
            volumes,
            render_volumes,
            array_volumes: 0,
            world_offset: b.world_offset,
            settings: settings(r),
            outputs: r.outputs.clone(),
            features,
            used_materials: stored.used,
            has_geometry,
            object_counts: stored.object_counts,
            degenerate_triangles: stored.dropped,
            bvh_time,
            plugin_time,
            moving: Default::default(),
            camera_moves: false,
            instances: shared,
            objects: Default::default(),
            prototypes,
            animation: None,
            budget: b.budget,
            casters: None,
            more_kinds: true,
            few: None,
        };
        if let Some(a) = &desc.animation {
            // An animated scene starts at its first frame.
            let mut shared_keyed = std::mem::take(&mut stored.shared_keyed);
            let mut keyed = keyed;
            if frame::per_ray(desc) {
                // Motion blur: what moves is placed at each ray's time, as shared instances.
                if scene.instances.is_empty() {
                    scene.instances = Instances::new(Vec::new(), Vec::new(), b.world_offset);
                }
                shared_keyed.retain(|(i, tracks)| {
                    let moves = frame::object_moves(tracks);
                    if moves {
                        scene.instances.key(*i, tracks.clone());
                    }
                    !moves
                });
                keyed = frame::blur_objects(keyed, &mut scene.instances, &scene.budget)?;
            }
            scene.settings.shutter = frame::shutter(desc).map(|(o, c)| (o as f32, c as f32));
            scene.features.motion_blur = scene.settings.shutter.is_some();
            let animation = Animation::new(
                desc,
                &scene.material_names,
                &shadowless_copies,
                keyed,
                shared_keyed,
            )?;
            scene.animation = Some(Box::new(animation));
            if let Some(animation) = scene.animation.as_mut() {
                animation.series = series;
            }
            scene.set_frame_with(a.value.first, true)?;
        }
        scene.casters = Casters::of(&scene);
        scene.more_kinds = scene.has_more_kinds();
        scene.few = Few::of(&scene);
        Ok(scene)
    }
}

/// What every stage reads: the description, the plugins, where relative paths start, and the
/// world position of render space's origin (the camera).
pub(super) struct Build<'a> {
    desc: &'a SceneDesc,
    registry: &'a Registry,
    scene_dir: PathBuf,
    world_offset: DVec3,
    /// `world_offset` was given (a retained scene's origin), not taken from the camera.
    origin_given: bool,
    budget: Arc<Budget>,
}

/// The materials of the imported geometry groups, then of the instanced objects, that cast no
/// shadow.
pub(crate) fn shadowless_groups(desc: &SceneDesc) -> Vec<Option<Spanned<String>>> {
    let groups = desc.inline.iter().filter(|g| g.shadowless);
    let groups = groups.map(|g| g.material.clone());
    groups.chain(instances::shadowless(desc)).collect()
}

/// The materials (index 0: the default; then the scene's, by name; then copies of those that
/// objects casting no shadow use), their names, and each one's copy that casts no shadow.
pub(super) struct Palette {
    pub(super) materials: Vec<Material>,
    pub(super) names: Vec<String>,
    pub(super) shadowless: Vec<Option<usize>>,
}

impl Palette {
    /// The material an object or geometry group names, its copy when it casts no shadow.
    fn index(&self, name: &Option<Spanned<String>>, shadows: bool) -> Result<usize, Error> {
        let m = material_index(&self.names, name)?;
        Ok(if shadows {
            m
        } else {
            self.shadowless[m].unwrap_or(m)
        })
    }
}

/// The scene's geometry while it is being stored, and what storing it tells.
struct Stored {
    spheres: Spheres,
    triangles: Triangles,
    planes: Planes,
    cones: Cones,
    discs: Discs,
    customs: Customs,
    /// Per material: whether any object uses it.
    used: Vec<bool>,
    /// Objects per plugin name, in first-use order.
    object_counts: Vec<(String, usize)>,
    /// Degenerate triangles dropped.
    dropped: u64,
    /// The keyed objects' geometry, recorded to be placed at each frame.
    keyed: Vec<Keyed>,
    /// Instances sharing their prototype's one copy, and the geometry bytes charged for them.
    shared: Instances,
    /// Keyed shared instances: index in `shared.list` and tracks.
    shared_keyed: Vec<(u32, ObjectTracks)>,
    shared_bytes: u64,
}

impl<'a> Build<'a> {
    fn new(desc: &'a SceneDesc, registry: &'a Registry, budget: Arc<Budget>) -> Build<'a> {
        Build {
            desc,
            registry,
            budget,
            scene_dir: desc
                .source
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_default(),
            world_offset: frame::world_offset(desc),
            origin_given: false,
        }
    }

    /// `new` with render space's origin at `origin` when given.
    fn at(
        desc: &'a SceneDesc,
        registry: &'a Registry,
        budget: Arc<Budget>,
        origin: Option<DVec3>,
    ) -> Build<'a> {
        let mut b = Build::new(desc, registry, budget);
        if let Some(o) = origin {
            b.world_offset = o;
            b.origin_given = true;
        }
        b
    }

    /// Stage: an instance of every texture, through its plugin; and their names. A scene with
    /// textures reserves the texture cache's share of the budget (what texture plugins may keep
    /// decoded; they are told its size).
    fn textures(&self) -> Result<(Vec<TextureInstance>, Vec<String>), Error> {
        let mut texture_names = Vec::new();
        let mut textures = Vec::new();
        if let Some((name, call)) = self.desc.textures.first() {
            let cache = self.budget.texture_cache();
            self.budget
                .reserve(Use::Textures, cache, || {
                    format!("the texture cache (for texture `{name}` and the others)")
                })
                .map_err(|e| Error::at(&call.at, e.0))?;
        }
        for (name, call) in &self.desc.textures {
            let entry = self
                .registry
                .get(&call.value.plugin.value, PluginKind::Texture)
                .map_err(|e| Error::at(&call.value.plugin.at, e.to_string()))?;
            let tex = create_texture(
                self.registry,
                entry,
                &call.value.params,
                &call.value.params_at,
                &self.scene_dir,
                name,
                &self.budget,
            )
            .map_err(|(at, m)| Error::at(&at, m))?;
            texture_names.push(name.clone());
            textures.push(tex);
        }
        Ok((textures, texture_names))
    }

    /// Stage: every volume, read by its reader plugin.
    fn volumes(&self) -> Result<Vec<Volume>, Error> {
        let mut volumes = Vec::with_capacity(self.desc.volumes.len());
        for (i, v) in self.desc.volumes.iter().enumerate() {
            let call = &v.value.call;
            let entry = self
                .registry
                .get(&call.plugin.value, PluginKind::VolumeReader)
                .map_err(|e| Error::at(&call.plugin.at, e.to_string()))?;
            let name = match &v.value.name {
                Some(n) => n.value.clone(),
                None => format!("volume {i}"),
            };
            let volume = read_volume(
                self.registry,
                entry,
                &call.params,
                &call.params_at,
                &self.scene_dir,
                &name,
                &self.budget,
            )
            .map_err(|(at, m)| Error::at(&at, m))?;
            volumes.push(volume);
        }
        Ok(volumes)
    }

    /// Stage: the materials (index 0: the default, which the scene may redefine) with their
    /// textures resolved, then a copy casting no shadow of each material that objects casting
    /// none use.
    pub(super) fn materials(
        desc: &SceneDesc,
        texture_names: &[String],
        textures: &[TextureInstance],
        shadowless_groups: &[Option<Spanned<String>>],
    ) -> Result<Palette, Error> {
        let t = &desc.render.transparency;
        let mut material_names = vec!["default".to_string()];
        let mut materials = vec![material(&Default::default(), [None; 3], false, t)];
        for (name, m) in &desc.materials {
            let find = |t: &Option<Spanned<String>>| -> Result<Option<u32>, Error> {
                match t {
                    Some(t) => texture_names
                        .iter()
                        .position(|n| n == &t.value)
                        .map(|i| Some(i as u32))
                        .ok_or_else(|| Error::at(&t.at, format!("no texture named `{}`", t.value))),
                    None => Ok(None),
                }
            };
            let tex = [
                find(&m.value.texture)?,
                find(&m.value.reflect_texture)?,
                find(&m.value.transmit_texture)?,
            ];
            // Whether shading must work out uv: one of its textures declares it reads them.
            let uv = tex
                .iter()
                .flatten()
                .any(|&i| textures[i as usize].reads & luxon_plugin::abi::READS_UV != 0);
            let mat = material(&m.value, tex, uv, t);
            if let Some(i) = material_names.iter().position(|n| n == name) {
                materials[i] = mat;
            } else {
                material_names.push(name.clone());
                materials.push(mat);
            }
        }
        let mut shadowless = vec![None; materials.len()];
        let unshadowed = desc
            .objects
            .iter()
            .filter(|o| !o.value.shadows)
            .map(|o| &o.value.material);
        for name in unshadowed.chain(shadowless_groups) {
            let m = material_index(&material_names, name)?;
            if shadowless[m].is_none() {
                shadowless[m] = Some(materials.len());
                let mut copy = materials[m].clone();
                copy.shadow = Some(Vec3A::ONE);
                materials.push(copy);
            }
        }
        if materials.len() as u32 > MAX_MATERIALS {
            return Err(Error::Render(format!(
                "the scene defines {} materials; at most {MAX_MATERIALS} are supported",
                materials.len()
            )));
        }
        Ok(Palette {
            materials,
            names: material_names,
            shadowless,
        })
    }

    /// Stage: the clip groups, in render space.
    fn clips(&self) -> Result<Clips, Error> {
        let groups = &self.desc.clip_groups;
        if groups.len() as u32 >= MAX_CLIP_GROUPS {
            return Err(Error::Render(format!(
                "the scene defines {} clip groups; at most {} are supported",
                groups.len(),
                MAX_CLIP_GROUPS - 1
            )));
        }
        Ok(Clips {
            groups: groups
                .iter()
                .map(|(_, g)| {
                    g.value
                        .iter()
                        .map(|p| {
                            let q =
                                Vec3A::from((DVec3::from(p.point) - self.world_offset).as_vec3());
                            (q, Vec3A::from(DVec3::from(p.normal).normalize().as_vec3()))
                        })
                        .collect()
                })
                .collect(),
        })
    }

    /// Stage: the volumes with `render` settings, prepared for ray casting.
    fn render_volumes(&self, volumes: &[Volume]) -> Result<Vec<RenderVolume>, Error> {
        let desc = self.desc;
        let mut out = Vec::new();
        for (i, (v, volume)) in desc.volumes.iter().zip(volumes).enumerate() {
            let Some(r) = &v.value.render else {
                continue;
            };
            if out.len() == MAX_RENDERED_VOLUMES {
                return Err(Error::at(
                    &r.at,
                    format!("more than {MAX_RENDERED_VOLUMES} volumes are drawn; at most {MAX_RENDERED_VOLUMES} may have `render` settings"),
                ));
            }
            let clip = self.clip_group(&r.value.clip)?;
            let rv = RenderVolume::new(
                &r.value,
                volume,
                i,
                desc.render.volume_step,
                self.world_offset,
                clip,
            )
            .map_err(|m| Error::at(&r.at, m))?;
            out.push(rv);
        }
        Ok(out)
    }

    /// Stage: every object, created by its primitive plugin into the native sets.
    fn objects(&self, palette: &Palette, stored: &mut Stored) -> Result<(), Error> {
        for (i, obj) in self.desc.objects.iter().enumerate() {
            let call = &obj.value.call;
            let entry = self
                .registry
                .get(&call.plugin.value, PluginKind::Primitive)
                .map_err(|e| Error::at(&call.plugin.at, e.to_string()))?;
            let material = palette.index(&obj.value.material, obj.value.shadows)?;
            stored.used[material] = true;
            let clip = self.clip_group(&obj.value.clip)?;
            let keyed = self.desc.animation.as_ref().and_then(|a| {
                let objects = &a.value.objects;
                objects.iter().find(|o| o.object == i)
            });
            let mut recorded = Recorded::default();
            let mut b = GeometryBuilder {
                spheres: &mut stored.spheres,
                triangles: &mut stored.triangles,
                planes: &mut stored.planes,
                cones: &mut stored.cones,
                discs: &mut stored.discs,
                customs: &mut stored.customs,
                material: pack(material as u32, clip),
                world_offset: self.world_offset,
                plugin: entry.name.clone(),
                dropped: 0,
                record: keyed.map(|_| &mut recorded),
                budget: &self.budget,
                object: format!("object {i} (plugin `{}`, {})", entry.name, obj.at),
                instance: format!("object {i}"),
                at: obj.at.clone(),
            };
            create_primitive(
                self.registry,
                entry,
                &call.params,
                &call.params_at,
                &self.scene_dir,
                &format!("object {i}"),
                &mut b,
            )
            .map_err(|(at, m)| Error::at(&at, m))?;
            stored.dropped += b.dropped;
            if let Some(tracks) = keyed {
                stored.keyed.push(Keyed {
                    tracks: tracks.clone(),
                    geometry: recorded,
                    material: pack(material as u32, clip),
                    at: obj.at.clone(),
                });
            }
            match stored
                .object_counts
                .iter_mut()
                .find(|(n, _)| n == &entry.name)
            {
                Some((_, c)) => *c += 1,
                None => stored.object_counts.push((entry.name.clone(), 1)),
            }
        }
        Ok(())
    }

    /// Stage: imported geometry (NFF, OBJ), stored group by group.
    fn imported(
        &self,
        inline: Inline,
        palette: &Palette,
        stored: &mut Stored,
    ) -> Result<(), Error> {
        let world_offset = self.world_offset;
        for (k, g) in inline.enumerate() {
            let at = || g.at.clone().unwrap_or_else(|| self.desc.camera.at.clone());
            let material = palette.index(&g.material, !g.shadowless)?;
            stored.used[material] = true;
            let m = pack(material as u32, self.clip_group(&g.clip)?);
            let fail = |e: String| Error::at(&at(), format!("imported geometry group {k}: {e}"));
            stored.reserve_group(&g, &self.budget).map_err(fail)?;
            for (i, s) in g.spheres.iter().enumerate() {
                stored
                    .spheres
                    .push_world(i, *s, world_offset, m)
                    .map_err(fail)?;
            }
            for (i, c) in g.cones.iter().enumerate() {
                stored
                    .cones
                    .push_world(i, *c, world_offset, m)
                    .map_err(fail)?;
            }
            for (i, d) in g.discs.iter().enumerate() {
                stored
                    .discs
                    .push_world(i, *d, world_offset, m)
                    .map_err(fail)?;
            }
            for (i, p) in g.planes.iter().enumerate() {
                stored
                    .planes
                    .push_world(i, *p, world_offset, m)
                    .map_err(fail)?;
            }
            if !g.mesh.indices.is_empty() {
                let input = MeshInput {
                    positions: g.mesh.positions.as_flattened(),
                    indices: g.mesh.indices.as_flattened(),
                    normals: g.mesh.normals.as_flattened(),
                    colors: &g
                        .mesh
                        .colors
                        .iter()
                        .flat_map(|c| c.map(|x| x as f32))
                        .collect::<Vec<_>>(),
                    uvs: &g
                        .mesh
                        .uvs
                        .iter()
                        .flat_map(|u| u.map(|x| x as f32))
                        .collect::<Vec<_>>(),
                };
                stored.dropped += stored
                    .triangles
                    .push_mesh(&input, world_offset, m)
                    .map_err(fail)?;
            }
        }
        Ok(())
    }

    /// Stage: the instances of prototypes, baked after everything else (see `instances`).
    fn instances(
        &self,
        palette: &Palette,
        stored: &mut Stored,
    ) -> Result<Vec<PrototypeUse>, Error> {
        let cx = instances::Context {
            desc: self.desc,
            registry: self.registry,
            scene_dir: &self.scene_dir,
            world_offset: self.world_offset,
            budget: &self.budget,
        };
        let sets = Sets {
            spheres: &mut stored.spheres,
            triangles: &mut stored.triangles,
            planes: &mut stored.planes,
            cones: &mut stored.cones,
            discs: &mut stored.discs,
        };
        let material = |name: &Option<Spanned<String>>, shadows| palette.index(name, shadows);
        let baked = instances::bake(&cx, &material, sets, &mut stored.used)?;
        stored.dropped += baked.dropped;
        stored.keyed.extend(baked.keyed);
        stored.shared = baked.shared;
        stored.shared_keyed = baked.shared_keyed;
        stored.shared_bytes = baked.shared_bytes;
        Ok(baked.prototypes)
    }

    /// Stage: the lights, in render space.
    fn lights(&self) -> Vec<Light> {
        Build::lights_from(
            &self.desc.lights,
            self.world_offset,
            self.desc.render.light_scale,
        )
    }

    /// `lights` in render space (also each frame's, in an animated scene); every light's colour
    /// carries the render's light scale.
    pub(super) fn lights_from(
        lights: &[Spanned<LightDesc>],
        world_offset: DVec3,
        scale: f64,
    ) -> Vec<Light> {
        let rgb = |color: &[f64; 3], intensity: &f64| v3(*color) * (*intensity * scale) as f32;
        let at = |p: &[f64; 3]| Vec3A::from((DVec3::from(*p) - world_offset).as_vec3());
        let unit = |d: &[f64; 3]| Vec3A::from(DVec3::from(*d).normalize().as_vec3());
        let att = |a: &luxon_formats::Attenuation| {
            [a.constant as f32, a.linear as f32, a.quadratic as f32]
        };
        lights
            .iter()
            .map(|l| match &l.value {
                LightDesc::Point {
                    position,
                    color,
                    intensity,
                    shadows,
                    attenuation,
                } => Light::Point {
                    position: at(position),
                    color: rgb(color, intensity),
                    shadows: *shadows,
                    attenuation: att(attenuation),
                },
                LightDesc::Directional {
                    direction,
                    color,
                    intensity,
                    shadows,
                } => Light::Directional {
                    to_light: -unit(direction),
                    color: rgb(color, intensity),
                    shadows: *shadows,
                },
                LightDesc::Spot {
                    position,
                    direction,
                    cone_deg,
                    falloff_deg,
                    fade,
                    color,
                    intensity,
                    shadows,
                    attenuation,
                } => Light::Spot {
                    position: at(position),
                    axis: unit(direction),
                    cos_inner: ((cone_deg - falloff_deg) * 0.5).to_radians().cos() as f32,
                    cos_outer: (cone_deg * 0.5).to_radians().cos() as f32,
                    fade: match fade {
                        SpotFade::Smooth => Fade::Smooth,
                        SpotFade::Linear => Fade::Linear {
                            inner: ((cone_deg - falloff_deg) * 0.5).to_radians() as f32,
                            outer: (cone_deg * 0.5).to_radians() as f32,
                        },
                    },
                    color: rgb(color, intensity),
                    shadows: *shadows,
                    attenuation: att(attenuation),
                },
                LightDesc::Sphere {
                    center,
                    radius,
                    samples,
                    color,
                    intensity,
                    shadows,
                    attenuation,
                } => Light::Sphere {
                    center: at(center),
                    radius: *radius as f32,
                    samples: *samples,
                    color: rgb(color, intensity),
                    shadows: *shadows,
                    attenuation: att(attenuation),
                },
                LightDesc::Rect {
                    corner,
                    edge1,
                    edge2,
                    samples,
                    color,
                    intensity,
                    shadows,
                    attenuation,
                } => Light::Rect {
                    corner: at(corner),
                    edge1: v3(*edge1),
                    edge2: v3(*edge2),
                    normal: v3(*edge1).cross(v3(*edge2)).normalize(),
                    samples: *samples,
                    color: rgb(color, intensity),
                    shadows: *shadows,
                    attenuation: att(attenuation),
                },
            })
            .collect()
    }

    /// Stage: fog and ambient occlusion.
    pub(super) fn effects(fog: &Option<FogDesc>, ao: &Option<AoDesc>) -> (Option<Fog>, Option<Ao>) {
        let fog = fog.as_ref().map(|f| Fog {
            mode: f.mode,
            color: v3(f.color),
            planar: f.planar,
            every_ray: f.every_ray,
            misses: f.misses,
        });
        let ao = ao.as_ref().map(|a| Ao {
            samples: a.samples,
            max_distance: a.max_distance as f32,
            sky: v3(a.color) * a.intensity as f32,
            direct: a.direct as f32,
        });
        (fog, ao)
    }

    /// The clip group a name refers to (0: none; group `k` is the `k`-th in the scene).
    fn clip_group(&self, name: &Option<Spanned<String>>) -> Result<u32, Error> {
        Ok(match name {
            Some(c) => {
                1 + self
                    .desc
                    .clip_groups
                    .iter()
                    .position(|(n, _)| n == &c.value)
                    .ok_or_else(|| Error::at(&c.at, format!("no clip group named `{}`", c.value)))?
                    as u32
            }
            None => 0,
        })
    }
}

/// The material a name refers to (0: the default).
fn material_index(names: &[String], name: &Option<Spanned<String>>) -> Result<usize, Error> {
    Ok(match name {
        Some(m) => names
            .iter()
            .position(|n| n == &m.value)
            .ok_or_else(|| Error::at(&m.at, format!("no material named `{}`", m.value)))?,
        None => 0,
    })
}

impl Stored {
    fn new(world_offset: DVec3, materials: usize) -> Stored {
        Stored {
            spheres: Spheres::default(),
            triangles: Triangles::default(),
            planes: Planes::default(),
            cones: Cones::default(),
            discs: Discs::default(),
            customs: Customs::new(world_offset),
            used: vec![false; materials],
            object_counts: Vec::new(),
            dropped: 0,
            keyed: Vec::new(),
            shared: Instances::default(),
            shared_keyed: Vec::new(),
            shared_bytes: 0,
        }
    }

    /// Room for an imported group's primitives, charged to `budget`.
    fn reserve_group(&mut self, g: &InlineGeometry, budget: &Budget) -> Result<(), String> {
        let n = |n: usize, kind: &'static str| move || format!("{n} {kind}");
        let (s, c, d, p) = (
            g.spheres.len(),
            g.cones.len(),
            g.discs.len(),
            g.planes.len(),
        );
        self.spheres.reserve(s, budget, &n(s, "spheres"))?;
        self.cones.reserve(c, budget, &n(c, "cones"))?;
        self.discs.reserve(d, budget, &n(d, "discs"))?;
        self.planes.reserve(p, budget, &n(p, "planes"))?;
        let m = &g.mesh;
        let attrs = !(m.normals.is_empty() && m.uvs.is_empty() && m.colors.is_empty());
        let t = m.indices.len();
        let describe = n(t, "triangles");
        self.triangles
            .reserve_mesh(t, m.positions.len(), attrs, budget, &describe)
    }

    /// Bytes of the stored geometry (its arrays' capacities), the keyed objects' recorded
    /// geometry included.
    fn geometry_bytes(&self) -> u64 {
        self.spheres.bytes()
            + self.triangles.bytes()
            + self.planes.bytes()
            + self.cones.bytes()
            + self.discs.bytes()
            + self.customs.bytes()
            + self.keyed.iter().map(|k| k.geometry.bytes()).sum::<u64>()
            + self.shared_bytes
    }

    /// Stage (with a geometry cache): its native sets and BVHs replace the (empty) ones here.
    fn take_prebuilt(&mut self, p: Prebuilt, world_offset: DVec3) -> Result<(), Error> {
        if p.used.len() != self.used.len() || p.world_offset != world_offset {
            return Err(Error::Render(
                "the geometry cache does not match the scene".into(),
            ));
        }
        self.spheres = p.spheres;
        self.triangles = p.triangles;
        self.cones = p.cones;
        for (u, p) in self.used.iter_mut().zip(p.used) {
            *u |= p;
        }
        self.dropped += p.degenerate;
        Ok(())
    }

    /// Stage: the BVHs of every set, in parallel; the native ones only when `native` (a
    /// cache's come built).
    /// Builds every set's BVH. The build's working memory is charged first (for the sets it
    /// builds at once) and given back after, keeping the BVHs' own bytes; the geometry's
    /// charge is brought down to what the sets hold once built (they grew by doubling).
    fn build_bvhs(&mut self, native: bool, budget: &Budget) -> Result<(), Error> {
        let n = if native {
            self.spheres.len() + self.triangles.len() + self.cones.len() + self.discs.len()
        } else {
            0
        } + self.customs.len();
        let work = n as u64 * BUILD_BYTES_PER_PRIM;
        budget.reserve(Use::Bvh, work, || {
            format!("building the BVHs over {n} primitives")
        })?;
        let built = self.build_sets(native);
        budget.release(Use::Bvh, work);
        built?;
        let bvhs = self.spheres.bvh_bytes()
            + self.triangles.set.bvh_bytes()
            + self.cones.bvh_bytes()
            + self.discs.bvh_bytes()
            + self.customs.bvh_bytes();
        budget.reserve(Use::Bvh, bvhs, || format!("the BVHs over {n} primitives"))?;
        let (charged, held) = (budget.used(Use::Geometry), self.geometry_bytes());
        if charged > held {
            budget.release(Use::Geometry, charged - held);
        }
        Ok(())
    }

    fn build_sets(&mut self, native: bool) -> Result<(), Error> {
        let Stored {
            spheres,
            triangles,
            cones,
            discs,
            customs,
            ..
        } = self;
        let total = spheres.len() + triangles.len() + cones.len() + discs.len() + customs.len();
        if crate::bvh::serial(total) {
            // Small: on this thread, leaving the thread pool asleep (see `bvh::serial`).
            if native {
                spheres.build();
                triangles.set.build();
                cones.build();
                discs.build();
            }
            return customs.build().map_err(Error::Plugin);
        }
        let (_, custom_result) = rayon::join(
            || {
                if native {
                    rayon::join(
                        || rayon::join(|| spheres.build(), || triangles.set.build()),
                        || rayon::join(|| cones.build(), || discs.build()),
                    );
                }
            },
            || customs.build(),
        );
        custom_result.map_err(Error::Plugin)
    }

    fn has_geometry(&self) -> bool {
        !(self.spheres.is_empty()
            && self.triangles.is_empty()
            && self.planes.planes.is_empty()
            && self.cones.is_empty()
            && self.discs.is_empty()
            && self.customs.is_empty()
            && self.keyed.iter().all(|k| k.geometry == Recorded::default())
            && self.shared.is_empty())
    }
}

/// Last: the effects the scene calls for, so the integrator skips the others (`used`: per
/// material, whether any primitive uses it).
#[allow(clippy::too_many_arguments)]
pub(super) fn features(
    r: &RenderDesc,
    materials: &[Material],
    used: &[bool],
    has_geometry: bool,
    lights: &[Light],
    fog: &Option<Fog>,
    ao: &Option<Ao>,
    render_volumes: &[RenderVolume],
) -> Features {
    let used_mats: Vec<&Material> = materials
        .iter()
        .zip(used)
        .filter(|(_, u)| **u)
        .map(|(m, _)| m)
        .collect();
    let transmission = used_mats.iter().any(|m| m.transmit > 0.0);
    let every_ray = fog.as_ref().is_some_and(|f| f.every_ray);
    Features {
        shadows: has_geometry && lights.iter().any(Light::casts_shadows),
        ambient_occlusion: has_geometry && ao.is_some(),
        fog: fog.is_some() && !every_ray,
        fog_every_ray: every_ray,
        reflection: used_mats.iter().any(|m| m.reflect > 0.0),
        transmission,
        // Transparent materials and the copies that cast no shadow.
        shadow_filters: used_mats.iter().any(|m| m.shadow.is_some()),
        see_through: used_mats.iter().any(|m| m.shadow == Some(Vec3A::ONE)),
        outline: used_mats.iter().any(|m| m.outline > 0.0),
        tachyon_lights: (r.tachyon.light_threshold || r.tachyon.plain_highlights)
            && !lights.is_empty(),
        textures: used_mats.iter().any(|m| {
            m.texture
                .or(m.reflect_texture)
                .or(m.transmit_texture)
                .is_some()
        }),
        antialiasing: r.samples > 1 || r.adaptive.is_some(),
        volumes: !render_volumes.is_empty(),
        motion_blur: false,
    }
}

/// The render settings (after command-line overrides, which change the description).
pub(super) fn settings(r: &RenderDesc) -> Settings {
    Settings {
        width: r.width,
        height: r.height,
        samples: r.samples,
        max_depth: r.max_depth,
        min_weight: r.min_weight as f32,
        frame: r.frame,
        time: r.time as f32,
        threads: r.parallel.threads,
        tile_size: r.parallel.tile_size,
        transparency: r.transparency,
        mode: r.parallel.mode,
        decomposition: r.parallel.decomposition,
        io: r.parallel.io,
        volume_skip: r.volume_skip,
        adaptive: r.adaptive,
        light_scale: r.light_scale as f32,
        tachyon: r.tachyon,
        shutter: None,
    }
}

pub(super) fn v3(a: [f64; 3]) -> Vec3A {
    Vec3A::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

/// What a shadow ray keeps after crossing a surface of transmit coefficient `transmit` and
/// colour `color` under the render's rule for transparent shadows; `None`: it is blocked.
pub(super) fn shadow_filter(
    transmit: f32,
    color: Vec3A,
    rule: TransparentShadows,
) -> Option<Vec3A> {
    if transmit <= 0.0 {
        return None;
    }
    Some(match rule {
        TransparentShadows::Tinted => transmit * color,
        TransparentShadows::Untinted => Vec3A::splat(transmit),
        TransparentShadows::Off => Vec3A::ONE,
    })
}

/// `textures`: the material's colour, reflect and transmit textures; `t`: the render's
/// transparency rules (the angle rule a material does not override, shadows' filters).
fn material(
    m: &luxon_formats::MaterialDesc,
    textures: [Option<u32>; 3],
    uv: bool,
    t: &TransparencyDesc,
) -> Material {
    let color = v3(m.color);
    let transmit = m.transmit as f32;
    let angle = match m.transparency_angle {
        Some(TransparencyAngle::Raster3D) => AngleRule::Raster3D,
        Some(TransparencyAngle::Constant) => AngleRule::Constant,
        None if t.mode == TransparencyMode::AngleModulated => AngleRule::Slab,
        None if t.angle == TransparencyAngle::Raster3D => AngleRule::Raster3D,
        None => AngleRule::Constant,
    };
    let shadow = shadow_filter(transmit, color, t.shadows);
    Material {
        color,
        texture: textures[0],
        reflect_texture: textures[1],
        transmit_texture: textures[2],
        ambient: m.ambient as f32,
        diffuse: m.diffuse as f32,
        specular: m.specular as f32,
        shininess: m.shininess as f32,
        highlight: m.highlight,
        highlight_surface: m.highlight_color == HighlightColor::Surface,
        reflect: m.reflect as f32,
        transmit,
        ior: m.ior as f32,
        angle,
        shadow,
        outline: m.outline as f32,
        outline_power: 32.0 * (1.0 - m.outline_width as f32),
        fog: m.fog,
        uv,
    }
}

/// The colour of rays that miss when there is no gradient (a gradient's bottom colour otherwise).
pub(super) fn background(b: &BackgroundDesc) -> Vec3A {
    match b {
        BackgroundDesc::Color(c) => v3(*c),
        BackgroundDesc::Gradient(g) => v3(g.bottom_color),
    }
}

/// A gradient background in render space (its ortho plane is placed relative to the origin).
pub(super) fn sky(b: &BackgroundDesc, world_offset: DVec3) -> Option<Sky> {
    match b {
        BackgroundDesc::Color(_) => None,
        BackgroundDesc::Gradient(g) => Some(Sky::new(g, world_offset)),
    }
}
