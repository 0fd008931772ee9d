/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Camera-space normals for every grid pixel: Blender's world-space Normal
 * pass rotated into the camera, or face normals reconstructed from depth
 * (Bavoil & Sainz: face normals avoid the false occlusion that interpolated
 * normals give). Every normal is turned to face the viewer. */
#include <math.h>

#include "internal_hbao.h"

typedef struct normal_job {
    const hbao_camera *camera;
    hbao_grid *grid;
    const hbao_channel *given; /* NULL: reconstruct everything */
    int scale;
} normal_job;

static void view_vector(const hbao_grid *grid, const float position[3], float v[3]) {
    if (grid->orthographic) {
        v[0] = 0.0f;
        v[1] = 0.0f;
        v[2] = 1.0f;
        return;
    }
    const float length =
        sqrtf(position[0] * position[0] + position[1] * position[1] + position[2] * position[2]);
    v[0] = -position[0] / length;
    v[1] = -position[1] / length;
    v[2] = -position[2] / length;
}

/* The neighbour difference along one axis whose depth changes least, so that
 * a depth discontinuity on one side does not bend the normal. Returns 0 when
 * neither neighbour is usable. */
static int pick_tangent(const hbao_grid *grid, int i, int j, int di, int dj, const float center[3],
                        float tangent[3]) {
    float best[3] = {0.0f, 0.0f, 0.0f};
    float best_change = INFINITY;
    for (int side = -1; side <= 1; side += 2) {
        const int ni = i + side * di, nj = j + side * dj;
        if (ni < 0 || nj < 0 || ni >= grid->width || nj >= grid->height) continue;
        const float z = grid->depth[(size_t)nj * grid->width + ni];
        if (z <= 0.0f) continue;
        float p[3];
        hbao_grid_position(grid, ni, nj, z, p);
        const float change = fabsf(p[2] - center[2]);
        if (change < best_change) {
            best_change = change;
            for (int c = 0; c < 3; c++) best[c] = side * (p[c] - center[c]);
        }
    }
    for (int c = 0; c < 3; c++) tangent[c] = best[c];
    return best_change < INFINITY;
}

static int reconstruct_normal(const hbao_grid *grid, int i, int j, const float center[3],
                              float n[3]) {
    float dx[3], dy[3];
    if (!pick_tangent(grid, i, j, 1, 0, center, dx) || !pick_tangent(grid, i, j, 0, 1, center, dy))
        return 0;
    n[0] = dx[1] * dy[2] - dx[2] * dy[1];
    n[1] = dx[2] * dy[0] - dx[0] * dy[2];
    n[2] = dx[0] * dy[1] - dx[1] * dy[0];
    const float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(length > 0.0f) || !isfinite(length)) return 0;
    for (int c = 0; c < 3; c++) n[c] /= length;
    return 1;
}

static int transform_given_normal(const normal_job *job, int i, int j, float n[3]) {
    const hbao_channel *given = job->given;
    const float *w = given->data + (int64_t)(j * job->scale) * given->row_stride +
                     (int64_t)(i * job->scale) * given->pixel_stride;
    const float wx = w[0], wy = w[1], wz = w[2];
    const float world_length = sqrtf(wx * wx + wy * wy + wz * wz);
    if (!isfinite(world_length) || world_length < HBAO_MIN_NORMAL_LENGTH) return 0;
    const float *m = job->camera->world_to_camera;
    n[0] = m[0] * wx + m[1] * wy + m[2] * wz;
    n[1] = m[4] * wx + m[5] * wy + m[6] * wz;
    n[2] = m[8] * wx + m[9] * wy + m[10] * wz;
    const float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!isfinite(length) || !(length > 0.0f)) return 0;
    for (int c = 0; c < 3; c++) n[c] /= length;
    return 1;
}

static void normal_row(void *context, int j) {
    const normal_job *job = context;
    hbao_grid *grid = job->grid;
    for (int i = 0; i < grid->width; i++) {
        const size_t index = (size_t)j * grid->width + i;
        float *n = grid->normal + 3 * index;
        const float z = grid->depth[index];
        if (z <= 0.0f) {
            n[0] = 0.0f;
            n[1] = 0.0f;
            n[2] = 1.0f;
            continue;
        }
        float p[3], v[3];
        hbao_grid_position(grid, i, j, z, p);
        view_vector(grid, p, v);
        int have = job->given != NULL && transform_given_normal(job, i, j, n);
        if (!have) have = reconstruct_normal(grid, i, j, p, n);
        if (!have) {
            for (int c = 0; c < 3; c++) n[c] = v[c];
        }
        if (n[0] * v[0] + n[1] * v[1] + n[2] * v[2] < 0.0f) {
            for (int c = 0; c < 3; c++) n[c] = -n[c];
        }
    }
}

void hbao_compute_normals(const hbao_settings *settings, const hbao_camera *camera,
                          hbao_grid *grid, const hbao_channel *normal, int scale) {
    normal_job job = {camera, grid, normal, scale};
    hbao_parallel_rows(settings->threads, grid->height, normal_row, &job);
}
