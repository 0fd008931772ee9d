/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Speed of hbao_compute() through the public API, on a synthetic scene that
 * fills the frame (a room corner with a box, no background), for the
 * settings issue 11 sets targets for: the defaults (cosine 4 x 16, blur 5)
 * at 1920x1080 full and half resolution, 8 x 6 with a 15-pixel blur, and the
 * defaults at 3840x2160. Each row is timed for every implementation the CPU
 * has (the scalar reference on 1 thread, the generic kernel, AVX2 and
 * AVX-512 on 1 and 2 threads; --implementations picks which), median of --runs rounds after a
 * warm-up round; a round times every column once, so that ratios compare
 * like with like on a loaded machine. The blur's share is the row's time
 * minus the same row without blur, over the row's time, on the last column. Prints
 * Markdown tables. Not a test: it asserts nothing, but says when a column's
 * output is not bit-identical to the scalar column's. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_common.h"
#include "hbao.h"

/* Issue 11's targets, all for 1920x1080 on 2 threads (the medians of the
 * fastest implementation), and the speed-up over the scalar reference on 1
 * thread. */
#define TARGET_DEFAULTS_FULL_MS 30.0
#define TARGET_8X6_BLUR15_MS 40.0
#define TARGET_DEFAULTS_HALF_MS 12.0
#define TARGET_SPEEDUP 25.0

typedef struct bench_row {
    const char *name;
    int width, height;
    int directions, steps, blur_size, half_resolution;
    double target_ms; /* 0: none */
} bench_row;

typedef struct bench_column {
    const char *name;
    int implementation, threads;
} bench_column;

static const bench_column all_columns[] = {
    {"scalar, 1 thread", HBAO_IMPLEMENTATION_SCALAR, 1},
    {"generic, 1 thread", HBAO_IMPLEMENTATION_GENERIC, 1},
    {"generic, 2 threads", HBAO_IMPLEMENTATION_GENERIC, 2},
    {"AVX2, 1 thread", HBAO_IMPLEMENTATION_AVX2, 1},
    {"AVX2, 2 threads", HBAO_IMPLEMENTATION_AVX2, 2},
    {"AVX-512, 1 thread", HBAO_IMPLEMENTATION_AVX512, 1},
    {"AVX-512, 2 threads", HBAO_IMPLEMENTATION_AVX512, 2},
};
#define COLUMN_COUNT ((int)(sizeof all_columns / sizeof all_columns[0]))

/* One call's wall-clock and process CPU seconds (all threads together; on
 * a loaded machine the steadier of the two). Returns 0 on error. */
typedef struct timing {
    double wall, cpu;
} timing;

static int time_call(const hbao_params *p, const bench_scene *b, float *ao, timing *t) {
    const int w = b->view.width, h = b->view.height;
    hbao_channel d = {b->depth, 1, w};
    hbao_channel n = {b->normal, 3, 3 * (int64_t)w};
    const double start = clock_seconds(CLOCK_MONOTONIC);
    const double cpu_start = clock_seconds(CLOCK_PROCESS_CPUTIME_ID);
    const hbao_result result = hbao_compute(p, &b->view.camera, w, h, &d, &n, ao, w);
    t->cpu = clock_seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu_start;
    t->wall = clock_seconds(CLOCK_MONOTONIC) - start;
    if (result != HBAO_SUCCESS) {
        fprintf(stderr, "bench_speed: %s\n", hbao_result_message(result));
        return 0;
    }
    return 1;
}

/* The median of a row's rounds and its fastest and slowest round (sorts
 * values[0 .. count)): on a shared machine the spread says how far one
 * run's median can move. */
typedef struct round_spread {
    double median, low, high;
} round_spread;

static round_spread spread_of(double *values, int count) {
    const double median = median_of(values, count);
    return (round_spread){median, values[0], values[count - 1]};
}

static int parse_implementations(const char *list, int wanted[COLUMN_COUNT]) {
    for (int c = 0; c < COLUMN_COUNT; c++) wanted[c] = 0;
    char copy[256];
    snprintf(copy, sizeof copy, "%s", list);
    for (char *token = strtok(copy, ","); token != NULL; token = strtok(NULL, ",")) {
        const int implementation = bench_implementation(token);
        if (implementation < 0) return 0;
        for (int c = 0; c < COLUMN_COUNT; c++)
            if (all_columns[c].implementation == implementation) wanted[c] = 1;
    }
    return 1;
}

static void usage(const char *program) {
    fprintf(stderr,
            "usage: %s [--runs N] [--implementations LIST] [--no-4k] [--quick] [--radius R]\n"
            "  LIST: comma-separated scalar,generic,avx2,avx512 (default: all this CPU has)\n"
            "  --quick: --runs 3 --no-4k\n",
            program);
}

int main(int argc, char **argv) {
    int runs = 5, with_4k = 1;
    float radius = 0.5f;
    int wanted[COLUMN_COUNT];
    parse_implementations("scalar,generic,avx2,avx512", wanted);
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--runs") && a + 1 < argc)
            runs = (int)bench_whole_number(argv[++a], 1, 1000);
        else if (!strcmp(argv[a], "--radius") && a + 1 < argc)
            radius = bench_positive_number(argv[++a]);
        else if (!strcmp(argv[a], "--no-4k"))
            with_4k = 0;
        else if (!strcmp(argv[a], "--quick")) { /* the README's quick look */
            runs = 3;
            with_4k = 0;
        } else if (!strcmp(argv[a], "--implementations") && a + 1 < argc) {
            if (!parse_implementations(argv[++a], wanted)) {
                usage(argv[0]);
                return 2;
            }
        } else {
            usage(argv[0]);
            return 2;
        }
    }
    if (runs < 1 || runs > 1000 || !(radius > 0.0f)) {
        fprintf(stderr, "bench_speed: --runs must be in [1, 1000] and --radius > 0\n");
        return 2;
    }
    /* A column the CPU cannot run would silently fall back to a lesser
     * kernel (the library's rule), so it is left out instead. */
    const int best = hbao_best_implementation();
    for (int c = 0; c < COLUMN_COUNT; c++)
        if (hbao_implementation_that_runs(all_columns[c].implementation) !=
            all_columns[c].implementation)
            wanted[c] = 0;

    const bench_row rows[] = {
        {"defaults, full", 1920, 1080, HBAO_DEFAULT_DIRECTIONS, HBAO_DEFAULT_STEPS,
         HBAO_DEFAULT_BLUR_SIZE, 0, TARGET_DEFAULTS_FULL_MS},
        {"defaults, half", 1920, 1080, HBAO_DEFAULT_DIRECTIONS, HBAO_DEFAULT_STEPS,
         HBAO_DEFAULT_BLUR_SIZE, 1, TARGET_DEFAULTS_HALF_MS},
        {"8 x 6, blur 15, full", 1920, 1080, 8, 6, 15, 0, TARGET_8X6_BLUR15_MS},
        {"defaults, full, 4K", 3840, 2160, HBAO_DEFAULT_DIRECTIONS, HBAO_DEFAULT_STEPS,
         HBAO_DEFAULT_BLUR_SIZE, 0, 0.0},
    };
    const int row_count = (int)(sizeof rows / sizeof rows[0]) - (with_4k ? 0 : 1);

    printf("# hbao_compute speed: radius %g (scene ~3-7 units deep), median of %d rounds after a "
           "warm-up round, ms per frame\n\n",
           radius, runs);
    printf(
        "Cosine integration; 'defaults' = %d directions x %d steps, blur %d. Best implementation "
        "on this CPU: %s (SIMD kernels compiled by %s). The scalar column is the portable "
        "reference code (horizon search and blur) on 1 thread. A round times every column once "
        "(and the last one without blur). Cells: median "
        "wall-clock ms (median process CPU ms, all threads together). Speed-up and blur share "
        "((time - time without blur) / time, on the last column: wall, with the least and the "
        "greatest round's; CPU; the blur's own CPU ms) are medians of the per-round values.\n",
        HBAO_DEFAULT_DIRECTIONS, HBAO_DEFAULT_STEPS, HBAO_DEFAULT_BLUR_SIZE,
        hbao_implementation_name(best), HBAO_KERNELS_BUILT_BY);
    print_load("before");
    printf("\n| settings | size |");
    int last_column = -1, scalar_column = -1;
    for (int c = 0; c < COLUMN_COUNT; c++) {
        if (!wanted[c]) continue;
        printf(" %s |", all_columns[c].name);
        last_column = c;
        if (all_columns[c].implementation == HBAO_IMPLEMENTATION_SCALAR) scalar_column = c;
    }
    if (last_column < 0) {
        fprintf(stderr, "bench_speed: no implementation to time\n");
        return 2;
    }
    printf(" speed-up (scalar 1 thread / last) | blur share |\n|---|---|");
    for (int c = 0; c < COLUMN_COUNT; c++)
        if (wanted[c]) printf("---|");
    printf("---|---|\n");
    fflush(stdout);

    /* Rounds: every variant (each column, and the last column without blur)
     * is timed once per round, so that a change of load during the run
     * affects them alike; ratios are taken within a round, then the median
     * over rounds. */
    enum { VARIANTS = COLUMN_COUNT + 1, UNBLURRED = COLUMN_COUNT };
    double measured[8][COLUMN_COUNT], speedup[8];
    /* the last column's fastest and slowest round, for the targets table:
     * on a shared machine they show how far one run's median can move */
    double round_fastest[8], round_slowest[8];
    int mismatched = 0;
    timing *times = malloc((size_t)VARIANTS * runs * sizeof(timing));
    double *scratch = malloc(2 * (size_t)runs * sizeof(double));
    if (times == NULL || scratch == NULL) {
        fprintf(stderr, "bench_speed: out of memory\n");
        return 1;
    }
    for (int r = 0; r < row_count; r++) {
        const bench_row *row = &rows[r];
        bench_scene b;
        bench_scene_make(&b, row->width, row->height);
        const size_t pixels = (size_t)row->width * row->height;
        float *ao = malloc(pixels * sizeof(float)), *reference = malloc(pixels * sizeof(float));
        if (ao == NULL || reference == NULL) {
            fprintf(stderr, "bench_speed: out of memory\n");
            return 1;
        }
        int have_reference = 0;
        for (int round = -1; round < runs; round++) { /* round -1: warm-up */
            for (int v = 0; v < VARIANTS; v++) {
                const int c = v == UNBLURRED ? last_column : v;
                if (!wanted[c]) continue;
                hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
                p.radius = radius;
                p.directions = row->directions;
                p.steps = row->steps;
                p.blur_size = v == UNBLURRED ? 0 : row->blur_size;
                p.half_resolution = row->half_resolution;
                p.implementation = all_columns[c].implementation;
                p.threads = all_columns[c].threads;
                timing t;
                if (!time_call(&p, &b, ao, &t)) return 1;
                if (round >= 0) times[v * runs + round] = t;
                if (round != -1 || v == UNBLURRED) continue;
                if (!have_reference) {
                    memcpy(reference, ao, pixels * sizeof(float));
                    have_reference = 1;
                } else if (memcmp(reference, ao, pixels * sizeof(float)) != 0) {
                    mismatched = 1;
                    fprintf(stderr, "bench_speed: %s, %s: output differs from the first column's\n",
                            row->name, all_columns[c].name);
                }
            }
        }
        printf("| %s | %dx%d |", row->name, row->width, row->height);
        for (int c = 0; c < COLUMN_COUNT; c++) {
            measured[r][c] = 0.0;
            if (!wanted[c]) continue;
            for (int k = 0; k < runs; k++) {
                scratch[k] = times[c * runs + k].wall;
                scratch[runs + k] = times[c * runs + k].cpu;
            }
            const round_spread wall = spread_of(scratch, runs);
            measured[r][c] = wall.median;
            if (c == last_column) {
                round_fastest[r] = wall.low;
                round_slowest[r] = wall.high;
            }
            printf(" %.1f (%.1f) |", 1e3 * wall.median, 1e3 * median_of(scratch + runs, runs));
        }
        speedup[r] = 0.0;
        if (scalar_column >= 0 && scalar_column != last_column) {
            for (int k = 0; k < runs; k++)
                scratch[k] =
                    times[scalar_column * runs + k].wall / times[last_column * runs + k].wall;
            speedup[r] = median_of(scratch, runs);
            printf(" %.1fx |", speedup[r]);
        } else {
            printf(" - |");
        }
        /* The blur's share, wall and CPU, and its own CPU time, per round. */
        for (int k = 0; k < runs; k++) {
            const timing with = times[last_column * runs + k],
                         without = times[UNBLURRED * runs + k];
            scratch[k] = (with.wall - without.wall) / with.wall;
            scratch[runs + k] = (with.cpu - without.cpu) / with.cpu;
        }
        const round_spread share_wall = spread_of(scratch, runs);
        const double share_cpu = median_of(scratch + runs, runs);
        for (int k = 0; k < runs; k++)
            scratch[k] = times[last_column * runs + k].cpu - times[UNBLURRED * runs + k].cpu;
        const double blur_cpu = median_of(scratch, runs);
        printf(" %.0f %% (rounds %.0f to %.0f %%; CPU %.0f %%; %.1f ms) |\n",
               100.0 * share_wall.median, 100.0 * share_wall.low, 100.0 * share_wall.high,
               100.0 * share_cpu, 1e3 * blur_cpu);
        fflush(stdout);
        free(ao);
        free(reference);
        free(b.depth);
        free(b.normal);
    }
    free(times);
    free(scratch);
    print_load("after");

    /* The stages around the horizon search alone: with a radius far under a
     * pixel no horizon is searched, so the time is depth conversion,
     * normals, upsample, blur and output. One thread, CPU time, the best
     * implementation: the steadiest measure of the blur's own cost. */
    {
        bench_scene b;
        bench_scene_make(&b, 1920, 1080);
        bench_near_pixel(b.depth);
        float *ao = malloc((size_t)1920 * 1080 * sizeof(float));
        double *cpu = malloc((size_t)runs * sizeof(double));
        if (ao == NULL || cpu == NULL) return 1;
        printf("\n## Stages around the horizon search, 1920x1080, %s, 1 thread, median CPU ms\n\n",
               hbao_implementation_name(best));
        printf("Radius 1e-4 (under a pixel everywhere but at one pixel brought near, so that the "
               "search is that pixel's): depth conversion, normals, [upsample], blur, output. "
               "Median CPU ms (fastest call's).\n\n");
        printf("| resolution | blur 0 | blur %d | blur 15 | blur %d alone | blur 15 alone |\n",
               HBAO_DEFAULT_BLUR_SIZE, HBAO_DEFAULT_BLUR_SIZE);
        printf("|---|---|---|---|---|---|\n");
        for (int half = 0; half <= 1; half++) {
            const int sizes[3] = {0, HBAO_DEFAULT_BLUR_SIZE, 15};
            double stage[3], fastest[3];
            for (int k = 0; k < 3; k++) {
                hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
                p.radius = 1e-4f;
                p.blur_size = sizes[k];
                p.half_resolution = half;
                p.threads = 1;
                fastest[k] = 1e30;
                for (int round = -1; round < runs; round++) {
                    timing t;
                    if (!time_call(&p, &b, ao, &t)) return 1;
                    if (round < 0) continue;
                    cpu[round] = t.cpu;
                    fastest[k] = t.cpu < fastest[k] ? t.cpu : fastest[k];
                }
                stage[k] = median_of(cpu, runs);
            }
            /* median (fastest call) */
            printf("| %s | %.1f (%.1f) | %.1f (%.1f) | %.1f (%.1f) | %.1f (%.1f) | %.1f (%.1f) |\n",
                   half ? "half" : "full", 1e3 * stage[0], 1e3 * fastest[0], 1e3 * stage[1],
                   1e3 * fastest[1], 1e3 * stage[2], 1e3 * fastest[2], 1e3 * (stage[1] - stage[0]),
                   1e3 * (fastest[1] - fastest[0]), 1e3 * (stage[2] - stage[0]),
                   1e3 * (fastest[2] - fastest[0]));
        }
        free(ao);
        free(cpu);
        free(b.depth);
        free(b.normal);
    }

    /* What a frame does not need is skipped: the same frame with and
     * without the thing that lets the library skip work. A round times
     * every case once, so that a change of load during the run affects
     * them alike, and each case's saving is the median of its per-round
     * ratio to the reference case of the same round. */
    {
        bench_scene b;
        bench_scene_make(&b, 1920, 1080);
        const size_t pixels = (size_t)1920 * 1080;
        enum { CASES = 7 };
        float *ao = malloc(pixels * sizeof(float)), *sky = malloc(pixels * sizeof(float));
        float *near = malloc(pixels * sizeof(float));
        double *wall = malloc((size_t)CASES * runs * sizeof(double));
        double *ratio = malloc((size_t)runs * sizeof(double));
        if (ao == NULL || sky == NULL || near == NULL || wall == NULL || ratio == NULL) return 1;
        memcpy(sky, b.depth, pixels * sizeof(float));
        bench_sky(sky, 1920, 1080, 50); /* the upper half: background */
        memcpy(near, b.depth, pixels * sizeof(float));
        bench_near_pixel(near);
        float *const full_depth = b.depth;
        printf("\n## Skips, 1920x1080, defaults, %s, wall ms\n\n", all_columns[last_column].name);
        printf("A round times every case once. Time: the median round, with the fastest and the "
               "slowest; time / reference: the median of the rounds' ratios.\n\n");
        printf("| what is skipped | frame | median ms | rounds: fastest - slowest | "
               "time / reference |\n|---|---|---|---|---|\n");
        const struct {
            const char *what, *frame;
            float radius;
            int depth;     /* 0: the scene's; 1: sky; 2: one pixel near */
            int half;      /* half resolution */
            int reference; /* the case whose time it is divided by */
        } cases[CASES] = {
            {"nothing (reference)", "every pixel geometry, radius 0.5", 0.5f, 0, 0, 0},
            {"background pixels and blocks", "upper half background, radius 0.5", 0.5f, 1, 0, 0},
            {"steps that land on the same pixel", "radius 0.02 (about 10 pixels)", 0.02f, 0, 0, 0},
            {"the horizon search (radius under a pixel but at one pixel)",
             "radius 1e-4, one pixel near", 1e-4f, 2, 0, 0},
            {"everything but the depths (radius under a pixel everywhere)", "radius 1e-4", 1e-4f, 0,
             0, 0},
            {"nothing (reference at half resolution)", "every pixel geometry, half resolution",
             0.5f, 0, 1, 5},
            {"background pixels, blocks and upsampled chunks",
             "upper half background, half resolution", 0.5f, 1, 1, 5},
        };
        for (int round = -1; round < runs; round++) {
            for (int c = 0; c < CASES; c++) {
                hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
                p.radius = cases[c].radius;
                p.half_resolution = cases[c].half;
                p.implementation = all_columns[last_column].implementation;
                p.threads = all_columns[last_column].threads;
                b.depth = cases[c].depth == 1 ? sky : cases[c].depth == 2 ? near : full_depth;
                timing t;
                if (!time_call(&p, &b, ao, &t)) return 1;
                if (round >= 0) wall[c * runs + round] = t.wall;
            }
        }
        /* every ratio first: spread_of sorts a case's rounds out of their order */
        double relative[CASES];
        for (int c = 0; c < CASES; c++) {
            for (int k = 0; k < runs; k++)
                ratio[k] = wall[c * runs + k] / wall[cases[c].reference * runs + k];
            relative[c] = median_of(ratio, runs);
        }
        for (int c = 0; c < CASES; c++) {
            const round_spread ms = spread_of(wall + c * runs, runs);
            printf("| %s | %s | %.1f | %.1f - %.1f | %.2f |\n", cases[c].what, cases[c].frame,
                   1e3 * ms.median, 1e3 * ms.low, 1e3 * ms.high, relative[c]);
        }
        b.depth = full_depth;
        free(ao);
        free(sky);
        free(near);
        free(wall);
        free(ratio);
        free(b.depth);
        free(b.normal);
    }

    /* The back-face layer (hbao_compute_layers): every surface 0.3 deep,
     * against the same frame without the layer. */
    {
        bench_scene b;
        bench_scene_make(&b, 1920, 1080);
        const size_t pixels = (size_t)1920 * 1080;
        float *ao = malloc(pixels * sizeof(float)), *back = malloc(pixels * sizeof(float));
        double *wall = malloc(2 * (size_t)runs * sizeof(double));
        double *ratio = malloc((size_t)runs * sizeof(double));
        if (ao == NULL || back == NULL || wall == NULL || ratio == NULL) return 1;
        for (size_t k = 0; k < pixels; k++) back[k] = b.depth[k] + 0.3f;
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.radius = radius;
        p.implementation = all_columns[last_column].implementation;
        p.threads = all_columns[last_column].threads;
        hbao_channel d = {b.depth, 1, 1920}, n = {b.normal, 3, 3 * 1920}, k = {back, 1, 1920};
        for (int round = -1; round < runs; round++) {
            for (int layered = 0; layered <= 1; layered++) {
                const double start = clock_seconds(CLOCK_MONOTONIC);
                const hbao_result result = hbao_compute_layers(&p, &b.view.camera, 1920, 1080, &d,
                                                               &n, layered ? &k : NULL, ao, 1920);
                if (result != HBAO_SUCCESS) return 1;
                if (round >= 0)
                    wall[layered * runs + round] = clock_seconds(CLOCK_MONOTONIC) - start;
            }
        }
        /* the rounds' ratios first: spread_of sorts the rounds out of their order */
        for (int r = 0; r < runs; r++) ratio[r] = wall[runs + r] / wall[r];
        const round_spread relative = spread_of(ratio, runs);
        const round_spread without = spread_of(wall, runs), with = spread_of(wall + runs, runs);
        printf("\n## Back-face layer, 1920x1080, defaults, %s, wall ms\n\n",
               all_columns[last_column].name);
        printf("A round times the frame without and with the layer. Times: the median round "
               "(fastest - slowest); ratio: the median of the rounds' ratios (least - "
               "greatest).\n\n");
        printf("| without the layer | with a layer (every surface 0.3 deep) | ratio |\n");
        printf("|---|---|---|\n| %.1f (%.1f - %.1f) | %.1f (%.1f - %.1f) | %.2fx (%.2f - "
               "%.2f) |\n",
               1e3 * without.median, 1e3 * without.low, 1e3 * without.high, 1e3 * with.median,
               1e3 * with.low, 1e3 * with.high, relative.median, relative.low, relative.high);
        free(ao);
        free(back);
        free(wall);
        free(ratio);
        free(b.depth);
        free(b.normal);
    }

    /* The targets beside the measurements of this run. */
    printf("\n## Issue 11 targets (%s)\n\n", all_columns[last_column].name);
    printf("| target | limit | measured median | rounds: fastest - slowest | met | speed-up over "
           "scalar, 1 thread |\n");
    printf("|---|---|---|---|---|---|\n");
    for (int r = 0; r < row_count; r++) {
        if (rows[r].target_ms <= 0.0) continue;
        const double ms = 1e3 * measured[r][last_column];
        printf("| %s, %dx%d | <= %.0f ms | %.1f ms | %.1f - %.1f ms | %s |", rows[r].name,
               rows[r].width, rows[r].height, rows[r].target_ms, ms, 1e3 * round_fastest[r],
               1e3 * round_slowest[r], ms <= rows[r].target_ms ? "yes" : "no");
        if (speedup[r] > 0.0)
            printf(" %.1fx |\n", speedup[r]);
        else
            printf(" - |\n");
    }
    if (speedup[0] > 0.0)
        printf("| speed-up over the scalar reference on 1 thread (defaults, full) | >= %.0fx | "
               "%.1fx | | "
               "%s | |\n",
               TARGET_SPEEDUP, speedup[0], speedup[0] >= TARGET_SPEEDUP ? "yes" : "no");
    if (mismatched) printf("\nWARNING: some columns' output was not bit-identical (see stderr).\n");
    return 0;
}
