/* SPDX-License-Identifier: GPL-2.0-or-later */
/* hbao_params_resolve(): the one place where parameter limits are applied
 * (hbao.h documents them). hbao_compute() and every front end call it. */
#include <math.h>
#include <stddef.h>

#include "internal_hbao.h"

static void clamp_int(int32_t *value, int32_t low, int32_t high, uint32_t field,
                      uint32_t *clamped) {
    if (*value < low || *value > high) {
        *value = *value < low ? low : high;
        *clamped |= field;
    }
}

/* The size of the blur kernel that hbao_blur_kernel_radius gives `size`'s
 * taps (even sizes round down; 0, 1 and 2 are no blur), said in one way:
 * 0 or odd. */
_Static_assert(HBAO_MAX_BLUR_SIZE % 2 == 1, "the largest size is a kernel's, as resolved");
static int32_t canonical_blur_size(int32_t size) {
    const int32_t radius = hbao_blur_kernel_radius(size);
    return radius > 0 ? 2 * radius + 1 : 0;
}

/* NaN and infinities have no nearest legal value: they are invalid. */
static void clamp_float(float *value, float low, float high, uint32_t field, uint32_t *clamped,
                        uint32_t *invalid) {
    if (!isfinite(*value)) {
        *invalid |= field;
    } else if (*value < low || *value > high) {
        *value = *value < low ? low : high;
        *clamped |= field;
    }
}

hbao_result hbao_params_resolve(const hbao_params *in, hbao_params *out, uint32_t *clamped_fields) {
    if (clamped_fields != NULL) *clamped_fields = 0;
    if (in == NULL || out == NULL) return HBAO_ERROR_NULL_ARGUMENT;
    hbao_params p = *in;
    uint32_t clamped = 0, invalid = 0;
    if (!isfinite(p.radius) || p.radius < 0.0f) invalid |= HBAO_PARAM_FIELD_RADIUS;
    if (!isfinite(p.thickness) || p.thickness < 0.0f) invalid |= HBAO_PARAM_FIELD_THICKNESS;
    clamp_float(&p.angle_bias_degrees, 0.0f, HBAO_MAX_ANGLE_BIAS_DEGREES,
                HBAO_PARAM_FIELD_ANGLE_BIAS_DEGREES, &clamped, &invalid);
    clamp_int(&p.directions, 1, HBAO_MAX_DIRECTIONS, HBAO_PARAM_FIELD_DIRECTIONS, &clamped);
    clamp_int(&p.steps, 1, HBAO_MAX_STEPS, HBAO_PARAM_FIELD_STEPS, &clamped);
    if (p.falloff != HBAO_FALLOFF_QUADRATIC && p.falloff != HBAO_FALLOFF_NONE)
        invalid |= HBAO_PARAM_FIELD_FALLOFF;
    if (p.integration != HBAO_INTEGRATION_HBAO && p.integration != HBAO_INTEGRATION_COSINE)
        invalid |= HBAO_PARAM_FIELD_INTEGRATION;
    clamp_int(&p.blur_size, 0, HBAO_MAX_BLUR_SIZE, HBAO_PARAM_FIELD_BLUR_SIZE, &clamped);
    clamp_float(&p.blur_sharpness, 0.0f, HBAO_MAX_BLUR_SHARPNESS, HBAO_PARAM_FIELD_BLUR_SHARPNESS,
                &clamped, &invalid);
    /* A setting written in more than one way comes back in one, so that
     * what compares settings (the CLI's sequence stamp, the add-on's AO
     * cache) finds them equal: a blur size as its kernel's, no sharpness
     * (nor its clamp's warning) where nothing is blurred, and -0 as 0 (the
     * stamp prints "-0"). */
    p.blur_size = canonical_blur_size(p.blur_size);
    if (p.blur_size == 0 && isfinite(p.blur_sharpness)) {
        p.blur_sharpness = 0.0f;
        clamped &= ~(uint32_t)HBAO_PARAM_FIELD_BLUR_SHARPNESS;
    }
    p.half_resolution = p.half_resolution != 0;
    float *const floats[] = {&p.radius, &p.angle_bias_degrees, &p.blur_sharpness, &p.strength,
                             &p.thickness};
    for (size_t k = 0; k < sizeof floats / sizeof floats[0]; k++)
        if (*floats[k] == 0.0f) *floats[k] = 0.0f;
    clamp_float(&p.strength, 0.0f, HBAO_MAX_STRENGTH, HBAO_PARAM_FIELD_STRENGTH, &clamped,
                &invalid);
    /* 0 means one thread per core, and so does any negative count. */
    if (p.threads < 0) p.threads = 0;
    clamp_int(&p.threads, 0, HBAO_MAX_THREADS, HBAO_PARAM_FIELD_THREADS, &clamped);
    /* +infinity is a legal background depth: nothing is background. */
    if (isnan(p.background_depth) || !(p.background_depth > 0.0f))
        invalid |= HBAO_PARAM_FIELD_BACKGROUND_DEPTH;
    if (p.implementation < HBAO_IMPLEMENTATION_AUTO ||
        p.implementation >= HBAO_IMPLEMENTATION_COUNT)
        invalid |= HBAO_PARAM_FIELD_IMPLEMENTATION;
    if (invalid != 0) {
        if (clamped_fields != NULL) *clamped_fields = invalid;
        return HBAO_ERROR_INVALID_PARAMETER;
    }
    if (clamped_fields != NULL) *clamped_fields = clamped;
    *out = p;
    return HBAO_SUCCESS;
}

const char *hbao_param_field_name(uint32_t bit) {
    switch (bit) {
#define HBAO_PARAM_FIELD_NAME_CASE(name, bit_index, text)                                          \
    case name:                                                                                     \
        return text;
        HBAO_PARAM_FIELD_LIST(HBAO_PARAM_FIELD_NAME_CASE)
#undef HBAO_PARAM_FIELD_NAME_CASE
        default:
            return NULL;
    }
}
