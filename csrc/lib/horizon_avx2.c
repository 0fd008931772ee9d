/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The horizon search, 8 pixels at a time with AVX2: horizon_simd.h
 * instantiated with AVX2's vectors. Compiled with -mavx2 and only called
 * after hbao_horizon_avx2_available() said yes. */
#include "internal_hbao.h"

#if defined(__x86_64__) && defined(__AVX2__)
#include <immintrin.h>

#define SIMD_LANES 8
#define VF __m256
#define VI __m256i
#define VM __m256 /* lanes of all ones or all zeros */
#define V_ADD _mm256_add_ps
#define V_SUB _mm256_sub_ps
#define V_MUL _mm256_mul_ps
#define V_DIV _mm256_div_ps
#define V_SQRT _mm256_sqrt_ps
#define V_SET _mm256_set1_ps
#define V_LOADU _mm256_loadu_ps
#define V_STOREU _mm256_storeu_ps
#define V_NEG(a) _mm256_xor_ps((a), _mm256_set1_ps(-0.0f))
#define V_ABS(a) _mm256_andnot_ps(_mm256_set1_ps(-0.0f), (a))
#define V_MAX0(a) _mm256_max_ps((a), _mm256_setzero_ps()) /* NaN -> 0, like fmaxf(0, a) */
#define V_GT(a, b) _mm256_cmp_ps((a), (b), _CMP_GT_OQ)
#define V_GE(a, b) _mm256_cmp_ps((a), (b), _CMP_GE_OQ)
#define V_LT(a, b) _mm256_cmp_ps((a), (b), _CMP_LT_OQ)
#define V_LE(a, b) _mm256_cmp_ps((a), (b), _CMP_LE_OQ)
#define M_AND _mm256_and_ps
#define M_OR _mm256_or_ps
#define M_ANDNOT(a, b) _mm256_andnot_ps((a), (b))
#define M_ANY(m) (_mm256_movemask_ps(m) != 0)
#define M_NONE() _mm256_setzero_ps()
#define V_SELECT(m, a, b) _mm256_blendv_ps((a), (b), (m))
#define V_ZERO_UNLESS(m, v) _mm256_and_ps((m), (v))
#define I_SET _mm256_set1_epi32
#define I_ADD _mm256_add_epi32
#define I_MULLO _mm256_mullo_epi32
#define I_LANES _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)
#define I_TO_F _mm256_cvtepi32_ps

#define V_CVTT _mm256_cvttps_epi32
#define I_STOREU(p, v) _mm256_storeu_si256((__m256i *)(p), (v))
#define M_BITS(m) _mm256_movemask_ps(m)

#define V_MIN _mm256_min_ps
#define V_CEIL(a) _mm256_round_ps((a), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)
#define V_FLOOR(a) _mm256_round_ps((a), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)
#define I_SUB _mm256_sub_epi32
#define I_AND _mm256_and_si256
#define I_OR _mm256_or_si256
#define I_ANDNOT _mm256_andnot_si256
#define I_SLLV _mm256_sllv_epi32
#define I_SRLI _mm256_srli_epi32
#define I_SRAI _mm256_srai_epi32
#define I_ZERO_UNLESS(m, v) _mm256_castps_si256(_mm256_and_ps((m), _mm256_castsi256_ps(v)))
/* m ? p[k] : fill[k]; lanes outside m are not read */
#define V_LOAD_LANES(m, p, fill)                                                                   \
    _mm256_blendv_ps((fill), _mm256_maskload_ps((p), _mm256_castps_si256(m)), (m))

/* p[0], p[4], ..., p[28]: four loads and three shuffles */
static inline __m256 load_every_fourth_avx2(const float *p) {
    /* per 128-bit half: v0[0], v0[0], v1[0], v1[0] (then the same of [4]) */
    const __m256 v01 =
        _mm256_shuffle_ps(_mm256_loadu_ps(p), _mm256_loadu_ps(p + 8), _MM_SHUFFLE(0, 0, 0, 0));
    const __m256 v23 = _mm256_shuffle_ps(_mm256_loadu_ps(p + 16), _mm256_loadu_ps(p + 24),
                                         _MM_SHUFFLE(0, 0, 0, 0));
    /* p[0], p[8], p[16], p[24], p[4], p[12], p[20], p[28] */
    const __m256 mixed = _mm256_shuffle_ps(v01, v23, _MM_SHUFFLE(2, 0, 2, 0));
    return _mm256_permutevar8x32_ps(mixed, _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7));
}
#define V_LOAD_EVERY_FOURTH load_every_fourth_avx2

#define SIMD_PREFETCH_STEPS 1
#define SIMD_ORTHOGRAPHIC 0
#define SIMD_NAME(name) name##_avx2
#include "horizon_simd.h"
#undef SIMD_ORTHOGRAPHIC
#undef SIMD_NAME
#define SIMD_ORTHOGRAPHIC 1
#define SIMD_NAME(name) name##_avx2_orthographic
#include "horizon_simd.h"

int hbao_horizon_avx2_available(void) {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
}

void hbao_horizon_span_avx2(const hbao_horizon_job *job, int x0, int x1, int j) {
    if (job->grid->orthographic)
        span_avx2_orthographic(job, x0, x1, j);
    else
        span_avx2(job, x0, x1, j);
}

#else /* not built for x86-64: never chosen */

int hbao_horizon_avx2_available(void) {
    return 0;
}

void hbao_horizon_span_avx2(const hbao_horizon_job *job, int x0, int x1, int j) {
    float *out = job->ao + (size_t)j * job->grid->width;
    for (int a = 0; a < 4; a++) {
        const float step_px = hbao_block_step(job, x0, x1, j, a);
        for (int i = x0 + a; i < x1; i += 4) out[i] = hbao_horizon_pixel(job, i, j, step_px);
    }
}

#endif
