//! Ids of the parts of a scene. Those that can be removed (lights, objects) are
//! generation-checked slots, so an id outlives its part safely (a removed part's id is refused,
//! never taken for the part that reuses its slot); materials and clip groups are never removed
//! and are numbered. Every id carries its scene's serial, so another scene's id is refused.

use crate::error::Error;
use std::fmt;
use std::marker::PhantomData;
use std::sync::atomic::{AtomicU32, Ordering};

/// What a kind of id is called in messages (`light 3 was removed from this scene`).
pub trait Kind {
    const NAME: &'static str;
}

/// The kind of [`LightId`].
#[derive(Debug)]
pub enum Light {}
/// The kind of [`ObjectId`].
#[derive(Debug)]
pub enum Object {}

impl Kind for Light {
    const NAME: &'static str = "light";
}
impl Kind for Object {
    const NAME: &'static str = "object";
}

/// A part of one scene: its slot, the slot's generation when the part was added, and the
/// scene's serial. Copied freely; checked on every use.
pub struct Id<K> {
    scene: u32,
    slot: u32,
    generation: u32,
    kind: PhantomData<fn() -> K>,
}

/// A light of a scene ([`super::Scene::add_light`]).
pub type LightId = Id<Light>;
/// An object of a scene ([`super::Scene::add_plugin_object`]).
pub type ObjectId = Id<Object>;

// Written out: derives would ask `K` for the same traits.
impl<K> Clone for Id<K> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<K> Copy for Id<K> {}
impl<K> PartialEq for Id<K> {
    fn eq(&self, o: &Self) -> bool {
        (self.scene, self.slot, self.generation) == (o.scene, o.slot, o.generation)
    }
}
impl<K> Eq for Id<K> {}
impl<K> std::hash::Hash for Id<K> {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        (self.scene, self.slot, self.generation).hash(h);
    }
}
impl<K: Kind> fmt::Debug for Id<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} {} (generation {})",
            K::NAME,
            self.slot,
            self.generation
        )
    }
}
impl<K: Kind> fmt::Display for Id<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", K::NAME, self.slot)
    }
}

/// A material of a scene ([`super::Scene::set_material`]): its number in the built scene
/// (0: the default material). Materials are added or changed, never removed, so their numbers
/// never move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId {
    pub(super) scene: u32,
    pub(super) index: u32,
}

/// A clip group of a scene ([`super::Scene::clip_group`]): its place among the scene's groups.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ClipId {
    pub(super) scene: u32,
    pub(super) index: u32,
}

/// A process-unique serial for a new scene.
pub(super) fn scene_serial() -> u32 {
    static NEXT: AtomicU32 = AtomicU32::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// The ids of one kind of part of one scene, and the parts' order in the scene. The parts
/// themselves stay in the description (in this order: index `i` of [`Slots::position`] is the
/// description's `i`-th light or object), so a scene loaded from a file keeps its file order
/// and builds exactly as the file does.
pub(super) struct Slots<K> {
    scene: u32,
    /// Per slot: its generation, and whether a part holds it.
    slots: Vec<(u32, bool)>,
    /// The slots held, in the scene's order.
    order: Vec<u32>,
    /// Slots free for reuse.
    free: Vec<u32>,
    kind: PhantomData<fn() -> K>,
}

impl<K: Kind> Slots<K> {
    /// `n` parts, in order (a loaded scene's).
    pub(super) fn new(scene: u32, n: usize) -> Slots<K> {
        Slots {
            scene,
            slots: vec![(0, true); n],
            order: (0..n as u32).collect(),
            free: Vec::new(),
            kind: PhantomData,
        }
    }

    /// A new part, after the others.
    pub(super) fn insert(&mut self) -> Id<K> {
        let slot = match self.free.pop() {
            Some(s) => s,
            None => {
                self.slots.push((0, false));
                (self.slots.len() - 1) as u32
            }
        };
        let s = &mut self.slots[slot as usize];
        s.1 = true;
        self.order.push(slot);
        Id {
            scene: self.scene,
            slot,
            generation: s.0,
            kind: PhantomData,
        }
    }

    /// Where `id`'s part is in the scene's order, or why it is refused.
    pub(super) fn position(&self, id: Id<K>) -> Result<usize, Error> {
        if id.scene != self.scene {
            return Err(Error::Api(format!(
                "this {} id belongs to another scene",
                K::NAME
            )));
        }
        let held = self.slots.get(id.slot as usize) == Some(&(id.generation, true));
        let at = self.order.iter().position(|&s| s == id.slot);
        match at.filter(|_| held) {
            Some(i) => Ok(i),
            None => Err(Error::Api(format!("{id} was removed from this scene"))),
        }
    }

    /// Removes `id`'s part; returns where it was. Its id is refused from now on.
    pub(super) fn remove(&mut self, id: Id<K>) -> Result<usize, Error> {
        let i = self.position(id)?;
        self.order.remove(i);
        let s = &mut self.slots[id.slot as usize];
        *s = (s.0.wrapping_add(1), false);
        self.free.push(id.slot);
        Ok(i)
    }

    /// The parts' ids, in the scene's order.
    pub(super) fn ids(&self) -> Vec<Id<K>> {
        let id = |&slot: &u32| Id {
            scene: self.scene,
            slot,
            generation: self.slots[slot as usize].0,
            kind: PhantomData,
        };
        self.order.iter().map(id).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_removed_id_is_refused_and_its_slot_reused_with_a_new_generation() {
        let mut s: Slots<Light> = Slots::new(7, 2);
        let ids = s.ids();
        assert_eq!(s.position(ids[1]).unwrap(), 1);
        assert_eq!(s.remove(ids[0]).unwrap(), 0);
        assert_eq!(s.position(ids[1]).unwrap(), 0);
        let e = s.position(ids[0]).unwrap_err().to_string();
        assert_eq!(e, "light 0 was removed from this scene");
        assert!(s.remove(ids[0]).is_err());
        let again = s.insert();
        assert_eq!(again.to_string(), "light 0");
        assert_ne!(again, ids[0]);
        assert_eq!(s.position(again).unwrap(), 1);
        assert!(s.position(ids[0]).is_err());
        assert_eq!(s.ids(), vec![ids[1], again]);
    }

    #[test]
    fn another_scenes_id_is_refused() {
        let mut a: Slots<Object> = Slots::new(1, 0);
        let b: Slots<Object> = Slots::new(2, 0);
        let id = a.insert();
        let e = b.position(id).unwrap_err().to_string();
        assert_eq!(e, "this object id belongs to another scene");
    }
}
