/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The public API's contract: result codes for bad arguments, clamping of
 * out-of-range parameters, messages, version and struct sizes. */
#include <pthread.h>
#include <stdint.h>
#include <string.h>

#include "hbao.h"
#include "test_harness.h"

#define W 16
#define H 12

static float depth[W * H];
static float normal[W * H * 3];
static float ao[W * H];

static void fill_inputs(void) {
    for (int k = 0; k < W * H; k++) {
        depth[k] = 3.0f + 0.1f * (float)(k % W);
        normal[3 * k] = 0.0f;
        normal[3 * k + 1] = 0.0f;
        normal[3 * k + 2] = 1.0f;
    }
}

/* One clampable field: set below (high = 0) or above (high = 1) its range,
 * and read back. */
#define FIELD_CASES(X)                                                                             \
    X(HBAO_PARAM_FIELD_ANGLE_BIAS_DEGREES, angle_bias_degrees, -5.0f, 90.0f, 0.0,                  \
      HBAO_MAX_ANGLE_BIAS_DEGREES)                                                                 \
    X(HBAO_PARAM_FIELD_DIRECTIONS, directions, 0, 1000, 1, HBAO_MAX_DIRECTIONS)                    \
    X(HBAO_PARAM_FIELD_STEPS, steps, -7, 500, 1, HBAO_MAX_STEPS)                                   \
    X(HBAO_PARAM_FIELD_BLUR_SIZE, blur_size, -1, 99, 0, HBAO_MAX_BLUR_SIZE)                        \
    X(HBAO_PARAM_FIELD_BLUR_SHARPNESS, blur_sharpness, -1.0f, 1e6f, 0.0, HBAO_MAX_BLUR_SHARPNESS)  \
    X(HBAO_PARAM_FIELD_STRENGTH, strength, -0.5f, 17.0f, 0.0, HBAO_MAX_STRENGTH)

#define FIELD_ACCESSORS(bit, member, low_value, high_value, low_limit, high_limit)                 \
    static void set_##member(hbao_params *p, int high) {                                           \
        p->member = high ? (high_value) : (low_value);                                             \
    }                                                                                              \
    static double get_##member(const hbao_params *p) {                                             \
        return (double)p->member;                                                                  \
    }
FIELD_CASES(FIELD_ACCESSORS)
#undef FIELD_ACCESSORS

static hbao_result compute_with(const hbao_params *p, const hbao_camera *c) {
    hbao_channel d = {depth, 1, W};
    return hbao_compute(p, c, W, H, &d, NULL, ao, W);
}

TEST_CASE(null_arguments_are_rejected) {
    fill_inputs();
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    hbao_camera c = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_channel d = {depth, 1, W};
    hbao_channel no_data = {NULL, 1, W};
    CHECK_RESULT(hbao_compute(NULL, &c, W, H, &d, NULL, ao, W), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_compute(&p, NULL, W, H, &d, NULL, ao, W), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_compute(&p, &c, W, H, NULL, NULL, ao, W), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &no_data, NULL, ao, W), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &d, NULL, NULL, W), HBAO_ERROR_NULL_ARGUMENT);
    /* a normal channel without data means "reconstruct" */
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &d, &no_data, ao, W), HBAO_SUCCESS);
}

TEST_CASE(sizes_and_strides_are_checked) {
    fill_inputs();
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    hbao_camera c = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_channel d = {depth, 1, W};
    CHECK_RESULT(hbao_compute(&p, &c, 0, H, &d, NULL, ao, W), HBAO_ERROR_INVALID_SIZE);
    CHECK_RESULT(hbao_compute(&p, &c, W, -1, &d, NULL, ao, W), HBAO_ERROR_INVALID_SIZE);
    CHECK_RESULT(hbao_compute(&p, &c, 70000, 1, &d, NULL, ao, W), HBAO_ERROR_INVALID_SIZE);
    hbao_channel overlapping = {depth, 1, W - 1};
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &overlapping, NULL, ao, W), HBAO_ERROR_INVALID_STRIDE);
    hbao_channel zero_pixel_stride = {depth, 0, W};
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &zero_pixel_stride, NULL, ao, W),
                 HBAO_ERROR_INVALID_STRIDE);
    hbao_channel thin_normals = {normal, 2, 3 * W};
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &d, &thin_normals, ao, W), HBAO_ERROR_INVALID_STRIDE);
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &d, NULL, ao, W - 1), HBAO_ERROR_INVALID_STRIDE);
    /* strides that put the last row past int64_t's offsets: the most
     * negative one, whose magnitude int64_t cannot hold (UBSan, in the
     * sanitizer run, sees how it is compared), and the largest */
    hbao_channel most_negative = {depth, 1, INT64_MIN};
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &most_negative, NULL, ao, W),
                 HBAO_ERROR_INVALID_STRIDE);
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &d, NULL, ao + (size_t)(H - 1) * W, INT64_MIN),
                 HBAO_ERROR_INVALID_STRIDE);
    hbao_channel largest = {depth, 1, INT64_MAX};
    CHECK_RESULT(hbao_compute(&p, &c, W, H, &largest, NULL, ao, W), HBAO_ERROR_INVALID_STRIDE);
    /* a single row may use any row stride */
    CHECK_RESULT(hbao_compute(&p, &c, W, 1, &d, NULL, ao, 0), HBAO_SUCCESS);
}

TEST_CASE(invalid_parameters_are_rejected) {
    fill_inputs();
    hbao_camera c = HBAO_CAMERA_DEFAULT_INITIALIZER;
    const hbao_params defaults = HBAO_PARAMS_DEFAULT_INITIALIZER;
    hbao_params p = defaults;
    p.radius = NAN;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.radius = -1.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.radius = INFINITY;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.strength = NAN;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.angle_bias_degrees = INFINITY;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.blur_sharpness = NAN;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.background_depth = 0.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.falloff = 7;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.integration = -1;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
    p = defaults;
    p.implementation = HBAO_IMPLEMENTATION_COUNT;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_PARAMETER);
}

TEST_CASE(invalid_cameras_are_rejected) {
    fill_inputs();
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    const hbao_camera defaults = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_camera c = defaults;
    c.lens = 0.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_CAMERA);
    c = defaults;
    c.sensor_width = NAN;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_CAMERA);
    c = defaults;
    c.projection = HBAO_PROJECTION_ORTHOGRAPHIC;
    c.ortho_scale = -2.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_CAMERA);
    c = defaults;
    c.pixel_aspect_y = 0.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_CAMERA);
    c = defaults;
    c.sensor_fit = 3;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_CAMERA);
    c = defaults;
    memset(c.world_to_camera, 0, sizeof c.world_to_camera);
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_CAMERA);
    c = defaults;
    c.shift_x = INFINITY;
    CHECK_RESULT(compute_with(&p, &c), HBAO_ERROR_INVALID_CAMERA);
    /* orthographic cameras do not need a lens */
    c = defaults;
    c.projection = HBAO_PROJECTION_ORTHOGRAPHIC;
    c.lens = 0.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_SUCCESS);
}

/* AO of the W x H test plane with given normals (all tilted, so that the
 * matrix matters) under camera c. */
static hbao_result compute_with_normals(const hbao_camera *c, float *out) {
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.threads = 1;
    hbao_channel d = {depth, 1, W};
    hbao_channel n = {normal, 3, 3 * W};
    for (int k = 0; k < W * H; k++) {
        normal[3 * k] = 0.6f;
        normal[3 * k + 1] = 0.0f;
        normal[3 * k + 2] = 0.8f;
    }
    return hbao_compute(&p, c, W, H, &d, &n, out, W);
}

/* Issue 13: a rotation scaled by 1e-5 is invertible and must be accepted;
 * only the matrix's direction matters, so the AO is that of the unscaled
 * rotation up to the float rounding of the renormalised normals. */
TEST_CASE(world_to_camera_check_is_scale_free) {
    fill_inputs();
    /* A rotation by 30 degrees about Y. */
    const float cosine = 0.8660254f, sine = 0.5f;
    const float rotation[16] = {cosine, 0, sine, 0, 0, 1, 0, 0, -sine, 0, cosine, 0, 0, 0, 0, 1};
    hbao_camera c = HBAO_CAMERA_DEFAULT_INITIALIZER;
    static float reference[W * H], scaled_ao[W * H];
    memcpy(c.world_to_camera, rotation, sizeof rotation);
    CHECK_RESULT(compute_with_normals(&c, reference), HBAO_SUCCESS);
    const float scales[] = {1e-5f, 1e-12f, 1e5f, 1e12f};
    for (size_t s = 0; s < sizeof scales / sizeof scales[0]; s++) {
        for (int k = 0; k < 12; k++) c.world_to_camera[k] = rotation[k] * scales[s];
        CHECK_RESULT(compute_with_normals(&c, scaled_ao), HBAO_SUCCESS);
        /* Scaling changes each normal by a few float ulps (2^-24 relative)
         * before renormalising; AO moves by a small multiple of that. 1e-5
         * is far above it and far below an 8-bit step (3.9e-3). */
        double worst = 0.0;
        for (int k = 0; k < W * H; k++) {
            /* a NaN is kept (fmax would drop it), and this loop, unlike an
             * fmax reduction, does not crash aarch64 GCC 12's vectorizer */
            const double difference = fabs(scaled_ao[k] - reference[k]);
            if (!(difference <= worst)) worst = difference;
        }
        CHECK_NEAR(worst, 0.0, 1e-5);
    }
    /* Singular: two equal rows, a zero row, the zero matrix; at any scale. */
    const float singular_rows[3][12] = {
        {1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0},
        {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0},
        {1e-5f, 0, 0, 0, 0, 1e-5f, 0, 0, 1e-5f, 1e-5f, 0, 0},
    };
    for (int m = 0; m < 3; m++) {
        memcpy(c.world_to_camera, singular_rows[m], sizeof singular_rows[m]);
        CHECK_RESULT(compute_with_normals(&c, scaled_ao), HBAO_ERROR_INVALID_CAMERA);
    }
    /* Beyond float's range for the normal transform (camera.c's row limits). */
    for (int k = 0; k < 12; k++) c.world_to_camera[k] = rotation[k] * 1e-20f;
    CHECK_RESULT(compute_with_normals(&c, scaled_ao), HBAO_ERROR_INVALID_CAMERA);
}

/* hbao_params_resolve(): each out-of-range field comes back at its limit,
 * with its bit and no other; exact, the limits are constants. */
TEST_CASE(params_resolve_clamps_each_field_and_names_it) {
    const hbao_params defaults = HBAO_PARAMS_DEFAULT_INITIALIZER;
    hbao_params in = defaults, out;
    uint32_t fields = 0xffffffffu;
    CHECK_RESULT(hbao_params_resolve(&in, &out, &fields), HBAO_SUCCESS);
    CHECK(fields == 0);
    CHECK(memcmp(&in, &out, sizeof in) == 0);

    struct {
        uint32_t field;
        void (*set)(hbao_params *, int high);
        double (*get)(const hbao_params *);
        double low_limit, high_limit;
    } cases[] = {
#define FIELD_CASE(bit, member, low_value, high_value, low_limit, high_limit)                      \
    {bit, set_##member, get_##member, low_limit, high_limit},
        FIELD_CASES(FIELD_CASE)
#undef FIELD_CASE
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        for (int high = 0; high <= 1; high++) {
            in = defaults;
            cases[k].set(&in, high);
            fields = 0;
            CHECK_RESULT(hbao_params_resolve(&in, &out, &fields), HBAO_SUCCESS);
            CHECK(fields == cases[k].field);
            CHECK(cases[k].get(&out) == (high ? cases[k].high_limit : cases[k].low_limit));
            /* the other fields are untouched, but for the sharpness of no
             * blur (params_resolve_says_one_setting_one_way) */
            cases[k].set(&out, high);
            if (out.blur_sharpness == 0.0f && in.blur_size < 3)
                out.blur_sharpness = in.blur_sharpness;
            CHECK(memcmp(&in, &out, sizeof in) == 0);
        }
        CHECK(hbao_param_field_name(cases[k].field) != NULL);
    }
    /* Several at once; `out` may be `in`. */
    in = defaults;
    in.steps = 500;
    in.blur_size = -3;
    CHECK_RESULT(hbao_params_resolve(&in, &in, &fields), HBAO_SUCCESS);
    CHECK(fields == (HBAO_PARAM_FIELD_STEPS | HBAO_PARAM_FIELD_BLUR_SIZE));
    CHECK(in.steps == HBAO_MAX_STEPS && in.blur_size == 0);
    /* Threads have only an upper limit: negative means "one per core", like
     * 0, and needs no warning. */
    in = defaults;
    in.threads = 100000;
    CHECK_RESULT(hbao_params_resolve(&in, &out, &fields), HBAO_SUCCESS);
    CHECK(fields == HBAO_PARAM_FIELD_THREADS && out.threads == HBAO_MAX_THREADS);
    in = defaults;
    in.threads = -4;
    in.half_resolution = 7;
    CHECK_RESULT(hbao_params_resolve(&in, &out, &fields), HBAO_SUCCESS);
    CHECK(fields == 0 && out.threads == 0 && out.half_resolution == 1);

    CHECK(strcmp(hbao_param_field_name(HBAO_PARAM_FIELD_STEPS), "steps") == 0);
    CHECK(strcmp(hbao_param_field_name(HBAO_PARAM_FIELD_RADIUS), "radius") == 0);
    CHECK(strcmp(hbao_param_field_name(HBAO_PARAM_FIELD_IMPLEMENTATION), "implementation") == 0);
    CHECK(hbao_param_field_name(0) == NULL);
    CHECK(hbao_param_field_name(HBAO_PARAM_FIELD_STEPS | HBAO_PARAM_FIELD_RADIUS) == NULL);
    CHECK(hbao_param_field_name(1u << 31) == NULL);
}

/* Settings that compute the same AO resolve to the same values, without a
 * bit: the blur size as 0 or odd (even sizes round down; 0 to 2 are no
 * blur), and the sharpness of no blur as 0, whatever it was (above its
 * limit too: no warning for a value that does nothing). The CLI's sequence
 * stamp and the add-on's AO cache compare resolved values. */
TEST_CASE(params_resolve_says_one_setting_one_way) {
    const hbao_params defaults = HBAO_PARAMS_DEFAULT_INITIALIZER;
    const struct {
        int32_t size;
        float sharpness;
        int32_t resolved_size;
        float resolved_sharpness;
        uint32_t fields;
    } cases[] = {
        {0, 32.0f, 0, 0.0f, 0},
        {1, 8.0f, 0, 0.0f, 0},
        {2, 1e6f, 0, 0.0f, 0},
        {-5, 7.0f, 0, 0.0f, HBAO_PARAM_FIELD_BLUR_SIZE},
        {3, 8.0f, 3, 8.0f, 0},
        {6, 8.0f, 5, 8.0f, 0},
        {64, 1e6f, 63, HBAO_MAX_BLUR_SHARPNESS, HBAO_PARAM_FIELD_BLUR_SHARPNESS},
        {HBAO_MAX_BLUR_SIZE + 1, 0.0f, HBAO_MAX_BLUR_SIZE, 0.0f, HBAO_PARAM_FIELD_BLUR_SIZE},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        hbao_params in = defaults, out;
        uint32_t fields = 0xffffffffu;
        in.blur_size = cases[k].size;
        in.blur_sharpness = cases[k].sharpness;
        CHECK_RESULT(hbao_params_resolve(&in, &out, &fields), HBAO_SUCCESS);
        CHECK(out.blur_size == cases[k].resolved_size);
        CHECK(out.blur_sharpness == cases[k].resolved_sharpness);
        CHECK(fields == cases[k].fields);
        /* resolving is idempotent */
        hbao_params again;
        CHECK_RESULT(hbao_params_resolve(&out, &again, &fields), HBAO_SUCCESS);
        CHECK(fields == 0 && memcmp(&out, &again, sizeof out) == 0);
    }
    /* -0 comes back as 0 (the CLI's stamp prints "-0") */
    hbao_params in = defaults, out;
    uint32_t fields;
    in.radius = -0.0f;
    in.angle_bias_degrees = -0.0f;
    in.blur_sharpness = -0.0f;
    in.strength = -0.0f;
    in.thickness = -0.0f;
    CHECK_RESULT(hbao_params_resolve(&in, &out, &fields), HBAO_SUCCESS);
    CHECK(fields == 0);
    CHECK(!signbit(out.radius) && !signbit(out.angle_bias_degrees) &&
          !signbit(out.blur_sharpness) && !signbit(out.strength) && !signbit(out.thickness));
    CHECK(out.radius == 0.0f && out.blur_sharpness == 0.0f && out.thickness == 0.0f);
    /* A NaN sharpness is refused with or without blur. */
    in = defaults;
    in.blur_size = 0;
    in.blur_sharpness = NAN;
    CHECK_RESULT(hbao_params_resolve(&in, &out, &fields), HBAO_ERROR_INVALID_PARAMETER);
    CHECK(fields == HBAO_PARAM_FIELD_BLUR_SHARPNESS);
    /* The resolved values compute what the given ones do, to the bit. */
    fill_inputs();
    const hbao_camera c = HBAO_CAMERA_DEFAULT_INITIALIZER;
    static float given_ao[W * H];
    const int32_t sizes[][2] = {{6, 5}, {2, 0}, {1, 0}};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        in = defaults;
        in.blur_size = sizes[k][0];
        in.blur_sharpness = 3.0f;
        CHECK_RESULT(compute_with(&in, &c), HBAO_SUCCESS);
        memcpy(given_ao, ao, sizeof given_ao);
        CHECK_RESULT(hbao_params_resolve(&in, &out, NULL), HBAO_SUCCESS);
        CHECK(out.blur_size == sizes[k][1]);
        CHECK_RESULT(compute_with(&out, &c), HBAO_SUCCESS);
        CHECK(memcmp(given_ao, ao, sizeof given_ao) == 0);
    }
}

/* Values with no nearest legal value are refused, their bits reported, and
 * *out left alone. */
TEST_CASE(params_resolve_rejects_what_cannot_be_clamped) {
    const hbao_params defaults = HBAO_PARAMS_DEFAULT_INITIALIZER;
    hbao_params in = defaults, out, untouched;
    memset(&untouched, 0x5a, sizeof untouched);
    uint32_t fields;
    struct {
        uint32_t field;
        hbao_params params;
    } cases[10];
    for (int k = 0; k < 10; k++) cases[k].params = defaults;
    cases[0].field = HBAO_PARAM_FIELD_RADIUS, cases[0].params.radius = -1.0f;
    cases[1].field = HBAO_PARAM_FIELD_RADIUS, cases[1].params.radius = NAN;
    cases[2].field = HBAO_PARAM_FIELD_ANGLE_BIAS_DEGREES,
    cases[2].params.angle_bias_degrees = INFINITY;
    cases[3].field = HBAO_PARAM_FIELD_BLUR_SHARPNESS, cases[3].params.blur_sharpness = NAN;
    cases[4].field = HBAO_PARAM_FIELD_STRENGTH, cases[4].params.strength = -INFINITY;
    cases[5].field = HBAO_PARAM_FIELD_BACKGROUND_DEPTH, cases[5].params.background_depth = 0.0f;
    cases[6].field = HBAO_PARAM_FIELD_FALLOFF | HBAO_PARAM_FIELD_INTEGRATION;
    cases[6].params.falloff = 9, cases[6].params.integration = -1;
    cases[7].field = HBAO_PARAM_FIELD_IMPLEMENTATION,
    cases[7].params.implementation = HBAO_IMPLEMENTATION_COUNT;
    cases[8].field = HBAO_PARAM_FIELD_THICKNESS, cases[8].params.thickness = -0.5f;
    cases[9].field = HBAO_PARAM_FIELD_THICKNESS, cases[9].params.thickness = INFINITY;
    for (int k = 0; k < 10; k++) {
        out = untouched;
        CHECK_RESULT(hbao_params_resolve(&cases[k].params, &out, &fields),
                     HBAO_ERROR_INVALID_PARAMETER);
        CHECK(fields == cases[k].field);
        CHECK(memcmp(&out, &untouched, sizeof out) == 0);
    }
    CHECK_RESULT(hbao_params_resolve(NULL, &out, &fields), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_params_resolve(&in, NULL, NULL), HBAO_ERROR_NULL_ARGUMENT);
    /* infinity is a legal background depth */
    in.background_depth = INFINITY;
    CHECK_RESULT(hbao_params_resolve(&in, &out, NULL), HBAO_SUCCESS);
}

TEST_CASE(out_of_range_counts_are_clamped) {
    fill_inputs();
    hbao_camera c = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    float clamped[W * H], limit[W * H];
    p.directions = 1000;
    p.steps = -4;
    p.blur_size = 999;
    p.threads = 100000;
    p.angle_bias_degrees = 200.0f;
    p.strength = -3.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_SUCCESS);
    memcpy(clamped, ao, sizeof ao);
    p.directions = HBAO_MAX_DIRECTIONS;
    p.steps = 1;
    p.blur_size = HBAO_MAX_BLUR_SIZE;
    p.threads = HBAO_MAX_THREADS;
    p.angle_bias_degrees = HBAO_MAX_ANGLE_BIAS_DEGREES;
    p.strength = 0.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_SUCCESS);
    memcpy(limit, ao, sizeof ao);
    CHECK(memcmp(clamped, limit, sizeof ao) == 0);
}

TEST_CASE(zero_radius_gives_ones) {
    fill_inputs();
    hbao_camera c = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.radius = 0.0f;
    for (int k = 0; k < W * H; k++) ao[k] = -1.0f;
    CHECK_RESULT(compute_with(&p, &c), HBAO_SUCCESS);
    for (int k = 0; k < W * H; k++) CHECK_NEAR(ao[k], 1.0f, 0.0);
}

/* hbao_implementation's order, slowest first, as hbao.h documents it */
static int speed_rank(int32_t implementation) {
    switch (implementation) {
        case HBAO_IMPLEMENTATION_SCALAR:
            return 0;
        case HBAO_IMPLEMENTATION_GENERIC:
            return 1;
        case HBAO_IMPLEMENTATION_AVX2:
            return 2;
        case HBAO_IMPLEMENTATION_AVX512:
            return 3;
        default:
            return -1;
    }
}

/* What runs for each request: itself or a slower one, AUTO the best, and
 * on x86-64 and ARM64 with GCC 9 or later or clang the generic kernel
 * everywhere (so no CPU is left to the scalar reference). */
TEST_CASE(each_implementation_runs_itself_or_a_slower_one) {
    const int32_t best = hbao_best_implementation();
    CHECK(hbao_implementation_that_runs(HBAO_IMPLEMENTATION_AUTO) == best);
    CHECK(hbao_implementation_that_runs(HBAO_IMPLEMENTATION_SCALAR) == HBAO_IMPLEMENTATION_SCALAR);
#if (defined(__x86_64__) || defined(__aarch64__)) && (defined(__clang__) || __GNUC__ >= 9)
    CHECK(hbao_implementation_that_runs(HBAO_IMPLEMENTATION_GENERIC) ==
          HBAO_IMPLEMENTATION_GENERIC);
    CHECK(speed_rank(best) >= speed_rank(HBAO_IMPLEMENTATION_GENERIC));
#endif
    for (int32_t asked = HBAO_IMPLEMENTATION_SCALAR; asked < HBAO_IMPLEMENTATION_COUNT; asked++) {
        const int32_t runs = hbao_implementation_that_runs(asked);
        CHECK(speed_rank(runs) >= 0 && speed_rank(runs) <= speed_rank(asked));
        CHECK(speed_rank(runs) <= speed_rank(best));
        /* what runs, asked for, runs itself */
        CHECK(hbao_implementation_that_runs(runs) == runs);
    }
    CHECK(hbao_implementation_that_runs(HBAO_IMPLEMENTATION_COUNT) == HBAO_IMPLEMENTATION_SCALAR);
    CHECK(strcmp(hbao_implementation_name(HBAO_IMPLEMENTATION_GENERIC), "generic") == 0);
    CHECK(strcmp(hbao_implementation_name(HBAO_IMPLEMENTATION_AVX512), "AVX-512") == 0);
    CHECK(strcmp(hbao_implementation_name(HBAO_IMPLEMENTATION_COUNT), "unknown implementation") ==
          0);
    CHECK(strcmp(hbao_implementation_name(-1), "unknown implementation") == 0);
    CHECK(hbao_implementation_that_runs(-1) == HBAO_IMPLEMENTATION_SCALAR);
#if defined(__x86_64__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f")) CHECK(best == HBAO_IMPLEMENTATION_AVX512);
    if (__builtin_cpu_supports("avx2") && !__builtin_cpu_supports("avx512f"))
        CHECK(best == HBAO_IMPLEMENTATION_AVX2);
#endif
}

TEST_CASE(messages_version_and_sizes) {
    for (int code = 0; code < HBAO_RESULT_COUNT; code++) {
        const char *message = hbao_result_message(code);
        CHECK(message != NULL && strlen(message) > 3);
    }
    CHECK(strcmp(hbao_result_message(-5), "unknown result code") == 0);
    CHECK(strcmp(hbao_result_message(HBAO_RESULT_COUNT), "unknown result code") == 0);
    CHECK(hbao_version() == HBAO_VERSION);
    const int32_t best = hbao_best_implementation();
    CHECK(best >= HBAO_IMPLEMENTATION_SCALAR && best < HBAO_IMPLEMENTATION_COUNT);
    CHECK(hbao_params_size() == sizeof(hbao_params));
    CHECK(hbao_camera_size() == sizeof(hbao_camera));
    hbao_params p;
    hbao_params_default(&p);
    const hbao_params expected = HBAO_PARAMS_DEFAULT_INITIALIZER;
    CHECK(memcmp(&p, &expected, sizeof p) == 0);
    hbao_camera c;
    hbao_camera_default(&c);
    const hbao_camera expected_camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    CHECK(memcmp(&c, &expected_camera, sizeof c) == 0);
    hbao_params_default(NULL); /* must not crash */
    hbao_camera_default(NULL);
}

/* A frame a few pixels high (an exploratory run rendered 4097x5: mean AO
 * 0.9996 against Cycles' 0.65, and nothing said why) has the radius span
 * many times its height: hbao_last_notes says so, with the AO computed as
 * usual. A usual frame, and the same strip with a radius that fits, get no
 * note. */
TEST_CASE(a_radius_past_the_image_is_noted) {
    enum { wide = 4097, low = 5, w = 96, h = 80 };
    static float strip_depth[wide * low], out[wide * low];
    for (int k = 0; k < wide * low; k++) strip_depth[k] = 4.0f + 0.001f * (float)(k % 7);
    const hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    const hbao_channel strip = {strip_depth, 1, wide};
    CHECK_RESULT(hbao_compute(&p, &camera, wide, low, &strip, NULL, out, wide), HBAO_SUCCESS);
    CHECK(hbao_last_notes() == HBAO_NOTE_RADIUS_BEYOND_IMAGE);
    for (int k = 0; k < wide * low; k++) CHECK(out[k] >= 0.0f && out[k] <= 1.0f);
    CHECK(strstr(hbao_note_message(HBAO_NOTE_RADIUS_BEYOND_IMAGE), "lower the radius") != NULL);
    /* the same at half resolution, where the grid is 2049 x 3 */
    p.half_resolution = 1;
    CHECK_RESULT(hbao_compute(&p, &camera, wide, low, &strip, NULL, out, wide), HBAO_SUCCESS);
    CHECK(hbao_last_notes() == HBAO_NOTE_RADIUS_BEYOND_IMAGE);
    /* a radius of under a pixel there: noted too (nothing is sampled, AO 1:
     * a review found radius 0 said nothing anywhere), and radius 0 */
    p.half_resolution = 0;
    p.radius = 0.0005f; /* 0.7 pixels */
    CHECK_RESULT(hbao_compute(&p, &camera, wide, low, &strip, NULL, out, wide), HBAO_SUCCESS);
    CHECK(hbao_last_notes() == HBAO_NOTE_RADIUS_UNDER_A_PIXEL);
    for (int k = 0; k < wide * low; k++) CHECK(out[k] == 1.0f);
    p.radius = 0.0f;
    CHECK_RESULT(hbao_compute(&p, &camera, wide, low, &strip, NULL, out, wide), HBAO_SUCCESS);
    CHECK(hbao_last_notes() == HBAO_NOTE_RADIUS_UNDER_A_PIXEL);
    CHECK(strstr(hbao_note_message(HBAO_NOTE_RADIUS_UNDER_A_PIXEL), "raise the radius") != NULL);
    /* a radius that fits the strip's 5 rows (2.8 pixels): nothing to note */
    p.radius = 0.002f;
    CHECK_RESULT(hbao_compute(&p, &camera, wide, low, &strip, NULL, out, wide), HBAO_SUCCESS);
    CHECK(hbao_last_notes() == 0);
    /* a usual frame: the radius spans 33 of its 80 rows */
    hbao_params usual = HBAO_PARAMS_DEFAULT_INITIALIZER;
    const hbao_channel frame = {strip_depth, 1, w};
    CHECK_RESULT(hbao_compute(&usual, &camera, w, h, &frame, NULL, out, w), HBAO_SUCCESS);
    CHECK(hbao_last_notes() == 0);
    /* all background: nothing to note either */
    for (int k = 0; k < w * h; k++) strip_depth[k] = 0.0f;
    CHECK_RESULT(hbao_compute(&usual, &camera, w, h, &frame, NULL, out, w), HBAO_SUCCESS);
    CHECK(hbao_last_notes() == 0);
}

typedef struct concurrent_call {
    float out[W * H];
    hbao_result result;
} concurrent_call;

static void *call_in_thread(void *argument) {
    concurrent_call *call = argument;
    hbao_camera c = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.threads = 2;
    p.half_resolution = 1;
    hbao_channel d = {depth, 1, W};
    for (int repeat = 0; repeat < 50 && call->result == HBAO_SUCCESS; repeat++)
        call->result = hbao_compute(&p, &c, W, H, &d, NULL, call->out, W);
    return NULL;
}

TEST_CASE(concurrent_calls_agree) {
    /* The only shared state is the kept working memory (scratch.c): four
     * threads calling at once get what one call alone gets (run under
     * ThreadSanitizer or ASan to see races, if any). */
    fill_inputs();
    static concurrent_call calls[5];
    memset(calls, 0, sizeof calls);
    call_in_thread(&calls[0]);
    pthread_t threads[4];
    for (int t = 0; t < 4; t++)
        CHECK(pthread_create(&threads[t], NULL, call_in_thread, &calls[t + 1]) == 0);
    for (int t = 0; t < 4; t++) pthread_join(threads[t], NULL);
    for (int t = 0; t < 5; t++) {
        CHECK_RESULT(calls[t].result, HBAO_SUCCESS);
        CHECK(memcmp(calls[0].out, calls[t].out, sizeof calls[0].out) == 0);
    }
}

TEST_CASE(kept_memory_changes_no_result) {
    /* A call takes the buffers an earlier call left (scratch.c): a larger
     * frame with other values before it, in every layout (full and half
     * resolution, the back layer), and hbao_release_memory between calls,
     * change nothing. */
    enum { BW = 2 * W + 3, BH = 2 * H + 1 };
    static float big_depth[BW * BH], big_normal[BW * BH * 3], big_back[BW * BH], big_ao[BW * BH];
    for (int k = 0; k < BW * BH; k++) {
        big_depth[k] = 1.0f + 0.37f * (float)(k % 7);
        big_back[k] = big_depth[k] + 0.2f;
        big_normal[3 * k] = 0.6f;
        big_normal[3 * k + 1] = 0.0f;
        big_normal[3 * k + 2] = 0.8f;
    }
    fill_inputs();
    static float back[W * H], first[W * H], again[W * H];
    for (int k = 0; k < W * H; k++) back[k] = depth[k] + 0.5f;
    hbao_camera c;
    hbao_camera_default(&c);
    const hbao_channel d = {depth, 1, W}, n = {normal, 3, 3 * W}, b = {back, 1, W};
    const hbao_channel bd = {big_depth, 1, BW}, bn = {big_normal, 3, 3 * BW};
    const hbao_channel bb = {big_back, 1, BW};
    for (int layout = 0; layout < 4; layout++) {
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.radius = 2.0f;
        p.half_resolution = layout & 1;
        const int layers = layout >> 1;
        hbao_release_memory();
        CHECK_RESULT(layers ? hbao_compute_layers(&p, &c, W, H, &d, &n, &b, first, W)
                            : hbao_compute(&p, &c, W, H, &d, &n, first, W),
                     HBAO_SUCCESS);
        CHECK_RESULT(layers ? hbao_compute_layers(&p, &c, BW, BH, &bd, &bn, &bb, big_ao, BW)
                            : hbao_compute(&p, &c, BW, BH, &bd, &bn, big_ao, BW),
                     HBAO_SUCCESS);
        CHECK_RESULT(layers ? hbao_compute_layers(&p, &c, W, H, &d, &n, &b, again, W)
                            : hbao_compute(&p, &c, W, H, &d, &n, again, W),
                     HBAO_SUCCESS);
        CHECK(memcmp(first, again, sizeof first) == 0);
        hbao_release_memory();
        hbao_release_memory(); /* twice: nothing left to free */
        CHECK_RESULT(layers ? hbao_compute_layers(&p, &c, W, H, &d, &n, &b, again, W)
                            : hbao_compute(&p, &c, W, H, &d, &n, again, W),
                     HBAO_SUCCESS);
        CHECK(memcmp(first, again, sizeof first) == 0);
    }
}

TEST_MAIN(TEST_ENTRY(null_arguments_are_rejected), TEST_ENTRY(sizes_and_strides_are_checked),
          TEST_ENTRY(invalid_parameters_are_rejected), TEST_ENTRY(invalid_cameras_are_rejected),
          TEST_ENTRY(world_to_camera_check_is_scale_free),
          TEST_ENTRY(params_resolve_clamps_each_field_and_names_it),
          TEST_ENTRY(params_resolve_rejects_what_cannot_be_clamped),
          TEST_ENTRY(params_resolve_says_one_setting_one_way),
          TEST_ENTRY(out_of_range_counts_are_clamped), TEST_ENTRY(zero_radius_gives_ones),
          TEST_ENTRY(messages_version_and_sizes),
          TEST_ENTRY(each_implementation_runs_itself_or_a_slower_one),
          TEST_ENTRY(a_radius_past_the_image_is_noted), TEST_ENTRY(concurrent_calls_agree),
          TEST_ENTRY(kept_memory_changes_no_result))
