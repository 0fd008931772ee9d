/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The horizon search, 16 pixels at a time with AVX-512F: horizon_simd.h
 * instantiated with 512-bit vectors and mask registers. Compiled with
 * -mavx512f and only called after hbao_horizon_avx512_available() said yes. */
#include "internal_hbao.h"

#if defined(__x86_64__) && defined(__AVX512F__)
#include <immintrin.h>

#define SIMD_LANES 16
#define VF __m512
#define VI __m512i
#define VM __mmask16
#define V_ADD _mm512_add_ps
#define V_SUB _mm512_sub_ps
#define V_MUL _mm512_mul_ps
#define V_DIV _mm512_div_ps
#define V_SQRT _mm512_sqrt_ps
#define V_SET _mm512_set1_ps
#define V_LOADU _mm512_loadu_ps
#define V_STOREU _mm512_storeu_ps
#define V_NEG(a)                                                                                   \
    _mm512_castsi512_ps(                                                                           \
        _mm512_xor_si512(_mm512_castps_si512(a), _mm512_set1_epi32((int)0x80000000u)))
#define V_ABS(a)                                                                                   \
    _mm512_castsi512_ps(_mm512_and_si512(_mm512_castps_si512(a), _mm512_set1_epi32(0x7fffffff)))
#define V_MAX0(a) _mm512_max_ps((a), _mm512_setzero_ps()) /* NaN -> 0, like fmaxf(0, a) */
#define V_GT(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_GT_OQ)
#define V_GE(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_GE_OQ)
#define V_LT(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_LT_OQ)
#define V_LE(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_LE_OQ)
#define M_AND(a, b) ((__mmask16)((a) & (b)))
#define M_OR(a, b) ((__mmask16)((a) | (b)))
#define M_ANDNOT(a, b) ((__mmask16)(~(a) & (b)))
#define M_ANY(m) ((m) != 0)
#define M_NONE() ((__mmask16)0)
#define V_SELECT(m, a, b) _mm512_mask_blend_ps((m), (a), (b))
#define V_ZERO_UNLESS(m, v) _mm512_maskz_mov_ps((m), (v))
#define I_SET _mm512_set1_epi32
#define I_ADD _mm512_add_epi32
#define I_MULLO _mm512_mullo_epi32
#define I_LANES _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15)
#define I_TO_F _mm512_cvtepi32_ps

#define V_CVTT _mm512_cvttps_epi32
#define I_STOREU(p, v) _mm512_storeu_si512((void *)(p), (v))
#define M_BITS(m) ((int)(m))

#define V_MIN _mm512_min_ps
/* lanes 0-7 a, lanes 8-15 b; the low and the high 8 lanes stored to p and q */
#define V_SET_HALVES(a, b) _mm512_mask_blend_ps(0xff00, _mm512_set1_ps(a), _mm512_set1_ps(b))
static inline void store_halves_avx512(float *p, float *q, __m512 v) {
    _mm256_storeu_ps(p, _mm512_castps512_ps256(v));
    _mm256_storeu_ps(q, _mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(v), 1)));
}
static inline void istore_halves_avx512(int *p, int *q, __m512i v) {
    _mm256_storeu_si256((__m256i *)p, _mm512_castsi512_si256(v));
    _mm256_storeu_si256((__m256i *)q, _mm512_extracti64x4_epi64(v, 1));
}
#define V_STORE_HALVES store_halves_avx512
#define I_STORE_HALVES istore_halves_avx512
#define V_LEAST _mm512_reduce_min_ps /* the least lane (no NaN lane) */
#define V_CEIL(a) _mm512_roundscale_ps((a), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)
#define V_FLOOR(a) _mm512_roundscale_ps((a), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)
#define I_SUB _mm512_sub_epi32
#define I_AND _mm512_and_si512
#define I_OR _mm512_or_si512
#define I_ANDNOT _mm512_andnot_si512
#define I_SLLV _mm512_sllv_epi32
#define I_SRLI _mm512_srli_epi32
#define I_SRAI _mm512_srai_epi32
#define I_ZERO_UNLESS(m, v) _mm512_maskz_mov_epi32((m), (v))
/* m ? p[k] : fill[k]; lanes outside m are not read */
#define V_LOAD_LANES(m, p, fill) _mm512_mask_loadu_ps((fill), (m), (p))

/* p[0], p[4], ..., p[60]: four loads and three shuffles */
static inline __m512 load_every_fourth_avx512(const float *p) {
    const __m512i every_fourth =
        _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 0, 4, 8, 12, 16, 20, 24, 28);
    const __m512 low = _mm512_permutex2var_ps(_mm512_loadu_ps(p), every_fourth,
                                              _mm512_loadu_ps(p + 16)); /* p[0..28] twice */
    const __m512 high = _mm512_permutex2var_ps(_mm512_loadu_ps(p + 32), every_fourth,
                                               _mm512_loadu_ps(p + 48)); /* p[32..60] twice */
    return _mm512_shuffle_f32x4(low, high, _MM_SHUFFLE(1, 0, 1, 0));
}
#define V_LOAD_EVERY_FOURTH load_every_fourth_avx512

#define SIMD_PREFETCH_STEPS 1
#define SIMD_PAIRED_DIRECTIONS 16
#define SIMD_ORTHOGRAPHIC 0
#define SIMD_NAME(name) name##_avx512
#include "horizon_simd.h"
#undef SIMD_ORTHOGRAPHIC
#undef SIMD_NAME
#define SIMD_ORTHOGRAPHIC 1
#define SIMD_NAME(name) name##_avx512_orthographic
#include "horizon_simd.h"

int hbao_horizon_avx512_available(void) {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") != 0;
}

void hbao_horizon_span_avx512(const hbao_horizon_job *job, int x0, int x1, int j) {
    if (job->grid->orthographic)
        span_avx512_orthographic(job, x0, x1, j);
    else
        span_avx512(job, x0, x1, j);
}

#else /* not built for x86-64: never chosen */

int hbao_horizon_avx512_available(void) {
    return 0;
}

void hbao_horizon_span_avx512(const hbao_horizon_job *job, int x0, int x1, int j) {
    hbao_horizon_span_reference(job, x0, x1, j);
}

#endif
