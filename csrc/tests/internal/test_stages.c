/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The library's stages tested from inside, on inputs that hbao_compute()
 * cannot be made to produce (the blur, hbao_finish, on a raw AO of the
 * test's choosing) or against answers that its AO would hide (the
 * upsample's weights, the blur's and the upsample's formulas, the normals,
 * the settings hbao_compute derives). Linked with the library's own objects
 * (CMakeLists.txt, hbao_add_internal_executable). */
#ifdef __linux__
#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* sched_setaffinity */
#endif
#include <malloc.h> /* mallopt */
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <unistd.h>
#endif
#include <stdint.h>

#include "background_runs.h"
#include "huge_block.h"
#include "internal_finish.h"
#include "test_harness.h"
#include "test_random.h"
#ifdef HBAO_FINISH_X86
#include <immintrin.h>
#endif

/* 24 random bits (test_random.h) */
static uint32_t next_random(uint32_t *state) {
    return test_random(state) >> 8;
}

/* A w x h grid of these depths and normals, nothing else set. */
static hbao_grid grid_of(int w, int h, float *depth, float *normal) {
    hbao_grid grid;
    memset(&grid, 0, sizeof grid);
    grid.width = w;
    grid.height = h;
    grid.depth = depth;
    grid.normal = normal;
    return grid;
}

/* A w x h grid whose rows mix background (0) with ordinary depths and, on
 * rows of their own, depths so small that the blur's depth factor is
 * capped (1e-40, and 1e-38 above sharpness 3.4) or so large that it is
 * tiny (1e30, 3e38: denormal where denormals are flushed), each kind of
 * row in its own proportions; random unit normals; two pixels in three
 * take their left neighbour's depth and normal (so that taps weigh
 * something); a random raw AO. */
static void make_grid(hbao_grid *grid, int w, int h, float *depth, float *normal, float *raw) {
    static const float small[] = {1e-40f, 1e-38f, 1e-30f}, large[] = {1e30f, 3e38f};
    *grid = grid_of(w, h, depth, normal);
    uint32_t state = 2024u;
    for (int j = 0; j < h; j++) {
        /* 0: ordinary; 1: small depths too; 2: no background; 3: sparse;
         * 4: large depths too */
        const int kind = j % 5;
        for (int i = 0; i < w; i++) {
            const uint32_t r = next_random(&state);
            float z =
                i > 0 && r % 3 != 0 ? depth[j * w + i - 1] : 1.0f + (float)(r % 1000) / 250.0f;
            if (kind == 1 && r % 5 == 0) z = small[(r >> 4) % 3];
            if (kind == 4 && r % 5 == 0) z = large[(r >> 4) % 2];
            if (kind != 2 && r % (kind == 3 ? 2 : 6) == 1) z = 0.0f;
            depth[j * w + i] = z;
            raw[j * w + i] = (float)next_random(&state) / 16777216.0f;
            float n[3] = {0.0f, 0.0f, 0.0f};
            if (i > 0 && r % 3 != 0) {
                hbao_grid_normal_at(grid, i - 1, j, n);
            } else {
                float length = 0.0f;
                for (int c = 0; c < 3; c++) {
                    n[c] = (float)next_random(&state) / 8388608.0f - 1.0f;
                    length += n[c] * n[c];
                }
                length = sqrtf(length) > 0.0f ? sqrtf(length) : 1.0f;
                for (int c = 0; c < 3; c++) n[c] /= length;
            }
            for (int c = 0; c < 3; c++) hbao_grid_normal_row(grid, j, c)[i] = n[c];
        }
    }
}

/* The settings of a blur alone (hbao_finish) at full resolution: radius,
 * sharpness, strength 1, the rest 0 (strips by blur.c's rule). */
static hbao_settings blur_settings(int radius, float sharpness, int threads, int implementation) {
    hbao_settings settings;
    memset(&settings, 0, sizeof settings);
    settings.blur_radius = settings.grid_blur_radius = radius;
    settings.blur_sharpness = sharpness;
    settings.strength = 1.0f;
    settings.threads = threads;
    settings.implementation = implementation;
    return settings;
}

/* The comparison of blur_copies_agree_on_background_at_every_sharpness,
 * in the floating-point mode it is called in (flush: its name, printed). */
static void compare_copies(const hbao_grid *g, const float *depth, const float *raw,
                           const char *flush) {
    enum { w = 97, h = 41 };
    static float reference[w * h], out[w * h];
    hbao_grid grid = *g;
    static const float sharpness[] = {0.0f, 2.0f, 4.0f, 4.001f, 4.01f, 32.0f, 1000.0f};
    static const int radii[] = {1, 7, 12};
    for (size_t s = 0; s < sizeof sharpness / sizeof sharpness[0]; s++) {
        for (size_t r = 0; r < sizeof radii / sizeof radii[0]; r++) {
            hbao_settings settings =
                blur_settings(radii[r], sharpness[s], 1, HBAO_IMPLEMENTATION_SCALAR);
            CHECK_RESULT(hbao_finish(&settings, &grid, raw, NULL, w, h, reference, w),
                         HBAO_SUCCESS);
            int blurred = 0;
            for (int k = 0; k < w * h; k++) blurred += depth[k] > 0.0f && reference[k] != raw[k];
            CHECK(blurred > w * h / 3);
            for (int implementation = HBAO_IMPLEMENTATION_AVX2;
                 implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
                settings.implementation = implementation;
                settings.threads = implementation == HBAO_IMPLEMENTATION_AVX2 ? 1 : 2;
                CHECK_RESULT(hbao_finish(&settings, &grid, raw, NULL, w, h, out, w), HBAO_SUCCESS);
                int differ = 0;
                for (int k = 0; k < w * h; k++) differ += memcmp(&out[k], &reference[k], 4) != 0;
                if (differ)
                    printf("  %s, sharpness %g, radius %d, implementation %d: %d pixels differ\n",
                           flush, (double)sharpness[s], radii[r], implementation, differ);
                CHECK(differ == 0);
            }
        }
    }
}

/* Every copy of the blur gives the scalar reference's floats, at every
 * sharpness: around SELF_MASKING_SHARPNESS (blur.c), above which a row's
 * vector loop leaves out the test for background taps, and on rows whose
 * small or large depths need the test at any sharpness
 * (background_needs_check); also with denormals flushed to zero, as a
 * host application's threads may run (Blender's may), where the large
 * depths' factor becomes 0. */
TEST_CASE(blur_copies_agree_on_background_at_every_sharpness) {
    enum { w = 97, h = 41 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING], raw[w * h];
    hbao_grid grid;
    make_grid(&grid, w, h, depth, normal, raw);
    if (hbao_best_implementation() != HBAO_IMPLEMENTATION_AVX512)
        printf("  no AVX-512 on this CPU: its copy falls back to a slower one's\n");
#ifdef HBAO_FINISH_X86
    const unsigned int mxcsr = _mm_getcsr();
    for (int flush = 0; flush < 2; flush++) {
        _mm_setcsr(flush ? mxcsr | 0x8040u : mxcsr); /* FTZ | DAZ */
        compare_copies(&grid, depth, raw, flush ? "denormals flushed" : "IEEE denormals");
    }
    _mm_setcsr(mxcsr);
#else
    compare_copies(&grid, depth, raw, "IEEE denormals");
#endif
}

/* The blur of picture `grid` (raw AO `raw`, out_stride floats a row of
 * out) in `strips` strips against `whole` (one strip, packed), with the
 * scratch filled with NaN, so that a strip reading a column of its rows
 * that it did not write shows, and with the output's padding (out_stride
 * past the width) left as it was. */
static void compare_strips(const hbao_grid *grid, const float *raw, hbao_settings settings,
                           int strips, const float *whole, float *out, int out_stride) {
    const int w = grid->width, h = grid->height;
    settings.blur_strips = strips;
    for (int k = 0; k < out_stride * h; k++) out[k] = -2.0f;
    hbao_scratch_fill = 0xff;
    CHECK_RESULT(hbao_finish(&settings, grid, raw, NULL, w, h, out, out_stride), HBAO_SUCCESS);
    hbao_scratch_fill = -1;
    int differ = 0, padding = 0;
    for (int j = 0; j < h; j++) {
        for (int i = 0; i < w; i++)
            differ += memcmp(&whole[j * w + i], &out[j * out_stride + i], sizeof *out) != 0;
        for (int i = w; i < out_stride; i++) padding += out[j * out_stride + i] != -2.0f;
    }
    if (differ || padding)
        printf("  %dx%d, sharpness %g, radius %d, implementation %d, %d strips, %d threads: %d "
               "pixels differ, %d of the padding written\n",
               w, h, (double)settings.blur_sharpness, settings.blur_radius, settings.implementation,
               strips, settings.threads, differ, padding);
    CHECK(differ == 0 && padding == 0);
}

/* A band of the blur's rows may be blurred in strips of columns (blur.c,
 * hbao_blur_strips: wide rows at a large radius), each pixel with the same
 * taps: from one strip to one a column (every pixel a strip's end), and
 * strips narrower than the radius or a vector, must give the floats of the
 * unsplit rows, for every copy, at a sharpness whose rows skip the
 * background test (32) and one whose rows test every tap (2), on 1 and 3
 * threads; also on pictures of one and two rows and narrower than a vector,
 * into an output whose rows are wider than the picture. Then the rule's
 * counts, and that hbao_compute's settings take them. */
TEST_CASE(blur_strips_give_the_same_floats) {
    enum { w = 97, h = 41, small_w = 7 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING], raw[w * h];
    static float whole[w * h], out[(w + 3) * h];
    hbao_grid grid;
    make_grid(&grid, w, h, depth, normal, raw);
    static const int radii[] = {0, 1, 7, 32}, counts[] = {2, 3, 6, 19, 40, w, 2 * w};
    static const float sharpness[] = {2.0f, 32.0f};
    for (size_t s = 0; s < sizeof sharpness / sizeof sharpness[0]; s++) {
        for (size_t r = 0; r < sizeof radii / sizeof radii[0]; r++) {
            for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
                 implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
                /* each copy once (the generic kernel's is the reference's,
                 * and one this CPU lacks falls back to another's): under
                 * qemu (scripts/test_arm64.sh) all four took 20 s */
                if (hbao_finish_implementation(implementation) != implementation) continue;
                hbao_settings settings = blur_settings(radii[r], sharpness[s], 1, implementation);
                settings.blur_strips = 1;
                CHECK_RESULT(hbao_finish(&settings, &grid, raw, NULL, w, h, whole, w),
                             HBAO_SUCCESS);
                for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
                    for (int threads = 1; threads <= 3; threads += 2) {
                        settings.threads = threads;
                        compare_strips(&grid, raw, settings, counts[k], whole, out, w + 3);
                    }
                }
                /* the first 1, 2 rows and small_w columns of the picture */
                for (int rows = 1; rows <= 2; rows++) {
                    hbao_grid part = grid;
                    part.width = small_w;
                    part.height = rows;
                    static float small_depth[small_w * 2], small_raw[small_w * 2],
                        small_normal[3 * small_w * 2 + HBAO_NORMAL_PADDING];
                    for (int j = 0; j < rows; j++)
                        for (int i = 0; i < small_w; i++) {
                            small_depth[j * small_w + i] = depth[j * w + i];
                            small_raw[j * small_w + i] = raw[j * w + i];
                        }
                    part.depth = small_depth;
                    part.normal = small_normal;
                    for (int j = 0; j < rows; j++)
                        for (int c = 0; c < 3; c++)
                            for (int i = 0; i < small_w; i++)
                                hbao_grid_normal_row(&part, j, c)[i] =
                                    hbao_grid_normal_row(&grid, j, c)[i];
                    settings.threads = 1;
                    settings.blur_strips = 1;
                    CHECK_RESULT(hbao_finish(&settings, &part, small_raw, NULL, small_w, rows,
                                             whole, small_w),
                                 HBAO_SUCCESS);
                    for (int strips = 2; strips <= small_w; strips += 5)
                        compare_strips(&part, small_raw, settings, strips, whole, out, w);
                }
            }
        }
    }
    /* The rule, at 384 KiB (three quarters of a Zen 3 core's cache): a
     * 1080p row at blur 15 (563 KiB of rows) in two strips, at blur 5 (188
     * KiB) and a 4K row at blur 5 (375 KiB) whole, at blur 65 in as many as
     * keep each 256 columns wide (7); a row under two such strips whole,
     * and no blur whole. */
    const double budget = 384.0 * 1024.0;
    CHECK(hbao_blur_strips(1920, 7, budget) == 2);
    CHECK(hbao_blur_strips(1920, 2, budget) == 1);
    CHECK(hbao_blur_strips(3840, 2, budget) == 1);
    CHECK(hbao_blur_strips(1920, 32, budget) == 7);
    CHECK(hbao_blur_strips(500, 32, budget) == 1);
    CHECK(hbao_blur_strips(16384, 0, budget) == 1);
    CHECK(hbao_blur_strips(16384, 32, 0.0) == 64); /* no budget at all: the most */
    CHECK(hbao_blur_strip_budget() > 0.0);
    /* hbao_compute's settings leave the count to the rule (a draft left it
     * unset, whatever the stack held: the same floats in narrow strips,
     * 1.7 times the defaults' time at 1080p) */
    hbao_settings made;
    memset(&made, 0x01, sizeof made);
    const hbao_params params = HBAO_PARAMS_DEFAULT_INITIALIZER;
    CHECK_RESULT(hbao_settings_make(&params, &made), HBAO_SUCCESS);
    CHECK(made.blur_strips == 0);
}

/* The blur's range weight F (docs/algorithm.md, "After sampling"), in
 * double, from the numbers the page gives: the exponent e = d^2 +
 * 8 (1 - min(n.c, 1)) with d = (sharpness / z_c)(z - z_c), and F(e) =
 * (1 - e / 16)^16 below 16, 0 from 16 on. */
static double documented_range_weight(double sharpness, double zc, double z, const float *nc,
                                      const float *n) {
    const double d = sharpness / zc * (z - zc);
    double facing = (double)n[0] * nc[0] + (double)n[1] * nc[1] + (double)n[2] * nc[2];
    if (facing > 1.0) facing = 1.0;
    const double e = d * d + 8.0 * (1.0 - facing);
    return e < 16.0 ? pow(1.0 - e / 16.0, 16.0) : 0.0;
}

/* One pass of the documented blur over the grid, in double: along the rows
 * (step 1) or down the columns (step w), taps k = -r..r inside the image,
 * each weighing exp(-k^2 / (2 sigma^2)) F [z > 0] with sigma = (r + 1) / 2,
 * the centre 1; background centres give 1. */
static void documented_blur_pass(const hbao_grid *grid, int radius, double sharpness, int along_row,
                                 const double *in, double *out) {
    const int w = grid->width, h = grid->height;
    const double sigma = 0.5 * (radius + 1);
    for (int j = 0; j < h; j++) {
        for (int i = 0; i < w; i++) {
            const double zc = grid->depth[j * w + i];
            if (!(zc > 0.0)) {
                out[j * w + i] = 1.0;
                continue;
            }
            float nc[3], n[3];
            hbao_grid_normal_at(grid, i, j, nc);
            double sum = in[j * w + i], weight_sum = 1.0;
            for (int k = -radius; k <= radius; k++) {
                const int x = along_row ? i + k : i, y = along_row ? j : j + k;
                if (k == 0 || x < 0 || x >= w || y < 0 || y >= h) continue;
                const double z = grid->depth[y * w + x];
                if (!(z > 0.0)) continue;
                hbao_grid_normal_at(grid, x, y, n);
                const double weight = exp(-(double)(k * k) / (2.0 * sigma * sigma)) *
                                      documented_range_weight(sharpness, zc, z, nc, n);
                sum += weight * in[y * w + x];
                weight_sum += weight;
            }
            out[j * w + i] = sum / weight_sum;
        }
    }
}

/* The blur gives what docs/algorithm.md writes, to float rounding: rows,
 * then columns, on a grid whose depths (2 to 2.1, a step to 3, a column of
 * background) and normals (up to ~35 degrees apart) give each tap a weight
 * between 0 and 1, at the default sharpness and a high one, radii 2 (blur
 * 5) and 7 (blur 15); every copy, on 1 and 2 threads. The tolerance, 2e-5,
 * is float rounding over 31 taps of AO in [0, 1] (the copies' floats
 * differ from double by ~1e-6); a tap left out or added, a normal
 * sharpness of 7 for 8 or a sigma off by half a pixel moves pixels by
 * more than 1e-3. */
TEST_CASE(blur_follows_its_formula) {
    enum { w = 61, h = 37 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING], raw[w * h], out[w * h];
    static double in[w * h], rows[w * h], expected[w * h];
    hbao_grid grid = grid_of(w, h, depth, normal);
    uint32_t state = 77u;
    for (int j = 0; j < h; j++) {
        for (int i = 0; i < w; i++) {
            const int k = j * w + i;
            depth[k] = 2.0f + (float)(next_random(&state) % 100) / 1000.0f;
            if (i > 40 && j > 20) depth[k] = 3.0f;
            if (i == 13) depth[k] = 0.0f;
            /* a normal tilted up to 0.35 rad from the view axis, as a face
             * seen from the camera */
            const float a = (float)(next_random(&state) % 1000) / 1000.0f * 6.2831853f;
            const float t = (float)(next_random(&state) % 1000) / 1000.0f * 0.35f;
            const float n[3] = {sinf(t) * cosf(a), sinf(t) * sinf(a), cosf(t)};
            for (int c = 0; c < 3; c++) hbao_grid_normal_row(&grid, j, c)[i] = n[c];
            raw[k] = (float)(next_random(&state) % 1000) / 1000.0f;
            in[k] = raw[k];
        }
    }
    static const float sharpness[] = {32.0f, 200.0f};
    static const int radii[] = {2, 7};
    for (size_t s = 0; s < sizeof sharpness / sizeof sharpness[0]; s++) {
        for (size_t r = 0; r < sizeof radii / sizeof radii[0]; r++) {
            documented_blur_pass(&grid, radii[r], sharpness[s], 1, in, rows);
            documented_blur_pass(&grid, radii[r], sharpness[s], 0, rows, expected);
            int changed = 0;
            for (int k = 0; k < w * h; k++) changed += fabs(expected[k] - in[k]) > 0.05;
            CHECK(changed > w * h / 2); /* the taps weigh something */
            for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
                 implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
                for (int threads = 1; threads <= 2; threads++) {
                    const hbao_settings settings =
                        blur_settings(radii[r], sharpness[s], threads, implementation);
                    CHECK_RESULT(hbao_finish(&settings, &grid, raw, NULL, w, h, out, w),
                                 HBAO_SUCCESS);
                    int off = 0;
                    double worst = 0.0;
                    for (int k = 0; k < w * h; k++) {
                        const double error = fabs(out[k] - expected[k]);
                        off += !(error <= 2e-5);
                        worst = error > worst ? error : worst;
                    }
                    if (off)
                        printf("  sharpness %g, radius %d, implementation %d, %d threads: %d "
                               "pixels off, worst %.3g\n",
                               (double)sharpness[s], radii[r], implementation, threads, off, worst);
                    CHECK(off == 0);
                }
            }
        }
    }
}

/* A blur of size b reaches r = (b - 1) / 2 pixels each side (none below
 * 2); at half resolution its taps on the half grid, 2 full pixels apart,
 * reach as far: the fewest whose reach is at least r (docs/algorithm.md,
 * r_grid = (r + 1) / 2), for every size up to the limit. */
TEST_CASE(half_resolution_blur_reaches_as_far) {
    for (int size = 0; size <= HBAO_MAX_BLUR_SIZE; size++) {
        hbao_params params = HBAO_PARAMS_DEFAULT_INITIALIZER;
        params.blur_size = size;
        hbao_settings full, half;
        CHECK_RESULT(hbao_settings_make(&params, &full), HBAO_SUCCESS);
        params.half_resolution = 1;
        CHECK_RESULT(hbao_settings_make(&params, &half), HBAO_SUCCESS);
        const int reach = size >= 2 ? (size - 1) / 2 : 0;
        const int taps = half.grid_blur_radius;
        const int ok = full.grid_blur_radius == reach && 2 * taps >= reach &&
                       (taps == 0 || 2 * (taps - 1) < reach);
        if (!ok)
            printf("  blur %d: %d taps at full resolution, %d on the half grid\n", size,
                   full.grid_blur_radius, taps);
        CHECK(ok);
    }
}

/* The half grid of a width x height image: ceil(width / 2) x
 * ceil(height / 2) pixels, with depths `depth` (no normals). */
static hbao_grid half_grid_of(int width, int height, float *depth) {
    hbao_grid half;
    memset(&half, 0, sizeof half);
    half.width = (width + 1) / 2;
    half.height = (height + 1) / 2;
    half.depth = depth;
    return half;
}

/* The half-resolution upsample (hbao_upsample_row) on a flat depth, where
 * only the bilinear weights count: a full-resolution pixel on a half-grid
 * column (and row) takes that sample's AO, one between two the mean of
 * both, and the last column (row) of an even width (height), which has no
 * half column (row) beyond it, its left (upper) one's. A ramp of AO makes
 * every weight show: each copy, for odd and even sizes. */
TEST_CASE(upsample_weights_are_bilinear_on_a_flat_depth) {
    enum { max_width = 18, max_height = 12 };
    static const int sizes[][2] = {{17, 11}, {18, 12}, {18, 11}, {17, 12}};
    static float full_depth[max_width * max_height], half_depth[max_width * max_height];
    static float half_ao[max_width * max_height], row[max_width];
    for (size_t size = 0; size < sizeof sizes / sizeof sizes[0]; size++) {
        const int width = sizes[size][0], height = sizes[size][1];
        const hbao_grid half = half_grid_of(width, height, half_depth);
        const hbao_channel guide = {full_depth, 1, width};
        for (int k = 0; k < width * height; k++) full_depth[k] = 2.0f;
        for (int r = 0; r < half.height; r++) {
            for (int k = 0; k < half.width; k++) {
                half_depth[r * half.width + k] = 2.0f;
                half_ao[r * half.width + k] = 0.1f + 0.05f * (float)k + 0.03f * (float)r;
            }
        }
        for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
             implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
            const int copy = hbao_finish_implementation(implementation);
            int wrong = 0;
            for (int j = 0; j < height; j++) {
                hbao_upsample_row(copy, &half, half_ao, &guide, INFINITY, width, j, row);
                /* the half-grid position, the last column and row held */
                const double y = j / 2 + 1 < half.height ? 0.5 * j : (double)(j / 2);
                for (int i = 0; i < width; i++) {
                    const double x = i / 2 + 1 < half.width ? 0.5 * i : (double)(i / 2);
                    const double expected = 0.1 + 0.05 * x + 0.03 * y;
                    wrong += !(fabs(row[i] - expected) <= 1e-6);
                }
            }
            if (wrong)
                printf("  %dx%d, implementation %d: %d pixels off\n", width, height, implementation,
                       wrong);
            CHECK(wrong == 0);
        }
    }
}

/* The documented upsample (docs/algorithm.md, "After sampling") of full
 * pixel (i, j) at depth z, in double: the half-grid samples at
 * floor(i/2) + {0, i odd} x floor(j/2) + {0, j odd} with their bilinear
 * weights (all on the left or upper one where there is no column or row
 * beyond) times F((16 |z_s - z| / z)^2), F the blur's falloff (F(e) =
 * (1 - e / 16)^16 below 16, 0 from 16 on), background samples and those
 * of bilinear weight 0 left out; where the weights sum to at most 1e-6, the
 * AO of the sample nearest in depth, of least |z_s - z| (the first of
 * equals, in the order left top, right top, left bottom, right bottom), 1
 * if none. Sets *sum to
 * the weights' sum and *blend_nearest_gap to how far apart the blend and
 * the nearest sample's AO are (what the fallback's threshold decides). */
static double documented_upsample(const hbao_grid *half, const float *half_ao, int i, int j,
                                  double z, double *sum, double *blend_nearest_gap) {
    *sum = 0.0;
    *blend_nearest_gap = 0.0;
    if (!(z > 0.0)) return 1.0;
    const int x0 = i / 2, y0 = j / 2;
    const int has_right = (i & 1) && x0 + 1 < half->width,
              has_below = (j & 1) && y0 + 1 < half->height;
    double weighted = 0.0, nearest_ao = 1.0, nearest = INFINITY;
    for (int c = 0; c < 4; c++) {
        const int dx = c & 1, dy = c >> 1;
        const double bx = has_right ? 0.5 : (dx ? 0.0 : 1.0);
        const double by = has_below ? 0.5 : (dy ? 0.0 : 1.0);
        const int at = (y0 + (dy && has_below)) * half->width + x0 + (dx && has_right);
        const double zs = half->depth[at];
        if (!(bx * by > 0.0) || !(zs > 0.0)) continue;
        const double gap = fabs(zs - z);
        const double e = (16.0 * gap / z) * (16.0 * gap / z);
        const double weight = bx * by * (e < 16.0 ? pow(1.0 - e / 16.0, 16.0) : 0.0);
        weighted += weight * half_ao[at];
        *sum += weight;
        if (gap < nearest) {
            nearest = gap;
            nearest_ao = half_ao[at];
        }
    }
    if (*sum > 0.0) *blend_nearest_gap = fabs(weighted / *sum - nearest_ao);
    const double ao = *sum > 1e-6 ? weighted / *sum : nearest_ao;
    return ao < 0.0 ? 0.0 : (ao > 1.0 ? 1.0 : ao);
}

/* How many pixels copy `implementation` (resolved by
 * hbao_finish_implementation) upsamples more than 1e-5 from
 * documented_upsample, half_ao on `half` guided by `guide` (width x height;
 * row: width floats of room). Pixels whose weights sum to within 1 % of the
 * fallback's 1e-6 are not compared (float and double may take different
 * sides): the scalar copy counts them in *not_compared, and in *blended and
 * *fallen_back the pixels that a fallback at 1e-5 or 1e-7 would move by more
 * than 0.05. */
static int upsample_off_documented(const hbao_grid *half, const float *half_ao,
                                   const hbao_channel *guide, int width, int height,
                                   int implementation, float *row, int *not_compared, int *blended,
                                   int *fallen_back) {
    const int copy = hbao_finish_implementation(implementation);
    const int counts = implementation == HBAO_IMPLEMENTATION_SCALAR;
    int off = 0;
    for (int j = 0; j < height; j++) {
        hbao_upsample_row(copy, half, half_ao, guide, INFINITY, width, j, row);
        for (int i = 0; i < width; i++) {
            double sum, gap;
            const double expected =
                documented_upsample(half, half_ao, i, j, guide->data[j * width + i], &sum, &gap);
            if (fabs(sum - 1e-6) < 1e-8) {
                *not_compared += counts;
                continue;
            }
            if (counts && gap > 0.05) {
                *blended += sum > 1e-6 && sum <= 1e-5;
                *fallen_back += sum > 1e-7 && sum <= 1e-6;
            }
            off += !(fabs(row[i] - expected) <= 1e-5);
        }
    }
    return off;
}

/* The upsample weighs depth as docs/algorithm.md writes, to 1e-5 (float
 * rounding, which F's four squarings multiply by 16): full depths 0.7 to 1.3 times
 * their half-grid sample's, in front and behind, and some background on
 * both grids, so that pixels blend their samples, fall back to the one
 * nearest in depth (where a sample in front is farther in relative depth
 * than one behind; the first of samples tied in depth), or are 1; odd and
 * even sizes, every copy. Pixels whose
 * weights sum to within 1 % of the fallback's 1e-6 are not compared (float
 * and double may take different sides). A sharpness of 15 for 16, a
 * signed depth difference or a fallback at 1e-5 or 1e-7 moves pixels by
 * more than 0.05. */
TEST_CASE(upsample_weighs_depth_as_documented) {
    enum { max_width = 34, max_height = 22 };
    static const int sizes[][2] = {{33, 21}, {34, 22}};
    static float full_depth[max_width * max_height], half_depth[max_width * max_height];
    static float half_ao[max_width * max_height], row[max_width];
    uint32_t state = 5u;
    int blended = 0, fallen_back = 0, near_threshold = 0, compared = 0;
    for (size_t size = 0; size < sizeof sizes / sizeof sizes[0]; size++) {
        const int width = sizes[size][0], height = sizes[size][1];
        const hbao_grid half = half_grid_of(width, height, half_depth);
        const hbao_channel guide = {full_depth, 1, width};
        compared += width * height;
        /* the upper half's depths by column only: samples above each other
         * tie in depth */
        const int tied_rows = half.height / 2;
        for (int k = 0; k < half.width * half.height; k++) {
            const int pattern = k / half.width < tied_rows ? k % half.width : k;
            half_depth[k] =
                next_random(&state) % 12 == 0 ? 0.0f : 1.0f + 0.02f * (float)(pattern % 5);
            half_ao[k] = (float)(next_random(&state) % 1000) / 1000.0f;
        }
        for (int j = 0; j < height; j++) {
            for (int i = 0; i < width; i++) {
                const int k = j / 2 * half.width + i / 2;
                const int pattern = j / 2 < tied_rows ? i / 2 : k;
                const float base = 1.0f + 0.02f * (float)(pattern % 5);
                const float u = (float)(next_random(&state) % 1000) / 1000.0f * 0.6f - 0.3f;
                full_depth[j * width + i] =
                    next_random(&state) % 15 == 0 ? 0.0f : base * (1.0f + u);
            }
        }
        for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
             implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
            const int off =
                upsample_off_documented(&half, half_ao, &guide, width, height, implementation, row,
                                        &near_threshold, &blended, &fallen_back);
            if (off)
                printf("  %dx%d, implementation %d: %d pixels off\n", width, height, implementation,
                       off);
            CHECK(off == 0);
        }
    }
    printf("  %d pixels blend weights in (1e-6, 1e-5], %d fall back from (1e-7, 1e-6], each "
           "0.05 or more from the other choice; %d not compared\n",
           blended, fallen_back, near_threshold);
    CHECK(blended >= 3 && fallen_back >= 3 && near_threshold <= compared / 100);
}

/* The half rows' skies of upsample_skips_only_skies: columns first to
 * end - 1, but for one column of geometry (hole; -1: none). Over whole
 * chunks of HBAO_UPSAMPLE_SKY_CHUNK pairs (each reads one column more),
 * short of one by its first or its last column or by one in its middle, on
 * one of a row's two half rows only, and over a whole row. */
static const int sky_spans[12][3] = {{0, 17, -1},  {0, 16, -1}, {16, 49, -1}, {17, 49, -1},
                                     {0, 68, -1},  {0, 68, 20}, {32, 68, -1}, {0, 33, -1},
                                     {32, 65, -1}, {0, 68, 40}, {0, 68, -1},  {5, 60, -1}};

/* For full row j of the half grid `half` (sky where its depth is 0): how
 * many of the row's chunks are sky on every column they read on both half
 * rows, and how many miss by one column or by one of the two rows. */
static void count_sky_chunks(const hbao_grid *half, int width, int j, int *sky, int *near) {
    const int r0 = j / 2, r1 = (j & 1) && r0 + 1 < half->height ? r0 + 1 : r0;
    const int odd_count = width / 2;
    const int pairs = odd_count < half->width - 1 ? odd_count : half->width - 1;
    for (int first = 0; first + HBAO_UPSAMPLE_SKY_CHUNK <= pairs;
         first += HBAO_UPSAMPLE_SKY_CHUNK) {
        int top = 0, bottom = 0;
        for (int k = first; k <= first + HBAO_UPSAMPLE_SKY_CHUNK; k++) {
            top += half->depth[r0 * half->width + k] > 0.0f;
            bottom += half->depth[r1 * half->width + k] > 0.0f;
        }
        *sky += top + bottom == 0;
        *near += top + bottom == 1 ||
                 (r0 != r1 && ((top == 0 && bottom > 0) || (bottom == 0 && top > 0)));
    }
}

/* upsample.c writes 1 over a chunk of pairs whose half columns are
 * background on both half rows, without weighing them. Half-grid skies
 * (sky_spans) between geometry of AO 0.1 to 0.9, full depths within 10 %
 * of their sample's and some background: every copy gives
 * documented_upsample's AO to 1e-5 (pixels whose weights sum to within 1 %
 * of the fallback's 1e-6 left out, as upsample_weighs_depth_as_documented
 * does), with sky chunks and near misses among the rows. A chunk written 1
 * where its last column or its lower row is not sky fails it. */
TEST_CASE(upsample_skips_only_skies) {
    enum { width = 135, height = 24 };
    static float full_depth[width * height], half_depth[width * height];
    static float half_ao[width * height], row[width];
    const hbao_grid half = half_grid_of(width, height, half_depth);
    const hbao_channel guide = {full_depth, 1, width};
    CHECK(half.width == 68 && half.height == 12);
    uint32_t state = 17u;
    for (int r = 0; r < half.height; r++) {
        for (int k = 0; k < half.width; k++) {
            const int sky = k >= sky_spans[r][0] && k < sky_spans[r][1] && k != sky_spans[r][2];
            half_depth[r * half.width + k] = sky ? 0.0f : 1.0f + 0.02f * (float)(k % 5);
            half_ao[r * half.width + k] = 0.1f + (float)(next_random(&state) % 801) / 1000.0f;
        }
    }
    for (int j = 0; j < height; j++) {
        for (int i = 0; i < width; i++) {
            const float u = (float)(next_random(&state) % 1000) / 1000.0f * 0.2f - 0.1f;
            full_depth[j * width + i] = next_random(&state) % 20 == 0 ? 0.0f : 1.0f + u;
        }
    }
    int sky = 0, near = 0, not_compared = 0, blended = 0, fallen_back = 0;
    for (int j = 0; j < height; j++) count_sky_chunks(&half, width, j, &sky, &near);
    for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
         implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
        const int off =
            upsample_off_documented(&half, half_ao, &guide, width, height, implementation, row,
                                    &not_compared, &blended, &fallen_back);
        if (off) printf("  implementation %d: %d pixels off\n", implementation, off);
        CHECK(off == 0);
    }
    printf("  %d sky chunks, %d missing sky by a column or a row; %d pixels not compared\n", sky,
           near, not_compared);
    CHECK(sky >= 8 && near >= 8 && not_compared <= width * height / 100);
}

/* The normals hbao_compute_normals makes for a w x h image of `depth`
 * through `camera` (NULL: the default one; into `normal`: 3 w h floats and
 * the padding), from `given` (world space, 3 floats a pixel) or, NULL, from
 * the depth; with copy `implementation` on `threads` threads. */
static void make_normals(hbao_grid *grid, int w, int h, float *depth, float *normal,
                         const float *given, const hbao_camera *camera, int implementation,
                         int threads) {
    *grid = grid_of(w, h, depth, normal);
    const hbao_camera default_camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    if (camera == NULL) camera = &default_camera;
    hbao_grid_set_projection(grid, camera, w, h, 1);
    hbao_settings settings;
    memset(&settings, 0, sizeof settings);
    settings.threads = threads;
    settings.implementation = implementation;
    const hbao_channel channel = {given, 3, 3 * (int64_t)w};
    hbao_compute_normals(&settings, camera, grid, given ? &channel : NULL, 1);
}

/* Pixels whose normal is not within 1e-6 of (x, y, z), among those for
 * which `select` (indexed by pixel) is nonzero or, NULL, every pixel
 * with a depth. */
static int normals_off(const hbao_grid *grid, const int *select, float x, float y, float z) {
    int off = 0;
    for (int j = 0; j < grid->height; j++) {
        for (int i = 0; i < grid->width; i++) {
            const int k = j * grid->width + i;
            if (select ? !select[k] : !(grid->depth[k] > 0.0f)) continue;
            float n[3];
            hbao_grid_normal_at(grid, i, j, n);
            off +=
                !(fabsf(n[0] - x) <= 1e-6f && fabsf(n[1] - y) <= 1e-6f && fabsf(n[2] - z) <= 1e-6f);
        }
    }
    return off;
}

/* Whether pixel k's normal is within 1e-5 of expected[0..3) */
static int normal_near(const hbao_grid *grid, int k, const float expected[3]) {
    float n[3];
    hbao_grid_normal_at(grid, k % grid->width, k / grid->width, n);
    return fabsf(n[0] - expected[0]) <= 1e-5f && fabsf(n[1] - expected[1]) <= 1e-5f &&
           fabsf(n[2] - expected[2]) <= 1e-5f;
}

/* Normals from depth take, along each axis, the neighbour whose depth
 * changes least, so that a step does not bend them: on planes facing the
 * camera, at 5.1 and 8.3 (or, as half floats, 5 and 8, fitted along runs)
 * with steps along rows and columns and a column of background, every
 * normal faces the camera exactly. */
TEST_CASE(face_normals_keep_to_their_side_of_a_step) {
    enum { w = 40, h = 30 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING];
    static const float near_far[2][2] = {{5.1f, 8.3f}, {5.0f, 8.0f}};
    for (int kind = 0; kind < 2; kind++) {
        for (int k = 0; k < w * h; k++) {
            const int i = k % w, j = k / w;
            depth[k] = near_far[kind][(i >= 17) != (j >= 12)];
            if (i == 30) depth[k] = 0.0f;
        }
        hbao_grid grid;
        make_normals(&grid, w, h, depth, normal, NULL, NULL, HBAO_IMPLEMENTATION_SCALAR, 2);
        CHECK_NEAR(grid.depth_precision,
                   kind ? HBAO_HALF_DEPTH_PRECISION : HBAO_FLOAT_DEPTH_PRECISION, 0.0);
        const int off = normals_off(&grid, NULL, 0.0f, 0.0f, 1.0f);
        if (off) printf("  %s depths: %d normals off\n", kind ? "half" : "float", off);
        CHECK(off == 0);
    }
}

/* The depth's format is told from every row, in any thread: half floats
 * (of a normal or a subnormal half's size) on every row but one depth
 * elsewhere make it float. */
TEST_CASE(depth_precision_is_told_from_every_row) {
    enum { w = 50, h = 40 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING];
    /* 3 x 2^-24: a subnormal half float; 1e-7: none */
    static const struct {
        float odd_one;
        float precision;
    } cases[] = {{0.0f, HBAO_HALF_DEPTH_PRECISION},
                 {3.0f * 5.9604645e-8f, HBAO_HALF_DEPTH_PRECISION},
                 {1.1f, HBAO_FLOAT_DEPTH_PRECISION},
                 {1e-7f, HBAO_FLOAT_DEPTH_PRECISION}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        for (int threads = 1; threads <= 2; threads++) {
            for (int k = 0; k < w * h; k++) depth[k] = 1.0f + 0.25f * (float)(k % 7);
            depth[(h - 3) * w + 11] = cases[c].odd_one;
            hbao_grid grid;
            make_normals(&grid, w, h, depth, normal, NULL, NULL, HBAO_IMPLEMENTATION_SCALAR,
                         threads);
            if (grid.depth_precision != cases[c].precision)
                printf("  depth %g on row %d, %d threads: precision %g\n", (double)cases[c].odd_one,
                       h - 3, threads, (double)grid.depth_precision);
            CHECK(grid.depth_precision == cases[c].precision);
        }
    }
}

/* For every copy of the given normals' stage, with the camera of a quarter
 * turn about its view axis (which sees the world normal (0, 0.6, 0.8) as
 * (0.6, 0, 0.8)): the pixels whose normal is not that where `usable` is
 * set, or not the face normal (0, 0, 1) of the plane facing the camera
 * where `unusable` is, printed for each copy that has any. */
static int quarter_turn_normals_off(int w, int h, float *depth, float *normal, const float *given,
                                    const hbao_camera *camera, const int *usable,
                                    const int *unusable) {
    int total = 0;
    for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
         implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
        hbao_grid grid;
        make_normals(&grid, w, h, depth, normal, given, camera, implementation, 1);
        const int off = normals_off(&grid, usable, 0.6f, 0.0f, 0.8f) +
                        normals_off(&grid, unusable, 0.0f, 0.0f, 1.0f);
        if (off) printf("  implementation %d: %d normals off\n", implementation, off);
        total += off;
    }
    return total;
}

/* A given normal is used, turned into the camera, normalized and made to
 * face the viewer, where it is at least HBAO_MIN_NORMAL_LENGTH long and
 * finite; shorter ones (Blender's Normal pass is 0 where nothing was
 * rendered, and filtering shortens it at edges), 0 and NaN give the face
 * normal from depth. A camera turned a quarter about its view axis (world
 * y is camera x) sees a plane facing it: (0.6, 0, 0.8) in the camera where
 * the world normal is (0, 0.6, 0.8), twice that or its opposite (a back
 * face), else (0, 0, 1); rows longer than the 64-pixel chunks that
 * given_normals_row works in; every copy. */
TEST_CASE(given_normals_too_short_give_the_face_normal) {
    enum { w = 150, h = 5, kinds = 6, usable_kinds = 3 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING], given[3 * w * h];
    static int usable[w * h], unusable[w * h];
    /* 0.0594, 0.0792: 0.099 long, just short of HBAO_MIN_NORMAL_LENGTH */
    static const float kind_normal[kinds][3] = {{0.0f, 0.6f, 0.8f},   {0.0f, 1.2f, 1.6f},
                                                {0.0f, -0.6f, -0.8f}, {0.0f, 0.0594f, 0.0792f},
                                                {0.0f, 0.0f, 0.0f},   {0.0f, NAN, 1.0f}};
    hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    static const float quarter_turn[16] = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(camera.world_to_camera, quarter_turn, sizeof quarter_turn);
    for (int k = 0; k < w * h; k++) {
        depth[k] = 5.1f;
        const int kind = (k * 7 / 3) % kinds;
        for (int c = 0; c < 3; c++) given[3 * k + c] = kind_normal[kind][c];
        usable[k] = kind < usable_kinds;
        unusable[k] = !usable[k];
    }
    CHECK(quarter_turn_normals_off(w, h, depth, normal, given, &camera, usable, unusable) == 0);
}

/* A given normal's length is tested through its square
 * (HBAO_MIN_NORMAL_LENGTH_SQUARED) exactly as through its square root: the
 * constant is the least float whose square root reaches
 * HBAO_MIN_NORMAL_LENGTH, and normals from 16 ulps shorter to 16 longer
 * than that length (both answers met) are used, or give the face normal
 * (0, 0, 1), as sqrtf of their squared length decides; every copy. */
TEST_CASE(a_given_normal_is_used_as_the_square_root_of_its_length_decides) {
    enum { w = 150, h = 5 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING], given[3 * w * h];
    static int usable[w * h], unusable[w * h];
    const float least = HBAO_MIN_NORMAL_LENGTH_SQUARED;
    CHECK(sqrtf(least) >= HBAO_MIN_NORMAL_LENGTH);
    CHECK(!(sqrtf(nextafterf(least, 0.0f)) >= HBAO_MIN_NORMAL_LENGTH));
    hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    static const float quarter_turn[16] = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(camera.world_to_camera, quarter_turn, sizeof quarter_turn);
    int used = 0;
    for (int k = 0; k < w * h; k++) {
        depth[k] = 5.1f;
        float length = HBAO_MIN_NORMAL_LENGTH;
        for (int ulps = k % 33 - 16; ulps != 0; ulps += ulps < 0 ? 1 : -1)
            length = nextafterf(length, ulps < 0 ? 0.0f : 1.0f);
        const float y = 0.6f * length, z = 0.8f * length;
        given[3 * k] = 0.0f;
        given[3 * k + 1] = y;
        given[3 * k + 2] = z;
        /* normals.c's squared length: x, y and z in that order */
        usable[k] = sqrtf(0.0f * 0.0f + y * y + z * z) >= HBAO_MIN_NORMAL_LENGTH;
        unusable[k] = !usable[k];
        used += usable[k];
    }
    CHECK(used > 0 && used < w * h);
    CHECK(quarter_turn_normals_off(w, h, depth, normal, given, &camera, usable, unusable) == 0);
}

/* A given normal is turned to face the viewer along the pixel's own ray:
 * from the eye through the pixel in a perspective view (here shifted, so
 * that rays lean up to ~35 degrees), along the view axis in an
 * orthographic one. Normals 1.1 degrees either side of edge-on to the ray
 * (a tangent of the ray plus or minus 0.02 times the ray's direction
 * towards the eye) keep their side or flip; a view vector leant by 0.1
 * would decide many of them the other way. Every copy; rays from the
 * documented pixel mapping (hbao_camera_view); depths about 4 times a scale
 * from the least denormal to near FLT_MAX (issue 13): with |P|^2 (until
 * session 22) about half the normals took the wrong side from 1e25 and
 * below 1e-30, with P's own coordinates at the least denormal and near
 * FLT_MAX. */
TEST_CASE(given_normals_face_the_viewer_along_its_ray) {
    enum { w = 150, h = 7 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING], given[3 * w * h];
    static float expected[3 * w * h], mirrored[3 * w * h];
    static const float scales[] = {1.0f, 1e-45f, 1e-40f, 1e-30f, 1e25f, 8e37f};
    for (int run = 0; run < 2 * (int)(sizeof scales / sizeof scales[0]); run++) {
        const int projection = run & 1;
        const float scale = scales[run / 2];
        hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
        camera.projection = projection ? HBAO_PROJECTION_ORTHOGRAPHIC : HBAO_PROJECTION_PERSPECTIVE;
        camera.shift_x = 0.4f;
        camera.shift_y = -0.3f;
        hbao_view view;
        CHECK_RESULT(hbao_camera_view(&camera, w, h, &view), HBAO_SUCCESS);
        for (int k = 0; k < w * h; k++) {
            const int i = k % w, j = k / w, kind = k % 4;
            depth[k] = (4.0f + 0.01f * (float)(k % 13)) * scale;
            const double x = view.origin_x + (i + 0.5) * view.pixel_size_x;
            const double y = view.origin_y + (h - 1 - j + 0.5) * view.pixel_size_y;
            /* towards the eye: -P / |P|, P = z (x, y, -1); or the view axis */
            double v[3] = {projection ? 0.0 : -x, projection ? 0.0 : -y, 1.0};
            const double v_length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            for (int c = 0; c < 3; c++) v[c] /= v_length;
            /* a tangent: v x (0, 1, 0) or v x (1, 0, 0) */
            const double t[3] = {kind < 2 ? -v[2] : 0.0, kind < 2 ? 0.0 : v[2],
                                 kind < 2 ? v[0] : -v[1]};
            const double sign = kind % 2 ? -1.0 : 1.0;
            double n[3], length = 0.0;
            for (int c = 0; c < 3; c++) {
                n[c] = t[c] + sign * 0.02 * v[c];
                length += n[c] * n[c];
            }
            length = sqrt(length);
            for (int c = 0; c < 3; c++) {
                given[3 * k + c] = (float)n[c];
                /* facing away: turned round, -n, or mirrored across the
                 * plane perpendicular to the ray, t + 0.02 v, as the face
                 * normal decides (given_normals_choose_how_to_face_the_viewer) */
                expected[3 * k + c] = (float)(sign * n[c] / length);
                mirrored[3 * k + c] = (float)((t[c] + 0.02 * v[c]) / length);
            }
        }
        for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
             implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
            hbao_grid grid;
            make_normals(&grid, w, h, depth, normal, given, &camera, implementation, 2);
            int off = 0;
            for (int k = 0; k < w * h; k++)
                off += !(normal_near(&grid, k, expected + 3 * k) ||
                         (k % 2 == 1 && normal_near(&grid, k, mirrored + 3 * k)));
            if (off)
                printf("  %s, depth scale %g, implementation %d: %d normals off\n",
                       projection ? "orthographic" : "perspective", (double)scale, implementation,
                       off);
            CHECK(off == 0);
        }
    }
}

/* A given normal that faces away from the viewer is turned to face it as
 * the surface's depth says. On a plane facing the camera (tilted up, its
 * normal N), in perspective and orthographic: shading normals tilted 3
 * degrees past edge-on to the ray (smooth shading of a coarse mesh, a bump:
 * Cycles 4.x and 5.x write such normals) are mirrored across the plane
 * perpendicular to the ray and keep their tilt towards N (turned round, they
 * pointed into the surface, which then hid itself: AO near 0 where Cycles
 * gives 0.6); the pass of a plane seen from behind, -N, is turned round to
 * N. Every copy. */
TEST_CASE(given_normals_choose_how_to_face_the_viewer) {
    enum { w = 96, h = 64 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING], given[3 * w * h];
    static float expected[3 * w * h];
    const double plane[3] = {0.0, 0.6, 0.8}; /* N, unit; the plane N . P = -4 */
    for (int run = 0; run < 4; run++) {
        const int orthographic = run & 1, seen_from_behind = run >> 1;
        hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
        camera.projection =
            orthographic ? HBAO_PROJECTION_ORTHOGRAPHIC : HBAO_PROJECTION_PERSPECTIVE;
        hbao_view view;
        CHECK_RESULT(hbao_camera_view(&camera, w, h, &view), HBAO_SUCCESS);
        for (int k = 0; k < w * h; k++) {
            const int i = k % w, j = k / w;
            const double x = view.origin_x + (i + 0.5) * view.pixel_size_x;
            const double y = view.origin_y + (h - 1 - j + 0.5) * view.pixel_size_y;
            /* the plane's depth along the pixel's ray, and V there */
            depth[k] = orthographic ? (float)((4.0 + plane[1] * y) / plane[2])
                                    : (float)(4.0 / (plane[2] - plane[1] * y));
            double v[3] = {orthographic ? 0.0 : -x, orthographic ? 0.0 : -y, 1.0};
            const double v_length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            for (int c = 0; c < 3; c++) v[c] /= v_length;
            const double n_dot_v = plane[0] * v[0] + plane[1] * v[1] + plane[2] * v[2];
            double u[3], u_length = 0.0;
            for (int c = 0; c < 3; c++) {
                /* N tilted past edge-on: its part along V made -0.05 */
                u[c] = seen_from_behind ? -plane[c] : plane[c] - (n_dot_v + 0.05) * v[c];
                u_length += u[c] * u[c];
            }
            u_length = sqrt(u_length);
            double u_dot_v = 0.0;
            for (int c = 0; c < 3; c++) {
                u[c] /= u_length;
                u_dot_v += u[c] * v[c];
            }
            for (int c = 0; c < 3; c++) {
                given[3 * k + c] = (float)u[c];
                expected[3 * k + c] =
                    (float)(seen_from_behind ? -u[c] : u[c] - 2.0 * u_dot_v * v[c]);
            }
        }
        for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
             implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
            hbao_grid grid;
            make_normals(&grid, w, h, depth, normal, given, &camera, implementation, 2);
            int off = 0;
            for (int k = 0; k < w * h; k++) off += !normal_near(&grid, k, expected + 3 * k);
            if (off)
                printf("  %s, %s, implementation %d: %d normals off\n",
                       orthographic ? "orthographic" : "perspective",
                       seen_from_behind ? "seen from behind" : "tilted", implementation, off);
            CHECK(off == 0);
        }
    }
}

/* ... and where depth gives no face normal (a pixel with no foreground
 * neighbour), a normal that faces away is turned round, -u, in every copy:
 * the two candidates' agreement with V then differs by rounding alone, and
 * decided the case either way (a review: the mirror in 41 % of them). */
TEST_CASE(a_lone_pixels_normal_that_faces_away_is_turned_round) {
    /* foreground on the pixels of even column and row, each alone between
     * background, all over a shifted frame (rays leaning every way) */
    enum { w = 31, h = 21 };
    static float depth[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING], given[3 * w * h];
    static float turned[3 * w * h];
    static int lone[w * h];
    hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    camera.shift_x = 0.2f;
    camera.shift_y = -0.1f;
    hbao_view view;
    CHECK_RESULT(hbao_camera_view(&camera, w, h, &view), HBAO_SUCCESS);
    for (int k = 0; k < w * h; k++) {
        const int i = k % w, j = k / w;
        lone[k] = i % 2 == 0 && j % 2 == 0;
        depth[k] = lone[k] ? 5.0f : 0.0f;
        /* a tangent of the ray, leant 0.05 away from the eye */
        const double x = view.origin_x + (i + 0.5) * view.pixel_size_x;
        const double y = view.origin_y + (h - 1 - j + 0.5) * view.pixel_size_y;
        double v[3] = {-x, -y, 1.0}, n[3], length = 0.0;
        const double v_length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int c = 0; c < 3; c++) v[c] /= v_length;
        const double t[3] = {-v[2], 0.0, v[0]};
        for (int c = 0; c < 3; c++) {
            n[c] = t[c] - 0.05 * v[c];
            length += n[c] * n[c];
        }
        for (int c = 0; c < 3; c++) {
            given[3 * k + c] = (float)n[c];
            turned[3 * k + c] = (float)(-n[c] / sqrt(length));
        }
    }
    for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
         implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
        hbao_grid grid;
        make_normals(&grid, w, h, depth, normal, given, &camera, implementation, 1);
        int off = 0;
        for (int k = 0; k < w * h; k++) off += lone[k] && !normal_near(&grid, k, turned + 3 * k);
        if (off)
            printf("  implementation %d: %d lone normals not turned round\n", implementation, off);
        CHECK(off == 0);
    }
}

/* hbao_scratch_fails for the test below: the take numbered fail_at fails */
static int takes_so_far, fail_at;
static int fail_one_take(size_t bytes) {
    (void)bytes;
    return ++takes_so_far == fail_at;
}

/* A call that runs out of memory leaves its output as it was: it is computed
 * over its own depth (in place) and the k-th allocation fails, for every k
 * until the call succeeds (hbao_scratch_fails). Before, the blur's bands
 * took their rows one band at a time: one that failed after others had
 * written theirs returned "out of memory" with a part of the depth replaced
 * by AO, and a retry computed AO from that (an exploratory run). Full and
 * half resolution, with and without the blur, on 1 and 3 threads. The one
 * allocation the call does without, the SIMD search's copy of the depths,
 * is noted (hbao_last_notes), so that callers can say why a frame was slow. */
TEST_CASE(running_out_of_memory_leaves_the_output_as_it_was) {
    enum { w = 96, h = 80 };
    static float depth[w * h], work[w * h], expected[w * h];
    for (int k = 0; k < w * h; k++)
        depth[k] = 4.0f + 0.5f * sinf(0.21f * (float)(k % w)) * cosf(0.17f * (float)(k / w));
    const hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    const hbao_channel channel = {work, 1, w};
    for (int variant = 0; variant < 8; variant++) {
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.half_resolution = variant & 1;
        p.blur_size = variant & 2 ? 0 : 7;
        p.threads = variant & 4 ? 3 : 1;
        memcpy(work, depth, sizeof work);
        CHECK_RESULT(hbao_compute(&p, &camera, w, h, &channel, NULL, work, w), HBAO_SUCCESS);
        CHECK(hbao_last_notes() == 0);
        memcpy(expected, work, sizeof work);
        int failed = 0, noted = 0;
        for (fail_at = 1;; fail_at++) {
            hbao_release_memory();
            memcpy(work, depth, sizeof work);
            takes_so_far = 0;
            hbao_scratch_fails = fail_one_take;
            const hbao_result result = hbao_compute(&p, &camera, w, h, &channel, NULL, work, w);
            hbao_scratch_fails = NULL;
            /* an allocation that may fail (the call then does without it)
             * succeeds with the AO; past the last allocation, nothing failed */
            if (result == HBAO_SUCCESS) {
                CHECK(memcmp(work, expected, sizeof work) == 0);
                if (takes_so_far < fail_at) break;
                /* the search's copy, the one such allocation, is noted */
                CHECK((hbao_last_notes() & ~HBAO_NOTE_REFERENCE_SEARCH) == 0);
                noted += hbao_last_notes() == HBAO_NOTE_REFERENCE_SEARCH;
                continue;
            }
            CHECK(hbao_last_notes() == 0);
            CHECK_RESULT(result, HBAO_ERROR_OUT_OF_MEMORY);
            if (memcmp(work, depth, sizeof work) != 0)
                printf("  variant %d: allocation %d failed after the output was written\n", variant,
                       fail_at);
            CHECK(memcmp(work, depth, sizeof work) == 0);
            failed++;
        }
        CHECK(failed >= 3); /* the call does allocate: depth, normals, AO at least */
        CHECK(noted == (hbao_best_implementation() != HBAO_IMPLEMENTATION_SCALAR));
    }
}

/* The picture, back layer and settings of scratch_memory_is_written_before_it_is_read */
enum { SCRATCH_W = 150, SCRATCH_H = 90 };
static float scratch_depth[SCRATCH_W * SCRATCH_H], scratch_back[SCRATCH_W * SCRATCH_H],
    scratch_normal[3 * SCRATCH_W * SCRATCH_H], scratch_work[SCRATCH_W * SCRATCH_H];

/* One frame of variant v (bits: blur size, half resolution, no given
 * normals, a back layer, in place) into out, with every scratch take
 * filled with the byte fill. */
static hbao_result scratch_frame(int v, int implementation, int threads, int fill, float *out) {
    const int sizes[] = {0, 5, 15, 65};
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.radius = 0.3f;
    p.background_depth = 1e9f;
    p.blur_size = sizes[v % 4];
    p.half_resolution = (v / 4) & 1;
    p.implementation = implementation;
    p.threads = threads;
    const hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    const int in_place = (v / 32) & 1;
    if (in_place) memcpy(scratch_work, scratch_depth, sizeof scratch_work);
    const hbao_channel d = {in_place ? scratch_work : scratch_depth, 1, SCRATCH_W};
    const hbao_channel n = {scratch_normal, 3, 3 * (int64_t)SCRATCH_W};
    const hbao_channel back = {scratch_back, 1, SCRATCH_W};
    hbao_scratch_fill = fill;
    const hbao_result result =
        hbao_compute_layers(&p, &camera, SCRATCH_W, SCRATCH_H, &d, (v / 8) & 1 ? NULL : &n,
                            (v / 16) & 1 ? &back : NULL, in_place ? scratch_work : out, SCRATCH_W);
    hbao_scratch_fill = -1;
    if (in_place) memcpy(out, scratch_work, sizeof scratch_work);
    return result;
}

/* Every scratch buffer is written before it is read (scratch.c): a frame
 * on scratch memory filled with 0x00 gives the bits of frames on memory
 * filled with 0xff (NaN as floats) and with 0x3f (about 0.75; a NaN depth
 * reads as background, which can hide an unwritten depth). A slanted floor
 * with background (background_runs.h: blur_lanes.h skips whole vectors of
 * background centres and must still write them) and a back layer 0.3 deep
 * (none known at every seventh pixel), at blur 0, 5, 15 and 65, full and
 * half resolution, with given normals and without, with and without the
 * back layer, into its own output and in place over the depth: every
 * stage's buffers (depth, half depth, normals, phase depths, raw AO, the
 * blur's bands and rows, the guide's copy, the back layer's), for every
 * implementation on 1 and 3 threads. */
TEST_CASE(scratch_memory_is_written_before_it_is_read) {
    for (int k = 0; k < SCRATCH_W * SCRATCH_H; k++) {
        const int i = k % SCRATCH_W, j = k / SCRATCH_W;
        scratch_depth[k] = background_runs_at(i, j)
                               ? 1e10f
                               : 3.0f + 0.02f * (float)j + 0.2f * (float)((i / 11) % 2);
        scratch_back[k] = k % 7 == 0 ? INFINITY : scratch_depth[k] + 0.3f;
        scratch_normal[3 * k] = (float)((i / 11) % 2) - 0.5f;
        scratch_normal[3 * k + 1] = 0.3f;
        scratch_normal[3 * k + 2] = 1.0f;
    }
    static float clean[SCRATCH_W * SCRATCH_H], filled[SCRATCH_W * SCRATCH_H];
    const int fills[] = {0xff, 0x3f};
    /* each kernel once (implementation_runs_itself; on ARM64 under qemu
     * the generic kernel had run three times, some 800 s) */
    int kernels_run = 0;
    for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
         implementation < HBAO_IMPLEMENTATION_COUNT; implementation++)
        kernels_run += implementation_runs_itself(implementation);
    CHECK(kernels_run >= 1); /* the scalar reference, at least */
    int cases = 0;
    for (int v = 0; v < 64; v++) {
        for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
             implementation < HBAO_IMPLEMENTATION_COUNT; implementation++) {
            if (!implementation_runs_itself(implementation)) continue;
            for (int threads = 1; threads <= 3; threads += 2) {
                CHECK_RESULT(scratch_frame(v, implementation, threads, 0x00, clean), HBAO_SUCCESS);
                for (int f = 0; f < 2; f++) {
                    CHECK_RESULT(scratch_frame(v, implementation, threads, fills[f], filled),
                                 HBAO_SUCCESS);
                    int differ = 0;
                    for (int k = 0; k < SCRATCH_W * SCRATCH_H; k++)
                        differ += memcmp(&clean[k], &filled[k], sizeof clean[k]) != 0;
                    if (differ)
                        printf("  variant %d, implementation %d, %d threads, fill 0x%02x: %d "
                               "pixels differ\n",
                               v, implementation, threads, fills[f], differ);
                    CHECK(differ == 0);
                    cases++;
                }
            }
        }
    }
    CHECK(cases == 64 * kernels_run * 2 * 2);
    hbao_release_memory();
}

/* hbao_parallel_rows runs every row once, on no more threads at once than
 * hbao_parallel_threads says, and hbao_parallel_each every job once on no
 * more than hbao_parallel_each_threads says (blur.c's band memory counts on
 * it), for row counts around a grab's and thread counts up to
 * HBAO_MAX_THREADS. */
static atomic_int rows_seen[8200], running_now, running_most;
static void count_row(void *context, int row) {
    (void)context;
    const int now = atomic_fetch_add(&running_now, 1) + 1;
    int most = atomic_load(&running_most);
    while (now > most && !atomic_compare_exchange_weak(&running_most, &most, now)) {
    }
    atomic_fetch_add(&rows_seen[row], 1);
    for (volatile int spin = 0; spin < 200; spin++) {
    }
    atomic_fetch_sub(&running_now, 1);
}

/* Runs `rows` jobs through `run` (hbao_parallel_rows or hbao_parallel_each)
 * on `threads` and checks each ran once, on no more than `allowed` threads
 * at once, and that `allowed` lies between 1 (0 without jobs) and
 * `threads`. */
static void check_parallel_run(const char *name,
                               void (*run)(int threads, int rows, hbao_row_job job, void *context),
                               int threads, int rows, int allowed) {
    for (int k = 0; k < rows; k++) atomic_store(&rows_seen[k], 0);
    atomic_store(&running_most, 0);
    run(threads, rows, count_row, NULL);
    int wrong = 0;
    for (int k = 0; k < rows; k++) wrong += atomic_load(&rows_seen[k]) != 1;
    if (wrong || atomic_load(&running_most) > allowed)
        printf("  %s: %d threads, %d rows: %d rows not run once, %d at once (at most %d)\n", name,
               threads, rows, wrong, atomic_load(&running_most), allowed);
    CHECK(wrong == 0);
    CHECK(atomic_load(&running_most) <= allowed);
    CHECK(allowed >= 1 || rows == 0);
    CHECK(allowed <= threads);
}

TEST_CASE(parallel_rows_run_each_row_once_on_the_threads_they_say) {
    const int threads[] = {1, 2, 3, 7, 64, HBAO_MAX_THREADS};
    const int rows[] = {0, 1, 5, 7, 8, 9, 31, 32, 33, 255, 256, 8192};
    for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
        for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
            check_parallel_run("rows", hbao_parallel_rows, threads[t], rows[r],
                               hbao_parallel_threads(threads[t], rows[r]));
            /* one a grab (the blur's jobs): each once, on no more threads
             * than hbao_parallel_each_threads says, nor more than jobs */
            const int each = hbao_parallel_each_threads(threads[t], rows[r]);
            check_parallel_run("each", hbao_parallel_each, threads[t], rows[r], each);
            CHECK(each <= rows[r]);
        }
    }
}

/* A block larger than the whole kept memory (SCRATCH_MAX_BYTES, 512 MiB:
 * an image above about 45 megapixels has such buffers) is freed when it is
 * given back, and the blocks kept until then stay kept: before, making room
 * for it freed every one of them first, so each call on such an image found
 * none of its buffers kept (an exploratory run). The 513 MiB are reserved,
 * never touched. */
TEST_CASE(a_block_too_large_to_keep_leaves_the_kept_ones) {
    hbao_release_memory();
    void *small = hbao_scratch_take((size_t)1 << 20);
    CHECK(small != NULL);
    hbao_scratch_give(small);
    void *huge = hbao_scratch_take(((size_t)513) << 20);
    CHECK(huge != NULL);
    hbao_scratch_give(huge);
    void *again = hbao_scratch_take((size_t)1 << 20);
    CHECK(again == small);
    hbao_scratch_give(again);
    hbao_release_memory();
}

#ifdef __linux__
/* The process's resident memory in bytes (/proc/self/statm), or -1. */
static long long resident_bytes(void) {
    long long pages = 0, resident = -1;
    FILE *statm = fopen("/proc/self/statm", "r");
    if (statm == NULL) return -1;
    if (fscanf(statm, "%lld %lld", &pages, &resident) != 2) resident = -1;
    fclose(statm);
    return resident < 0 ? -1 : resident * (long long)sysconf(_SC_PAGESIZE);
}
#endif

/* hbao_release_memory() hands the kept blocks back to the system, even in
 * a host whose malloc serves large blocks from its heap (its mapping
 * threshold raised, as glibc raises it by itself after a large free, or as
 * the host sets it; 32 MiB, the most older glibc accepts) and has allocated
 * after them: there a block freed stays resident until what lies above it
 * in the heap is freed. libhbao 0.6.0's scratch took its blocks from
 * posix_memalign: after a 1080p compute and the release such a host kept
 * 70 MB resident (18 MB where the blocks were mapped by malloc; a test
 * program). Each block of 2 MiB or more is now a mapping of its own
 * (csrc/memory/huge_block.c). Under AddressSanitizer every block comes from
 * its malloc (whose quarantine keeps what is freed), exactly the size asked
 * for. */
TEST_CASE(released_memory_goes_back_to_the_system) {
    const size_t bytes = (size_t)24 << 20;
    unsigned char *block = hbao_huge_block_alloc(bytes + 1);
    CHECK(block != NULL);
#if HBAO_HUGE_BLOCK_MAPS
    /* whole huge pages, starting on one, less the 64-byte header */
    CHECK((uintptr_t)(block - 64) % HBAO_HUGE_PAGE == 0);
    CHECK(hbao_huge_block_capacity(block) == bytes + HBAO_HUGE_PAGE - 64);
#else
    CHECK(hbao_huge_block_capacity(block) == bytes + 1);
#endif
    hbao_huge_block_free(block);
    unsigned char *small = hbao_huge_block_alloc(0); /* as malloc(0): a block, of nothing */
    CHECK(small != NULL && hbao_huge_block_capacity(small) == 0);
    hbao_huge_block_free(small);
#ifdef __linux__
#if HBAO_HUGE_BLOCK_MAPS && defined(__GLIBC__)
    CHECK(mallopt(M_MMAP_THRESHOLD, 32 << 20) == 1);
    CHECK(mallopt(M_TRIM_THRESHOLD, 64 << 20) == 1);
#endif
    hbao_release_memory();
    unsigned char *scratch = hbao_scratch_take(bytes);
    CHECK(scratch != NULL);
    memset(scratch, 1, bytes);
    unsigned char *later = malloc(4096); /* the host's, above the block in a heap */
    CHECK(later != NULL);
    memset(later, 2, 4096);
    const long long before = resident_bytes();
    hbao_scratch_give(scratch);
    hbao_release_memory();
    const long long after = resident_bytes();
    CHECK(before > 0 && after > 0);
#if HBAO_HUGE_BLOCK_MAPS
    CHECK(before - after >= (long long)(bytes / 10 * 9));
#endif
    free(later);
#endif
}

/* threads = 0 is one thread per CPU the process may run on: with its
 * affinity narrowed to one CPU (as taskset, a container's cpuset or a farm
 * scheduler narrows it), one thread, not one per CPU online (on this
 * project's 2-core machines, 2). */
TEST_CASE(default_threads_follow_the_cpus_the_process_may_use) {
#ifdef __linux__
    cpu_set_t allowed;
    /* (more CPUs than a cpu_set_t holds: the library counts the CPUs
     * online there, and this test has nothing to narrow) */
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return;
    hbao_params params = HBAO_PARAMS_DEFAULT_INITIALIZER;
    params.threads = 0;
    hbao_settings all;
    CHECK_RESULT(hbao_settings_make(&params, &all), HBAO_SUCCESS);
    CHECK(all.threads ==
          (CPU_COUNT(&allowed) < HBAO_MAX_THREADS ? CPU_COUNT(&allowed) : HBAO_MAX_THREADS));
    int first = 0;
    while (!CPU_ISSET(first, &allowed)) first++;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    CHECK(sched_setaffinity(0, sizeof one, &one) == 0);
    hbao_settings narrowed;
    const hbao_result result = hbao_settings_make(&params, &narrowed);
    CHECK(sched_setaffinity(0, sizeof allowed, &allowed) == 0);
    CHECK_RESULT(result, HBAO_SUCCESS);
    CHECK(narrowed.threads == 1);
#endif
}

/* A frame sampled nowhere (hbao_grid_sampled 0: every projected radius under
 * a pixel) is all 1s from hbao_compute(), which then computes nothing but
 * the depths: the stages it leaves out give exactly that. On a grid of
 * random depths (background among them), perspective and orthographic:
 * hbao_grid_sampled says whether any foreground pixel's projected radius,
 * as hbao_horizon_pixel forms it, is a pixel or more, for radii around
 * the nearest pixel's threshold; where it is 0, the normals, the horizons
 * and the blur (radius 7, strength 2) give 1 at every pixel, with every
 * copy, and hbao_compute() gives 1 at full and half resolution. */
TEST_CASE(a_frame_sampled_nowhere_is_the_stages_ones) {
    enum { w = 61, h = 23 };
    static float depth[w * h], converted[w * h], normal[3 * w * h + HBAO_NORMAL_PADDING];
    static float raw[w * h], out[w * h];
    float *beyond = malloc(hbao_beyond_floats(w, h) * sizeof(float));
    CHECK(beyond != NULL);
    uint32_t state = 58u;
    float nearest = INFINITY;
    for (int k = 0; k < w * h; k++) {
        const uint32_t r = next_random(&state);
        depth[k] = r % 7 == 0 ? 1e10f : 2.0f + (float)(r % 4000) / 1000.0f;
        if (depth[k] < nearest) nearest = depth[k];
    }
    for (int projection = 0; projection < 2; projection++) {
        hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
        camera.projection = projection ? HBAO_PROJECTION_ORTHOGRAPHIC : HBAO_PROJECTION_PERSPECTIVE;
        hbao_grid grid = grid_of(w, h, converted, normal);
        grid.beyond = beyond;
        hbao_grid_set_projection(&grid, &camera, w, h, 1);
        /* the radius at which the nearest pixel's projected radius is 1 */
        const float threshold = projection ? grid.pixel_size : grid.pixel_size * nearest;
        static const float factors[] = {0.5f, 0.999f, 0.9999999f, 1.0f, 1.0000001f, 1.001f};
        for (size_t f = 0; f < sizeof factors / sizeof factors[0]; f++) {
            hbao_params params = HBAO_PARAMS_DEFAULT_INITIALIZER;
            params.radius = threshold * factors[f];
            params.blur_size = 15;
            params.strength = 2.0f;
            params.threads = 2;
            hbao_settings settings;
            CHECK_RESULT(hbao_settings_make(&params, &settings), HBAO_SUCCESS);
            for (int k = 0; k < w * h; k++) converted[k] = depth[k] < 1e10f ? depth[k] : 0.0f;
            int any = 0;
            for (int k = 0; k < w * h; k++) {
                const float z = converted[k];
                const float radius_px = projection ? settings.radius / grid.pixel_size
                                                   : settings.radius / (grid.pixel_size * z);
                any |= z > 0.0f && radius_px >= 1.0f;
            }
            const int sampled = hbao_grid_sampled(&settings, &grid);
            if (sampled != any)
                printf("  projection %d, radius %.9g (x %.9g): sampled %d, a pixel's radius %d\n",
                       projection, (double)settings.radius, (double)factors[f], sampled, any);
            CHECK(sampled == any);
            if (sampled) continue;
            for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
                 implementation <= HBAO_IMPLEMENTATION_AVX512; implementation++) {
                settings.implementation = implementation;
                hbao_compute_normals(&settings, &camera, &grid, NULL, 1);
                hbao_beyond_planes(&grid);
                /* (no note but that nothing is sampled) */
                CHECK((hbao_compute_horizons(&settings, &grid, raw) &
                       ~HBAO_NOTE_RADIUS_UNDER_A_PIXEL) == 0u);
                CHECK_RESULT(hbao_finish(&settings, &grid, raw, NULL, w, h, out, w), HBAO_SUCCESS);
                int ones = 0;
                for (int k = 0; k < w * h; k++) ones += raw[k] == 1.0f && out[k] == 1.0f;
                CHECK(ones == w * h);
            }
            for (int half = 0; half < 2; half++) {
                params.half_resolution = half;
                hbao_channel channel = {depth, 1, w};
                for (int k = 0; k < w * h; k++) out[k] = 0.5f;
                CHECK_RESULT(hbao_compute(&params, &camera, w, h, &channel, NULL, out, w),
                             HBAO_SUCCESS);
                int ones = 0;
                for (int k = 0; k < w * h; k++) ones += out[k] == 1.0f;
                CHECK(ones == w * h);
            }
        }
    }
    /* Sampled only in its last rows (the rest 1000 times as far, its radius
     * under a pixel there): every row reaches the test, and the AO is
     * computed, below 1 at many of those rows' pixels. */
    static float far[w * h], ao[w * h];
    for (int k = 0; k < w * h; k++) far[k] = k < w * (h - 3) ? depth[k] * 1000.0f : depth[k];
    hbao_params params = HBAO_PARAMS_DEFAULT_INITIALIZER;
    params.radius = 0.5f;
    const hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    for (int half = 0; half < 2; half++) {
        params.half_resolution = half;
        const hbao_channel channel = {far, 1, w};
        CHECK_RESULT(hbao_compute(&params, &camera, w, h, &channel, NULL, ao, w), HBAO_SUCCESS);
        int darker = 0;
        for (int k = w * (h - 3); k < w * h; k++) darker += ao[k] < 1.0f;
        CHECK(darker > w / 4); /* (106 and 53 of 183 when written) */
    }
    free(beyond);
}

TEST_MAIN(TEST_ENTRY(blur_copies_agree_on_background_at_every_sharpness),
          TEST_ENTRY(blur_strips_give_the_same_floats), TEST_ENTRY(blur_follows_its_formula),
          TEST_ENTRY(half_resolution_blur_reaches_as_far),
          TEST_ENTRY(upsample_weights_are_bilinear_on_a_flat_depth),
          TEST_ENTRY(upsample_weighs_depth_as_documented), TEST_ENTRY(upsample_skips_only_skies),
          TEST_ENTRY(face_normals_keep_to_their_side_of_a_step),
          TEST_ENTRY(depth_precision_is_told_from_every_row),
          TEST_ENTRY(given_normals_too_short_give_the_face_normal),
          TEST_ENTRY(a_given_normal_is_used_as_the_square_root_of_its_length_decides),
          TEST_ENTRY(given_normals_face_the_viewer_along_its_ray),
          TEST_ENTRY(given_normals_choose_how_to_face_the_viewer),
          TEST_ENTRY(a_lone_pixels_normal_that_faces_away_is_turned_round),
          TEST_ENTRY(running_out_of_memory_leaves_the_output_as_it_was),
          TEST_ENTRY(scratch_memory_is_written_before_it_is_read),
          TEST_ENTRY(parallel_rows_run_each_row_once_on_the_threads_they_say),
          TEST_ENTRY(a_block_too_large_to_keep_leaves_the_kept_ones),
          TEST_ENTRY(released_memory_goes_back_to_the_system),
          TEST_ENTRY(default_threads_follow_the_cpus_the_process_may_use),
          TEST_ENTRY(a_frame_sampled_nowhere_is_the_stages_ones))
