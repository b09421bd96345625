//! Handles: what the caller holds is a number naming a slot of a process-wide table, checked
//! on every use (kind, slot, generation, poison), so a NULL, released or mixed-up handle is an
//! error, never a dangling pointer.

use crate::guard::{hold, Poison};
use crate::status::{Failure, LUXON_ERROR_INVALID_HANDLE};
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, RwLock};

/// A context: the plugins found and a thread pool. `{0}` is the null handle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct luxon_context {
    pub id: u64,
}

/// A scene kept between renders. `{0}` is the null handle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct luxon_scene {
    pub id: u64,
}

/// A renderer: renders scenes on its thread pool into the caller's buffers. `{0}` is the null
/// handle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct luxon_renderer {
    pub id: u64,
}

/// A part of one scene (a light or an object), valid until it is removed or its scene is
/// released. `{0}` is the null handle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct luxon_object {
    pub id: u64,
}

/// An array of the caller's (read in place) or Luxon's copy of one, for the array objects and
/// volumes of scenes (see `luxon_array_create_shared`). `{0}` is the null handle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct luxon_array {
    pub id: u64,
}

/// The kinds of handle, in the top 4 bits of an id (0 is never used, so no valid id is 0).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Context = 1,
    Scene = 2,
    Renderer = 3,
    Object = 4,
    Array = 5,
}

impl Kind {
    fn name(self) -> &'static str {
        kind_name(self as u64).unwrap_or("?")
    }
}

fn kind_name(code: u64) -> Option<&'static str> {
    match code {
        1 => Some("luxon_context"),
        2 => Some("luxon_scene"),
        3 => Some("luxon_renderer"),
        4 => Some("luxon_object"),
        5 => Some("luxon_array"),
        _ => None,
    }
}

const GENERATION_BITS: u32 = 28;
const GENERATION_MASK: u32 = (1 << GENERATION_BITS) - 1;

/// An id: kind (4 bits) | generation (28 bits) | slot index + 1 (32 bits). A slot's generation
/// grows at each release (wrapping after 2^28 reuses of one slot).
fn pack(kind: Kind, generation: u32, index: usize) -> u64 {
    (kind as u64) << 60 | u64::from(generation & GENERATION_MASK) << 32 | (index as u64 + 1)
}

/// What a handle names, with the flag an internal error sets.
pub(crate) struct Entry<T> {
    pub value: T,
    pub id: u64,
    poisoned: AtomicBool,
}

impl<T: Send + Sync> Poison for Entry<T> {
    fn flag(&self) -> &AtomicBool {
        &self.poisoned
    }
}

struct Slot<T> {
    generation: u32,
    value: Option<Arc<Entry<T>>>,
}

struct Slots<T> {
    slots: Vec<Slot<T>>,
    free: Vec<usize>,
}

/// The live handles of one kind. A call takes its entry's `Arc` under the read lock and lets
/// the lock go before it works, so a long render never blocks other handles; a release during
/// a call leaves the call its `Arc` (the object goes when the call ends).
pub(crate) struct Table<T> {
    kind: Kind,
    slots: RwLock<Slots<T>>,
}

impl<T: Send + Sync + 'static> Table<T> {
    pub const fn new(kind: Kind) -> Table<T> {
        Table {
            kind,
            slots: RwLock::new(Slots {
                slots: Vec::new(),
                free: Vec::new(),
            }),
        }
    }

    /// A new handle for `value`.
    pub fn insert(&self, value: T) -> Result<u64, Failure> {
        let mut s = self.slots.write().unwrap_or_else(|e| e.into_inner());
        let index = match s.free.pop() {
            Some(i) => i,
            None => {
                if s.slots.len() >= u32::MAX as usize {
                    return Err(Failure::new(
                        crate::status::LUXON_ERROR_OUT_OF_MEMORY,
                        format!("too many {} handles alive", self.kind.name()),
                    ));
                }
                s.slots.push(Slot {
                    generation: 1,
                    value: None,
                });
                s.slots.len() - 1
            }
        };
        let id = pack(self.kind, s.slots[index].generation, index);
        s.slots[index].value = Some(Arc::new(Entry {
            value,
            id,
            poisoned: AtomicBool::new(false),
        }));
        Ok(id)
    }

    /// The entry `id` names, held by the running call (poisoned if it panics).
    pub fn get(&self, id: u64) -> Result<Arc<Entry<T>>, Failure> {
        let entry = self.find(id)?;
        if entry.poisoned.load(std::sync::atomic::Ordering::SeqCst) {
            return Err(Failure::new(
                LUXON_ERROR_INVALID_HANDLE,
                format!(
                    "{} {id:#x} is unusable after an internal error; release it",
                    self.kind.name()
                ),
            ));
        }
        hold(entry.clone());
        Ok(entry)
    }

    /// Takes the entry out: the handle is invalid from now on (a poisoned one too).
    pub fn release(&self, id: u64) -> Result<Arc<Entry<T>>, Failure> {
        self.find(id)?;
        let mut s = self.slots.write().unwrap_or_else(|e| e.into_inner());
        let index = (id & 0xFFFF_FFFF) as usize - 1;
        let slot = &mut s.slots[index];
        // Checked again under the write lock: another thread may have released it meanwhile.
        let taken = match slot.value.take() {
            Some(e) if e.id == id => e,
            other => {
                slot.value = other;
                return Err(self.released(id));
            }
        };
        slot.generation = slot.generation.wrapping_add(1) & GENERATION_MASK;
        s.free.push(index);
        Ok(taken)
    }

    fn find(&self, id: u64) -> Result<Arc<Entry<T>>, Failure> {
        let kind = self.kind.name();
        if id == 0 {
            return Err(Failure::new(
                LUXON_ERROR_INVALID_HANDLE,
                format!("the {kind} is null"),
            ));
        }
        if id >> 60 != self.kind as u64 {
            let message = match kind_name(id >> 60) {
                Some(other) => format!("this handle is a {other}, expected a {kind}"),
                None => format!("{id:#x} is not a Luxon handle; expected a {kind}"),
            };
            return Err(Failure::new(LUXON_ERROR_INVALID_HANDLE, message));
        }
        let s = self.slots.read().unwrap_or_else(|e| e.into_inner());
        let index = (id & 0xFFFF_FFFF) as usize;
        match index.checked_sub(1).and_then(|i| s.slots.get(i)) {
            Some(Slot { value: Some(e), .. }) if e.id == id => Ok(e.clone()),
            _ => Err(self.released(id)),
        }
    }

    fn released(&self, id: u64) -> Failure {
        Failure::new(
            LUXON_ERROR_INVALID_HANDLE,
            format!(
                "{} {id:#x} was released (or never created)",
                self.kind.name()
            ),
        )
    }
}
