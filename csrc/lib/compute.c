/* SPDX-License-Identifier: GPL-2.0-or-later */
/* hbao_compute(): argument checks and the pipeline. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal_finish.h"

/* The limits are hbao_params_resolve()'s (params.c); this only derives the
 * pipeline's settings from the resolved values. */
hbao_result hbao_settings_make(const hbao_params *params, hbao_settings *s) {
    hbao_params p;
    const hbao_result resolved = hbao_params_resolve(params, &p, NULL);
    if (resolved != HBAO_SUCCESS) return resolved;
    s->radius = p.radius;
    {
        const float inverse = 1.0f / (p.radius * p.radius);
        s->inv_radius2 = inverse < FLT_MAX ? inverse : FLT_MAX;
    }
    s->sin_bias = sinf(p.angle_bias_degrees * (HBAO_PI / 180.0f));
    s->bias_elevation_sine = hbao_sine_from_cosine(s->sin_bias);
    s->bias_elevation_acos = hbao_acos(s->sin_bias);
    s->directions = p.directions;
    s->steps = p.steps;
    s->falloff = p.falloff;
    s->integration = p.integration;
    s->blur_radius = hbao_blur_kernel_radius(p.blur_size);
    s->blur_sharpness = p.blur_sharpness;
    s->half_resolution = p.half_resolution;
    s->grid_blur_radius = s->half_resolution ? (s->blur_radius + 1) / 2 : s->blur_radius;
    s->strength = p.strength;
    s->threads = p.threads == 0 ? hbao_available_cores() : p.threads;
    s->background_depth = p.background_depth;
    s->implementation = p.implementation;
    s->thickness = p.thickness;
    s->blur_strips = 0; /* blur.c's rule */
    return HBAO_SUCCESS;
}

/* The row stride must keep rows from overlapping: |row_stride| covers a row. */
static int stride_fits(int32_t pixel_stride, int64_t row_stride, int width, int height,
                       int channels) {
    if (pixel_stride < channels) return 0;
    if (height == 1) return 1;
    const int64_t row_extent = (int64_t)(width - 1) * pixel_stride + channels;
    /* unsigned: -INT64_MIN does not fit int64_t */
    const uint64_t magnitude = row_stride < 0 ? 0u - (uint64_t)row_stride : (uint64_t)row_stride;
    /* and the whole channel, (height - 1) strides and a row, within int64_t's
     * offsets (INT64_MIN's magnitude is not) */
    return magnitude >= (uint64_t)row_extent &&
           magnitude <= ((uint64_t)INT64_MAX - (uint64_t)row_extent) / (uint64_t)(height - 1);
}

typedef struct depth_job {
    const hbao_channel *source;
    float background_depth;
    int width;
    float *depth;
} depth_job;

/* Dense depth (hbao_depth_value). The stage is bound by memory: the dense
 * row's loop vectorized (this file compiled at -O3 -fno-trapping-math, as a
 * trial) timed the same, bench_ab_copies.sh 0.998 on 1 and 2 threads. */
static void convert_depth_row(void *context, int j) {
    const depth_job *job = context;
    const float *row = job->source->data + (int64_t)j * job->source->row_stride;
    float *restrict out = job->depth + (size_t)j * job->width;
    const float background = job->background_depth;
    const int64_t stride = job->source->pixel_stride;
    if (stride == 1) {
        for (int i = 0; i < job->width; i++) out[i] = hbao_depth_value(row[i], background);
        return;
    }
    for (int i = 0; i < job->width; i++)
        out[i] = hbao_depth_value(row[(int64_t)i * stride], background);
}

/* The back layer's value for back depth b behind front depth `front`
 * (hbao_depth_value's): b where it is known (behind the visible surface,
 * not background by hbao_depth_value's rule, EEVEE's half-float sky
 * included, and the pixel not background), else INFINITY. */
static inline float back_value(float front, float b, float background) {
    const int known = front > 0.0f && hbao_depth_value(b, background) > front;
    return known ? b : INFINITY;
}

typedef struct back_job {
    const hbao_channel *source;
    const float *front; /* the converted depth, dense */
    float background_depth;
    int width;
    float *back;
} back_job;

/* The back layer, dense, INFINITY where no back face is known (back_value). */
static void convert_back_row(void *context, int j) {
    const back_job *job = context;
    const float *row = job->source->data + (int64_t)j * job->source->row_stride;
    const float *front = job->front + (size_t)j * job->width;
    float *out = job->back + (size_t)j * job->width;
    for (int i = 0; i < job->width; i++)
        out[i] = back_value(front[i], row[(int64_t)i * job->source->pixel_stride],
                            job->background_depth);
}

/* The half grid's depth (and back layer), the full image's even pixels of
 * its even rows, converted straight from the caller's channels: at half
 * resolution no full-size converted copy is made (the upsample converts
 * the rows it reads, upsample.c). */
typedef struct half_depth_job {
    const hbao_channel *source, *back_source;
    float background_depth;
    hbao_grid *half;
    float *half_back; /* with back_source */
} half_depth_job;

static void half_depth_row(void *context, int j) {
    const half_depth_job *job = context;
    const hbao_channel *source = job->source;
    const float *row = source->data + (int64_t)(2 * j) * source->row_stride;
    const int64_t stride = 2 * (int64_t)source->pixel_stride;
    const size_t at = (size_t)j * job->half->width;
    float *out = job->half->depth + at;
    for (int i = 0; i < job->half->width; i++)
        out[i] = hbao_depth_value(row[(int64_t)i * stride], job->background_depth);
    if (job->back_source == NULL) return;
    const float *backs = job->back_source->data + (int64_t)(2 * j) * job->back_source->row_stride;
    const int64_t back_stride = 2 * (int64_t)job->back_source->pixel_stride;
    float *back_out = job->half_back + at;
    for (int i = 0; i < job->half->width; i++)
        back_out[i] = back_value(out[i], backs[(int64_t)i * back_stride], job->background_depth);
}

/* The first and last byte address that a channel's pixels (`channels`
 * floats each) span, from its strides; in uintptr_t arithmetic, exact for
 * any buffer that the address space can hold. */
static void channel_bytes(const float *data, int32_t pixel_stride, int64_t row_stride, int width,
                          int height, int channels, uintptr_t *first, uintptr_t *last) {
    const int64_t rows = (int64_t)(height - 1) * row_stride; /* stride_fits: in range */
    const int64_t low = rows < 0 ? rows : 0;
    const int64_t high = (rows > 0 ? rows : 0) + (int64_t)(width - 1) * pixel_stride + channels - 1;
    const uintptr_t base = (uintptr_t)data;
    *first = base + (uintptr_t)low * sizeof(float);
    *last = base + (uintptr_t)high * sizeof(float) + (sizeof(float) - 1);
}

/* Whether the output's floats share memory with the depth channel's: the
 * half resolution's upsample reads the depth rows while other rows of the
 * output are written (upsample.c), so that depth is then copied first. */
static int output_overlaps_depth(const hbao_channel *depth, const float *ao, int64_t ao_row_stride,
                                 int width, int height) {
    uintptr_t depth_first, depth_last, ao_first, ao_last;
    channel_bytes(depth->data, depth->pixel_stride, depth->row_stride, width, height, 1,
                  &depth_first, &depth_last);
    channel_bytes(ao, 1, ao_row_stride, width, height, 1, &ao_first, &ao_last);
    return depth_first <= ao_last && ao_first <= depth_last;
}

static int any_finite(const float *values, size_t count) {
    for (size_t k = 0; k < count; k++)
        if (values[k] < INFINITY) return 1;
    return 0;
}

typedef struct ones_job {
    float *ao;
    int64_t row_stride;
    int width;
} ones_job;

static void ones_row(void *context, int j) {
    const ones_job *job = context;
    float *row = job->ao + (int64_t)j * job->row_stride;
    for (int i = 0; i < job->width; i++) row[i] = 1.0f;
}

/* 1 at every output pixel, the rows shared among the threads */
static void fill_ones(const hbao_settings *s, float *ao, int64_t row_stride, int width,
                      int height) {
    ones_job job = {ao, row_stride, width};
    hbao_parallel_rows(s->threads, height, ones_row, &job);
}

/* The calling thread's last call's HBAO_NOTE_* bits (hbao_last_notes). */
static _Thread_local uint32_t last_notes;

uint32_t hbao_last_notes(void) {
    return last_notes;
}

hbao_result hbao_compute(const hbao_params *params, const hbao_camera *camera, int32_t width,
                         int32_t height, const hbao_channel *depth, const hbao_channel *normal,
                         float *ao, int64_t ao_row_stride) {
    return hbao_compute_layers(params, camera, width, height, depth, normal, NULL, ao,
                               ao_row_stride);
}

hbao_result hbao_compute_layers(const hbao_params *params, const hbao_camera *camera, int32_t width,
                                int32_t height, const hbao_channel *depth,
                                const hbao_channel *normal, const hbao_channel *back_depth,
                                float *ao, int64_t ao_row_stride) {
    last_notes = 0;
    if (params == NULL || camera == NULL || depth == NULL || depth->data == NULL || ao == NULL)
        return HBAO_ERROR_NULL_ARGUMENT;
    if (width < 1 || height < 1 || width > HBAO_MAX_IMAGE_SIZE || height > HBAO_MAX_IMAGE_SIZE)
        return HBAO_ERROR_INVALID_SIZE;
    if (normal != NULL && normal->data == NULL) normal = NULL;
    if (back_depth != NULL && back_depth->data == NULL) back_depth = NULL;
    if (!stride_fits(depth->pixel_stride, depth->row_stride, width, height, 1) ||
        (normal != NULL &&
         !stride_fits(normal->pixel_stride, normal->row_stride, width, height, 3)) ||
        (back_depth != NULL &&
         !stride_fits(back_depth->pixel_stride, back_depth->row_stride, width, height, 1)) ||
        !stride_fits(1, ao_row_stride, width, height, 1))
        return HBAO_ERROR_INVALID_STRIDE;
    hbao_settings s;
    hbao_result result = hbao_settings_make(params, &s);
    if (result != HBAO_SUCCESS) return result;
    result = hbao_validate_camera(camera);
    if (result != HBAO_SUCCESS) return result;
    if (s.radius == 0.0f) { /* nothing sampled anywhere, depths unread */
        last_notes = HBAO_NOTE_RADIUS_UNDER_A_PIXEL;
        fill_ones(&s, ao, ao_row_stride, width, height);
        return HBAO_SUCCESS;
    }

    const int scale = s.half_resolution ? 2 : 1;
    hbao_grid grid;
    grid.width = (width + scale - 1) / scale;
    grid.height = (height + scale - 1) / scale;
    const size_t grid_pixels = (size_t)grid.width * grid.height;

    /* The raw AO on the grid; the later stages (blur.c) turn it into the
     * output row by row, with no other full-size buffer. */
    float *guide_copy = NULL; /* the upsample's, where it needs one (below) */
    float *grid_depth = hbao_scratch_take(grid_pixels * sizeof(float));
    float *grid_ao = hbao_scratch_take(grid_pixels * sizeof(float));
    float *grid_back = back_depth != NULL ? hbao_scratch_take(grid_pixels * sizeof(float)) : NULL;
    grid.normal = hbao_scratch_take((grid_pixels * 3 + HBAO_NORMAL_PADDING) * sizeof(float));
    grid.beyond = hbao_scratch_take(hbao_beyond_floats(grid.width, grid.height) * sizeof(float));
    grid.depth = grid_depth;
    grid.back = grid_back;
    if (grid_depth == NULL || grid_ao == NULL || grid.normal == NULL || grid.beyond == NULL ||
        (back_depth != NULL && grid_back == NULL)) {
        result = HBAO_ERROR_OUT_OF_MEMORY;
        goto done;
    }

    /* The upsample's guide: the caller's depth, or where the output
     * overlaps it (computed in place), a converted copy taken first. */
    hbao_channel guide = *depth;
    if (s.half_resolution && output_overlaps_depth(depth, ao, ao_row_stride, width, height)) {
        guide_copy = hbao_scratch_take((size_t)width * height * sizeof(float));
        if (guide_copy == NULL) {
            result = HBAO_ERROR_OUT_OF_MEMORY;
            goto done;
        }
        depth_job convert = {depth, s.background_depth, width, guide_copy};
        hbao_parallel_rows(s.threads, height, convert_depth_row, &convert);
        guide = (hbao_channel){guide_copy, 1, width}; /* background already 0 */
    }
    if (s.half_resolution) {
        half_depth_job halve = {depth, back_depth, s.background_depth, &grid, grid_back};
        hbao_parallel_rows(s.threads, grid.height, half_depth_row, &halve);
    } else {
        depth_job convert = {depth, s.background_depth, width, grid_depth};
        hbao_parallel_rows(s.threads, height, convert_depth_row, &convert);
        if (back_depth != NULL) {
            back_job backs = {back_depth, grid_depth, s.background_depth, width, grid_back};
            hbao_parallel_rows(s.threads, height, convert_back_row, &backs);
        }
    }
    hbao_grid_set_projection(&grid, camera, width, height, scale);
    if (!hbao_grid_sampled(&s, &grid)) {
        /* every projected radius under a pixel: 1s, as the stages give */
        last_notes = hbao_radius_notes(&s, &grid);
        fill_ones(&s, ao, ao_row_stride, width, height);
        goto done;
    }
    /* A layer with no back face known anywhere is no layer: the result is
     * hbao_compute()'s, exactly, not its sector-quantised twin. */
    if (grid.back != NULL && !any_finite(grid.back, grid_pixels)) grid.back = NULL;
    hbao_compute_normals(&s, camera, &grid, normal, scale);
    hbao_beyond_planes(&grid);

    last_notes = hbao_compute_horizons(&s, &grid, grid_ao);
    result = hbao_finish(&s, &grid, grid_ao, &guide, width, height, ao, ao_row_stride);

done:
    hbao_scratch_give(guide_copy);
    hbao_scratch_give(grid_depth);
    hbao_scratch_give(grid_ao);
    hbao_scratch_give(grid_back);
    hbao_scratch_give(grid.normal);
    hbao_scratch_give(grid.beyond);
    return result;
}
