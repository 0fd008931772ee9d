/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Two builds of libhbao timed against each other in the same run: "before"
 * and "after" a change, on bench_speed's scene at 1920x1080 (--size WxH
 * for another) at the defaults (or --half, --radius). On a shared machine the time of one build moves by
 * 10 % between minutes, so the builds alternate: a round makes --calls calls
 * with each, and prints each build's fastest call and lower quartile (the
 * steadiest figures under load: CPU ms on 1 thread, wall ms on more). Also
 * says whether the two builds' AO is bit-identical, which a lossless change
 * must keep. Not a test: it asserts nothing.
 *
 *   bench_ab BEFORE/libhbao.so AFTER/libhbao.so [--rounds R] [--calls N]
 *            [--threads T] [--half] [--radius R] [--directions D] [--steps S]
 *            [--blur B] [--size WxH] [--implementation NAME] [--back-faces]
 *            [--background P] [--near-pixel]
 *
 * --back-faces: with a back-face layer every surface 0.3 deep, as
 * bench_speed's back-face row (hbao_compute_layers; without it the same
 * function with no layer, which is hbao_compute). --background P: the
 * upper P per cent of the rows background (bench_sky, as bench_speed's
 * skips row has the upper half). --near-pixel: one pixel brought near
 * (bench_near_pixel), so that a radius under a pixel elsewhere still runs
 * every stage around the search (scripts/bench_search_parts.py). */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* RTLD_DEEPBIND */
#endif
#include <dlfcn.h>

#include "bench_common.h"

typedef hbao_result (*compute_function)(const hbao_params *, const hbao_camera *, int32_t, int32_t,
                                        const hbao_channel *, const hbao_channel *,
                                        const hbao_channel *, float *, int64_t);

typedef struct build {
    const char *path;
    compute_function compute;
    float *ao;
    double best_sum, quartile_sum;
} build;

static int load(build *b, int width, int height) {
    /* By path: two files are two libraries, whatever their soname. This
     * program is linked with a third (for the scene's camera): DEEPBIND
     * makes each loaded library call its own functions, not that one's. */
    void *library = dlopen(b->path, RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
    if (library == NULL) {
        fprintf(stderr, "bench_ab: %s\n", dlerror());
        return 0;
    }
    b->compute = (compute_function)(uintptr_t)dlsym(library, "hbao_compute_layers");
    b->ao = malloc(sizeof(float) * (size_t)width * (size_t)height);
    if (b->compute == NULL || b->ao == NULL) {
        fprintf(stderr, "bench_ab: %s has no hbao_compute_layers\n", b->path);
        return 0;
    }
    return 1;
}

static void usage(const char *program) {
    fprintf(stderr,
            "usage: %s BEFORE_LIBRARY AFTER_LIBRARY [--rounds R] [--calls N] [--threads T] "
            "[--half] [--radius R] [--directions D] [--steps S] [--blur B] [--size WxH]\n"
            "  [--implementation scalar|generic|avx2|avx512] (default: the best this CPU has) "
            "[--back-faces] [--background P] [--near-pixel]\n",
            program);
}

int main(int argc, char **argv) {
    int rounds = 3, calls = 15, threads = 1, half = 0, back_faces = 0, background = 0,
        near_pixel = 0;
    int width = 1920, height = 1080;
    hbao_params params = HBAO_PARAMS_DEFAULT_INITIALIZER;
    float radius = 0.5f;
    if (argc < 3) {
        usage(argv[0]);
        return 2;
    }
    for (int a = 3; a < argc; a++) {
        if (!strcmp(argv[a], "--rounds") && a + 1 < argc)
            rounds = (int)bench_whole_number(argv[++a], 1, 100);
        else if (!strcmp(argv[a], "--calls") && a + 1 < argc)
            calls = (int)bench_whole_number(argv[++a], 1, 1000);
        else if (!strcmp(argv[a], "--threads") && a + 1 < argc)
            threads = (int)bench_whole_number(argv[++a], 1, 64);
        else if (!strcmp(argv[a], "--radius") && a + 1 < argc)
            radius = bench_positive_number(argv[++a]);
        else if (!strcmp(argv[a], "--directions") && a + 1 < argc)
            params.directions = (int)bench_whole_number(argv[++a], 1, HBAO_MAX_DIRECTIONS);
        else if (!strcmp(argv[a], "--steps") && a + 1 < argc)
            params.steps = (int)bench_whole_number(argv[++a], 1, HBAO_MAX_STEPS);
        else if (!strcmp(argv[a], "--blur") && a + 1 < argc)
            params.blur_size = (int)bench_whole_number(argv[++a], 0, HBAO_MAX_BLUR_SIZE);
        else if (!strcmp(argv[a], "--half"))
            half = 1;
        else if (!strcmp(argv[a], "--back-faces"))
            back_faces = 1;
        else if (!strcmp(argv[a], "--background") && a + 1 < argc)
            background = (int)bench_whole_number(argv[++a], 0, 100);
        else if (!strcmp(argv[a], "--near-pixel"))
            near_pixel = 1;
        else if (!strcmp(argv[a], "--size") && a + 1 < argc)
            bench_size(argv[++a], 16, 8192, &width, &height);
        else if (!strcmp(argv[a], "--implementation") && a + 1 < argc)
            params.implementation = bench_implementation(argv[++a]);
        else {
            usage(argv[0]);
            return 2;
        }
    }
    if (rounds < 1 || calls < 1 || threads < 1 || !(radius > 0.0f) || params.directions < 1 ||
        params.steps < 1 || params.blur_size < 0 || params.implementation < 0 || width < 16 ||
        width > 8192 || height < 16 || height > 8192 || background < 0) {
        fprintf(stderr,
                "bench_ab: --rounds 1-100, --calls 1-1000, --threads 1-64, radius > 0, "
                "--directions 1-%d, --steps 1-%d, --blur 0-%d, --implementation "
                "scalar, generic, avx2 or avx512, --size WxH with W and H in 16-8192, "
                "--background 0-100\n",
                HBAO_MAX_DIRECTIONS, HBAO_MAX_STEPS, HBAO_MAX_BLUR_SIZE);
        return 2;
    }
    build builds[2] = {{argv[1], NULL, NULL, 0.0, 0.0}, {argv[2], NULL, NULL, 0.0, 0.0}};
    for (int k = 0; k < 2; k++)
        if (!load(&builds[k], width, height)) return 1;
    bench_scene frame;
    bench_scene_make(&frame, width, height);
    bench_sky(frame.depth, width, height, background);
    if (near_pixel) bench_near_pixel(frame.depth);
    params.radius = radius;
    params.threads = threads;
    params.half_resolution = half;
    const hbao_channel depth = {frame.depth, 1, width};
    const hbao_channel normal = {frame.normal, 3, 3 * (int64_t)width};
    float *back = malloc(sizeof(float) * (size_t)width * height);
    if (back == NULL) return 1;
    for (size_t k = 0; k < (size_t)width * height; k++) back[k] = frame.depth[k] + 0.3f;
    const hbao_channel back_depth = {back, 1, width};
    double *times = malloc(sizeof(double) * (size_t)calls);
    if (times == NULL) return 1;
    const char *unit = threads == 1 ? "CPU ms" : "wall ms";
    char sky[48] = "";
    if (background > 0) snprintf(sky, sizeof sky, ", %d %% background", background);
    if (near_pixel) snprintf(sky + strlen(sky), sizeof sky - strlen(sky), ", one pixel near");
    printf("%dx%d, %d x %d, blur %d%s%s%s, radius %g, %d thread(s); per round and build: "
           "fastest and lower-quartile %s of %d calls\n",
           width, height, params.directions, params.steps, params.blur_size,
           half ? ", half resolution" : "", back_faces ? ", back faces" : "", sky, radius, threads,
           unit, calls);
    print_load("before");
    for (int round = 0; round < rounds; round++) {
        for (int k = 0; k < 2; k++) {
            build *b = &builds[k];
            for (int call = 0; call < calls; call++) {
                const clockid_t clock = threads == 1 ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_MONOTONIC;
                const double start = clock_seconds(clock);
                const hbao_result result =
                    b->compute(&params, &frame.view.camera, width, height, &depth, &normal,
                               back_faces ? &back_depth : NULL, b->ao, width);
                times[call] = 1e3 * (clock_seconds(clock) - start);
                if (result != HBAO_SUCCESS) {
                    fprintf(stderr, "bench_ab: %s failed (%d)\n", b->path, (int)result);
                    return 1;
                }
            }
            qsort(times, (size_t)calls, sizeof(double), compare_doubles);
            b->best_sum += times[0];
            b->quartile_sum += times[calls / 4];
            printf("round %d  %-6s %7.1f %7.1f  %s\n", round + 1, k == 0 ? "before" : "after",
                   times[0], times[calls / 4], b->path);
        }
    }
    print_load("after");
    printf("mean over rounds, fastest / lower quartile: before %.1f / %.1f, after %.1f / %.1f "
           "%s; after / before %.3f / %.3f\n",
           builds[0].best_sum / rounds, builds[0].quartile_sum / rounds,
           builds[1].best_sum / rounds, builds[1].quartile_sum / rounds, unit,
           builds[1].best_sum / builds[0].best_sum,
           builds[1].quartile_sum / builds[0].quartile_sum);
    const int same = !memcmp(builds[0].ao, builds[1].ao, sizeof(float) * (size_t)width * height);
    printf("AO of the two builds: %s\n", same ? "bit-identical" : "DIFFERENT");
    return 0;
}
