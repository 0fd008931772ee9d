/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The horizon search: for every grid pixel, march N rotated directions for S
 * jittered steps inside the projected radius and integrate the occlusion of
 * the highest horizon found, per docs/algorithm.md. */
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "internal_hbao.h"

#define HALF_PI (0.5f * HBAO_PI)

/* The interleaved 4x4 pattern (a Bayer matrix): neighbouring pixels get
 * rotations and jitters far apart, so a small blur averages them out. */
static const int bayer_4x4[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};

typedef hbao_horizon_job horizon_job;

/* One pixel's march along one direction. */
typedef struct march {
    const hbao_grid *grid;
    int i, j;
    float p[3];   /* the pixel's position */
    float dc, ds; /* the direction, view plane */
    float inv_ycor;
    float jitter;
    float step_px;
    float radius2;
    /* What every sample is compared with: the depth's rounding tolerance
     * along the normal (docs/algorithm.md, "Depth precision"), and the sine
     * of V's elevation above the tangent plane, dot(n, V). */
    float height_tolerance;
    float n_dot_v;
    /* Samples nearer than this depth are occluders of finite thickness
     * wholly in front of the pixel: skipped (hbao_near_limit). */
    float near_limit;
    float min_thickness;      /* the back layer: HBAO_MIN_BACK_THICKNESS radii */
    hbao_height_plane height; /* the one-layer search's sample heights */
} march;

enum { SAMPLE_END = -1, SAMPLE_SKIP = 0, SAMPLE_OK = 1, SAMPLE_FAR = 2 };

/* A step's sample: its grid pixel (outside the image past its edges), its
 * depth and its back depth (INFINITY: unknown, as beyond the image). */
typedef struct sample_point {
    int si, sj;
    float zs, zb;
} sample_point;

/* The vector to the sample of a step and its squared length; *at receives
 * the sample (sample_point), and *height (where not NULL) the sample's
 * height above the tangent plane (hbao_sample_height). A sample outside the
 * image has the depth of hbao_beyond_depth. */
static inline int march_sample(const march *m, int step, float delta[3], float *dist2,
                               sample_point *at, float *height) {
    const hbao_grid *g = m->grid;
    int ox, oy;
    if (!hbao_step_offset(g, m->dc, m->ds, m->inv_ycor, m->jitter, m->step_px, step, &ox, &oy))
        return SAMPLE_END;
    const int si = m->i + ox, sj = m->j + oy;
    const int columns = g->beyond_columns, rows = g->beyond_rows;
    if (si < -columns || sj < -rows || si >= g->width + columns || sj >= g->height + rows)
        return SAMPLE_END;
    if (ox == 0 && oy == 0) return SAMPLE_SKIP;
    const int inside = si >= 0 && sj >= 0 && si < g->width && sj < g->height;
    const size_t index = inside ? (size_t)sj * g->width + si : 0;
    const float zs = inside ? g->depth[index] : hbao_beyond_depth(g, si, sj);
    at->si = si;
    at->sj = sj;
    at->zs = zs;
    at->zb = g->back != NULL && inside ? g->back[index] : INFINITY;
    if (zs <= 0.0f || zs < m->near_limit) return SAMPLE_SKIP;
    if (height != NULL)
        *height = hbao_sample_height(g, &m->height, zs, (float)ox, hbao_grid_y(g, sj));
    float q[3];
    hbao_grid_position(g, si, sj, zs, q);
    delta[0] = q[0] - m->p[0];
    delta[1] = q[1] - m->p[1];
    delta[2] = q[2] - m->p[2];
    *dist2 = delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2];
    if (!(*dist2 > 0.0f)) return SAMPLE_SKIP;
    if (!(*dist2 < m->radius2)) return *dist2 < INFINITY ? SAMPLE_FAR : SAMPLE_SKIP;
    return SAMPLE_OK;
}

/* The slice of a direction: the normal projected into it. */
typedef struct slice {
    float np_length; /* |normal projected into the slice| */
    float inv_np;    /* 1 / np_length */
    float cos_gamma; /* angle of the projected normal from V towards e */
    float sin_gamma;
    int usable;
} slice;

/* The slice of direction d = (dc, ds, 0) through V has the in-plane axis
 * e = (d - V dot(d, V)) / |d - V dot(d, V)| (perpendicular to V, on the
 * marching side) and the normal m = V x e. With |n| = |V| = |d| = 1 (to
 * rounding) no vector needs building: |d - V dot(d, V)|^2 = 1 - dot(d, V)^2,
 * dot(n, m) = dot(d, n x V) / |d - V dot(d, V)|, and the projected normal
 * np = n - m dot(n, m) has |np|^2 = 1 - dot(n, m)^2, dot(np, V) = dot(n, V)
 * and dot(np, e) = (dot(n, d) - dot(d, V) dot(n, V)) / |d - V dot(d, V)|.
 * n_cross_v holds the x and y of n x V, which every slice of the pixel
 * shares. */
static inline void slice_setup(const float v[3], const float n[3], const float n_cross_v[2],
                               float n_dot_v, float dc, float ds, slice *sl) {
    const float dir_dot_v = dc * v[0] + ds * v[1];
    const float e_inv = 1.0f / sqrtf(1.0f - dir_dot_v * dir_dot_v);
    const float n_dot_m = (dc * n_cross_v[0] + ds * n_cross_v[1]) * e_inv;
    sl->np_length = sqrtf(fmaxf(0.0f, 1.0f - n_dot_m * n_dot_m));
    sl->usable = sl->np_length > 1e-6f;
    sl->inv_np = 1.0f / sl->np_length;
    if (sl->usable) {
        sl->cos_gamma = n_dot_v * sl->inv_np;
        sl->sin_gamma = (dc * n[0] + ds * n[1] - dir_dot_v * n_dot_v) * e_inv * sl->inv_np;
    } else {
        sl->cos_gamma = 1.0f;
        sl->sin_gamma = 0.0f;
    }
}

/* The sine of a sample's elevation above the tangent plane, its height
 * lowered by what the depth's rounding could have raised it. */
static inline float sample_elevation(const march *m, const float n[3], const float delta[3],
                                     float inv_dist) {
    return (delta[0] * n[0] + delta[1] * n[1] + delta[2] * n[2] - m->height_tolerance) * inv_dist;
}

/* Whether a sample lies past the normal. In the slice that means an angle
 * from V below gamma; but samples are snapped to pixel centres, off the
 * slice, and near a plane seen at a grazing angle (V nearly in the tangent
 * plane) a sample on the plane itself can lie within gamma of V. A sample
 * past the normal inside the slice also rises above the tangent plane at
 * least as steeply as V does (its elevation is cos(h - gamma) >= cos(gamma),
 * i.e. sin_s >= dot(n, V)), which no sample on or near the plane does, so
 * both are required. */
static inline int past_the_normal(const march *m, const slice *sl, const float v[3],
                                  const float delta[3], float inv_dist, float sin_s) {
    const float cos_v = (delta[0] * v[0] + delta[1] * v[1] + delta[2] * v[2]) * inv_dist;
    return cos_v > sl->cos_gamma && sin_s > m->n_dot_v;
}

/* HBAO integration of one direction: sum of W * (increase of the sine of the
 * elevation above the tangent plane), Bavoil & Sainz with the half-occluded rule past the normal. */
static float direction_occlusion_hbao(const hbao_settings *s, const march *m, const float v[3],
                                      const slice *sl) {
    const int quadratic = s->falloff == HBAO_FALLOFF_QUADRATIC;
    const float inv_radius2 = s->inv_radius2;
    const float half_occluded = 0.5f * (1.0f - s->sin_bias);
    const int check_past_normal = sl->usable && sl->sin_gamma > 0.0f;
    float sin_max = s->sin_bias;
    float occlusion = 0.0f;
    for (int step = 0; step < s->steps; step++) {
        float delta[3], dist2;
        sample_point at;
        float height;
        const int status = march_sample(m, step, delta, &dist2, &at, &height);
        if (status == SAMPLE_END) break;
        if (status != SAMPLE_OK) continue;
        const float inv_dist = 1.0f / sqrtf(dist2);
        const float sin_s = height * inv_dist;
        if (check_past_normal && past_the_normal(m, sl, v, delta, inv_dist, sin_s)) {
            /* Beyond the normal inside the slice: the screen-space march
             * has no proper data here; count the direction half occluded. */
            if (occlusion < half_occluded) occlusion = half_occluded;
            break;
        }
        if (sin_s > sin_max) {
            const float weight = quadratic ? 1.0f - dist2 * inv_radius2 : 1.0f;
            occlusion += weight * (sin_s - sin_max);
            sin_max = sin_s;
        }
    }
    return occlusion;
}

/* Visibility of a half slice from V up to angle h: the integral of
 * cos(t - gamma) sin(t) over [0, h] (docs/algorithm.md, T(h)). */
static inline float half_slice_visibility(float h, float cos_h, float sin_h, const slice *sl) {
    const float cos_2h = 2.0f * cos_h * cos_h - 1.0f;
    const float sin_2h = 2.0f * sin_h * cos_h;
    const float cos_2h_minus_gamma = cos_2h * sl->cos_gamma + sin_2h * sl->sin_gamma;
    return 0.25f * (-cos_2h_minus_gamma + sl->cos_gamma + 2.0f * h * sl->sin_gamma);
}

/* The horizon angle h = gamma + acos(elevation) (from V), clamped to >= 0,
 * with its cosine and sine. */
static inline void horizon_from_elevation(float elevation, float gamma, const slice *sl, float *h,
                                          float *cos_h, float *sin_h) {
    const float cos_a = elevation, sin_a = hbao_sine_from_cosine(elevation);
    *h = gamma + hbao_acos(elevation);
    if (*h <= 0.0f) {
        *h = 0.0f;
        *cos_h = 1.0f;
        *sin_h = 0.0f;
        return;
    }
    *cos_h = sl->cos_gamma * cos_a - sl->sin_gamma * sin_a;
    *sin_h = sl->sin_gamma * cos_a + sl->cos_gamma * sin_a;
}

static inline void horizon_state(int past_normal, float cos_past_max, float elevation_max,
                                 float gamma, const slice *sl, float *h, float *cos_h,
                                 float *sin_h) {
    if (past_normal) {
        *cos_h = cos_past_max;
        *sin_h = hbao_sine_from_cosine(cos_past_max);
        *h = hbao_acos(cos_past_max);
    } else {
        horizon_from_elevation(elevation_max, gamma, sl, h, cos_h, sin_h);
    }
}

/* Cosine integration of one direction: the visibility lost to the horizon,
 * attenuated per sample. Returns the occluded part; *open_part receives the
 * visibility of the unoccluded half slice.
 * A sample's angle h from V is measured through its elevation above the
 * tangent plane, sin(phi) = sin_s / |np| (sample_elevation),
 * h = gamma + pi/2 - phi: exact for samples in the slice, and, unlike the angle to V, still exact
 * (0) for snapped samples that lie on the tangent plane but off the slice.
 * Past the normal (past_the_normal) the elevation turns back, so there the
 * angle to V is used. */
static float direction_occlusion_cosine(const hbao_settings *s, const march *m, const float v[3],
                                        const slice *sl, float *open_part) {
    const float gamma = HALF_PI - hbao_acos(sl->sin_gamma); /* asin; cos_gamma >= 0 */
    *open_part = 0.25f * (2.0f * sl->cos_gamma + (2.0f * gamma + HBAO_PI) * sl->sin_gamma);
    const float inv_np = sl->inv_np;
    const int check_past_normal = sl->sin_gamma > 0.0f;
    const int quadratic = s->falloff == HBAO_FALLOFF_QUADRATIC;
    const float inv_radius2 = s->inv_radius2;

    /* Horizon state: the highest elevation sine (starting at the bias), and
     * once past the normal, the highest cosine to V. */
    float elevation_max = s->sin_bias;
    int past_normal = 0;
    float cos_past_max = sl->cos_gamma;
    float visibility_start = 0.0f, visibility_at_max = 0.0f;
    float h, cos_h, sin_h;
    horizon_from_elevation(elevation_max, gamma, sl, &h, &cos_h, &sin_h);
    visibility_start = half_slice_visibility(h, cos_h, sin_h, sl);
    visibility_at_max = visibility_start;
    float occlusion = 0.0f;

    for (int step = 0; step < s->steps; step++) {
        float delta[3], dist2;
        sample_point at;
        float height;
        const int status = march_sample(m, step, delta, &dist2, &at, &height);
        if (status == SAMPLE_END) break;
        if (status != SAMPLE_OK) continue;
        const float inv_dist = 1.0f / sqrtf(dist2);
        const float sin_s = height * inv_dist;
        int raised = 0;
        if (check_past_normal && past_the_normal(m, sl, v, delta, inv_dist, sin_s)) {
            const float cos_v = (delta[0] * v[0] + delta[1] * v[1] + delta[2] * v[2]) * inv_dist;
            if (cos_v > cos_past_max) {
                past_normal = 1;
                cos_past_max = cos_v > 1.0f ? 1.0f : cos_v;
                raised = 1;
            }
        }
        if (!raised) {
            if (past_normal) continue; /* nothing below the normal can raise it now */
            const float elevation = sin_s * inv_np;
            if (elevation <= elevation_max) continue;
            elevation_max = elevation > 1.0f ? 1.0f : elevation;
            raised = 1;
        }
        if (quadratic) {
            /* Each rise of the horizon costs visibility, weighted by the
             * attenuation of the sample that caused it. */
            horizon_state(past_normal, cos_past_max, elevation_max, gamma, sl, &h, &cos_h, &sin_h);
            const float visibility = half_slice_visibility(h, cos_h, sin_h, sl);
            occlusion += (1.0f - dist2 * inv_radius2) * (visibility_at_max - visibility);
            visibility_at_max = visibility;
        }
    }
    if (!quadratic) {
        horizon_state(past_normal, cos_past_max, elevation_max, gamma, sl, &h, &cos_h, &sin_h);
        occlusion = visibility_start - half_slice_visibility(h, cos_h, sin_h, sl);
    }
    return occlusion;
}

/* --- Two depth layers: sector masks ------------------------------------
 * With the back faces known (grid->back), an occluder covers only the
 * angles between its front point and its back point (the point behind it
 * on the same view ray), as in Bavoil & Sainz's multi-layer SSAO: light
 * passes below a floating occluder, between it and the surface. A horizon
 * (everything below the highest sample is dark) cannot hold such a gap, so
 * each direction keeps a mask of HBAO_SECTORS sectors of equal weight, as
 * visibility bitmasks do: equal visibility (cosine integration) or equal
 * rise of the elevation's sine (HBAO), from the top of the direction's
 * range down to its bias-lowered tangent plane. A sample marks the sectors
 * whose centres its interval covers; where its back is unknown, the
 * interval reaches the tangent plane, the one-layer rule at the sectors'
 * resolution. An occluder is taken as at least HBAO_MIN_BACK_THICKNESS
 * radii thick: steps sample a thin occluder (a shelf, a table top) at a few
 * points, and between their thin intervals light would leak through it.
 * With quadratic falloff, each newly marked sector costs the attenuation
 * of the sample that marked it. */
/* The sectors whose centres lie in [lo, hi], fractions of the range (from
 * its top); NaN counts as 0. */
static inline uint32_t sector_bits(float lo, float hi) {
    const float n = (float)HBAO_SECTORS;
    const float first = ceilf(fminf(fmaxf(lo, 0.0f), 1.0f) * n - 0.5f);
    const float end = floorf(fminf(fmaxf(hi, 0.0f), 1.0f) * n - 0.5f) + 1.0f;
    if (!(end > first)) return 0u;
    const int a = (int)first, b = (int)end; /* 0 <= a < b <= 32 */
    const uint32_t below_end = b >= 32 ? 0xffffffffu : (1u << b) - 1u;
    return below_end & ~((1u << a) - 1u);
}

/* Marks the sectors between fractions a and b (either order) in *marked:
 * the count of newly marked ones, times the sample's weight. */
static inline float mark_sectors(uint32_t *marked, float a, float b, float weight) {
    const uint32_t fresh = sector_bits(fminf(a, b), fmaxf(a, b)) & ~*marked;
    if (fresh == 0u) return 0.0f;
    *marked |= fresh;
    return weight * (float)__builtin_popcount(fresh);
}

/* The fraction of the cosine-weighted range [0, T_bias] of visibility
 * lying above (nearer V than) the point at delta. */
static inline float sector_fraction_cosine(const march *m, const slice *sl, const float n[3],
                                           const float v[3], const float delta[3], float dist2,
                                           float gamma, int check_past_normal, float sin_bias,
                                           float inv_bias) {
    const float inv_dist = 1.0f / sqrtf(dist2);
    const float sin_s = sample_elevation(m, n, delta, inv_dist);
    float h, cos_h, sin_h;
    if (check_past_normal && past_the_normal(m, sl, v, delta, inv_dist, sin_s)) {
        float cos_v = (delta[0] * v[0] + delta[1] * v[1] + delta[2] * v[2]) * inv_dist;
        cos_v = cos_v > 1.0f ? 1.0f : cos_v;
        horizon_state(1, cos_v, 0.0f, gamma, sl, &h, &cos_h, &sin_h);
    } else {
        /* below the bias the visibility integral turns back: the end */
        float elevation = sin_s * sl->inv_np;
        if (!(elevation > sin_bias)) return 1.0f;
        elevation = elevation > 1.0f ? 1.0f : elevation;
        horizon_state(0, 0.0f, elevation, gamma, sl, &h, &cos_h, &sin_h);
    }
    return half_slice_visibility(h, cos_h, sin_h, sl) * inv_bias;
}

/* A sample's back point, where its back face is known: the view ray
 * through the sample's pixel at its back depth, as a vector from the pixel
 * and its squared length. Returns 0 where unknown. */
static inline int back_point(const march *m, const sample_point *at, float delta[3], float *dist2) {
    const hbao_grid *g = m->grid;
    if (!(at->zb < INFINITY)) return 0;
    float q[3];
    hbao_grid_position(g, at->si, at->sj, hbao_back_depth(at->zs, at->zb, m->min_thickness), q);
    delta[0] = q[0] - m->p[0];
    delta[1] = q[1] - m->p[1];
    delta[2] = q[2] - m->p[2];
    *dist2 = delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2];
    return *dist2 > 0.0f;
}

/* A sample beyond the radius still occludes within it where its occluder,
 * [its depth, its back depth] along its view ray (infinitely deep where the
 * back is unknown), reaches into the radius: the part of the surface hidden
 * behind it (a pit's near wall behind its rim) lies there. *delta becomes
 * the point where the view ray enters the radius (*dist2 its squared
 * length, about radius^2). Returns 0 where it does not enter before the back
 * depth. (Without the layer a sample beyond the radius is ignored, as
 * before: the layer is what tells a thin object from a solid one.) */
static inline int enter_the_ball(const march *m, const sample_point *at, float delta[3],
                                 float *dist2) {
    const hbao_grid *g = m->grid;
    const float q[3] = {delta[0] + m->p[0], delta[1] + m->p[1], delta[2] + m->p[2]};
    float d[3] = {0.0f, 0.0f, -1.0f};
    if (!g->orthographic) {
        const float inv = 1.0f / sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        for (int c = 0; c < 3; c++) d[c] = q[c] * inv;
    }
    const float b = delta[0] * d[0] + delta[1] * d[1] + delta[2] * d[2];
    const float disc = b * b - (*dist2 - m->radius2);
    if (!(b < 0.0f) || !(disc >= 0.0f)) return 0;
    const float t = -b - sqrtf(disc);
    if (!(-(q[2] + t * d[2]) <= at->zb)) return 0;
    for (int c = 0; c < 3; c++) delta[c] += t * d[c];
    *dist2 = delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2];
    return *dist2 > 0.0f;
}

/* Whether a sample of the two-layer search lies wholly on or below the
 * tangent plane (hbao_height_plane's heights), so that it can mark no
 * sector: its front, its back point and, beyond the radius, the point
 * where its occluder enters the ball all lie on its view ray between its
 * depth and max(back depth, depth + min_thickness), where the height is
 * linear in depth; where the back is unknown the occluder reaches any
 * depth behind, so the height must not rise with depth. Not where V lies
 * below the plane (a sample below it can then count, as in the one-layer
 * search). The SIMD kernels leave the same samples out, lane by lane. */
static inline int layer_sample_below(const march *m, const sample_point *at) {
    const hbao_grid *g = m->grid;
    if (m->n_dot_v < 0.0f) return 0;
    const float across =
        hbao_height_across(&m->height, (float)(at->si - m->i), hbao_grid_y(g, at->sj));
    if (!(hbao_height_at(g, &m->height, across, at->zs) <= 0.0f)) return 0;
    if (at->zb < INFINITY)
        return hbao_height_at(g, &m->height, across,
                              hbao_back_depth(at->zs, at->zb, m->min_thickness)) <= 0.0f;
    return g->orthographic ? m->height.depth >= 0.0f : across <= 0.0f;
}

/* march_sample with the back layer: a sample wholly below the tangent
 * plane is skipped (layer_sample_below), and a sample beyond the radius
 * whose occluder enters it is a sample at the entry point (enter_the_ball). */
static inline int march_layer_sample(const march *m, int step, float delta[3], float *dist2,
                                     sample_point *at) {
    const int status = march_sample(m, step, delta, dist2, at, NULL);
    if (status != SAMPLE_OK && status != SAMPLE_FAR) return status;
    if (layer_sample_below(m, at)) return SAMPLE_SKIP;
    if (status != SAMPLE_FAR) return status;
    return enter_the_ball(m, at, delta, dist2) ? SAMPLE_OK : SAMPLE_SKIP;
}

/* direction_occlusion_cosine with the back layer. */
static float direction_occlusion_cosine_layers(const hbao_settings *s, const march *m,
                                               const float n[3], const float v[3], const slice *sl,
                                               float *open_part) {
    const float gamma = HALF_PI - hbao_acos(sl->sin_gamma);
    *open_part = 0.25f * (2.0f * sl->cos_gamma + (2.0f * gamma + HBAO_PI) * sl->sin_gamma);
    const int check_past_normal = sl->sin_gamma > 0.0f;
    const int quadratic = s->falloff == HBAO_FALLOFF_QUADRATIC;
    const float inv_radius2 = s->inv_radius2;
    float h, cos_h, sin_h;
    horizon_from_elevation(s->sin_bias, gamma, sl, &h, &cos_h, &sin_h);
    const float visibility_bias = half_slice_visibility(h, cos_h, sin_h, sl);
    if (!(visibility_bias > 0.0f)) return 0.0f;
    const float inv_bias = 1.0f / visibility_bias;
    uint32_t marked = 0u;
    float occlusion = 0.0f; /* in sectors */
    for (int step = 0; step < s->steps; step++) {
        float delta[3], dist2;
        sample_point at;
        const int status = march_layer_sample(m, step, delta, &dist2, &at);
        if (status == SAMPLE_END) break;
        if (status != SAMPLE_OK) continue;
        const float front = sector_fraction_cosine(m, sl, n, v, delta, dist2, gamma,
                                                   check_past_normal, s->sin_bias, inv_bias);
        float delta_back[3], dist2_back;
        const float behind =
            back_point(m, &at, delta_back, &dist2_back)
                ? sector_fraction_cosine(m, sl, n, v, delta_back, dist2_back, gamma,
                                         check_past_normal, s->sin_bias, inv_bias)
                : 1.0f;
        occlusion += mark_sectors(&marked, front, behind,
                                  quadratic ? fmaxf(0.0f, 1.0f - dist2 * inv_radius2) : 1.0f);
    }
    return occlusion * (visibility_bias / (float)HBAO_SECTORS);
}

/* direction_occlusion_hbao with the back layer: sectors of equal rise of the
 * elevation's sine, from 1 down to the bias. */
static float direction_occlusion_hbao_layers(const hbao_settings *s, const march *m,
                                             const float n[3], const float v[3], const slice *sl) {
    const int quadratic = s->falloff == HBAO_FALLOFF_QUADRATIC;
    const float inv_radius2 = s->inv_radius2;
    const float range = 1.0f - s->sin_bias;
    const float inv_range = 1.0f / range;
    const float half_occluded = 0.5f * range;
    const int check_past_normal = sl->usable && sl->sin_gamma > 0.0f;
    uint32_t marked = 0u;
    float occlusion = 0.0f; /* in sectors */
    float past = 0.0f;
    for (int step = 0; step < s->steps; step++) {
        float delta[3], dist2;
        sample_point at;
        const int status = march_layer_sample(m, step, delta, &dist2, &at);
        if (status == SAMPLE_END) break;
        if (status != SAMPLE_OK) continue;
        const float inv_dist = 1.0f / sqrtf(dist2);
        const float sin_s = sample_elevation(m, n, delta, inv_dist);
        if (check_past_normal && past_the_normal(m, sl, v, delta, inv_dist, sin_s)) {
            past = half_occluded;
            break;
        }
        const float front = (1.0f - sin_s) * inv_range;
        float delta_back[3], dist2_back;
        const float behind =
            back_point(m, &at, delta_back, &dist2_back)
                ? (1.0f - sample_elevation(m, n, delta_back, 1.0f / sqrtf(dist2_back))) * inv_range
                : 1.0f;
        occlusion += mark_sectors(&marked, front, behind,
                                  quadratic ? fmaxf(0.0f, 1.0f - dist2 * inv_radius2) : 1.0f);
    }
    occlusion *= range / (float)HBAO_SECTORS;
    return occlusion > past ? occlusion : past;
}

float hbao_horizon_pixel(const horizon_job *job, int i, int j, float step_px) {
    const hbao_settings *s = job->settings;
    const hbao_grid *g = job->grid;
    const float z = g->depth[(size_t)j * g->width + i];
    if (z <= 0.0f) return 1.0f;

    march m;
    m.grid = g;
    m.i = i;
    m.j = j;
    hbao_grid_position(g, i, j, z, m.p);
    const float radius_px =
        g->orthographic ? s->radius / g->pixel_size : s->radius / (g->pixel_size * z);
    if (!(radius_px >= 1.0f)) return 1.0f;
    const int cell = (i & 3) + 4 * (j & 3);
    m.inv_ycor = 1.0f / g->ycor;
    m.jitter = job->jitter[cell];
    m.step_px = step_px;
    m.radius2 = s->radius * s->radius;

    float v[3] = {0.0f, 0.0f, 1.0f};
    if (!g->orthographic) {
        const float inv = 1.0f / sqrtf(m.p[0] * m.p[0] + m.p[1] * m.p[1] + m.p[2] * m.p[2]);
        for (int c = 0; c < 3; c++) v[c] = -m.p[c] * inv;
    }
    float n[3];
    hbao_grid_normal_at(g, i, j, n);
    m.n_dot_v = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
    m.height_tolerance = g->depth_precision * hbao_rounding_along_normal(g, n, m.p);
    hbao_height_plane_setup(g, n, m.p, hbao_grid_x(g, i), m.height_tolerance, &m.height);
    m.near_limit = hbao_near_limit(s, z);
    m.min_thickness = HBAO_MIN_BACK_THICKNESS * s->radius;
    const int cosine = s->integration == HBAO_INTEGRATION_COSINE;
    const int layers = g->back != NULL;

    const float n_cross_v[2] = {n[1] * v[2] - n[2] * v[1], n[2] * v[0] - n[0] * v[2]};
    float occlusion_sum = 0.0f;                /* HBAO */
    float visible_sum = 0.0f, open_sum = 0.0f; /* COSINE */
    for (int d = 0; d < s->directions; d++) {
        m.dc = job->direction_cos[cell][d];
        m.ds = job->direction_sin[cell][d];
        slice sl;
        slice_setup(v, n, n_cross_v, m.n_dot_v, m.dc, m.ds, &sl);
        if (cosine) {
            if (!sl.usable) continue; /* weight |np| = 0 */
            float open;
            const float occlusion = layers
                                        ? direction_occlusion_cosine_layers(s, &m, n, v, &sl, &open)
                                        : direction_occlusion_cosine(s, &m, v, &sl, &open);
            visible_sum += sl.np_length * (open - occlusion);
            open_sum += sl.np_length * open;
        } else {
            occlusion_sum += layers ? direction_occlusion_hbao_layers(s, &m, n, v, &sl)
                                    : direction_occlusion_hbao(s, &m, v, &sl);
        }
    }

    float ao;
    if (cosine)
        ao = open_sum > 1e-12f ? visible_sum / open_sum : 1.0f;
    else
        ao = 1.0f - occlusion_sum / ((float)s->directions * (1.0f - s->sin_bias));
    if (!(ao > 0.0f)) return 0.0f; /* also catches NaN */
    return ao < 1.0f ? ao : 1.0f;
}

/* The radius in grid pixels at depth z, as hbao_horizon_pixel and the SIMD
 * kernels compute it per pixel. */
static float projected_radius(const hbao_settings *s, const hbao_grid *g, float z) {
    return g->orthographic ? s->radius / g->pixel_size : s->radius / (g->pixel_size * z);
}

float hbao_block_step_at(const hbao_settings *s, const hbao_grid *g, float nearest) {
    /* The largest projected radius is the nearest pixel's: pixel_size * z
     * and the division round monotonically, so radius / (pixel_size * z) is
     * largest, to the bit, where z is smallest. One division per block. */
    if (nearest == INFINITY) return HBAO_BLOCK_UNSAMPLED;
    const float largest = projected_radius(s, g, nearest);
    return largest >= 1.0f ? (largest - 1.0f) / (float)s->steps : HBAO_BLOCK_UNSAMPLED;
}

/* hbao_grid_sampled's rows: every SAMPLED_ROW_STRIDE-th first (0, 16, 32...),
 * so that geometry in a band of that many rows anywhere is met in the first
 * pass, whatever lies above and below it. In order from row 0, a frame
 * whose upper 90 % is sky took 1.07x its time (the rows scanned on one
 * thread, bench_ab_pairs.sh --background 90). The first pass is one
 * thread's (an ordinary frame stops at its first row); where it finds no
 * sampled row, the bands' other rows are shared among the threads, which
 * stop as soon as any has found one. */
#define SAMPLED_ROW_STRIDE 16

/* Whether row j has a sampled pixel: its nearest foreground depth (NaN and
 * +inf are no foreground: a pixel there is 1, hbao_horizon_pixel), tested
 * as a block's nearest depth is. */
static int row_sampled(const hbao_settings *s, const hbao_grid *g, int j) {
    const float *row = g->depth + (size_t)j * g->width;
    float nearest = INFINITY;
    for (int i = 0; i < g->width; i++)
        nearest = row[i] > 0.0f && row[i] < nearest ? row[i] : nearest;
    return hbao_block_step_at(s, g, nearest) != HBAO_BLOCK_UNSAMPLED;
}

typedef struct sampled_job {
    const hbao_settings *settings;
    const hbao_grid *grid;
    atomic_int found; /* a row with a sampled pixel has been found */
} sampled_job;

/* Band b's rows after its first (b * SAMPLED_ROW_STRIDE + 1 ...) */
static void band_sampled(void *context, int band) {
    sampled_job *job = context;
    const int first = band * SAMPLED_ROW_STRIDE;
    const int end = first + SAMPLED_ROW_STRIDE < job->grid->height ? first + SAMPLED_ROW_STRIDE
                                                                   : job->grid->height;
    for (int j = first + 1; j < end; j++) {
        if (atomic_load_explicit(&job->found, memory_order_relaxed)) return;
        if (row_sampled(job->settings, job->grid, j)) {
            atomic_store_explicit(&job->found, 1, memory_order_relaxed);
            return;
        }
    }
}

int hbao_grid_sampled(const hbao_settings *s, const hbao_grid *g) {
    for (int j = 0; j < g->height; j += SAMPLED_ROW_STRIDE)
        if (row_sampled(s, g, j)) return 1;
    sampled_job job = {.settings = s, .grid = g};
    atomic_init(&job.found, 0);
    /* the rows' threads have all finished when this returns */
    hbao_parallel_rows(s->threads, (g->height + SAMPLED_ROW_STRIDE - 1) / SAMPLED_ROW_STRIDE,
                       band_sampled, &job);
    return atomic_load(&job.found);
}

uint32_t hbao_radius_notes(const hbao_settings *s, const hbao_grid *g) {
    const float shorter = fminf((float)g->width, (float)g->height * g->ycor);
    const int step_i = g->width / 64 + 1, step_j = g->height / 64 + 1;
    long foreground = 0, beyond = 0, under = 0;
    for (int j = step_j / 2; j < g->height; j += step_j)
        for (int i = step_i / 2; i < g->width; i += step_i) {
            const float z = g->depth[(size_t)j * g->width + i];
            if (!(z > 0.0f && z < INFINITY)) continue; /* background */
            foreground++;
            const float radius = projected_radius(s, g, z);
            beyond += radius > shorter;
            under += !(radius >= 1.0f); /* as hbao_block_step_at */
        }
    return (2 * beyond > foreground ? HBAO_NOTE_RADIUS_BEYOND_IMAGE : 0u) |
           (2 * under > foreground ? HBAO_NOTE_RADIUS_UNDER_A_PIXEL : 0u);
}

int hbao_block_classes(const hbao_settings *s, const hbao_grid *g, const float z[HBAO_BLOCK_PIXELS],
                       float class_step[HBAO_BLOCK_PIXELS],
                       unsigned class_lanes[HBAO_BLOCK_PIXELS]) {
    unsigned left = 0;
    for (int k = 0; k < HBAO_BLOCK_PIXELS; k++)
        if (z[k] > 0.0f && z[k] < INFINITY) left |= 1u << k;
    int classes = 0;
    while (left != 0) {
        float nearest = INFINITY;
        for (int k = 0; k < HBAO_BLOCK_PIXELS; k++)
            if ((left >> k & 1u) && z[k] < nearest) nearest = z[k];
        const float reach = g->orthographic ? INFINITY : HBAO_BLOCK_DEPTH_RATIO * nearest;
        unsigned lanes = 0;
        for (int k = 0; k < HBAO_BLOCK_PIXELS; k++)
            if ((left >> k & 1u) && z[k] <= reach) lanes |= 1u << k;
        class_step[classes] = hbao_block_step_at(s, g, nearest);
        class_lanes[classes] = lanes;
        classes++;
        left &= ~lanes;
    }
    return classes;
}

void hbao_block_steps(const horizon_job *job, int x0, int x1, int j, int a,
                      float step[HBAO_BLOCK_PIXELS]) {
    const hbao_grid *g = job->grid;
    float z[HBAO_BLOCK_PIXELS], class_step[HBAO_BLOCK_PIXELS];
    unsigned class_lanes[HBAO_BLOCK_PIXELS];
    for (int k = 0; k < HBAO_BLOCK_PIXELS; k++) {
        const int i = x0 + a + 4 * k;
        z[k] = i < x1 ? g->depth[(size_t)j * g->width + i] : 0.0f;
        step[k] = HBAO_BLOCK_UNSAMPLED;
    }
    const int classes = hbao_block_classes(job->settings, g, z, class_step, class_lanes);
    for (int c = 0; c < classes; c++)
        for (int k = 0; k < HBAO_BLOCK_PIXELS; k++)
            if (class_lanes[c] >> k & 1u) step[k] = class_step[c];
}

/* Pixels are visited tile by tile: a pixel's samples spread over the whole
 * projected radius, and the pixel below it samples nearly the same cache
 * lines, which are still cached when only a tile's height lies between them
 * (not a whole image). A tile is four block spans wide (TILE_COLUMNS, 256
 * columns; its rows are searched span by span) and TILE_ROWS high, and the
 * tiles are taken down the image's columns of tiles, each from top to
 * bottom. The cache lines a tile's samples reach span the radius around
 * it; the tile below shares all but TILE_ROWS rows of them. Taken along the
 * image's rows instead (as before), the lines left behind were evicted from
 * a 512 KiB L2 before the next band of tiles came back to them; and a
 * wider tile brings fewer new lines per pixel, as long as the lines around
 * it stay cached. scripts/bench_ab_pairs.sh on the Zen 3 machine, against
 * one-span tiles along the rows: 1080p defaults 0.879, 0.934, 0.967 and
 * 0.989 on 2 threads (60, 60, 60 and 30 rounds), 0.889 on 1; 8 x 6 + blur 15
 * 0.965 (60 rounds) and 0.991; back faces 0.737; 3840x2160 0.756. One-span
 * tiles down the columns took 0.928 on 1 thread, 0.96-1.01 on 2; two, four
 * and eight spans against one: four best on 2 threads (0.93-0.98), eight on
 * 1 (0.915); 4, 16 or 32 rows: no change. Each thread walking a half of
 * the image's columns of its own: 1.07 (the two threads' samples shared the
 * L3's lines). */
#define TILE_COLUMNS (4 * HBAO_BLOCK_SPAN)
#define TILE_ROWS 16

typedef struct tiled_job {
    const horizon_job *job;
    int tiles_across, tiles_down;
    hbao_horizon_span simd; /* NULL: the scalar reference */
} tiled_job;

void hbao_horizon_span_reference(const hbao_horizon_job *job, int x0, int x1, int j) {
    float *out = job->ao + (size_t)j * job->grid->width;
    for (int a = 0; a < 4; a++) {
        float step[HBAO_BLOCK_PIXELS];
        hbao_block_steps(job, x0, x1, j, a, step);
        for (int i = x0 + a; i < x1; i += 4)
            out[i] = hbao_horizon_pixel(job, i, j, step[(i - x0) / 4]);
    }
}

static void horizon_tile(void *context, int tile) {
    const tiled_job *tiled = context;
    const horizon_job *job = tiled->job;
    const int width = job->grid->width, height = job->grid->height;
    const int x0 = (tile / tiled->tiles_down) * TILE_COLUMNS;
    const int y0 = (tile % tiled->tiles_down) * TILE_ROWS;
    const int x1 = x0 + TILE_COLUMNS < width ? x0 + TILE_COLUMNS : width;
    const int y1 = y0 + TILE_ROWS < height ? y0 + TILE_ROWS : height;
    for (int j = y0; j < y1; j++) {
        for (int s0 = x0; s0 < x1; s0 += HBAO_BLOCK_SPAN) {
            const int s1 = s0 + HBAO_BLOCK_SPAN < x1 ? s0 + HBAO_BLOCK_SPAN : x1;
            if (tiled->simd != NULL)
                tiled->simd(job, s0, s1, j);
            else
                hbao_horizon_span_reference(job, s0, s1, j);
        }
    }
}

/* hbao_horizon_job.phase_depth (and phase_back), row by row. */
typedef struct deinterleave_job {
    const hbao_grid *grid;
    int phase_width, phase_rows, phase_pad;
    float *phase_depth; /* the origins, as in hbao_horizon_job */
    float *phase_back;  /* NULL without the back layer */
} deinterleave_job;

#if defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 12)
#define HBAO_SHUFFLE_VECTOR 1
typedef float four_floats __attribute__((vector_size(16)));
#endif

/* Row j of the grid into its four column phases (out[a]: phase a's row at
 * X = 0): phase a gets columns 4 X + a, for X from -pad up to
 * phase_width - pad; outside the image, hbao_beyond_fill's depths, or
 * INFINITY where `back` (the back layer's: unknown). A row outside the
 * image (j < 0 or j >= height) is all outside. */
static void deinterleave(const hbao_grid *g, const float *row, int j, int phase_width, int pad,
                         int back, float *const out[4]) {
    const int inside_row = j >= 0 && j < g->height;
    int x = 0;
#ifdef HBAO_SHUFFLE_VECTOR
    /* 16 columns at a time, a 4 x 4 transpose in vector registers (SSE2's
     * baseline), where the element loop below takes a load and a store per
     * float: the stages around the search (bench_ab_copies.sh, 1080p,
     * radius 1e-4, blur 0) 0.971 on 1 thread, 0.967 on 2. */
    for (; inside_row && 4 * (x + 4) <= g->width; x += 4) {
        four_floats r[4], o[4];
        memcpy(r, row + 4 * x, sizeof r);
        const four_floats low01 = __builtin_shufflevector(r[0], r[1], 0, 4, 1, 5);
        const four_floats high01 = __builtin_shufflevector(r[0], r[1], 2, 6, 3, 7);
        const four_floats low23 = __builtin_shufflevector(r[2], r[3], 0, 4, 1, 5);
        const four_floats high23 = __builtin_shufflevector(r[2], r[3], 2, 6, 3, 7);
        o[0] = __builtin_shufflevector(low01, low23, 0, 1, 4, 5);
        o[1] = __builtin_shufflevector(low01, low23, 2, 3, 6, 7);
        o[2] = __builtin_shufflevector(high01, high23, 0, 1, 4, 5);
        o[3] = __builtin_shufflevector(high01, high23, 2, 3, 6, 7);
        for (int a = 0; a < 4; a++) memcpy(out[a] + x, &o[a], sizeof o[a]);
    }
#endif
    for (int a = 0; a < 4; a++) {
        /* the phase's columns inside the image: X < ceil((width - a) / 4) */
        const int inside_end = inside_row ? (g->width - a + 3) / 4 : 0;
        for (int i = x; i < inside_end; i++) out[a][i] = row[4 * i + a];
        const int outside_from = inside_end > x ? inside_end : (inside_row ? x : -pad);
        if (back) {
            for (int i = -pad; i < 0; i++) out[a][i] = INFINITY;
            for (int i = outside_from > 0 ? outside_from : 0; i < phase_width - pad; i++)
                out[a][i] = INFINITY;
        } else if (inside_row) {
            hbao_beyond_fill(g, j, a, -pad, 0, out[a]);
            hbao_beyond_fill(g, j, a, outside_from, phase_width - pad, out[a]);
        } else {
            hbao_beyond_fill(g, j, a, -pad, phase_width - pad, out[a]);
        }
    }
}

static void deinterleave_row(void *context, int r) {
    const deinterleave_job *job = context;
    const hbao_grid *g = job->grid;
    const int j = r - g->beyond_rows;
    const size_t offset = j >= 0 && j < g->height ? (size_t)j * g->width : 0;
    float *out[4];
    for (int a = 0; a < 4; a++)
        out[a] = job->phase_depth + ((ptrdiff_t)a * job->phase_rows + j) * job->phase_width;
    deinterleave(g, g->depth + offset, j, job->phase_width, job->phase_pad, 0, out);
    if (job->phase_back != NULL) {
        for (int a = 0; a < 4; a++)
            out[a] = job->phase_back + ((ptrdiff_t)a * job->phase_rows + j) * job->phase_width;
        deinterleave(g, g->back + offset, j, job->phase_width, job->phase_pad, 1, out);
    }
}

/* The implementations from the slowest to the fastest (hbao.h): a kernel
 * the CPU lacks falls back to the one before it here, the one place that
 * orders them (hbao_implementation_that_runs). */
static const int32_t by_speed[] = {HBAO_IMPLEMENTATION_SCALAR, HBAO_IMPLEMENTATION_GENERIC,
                                   HBAO_IMPLEMENTATION_AVX2, HBAO_IMPLEMENTATION_AVX512};
#define IMPLEMENTATIONS ((int)(sizeof by_speed / sizeof by_speed[0]))

static int runs_here(int32_t implementation) {
    switch (implementation) {
        case HBAO_IMPLEMENTATION_GENERIC:
            return hbao_horizon_generic_available();
        case HBAO_IMPLEMENTATION_AVX2:
            return hbao_horizon_avx2_available();
        case HBAO_IMPLEMENTATION_AVX512:
            return hbao_horizon_avx512_available();
        default:
            return 1; /* the scalar reference */
    }
}

int32_t hbao_implementation_that_runs(int32_t requested) {
    int k = IMPLEMENTATIONS - 1;
    if (requested != HBAO_IMPLEMENTATION_AUTO)
        while (k > 0 && by_speed[k] != requested) k--;
    while (k > 0 && !runs_here(by_speed[k])) k--;
    return by_speed[k];
}

/* The kernel that runs for the implementation asked for; NULL: the scalar
 * reference. */
static hbao_horizon_span choose_kernel(int32_t implementation) {
    switch (hbao_implementation_that_runs(implementation)) {
        case HBAO_IMPLEMENTATION_AVX512:
            return hbao_horizon_span_avx512;
        case HBAO_IMPLEMENTATION_AVX2:
            return hbao_horizon_span_avx2;
        case HBAO_IMPLEMENTATION_GENERIC:
            return hbao_horizon_span_generic;
        default:
            return NULL;
    }
}

int32_t hbao_best_implementation(void) {
    return hbao_implementation_that_runs(HBAO_IMPLEMENTATION_AUTO);
}

uint32_t hbao_compute_horizons(const hbao_settings *settings, const hbao_grid *grid, float *ao) {
    horizon_job job;
    job.settings = settings;
    job.grid = grid;
    job.ao = ao;
    for (int cell = 0; cell < 16; cell++) {
        const int i = cell & 3, j = cell >> 2;
        const double rotation = (bayer_4x4[cell] + 0.5) / 16.0;
        job.jitter[cell] = (float)((bayer_4x4[j + 4 * i] + 0.5) / 16.0);
        /* An even count's second half is its first half negated (the
         * angles plus pi), exactly, so that the SIMD kernels set up a pair
         * of opposite directions at once (horizon_simd.h, block_ao). */
        const int directions = settings->directions;
        const int half = directions % 2 == 0 ? directions / 2 : directions;
        for (int d = 0; d < half; d++) {
            const double theta = 2.0 * 3.14159265358979323846 * (d + rotation) / directions;
            job.direction_cos[cell][d] = (float)cos(theta);
            job.direction_sin[cell][d] = (float)sin(theta);
        }
        for (int d = half; d < directions; d++) {
            job.direction_cos[cell][d] = -job.direction_cos[cell][d - half];
            job.direction_sin[cell][d] = -job.direction_sin[cell][d - half];
        }
    }
    tiled_job tiled;
    tiled.job = &job;
    tiled.tiles_across = (grid->width + TILE_COLUMNS - 1) / TILE_COLUMNS;
    tiled.tiles_down = (grid->height + TILE_ROWS - 1) / TILE_ROWS;
    tiled.simd = choose_kernel(settings->implementation);
    uint32_t notes = hbao_radius_notes(settings, grid);
    float *phase_depth = NULL, *phase_back = NULL;
    job.phase_depth = NULL;
    job.phase_back = NULL;
    /* whole blocks, so that a block's depths are always one full load, and
     * a block's lanes stepped into the band too */
    const int columns = grid->beyond_columns, rows = grid->beyond_rows;
    job.phase_pad = (columns + 3) / 4 + 1;
    job.phase_rows = grid->height + 2 * rows;
    job.phase_width =
        (job.phase_pad + (grid->width + columns + 3) / 4 + 2 * HBAO_BLOCK_PIXELS - 1) /
        HBAO_BLOCK_PIXELS * HBAO_BLOCK_PIXELS;
    job.int_indices = (int64_t)4 * job.phase_rows * job.phase_width <= INT32_MAX;
    /* the origin: row 0, X = 0 of phase 0 */
    const ptrdiff_t origin = (ptrdiff_t)rows * job.phase_width + job.phase_pad;
    if (tiled.simd != NULL) {
        const size_t bytes = (size_t)4 * job.phase_rows * job.phase_width * sizeof(float);
        phase_depth = hbao_scratch_take(bytes);
        if (grid->back != NULL) phase_back = hbao_scratch_take(bytes);
        /* Without memory for the copies the scalar reference computes the
         * same result, only slower. */
        if (phase_depth == NULL || (grid->back != NULL && phase_back == NULL)) {
            tiled.simd = NULL;
            notes |= HBAO_NOTE_REFERENCE_SEARCH;
            hbao_scratch_give(phase_depth);
            hbao_scratch_give(phase_back);
            phase_depth = phase_back = NULL;
        }
    }
    if (phase_depth != NULL) {
        deinterleave_job split = {
            grid,          job.phase_width,      job.phase_rows,
            job.phase_pad, phase_depth + origin, phase_back != NULL ? phase_back + origin : NULL};
        hbao_parallel_rows(settings->threads, job.phase_rows, deinterleave_row, &split);
        job.phase_depth = split.phase_depth;
        job.phase_back = split.phase_back;
    }
    hbao_parallel_rows(settings->threads, tiled.tiles_across * tiled.tiles_down, horizon_tile,
                       &tiled);
    hbao_scratch_give(phase_depth);
    hbao_scratch_give(phase_back);
    return notes;
}
