/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The horizon search, 16 pixels at a time in the compiler's generic vector
 * types: horizon_simd.h instantiated for any CPU. It is compiled with the
 * library's own flags, for the baseline of the target (SSE2 on x86-64,
 * Advanced SIMD on ARM64), so it is the search of the CPUs that have no
 * AVX2 (older x86 farm nodes) and of every other architecture, where the
 * scalar reference used to run. Every operation is the reference's, lane by
 * lane and never contracted into an FMA (-ffp-contract=off), so it gives
 * the same floats to the bit (the tests hold it to the reference beside the
 * other kernels, test_ao.c and test_planes.c; on ARM64 as well, under qemu:
 * scripts/test_arm64.sh, whose --all runs every test). bench_speed, 1080p defaults, 1 thread, on an
 * Intel Xeon (SSE2 code): 197 ms against the reference's 2174 (AVX2 97,
 * AVX-512 74); 4K 807 against 9473 (session 54). */
#include <float.h>

#include "internal_hbao.h"

/* GCC's vector types with __builtin_convertvector (GCC 9 on, clang), and
 * floats evaluated in their own precision, as the scalar reference's are
 * (not so with x87 arithmetic, 32-bit x86's default) */
#if (defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 9)) && FLT_EVAL_METHOD == 0
#include <math.h>
#include <string.h>

#define SIMD_LANES 16
/* A vector is four of the target's 128-bit vectors (lanes 0-3, 4-7, 8-11
 * and 12-15), as AVX2's is a pair of registers: where the target's vectors
 * are narrower, GCC lowers a comparison of a 64-byte vector type to a
 * compare and a conditional move per lane (and a 16-byte one to one
 * instruction). Every operation is done on each quarter, lane by lane. */
typedef float f4 __attribute__((vector_size(16)));
typedef int32_t i4 __attribute__((vector_size(16)));
typedef uint32_t u4 __attribute__((vector_size(16)));
typedef struct quad_f {
    f4 a, b, c, d;
} quad_f;
typedef struct quad_i {
    i4 a, b, c, d;
} quad_i;
#define VF quad_f
#define VI quad_i
#define VM quad_i /* lanes of all ones or all zeros */
#define GENERIC static inline __attribute__((always_inline))

/* out_type name(in_type x[, in_type y]): op on each quarter */
#define QUAD_1(name, out_type, in_type, op)                                                        \
    GENERIC out_type name(in_type x) {                                                             \
        return (out_type){op(x.a), op(x.b), op(x.c), op(x.d)};                                     \
    }
#define QUAD_2(name, out_type, in_type, op)                                                        \
    GENERIC out_type name(in_type x, in_type y) {                                                  \
        return (out_type){op(x.a, y.a), op(x.b, y.b), op(x.c, y.c), op(x.d, y.d)};                 \
    }

/* the quarters' operations */
#define ADD(u, v) ((u) + (v))
#define SUB(u, v) ((u) - (v))
#define MUL(u, v) ((u) * (v))
#define DIV(u, v) ((u) / (v))
#define GT(u, v) ((u) > (v))
#define GE(u, v) ((u) >= (v))
#define LT(u, v) ((u) < (v))
#define LE(u, v) ((u) <= (v))
#define AND(u, v) ((u) & (v))
#define OR(u, v) ((u) | (v))
#define ANDNOT(u, v) (~(u) & (v))
/* integer products and differences wrap, as the x86 kernels' */
#define IMUL(u, v) ((i4)((u4)(u) * (u4)(v)))
#define ISUB(u, v) ((i4)((u4)(u) - (u4)(v)))
#define IADD(u, v) ((i4)((u4)(u) + (u4)(v)))
#define NEG(u) ((f4)((i4)(u) ^ (int32_t)0x80000000u))
#define ABS(u) ((f4)((i4)(u)&0x7fffffff))
#define MAX0(u) ((f4)((i4)(u) & ((u) > 0.0f))) /* NaN -> 0, like fmaxf(0, u) */
#define ITOF(u) __builtin_convertvector((u), f4)
/* a << b, 0 where b is 32 or more (as AVX2's vpsllvd) */
#define SLLV(u, v) ((i4)((u4)(u) << ((u4)(v)&31u)) & (i4)((u4)(v) < 32u))
/* m ? v : u and m ? v : 0 on masks of all ones or zeros */
#define SELECT4(m, u, v) ((f4)(((m) & (i4)(v)) | (~(m) & (i4)(u))))
#define ZERO_UNLESS4(m, v) ((f4)((m) & (i4)(v)))
/* a < b ? a : b (b where either is NaN), as x86's min */
#define MIN(u, v) SELECT4((u) < (v), (v), (u))
#if defined(__SSE2__)
#include <emmintrin.h>
#define SQRT(u) ((f4)_mm_sqrt_ps((__m128)(u)))
#elif defined(__aarch64__) && defined(__ARM_NEON)
#include <arm_neon.h>
#define SQRT(u) ((f4)vsqrtq_f32((float32x4_t)(u)))
#else
GENERIC f4 sqrt4(f4 u) {
    return (f4){sqrtf(u[0]), sqrtf(u[1]), sqrtf(u[2]), sqrtf(u[3])};
}
#define SQRT sqrt4
#endif
/* x86's truncating conversion, INT32_MIN where it overflows or for NaN:
 * lanes with |u| >= 2^23 (a whole float) give INT32_MIN, the others the
 * conversion (of 0 in the former, never out of range, undefined in C).
 * The search's uses are small whole numbers in range, but a step's offset
 * can be huge or NaN where the steps leave the image far behind; the
 * template reads no such lane (plan_steps stops the count before it), and
 * it gets x86's value all the same. */
#define EXACT 8388608.0f /* 2^23: from here on every float is whole */
#if defined(__SSE2__)
#define CVTT(u) ((i4)_mm_cvttps_epi32((__m128)(u))) /* itself: 0.98 of the time of the below */
#else
#define CVTT(u)                                                                                    \
    ((__builtin_convertvector(ZERO_UNLESS4(ABS(u) < EXACT, (u)), i4) & (ABS(u) < EXACT)) |         \
     (~(ABS(u) < EXACT) & INT32_MIN))
#endif
/* floor and ceil, exact: truncated and corrected below 2^23, the float
 * itself from there (and for NaN). The sign of a zero may differ from
 * floorf's, which no use sees (each is converted to an integer). */
GENERIC f4 floor4(f4 u) {
    const f4 t = ITOF(CVTT(u)), one = {1.0f, 1.0f, 1.0f, 1.0f};
    return SELECT4(ABS(u) < EXACT, u, t - ZERO_UNLESS4(t > u, one));
}
GENERIC f4 ceil4(f4 u) {
    const f4 t = ITOF(CVTT(u)), one = {1.0f, 1.0f, 1.0f, 1.0f};
    return SELECT4(ABS(u) < EXACT, u, t + ZERO_UNLESS4(t < u, one));
}

QUAD_2(quad_add, quad_f, quad_f, ADD)
QUAD_2(quad_sub, quad_f, quad_f, SUB)
QUAD_2(quad_mul, quad_f, quad_f, MUL)
QUAD_2(quad_div, quad_f, quad_f, DIV)
QUAD_2(quad_min, quad_f, quad_f, MIN)
QUAD_2(quad_gt, quad_i, quad_f, GT)
QUAD_2(quad_ge, quad_i, quad_f, GE)
QUAD_2(quad_lt, quad_i, quad_f, LT)
QUAD_2(quad_le, quad_i, quad_f, LE)
QUAD_2(quad_and, quad_i, quad_i, AND)
QUAD_2(quad_or, quad_i, quad_i, OR)
QUAD_2(quad_andnot, quad_i, quad_i, ANDNOT)
QUAD_2(quad_iadd, quad_i, quad_i, IADD)
QUAD_2(quad_isub, quad_i, quad_i, ISUB)
QUAD_2(quad_imullo, quad_i, quad_i, IMUL)
QUAD_2(quad_isllv, quad_i, quad_i, SLLV)
QUAD_1(quad_sqrt, quad_f, quad_f, SQRT)
QUAD_1(quad_neg, quad_f, quad_f, NEG)
QUAD_1(quad_abs, quad_f, quad_f, ABS)
QUAD_1(quad_max0, quad_f, quad_f, MAX0)
QUAD_1(quad_floor, quad_f, quad_f, floor4)
QUAD_1(quad_ceil, quad_f, quad_f, ceil4)
QUAD_1(quad_itof, quad_f, quad_i, ITOF)
QUAD_1(quad_cvtt, quad_i, quad_f, CVTT)

GENERIC quad_f quad_set(float x) {
    const f4 v = {x, x, x, x};
    return (quad_f){v, v, v, v};
}
GENERIC quad_i quad_iset(int32_t x) {
    const i4 v = {x, x, x, x};
    return (quad_i){v, v, v, v};
}
/* m ? b : a */
GENERIC quad_f quad_select(quad_i m, quad_f a, quad_f b) {
    return (quad_f){SELECT4(m.a, a.a, b.a), SELECT4(m.b, a.b, b.b), SELECT4(m.c, a.c, b.c),
                    SELECT4(m.d, a.d, b.d)};
}
GENERIC quad_f quad_zero_unless(quad_i m, quad_f v) {
    return (quad_f){ZERO_UNLESS4(m.a, v.a), ZERO_UNLESS4(m.b, v.b), ZERO_UNLESS4(m.c, v.c),
                    ZERO_UNLESS4(m.d, v.d)};
}
#define QUAD_SHIFT(name, type, op)                                                                 \
    GENERIC quad_i name(quad_i x, int n) {                                                         \
        return (quad_i){(i4)((type)x.a op n), (i4)((type)x.b op n), (i4)((type)x.c op n),          \
                        (i4)((type)x.d op n)};                                                     \
    }
QUAD_SHIFT(quad_srli, u4, >>)
QUAD_SHIFT(quad_srai, i4, >>)

/* Lane by lane, through memory: the loads and stores, and what crosses the
 * quarters */
GENERIC quad_f quad_loadu(const float *p) {
    quad_f v;
    memcpy(&v, p, sizeof v);
    return v;
}
GENERIC void quad_storeu(float *p, quad_f v) {
    memcpy(p, &v, sizeof v);
}
GENERIC void quad_istoreu(void *p, quad_i v) {
    memcpy(p, &v, sizeof v);
}
GENERIC quad_i quad_lanes(void) {
    return (quad_i){{0, 1, 2, 3}, {4, 5, 6, 7}, {8, 9, 10, 11}, {12, 13, 14, 15}};
}
GENERIC quad_f quad_set_halves(float x, float y) {
    const f4 u = {x, x, x, x}, v = {y, y, y, y};
    return (quad_f){u, u, v, v};
}
GENERIC void quad_store_halves(float *p, float *q, quad_f v) {
    memcpy(p, &v.a, sizeof v.a);
    memcpy(p + 4, &v.b, sizeof v.b);
    memcpy(q, &v.c, sizeof v.c);
    memcpy(q + 4, &v.d, sizeof v.d);
}
GENERIC void quad_istore_halves(int *p, int *q, quad_i v) {
    memcpy(p, &v.a, sizeof v.a);
    memcpy(p + 4, &v.b, sizeof v.b);
    memcpy(q, &v.c, sizeof v.c);
    memcpy(q + 4, &v.d, sizeof v.d);
}
/* whether any lane is set, and lane k -> bit k */
GENERIC int quad_any(quad_i m) {
    const i4 any = m.a | m.b | m.c | m.d;
#if defined(__SSE2__)
    return _mm_movemask_ps((__m128)any) != 0;
#else
    return (any[0] | any[1] | any[2] | any[3]) != 0;
#endif
}
GENERIC int quad_bits(quad_i m) {
#if defined(__SSE2__)
    return _mm_movemask_ps((__m128)m.a) | _mm_movemask_ps((__m128)m.b) << 4 |
           _mm_movemask_ps((__m128)m.c) << 8 | _mm_movemask_ps((__m128)m.d) << 12;
#else
    const i4 weights = {1, 2, 4, 8};
    const i4 sum =
        (m.a & weights) | (m.b & (weights << 4)) | (m.c & (weights << 8)) | (m.d & (weights << 12));
    return sum[0] | sum[1] | sum[2] | sum[3];
#endif
}
/* the least lane (no NaN lane) */
GENERIC float quad_least(quad_f v) {
    const f4 m = MIN(MIN(v.a, v.b), MIN(v.c, v.d));
    const float low = m[0] < m[1] ? m[0] : m[1], high = m[2] < m[3] ? m[2] : m[3];
    return low < high ? low : high;
}
/* m ? p[k] : fill[k]; lanes outside m are not read */
GENERIC quad_f quad_load_lanes(quad_i m, const float *p, quad_f fill) {
    float lanes[SIMD_LANES];
    int32_t read[SIMD_LANES];
    memcpy(lanes, &fill, sizeof lanes);
    memcpy(read, &m, sizeof read);
    for (int k = 0; k < SIMD_LANES; k++)
        if (read[k]) lanes[k] = p[k];
    return quad_loadu(lanes);
}
/* p[0], p[4], ..., p[60] */
GENERIC quad_f quad_load_every_fourth(const float *p) {
    return (quad_f){{p[0], p[4], p[8], p[12]},
                    {p[16], p[20], p[24], p[28]},
                    {p[32], p[36], p[40], p[44]},
                    {p[48], p[52], p[56], p[60]}};
}

#define V_ADD quad_add
#define V_SUB quad_sub
#define V_MUL quad_mul
#define V_DIV quad_div
#define V_SQRT quad_sqrt
#define V_SET quad_set
#define V_LOADU quad_loadu
#define V_STOREU quad_storeu
#define V_NEG quad_neg
#define V_ABS quad_abs
#define V_MAX0 quad_max0
#define V_GT quad_gt
#define V_GE quad_ge
#define V_LT quad_lt
#define V_LE quad_le
#define M_AND quad_and
#define M_OR quad_or
#define M_ANDNOT quad_andnot
#define M_ANY quad_any
#define M_NONE() quad_iset(0)
#define V_SELECT quad_select
#define V_ZERO_UNLESS quad_zero_unless
#define I_SET quad_iset
#define I_ADD quad_iadd
#define I_MULLO quad_imullo
#define I_LANES quad_lanes()
#define I_TO_F quad_itof
#define V_CVTT quad_cvtt
#define I_STOREU quad_istoreu
#define M_BITS quad_bits
#define V_MIN quad_min
#define V_LEAST quad_least
#define V_SET_HALVES quad_set_halves
#define V_STORE_HALVES quad_store_halves
#define I_STORE_HALVES quad_istore_halves
#define V_CEIL quad_ceil
#define V_FLOOR quad_floor
#define I_SUB quad_isub
#define I_AND quad_and
#define I_OR quad_or
#define I_ANDNOT quad_andnot
#define I_SLLV quad_isllv
#define I_SRLI quad_srli
#define I_SRAI quad_srai
#define I_ZERO_UNLESS(m, v) quad_and((m), (v))
#define V_LOAD_LANES quad_load_lanes
#define V_LOAD_EVERY_FOURTH quad_load_every_fourth

#define SIMD_PREFETCH(p) __builtin_prefetch(p)
#define SIMD_PREFETCH_STEPS 1
#define SIMD_PAIRED_DIRECTIONS 16
#define SIMD_ORTHOGRAPHIC 0
#define SIMD_NAME(name) name##_generic
#include "horizon_simd.h"
#undef SIMD_ORTHOGRAPHIC
#undef SIMD_NAME
#define SIMD_ORTHOGRAPHIC 1
#define SIMD_NAME(name) name##_generic_orthographic
#include "horizon_simd.h"

int hbao_horizon_generic_available(void) {
    return 1;
}

void hbao_horizon_span_generic(const hbao_horizon_job *job, int x0, int x1, int j) {
    if (job->grid->orthographic)
        span_generic_orthographic(job, x0, x1, j);
    else
        span_generic(job, x0, x1, j);
}

#else /* without GCC's vector types, or with excess precision: never chosen */

int hbao_horizon_generic_available(void) {
    return 0;
}

void hbao_horizon_span_generic(const hbao_horizon_job *job, int x0, int x1, int j) {
    hbao_horizon_span_reference(job, x0, x1, j);
}

#endif
