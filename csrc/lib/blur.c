/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Cross-bilateral (depth-aware) blur, applied separably: rows, then columns
 * (Bavoil & Sainz; the filter is not separable, but the separable version is
 * close and costs 2r+1 taps instead of (2r+1)^2). */
#include <math.h>

#include "internal_hbao.h"

#define MAX_BLUR_RADIUS ((HBAO_MAX_BLUR_SIZE - 1) / 2)

typedef struct blur_job {
    const hbao_settings *settings;
    const float *depth;
    int width, height;
    const float *source;
    float *target;
    float spatial[MAX_BLUR_RADIUS + 1]; /* Gaussian weight by tap distance */
    int step;      /* floats between taps: 1 for rows, width for columns */
    int along_row; /* 1: taps along the row */
} blur_job;

static void blur_row(void *context, int j) {
    const blur_job *job = context;
    const int radius = job->settings->blur_radius;
    const float sharpness = job->settings->blur_sharpness;
    const int width = job->width;
    for (int i = 0; i < width; i++) {
        const size_t center = (size_t)j * width + i;
        const float zc = job->depth[center];
        if (zc <= 0.0f) {
            job->target[center] = 1.0f;
            continue;
        }
        const int position = job->along_row ? i : j;
        const int extent = job->along_row ? width : job->height;
        const int first = position - radius < 0 ? -position : -radius;
        const int last = position + radius >= extent ? extent - 1 - position : radius;
        const float inv_zc = sharpness / zc;
        float sum = 0.0f, weight_sum = 0.0f;
        for (int k = first; k <= last; k++) {
            const size_t tap = (size_t)((ptrdiff_t)center + (ptrdiff_t)k * job->step);
            const float z = job->depth[tap];
            if (z <= 0.0f) continue;
            const float difference = (z - zc) * inv_zc;
            const float weight =
                job->spatial[k < 0 ? -k : k] * hbao_exp_negative(difference * difference);
            sum += weight * job->source[tap];
            weight_sum += weight;
        }
        /* The centre tap always counts, so weight_sum > 0. */
        job->target[center] = sum / weight_sum;
    }
}

void hbao_blur(const hbao_settings *settings, const float *depth, int width, int height, float *ao,
               float *scratch) {
    const int radius = settings->blur_radius;
    if (radius <= 0) return;
    blur_job job;
    job.settings = settings;
    job.depth = depth;
    job.width = width;
    job.height = height;
    const float sigma = 0.5f * (float)(radius + 1);
    for (int k = 0; k <= radius; k++) job.spatial[k] = expf(-(float)(k * k) / (2.0f * sigma * sigma));

    job.source = ao;
    job.target = scratch;
    job.step = 1;
    job.along_row = 1;
    hbao_parallel_rows(settings->threads, height, blur_row, &job);

    job.source = scratch;
    job.target = ao;
    job.step = width;
    job.along_row = 0;
    hbao_parallel_rows(settings->threads, height, blur_row, &job);
}
