/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Joint bilateral upsampling (Kopf et al. 2007) of half-resolution AO, guided
 * by the full-resolution depth so that AO does not bleed across edges. One
 * full-resolution row at a time, written straight into the caller's output
 * (blur.c): the AO arrives already blurred on the half grid. */
#include <math.h>

#include "internal_finish.h"

/* One candidate's share: bilinear weight times depth similarity. Written
 * with selects only (no branches) so that the row loop vectorizes. */
static HBAO_ALWAYS_INLINE void add_candidate(float bilinear, float zs, float ao, float z,
                                             float *sum, float *weight_sum, float *nearest_ao,
                                             float *nearest_difference) {
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

/* One pixel's AO from its candidates' sums; with no sample at a similar
 * depth, the candidate nearest in depth (1 if none is usable). Clamped to
 * [0, 1] as the output is (hbao_clamp_ao): a weighted mean of values
 * in [0, 1] can round past 1. */
static HBAO_ALWAYS_INLINE float finish_pixel(float z, float sum, float weight_sum,
                                             float nearest_ao) {
    const float blended = weight_sum > 1e-6f ? sum / weight_sum : nearest_ao;
    return hbao_clamp_ao(z > 0.0f ? blended : 1.0f);
}

/* One full-resolution row; candidates in the order (left, top), (right,
 * top), (left, bottom), (right, bottom). Even pixels sit on a half-grid
 * column and odd ones between two, so each gets its own loop over the half
 * columns k: every access to the half grid is then contiguous and both loops
 * vectorize. A candidate with bilinear weight 0 adds nothing, so even pixels
 * skip the right-hand column (and rows without a row below, see
 * upsample_row, skip the bottom candidates). */
static HBAO_ALWAYS_INLINE void upsample_rows(const hbao_grid *half, const float *half_ao,
                                             const float *full_depth, int width, int j,
                                             int two_rows, float *restrict out) {
    const int half_width = half->width;
    const int r0 = j / 2;
    const int r1 = two_rows ? r0 + 1 : r0;
    const float top_weight = two_rows ? 0.5f : 1.0f, bottom_weight = 1.0f - top_weight;
    const float *z_top = half->depth + (size_t)r0 * half_width;
    const float *z_bottom = half->depth + (size_t)r1 * half_width;
    const float *ao_top = half_ao + (size_t)r0 * half_width;
    const float *ao_bottom = half_ao + (size_t)r1 * half_width;
    const float *z_row = full_depth + (size_t)j * width;

    const int even_count = (width + 1) / 2; /* pixels 2k */
    for (int k = 0; k < even_count; k++) {
        const float z = z_row[2 * k];
        float sum = 0.0f, weight_sum = 0.0f, nearest_ao = 1.0f, nearest_difference = INFINITY;
        add_candidate(top_weight, z_top[k], ao_top[k], z, &sum, &weight_sum, &nearest_ao,
                      &nearest_difference);
        if (two_rows)
            add_candidate(bottom_weight, z_bottom[k], ao_bottom[k], z, &sum, &weight_sum,
                          &nearest_ao, &nearest_difference);
        out[2 * k] = finish_pixel(z, sum, weight_sum, nearest_ao);
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
        add_candidate(right_weight * top_weight, z_top[right], ao_top[right], z, &sum, &weight_sum,
                      &nearest_ao, &nearest_difference);
        if (two_rows) {
            add_candidate(left_weight * bottom_weight, z_bottom[k], ao_bottom[k], z, &sum,
                          &weight_sum, &nearest_ao, &nearest_difference);
            add_candidate(right_weight * bottom_weight, z_bottom[right], ao_bottom[right], z, &sum,
                          &weight_sum, &nearest_ao, &nearest_difference);
        }
        out[2 * k + 1] = finish_pixel(z, sum, weight_sum, nearest_ao);
    }
}

/* Rows that lie on a half-grid row (and the last odd row, which has no row
 * below) have bilinear weight 0 on the row below: a candidate of weight 0
 * adds exactly nothing, so those rows skip it. */
static HBAO_ALWAYS_INLINE void upsample_row(const hbao_grid *half, const float *half_ao,
                                            const float *full_depth, int width, int j,
                                            float *restrict out) {
    if ((j & 1) && j / 2 + 1 < half->height)
        upsample_rows(half, half_ao, full_depth, width, j, 1, out);
    else
        upsample_rows(half, half_ao, full_depth, width, j, 0, out);
}

static void upsample_row_portable(const hbao_grid *half, const float *half_ao,
                                  const float *full_depth, int width, int j, float *out) {
    upsample_row(half, half_ao, full_depth, width, j, out);
}

#ifdef HBAO_FINISH_X86
HBAO_TARGET_AVX2 static void upsample_row_avx2(const hbao_grid *half, const float *half_ao,
                                               const float *full_depth, int width, int j,
                                               float *out) {
    upsample_row(half, half_ao, full_depth, width, j, out);
}

HBAO_TARGET_AVX512 static void upsample_row_avx512(const hbao_grid *half, const float *half_ao,
                                                   const float *full_depth, int width, int j,
                                                   float *out) {
    upsample_row(half, half_ao, full_depth, width, j, out);
}
#endif

void hbao_upsample_row(int implementation, const hbao_grid *half, const float *half_ao,
                       const float *full_depth, int width, int j, float *ao) {
#ifdef HBAO_FINISH_X86
    if (implementation == HBAO_IMPLEMENTATION_AVX512) {
        upsample_row_avx512(half, half_ao, full_depth, width, j, ao);
        return;
    }
    if (implementation == HBAO_IMPLEMENTATION_AVX2) {
        upsample_row_avx2(half, half_ao, full_depth, width, j, ao);
        return;
    }
#else
    (void)implementation;
#endif
    upsample_row_portable(half, half_ao, full_depth, width, j, ao);
}
