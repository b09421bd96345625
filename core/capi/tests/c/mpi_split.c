/* Compiled by tests/mpi.rs with mpicc (C99, -Wall -Wextra -Werror), linked against a libluxon
 * built with MPI, and run as `mpirun -np 4 mpi_split SCENE OUTDIR`: a simulation-like job that
 * splits its world in two. Ranks 0-1 render SCENE through the C API over their half (the
 * communicator given with luxon_renderer_set_mpi_comm) while ranks 2-3 run 2,000 allreduces on
 * theirs; then every rank meets in a world barrier. Rank 0 writes the image (RGBA f32) to
 * OUTDIR/image.f32; with LUXON_TEST_FAIL_RANK set the renders must fail, and each rendering
 * rank writes the message it got to OUTDIR/error-RANK.txt. Every rank that got through writes
 * OUTDIR/finished-RANK.txt. MPI is initialised with MPI_THREAD_FUNNELED and Luxon is called
 * from the main thread. */
#include <mpi.h>

#include "luxon_mpi.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 97
#define H 61

static int write_file(const char *dir, const char *name, const void *data, size_t bytes) {
    char path[4096];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "wb");
    if (!f || fwrite(data, 1, bytes, f) != bytes) {
        fprintf(stderr, "mpi_split: cannot write %s\n", path);
        if (f) {
            fclose(f);
        }
        return 1;
    }
    return fclose(f) != 0;
}

#define CHECK(call)                                                                   \
    do {                                                                              \
        luxon_status s_ = (call);                                                     \
        if (s_ != LUXON_OK) {                                                         \
            fprintf(stderr, "mpi_split: rank %d: %s: status %d: %s\n", rank, #call,   \
                    (int)s_, luxon_last_error());                                     \
            return 1;                                                                 \
        }                                                                             \
    } while (0)

/* Ranks 0-1: two renders over `half` (the same renderer: nothing of the first may disturb the
 * second). */
static int render_half(MPI_Comm half, const char *scene_path, const char *out) {
    luxon_context ctx = {0};
    luxon_renderer renderer = {0};
    luxon_scene scene = {0};
    luxon_target target;
    luxon_status status;
    int rank, round, failing = getenv("LUXON_TEST_FAIL_RANK") != NULL, code = 0;
    float *pixels = (float *)calloc((size_t)W * H * 4, sizeof(float));

    MPI_Comm_rank(half, &rank);
    if (!pixels) {
        return 1;
    }
    CHECK(luxon_has_mpi() ? LUXON_OK : LUXON_ERROR_UNSUPPORTED);
    CHECK(luxon_context_create(NULL, &ctx));
    CHECK(luxon_renderer_create(ctx, 2, &renderer));
    CHECK(luxon_renderer_set_mpi_comm(renderer, half));
    CHECK(luxon_scene_load(ctx, scene_path, &scene));

    memset(&target, 0, sizeof target);
    target.size = sizeof target;
    target.width = W;
    target.height = H;
    /* Rank 0 receives the image; the others give a target without pixels. */
    target.format = rank == 0 ? LUXON_PIXELS_RGBA32F : LUXON_PIXELS_NONE;
    target.pixels = rank == 0 ? pixels : NULL;
    for (round = 0; round < 2; round++) {
        status = luxon_render(renderer, scene, &target, NULL);
        if (failing) {
            char name[64];
            const char *message = luxon_last_error();
            if (status == LUXON_OK) {
                fprintf(stderr, "mpi_split: rank %d: the render did not fail\n", rank);
                code = 1;
            }
            snprintf(name, sizeof name, "error-%d.txt", rank);
            code |= write_file(out, name, message, strlen(message));
        } else if (status != LUXON_OK) {
            fprintf(stderr, "mpi_split: rank %d: luxon_render: status %d: %s\n", rank,
                    (int)status, luxon_last_error());
            code = 1;
        } else if (rank == 0) {
            code |= write_file(out, "image.f32", pixels, (size_t)W * H * 4 * sizeof(float));
        }
    }
    /* Before MPI_Finalize: the renderer frees its duplicate communicator. */
    CHECK(luxon_scene_release(scene));
    CHECK(luxon_renderer_release(renderer));
    CHECK(luxon_context_release(ctx));
    free(pixels);
    return code;
}

/* Ranks 2-3: collectives of their own while the others render. */
static int collectives(MPI_Comm half, int rank) {
    int i;
    for (i = 0; i < 2000; i++) {
        long mine = i + rank, sum = 0;
        MPI_Allreduce(&mine, &sum, 1, MPI_LONG, MPI_SUM, half);
        if (sum != 2L * i + 5) {
            fprintf(stderr, "mpi_split: rank %d: allreduce %d gave %ld\n", rank, i, sum);
            return 1;
        }
    }
    return 0;
}

int main(int argc, char **argv) {
    int provided, rank, size, code;
    char name[64];
    MPI_Comm half;

    if (argc != 3) {
        fprintf(stderr, "usage: mpi_split SCENE OUTDIR\n");
        return 2;
    }
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    MPI_Comm_split(MPI_COMM_WORLD, rank / 2, rank, &half);
    if (size != 4) {
        fprintf(stderr, "mpi_split: run me on 4 ranks, not %d\n", size);
        code = 1;
    } else if (rank < 2) {
        code = render_half(half, argv[1], argv[2]);
    } else {
        code = collectives(half, rank);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    MPI_Comm_free(&half);
    MPI_Finalize();
    snprintf(name, sizeof name, "finished-%d.txt", rank);
    if (code == 0) {
        code = write_file(argv[2], name, "", 0);
    }
    return code;
}
