/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Blender's camera model: where each pixel lies in the view plane.
 * Follows BKE_camera_params_compute_viewplane (docs/algorithm.md, "Camera"). */
#include <float.h>
#include <math.h>

#include "internal_hbao.h"

static int finite_positive(float value) {
    return isfinite(value) && value > 0.0f;
}

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
        const double length =
            sqrt((double)m[4 * r] * m[4 * r] + (double)m[4 * r + 1] * m[4 * r + 1] +
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

/* Blender's view plane of a camera on a width x height image, in units of
 * one pixel width: the sensor-fit rule, written once for hbao_compute(),
 * hbao_camera_view() and hbao_camera_crop(). */
typedef struct view_plane {
    int horizontal_fit;
    int orthographic;
    double sensor_size; /* mm of sensor spanning the fitted side */
    double viewfac;     /* the fitted side's length, in pixel widths */
    double ycor;        /* pixel height / pixel width */
    double pixel_size;  /* view-plane width of one pixel (per unit depth if perspective) */
    double left;        /* the image's left edge, in pixel widths */
    double bottom;      /* its bottom edge, in pixel widths */
} view_plane;

static view_plane fit_view_plane(const hbao_camera *camera, int width, int height) {
    view_plane plane;
    const double aspect_x = camera->pixel_aspect_x, aspect_y = camera->pixel_aspect_y;
    plane.ycor = aspect_y / aspect_x;
    if (camera->sensor_fit == HBAO_SENSOR_FIT_AUTO)
        plane.horizontal_fit = aspect_x * width >= aspect_y * height;
    else
        plane.horizontal_fit = camera->sensor_fit == HBAO_SENSOR_FIT_HORIZONTAL;
    /* AUTO always uses sensor_width, for whichever side is larger
     * (BKE_camera_sensor_size). */
    plane.sensor_size = camera->sensor_fit == HBAO_SENSOR_FIT_VERTICAL ? camera->sensor_height
                                                                       : camera->sensor_width;
    plane.viewfac = plane.horizontal_fit ? (double)width : plane.ycor * height;
    plane.orthographic = camera->projection == HBAO_PROJECTION_ORTHOGRAPHIC;
    plane.pixel_size =
        (plane.orthographic ? camera->ortho_scale : plane.sensor_size / camera->lens) /
        plane.viewfac;
    plane.left = -0.5 * width + camera->shift_x * plane.viewfac;
    plane.bottom = -0.5 * plane.ycor * height + camera->shift_y * plane.viewfac;
    return plane;
}

void hbao_grid_set_projection(hbao_grid *grid, const hbao_camera *camera, int full_width,
                              int full_height, int scale) {
    const view_plane plane = fit_view_plane(camera, full_width, full_height);
    const double pixel_size = plane.pixel_size, ycor = plane.ycor;

    /* Column i of the grid is full-resolution pixel scale * i, whose centre
     * lies at (left + scale * i + 0.5) * pixel_size; likewise for rows,
     * counted from the top. */
    grid->x_step = (float)(scale * pixel_size);
    grid->x_offset = (float)((plane.left + 0.5) / scale);
    grid->y_step = (float)(-scale * ycor * pixel_size);
    grid->y_offset = (float)((plane.bottom + (full_height - 0.5) * ycor) / (-scale * ycor));
    grid->orthographic = plane.orthographic;
    grid->pixel_size = (float)(pixel_size * scale);
    grid->ycor = (float)ycor;
}

static int image_size_is_valid(int32_t width, int32_t height) {
    return width >= 1 && height >= 1 && width <= HBAO_MAX_IMAGE_SIZE &&
           height <= HBAO_MAX_IMAGE_SIZE;
}

/* hbao_clip_background_depth's margins: below Clip End by at least
 * CLIP_END_MARGIN (EEVEE's rounding of it), by twice the depth buffer's
 * precision over a long clip range, by at most MOST_CLIP_END_MARGIN. */
#define CLIP_END_MARGIN 1e-5
#define CLIP_RANGE_PRECISION 0x1p-23
#define MOST_CLIP_END_MARGIN 0.5

float hbao_clip_background_depth(float clip_start, float clip_end, float depth) {
    if (!finite_positive(clip_end)) return depth;
    if (!finite_positive(clip_start)) {
        const float at_clip_end = (float)((double)clip_end * (1.0 - CLIP_END_MARGIN));
        return at_clip_end < depth ? at_clip_end : depth;
    }
    double margin = CLIP_RANGE_PRECISION * (double)clip_end / (double)clip_start;
    if (margin > MOST_CLIP_END_MARGIN) margin = MOST_CLIP_END_MARGIN;
    if (margin < CLIP_END_MARGIN) margin = CLIP_END_MARGIN;
    return (float)((double)clip_end * (1.0 - margin));
}

hbao_result hbao_camera_view(const hbao_camera *camera, int32_t width, int32_t height,
                             hbao_view *view) {
    if (camera == NULL || view == NULL) return HBAO_ERROR_NULL_ARGUMENT;
    if (!image_size_is_valid(width, height)) return HBAO_ERROR_INVALID_SIZE;
    const hbao_result result = hbao_validate_camera(camera);
    if (result != HBAO_SUCCESS) return result;
    const view_plane plane = fit_view_plane(camera, width, height);
    view->perspective = !plane.orthographic;
    view->pixel_size_x = plane.pixel_size;
    view->pixel_size_y = plane.ycor * plane.pixel_size;
    view->origin_x = plane.left * plane.pixel_size;
    view->origin_y = plane.bottom * plane.pixel_size;
    return HBAO_SUCCESS;
}

/* A double that converts to a finite float (converting one beyond FLT_MAX is
 * undefined behaviour in C). */
static int fits_float(double value) {
    return isfinite(value) && fabs(value) <= FLT_MAX;
}

hbao_result hbao_camera_crop(const hbao_camera *camera, int32_t full_width, int32_t full_height,
                             int32_t x, int32_t y, int32_t width, int32_t height,
                             hbao_camera *cropped) {
    if (camera == NULL || cropped == NULL) return HBAO_ERROR_NULL_ARGUMENT;
    if (!image_size_is_valid(full_width, full_height)) return HBAO_ERROR_INVALID_SIZE;
    /* The rectangle may reach past the image on any side (overscan: an EXR
     * data window larger than its display window, a guard band): its pixels
     * there get the view rays the full camera's plane continues with. Only
     * its size is bounded, by the largest image hbao_compute takes. */
    if (!image_size_is_valid(width, height)) return HBAO_ERROR_INVALID_RECTANGLE;
    hbao_result result = hbao_validate_camera(camera);
    if (result != HBAO_SUCCESS) return result;
    if (x == 0 && y == 0 && width == full_width && height == full_height) {
        *cropped = *camera;
        return HBAO_SUCCESS;
    }

    const view_plane full = fit_view_plane(camera, full_width, full_height);
    /* The crop keeps the full image's fitted side, so that its pixels keep
     * their size: that side's sensor (or ortho scale) shrinks with it. */
    const double crop_viewfac = full.horizontal_fit ? (double)width : full.ycor * height;
    const double scale = crop_viewfac / full.viewfac;
    /* The crop's left and bottom edges in the full view plane, in pixel
     * widths; the crop's own plane puts them at -width / 2 + shift * viewfac. */
    const double left = full.left + x;
    const double bottom = full.bottom + full.ycor * ((double)full_height - y - height);
    /* Only the projection's own size is scaled and checked: the other one
     * (a perspective camera's ortho scale, an orthographic one's sensor)
     * is unused, as hbao_validate_camera and hbao_compute take it. */
    const int orthographic = camera->projection == HBAO_PROJECTION_ORTHOGRAPHIC;
    const double size = orthographic ? camera->ortho_scale * scale : full.sensor_size * scale;
    const double shift_x = (left + 0.5 * width) / crop_viewfac;
    const double shift_y = (bottom + 0.5 * full.ycor * height) / crop_viewfac;
    if (!fits_float(size) || !fits_float(shift_x) || !fits_float(shift_y))
        return HBAO_ERROR_INVALID_CAMERA;

    hbao_camera out = *camera;
    out.sensor_fit = full.horizontal_fit ? HBAO_SENSOR_FIT_HORIZONTAL : HBAO_SENSOR_FIT_VERTICAL;
    if (orthographic)
        out.ortho_scale = (float)size;
    else if (full.horizontal_fit)
        out.sensor_width = (float)size;
    else
        out.sensor_height = (float)size;
    out.shift_x = (float)shift_x;
    out.shift_y = (float)shift_y;
    /* A sensor or ortho scale scaled below float's range is not a camera. */
    result = hbao_validate_camera(&out);
    if (result != HBAO_SUCCESS) return result;
    *cropped = out;
    return HBAO_SUCCESS;
}
