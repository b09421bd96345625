/* Compiled by tests/arrays.rs as C99 (-Wall -Wextra -Wpedantic -Werror), linked against
 * libluxon.so, and run: `arrays OUTDIR`. Builds spheres from a field of an array of structs
 * (read in place), a mesh and a volume (copies) through the C calls, renders them, moves the
 * spheres, renders again, and writes the pixels to OUTDIR for the Rust test to compare with the
 * Rust API's renders of the same data (tests/common/mod.rs — arrays_scene). Checks the error
 * codes of bad and released arrays and the ownership rule: an array released while a scene
 * uses it stays read until the scene lets it go, then its deleter runs once; an index array
 * changed without being marked renders without a crash. Prints nothing unless something
 * fails. */
#include "luxon.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 32
#define H 24
#define ATOMS 27
#define GRID 6
#define VOX 12

static int failures = 0;

#define CHECK(call)                                                                       \
    do {                                                                                  \
        luxon_status s_ = (call);                                                         \
        if (s_ != LUXON_OK) {                                                             \
            fprintf(stderr, "arrays: %s: status %d: %s\n", #call, (int)s_, luxon_last_error()); \
            return 1;                                                                     \
        }                                                                                 \
    } while (0)

#define EXPECT(cond)                                                    \
    do {                                                                \
        if (!(cond)) {                                                  \
            fprintf(stderr, "arrays: line %d: %s (last error: %s)\n", __LINE__, #cond, \
                    luxon_last_error());                                \
            failures++;                                                 \
        }                                                               \
    } while (0)

/* A simulation's particles: the positions and radii are fields of its structs. */
struct atom {
    unsigned char kind;
    double pos[3];
    double radius;
    float charge;
};

static int deleted = 0;

static void on_delete(void *user) {
    int *count = (int *)user;
    (*count)++;
}

static int write_file(const char *dir, const char *name, const void *data, size_t bytes) {
    char path[4096];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "wb");
    if (!f || fwrite(data, 1, bytes, f) != bytes) {
        fprintf(stderr, "arrays: cannot write %s\n", path);
        return 1;
    }
    return fclose(f) != 0;
}

static int render(luxon_renderer r, luxon_scene s, float *pixels) {
    luxon_target t;
    memset(&t, 0, sizeof t);
    t.size = sizeof t;
    t.width = W;
    t.height = H;
    t.format = LUXON_PIXELS_RGBA32F;
    t.pixels = pixels;
    return luxon_render(r, s, &t, NULL);
}

int main(int argc, char **argv) {
    static struct atom atoms[ATOMS];
    static float positions[GRID * GRID][3];
    static uint32_t triangles[(GRID - 1) * (GRID - 1) * 2][3];
    static float voxels[VOX * VOX * VOX];
    static float pixels[W * H * 4];
    double eye[3] = {0.0, 1.0, 6.0}, at[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 1.0, 0.0};
    luxon_context ctx = {0};
    luxon_renderer renderer = {0};
    luxon_scene scene = {0};
    luxon_array centers = {0}, radii = {0}, verts = {0}, tris = {0}, values = {0}, bad = {0};
    luxon_object balls = {0}, sheet = {0}, cloud = {0}, none = {0};
    luxon_point_light lamp;
    luxon_material clay;
    luxon_spheres sp;
    luxon_mesh mesh;
    luxon_volume vol;
    luxon_commit_report report;
    int i, j, k, n;

    if (argc != 2) {
        fprintf(stderr, "usage: arrays OUTDIR\n");
        return 2;
    }
    for (i = 0; i < ATOMS; i++) {
        atoms[i].kind = (unsigned char)i;
        atoms[i].pos[0] = (i % 3 - 1) * 0.75;
        atoms[i].pos[1] = (i / 3 % 3 - 1) * 0.75 + 0.5;
        atoms[i].pos[2] = (i / 9 - 1) * 0.75;
        atoms[i].radius = 0.15 + 0.01 * (i % 4);
        atoms[i].charge = -1.0f;
    }
    for (j = 0; j < GRID; j++)
        for (i = 0; i < GRID; i++) {
            positions[j * GRID + i][0] = (float)(i - 2.5) * 0.8f;
            positions[j * GRID + i][1] = -0.6f + 0.1f * (float)((i * j) % 3);
            positions[j * GRID + i][2] = (float)(j - 2.5) * 0.8f;
        }
    n = 0;
    for (j = 0; j + 1 < GRID; j++)
        for (i = 0; i + 1 < GRID; i++) {
            uint32_t a = (uint32_t)(j * GRID + i);
            triangles[n][0] = a;
            triangles[n][1] = a + GRID;
            triangles[n][2] = a + 1;
            n++;
            triangles[n][0] = a + 1;
            triangles[n][1] = a + GRID;
            triangles[n][2] = a + GRID + 1;
            n++;
        }
    for (k = 0; k < VOX; k++)
        for (j = 0; j < VOX; j++)
            for (i = 0; i < VOX; i++) {
                double x = i - 5.5, y = j - 5.5, z = k - 5.5;
                double b = 1.0 - (x * x + y * y + z * z) / 36.0;
                voxels[(k * VOX + j) * VOX + i] = (float)(b > 0.0 ? b * b : 0.0);
            }

    CHECK(luxon_context_create(NULL, &ctx));
    CHECK(luxon_renderer_create(ctx, 1, &renderer));
    CHECK(luxon_scene_create(ctx, &scene));
    CHECK(luxon_scene_set_camera_view(scene, eye, at, up, 40.0));
    CHECK(luxon_scene_set_background(scene, 0.1, 0.15, 0.3));
    CHECK(luxon_point_light_init(&lamp));
    lamp.position[0] = 4.0;
    lamp.position[1] = 6.0;
    lamp.position[2] = 5.0;
    CHECK(luxon_scene_add_point_light(scene, &lamp, NULL));
    CHECK(luxon_material_init(&clay));
    clay.color[0] = 0.8;
    clay.color[1] = 0.4;
    clay.color[2] = 0.2;
    clay.specular = 0.4;
    CHECK(luxon_scene_set_material(scene, "clay", &clay));

    /* Fields of the structs, read in place; the deleter tells when Luxon lets them go. */
    CHECK(luxon_array_create_shared(&atoms[0].pos, ATOMS, sizeof(struct atom),
                                    LUXON_FLOAT64_VEC3, on_delete, &deleted, &centers));
    CHECK(luxon_array_create_shared(&atoms[0].radius, ATOMS, sizeof(struct atom), LUXON_FLOAT64,
                                    NULL, NULL, &radii));
    CHECK(luxon_spheres_init(&sp));
    sp.centers = centers;
    sp.radii = radii;
    sp.material = "clay";
    CHECK(luxon_scene_add_spheres(scene, &sp, &balls));

    /* Copies: the caller's buffers could be reused at once. */
    CHECK(luxon_array_create_copy(positions, GRID * GRID, 0, LUXON_FLOAT32_VEC3, &verts));
    CHECK(luxon_array_create_copy(triangles, (size_t)n, 0, LUXON_UINT32_VEC3, &tris));
    CHECK(luxon_mesh_init(&mesh));
    mesh.positions = verts;
    mesh.indices = tris;
    CHECK(luxon_scene_add_mesh(scene, &mesh, &sheet));

    CHECK(luxon_array_create_copy(voxels, VOX * VOX * VOX, 0, LUXON_FLOAT32, &values));
    CHECK(luxon_volume_init(&vol));
    vol.values = values;
    vol.dims[0] = vol.dims[1] = vol.dims[2] = VOX;
    vol.origin[0] = vol.origin[1] = vol.origin[2] = -1.1;
    vol.spacing[0] = vol.spacing[1] = vol.spacing[2] = 0.2;
    vol.name = "bump";
    vol.render_ron = "(transfer: (points: [(x: 0, color: (0.2, 0.6, 1), opacity: 0), "
                     "(x: 1, color: (0.9, 1, 1), opacity: 3)], range: (0, 1)))";
    CHECK(luxon_scene_add_volume(scene, &vol, &cloud));

    memset(&report, 0, sizeof report);
    report.size = sizeof report;
    CHECK(luxon_scene_commit(scene, renderer, &report));
    EXPECT(report.rebuilt == 3 && report.volumes_read == 1 && report.refitted == 0);
    CHECK(render(renderer, scene, pixels));
    if (write_file(argv[1], "arrays.f32", pixels, sizeof pixels)) return 1;

    /* A step: the particles move; Luxon is told, and refits. */
    for (i = 0; i < ATOMS; i++) atoms[i].pos[0] += 0.05 * (i % 2 ? 1 : -1);
    CHECK(luxon_array_mark_modified(centers, 0, ATOMS));
    memset(&report, 0, sizeof report);
    report.size = sizeof report;
    CHECK(luxon_scene_commit(scene, renderer, &report));
    EXPECT(report.rebuilt == 0 && report.refitted == 1 && report.volumes_read == 0);
    CHECK(render(renderer, scene, pixels));
    if (write_file(argv[1], "moved.f32", pixels, sizeof pixels)) return 1;

    /* Errors: bad arrays, NULL and released handles. */
    EXPECT(luxon_array_create_shared(atoms, 4, 2, LUXON_FLOAT64_VEC3, on_delete, &deleted, &bad) ==
           LUXON_ERROR_INVALID_ARGUMENT);
    EXPECT(bad.id == 0 && deleted == 0);
    EXPECT(luxon_array_create_copy(NULL, 4, 0, LUXON_FLOAT32, &bad) == LUXON_ERROR_INVALID_ARGUMENT);
    EXPECT(luxon_array_create_copy(voxels, 4, 0, 99, &bad) == LUXON_ERROR_INVALID_ARGUMENT);
    EXPECT(luxon_array_mark_modified(centers, 20, 8) == LUXON_ERROR_INVALID_ARGUMENT);
    EXPECT(luxon_array_update(centers, voxels, 0, 1, 0) == LUXON_ERROR_INVALID_ARGUMENT);
    sp.centers = bad; /* {0} */
    EXPECT(luxon_scene_add_spheres(scene, &sp, &none) == LUXON_ERROR_INVALID_HANDLE);
    EXPECT(none.id == 0 && strstr(luxon_last_error(), "centers") != NULL);
    CHECK(luxon_array_create_copy(voxels, 8, 0, LUXON_FLOAT32, &bad));
    CHECK(luxon_array_release(bad));
    EXPECT(luxon_array_release(bad) == LUXON_ERROR_INVALID_HANDLE);
    EXPECT(luxon_array_mark_modified(bad, 0, 1) == LUXON_ERROR_INVALID_HANDLE);
    vol.values = bad;
    EXPECT(luxon_scene_set_volume(scene, cloud, &vol) == LUXON_ERROR_INVALID_HANDLE);
    EXPECT(strstr(luxon_last_error(), "released") != NULL);
    vol.values = values;
    vol.dims[2] = VOX + 1;
    EXPECT(luxon_scene_set_volume(scene, cloud, &vol) == LUXON_ERROR_INVALID_ARGUMENT);
    EXPECT(strstr(luxon_last_error(), "has 1728 elements") != NULL);
    vol.dims[2] = VOX;
    EXPECT(luxon_scene_set_volume(scene, balls, &vol) == LUXON_ERROR_INVALID_ARGUMENT);
    sp.centers = centers;
    EXPECT(luxon_scene_set_spheres(scene, sheet, &sp) == LUXON_ERROR_INVALID_ARGUMENT);

    /* Released while the scene uses it: still read (the same picture), deleted later. */
    CHECK(luxon_array_release(centers));
    CHECK(luxon_array_release(radii));
    CHECK(luxon_array_release(verts));
    CHECK(luxon_array_release(tris));
    CHECK(luxon_array_release(values));
    {
        static float again[W * H * 4];
        CHECK(render(renderer, scene, again));
        EXPECT(memcmp(again, pixels, sizeof again) == 0);
    }
    EXPECT(deleted == 0);
    CHECK(luxon_scene_remove(scene, balls));
    CHECK(luxon_scene_commit(scene, renderer, NULL));
    EXPECT(deleted == 1);

    /* An index array changed to out-of-range values without luxon_array_mark_modified: at
     * worst a wrong picture, never a read outside the arrays; once marked, the commit refuses
     * it, naming the triangle and the vertex. */
    {
        static float quad[4][3] = {{-1, -1, -1}, {1, -1, -1}, {-1, -1, 1}, {1, -1, 1}};
        static uint32_t corners[2][3] = {{0, 2, 1}, {1, 2, 3}};
        luxon_array qv = {0}, qi = {0};
        luxon_object q = {0};
        CHECK(luxon_array_create_shared(quad, 4, 0, LUXON_FLOAT32_VEC3, NULL, NULL, &qv));
        CHECK(luxon_array_create_shared(corners, 2, 0, LUXON_UINT32_VEC3, NULL, NULL, &qi));
        CHECK(luxon_mesh_init(&mesh));
        mesh.positions = qv;
        mesh.indices = qi;
        CHECK(luxon_scene_add_mesh(scene, &mesh, &q));
        CHECK(render(renderer, scene, pixels));
        corners[0][1] = 4000000000u;
        corners[1][2] = 7;
        CHECK(render(renderer, scene, pixels));
        CHECK(luxon_array_mark_modified(qi, 0, 2));
        EXPECT(render(renderer, scene, pixels) == LUXON_ERROR_INVALID_ARGUMENT);
        EXPECT(strstr(luxon_last_error(), "triangle 0 uses vertex 4000000000") != NULL);
        CHECK(luxon_scene_remove(scene, q));
        CHECK(render(renderer, scene, pixels));
        CHECK(luxon_array_release(qv));
        CHECK(luxon_array_release(qi));
    }

    CHECK(luxon_scene_release(scene));
    CHECK(luxon_renderer_release(renderer));
    CHECK(luxon_context_release(ctx));
    EXPECT(deleted == 1);
    return failures != 0;
}
