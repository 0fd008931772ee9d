/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Private declarations of the stages after the horizon search (blur.c,
 * upsample.c): the half-resolution upsample, the cross-bilateral blur, the
 * strength and the write to the caller's output, fused per band of rows. */
#ifndef HBAO_INTERNAL_FINISH_H
#define HBAO_INTERNAL_FINISH_H

/* Before internal_hbao.h, so that its inline helpers are not contracted
 * into FMAs either where the AVX-512 copies inline them: clang contracts
 * by default, GCC does not in ISO C mode. Include this header before
 * internal_hbao.h. */
#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif
#include "internal_hbao.h"

/* How strongly the blur stops where the normal turns, in units of
 * 1 - cos(angle between the two normals) (docs/algorithm.md, "After
 * sampling"): a tap on a face at 90 degrees weighs F(8) ~ 1.5e-5, at
 * 45 degrees 0.08, at 20 degrees 0.61, at 5 degrees 0.97. A crease is cut
 * off at 8 as at 16 (the fin test measures the same errors), while the
 * facets of a low-polygon curved surface (10-25 degrees apart) keep most of
 * their smoothing, so that the 4x4 sampling pattern does not show along
 * them. */
#define HBAO_BLUR_NORMAL_SHARPNESS 8.0f

/* The blur's range weight (docs/algorithm.md, "After sampling"): with
 * d = f_c (z - z_c) and the bend NS (1 - min(n.c, 1)) (NS =
 * HBAO_BLUR_NORMAL_SHARPNESS), the weight of the exponent e = d^2 + bend is
 * F(e) = (1 - e / R)^R, 0 from e = R on, with R = HBAO_BLUR_FALLOFF_REACH.
 * F follows exp(-e) where the weights matter (e = 0.5: 0.602 for 0.607,
 * e = 1: 0.356 for 0.368, e = 2: 0.118 for 0.135) and falls faster beyond,
 * to exactly 0 where exp(-e) is below 1e-7. Its base 1 - e / R is formed as
 *   (1 - NS / R + min(n.(NS / R c), NS / R)) - (d / sqrt(R))^2,
 * the centre's normal and depth factor scaled once per pixel
 * (HBAO_BLUR_NORMAL_WEIGHT, HBAO_BLUR_DEPTH_WEIGHT; both scalings are by
 * powers of 2, so exact): 22 vector operations a tap, where exp(-e) with
 * the old exponent took 38 (docs/speed.md). The GLSL preview
 * (addon/hbao/viewport/shader_sources.py, blur_power) computes the same. */
#define HBAO_BLUR_FALLOFF_REACH 16.0f
#define HBAO_BLUR_NORMAL_WEIGHT (HBAO_BLUR_NORMAL_SHARPNESS / HBAO_BLUR_FALLOFF_REACH)
#define HBAO_BLUR_DEPTH_WEIGHT 0.25f /* 1 / sqrt(HBAO_BLUR_FALLOFF_REACH) */
/* The upsample weighs a candidate's depth by the same F, of
 * (UPSAMPLE_SHARPNESS |zs - z| / z)^2: its base is 1 - scaled^2 with
 * scaled = |zs - z| (UPSAMPLE_DEPTH_WEIGHT / z), the factor once per pixel
 * (upsample.c; exp(-e) until session 22, which took the upsample a
 * division and an exponential for each of a pixel's candidates). */
#define HBAO_UPSAMPLE_DEPTH_WEIGHT (HBAO_UPSAMPLE_SHARPNESS * HBAO_BLUR_DEPTH_WEIGHT)

/* F's power: max(0, base)^R by four squarings (R = 16), 0 for NaN.
 * Branch-free (the select is an integer mask) so that loops calling it
 * vectorize. */
static inline float hbao_blur_power(float base) {
    union {
        float f;
        uint32_t u;
    } clamped;
    clamped.f = base;
    clamped.u &= 0u - (uint32_t)(base > 0.0f); /* max(0, base); NaN: 0 */
    float power = clamped.f * clamped.f;       /* ^2 */
    power *= power;                            /* ^4 */
    power *= power;                            /* ^8 */
    return power * power;                      /* ^16 */
}

/* The loops of these stages are plain C written to auto-vectorize (the
 * blur's tap loop in GCC vector types, blur_lanes.h); each is compiled three
 * times (baseline, AVX2, AVX-512) and the copy matching
 * params.implementation runs, so that the scalar column of the benchmark is
 * the portable code and the tests compare every copy. Their operations are
 * element-wise and never contracted into FMAs (ISO C mode; clang is told
 * above), so every copy computes the same floats. */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define HBAO_FINISH_X86 1
#define HBAO_TARGET_AVX2 __attribute__((target("avx2")))
#define HBAO_TARGET_AVX512 __attribute__((target("avx512f")))
#endif
#define HBAO_ALWAYS_INLINE inline __attribute__((always_inline))

/* The copy to run for a requested hbao_implementation: that of the
 * implementation that runs (hbao_implementation_that_runs), the baseline
 * copy for the scalar reference and the generic kernel (their stages are the
 * same portable code, vectorized for the baseline). */
static inline int hbao_finish_implementation(int requested) {
#ifdef HBAO_FINISH_X86
    const int runs = hbao_implementation_that_runs(requested);
    return runs == HBAO_IMPLEMENTATION_AVX2 || runs == HBAO_IMPLEMENTATION_AVX512
               ? runs
               : HBAO_IMPLEMENTATION_SCALAR;
#else
    (void)requested;
    return HBAO_IMPLEMENTATION_SCALAR;
#endif
}

/* The output's clamp to [0, 1], written so that a NaN could never pass
 * through (it gives 0). */
static inline float hbao_clamp_ao(float value) {
    return value > 0.0f ? (value < 1.0f ? value : 1.0f) : 0.0f;
}

/* blur.c: AO on the full image from the raw AO on the grid (grid_ao, dense,
 * grid->width wide): cross-bilateral blur on depth and normals (rows, then
 * columns) on the grid -> [upsample] -> strength -> clamp to [0, 1],
 * written to out. depth: the caller's depth channel, which only the half
 * resolution's upsample reads (NULL will do at full resolution).
 * HBAO_ERROR_OUT_OF_MEMORY if its buffers cannot be allocated. */
hbao_result hbao_finish(const hbao_settings *settings, const hbao_grid *grid, const float *grid_ao,
                        const hbao_channel *depth, int width, int height, float *out,
                        int64_t out_row_stride);

/* upsample.c: full-resolution row j (width floats, into ao, in [0, 1] and 1
 * on background) of the half-resolution AO half_ao (half->width wide),
 * guided by the caller's depth channel (hbao_depth_value with background).
 * implementation: as resolved by hbao_finish_implementation(). */
void hbao_upsample_row(int implementation, const hbao_grid *half, const float *half_ao,
                       const hbao_channel *depth, float background, int width, int j, float *ao);

/* The upsample's chunks of half columns: where the half grid is background
 * at a chunk's HBAO_UPSAMPLE_SKY_CHUNK + 1 columns on both of a row's half
 * rows, no pixel of the chunk has a usable sample, and it writes 1 there
 * without weighing any. 16 (32 pixels): a sky narrower than a chunk, or
 * a chunk with any geometry, is weighed as before. */
#define HBAO_UPSAMPLE_SKY_CHUNK 16

/* How many strips of columns the blur cuts a band's rows of `width`
 * pixels into at `radius` (blur.c, STRIP_BYTES_PER_PIXEL): one where the
 * 2r + 1 rows of taps fit in `budget` bytes, else as many as bring each
 * strip's within it, but no more than keep each at least 256 columns wide;
 * one without a blur (radius 0). And the budget for this machine's cores. */
int hbao_blur_strips(int width, int radius, double budget);
double hbao_blur_strip_budget(void);

#endif /* HBAO_INTERNAL_FINISH_H */
