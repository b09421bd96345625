//! Array objects: primitives a retained scene ([`crate::api::Scene`]) reads in place from the
//! caller's arrays, one [`ArraySet`] (with its own BVH) per object. The scene tests them one
//! after another after its stored geometry (each object's tree tests its own root box first);
//! issue 19's top-level BVH will index them once scenes hold many. An object's arrays are
//! pinned (held still, writers waiting) from the commit that reads them to the end of the
//! render after it, and released between renders ([`Objects::unpin`]).

use super::array_set::{ArraySet, CapReader, CylinderReader, MeshReader, Reader, SphereReader};
use super::Kind;
use super::{Counters, Hit, Surface};
use crate::arrays::{Array, Pins};
use crate::budget::{Budget, Charge, Use};
use crate::bvh::{BoxRay, BUILD_BYTES_PER_PRIM, REBUILD_RATIO};
use crate::error::Error;
use crate::math::{DVec3, Vec3A};
use crate::ray::Ray;
use std::sync::Arc;

/// Array objects a scene can hold (their number is 16 bits of a hit).
pub const MAX_OBJECTS: usize = u16::MAX as usize;

/// What an object is made of: the reader of its kind (what to build it from).
#[derive(Clone, Copy, Debug)]
pub enum Spec {
    Spheres(SphereReader),
    Mesh(MeshReader),
    /// Cylinders, capped at both ends when `caps`.
    Cylinders {
        reader: CylinderReader,
        caps: bool,
    },
}

impl Spec {
    /// The kind in messages (`object 2 (spheres)`).
    pub fn kind(&self) -> &'static str {
        match self {
            Spec::Spheres(_) => "spheres",
            Spec::Mesh(_) => "mesh",
            Spec::Cylinders { .. } => "cylinders",
        }
    }

    /// The pin whose change is a change of topology (a mesh's indices): built again.
    fn topology(&self) -> Option<usize> {
        match self {
            Spec::Spheres(_) | Spec::Cylinders { .. } => None,
            Spec::Mesh(m) => m.indices,
        }
    }

    /// The primitives its trees hold over `pins` (a cylinder's caps count).
    fn prims(&self, pins: &Pins) -> usize {
        match self {
            Spec::Spheres(r) => r.len(pins),
            Spec::Mesh(r) => r.len(pins),
            Spec::Cylinders { reader, caps } => reader.len(pins) * (1 + *caps as usize),
        }
    }

    /// The same reader with render space's origin at `offset`.
    fn at(self, offset: DVec3) -> Spec {
        match self {
            Spec::Spheres(r) => Spec::Spheres(SphereReader { offset, ..r }),
            Spec::Mesh(r) => Spec::Mesh(MeshReader { offset, ..r }),
            Spec::Cylinders { reader, caps } => Spec::Cylinders {
                reader: CylinderReader { offset, ..reader },
                caps,
            },
        }
    }
}

/// A built object's primitives.
enum Shapes {
    Spheres(ArraySet<SphereReader>),
    Mesh(ArraySet<MeshReader>),
    /// The tubes, then their caps (tested in that order, as the stored cones and discs are).
    Cylinders(ArraySet<CylinderReader>, Option<ArraySet<CapReader>>),
}

/// What a commit did to an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    /// Nothing changed.
    Kept,
    /// New content, same counts: the tree was refitted; its cost over the built tree's.
    Refitted(f32),
    /// Built (first time, new counts, new arrays or a new origin).
    Built,
    /// Refitted, but its cost grew past [`REBUILD_RATIO`] times the built tree's (the ratio),
    /// so built again.
    Degraded(f32),
}

/// One array object: its arrays, what it is, and its tree.
pub struct Object {
    /// The retained scene's name for it (the same object keeps its key across commits).
    pub key: u64,
    /// `object 2 (spheres)`.
    label: String,
    /// Render space's origin it was built for.
    offset: DVec3,
    // Dropped before the arrays (a `Pins` holds clones of them anyway).
    pins: Option<Pins>,
    arrays: Vec<Array>,
    spec: Spec,
    /// Packed material.
    material: u32,
    /// The arrays' lengths and generations the tree was built or refitted from.
    lens: Vec<usize>,
    generations: Vec<u64>,
    shapes: Shapes,
    /// Its tree's bytes, charged to the memory budget of the build that holds it.
    charge: Charge,
}

impl Object {
    /// Pins `arrays`, checks every element and builds the tree (in render space whose origin
    /// is `offset`); the arrays stay pinned (see [`Objects::unpin`]). The build's working
    /// memory is charged to `budget` first (refused with a message when it does not fit), and
    /// the tree's bytes for the object's life.
    pub fn build(
        key: u64,
        label: String,
        arrays: Vec<Array>,
        spec: Spec,
        material: u32,
        offset: DVec3,
        budget: &Arc<Budget>,
    ) -> Result<Object, Error> {
        let pins = Pins::new(&arrays)?;
        let spec = spec.at(offset);
        let n = spec.prims(&pins);
        let work = (n as u64).saturating_mul(BUILD_BYTES_PER_PRIM);
        let work = budget.charge(Use::Bvh, work, || {
            format!("building the BVH of {label} over {n} primitives")
        })?;
        let shapes = match spec {
            Spec::Spheres(r) => ArraySet::build(r, &pins, material).map(Shapes::Spheres),
            Spec::Mesh(r) => ArraySet::build(r, &pins, material).map(Shapes::Mesh),
            Spec::Cylinders { reader, caps } => {
                ArraySet::build(reader, &pins, material).and_then(|tubes| {
                    let caps = caps
                        .then(|| ArraySet::build(CapReader(reader), &pins, material))
                        .transpose()?;
                    Ok(Shapes::Cylinders(tubes, caps))
                })
            }
        };
        let shapes = shapes.map_err(|m| Error::Api(format!("{label}: {m}")))?;
        drop(work);
        let charge = budget.charge(Use::Bvh, shapes.bytes(), || format!("the BVH of {label}"))?;
        Ok(Object {
            charge,
            key,
            label,
            offset,
            lens: (0..arrays.len()).map(|k| pins.view(k).len()).collect(),
            generations: (0..arrays.len()).map(|k| pins.generation(k)).collect(),
            pins: Some(pins),
            arrays,
            spec,
            material,
            shapes,
        })
    }

    /// Pins the arrays again and brings the tree up to date with them: kept when no array
    /// changed, refitted when contents changed but not counts, built again when counts changed
    /// or render space's origin is now `offset`, or when the refitted tree degraded. On an
    /// error the object is unusable (unpinned and emptied) until a later update succeeds.
    /// Its tree stays charged to `budget` (the build's that holds it now).
    pub fn update(self, offset: DVec3, budget: &Arc<Budget>) -> Result<(Object, Outcome), Error> {
        let Object {
            key,
            label,
            arrays,
            spec,
            material,
            ..
        } = self;
        if offset != self.offset {
            let o = Object::build(key, label, arrays, spec, material, offset, budget)?;
            return Ok((o, Outcome::Built));
        }
        let pins = Pins::new(&arrays)?;
        let lens: Vec<usize> = (0..arrays.len()).map(|k| pins.view(k).len()).collect();
        let generations: Vec<u64> = (0..arrays.len()).map(|k| pins.generation(k)).collect();
        let topology = spec.topology();
        let retopo = topology.is_some_and(|k| generations[k] != self.generations[k]);
        if lens != self.lens || retopo {
            drop(pins);
            let o = Object::build(key, label, arrays, spec, material, offset, budget)?;
            return Ok((o, Outcome::Built));
        }
        let mut object = Object {
            key,
            label,
            offset,
            pins: None,
            arrays,
            spec,
            material,
            lens,
            generations: self.generations,
            shapes: self.shapes,
            charge: self.charge,
        };
        let label = &object.label;
        object.charge = (object.charge).move_to(budget, || format!("the BVH of {label}"))?;
        if generations == object.generations {
            object.pins = Some(pins);
            return Ok((object, Outcome::Kept));
        }
        let ratio = match &mut object.shapes {
            Shapes::Spheres(s) => s.refit(&pins),
            Shapes::Mesh(m) => m.refit(&pins),
            Shapes::Cylinders(tubes, caps) => tubes.refit(&pins).and_then(|a| match caps {
                Some(c) => Ok(a.max(c.refit(&pins)?)),
                None => Ok(a),
            }),
        };
        let ratio = ratio.map_err(|m| Error::Api(format!("{}: {m}", object.label)))?;
        if ratio > REBUILD_RATIO {
            drop(pins);
            let Object {
                key,
                label,
                arrays,
                spec,
                material,
                ..
            } = object;
            let o = Object::build(key, label, arrays, spec, material, offset, budget)?;
            return Ok((o, Outcome::Degraded(ratio)));
        }
        object.generations = generations;
        object.pins = Some(pins);
        Ok((object, Outcome::Refitted(ratio)))
    }

    /// Primitives.
    pub fn len(&self) -> usize {
        match &self.shapes {
            Shapes::Spheres(s) => s.len(),
            Shapes::Mesh(m) => m.len(),
            Shapes::Cylinders(tubes, caps) => tubes.len() + caps.as_ref().map_or(0, |c| c.len()),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The material (packed) of its primitives.
    pub fn material(&self) -> u32 {
        self.material
    }

    pub fn label(&self) -> &str {
        &self.label
    }

    /// Bytes of its tree and leaf order in use (the arrays are the caller's).
    pub fn bytes(&self) -> u64 {
        self.shapes.bytes()
    }
}

impl Shapes {
    fn bytes(&self) -> u64 {
        match self {
            Shapes::Spheres(s) => s.bytes(),
            Shapes::Mesh(m) => m.bytes(),
            Shapes::Cylinders(tubes, caps) => {
                tubes.bytes() + caps.as_ref().map_or(0, |c| c.bytes())
            }
        }
    }
}

/// The array objects of a built scene, tested in order.
#[derive(Default)]
pub struct Objects {
    list: Vec<Object>,
}

impl Objects {
    pub fn new(list: Vec<Object>) -> Objects {
        Objects { list }
    }

    /// The objects, for a commit to update them.
    pub fn take(&mut self) -> Vec<Object> {
        std::mem::take(&mut self.list)
    }

    pub fn list(&self) -> &[Object] {
        &self.list
    }

    /// Whether there is no array object (scenes without any skip them in one test).
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Primitives in all objects.
    pub fn len(&self) -> usize {
        self.list.iter().map(Object::len).sum()
    }

    /// Releases every object's arrays (the caller may write them again); rays find nothing in
    /// an object until a commit pins it again.
    pub fn unpin(&mut self) {
        for o in &mut self.list {
            o.pins = None;
        }
    }

    /// The closest hit before `t_max`, if closer than `hit`.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: &mut f32,
        hit: &mut Option<Hit>,
        c: &mut Counters,
    ) {
        for (k, o) in self.list.iter().enumerate() {
            let Some(pins) = &o.pins else { continue };
            // At most `MAX_OBJECTS` (the api refuses more).
            let object = (k + 1) as u16;
            match &o.shapes {
                Shapes::Spheres(s) => s.intersect(pins, ray, boxes, t_max, hit, c, object),
                Shapes::Mesh(m) => m.intersect(pins, ray, boxes, t_max, hit, c, object),
                Shapes::Cylinders(tubes, caps) => {
                    tubes.intersect(pins, ray, boxes, t_max, hit, c, object);
                    if let Some(caps) = caps {
                        caps.intersect(pins, ray, boxes, t_max, hit, c, object);
                    }
                }
            }
        }
    }

    /// Calls `on_hit(material, crossings)` for what the ray crosses in (0, t_max) until it
    /// returns true; returns whether it did.
    #[inline]
    pub fn any(
        &self,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: f32,
        c: &mut Counters,
        on_hit: &mut impl FnMut(u32, u32) -> bool,
    ) -> bool {
        self.list.iter().any(|o| {
            let Some(pins) = &o.pins else { return false };
            match &o.shapes {
                Shapes::Spheres(s) => s.any(pins, ray, boxes, t_max, c, on_hit),
                Shapes::Mesh(m) => m.any(pins, ray, boxes, t_max, c, on_hit),
                Shapes::Cylinders(tubes, caps) => {
                    tubes.any(pins, ray, boxes, t_max, c, on_hit)
                        || caps
                            .as_ref()
                            .is_some_and(|caps| caps.any(pins, ray, boxes, t_max, c, on_hit))
                }
            }
        })
    }

    /// The surface at a hit on an object (`hit.object` ≥ 1); `uv(material)`: whether its
    /// texture coordinates are read.
    pub fn surface(&self, hit: &Hit, ray: &Ray, uv: impl Fn(u32) -> bool) -> Surface {
        let o = &self.list[hit.object as usize - 1];
        let m = super::material_of(o.material);
        let found = o.pins.as_ref().and_then(|pins| match &o.shapes {
            Shapes::Spheres(s) => s.surface(pins, hit, ray, uv(m)),
            Shapes::Mesh(t) => t.surface(pins, hit, ray, uv(m)),
            Shapes::Cylinders(tubes, caps) => match (hit.kind, caps) {
                (Kind::Disc, Some(caps)) => caps.surface(pins, hit, ray, uv(m)),
                _ => tubes.surface(pins, hit, ray, uv(m)),
            },
        });
        // Only if the arrays were released between the hit and its shading (never in a
        // render): a flat surface facing the ray.
        found.unwrap_or_else(|| Surface::solid(ray.at(hit.t), Vec3A::ZERO, -ray.dir, [0.0; 2], m))
    }
}
