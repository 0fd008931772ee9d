/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The horizon search on SIMD_LANES neighbouring pixels at once, written once
 * for every instruction set: a file that includes this header first defines
 * the vector vocabulary below (horizon_avx2.c, horizon_avx512.c,
 * horizon_generic.c). The kernel
 * performs the same float operations in the same order as the scalar
 * reference in horizon.c (no FMA contraction), so every instance gives
 * bit-identical results (tested in test_ao.c and test_planes.c); where the
 * scalar code leaves a loop with break or continue, lanes are masked instead.
 *
 * Vocabulary: VF float vector, VI int32 vector, VM lane mask;
 * V_ADD V_SUB V_MUL V_DIV V_SQRT V_SET V_LOADU V_STOREU V_NEG V_ABS V_MAX0 (max
 * with 0, NaN -> 0); comparisons V_GT V_GE V_LT V_LE -> VM; masks M_AND M_OR
 * M_ANDNOT(a, b) = ~a & b, M_ANY, M_NONE() (no lane); V_SELECT(m, a, b) = m ? b : a;
 * V_ZERO_UNLESS(m, v); I_SET I_ADD I_MULLO I_LANES (0, 1, ...) I_TO_F; V_CVTT
 * (truncating float -> int32); V_FLOOR; I_STOREU; M_BITS(m) (lane k -> bit k);
 * V_LEAST(v): the least lane, where no lane is NaN; V_SET_HALVES(a, b) (a in
 * the low half of the lanes, b in the high), V_STORE_HALVES(p, q, v) and
 * I_STORE_HALVES (the low half of the lanes to p, the high to q);
 * for the back layer's sector masks: V_MIN V_CEIL, I_SUB I_AND I_OR
 * I_ANDNOT(a, b) = ~a & b, I_SLLV (per-lane shift, 0 from 32 on) I_SRLI,
 * I_ZERO_UNLESS(m, v); I_SRAI (arithmetic shift) for the steps' indices;
 * SIMD_NAME(x) gives the instance's function names. SIMD_PREFETCH_STEPS (0 or
 * 1): whether a direction's depths are prefetched once its steps are planned
 * (prefetch_steps). SIMD_PAIRED_DIRECTIONS: up to how many directions (an
 * even count) block_ao sets up in opposite pairs, 0 for none. SIMD_ORTHOGRAPHIC (0 or
 * 1) is the camera's projection, hbao_grid.orthographic: each file makes
 * an instance for each, so that no step tests it (bench_ab, 1080p, four
 * file copies of each build: 0.970 on 1 thread, 0.958 on 2). */

/* sample_rising leaves a sample's delta unset where it returns 0, and
 * its callers read it only where it returns 1; GCC cannot see
 * that through the masks, and zeroing it cost 4 instructions per step. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

static inline VF SIMD_NAME(dot3)(VF a0, VF a1, VF a2, VF b0, VF b1, VF b2) {
    return V_ADD(V_ADD(V_MUL(a0, b0), V_MUL(a1, b1)), V_MUL(a2, b2));
}

/* hbao_acos of |x|, lane by lane (x = |x| or -|x|: the same result) */
static inline VF SIMD_NAME(acos_of_magnitude)(VF x) {
    const VM negative = V_LT(x, V_SET(0.0f));
    const VF ax = V_SELECT(negative, x, V_NEG(x));
    VF p = V_SET(HBAO_ACOS_A3);
    p = V_ADD(V_MUL(p, ax), V_SET(HBAO_ACOS_A2));
    p = V_ADD(V_MUL(p, ax), V_SET(HBAO_ACOS_A1));
    p = V_ADD(V_MUL(p, ax), V_SET(HBAO_ACOS_A0));
    const VF one_minus = V_SUB(V_SET(1.0f), ax);
    const VF root = V_ZERO_UNLESS(V_GT(one_minus, V_SET(0.0f)), V_SQRT(one_minus));
    return V_MUL(root, p);
}

/* hbao_acos, lane by lane, from r = acos_of_magnitude(x) */
static inline VF SIMD_NAME(acos_from)(VF x, VF r) {
    return V_SELECT(V_LT(x, V_SET(0.0f)), r, V_SUB(V_SET(HBAO_PI), r));
}

/* hbao_acos, lane by lane */
static inline VF SIMD_NAME(acos)(VF x) {
    return SIMD_NAME(acos_from)(x, SIMD_NAME(acos_of_magnitude)(x));
}

/* horizon.c's gamma (asin of sin_gamma, as pi/2 - acos), from
 * r = acos_of_magnitude(sin_gamma) */
static inline VF SIMD_NAME(gamma_from)(VF sin_gamma, VF r) {
    return V_SUB(V_SET(0.5f * HBAO_PI), SIMD_NAME(acos_from)(sin_gamma, r));
}

typedef struct SIMD_NAME(slice) {
    VF np_length, inv_np, cos_gamma, sin_gamma;
    VF gamma; /* gamma_from; set only for the cosine integration */
    VM usable;
} SIMD_NAME(slice);

/* horizon.c's slice_setup for direction (dc, ds) into *sl and, where mirror
 * is not NULL, for the opposite direction (-dc, -ds) into *mirror. The
 * opposite direction's products are *sl's negated, exactly, so its sums are
 * formed here from the negated products as the reference forms them (even
 * a zero gets the same sign); the quantities that depend on them only
 * through a square (the square roots, the divisions, gamma's arc cosine of
 * |sin_gamma|) are *sl's. So *mirror is the reference's slice of the
 * opposite direction, bit for bit, for a third of the work (bench_ab,
 * docs/speed.md). n_cross_v: the x and y of n x V; with_gamma: whether
 * gamma is wanted (the cosine integration). */
static inline void SIMD_NAME(slice_setup)(const VF v[3], const VF n[3], const VF n_cross_v[2],
                                          VF n_dot_v, VF dc, VF ds, int with_gamma,
                                          SIMD_NAME(slice) * sl, SIMD_NAME(slice) * mirror) {
    const VF dv0 = V_MUL(dc, v[0]), dv1 = V_MUL(ds, v[1]);
    const VF dir_dot_v = V_ADD(dv0, dv1);
    const VF e_inv = V_DIV(V_SET(1.0f), V_SQRT(V_SUB(V_SET(1.0f), V_MUL(dir_dot_v, dir_dot_v))));
    const VF n_dot_m = V_MUL(V_ADD(V_MUL(dc, n_cross_v[0]), V_MUL(ds, n_cross_v[1])), e_inv);
    sl->np_length = V_SQRT(V_MAX0(V_SUB(V_SET(1.0f), V_MUL(n_dot_m, n_dot_m))));
    sl->usable = V_GT(sl->np_length, V_SET(1e-6f));
    sl->inv_np = V_DIV(V_SET(1.0f), sl->np_length);
    sl->cos_gamma = V_SELECT(sl->usable, V_SET(1.0f), V_MUL(n_dot_v, sl->inv_np));
    const VF dn0 = V_MUL(dc, n[0]), dn1 = V_MUL(ds, n[1]);
    const VF n_dot_e = V_MUL(V_SUB(V_ADD(dn0, dn1), V_MUL(dir_dot_v, n_dot_v)), e_inv);
    sl->sin_gamma = V_SELECT(sl->usable, V_SET(0.0f), V_MUL(n_dot_e, sl->inv_np));
    const VF acos_r = with_gamma ? SIMD_NAME(acos_of_magnitude)(sl->sin_gamma) : V_SET(0.0f);
    if (with_gamma) sl->gamma = SIMD_NAME(gamma_from)(sl->sin_gamma, acos_r);
    if (mirror == NULL) return;
    mirror->np_length = sl->np_length;
    mirror->usable = sl->usable;
    mirror->inv_np = sl->inv_np;
    mirror->cos_gamma = sl->cos_gamma;
    const VF back_dot_v = V_ADD(V_NEG(dv0), V_NEG(dv1));
    const VF back_dot_e =
        V_MUL(V_SUB(V_ADD(V_NEG(dn0), V_NEG(dn1)), V_MUL(back_dot_v, n_dot_v)), e_inv);
    mirror->sin_gamma = V_SELECT(sl->usable, V_SET(0.0f), V_MUL(back_dot_e, sl->inv_np));
    if (with_gamma) mirror->gamma = SIMD_NAME(gamma_from)(mirror->sin_gamma, acos_r);
}

/* A vector holds a whole block: its HBAO_BLOCK_PIXELS pixels (internal_hbao.h)
 * are the lanes (AVX-512's registers; AVX2's in pairs, horizon_avx2.c; four
 * of the baseline's 4-lane vectors, horizon_generic.c). */
_Static_assert(SIMD_LANES == HBAO_BLOCK_PIXELS, "a vector is a block");

/* The lanes' pixels (a block's) and what does not change between
 * directions. */
typedef struct SIMD_NAME(block) {
    const hbao_horizon_job *job;
    const hbao_grid *grid;
    VI lane_i;     /* the lanes' columns: first_i + 4 k */
    VF lane_float; /* and as floats (exact) */
    int first_i;   /* lane 0's column */
    int phase;     /* first_i & 3: the lanes' column phase */
    int first_x;   /* lane 0's index in its phase_depth row: first_i / 4 */
    int j;
    float jitter, step_px, inv_ycor; /* shared by the block */
    VF p[3], v[3], n[3];
    VF n_cross_v[2]; /* the x and y of n x V, for slice_setup */
    VF radius2, inv_radius2;
    VF height_tolerance, n_dot_v, near_limit; /* as in horizon.c's march */
    VM view_below;                            /* n_dot_v < 0: V below the tangent plane */
    /* hbao_height_plane, lane by lane */
    VF height_across, height_per_pixel, height_per_row, height_depth, height_offset;
    VF min_thickness; /* the back layer's, as in march */
} SIMD_NAME(block);

/* The depth fetch of one step. A step is one pixel offset for every lane,
 * so its depths are one contiguous load from the phase_depth row of the
 * lanes' new phase. The one-layer search fetches each step in its loop: a
 * skipped step (below the tangent plane) is a dozen instructions, so the
 * processor runs many steps ahead and their loads overlap; the two-layer
 * search fetches a direction's steps first (fetch_steps). */
typedef struct SIMD_NAME(fetch) {
    VF zs;
    VF zb;        /* the back layer's depth there (INFINITY: unknown) */
    float row;    /* the samples' hbao_grid y, the same for all lanes */
    float ox;     /* the step's pixel offset along the row, as a float */
    VM candidate; /* within the band past the image, on another pixel */
} SIMD_NAME(fetch);

/* A direction's steps for a whole block, worked out SIMD_LANES steps at a
 * time: each step's pixel offset from a lane to its sample (ox, oy), and
 * for a step whose lanes all lie inside the image (a `plain` step, the
 * common case) what its fetch needs: the index of the lanes' depths in
 * phase_depth, its grid row and ox as a float. Arrays hold whole vectors:
 * HBAO_MAX_STEPS + SIMD_LANES entries. Directions are planned ahead of
 * their search (SIMD_PLAN_AHEAD); an earlier form, the next direction
 * planned during a search (AVX2, when it searched a block in two halves),
 * measured 0.99, 0.977, 1.049 (half) on 2 threads: not kept then. */
#define SIMD_STEP_ROOM (HBAO_MAX_STEPS + SIMD_LANES)
typedef struct SIMD_NAME(steps) {
    int count; /* the steps before the first that lies a whole image away */
    int ox[SIMD_STEP_ROOM], oy[SIMD_STEP_ROOM], index[SIMD_STEP_ROOM];
    float row[SIMD_STEP_ROOM], ox_float[SIMD_STEP_ROOM];
    /* Steps 0 .. plain_end - 1 are plain (the steps move away from the
     * pixel, so plain steps come first; a later one would take the side
     * path, which is right for any step). One comparison per step instead
     * of a bit test: bench_ab, 1080p, four file copies of each build, 0.973
     * on 1 thread, 0.979 on 2. */
    int plain_end;
    /* Whether each step samples another pixel than the step before it and
     * than the pixel itself: one coordinate of the step's offset moves by
     * more than a pixel a step, and the first step is not on the pixel (the
     * steps move away from the pixel). 1/16 of a pixel is to spare for the
     * floats' rounding: a position is some five roundings, so two steps'
     * positions differ from their exact difference by at most about 10
     * 2^-24 |x|, 0.04 of a pixel at the largest plain offset, an image's
     * size (HBAO_MAX_IMAGE_SIZE, asserted below). fetch_step would then
     * skip no plain step, and they take the lanes of `active` as
     * candidates (*alive changes only on the side path). */
    int distinct;
} SIMD_NAME(steps);
_Static_assert(HBAO_MAX_IMAGE_SIZE <= 65536, "steps.distinct's margin holds to 2^16 pixels");

static inline VI SIMD_NAME(floor_to_int)(VF x) {
    /* hbao_floor_in_range's result in range (its truncation and correction
     * is the floor there) */
    return V_CVTT(V_FLOOR(x));
}

/* One vector of steps of plan_steps: each lane one step of direction (dc,
 * ds) (lane by lane: plan_two plans two directions in one vector), step
 * index `step`: hbao_step_offset with the same float operations, and what
 * a plain step's fetch needs. */
typedef struct SIMD_NAME(step_lanes) {
    VF x, y;        /* the offsets, as floats */
    VI ox, oy;      /* and as whole pixels */
    VI index;       /* the lanes' depths in phase_depth (for plain steps) */
    VF row;         /* the samples' grid row (hbao_grid_y) */
    VF ox_float;    /* ox, as floats (exact) */
    VM row_in_band; /* the sample row within the band past the image */
} SIMD_NAME(step_lanes);

static inline void SIMD_NAME(step_lanes_of)(const SIMD_NAME(block) * b, VF step, VF dc, VF ds,
                                            SIMD_NAME(step_lanes) * v) {
    const hbao_grid *g = b->grid;
    const VF along = V_ADD(V_SET(1.0f), V_MUL(V_ADD(step, V_SET(b->jitter)), V_SET(b->step_px)));
    v->x = V_ADD(V_SET(0.5f), V_MUL(dc, along));
    v->y = V_SUB(V_SET(0.5f), V_MUL(V_MUL(ds, along), V_SET(b->inv_ycor)));
    v->ox = SIMD_NAME(floor_to_int)(v->x);
    v->oy = SIMD_NAME(floor_to_int)(v->y);
    const VI sj = I_ADD(I_SET(b->j), v->oy);
    const VF sj_float = I_TO_F(sj);
    v->ox_float = I_TO_F(v->ox);
    const float rows = (float)g->beyond_rows;
    v->row_in_band =
        M_AND(V_GE(sj_float, V_SET(-rows)), V_LT(sj_float, V_SET((float)g->height + rows)));
    /* lane k samples column first_i + 4 k + ox: phase (phase + ox) mod
     * 4, index first_x + k + floor((phase + ox) / 4) of that phase's row */
    const VI moved = I_ADD(I_SET(b->phase), v->ox);
    const VI row_index = I_ADD(I_MULLO(I_AND(moved, I_SET(3)), I_SET(b->job->phase_rows)), sj);
    v->index = I_ADD(I_MULLO(row_index, I_SET(b->job->phase_width)),
                     I_ADD(I_SET(b->first_x), I_SRAI(moved, 2)));
    v->row = V_MUL(V_ADD(sj_float, V_SET(g->y_offset)), V_SET(g->y_step));
}

/* The lanes whose step's offset lies less than an image away */
static inline VM SIMD_NAME(inside_lanes)(const hbao_grid *g, const SIMD_NAME(step_lanes) * v) {
    return M_AND(
        M_AND(V_GE(v->x, V_SET((float)(1 - g->width))), V_LT(v->x, V_SET((float)g->width))),
        M_AND(V_GE(v->y, V_SET((float)(1 - g->height))), V_LT(v->y, V_SET((float)g->height))));
}

/* The lanes whose step is plain: the sample row, and lane 0's and the last
 * lane's columns (exact small integers as floats), within the band past the
 * image (grid->beyond_columns, beyond_rows), whose depths phase_depth holds, and the step
 * less than an image away (inside_bits: a block near one side can reach
 * the band past the other). */
static inline unsigned SIMD_NAME(plain_bits)(const SIMD_NAME(block) * b,
                                             const SIMD_NAME(step_lanes) * v) {
    const hbao_grid *g = b->grid;
    const VF column0 = V_ADD(V_SET((float)b->first_i), v->ox_float);
    const float band = (float)g->beyond_columns;
    const VM in_band =
        M_AND(v->row_in_band, M_AND(V_GE(column0, V_SET(-band)),
                                    V_LT(V_ADD(column0, V_SET((float)(4 * (SIMD_LANES - 1)))),
                                         V_SET((float)g->width + band))));
    return (unsigned)M_BITS(M_AND(in_band, SIMD_NAME(inside_lanes)(g, v)));
}

/* The lanes whose step lies less than an image away (hbao_step_offset).
 * A plain step does (plain_bits), so where every step is plain the test is
 * left out (bench_ab_pairs.sh, 1080p, Zen 5, 1 thread, against testing
 * every plan: 0.986 at the defaults, 0.987 at 8 x 6 + blur 15; session
 * 45). */
static inline unsigned SIMD_NAME(inside_bits)(const hbao_grid *g, const SIMD_NAME(step_lanes) * v) {
    return (unsigned)M_BITS(SIMD_NAME(inside_lanes)(g, v));
}

/* plan_two's t: its count and plain_end from the bits of its `steps`
 * lanes (steps <= SIMD_LANES / 2; plain: plain_bits, or 0 where indices
 * may overflow; inside: inside_bits, or all where every lane is plain),
 * as plan_steps sets them. */
static inline void SIMD_NAME(plan_counts)(SIMD_NAME(steps) * t, int steps, unsigned plain,
                                          unsigned inside) {
    const unsigned wanted = (1u << steps) - 1u;
    const unsigned run = ~plain & wanted, outside = ~inside & wanted;
    t->plain_end = run == 0 ? steps : __builtin_ctz(run);
    t->count = outside == 0 ? steps : __builtin_ctz(outside);
}

/* Whether each step of t samples another pixel than the one before
 * (steps.distinct), for direction (dc, ds) of block b. */
static inline void SIMD_NAME(plan_distinct)(const SIMD_NAME(block) * b, float dc, float ds,
                                            SIMD_NAME(steps) * t) {
    const float moves = fmaxf(fabsf(dc), fabsf(ds) * b->inv_ycor) * b->step_px;
    t->distinct = moves >= 1.0625f && t->count > 0 && (t->ox[0] | t->oy[0]) != 0;
}

/* hbao_step_offset for SIMD_LANES steps at once, each lane one step, with
 * the same float operations, and the plain steps' fetch data, for block b. */
static inline void SIMD_NAME(plan_steps)(const SIMD_NAME(block) * b, float dc, float ds, int steps,
                                         SIMD_NAME(steps) * t) {
    t->count = steps;
    t->plain_end = 0;
    for (int first = 0; first < steps; first += SIMD_LANES) {
        SIMD_NAME(step_lanes) v;
        SIMD_NAME(step_lanes_of)
        (b, I_TO_F(I_ADD(I_SET(first), I_LANES)), V_SET(dc), V_SET(ds), &v);
        I_STOREU(t->ox + first, v.ox);
        I_STOREU(t->oy + first, v.oy);
        I_STOREU(t->index + first, v.index);
        V_STOREU(t->row + first, v.row);
        V_STOREU(t->ox_float + first, v.ox_float);
        const int count = steps - first < SIMD_LANES ? steps - first : SIMD_LANES;
        const unsigned wanted = (count == 32 ? 0u : 1u << count) - 1u;
        int every_lane_plain = 0;
        if (t->plain_end == first && b->job->int_indices) {
            const unsigned run = ~SIMD_NAME(plain_bits)(b, &v) & wanted;
            t->plain_end = first + (run == 0 ? count : __builtin_ctz(run));
            every_lane_plain = run == 0;
        }
        if (every_lane_plain) continue; /* inside_bits: a plain step lies inside */
        const unsigned outside = ~SIMD_NAME(inside_bits)(b->grid, &v) & wanted;
        if (outside != 0) {
            t->count = first + __builtin_ctz(outside);
            break;
        }
    }
    SIMD_NAME(plan_distinct)(b, dc, ds, t);
}

/* plan_steps for two directions at once, (dc0, ds0) into *t0 and (dc1,
 * ds1) into *t1, where their steps fit in half a vector (steps <=
 * SIMD_LANES / 2): the lanes of each half are one direction's, with the
 * same float operations, so each plan is plan_steps', exactly. A plan was
 * a tenth of the frame at 8 x 6, whose 6 steps left 10 of 16 lanes idle.
 * With block_ao's copies for one and two layers (below), against a plan
 * each (bench_ab_pairs.sh, 1080p, Zen 5), 8 x 6 + blur 15: 0.938 on 1
 * thread, 0.947 on 2, AVX2 0.895; session 45. */
static inline void SIMD_NAME(plan_two)(const SIMD_NAME(block) * b, float dc0, float ds0, float dc1,
                                       float ds1, int steps, SIMD_NAME(steps) * t0,
                                       SIMD_NAME(steps) * t1) {
    enum { half = SIMD_LANES / 2 };
    SIMD_NAME(step_lanes) v;
    SIMD_NAME(step_lanes_of)
    (b, I_TO_F(I_AND(I_LANES, I_SET(half - 1))), V_SET_HALVES(dc0, dc1), V_SET_HALVES(ds0, ds1),
     &v);
    I_STORE_HALVES(t0->ox, t1->ox, v.ox);
    I_STORE_HALVES(t0->oy, t1->oy, v.oy);
    I_STORE_HALVES(t0->index, t1->index, v.index);
    V_STORE_HALVES(t0->row, t1->row, v.row);
    V_STORE_HALVES(t0->ox_float, t1->ox_float, v.ox_float);
    const unsigned wanted = (1u << steps) - 1u, both = wanted | wanted << half;
    const unsigned plain = b->job->int_indices ? SIMD_NAME(plain_bits)(b, &v) : 0u;
    const unsigned inside = (~plain & both) == 0 ? both : SIMD_NAME(inside_bits)(b->grid, &v);
    SIMD_NAME(plan_counts)(t0, steps, plain, inside);
    SIMD_NAME(plan_counts)(t1, steps, plain >> half, inside >> half);
    SIMD_NAME(plan_distinct)(b, dc0, ds0, t0);
    SIMD_NAME(plan_distinct)(b, dc1, ds1, t1);
}

/* The plain steps' depths, asked of the memory as soon as the steps are
 * planned, before the search reaches them: the cache lines of a step's first
 * and last lane (the block's HBAO_BLOCK_PIXELS floats, 64 bytes, lie in two
 * lines unless they start one), for the plain steps. Where
 * SIMD_PREFETCH_STEPS is 1: the AVX2 copy, measured on a Zen 3 (AMD EPYC,
 * 512 KiB of L2 per core, where a timer profile put half of the search's
 * time on the depth load) by bench_ab with paired calls in both orders
 * (scripts/bench_ab_pairs.sh), 1080p defaults: the first lane's line 0.884
 * and 0.908 on 1 thread, 0.924 and 0.926 on 2; the last lane's as well, on
 * top of that, 0.848-0.939 on 1 thread (three runs), 0.948-0.979 on 2 (then
 * with a block searched in two halves of 8 lanes, sharing one plan). The
 * AVX-512 copy too, since session 25 measured it on an Intel Xeon with
 * AVX-512 together with paired directions (see SIMD_PAIRED_DIRECTIONS). */
#ifndef SIMD_PREFETCH
/* prefetcht0 as a statement the compiler keeps: GCC 12 deleted every
 * __builtin_prefetch of prefetch_steps when its loop took the least of two
 * halves' plain_end (in the x86 copies; the generic copy, for any CPU,
 * defines it as __builtin_prefetch, which GCC 12 keeps there: prefetcht0
 * on x86-64, prfm on ARM64). Every prefetch of this file (prefetch_normals
 * too) goes through it. */
#define SIMD_PREFETCH(p) __asm__ volatile("prefetcht0 %0" : : "m"(*(const char *)(p)))
#endif
static inline void SIMD_NAME(prefetch_steps)(const SIMD_NAME(block) * b,
                                             const SIMD_NAME(steps) * t) {
#if SIMD_PREFETCH_STEPS
    const float *depths = b->job->phase_depth;
    for (int k = 0; k < t->plain_end; k++) {
        SIMD_PREFETCH(depths + t->index[k]);
        SIMD_PREFETCH(depths + t->index[k] + HBAO_BLOCK_PIXELS - 1);
    }
#else
    (void)b;
    (void)t;
#endif
}

/* The address of row[first], which may lie before the row (first < 0):
 * formed as an integer, not by pointer arithmetic outside the array; only
 * the lanes inside the row are read from it (V_LOAD_LANES). */
static inline const float *SIMD_NAME(lane_address)(const float *row, int first) {
    return (const float *)((uintptr_t)row + (uintptr_t)(intptr_t)first * sizeof(float));
}

/* A step that is not plain: lanes whose column leaves the band past the
 * image's sides (grid->beyond_columns) stop (in *alive), and only the lanes
 * within it read (phase_depth holds the band's depths: the image's edge
 * continued, hbao_beyond_depth). Returns 0 where every lane's sample row,
 * or every lane's column, has left the band: the direction's search ends
 * there (no step can bring a lane back: the steps move away from the
 * pixel). */
static int SIMD_NAME(fetch_at_side)(const SIMD_NAME(block) * b, int ox, int oy, VM *alive,
                                    SIMD_NAME(fetch) * f) {
    const hbao_grid *g = b->grid;
    const hbao_horizon_job *job = b->job;
    const int band = g->beyond_columns, phase_width = job->phase_width;
    const int sj = b->j + oy;
    if (sj < -g->beyond_rows || sj >= g->height + g->beyond_rows) return 0;
    const VF si = I_TO_F(I_ADD(b->lane_i, I_SET(ox))); /* exact: |si| < 2^24 */
    *alive = M_AND(*alive, M_AND(V_GE(si, V_SET((float)-band)),
                                 V_LT(si, V_SET((float)g->width + (float)band))));
    if (!M_ANY(*alive)) return 0;
    const VM candidate = (ox == 0 && oy == 0) ? M_NONE() : *alive;
    const int moved = b->phase + ox;
    const int new_phase = moved & 3;                        /* moved mod 4, two's complement */
    const int first = b->first_x + (moved - new_phase) / 4; /* exact */
    const ptrdiff_t row_start = ((ptrdiff_t)new_phase * job->phase_rows + sj) * phase_width;
    /* the lanes whose index lies in the row (exact small integers) */
    const VF index = I_TO_F(I_ADD(I_LANES, I_SET(first)));
    const VM in_row = M_AND(V_GE(index, V_SET((float)-job->phase_pad)),
                            V_LT(index, V_SET((float)(phase_width - job->phase_pad))));
    const float *depths = SIMD_NAME(lane_address)(job->phase_depth + row_start, first);
    f->zs = V_ZERO_UNLESS(candidate, V_LOAD_LANES(in_row, depths, V_SET(0.0f)));
    if (job->phase_back != NULL) {
        const float *backs = SIMD_NAME(lane_address)(job->phase_back + row_start, first);
        f->zb = V_LOAD_LANES(in_row, backs, V_SET(INFINITY));
    }
    f->row = hbao_grid_y(g, sj);
    f->ox = (float)ox;
    f->candidate = candidate;
    return 1;
}

/* Plain step `step` of plan t into *f, its samples candidates in the lanes
 * of `candidate`. */
static inline void SIMD_NAME(fetch_plain)(const SIMD_NAME(block) * b, const SIMD_NAME(steps) * t,
                                          int step, VM candidate, SIMD_NAME(fetch) * f) {
    const int index = t->index[step];
    f->zs = V_ZERO_UNLESS(candidate, V_LOADU(b->job->phase_depth + index));
    if (b->job->phase_back != NULL) f->zb = V_LOADU(b->job->phase_back + index);
    f->row = t->row[step];
    f->ox = t->ox_float[step];
    f->candidate = candidate;
}

/* Step `step` of plan t into *f: 1, or 0 where it repeats the previous
 * step's pixel, or -1 where the direction's search ends because every lane
 * has left the band past the image (*alive: the lanes still within it). Where the projected
 * radius spans fewer pixels than there are steps, steps snap to the same
 * pixel; a repeated sample cannot raise a horizon that its first visit set
 * (every test compares with > or reaches the same stop), so leaving it out
 * changes no result, and the step count adapts to the projected radius. */
static inline int SIMD_NAME(fetch_step)(const SIMD_NAME(block) * b, const SIMD_NAME(steps) * t,
                                        int step, VM *alive, SIMD_NAME(fetch) * f) {
    const int ox = t->ox[step], oy = t->oy[step];
    if (step > 0 && ox == t->ox[step - 1] && oy == t->oy[step - 1]) return 0;
    if (step < t->plain_end) {
        SIMD_NAME(fetch_plain)(b, t, step, (ox | oy) == 0 ? M_NONE() : *alive, f);
        return 1;
    }
    return SIMD_NAME(fetch_at_side)(b, ox, oy, alive, f) ? 1 : -1;
}

/* Fills fetches[0..n) with plan t's steps and returns n: the steps before
 * every lane has left the band past the image, less the steps that repeat
 * the previous step's pixel. */
static inline int SIMD_NAME(fetch_steps)(const SIMD_NAME(block) * b, const SIMD_NAME(steps) * t,
                                         VM active, SIMD_NAME(fetch) * fetches) {
    VM alive = active;
    int fetched = 0;
    for (int step = 0; step < t->count; step++) {
        const int got = SIMD_NAME(fetch_step)(b, t, step, &alive, &fetches[fetched]);
        if (got < 0) break;
        fetched += got;
    }
    return fetched;
}

/* The samples' hbao_grid x (view x per unit depth): lane_float + ox is
 * exact, as I_TO_F(lane_i + ox). */
static inline VF SIMD_NAME(sample_column)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f) {
    const hbao_grid *g = b->grid;
    return V_MUL(V_ADD(V_ADD(b->lane_float, V_SET(f->ox)), V_SET(g->x_offset)), V_SET(g->x_step));
}

/* horizon.c's hbao_height_across and hbao_height_at, lane by lane: the
 * height plane at a fetched step's pixels, and the height there at depth z */
static inline VF SIMD_NAME(height_across)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f) {
    return V_ADD(V_ADD(b->height_across, V_MUL(V_SET(f->ox), b->height_per_pixel)),
                 V_MUL(V_SET(f->row), b->height_per_row));
}

/* height_at before its offset: the height is height_scaled - height_offset */
static inline VF SIMD_NAME(height_scaled)(const SIMD_NAME(block) * b, VF across, VF z) {
    return SIMD_ORTHOGRAPHIC ? V_SUB(across, V_MUL(z, b->height_depth)) : V_MUL(z, across);
}

static inline VF SIMD_NAME(height_at)(const SIMD_NAME(block) * b, VF across, VF z) {
    return V_SUB(SIMD_NAME(height_scaled)(b, across, z), b->height_offset);
}

/* hbao_back_depth: the back made at least min_thickness thick */
static inline VF SIMD_NAME(back_depth)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f) {
    const VF thinnest = V_ADD(f->zs, b->min_thickness);
    return V_SELECT(V_GT(f->zb, thinnest), thinnest, f->zb);
}

/* The lanes among `live` whose fetched sample has a usable depth. */
static inline VM SIMD_NAME(sample_valid)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f,
                                         VM live) {
    const VF zs = f->zs;
    return M_AND(M_AND(f->candidate, live), M_AND(V_GT(zs, V_SET(0.0f)), V_GE(zs, b->near_limit)));
}

/* A fetched step's sample vector: delta, from the pixel's point. */
static inline void SIMD_NAME(sample_delta)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f,
                                           VF delta[3]) {
    const VF zs = f->zs;
    const VF column = SIMD_NAME(sample_column)(b, f);
    const VF row = V_SET(f->row);
    const VF q0 = SIMD_ORTHOGRAPHIC ? column : V_MUL(column, zs);
    const VF q1 = SIMD_ORTHOGRAPHIC ? row : V_MUL(row, zs);
    delta[0] = V_SUB(q0, b->p[0]);
    delta[1] = V_SUB(q1, b->p[1]);
    delta[2] = V_SUB(V_NEG(zs), b->p[2]);
}

/* Both: delta, and the lanes with a usable depth (returned). */
static inline VM SIMD_NAME(sample_point)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f,
                                         VM live, VF delta[3]) {
    SIMD_NAME(sample_delta)(b, f, delta);
    return SIMD_NAME(sample_valid)(b, f, live);
}

/* The squared length of delta, and which lanes of `valid` have a sample
 * within the radius (returned) and which beyond it (*far). */
static inline VM SIMD_NAME(sample_reach)(const SIMD_NAME(block) * b, VM valid, const VF delta[3],
                                         VF *dist2, VM *far) {
    *dist2 = SIMD_NAME(dot3)(delta[0], delta[1], delta[2], delta[0], delta[1], delta[2]);
    const VM near = V_LT(*dist2, b->radius2);
    const VM positive = M_AND(valid, V_GT(*dist2, V_SET(0.0f)));
    /* horizon.c's SAMPLE_FAR: usable but beyond the radius (finite) */
    *far = M_ANDNOT(near, M_AND(positive, V_LT(*dist2, V_SET(INFINITY))));
    return M_AND(positive, near);
}

/* Both: the lanes with a usable sample within the radius. */
static inline VM SIMD_NAME(sample_far)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f,
                                       VM live, VF delta[3], VF *dist2, VM *far) {
    return SIMD_NAME(sample_reach)(b, SIMD_NAME(sample_point)(b, f, live, delta), delta, dist2,
                                   far);
}

/* SIMD_NAME(sample_far) with the back layer: the lanes beyond the radius whose
 * occluder reaches into it (horizon.c's enter_the_ball) join, at the point
 * where their view ray enters the radius. */
static inline VM SIMD_NAME(sample_layers)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f,
                                          VM live, VF delta[3], VF *dist2) {
    VM far;
    const VM ok = SIMD_NAME(sample_far)(b, f, live, delta, dist2, &far);
    if (!M_ANY(far)) return ok;
    const VF q[3] = {V_ADD(delta[0], b->p[0]), V_ADD(delta[1], b->p[1]), V_ADD(delta[2], b->p[2])};
    VF d[3] = {V_SET(0.0f), V_SET(0.0f), V_SET(-1.0f)};
    if (!SIMD_ORTHOGRAPHIC) {
        const VF inv =
            V_DIV(V_SET(1.0f), V_SQRT(SIMD_NAME(dot3)(q[0], q[1], q[2], q[0], q[1], q[2])));
        for (int c = 0; c < 3; c++) d[c] = V_MUL(q[c], inv);
    }
    const VF along = SIMD_NAME(dot3)(delta[0], delta[1], delta[2], d[0], d[1], d[2]);
    const VF disc = V_SUB(V_MUL(along, along), V_SUB(*dist2, b->radius2));
    VM enter = M_AND(far, M_AND(V_LT(along, V_SET(0.0f)), V_GE(disc, V_SET(0.0f))));
    if (!M_ANY(enter)) return ok;
    const VF t = V_SUB(V_NEG(along), V_SQRT(V_MAX0(disc)));
    const VF entry_depth = V_NEG(V_ADD(q[2], V_MUL(t, d[2])));
    enter = M_AND(enter, V_LE(entry_depth, f->zb)); /* INFINITY: unknown, any depth */
    VF entered[3];
    for (int c = 0; c < 3; c++) entered[c] = V_ADD(delta[c], V_MUL(t, d[c]));
    const VF entered2 =
        SIMD_NAME(dot3)(entered[0], entered[1], entered[2], entered[0], entered[1], entered[2]);
    enter = M_AND(enter, V_GT(entered2, V_SET(0.0f)));
    for (int c = 0; c < 3; c++) delta[c] = V_SELECT(enter, delta[c], entered[c]);
    *dist2 = V_SELECT(enter, *dist2, entered2);
    return M_OR(ok, enter);
}

/* horizon.c's sample_elevation, and the angle to V of past_the_normal */
static inline VF SIMD_NAME(sample_height)(const SIMD_NAME(block) * b, const VF delta[3]) {
    const VF height = SIMD_NAME(dot3)(delta[0], delta[1], delta[2], b->n[0], b->n[1], b->n[2]);
    return V_SUB(height, b->height_tolerance);
}

static inline VF SIMD_NAME(sample_elevation)(const SIMD_NAME(block) * b, const VF delta[3],
                                             VF inv_dist) {
    return V_MUL(SIMD_NAME(sample_height)(b, delta), inv_dist);
}

/* The lanes of `ok` whose sample can change a one-layer horizon: one above
 * the tangent plane (height > 0), or any where V lies below it (a sample
 * then can be past the normal with a negative elevation). Every horizon
 * starts at the bias, sin_bias >= 0, and rises only past a larger
 * elevation; a sample at or below the tangent plane has elevation <= 0 and,
 * where dot(n, V) >= 0, cannot rise more steeply than V. So a step whose
 * samples all lie on or below the tangent plane (most of them, on a flat
 * surface) is skipped before its square root and division, and the result
 * is that of the scalar reference, which computes them. */
static inline VM SIMD_NAME(above_tangent)(const SIMD_NAME(block) * b, VM ok, VF height) {
    return M_AND(ok, M_OR(V_GT(height, V_SET(0.0f)), b->view_below));
}

/* The one-layer search's sample: whether any lane of sample_far's result
 * lies above the tangent plane (above_tangent: otherwise the step cannot
 * change a horizon), with those lanes in *ok. The tangent test comes first,
 * on every lane, so such a step (about 9 in 10 in bench_speed's scene)
 * skips the usable-depth test and the squared length; always inlined, so
 * that each test that fails leaves the caller's step at once. delta and
 * dist2 are set only where it returns 1. */
static inline __attribute__((always_inline)) int
SIMD_NAME(sample_rising)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f, VM live,
                         int any_below, VF delta[3], VF *dist2, VF *height, VM *ok) {
    /* (any_below: 0 where no lane of the block has b->view_below, a
     * constant of the caller's: cosine_plain_steps) */
    /* hbao_sample_height is height_at's height_scaled - height_offset;
     * its test height > 0 is made as height_scaled > height_offset, an
     * operation fewer on the path of the steps it skips. The two agree
     * wherever a - b is exact to its sign: IEEE with gradual underflow
     * gives a - b > 0 exactly where a > b, infinities and NaN included
     * (ordered compares: inf - inf is NaN, inf > inf false), and with
     * denormals read as zero (DAZ) both read the same zeroed inputs. Where
     * flush-to-zero makes a tiny difference +0, the step is searched
     * instead of skipped, and changes nothing: a height of 0 gives an
     * elevation of 0 (or NaN, which compares false), no horizon rises past
     * sin_bias >= 0 (params.c clamps the bias to 0 and up), and none passes
     * the normal, n_dot_v >= 0 where V is not below the tangent plane.
     * scripts/bench_ab_pairs.sh, 1080p defaults, Intel Xeon with AVX-512,
     * 40 rounds: 0.990 on 1 thread, 0.987 on 2 (session 50). */
    const VF scaled = SIMD_NAME(height_scaled)(b, SIMD_NAME(height_across)(b, f), f->zs);
    const VM rises = V_GT(scaled, b->height_offset);
    const VM tangent = any_below ? M_OR(rises, b->view_below) : rises;
    if (!M_ANY(tangent)) return 0;
    *height = V_SUB(scaled, b->height_offset);
    const VM valid = SIMD_NAME(sample_valid)(b, f, live);
    if (!M_ANY(M_AND(valid, tangent))) return 0;
    SIMD_NAME(sample_delta)(b, f, delta);
    VM far;
    *ok = SIMD_NAME(sample_reach)(b, valid, delta, dist2, &far);
    return M_ANY(M_AND(*ok, tangent)); /* above_tangent's test, on the scaled height */
}

static inline VF SIMD_NAME(cos_to_view)(const SIMD_NAME(block) * b, const VF delta[3],
                                        VF inv_dist) {
    return V_MUL(SIMD_NAME(dot3)(delta[0], delta[1], delta[2], b->v[0], b->v[1], b->v[2]),
                 inv_dist);
}

static VF SIMD_NAME(direction_occlusion_hbao)(const hbao_settings *s, const SIMD_NAME(block) * b,
                                              VM active, const SIMD_NAME(steps) * t,
                                              const SIMD_NAME(slice) * sl) {
    const int quadratic = s->falloff == HBAO_FALLOFF_QUADRATIC;
    const VF half_occluded = V_SET(0.5f * (1.0f - s->sin_bias));
    const VM check_past_normal = M_AND(sl->usable, V_GT(sl->sin_gamma, V_SET(0.0f)));
    const int any_check = M_ANY(M_AND(check_past_normal, active));
    VF sin_max = V_SET(s->sin_bias);
    VF occlusion = V_SET(0.0f);
    VM inside = active; /* lanes within the band past the image */
    VM alive = active;  /* lanes that have not stopped past the normal */
    for (int step = 0; step < t->count && M_ANY(alive); step++) {
        SIMD_NAME(fetch) f;
        const int got = SIMD_NAME(fetch_step)(b, t, step, &inside, &f);
        if (got < 0) break;
        if (got == 0) continue;
        VF delta[3], dist2, height;
        VM ok;
        if (!SIMD_NAME(sample_rising)(b, &f, alive, 1, delta, &dist2, &height, &ok)) continue;
        const VF inv_dist = V_DIV(V_SET(1.0f), V_SQRT(dist2));
        const VF sin_s = V_MUL(height, inv_dist);
        VM rest = ok;
        /* past_the_normal, its cheap half first: most samples rise less
         * steeply than V, and then the angle to V is not needed */
        const VM steep =
            any_check ? M_AND(M_AND(ok, check_past_normal), V_GT(sin_s, b->n_dot_v)) : M_NONE();
        if (M_ANY(steep)) {
            const VM past =
                M_AND(steep, V_GT(SIMD_NAME(cos_to_view)(b, delta, inv_dist), sl->cos_gamma));
            occlusion =
                V_SELECT(M_AND(past, V_LT(occlusion, half_occluded)), occlusion, half_occluded);
            alive = M_ANDNOT(past, alive);
            rest = M_ANDNOT(past, ok);
        }
        const VM rise = M_AND(rest, V_GT(sin_s, sin_max));
        const VF weight =
            quadratic ? V_SUB(V_SET(1.0f), V_MUL(dist2, b->inv_radius2)) : V_SET(1.0f);
        occlusion =
            V_SELECT(rise, occlusion, V_ADD(occlusion, V_MUL(weight, V_SUB(sin_s, sin_max))));
        sin_max = V_SELECT(rise, sin_max, sin_s);
    }
    return occlusion;
}

static inline VF SIMD_NAME(half_slice_visibility)(VF h, VF cos_h, VF sin_h,
                                                  const SIMD_NAME(slice) * sl) {
    const VF cos_2h = V_SUB(V_MUL(V_MUL(V_SET(2.0f), cos_h), cos_h), V_SET(1.0f));
    const VF sin_2h = V_MUL(V_MUL(V_SET(2.0f), sin_h), cos_h);
    const VF cos_2h_minus_gamma = V_ADD(V_MUL(cos_2h, sl->cos_gamma), V_MUL(sin_2h, sl->sin_gamma));
    return V_MUL(V_SET(0.25f), V_ADD(V_ADD(V_NEG(cos_2h_minus_gamma), sl->cos_gamma),
                                     V_MUL(V_MUL(V_SET(2.0f), h), sl->sin_gamma)));
}

/* hbao_sine_from_cosine, lane by lane (V_MAX0 is fmaxf(0, x)) */
static inline VF SIMD_NAME(sine_from_cosine)(VF c) {
    return V_SQRT(V_MAX0(V_SUB(V_SET(1.0f), V_MUL(c, c))));
}

/* horizon_visibility with the elevation's sine (sin_a) and arc cosine
 * (acos_a) given: every direction starts at the same elevation, the bias,
 * whose sine and arc cosine hbao_settings holds (compute.c). */
static inline VF SIMD_NAME(horizon_visibility_of)(VM past_normal, VF cos_past_max, VF elevation_max,
                                                  VF sin_a, VF acos_a, VF gamma,
                                                  const SIMD_NAME(slice) * sl) {
    /* horizon_from_elevation */
    const VF cos_a = elevation_max;
    const VF angle = V_ADD(gamma, acos_a);
    const VM flat = V_LE(angle, V_SET(0.0f));
    VF h = V_SELECT(flat, angle, V_SET(0.0f));
    VF cos_h = V_SELECT(flat, V_SUB(V_MUL(sl->cos_gamma, cos_a), V_MUL(sl->sin_gamma, sin_a)),
                        V_SET(1.0f));
    VF sin_h = V_SELECT(flat, V_ADD(V_MUL(sl->sin_gamma, cos_a), V_MUL(sl->cos_gamma, sin_a)),
                        V_SET(0.0f));
    if (M_ANY(past_normal)) {
        const VF past_sin = SIMD_NAME(sine_from_cosine)(cos_past_max);
        h = V_SELECT(past_normal, h, SIMD_NAME(acos)(cos_past_max));
        cos_h = V_SELECT(past_normal, cos_h, cos_past_max);
        sin_h = V_SELECT(past_normal, sin_h, past_sin);
    }
    return SIMD_NAME(half_slice_visibility)(h, cos_h, sin_h, sl);
}

static inline VF SIMD_NAME(horizon_visibility)(VM past_normal, VF cos_past_max, VF elevation_max,
                                               VF gamma, const SIMD_NAME(slice) * sl) {
    return SIMD_NAME(horizon_visibility_of)(past_normal, cos_past_max, elevation_max,
                                            SIMD_NAME(sine_from_cosine)(elevation_max),
                                            SIMD_NAME(acos)(elevation_max), gamma, sl);
}

/* The visibility at the bias elevation, below which no horizon lies: every
 * direction's start (the bias's sine and arc cosine from hbao_settings). */
static inline VF SIMD_NAME(visibility_start)(const hbao_settings *s, VF gamma,
                                             const SIMD_NAME(slice) * sl) {
    return SIMD_NAME(horizon_visibility_of)(M_NONE(), sl->cos_gamma, V_SET(s->sin_bias),
                                            V_SET(s->bias_elevation_sine),
                                            V_SET(s->bias_elevation_acos), gamma, sl);
}

/* The state of a direction's one-layer cosine search: its horizon so far,
 * lane by lane, and what the search found (direction_occlusion_cosine). */
typedef struct SIMD_NAME(cosine_search) {
    VF elevation_max, cos_past_max, visibility_at_max, occlusion;
    VM past_normal; /* lanes whose horizon passed the normal */
    VM check_past_normal;
    int any_check, quadratic, any_raised;
} SIMD_NAME(cosine_search);

/* One fetched step of the one-layer cosine search: its samples can raise
 * the horizons of the lanes of `active`. */
static inline __attribute__((always_inline)) void
SIMD_NAME(cosine_step)(const SIMD_NAME(block) * b, const SIMD_NAME(slice) * sl,
                       const SIMD_NAME(fetch) * f, VM active, int any_below,
                       SIMD_NAME(cosine_search) * c) {
    VF delta[3], dist2, height;
    VM ok;
    if (!SIMD_NAME(sample_rising)(b, f, active, any_below, delta, &dist2, &height, &ok)) return;
    const VF inv_dist = V_DIV(V_SET(1.0f), V_SQRT(dist2));
    const VF sin_s = V_MUL(height, inv_dist);
    VM raised = M_NONE(); /* no lane */
    /* past_the_normal, its cheap half first (see above) */
    const VM steep =
        c->any_check ? M_AND(M_AND(ok, c->check_past_normal), V_GT(sin_s, b->n_dot_v)) : raised;
    if (M_ANY(steep)) {
        const VF cos_v = SIMD_NAME(cos_to_view)(b, delta, inv_dist);
        const VM newly =
            M_AND(M_AND(steep, V_GT(cos_v, sl->cos_gamma)), V_GT(cos_v, c->cos_past_max));
        c->past_normal = M_OR(c->past_normal, newly);
        c->cos_past_max = V_SELECT(newly, c->cos_past_max,
                                   V_SELECT(V_GT(cos_v, V_SET(1.0f)), cos_v, V_SET(1.0f)));
        raised = newly;
    }
    const VM elevation_candidates = M_ANDNOT(c->past_normal, M_ANDNOT(raised, ok));
    const VF elevation = V_MUL(sin_s, sl->inv_np);
    const VM rise = M_AND(elevation_candidates, V_GT(elevation, c->elevation_max));
    c->elevation_max = V_SELECT(rise, c->elevation_max,
                                V_SELECT(V_GT(elevation, V_SET(1.0f)), elevation, V_SET(1.0f)));
    raised = M_OR(raised, rise);
    c->any_raised |= M_ANY(raised);
    if (c->quadratic && M_ANY(raised)) {
        const VF visibility = SIMD_NAME(horizon_visibility)(c->past_normal, c->cos_past_max,
                                                            c->elevation_max, sl->gamma, sl);
        const VF weight = V_SUB(V_SET(1.0f), V_MUL(dist2, b->inv_radius2));
        c->occlusion =
            V_SELECT(raised, c->occlusion,
                     V_ADD(c->occlusion, V_MUL(weight, V_SUB(c->visibility_at_max, visibility))));
        c->visibility_at_max = V_SELECT(raised, c->visibility_at_max, visibility);
    }
}

/* The plain steps of a plan whose steps each sample a pixel of their own
 * (steps.distinct), searched by a loop with none of fetch_step's tests;
 * returns plain_end. any_below: whether some lane of the block has V below
 * its tangent plane (block.view_below), a constant in each of the two
 * copies that direction_occlusion_cosine inlines: the copy for blocks
 * without such a lane (nearly all) leaves view_below out of each step's
 * first test, two loads and two operations fewer a skipped AVX2 step.
 * Bit-identical; scripts/bench_ab_pairs.sh, 1080p, Zen 3 (AVX2), against
 * one loop: defaults 0.987 on 1 thread and 0.985 on 2 (30 rounds), half
 * resolution 0.982 on 2, the generic kernel 0.986 (session 61). */
static inline __attribute__((always_inline)) int
SIMD_NAME(cosine_plain_steps)(const SIMD_NAME(block) * b, const SIMD_NAME(slice) * sl,
                              const SIMD_NAME(steps) * t, VM active, int any_below,
                              SIMD_NAME(cosine_search) * c) {
    for (int step = 0; step < t->plain_end; step++) {
        SIMD_NAME(fetch) f;
        SIMD_NAME(fetch_plain)(b, t, step, active, &f);
        SIMD_NAME(cosine_step)(b, sl, &f, active, any_below, c);
    }
    return t->plain_end;
}

/* t: the direction's steps, planned (by the caller) before anything else:
 * the search does not wait on them; the open part is left to the end
 * (bench_ab, 1080p, four file copies of each build: 0.97 on 1 thread,
 * 0.98 on 2, against gamma and the open part first). Where the plan's
 * plain steps each sample a pixel of their own (steps.distinct), they are
 * searched first by a loop with none of fetch_step's tests, and a step
 * leaves at its first failed test (cosine_step, sample_rising): on the
 * Zen 2 VM of session 38, where a skipped step was some 54 instructions,
 * 7 of them branches, and ran at 3.4 instructions a cycle, bit-identical,
 * scripts/bench_ab_pairs.sh 1080p: defaults 0.948 on 1 thread, 0.949 on
 * 2, half resolution 0.951, 8 x 6 + blur 15 0.986, back faces 0.991,
 * radius 0.02 (steps on the same pixel: the loop with the tests) 1.006.
 * The same for the HBAO integration measured 1.008: not kept there. */
static VF SIMD_NAME(direction_occlusion_cosine)(const hbao_settings *s, const SIMD_NAME(block) * b,
                                                VM active, const SIMD_NAME(steps) * t,
                                                const SIMD_NAME(slice) * sl, VF *open_part) {
    const VF gamma = sl->gamma;
    SIMD_NAME(cosine_search) c;
    c.check_past_normal = V_GT(sl->sin_gamma, V_SET(0.0f));
    c.any_check = M_ANY(M_AND(c.check_past_normal, active));
    c.quadratic = s->falloff == HBAO_FALLOFF_QUADRATIC;
    c.elevation_max = V_SET(s->sin_bias);
    c.past_normal = M_NONE(); /* no lane */
    c.cos_past_max = sl->cos_gamma;
    c.visibility_at_max = c.quadratic ? SIMD_NAME(visibility_start)(s, gamma, sl) : V_SET(0.0f);
    c.occlusion = V_SET(0.0f);
    c.any_raised = 0;
    int step = 0;
    if (t->distinct)
        step = M_ANY(b->view_below) ? SIMD_NAME(cosine_plain_steps)(b, sl, t, active, 1, &c)
                                    : SIMD_NAME(cosine_plain_steps)(b, sl, t, active, 0, &c);
    VM inside = active; /* lanes within the band past the image */
    for (; step < t->count; step++) {
        SIMD_NAME(fetch) f;
        const int got = SIMD_NAME(fetch_step)(b, t, step, &inside, &f);
        if (got < 0) break;
        if (got == 0) continue;
        SIMD_NAME(cosine_step)(b, sl, &f, active, 1, &c);
    }
    const int quadratic = c.quadratic, any_raised = c.any_raised;
    const VM past_normal = c.past_normal;
    const VF cos_past_max = c.cos_past_max, elevation_max = c.elevation_max;
    VF occlusion = c.occlusion;
    /* Where no lane's horizon rose or passed the normal, the end is the
     * start, and start - start is 0 on every lane that counts (a finite
     * start; the others are left out by the caller): neither is computed. */
    *open_part =
        V_MUL(V_SET(0.25f),
              V_ADD(V_MUL(V_SET(2.0f), sl->cos_gamma),
                    V_MUL(V_ADD(V_MUL(V_SET(2.0f), gamma), V_SET(HBAO_PI)), sl->sin_gamma)));
    if (!quadratic && any_raised)
        occlusion = V_SUB(
            SIMD_NAME(visibility_start)(s, gamma, sl),
            SIMD_NAME(horizon_visibility)(past_normal, cos_past_max, elevation_max, gamma, sl));
    return occlusion;
}

/* --- The back layer: sector masks (horizon.c, "Two depth layers") --- */

/* sector_bits, lane by lane: the same clamps and roundings; a shift by 32
 * gives 0, so an empty interval needs no test. */
static inline VI SIMD_NAME(sector_bits)(VF lo, VF hi) {
    const VF n = V_SET((float)HBAO_SECTORS);
    const VF first = V_CEIL(V_SUB(V_MUL(V_MIN(V_MAX0(lo), V_SET(1.0f)), n), V_SET(0.5f)));
    const VF end =
        V_ADD(V_FLOOR(V_SUB(V_MUL(V_MIN(V_MAX0(hi), V_SET(1.0f)), n), V_SET(0.5f))), V_SET(1.0f));
    const VI one = I_SET(1);
    const VI below_end = I_SUB(I_SLLV(one, V_CVTT(end)), one);
    const VI below_first = I_SUB(I_SLLV(one, V_CVTT(first)), one);
    return I_ANDNOT(below_first, below_end);
}

static inline VI SIMD_NAME(popcount)(VI x) {
    x = I_SUB(x, I_AND(I_SRLI(x, 1), I_SET(0x55555555)));
    x = I_ADD(I_AND(x, I_SET(0x33333333)), I_AND(I_SRLI(x, 2), I_SET(0x33333333)));
    x = I_AND(I_ADD(x, I_SRLI(x, 4)), I_SET(0x0f0f0f0f));
    return I_SRLI(I_MULLO(x, I_SET(0x01010101)), 24);
}

/* horizon.c's mark_sectors, in the lanes of ok: occlusion plus the newly
 * marked sectors times weight. */
static inline VF SIMD_NAME(mark_sectors)(VI *marked, VM ok, VF a, VF b, VF weight, VF occlusion) {
    const VI fresh = I_ZERO_UNLESS(
        ok, I_ANDNOT(*marked, SIMD_NAME(sector_bits)(V_MIN(a, b), V_SELECT(V_GT(a, b), b, a))));
    *marked = I_OR(*marked, fresh);
    return V_SELECT(ok, occlusion,
                    V_ADD(occlusion, V_MUL(weight, I_TO_F(SIMD_NAME(popcount)(fresh)))));
}

/* The back point of a fetched step: the view ray through each lane's sample
 * pixel at the back depth (made at least min_thickness thick); *known:
 * lanes whose back is known. Returns the squared length of delta. */
static inline VF SIMD_NAME(back_point)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f,
                                       VF delta[3], VM *known) {
    const VF zb = SIMD_NAME(back_depth)(b, f);
    *known = V_LT(f->zb, V_SET(INFINITY));
    const VF column = SIMD_NAME(sample_column)(b, f);
    const VF row = V_SET(f->row);
    delta[0] = V_SUB(SIMD_ORTHOGRAPHIC ? column : V_MUL(column, zb), b->p[0]);
    delta[1] = V_SUB(SIMD_ORTHOGRAPHIC ? row : V_MUL(row, zb), b->p[1]);
    delta[2] = V_SUB(V_NEG(zb), b->p[2]);
    return SIMD_NAME(dot3)(delta[0], delta[1], delta[2], delta[0], delta[1], delta[2]);
}

/* horizon.c's layer_sample_below, lane by lane */
static inline VM SIMD_NAME(layer_below)(const SIMD_NAME(block) * b, const SIMD_NAME(fetch) * f) {
    const VF across = SIMD_NAME(height_across)(b, f);
    const VF front = SIMD_NAME(height_at)(b, across, f->zs);
    const VF back = SIMD_NAME(height_at)(b, across, SIMD_NAME(back_depth)(b, f));
    const VM known = V_LT(f->zb, V_SET(INFINITY));
    const VM falling =
        SIMD_ORTHOGRAPHIC ? V_GE(b->height_depth, V_SET(0.0f)) : V_LE(across, V_SET(0.0f));
    const VM rest = M_OR(M_AND(known, V_LE(back, V_SET(0.0f))), M_ANDNOT(known, falling));
    return M_ANDNOT(b->view_below, M_AND(V_LE(front, V_SET(0.0f)), rest));
}

/* Whether any lane of `ok` can mark a sector: as above_tangent, with the
 * back point too (a sample whose front and known back both lie on or below
 * the tangent plane has both fractions at 1, an empty interval). */
static inline int SIMD_NAME(layer_step_matters)(const SIMD_NAME(block) * b, VM ok,
                                                const VF delta[3], const VF delta_back[3],
                                                VM known) {
    const VM front = SIMD_NAME(above_tangent)(b, ok, SIMD_NAME(sample_height)(b, delta));
    const VM back =
        M_AND(M_AND(ok, known), V_GT(SIMD_NAME(sample_height)(b, delta_back), V_SET(0.0f)));
    return M_ANY(M_OR(front, back));
}

/* horizon.c's sector_fraction_cosine */
static inline VF SIMD_NAME(sector_fraction_cosine)(const SIMD_NAME(block) * b,
                                                   const SIMD_NAME(slice) * sl, const VF delta[3],
                                                   VF dist2, VF gamma, VM check_past_normal,
                                                   int any_check, VF sin_bias, VF inv_bias) {
    const VF inv_dist = V_DIV(V_SET(1.0f), V_SQRT(dist2));
    const VF sin_s = SIMD_NAME(sample_elevation)(b, delta, inv_dist);
    VM past = M_NONE(); /* no lane */
    VF cos_v = V_SET(1.0f);
    if (any_check) {
        const VM steep = M_AND(check_past_normal, V_GT(sin_s, b->n_dot_v));
        if (M_ANY(steep)) {
            cos_v = SIMD_NAME(cos_to_view)(b, delta, inv_dist);
            past = M_AND(steep, V_GT(cos_v, sl->cos_gamma));
            cos_v = V_SELECT(V_GT(cos_v, V_SET(1.0f)), cos_v, V_SET(1.0f));
        }
    }
    VF elevation = V_MUL(sin_s, sl->inv_np);
    const VM above = V_GT(elevation, sin_bias);
    elevation = V_SELECT(V_GT(elevation, V_SET(1.0f)), elevation, V_SET(1.0f));
    const VF fraction =
        V_MUL(SIMD_NAME(horizon_visibility)(past, cos_v, elevation, gamma, sl), inv_bias);
    return V_SELECT(M_OR(past, above), V_SET(1.0f), fraction);
}

static VF SIMD_NAME(direction_occlusion_cosine_layers)(const hbao_settings *s,
                                                       const SIMD_NAME(block) * b, VM active,
                                                       const SIMD_NAME(steps) * t,
                                                       const SIMD_NAME(slice) * sl, VF *open_part) {
    const VF gamma = sl->gamma;
    *open_part =
        V_MUL(V_SET(0.25f),
              V_ADD(V_MUL(V_SET(2.0f), sl->cos_gamma),
                    V_MUL(V_ADD(V_MUL(V_SET(2.0f), gamma), V_SET(HBAO_PI)), sl->sin_gamma)));
    const VM check_past_normal = V_GT(sl->sin_gamma, V_SET(0.0f));
    const int any_check = M_ANY(M_AND(check_past_normal, active));
    const int quadratic = s->falloff == HBAO_FALLOFF_QUADRATIC;
    const VF sin_bias = V_SET(s->sin_bias);
    const VF visibility_bias = SIMD_NAME(horizon_visibility_of)(
        M_NONE(), sl->cos_gamma, sin_bias, V_SET(s->bias_elevation_sine),
        V_SET(s->bias_elevation_acos), gamma, sl);
    const VM lanes = M_AND(active, V_GT(visibility_bias, V_SET(0.0f)));
    const VF inv_bias = V_DIV(V_SET(1.0f), visibility_bias);
    VI marked = I_SET(0);
    VF occlusion = V_SET(0.0f); /* in sectors */
    SIMD_NAME(fetch) fetches[HBAO_MAX_STEPS];
    const int fetched = SIMD_NAME(fetch_steps)(b, t, lanes, fetches);
    for (int step = 0; step < fetched; step++) {
        const VM live = M_ANDNOT(SIMD_NAME(layer_below)(b, &fetches[step]), lanes);
        if (!M_ANY(M_AND(live, fetches[step].candidate))) continue;
        VF delta[3], dist2;
        const VM ok = SIMD_NAME(sample_layers)(b, &fetches[step], live, delta, &dist2);
        if (!M_ANY(ok)) continue;
        VF delta_back[3];
        VM known;
        const VF dist2_back = SIMD_NAME(back_point)(b, &fetches[step], delta_back, &known);
        if (!SIMD_NAME(layer_step_matters)(b, ok, delta, delta_back, known)) continue;
        const VF front = SIMD_NAME(sector_fraction_cosine)(
            b, sl, delta, dist2, gamma, check_past_normal, any_check, sin_bias, inv_bias);
        const VF behind = V_SELECT(
            M_AND(known, V_GT(dist2_back, V_SET(0.0f))), V_SET(1.0f),
            SIMD_NAME(sector_fraction_cosine)(b, sl, delta_back, dist2_back, gamma,
                                              check_past_normal, any_check, sin_bias, inv_bias));
        occlusion = SIMD_NAME(mark_sectors)(
            &marked, ok, front, behind,
            quadratic ? V_MAX0(V_SUB(V_SET(1.0f), V_MUL(dist2, b->inv_radius2))) : V_SET(1.0f),
            occlusion);
    }
    return V_ZERO_UNLESS(lanes,
                         V_MUL(occlusion, V_DIV(visibility_bias, V_SET((float)HBAO_SECTORS))));
}

static VF SIMD_NAME(direction_occlusion_hbao_layers)(const hbao_settings *s,
                                                     const SIMD_NAME(block) * b, VM active,
                                                     const SIMD_NAME(steps) * t,
                                                     const SIMD_NAME(slice) * sl) {
    const int quadratic = s->falloff == HBAO_FALLOFF_QUADRATIC;
    const float range = 1.0f - s->sin_bias;
    const VF inv_range = V_SET(1.0f / range);
    const VF half_occluded = V_SET(0.5f * range);
    const VM check_past_normal = M_AND(sl->usable, V_GT(sl->sin_gamma, V_SET(0.0f)));
    const int any_check = M_ANY(M_AND(check_past_normal, active));
    VI marked = I_SET(0);
    VF occlusion = V_SET(0.0f); /* in sectors */
    VF past = V_SET(0.0f);
    SIMD_NAME(fetch) fetches[HBAO_MAX_STEPS];
    const int fetched = SIMD_NAME(fetch_steps)(b, t, active, fetches);
    VM alive = active; /* lanes that have not stopped past the normal */
    for (int step = 0; step < fetched && M_ANY(alive); step++) {
        const VM live = M_ANDNOT(SIMD_NAME(layer_below)(b, &fetches[step]), alive);
        if (!M_ANY(M_AND(live, fetches[step].candidate))) continue;
        VF delta[3], dist2;
        VM ok = SIMD_NAME(sample_layers)(b, &fetches[step], live, delta, &dist2);
        if (!M_ANY(ok)) continue;
        VF delta_back[3];
        VM known;
        const VF dist2_back = SIMD_NAME(back_point)(b, &fetches[step], delta_back, &known);
        if (!SIMD_NAME(layer_step_matters)(b, ok, delta, delta_back, known)) continue;
        const VF inv_dist = V_DIV(V_SET(1.0f), V_SQRT(dist2));
        const VF sin_s = SIMD_NAME(sample_elevation)(b, delta, inv_dist);
        if (any_check) {
            const VM steep = M_AND(M_AND(ok, check_past_normal), V_GT(sin_s, b->n_dot_v));
            if (M_ANY(steep)) {
                const VM beyond =
                    M_AND(steep, V_GT(SIMD_NAME(cos_to_view)(b, delta, inv_dist), sl->cos_gamma));
                past = V_SELECT(beyond, past, half_occluded);
                alive = M_ANDNOT(beyond, alive);
                ok = M_ANDNOT(beyond, ok);
            }
        }
        const VF front = V_MUL(V_SUB(V_SET(1.0f), sin_s), inv_range);
        const VF sin_back =
            SIMD_NAME(sample_elevation)(b, delta_back, V_DIV(V_SET(1.0f), V_SQRT(dist2_back)));
        const VF behind = V_SELECT(M_AND(known, V_GT(dist2_back, V_SET(0.0f))), V_SET(1.0f),
                                   V_MUL(V_SUB(V_SET(1.0f), sin_back), inv_range));
        occlusion = SIMD_NAME(mark_sectors)(
            &marked, ok, front, behind,
            quadratic ? V_MAX0(V_SUB(V_SET(1.0f), V_MUL(dist2, b->inv_radius2))) : V_SET(1.0f),
            occlusion);
    }
    occlusion = V_MUL(occlusion, V_SET(range / (float)HBAO_SECTORS));
    return V_SELECT(V_GT(occlusion, past), past, occlusion);
}

/* Directions whose slices block_ao sets up together: groups of 8, except
 * that an even number of directions up to SIMD_PAIRED_DIRECTIONS (0: never)
 * is set up as one group, in opposite pairs (direction d + N/2 is direction
 * d negated: horizon.c's table), each pair by one slice_setup. The AVX2
 * copy pairs up to 16 (6 KiB of slices on the stack): bench_ab, 1080p, Zen
 * 1, defaults 0.954 on 1 thread, 0.948-0.972 on 2, 8 x 6 + blur 15 0.951
 * (docs/speed.md, session 24). The AVX-512 copy pairs up to 16 as well
 * (12 KiB), with SIMD_PREFETCH_STEPS 1: bench_ab, 1080p, Intel Xeon with
 * AVX-512 (session 25), defaults 0.938-0.963 on 1 thread, 0.949-0.959 on
 * 2, half resolution 0.986 and 0.970, 8 x 6 + blur 15 0.908 and 0.921, 4K
 * 0.916. Either alone did less (pairs 1.008 at the defaults, the prefetch
 * 1.044 at half resolution). Session 11 had measured an older form of
 * pairs slower on an AMD EPYC with AVX-512 (1.03-1.04), not re-measured. */
#define SIMD_DIRECTION_GROUP 8
/* How many directions' steps block_ao keeps planned and prefetched: the
 * first SIMD_PLAN_AHEAD of a group before any search, then, as direction k
 * is searched, direction k + SIMD_PLAN_AHEAD - 1, into the plan of k - 1.
 * A step's depths were asked of the memory only just before its own
 * direction's search; now the searches of the directions before it cover
 * the wait. bench_ab, 1080p, Intel Xeon with AVX-512 (session 27),
 * bit-identical, against planning each direction just before its search:
 * defaults 0.944 on 1 thread, 0.974-0.976 on 2; 8 x 6 + blur 15 0.920 and
 * 0.921; back faces 0.975 and 0.984; half resolution 1.020 and 0.997; 4K
 * 0.929 and 0.926; AVX2 on the same machine: defaults 1.008 and
 * 1.013, 8 x 6 + blur 15 0.970 and 0.974. 8 ahead instead of 4: 16
 * directions 0.988, 4 and 8 directions 1.003-1.013. Where plan_two plans
 * two directions at once (up to 8 steps), the first four are planned
 * before any search, then, as an even direction k >= 2 is searched, k + 2
 * and k + 3 into the plans of k - 2 and k - 1 (plan_ahead). */
#define SIMD_PLAN_AHEAD 4
_Static_assert(SIMD_PLAN_AHEAD % 2 == 0, "plan_two's two plans are neighbours in the ring");

/* Plans direction k of a group (its cosines and sines) into
 * plans[k % SIMD_PLAN_AHEAD] and prefetches its steps' depths; where
 * `left` (the directions from k on) is at least 2 and steps fit in half a
 * vector, direction k + 1 too (plan_two). */
static inline __attribute__((always_inline)) void
SIMD_NAME(plan_ahead)(const SIMD_NAME(block) * b, const float *group_cos, const float *group_sin,
                      int k, int left, int steps, SIMD_NAME(steps) * plans) {
    SIMD_NAME(steps) *t = &plans[k % SIMD_PLAN_AHEAD];
    if (left >= 2 && steps <= SIMD_LANES / 2) {
        SIMD_NAME(plan_two)
        (b, group_cos[k], group_sin[k], group_cos[k + 1], group_sin[k + 1], steps, t, t + 1);
        SIMD_NAME(prefetch_steps)(b, t);
        SIMD_NAME(prefetch_steps)(b, t + 1);
    } else {
        SIMD_NAME(plan_steps)(b, group_cos[k], group_sin[k], steps, t);
        SIMD_NAME(prefetch_steps)(b, t);
    }
}

#if SIMD_PAIRED_DIRECTIONS > SIMD_DIRECTION_GROUP
#define SIMD_SLICE_ROOM SIMD_PAIRED_DIRECTIONS
#else
#define SIMD_SLICE_ROOM SIMD_DIRECTION_GROUP
#endif

/* The depths of the block of phase a at x0 in row j: its row of
 * phase_depth, background (0) for the lanes past the image's width (where
 * phase_depth holds the band past the edge). */
static inline VF SIMD_NAME(block_depths)(const hbao_horizon_job *job, int x0, int j, int a) {
    const VF z =
        V_LOADU(job->phase_depth + ((size_t)a * job->phase_rows + j) * job->phase_width + x0 / 4);
    if (x0 + 4 * HBAO_BLOCK_PIXELS <= job->grid->width) return z;
    const VF column = I_TO_F(I_ADD(I_SET(x0 + a), I_MULLO(I_LANES, I_SET(4))));
    return V_ZERO_UNLESS(V_LT(column, V_SET((float)job->grid->width)), z);
}

/* Sets up *b, the block of phase a at x0 in row j, with the block's step
 * step_px, and returns its active lanes. What the steps' plan reads is set
 * first; the rest only where a lane is active. */
static VM SIMD_NAME(block_setup)(const hbao_horizon_job *job, int x0, int j, int a, float step_px,
                                 SIMD_NAME(block) * b) {
    const hbao_settings *s = job->settings;
    const hbao_grid *g = job->grid;
    b->job = job;
    b->grid = g;
    b->j = j;
    const int first_i = x0 + a;
    b->first_i = first_i;
    b->phase = a;
    b->first_x = first_i / 4;
    b->jitter = job->jitter[a + 4 * (j & 3)];
    b->step_px = step_px;
    b->inv_ycor = 1.0f / g->ycor;
    const VF z = SIMD_NAME(block_depths)(job, x0, j, a);
    b->lane_i = I_ADD(I_SET(first_i), I_MULLO(I_LANES, I_SET(4)));
    b->lane_float = I_TO_F(b->lane_i);
    const VF column = V_MUL(V_ADD(b->lane_float, V_SET(g->x_offset)), V_SET(g->x_step));
    const VF row = V_SET(hbao_grid_y(g, j));
    b->p[0] = SIMD_ORTHOGRAPHIC ? column : V_MUL(column, z);
    b->p[1] = SIMD_ORTHOGRAPHIC ? row : V_MUL(row, z);
    b->p[2] = V_NEG(z);
    const VF radius_px = SIMD_ORTHOGRAPHIC
                             ? V_SET(s->radius / g->pixel_size)
                             : V_DIV(V_SET(s->radius), V_MUL(V_SET(g->pixel_size), z));
    const VM active = M_AND(V_GT(z, V_SET(0.0f)), V_GE(radius_px, V_SET(1.0f)));
    if (!M_ANY(active)) return active;
    b->radius2 = V_SET(s->radius * s->radius);
    b->inv_radius2 = V_SET(s->inv_radius2);
    if (SIMD_ORTHOGRAPHIC) {
        b->v[0] = V_SET(0.0f);
        b->v[1] = V_SET(0.0f);
        b->v[2] = V_SET(1.0f);
    } else {
        const VF inv =
            V_DIV(V_SET(1.0f),
                  V_SQRT(SIMD_NAME(dot3)(b->p[0], b->p[1], b->p[2], b->p[0], b->p[1], b->p[2])));
        for (int c = 0; c < 3; c++) b->v[c] = V_MUL(V_NEG(b->p[c]), inv);
    }
    /* lanes past the image's width read the next component's or row's
     * normals, or the padding: they are background (not active) */
    for (int c = 0; c < 3; c++)
        b->n[c] = V_LOAD_EVERY_FOURTH(hbao_grid_normal_row(g, j, c) + first_i);
    b->n_dot_v = SIMD_NAME(dot3)(b->n[0], b->n[1], b->n[2], b->v[0], b->v[1], b->v[2]);
    b->view_below = V_LT(b->n_dot_v, V_SET(0.0f));
    b->n_cross_v[0] = V_SUB(V_MUL(b->n[1], b->v[2]), V_MUL(b->n[2], b->v[1]));
    b->n_cross_v[1] = V_SUB(V_MUL(b->n[2], b->v[0]), V_MUL(b->n[0], b->v[2]));
    /* hbao_rounding_along_normal */
    const VF along = SIMD_ORTHOGRAPHIC
                         ? V_MUL(b->n[2], b->p[2])
                         : SIMD_NAME(dot3)(b->n[0], b->n[1], b->n[2], b->p[0], b->p[1], b->p[2]);
    b->height_tolerance =
        V_MUL(V_SET(g->depth_precision), V_SELECT(V_LT(along, V_SET(0.0f)), along, V_NEG(along)));
    /* hbao_height_plane_setup */
    b->height_across =
        SIMD_ORTHOGRAPHIC ? V_MUL(column, b->n[0]) : V_SUB(V_MUL(column, b->n[0]), b->n[2]);
    b->height_per_pixel = V_MUL(V_SET(g->x_step), b->n[0]);
    b->height_per_row = b->n[1];
    b->height_depth = b->n[2];
    {
        const VF pn0 = V_MUL(b->p[0], b->n[0]), pn1 = V_MUL(b->p[1], b->n[1]);
        const VF pn2 = V_MUL(b->p[2], b->n[2]);
        const VF rounding = V_ADD(V_ADD(V_ABS(pn0), V_ABS(pn1)), V_ABS(pn2));
        b->height_offset = V_ADD(V_ADD(V_ADD(V_ADD(pn0, pn1), pn2), b->height_tolerance),
                                 V_MUL(V_SET(HBAO_HEIGHT_ROUNDING), rounding));
    }
    /* hbao_near_limit */
    b->near_limit = s->thickness > 0.0f ? V_SUB(z, V_SET(s->thickness)) : V_SET(0.0f);
    b->min_thickness = V_SET(HBAO_MIN_BACK_THICKNESS * s->radius);
    return active;
}

/* The lanes whose bits are set in `lanes` (bit k: lane k) */
static inline VM SIMD_NAME(lane_mask)(unsigned lanes) {
    return V_GT(I_TO_F(I_AND(I_SET((int)lanes), I_SLLV(I_SET(1), I_LANES))), V_SET(0.0f));
}

/* Every lane of a block (HBAO_BLOCK_PIXELS bits) */
#define SIMD_ALL_LANES ((1u << HBAO_BLOCK_PIXELS) - 1u)

/* The AO of the lanes `lanes_wanted` (a class: hbao_block_classes; bit k: lane k)
 * of the block of phase a at x0 in row j (its pixels before x1), with the
 * class's step step_px: each direction's steps are planned, then searched.
 * Writes those lanes' pixels only. layers: whether the job has a back
 * layer (job->phase_back), a constant in each of block_ao's copies. */
static inline __attribute__((always_inline)) void
SIMD_NAME(block_ao_copy)(const hbao_horizon_job *job, int x0, int x1, int j, int a, float step_px,
                         unsigned lanes_wanted, const int layers) {
    const hbao_settings *s = job->settings;
    SIMD_NAME(block) b;
    VM active = SIMD_NAME(block_setup)(job, x0, j, a, step_px, &b);
    if (lanes_wanted != SIMD_ALL_LANES) active = M_AND(active, SIMD_NAME(lane_mask)(lanes_wanted));
    const int live = M_ANY(active);
    const int cosine = s->integration == HBAO_INTEGRATION_COSINE;
    VF occlusion_sum = V_SET(0.0f), visible_sum = V_SET(0.0f), open_sum = V_SET(0.0f);
    const int cell = a + 4 * (j & 3);
    const float *direction_cos = job->direction_cos[cell];
    const float *direction_sin = job->direction_sin[cell];
    /* The slices of a group of directions are set up first, one after the
     * other: their chains of square roots and divisions overlap, where a
     * search loop between them would keep each waiting. */
    const int paired = SIMD_PAIRED_DIRECTIONS > 0 && s->directions % 2 == 0 &&
                       s->directions <= SIMD_PAIRED_DIRECTIONS;
    const int group = paired ? SIMD_PAIRED_DIRECTIONS : SIMD_DIRECTION_GROUP;
    for (int first = 0; live && first < s->directions; first += group) {
        const int count = s->directions - first < group ? s->directions - first : group;
        /* The first plans, and their prefetches, before the slices: the
         * depths are asked of the memory that much sooner, and the slices'
         * arithmetic covers some of the wait. scripts/bench_ab_pairs.sh,
         * 1080p, Zen 4 with AVX-512, 25 rounds an order, bit-identical:
         * defaults 0.986 on 1 thread and on 2, half resolution 0.991, 4K
         * 0.968, AVX2 0.993, 8 x 6 + blur 15 0.996, back faces 1.005
         * (session 71; on the Intel Xeon of session 27, 0.992 and 1.000).
         * Later, not sooner: the four plans made before any prefetch took
         * 1.058 on 1 thread, and the plans made before the block's own
         * set-up (its normals' loads then waiting behind the prefetches)
         * 1.018. */
        SIMD_NAME(steps) plans[SIMD_PLAN_AHEAD];
        const float *group_cos = direction_cos + first, *group_sin = direction_sin + first;
        const int by_two = s->steps <= SIMD_LANES / 2; /* two directions a plan_two */
        for (int k = 0; k < count && k < SIMD_PLAN_AHEAD; k += by_two ? 2 : 1) {
            SIMD_NAME(plan_ahead)
            (&b, group_cos, group_sin, k, by_two ? count - k : 1, s->steps, plans);
        }
        SIMD_NAME(slice) slices[SIMD_SLICE_ROOM];
        if (paired) { /* first is 0, count all the directions */
            const int half = count / 2;
            for (int k = 0; k < half; k++) {
                const VF dc = V_SET(direction_cos[k]), ds = V_SET(direction_sin[k]);
                SIMD_NAME(slice_setup)
                (b.v, b.n, b.n_cross_v, b.n_dot_v, dc, ds, cosine, &slices[k], &slices[k + half]);
            }
        } else {
            for (int k = 0; k < count; k++) {
                const VF dc = V_SET(direction_cos[first + k]), ds = V_SET(direction_sin[first + k]);
                SIMD_NAME(slice_setup)
                (b.v, b.n, b.n_cross_v, b.n_dot_v, dc, ds, cosine, &slices[k], NULL);
            }
        }
        for (int k = 0; k < count; k++) {
            const SIMD_NAME(slice) *sl = &slices[k];
            const VM lanes = cosine ? M_AND(active, sl->usable) : active;
            SIMD_NAME(steps) *t = &plans[k % SIMD_PLAN_AHEAD];
            if (by_two) { /* at an even k, k + 2 and k + 3 into the plans of k - 2 and k - 1 */
                if (k >= 2 && k % 2 == 0 && k + 2 < count) {
                    SIMD_NAME(plan_ahead)
                    (&b, group_cos, group_sin, k + 2, count - (k + 2), s->steps, plans);
                }
            } else if (k > 0 && k + SIMD_PLAN_AHEAD - 1 < count) { /* into the plan of k - 1 */
                SIMD_NAME(plan_ahead)
                (&b, group_cos, group_sin, k + SIMD_PLAN_AHEAD - 1, 1, s->steps, plans);
            }
            if (!M_ANY(lanes)) continue;
            if (cosine) {
                VF open;
                const VF occlusion =
                    layers
                        ? SIMD_NAME(direction_occlusion_cosine_layers)(s, &b, lanes, t, sl, &open)
                        : SIMD_NAME(direction_occlusion_cosine)(s, &b, lanes, t, sl, &open);
                visible_sum =
                    V_SELECT(lanes, visible_sum,
                             V_ADD(visible_sum, V_MUL(sl->np_length, V_SUB(open, occlusion))));
                open_sum = V_SELECT(lanes, open_sum, V_ADD(open_sum, V_MUL(sl->np_length, open)));
            } else {
                occlusion_sum =
                    V_ADD(occlusion_sum,
                          layers ? SIMD_NAME(direction_occlusion_hbao_layers)(s, &b, active, t, sl)
                                 : SIMD_NAME(direction_occlusion_hbao)(s, &b, active, t, sl));
            }
        }
    }
    float result[SIMD_LANES];
    if (!live) {
        V_STOREU(result, V_SET(1.0f));
    } else {
        VF ao;
        if (cosine)
            ao = V_SELECT(V_GT(open_sum, V_SET(1e-12f)), V_SET(1.0f), V_DIV(visible_sum, open_sum));
        else
            ao = V_SUB(V_SET(1.0f),
                       V_DIV(occlusion_sum, V_SET((float)s->directions * (1.0f - s->sin_bias))));
        ao = V_ZERO_UNLESS(V_GT(ao, V_SET(0.0f)), ao); /* !(ao > 0) -> 0, NaN included */
        ao = V_SELECT(V_LT(ao, V_SET(1.0f)), V_SET(1.0f), ao);
        ao = V_SELECT(active, V_SET(1.0f), ao);
        V_STOREU(result, ao);
    }
    float *out = job->ao + (size_t)j * job->grid->width;
    for (int k = 0; k < SIMD_LANES; k++) {
        const int i = b.first_i + 4 * k;
        if (i < x1 && (lanes_wanted == SIMD_ALL_LANES || (lanes_wanted >> k & 1u)))
            out[i] = result[k];
    }
}

/* block_ao's two copies, for one depth layer and for two, each with
 * everything inlined and the block's state in registers. Since plan_two
 * (which only a plan of up to half a vector of steps takes) the choices
 * made as the block is searched had made one function's code slower at
 * the defaults, and one copy for each way of planning 1.10 of the time
 * with back faces. Against block_ao as one function before plan_two
 * (bench_ab_pairs.sh, 1080p, Zen 5, plan_two included): the defaults
 * 0.970 on 1 thread and 0.980 on 2, half resolution 0.972, back faces
 * 1.017 (AVX2 0.946). */
static __attribute__((noinline)) void SIMD_NAME(block_ao_one_layer)(const hbao_horizon_job *job,
                                                                    int x0, int x1, int j, int a,
                                                                    float step_px,
                                                                    unsigned lanes_wanted) {
    SIMD_NAME(block_ao_copy)(job, x0, x1, j, a, step_px, lanes_wanted, 0);
}

static __attribute__((noinline)) void SIMD_NAME(block_ao_two_layers)(const hbao_horizon_job *job,
                                                                     int x0, int x1, int j, int a,
                                                                     float step_px,
                                                                     unsigned lanes_wanted) {
    SIMD_NAME(block_ao_copy)(job, x0, x1, j, a, step_px, lanes_wanted, 1);
}

static inline void SIMD_NAME(block_ao)(const hbao_horizon_job *job, int x0, int x1, int j, int a,
                                       float step_px, unsigned lanes_wanted) {
    if (job->phase_back != NULL)
        SIMD_NAME(block_ao_two_layers)(job, x0, x1, j, a, step_px, lanes_wanted);
    else
        SIMD_NAME(block_ao_one_layer)(job, x0, x1, j, a, step_px, lanes_wanted);
}

/* The step of a block that is one class (hbao_block_classes), or
 * HBAO_BLOCK_CLASSES where it is several: its nearest foreground depth, and
 * whether any lies beyond the class it leads, from one load, not 16 strided
 * ones. */
#define HBAO_BLOCK_CLASSES (-2.0f)
static inline float SIMD_NAME(block_step)(const hbao_horizon_job *job, int x0, int j, int a) {
    const VF z = SIMD_NAME(block_depths)(job, x0, j, a);
    const VM foreground = M_AND(V_GT(z, V_SET(0.0f)), V_LT(z, V_SET(INFINITY)));
    /* the least of positive floats and INFINITY: the same in any order.
     * Against the lanes stored and compared one after the other,
     * scripts/bench_ab_pairs.sh, 1080p defaults, Zen 5: 0.994 on 1 and on 2
     * threads, AVX2 0.987 (session 45). */
    const float nearest = V_LEAST(V_SELECT(foreground, V_SET(INFINITY), z));
    const hbao_grid *g = job->grid;
    const float step = hbao_block_step_at(job->settings, g, nearest);
    if (step < 0.0f || g->orthographic) return step;
    const VM beyond = V_GT(z, V_SET(HBAO_BLOCK_DEPTH_RATIO * nearest));
    return M_ANY(M_AND(foreground, beyond)) ? HBAO_BLOCK_CLASSES : step;
}

/* A block of several classes: each class searched with its own step. */
static void SIMD_NAME(block_in_classes)(const hbao_horizon_job *job, int x0, int x1, int j, int a) {
    float z[HBAO_BLOCK_PIXELS], class_step[HBAO_BLOCK_PIXELS];
    unsigned class_lanes[HBAO_BLOCK_PIXELS];
    V_STOREU(z, SIMD_NAME(block_depths)(job, x0, j, a));
    float *out = job->ao + (size_t)j * job->grid->width;
    for (int i = x0 + a; i < x1; i += 4) out[i] = 1.0f; /* the lanes of no class */
    const int classes = hbao_block_classes(job->settings, job->grid, z, class_step, class_lanes);
    for (int c = 0; c < classes; c++) {
        if (class_step[c] < 0.0f) continue; /* no lane sampled: 1, as written */
        SIMD_NAME(block_ao)(job, x0, x1, j, a, class_step[c], class_lanes[c]);
    }
}

/* The span's normals in the next row, which the tile computes next: its
 * blocks load them as their first step, and these rows were written by the
 * normals stage long before. bench_ab, 1080p, four file copies of each
 * build: AVX2 0.964 on 2 threads, 0.971 on 1, half 0.973; AVX-512 1.00
 * (why it gains nothing there is not known). */
static inline void SIMD_NAME(prefetch_normals)(const hbao_grid *g, int x0, int j) {
    if (j >= g->height) return;
    for (int c = 0; c < 3; c++) {
        const char *row = (const char *)(hbao_grid_normal_row(g, j, c) + x0);
        for (int at = 0; at < HBAO_BLOCK_SPAN * (int)sizeof(float); at += 64)
            SIMD_PREFETCH(row + at);
    }
}

static void SIMD_NAME(span)(const hbao_horizon_job *job, int x0, int x1, int j) {
    float *out = job->ao + (size_t)j * job->grid->width;
    SIMD_NAME(prefetch_normals)(job->grid, x0, j + 1);
    float step[4];
    int unsampled = 0;
    for (int a = 0; a < 4; a++) {
        step[a] = SIMD_NAME(block_step)(job, x0, j, a);
        unsampled += step[a] == HBAO_BLOCK_UNSAMPLED;
    }
    if (unsampled == 4) { /* the whole span, in one contiguous run */
        for (int i = x0; i < x1; i++) out[i] = 1.0f;
        return;
    }
    for (int a = 0; a < 4; a++) {
        const float step_px = step[a];
        if (step_px == HBAO_BLOCK_CLASSES) {
            SIMD_NAME(block_in_classes)(job, x0, x1, j, a);
        } else if (step_px < 0.0f) { /* no lane active: block_ao's result, without its set-up */
            for (int i = x0 + a; i < x1; i += 4) out[i] = 1.0f;
        } else {
            SIMD_NAME(block_ao)(job, x0, x1, j, a, step_px, SIMD_ALL_LANES);
        }
    }
}
