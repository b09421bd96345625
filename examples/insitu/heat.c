/* heat.c: a 3-D heat simulation rendered in situ through Luxon's C API.
 *
 * An explicit 7-point stencil on an n*n*n grid of doubles: the faces are held at 0, two small
 * heaters at 1. Every `--every` steps the field is handed to Luxon as a volume (a shared
 * FLOAT64 array over the simulation's own buffer, marked modified after each step, so the next
 * commit reads it again) and rendered with the "hot" transfer function and gradient shading
 * into frame0000.png, frame0001.png... Every Luxon call's status is checked and
 * luxon_last_error() printed on failure: the pattern to copy.
 *
 *   cc -std=c99 -O2 -I core/capi/include examples/insitu/heat.c -L target/release \
 *      -Wl,-rpath,target/release -lluxon -lm -o heat
 *   ./heat [--size 64] [--steps 200] [--every 10] [--threads 2] [--out out/heat] [--quiet]
 *
 * With MPI (a libluxon built with `--features mpi`), compiled with mpicc -DLUXON_EXAMPLE_MPI:
 *
 *   mpirun -np 4 ./heat --split
 *
 * splits the world in two: ranks 0-1 each run the whole simulation (replicated data) and render
 * it together over their half (image-parallel; rank 0 of the half writes the frames), while
 * ranks 2-3 run collectives of their own, as another part of a coupled code would. Without
 * --split every rank of the world renders. The frames equal the one-process frames, bit for bit.
 */
#define _POSIX_C_SOURCE 200809L

#ifdef LUXON_EXAMPLE_MPI
#include <mpi.h>

#include "luxon_mpi.h"
#else
#include "luxon.h"
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Stops with Luxon's message when a call fails (the handles are released by the caller's
 * cleanup: here the process ends). */
#define CHECK(call)                                                                        \
    do {                                                                                   \
        luxon_status status_ = (call);                                                     \
        if (status_ != LUXON_OK) {                                                         \
            fprintf(stderr, "heat: %s failed (status %d): %s\n", #call, (int)status_,      \
                    luxon_last_error());                                                   \
            return 1;                                                                      \
        }                                                                                  \
    } while (0)

typedef struct options {
    int size, steps, every, threads, quiet, split;
    const char *out;
} options;

static double now(void) {
#ifdef LUXON_EXAMPLE_MPI
    return MPI_Wtime();
#else
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
#endif
}

static int parse(int argc, char **argv, options *o) {
    int i;
    o->size = 64;
    o->steps = 200;
    o->every = 10;
    o->threads = 2;
    o->quiet = 0;
    o->split = 0;
    o->out = "out/heat";
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        int *number = NULL;
        if (strcmp(a, "--quiet") == 0) {
            o->quiet = 1;
        } else if (strcmp(a, "--split") == 0) {
#ifdef LUXON_EXAMPLE_MPI
            o->split = 1;
#else
            fprintf(stderr, "heat: --split needs the MPI build (mpicc -DLUXON_EXAMPLE_MPI)\n");
            return 1;
#endif
        } else if (strcmp(a, "--out") == 0 && i + 1 < argc) {
            o->out = argv[++i];
        } else if (strcmp(a, "--size") == 0) {
            number = &o->size;
        } else if (strcmp(a, "--steps") == 0) {
            number = &o->steps;
        } else if (strcmp(a, "--every") == 0) {
            number = &o->every;
        } else if (strcmp(a, "--threads") == 0) {
            number = &o->threads;
        } else {
            fprintf(stderr, "heat: unknown or incomplete argument `%s`\n", a);
            return 1;
        }
        if (number) {
            char *end;
            long v;
            if (i + 1 >= argc) {
                fprintf(stderr, "heat: %s needs a value\n", a);
                return 1;
            }
            v = strtol(argv[++i], &end, 10);
            if (*end != '\0' || v < 0 || v > 100000) {
                fprintf(stderr, "heat: %s: `%s` is not a count\n", a, argv[i]);
                return 1;
            }
            *number = (int)v;
        }
    }
    if (o->size < 8 || o->every < 1) {
        fprintf(stderr, "heat: --size must be at least 8 and --every at least 1\n");
        return 1;
    }
    return 0;
}

/* Voxel (i, j, k) of an n^3 grid, x fastest (what Luxon's default strides say). */
#define AT(n, i, j, k) (((size_t)(k) * (size_t)(n) + (size_t)(j)) * (size_t)(n) + (size_t)(i))

/* Whether voxel (i, j, k) is inside one of the two heaters (spheres of radius n/10). */
static int heater(int n, int i, int j, int k) {
    static const double centers[2][3] = {{0.32, 0.42, 0.38}, {0.66, 0.58, 0.62}};
    int h;
    for (h = 0; h < 2; h++) {
        double dx = i - centers[h][0] * (n - 1), dy = j - centers[h][1] * (n - 1);
        double dz = k - centers[h][2] * (n - 1), r = 0.1 * n;
        if (dx * dx + dy * dy + dz * dz <= r * r) {
            return 1;
        }
    }
    return 0;
}

/* One explicit step: `next` from `u` (faces stay 0, heaters 1); then `u` takes it. */
static void step(int n, const unsigned char *hot, double *u, double *next) {
    const double c = 0.15; /* alpha dt / dx^2, below the limit 1/6 */
    int i, j, k;
    for (k = 1; k < n - 1; k++) {
        for (j = 1; j < n - 1; j++) {
            for (i = 1; i < n - 1; i++) {
                size_t at = AT(n, i, j, k);
                double sum = u[at - 1] + u[at + 1] + u[AT(n, i, j - 1, k)] +
                             u[AT(n, i, j + 1, k)] + u[AT(n, i, j, k - 1)] +
                             u[AT(n, i, j, k + 1)];
                next[at] = hot[at] ? 1.0 : u[at] + c * (sum - 6.0 * u[at]);
            }
        }
    }
    memcpy(u, next, (size_t)n * n * n * sizeof *u);
}

/* The simulation with its renders. `comm` is where Luxon renders (MPI builds; NULL: alone);
 * `writer` says whether this rank writes the frames. */
static int simulate(const options *o, void *comm, int writer) {
    const int n = o->size;
    const size_t voxels = (size_t)n * n * n;
    const uint32_t width = 320, height = 240;
    double *u = calloc(voxels, sizeof *u), *next = calloc(voxels, sizeof *next);
    unsigned char *hot = calloc(voxels, 1);
    float *pixels = calloc((size_t)width * height * 4, sizeof *pixels);
    luxon_context_options copts;
    luxon_context ctx = {0};
    luxon_renderer renderer = {0};
    luxon_scene scene = {0};
    luxon_array field = {0};
    luxon_volume volume;
    luxon_target target;
    luxon_commit_report report;
    double sim_seconds = 0, commit_seconds = 0, render_seconds = 0;
    int s, frame = 0, i, j, k;
    char path[4096];

    if (!u || !next || !hot || !pixels) {
        fprintf(stderr, "heat: out of memory for a %d^3 grid\n", n);
        return 1;
    }
    for (k = 0; k < n; k++) {
        for (j = 0; j < n; j++) {
            for (i = 0; i < n; i++) {
                hot[AT(n, i, j, k)] = (unsigned char)heater(n, i, j, k);
                u[AT(n, i, j, k)] = hot[AT(n, i, j, k)];
            }
        }
    }

    memset(&copts, 0, sizeof copts);
    copts.size = sizeof copts;
    copts.threads = (uint32_t)o->threads;
    CHECK(luxon_context_create(&copts, &ctx));
    CHECK(luxon_renderer_create(ctx, 0, &renderer));
#ifdef LUXON_EXAMPLE_MPI
    if (comm) {
        CHECK(luxon_renderer_set_mpi_comm(renderer, *(MPI_Comm *)comm));
    }
#else
    (void)comm;
#endif
    CHECK(luxon_scene_create(ctx, &scene));
    CHECK(luxon_scene_set_camera_ron(
        scene, "(position: (0.35, 0.75, 2.1), look_at: (0, 0, 0), up: (0, 1, 0), fov: 34)"));
    CHECK(luxon_scene_set_background(scene, 0.02, 0.02, 0.04));
    CHECK(luxon_scene_add_light_ron(scene, "Point(position: (2, 3, 2), intensity: 1)", NULL));

    /* The simulation's buffer, read by Luxon at the commits after it was marked modified (a
     * volume is copied into Luxon's bricks then: it may be written between commits). */
    CHECK(luxon_array_create_shared(u, voxels, 0, LUXON_FLOAT64, NULL, NULL, &field));
    CHECK(luxon_volume_init(&volume));
    volume.values = field;
    volume.dims[0] = volume.dims[1] = volume.dims[2] = (uint64_t)n;
    volume.origin[0] = volume.origin[1] = volume.origin[2] = -0.5;
    volume.spacing[0] = volume.spacing[1] = volume.spacing[2] = 1.0 / (n - 1);
    volume.name = "temperature";
    volume.render_ron = "(transfer: (preset: \"hot\", range: (0, 0.6), opacity: 12), step: 0.012, "
                        "shading: (ambient: 0.45, diffuse: 0.6, specular: 0.2, shininess: 20, "
                        "shadows: false))";
    CHECK(luxon_scene_add_volume(scene, &volume, NULL));

    memset(&target, 0, sizeof target);
    target.size = sizeof target;
    target.width = width;
    target.height = height;
    target.format = writer ? LUXON_PIXELS_RGBA32F : LUXON_PIXELS_NONE;
    target.pixels = writer ? pixels : NULL;

    for (s = 1; s <= o->steps; s++) {
        double t = now();
        step(n, hot, u, next);
        sim_seconds += now() - t;
        /* The field changed: the next commit reads it again. */
        CHECK(luxon_array_mark_modified(field, 0, voxels));
        if (s % o->every != 0) {
            continue;
        }
        memset(&report, 0, sizeof report);
        report.size = sizeof report;
        t = now();
        CHECK(luxon_scene_commit(scene, renderer, &report));
        commit_seconds += now() - t;
        t = now();
        CHECK(luxon_render(renderer, scene, &target, NULL));
        t = now() - t;
        render_seconds += t;
        if (writer) {
            snprintf(path, sizeof path, "%s/frame%04d.png", o->out, frame);
            CHECK(luxon_write_image(ctx, path, pixels, width, height, 0));
            if (!o->quiet) {
                printf("step %5d: sim %8.2f ms/step, commit %6.2f ms (%u volume read), render "
                       "%7.1f ms -> %s\n",
                       s, 1e3 * sim_seconds / s, 1e3 * report.commit_seconds,
                       report.volumes_read, 1e3 * t, path);
            }
        }
        frame++;
    }
    if (writer && !o->quiet && frame > 0) {
        printf("%d^3 grid, %d steps, %d frames: sim %.2f ms/step, commit %.2f ms, render %.1f "
               "ms/frame; rendering every %d steps costs %.0f %% of the simulation's time\n",
               n, o->steps, frame, 1e3 * sim_seconds / o->steps, 1e3 * commit_seconds / frame,
               1e3 * render_seconds / frame, o->every,
               100.0 * (commit_seconds + render_seconds) / sim_seconds);
    }

    /* Releases in any order; the renderer before MPI_Finalize (it frees its communicator). */
    CHECK(luxon_scene_release(scene));
    CHECK(luxon_array_release(field));
    CHECK(luxon_renderer_release(renderer));
    CHECK(luxon_context_release(ctx));
    free(u);
    free(next);
    free(hot);
    free(pixels);
    return 0;
}

#ifdef LUXON_EXAMPLE_MPI
/* What ranks 2-3 do with --split: collectives of their own while the others render. */
static int other_work(MPI_Comm half, int steps) {
    int i, rank, size;
    MPI_Comm_rank(half, &rank);
    MPI_Comm_size(half, &size);
    for (i = 0; i < 100 * steps; i++) {
        long mine = i + rank, sum = 0;
        MPI_Allreduce(&mine, &sum, 1, MPI_LONG, MPI_SUM, half);
        if (sum != (long)size * i + (long)size * (size - 1) / 2) {
            fprintf(stderr, "heat: allreduce %d gave %ld\n", i, sum);
            return 1;
        }
    }
    return 0;
}

int main(int argc, char **argv) {
    options o;
    int provided, rank, size, code, all = 0;
    MPI_Comm comm;

    /* The program owns MPI: Luxon is called from this (the main) thread only. */
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (parse(argc, argv, &o) != 0) {
        MPI_Finalize();
        return 1;
    }
    if (o.split) {
        /* Ranks 0 .. size/2 - 1 render; the others go their own way. */
        int renders = rank < size / 2;
        MPI_Comm_split(MPI_COMM_WORLD, renders ? 0 : 1, rank, &comm);
        if (renders) {
            int half_rank;
            MPI_Comm_rank(comm, &half_rank);
            code = simulate(&o, &comm, half_rank == 0);
        } else {
            code = other_work(comm, o.steps);
        }
        MPI_Comm_free(&comm);
    } else {
        comm = MPI_COMM_WORLD;
        code = simulate(&o, &comm, rank == 0);
    }
    MPI_Allreduce(&code, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Finalize();
    return all;
}
#else
int main(int argc, char **argv) {
    options o;
    if (parse(argc, argv, &o) != 0) {
        return 1;
    }
    return simulate(&o, NULL, 1);
}
#endif
