/* SPDX-License-Identifier: GPL-2.0-or-later */
/* A pass of the blur over a row of centres, BLUR_LANES pixels at a time in
 * GCC vector types, and the row job that runs it: written once for every
 * instruction set, blur.c includes this header once per copy, after
 * defining BLUR_LANES (the lanes of a vector), BLUR_NAME(x) (the copy's
 * names) and BLUR_TARGET (its instruction set's function attribute, or
 * nothing). Every operation is blur_pixel's (blur.c), lane by lane and
 * never contracted into an FMA, so every copy gives the same floats as the
 * scalar reference (test_blur.c compares them). */

/* GCC and clang warn that passing these vectors by value differs between
 * instruction sets; the helpers are always inlined, so no call passes one. */
#pragma GCC diagnostic ignored "-Wpsabi"
typedef float BLUR_NAME(vfloat) __attribute__((vector_size(4 * BLUR_LANES)));
typedef int32_t BLUR_NAME(vint) __attribute__((vector_size(4 * BLUR_LANES)));
#define VF BLUR_NAME(vfloat)
#define VI BLUR_NAME(vint)

static HBAO_ALWAYS_INLINE VF BLUR_NAME(load)(const float *p) {
    VF v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* mask ? a : b, mask lanes all ones or zero */
static HBAO_ALWAYS_INLINE VF BLUR_NAME(select)(VI mask, VF a, VF b) {
    return (VF)((mask & (VI)a) | (~mask & (VI)b));
}

/* m ? x : 0, m lanes all ones or zero */
static HBAO_ALWAYS_INLINE VF BLUR_NAME(zero_unless)(VI m, VF x) {
    return (VF)(m & (VI)x);
}

/* hbao_blur_falloff, lane by lane: a loop of BLUR_LANES iterations that the
 * compiler vectorizes, so that the function is written once. */
static HBAO_ALWAYS_INLINE VF BLUR_NAME(falloff)(VF x) {
    float in[BLUR_LANES], out[BLUR_LANES];
    memcpy(in, &x, sizeof in);
    for (int l = 0; l < BLUR_LANES; l++) out[l] = hbao_blur_falloff(in[l]);
    VF result;
    memcpy(&result, out, sizeof result);
    return result;
}

/* blur_pixel for pixels i .. i + BLUR_LANES - 1, all of whose taps lie
 * inside the row. */
static HBAO_ALWAYS_INLINE void BLUR_NAME(lanes)(const tap_set *taps, const centre_row *c,
                                                float sharpness, int i, float *target) {
    const VF zero = {0.0f}, one = zero + 1.0f;
    const VF zc = BLUR_NAME(load)(c->z + i);
    const VI geometry = zc > 0.0f;
    const VF scaled = BLUR_NAME(select)(geometry, sharpness / zc, zero);
    const VF factor = BLUR_NAME(select)(scaled < FLT_MAX, scaled, zero + FLT_MAX);
    const VF cx = BLUR_NAME(load)(c->nx + i), cy = BLUR_NAME(load)(c->ny + i),
             cz = BLUR_NAME(load)(c->nz + i);
    VF sum = BLUR_NAME(load)(c->ao + i), weight_sum = one;
    for (int t = 0; t < taps->count; t++) {
        const int at = i + taps->offset[t];
        const VF z = BLUR_NAME(load)(taps->z[t] + at);
        const VF difference = (z - zc) * factor;
        const VF facing = BLUR_NAME(load)(taps->nx[t] + at) * cx +
                          BLUR_NAME(load)(taps->ny[t] + at) * cy +
                          BLUR_NAME(load)(taps->nz[t] + at) * cz;
        const VF bend = 1.0f - facing;
        const VF exponent =
            difference * difference + HBAO_BLUR_NORMAL_SHARPNESS * (VF)((VI)bend & (bend > 0.0f));
        /* blur_pixel's "* valid": the product is finite, so times 1 is itself */
        const VF weight =
            BLUR_NAME(zero_unless)(z > 0.0f, taps->spatial[t] * BLUR_NAME(falloff)(exponent));
        sum += weight * BLUR_NAME(load)(taps->ao[t] + at);
        weight_sum += weight;
    }
    const VF blurred = BLUR_NAME(select)(geometry, sum / weight_sum, one);
    memcpy(target + i, &blurred, sizeof blurred);
}

/* The copy's blur_pass_fn (blur.c): the vector loop where every tap lies
 * inside the row, blur_pixel at the ends. */
static HBAO_ALWAYS_INLINE void BLUR_NAME(blur_pass)(const tap_set *taps, const centre_row *c,
                                                    float sharpness, int width, int radius,
                                                    float *target) {
    const int first = taps->along_row ? radius : 0;
    const int last = taps->along_row ? width - radius : width; /* vector lanes in [first, last) */
    int i = 0;
    for (; i < first && i < width; i++) target[i] = blur_pixel(taps, c, sharpness, width, i);
    for (; i + BLUR_LANES <= last; i += BLUR_LANES) BLUR_NAME(lanes)(taps, c, sharpness, i, target);
    for (; i < width; i++) target[i] = blur_pixel(taps, c, sharpness, width, i);
}

/* The copy's row job: blur.c's finish_band with this copy's pass inlined. */
BLUR_TARGET static void BLUR_NAME(finish_band)(void *context, int band) {
    finish_band(context, band, BLUR_NAME(blur_pass));
}

#undef VF
#undef VI
#undef BLUR_LANES
#undef BLUR_NAME
#undef BLUR_TARGET
