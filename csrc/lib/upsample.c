/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Joint bilateral upsampling (Kopf et al. 2007) of half-resolution AO, guided
 * by the full-resolution depth so that AO does not bleed across edges. One
 * full-resolution row at a time: the blur (blur.c) asks for each row as it
 * needs it, so the upsampled image is never written out whole. */
#include <math.h>

#include "internal_finish.h"

/* One candidate's share: bilinear weight times depth similarity, for the AO
 * and for the blur's guide normal alike. Written with selects only (no
 * branches) so that the row loop vectorizes. */
static HBAO_ALWAYS_INLINE void add_candidate(float bilinear, float zs, float ao,
                                             const float *normal, float z, float *sum,
                                             float *weight_sum, float *nearest_ao,
                                             float *nearest_difference, float normal_sum[3],
                                             float nearest_normal[3]) {
    const int usable = (bilinear > 0.0f) & (zs > 0.0f);
    const float difference = fabsf(zs - z) / z;
    const float scaled = HBAO_UPSAMPLE_SHARPNESS * difference;
    const float weight = bilinear * hbao_exp_negative(scaled * scaled) * (float)usable;
    *sum += weight * ao;
    *weight_sum += weight;
    for (int c = 0; c < 3; c++) normal_sum[c] += weight * normal[c];
    const int nearer = usable & (difference < *nearest_difference);
    *nearest_ao = nearer ? ao : *nearest_ao;
    *nearest_difference = nearer ? difference : *nearest_difference;
    for (int c = 0; c < 3; c++) nearest_normal[c] = nearer ? normal[c] : nearest_normal[c];
}

/* One pixel's AO and guide normal from its candidates' sums. The guide
 * normal is the candidates' normals averaged with the AO's weights and
 * normalised: a weighted mean rather than the nearest candidate's, so that
 * it does not jump where two candidates are about equally near in depth (at
 * a crease); there it lies between the faces and the blur leaves the pixel
 * nearly alone. Without weight it falls back like the AO: to the candidate
 * nearest in depth, or the top-left one's if none is usable. */
static HBAO_ALWAYS_INLINE void finish_pixel(float z, float sum, float weight_sum, float nearest_ao,
                                            const float normal_sum[3],
                                            const float nearest_normal[3], float *out, float *nx,
                                            float *ny, float *nz) {
    const int weighted = weight_sum > 1e-6f;
    /* No sample at a similar depth: take the closest one in depth. */
    const float blended = weighted ? sum / weight_sum : nearest_ao;
    *out = z > 0.0f ? blended : 1.0f;
    const float length = sqrtf(normal_sum[0] * normal_sum[0] + normal_sum[1] * normal_sum[1] +
                               normal_sum[2] * normal_sum[2]);
    const int averaged = weighted & (length > 0.0f);
    const float inverse = 1.0f / (averaged ? length : 1.0f);
    *nx = averaged ? normal_sum[0] * inverse : nearest_normal[0];
    *ny = averaged ? normal_sum[1] * inverse : nearest_normal[1];
    *nz = averaged ? normal_sum[2] * inverse : nearest_normal[2];
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
                                             int two_rows, float *restrict out, float *restrict nx,
                                             float *restrict ny, float *restrict nz) {
    const int half_width = half->width;
    const int r0 = j / 2;
    const int r1 = two_rows ? r0 + 1 : r0;
    const float top_weight = two_rows ? 0.5f : 1.0f, bottom_weight = 1.0f - top_weight;
    const float *z_top = half->depth + (size_t)r0 * half_width;
    const float *z_bottom = half->depth + (size_t)r1 * half_width;
    const float *ao_top = half_ao + (size_t)r0 * half_width;
    const float *ao_bottom = half_ao + (size_t)r1 * half_width;
    const float *n_top = half->normal + 3 * (size_t)r0 * half_width;
    const float *n_bottom = half->normal + 3 * (size_t)r1 * half_width;
    const float *z_row = full_depth + (size_t)j * width;

    const int even_count = (width + 1) / 2; /* pixels 2k */
    for (int k = 0; k < even_count; k++) {
        const float z = z_row[2 * k];
        float sum = 0.0f, weight_sum = 0.0f, nearest_ao = 1.0f, nearest_difference = INFINITY;
        float normal[3] = {n_top[3 * k], n_top[3 * k + 1], n_top[3 * k + 2]};
        float normal_sum[3] = {0.0f, 0.0f, 0.0f};
        add_candidate(top_weight, z_top[k], ao_top[k], n_top + 3 * k, z, &sum, &weight_sum,
                      &nearest_ao, &nearest_difference, normal_sum, normal);
        if (two_rows)
            add_candidate(bottom_weight, z_bottom[k], ao_bottom[k], n_bottom + 3 * k, z, &sum,
                          &weight_sum, &nearest_ao, &nearest_difference, normal_sum, normal);
        finish_pixel(z, sum, weight_sum, nearest_ao, normal_sum, normal, out + 2 * k, nx + 2 * k,
                     ny + 2 * k, nz + 2 * k);
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
        float normal[3] = {n_top[3 * k], n_top[3 * k + 1], n_top[3 * k + 2]};
        float normal_sum[3] = {0.0f, 0.0f, 0.0f};
        add_candidate(left_weight * top_weight, z_top[k], ao_top[k], n_top + 3 * k, z, &sum,
                      &weight_sum, &nearest_ao, &nearest_difference, normal_sum, normal);
        add_candidate(right_weight * top_weight, z_top[right], ao_top[right], n_top + 3 * right, z,
                      &sum, &weight_sum, &nearest_ao, &nearest_difference, normal_sum, normal);
        if (two_rows) {
            add_candidate(left_weight * bottom_weight, z_bottom[k], ao_bottom[k], n_bottom + 3 * k,
                          z, &sum, &weight_sum, &nearest_ao, &nearest_difference, normal_sum,
                          normal);
            add_candidate(right_weight * bottom_weight, z_bottom[right], ao_bottom[right],
                          n_bottom + 3 * right, z, &sum, &weight_sum, &nearest_ao,
                          &nearest_difference, normal_sum, normal);
        }
        finish_pixel(z, sum, weight_sum, nearest_ao, normal_sum, normal, out + 2 * k + 1,
                     nx + 2 * k + 1, ny + 2 * k + 1, nz + 2 * k + 1);
    }
}

/* Rows that lie on a half-grid row (and the last odd row, which has no row
 * below) have bilinear weight 0 on the row below: a candidate of weight 0
 * adds exactly nothing, so those rows skip it. */
static HBAO_ALWAYS_INLINE void upsample_row(const hbao_grid *half, const float *half_ao,
                                            const float *full_depth, int width, int j,
                                            float *restrict out, float *restrict nx,
                                            float *restrict ny, float *restrict nz) {
    if ((j & 1) && j / 2 + 1 < half->height)
        upsample_rows(half, half_ao, full_depth, width, j, 1, out, nx, ny, nz);
    else
        upsample_rows(half, half_ao, full_depth, width, j, 0, out, nx, ny, nz);
}

static void upsample_row_portable(const hbao_grid *half, const float *half_ao,
                                  const float *full_depth, int width, int j, float *out, float *nx,
                                  float *ny, float *nz) {
    upsample_row(half, half_ao, full_depth, width, j, out, nx, ny, nz);
}

#ifdef HBAO_FINISH_X86
HBAO_TARGET_AVX2 static void upsample_row_avx2(const hbao_grid *half, const float *half_ao,
                                               const float *full_depth, int width, int j,
                                               float *out, float *nx, float *ny, float *nz) {
    upsample_row(half, half_ao, full_depth, width, j, out, nx, ny, nz);
}

HBAO_TARGET_AVX512 static void upsample_row_avx512(const hbao_grid *half, const float *half_ao,
                                                   const float *full_depth, int width, int j,
                                                   float *out, float *nx, float *ny, float *nz) {
    upsample_row(half, half_ao, full_depth, width, j, out, nx, ny, nz);
}
#endif

void hbao_upsample_row(int implementation, const hbao_grid *half, const float *half_ao,
                       const float *full_depth, int width, int j, float *ao, float *normal_x,
                       float *normal_y, float *normal_z) {
#ifdef HBAO_FINISH_X86
    if (implementation == HBAO_IMPLEMENTATION_AVX512) {
        upsample_row_avx512(half, half_ao, full_depth, width, j, ao, normal_x, normal_y, normal_z);
        return;
    }
    if (implementation == HBAO_IMPLEMENTATION_AVX2) {
        upsample_row_avx2(half, half_ao, full_depth, width, j, ao, normal_x, normal_y, normal_z);
        return;
    }
#else
    (void)implementation;
#endif
    upsample_row_portable(half, half_ao, full_depth, width, j, ao, normal_x, normal_y, normal_z);
}
