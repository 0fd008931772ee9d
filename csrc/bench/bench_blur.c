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
 *              [--threads T] [--implementation scalar|avx2|avx512]
 * Prints one line: the fastest and the median CPU ms of N calls, and a
 * checksum of the output (the same for every build that blurs alike). */
#include <stdint.h>

#include "bench_common.h"
#include "internal_finish.h"

static void usage(const char *program) {
    fprintf(stderr,
            "usage: %s [--calls N] [--blur B] [--sharpness S] [--size WxH] [--threads T]\n"
            "  [--implementation scalar|avx2|avx512] (default: the best this CPU has)\n",
            program);
}

int main(int argc, char **argv) {
    int calls = 10, blur = 15, width = 1920, height = 1080, threads = 1;
    int implementation = HBAO_IMPLEMENTATION_AUTO;
    float sharpness = HBAO_DEFAULT_BLUR_SHARPNESS;
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--calls") && a + 1 < argc)
            calls = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--blur") && a + 1 < argc)
            blur = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--sharpness") && a + 1 < argc)
            sharpness = (float)atof(argv[++a]);
        else if (!strcmp(argv[a], "--threads") && a + 1 < argc)
            threads = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--size") && a + 1 < argc) {
            if (sscanf(argv[++a], "%dx%d", &width, &height) != 2) width = 0;
        } else if (!strcmp(argv[a], "--implementation") && a + 1 < argc) {
            implementation = bench_implementation(argv[++a]);
        } else {
            usage(argv[0]);
            return 2;
        }
    }
    if (calls < 1 || calls > 1000 || blur < 1 || blur > HBAO_MAX_BLUR_SIZE || blur % 2 == 0 ||
        !(sharpness >= 0.0f && sharpness <= HBAO_MAX_BLUR_SHARPNESS) || width < 16 || height < 16 ||
        width > 16384 || height > 16384 || threads < 1 || threads > 64 || implementation < 0) {
        usage(argv[0]);
        fprintf(stderr,
                "bench_blur: --calls 1-1000, --blur an odd size 1-%d, --sharpness 0-%g, "
                "--size 16-16384 each way, --threads 1-64\n",
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
    memset(grid.normal + 3 * pixels, 0, HBAO_NORMAL_PADDING * sizeof(float));
    uint32_t state = 12345u;
    for (int j = 0; j < height; j++) {
        for (int i = 0; i < width; i++) {
            const size_t k = (size_t)j * width + i;
            for (int c = 0; c < 3; c++) hbao_grid_normal_row(&grid, j, c)[i] = b.normal[3 * k + c];
            state = state * 1664525u + 1013904223u;
            raw[k] = (float)(state >> 8) / 16777216.0f;
        }
    }

    hbao_settings s;
    memset(&s, 0, sizeof s);
    s.blur_radius = s.grid_blur_radius = (blur - 1) / 2;
    s.blur_sharpness = sharpness;
    s.strength = 1.0f;
    s.threads = threads;
    s.implementation = implementation;
    for (int call = 0; call < calls; call++) {
        const double start = clock_seconds(CLOCK_PROCESS_CPUTIME_ID);
        if (hbao_finish(&s, &grid, raw, grid.depth, width, height, out, width) != HBAO_SUCCESS) {
            fprintf(stderr, "bench_blur: out of memory\n");
            return 1;
        }
        times[call] = 1e3 * (clock_seconds(CLOCK_PROCESS_CPUTIME_ID) - start);
    }
    double checksum = 0.0;
    for (size_t k = 0; k < pixels; k++) checksum += out[k];
    double fastest = times[0];
    for (int call = 1; call < calls; call++)
        fastest = times[call] < fastest ? times[call] : fastest;
    static const char *const names[] = {"auto", "scalar", "AVX2", "AVX-512"};
    printf("bench_blur %dx%d, blur %d, sharpness %g, %d thread(s), %s: fastest %.2f, median "
           "%.2f CPU ms over %d calls; checksum %.6f\n",
           width, height, blur, (double)sharpness, threads,
           names[hbao_finish_implementation(implementation)], fastest, median_of(times, calls),
           calls, checksum);
    free(times);
    free(out);
    hbao_scratch_give(raw);
    hbao_scratch_give(grid.normal);
    hbao_scratch_give(grid.depth);
    free(b.normal);
    free(b.depth);
    return 0;
}
