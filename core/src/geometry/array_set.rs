//! Primitives read in place from the caller's arrays ([`crate::arrays`]): an [`ArraySet`] is a
//! BVH over the elements a [`Reader`] finds in pinned arrays, with the element order of its
//! leaves. Nothing is copied: every test reads the element again through its views (checked
//! against the arrays' lengths; a read past the end is a miss), re-centred exactly as the
//! stored sets' `push_world` re-centres (f64 value minus the origin, then f32), and runs the
//! kind's own `Shape` test and surface function, so an array set and a stored set of the same
//! primitives give the same tree and the same pixels.
//!
//! When the arrays' content changes but not their lengths, [`ArraySet::refit`] puts the new
//! bounds into the tree (leaves keep their elements) and says how much its cost grew.

use super::cone::{self, Cone};
use super::disc::{self, Disc};
use super::set::Shape;
use super::sphere::{self, Sphere};
use super::triangle::{self, Triangle, VertexAttr, NO_ATTR};
use super::{Counters, Hit, Surface};
use crate::arrays::Pins;
use crate::bvh::{BoxRay, Bvh};
use crate::math::{Aabb, DVec3, Vec3A};
use crate::ray::Ray;
use glam::Vec3;
use rayon::prelude::*;

/// How a kind of primitive is read from pinned arrays (which arrays: the reader knows their
/// places among the object's pins).
pub trait Reader: Send + Sync {
    type Shape: Shape;
    /// What the primitives are called in messages (`sphere`).
    const ELEMENT: &'static str;
    /// Elements in the arrays.
    fn len(&self, pins: &Pins) -> usize;
    /// Element `i` in render space, computed as `push_world` computes it; `None` when an array
    /// is too short for it.
    fn get(&self, pins: &Pins, i: usize) -> Option<Self::Shape>;
    /// Whether element `i` is valid (`push_world`'s rules); the message names it.
    fn check(&self, pins: &Pins, i: usize) -> Result<(), String>;
    /// Checks that need every array at once (lengths that must agree).
    fn check_arrays(&self, pins: &Pins) -> Result<(), String>;
    /// The surface of element `i` at `hit` (`uv`: texture coordinates wanted).
    fn surface(
        &self,
        pins: &Pins,
        i: usize,
        hit: &Hit,
        ray: &Ray,
        uv: bool,
        material: u32,
    ) -> Option<Surface>;
}

/// A sphere's radius: one for all, or one per sphere from an array.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RadiusRead {
    Const(f64),
    /// The pin holding the radii.
    Each(usize),
}

impl RadiusRead {
    /// The pin of per-element radii, if any.
    fn each(self) -> Option<usize> {
        match self {
            RadiusRead::Each(k) => Some(k),
            RadiusRead::Const(_) => None,
        }
    }
}

/// Checks that every pin in `arrays` (named, `None`: not given) holds `n` values; `wrong(m,
/// name)` words the error for one that holds `m`.
fn one_each<const N: usize>(
    pins: &Pins,
    n: usize,
    arrays: [(&str, Option<usize>); N],
    wrong: impl Fn(usize, &str) -> String,
) -> Result<(), String> {
    for (what, k) in arrays {
        let Some(k) = k else { continue };
        let m = pins.view(k).len();
        if m != n {
            return Err(wrong(m, what));
        }
    }
    Ok(())
}

/// Spheres: centres from pin 0 (f32x3 or f64x3), radii (a constant or a pin of scalars) and
/// optional linear RGB colours (a pin of f32x3 or f64x3).
#[derive(Clone, Copy, Debug)]
pub struct SphereReader {
    pub radius: RadiusRead,
    /// The pin holding the colours.
    pub colors: Option<usize>,
    /// Render space's origin in world coordinates.
    pub offset: DVec3,
}

impl SphereReader {
    /// Centre and radius in world coordinates, as given.
    #[inline(always)]
    fn world(&self, pins: &Pins, i: usize) -> Option<[f64; 4]> {
        let c = pins.view(0).vec3(i)?;
        let r = match self.radius {
            RadiusRead::Const(r) => r,
            RadiusRead::Each(k) => pins.view(k).scalar(i)?,
        };
        Some([c.x, c.y, c.z, r])
    }
}

impl Reader for SphereReader {
    type Shape = Sphere;
    const ELEMENT: &'static str = "sphere";

    fn len(&self, pins: &Pins) -> usize {
        pins.view(0).len()
    }

    #[inline(always)]
    fn get(&self, pins: &Pins, i: usize) -> Option<Sphere> {
        let s = self.world(pins, i)?;
        Some(Sphere {
            center: (DVec3::new(s[0], s[1], s[2]) - self.offset).as_vec3(),
            radius: s[3] as f32,
        })
    }

    fn check(&self, pins: &Pins, i: usize) -> Result<(), String> {
        let Some(s) = self.world(pins, i) else {
            return Err(format!("sphere {i} cannot be read"));
        };
        // The messages of `Set<Sphere>::push_world`.
        if s.iter().any(|x| !x.is_finite()) {
            return Err(format!("sphere {i} has a non-finite value {s:?}"));
        }
        if s[3] <= 0.0 {
            return Err(format!(
                "sphere {i} has radius {}; expected a radius > 0",
                s[3]
            ));
        }
        if let Some(k) = self.colors {
            let c = pins.view(k).vec3(i);
            if !c.is_some_and(|c| c.is_finite() && c.min_element() >= 0.0) {
                return Err(format!(
                    "sphere {i} has colour {c:?}; expected finite components >= 0"
                ));
            }
        }
        Ok(())
    }

    fn check_arrays(&self, pins: &Pins) -> Result<(), String> {
        let n = self.len(pins);
        let radii = ("radii", self.radius.each());
        one_each(pins, n, [("colours", self.colors), radii], |m, what| {
            format!("{m} {what} for {n} centres; give one per centre")
        })
    }

    #[inline]
    fn surface(
        &self,
        pins: &Pins,
        i: usize,
        hit: &Hit,
        ray: &Ray,
        uv: bool,
        material: u32,
    ) -> Option<Surface> {
        let mut s = sphere::surface(self.get(pins, i)?, hit.t, ray, uv, material);
        if let Some(k) = self.colors {
            s.color = pins.view(k).vec3(i).map(|c| Vec3A::from(c.as_vec3()));
        }
        Some(s)
    }
}

/// Cylinders: base centres from pin 0 and apex centres from pin 1 (f32x3 or f64x3), radii (a
/// constant or a pin of scalars), as the `cylinder` plugin gives them.
#[derive(Clone, Copy, Debug)]
pub struct CylinderReader {
    pub radius: RadiusRead,
    /// Render space's origin in world coordinates.
    pub offset: DVec3,
}

impl CylinderReader {
    /// Base, apex and radius of cylinder `i` in world coordinates.
    #[inline(always)]
    fn world(&self, pins: &Pins, i: usize) -> Option<(DVec3, DVec3, f64)> {
        let b = pins.view(0).vec3(i)?;
        let a = pins.view(1).vec3(i)?;
        let r = match self.radius {
            RadiusRead::Const(r) => r,
            RadiusRead::Each(k) => pins.view(k).scalar(i)?,
        };
        Some((b, a, r))
    }

    fn count(&self, pins: &Pins) -> usize {
        pins.view(0).len()
    }

    fn check_cylinder(&self, pins: &Pins, i: usize) -> Result<(), String> {
        let Some((b, a, r)) = self.world(pins, i) else {
            return Err(format!("cylinder {i} cannot be read"));
        };
        if !(b.is_finite() && a.is_finite() && r.is_finite()) {
            let v = [b.x, b.y, b.z, a.x, a.y, a.z, r];
            return Err(format!("cylinder {i} has a non-finite value {v:?}"));
        }
        if r <= 0.0 {
            return Err(format!(
                "cylinder {i} has radius {r}; expected a radius > 0"
            ));
        }
        if (b - self.offset).as_vec3() == (a - self.offset).as_vec3() || a == b {
            return Err(format!(
                "cylinder {i} has the same base and apex centre; expected a length > 0"
            ));
        }
        Ok(())
    }

    fn check_all(&self, pins: &Pins) -> Result<(), String> {
        let n = self.count(pins);
        let radii = ("radii", self.radius.each());
        one_each(pins, n, [("apexes", Some(1)), radii], |m, what| {
            format!("{m} {what} for {n} bases; give one per base")
        })
    }
}

impl Reader for CylinderReader {
    type Shape = Cone;
    const ELEMENT: &'static str = "cylinder";

    fn len(&self, pins: &Pins) -> usize {
        self.count(pins)
    }

    #[inline(always)]
    fn get(&self, pins: &Pins, i: usize) -> Option<Cone> {
        let (b, a, r) = self.world(pins, i)?;
        // `Set<Cone>::push_world`'s conversions.
        Some(Cone {
            base: (b - self.offset).as_vec3(),
            base_radius: r as f32,
            apex: (a - self.offset).as_vec3(),
            apex_radius: r as f32,
        })
    }

    fn check(&self, pins: &Pins, i: usize) -> Result<(), String> {
        self.check_cylinder(pins, i)
    }

    fn check_arrays(&self, pins: &Pins) -> Result<(), String> {
        self.check_all(pins)
    }

    #[inline]
    fn surface(
        &self,
        pins: &Pins,
        i: usize,
        hit: &Hit,
        ray: &Ray,
        uv: bool,
        material: u32,
    ) -> Option<Surface> {
        Some(cone::surface(&self.get(pins, i)?, hit.t, ray, uv, material))
    }
}

/// The caps of cylinders (the same arrays as a [`CylinderReader`]'s): element `2i` closes
/// cylinder `i` at its base, `2i + 1` at its apex, as the `cylinder` plugin gives them.
#[derive(Clone, Copy, Debug)]
pub struct CapReader(pub CylinderReader);

impl Reader for CapReader {
    type Shape = Disc;
    const ELEMENT: &'static str = "cap";

    fn len(&self, pins: &Pins) -> usize {
        2 * self.0.count(pins)
    }

    #[inline(always)]
    fn get(&self, pins: &Pins, j: usize) -> Option<Disc> {
        let (b, a, r) = self.0.world(pins, j / 2)?;
        // The plugin's axis (its own arithmetic, in f64), then `Set<Disc>::push_world`'s.
        let axis = [a.x - b.x, a.y - b.y, a.z - b.z];
        let h = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let w = axis.map(|x| x * (1.0 / h));
        let (center, n) = match j % 2 {
            0 => (b, DVec3::new(-w[0], -w[1], -w[2])),
            _ => (a, DVec3::from(w)),
        };
        Some(Disc {
            center: (center - self.0.offset).as_vec3(),
            normal: n.normalize().as_vec3(),
            inner: 0.0,
            outer: r as f32,
        })
    }

    fn check(&self, pins: &Pins, j: usize) -> Result<(), String> {
        self.0.check_cylinder(pins, j / 2)
    }

    fn check_arrays(&self, pins: &Pins) -> Result<(), String> {
        self.0.check_all(pins)
    }

    #[inline]
    fn surface(
        &self,
        pins: &Pins,
        j: usize,
        hit: &Hit,
        ray: &Ray,
        uv: bool,
        material: u32,
    ) -> Option<Surface> {
        Some(disc::surface(&self.get(pins, j)?, hit.t, ray, uv, material))
    }
}

/// A triangle mesh: positions from pin 0 (f32x3 or f64x3), triangles as index triples (a pin
/// of u32x3 or u64x3) or, without one, consecutive triples of positions; optional per-vertex
/// normals, linear RGB colours (f32x3 or f64x3) and texture coordinates (f32x2). Triangles of
/// zero area are kept (never hit), so an element is a triangle index whatever the vertices do.
#[derive(Clone, Copy, Debug)]
pub struct MeshReader {
    pub indices: Option<usize>,
    pub normals: Option<usize>,
    pub colors: Option<usize>,
    pub uvs: Option<usize>,
    /// Render space's origin in world coordinates.
    pub offset: DVec3,
}

impl MeshReader {
    /// Vertices.
    fn vertices(&self, pins: &Pins) -> usize {
        pins.view(0).len()
    }

    /// The vertex indices of triangle `t`.
    #[inline(always)]
    fn corners(&self, pins: &Pins, t: usize) -> Option<[u64; 3]> {
        match self.indices {
            Some(k) => pins.view(k).index3(t),
            None => {
                let first = t.checked_mul(3)? as u64;
                Some([first, first + 1, first + 2])
            }
        }
    }

    fn has_attrs(&self) -> bool {
        self.normals.is_some() || self.colors.is_some() || self.uvs.is_some()
    }

    /// Vertex `v`'s shading attributes, as `Triangles::push_mesh` stores them.
    fn attr(&self, pins: &Pins, v: usize) -> Option<VertexAttr> {
        let n = match self.normals {
            Some(k) => pins.view(k).vec3(v)?.normalize_or_zero().as_vec3(),
            None => Vec3::ZERO,
        };
        let c = match self.colors {
            Some(k) => {
                let c = pins.view(k).vec3(v)?;
                Vec3::new(c.x as f32, c.y as f32, c.z as f32)
            }
            None => Vec3::splat(-1.0),
        };
        let uv = match self.uvs {
            Some(k) => pins.view(k).vec2(v)?.map(|x| x as f32),
            None => [0.0; 2],
        };
        Some(VertexAttr { n, c, uv })
    }
}

impl Reader for MeshReader {
    type Shape = Triangle;
    const ELEMENT: &'static str = "triangle";

    fn len(&self, pins: &Pins) -> usize {
        match self.indices {
            Some(k) => pins.view(k).len(),
            None => self.vertices(pins) / 3,
        }
    }

    #[inline(always)]
    fn get(&self, pins: &Pins, t: usize) -> Option<Triangle> {
        let c = self.corners(pins, t)?;
        let p = pins.view(0);
        let at = |i: u64| -> Option<Vec3> {
            let v = p.vec3(usize::try_from(i).ok()?)?;
            Some((v - self.offset).as_vec3())
        };
        Some(Triangle {
            v: [at(c[0])?, at(c[1])?, at(c[2])?],
            attr: NO_ATTR,
        })
    }

    fn check(&self, pins: &Pins, t: usize) -> Result<(), String> {
        let nv = self.vertices(pins);
        let Some(c) = self.corners(pins, t) else {
            return Err(format!("triangle {t} cannot be read"));
        };
        for i in c {
            // The messages of `Triangles::push_mesh`.
            if i >= nv as u64 {
                return Err(format!(
                    "triangle {t} uses vertex {i}, but the mesh has {nv} vertices"
                ));
            }
            let v = i as usize;
            if !pins.view(0).vec3(v).is_some_and(|p| p.is_finite()) {
                return Err(format!("vertex {v} has a non-finite coordinate"));
            }
            if self.has_attrs() {
                let finite = self.attr(pins, v).is_some_and(|a| {
                    a.n.is_finite() && a.c.is_finite() && a.uv.iter().all(|x| x.is_finite())
                });
                if !finite {
                    return Err(format!("vertex {v} has a non-finite normal, colour or uv"));
                }
            }
        }
        Ok(())
    }

    fn check_arrays(&self, pins: &Pins) -> Result<(), String> {
        let nv = self.vertices(pins);
        if self.indices.is_none() && !nv.is_multiple_of(3) {
            return Err(format!(
                "{nv} positions and no indices: the positions are not whole triangles"
            ));
        }
        let per_vertex = [
            ("normals", self.normals),
            ("colours", self.colors),
            ("uvs", self.uvs),
        ];
        one_each(pins, nv, per_vertex, |m, what| {
            format!("mesh has {nv} vertices but {m} {what}")
        })
    }

    #[inline]
    fn surface(
        &self,
        pins: &Pins,
        t: usize,
        hit: &Hit,
        _: &Ray,
        uv: bool,
        material: u32,
    ) -> Option<Surface> {
        let tri = self.get(pins, t)?;
        let va = match self.has_attrs() {
            true => {
                let c = self.corners(pins, t)?;
                let at = |i: u64| self.attr(pins, usize::try_from(i).ok()?);
                Some([at(c[0])?, at(c[1])?, at(c[2])?])
            }
            false => None,
        };
        Some(triangle::surface(tri.v, va, hit, uv, material))
    }
}

/// Primitives read through a [`Reader`], in a BVH of their own, all of one material.
pub struct ArraySet<R> {
    pub reader: R,
    /// Leaf slot → element.
    order: Vec<u64>,
    bvh: Bvh,
    /// Packed material (no clip group).
    material: u32,
    /// The tree's normalised SAH cost when built.
    cost_at_build: f32,
}

/// The first element (lowest index) that fails `check`, and why.
fn first_error(n: usize, check: impl Fn(usize) -> Result<(), String> + Sync) -> Result<(), String> {
    let bad = if crate::bvh::serial(n) {
        (0..n).find(|&i| check(i).is_err())
    } else {
        (0..n).into_par_iter().find_first(|&i| check(i).is_err())
    };
    match bad {
        Some(i) => check(i),
        None => Ok(()),
    }
}

impl<R: Reader> ArraySet<R> {
    /// Checks every element and builds the tree over them.
    pub fn build(reader: R, pins: &Pins, material: u32) -> Result<ArraySet<R>, String> {
        reader.check_arrays(pins)?;
        let n = reader.len(pins);
        first_error(n, |i| reader.check(pins, i))?;
        let bound = |i: usize| reader.get(pins, i).map_or(Aabb::EMPTY, |s| s.bounds());
        let (bvh, order) = Bvh::build_with(n, bound);
        let cost_at_build = bvh.sah_cost();
        Ok(ArraySet {
            reader,
            order,
            bvh,
            material,
            cost_at_build,
        })
    }

    /// Checks every element and puts their new bounds into the tree (the arrays' lengths must
    /// be those of the build). Returns the refitted tree's cost over its cost when built.
    pub fn refit(&mut self, pins: &Pins) -> Result<f32, String> {
        let reader = &self.reader;
        reader.check_arrays(pins)?;
        let n = reader.len(pins);
        if n != self.order.len() {
            return Err(format!(
                "{n} {}s where the tree has {}: a refit needs the same count",
                R::ELEMENT,
                self.order.len()
            ));
        }
        first_error(n, |i| reader.check(pins, i))?;
        let order = &self.order;
        let cost = self.bvh.refit(|slot| {
            let i = order[slot] as usize;
            reader.get(pins, i).map_or(Aabb::EMPTY, |s| s.bounds())
        });
        Ok(match self.cost_at_build > 0.0 {
            true => cost / self.cost_at_build,
            false => 1.0,
        })
    }

    /// Elements in the tree.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// The packed material of every element.
    pub fn material(&self) -> u32 {
        self.material
    }

    /// Bytes of the tree and the leaf order in use.
    pub fn bytes(&self) -> u64 {
        self.bvh.used_bytes() + (self.order.len() * 8) as u64
    }

    /// The closest hit before `t_max`, if closer than `hit` (marked as object `object`).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn intersect(
        &self,
        pins: &Pins,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: &mut f32,
        hit: &mut Option<Hit>,
        c: &mut Counters,
        object: u16,
    ) {
        if self.order.is_empty() {
            return;
        }
        let prep = R::Shape::prep(ray);
        *t_max = self.bvh.intersect_ray(
            boxes,
            *t_max,
            #[inline(always)]
            |slot, tm| {
                c.tests += 1;
                let i = self.order[slot] as usize;
                let (t, b1, b2) = self.reader.get(pins, i)?.hit(ray, &prep, tm)?;
                let mut h = Hit::new(t, R::Shape::KIND, i);
                h.b1 = b1;
                h.b2 = b2;
                h.object = object;
                *hit = Some(h);
                Some(t)
            },
        );
    }

    /// Calls `on_hit(material, crossings)` for the elements the ray crosses in (0, t_max)
    /// until it returns true; returns whether it did.
    #[inline]
    pub fn any(
        &self,
        pins: &Pins,
        ray: &Ray,
        boxes: &BoxRay,
        t_max: f32,
        c: &mut Counters,
        on_hit: &mut impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.order.is_empty() {
            return false;
        }
        let prep = R::Shape::prep(ray);
        let material = super::material_of(self.material);
        self.bvh.any_ray(
            boxes,
            t_max,
            #[inline(always)]
            |slot| {
                c.tests += 1;
                let i = self.order[slot] as usize;
                let n = match self.reader.get(pins, i) {
                    Some(s) => s.crossings(ray, &prep, t_max),
                    None => 0,
                };
                n > 0 && on_hit(material, n)
            },
        )
    }

    /// The surface at a hit on element `hit.index`.
    pub fn surface(&self, pins: &Pins, hit: &Hit, ray: &Ray, uv: bool) -> Option<Surface> {
        let material = super::material_of(self.material);
        (self.reader).surface(pins, hit.index as usize, hit, ray, uv, material)
    }
}
