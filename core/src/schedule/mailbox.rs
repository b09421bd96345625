//! Passing tiles and chunks between a rank's main thread (the only one that talks MPI) and its
//! render threads (feature `mpi`).

use mpi::ffi;
use mpi::topology::SimpleCommunicator;
use mpi::traits::AsRaw;
use std::collections::VecDeque;
use std::os::raw::{c_int, c_void};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How long the main thread sleeps between polls.
pub(super) const POLL: Duration = Duration::from_micros(500);

/// Chunks on their way to rank 0. Non-blocking sends: a blocking send of a large message waits
/// for rank 0 to poll, and OpenMPI waits by spinning, which takes a core from the renderers.
pub(super) struct Outbox<'c> {
    comm: &'c SimpleCommunicator,
    /// Sends not known to be complete, each with the buffer MPI may still be reading.
    pending: Vec<(ffi::MPI_Request, Vec<u8>)>,
}

impl<'c> Outbox<'c> {
    pub(super) fn new(comm: &'c SimpleCommunicator) -> Outbox<'c> {
        Outbox {
            comm,
            pending: Vec::new(),
        }
    }

    pub(super) fn send(&mut self, bytes: Vec<u8>, tag: i32) -> Result<(), String> {
        let Ok(len) = c_int::try_from(bytes.len()) else {
            return Err("a chunk is too large for one MPI message".into());
        };
        // SAFETY: MPI is up (a `SimpleCommunicator` exists only while it is) and `comm` is a
        // live communicator; the `RSMPI_*` statics are rsmpi's constant handles. The send reads
        // `len` bytes of `bytes` until it completes: the buffer is heap memory that moves into
        // `pending` with its request (moving a `Vec` does not move its buffer) and is freed
        // only once `MPI_Test` reports the send complete (`progress`), or after waiting for
        // that (`Drop`); `req` is a local.
        let (code, req) = unsafe {
            let mut req = ffi::RSMPI_REQUEST_NULL;
            let code = ffi::MPI_Isend(
                bytes.as_ptr() as *const c_void,
                len,
                ffi::RSMPI_UINT8_T,
                0,
                tag,
                self.comm.as_raw(),
                &mut req,
            );
            (code, req)
        };
        if code != 0 {
            return Err("MPI_Isend failed".into());
        }
        self.pending.push((req, bytes));
        Ok(())
    }

    /// Drops the buffers of completed sends.
    pub(super) fn progress(&mut self) {
        self.pending.retain_mut(|(req, _)| {
            let mut done: c_int = 0;
            // SAFETY: `req` is a request of `MPI_Isend` not yet reported complete (those are
            // removed here), `done` a local, and `RSMPI_STATUS_IGNORE` rsmpi's constant.
            unsafe { ffi::MPI_Test(req, &mut done, ffi::RSMPI_STATUS_IGNORE) };
            done == 0
        });
    }

    pub(super) fn flush(&mut self) {
        while !self.pending.is_empty() {
            self.progress();
            std::thread::sleep(POLL);
        }
    }
}

impl Drop for Outbox<'_> {
    /// Buffers of unfinished sends must outlive them (nothing to wait for after `flush`).
    fn drop(&mut self) {
        self.flush();
    }
}

/// Every message is bytes (MPI matches datatypes); numbers are native-endian u64.
pub(super) fn bytes_of(v: u64) -> [u8; 8] {
    v.to_ne_bytes()
}

pub(super) fn word(bytes: &[u8]) -> u64 {
    bytes
        .get(..8)
        .and_then(|b| b.try_into().ok())
        .map_or(0, u64::from_ne_bytes)
}

/// Tiles a follower has been given and not yet started; `pop` waits for one (and counts the
/// waits: the follower then asks further ahead).
#[derive(Default)]
pub(super) struct TileQueue {
    state: Mutex<(VecDeque<usize>, bool)>,
    ready: Condvar,
    pub(super) starved: AtomicUsize,
}

impl TileQueue {
    pub(super) fn push(&self, i: usize) {
        self.state
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .0
            .push_back(i);
        self.ready.notify_one();
    }
    pub(super) fn close(&self) {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).1 = true;
        self.ready.notify_all();
    }
    pub(super) fn pop(&self) -> Option<usize> {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if let Some(i) = s.0.pop_front() {
                return Some(i);
            }
            if s.1 {
                return None;
            }
            self.starved.fetch_add(1, Ordering::Relaxed);
            s = self.ready.wait(s).unwrap_or_else(|e| e.into_inner());
        }
    }
}
