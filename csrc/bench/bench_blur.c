/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The blur stage alone (hbao_finish at full resolution: the cross-bilateral
 * blur, then strength and clamp), timed in process CPU time on the bench
 * scene's depth and normals with a random raw AO. bench_speed measures the
 * blur's share of a whole frame as the difference of two timings; this
 * times the stage itself, so that a change to the blur can be measured
 * without the horizon search's noise around it. Built from the library's
 * sources (the stage is internal). scripts/bench_blur_ab.sh runs two
 * builds of it against each other.
 *   bench_blur [--calls N] [--blur B] [--sharpness S] [--size WxH]
 *              [--threads T] [--implementation scalar|generic|avx2|avx512]
 *              [--background P] [--strips S]
 * Prints one line: the fastest and the median CPU ms of N calls, and a
 * hash of the output's bits (the same for every build that blurs alike).
 * --background P: the upper P per cent of the rows are background (depth
 * 0, as the grid holds it; normals 0, where the grid holds (0, 0, 1): a
 * background pixel's normal changes no float), as a sky above a horizon.
 * --strips S: the blur's rows in S strips of columns (blur.c,
 * hbao_blur_strips; default 0: the library's rule for this machine); the
 * line says how many it blurred in. */
#include <stdint.h>

#include "bench_common.h"
#include "internal_finish.h"
#include "test_random.h"

static void usage(const char *program) {
    fprintf(stderr,
            "usage: %s [--calls N] [--blur B] [--sharpness S] [--size WxH] [--threads T]\n"
            "  [--implementation scalar|generic|avx2|avx512] (default: the best this CPU has)\n"
            "  [--background P] (the upper P per cent of the rows background; default 0)\n"
            "  [--strips S] (the blur's strips of columns; default 0: the library's rule)\n",
            program);
}

int main(int argc, char **argv) {
    long calls = 10, blur = 15, width = 1920, height = 1080, threads = 1, background = 0;
    long strips = 0;
    int implementation = HBAO_IMPLEMENTATION_AUTO;
    float sharpness = HBAO_DEFAULT_BLUR_SHARPNESS;
    int bad = 0;
    for (int a = 1; a < argc && !bad; a += 2) {
        const char *value = a + 1 < argc ? argv[a + 1] : NULL;
        if (value == NULL) {
            bad = 1;
        } else if (!strcmp(argv[a], "--calls")) {
            bad = (calls = bench_whole_number(value, 1, 1000)) < 1;
        } else if (!strcmp(argv[a], "--blur")) {
            blur = bench_whole_number(value, 1, HBAO_MAX_BLUR_SIZE);
            bad = blur < 1 || blur % 2 == 0;
        } else if (!strcmp(argv[a], "--sharpness")) {
            char *end;
            sharpness = strtof(value, &end);
            bad = end == value || *end != '\0' ||
                  !(sharpness >= 0.0f && sharpness <= HBAO_MAX_BLUR_SHARPNESS);
        } else if (!strcmp(argv[a], "--background")) {
            bad = (background = bench_whole_number(value, 0, 100)) < 0;
        } else if (!strcmp(argv[a], "--strips")) {
            bad = (strips = bench_whole_number(value, 0, 16384)) < 0;
        } else if (!strcmp(argv[a], "--threads")) {
            bad = (threads = bench_whole_number(value, 1, 64)) < 1;
        } else if (!strcmp(argv[a], "--size")) {
            int w, h;
            bad = !bench_size(value, 16, 16384, &w, &h);
            width = w;
            height = h;
        } else if (!strcmp(argv[a], "--implementation")) {
            bad = (implementation = bench_implementation(value)) < 0;
        } else {
            bad = 1;
        }
    }
    if (bad) {
        usage(argv[0]);
        fprintf(stderr,
                "bench_blur: --calls 1-1000, --blur an odd size 1-%d, --sharpness 0-%g, "
                "--size WxH with each 16-16384, --threads 1-64, --implementation "
                "scalar|generic|avx2|avx512, --background 0-100, --strips 0-16384\n",
                HBAO_MAX_BLUR_SIZE, (double)HBAO_MAX_BLUR_SHARPNESS);
        return 2;
    }

    bench_scene b;
    bench_scene_make(&b, width, height);
    const size_t pixels = (size_t)width * height;
    /* the grid's buffers from the library's scratch memory, as hbao_compute
     * takes them (huge pages where the system gives them) */
    hbao_grid grid;
    memset(&grid, 0, sizeof grid);
    grid.width = width;
    grid.height = height;
    grid.depth = hbao_scratch_take(pixels * sizeof(float));
    grid.normal = hbao_scratch_take((3 * pixels + HBAO_NORMAL_PADDING) * sizeof(float));
    float *raw = hbao_scratch_take(pixels * sizeof(float)), *out = malloc(pixels * sizeof(float));
    double *times = malloc((size_t)calls * sizeof(double));
    if (grid.depth == NULL || grid.normal == NULL || raw == NULL || out == NULL || times == NULL) {
        fprintf(stderr, "bench_blur: out of memory\n");
        return 1;
    }
    memcpy(grid.depth, b.depth, pixels * sizeof(float));
    const size_t sky = (size_t)(height * background / 100) * width; /* background pixels */
    memset(grid.depth, 0, sky * sizeof(float));
    memset(grid.normal + 3 * pixels, 0, HBAO_NORMAL_PADDING * sizeof(float));
    uint32_t state = 12345u;
    for (int j = 0; j < height; j++) {
        for (int i = 0; i < width; i++) {
            const size_t k = (size_t)j * width + i;
            for (int c = 0; c < 3; c++)
                hbao_grid_normal_row(&grid, j, c)[i] = k < sky ? 0.0f : b.normal[3 * k + c];
            raw[k] = (float)(test_random(&state) >> 8) / 16777216.0f;
        }
    }

    hbao_settings s;
    memset(&s, 0, sizeof s);
    s.blur_radius = s.grid_blur_radius = (blur - 1) / 2;
    s.blur_sharpness = sharpness;
    s.strength = 1.0f;
    s.threads = threads;
    s.implementation = implementation;
    s.blur_strips = (int)strips;
    const int strips_in =
        strips > 0 ? (int)strips
                   : hbao_blur_strips((int)width, s.grid_blur_radius, hbao_blur_strip_budget());
    for (int call = 0; call < calls; call++) {
        const double start = clock_seconds(CLOCK_PROCESS_CPUTIME_ID);
        if (hbao_finish(&s, &grid, raw, NULL, width, height, out, width) != HBAO_SUCCESS) {
            fprintf(stderr, "bench_blur: out of memory\n");
            return 1;
        }
        times[call] = 1e3 * (clock_seconds(CLOCK_PROCESS_CPUTIME_ID) - start);
    }
    /* FNV-1a over the output's bits: two builds that blur alike print the
     * same hash, and one bit of difference changes it */
    uint64_t hash = 14695981039346656037u;
    const unsigned char *bytes = (const unsigned char *)out;
    for (size_t k = 0; k < pixels * sizeof(float); k++) hash = (hash ^ bytes[k]) * 1099511628211u;
    double fastest = times[0];
    for (int call = 1; call < calls; call++)
        fastest = times[call] < fastest ? times[call] : fastest;
    printf("bench_blur %ldx%ld, blur %ld, sharpness %g, %ld thread(s), %ld %% background, "
           "%d strip(s), %s: fastest %.2f, median %.2f CPU ms over %ld calls; output hash "
           "%016llx\n",
           width, height, blur, (double)sharpness, threads, background,
           strips_in < width ? strips_in : (int)width,
           hbao_implementation_name(hbao_finish_implementation(implementation)), fastest,
           median_of(times, (int)calls), calls, (unsigned long long)hash);
    free(times);
    free(out);
    hbao_scratch_give(raw);
    hbao_scratch_give(grid.normal);
    hbao_scratch_give(grid.depth);
    free(b.normal);
    free(b.depth);
    return 0;
}
