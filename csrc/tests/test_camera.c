/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The camera rule's public face: hbao_camera_view (the view frame every front
 * end draws with) and hbao_camera_crop (the camera of a border or data
 * window). Both are held to scene.h's camera model, the independent copy of
 * docs/algorithm.md's "Camera" that test_ao.c renders its analytic scenes
 * with: since hbao_compute passes those tests, a view equal to scene.h's is
 * the view hbao_compute uses. */
#include <stdint.h>
#include <string.h>

#include "hbao.h"
#include "scene.h"
#include "test_harness.h"

/* Every view number is computed in double from float camera fields, by the
 * same formula in a different order: they agree to a few double roundings of
 * numbers up to ~1e3 pixel widths. */
#define VIEW_TOLERANCE_PIXELS 1e-9
/* A cropped camera stores its sensor and shift as floats (24-bit mantissa,
 * 6e-8 relative) of numbers up to ~2 image widths (shift * viewfac): under
 * 1e-4 pixel widths for the images here, under 1e-6 relative for sizes. */
#define CROP_TOLERANCE_PIXELS 1e-4
#define CROP_TOLERANCE_RELATIVE 1e-6

typedef struct camera_case {
    const char *name;
    hbao_camera camera;
} camera_case;

#define CASE_COUNT 8

/* Perspective and orthographic, shifted, non-square pixels, each sensor fit. */
static void camera_cases(camera_case cases[CASE_COUNT]) {
    const hbao_camera base = HBAO_CAMERA_DEFAULT_INITIALIZER;
    for (int k = 0; k < CASE_COUNT; k++) cases[k].camera = base;
    cases[0].name = "auto";
    cases[1].name = "auto shifted, tall pixels";
    cases[1].camera.shift_x = 0.2f;
    cases[1].camera.shift_y = -0.15f;
    cases[1].camera.pixel_aspect_y = 2.0f;
    cases[2].name = "auto, wide pixels";
    cases[2].camera.pixel_aspect_x = 3.0f;
    cases[2].camera.lens = 24.0f;
    cases[3].name = "vertical";
    cases[3].camera.sensor_fit = HBAO_SENSOR_FIT_VERTICAL;
    cases[3].camera.sensor_height = 10.0f;
    cases[3].camera.shift_y = 0.3f;
    cases[4].name = "horizontal, tall pixels";
    cases[4].camera.sensor_fit = HBAO_SENSOR_FIT_HORIZONTAL;
    cases[4].camera.pixel_aspect_y = 1.5f;
    cases[4].camera.shift_x = -0.25f;
    cases[5].name = "ortho";
    cases[5].camera.projection = HBAO_PROJECTION_ORTHOGRAPHIC;
    cases[5].camera.ortho_scale = 4.0f;
    cases[5].camera.shift_y = 0.3f;
    cases[6].name = "ortho vertical, wide pixels";
    cases[6].camera.projection = HBAO_PROJECTION_ORTHOGRAPHIC;
    cases[6].camera.sensor_fit = HBAO_SENSOR_FIT_VERTICAL;
    cases[6].camera.pixel_aspect_x = 2.0f;
    cases[6].camera.shift_x = 0.1f;
    cases[7].name = "auto shifted";
    cases[7].camera.lens = 30.0f;
    cases[7].camera.shift_x = 0.1f;
}

/* Landscape and portrait, so that AUTO fits each side; a portrait that turns
 * landscape with wide pixels. */
static const int SIZES[][2] = {{64, 48}, {30, 90}, {40, 72}};
#define SIZE_COUNT 3

/* Rectangles (x, y, width, height from the top left): inside every size,
 * then overscan (around every size: a guard band), reaching past one side
 * only, and wholly outside. */
static const int RECTS[][4] = {{0, 0, 30, 48},    {5, 8, 16, 33},    {13, 1, 16, 17},
                               {4, 20, 1, 1},     {-9, -7, 90, 110}, {-3, 10, 20, 90},
                               {60, -40, 12, 30}, {-50, 100, 5, 5}};
#define RECT_COUNT 8

/* Camera-space point of pixel centre (i, j) at unit depth (perspective) or
 * on the view plane (orthographic), from a view. */
static void view_point(const hbao_view *view, int height, double i, double j, double point[2]) {
    point[0] = view->origin_x + (i + 0.5) * view->pixel_size_x;
    point[1] = view->origin_y + (height - 1 - j + 0.5) * view->pixel_size_y;
}

TEST_CASE(view_equals_the_scene_model) {
    camera_case cases[CASE_COUNT];
    camera_cases(cases);
    for (int c = 0; c < CASE_COUNT; c++) {
        for (int s = 0; s < SIZE_COUNT; s++) {
            scene_view model = {SIZES[s][0], SIZES[s][1], cases[c].camera, {0}};
            hbao_view view;
            CHECK_RESULT(hbao_camera_view(&cases[c].camera, model.width, model.height, &view),
                         HBAO_SUCCESS);
            const int orthographic = cases[c].camera.projection == HBAO_PROJECTION_ORTHOGRAPHIC;
            CHECK(view.perspective == !orthographic);
            const int corners[3][2] = {{0, 0}, {model.width - 1, model.height - 1}, {7, 3}};
            for (int k = 0; k < 3; k++) {
                double origin[3], direction[3], point[2];
                scene_pixel_ray(&model, corners[k][0], corners[k][1], origin, direction);
                view_point(&view, model.height, corners[k][0], corners[k][1], point);
                const double *expected = orthographic ? origin : direction;
                CHECK_NEAR(point[0], expected[0], VIEW_TOLERANCE_PIXELS * view.pixel_size_x);
                CHECK_NEAR(point[1], expected[1], VIEW_TOLERANCE_PIXELS * view.pixel_size_x);
            }
        }
    }
}

/* Every pixel of the crop lies where the full camera puts the same pixel. */
static void check_crop_sees_the_full_rays(const hbao_camera *camera, int full_width,
                                          int full_height, const int rect[4]) {
    hbao_camera cropped;
    CHECK_RESULT(hbao_camera_crop(camera, full_width, full_height, rect[0], rect[1], rect[2],
                                  rect[3], &cropped),
                 HBAO_SUCCESS);
    hbao_view full, crop;
    CHECK_RESULT(hbao_camera_view(camera, full_width, full_height, &full), HBAO_SUCCESS);
    CHECK_RESULT(hbao_camera_view(&cropped, rect[2], rect[3], &crop), HBAO_SUCCESS);
    CHECK(crop.perspective == full.perspective);
    CHECK_NEAR(crop.pixel_size_x, full.pixel_size_x, CROP_TOLERANCE_RELATIVE * full.pixel_size_x);
    CHECK_NEAR(crop.pixel_size_y, full.pixel_size_y, CROP_TOLERANCE_RELATIVE * full.pixel_size_y);
    const int pixels[2][2] = {{0, 0}, {rect[2] - 1, rect[3] - 1}};
    for (int k = 0; k < 2; k++) {
        double in_crop[2], in_full[2];
        view_point(&crop, rect[3], pixels[k][0], pixels[k][1], in_crop);
        view_point(&full, full_height, rect[0] + pixels[k][0], rect[1] + pixels[k][1], in_full);
        CHECK_NEAR(in_crop[0], in_full[0], CROP_TOLERANCE_PIXELS * full.pixel_size_x);
        CHECK_NEAR(in_crop[1], in_full[1], CROP_TOLERANCE_PIXELS * full.pixel_size_x);
    }
}

TEST_CASE(cropped_camera_keeps_the_view_rays) {
    camera_case cases[CASE_COUNT];
    camera_cases(cases);
    for (int c = 0; c < CASE_COUNT; c++)
        for (int s = 0; s < SIZE_COUNT; s++)
            for (int r = 0; r < RECT_COUNT; r++)
                check_crop_sees_the_full_rays(&cases[c].camera, SIZES[s][0], SIZES[s][1], RECTS[r]);
}

TEST_CASE(crop_of_a_crop_equals_the_direct_crop) {
    camera_case cases[CASE_COUNT];
    camera_cases(cases);
    const int outer[4] = {3, 5, 24, 31}, inner[4] = {4, 6, 11, 13};
    for (int c = 0; c < CASE_COUNT; c++) {
        for (int s = 0; s < SIZE_COUNT; s++) {
            const hbao_camera *camera = &cases[c].camera;
            hbao_camera once, twice, direct;
            CHECK_RESULT(hbao_camera_crop(camera, SIZES[s][0], SIZES[s][1], outer[0], outer[1],
                                          outer[2], outer[3], &once),
                         HBAO_SUCCESS);
            CHECK_RESULT(hbao_camera_crop(&once, outer[2], outer[3], inner[0], inner[1], inner[2],
                                          inner[3], &twice),
                         HBAO_SUCCESS);
            CHECK_RESULT(hbao_camera_crop(camera, SIZES[s][0], SIZES[s][1], outer[0] + inner[0],
                                          outer[1] + inner[1], inner[2], inner[3], &direct),
                         HBAO_SUCCESS);
            CHECK(twice.sensor_fit == direct.sensor_fit);
            CHECK(twice.projection == direct.projection && twice.lens == direct.lens);
            const int vertical = direct.sensor_fit == HBAO_SENSOR_FIT_VERTICAL;
            const double sensor_twice = vertical ? twice.sensor_height : twice.sensor_width;
            const double sensor_direct = vertical ? direct.sensor_height : direct.sensor_width;
            CHECK_NEAR(sensor_twice, sensor_direct, CROP_TOLERANCE_RELATIVE * sensor_direct);
            CHECK_NEAR(twice.ortho_scale, direct.ortho_scale,
                       CROP_TOLERANCE_RELATIVE * direct.ortho_scale);
            /* Shifts count fitted-side lengths of the 11 x 13 crop: the
             * pixel tolerance over at least 11 pixels. */
            CHECK_NEAR(twice.shift_x, direct.shift_x, CROP_TOLERANCE_PIXELS);
            CHECK_NEAR(twice.shift_y, direct.shift_y, CROP_TOLERANCE_PIXELS);
        }
    }
}

TEST_CASE(crop_of_the_whole_image_is_the_camera) {
    camera_case cases[CASE_COUNT];
    camera_cases(cases);
    for (int c = 0; c < CASE_COUNT; c++) {
        hbao_camera cropped;
        CHECK_RESULT(hbao_camera_crop(&cases[c].camera, 64, 48, 0, 0, 64, 48, &cropped),
                     HBAO_SUCCESS);
        CHECK(memcmp(&cropped, &cases[c].camera, sizeof cropped) == 0);
    }
}

TEST_CASE(crop_may_write_over_its_input) {
    hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER, expected;
    camera.shift_x = 0.1f;
    CHECK_RESULT(hbao_camera_crop(&camera, 64, 48, 8, 4, 20, 30, &expected), HBAO_SUCCESS);
    CHECK_RESULT(hbao_camera_crop(&camera, 64, 48, 8, 4, 20, 30, &camera), HBAO_SUCCESS);
    CHECK(memcmp(&camera, &expected, sizeof camera) == 0);
}

TEST_CASE(crop_rejects_bad_arguments) {
    const hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_camera out = HBAO_CAMERA_DEFAULT_INITIALIZER;
    out.lens = 123.0f; /* a marker: failed calls leave *out alone */
    CHECK_RESULT(hbao_camera_crop(NULL, 64, 48, 0, 0, 8, 8, &out), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_camera_crop(&camera, 64, 48, 0, 0, 8, 8, NULL), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_camera_crop(&camera, 0, 48, 0, 0, 8, 8, &out), HBAO_ERROR_INVALID_SIZE);
    CHECK_RESULT(hbao_camera_crop(&camera, 64, -1, 0, 0, 8, 8, &out), HBAO_ERROR_INVALID_SIZE);
    CHECK_RESULT(hbao_camera_crop(&camera, HBAO_MAX_IMAGE_SIZE + 1, 48, 0, 0, 8, 8, &out),
                 HBAO_ERROR_INVALID_SIZE);
    CHECK_RESULT(hbao_camera_crop(&camera, 64, INT32_MAX, 0, 0, 8, 8, &out),
                 HBAO_ERROR_INVALID_SIZE);
    /* Only the size is bounded: rectangles past the image are overscan. */
    const int32_t bad_rects[][4] = {{0, 0, 0, 8},
                                    {0, 0, 8, 0},
                                    {0, 0, -8, 8},
                                    {-4, 0, 8, INT32_MIN},
                                    {1, 0, INT32_MAX, 8},
                                    {0, 0, HBAO_MAX_IMAGE_SIZE + 1, 8},
                                    {-1, -1, 8, HBAO_MAX_IMAGE_SIZE + 1}};
    for (size_t k = 0; k < sizeof bad_rects / sizeof bad_rects[0]; k++)
        CHECK_RESULT(hbao_camera_crop(&camera, 64, 48, bad_rects[k][0], bad_rects[k][1],
                                      bad_rects[k][2], bad_rects[k][3], &out),
                     HBAO_ERROR_INVALID_RECTANGLE);
    hbao_camera invalid = camera;
    invalid.lens = 0.0f;
    CHECK_RESULT(hbao_camera_crop(&invalid, 64, 48, 0, 0, 8, 8, &out), HBAO_ERROR_INVALID_CAMERA);
    /* A shift that the crop carries beyond float's range. */
    hbao_camera far_shift = camera;
    far_shift.shift_x = 3e38f;
    CHECK_RESULT(hbao_camera_crop(&far_shift, 64, 48, 0, 0, 8, 8, &out), HBAO_ERROR_INVALID_CAMERA);
    /* A sensor that the crop scales below float's range. */
    hbao_camera tiny = camera;
    tiny.sensor_width = 1e-44f;
    CHECK_RESULT(hbao_camera_crop(&tiny, 64, 48, 0, 0, 1, 1, &out), HBAO_ERROR_INVALID_CAMERA);
    CHECK(out.lens == 123.0f);
}

/* The size a projection does not use (a perspective camera's ortho scale,
 * an orthographic one's sensor) may be anything, for the crop as for
 * hbao_camera_view and hbao_compute: the crop keeps it and scales the other. */
TEST_CASE(crop_ignores_the_size_its_projection_does_not_use) {
    for (int orthographic = 0; orthographic < 2; orthographic++) {
        hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
        camera.projection =
            orthographic ? HBAO_PROJECTION_ORTHOGRAPHIC : HBAO_PROJECTION_PERSPECTIVE;
        hbao_camera odd = camera;
        if (orthographic)
            odd.sensor_width = NAN;
        else
            odd.ortho_scale = NAN;
        hbao_view view;
        CHECK_RESULT(hbao_camera_view(&odd, 64, 48, &view), HBAO_SUCCESS);
        hbao_camera plain_crop, odd_crop;
        CHECK_RESULT(hbao_camera_crop(&camera, 64, 48, -8, 4, 80, 20, &plain_crop), HBAO_SUCCESS);
        CHECK_RESULT(hbao_camera_crop(&odd, 64, 48, -8, 4, 80, 20, &odd_crop), HBAO_SUCCESS);
        if (orthographic) {
            CHECK(isnan(odd_crop.sensor_width));
            CHECK(odd_crop.ortho_scale == plain_crop.ortho_scale);
        } else {
            CHECK(isnan(odd_crop.ortho_scale));
            CHECK(odd_crop.sensor_width == plain_crop.sensor_width);
        }
        CHECK(odd_crop.shift_x == plain_crop.shift_x && odd_crop.shift_y == plain_crop.shift_y);
    }
}

TEST_CASE(view_rejects_bad_arguments) {
    const hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_view view = {7, 1.0, 2.0, 3.0, 4.0};
    CHECK_RESULT(hbao_camera_view(NULL, 64, 48, &view), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_camera_view(&camera, 64, 48, NULL), HBAO_ERROR_NULL_ARGUMENT);
    CHECK_RESULT(hbao_camera_view(&camera, 0, 48, &view), HBAO_ERROR_INVALID_SIZE);
    CHECK_RESULT(hbao_camera_view(&camera, 64, HBAO_MAX_IMAGE_SIZE + 1, &view),
                 HBAO_ERROR_INVALID_SIZE);
    CHECK_RESULT(hbao_camera_view(&camera, INT32_MIN, 48, &view), HBAO_ERROR_INVALID_SIZE);
    hbao_camera invalid = camera;
    invalid.sensor_fit = 7;
    CHECK_RESULT(hbao_camera_view(&invalid, 64, 48, &view), HBAO_ERROR_INVALID_CAMERA);
    CHECK(view.perspective == 7 && view.origin_y == 4.0);
    CHECK(hbao_view_size() == sizeof(hbao_view));
}

/* End to end: AO computed on a crop of the depth image with the cropped
 * camera equals the full image's AO at the same pixels, wherever the radius
 * stays inside the crop (the pixel's radius in pixels, plus one). The crop's corner is at a multiple of
 * 64 columns (HBAO's blocks, which share one step length) and 4 rows (the
 * 4 x 4 sampling pattern), so both images sample alike; no blur. */
/* The two cameras' view numbers differ by float roundings (~1e-7
 * relative), which move each pixel's step length as much: a step whose
 * offset lies on a pixel boundary rounds to the other pixel, and at a crease
 * that changes the pixel's AO visibly. So: most pixels agree to 1e-3 (the
 * horizons' rounding), and only a few may differ more. */
#define AO_CROP_TOLERANCE 1e-3
#define AO_CROP_MAX_FLIPPED_FRACTION 0.03

/* Three planes (a floor, a wall and a clipped fin before it) seen from above,
 * rendered on view->width x view->height pixels with `camera`. */
static void render_crease_scene(const hbao_camera *camera, scene_view *view, float **depth,
                                float **normal) {
    scene s;
    memset(&s, 0, sizeof s);
    s.planes = 3;
    s.plane[0] = scene_plane_make(0, 0, 0, 0, 0, 1);
    s.plane[1] = scene_plane_make(0, 0, 0, -1, 0, 0);
    scene_plane_clip(&s.plane[1], 0, 0, -1, 0);
    s.plane[2] = scene_plane_make(-1.5, 0, 0, -1, 0, 0.2);
    scene_plane_clip(&s.plane[2], 0, 0, 1, 0.6);
    view->camera = *camera;
    const double eye[3] = {-5.0, -2.5, 3.5}, target[3] = {-0.8, 0, 0.3};
    scene_look_at(view, eye, target);
    if (view->camera.projection == HBAO_PROJECTION_ORTHOGRAPHIC) view->camera.ortho_scale = 8.0f;
    scene_render(&s, view, depth, normal);
}

static hbao_params crop_test_params(void) {
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.radius = 0.3f;
    p.blur_size = 0;
    p.threads = 1;
    return p;
}

/* Whether pixel (i, j) of a rect[2] x rect[3] window lies farther than its
 * radius (in pixels, plus one) from the window's edges. */
static int radius_inside_window(const hbao_view *frame, const hbao_params *p, double z, int i,
                                int j, const int rect[4]) {
    const double unit = frame->perspective ? z : 1.0;
    const double reach_x = 1.0 + p->radius / (unit * frame->pixel_size_x);
    const double reach_y = 1.0 + p->radius / (unit * frame->pixel_size_y);
    return !(i < reach_x || i >= rect[2] - reach_x || j < reach_y || j >= rect[3] - reach_y);
}

#define FULL_WIDTH 160
#define FULL_HEIGHT 96
/* The window inside the full image: its corner at a multiple of 64 columns
 * and 4 rows (see above). */
static const int WINDOW[4] = {64, 12, 64, 72};

TEST_CASE(ao_of_a_crop_equals_the_full_ao) {
    camera_case cases[CASE_COUNT];
    camera_cases(cases);
    const int full_width = FULL_WIDTH, full_height = FULL_HEIGHT;
    const int *rect = WINDOW;
    float *crop_ao = malloc((size_t)rect[2] * rect[3] * sizeof(float));
    float *full_ao = malloc((size_t)full_width * full_height * sizeof(float));
    double total_occlusion = 0.0;
    for (int c = 0; c < CASE_COUNT; c++) {
        scene_view view = {full_width, full_height, cases[c].camera, {0}};
        float *depth, *normal;
        render_crease_scene(&cases[c].camera, &view, &depth, &normal);
        const hbao_params p = crop_test_params();
        hbao_camera cropped;
        CHECK_RESULT(hbao_camera_crop(&view.camera, full_width, full_height, rect[0], rect[1],
                                      rect[2], rect[3], &cropped),
                     HBAO_SUCCESS);
        const hbao_channel full_depth = {depth, 1, full_width};
        const hbao_channel crop_depth = {depth + (size_t)rect[1] * full_width + rect[0], 1,
                                         full_width};
        CHECK_RESULT(hbao_compute(&p, &view.camera, full_width, full_height, &full_depth, NULL,
                                  full_ao, full_width),
                     HBAO_SUCCESS);
        CHECK_RESULT(
            hbao_compute(&p, &cropped, rect[2], rect[3], &crop_depth, NULL, crop_ao, rect[2]),
            HBAO_SUCCESS);
        hbao_view frame;
        CHECK_RESULT(hbao_camera_view(&view.camera, full_width, full_height, &frame), HBAO_SUCCESS);
        int compared = 0, flipped = 0;
        double occlusion = 0.0;
        for (int j = 0; j < rect[3]; j++) {
            for (int i = 0; i < rect[2]; i++) {
                const double z = depth[(size_t)(j + rect[1]) * full_width + i + rect[0]];
                if (!radius_inside_window(&frame, &p, z, i, j, rect)) continue;
                const double a = crop_ao[(size_t)j * rect[2] + i];
                const double b = full_ao[(size_t)(j + rect[1]) * full_width + i + rect[0]];
                compared++;
                if (!(fabs(a - b) <= AO_CROP_TOLERANCE)) flipped++;
                occlusion += 1.0 - b;
            }
        }
        if (!(flipped <= AO_CROP_MAX_FLIPPED_FRACTION * compared))
            fprintf(stderr, "%s: %d of %d pixels differ\n", cases[c].name, flipped, compared);
        CHECK(flipped <= AO_CROP_MAX_FLIPPED_FRACTION * compared);
        CHECK(compared >= 100);
        total_occlusion += occlusion / (compared > 0 ? compared : 1);
        free(depth);
        free(normal);
    }
    /* The compared pixels see occlusion, so AO that ignored the camera
     * would not pass: on average at least 5 % per case. */
    CHECK(total_occlusion > 0.05 * CASE_COUNT);
    free(crop_ao);
    free(full_ao);
}

/* A pixel "sees the guard band" when its AO without the band differs from
 * the full image's by more than the rounding tolerance. The window's edges
 * cut the fin and the wall's foot, so border pixels do: in every case some
 * (the orthographic ones, whose radius spans ~6 pixels, only a dozen), over
 * all cases at least this fraction of the window, else the test would not
 * show that the band is used. 4 % when written; 1.3 % since a step past
 * the image's edge sees the edge's surface continued (hbao_beyond_depth),
 * which is the wall's foot without a band, but not the fin beyond it. */
#define GUARD_BAND_MIN_AFFECTED_FRACTION 0.01

/* Guard band (overscan): the display window is WINDOW of the full image, and
 * the depth is given for the whole full image, i.e. the data window reaches
 * past the display window on every side. The display window's camera widened
 * to the data window by hbao_camera_crop (a rectangle with a negative
 * origin) must give every display pixel the AO of the full image's own
 * camera, border pixels included, where the AO of the display window alone
 * misses the occluders outside it. Same tolerances as above: the widened
 * camera differs from the full one by float roundings. */
TEST_CASE(ao_with_a_guard_band_equals_the_larger_frame) {
    camera_case cases[CASE_COUNT];
    camera_cases(cases);
    const int full_width = FULL_WIDTH, full_height = FULL_HEIGHT;
    const int *window = WINDOW;
    const size_t full_pixels = (size_t)full_width * full_height;
    float *full_ao = malloc(full_pixels * sizeof(float));
    float *band_ao = malloc(full_pixels * sizeof(float));
    float *window_ao = malloc((size_t)window[2] * window[3] * sizeof(float));
    int all_compared = 0, all_affected = 0, all_flipped = 0;
    for (int c = 0; c < CASE_COUNT; c++) {
        scene_view view = {full_width, full_height, cases[c].camera, {0}};
        float *depth, *normal;
        render_crease_scene(&cases[c].camera, &view, &depth, &normal);
        const hbao_params p = crop_test_params();
        /* What the renderer's display window was, and its data window
         * (the full image) in the display window's pixel grid. */
        hbao_camera display, widened;
        CHECK_RESULT(hbao_camera_crop(&view.camera, full_width, full_height, window[0], window[1],
                                      window[2], window[3], &display),
                     HBAO_SUCCESS);
        CHECK_RESULT(hbao_camera_crop(&display, window[2], window[3], -window[0], -window[1],
                                      full_width, full_height, &widened),
                     HBAO_SUCCESS);
        const hbao_channel full_depth = {depth, 1, full_width};
        const hbao_channel window_depth = {depth + (size_t)window[1] * full_width + window[0], 1,
                                           full_width};
        CHECK_RESULT(hbao_compute(&p, &view.camera, full_width, full_height, &full_depth, NULL,
                                  full_ao, full_width),
                     HBAO_SUCCESS);
        CHECK_RESULT(hbao_compute(&p, &widened, full_width, full_height, &full_depth, NULL, band_ao,
                                  full_width),
                     HBAO_SUCCESS);
        CHECK_RESULT(hbao_compute(&p, &display, window[2], window[3], &window_depth, NULL,
                                  window_ao, window[2]),
                     HBAO_SUCCESS);
        int compared = 0, flipped = 0, affected = 0;
        for (int j = 0; j < window[3]; j++) {
            for (int i = 0; i < window[2]; i++) {
                const size_t at = (size_t)(j + window[1]) * full_width + i + window[0];
                const double expected = full_ao[at];
                compared++;
                if (!(fabs(band_ao[at] - expected) <= AO_CROP_TOLERANCE)) flipped++;
                if (!(fabs(window_ao[(size_t)j * window[2] + i] - expected) <= AO_CROP_TOLERANCE))
                    affected++;
            }
        }
        if (!(flipped <= AO_CROP_MAX_FLIPPED_FRACTION * compared) || affected == 0)
            fprintf(stderr, "%s: %d of %d pixels differ with the band, %d without\n", cases[c].name,
                    flipped, compared, affected);
        CHECK(flipped <= AO_CROP_MAX_FLIPPED_FRACTION * compared);
        CHECK(affected > 0);
        all_compared += compared;
        all_affected += affected;
        all_flipped += flipped;
        free(depth);
        free(normal);
    }
    CHECK(all_affected >= GUARD_BAND_MIN_AFFECTED_FRACTION * all_compared);
    /* and the band gives most of them the full image's AO (none, when
     * written): a band left unused would flip every one */
    CHECK(4 * all_flipped <= all_affected);
    free(full_ao);
    free(band_ao);
    free(window_ao);
}

/* hbao_clip_background_depth: the one rule the node and the CLI take the
 * background below a camera's Clip End from. Depths EEVEE 4.5 and 5.0 wrote
 * for the sky (measured: 8.99996 for Clip End 9, 5.600006 for 5.6, 99864.38
 * for 0.1 .. 1e5, 699051 for 0.1 .. 1e6) are background; geometry a
 * hundredth short of a short range's Clip End is not. */
TEST_CASE(clip_range_background_depth) {
    const struct {
        float clip_start, clip_end, sky;
    } skies[] = {{0.1f, 9.0f, 8.99996f},
                 {0.1f, 5.6f, 5.600006f},
                 {0.1f, 1e5f, 99864.38f},
                 {0.1f, 1e6f, 699051.0f}};
    for (size_t s = 0; s < sizeof skies / sizeof skies[0]; s++) {
        const float background =
            hbao_clip_background_depth(skies[s].clip_start, skies[s].clip_end, 65504.0f);
        CHECK(skies[s].sky >= background);
        CHECK(background < skies[s].clip_end);
        CHECK(background >= 0.5f * skies[s].clip_end);
    }
    /* the margin: 1e-5 of Clip End at least, 2^-23 x Clip End / Clip Start,
     * half of Clip End at most */
    CHECK(hbao_clip_background_depth(1.0f, 9.0f, 65504.0f) == (float)(9.0 * (1.0 - 1e-5)));
    CHECK(hbao_clip_background_depth(0.1f, 1e5f, 65504.0f) ==
          (float)(1e5 * (1.0 - 0x1p-23 * 1e5 / (double)0.1f)));
    CHECK(hbao_clip_background_depth(1e-3f, 1e6f, 65504.0f) == 5e5f);
    CHECK(hbao_clip_background_depth(0.1f, 100.0f, 65504.0f) > 99.0f);
    /* past 65504: a scene in centimetres keeps its geometry */
    CHECK(hbao_clip_background_depth(1.0f, 2e6f, 65504.0f) > 1e6f);
    /* Clip Start unknown (a camera file written before it was): the lesser
     * of the depth and Clip End less 1e-5 */
    CHECK(hbao_clip_background_depth(0.0f, 9.0f, 65504.0f) == (float)(9.0 * (1.0 - 1e-5)));
    CHECK(hbao_clip_background_depth(-1.0f, 1e6f, 65504.0f) == 65504.0f);
    CHECK(hbao_clip_background_depth(NAN, 1e6f, 1e10f) == (float)(1e6 * (1.0 - 1e-5)));
    /* Clip End unknown: the depth as given */
    const float unknown_ends[] = {0.0f, -5.0f, NAN, INFINITY};
    for (size_t e = 0; e < sizeof unknown_ends / sizeof unknown_ends[0]; e++)
        CHECK(hbao_clip_background_depth(0.1f, unknown_ends[e], 1234.5f) == 1234.5f);
}

TEST_MAIN(TEST_ENTRY(view_equals_the_scene_model), TEST_ENTRY(clip_range_background_depth),
          TEST_ENTRY(cropped_camera_keeps_the_view_rays),
          TEST_ENTRY(crop_of_a_crop_equals_the_direct_crop),
          TEST_ENTRY(crop_of_the_whole_image_is_the_camera),
          TEST_ENTRY(crop_may_write_over_its_input), TEST_ENTRY(crop_rejects_bad_arguments),
          TEST_ENTRY(crop_ignores_the_size_its_projection_does_not_use),
          TEST_ENTRY(view_rejects_bad_arguments), TEST_ENTRY(ao_of_a_crop_equals_the_full_ao),
          TEST_ENTRY(ao_with_a_guard_band_equals_the_larger_frame))
