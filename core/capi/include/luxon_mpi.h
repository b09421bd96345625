/* Luxon's C API with MPI: give a renderer the caller's communicator as an MPI_Comm.
 *
 * Written by hand (not generated): luxon.h never includes mpi.h, so that programs without MPI
 * can use it; this header adds the MPI_Comm form of luxon_renderer_set_mpi_comm_f. Include it
 * after mpi.h, with a libluxon built with the cargo feature `mpi` (luxon_has_mpi() is true;
 * otherwise the call returns LUXON_ERROR_UNSUPPORTED).
 *
 * The rules (see luxon_renderer_set_mpi_comm_f in luxon.h): the caller owns MPI (Luxon never
 * calls MPI_Init, MPI_Finalize or MPI_Abort and never uses MPI_COMM_WORLD on its own); setting
 * the communicator and every luxon_render are collective over it; rank 0 of the communicator
 * receives the image; release the renderer before MPI_Finalize; with MPI_THREAD_FUNNELED call
 * Luxon from the thread that initialised MPI; a rank killed by a signal leaves the others
 * waiting. */

#ifndef LUXON_MPI_H
#define LUXON_MPI_H

#include <mpi.h>

#include "luxon.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Renders on `renderer` become image-parallel over the ranks of `comm` (a duplicate of it:
 * collective, every rank of `comm` calls this). */
static inline luxon_status luxon_renderer_set_mpi_comm(luxon_renderer renderer, MPI_Comm comm)
{
    return luxon_renderer_set_mpi_comm_f(renderer, (int)MPI_Comm_c2f(comm));
}

#ifdef __cplusplus
}
#endif

#endif /* LUXON_MPI_H */
