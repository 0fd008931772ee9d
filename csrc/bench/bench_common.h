/* SPDX-License-Identifier: GPL-2.0-or-later */
/* What the speed benchmarks share: clocks, medians, the load line and the
 * synthetic 1080p scene (bench_speed.c, bench_ab.c). */
#ifndef HBAO_BENCH_COMMON_H
#define HBAO_BENCH_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hbao.h"
#include "scene.h"

static inline int compare_doubles(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* A whole number in [low, high] (low >= 0) from the whole of text, digits
 * only, or low - 1: a benchmark option ("--calls 1O" is refused, not read
 * as 1). */
static inline long bench_whole_number(const char *text, long low, long high) {
    char *end;
    if (!(text[0] >= '0' && text[0] <= '9')) return low - 1;
    const long value = strtol(text, &end, 10);
    return *end == '\0' && value >= low && value <= high ? value : low - 1;
}

/* --size WxH, each in [low, high], into *width and *height; 0 (and both
 * low - 1) if text is not that. */
static inline int bench_size(const char *text, long low, long high, int *width, int *height) {
    char copy[32];
    char *by = strlen(text) < sizeof copy ? strchr(strcpy(copy, text), 'x') : NULL;
    if (by != NULL) *by = '\0';
    const long w = by != NULL ? bench_whole_number(copy, low, high) : low - 1;
    const long h = by != NULL ? bench_whole_number(by + 1, low, high) : low - 1;
    const int good = w >= low && h >= low;
    *width = good ? (int)w : (int)low - 1;
    *height = good ? (int)h : (int)low - 1;
    return good;
}

/* A finite number above 0 from the whole of text, or 0. */
static inline float bench_positive_number(const char *text) {
    char *end;
    const float value = strtof(text, &end);
    return end != text && *end == '\0' && value > 0.0f && isfinite(value) ? value : 0.0f;
}

/* hbao_implementation by name (scalar, generic, avx2, avx512); -1 if none */
static inline int bench_implementation(const char *name) {
    if (!strcmp(name, "scalar")) return HBAO_IMPLEMENTATION_SCALAR;
    if (!strcmp(name, "generic")) return HBAO_IMPLEMENTATION_GENERIC;
    if (!strcmp(name, "avx2")) return HBAO_IMPLEMENTATION_AVX2;
    if (!strcmp(name, "avx512")) return HBAO_IMPLEMENTATION_AVX512;
    return -1;
}

static inline double clock_seconds(clockid_t clock) {
    struct timespec t;
    clock_gettime(clock, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static inline double median_of(double *values, int count) {
    qsort(values, (size_t)count, sizeof(double), compare_doubles);
    return count % 2 ? values[count / 2] : 0.5 * (values[count / 2 - 1] + values[count / 2]);
}

static inline void print_load(const char *when) {
    FILE *f = fopen("/proc/loadavg", "r");
    double one = 0.0, five = 0.0;
    if (f != NULL && fscanf(f, "%lf %lf", &one, &five) == 2)
        printf("Load average %s: %.2f (1 min), %.2f (5 min).\n", when, one, five);
    if (f != NULL) fclose(f);
}

/* The upper `percent` per cent of the rows of a width-wide depth image
 * made a sky: a depth of 1e10, beyond any background_depth the benchmarks
 * set (bench_speed's skips row, bench_ab --background). */
static inline void bench_sky(float *depth, int width, int height, int percent) {
    const size_t pixels = (size_t)(height * percent / 100) * (size_t)width;
    for (size_t k = 0; k < pixels; k++) depth[k] = 1e10f;
}

/* The top-left pixel of a depth image brought to a depth of 1e-6, so near
 * that its projected radius is a pixel or more at any radius the benchmarks
 * set: a frame whose radius is under a pixel elsewhere still runs every
 * stage around the search, and the search is that one pixel's. Without it
 * such a frame computes nothing (hbao_compute writes 1s where no pixel is
 * sampled). bench_speed's stages table and its skips row, bench_ab
 * --near-pixel. */
static inline void bench_near_pixel(float *depth) {
    depth[0] = 1e-6f;
}

/* A room corner (floor, two walls) with a box: every pixel is geometry. */
typedef struct bench_scene {
    scene_view view;
    float *depth, *normal;
} bench_scene;

static inline void bench_scene_make(bench_scene *b, int width, int height) {
    scene s;
    memset(&s, 0, sizeof s);
    s.plane[s.planes] = scene_plane_make(0, 0, 0, 0, 0, 1);
    scene_plane_clip(&s.plane[s.planes++], 1, 0, 0, 0);
    s.plane[s.planes] = scene_plane_make(0, 0, 0, -1, 0, 0);
    scene_plane_clip(&s.plane[s.planes++], 0, 0, -1, 0);
    s.plane[s.planes++] = scene_plane_make(0, 4, 0, 0, -1, 0);
    scene_plane front = scene_plane_make(-1.5, 0, 0, -1, 0, 0);
    scene_plane_clip(&front, 0, 0, 1, 0.6);
    scene_plane_clip(&front, 0, 1, 0, 0.5);
    s.plane[s.planes++] = front;
    scene_plane top = scene_plane_make(0, 0, 0.6, 0, 0, 1);
    scene_plane_clip(&top, -1, 0, 0, 1.5);
    scene_plane_clip(&top, 0, 1, 0, 0.5);
    s.plane[s.planes++] = top;
    memset(&b->view, 0, sizeof b->view);
    b->view.width = width;
    b->view.height = height;
    hbao_camera_default(&b->view.camera);
    const double eye[3] = {-5.0, -2.0, 2.5}, target[3] = {-0.5, 1.0, 0.4};
    scene_look_at(&b->view, eye, target);
    scene_render(&s, &b->view, &b->depth, &b->normal);
}

#endif
