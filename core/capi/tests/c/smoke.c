/* Compiled by tests/compile.rs as C99 and as C++17 (-Wall -Wextra -Wpedantic -Werror), linked
 * against libluxon, and run: `smoke SCENE OUTDIR`. Builds a scene through the C calls, loads
 * SCENE, renders both, checks what C alone can check, and writes the pixels to OUTDIR for the
 * Rust test to compare with the Rust API's renders. Prints nothing unless something fails. */
#include "luxon.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 32
#define H 24

static int failures = 0;

static void fail(const char *what, luxon_status s) {
    fprintf(stderr, "smoke: %s: status %d: %s\n", what, (int)s, luxon_last_error());
    failures++;
}

#define CHECK(call)                 \
    do {                            \
        luxon_status s_ = (call);   \
        if (s_ != LUXON_OK) {       \
            fail(#call, s_);        \
            return 1;               \
        }                           \
    } while (0)

#define EXPECT(cond)                                              \
    do {                                                          \
        if (!(cond)) {                                            \
            fprintf(stderr, "smoke: line %d: %s\n", __LINE__, #cond); \
            failures++;                                           \
        }                                                         \
    } while (0)

static int write_file(const char *dir, const char *name, const void *data, size_t bytes) {
    char path[4096];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "wb");
    if (!f || fwrite(data, 1, bytes, f) != bytes) {
        fprintf(stderr, "smoke: cannot write %s\n", path);
        return 1;
    }
    return fclose(f) != 0;
}

static int cancel_at_once(uint64_t done, uint64_t total, void *user) {
    int *calls = (int *)user;
    (void)done;
    (void)total;
    (*calls)++;
    return 1;
}

static luxon_target rgba32f(float *pixels, float *depth) {
    luxon_target t;
    memset(&t, 0, sizeof t);
    t.size = sizeof t;
    t.width = W;
    t.height = H;
    t.format = LUXON_PIXELS_RGBA32F;
    t.pixels = pixels;
    t.depth = depth;
    return t;
}

int main(int argc, char **argv) {
    luxon_context_options options;
    luxon_context ctx = {0};
    luxon_renderer renderer = {0};
    luxon_scene scene = {0}, loaded = {0};
    luxon_object light = {0}, ball = {0};
    luxon_point_light lamp;
    luxon_material red;
    luxon_target target;
    luxon_render_stats stats;
    luxon_commit_report report;
    static float pixels[W * H * 4], again[W * H * 4], depth[W * H];
    static unsigned char bytes[H * (W + 8) * 4];
    const double eye[3] = {0, 0.5, -5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    const float *centre;
    int calls = 0;
    size_t i, n = 0;
    uint32_t major = 99, minor = 99, patch = 99;

    if (argc != 3) {
        fprintf(stderr, "usage: smoke SCENE OUTDIR\n");
        return 2;
    }

    /* Versions. */
    EXPECT(luxon_api_version() == LUXON_API_VERSION);
    EXPECT(strlen(luxon_version_string()) > 0);
    luxon_version(&major, &minor, &patch);
    EXPECT(major != 99 && minor != 99 && patch != 99);
    EXPECT(luxon_plugin_abi_version() > 0);

    memset(&options, 0, sizeof options);
    options.size = sizeof options;
    options.threads = 2;
    CHECK(luxon_context_create(&options, &ctx));
    CHECK(luxon_renderer_create(ctx, 0, &renderer));

    /* A scene made through the calls: a red sphere under a point light. */
    CHECK(luxon_scene_create(ctx, &scene));
    CHECK(luxon_scene_set_camera_view(scene, eye, at, up, 40.0));
    CHECK(luxon_scene_set_background(scene, 0.1, 0.2, 0.4));
    CHECK(luxon_point_light_init(&lamp));
    lamp.position[0] = -4;
    lamp.position[1] = 6;
    lamp.position[2] = -5;
    CHECK(luxon_scene_add_point_light(scene, &lamp, &light));
    CHECK(luxon_material_init(&red));
    red.color[0] = 0.8;
    red.color[1] = 0.1;
    red.color[2] = 0.1;
    red.specular = 0.5;
    CHECK(luxon_scene_set_material(scene, "red", &red));
    CHECK(luxon_scene_add_object(scene, "sphere", "(center: (0, 0, 0), radius: 1)", "red", NULL,
                                 &ball));
    CHECK(luxon_scene_set_render_ron(scene, "(samples: 1)"));

    memset(&report, 0, sizeof report);
    report.size = sizeof report;
    CHECK(luxon_scene_commit(scene, renderer, &report));
    EXPECT(report.rebuilt == 1);

    target = rgba32f(pixels, depth);
    memset(&stats, 0, sizeof stats);
    stats.size = sizeof stats;
    CHECK(luxon_render(renderer, scene, &target, &stats));
    EXPECT(stats.primary_rays >= W * H && stats.rays >= stats.primary_rays && stats.threads == 2);
    centre = &pixels[((H / 2) * W + W / 2) * 4];
    EXPECT(centre[0] > 0.05f && centre[0] > 2 * centre[2]); /* red, not black */
    EXPECT(isfinite(depth[(H / 2) * W + W / 2]) && depth[(H / 2) * W + W / 2] > 3.0f);
    EXPECT(isinf(depth[0]));
    if (write_file(argv[2], "code.f32", pixels, sizeof pixels)) return 1;

    /* RGBA8 in rows of W + 8 pixels: the padding stays as it was. */
    memset(bytes, 0xAB, sizeof bytes);
    memset(&target, 0, sizeof target);
    target.size = sizeof target;
    target.width = W;
    target.height = H;
    target.format = LUXON_PIXELS_RGBA8_SRGB;
    target.pixels = bytes;
    target.row_bytes = (W + 8) * 4;
    CHECK(luxon_render(renderer, scene, &target, NULL));
    for (i = 0; i < H; i++) {
        size_t x;
        for (x = W * 4; x < (W + 8) * 4; x++) EXPECT(bytes[i * (W + 8) * 4 + x] == 0xAB);
    }
    if (write_file(argv[2], "code.rgba8", bytes, sizeof bytes)) return 1;

    /* A progress callback that asks to stop cancels; the next render is whole again. */
    CHECK(luxon_renderer_set_progress(renderer, cancel_at_once, &calls));
    target = rgba32f(again, NULL);
    EXPECT(luxon_render(renderer, scene, &target, NULL) == LUXON_ERROR_CANCELLED);
    EXPECT(calls >= 1);
    EXPECT(strcmp(luxon_last_error(), "the render was cancelled") == 0);
    CHECK(luxon_renderer_set_progress(renderer, NULL, NULL));
    CHECK(luxon_render(renderer, scene, &target, NULL));
    EXPECT(memcmp(again, pixels, sizeof pixels) == 0);

    /* Errors are codes with messages; a removed part's handle is refused. */
    EXPECT(luxon_scene_set_camera_ron(scene, "(positon: (0, 0, 5))") == LUXON_ERROR_SCENE);
    EXPECT(strncmp(luxon_last_error(), "<camera>:1:2: ", 14) == 0);
    EXPECT(luxon_scene_add_object(scene, "no-such-plugin", "()", NULL, NULL, NULL) ==
           LUXON_ERROR_PLUGIN_NOT_FOUND);
    EXPECT(luxon_scene_set_texture(scene, "t", "no-such-texture", NULL) ==
           LUXON_ERROR_PLUGIN_NOT_FOUND);
    EXPECT(luxon_scene_set_clip_group(scene, "g", "[(normal: (0, 0, 0))]") == LUXON_ERROR_SCENE);
    EXPECT(strncmp(luxon_last_error(), "<clip_planes>:1:", 16) == 0);
    EXPECT(luxon_scene_add_volume_plugin(scene, "no-such-reader", "()", NULL, NULL, NULL) ==
           LUXON_ERROR_PLUGIN_NOT_FOUND);
    CHECK(luxon_scene_remove(scene, light));
    EXPECT(luxon_scene_remove(scene, light) == LUXON_ERROR_INVALID_HANDLE);
    EXPECT(luxon_scene_set_background(scene, 0, 0, 0) == LUXON_OK);
    EXPECT(strcmp(luxon_last_error(), "") == 0);

    /* A scene file. */
    CHECK(luxon_scene_load(ctx, argv[1], &loaded));
    CHECK(luxon_scene_lights(loaded, NULL, 0, &n));
    EXPECT(n > 0);
    target = rgba32f(pixels, NULL);
    CHECK(luxon_render(renderer, loaded, &target, NULL));
    if (write_file(argv[2], "loaded.f32", pixels, sizeof pixels)) return 1;

    CHECK(luxon_scene_release(loaded));
    CHECK(luxon_scene_release(scene));
    EXPECT(luxon_scene_release(scene) == LUXON_ERROR_INVALID_HANDLE);
    CHECK(luxon_renderer_release(renderer));
    CHECK(luxon_context_release(ctx));
    (void)ball;
    return failures != 0;
}
