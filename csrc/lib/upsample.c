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

/* One candidate's share: bilinear weight times depth similarity. Written
 * with selects only (no branches) so that the row loop vectorizes. */
static inline __attribute__((always_inline)) void add_candidate(float bilinear, float zs, float ao, float z, float *sum,
                                 float *weight_sum, float *nearest_ao, float *nearest_difference) {
    const int usable = (bilinear > 0.0f) & (zs > 0.0f);
    const float difference = fabsf(zs - z) / z;
    const float scaled = HBAO_UPSAMPLE_SHARPNESS * difference;
    const float weight = bilinear * hbao_exp_negative(scaled * scaled) * (float)usable;
    *sum += weight * ao;
    *weight_sum += weight;
    const int nearer = usable & (difference < *nearest_difference);
    *nearest_ao = nearer ? ao : *nearest_ao;
    *nearest_difference = nearer ? difference : *nearest_difference;
}

/* One full-resolution row; candidates in the order (left, top), (right,
 * top), (left, bottom), (right, bottom). Even pixels sit on a half-grid
 * column and odd ones between two, so each gets its own loop over the half
 * columns k: every access to the half grid is then contiguous and both loops
 * vectorize. A candidate with bilinear weight 0 adds nothing, so even pixels
 * skip the right-hand column. */
HBAO_VECTOR_CLONES static void upsample_row(void *context, int j) {
    const upsample_job *job = context;
    const hbao_grid *half = job->half;
    const int half_width = half->width, width = job->width;
    const int r0 = j / 2;
    const int r1 = (j & 1) && r0 + 1 < half->height ? r0 + 1 : r0;
    const float top_weight = r1 != r0 ? 0.5f : 1.0f, bottom_weight = 1.0f - top_weight;
    const float *z_top = half->depth + (size_t)r0 * half_width;
    const float *z_bottom = half->depth + (size_t)r1 * half_width;
    const float *ao_top = job->half_ao + (size_t)r0 * half_width;
    const float *ao_bottom = job->half_ao + (size_t)r1 * half_width;
    const float *z_row = job->full_depth + (size_t)j * width;
    float *out = job->full_ao + (size_t)j * width;

    const int even_count = (width + 1) / 2; /* pixels 2k */
    for (int k = 0; k < even_count; k++) {
        const float z = z_row[2 * k];
        float sum = 0.0f, weight_sum = 0.0f, nearest_ao = 1.0f, nearest_difference = INFINITY;
        add_candidate(top_weight, z_top[k], ao_top[k], z, &sum, &weight_sum, &nearest_ao,
                      &nearest_difference);
        add_candidate(bottom_weight, z_bottom[k], ao_bottom[k], z, &sum, &weight_sum, &nearest_ao,
                      &nearest_difference);
        /* No sample at a similar depth: take the closest one in depth. */
        const float blended = weight_sum > 1e-6f ? sum / weight_sum : nearest_ao;
        out[2 * k] = z > 0.0f ? blended : 1.0f;
    }
    /* Odd pixels 2k + 1 lie between half columns k and k + 1; the last one
     * may have no right neighbour (width even, half_width = width / 2). */
    const int odd_count = width / 2;
    const int odd_inner = odd_count < half_width - 1 ? odd_count : half_width - 1;
    for (int k = 0; k < odd_count; k++) {
        const int right = k < odd_inner ? k + 1 : k;
        const float right_weight = k < odd_inner ? 0.5f : 0.0f, left_weight = 1.0f - right_weight;
        const float z = z_row[2 * k + 1];
        float sum = 0.0f, weight_sum = 0.0f, nearest_ao = 1.0f, nearest_difference = INFINITY;
        add_candidate(left_weight * top_weight, z_top[k], ao_top[k], z, &sum, &weight_sum,
                      &nearest_ao, &nearest_difference);
        add_candidate(right_weight * top_weight, z_top[right], ao_top[right], z, &sum,
                      &weight_sum, &nearest_ao, &nearest_difference);
        add_candidate(left_weight * bottom_weight, z_bottom[k], ao_bottom[k], z, &sum,
                      &weight_sum, &nearest_ao, &nearest_difference);
        add_candidate(right_weight * bottom_weight, z_bottom[right], ao_bottom[right], z, &sum,
                      &weight_sum, &nearest_ao, &nearest_difference);
        const float blended = weight_sum > 1e-6f ? sum / weight_sum : nearest_ao;
        out[2 * k + 1] = z > 0.0f ? blended : 1.0f;
    }
}

void hbao_upsample(const hbao_settings *settings, const hbao_grid *half, const float *half_ao,
                   const float *full_depth, int width, int height, float *full_ao) {
    upsample_job job = {half, half_ao, full_depth, width, full_ao};
    hbao_parallel_rows(settings->threads, height, upsample_row, &job);
}
