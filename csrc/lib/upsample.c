/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Joint bilateral upsampling (Kopf et al. 2007) of half-resolution AO, guided
 * by the full-resolution depth so that AO does not bleed across edges. */
#include <math.h>

#include "internal_hbao.h"

typedef struct upsample_job {
    const hbao_grid *half;
    const float *half_ao;
    const float *full_depth;
    int width;
    float *full_ao;
} upsample_job;

static void upsample_row(void *context, int j) {
    const upsample_job *job = context;
    const hbao_grid *half = job->half;
    const int j0 = j / 2;
    const int j1 = (j & 1) && j0 + 1 < half->height ? j0 + 1 : j0;
    const float wy1 = j1 != j0 ? 0.5f : 0.0f;
    for (int i = 0; i < job->width; i++) {
        const size_t index = (size_t)j * job->width + i;
        const float z = job->full_depth[index];
        if (z <= 0.0f) {
            job->full_ao[index] = 1.0f;
            continue;
        }
        const int i0 = i / 2;
        const int i1 = (i & 1) && i0 + 1 < half->width ? i0 + 1 : i0;
        const float wx1 = i1 != i0 ? 0.5f : 0.0f;
        const int columns[2] = {i0, i1}, rows[2] = {j0, j1};
        const float column_weight[2] = {1.0f - wx1, wx1}, row_weight[2] = {1.0f - wy1, wy1};
        float sum = 0.0f, weight_sum = 0.0f;
        float nearest_ao = 1.0f, nearest_difference = INFINITY;
        for (int b = 0; b < 2; b++) {
            for (int a = 0; a < 2; a++) {
                const float bilinear = column_weight[a] * row_weight[b];
                if (bilinear <= 0.0f) continue;
                const size_t sample = (size_t)rows[b] * half->width + columns[a];
                const float zs = half->depth[sample];
                if (zs <= 0.0f) continue;
                const float difference = fabsf(zs - z) / z;
                const float scaled = HBAO_UPSAMPLE_SHARPNESS * difference;
                const float weight = bilinear * hbao_exp_negative(scaled * scaled);
                sum += weight * job->half_ao[sample];
                weight_sum += weight;
                if (difference < nearest_difference) {
                    nearest_difference = difference;
                    nearest_ao = job->half_ao[sample];
                }
            }
        }
        /* No sample at a similar depth: take the closest one in depth. */
        job->full_ao[index] = weight_sum > 1e-6f ? sum / weight_sum : nearest_ao;
    }
}

void hbao_upsample(const hbao_settings *settings, const hbao_grid *half, const float *half_ao,
                   const float *full_depth, int width, int height, float *full_ao) {
    upsample_job job = {half, half_ao, full_depth, width, full_ao};
    hbao_parallel_rows(settings->threads, height, upsample_row, &job);
}
