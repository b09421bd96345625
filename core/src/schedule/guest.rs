//! What a library (guest) use of MPI needs beyond rsmpi's safe API (feature `mpi`): the checks
//! made before every MPI call on a caller's behalf, a communicator from a Fortran handle, and
//! the wrapper that lets a renderer holding a communicator move between threads.
//!
//! In guest mode the caller owns MPI: Luxon never initialises or finalises it, never uses
//! `MPI_COMM_WORLD` on its own and never aborts; it works on a duplicate of the caller's
//! communicator, so its messages never meet the caller's.

use super::cluster::Cluster;
use crate::error::Error;
use mpi::environment::{is_finalized, is_initialized, threading_support};
use mpi::ffi;
use mpi::topology::SimpleCommunicator;
use mpi::traits::FromRaw;
use mpi::Threading;
use std::os::raw::c_int;

/// Whether this thread may call MPI for the caller now: MPI is initialised and not finalised,
/// and its thread level allows this thread (`MPI_THREAD_SERIALIZED` and `MULTIPLE`: any
/// thread; `FUNNELED` and `SINGLE`: the thread that initialised MPI). Luxon's MPI calls are
/// made only by the thread that calls it (never by render threads), so that is all it needs.
pub fn usable_here() -> Result<(), Error> {
    if !is_initialized() {
        return Err(Error::Mpi(
            "MPI is not initialised: call MPI_Init_thread before giving Luxon a communicator \
             (Luxon never initialises MPI for a library caller)"
                .into(),
        ));
    }
    if is_finalized() {
        return Err(Error::Mpi(
            "MPI has been finalised: Luxon cannot use a communicator after MPI_Finalize \
             (release renderers with a communicator before it)"
                .into(),
        ));
    }
    let level = threading_support();
    if matches!(level, Threading::Funneled | Threading::Single) && !is_thread_main() {
        let name = match level {
            Threading::Single => "MPI_THREAD_SINGLE",
            _ => "MPI_THREAD_FUNNELED",
        };
        return Err(Error::Mpi(format!(
            "MPI was initialised with {name} and Luxon was called from another thread than \
             the one that initialised it; call it from that thread or initialise MPI with \
             MPI_THREAD_SERIALIZED"
        )));
    }
    Ok(())
}

/// `MPI_Is_thread_main` (MPI is initialised and not finalised).
fn is_thread_main() -> bool {
    let mut flag: c_int = 0;
    // SAFETY: `usable_here` checked that MPI is initialised and not finalised; MPI_Is_thread_main
    // may be called from any thread at any thread level, and writes only `flag`, a local.
    unsafe { ffi::MPI_Is_thread_main(&mut flag) };
    flag != 0
}

/// A duplicate (`MPI_Comm_dup`, collective over the communicator) of the communicator whose
/// Fortran handle is `handle` (`MPI_Comm_c2f` of a C `MPI_Comm`); the caller keeps its own.
pub fn duplicate_fortran(handle: i32) -> Result<SimpleCommunicator, Error> {
    usable_here()?;
    // SAFETY: MPI is initialised and not finalised, and this thread may call it (checked
    // above); MPI_Comm_f2c only converts the integer (an unknown one gives MPI_COMM_NULL).
    let raw = unsafe { ffi::RSMPI_Comm_f2c(handle as ffi::RSMPI_Fint) };
    // SAFETY: reads rsmpi's constant handle.
    if raw == unsafe { ffi::RSMPI_COMM_NULL } {
        return Err(Error::Mpi(format!(
            "Fortran handle {handle} is not a communicator (MPI_Comm_f2c gives MPI_COMM_NULL)"
        )));
    }
    let mut inter: c_int = 0;
    // SAFETY: as above; `raw` is a communicator handle (not null), `inter` a local.
    unsafe { ffi::MPI_Comm_test_inter(raw, &mut inter) };
    if inter != 0 {
        return Err(Error::Mpi(format!(
            "Fortran handle {handle} is an inter-communicator; Luxon renders over an \
             intra-communicator"
        )));
    }
    // SAFETY: as above; `dup` is a local that MPI_Comm_dup writes.
    let dup = unsafe {
        let mut dup = ffi::RSMPI_COMM_NULL;
        ffi::MPI_Comm_dup(raw, &mut dup);
        dup
    };
    // SAFETY: `dup` is a new intra-communicator of our own (not a system handle), used only
    // through the value returned, which frees it when dropped.
    Ok(unsafe { SimpleCommunicator::from_raw(dup) })
}

/// A guest-mode [`Cluster`] that may move between threads: held by a renderer (which must be
/// `Send + Sync`) in a `Mutex`, so only one thread drives it at a time.
pub struct Guest(pub Cluster);

// SAFETY: the cluster holds an MPI communicator handle, a plain value that any thread may pass
// to MPI when the thread level allows that thread; `usable_here` checks that before every use
// (and the renderer's `Mutex` keeps two threads from using it at once). rsmpi marks it !Send
// only because the handle is a raw pointer in some MPI libraries.
unsafe impl Send for Guest {}
