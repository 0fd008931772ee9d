/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The horizon search, 16 pixels at a time with AVX2: horizon_simd.h
 * instantiated with pairs of AVX2 registers. Compiled with -mavx2 and only
 * called after hbao_horizon_avx2_available() said yes. */
#include "internal_hbao.h"

#if defined(__x86_64__) && defined(__AVX2__)
#include <immintrin.h>

/* A vector is a pair of AVX2 registers (lanes 0-7 and 8-15), so that a
 * block's 16 pixels are searched together, as with AVX-512: one plan, one
 * loop and one branch per step for the block, and two independent loads
 * and chains of arithmetic in flight. Every operation is done on both
 * halves, lane by lane, so the results stay bit-identical. Against the
 * block searched as two vectors of 8 lanes one after the other (which
 * shared only the steps' plan), scripts/bench_ab_pairs.sh, 1080p, Zen 3:
 * defaults 0.940 and 0.922 on 2 threads, 0.969 and 0.915 on 1; 8 x 6 + blur
 * 15 0.963 and 0.970; back faces 0.883 and 0.917; half resolution 0.989
 * and 0.930; 3840x2160 0.928 and 0.902 (two builds: this one, and the
 * first, which left horizon_simd.h's loop over a block's parts in place). */
#define SIMD_LANES 16
typedef struct pair_f {
    __m256 lo, hi;
} pair_f;
typedef struct pair_i {
    __m256i lo, hi;
} pair_i;
#define VF pair_f
#define VI pair_i
#define VM pair_f /* lanes of all ones or all zeros */

#define PAIR_F2(name, op)                                                                          \
    static inline pair_f name(pair_f a, pair_f b) {                                                \
        return (pair_f){op(a.lo, b.lo), op(a.hi, b.hi)};                                           \
    }
#define PAIR_I2(name, op)                                                                          \
    static inline pair_i name(pair_i a, pair_i b) {                                                \
        return (pair_i){op(a.lo, b.lo), op(a.hi, b.hi)};                                           \
    }
PAIR_F2(pair_add, _mm256_add_ps)
PAIR_F2(pair_sub, _mm256_sub_ps)
PAIR_F2(pair_mul, _mm256_mul_ps)
PAIR_F2(pair_div, _mm256_div_ps)
PAIR_F2(pair_and, _mm256_and_ps)
PAIR_F2(pair_or, _mm256_or_ps)
PAIR_F2(pair_andnot, _mm256_andnot_ps)
PAIR_F2(pair_min, _mm256_min_ps)
PAIR_I2(pair_iadd, _mm256_add_epi32)
PAIR_I2(pair_isub, _mm256_sub_epi32)
PAIR_I2(pair_imullo, _mm256_mullo_epi32)
PAIR_I2(pair_iand, _mm256_and_si256)
PAIR_I2(pair_ior, _mm256_or_si256)
PAIR_I2(pair_iandnot, _mm256_andnot_si256)
PAIR_I2(pair_isllv, _mm256_sllv_epi32)
/* one-argument operations: out_type name(in_type), on both halves; HALF_*:
 * an operation on one register, a half */
#define PAIR_1(name, out_type, in_type, op)                                                        \
    static inline out_type name(in_type a) {                                                       \
        return (out_type){op(a.lo), op(a.hi)};                                                     \
    }
#define HALF_CMP_GT(a, b) _mm256_cmp_ps((a), (b), _CMP_GT_OQ)
#define HALF_CMP_GE(a, b) _mm256_cmp_ps((a), (b), _CMP_GE_OQ)
#define HALF_CMP_LT(a, b) _mm256_cmp_ps((a), (b), _CMP_LT_OQ)
#define HALF_CMP_LE(a, b) _mm256_cmp_ps((a), (b), _CMP_LE_OQ)
PAIR_F2(pair_gt, HALF_CMP_GT)
PAIR_F2(pair_ge, HALF_CMP_GE)
PAIR_F2(pair_lt, HALF_CMP_LT)
PAIR_F2(pair_le, HALF_CMP_LE)
#define HALF_NEG(a) _mm256_xor_ps((a), _mm256_set1_ps(-0.0f))
#define HALF_ABS(a) _mm256_andnot_ps(_mm256_set1_ps(-0.0f), (a))
#define HALF_MAX0(a) _mm256_max_ps((a), _mm256_setzero_ps()) /* NaN -> 0, like fmaxf(0, a) */
#define HALF_FLOOR(a) _mm256_round_ps((a), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)
#define HALF_CEIL(a) _mm256_round_ps((a), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)
PAIR_1(pair_sqrt, pair_f, pair_f, _mm256_sqrt_ps)
PAIR_1(pair_neg, pair_f, pair_f, HALF_NEG)
PAIR_1(pair_abs, pair_f, pair_f, HALF_ABS)
PAIR_1(pair_max0, pair_f, pair_f, HALF_MAX0)
PAIR_1(pair_floor, pair_f, pair_f, HALF_FLOOR)
PAIR_1(pair_ceil, pair_f, pair_f, HALF_CEIL)
PAIR_1(pair_itof, pair_f, pair_i, _mm256_cvtepi32_ps)
PAIR_1(pair_cvtt, pair_i, pair_f, _mm256_cvttps_epi32)
static inline pair_f pair_set(float x) {
    const __m256 v = _mm256_set1_ps(x);
    return (pair_f){v, v};
}
static inline pair_i pair_iset(int x) {
    const __m256i v = _mm256_set1_epi32(x);
    return (pair_i){v, v};
}
static inline pair_f pair_loadu(const float *p) {
    return (pair_f){_mm256_loadu_ps(p), _mm256_loadu_ps(p + 8)};
}
static inline void pair_storeu(float *p, pair_f a) {
    _mm256_storeu_ps(p, a.lo);
    _mm256_storeu_ps(p + 8, a.hi);
}
static inline void pair_istoreu(int *p, pair_i a) {
    _mm256_storeu_si256((__m256i *)p, a.lo);
    _mm256_storeu_si256((__m256i *)(p + 8), a.hi);
}
static inline int pair_bits(pair_f m) {
    return _mm256_movemask_ps(m.lo) | _mm256_movemask_ps(m.hi) << 8;
}
static inline int pair_any(pair_f m) {
    return !_mm256_testz_ps(_mm256_or_ps(m.lo, m.hi), _mm256_or_ps(m.lo, m.hi));
}
static inline pair_f pair_select(pair_f m, pair_f a, pair_f b) {
    return (pair_f){_mm256_blendv_ps(a.lo, b.lo, m.lo), _mm256_blendv_ps(a.hi, b.hi, m.hi)};
}
/* the least lane (no NaN lane) */
static inline float pair_least(pair_f a) {
    __m256 m = _mm256_min_ps(a.lo, a.hi);
    m = _mm256_min_ps(m, _mm256_permute2f128_ps(m, m, 1));
    m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
    m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
    return _mm256_cvtss_f32(m);
}
static inline pair_f pair_set_halves(float a, float b) {
    return (pair_f){_mm256_set1_ps(a), _mm256_set1_ps(b)};
}
static inline void pair_store_halves(float *p, float *q, pair_f a) {
    _mm256_storeu_ps(p, a.lo);
    _mm256_storeu_ps(q, a.hi);
}
static inline void pair_istore_halves(int *p, int *q, pair_i a) {
    _mm256_storeu_si256((__m256i *)p, a.lo);
    _mm256_storeu_si256((__m256i *)q, a.hi);
}
static inline pair_i pair_lanes(void) {
    return (pair_i){_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
                    _mm256_setr_epi32(8, 9, 10, 11, 12, 13, 14, 15)};
}
#define PAIR_SHIFT(name, op)                                                                       \
    static inline pair_i name(pair_i a, const int n) {                                             \
        return (pair_i){op(a.lo, n), op(a.hi, n)};                                                 \
    }
PAIR_SHIFT(pair_srli, _mm256_srli_epi32)
PAIR_SHIFT(pair_srai, _mm256_srai_epi32)
static inline pair_i pair_izero_unless(pair_f m, pair_i v) {
    return (pair_i){_mm256_castps_si256(_mm256_and_ps(m.lo, _mm256_castsi256_ps(v.lo))),
                    _mm256_castps_si256(_mm256_and_ps(m.hi, _mm256_castsi256_ps(v.hi)))};
}
/* m ? p[k] : fill[k]; lanes outside m are not read */
static inline pair_f pair_load_lanes(pair_f m, const float *p, pair_f fill) {
    return (pair_f){
        _mm256_blendv_ps(fill.lo, _mm256_maskload_ps(p, _mm256_castps_si256(m.lo)), m.lo),
        _mm256_blendv_ps(fill.hi, _mm256_maskload_ps(p + 8, _mm256_castps_si256(m.hi)), m.hi)};
}

#define V_ADD pair_add
#define V_SUB pair_sub
#define V_MUL pair_mul
#define V_DIV pair_div
#define V_SQRT pair_sqrt
#define V_SET pair_set
#define V_LOADU pair_loadu
#define V_STOREU pair_storeu
#define V_NEG pair_neg
#define V_ABS pair_abs
#define V_MAX0 pair_max0
#define V_GT pair_gt
#define V_GE pair_ge
#define V_LT pair_lt
#define V_LE pair_le
#define M_AND pair_and
#define M_OR pair_or
#define M_ANDNOT pair_andnot
#define M_ANY pair_any
#define M_NONE() pair_set(0.0f)
#define V_SELECT pair_select
#define V_ZERO_UNLESS pair_and
#define I_SET pair_iset
#define I_ADD pair_iadd
#define I_MULLO pair_imullo
#define I_LANES pair_lanes()
#define I_TO_F pair_itof
#define V_CVTT pair_cvtt
#define I_STOREU(p, v) pair_istoreu((int *)(p), (v))
#define M_BITS pair_bits
#define V_MIN pair_min
#define V_LEAST pair_least
#define V_SET_HALVES pair_set_halves
#define V_STORE_HALVES pair_store_halves
#define I_STORE_HALVES pair_istore_halves
#define V_CEIL pair_ceil
#define V_FLOOR pair_floor
#define I_SUB pair_isub
#define I_AND pair_iand
#define I_OR pair_ior
#define I_ANDNOT pair_iandnot
#define I_SLLV pair_isllv
#define I_SRLI pair_srli
#define I_SRAI pair_srai
#define I_ZERO_UNLESS pair_izero_unless
#define V_LOAD_LANES pair_load_lanes

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
static inline pair_f load_every_fourth_pair(const float *p) {
    return (pair_f){load_every_fourth_avx2(p), load_every_fourth_avx2(p + 32)};
}
#define V_LOAD_EVERY_FOURTH load_every_fourth_pair

#define SIMD_PREFETCH_STEPS 1
#define SIMD_PAIRED_DIRECTIONS 16
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
    hbao_horizon_span_reference(job, x0, x1, j);
}

#endif
