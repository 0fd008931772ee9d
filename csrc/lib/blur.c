/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Cross-bilateral (depth-aware) blur, applied separably: rows, then columns
 * (Bavoil & Sainz; the filter is not separable, but the separable version is
 * close and costs 2r+1 taps instead of (2r+1)^2). */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "internal_hbao.h"

#define MAX_BLUR_RADIUS ((HBAO_MAX_BLUR_SIZE - 1) / 2)

typedef struct blur_job {
    const hbao_settings *settings;
    const float *depth;
    int width, height;
    const float *source;
    float *target;
    float spatial[MAX_BLUR_RADIUS + 1]; /* Gaussian weight by tap distance */
    int along_row; /* 1: taps along the row, 0: along the column */
} blur_job;

/* One output row. Taps run in the outer loop and pixels in the inner one,
 * so the inner loop reads contiguous memory and vectorizes; each pixel still
 * sums its taps in the same order. Taps on background get weight 0. */
HBAO_VECTOR_CLONES static void blur_row(void *context, int j) {
    const blur_job *job = context;
    const int radius = job->settings->blur_radius;
    const float sharpness = job->settings->blur_sharpness;
    const int width = job->width;
    const size_t row_start = (size_t)j * width;
    const float *zc = job->depth + row_start;
    float *target = job->target + row_start;
    float *sums = malloc(3 * (size_t)width * sizeof(float));
    if (sums == NULL) {
        /* Without scratch memory, leave the row unblurred rather than fail. */
        for (int i = 0; i < width; i++) target[i] = zc[i] > 0.0f ? job->source[row_start + i] : 1.0f;
        return;
    }
    float *sum = sums, *weight_sum = sums + width, *inv_zc = sums + 2 * (size_t)width;
    for (int i = 0; i < width; i++) {
        sum[i] = 0.0f;
        weight_sum[i] = 0.0f;
        /* sharpness / z overflows for tiny depths (1e-40, or 1e-37 at the
         * largest sharpness); an infinite factor would turn the centre tap's
         * 0 difference into NaN. Capped at FLT_MAX the product stays a number:
         * the centre weighs 1, and other taps 0 or their usual weight. */
        inv_zc[i] = zc[i] > 0.0f ? fminf(sharpness / zc[i], FLT_MAX) : 0.0f;
    }
    for (int k = -radius; k <= radius; k++) {
        const float spatial = job->spatial[k < 0 ? -k : k];
        int first, last; /* pixels i whose tap i + k (or row j + k) exists */
        ptrdiff_t offset;
        if (job->along_row) {
            first = k < 0 ? -k : 0;
            last = k > 0 ? width - k : width;
            offset = (ptrdiff_t)row_start + k;
        } else {
            if (j + k < 0 || j + k >= job->height) continue;
            first = 0;
            last = width;
            offset = (ptrdiff_t)(j + k) * width;
        }
        const float *z = job->depth + offset;
        const float *ao = job->source + offset;
        for (int i = first; i < last; i++) {
            const float difference = (z[i] - zc[i]) * inv_zc[i];
            /* A 0/1 factor rather than a branch keeps the loop vectorized;
             * the weight is finite, so the product is exact. */
            const float valid = (float)(z[i] > 0.0f);
            const float weight = spatial * hbao_exp_negative(difference * difference) * valid;
            sum[i] += weight * ao[i];
            weight_sum[i] += weight;
        }
    }
    /* The centre tap always counts (weight > 0) unless the pixel is
     * background, which stays 1. */
    for (int i = 0; i < width; i++) target[i] = zc[i] > 0.0f ? sum[i] / weight_sum[i] : 1.0f;
    free(sums);
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
    job.along_row = 1;
    hbao_parallel_rows(settings->threads, height, blur_row, &job);

    job.source = scratch;
    job.target = ao;
    job.along_row = 0;
    hbao_parallel_rows(settings->threads, height, blur_row, &job);
}
