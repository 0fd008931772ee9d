/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Correctness of hbao_compute() on analytic scenes: flat and tilted planes,
 * the 90-degree corner against its analytic value, scale invariance,
 * convergence towards a brute-force reference, threads, half resolution,
 * blur, strength and background handling, and cones whose closed forms pin
 * the thickness, the angle bias and the back layer's minimum thickness. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "hbao.h"
#include "scene.h"
#include "test_harness.h"
#include "test_random.h"

#define PI 3.14159265358979323846

/* --- helpers ------------------------------------------------------------- */

static hbao_params exact_params(int integration) {
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.integration = integration;
    p.angle_bias_degrees = 0.0f;
    p.blur_size = 0;
    p.falloff = HBAO_FALLOFF_NONE;
    return p;
}

static float *run(const hbao_params *p, const scene_view *view, const float *depth,
                  const float *normal) {
    float *ao = malloc((size_t)view->width * view->height * sizeof(float));
    hbao_channel d = {depth, 1, view->width};
    hbao_channel n = {normal, 3, 3 * (int64_t)view->width};
    CHECK_RESULT(hbao_compute(p, &view->camera, view->width, view->height, &d, normal ? &n : NULL,
                              ao, view->width),
                 HBAO_SUCCESS);
    return ao;
}

static float *run_layers(const hbao_params *p, const scene_view *view, const float *depth,
                         const float *normal, const float *back) {
    float *ao = malloc((size_t)view->width * view->height * sizeof(float));
    hbao_channel d = {depth, 1, view->width};
    hbao_channel n = {normal, 3, 3 * (int64_t)view->width};
    hbao_channel b = {back, 1, view->width};
    CHECK_RESULT(hbao_compute_layers(p, &view->camera, view->width, view->height, &d,
                                     normal ? &n : NULL, back ? &b : NULL, ao, view->width),
                 HBAO_SUCCESS);
    return ao;
}

static scene_view make_view(int width, int height, const double eye[3], const double target[3]) {
    scene_view view;
    memset(&view, 0, sizeof view);
    view.width = width;
    view.height = height;
    hbao_camera_default(&view.camera);
    scene_look_at(&view, eye, target);
    return view;
}

/* The floor z = 0 for x <= 0 and the wall x = 0 for z >= 0, facing -x. */
static scene corner_scene(void) {
    scene s;
    memset(&s, 0, sizeof s);
    s.planes = 2;
    s.plane[0] = scene_plane_make(0, 0, 0, 0, 0, 1);
    scene_plane_clip(&s.plane[0], 1, 0, 0, 0);
    s.plane[1] = scene_plane_make(0, 0, 0, -1, 0, 0);
    scene_plane_clip(&s.plane[1], 0, 0, -1, 0);
    return s;
}

/* The view most tests use: the corner (and boxes) seen from above and to the
 * side, so that floor, wall and box faces are all visible at an angle. */
static void render_standard_view(scene s, int width, int height, scene_view *view, float **depth,
                                 float **normal) {
    const double eye[3] = {-5.0, -2.5, 3.5}, target[3] = {-0.8, 0, 0.3};
    *view = make_view(width, height, eye, target);
    scene_render(&s, view, depth, normal);
}

/* --- planes -------------------------------------------------------------- */

/* A single plane occludes nothing: AO = 1. Tolerance 1e-4: samples on the
 * plane have elevation 0 up to float rounding of positions (~1e-6 relative). */
static void check_plane_is_unoccluded(const double eye[3], const double target[3],
                                      scene_plane plane) {
    scene s;
    memset(&s, 0, sizeof s);
    s.planes = 1;
    s.plane[0] = plane;
    scene_view view = make_view(96, 64, eye, target);
    float *depth, *normal;
    scene_render(&s, &view, &depth, &normal);
    for (int integration = 0; integration <= 1; integration++) {
        for (int given = 0; given <= 1; given++) {
            hbao_params p = exact_params(integration);
            p.radius = 2.0f;
            float *ao = run(&p, &view, depth, given ? normal : NULL);
            float worst = 1.0f;
            for (int k = 0; k < view.width * view.height; k++)
                worst = ao[k] < worst ? ao[k] : worst;
            if (worst < 1.0f - 1e-4f)
                printf("  integration %d given normals %d\n", integration, given);
            CHECK_NEAR(worst, 1.0f, 1e-4);
            free(ao);
        }
    }
    free(depth);
    free(normal);
}

TEST_CASE(plane_facing_camera_is_unoccluded) {
    const double eye[3] = {0, 0, 5}, target[3] = {0, 0, 0};
    /* looking straight down at the floor */
    const double eye_down[3] = {0, -1e-3, 5};
    (void)eye;
    check_plane_is_unoccluded(eye_down, target, scene_plane_make(0, 0, 0, 0, 0, 1));
}

TEST_CASE(tilted_plane_is_unoccluded) {
    const double eye[3] = {0, -6, 3}, target[3] = {0, 0, 0};
    check_plane_is_unoccluded(eye, target, scene_plane_make(0, 0, 0, 0.3, -0.2, 1));
}

/* --- the corner ---------------------------------------------------------- */

/* Occluded fraction at distance a = d / R from an infinite wall, radius R,
 * for a floor point (falloff none, no bias).
 * Cosine-weighted: cosine-distributed directions project to points spread
 * uniformly on the unit disk (Malley); a direction hits the wall within R
 * iff its component towards the wall exceeds a, i.e. the disk segment
 * x > a, of area acos(a) - a sqrt(1 - a^2) out of pi. */
static double corner_cosine_occlusion(double a) {
    if (a >= 1.0) return 0.0;
    return (acos(a) - a * sqrt(1.0 - a * a)) / PI;
}

/* The classic HBAO estimator for the same point, as the library integrates
 * it: the mean over screen directions of sin(elevation of the highest wall
 * point within R in that direction's slice), with the half-occluded
 * rule. Derived per slice from the geometry: the slice is the plane through
 * the eye, P and P's screen direction; it cuts the wall in a line. */
static double corner_hbao_occlusion(const scene_view *view, int i, int j, double depth) {
    const int directions = 720;
    double p_cam[3], o[3], d[3];
    scene_pixel_ray(view, i, j, o, d);
    for (int c = 0; c < 3; c++) p_cam[c] = o[c] + depth * d[c];
    double vlen = sqrt(p_cam[0] * p_cam[0] + p_cam[1] * p_cam[1] + p_cam[2] * p_cam[2]);
    const double v[3] = {-p_cam[0] / vlen, -p_cam[1] / vlen, -p_cam[2] / vlen};
    double p_world[3];
    mat_mul_point(view->camera_to_world, p_cam, p_world);
    const double n_world[3] = {0, 0, 1};
    double sum = 0.0;
    for (int k = 0; k < directions; k++) {
        const double theta = 2.0 * PI * (k + 0.5) / directions;
        const double dir[3] = {cos(theta), sin(theta), 0};
        const double dv = dir[0] * v[0] + dir[1] * v[1];
        double e[3] = {dir[0] - v[0] * dv, dir[1] - v[1] * dv, -v[2] * dv};
        double el = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        for (int c = 0; c < 3; c++) e[c] /= el;
        double e_w[3], v_w[3];
        mat_mul_dir(view->camera_to_world, e, e_w);
        mat_mul_dir(view->camera_to_world, v, v_w);
        /* in-slice projected normal angle: cos/sin of gamma */
        const double nv = n_world[0] * v_w[0] + n_world[1] * v_w[1] + n_world[2] * v_w[2];
        const double ne = n_world[0] * e_w[0] + n_world[1] * e_w[1] + n_world[2] * e_w[2];
        const double np_len = sqrt(nv * nv + ne * ne);
        /* slice points: P + a V + b e with b > 0; on the wall x = 0. March
         * outwards in b (screen distance grows with b) and keep the highest
         * elevation, as a dense march would. */
        double occlusion = 0.0;
        const double vx = v_w[0], ex = e_w[0];
        for (int step = 1; step <= 4000; step++) {
            const double b = step * 1e-3 * 4.0; /* up to 16 scene units sideways */
            if (fabs(vx) < 1e-12) break;
            const double a = -(p_world[0] + b * ex) / vx; /* x = 0 */
            double x[3];
            for (int c = 0; c < 3; c++) x[c] = p_world[c] + a * v_w[c] + b * e_w[c];
            if (x[2] < 0.0) continue; /* below the floor: hidden */
            double delta[3] = {x[0] - p_world[0], x[1] - p_world[1], x[2] - p_world[2]};
            const double dist =
                sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
            if (dist >= 1.0) continue; /* radius R = 1 */
            const double cos_h = (delta[0] * v_w[0] + delta[1] * v_w[1] + delta[2] * v_w[2]) / dist;
            if (ne > 0.0 && cos_h > nv / np_len) { /* past the normal */
                if (occlusion < 0.5) occlusion = 0.5;
                break;
            }
            const double sin_e = delta[2] / dist;
            if (sin_e > occlusion) occlusion = sin_e;
        }
        sum += occlusion;
    }
    return sum / directions;
}

/* Floor pixels of the corner, away from the image border by more than the
 * projected radius (no sampling outside the image). */
static void check_corner(int integration) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(corner_scene(), 200, 150, &view, &depth, &normal);
    hbao_params p = exact_params(integration);
    p.radius = 1.0f;
    p.directions = 32;
    p.steps = 32;
    float *ao = run(&p, &view, depth, normal);
    double error_sum = 0.0, worst = 0.0;
    int count = 0;
    for (int j = 0; j < view.height; j += 3) {
        for (int i = 0; i < view.width; i += 3) {
            const size_t k = (size_t)j * view.width + i;
            if (normal[3 * k + 2] < 0.5f) continue; /* floor pixels only */
            double w[3];
            scene_pixel_position(&view, i, j, depth[k], w);
            const double a = -w[0]; /* distance to the wall, R = 1 */
            /* projected radius in pixels, with a margin to the border */
            const double radius_px = 1.0 / (36.0 / 50.0 / view.width * depth[k]);
            if (i < radius_px || j < radius_px || i >= view.width - radius_px ||
                j >= view.height - radius_px || a < 0.05 || a > 1.2)
                continue;
            const double expected = 1.0 - (integration == HBAO_INTEGRATION_COSINE
                                               ? corner_cosine_occlusion(a)
                                               : corner_hbao_occlusion(&view, i, j, depth[k]));
            const double error = fabs(ao[k] - expected);
            error_sum += error;
            worst = error > worst ? error : worst;
            count++;
        }
    }
    CHECK(count > 40);
    /* 32 directions x 32 steps: the steps find the horizon up to one step
     * (1/32 of the radius) and pixel snapping; 0.02 mean and 0.06 worst
     * leave room for that and nothing like a wrong formula (which is off by
     * 0.1 or more near the wall). */
    printf("  corner (%s): %d pixels, mean |error| %.4f, worst %.4f\n",
           integration == HBAO_INTEGRATION_COSINE ? "cosine" : "hbao", count, error_sum / count,
           worst);
    CHECK(error_sum / count < 0.02);
    CHECK(worst < 0.06);
    free(ao);
    free(depth);
    free(normal);
}

TEST_CASE(corner_matches_analytic_cosine) {
    check_corner(HBAO_INTEGRATION_COSINE);
}

TEST_CASE(corner_matches_analytic_hbao) {
    check_corner(HBAO_INTEGRATION_HBAO);
}

TEST_CASE(corner_value_at_the_crease_is_one_half) {
    /* At the crease the wall takes exactly half the hemisphere, in both
     * solid angle and cosine weighting. */
    CHECK_NEAR(corner_cosine_occlusion(0.0), 0.5, 1e-12);
}

/* --- invariances --------------------------------------------------------- */

static scene boxes_scene(void) {
    scene s = corner_scene();
    /* a box standing on the floor: two visible faces and the top */
    scene_plane front = scene_plane_make(-1.5, 0, 0, -1, 0, 0);
    scene_plane_clip(&front, 0, 0, 1, 0.6);
    scene_plane_clip(&front, 0, 1, 0, 0.5);
    scene_plane side = scene_plane_make(0, -0.5, 0, 0, -1, 0);
    scene_plane_clip(&side, 0, 0, 1, 0.6);
    scene_plane_clip(&side, -1, 0, 0, 1.5);
    s.plane[s.planes++] = front;
    s.plane[s.planes++] = side;
    return s;
}

TEST_CASE(scaling_depth_and_radius_keeps_ao) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 128, 96, &view, &depth, &normal);
    const size_t pixels = (size_t)view.width * view.height;
    float *scaled = malloc(pixels * sizeof(float));
    const float factor = 7.5f;
    for (size_t k = 0; k < pixels; k++) scaled[k] = depth[k] < 1e9f ? depth[k] * factor : depth[k];
    for (int integration = 0; integration <= 1; integration++) {
        for (int half = 0; half <= 1; half++) {
            hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
            p.integration = integration;
            p.half_resolution = half;
            p.blur_size = 7;
            p.radius = 0.8f;
            float *a = run(&p, &view, depth, NULL);
            p.radius *= factor;
            float *b = run(&p, &view, scaled, NULL);
            float worst = 0.0f;
            for (size_t k = 0; k < pixels; k++) worst = fmaxf(worst, fabsf(a[k] - b[k]));
            /* Same geometry in other units: only float rounding differs
             * (positions carry ~1e-7 relative error; a snapped sample can
             * flip at a pixel boundary, hence 1e-3 rather than 1e-6). */
            CHECK_NEAR(worst, 0.0, 1e-3);
            free(a);
            free(b);
        }
    }
    free(scaled);
    free(depth);
    free(normal);
}

/* Brute force, written here independently from docs/algorithm.md: the
 * cosine estimator with 512 directions, marching every quarter pixel up to
 * the radius, in double precision, with the scene's exact normals. */
/* The camera-space point a sample at pixel (si, sj) sees: the rendered
 * depth's inside the image; outside it, the documented rule (docs/algorithm.md,
 * "Beyond the frame"), computed here in doubles from the scene's rays: the
 * surface at the nearest edge pixel continued as its tangent plane, met by
 * the pixel's ray. 0 where there is none (background, or the plane behind
 * the camera). The caller ends a direction past the band beyond the edges
 * (the longer side / 16). */
static int beyond_point(const scene_view *view, const float *depth, const float *normal_w, int si,
                        int sj, double q[3]) {
    const int ei = si < 0 ? 0 : si >= view->width ? view->width - 1 : si;
    const int ej = sj < 0 ? 0 : sj >= view->height ? view->height - 1 : sj;
    const size_t at = (size_t)ej * view->width + ei;
    const double ze = depth[at];
    if (ze >= 1e9) return 0;
    double o[3], d[3];
    scene_pixel_ray(view, ei, ej, o, d);
    if (ei == si && ej == sj) {
        for (int c = 0; c < 3; c++) q[c] = o[c] + ze * d[c];
        return 1;
    }
    const float *m = view->camera.world_to_camera;
    const float *nw = normal_w + 3 * at;
    double n[3], e[3];
    for (int r = 0; r < 3; r++) {
        n[r] = m[4 * r] * nw[0] + m[4 * r + 1] * nw[1] + m[4 * r + 2] * nw[2];
        e[r] = o[r] + ze * d[r];
    }
    scene_pixel_ray(view, si, sj, o, d);
    const double facing = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    const double t = (n[0] * (e[0] - o[0]) + n[1] * (e[1] - o[1]) + n[2] * (e[2] - o[2])) / facing;
    if (!(t > 0.0) || !isfinite(t)) return 0;
    for (int c = 0; c < 3; c++) q[c] = o[c] + t * d[c];
    return 1;
}

static double brute_force_cosine(const scene_view *view, const float *depth, const float *normal_w,
                                 int i, int j, double radius) {
    const int directions = 512;
    double o[3], d[3];
    double p[3];
    scene_pixel_ray(view, i, j, o, d);
    for (int c = 0; c < 3; c++) p[c] = o[c] + depth[(size_t)j * view->width + i] * d[c];
    const double pl = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    const double v[3] = {-p[0] / pl, -p[1] / pl, -p[2] / pl};
    const float *m = view->camera.world_to_camera;
    const float *nw = normal_w + 3 * ((size_t)j * view->width + i);
    double n[3];
    for (int r = 0; r < 3; r++)
        n[r] = m[4 * r] * nw[0] + m[4 * r + 1] * nw[1] + m[4 * r + 2] * nw[2];
    const double pixel = 36.0 / 50.0 / view->width; /* per unit depth, horizontal fit */
    const double radius_px = radius / (pixel * -p[2]);
    double visible = 0.0, open = 0.0;
    for (int k = 0; k < directions; k++) {
        const double theta = 2.0 * PI * (k + 0.5) / directions;
        const double dc = cos(theta), ds = sin(theta);
        const double dv = dc * v[0] + ds * v[1];
        double e[3] = {dc - v[0] * dv, ds - v[1] * dv, -v[2] * dv};
        const double el = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        for (int c = 0; c < 3; c++) e[c] /= el;
        const double mm[3] = {v[1] * e[2] - v[2] * e[1], v[2] * e[0] - v[0] * e[2],
                              v[0] * e[1] - v[1] * e[0]};
        const double nm = n[0] * mm[0] + n[1] * mm[1] + n[2] * mm[2];
        const double np[3] = {n[0] - mm[0] * nm, n[1] - mm[1] * nm, n[2] - mm[2] * nm};
        const double npl = sqrt(np[0] * np[0] + np[1] * np[1] + np[2] * np[2]);
        if (npl < 1e-9) continue;
        const double gamma = atan2((np[0] * e[0] + np[1] * e[1] + np[2] * e[2]) / npl,
                                   (np[0] * v[0] + np[1] * v[1] + np[2] * v[2]) / npl);
        double h = gamma + PI / 2;
        const double h_open = h;
        for (double t = 1.0; t <= radius_px; t += 0.25) {
            const int si = (int)floor(i + 0.5 + dc * t), sj = (int)floor(j + 0.5 - ds * t);
            const int band = (view->width > view->height ? view->width : view->height) / 16;
            if (si < -band || sj < -band || si >= view->width + band || sj >= view->height + band)
                break;
            if (si == i && sj == j) continue;
            double q[3];
            if (!beyond_point(view, depth, normal_w, si, sj, q)) continue;
            for (int c = 0; c < 3; c++) q[c] -= p[c];
            const double dist = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
            if (dist >= radius) continue;
            /* the sample's angle from V: through its elevation above the
             * tangent plane, or past the normal through its angle to V */
            const double cos_v = (q[0] * v[0] + q[1] * v[1] + q[2] * v[2]) / dist;
            double hs;
            /* past the normal: within gamma of V and rising above the
             * tangent plane at least as steeply as V */
            const double sin_s = (q[0] * n[0] + q[1] * n[1] + q[2] * n[2]) / dist;
            if (gamma > 0 && cos_v > cos(gamma) && sin_s > n[0] * v[0] + n[1] * v[1] + n[2] * v[2])
                hs = acos(fmin(1.0, cos_v));
            else
                hs = gamma + acos(fmax(-1.0, fmin(1.0, (q[0] * n[0] + q[1] * n[1] + q[2] * n[2]) /
                                                           dist / npl)));
            if (hs < h) h = hs;
        }
        /* visibility integral from 0 to h of cos(t - gamma) sin(t) dt */
#define HALF_SLICE(x) (0.25 * (-cos(2 * (x)-gamma) + cos(gamma) + 2 * (x)*sin(gamma)))
        visible += npl * HALF_SLICE(h);
        open += npl * HALF_SLICE(h_open);
#undef HALF_SLICE
    }
    return open > 0 ? visible / open : 1.0;
}

TEST_CASE(more_samples_converge_to_brute_force) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 120, 90, &view, &depth, &normal);
    const double radius = 0.7;
    /* reference on a sparse grid of pixels */
    int count = 0;
    static double reference[120 * 90];
    for (int j = 2; j < view.height; j += 4)
        for (int i = 2; i < view.width; i += 4) {
            const size_t k = (size_t)j * view.width + i;
            reference[k] =
                depth[k] < 1e9f ? brute_force_cosine(&view, depth, normal, i, j, radius) : 1.0;
            count++;
        }
    const int settings[4][2] = {{4, 3}, {8, 6}, {16, 16}, {32, 32}};
    double errors[4];
    for (int k = 0; k < 4; k++) {
        hbao_params p = exact_params(HBAO_INTEGRATION_COSINE);
        p.radius = (float)radius;
        p.directions = settings[k][0];
        p.steps = settings[k][1];
        float *ao = run(&p, &view, depth, normal);
        double sum = 0.0;
        for (int j = 2; j < view.height; j += 4)
            for (int i = 2; i < view.width; i += 4) {
                const size_t q = (size_t)j * view.width + i;
                sum += fabs(ao[q] - reference[q]);
            }
        errors[k] = sum / count;
        printf("  %2d directions x %2d steps: mean |AO - brute force| = %.4f\n", settings[k][0],
               settings[k][1], errors[k]);
        free(ao);
    }
    /* Each doubling of the samples lowers the error; the finest setting is
     * within 0.01 of the brute force (one step = 1/32 radius). */
    CHECK(errors[1] < errors[0]);
    CHECK(errors[2] < errors[1]);
    CHECK(errors[3] <= errors[2] + 1e-4);
    CHECK(errors[3] < 0.01);
    free(depth);
    free(normal);
}

/* Under a table: the camera, below the table top, looks at the floor under
 * it, so the table top lies between V and the floor's normal as seen from
 * the floor: the samples that matter are past the normal, where the half-occluded
 * rule decides (docs/algorithm.md). The library must match the brute force,
 * which applies the same documented rule independently. */
TEST_CASE(past_the_normal_matches_brute_force_under_a_table) {
    scene s;
    memset(&s, 0, sizeof s);
    s.planes = 2;
    s.plane[0] = scene_plane_make(0, 0, 0, 0, 0, 1);    /* the floor */
    s.plane[1] = scene_plane_make(0, 0, 0.5, 0, 0, -1); /* the table top's underside */
    scene_plane_clip(&s.plane[1], 0, -1, 0, -1.0); /* y >= 1: starting 1 m in front of the camera */
    const double eye[3] = {0, 0, 0.3}, target[3] = {0, 3.0, 0.0};
    scene_view view = make_view(120, 90, eye, target);
    float *depth, *normal;
    scene_render(&s, &view, &depth, &normal);
    const double radius = 0.7;
    hbao_params p = exact_params(HBAO_INTEGRATION_COSINE);
    p.radius = (float)radius;
    p.directions = 32;
    p.steps = 32;
    float *ao = run(&p, &view, depth, normal);
    double error_sum = 0.0, darkness = 0.0;
    int count = 0;
    for (int j = 2; j < view.height; j += 4)
        for (int i = 2; i < view.width; i += 4) {
            const size_t k = (size_t)j * view.width + i;
            if (depth[k] > 1e9f || normal[3 * k + 2] < 0.5f) continue; /* floor pixels */
            double w[3];
            scene_pixel_position(&view, i, j, depth[k], w);
            if (w[1] < 1.5) continue; /* under the table, past its edge */
            const double reference = brute_force_cosine(&view, depth, normal, i, j, radius);
            error_sum += fabs(ao[k] - reference);
            darkness += 1.0 - reference;
            count++;
        }
    CHECK(count > 50);
    printf("  %d floor pixels under the table: mean brute-force occlusion %.3f, mean |AO - brute "
           "force| %.4f\n",
           count, darkness / count, error_sum / count);
    CHECK(darkness / count > 0.1); /* the table does occlude: the case is not trivial */
    /* The table top is seen at grazing angles, so snapping moves a step's
     * elevation a lot and steps converge slowly: measured 0.17, 0.078,
     * 0.021 and 0.007 at 8, 16, 32 and 64 directions x as many steps. With
     * the rule broken (no sample ever past the normal) the error measured
     * 0.155 at 32 x 32; 0.04 is twice the measured error and a quarter of
     * that. */
    CHECK(error_sum / count < 0.04);
    free(ao);
    free(depth);
    free(normal);
}

/* Beyond the frame (docs/algorithm.md): a step past the image's edge sees
 * the surface at the nearest edge pixel continued as its tangent plane. The
 * wall's foot is darkened by the floor in front of it; a frame whose bottom
 * edge cuts the floor a few pixels below the crease keeps that floor, so the
 * wall pixels just above the crease get nearly the AO of a frame that shows
 * it: measured 0.0024 apart, where the rule before (a direction ends at the
 * edge) left them 0.23 apart, their AO without most of the floor's
 * occlusion (0.41). */
TEST_CASE(steps_past_the_frame_see_the_edge_surface_continued) {
    const scene s = corner_scene();
    const double eye[3] = {-2.5, 0.0, 2.0}, target[3] = {0.0, 0.0, 0.3};
    const int w = 160, h = 120;
    scene_view view = make_view(w, h, eye, target);
    float *depth, *normal;
    scene_render(&s, &view, &depth, &normal);
    int crease = -1; /* the first floor row at the middle column */
    for (int j = 0; j < h && crease < 0; j++)
        if (normal[3 * ((size_t)j * w + w / 2) + 2] > 0.5f) crease = j;
    CHECK(crease > 20 && crease < h - 20);
    hbao_params p = exact_params(HBAO_INTEGRATION_COSINE);
    p.radius = 0.3f;
    p.directions = 8;
    p.steps = 12;
    float *full = run(&p, &view, depth, normal);
    const int window_height = crease + 3;
    hbao_camera window;
    CHECK_RESULT(hbao_camera_crop(&view.camera, w, h, 0, 0, w, window_height, &window),
                 HBAO_SUCCESS);
    float *cut = malloc((size_t)w * window_height * sizeof(float));
    const hbao_channel d = {depth, 1, w}, n = {normal, 3, 3 * (int64_t)w};
    CHECK_RESULT(hbao_compute(&p, &window, w, window_height, &d, &n, cut, w), HBAO_SUCCESS);
    double difference = 0.0, occlusion = 0.0;
    int count = 0;
    for (int j = crease - 4; j < crease; j++)
        for (int i = 8; i < w - 8; i++) {
            const size_t k = (size_t)j * w + i;
            if (normal[3 * k] > -0.5f) continue; /* the wall's pixels */
            difference += fabs(cut[k] - full[k]);
            occlusion += 1.0 - full[k];
            count++;
        }
    CHECK(count > 300);
    printf("  %d wall pixels above the crease: occlusion %.3f, |cut frame - whole frame| %.4f\n",
           count, occlusion / count, difference / count);
    CHECK(occlusion / count > 0.1);
    CHECK(difference / count < 0.02);
    free(cut);
    free(full);
    free(depth);
    free(normal);
}

/* --- robustness ---------------------------------------------------------- */

static uint32_t rng_state = 12345u;
static uint32_t next_random(void) {
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}
static float random_unit(void) {
    return (float)(next_random() >> 8) / 16777216.0f;
}

TEST_CASE(random_and_degenerate_inputs_give_finite_ao_in_range) {
    static const float specials[] = {NAN,      INFINITY, -INFINITY, 0.0f,  -1.0f, 1e10f,
                                     65504.0f, 1e-38f,   1e-45f,    3e38f, 1e-3f, 1.0f};
    const int sizes[][2] = {{1, 1}, {1, 7}, {9, 1}, {2, 2}, {37, 23}, {64, 48}};
    for (int trial = 0; trial < 60; trial++) {
        const int w = sizes[trial % 6][0], h = sizes[trial % 6][1];
        const size_t pixels = (size_t)w * h;
        float *depth = malloc(pixels * sizeof(float));
        float *normal = malloc(pixels * 3 * sizeof(float));
        float *ao = malloc(pixels * sizeof(float));
        for (size_t k = 0; k < pixels; k++) {
            depth[k] = (next_random() % 4 == 0) ? specials[next_random() % 12]
                                                : 0.5f + 20.0f * random_unit();
            for (int c = 0; c < 3; c++)
                normal[3 * k + c] = (next_random() % 8 == 0) ? specials[next_random() % 12]
                                                             : 2.0f * random_unit() - 1.0f;
        }
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.radius = (trial % 5 == 0) ? 1e30f : 0.01f + 5.0f * random_unit();
        p.directions = (int)(next_random() % 80) - 5;
        p.steps = (int)(next_random() % 80) - 5;
        p.blur_size = (int)(next_random() % 80) - 5;
        p.blur_sharpness = 100.0f * random_unit();
        p.half_resolution = trial & 1;
        p.integration = (trial >> 1) & 1;
        p.falloff = (trial >> 2) & 1;
        p.angle_bias_degrees = 120.0f * random_unit() - 30.0f;
        p.strength = 20.0f * random_unit();
        p.threads = 1 + trial % 3;
        hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
        camera.projection =
            trial % 3 == 0 ? HBAO_PROJECTION_ORTHOGRAPHIC : HBAO_PROJECTION_PERSPECTIVE;
        camera.lens = 1.0f + 200.0f * random_unit();
        camera.shift_x = random_unit() - 0.5f;
        camera.sensor_fit = trial % 3;
        hbao_channel d = {depth, 1, w};
        hbao_channel n = {normal, 3, 3 * (int64_t)w};
        CHECK_RESULT(hbao_compute(&p, &camera, w, h, &d, (trial & 4) ? &n : NULL, ao, w),
                     HBAO_SUCCESS);
        int bad = 0;
        for (size_t k = 0; k < pixels; k++)
            if (!(ao[k] >= 0.0f && ao[k] <= 1.0f)) bad++;
        CHECK(bad == 0);
        free(depth);
        free(normal);
        free(ao);
    }
}

TEST_CASE(identical_output_for_any_thread_count) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 161, 117, &view, &depth, &normal);
    const size_t bytes = (size_t)view.width * view.height * sizeof(float);
    for (int variant = 0; variant < 4; variant++) {
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.half_resolution = variant & 1;
        p.integration = variant >> 1;
        p.blur_size = 15;
        p.threads = 1;
        float *one = run(&p, &view, depth, variant & 2 ? normal : NULL);
        const int counts[] = {2, 3, 8};
        for (int c = 0; c < 3; c++) {
            p.threads = counts[c];
            float *many = run(&p, &view, depth, variant & 2 ? normal : NULL);
            CHECK(memcmp(one, many, bytes) == 0);
            free(many);
        }
        free(one);
    }
    free(depth);
    free(normal);
}

TEST_CASE(bottom_up_rows_with_negative_stride) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 64, 48, &view, &depth, &normal);
    const int w = view.width, h = view.height;
    /* The same image stored bottom-up, as Blender's render passes are, with
     * depth in an RGBA-like 4-float pixel. */
    float *flipped = malloc((size_t)w * h * 4 * sizeof(float));
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++)
            flipped[4 * ((size_t)(h - 1 - j) * w + i)] = depth[(size_t)j * w + i];
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    float *top_down = run(&p, &view, depth, NULL);
    float *ao = malloc((size_t)w * h * sizeof(float));
    hbao_channel d = {flipped + 4 * (size_t)(h - 1) * w, 4, -4 * (int64_t)w};
    /* the output bottom-up too */
    CHECK_RESULT(
        hbao_compute(&p, &view.camera, w, h, &d, NULL, ao + (size_t)(h - 1) * w, -(int64_t)w),
        HBAO_SUCCESS);
    int mismatches = 0;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++)
            if (ao[(size_t)(h - 1 - j) * w + i] != top_down[(size_t)j * w + i]) mismatches++;
    CHECK(mismatches == 0);
    free(flipped);
    free(ao);
    free(top_down);
    free(depth);
    free(normal);
}

/* The pixels of ao whose bits differ from expected's; *occluded: those
 * with an expected AO under 0.9 (that the comparison is not of ones). */
/* Checks that `ao` is `expected` to the bit and that the view has occlusion
 * to compare (over 2 % of its pixels under 0.9); returns how many pixels
 * differ, for the caller's message. */
static int check_same_bits(const float *ao, const float *expected, int pixels) {
    int differ = 0, occluded = 0;
    for (int k = 0; k < pixels; k++) {
        differ += memcmp(&ao[k], &expected[k], sizeof(float)) != 0;
        occluded += expected[k] < 0.9f;
    }
    CHECK(occluded > pixels / 50);
    CHECK(differ == 0);
    return differ;
}

/* The depth in any layout (four floats a pixel, rows bottom-up; dense) and
 * its background in any of its spellings (0, -1, NaN, +-inf, at or past
 * background_depth): the same AO to the bit, at full and at half
 * resolution, where the half grid and the upsample read the caller's
 * channels directly (compute.c, upsample.c: no converted full-size copy),
 * with and without a back layer and a strength. Odd sizes: the upsample's
 * last column and row. */
TEST_CASE(depth_layouts_and_background_spellings_give_the_same_ao) {
    const int sizes[2][2] = {{64, 48}, {65, 47}};
    /* the view's floor reaches from 4.25 to 8.2: the far part is background */
    const float far = 7.0f;
    const float spellings[7] = {0.0f, -1.0f, NAN, INFINITY, -INFINITY, far, 1e30f};
    for (int s = 0; s < 2; s++) {
        scene_view view;
        float *depth, *normal;
        render_standard_view(boxes_scene(), sizes[s][0], sizes[s][1], &view, &depth, &normal);
        const int w = view.width, h = view.height;
        float *back = malloc((size_t)w * h * sizeof(float));
        float *rgba = malloc((size_t)w * h * 4 * sizeof(float));
        float *back_pairs = malloc((size_t)w * h * 2 * sizeof(float));
        int background = 0;
        for (int j = 0; j < h; j++) {
            for (int i = 0; i < w; i++) {
                const size_t k = (size_t)j * w + i, flipped = (size_t)(h - 1 - j) * w + i;
                const int sky = !(depth[k] > 0.0f && depth[k] < far);
                background += sky;
                if (sky) depth[k] = 0.0f;
                back[k] = sky ? 0.0f : depth[k] + 0.05f;
                rgba[4 * flipped] = sky ? spellings[k % 7] : depth[k];
                rgba[4 * flipped + 1] = rgba[4 * flipped + 2] = rgba[4 * flipped + 3] = 7.0f;
                back_pairs[2 * flipped] = sky ? spellings[(k + 1) % 7] : back[k];
                back_pairs[2 * flipped + 1] = -3.0f;
            }
        }
        CHECK(background > w * h / 10 && background < w * h * 9 / 10);
        const hbao_channel d = {rgba + 4 * (size_t)(h - 1) * w, 4, -4 * (int64_t)w};
        const hbao_channel b = {back_pairs + 2 * (size_t)(h - 1) * w, 2, -2 * (int64_t)w};
        const hbao_channel n = {normal, 3, 3 * (int64_t)w};
        for (int variant = 0; variant < 8; variant++) {
            hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
            p.background_depth = far;
            p.half_resolution = variant & 1;
            p.strength = variant & 2 ? 1.5f : 1.0f;
            const int layered = (variant & 4) != 0;
            float *expected = run_layers(&p, &view, depth, normal, layered ? back : NULL);
            float *ao = malloc((size_t)w * h * sizeof(float));
            CHECK_RESULT(
                hbao_compute_layers(&p, &view.camera, w, h, &d, &n, layered ? &b : NULL, ao, w),
                HBAO_SUCCESS);
            const int differ = check_same_bits(ao, expected, w * h);
            if (differ)
                printf("  %dx%d, half %d, strength %g, layered %d: %d pixels differ\n", w, h,
                       p.half_resolution, (double)p.strength, layered, differ);
            free(expected);
            free(ao);
        }
        free(back);
        free(rgba);
        free(back_pairs);
        free(depth);
        free(normal);
    }
}

/* The output written over the depth it is computed from (in place), in the
 * same row order or the opposite one, at full and half resolution: the AO
 * of separate buffers, to the bit. The half resolution's upsample reads the
 * caller's depth rows while it writes other output rows, so there the
 * depth is copied first (compute.c, output_overlaps_depth); it gave 1027
 * pixels of 3072 wrong before. */
TEST_CASE(ao_computed_in_place_over_its_depth) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 64, 48, &view, &depth, &normal);
    const int w = view.width, h = view.height;
    float *shared = malloc((size_t)w * h * sizeof(float));
    for (int variant = 0; variant < 4; variant++) {
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.radius = 1.5f;
        p.half_resolution = variant & 1;
        const int flipped = (variant & 2) != 0;
        float *expected = run(&p, &view, depth, normal);
        for (int j = 0; j < h; j++)
            memcpy(shared + (size_t)(flipped ? h - 1 - j : j) * w, depth + (size_t)j * w,
                   (size_t)w * sizeof(float));
        const hbao_channel d = {flipped ? shared + (size_t)(h - 1) * w : shared, 1,
                                flipped ? -(int64_t)w : w};
        const hbao_channel n = {normal, 3, 3 * (int64_t)w};
        CHECK_RESULT(hbao_compute(&p, &view.camera, w, h, &d, &n, shared, w), HBAO_SUCCESS);
        const int differ = check_same_bits(shared, expected, w * h);
        if (differ)
            printf("  half %d, %s row order: %d pixels differ\n", p.half_resolution,
                   flipped ? "opposite" : "the same", differ);
        free(expected);
    }
    free(shared);
    free(depth);
    free(normal);
}

/* Normals read as x, y, z three floats apart (normals.c's vector read of a
 * whole chunk) or in any other layout (four floats a pixel, rows bottom-up,
 * a row shorter than a chunk): the same AO, to the bit. */
TEST_CASE(normal_layouts_give_the_same_ao) {
    const int sizes[2][2] = {{203, 157}, {40, 30}}; /* chunks and a tail; a row in one tail */
    for (int s = 0; s < 2; s++) {
        scene_view view;
        float *depth, *normal;
        render_standard_view(boxes_scene(), sizes[s][0], sizes[s][1], &view, &depth, &normal);
        const int w = view.width, h = view.height;
        float *rgba = malloc((size_t)w * h * 4 * sizeof(float));
        for (int j = 0; j < h; j++)
            for (int i = 0; i < w; i++)
                for (int c = 0; c < 4; c++)
                    rgba[4 * ((size_t)(h - 1 - j) * w + i) + c] =
                        c < 3 ? normal[3 * ((size_t)j * w + i) + c] : 1.0f;
        for (int half = 0; half < 2; half++) {
            hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
            p.half_resolution = half;
            float *packed = run(&p, &view, depth, normal);
            float *ao = malloc((size_t)w * h * sizeof(float));
            const hbao_channel d = {depth, 1, w};
            const hbao_channel n = {rgba + 4 * (size_t)(h - 1) * w, 4, -4 * (int64_t)w};
            CHECK_RESULT(hbao_compute(&p, &view.camera, w, h, &d, &n, ao, w), HBAO_SUCCESS);
            int mismatches = 0;
            for (int k = 0; k < w * h; k++) mismatches += ao[k] != packed[k];
            CHECK(mismatches == 0);
            free(ao);
            free(packed);
        }
        free(rgba);
        free(depth);
        free(normal);
    }
}

/* A given normal of any finite length is used: scaled by a power of two
 * (exact), by itself or through the matrix (a world of another unit), the
 * AO is the same to the bit, also where its squares overflow float. */
TEST_CASE(normals_of_any_finite_length_give_the_same_ao) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 96, 64, &view, &depth, &normal);
    const size_t values = (size_t)view.width * view.height * 3;
    float *scaled = malloc(values * sizeof(float));
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    float *reference = run(&p, &view, depth, normal);
    /* (normal scale, matrix scale) as powers of two: the matrix's rotation
     * rows may be up to 1e15 long (camera.c) */
    const int exponents[][2] = {{40, 0}, {63, 0}, {64, 0}, {100, 0}, {126, 0}, {20, 49}, {70, 49}};
    for (size_t e = 0; e < sizeof exponents / sizeof exponents[0]; e++) {
        for (size_t k = 0; k < values; k++) scaled[k] = ldexpf(normal[k], exponents[e][0]);
        scene_view wide = view;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                wide.camera.world_to_camera[4 * r + c] =
                    ldexpf(view.camera.world_to_camera[4 * r + c], exponents[e][1]);
        float *ao = run(&p, &wide, depth, scaled);
        int mismatches = 0;
        for (int k = 0; k < view.width * view.height; k++) mismatches += ao[k] != reference[k];
        if (mismatches != 0)
            printf("  normals 2^%d, matrix 2^%d: %d pixels differ\n", exponents[e][0],
                   exponents[e][1], mismatches);
        CHECK(mismatches == 0);
        free(ao);
    }
    free(reference);
    free(scaled);
    free(depth);
    free(normal);
}

/* A camera scaled unevenly (or under a parent scaled so): world_to_camera
 * as camera.matrix_world inverted has rotation rows each over one axis's
 * scale. Its normals turn as the rotation's: the AO is that of the
 * rotation alone, to float rounding; the rows taken as given leaned the
 * normals towards the shorter axes (AO off by up to 0.25, a review's find). */
TEST_CASE(an_unevenly_scaled_camera_turns_normals_as_its_rotation) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 96, 64, &view, &depth, &normal);
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    float *reference = run(&p, &view, depth, normal);
    const float scales[][3] = {{1.0f, 2.5f, 0.6f}, {3.0f, 3.0f, 0.2f}, {0.01f, 1.0f, 1.0f}};
    for (size_t s = 0; s < sizeof scales / sizeof scales[0]; s++) {
        scene_view scaled = view;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                scaled.camera.world_to_camera[4 * r + c] =
                    view.camera.world_to_camera[4 * r + c] / scales[s][r];
        float *ao = run(&p, &scaled, depth, normal);
        float largest = 0.0f;
        for (int k = 0; k < view.width * view.height; k++)
            largest = fmaxf(largest, fabsf(ao[k] - reference[k]));
        printf("  scales %g %g %g: largest AO difference %g\n", scales[s][0], scales[s][1],
               scales[s][2], largest);
        CHECK(largest <= 1e-4f);
        free(ao);
    }
    free(reference);
    free(depth);
    free(normal);
}

/* --- stages ---------------------------------------------------------------- */

TEST_CASE(half_resolution_is_close_to_full) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 160, 120, &view, &depth, &normal);
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.directions = 16;
    p.steps = 12;
    p.blur_size = 9;
    float *full = run(&p, &view, depth, normal);
    p.half_resolution = 1;
    float *half = run(&p, &view, depth, normal);
    double sum = 0.0;
    const int pixels = view.width * view.height;
    for (int k = 0; k < pixels; k++) sum += fabs(full[k] - half[k]);
    printf("  mean |full - half| = %.4f\n", sum / pixels);
    /* Half resolution samples a quarter of the pixels; on smooth AO the
     * difference stays small (measured ~0.01), edges add a little. */
    CHECK(sum / pixels < 0.03);
    free(full);
    free(half);
    free(depth);
    free(normal);
}

TEST_CASE(blur_keeps_depth_edges) {
    /* Left half: AO 1 region on a near plane; right half: far plane. The blur
     * must not move AO across the edge, and must average noise inside. */
    const int w = 64, h = 16;
    float depth[64 * 16];
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) depth[j * w + i] = i < w / 2 ? 2.0f : 6.0f;
    hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.blur_size = 15;
    p.blur_sharpness = 8.0f;
    float ao[64 * 16];
    hbao_channel d = {depth, 1, w};
    CHECK_RESULT(hbao_compute(&p, &camera, w, h, &d, NULL, ao, w), HBAO_SUCCESS);
    /* The far plane right of the edge is occluded by the near plane's edge?
     * No: the near plane is in front, the far plane behind it; the near
     * plane's pixels see nothing above them. */
    CHECK_NEAR(ao[8 * w + 5], 1.0f, 1e-4);
    p.blur_size = 0;
    float sharp[64 * 16];
    CHECK_RESULT(hbao_compute(&p, &camera, w, h, &d, NULL, sharp, w), HBAO_SUCCESS);
    /* near-plane pixels next to the edge: unchanged by the blur, because the
     * far plane's taps are 200% deeper (the range weight F is 0 there) */
    CHECK_NEAR(ao[8 * w + w / 2 - 1], sharp[8 * w + w / 2 - 1], 1e-4);
}

TEST_CASE(strength_is_a_power) {
    /* at full and at half resolution, whose output the upsample writes */
    scene_view view;
    float *depth, *normal;
    render_standard_view(corner_scene(), 64, 48, &view, &depth, &normal);
    for (int half = 0; half <= 1; half++) {
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.half_resolution = half;
        float *base = run(&p, &view, depth, normal);
        p.strength = 2.0f;
        float *squared = run(&p, &view, depth, normal);
        p.strength = 0.0f;
        float *none = run(&p, &view, depth, normal);
        double darkest = 1.0;
        for (int k = 0; k < view.width * view.height; k++) {
            CHECK_NEAR(squared[k], base[k] * base[k], 1e-5);
            CHECK_NEAR(none[k], 1.0f, 0.0);
            darkest = fmin(darkest, base[k]);
        }
        CHECK(darkest < 0.8); /* the corner is occluded at all */
        free(base);
        free(squared);
        free(none);
    }
    free(depth);
    free(normal);
}

TEST_CASE(background_never_occludes) {
    /* A floor seen from above with a square of background (a hole, depth
     * 1e10) in the middle: the hole must not darken the floor around it. */
    const double eye[3] = {0, -1e-3, 5}, target[3] = {0, 0, 0};
    scene s;
    memset(&s, 0, sizeof s);
    s.planes = 1;
    s.plane[0] = scene_plane_make(0, 0, 0, 0, 0, 1);
    scene_view view = make_view(64, 64, eye, target);
    float *depth, *normal;
    scene_render(&s, &view, &depth, &normal);
    for (int j = 24; j < 40; j++)
        for (int i = 24; i < 40; i++) depth[j * 64 + i] = (i + j) % 2 ? 1e10f : 65504.0f;
    depth[0] = NAN;
    depth[1] = INFINITY;
    for (int integration = 0; integration <= 1; integration++) {
        hbao_params p = exact_params(integration);
        p.radius = 1.0f;
        p.blur_size = 9;
        float *ao = run(&p, &view, depth, NULL);
        float worst = 1.0f;
        for (int k = 0; k < 64 * 64; k++) worst = fminf(worst, ao[k]);
        CHECK_NEAR(worst, 1.0f, 1e-4);
        free(ao);
    }
    free(depth);
    free(normal);
}

TEST_CASE(tiny_projected_radius_gives_one) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(corner_scene(), 64, 48, &view, &depth, &normal);
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    /* under one pixel: 1e-3 units at depth ~6 with 64 px over a 36/50 view */
    p.radius = 1e-3f;
    float *ao = run(&p, &view, depth, normal);
    for (int k = 0; k < view.width * view.height; k++) CHECK_NEAR(ao[k], 1.0f, 0.0);
    free(ao);
    free(depth);
    free(normal);
}

/* The variants of simd_paths_match_scalar_reference, dealt out to
 * SIMD_PATH_PARTS cases (variant % SIMD_PATH_PARTS is the case's part), so
 * that ctest runs them side by side and the ARM64 run under qemu
 * (scripts/test_arm64.sh), where all of them took some 350 s, can keep
 * them. */
#define SIMD_PATH_VARIANTS 112
#define SIMD_PATH_PARTS 4

/* Every SIMD kernel must give exactly the scalar reference's floats: they
 * perform the same operations in the same order. A kernel this CPU lacks
 * falls back to the one below it, so the comparison still runs. */
static void simd_paths_match_scalar_reference(int part) {
    scene_view view;
    float *depth, *normal;
    /* odd sizes: row tails that the SIMD kernels leave to scalar code */
    render_standard_view(boxes_scene(), 203, 157, &view, &depth, &normal);
    for (int k = 0; k < 300; k++)
        depth[(k * 7919) % (view.width * view.height)] = 1e10f; /* holes */
    /* specks at a tenth of their depth, more than HBAO_BLOCK_DEPTH_RATIO
     * nearer: their blocks are searched in classes of one step each */
    for (int k = 0; k < 300; k++) depth[(k * 6007) % (view.width * view.height)] *= 0.1f;
    /* given normals too short to trust, reconstructed from depth among
     * pixels whose normals are used as given */
    for (int k = 0; k < 300; k++) {
        float *n = normal + 3 * ((size_t)(k * 104729) % ((size_t)view.width * view.height));
        n[0] = n[1] = n[2] = 0.01f;
    }
    const size_t bytes = (size_t)view.width * view.height * sizeof(float);
    /* (AUTO runs the code of the kernel that hbao_implementation_that_runs
     * names for it, the fastest of these that runs: every stage chooses its
     * copy through that function, horizon.c's choose_kernel and
     * internal_finish.h's hbao_finish_implementation. Run again here, it
     * took a quarter of this test's time under qemu, scripts/test_arm64.sh:
     * part 1 took 70.3 s of one core, 52.6 s without it.) */
    const int kernels[] = {HBAO_IMPLEMENTATION_GENERIC, HBAO_IMPLEMENTATION_AVX2,
                           HBAO_IMPLEMENTATION_AVX512};
    /* Bit 4: a finite thickness (0.2, about a third of the box's height),
     * which skips some samples in every kernel alike. Bit 5: 40 steps over a
     * radius of 10 to 20 pixels, so consecutive steps snap to the same pixel
     * (the SIMD kernels fetch such a pixel once). Bit 6 (variants 64 to 95,
     * bit 5 clear): a back-face layer, known on two pixels in three. Bit 1
     * also lowers the blur's sharpness to 2, where a tap on background does
     * not weigh 0 by its depth difference alone (blur.c,
     * background_needs_check) and the vector loop must test it. The
     * direction count cycles through an odd one, even ones that the SIMD
     * kernels set up in opposite pairs (6, 16: horizon_simd.h, block_ao) and
     * an even one above those (18), set up one by one. Variants 96 to 111
     * repeat 0 to 15 with a radius of 8, whose steps reach past the band
     * beyond the edges and a whole image away: a block near one side steps
     * into the band past the other (a plain step there must still end the
     * direction, as hbao_step_offset does). */
    const int direction_counts[4] = {7, 6, 16, 18};
    float *back = malloc(bytes);
    for (int k = 0; k < view.width * view.height; k++)
        back[k] = k % 3 == 0 ? 0.0f : depth[k] + 0.05f + 0.1f * (float)(k % 5);
    for (int variant = part; variant < SIMD_PATH_VARIANTS; variant += SIMD_PATH_PARTS) {
        const int far = variant >= 96;
        const float *layer = (far ? variant & 4 : variant & 64) ? back : NULL;
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.thickness = (variant & 16) ? 0.2f : 0.0f;
        p.integration = variant & 1;
        p.falloff = (variant >> 1) & 1;
        p.blur_sharpness = variant & 2 ? 2.0f : HBAO_DEFAULT_BLUR_SHARPNESS;
        p.half_resolution = (variant >> 2) & 1;
        p.angle_bias_degrees = (variant & 8) ? 0.0f : 20.0f;
        p.directions = direction_counts[(variant + variant / 8) % 4];
        p.steps = far ? 12 : (variant & 32) ? 40 : 5;
        p.radius = far ? 8.0f : (variant & 32) ? 0.3f : 0.9f;
        view.camera.projection =
            (variant & 8) ? HBAO_PROJECTION_ORTHOGRAPHIC : HBAO_PROJECTION_PERSPECTIVE;
        p.implementation = HBAO_IMPLEMENTATION_SCALAR;
        float *scalar = run_layers(&p, &view, depth, (variant & 4) ? NULL : normal, layer);
        for (size_t k = 0; k < sizeof kernels / sizeof kernels[0]; k++) {
            /* a kernel this CPU lacks runs another of the list */
            if (!implementation_runs_itself(kernels[k])) continue;
            p.implementation = kernels[k];
            float *fast = run_layers(&p, &view, depth, (variant & 4) ? NULL : normal, layer);
            int differing = 0;
            for (int q = 0; q < view.width * view.height; q++) differing += scalar[q] != fast[q];
            if (differing)
                printf("  variant %d, kernel %d: %d pixels differ\n", variant, kernels[k],
                       differing);
            CHECK(memcmp(scalar, fast, bytes) == 0);
            free(fast);
        }
        free(scalar);
    }
    free(back);
    free(depth);
    free(normal);
}

TEST_CASE(simd_paths_match_scalar_reference_part_1_of_4) {
    simd_paths_match_scalar_reference(0);
}
TEST_CASE(simd_paths_match_scalar_reference_part_2_of_4) {
    simd_paths_match_scalar_reference(1);
}
TEST_CASE(simd_paths_match_scalar_reference_part_3_of_4) {
    simd_paths_match_scalar_reference(2);
}
TEST_CASE(simd_paths_match_scalar_reference_part_4_of_4) {
    simd_paths_match_scalar_reference(3);
}
_Static_assert(SIMD_PATH_PARTS == 4, "one case for each part");

/* A grid far taller than wide (or wider than tall): the band past the
 * edges (max(W, H) / 16) is cut to what a step less than an image away can
 * reach on each axis, so the padded depth the SIMD kernels read and the
 * fill of its band stay within their buffers (an early form read before
 * the plane tables at 1 x 1152 and sized 2.4 GB for 65536 x 1), and every
 * kernel still gives the reference's floats. */
TEST_CASE(long_thin_images_match_the_scalar_reference) {
    const int sizes[][2] = {{3, 1200}, {1, 1152}, {1200, 2}, {5, 5}};
    for (int k = 0; k < 4; k++) {
        scene_view view;
        float *depth, *normal;
        render_standard_view(corner_scene(), sizes[k][0], sizes[k][1], &view, &depth, &normal);
        const size_t bytes = (size_t)view.width * view.height * sizeof(float);
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.radius = 2.0f;
        p.implementation = HBAO_IMPLEMENTATION_SCALAR;
        float *scalar = run(&p, &view, depth, normal);
        for (int kernel = HBAO_IMPLEMENTATION_AVX2; kernel <= HBAO_IMPLEMENTATION_GENERIC;
             kernel++) {
            if (!implementation_runs_itself(kernel)) continue; /* runs another of the list */
            p.implementation = kernel;
            float *fast = run(&p, &view, depth, normal);
            CHECK(memcmp(scalar, fast, bytes) == 0);
            for (size_t q = 0; q < bytes / sizeof(float); q++)
                CHECK(fast[q] >= 0.0f && fast[q] <= 1.0f);
            free(fast);
        }
        free(scalar);
        free(depth);
        free(normal);
    }
}

/* A radius under 2^-64 scene units, every length with it (a scene modelled
 * in tiny units): 1 / radius^2 overflowed to +inf, the quadratic falloff's
 * weight of a sample became -inf, and a step on the pixel of the step
 * before, which the SIMD kernels skip (it changes nothing), gave the
 * scalar reference -inf * 0 = NaN, an AO of 0: on 224 of this scene's
 * pixels at 2^-64 the kernels disagreed with it (a review). The factor is
 * capped at FLT_MAX (hbao_settings.inv_radius2): every kernel gives the
 * reference's floats, and none is 0 where the scene at its own scale has
 * no pixel darker than 0.2. More steps than the radius has pixels, so that
 * steps repeat pixels; given normals tilted off the depth's. */
TEST_CASE(a_tiny_radius_with_quadratic_falloff_matches_the_scalar_reference) {
    enum { W = 64, H = 48 };
    static float depth[W * H], normal[3 * W * H], scalar[W * H], fast[W * H];
    const int kernels[] = {HBAO_IMPLEMENTATION_GENERIC, HBAO_IMPLEMENTATION_AVX2,
                           HBAO_IMPLEMENTATION_AVX512};
    const int exponents[] = {0, 64, 70, 100};
    for (int e = 0; e < 4; e++)
        for (int integration = 0; integration < 2; integration++) {
            for (int j = 0; j < H; j++)
                for (int i = 0; i < W; i++) {
                    float z = 4.0f + 0.05f * (float)(H - j); /* a floor, a box on it */
                    if (i > 20 && i < 40 && j > 15 && j < 35) z -= 0.6f;
                    depth[j * W + i] = ldexpf(z, -exponents[e]);
                    const float a = 0.15f * (float)((i * 7 + j * 3) % 11);
                    normal[3 * (j * W + i) + 0] = sinf(a);
                    normal[3 * (j * W + i) + 1] = 0.3f;
                    normal[3 * (j * W + i) + 2] = cosf(a);
                }
            hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
            p.radius = ldexpf(0.3f, -exponents[e]);
            p.steps = 32;
            p.falloff = HBAO_FALLOFF_QUADRATIC;
            p.integration = integration;
            p.blur_size = 0;
            const hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
            const hbao_channel d = {depth, 1, W}, n = {normal, 3, 3 * W};
            p.implementation = HBAO_IMPLEMENTATION_SCALAR;
            CHECK(hbao_compute(&p, &camera, W, H, &d, &n, scalar, W) == HBAO_SUCCESS);
            float darkest = 1.0f;
            for (int k = 0; k < W * H; k++) darkest = scalar[k] < darkest ? scalar[k] : darkest;
            CHECK(darkest > 0.2f);
            for (int k = 0; k < 3; k++) {
                if (!implementation_runs_itself(kernels[k])) continue;
                p.implementation = kernels[k];
                CHECK(hbao_compute(&p, &camera, W, H, &d, &n, fast, W) == HBAO_SUCCESS);
                CHECK(memcmp(scalar, fast, sizeof fast) == 0);
            }
        }
}

/* The SIMD kernels plan a direction's steps a vector at a time, and two
 * directions in one vector where the steps fit in half of it (up to 8); a
 * group's plans are made ahead, two at a time or one (horizon_simd.h,
 * plan_two and plan_ahead). Every step count around those halves and
 * wholes, and direction counts below, at and above the plans kept ahead
 * and the paired groups, against the scalar reference: perspective and
 * orthographic, with and without a back layer, both integrations. */
TEST_CASE(every_step_and_direction_count_matches_the_scalar_reference) {
    scene_view view;
    float *depth, *normal;
    render_standard_view(boxes_scene(), 141, 97, &view, &depth, &normal);
    const int pixels = view.width * view.height;
    for (int k = 0; k < 60; k++) depth[(k * 7919) % pixels] = 1e10f; /* holes */
    for (int k = 0; k < 60; k++) depth[(k * 6007) % pixels] *= 0.1f; /* specks */
    const size_t bytes = (size_t)pixels * sizeof(float);
    float *back = malloc(bytes);
    for (int k = 0; k < pixels; k++)
        back[k] = k % 3 == 0 ? 0.0f : depth[k] + 0.05f + 0.1f * (float)(k % 5);
    const int step_counts[] = {1, 3, 7, 8, 9, 16, 17};
    const int direction_counts[] = {1, 2, 3, 5, 8, 17};
    const int kernels[] = {HBAO_IMPLEMENTATION_GENERIC, HBAO_IMPLEMENTATION_AVX2,
                           HBAO_IMPLEMENTATION_AVX512};
    int differing_runs = 0;
    for (int a = 0; a < 7; a++)
        for (int d = 0; d < 6; d++)
            for (int variant = 0; variant < 8; variant++) {
                hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
                p.steps = step_counts[a];
                p.directions = direction_counts[d];
                p.integration = variant & 1;
                p.half_resolution = (a + d) & 1;
                p.radius = (a + d + variant) & 2 ? 0.3f : 0.9f;
                const float *layer = variant & 2 ? back : NULL;
                view.camera.projection =
                    variant & 4 ? HBAO_PROJECTION_ORTHOGRAPHIC : HBAO_PROJECTION_PERSPECTIVE;
                p.implementation = HBAO_IMPLEMENTATION_SCALAR;
                float *scalar = run_layers(&p, &view, depth, normal, layer);
                for (int k = 0; k < 3; k++) {
                    if (!implementation_runs_itself(kernels[k]))
                        continue; /* runs another of the list */
                    p.implementation = kernels[k];
                    float *fast = run_layers(&p, &view, depth, normal, layer);
                    if (memcmp(scalar, fast, bytes) != 0) {
                        differing_runs++;
                        printf("  %d steps, %d directions, variant %d, kernel %d differ\n", p.steps,
                               p.directions, variant, kernels[k]);
                    }
                    free(fast);
                }
                free(scalar);
            }
    CHECK(differing_runs == 0);
    free(back);
    free(depth);
    free(normal);
}

/* A post at the lens (depth 0.25, four columns wide, every row) in front of
 * the corner (depths 4 to 7): the pixels of the corner that share a block
 * with it and lie beyond its reach keep their AO. With one step length for
 * a block (the post's, 20 times the corner's projected radius) every step of
 * theirs lay past their own radius, and their AO was 1: a light band 64
 * columns wide (an exploratory run: up to 0.66 lighter). Compared with the
 * corner without the post: the same AO but where the post hid a sample, or
 * where a block's nearest corner pixel, and so its step, changed under it
 * (mean 0.0015, worst 0.10). Every kernel. */
TEST_CASE(a_post_at_the_lens_leaves_the_ao_of_its_blocks) {
    enum { posts = 3 };
    static const int post_columns[posts] = {66, 130, 194}; /* spans 1, 2 and 3 */
    scene_view view;
    float *depth, *normal;
    render_standard_view(corner_scene(), 256, 150, &view, &depth, &normal);
    const size_t pixels = (size_t)view.width * view.height;
    float *post_depth = malloc(pixels * sizeof(float));
    float *post_normal = malloc(3 * pixels * sizeof(float));
    memcpy(post_depth, depth, pixels * sizeof(float));
    memcpy(post_normal, normal, 3 * pixels * sizeof(float));
    for (int j = 0; j < view.height; j++)
        for (int q = 0; q < posts; q++)
            for (int i = post_columns[q]; i < post_columns[q] + 4; i++) {
                const size_t k = (size_t)j * view.width + i;
                post_depth[k] = 0.25f;
                /* facing the camera, which looks along +x and down */
                post_normal[3 * k] = -1.0f;
                post_normal[3 * k + 1] = post_normal[3 * k + 2] = 0.0f;
            }
    const int kernels[] = {HBAO_IMPLEMENTATION_SCALAR, HBAO_IMPLEMENTATION_GENERIC,
                           HBAO_IMPLEMENTATION_AVX2, HBAO_IMPLEMENTATION_AVX512};
    for (int kernel = 0; kernel < 4; kernel++) {
        hbao_params p = exact_params(HBAO_INTEGRATION_COSINE);
        p.radius = 0.3f; /* about 16 pixels at the corner */
        p.directions = 8;
        p.steps = 16;
        if (!implementation_runs_itself(kernels[kernel])) continue; /* runs another of the list */
        p.implementation = kernels[kernel];
        float *plain = run(&p, &view, depth, normal);
        float *with_post = run(&p, &view, post_depth, post_normal);
        double difference_sum = 0.0, worst = 0.0;
        int count = 0;
        for (int j = 0; j < view.height; j++) {
            for (int q = 0; q < posts; q++) {
                /* the rest of the post's span, beyond its reach */
                for (int i = post_columns[q] + 28; i < (post_columns[q] / 64 + 1) * 64; i++) {
                    const size_t k = (size_t)j * view.width + i;
                    if (!(depth[k] < 1e9f) || plain[k] > 0.95f) continue; /* occluded only */
                    const double difference = fabs(with_post[k] - plain[k]);
                    difference_sum += difference;
                    worst = difference > worst ? difference : worst;
                    count++;
                }
            }
        }
        printf("  kernel %d: %d occluded pixels, mean |difference| %.4f, worst %.4f\n",
               kernels[kernel], count, difference_sum / count, worst);
        /* one step length for the block: mean 0.19, worst 0.61 */
        CHECK(count > 200);
        CHECK(difference_sum / count < 0.02);
        CHECK(worst < 0.2);
        free(plain);
        free(with_post);
    }
    free(post_depth);
    free(post_normal);
    free(depth);
    free(normal);
}

/* A plate (a vertical strip 1 unit wide) floating PLATE_GAP in front of a
 * wall that faces the camera: its edges darken the wall beside its
 * silhouette when occluders are infinitely thick (the halo of a foreground
 * object on the background). */
#define PLATE_GAP 0.3
static scene plate_before_wall(void) {
    scene s;
    memset(&s, 0, sizeof s);
    s.planes = 2;
    s.plane[0] = scene_plane_make(0, 0, 0, 0, -1, 0);
    s.plane[1] = scene_plane_make(0, -PLATE_GAP, 0, 0, -1, 0);
    scene_plane_clip(&s.plane[1], 1, 0, 0, 0.5);
    scene_plane_clip(&s.plane[1], -1, 0, 0, 0.5);
    return s;
}

/* The same plate as a slab `thickness` deep (front, back and the two sides
 * that the camera cannot see): what a back-face layer describes. */
static scene plate_slab_before_wall(double thickness) {
    scene s = plate_before_wall();
    const double back_y = -PLATE_GAP + thickness;
    s.plane[s.planes] = scene_plane_make(0, back_y, 0, 0, 1, 0);
    scene_plane_clip(&s.plane[s.planes], 1, 0, 0, 0.5);
    scene_plane_clip(&s.plane[s.planes++], -1, 0, 0, 0.5);
    for (int side = -1; side <= 1; side += 2) {
        s.plane[s.planes] = scene_plane_make(0.5 * side, 0, 0, side, 0, 0);
        scene_plane_clip(&s.plane[s.planes], 0, -1, 0, PLATE_GAP);
        scene_plane_clip(&s.plane[s.planes++], 0, 1, 0, back_y);
    }
    return s;
}

/* Whether pixel k (12 or more pixels from the image's sides) of
 * render_plate_before_wall's depth is the wall within 12 pixels of the
 * plate's silhouette along its row. */
static int wall_beside_the_plate(const float *depth, int k) {
    if (depth[k] < 4.9f) return 0; /* the plate (depth ~4.7) */
    for (int di = -12; di <= 12; di += 3)
        if (depth[k + di] < 4.9f) return 1;
    return 0;
}

static void render_plate_before_wall(scene_view *view, float **depth, float **normal) {
    const scene s = plate_before_wall();
    const double eye[3] = {0.3, -5.0, 0.2}, target[3] = {0, 0, 0};
    *view = make_view(128, 96, eye, target);
    scene_render(&s, view, depth, normal);
}

/* Ray-traced ambient occlusion with a distance limit: the cosine-weighted
 * fraction of the hemisphere around world normal n at world point p whose
 * rays hit nothing closer than `radius` (24 x 24 stratified rays). */
static double ray_traced_ao(const scene *s, const double p[3], const double n[3], double radius) {
    double t1[3], t2[3];
    const double a[3] = {fabs(n[0]) < 0.9 ? 1.0 : 0.0, fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    t1[0] = n[1] * a[2] - n[2] * a[1];
    t1[1] = n[2] * a[0] - n[0] * a[2];
    t1[2] = n[0] * a[1] - n[1] * a[0];
    const double l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (int c = 0; c < 3; c++) t1[c] /= l;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
    const int strata = 24;
    int open = 0;
    for (int u = 0; u < strata; u++) {
        for (int w = 0; w < strata; w++) {
            /* Malley: a uniform disk point lifted onto the hemisphere */
            const double r = sqrt((u + 0.5) / strata), phi = 2.0 * PI * (w + 0.5) / strata;
            const double x = r * cos(phi), y = r * sin(phi), z = sqrt(fmax(0.0, 1.0 - r * r));
            double o[3], d[3], hit_normal[3];
            for (int c = 0; c < 3; c++) {
                d[c] = x * t1[c] + y * t2[c] + z * n[c];
                o[c] = p[c] + 1e-6 * n[c];
            }
            open += !(scene_trace(s, o, d, hit_normal) < radius);
        }
    }
    return (double)open / (strata * strata);
}

TEST_CASE(thin_occluders_do_not_darken_what_is_behind_them) {
    scene_view view;
    float *depth, *normal;
    render_plate_before_wall(&view, &depth, &normal);
    const int pixels = view.width * view.height;
    for (int integration = 0; integration <= 1; integration++) {
        for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
             implementation <= HBAO_IMPLEMENTATION_GENERIC; implementation++) {
            hbao_params p = exact_params(integration);
            p.radius = 0.8f;
            if (!implementation_runs_itself(implementation))
                continue; /* runs another of the list */
            p.implementation = implementation;
            float *thick = run(&p, &view, depth, normal);
            /* thinner than the gap: the plate lies wholly in front of the wall */
            p.thickness = (float)(0.5 * PLATE_GAP);
            float *thin = run(&p, &view, depth, normal);
            /* thicker than every depth difference within the radius: nothing
             * is skipped, so the result is exactly the infinite thickness's */
            p.thickness = (float)(2.0 * PLATE_GAP);
            float *covering = run(&p, &view, depth, normal);
            float darkest_wall_thick = 1.0f, darkest_wall_thin = 1.0f;
            int wall_pixels = 0;
            for (int k = 0; k < pixels; k++) {
                CHECK(covering[k] == thick[k]);
                if (depth[k] < 4.9f) continue; /* the plate (depth ~4.7) */
                wall_pixels++;
                darkest_wall_thick = fminf(darkest_wall_thick, thick[k]);
                darkest_wall_thin = fminf(darkest_wall_thin, thin[k]);
            }
            CHECK(wall_pixels > pixels / 2);
            /* The halo exists with infinite thickness, so the test can fail. */
            CHECK(darkest_wall_thick < 0.9f);
            /* The wall alone is a plane: AO 1 within plane_facing_camera's 1e-4. */
            CHECK_NEAR(darkest_wall_thin, 1.0f, 1e-4);
            free(thick);
            free(thin);
            free(covering);
        }
    }
    free(depth);
    free(normal);
}

TEST_CASE(back_face_layer_lets_light_pass_behind_a_thin_plate) {
    /* The plate before the wall again, now with a back-face layer: the
     * plate is PLATE_GAP / 4 thick (its back faces that far behind it), the
     * wall has no back face (0: unknown, infinitely thick). On the wall
     * beside the plate the halo of an infinitely thick plate gives way to
     * the light that passes between plate and wall: the AO comes closer to
     * ray-traced AO of the scene with the plate as a slab that thick. An unknown back everywhere gives exactly
     * hbao_compute()'s result; every kernel gives the scalar reference's
     * floats. */
    scene_view view;
    float *depth, *normal;
    render_plate_before_wall(&view, &depth, &normal);
    const scene plate_scene = plate_slab_before_wall(0.25 * PLATE_GAP);
    const int pixels = view.width * view.height;
    float *back = malloc((size_t)pixels * sizeof(float));
    float *unknown = malloc((size_t)pixels * sizeof(float));
    for (int k = 0; k < pixels; k++) {
        back[k] = depth[k] < 4.9f ? depth[k] + (float)(0.25 * PLATE_GAP) : 0.0f;
        /* background, not finite, in front of the surface, on it */
        const float not_behind[4] = {0.0f, NAN, depth[k] * 0.5f, depth[k]};
        unknown[k] = not_behind[k % 4];
    }
    /* the gap between plate and wall (PLATE_GAP) is wider than the thinnest
     * occluder the layer assumes, HBAO_MIN_BACK_THICKNESS radii */
    const double radius = 0.4;
    for (int integration = 0; integration <= 1; integration++) {
        for (int half = 0; half <= 1; half++) {
            hbao_params p = exact_params(integration);
            p.radius = (float)radius;
            p.half_resolution = half;
            p.implementation = HBAO_IMPLEMENTATION_SCALAR;
            float *plain = run(&p, &view, depth, normal);
            float *no_back = run_layers(&p, &view, depth, normal, unknown);
            float *layered = run_layers(&p, &view, depth, normal, back);
            CHECK(memcmp(plain, no_back, (size_t)pixels * sizeof(float)) == 0);
            /* the wall within 12 pixels of the plate's silhouette */
            float darkest_plain = 1.0f, darkest_layered = 1.0f;
            double error_plain = 0.0, error_layered = 0.0, darkest_truth = 1.0;
            int count = 0;
            for (int j = 12; j < view.height - 12; j++) {
                for (int i = 12; i < view.width - 12; i++) {
                    const int k = j * view.width + i;
                    if (!wall_beside_the_plate(depth, k)) continue;
                    double world[3];
                    scene_pixel_position(&view, i, j, depth[k], world);
                    const double wall_normal[3] = {0.0, -1.0, 0.0};
                    const double truth = ray_traced_ao(&plate_scene, world, wall_normal, radius);
                    error_plain += fabs(plain[k] - truth);
                    error_layered += fabs(layered[k] - truth);
                    darkest_plain = fminf(darkest_plain, plain[k]);
                    darkest_layered = fminf(darkest_layered, layered[k]);
                    darkest_truth = fmin(darkest_truth, truth);
                    count++;
                }
            }
            error_plain /= count;
            error_layered /= count;
            printf("  %s%s: %d wall pixels beside the plate, mean |AO - ray traced| %.4f "
                   "without the layer, %.4f with it; darkest %.3f without, %.3f with, %.3f "
                   "ray traced\n",
                   integration ? "cosine" : "hbao", half ? ", half resolution" : "", count,
                   error_plain, error_layered, darkest_plain, darkest_layered, darkest_truth);
            CHECK(count > 500);
            CHECK(darkest_plain < 0.9f); /* the halo is there without the layer */
            /* the halo's darkest pixel comes closer to the ray-traced one */
            CHECK(fabs(darkest_layered - darkest_truth) < fabs(darkest_plain - darkest_truth));
            CHECK(error_layered < 0.9 * error_plain); /* measured 0.40x to 0.89x */
            for (int implementation = HBAO_IMPLEMENTATION_AVX2;
                 implementation <= HBAO_IMPLEMENTATION_GENERIC; implementation++) {
                if (!implementation_runs_itself(implementation))
                    continue; /* runs another of the list */
                p.implementation = implementation;
                float *fast = run_layers(&p, &view, depth, normal, back);
                CHECK(memcmp(layered, fast, (size_t)pixels * sizeof(float)) == 0);
                free(fast);
            }
            free(plain);
            free(no_back);
            free(layered);
        }
    }
    free(back);
    free(unknown);
    free(depth);
    free(normal);
}

TEST_CASE(a_back_layer_of_the_half_float_sky_is_no_back_layer) {
    /* A back-face layer from a half-float render whose sky is 65504 (EEVEE
     * 3.x), with a background depth above it (a camera's Clip End past
     * 65504): those backs are background, as the front's 65504 is, so a
     * layer of nothing else gives the AO without a layer, bit for bit. They
     * were taken for backs far behind (a review: 8157 pixels of 32768 off,
     * by up to 0.91). */
    scene_view view;
    float *depth, *normal;
    render_plate_before_wall(&view, &depth, &normal);
    const int pixels = view.width * view.height;
    float *sky = malloc((size_t)pixels * sizeof(float));
    for (int k = 0; k < pixels; k++) sky[k] = HBAO_HALF_FLOAT_SKY;
    hbao_params p = exact_params(HBAO_INTEGRATION_COSINE);
    p.radius = 0.4f;
    p.background_depth = 1e6f;
    float *plain = run(&p, &view, depth, normal);
    float *layered = run_layers(&p, &view, depth, normal, sky);
    CHECK(memcmp(plain, layered, (size_t)pixels * sizeof(float)) == 0);
    free(plain);
    free(layered);
    free(sky);
    free(depth);
    free(normal);
}

/* --- known answers on cones ---------------------------------------------- */

/* An orthographic camera looks down -z at a point P at depth CONE_DEPTH,
 * whose given normal is n (world_to_camera is the identity: camera space
 * is the world); V = (0, 0, 1). A point at D from P is seen from P at the
 * elevation asin(dot(n, D) / |D|) above P's tangent plane. On a cone with
 * its apex at P around the axis n, every point is seen at the same
 * elevation alpha, in every direction: a step that lands on it, snapped to
 * whichever pixel centre, finds sin_s = sin(alpha). So P's AO on such a
 * surface has a closed form that the snapping of the steps does not
 * change. With n = V every direction's slice holds the normal: gamma = 0
 * and |np| = 1 (docs/algorithm.md, "The slice of a direction"), so
 * T(h) = (1 - cos 2h) / 4 = sin^2(h) / 2, the open half slice is
 * T(pi/2) = 1/2, and the number of directions does not matter either; the
 * cone is then h = r tan(alpha), for a point at distance r from P's view
 * ray and h in front of P (depth CONE_DEPTH - h).
 * What is left is float rounding: of the depths (~5e-7 at depth 5), and the
 * height tolerance and rounding margin of "Depth precision" (~3e-6 units),
 * which lower the elevation's sine of a step 1 pixel (0.05 units) away by
 * ~1e-4 and of the farther ones, which set the horizon, by less (measured
 * at most 1.5e-5 in the AO). */
#define CONE_PIXEL 0.05 /* scene units per pixel of the grid searched */
#define CONE_DEPTH 5.0

/* The grid is 2 m + 4 pixels square, m a margin of two pixels more than
 * the radius (so that no step leaves the image), and P's grid pixel is
 * (m + a, m + b) for these (a, b): four cells of the 4x4 pattern at full
 * and at half resolution alike, so four rotations of the directions and
 * jitters of the steps. */
static const int cone_apex_offsets[4][2] = {{0, 0}, {1, 3}, {2, 1}, {3, 2}};

/* The cone of elevation alpha around the normal n = (sin tilt, 0,
 * cos tilt), raised by lift along the view ray, for inner <= r <= outer
 * (r, lift in scene units); elsewhere background, P itself excepted (a
 * floor around P would lie on its tangent plane, where it occludes
 * nothing, so it is left out to keep the tests fast). */
typedef struct cone {
    double alpha, tilt, lift, inner, outer;
    double shell; /* > 0: back faces this far behind the front (the layer) */
} cone;

/* h of the cone at (dx, dy) from P: dot(n, D) = sin(alpha) |D| for
 * D = (dx, dy, h), a quadratic in h whose larger root is the cone's half in
 * front of the tangent plane (its other root, the half behind it). With
 * tilt 0, h = r tan(alpha). */
static double cone_height(const cone *c, double dx, double dy) {
    const double nx = sin(c->tilt), nz = cos(c->tilt), s = sin(c->alpha);
    const double a = nz * nz - s * s, b = nx * nz * dx;
    const double q = nx * nx * dx * dx - s * s * (dx * dx + dy * dy);
    return (-b + sqrt(b * b - a * q)) / a;
}

typedef struct cone_image {
    scene_view view;
    float *depth, *normal, *back;
    int apex; /* P's index in the image */
    int cell; /* P's cell of the 4x4 pattern on the grid */
} cone_image;

/* The cone around P at the grid pixel of apex offset `at`, for a search
 * of radius radius_px grid pixels, at full resolution or at half: then the
 * image is twice as wide, its pixels half as large, and the half grid,
 * whose pixel (i, j) is the image's (2i, 2j), is the same grid. P is an
 * even pixel of an even row, where (without the blur) the upsample gives
 * the half grid's AO alone. */
static cone_image render_cone(const cone *c, int radius_px, int at, int half) {
    const int scale = half ? 2 : 1, margin = radius_px + 2, grid = 2 * margin + 4;
    const int ai = margin + cone_apex_offsets[at][0], aj = margin + cone_apex_offsets[at][1];
    const double pixel = CONE_PIXEL / scale;
    cone_image im;
    memset(&im.view, 0, sizeof im.view);
    im.view.width = im.view.height = grid * scale;
    hbao_camera_default(&im.view.camera);
    im.view.camera.projection = HBAO_PROJECTION_ORTHOGRAPHIC;
    im.view.camera.ortho_scale = (float)(grid * CONE_PIXEL);
    im.cell = (ai & 3) + 4 * (aj & 3);
    const size_t pixels = (size_t)im.view.width * im.view.height;
    im.depth = malloc(pixels * sizeof(float));
    im.normal = malloc(3 * pixels * sizeof(float));
    im.back = malloc(pixels * sizeof(float));
    const int pi = scale * ai, pj = scale * aj;
    im.apex = pj * im.view.width + pi;
    for (int j = 0; j < im.view.height; j++) {
        for (int i = 0; i < im.view.width; i++) {
            const int k = j * im.view.width + i;
            const double dx = pixel * (i - pi), dy = pixel * (pj - j); /* rows grow down */
            const double r = sqrt(dx * dx + dy * dy);
            const int on_cone = k != im.apex && r >= c->inner && r <= c->outer;
            const double front = CONE_DEPTH - c->lift - cone_height(c, dx, dy);
            im.depth[k] = k == im.apex ? (float)CONE_DEPTH : on_cone ? (float)front : 1e10f;
            im.back[k] = on_cone && c->shell > 0.0 ? (float)(front + c->shell) : 0.0f;
            im.normal[3 * k] = (float)sin(c->tilt);
            im.normal[3 * k + 1] = 0.0f;
            im.normal[3 * k + 2] = (float)cos(c->tilt);
        }
    }
    return im;
}

static void free_cone(cone_image *im) {
    free(im->depth);
    free(im->normal);
    free(im->back);
}

/* P's AO, with the back layer or without it. */
static float cone_ao(const hbao_params *p, const cone_image *im, int layer) {
    float *ao = run_layers(p, &im->view, im->depth, im->normal, layer ? im->back : NULL);
    const float at_apex = ao[im->apex];
    free(ao);
    return at_apex;
}

/* The parameters of every cone test: exact_params' with the search's
 * radius, directions and steps, at full or half resolution, on one kernel. */
static hbao_params cone_params(int integration, double radius, int directions, int steps, int half,
                               int implementation) {
    hbao_params p = exact_params(integration);
    p.radius = (float)radius;
    p.directions = directions;
    p.steps = steps;
    p.half_resolution = half;
    p.implementation = implementation;
    return p;
}

/* Checks P's AO on `im` (layer: with the back layer) against `expected`
 * to `tolerance`; where it is off, prints the case (`what`, the apex
 * offset `at` and p's integration, resolution and kernel) and both values.
 * Returns |AO - expected|. */
static double check_cone_ao(const hbao_params *p, const cone_image *im, int layer, double expected,
                            double tolerance, const char *what, int at) {
    const float ao = cone_ao(p, im, layer);
    if (fabs(ao - expected) > tolerance)
        printf("  %s%s%s, apex %d, kernel %d: AO %.5f, expected %.5f\n",
               p->integration == HBAO_INTEGRATION_COSINE ? "cosine" : "hbao",
               p->half_resolution ? ", half" : "", what, at, p->implementation, (double)ao,
               expected);
    CHECK_NEAR(ao, expected, tolerance);
    return fabs(ao - expected);
}

/* P's AO on a cone of elevation alpha around n = V, by the closed forms
 * of docs/algorithm.md with angle bias b < alpha and falloff NONE. HBAO:
 * every direction starts at sin(b) and rises to sin(alpha),
 * occ = sin(alpha) - sin(b), normalised by 1 - sin(b) (this one holds for
 * a tilted n too: it sees only the elevation's sine). Cosine: the horizon
 * falls from h_open - b = pi/2 - b to acos(sin alpha) = pi/2 - alpha,
 * occluding T(pi/2 - b) - T(pi/2 - alpha) = (cos^2 b - cos^2 alpha) / 2 of
 * T(h_open) = 1/2. With b >= alpha no step rises above the start: AO = 1. */
static double cone_closed_form(int integration, double alpha, double bias) {
    if (bias >= alpha) return 1.0;
    if (integration == HBAO_INTEGRATION_HBAO)
        return 1.0 - (sin(alpha) - sin(bias)) / (1.0 - sin(bias));
    return 1.0 - (cos(bias) * cos(bias) - cos(alpha) * cos(alpha));
}

/* P's cosine AO on the cone of elevation alpha around n = (sin tilt, 0,
 * cos tilt): every sample still has sin_s = sin(alpha), but a slice now
 * holds only the normal projected into it, so the AO is the sum of
 * docs/algorithm.md, "Integration COSINE", over the directions the library
 * takes at P's pattern cell ("Per-pixel sampling"). With V = (0, 0, 1) and
 * dir3 = (cos theta, sin theta, 0): dot(n, m) = dot(dir3, n x V), |np| =
 * sqrt(1 - dot(n, m)^2), gamma = atan2(dot(n, dir3), dot(n, V)), the
 * horizon at gamma + acos(sin(alpha) / |np|), the start at
 * gamma + acos(sin(b)) = h_open - b. At tilt 0 it is cone_closed_form's. */
static double cone_cosine_sum(double alpha, double tilt, double bias, int directions, int cell) {
    static const int pattern[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};
    const double n[3] = {sin(tilt), 0.0, cos(tilt)};
    const double rotation = (pattern[cell] + 0.5) / 16.0;
    double visible = 0.0, open = 0.0;
    for (int d = 0; d < directions; d++) {
        const double theta = 2.0 * PI * (d + rotation) / directions;
        const double dc = cos(theta), ds = sin(theta);
        const double n_dot_m = dc * n[1] - ds * n[0];
        const double np = sqrt(1.0 - n_dot_m * n_dot_m);
        const double gamma = atan2(dc * n[0] + ds * n[1], n[2]);
#define HALF_SLICE(x) (0.25 * (-cos(2 * (x)-gamma) + cos(gamma) + 2 * (x)*sin(gamma)))
        const double h_open = gamma + PI / 2, h_start = gamma + acos(sin(bias));
        const double h = fmax(0.0, gamma + acos(fmin(1.0, sin(alpha) / np)));
        const double occlusion = h < h_start ? HALF_SLICE(h_start) - HALF_SLICE(h) : 0.0;
        visible += np * (HALF_SLICE(h_open) - occlusion);
        open += np * HALF_SLICE(h_open);
#undef HALF_SLICE
    }
    return visible / open;
}

TEST_CASE(thickness_skips_exactly_the_occluders_wholly_in_front) {
    /* P seen through the lower opening of a funnel: the cone of elevation
     * alpha = 30 degrees with apex P (n = V), cut off below r = 32 grid
     * pixels (and a pixel beyond r = R cos(alpha), where it leaves the
     * radius R = 44 px). Its nearest points lie h_in = 32 px tan(alpha) in
     * front of P. With thickness t a sample is skipped when its depth is
     * below P's minus t, i.e. when h > t (docs/algorithm.md, "Thickness"):
     * - t = h_in / 1.05: every point of the funnel lies more than t in
     *   front of P, every sample is skipped: AO = 1.
     * - t = 1.1 h_in: the samples up to r = 1.1 x 32 = 35.2 px are kept
     *   (within the radius: 35.2 / cos(alpha) < 44). Steps lie 43/44 =
     *   0.98 px apart along a direction and snapping moves a step at most
     *   0.71 px, so every direction keeps at least one sample (the 1.8 px
     *   from 32.7 to 34.5 px hold a step), seen at alpha: the cone's closed
     *   form.
     * A thickness 10 % too large keeps the funnel's first 1.5 px at
     * t = h_in / 1.05 (their samples occlude); 10 % too small skips every
     * sample at t = 1.1 h_in (AO 1). Tolerance 2e-4: the float rounding
     * above, with room to spare; a direction's sample kept or lost moves
     * the AO by 0.03 or more. */
    const int radius_px = 44;
    const double alpha = 30.0 * PI / 180.0, radius = radius_px * CONE_PIXEL;
    const double inner = 32 * CONE_PIXEL;
    const cone funnel = {alpha, 0.0, 0.0, inner, radius * cos(alpha) + CONE_PIXEL, 0.0};
    const double h_in = inner * tan(alpha);
    const double thickness[2] = {h_in / 1.05, 1.1 * h_in};
    double worst = 0.0;
    for (int half = 0; half <= 1; half++) {
        for (int at = 0; at < 4; at++) {
            cone_image im = render_cone(&funnel, radius_px, at, half);
            for (int integration = 0; integration <= 1; integration++) {
                for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
                     implementation < HBAO_IMPLEMENTATION_COUNT; implementation++) {
                    if (!implementation_runs_itself(implementation))
                        continue; /* not on this CPU: another of the loop runs */
                    for (int c = 0; c < 2; c++) {
                        hbao_params p =
                            cone_params(integration, radius, 8, 44, half, implementation);
                        p.thickness = (float)thickness[c];
                        const double expected =
                            c == 0 ? 1.0 : cone_closed_form(integration, alpha, 0.0);
                        char what[64];
                        snprintf(what, sizeof what, ", thickness %.3f h_in", thickness[c] / h_in);
                        worst = fmax(worst, check_cone_ao(&p, &im, 0, expected, 2e-4, what, at));
                    }
                }
            }
            free_cone(&im);
        }
    }
    printf("  funnel: largest |AO - closed form| %.2g\n", worst);
}

TEST_CASE(angle_bias_matches_the_closed_form_on_a_cone) {
    /* P at the apex of a cone of elevation alpha = 50 degrees (a funnel
     * with its tip at P, out to where it leaves the radius of 16 px) under
     * angle biases from 0 to beyond alpha: every direction starts its
     * horizon at the bias, and every sample has sin_s = sin(alpha). Around
     * n = V the AO is cone_closed_form's, 1 - (sin alpha - sin b) /
     * (1 - sin b) (HBAO) and 1 - (cos^2 b - cos^2 alpha) (cosine), and 1
     * from b = alpha on. Around a normal tilted 25 degrees from V, HBAO's
     * is the same and the cosine's is cone_cosine_sum's, where each slice
     * has its own gamma (-25 to 25 degrees) and |np| (no sample lies past
     * the normal there: sin(alpha) = 0.77 < dot(n, V) = 0.91). 7
     * directions, an odd number: no direction has its opposite, whose
     * gamma is the negative of its own, so a change to the start's terms
     * odd in gamma does not cancel in the sum. A bias 10 % off moves the
     * AO by 0.01 to 0.18 at 15 to 45 degrees; tolerance 2e-4, the float
     * rounding above with room to spare. */
    const int radius_px = 16;
    const double alpha = 50.0 * PI / 180.0, radius = radius_px * CONE_PIXEL;
    const float biases[] = {0.0f, 15.0f, 30.0f, 45.0f, 55.0f};
    const int directions = 7;
    double worst = 0.0;
    for (int tilted = 0; tilted <= 1; tilted++) {
        /* out to a pixel beyond the radius: the cone's lines lie at most
         * 90 degrees - alpha + tilt from V, so r <= R cos(alpha - tilt) */
        const double tilt = tilted ? 25.0 * PI / 180.0 : 0.0;
        const cone funnel = {alpha, tilt, 0.0, 0.0, radius * cos(alpha - tilt) + CONE_PIXEL, 0.0};
        for (int half = 0; half <= 1; half++) {
            for (int at = 0; at < 4; at++) {
                cone_image im = render_cone(&funnel, radius_px, at, half);
                for (int integration = 0; integration <= 1; integration++) {
                    for (int b = 0; b < 5; b++) {
                        const double bias = biases[b] * PI / 180.0;
                        double expected = cone_closed_form(integration, alpha, bias);
                        if (integration == HBAO_INTEGRATION_COSINE) {
                            const double sum =
                                cone_cosine_sum(alpha, tilt, bias, directions, im.cell);
                            if (!tilted) CHECK_NEAR(sum, expected, 1e-12);
                            expected = sum;
                        }
                        for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
                             implementation < HBAO_IMPLEMENTATION_COUNT; implementation++) {
                            if (!implementation_runs_itself(implementation))
                                continue; /* not on this CPU: another of the loop runs */
                            hbao_params p = cone_params(integration, radius, directions, 16, half,
                                                        implementation);
                            p.angle_bias_degrees = biases[b];
                            char what[64];
                            snprintf(what, sizeof what, "%s, bias %.0f", tilted ? ", tilted" : "",
                                     (double)biases[b]);
                            worst =
                                fmax(worst, check_cone_ao(&p, &im, 0, expected, 2e-4, what, at));
                        }
                    }
                }
                free_cone(&im);
            }
        }
    }
    printf("  cone: largest |AO - closed form| %.2g\n", worst);
}

TEST_CASE(back_layer_takes_occluders_half_the_radius_thick) {
    /* A lampshade over P: the cone of elevation alpha = 32 degrees with
     * apex P (n = V) raised by half the radius R = 40 px (h = 0.5 R +
     * r tan(alpha), out to r = 0.4 R, all within the radius), a thin shell
     * whose back faces the layer gives 0.05 R behind its front. The back
     * depth used is at least the front's plus HBAO_MIN_BACK_THICKNESS = 0.5
     * radii (docs/algorithm.md, "Two depth layers"), so every sample's back
     * point lies 0.5 R behind its front: on the cone h = r tan(alpha)
     * through P, seen at exactly alpha. The fronts lie higher; the first
     * step of every direction (within 2.4 px of P: steps 39/64 = 0.61 px
     * apart, snapping <= 0.71 px) at over 83 degrees (h / r >= 20 / 2.4),
     * where the fraction f of the direction's range (from the top) is under
     * 1/64 (cosine cos^2(83 deg) = 0.015, HBAO 1 - sin(83 deg) = 0.007):
     * before sector 0's centre. A sample marks the sectors whose centres
     * lie between its front's f and its back's, f(alpha); so each
     * direction's samples mark those from 0 to the last whose centre
     * (k + 0.5) / 32 lies at or before f(alpha): n = floor(32 f(alpha) - 0.5) + 1 of 32, and with
     * bias 0, AO = 1 - n / 32, where f(alpha) = T(pi/2 - alpha) / T(pi/2) =
     * cos^2(alpha) (cosine: 32 f - 0.5 = 22.51, n = 23) or 1 - sin(alpha)
     * (HBAO: 14.54, n = 15). Both lie far from a sector's centre, so float
     * rounding (above) moves no sector: tolerance 1e-5 (the AO itself in
     * float).
     * At 0.4 R the back points rise above the cone (to at least 41 degrees
     * within the 0.4 R: at least four sectors fewer, AO +0.125); at 0.6 R
     * those within 0.1 R / tan(alpha) = 6.4 px of P fall below the tangent
     * plane and every sector is marked (AO 0). */
    const int radius_px = 40;
    const double alpha = 32.0 * PI / 180.0, radius = radius_px * CONE_PIXEL;
    const cone lampshade = {alpha, 0.0, 0.5 * radius, 0.0, 0.4 * radius, 0.05 * radius};
    for (int half = 0; half <= 1; half++) {
        for (int at = 0; at < 4; at++) {
            cone_image im = render_cone(&lampshade, radius_px, at, half);
            for (int integration = 0; integration <= 1; integration++) {
                const double f = integration == HBAO_INTEGRATION_COSINE ? cos(alpha) * cos(alpha)
                                                                        : 1.0 - sin(alpha);
                const double expected = 1.0 - (floor(32.0 * f - 0.5) + 1.0) / 32.0;
                for (int implementation = HBAO_IMPLEMENTATION_SCALAR;
                     implementation < HBAO_IMPLEMENTATION_COUNT; implementation++) {
                    if (!implementation_runs_itself(implementation))
                        continue; /* not on this CPU: another of the loop runs */
                    const hbao_params p =
                        cone_params(integration, radius, 8, 64, half, implementation);
                    check_cone_ao(&p, &im, 1, expected, 1e-5, "", at);
                }
            }
            free_cone(&im);
        }
    }
}

TEST_CASE(half_resolution_reads_the_even_pixels_of_even_rows) {
    /* The half grid's pixel (i, j) is full-resolution pixel (2i, 2j)
     * (hbao_grid_set_projection): its depth, given normal and back face
     * come from there, and nowhere else. So an image that agrees with the
     * plate before the wall on those pixels, with other depths, normals and
     * backs elsewhere, has the same AO there, bit for bit: at even pixels
     * of even rows the upsample takes the half grid's AO alone. */
    scene_view view;
    float *depth, *normal;
    render_plate_before_wall(&view, &depth, &normal);
    const int pixels = view.width * view.height;
    float *back = malloc((size_t)pixels * sizeof(float));
    float *other_depth = malloc((size_t)pixels * sizeof(float));
    float *other_normal = malloc((size_t)pixels * 3 * sizeof(float));
    float *other_back = malloc((size_t)pixels * sizeof(float));
    uint32_t state = 7u;
    for (int j = 0; j < view.height; j++) {
        for (int i = 0; i < view.width; i++) {
            const int k = j * view.width + i;
            back[k] = depth[k] < 4.9f ? depth[k] + (float)(0.25 * PLATE_GAP) : 0.0f;
            const int kept = i % 2 == 0 && j % 2 == 0;
            const float z = 1.0f + (float)((test_random(&state) >> 8) % 800) / 100.0f;
            other_depth[k] = kept ? depth[k] : z;
            other_back[k] = kept ? back[k] : z + 0.01f; /* a thin back: known */
            for (int c = 0; c < 3; c++)
                other_normal[3 * k + c] = kept ? normal[3 * k + c] : (c == 0 ? 1.0f : 0.0f);
        }
    }
    for (int layered = 0; layered <= 1; layered++) {
        hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
        p.radius = 0.4f;
        p.half_resolution = 1;
        float *expected = run_layers(&p, &view, depth, normal, layered ? back : NULL);
        float *ao = run_layers(&p, &view, other_depth, other_normal, layered ? other_back : NULL);
        int differ = 0, occluded = 0;
        for (int j = 0; j < view.height; j += 2) {
            for (int i = 0; i < view.width; i += 2) {
                const int k = j * view.width + i;
                differ += memcmp(&ao[k], &expected[k], sizeof(float)) != 0;
                occluded += expected[k] < 0.9f;
            }
        }
        printf("  %s: %d of the even pixels occluded, %d differ\n",
               layered ? "with the back layer" : "one layer", occluded, differ);
        CHECK(occluded > 100);
        CHECK(differ == 0);
        free(expected);
        free(ao);
    }
    free(back);
    free(other_depth);
    free(other_normal);
    free(other_back);
    free(depth);
    free(normal);
}

TEST_CASE(depth_at_the_background_depth_is_background) {
    /* hbao_params.background_depth: depths at or beyond it are background.
     * A plane at 5 beside depths of exactly 6 with background_depth 6: the
     * 6s give what background (0) gives, not a far wall that the plane's
     * edge occludes. */
    const double eye[3] = {0.0, -5.0, 0.0}, target[3] = {0, 0, 0};
    scene_view view = make_view(64, 48, eye, target);
    const int pixels = view.width * view.height;
    float *at_limit = malloc((size_t)pixels * sizeof(float));
    float *zero = malloc((size_t)pixels * sizeof(float));
    for (int k = 0; k < pixels; k++) {
        const int near = k % view.width < view.width / 2;
        at_limit[k] = near ? 5.0f : 6.0f;
        zero[k] = near ? 5.0f : 0.0f;
    }
    hbao_params p = HBAO_PARAMS_DEFAULT_INITIALIZER;
    p.radius = 2.0f; /* reaches from the far depths to the plane */
    p.background_depth = 6.0f;
    float *limit_ao = run(&p, &view, at_limit, NULL);
    float *zero_ao = run(&p, &view, zero, NULL);
    CHECK(memcmp(limit_ao, zero_ao, (size_t)pixels * sizeof(float)) == 0);
    /* and the test can see a far wall: just before the limit, the edge
     * occludes it */
    for (int k = 0; k < pixels; k++) at_limit[k] = at_limit[k] == 6.0f ? 5.99f : 5.0f;
    float *wall_ao = run(&p, &view, at_limit, NULL);
    float darkest = 1.0f;
    for (int k = 0; k < pixels; k++) darkest = fminf(darkest, wall_ao[k]);
    printf("  darkest AO with a wall at 5.99: %.3f\n", (double)darkest);
    CHECK(darkest < 0.9f);
    free(at_limit);
    free(zero);
    free(limit_ao);
    free(zero_ao);
    free(wall_ao);
}

TEST_MAIN(TEST_ENTRY(plane_facing_camera_is_unoccluded), TEST_ENTRY(tilted_plane_is_unoccluded),
          TEST_ENTRY(corner_matches_analytic_cosine), TEST_ENTRY(corner_matches_analytic_hbao),
          TEST_ENTRY(corner_value_at_the_crease_is_one_half),
          TEST_ENTRY(scaling_depth_and_radius_keeps_ao),
          TEST_ENTRY(more_samples_converge_to_brute_force),
          TEST_ENTRY(past_the_normal_matches_brute_force_under_a_table),
          TEST_ENTRY(steps_past_the_frame_see_the_edge_surface_continued),
          TEST_ENTRY(random_and_degenerate_inputs_give_finite_ao_in_range),
          TEST_ENTRY(identical_output_for_any_thread_count),
          TEST_ENTRY(bottom_up_rows_with_negative_stride),
          TEST_ENTRY(depth_layouts_and_background_spellings_give_the_same_ao),
          TEST_ENTRY(ao_computed_in_place_over_its_depth),
          TEST_ENTRY(normal_layouts_give_the_same_ao),
          TEST_ENTRY(normals_of_any_finite_length_give_the_same_ao),
          TEST_ENTRY(an_unevenly_scaled_camera_turns_normals_as_its_rotation),
          TEST_ENTRY(half_resolution_is_close_to_full), TEST_ENTRY(blur_keeps_depth_edges),
          TEST_ENTRY(strength_is_a_power), TEST_ENTRY(background_never_occludes),
          TEST_ENTRY(tiny_projected_radius_gives_one),
          TEST_ENTRY(simd_paths_match_scalar_reference_part_1_of_4),
          TEST_ENTRY(simd_paths_match_scalar_reference_part_2_of_4),
          TEST_ENTRY(simd_paths_match_scalar_reference_part_3_of_4),
          TEST_ENTRY(simd_paths_match_scalar_reference_part_4_of_4),
          TEST_ENTRY(long_thin_images_match_the_scalar_reference),
          TEST_ENTRY(every_step_and_direction_count_matches_the_scalar_reference),
          TEST_ENTRY(a_tiny_radius_with_quadratic_falloff_matches_the_scalar_reference),
          TEST_ENTRY(a_post_at_the_lens_leaves_the_ao_of_its_blocks),
          TEST_ENTRY(a_back_layer_of_the_half_float_sky_is_no_back_layer),
          TEST_ENTRY(thin_occluders_do_not_darken_what_is_behind_them),
          TEST_ENTRY(back_face_layer_lets_light_pass_behind_a_thin_plate),
          TEST_ENTRY(thickness_skips_exactly_the_occluders_wholly_in_front),
          TEST_ENTRY(angle_bias_matches_the_closed_form_on_a_cone),
          TEST_ENTRY(back_layer_takes_occluders_half_the_radius_thick),
          TEST_ENTRY(half_resolution_reads_the_even_pixels_of_even_rows),
          TEST_ENTRY(depth_at_the_background_depth_is_background))
