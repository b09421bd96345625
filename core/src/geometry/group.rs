//! A group of native sets of its own: the geometry of an animated scene's keyed objects, stored
//! for one frame at a time and rebuilt from scratch for each (so a frame never depends on the
//! frames before it). It is tested after the scene's still geometry; hits in it are marked
//! `Hit::moving`. Custom (plugin-intersected) geometry cannot be moved, so it has none. The
//! group holds the charges of its memory to the budget, given back when it is replaced.
//! A shared prototype (`instance`) is a group too, in its own object space.
//!
//! Under an open shutter, time-sampled data (`series:`) is held as [`Sweep`]s, moving
//! between its data frames at each ray's time; a hit on sweep `j` carries `object = j + 1`
//! (0: the group's own sets; moving hits are never on array objects, which `object` numbers
//! elsewhere).

use super::cone::Cones;
use super::disc::Discs;
use super::plane::Planes;
use super::sphere::Spheres;
use super::sweep::Sweep;
use super::triangle::Triangles;
use super::{Clips, Counters, Hit, Kind, Surface};
use crate::budget::{Budget, BudgetError, Charge, Use};
use crate::bvh::BUILD_BYTES_PER_PRIM;
use crate::ray::Ray;
use std::sync::Arc;

#[derive(Default)]
pub struct Group {
    pub spheres: Spheres,
    pub triangles: Triangles,
    pub planes: Planes,
    pub cones: Cones,
    pub discs: Discs,
    /// Time-sampled data moving during the shutter, one sweep per series (its own steps).
    pub sweeps: Vec<Sweep>,
    /// What the group's arrays and BVHs hold of the memory budget.
    pub charges: Vec<Charge>,
}

impl Group {
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn len(&self) -> usize {
        self.spheres.len()
            + self.triangles.len()
            + self.planes.planes.len()
            + self.cones.len()
            + self.discs.len()
            + self.sweeps.iter().map(Sweep::len).sum::<usize>()
    }

    /// Bytes of the primitives and BVHs.
    pub fn memory_bytes(&self) -> u64 {
        self.spheres.bytes()
            + self.triangles.bytes()
            + self.planes.bytes()
            + self.cones.bytes()
            + self.discs.bytes()
            + self.spheres.bvh_bytes()
            + self.triangles.set.bvh_bytes()
            + self.cones.bvh_bytes()
            + self.discs.bvh_bytes()
            + self.sweeps.iter().map(Sweep::bytes).sum::<u64>()
    }

    /// Builds every set's BVH, charging the build's working memory while it runs and the BVHs'
    /// bytes for the group's life.
    pub fn build(&mut self, budget: &Arc<Budget>) -> Result<(), BudgetError> {
        let swept: usize = self.sweeps.iter().map(Sweep::len).sum();
        let n =
            self.spheres.len() + self.triangles.len() + self.cones.len() + self.discs.len() + swept;
        let work = budget.charge(Use::Bvh, n as u64 * BUILD_BYTES_PER_PRIM, || {
            format!("building the BVHs over {n} moving primitives")
        })?;
        self.spheres.build();
        self.triangles.set.build();
        self.cones.build();
        self.discs.build();
        self.sweeps.iter_mut().for_each(Sweep::build);
        drop(work);
        let bvhs = self.spheres.bvh_bytes()
            + self.triangles.set.bvh_bytes()
            + self.cones.bvh_bytes()
            + self.discs.bvh_bytes()
            + (self.sweeps.iter())
                .flat_map(|s| s.spheres.iter().map(|s| s.bvh_bytes()))
                .sum::<u64>()
            + (self.sweeps.iter())
                .flat_map(|s| s.triangles.iter().map(|s| s.bvh_bytes()))
                .sum::<u64>();
        let held = budget.charge(Use::Bvh, bvhs, || {
            format!("the BVHs over {n} moving primitives")
        })?;
        self.charges.push(held);
        Ok(())
    }

    /// The closest hit before `t_max`, if closer than `hit`: kinds in the scene's order.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        hit: &mut Option<Hit>,
        clips: &Clips,
        c: &mut Counters,
    ) {
        if let Some(mut h) = self.closest(ray, t_max, clips, c) {
            h.moving = true;
            *hit = Some(h);
        }
    }

    /// The closest hit in the group before `t_max` (which it lowers), unmarked: kinds in the
    /// scene's order. (A shared instance's prototype is a group traced this way.)
    #[inline]
    pub fn closest(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        clips: &Clips,
        c: &mut Counters,
    ) -> Option<Hit> {
        let mut found = None;
        self.spheres.intersect(ray, t_max, &mut found, clips, c);
        self.triangles
            .set
            .intersect(ray, t_max, &mut found, clips, c);
        self.planes.intersect(ray, t_max, &mut found, clips, c);
        self.cones.intersect(ray, t_max, &mut found, clips, c);
        self.discs.intersect(ray, t_max, &mut found, clips, c);
        for (j, sweep) in self.sweeps.iter().enumerate() {
            if let Some(mut h) = sweep.closest(ray, t_max, clips, c) {
                // The loader keeps the series' count within u16.
                h.object = (j + 1) as u16;
                found = Some(h);
            }
        }
        found
    }

    /// Calls `on_hit(material, crossings)` for what the ray crosses in (0, t_max) until it
    /// returns true; returns whether it did.
    #[inline]
    pub fn any(
        &self,
        ray: &Ray,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        on_hit: &mut impl FnMut(u32, u32) -> bool,
    ) -> bool {
        self.spheres.any(ray, t_max, clips, c, &mut *on_hit)
            || self.triangles.set.any(ray, t_max, clips, c, &mut *on_hit)
            || self.planes.any(ray, t_max, clips, c, &mut *on_hit)
            || self.cones.any(ray, t_max, clips, c, &mut *on_hit)
            || self.discs.any(ray, t_max, clips, c, &mut *on_hit)
            || (self.sweeps.iter()).any(|s| s.any(ray, t_max, clips, c, &mut *on_hit))
    }

    pub fn surface(&self, hit: &Hit, ray: &Ray, textured: bool) -> Surface {
        if let Some(sweep) = (hit.object as usize).checked_sub(1) {
            return self.sweeps[sweep].surface(hit, ray, textured);
        }
        match hit.kind {
            Kind::Sphere => self.spheres.surface(hit, ray, textured),
            Kind::Triangle => self.triangles.surface(hit, textured),
            Kind::Plane => self.planes.surface(hit, ray, textured),
            Kind::Cone => self.cones.surface(hit, ray, textured),
            // The group holds no custom geometry: a hit can only be on a disc here.
            Kind::Disc | Kind::Custom => self.discs.surface(hit, ray, textured),
        }
    }
}
