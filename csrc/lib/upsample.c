/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Joint bilateral upsampling (Kopf et al. 2007) of half-resolution AO, guided
 * by the caller's full-resolution depth (guide_depth) so that AO does not
 * bleed across edges. One full-resolution row at a time, written straight
 * into the caller's output (blur.c): the AO arrives already blurred on the
 * half grid. */
#include <float.h>
#include <math.h>

#include "internal_finish.h"

/* One candidate's share: bilinear weight times depth similarity, the
 * blur's falloff F (internal_finish.h) of (UPSAMPLE_SHARPNESS |zs - z| / z)^2,
 * its base formed from the pixel's factor (upsample_factor). The nearest
 * candidate is the one nearest in |zs - z|, which orders the candidates of
 * a pixel as the relative difference does. Written with selects only (no
 * branches) so that the row loop vectorizes. */
static HBAO_ALWAYS_INLINE void add_candidate(float bilinear, float zs, float ao, float z,
                                             float factor, float *sum, float *weight_sum,
                                             float *nearest_ao, float *nearest_gap) {
    const int usable = (bilinear > 0.0f) & (zs > 0.0f);
    const float gap = fabsf(zs - z);
    const float scaled = gap * factor;
    const float weight = bilinear * hbao_blur_power(1.0f - scaled * scaled) * (float)usable;
    *sum += weight * ao;
    *weight_sum += weight;
    const int nearer = usable & (gap < *nearest_gap);
    *nearest_ao = nearer ? ao : *nearest_ao;
    *nearest_gap = nearer ? gap : *nearest_gap;
}

/* A pixel's factor: UPSAMPLE_SHARPNESS / sqrt(R) / z, computed once for
 * its candidates. Capped at FLT_MAX, as the blur's is: for a tiny depth it
 * overflows, and a candidate at the same depth would weigh 0 * inf = NaN. */
static HBAO_ALWAYS_INLINE float upsample_factor(float z) {
    const float factor = HBAO_UPSAMPLE_DEPTH_WEIGHT / z;
    return factor < FLT_MAX ? factor : FLT_MAX;
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

/* Pixel i's depth in the caller's row z_row (stride floats apart), as the
 * pipeline uses it (hbao_depth_value: background is 0). The upsample reads
 * the caller's depth channel itself: no converted full-size copy is made at
 * half resolution (bench_ab, 1080p defaults at half resolution, 0.955 on 2
 * threads, 0.952-0.960 on 1; docs/speed.md, session 26). Where the output
 * overlaps that depth, compute.c hands a copy instead. */
static HBAO_ALWAYS_INLINE float guide_depth(const float *z_row, int64_t stride, float background,
                                            int i) {
    return hbao_depth_value(z_row[(int64_t)i * stride], background);
}

/* The half grid's two rows that a full-resolution row's candidates come
 * from (the same row twice where there is no row below), and their
 * bilinear weights. */
typedef struct half_rows {
    const float *z_top, *z_bottom, *ao_top, *ao_bottom;
    float top_weight, bottom_weight;
} half_rows;

/* Even pixel 2k: on half column k. */
static HBAO_ALWAYS_INLINE float even_pixel(const half_rows *h, int two_rows, float z, int k) {
    const float factor = upsample_factor(z);
    float sum = 0.0f, weight_sum = 0.0f, nearest_ao = 1.0f, nearest_gap = INFINITY;
    add_candidate(h->top_weight, h->z_top[k], h->ao_top[k], z, factor, &sum, &weight_sum,
                  &nearest_ao, &nearest_gap);
    if (two_rows)
        add_candidate(h->bottom_weight, h->z_bottom[k], h->ao_bottom[k], z, factor, &sum,
                      &weight_sum, &nearest_ao, &nearest_gap);
    return finish_pixel(z, sum, weight_sum, nearest_ao);
}

/* Odd pixel 2k + 1: between half columns k and right (k + 1, or k itself
 * with right_weight 0 where there is no column to the right). */
static HBAO_ALWAYS_INLINE float odd_pixel(const half_rows *h, int two_rows, float z, int k,
                                          int right, float right_weight) {
    const float left_weight = 1.0f - right_weight;
    const float factor = upsample_factor(z);
    float sum = 0.0f, weight_sum = 0.0f, nearest_ao = 1.0f, nearest_gap = INFINITY;
    add_candidate(left_weight * h->top_weight, h->z_top[k], h->ao_top[k], z, factor, &sum,
                  &weight_sum, &nearest_ao, &nearest_gap);
    add_candidate(right_weight * h->top_weight, h->z_top[right], h->ao_top[right], z, factor, &sum,
                  &weight_sum, &nearest_ao, &nearest_gap);
    if (two_rows) {
        add_candidate(left_weight * h->bottom_weight, h->z_bottom[k], h->ao_bottom[k], z, factor,
                      &sum, &weight_sum, &nearest_ao, &nearest_gap);
        add_candidate(right_weight * h->bottom_weight, h->z_bottom[right], h->ao_bottom[right], z,
                      factor, &sum, &weight_sum, &nearest_ao, &nearest_gap);
    }
    return finish_pixel(z, sum, weight_sum, nearest_ao);
}

/* Whether the half grid is background (depth 0) at columns first to
 * first + SKY_CHUNK of both rows (internal_finish.h): then no candidate of
 * the chunk's pairs is usable, and each of its 2 * SKY_CHUNK pixels is
 * finish_pixel's 1 (the nearest candidate's AO where none weighs enough, 1
 * where none is usable; 1 on background). A sky above geometry at half
 * resolution. Testing the row's own depths instead (32 strided reads a
 * chunk) cost frames without sky 1-2 %; the first column's test alone
 * leaves most chunks of geometry. */
#define SKY_CHUNK HBAO_UPSAMPLE_SKY_CHUNK
static HBAO_ALWAYS_INLINE int sky_chunk(const half_rows *h, int first) {
    if ((h->z_top[first] > 0.0f) | (h->z_bottom[first] > 0.0f)) return 0;
    int any = (h->z_top[first + SKY_CHUNK] > 0.0f) | (h->z_bottom[first + SKY_CHUNK] > 0.0f);
    for (int i = first; i < first + SKY_CHUNK; i++)
        any |= (h->z_top[i] > 0.0f) | (h->z_bottom[i] > 0.0f);
    return !any;
}

/* Pixels 2k and 2k + 1 of a pair (half columns k and k + 1) */
static HBAO_ALWAYS_INLINE void upsample_pair(const half_rows *h, int two_rows, const float *z_row,
                                             int64_t stride, float background, int k,
                                             float *restrict out) {
    out[2 * k] = even_pixel(h, two_rows, guide_depth(z_row, stride, background, 2 * k), k);
    out[2 * k + 1] =
        odd_pixel(h, two_rows, guide_depth(z_row, stride, background, 2 * k + 1), k, k + 1, 0.5f);
}

/* One full-resolution row; candidates in the order (left, top), (right,
 * top), (left, bottom), (right, bottom). Pixel 2k sits on half column k and
 * pixel 2k + 1 between columns k and k + 1: one loop over k makes both, so
 * that the row's depths are read and its AO written as whole vectors (with
 * a loop per parity, the stride-2 stores took one instruction a pixel). A
 * candidate with bilinear weight 0 adds nothing, so even pixels skip the
 * right-hand column (and rows without a row below, see upsample_row, skip
 * the bottom candidates). */
static HBAO_ALWAYS_INLINE void upsample_rows(const hbao_grid *half, const float *half_ao,
                                             const float *z_row, int64_t stride, float background,
                                             int width, int j, int two_rows, float *restrict out) {
    const int half_width = half->width;
    const int r0 = j / 2;
    const int r1 = two_rows ? r0 + 1 : r0;
    half_rows h;
    h.top_weight = two_rows ? 0.5f : 1.0f;
    h.bottom_weight = 1.0f - h.top_weight;
    h.z_top = half->depth + (size_t)r0 * half_width;
    h.z_bottom = half->depth + (size_t)r1 * half_width;
    h.ao_top = half_ao + (size_t)r0 * half_width;
    h.ao_bottom = half_ao + (size_t)r1 * half_width;
    const int even_count = (width + 1) / 2; /* pixels 2k */
    const int odd_count = width / 2;        /* pixels 2k + 1 */
    /* odd pixels with a half column to their right; the last one may have
     * none (width even, half_width = width / 2) */
    const int pairs = odd_count < half_width - 1 ? odd_count : half_width - 1;
    int first = 0;
    while (first < pairs) {
        /* a run of sky chunks */
        while (first + SKY_CHUNK <= pairs && sky_chunk(&h, first)) {
            for (int i = 0; i < 2 * SKY_CHUNK; i++) out[2 * first + i] = 1.0f;
            first += SKY_CHUNK;
        }
        /* then one of the others (or the pairs left), made in one loop */
        int end = first + SKY_CHUNK;
        while (end + SKY_CHUNK <= pairs && !sky_chunk(&h, end)) end += SKY_CHUNK;
        end = end < pairs ? end : pairs;
        for (int k = first; k < end; k++)
            upsample_pair(&h, two_rows, z_row, stride, background, k, out);
        first = end;
    }
    for (int k = pairs; k < even_count; k++)
        out[2 * k] = even_pixel(&h, two_rows, guide_depth(z_row, stride, background, 2 * k), k);
    for (int k = pairs; k < odd_count; k++)
        out[2 * k + 1] =
            odd_pixel(&h, two_rows, guide_depth(z_row, stride, background, 2 * k + 1), k, k, 0.0f);
}

/* Rows that lie on a half-grid row (and the last odd row, which has no row
 * below) have bilinear weight 0 on the row below: a candidate of weight 0
 * adds exactly nothing, so those rows skip it. */
static HBAO_ALWAYS_INLINE void upsample_row(const hbao_grid *half, const float *half_ao,
                                            const hbao_channel *depth, float background, int width,
                                            int j, float *restrict out) {
    const float *z_row = depth->data + (int64_t)j * depth->row_stride;
    const int two_rows = (j & 1) && j / 2 + 1 < half->height;
    if (depth->pixel_stride == 1) { /* the common layout: whole vectors */
        if (two_rows)
            upsample_rows(half, half_ao, z_row, 1, background, width, j, 1, out);
        else
            upsample_rows(half, half_ao, z_row, 1, background, width, j, 0, out);
    } else if (two_rows) {
        upsample_rows(half, half_ao, z_row, depth->pixel_stride, background, width, j, 1, out);
    } else {
        upsample_rows(half, half_ao, z_row, depth->pixel_stride, background, width, j, 0, out);
    }
}

static void upsample_row_portable(const hbao_grid *half, const float *half_ao,
                                  const hbao_channel *depth, float background, int width, int j,
                                  float *out) {
    upsample_row(half, half_ao, depth, background, width, j, out);
}

#ifdef HBAO_FINISH_X86
HBAO_TARGET_AVX2 static void upsample_row_avx2(const hbao_grid *half, const float *half_ao,
                                               const hbao_channel *depth, float background,
                                               int width, int j, float *out) {
    upsample_row(half, half_ao, depth, background, width, j, out);
}

HBAO_TARGET_AVX512 static void upsample_row_avx512(const hbao_grid *half, const float *half_ao,
                                                   const hbao_channel *depth, float background,
                                                   int width, int j, float *out) {
    upsample_row(half, half_ao, depth, background, width, j, out);
}
#endif

void hbao_upsample_row(int implementation, const hbao_grid *half, const float *half_ao,
                       const hbao_channel *depth, float background, int width, int j, float *ao) {
#ifdef HBAO_FINISH_X86
    if (implementation == HBAO_IMPLEMENTATION_AVX512) {
        upsample_row_avx512(half, half_ao, depth, background, width, j, ao);
        return;
    }
    if (implementation == HBAO_IMPLEMENTATION_AVX2) {
        upsample_row_avx2(half, half_ao, depth, background, width, j, ao);
        return;
    }
#else
    (void)implementation;
#endif
    upsample_row_portable(half, half_ao, depth, background, width, j, ao);
}
