//! MPI owned by the caller: a renderer's communicator, given by its Fortran handle so that
//! `luxon.h` never includes `mpi.h` (`include/luxon_mpi.h` adds the `MPI_Comm` form).

use crate::guard::guard;
use crate::handles::luxon_renderer;
use crate::renderer::RENDERERS;
#[cfg(not(feature = "mpi"))]
use crate::status::LUXON_ERROR_UNSUPPORTED;
use crate::status::{luxon_status, Failure};
use luxon_core::api::Renderer;
use std::os::raw::c_int;

/// From now on, renders on `renderer` are image-parallel over the ranks of the communicator
/// whose Fortran handle is `fortran_comm`: C callers pass `MPI_Comm_c2f(comm)` (or use
/// `luxon_renderer_set_mpi_comm` of `luxon_mpi.h`), Fortran callers their integer
/// communicator. Luxon works on a duplicate (`MPI_Comm_dup`), so the call is collective: every
/// rank of the communicator makes it.
///
/// Then every rank holds the whole scene and calls `luxon_render` with a target of the same
/// size (collective too); rank 0 of the communicator receives the whole image, the same bits
/// as one process renders (other ranks' targets are not written: they may give
/// `LUXON_PIXELS_NONE` without a depth plane). A failure on any rank (its scene, a plugin, an
/// internal error) is returned on every rank, naming the first failing rank; the job goes on.
/// Only a call refused for its own arguments (a NULL or malformed target, a released handle)
/// returns on its rank alone, before any MPI call: the other ranks then wait.
///
/// Rules: the caller owns MPI. Luxon never calls `MPI_Init` or `MPI_Finalize`, never uses
/// `MPI_COMM_WORLD` on its own and never aborts. Call this after `MPI_Init_thread` and release
/// the renderer before `MPI_Finalize` (else `LUXON_ERROR_MPI`). Only the thread that calls
/// Luxon makes its MPI calls: with `MPI_THREAD_FUNNELED` (or `SINGLE`) call it from the thread
/// that initialised MPI, with `MPI_THREAD_SERIALIZED` from any thread while no other MPI call
/// runs, with `MPI_THREAD_MULTIPLE` from any thread. A rank killed by a signal still leaves
/// the others waiting in `luxon_render`.
///
/// Returns `LUXON_ERROR_UNSUPPORTED` when this library was built without MPI (the cargo
/// feature `mpi`; see `luxon_has_mpi`), `LUXON_ERROR_MPI` when MPI is not usable as above or
/// `fortran_comm` is not a communicator.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_renderer_set_mpi_comm_f(
    renderer: luxon_renderer,
    fortran_comm: c_int,
) -> luxon_status {
    guard("luxon_renderer_set_mpi_comm_f", || {
        let r = RENDERERS.get(renderer.id)?;
        set_communicator(&r.value.renderer, fortran_comm)
    })
}

#[cfg(feature = "mpi")]
fn set_communicator(r: &Renderer, fortran_comm: c_int) -> Result<(), Failure> {
    Ok(r.set_fortran_communicator(fortran_comm)?)
}

#[cfg(not(feature = "mpi"))]
fn set_communicator(_: &Renderer, _: c_int) -> Result<(), Failure> {
    Err(Failure::new(
        LUXON_ERROR_UNSUPPORTED,
        "this libluxon was built without MPI: rebuild it with the cargo feature `mpi` \
         (cargo build --release --features mpi)",
    ))
}

/// Whether `r` renders over a communicator (then its ranks above 0 may give a target without
/// planes).
#[cfg(feature = "mpi")]
pub(crate) fn has_communicator(r: &Renderer) -> bool {
    r.communicator().is_some()
}

#[cfg(not(feature = "mpi"))]
pub(crate) fn has_communicator(_: &Renderer) -> bool {
    false
}
