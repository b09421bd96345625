//! A volume's account with the memory budget: every dense brick, the brick map's growth and
//! the finished tables are charged before they are allocated, and allocated without aborting.
//! What a finished volume holds stays charged; a volume that fails gives everything back.

use super::{Brick, BrickMap};
use crate::budget::{bytes, Budget, Use};
use std::sync::Arc;

pub(super) struct Charger {
    budget: Arc<Budget>,
    /// The volume's name, for messages.
    name: String,
    /// Bytes charged for the volume so far.
    held: u64,
    /// Whether a charge failed: the budget (or the system) refused memory, as opposed to bad data.
    refused: bool,
}

/// Bytes a map entry of `T` takes (its key and value, and hashbrown's control byte).
pub(super) fn entry_bytes<T>() -> u64 {
    (std::mem::size_of::<([i64; 3], T)>() + 1) as u64
}

impl Charger {
    pub(super) fn new(budget: Arc<Budget>, name: &str) -> Charger {
        Charger {
            budget,
            name: name.to_string(),
            held: 0,
            refused: false,
        }
    }

    pub(super) fn budget(&self) -> &Arc<Budget> {
        &self.budget
    }

    /// Charges `n` more bytes for the volume, or says that it does not fit.
    pub(super) fn add(&mut self, n: u64) -> Result<(), String> {
        let (name, held) = (&self.name, self.held);
        let charged = self.budget.reserve(Use::Volumes, n, || {
            format!("volume `{name}` (its storage so far: {})", bytes(held))
        });
        self.refused |= charged.is_err();
        charged?;
        self.held += n;
        Ok(())
    }

    /// Gives back `n` bytes (of storage freed).
    pub(super) fn sub(&mut self, n: u64) {
        let n = n.min(self.held);
        self.budget.release(Use::Volumes, n);
        self.held -= n;
    }

    /// The error for `n` bytes the system refused.
    pub(super) fn refused(&mut self, n: u64) -> String {
        self.refused = true;
        self.budget.refused(n, &format!("volume `{}`", self.name)).0
    }

    /// Whether the volume failed for want of memory (the budget's or the system's).
    pub(super) fn was_refused(&self) -> bool {
        self.refused
    }

    /// The bytes charged stay charged for the finished volume's life (its budget's).
    pub(super) fn keep(&mut self) {
        self.held = 0;
    }

    /// Room in `map` for one more entry, its growth charged first.
    pub(super) fn room_for_one<T>(&mut self, map: &mut BrickMap<T>) -> Result<(), String> {
        let before = map.capacity();
        if map.len() < before {
            return Ok(());
        }
        let want = (before * 2).max(64);
        let per = entry_bytes::<T>();
        self.add((want - before) as u64 * per)?;
        if map.try_reserve(want - map.len()).is_err() {
            self.sub((want - before) as u64 * per);
            return Err(self.refused((want - before) as u64 * per));
        }
        // The table may round its size up: charge what it really took.
        let more = map.capacity().saturating_sub(want) as u64 * per;
        if more > 0 {
            self.add(more)?;
        }
        Ok(())
    }

    /// A new dense brick, charged (`partial`: its unset voxels must read as `background`).
    pub(super) fn brick(
        &mut self,
        make: impl FnOnce() -> Option<Brick>,
        size: u64,
    ) -> Result<Brick, String> {
        self.add(size)?;
        make().ok_or_else(|| {
            self.sub(size);
            self.refused(size)
        })
    }
}

impl Drop for Charger {
    /// A volume that never finished gives its bytes back.
    fn drop(&mut self) {
        self.budget.release(Use::Volumes, self.held);
    }
}
