/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Blender's camera model: where each pixel lies in the view plane.
 * Follows BKE_camera_params_compute_viewplane (docs/algorithm.md, "Camera"). */
#include <math.h>

#include "internal_hbao.h"

static int finite_positive(float value) { return isfinite(value) && value > 0.0f; }

/* The rotation part (upper-left 3x3) maps normals into the camera; only its
 * direction matters, the normals are renormalised after it. So the test is
 * scale-free: |det| / (product of the row lengths) is 1 for orthogonal rows
 * (any rotation, at any uniform scale) and 0 for a singular matrix (Hadamard's
 * inequality). Below MIN_HADAMARD_RATIO the rows are dependent to within
 * float precision (1.2e-7) and the normals they give are noise. */
#define MIN_HADAMARD_RATIO 1e-6
/* The normal transform runs in float: a row length outside these bounds
 * makes the squared length of a transformed unit normal underflow to zero
 * or overflow (float's range is 1.2e-38 .. 3.4e38, squares double the
 * exponent), so such matrices are refused rather than silently ignored. */
#define MIN_ROW_LENGTH 1e-15
#define MAX_ROW_LENGTH 1e15

static int rotation_part_is_invertible(const float *m) {
    double row_length_product = 1.0;
    for (int r = 0; r < 3; r++) {
        const double length = sqrt((double)m[4 * r] * m[4 * r] + (double)m[4 * r + 1] * m[4 * r + 1] +
                                   (double)m[4 * r + 2] * m[4 * r + 2]);
        if (!(length >= MIN_ROW_LENGTH && length <= MAX_ROW_LENGTH)) return 0;
        row_length_product *= length;
    }
    const double determinant = (double)m[0] * ((double)m[5] * m[10] - (double)m[6] * m[9]) -
                               (double)m[1] * ((double)m[4] * m[10] - (double)m[6] * m[8]) +
                               (double)m[2] * ((double)m[4] * m[9] - (double)m[5] * m[8]);
    return fabs(determinant) / row_length_product >= MIN_HADAMARD_RATIO;
}

hbao_result hbao_validate_camera(const hbao_camera *camera) {
    if (camera->projection != HBAO_PROJECTION_PERSPECTIVE &&
        camera->projection != HBAO_PROJECTION_ORTHOGRAPHIC)
        return HBAO_ERROR_INVALID_CAMERA;
    if (camera->sensor_fit < HBAO_SENSOR_FIT_AUTO || camera->sensor_fit > HBAO_SENSOR_FIT_VERTICAL)
        return HBAO_ERROR_INVALID_CAMERA;
    if (!finite_positive(camera->pixel_aspect_x) || !finite_positive(camera->pixel_aspect_y))
        return HBAO_ERROR_INVALID_CAMERA;
    if (!isfinite(camera->shift_x) || !isfinite(camera->shift_y)) return HBAO_ERROR_INVALID_CAMERA;
    if (camera->projection == HBAO_PROJECTION_PERSPECTIVE) {
        if (!finite_positive(camera->lens) || !finite_positive(camera->sensor_width) ||
            !finite_positive(camera->sensor_height))
            return HBAO_ERROR_INVALID_CAMERA;
    } else if (!finite_positive(camera->ortho_scale)) {
        return HBAO_ERROR_INVALID_CAMERA;
    }
    const float *m = camera->world_to_camera;
    for (int k = 0; k < 16; k++)
        if (!isfinite(m[k])) return HBAO_ERROR_INVALID_CAMERA;
    if (!rotation_part_is_invertible(m)) return HBAO_ERROR_INVALID_CAMERA;
    return HBAO_SUCCESS;
}

void hbao_grid_set_projection(hbao_grid *grid, const hbao_camera *camera, int full_width,
                              int full_height, int scale) {
    const double aspect_x = camera->pixel_aspect_x, aspect_y = camera->pixel_aspect_y;
    const double ycor = aspect_y / aspect_x;
    int horizontal_fit;
    if (camera->sensor_fit == HBAO_SENSOR_FIT_AUTO)
        horizontal_fit = aspect_x * full_width >= aspect_y * full_height;
    else
        horizontal_fit = camera->sensor_fit == HBAO_SENSOR_FIT_HORIZONTAL;
    /* AUTO always uses sensor_width, for whichever side is larger. */
    const double sensor_size = camera->sensor_fit == HBAO_SENSOR_FIT_VERTICAL
                                   ? camera->sensor_height
                                   : camera->sensor_width;
    const double viewfac = horizontal_fit ? (double)full_width : ycor * full_height;
    const int orthographic = camera->projection == HBAO_PROJECTION_ORTHOGRAPHIC;
    const double pixel_size =
        (orthographic ? camera->ortho_scale : sensor_size / camera->lens) / viewfac;
    const double left = -0.5 * full_width + camera->shift_x * viewfac;
    const double bottom = -0.5 * ycor * full_height + camera->shift_y * viewfac;

    /* Column i of the grid is full-resolution pixel scale * i, whose centre
     * lies at (left + scale * i + 0.5) * pixel_size; likewise for rows,
     * counted from the top. */
    grid->x_step = (float)(scale * pixel_size);
    grid->x_offset = (float)((left + 0.5) / scale);
    grid->y_step = (float)(-scale * ycor * pixel_size);
    grid->y_offset = (float)((bottom + (full_height - 0.5) * ycor) / (-scale * ycor));
    grid->orthographic = orthographic;
    grid->pixel_size = (float)(pixel_size * scale);
    grid->ycor = (float)ycor;
}
