/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Test scenes made of planes, rendered analytically into a depth image and a
 * world-space normal image through Blender's camera model, independently of
 * the library (docs/algorithm.md, "Camera"). */
#ifndef HBAO_TEST_SCENE_H
#define HBAO_TEST_SCENE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hbao.h"

#define SCENE_MAX_PLANES 8

/* A plane in world space, bounded by up to two half-space clips:
 * points x with dot(clip_normal, x) <= clip_offset. */
typedef struct scene_plane {
    double point[3], normal[3];
    int clips;
    double clip_normal[2][3], clip_offset[2];
} scene_plane;

typedef struct scene {
    int planes;
    scene_plane plane[SCENE_MAX_PLANES];
} scene;

typedef struct scene_view {
    int width, height;
    hbao_camera camera;
    double camera_to_world[16]; /* row-major, rigid */
} scene_view;

/* An unbounded plane through (px, py, pz) with normal (nx, ny, nz). */
static inline scene_plane scene_plane_make(double px, double py, double pz, double nx, double ny,
                                           double nz) {
    scene_plane p;
    memset(&p, 0, sizeof p);
    p.point[0] = px;
    p.point[1] = py;
    p.point[2] = pz;
    const double l = sqrt(nx * nx + ny * ny + nz * nz);
    p.normal[0] = nx / l;
    p.normal[1] = ny / l;
    p.normal[2] = nz / l;
    return p;
}

/* Keep only the part of the plane where dot((nx, ny, nz), x) <= offset. */
static inline void scene_plane_clip(scene_plane *p, double nx, double ny, double nz,
                                    double offset) {
    p->clip_normal[p->clips][0] = nx;
    p->clip_normal[p->clips][1] = ny;
    p->clip_normal[p->clips][2] = nz;
    p->clip_offset[p->clips] = offset;
    p->clips++;
}

static inline void mat_mul_point(const double m[16], const double p[3], double out[3]) {
    for (int r = 0; r < 3; r++)
        out[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
}

static inline void mat_mul_dir(const double m[16], const double p[3], double out[3]) {
    for (int r = 0; r < 3; r++)
        out[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2];
}

/* A camera at `eye` looking at `target`, world up +Z (Blender's convention:
 * the camera looks down its local -Z, local +Y is up). Fills both matrices. */
static inline void scene_look_at(scene_view *view, const double eye[3], const double target[3]) {
    double f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
    double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int c = 0; c < 3; c++) f[c] /= fl;
    const double up[3] = {0, 0, 1};
    double r[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2],
                   f[0] * up[1] - f[1] * up[0]};
    double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int c = 0; c < 3; c++) r[c] /= rl;
    double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    /* camera axes in world: x = r, y = u, z = -f */
    double *m = view->camera_to_world;
    const double cols[3][3] = {{r[0], r[1], r[2]}, {u[0], u[1], u[2]}, {-f[0], -f[1], -f[2]}};
    for (int row = 0; row < 3; row++) {
        for (int col = 0; col < 3; col++) m[4 * row + col] = cols[col][row];
        m[4 * row + 3] = eye[row];
    }
    m[12] = m[13] = m[14] = 0;
    m[15] = 1;
    /* inverse of a rigid transform: R^T, -R^T t */
    float *w = view->camera.world_to_camera;
    for (int row = 0; row < 3; row++) {
        double t = 0;
        for (int col = 0; col < 3; col++) {
            w[4 * row + col] = (float)cols[row][col];
            t -= cols[row][col] * eye[col];
        }
        w[4 * row + 3] = (float)t;
    }
    w[12] = w[13] = w[14] = 0;
    w[15] = 1;
}

/* The camera-space ray of pixel (i, j): origin and direction with z = -1. */
static inline void scene_pixel_ray(const scene_view *view, double i, double j, double origin[3],
                                   double direction[3]) {
    const hbao_camera *c = &view->camera;
    const double w = view->width, h = view->height;
    const double ycor = (double)c->pixel_aspect_y / c->pixel_aspect_x;
    int horizontal =
        c->sensor_fit == HBAO_SENSOR_FIT_HORIZONTAL ||
        (c->sensor_fit == HBAO_SENSOR_FIT_AUTO && c->pixel_aspect_x * w >= c->pixel_aspect_y * h);
    const double sensor =
        c->sensor_fit == HBAO_SENSOR_FIT_VERTICAL ? c->sensor_height : c->sensor_width;
    const double viewfac = horizontal ? w : ycor * h;
    const int ortho = c->projection == HBAO_PROJECTION_ORTHOGRAPHIC;
    const double size = (ortho ? c->ortho_scale : sensor / c->lens) / viewfac;
    const double x = (-0.5 * w + c->shift_x * viewfac + i + 0.5) * size;
    const double y = (-0.5 * ycor * h + c->shift_y * viewfac + (h - 1 - j + 0.5) * ycor) * size;
    if (ortho) {
        origin[0] = x;
        origin[1] = y;
        origin[2] = 0;
        direction[0] = 0;
        direction[1] = 0;
        direction[2] = -1;
    } else {
        origin[0] = origin[1] = origin[2] = 0;
        direction[0] = x;
        direction[1] = y;
        direction[2] = -1;
    }
}

/* Nearest hit of a world-space ray: returns t (or INFINITY), normal in world. */
static inline double scene_trace(const scene *s, const double o[3], const double d[3],
                                 double normal[3]) {
    double best = INFINITY;
    for (int k = 0; k < s->planes; k++) {
        const scene_plane *p = &s->plane[k];
        const double denom = p->normal[0] * d[0] + p->normal[1] * d[1] + p->normal[2] * d[2];
        if (fabs(denom) < 1e-12) continue;
        const double t =
            ((p->point[0] - o[0]) * p->normal[0] + (p->point[1] - o[1]) * p->normal[1] +
             (p->point[2] - o[2]) * p->normal[2]) /
            denom;
        if (!(t > 1e-9) || t >= best) continue;
        const double x[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        int inside = 1;
        for (int c = 0; c < p->clips; c++) {
            const double v = p->clip_normal[c][0] * x[0] + p->clip_normal[c][1] * x[1] +
                             p->clip_normal[c][2] * x[2];
            if (v > p->clip_offset[c] + 1e-12) inside = 0;
        }
        if (!inside) continue;
        best = t;
        for (int c = 0; c < 3; c++) normal[c] = p->normal[c];
    }
    return best;
}

/* Depth (planar, Cycles' 1e10 for background) and world normals (xyz per
 * pixel, 0 for background) of the scene; caller frees both. */
static inline void scene_render(const scene *s, const scene_view *view, float **depth_out,
                                float **normal_out) {
    const size_t pixels = (size_t)view->width * view->height;
    float *depth = malloc(pixels * sizeof(float));
    float *normal = malloc(pixels * 3 * sizeof(float));
    for (int j = 0; j < view->height; j++) {
        for (int i = 0; i < view->width; i++) {
            double o[3], d[3], ow[3], dw[3], n[3] = {0, 0, 0};
            scene_pixel_ray(view, i, j, o, d);
            mat_mul_point(view->camera_to_world, o, ow);
            mat_mul_dir(view->camera_to_world, d, dw);
            /* d has camera z = -1, so t is the planar depth directly. */
            const double t = scene_trace(s, ow, dw, n);
            const size_t k = (size_t)j * view->width + i;
            depth[k] = isfinite(t) ? (float)t : 1e10f;
            for (int c = 0; c < 3; c++) normal[3 * k + c] = isfinite(t) ? (float)n[c] : 0.0f;
        }
    }
    *depth_out = depth;
    *normal_out = normal;
}

/* World position of pixel (i, j) at its depth. */
static inline void scene_pixel_position(const scene_view *view, int i, int j, double depth,
                                        double world[3]) {
    double o[3], d[3], p[3];
    scene_pixel_ray(view, i, j, o, d);
    for (int c = 0; c < 3; c++) p[c] = o[c] + depth * d[c];
    mat_mul_point(view->camera_to_world, p, world);
}

#endif /* HBAO_TEST_SCENE_H */
