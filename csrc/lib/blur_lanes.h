/* SPDX-License-Identifier: GPL-2.0-or-later */
/* A pass of the blur over a row of centres, BLUR_LANES pixels at a time in
 * GCC vector types, and the band job that runs it: written once for every
 * instruction set, blur.c includes this header once per copy, after
 * defining BLUR_LANES (the lanes of a vector), BLUR_GROUPS (how many
 * vectors a step of the loop takes side by side), BLUR_SKIPS_CHECK (1: a
 * row whose background taps weigh 0 by themselves skips the test for them,
 * blur.c's background_needs_check; 0: every row tests, as the scalar
 * reference, which the tests hold the others to), BLUR_NAME(x) (the copy's
 * names), BLUR_TARGET (its instruction set's function attribute, or
 * nothing) and, optionally, BLUR_MIN and BLUR_MAX (the instruction set's
 * minimum and maximum of two vectors of BLUR_LANES floats: a < b ? a : b
 * and a > b ? a : b, b where either is NaN). Every operation is
 * blur_pixel's (blur.c), lane by lane and never contracted into an FMA
 * (the background test, where it is skipped, changes no float), so every
 * copy gives the same floats as the scalar reference. test_blur.c
 * compares the copies with each other, and each copy's blur_pixel with its
 * vector loop (blur_pixel_and_the_vector_loop_agree). */

/* GCC and clang warn that passing these vectors by value differs between
 * instruction sets; the helpers are always inlined, so no call passes one. */
#pragma GCC diagnostic ignored "-Wpsabi"
typedef float BLUR_NAME(vfloat) __attribute__((vector_size(4 * BLUR_LANES)));
typedef int32_t BLUR_NAME(vint) __attribute__((vector_size(4 * BLUR_LANES)));
#define VF BLUR_NAME(vfloat)
#define VI BLUR_NAME(vint)

BLUR_TARGET static HBAO_ALWAYS_INLINE VF BLUR_NAME(load)(const float *p) {
    VF v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* mask ? a : b, mask lanes all ones or zero */
BLUR_TARGET static HBAO_ALWAYS_INLINE VF BLUR_NAME(select)(VI mask, VF a, VF b) {
    return (VF)((mask & (VI)a) | (~mask & (VI)b));
}

/* m ? x : 0, m lanes all ones or zero */
BLUR_TARGET static HBAO_ALWAYS_INLINE VF BLUR_NAME(zero_unless)(VI m, VF x) {
    return (VF)(m & (VI)x);
}

/* min(a, b) as blur_pixel's a < b ? a : b, lane by lane */
BLUR_TARGET static HBAO_ALWAYS_INLINE VF BLUR_NAME(min)(VF a, VF b) {
#ifdef BLUR_MIN
    return (VF)BLUR_MIN(a, b);
#else
    return BLUR_NAME(select)(a < b, a, b);
#endif
}

/* hbao_blur_power, lane by lane */
BLUR_TARGET static HBAO_ALWAYS_INLINE VF BLUR_NAME(power)(VF base) {
#ifdef BLUR_MAX
    const VF zero = {0.0f};
    VF power = (VF)BLUR_MAX(base, zero);
#else
    VF power = BLUR_NAME(zero_unless)(base > 0.0f, base);
#endif
    power *= power; /* ^2 */
    power *= power; /* ^4 */
    power *= power; /* ^8 */
    return power * power;
}

/* blur_pixel for pixels i .. i + groups * BLUR_LANES - 1, all of whose
 * taps lie inside the row, as `groups` vectors side by side. along_row is
 * taps->along_row as a constant, so that each pass loads only the steps it
 * has: along a row one per tap, down a column two and the AO's row. check
 * is a constant too (blur_pass decides it), so that a row whose background
 * taps weigh 0 by themselves (background_needs_check, blur.c) skips the
 * test. A tap's weight is a chain of some fifteen dependent
 * operations (four of them the power's squarings); with one vector the
 * processor cannot hold enough taps in flight to keep its multipliers
 * busy, and two vectors whose chains interleave keep more of them in
 * flight (blur.c says where it pays). The groups are independent, so the
 * result is the same for any count. */
BLUR_TARGET static HBAO_ALWAYS_INLINE void BLUR_NAME(lanes)(const tap_set *taps,
                                                            const centre_row *c, float sharpness,
                                                            int i, float *target, int along_row,
                                                            int check, int groups) {
    const VF zero = {0.0f}, one = zero + 1.0f;
    VF zc[BLUR_GROUPS], factor[BLUR_GROUPS], cx[BLUR_GROUPS], cy[BLUR_GROUPS], cz[BLUR_GROUPS];
    VF sum[BLUR_GROUPS], weight_sum[BLUR_GROUPS];
    for (int g = 0; g < groups; g++) {
        const int at = i + g * BLUR_LANES;
        zc[g] = BLUR_NAME(load)(c->z + at);
        const VF scaled = BLUR_NAME(select)(zc[g] > 0.0f, sharpness / zc[g], zero);
        factor[g] =
            BLUR_NAME(select)(scaled < FLT_MAX, scaled, zero + FLT_MAX) * HBAO_BLUR_DEPTH_WEIGHT;
        cx[g] = BLUR_NAME(load)(c->nx + at) * HBAO_BLUR_NORMAL_WEIGHT;
        cy[g] = BLUR_NAME(load)(c->ny + at) * HBAO_BLUR_NORMAL_WEIGHT;
        cz[g] = BLUR_NAME(load)(c->nz + at) * HBAO_BLUR_NORMAL_WEIGHT;
        sum[g] = BLUR_NAME(load)(c->ao + at);
        weight_sum[g] = one;
    }
    for (int t = 0; t < taps->count; t++) {
        for (int g = 0; g < groups; g++) {
            const int centre = i + g * BLUR_LANES;
            const int at = centre + taps->depth_step[t];
            const int normal_at = along_row ? at : centre + taps->normal_step[t];
            const VF z = BLUR_NAME(load)(c->z + at);
            const VF difference = (z - zc[g]) * factor[g];
            const VF facing = BLUR_NAME(load)(c->nx + normal_at) * cx[g] +
                              BLUR_NAME(load)(c->ny + normal_at) * cy[g] +
                              BLUR_NAME(load)(c->nz + normal_at) * cz[g];
            const VF capped = BLUR_NAME(min)(facing, zero + HBAO_BLUR_NORMAL_WEIGHT);
            const VF base = (1.0f - HBAO_BLUR_NORMAL_WEIGHT + capped) - difference * difference;
            /* blur_pixel's "* valid": the product is finite, so times 1 is itself */
            const VF unchecked = taps->spatial[t] * BLUR_NAME(power)(base);
            const VF weight = check ? BLUR_NAME(zero_unless)(z > 0.0f, unchecked) : unchecked;
            sum[g] += weight * BLUR_NAME(load)(along_row ? c->ao + at : taps->ao[t] + centre);
            weight_sum[g] += weight;
        }
    }
    for (int g = 0; g < groups; g++) {
        const VF blurred = BLUR_NAME(select)(zc[g] > 0.0f, sum[g] / weight_sum[g], one);
        memcpy(target + i + g * BLUR_LANES, &blurred, sizeof blurred);
    }
}

/* The vector loop of a pass over pixels i .. last - 1, as far as whole
 * vectors go: groups of vectors, then single ones. Returns the first pixel
 * left. along_row and check are constants (BLUR_NAME(lanes)). */
BLUR_TARGET static HBAO_ALWAYS_INLINE int BLUR_NAME(vectors)(const tap_set *taps,
                                                             const centre_row *c, float sharpness,
                                                             int i, int last, float *target,
                                                             int along_row, int check) {
    for (; i + BLUR_GROUPS * BLUR_LANES <= last; i += BLUR_GROUPS * BLUR_LANES)
        BLUR_NAME(lanes)(taps, c, sharpness, i, target, along_row, check, BLUR_GROUPS);
    for (; i + BLUR_LANES <= last; i += BLUR_LANES)
        BLUR_NAME(lanes)(taps, c, sharpness, i, target, along_row, check, 1);
    return i;
}

/* One pass over a row of centres into target: the vector loop where every
 * tap lies inside the row, blur_pixel (blur.c) at the ends. */
BLUR_TARGET static HBAO_ALWAYS_INLINE void BLUR_NAME(blur_pass)(const tap_set *taps,
                                                                const centre_row *c,
                                                                float sharpness, int width,
                                                                int radius, float *target) {
    const int first = taps->along_row ? radius : 0;
    const int last = taps->along_row ? width - radius : width; /* vector lanes in [first, last) */
    int i = 0;
    for (; i < first && i < width; i++) target[i] = blur_pixel(taps, c, sharpness, width, i);
    /* a constant 1 where the copy never skips: no scan of the row then */
    const int check = !BLUR_SKIPS_CHECK || background_needs_check(c->z, width, sharpness);
    if (taps->along_row)
        i = check ? BLUR_NAME(vectors)(taps, c, sharpness, i, last, target, 1, 1)
                  : BLUR_NAME(vectors)(taps, c, sharpness, i, last, target, 1, 0);
    else
        i = check ? BLUR_NAME(vectors)(taps, c, sharpness, i, last, target, 0, 1)
                  : BLUR_NAME(vectors)(taps, c, sharpness, i, last, target, 0, 0);
    for (; i < width; i++) target[i] = blur_pixel(taps, c, sharpness, width, i);
}

/* The copy's job for one band of output rows: each row is made (blurred
 * along itself into the ring) once a column pass needs it, then the band's
 * rows are blurred down their columns and written out. */
BLUR_TARGET static void BLUR_NAME(finish_band)(void *context, int band) {
    finish_job *job = context;
    const int width = job->width, radius = job->radius, height = job->height;
    const int slots = 2 * radius + 1;
    const int first = band * job->band_rows;
    const int last = first + job->band_rows < height ? first + job->band_rows : height;
    band_memory m;
    const int set = band_memory_take(job, &m, slots);
    tap_set taps;
    centre_row c;
    int next = first - radius > 0 ? first - radius : 0; /* the next row to make */
    for (int j = first; j < last; j++) {
        const int needed = j + radius < height ? j + radius : height - 1;
        for (; next <= needed; next++) {
            float *slot = m.ring[next % slots];
            if (radius == 0) {
                memcpy(slot, job->grid_ao + (size_t)next * width, (size_t)width * sizeof(float));
                continue;
            }
            row_pass(job, next, &taps, &c);
            BLUR_NAME(blur_pass)(&taps, &c, job->sharpness, width, radius, slot);
        }
        const float *blurred = m.ring[j % slots];
        if (radius > 0) {
            column_pass(job, &m, j, &taps, &c);
            BLUR_NAME(blur_pass)(&taps, &c, job->sharpness, width, radius, m.finished);
            blurred = m.finished;
        }
        write_output(job->depth + (size_t)j * width, blurred, width, job->strength,
                     job->out + (int64_t)j * job->out_row_stride);
    }
    band_memory_give(job, set);
}

#undef VF
#undef VI
#undef BLUR_LANES
#undef BLUR_GROUPS
#undef BLUR_SKIPS_CHECK
#undef BLUR_NAME
#undef BLUR_TARGET
#undef BLUR_MIN
#undef BLUR_MAX
