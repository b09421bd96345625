//! Instances of prototypes, realised by **baking**: each prototype's objects are run through
//! their plugins once, recorded as the plugins give them (f64, object space), and replayed
//! through every instance's `world_from_object` (f64) into the scene's ordinary sets — after
//! the scene's own objects and imported meshes, in instance order, each prototype's objects in
//! their order. The stored copies are then exactly what the same geometry written out flat at
//! those coordinates would store: same f64 values, same f32 values, same order, same BVHs,
//! same picture, bit for bit.
//!
//! Or by **sharing**: one copy of the prototype in its own object space (a bottom-level BVH)
//! for all its static instances, a top-level BVH over the instances, and rays moved into
//! object space per instance (`geometry::instance`): memory for one copy plus a few hundred
//! bytes per instance, the picture within rounding of the flat one (not bit for bit).
//!
//! The render setting `instancing` chooses, per prototype: `Bake` bakes every static instance
//! (refusing by name what baking cannot do: spheres, cones or discs under a scale that is not
//! uniform — a sphere cannot become an ellipsoid); `Share` shares them all; `Auto` (the
//! default) bakes a prototype's static instances when baking is exact — no instance stretches
//! a prototype holding spheres, cones or discs — and small — at most [`BAKE_LIMIT`] primitives
//! in all its baked copies — and shares them otherwise. Custom (plugin-intersected) geometry
//! cannot be copied either way (the host cannot move it).
//!
//! An instance the animation keys (by its `name`) is not baked: its copies are recorded as
//! keyed objects and placed anew at every frame in the scene's moving group (`frame`), or,
//! under `Share` or when it moves during an open shutter (motion blur), shares its prototype.

use super::frame::Keyed;
use super::place::{place, Sets};
use crate::budget::Budget;
use crate::budget::Use;
use crate::error::Error;
use crate::geometry::cone::Cones;
use crate::geometry::custom::Customs;
use crate::geometry::disc::Discs;
use crate::geometry::group::Group;
use crate::geometry::instance::{self, Instance, Instances, Motion};
use crate::geometry::pack;
use crate::geometry::plane::Planes;
use crate::geometry::sphere::Spheres;
use crate::geometry::triangle::Triangles;
use crate::math::DVec3;
use crate::motion::Placement;
use crate::plugin::primitive::{create_primitive, GeometryBuilder, Recorded, RecordedMesh};
use crate::plugin::{PluginKind, Registry};
use luxon_formats::{
    InlineGeometry, InstanceDesc, Instancing, Key, ObjectTracks, Origin, SceneDesc, Spanned, Track,
    TransformDesc,
};
use std::path::Path;
use std::sync::Arc;

/// How a prototype was realised, for `luxon check`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PrototypeUse {
    pub name: String,
    /// Objects in the prototype.
    pub objects: usize,
    /// Groups of its mesh files (one per material).
    pub meshes: usize,
    /// Instances stored as flat copies.
    pub baked: usize,
    /// Instances keyed by the animation, placed anew at every frame.
    pub keyed: usize,
    /// Instances sharing one copy of the prototype (a two-level BVH).
    pub shared: usize,
    /// Primitives (spheres, triangles, planes, cones, discs) in one copy.
    pub primitives: usize,
}

/// What the stage reads.
pub(super) struct Context<'a> {
    pub desc: &'a SceneDesc,
    pub registry: &'a Registry,
    pub scene_dir: &'a Path,
    pub world_offset: DVec3,
    pub budget: &'a Arc<Budget>,
}

/// The material index for an object's material name and whether it casts shadows.
pub(super) type MaterialOf<'m> =
    dyn Fn(&Option<Spanned<String>>, bool) -> Result<usize, Error> + 'm;

/// The baked instances' results besides their geometry.
pub(super) struct Baked {
    pub prototypes: Vec<PrototypeUse>,
    /// Keyed instances' copies, one per prototype object.
    pub keyed: Vec<Keyed>,
    /// Keyed instances sharing their prototype (`instancing: Share`): the index in
    /// `shared.list` and the tracks that place it at each frame.
    pub shared_keyed: Vec<(u32, ObjectTracks)>,
    /// Zero-area triangles dropped.
    pub dropped: u64,
    /// The shared instances (empty when every instance was baked or keyed).
    pub shared: Instances,
    /// Bytes charged to the budget's geometry for the shared instances (their prototypes'
    /// copies and the instance table), kept for the scene's life.
    pub shared_bytes: u64,
}

/// `Auto` bakes a prototype's static instances only while all its copies hold at most this
/// many primitives in all; more share one copy.
pub const BAKE_LIMIT: usize = 1 << 20;

/// The stage: every instance of `cx.desc` stored into `sets` (or, when keyed, recorded into
/// `Baked::keyed`); `used` marks the materials the copies use.
pub(super) fn bake(
    cx: &Context,
    material_of: &MaterialOf,
    mut sets: Sets,
    used: &mut [bool],
) -> Result<Baked, Error> {
    let desc = cx.desc;
    let mut baked = Baked {
        prototypes: Vec::new(),
        keyed: Vec::new(),
        shared_keyed: Vec::new(),
        dropped: 0,
        shared: Instances::default(),
        shared_bytes: 0,
    };
    if desc.instances.is_empty() {
        return Ok(baked);
    }
    // Each prototype with an instance, recorded once.
    let mut recorded: Vec<Option<Vec<Part>>> = vec![None; desc.prototypes.len()];
    let mut instance_of = Vec::with_capacity(desc.instances.len());
    for inst in &desc.instances {
        let want = &inst.value.prototype;
        let Some(p) = desc.prototypes.iter().position(|(n, _)| *n == want.value) else {
            return Err(Error::at(
                &want.at,
                format!("no prototype named `{}`", want.value),
            ));
        };
        if recorded[p].is_none() {
            recorded[p] = Some(record(cx, p)?);
        }
        instance_of.push(p);
    }
    let mut uses: Vec<PrototypeUse> = desc
        .prototypes
        .iter()
        .zip(&recorded)
        .map(|((name, p), r)| PrototypeUse {
            name: name.clone(),
            objects: p.value.objects.len(),
            meshes: p.value.inline.len(),
            baked: 0,
            keyed: 0,
            shared: 0,
            primitives: r
                .as_ref()
                .map_or(0, |r| r.iter().map(|p| primitives(&p.geometry)).sum()),
        })
        .collect();
    let keyed_tracks = desc.animation.as_ref().map(|a| &a.value.instances);
    let keyed = |k: usize| keyed_tracks.and_then(|t| t.iter().find(|t| t.object == k));
    let share = realisations(desc, &instance_of, &recorded, &keyed);
    let mut shared = Shared::default();
    for (k, (inst, &p)) in desc.instances.iter().zip(&instance_of).enumerate() {
        let name = &desc.prototypes[p].0;
        let parts = recorded[p].as_ref().expect("recorded above");
        let what = || describe(k, inst, name);
        if let Some(tracks) = keyed(k) {
            let tracks = with_static(tracks, &inst.value.world_from_object, &what)?;
            // Motion blur traces what moves as shared instances whatever `instancing` says
            // (a baked copy stands still for the whole shutter).
            let blurred = super::frame::per_ray(desc) && super::frame::object_moves(&tracks);
            if desc.render.instancing == Instancing::Share || blurred {
                // Shared like a static copy; `set_frame` places it at each frame (or, blurred,
                // at each ray's time) and rebuilds the top level (here it stands where the
                // first frame puts it).
                let first = desc.animation.as_ref().map_or(0, |a| a.value.first);
                let placement = Placement::at(&tracks, f64::from(first));
                shared.add(cx, material_of, (inst, p), parts, &placement, used, &what)?;
                let index = shared.list.len() as u32 - 1;
                baked.shared_keyed.push((index, tracks));
                uses[p].keyed += 1;
                continue;
            }
            for part in parts {
                let m = material(material_of, &inst.value, &part.material, part.shadows)?;
                used[m] = true;
                baked.keyed.push(Keyed {
                    tracks: tracks.clone(),
                    geometry: part.geometry.clone(),
                    material: pack(m as u32, 0),
                    at: inst.at.clone(),
                });
            }
            uses[p].keyed += 1;
            continue;
        }
        let placement = Placement::from_desc(&inst.value.world_from_object.value);
        if share[p] {
            shared.add(cx, material_of, (inst, p), parts, &placement, used, &what)?;
            uses[p].shared += 1;
            continue;
        }
        let round = parts
            .iter()
            .map(|p| &p.geometry)
            .any(|g| !(g.spheres.is_empty() && g.cones.is_empty() && g.discs.is_empty()));
        if round && placement.uniform_scale().is_none() {
            return Err(Error::at(
                &inst.value.world_from_object.at,
                format!(
                    "{}: its `world_from_object` does not scale the same on every axis, and the \
                     prototype holds spheres, cones or discs, which baking cannot stretch (a \
                     sphere does not become an ellipsoid); expected a uniform scale (a rotation, \
                     one scale factor and a translation), or `instancing: Share` or `Auto` in the \
                     render settings, which share the prototype instead (one copy traced \
                     through each instance's transform stretches fine)",
                    what()
                ),
            ));
        }
        for part in parts {
            let m = material(material_of, &inst.value, &part.material, part.shadows)?;
            used[m] = true;
            baked.dropped += place(
                &part.geometry,
                &placement,
                cx.world_offset,
                pack(m as u32, 0),
                sets.reborrow(),
                cx.budget,
            )
            .map_err(|e| Error::at(&inst.at, format!("{}, {}: {e}", what(), part.label)))?;
        }
        uses[p].baked += 1;
    }
    uses.retain(|u| u.baked + u.keyed + u.shared > 0);
    baked.prototypes = uses;
    baked.dropped += shared.dropped;
    (baked.shared, baked.shared_bytes) = shared.finish(cx)?;
    Ok(baked)
}

/// Per prototype: whether its static instances are shared (else baked), as the render
/// setting `instancing` says (see the module's documentation for `Auto`'s rule).
fn realisations<'d>(
    desc: &'d SceneDesc,
    instance_of: &[usize],
    recorded: &[Option<Vec<Part>>],
    keyed: &dyn Fn(usize) -> Option<&'d ObjectTracks>,
) -> Vec<bool> {
    let n = desc.prototypes.len();
    match desc.render.instancing {
        Instancing::Bake => return vec![false; n],
        Instancing::Share => return vec![true; n],
        Instancing::Auto => {}
    }
    let mut copies = vec![0usize; n];
    let mut stretched = vec![false; n];
    for (k, (inst, &p)) in desc.instances.iter().zip(instance_of).enumerate() {
        if keyed(k).is_some() {
            continue;
        }
        copies[p] += 1;
        let placement = Placement::from_desc(&inst.value.world_from_object.value);
        stretched[p] |= placement.uniform_scale().is_none();
    }
    (0..n)
        .map(|p| {
            let Some(parts) = &recorded[p] else {
                return false;
            };
            let round = parts
                .iter()
                .map(|p| &p.geometry)
                .any(|g| !(g.spheres.is_empty() && g.cones.is_empty() && g.discs.is_empty()));
            let size: usize = parts.iter().map(|p| primitives(&p.geometry)).sum();
            (round && stretched[p]) || copies[p].saturating_mul(size) > BAKE_LIMIT
        })
        .collect()
}

/// The shared instances as they are collected: one bottom level per prototype and material
/// override (an instance's `material` recolours its copy), the instances placing them.
#[derive(Default)]
struct Shared {
    blases: Vec<Group>,
    /// What each bottom level is: (prototype, the instance's material override).
    keys: Vec<(usize, Option<String>)>,
    list: Vec<Instance>,
    dropped: u64,
    /// Geometry charged for the bottom levels' arrays.
    bytes: u64,
}

impl Shared {
    /// An instance (of prototype `p`, whose recorded parts are `parts`) placed by `placement`:
    /// its prototype's bottom level made on first use, in object space.
    #[allow(clippy::too_many_arguments)]
    fn add(
        &mut self,
        cx: &Context,
        material_of: &MaterialOf,
        (inst, p): (&Spanned<InstanceDesc>, usize),
        parts: &[Part],
        placement: &Placement,
        used: &mut [bool],
        what: &dyn Fn() -> String,
    ) -> Result<(), Error> {
        let det = placement.world_from_object.matrix3.determinant();
        if !(det.is_finite() && det != 0.0) {
            return Err(Error::at(
                &inst.value.world_from_object.at,
                format!("{}: its transform is singular (a scale of 0?)", what()),
            ));
        }
        let key = (p, inst.value.material.as_ref().map(|m| m.value.clone()));
        let blas = match self.keys.iter().position(|b| *b == key) {
            Some(b) => b,
            None => {
                let before = cx.budget.used(Use::Geometry);
                let mut group = Group::default();
                let identity = Placement::from_desc(&TransformDesc::IDENTITY);
                for part in parts {
                    let m = material(material_of, &inst.value, &part.material, part.shadows)?;
                    used[m] = true;
                    let at = pack(m as u32, 0);
                    // Object space: no offset (the instances' transforms carry it).
                    let sets = group.sets();
                    self.dropped +=
                        place(&part.geometry, &identity, DVec3::ZERO, at, sets, cx.budget)
                            .map_err(|e| {
                                Error::at(&inst.at, format!("{}, {}: {e}", what(), part.label))
                            })?;
                }
                self.bytes += cx.budget.used(Use::Geometry).saturating_sub(before);
                self.blases.push(group);
                self.keys.push(key);
                self.blases.len() - 1
            }
        };
        let placement = instance::Placement::new(placement.world_from_object, cx.world_offset);
        self.list.push(Instance {
            blas: blas as u32,
            motion: Motion::Fixed(Box::new(placement)),
        });
        Ok(())
    }

    /// The bottom levels built, the table charged and the top level built over it; with the
    /// geometry bytes charged for good.
    fn finish(mut self, cx: &Context) -> Result<(Instances, u64), Error> {
        if self.list.is_empty() {
            return Ok((Instances::default(), 0));
        }
        let n = self.list.len();
        let table = (n
            * (std::mem::size_of::<Instance>() + std::mem::size_of::<instance::Placement>()))
            as u64;
        cx.budget.reserve(Use::Geometry, table, || {
            format!("the table of {n} shared instances")
        })?;
        for g in &mut self.blases {
            g.build(cx.budget)
                .map_err(|e| Error::Render(format!("the shared prototypes: {}", e.0)))?;
        }
        Ok((
            Instances::new(self.blases, self.list, cx.world_offset),
            self.bytes + table,
        ))
    }
}

/// "instance 3 of prototype `gear`" (with its name when it has one).
fn describe(k: usize, inst: &Spanned<InstanceDesc>, prototype: &str) -> String {
    match &inst.value.name {
        Some(n) => format!("instance {k} (`{}`) of prototype `{prototype}`", n.value),
        None => format!("instance {k} of prototype `{prototype}`"),
    }
}

/// The material of a prototype object in an instance: the instance's, else the object's.
fn material(
    material_of: &MaterialOf,
    inst: &InstanceDesc,
    own: &Option<Spanned<String>>,
    shadows: bool,
) -> Result<usize, Error> {
    let name = if inst.material.is_some() {
        &inst.material
    } else {
        own
    };
    material_of(name, shadows)
}

fn primitives(g: &Recorded) -> usize {
    g.spheres.len()
        + g.planes.len()
        + g.cones.len()
        + g.discs.len()
        + g.meshes.iter().map(|m| m.indices.len() / 3).sum::<usize>()
}

/// A part of a prototype as recorded: an object's plugin output, or a group of a mesh file.
#[derive(Clone)]
struct Part {
    geometry: Recorded,
    material: Option<Spanned<String>>,
    shadows: bool,
    /// "object 2", "mesh group 0", for messages.
    label: String,
}

/// Group `k` of a prototype's mesh files as a recording (its arrays as a plugin would give
/// them).
fn inline_part(k: usize, g: &InlineGeometry) -> Part {
    let m = &g.mesh;
    let mut geometry = Recorded {
        spheres: g.spheres.clone(),
        planes: g.planes.clone(),
        cones: g.cones.clone(),
        discs: g.discs.clone(),
        meshes: Vec::new(),
    };
    if !m.indices.is_empty() {
        geometry.meshes.push(RecordedMesh {
            positions: m.positions.as_flattened().to_vec(),
            indices: m.indices.as_flattened().to_vec(),
            normals: m.normals.as_flattened().to_vec(),
            colors: Vec::new(),
            uvs: m.uvs.iter().flat_map(|u| u.map(|x| x as f32)).collect(),
        });
    }
    Part {
        geometry,
        material: g.material.clone(),
        shadows: !g.shadowless,
        label: format!("mesh group {k}"),
    }
}

/// Runs prototype `p`'s objects through their plugins into recordings (object space), then
/// its mesh files' groups.
fn record(cx: &Context, p: usize) -> Result<Vec<Part>, Error> {
    let (name, proto) = &cx.desc.prototypes[p];
    let mut out = Vec::with_capacity(proto.value.objects.len());
    // Recording stores nothing in these; the builder wants somewhere to point.
    let (mut spheres, mut triangles, mut planes) =
        (Spheres::default(), Triangles::default(), Planes::default());
    let (mut cones, mut discs) = (Cones::default(), Discs::default());
    let mut customs = Customs::new(cx.world_offset);
    for (j, obj) in proto.value.objects.iter().enumerate() {
        let call = &obj.value.call;
        let entry = cx
            .registry
            .get(&call.plugin.value, PluginKind::Primitive)
            .map_err(|e| Error::at(&call.plugin.at, e.to_string()))?;
        let mut geometry = Recorded::default();
        let instance = format!("prototype `{name}` object {j}");
        let mut b = GeometryBuilder {
            spheres: &mut spheres,
            triangles: &mut triangles,
            planes: &mut planes,
            cones: &mut cones,
            discs: &mut discs,
            customs: &mut customs,
            material: 0,
            world_offset: cx.world_offset,
            plugin: entry.name.clone(),
            dropped: 0,
            record: Some(&mut geometry),
            budget: cx.budget,
            object: format!("{instance} (plugin `{}`, {})", entry.name, obj.at),
            instance: instance.clone(),
            at: obj.at.clone(),
        };
        create_primitive(
            cx.registry,
            entry,
            &call.params,
            &call.params_at,
            cx.scene_dir,
            &instance,
            &mut b,
        )
        .map_err(|(at, m)| Error::at(&at, m))?;
        out.push(Part {
            geometry,
            material: obj.value.material.clone(),
            shadows: obj.value.shadows,
            label: format!("object {j}"),
        });
    }
    out.extend(
        proto
            .value
            .inline
            .iter()
            .enumerate()
            .map(|(k, g)| inline_part(k, g)),
    );
    Ok(out)
}

/// A keyed instance's tracks with its static transform filling the tracks it lacks (a
/// keyed property replaces the static one; the others keep theirs).
fn with_static(
    tracks: &ObjectTracks,
    t: &Spanned<TransformDesc>,
    what: &dyn Fn() -> String,
) -> Result<ObjectTracks, Error> {
    let TransformDesc::Trs {
        translate,
        rotate,
        scale,
    } = t.value
    else {
        return Err(Error::at(
            &tracks.name.at,
            format!(
                "{} is placed by a `matrix`, which keys cannot change; expected \
                 `translate`/`rotate`/`scale` in its `world_from_object` to key it",
                what()
            ),
        ));
    };
    let mut out = tracks.clone();
    if out.translate.is_none() && translate != [0.0; 3] {
        out.translate = Some(constant(translate, &t.at));
    }
    if let (None, Some(r)) = (&out.rotate, rotate) {
        out.rotate = Some(constant(r, &t.at));
    }
    if out.scale.is_none() && scale != [1.0; 3] {
        out.scale = Some(constant(scale, &t.at));
    }
    Ok(out)
}

/// A track of one key: the value at every frame.
fn constant<T>(value: T, at: &Origin) -> Track<T> {
    Track {
        keys: vec![Key {
            frame: 0.0,
            value,
            at: at.clone(),
        }],
        interpolation: Default::default(),
        at: at.clone(),
    }
}

/// The materials of instanced objects that cast no shadow (each needs a copy of its material
/// that casts none), in instance order.
pub(super) fn shadowless(desc: &SceneDesc) -> Vec<Option<Spanned<String>>> {
    let mut out = Vec::new();
    for inst in &desc.instances {
        let want = &inst.value.prototype.value;
        let Some((_, p)) = desc.prototypes.iter().find(|(n, _)| n == want) else {
            continue;
        };
        let objects = p
            .value
            .objects
            .iter()
            .map(|o| (&o.value.material, o.value.shadows));
        let groups = p.value.inline.iter().map(|g| (&g.material, !g.shadowless));
        for (own, _) in objects.chain(groups).filter(|(_, shadows)| !shadows) {
            let name = inst.value.material.as_ref().or(own.as_ref());
            out.push(name.cloned());
        }
    }
    out
}
