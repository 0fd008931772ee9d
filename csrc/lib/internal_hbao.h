/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Private declarations shared by the library's source files. The pipeline
 * (compute.c) is: convert depth -> [half-resolution grid] -> camera-space
 * normals -> horizon sampling -> [depth-aware upsample] -> cross-bilateral
 * blur -> strength. Every stage works on whole rows so that rows can be
 * handed to worker threads; no stage reads what another thread writes in the
 * same stage, so the result does not depend on the number of threads. */
#ifndef HBAO_INTERNAL_H
#define HBAO_INTERNAL_H

#include <stddef.h>
#include <math.h>
#include <stdint.h>

#include "hbao.h"

#define HBAO_PI 3.14159265358979323846f

/* A normal shorter than this before the transform is not trusted (Cycles
 * averages normals over samples, so anti-aliased edges are short; background
 * is zero) and is reconstructed from depth instead. */
#define HBAO_MIN_NORMAL_LENGTH 0.1f
/* The least float whose sqrtf is at least HBAO_MIN_NORMAL_LENGTH (1 ulp
 * below 0.1f * 0.1f): sqrtf rounds correctly and never decreases, so a
 * squared length s has sqrtf(s) >= HBAO_MIN_NORMAL_LENGTH exactly where
 * s >= this, and the test needs no square root (test_stages.c holds both
 * sides of it). */
#define HBAO_MIN_NORMAL_LENGTH_SQUARED 0x1.47ae14p-7f

/* How strongly the half-resolution upsample rejects samples at other depths,
 * in units of 1 / relative depth difference (docs/algorithm.md). */
#define HBAO_UPSAMPLE_SHARPNESS 16.0f

/* Parameters after clamping to the documented limits. */
typedef struct hbao_settings {
    float radius;
    /* The quadratic falloff's 1 / radius^2 (its weight is 1 - dist2 *
     * inv_radius2), at most FLT_MAX: under a radius of 2^-64 the reciprocal
     * overflowed to +inf, a weight became -inf, and a step the SIMD copies
     * skip as a repeat of its pixel (it changes nothing) gave the scalar
     * reference -inf * 0 = NaN: the copies disagreed (a review). Capped,
     * the weight of a sample within the radius stays finite. */
    float inv_radius2;
    float sin_bias; /* of the angle bias */
    /* the bias elevation's (sin_bias as an elevation) sine and arc cosine,
     * as horizon_from_elevation computes them: where every horizon starts */
    float bias_elevation_sine, bias_elevation_acos;
    int directions;
    int steps;
    int falloff;
    int integration;
    int blur_radius; /* taps on each side; 0 = no blur */
    /* the blur's taps on each side on the grid it runs on: blur_radius at
     * full resolution; at half resolution, where the blur runs on the half
     * grid before the upsample, half of it rounded up (same reach) */
    int grid_blur_radius;
    float blur_sharpness;
    int half_resolution;
    float strength;
    int threads;
    float background_depth;
    int implementation; /* hbao_implementation as asked for */
    float thickness;    /* occluder thickness, 0 = infinite (hbao_params) */
    /* How many strips of columns the blur cuts a band's rows into (blur.c,
     * hbao_blur_strips; at most one a column); 0, as hbao_settings_make
     * sets it: blur.c's rule. The tests set it to cut any image into
     * strips, which give the same floats. */
    int blur_strips;
} hbao_settings;

/* The blur's taps on each side for a kernel of `size` pixels (hbao_params'
 * blur_size): even sizes round down, and 0, 1 and 2 are no blur. The one
 * rule: hbao_params_resolve gives the size in its canonical form by it,
 * hbao_settings_make the radius (the add-on's parameters.py holds a copy
 * for the viewport's shader, tests/test_parameter_contract.py to this). */
static inline int hbao_blur_kernel_radius(int32_t size) {
    return size >= 2 ? (size - 1) / 2 : 0;
}

/* A depth value as the pipeline uses it: background (not finite, <= 0,
 * >= background_depth, or exactly HBAO_HALF_FLOAT_SKY) as 0. z > 0 && z <
 * background fails for NaN, -inf and +inf (+inf < +inf is false where the
 * background depth is infinite) as for background, so no isfinite() is
 * needed. Written as a select so that the loops calling it vectorize. */
static inline float hbao_depth_value(float z, float background) {
    /* & rather than &&: no branch, so the loops still vectorize (&& made
     * the full-resolution depth conversion 1.3x slower, bench_ab) */
    const int keep = (z > 0.0f) & (z < background) & (z != HBAO_HALF_FLOAT_SKY);
    return keep ? z : 0.0f;
}

/* The image that horizons are searched on: the full image, or the
 * half-resolution grid. Depth is dense and positive; 0 marks background. */
typedef struct hbao_grid {
    int width, height;
    float *depth; /* width * height */
    /* width * height: the back faces' depth (hbao_compute_layers), INFINITY
     * where unknown; NULL without the layer */
    const float *back;
    /* Camera space, facing the viewer. Each row is three rows of width
     * floats, its normals' x, y and z (hbao_grid_normal_row), and
     * HBAO_NORMAL_PADDING zeros follow the last: so the blur reads each
     * component as a row, and a SIMD kernel loads the lanes of a column
     * phase with whole vectors (horizon_simd.h) without reading past the
     * end. The three rows of a row lie together, so that writing them is
     * one stream through memory, not three. */
    float *normal;
    /* View-plane coordinates (per unit depth if perspective) of column i and
     * row j: (i + x_offset) * x_step and (j + y_offset) * y_step. Computed,
     * not tabulated, so that SIMD code needs no gather for them. */
    float x_offset, x_step, y_offset, y_step;
    int orthographic;
    float pixel_size; /* view-plane width of one grid pixel (per unit depth if perspective) */
    float ycor;       /* pixel height / pixel width */
    /* The spacing of representable depths relative to the depth: an upper
     * bound on ulp(z) / z for the format the depth came in (set by
     * hbao_compute_normals(), docs/algorithm.md "Depth precision"). */
    float depth_precision;
    /* The tangent planes of the image's edge pixels, which steps past the
     * edge see continued (hbao_beyond_depth; beyond.c fills them once the
     * normals are known): hbao_beyond_floats(width, height) floats. */
    float *beyond;
    /* How far past the edges steps go on, in grid pixels, past the left and
     * right sides and past the top and bottom: the band of
     * HBAO_BEYOND_BAND_DIVISOR, but no more than a step less than an image
     * away can reach (width - 1, height - 1), which bounds the band's
     * memory for a grid much longer than wide */
    int beyond_columns, beyond_rows;
} hbao_grid;

/* Component c (x, y, z) of row j's normals; row `height` is the padding */
static inline float *hbao_grid_normal_row(const hbao_grid *grid, int j, int c) {
    return grid->normal + (3 * (size_t)j + (size_t)c) * (size_t)grid->width;
}

static inline void hbao_grid_normal_at(const hbao_grid *grid, int i, int j, float n[3]) {
    for (int c = 0; c < 3; c++) n[c] = hbao_grid_normal_row(grid, j, c)[i];
}

/* ulp(z) / z <= 2^-10 for half floats (10 mantissa bits), 2^-23 for floats. */
#define HBAO_HALF_DEPTH_PRECISION 9.765625e-4f
#define HBAO_FLOAT_DEPTH_PRECISION 1.1920929e-7f

/* How far rounding the depth to a spacing of 1 (times z) moves the point at
 * `position` along the normal n: |dot(n, P)| in perspective (the point moves
 * along its ray, P / z per unit of depth; for every point of a plane this is
 * the plane's distance from the eye), |n.z| z in orthographic views. Times
 * depth_precision it bounds the height error of a sample relative to the
 * centre's tangent plane when both depths are rounded (each by at most half
 * a spacing). Written as the SIMD kernels compute it. */
static inline float hbao_rounding_along_normal(const hbao_grid *grid, const float n[3],
                                               const float position[3]) {
    const float along = grid->orthographic
                            ? n[2] * position[2]
                            : n[0] * position[0] + n[1] * position[1] + n[2] * position[2];
    return along < 0.0f ? -along : along;
}

/* Finite occluder thickness (hbao_params.thickness, docs/algorithm.md
 * "Thickness"): a sample at depth zs stands for a block over [zs, zs + t];
 * when zs + t < z, written zs < z - t, the block lies wholly in front of the
 * pixel at depth z and the sample is skipped. t = 0 (infinitely thick)
 * skips nothing: the limit 0 is below every foreground depth. The SIMD
 * kernels compute the same z - t lane by lane. */
static inline float hbao_near_limit(const hbao_settings *settings, float z) {
    return settings->thickness > 0.0f ? z - settings->thickness : 0.0f;
}

/* The back layer (grid->back): an occluder is taken as at least this many
 * radii thick (horizon.c, "Two depth layers"; chosen with
 * bench/guard_band.py: 0.1 to 1 tried, 0.5 best on three of four scenes). */
#define HBAO_MIN_BACK_THICKNESS 0.5f
/* ... and each direction's sector mask has this many sectors (bits). */
#define HBAO_SECTORS 32

/* The back depth used for a sample of depth zs whose back face lies at zb
 * (finite: known). */
static inline float hbao_back_depth(float zs, float zb, float min_thickness) {
    const float thinnest = zs + min_thickness;
    return zb > thinnest ? zb : thinnest;
}

/* camera.c */
hbao_result hbao_validate_camera(const hbao_camera *camera);
/* Fill the grid's view-plane mapping, pixel_size, ycor, orthographic for a grid whose
 * pixel (i, j) is full-resolution pixel (scale * i, scale * j) of a
 * full_width x full_height image. */
void hbao_grid_set_projection(hbao_grid *grid, const hbao_camera *camera, int full_width,
                              int full_height, int scale);

static inline float hbao_grid_x(const hbao_grid *grid, int i) {
    return ((float)i + grid->x_offset) * grid->x_step;
}

static inline float hbao_grid_y(const hbao_grid *grid, int j) {
    return ((float)j + grid->y_offset) * grid->y_step;
}

static inline void hbao_grid_position(const hbao_grid *grid, int i, int j, float depth,
                                      float position[3]) {
    if (grid->orthographic) {
        position[0] = hbao_grid_x(grid, i);
        position[1] = hbao_grid_y(grid, j);
    } else {
        position[0] = hbao_grid_x(grid, i) * depth;
        position[1] = hbao_grid_y(grid, j) * depth;
    }
    position[2] = -depth;
}

/* A sample's height above the pixel's tangent plane, dot(n, Q - P) lowered
 * by the depth's rounding tolerance, written as a plane in the sample's
 * pixel offset ox and grid row y: in perspective Q = zs (x, y, -1), so the
 * height is zs (x n0 + y n1 - n2) - (dot(n, P) + tolerance), and x n0 is
 * the pixel's own column term plus ox x_step n0. Three products and sums
 * per sample instead of the vector Q - P: the one-layer search computes it
 * for every step and the vector only for samples above the plane. The
 * SIMD kernels perform the same operations in the same order. */
typedef struct hbao_height_plane {
    float across;    /* x n0 - n2 at the pixel's column (x n0 if orthographic) */
    float per_pixel; /* x_step n0: the change of across per column */
    float per_row;   /* n1 */
    float depth;     /* n2, orthographic only: Q = (x, y, -zs) */
    float offset;    /* dot(n, P) + tolerance + HBAO_HEIGHT_ROUNDING sum |P_c n_c| */
} hbao_height_plane;

/* The rounding of hbao_sample_height's eight operations, relative to
 * sum |P_c n_c| (to zs (|x n0| + |y n1| + |n2|) for the sample): 8 ulps of
 * 1 (2^-24 each). Samples on the tangent plane then never come out above
 * it, so they are skipped before any square root, as with the exact
 * difference Q - P; what it hides is an elevation of under 0.1 degrees one
 * pixel away at 1080p with a 50 mm lens. */
#define HBAO_HEIGHT_ROUNDING 4.7683716e-7f

static inline void hbao_height_plane_setup(const hbao_grid *grid, const float n[3],
                                           const float position[3], float column, float tolerance,
                                           hbao_height_plane *plane) {
    plane->across = grid->orthographic ? column * n[0] : column * n[0] - n[2];
    plane->per_pixel = grid->x_step * n[0];
    plane->per_row = n[1];
    plane->depth = n[2];
    const float rounding =
        fabsf(position[0] * n[0]) + fabsf(position[1] * n[1]) + fabsf(position[2] * n[2]);
    plane->offset = position[0] * n[0] + position[1] * n[1] + position[2] * n[2] + tolerance +
                    HBAO_HEIGHT_ROUNDING * rounding;
}

/* The plane's across term at a sample's pixel, and the height there at
 * depth z: along the sample's view ray the height is linear in z. */
static inline float hbao_height_across(const hbao_height_plane *plane, float ox, float row) {
    return plane->across + ox * plane->per_pixel + row * plane->per_row;
}

static inline float hbao_height_at(const hbao_grid *grid, const hbao_height_plane *plane,
                                   float across, float z) {
    return (grid->orthographic ? across - z * plane->depth : z * across) - plane->offset;
}

static inline float hbao_sample_height(const hbao_grid *grid, const hbao_height_plane *plane,
                                       float zs, float ox, float row) {
    return hbao_height_at(grid, plane, hbao_height_across(plane, ox, row), zs);
}

/* parallel.c: run job(context, row) for every row in [0, rows), on up to
 * `threads` threads (the calling thread included). If a thread cannot be
 * started, the threads that did start do its rows. */
typedef void (*hbao_row_job)(void *context, int row);
void hbao_parallel_rows(int threads, int rows, hbao_row_job job, void *context);
/* How many of `threads` hbao_parallel_rows runs `rows` on (the calling
 * thread included): at most as many as there are grabs of rows, and at most
 * `threads`. */
int hbao_parallel_threads(int threads, int rows);
/* hbao_parallel_rows with one job a grab: for a few jobs of uneven cost
 * (the blur's bands and their strips, blur.c). It runs them on
 * hbao_parallel_each_threads(threads, jobs) threads at most, the calling
 * thread included (blur.c's band memory, one set a thread, counts on it). */
void hbao_parallel_each(int threads, int jobs, hbao_row_job job, void *context);
int hbao_parallel_each_threads(int threads, int jobs);

/* Large working buffers (scratch.c): like malloc and free, but a given
 * buffer is kept for the next call (hbao_release_memory frees them). */
void *hbao_scratch_take(size_t bytes);
void hbao_scratch_give(void *memory);
/* Every allocation of the library is a scratch take, made before the stage
 * that writes the caller's output starts (blur.c's band pool), so that a
 * call that runs out of memory leaves the output as it was. For tests
 * (csrc/tests/internal): where set, a take that it answers 1 for fails. */
extern int (*hbao_scratch_fails)(size_t bytes);
/* For tests too: where 0-255, every take fills the block it gives, to its
 * whole capacity, with that byte (0xff: NaN as floats; 0x3f: about 0.75),
 * so that a buffer read before it is written, or past the bytes asked
 * (which ASan does not see in a kept block), shows in the output; -1: no
 * fill. */
extern int hbao_scratch_fill;
/* The threads "one per core" gives (threads = 0): the CPUs this process may
 * run on (hbao_cpus.h), at most HBAO_MAX_THREADS. */
int hbao_available_cores(void);
/* The second-level cache of one core in bytes, as the C library reports
 * it (glibc: CPUID), or 0 where it is not known. */
long hbao_core_cache_bytes(void);

/* compute.c: the pipeline's settings from params (resolved within their
 * limits, hbao_params_resolve), or the error that hbao_compute returns. */
hbao_result hbao_settings_make(const hbao_params *params, hbao_settings *s);

/* normals.c: grid->normal from the given normals (world space, sampled at
 * full-resolution pixel (scale*i, scale*j)) or reconstructed from depth. */
void hbao_compute_normals(const hbao_settings *settings, const hbao_camera *camera, hbao_grid *grid,
                          const hbao_channel *normal, int scale);

/* horizon.c: raw AO on the grid (dense, grid->width wide). Returns the
 * HBAO_NOTE_* bits of what it did other than usual. */
uint32_t hbao_compute_horizons(const hbao_settings *settings, const hbao_grid *grid, float *ao);

/* horizon.c: whether any pixel of the grid (its depths and projection set)
 * is sampled, its projected radius a pixel or more. Where none is, every
 * raw AO is 1, and so is everything the blur, the upsample and any
 * strength make of it, exactly: hbao_compute_layers then writes 1s and
 * computes nothing else. Stops once a row that has such a pixel is found
 * (its rows in the order and on the threads that horizon.c gives). */
int hbao_grid_sampled(const hbao_settings *settings, const hbao_grid *grid);
/* The HBAO_NOTE_RADIUS_* bits of a frame: where, at more than half of the
 * foreground pixels among about 4096 spread over the grid (every k-th of
 * every k-th row), the projected radius exceeds the grid's shorter side
 * (BEYOND_IMAGE), or spans less than a pixel (UNDER_A_PIXEL). The radius is
 * in pixels along a row; a column's pixels are ycor times as tall. */
uint32_t hbao_radius_notes(const hbao_settings *settings, const hbao_grid *grid);

/* What every horizon kernel needs: settings, grid and per-pattern-cell
 * tables (4x4 interleaved rotation and jitter, docs/algorithm.md). */
typedef struct hbao_horizon_job {
    const hbao_settings *settings;
    const hbao_grid *grid;
    float *ao;
    float direction_cos[16][HBAO_MAX_DIRECTIONS];
    float direction_sin[16][HBAO_MAX_DIRECTIONS];
    float jitter[16];
    /* The depth deinterleaved by column phase (SIMD kernels only; NULL for
     * the scalar reference), with the band past the image's edges that
     * steps see (grid->beyond_columns, beyond_rows) filled in:
     * phase_depth[(a * phase_rows + j) * phase_width + X] is grid depth
     * (4 X + a, j) inside the image, hbao_beyond_depth's in the band, 0 past
     * it, for rows j from -beyond_rows to height + beyond_rows - 1 and X
     * from -phase_pad to
     * phase_width - phase_pad - 1 (the pointer is the origin's, inside its
     * buffer). A block's step into the band is then a plain load, like a
     * step inside the image. */
    const float *phase_depth;
    /* grid->back deinterleaved the same way, INFINITY (unknown) outside the
     * image (NULL without the layer) */
    const float *phase_back;
    int phase_width, phase_rows, phase_pad;
    /* whether every index into phase_depth fits an int32 (4 * phase_rows *
     * phase_width < 2^31): the SIMD kernels' step plan then computes them */
    int int_indices;
} hbao_horizon_job;

/* The horizon search works on blocks: the HBAO_BLOCK_PIXELS pixels
 * i = x0 + a + 4 k of one row (x0 a multiple of 4 * HBAO_BLOCK_PIXELS,
 * phase a in 0..3, k in 0..HBAO_BLOCK_PIXELS-1) share a pattern cell, so
 * they march the same directions with the same jitter; the pixels of a
 * class (hbao_block_classes) also share one step length, from the largest
 * projected radius among them, so every step is one pixel offset for all of
 * them and their depths are one contiguous load from phase_depth
 * (docs/algorithm.md, "Per-pixel sampling"). */
#define HBAO_BLOCK_PIXELS 16
#define HBAO_BLOCK_SPAN (4 * HBAO_BLOCK_PIXELS) /* columns a block spans */

/* Past the image's edges (docs/algorithm.md, "Beyond the frame"): a step
 * that leaves the image (less than an image away: hbao_step_offset) sees
 * the surface at the nearest pixel of the edge continued as its tangent
 * plane, met by the step's own view ray. A floor or a wall that the frame
 * cuts goes on past it, so a pixel near the frame's edge keeps the
 * occluders there, which a direction that ended at the edge lost.
 *
 * grid->beyond holds each edge pixel's plane as four floats, n0 n1 n2 and
 * dot(n, P) (NaN where the pixel is background), in two tables:
 * - the top and bottom rows' (samples above or below the image, corners
 *   included), for columns -HBAO_BEYOND_PAD(width) .. 2 width + pad (a
 *   step less than an image away reaches 1 - width .. 2 width - 2), each
 *   column taking the plane of the nearest column inside, and laid out as
 *   phase_depth is (by column phase, so that a phase row's run of the band
 *   is a run of each term: hbao_beyond_fill): float (row r, term q, column c) at
 *   ((4 r + q) 4 + x % 4) hbao_beyond_row_floats(width) + x / 4, x = c +
 *   pad;
 * - the left and right columns' (samples beside the image), four floats a
 *   row: float (side s, row j, term q) at the rows' table's end + (s height
 *   + j) 4 + q. */
#define HBAO_BEYOND_PAD(width) (((width) + 3) / 4 * 4)

/* Floats of one phase row of the row tables: columns up to 2 width past
 * the pad, and a vector's more to spare. */
static inline size_t hbao_beyond_row_floats(int width) {
    return ((size_t)HBAO_BEYOND_PAD(width) + 2 * (size_t)width + 3) / 4 + HBAO_BLOCK_PIXELS;
}

static inline size_t hbao_beyond_floats(int width, int height) {
    return 32 * hbao_beyond_row_floats(width) + 8 * (size_t)height;
}

/* The depth of the plane (n0, n1, n2, plane) on the view ray of grid
 * coordinates (x, y) (hbao_grid_x, hbao_grid_y), or 0 (background) where it
 * meets the ray behind the camera or not at all. One function for every
 * kernel: the SIMD kernels perform its operations lane by lane. */
static inline float hbao_plane_depth(const hbao_grid *grid, float n0, float n1, float n2,
                                     float plane, float x, float y) {
    const float across = n0 * x + n1 * y;
    /* perspective: z (x, y, -1) on the plane; orthographic: (x, y, -z) */
    const float z = grid->orthographic ? (across - plane) / n2 : plane / (across - n2);
    return z > 0.0f && z < INFINITY ? z : 0.0f; /* NaN: 0 */
}

/* The depth a step sees at grid pixel (si, sj) outside the image. */
static inline float hbao_beyond_depth(const hbao_grid *grid, int si, int sj) {
    const float *plane;
    size_t term;
    if (sj < 0 || sj >= grid->height) {
        const size_t length = hbao_beyond_row_floats(grid->width);
        const int x = si + HBAO_BEYOND_PAD(grid->width); /* >= 1: si > -width */
        plane =
            grid->beyond + ((size_t)(sj >= 0) * 16 + (size_t)(x & 3)) * length + (size_t)(x >> 2);
        term = 4 * length;
    } else {
        plane = grid->beyond + 32 * hbao_beyond_row_floats(grid->width) +
                ((size_t)(si >= 0) * grid->height + (size_t)sj) * 4;
        term = 1;
    }
    return hbao_plane_depth(grid, plane[0], plane[term], plane[2 * term], plane[3 * term],
                            hbao_grid_x(grid, si), hbao_grid_y(grid, sj));
}

/* Steps go on past the edges for the image's longer side over this many
 * pixels (grid->beyond_columns, beyond_rows), then end their direction as at a whole
 * image away: 120 pixels at 1920x1080. bench/guard_band.py's real guard
 * bands, 480x270: a band of 1/16 of the width reached nearly all that 1/8
 * and 1/4 did. Continued without end (an image away), the four 1080p
 * scenes' RMSE fell at most 0.0004 more (terrain) for 1.03 of the time
 * (bench_ab); to 1/32, it rose up to 0.011 (bunny: 0.0343 against 0.0236). */
#define HBAO_BEYOND_BAND_DIVISOR 16

/* beyond.c: grid->beyond from the grid's depth and normals, and
 * grid->beyond_columns and beyond_rows. */
void hbao_beyond_planes(hbao_grid *grid);
/* beyond.c: out[x] = the depth at column 4 x + a of row j, for x in [from,
 * to), every such column outside the image (hbao_beyond_depth within the
 * band, 0 past it). */
void hbao_beyond_fill(const hbao_grid *grid, int j, int a, int from, int to, float *out);
/* Floats after grid->normal's last row: more than a block spans, so that a
 * kernel may load a block's normals as whole vectors from its first pixel
 * on, even in the z row of the grid's last row. */
#define HBAO_NORMAL_PADDING (2 * HBAO_BLOCK_SPAN)

/* A step length in pixels, (R - 1) / steps for the largest projected
 * radius R of the pixels that share it; negative (HBAO_BLOCK_UNSAMPLED)
 * where none of them is sampled (every projected radius under a pixel), so
 * every AO there is 1. From the nearest foreground depth of those pixels
 * (INFINITY: none). */
#define HBAO_BLOCK_UNSAMPLED (-1.0f)
float hbao_block_step_at(const hbao_settings *settings, const hbao_grid *grid, float nearest);

/* A block's pixels in classes that each share one step length: the nearest
 * foreground depth z0 leads the first class, of the depths up to
 * HBAO_BLOCK_DEPTH_RATIO z0 (in perspective; in an orthographic view every
 * depth has one projected radius, and all are one class); the nearest depth
 * beyond leads the next class, and so on. One step length for a whole
 * block took every step of a pixel far behind a near one (an object at
 * the lens) past that pixel's own radius, so its AO was 1: a light band 64
 * columns wide with hard edges. Within a class a pixel spends at least a
 * quarter of its steps inside its radius. Most blocks are one class. */
#define HBAO_BLOCK_DEPTH_RATIO 4.0f
/* z: the block's depths, lane k at column x0 + a + 4 k, 0 past the image
 * (those of no class: background, <= 0, +inf or NaN). Fills each class's
 * step length and lanes (bit k: lane k), nearest class first, and returns
 * how many there are (0 to HBAO_BLOCK_PIXELS). */
int hbao_block_classes(const hbao_settings *settings, const hbao_grid *grid,
                       const float z[HBAO_BLOCK_PIXELS], float class_step[HBAO_BLOCK_PIXELS],
                       unsigned class_lanes[HBAO_BLOCK_PIXELS]);
/* The step length of each pixel of the block of phase a that starts at
 * column x0 of row j (pixels before x1 only): its class's, or
 * HBAO_BLOCK_UNSAMPLED for a pixel of no class. */
void hbao_block_steps(const hbao_horizon_job *job, int x0, int x1, int j, int a,
                      float step[HBAO_BLOCK_PIXELS]);

/* The pixel offset (ox, oy) of step `step` along direction (dc, ds) of a
 * block: floor(0.5 + dc t), floor(0.5 - ds t / ycor), t = 1 + (step +
 * jitter) * step_px. Returns 0 when it lies a whole image away, where every
 * later step lies too. One function for every kernel, so all compute the
 * same offsets. */
static inline int hbao_floor_in_range(float x, int limit, int *floor_x) {
    /* floor(x) in (-limit, limit), tested before converting so that a huge
     * projected radius cannot overflow int; NaN fails. Floor by truncation
     * and correction: no libm call in the scalar reference's inner loop. */
    if (!(x >= (float)(1 - limit) && x < (float)limit)) return 0;
    const int truncated = (int)x;
    *floor_x = (float)truncated > x ? truncated - 1 : truncated;
    return 1;
}

static inline int hbao_step_offset(const hbao_grid *grid, float dc, float ds, float inv_ycor,
                                   float jitter, float step_px, int step, int *ox, int *oy) {
    const float t = 1.0f + ((float)step + jitter) * step_px;
    return hbao_floor_in_range(0.5f + dc * t, grid->width, ox) &&
           hbao_floor_in_range(0.5f - ds * t * inv_ycor, grid->height, oy);
}

/* The scalar reference for one pixel (horizon.c), with its block's step. */
float hbao_horizon_pixel(const hbao_horizon_job *job, int i, int j, float step_px);

/* SIMD kernels (horizon_generic.c, horizon_avx2.c, horizon_avx512.c, all
 * made from horizon_simd.h): whether this CPU and build can run each, and the kernel
 * that computes pixels [x0, x1) of row j bit-identically to
 * hbao_horizon_pixel(); x0 is a multiple of HBAO_BLOCK_SPAN and x1 - x0 at
 * most HBAO_BLOCK_SPAN. */
typedef void (*hbao_horizon_span)(const hbao_horizon_job *job, int x0, int x1, int j);
int hbao_horizon_avx2_available(void);
void hbao_horizon_span_avx2(const hbao_horizon_job *job, int x0, int x1, int j);
int hbao_horizon_avx512_available(void);
void hbao_horizon_span_avx512(const hbao_horizon_job *job, int x0, int x1, int j);
/* The scalar reference's span: what the kernels' copies built without their
 * instruction set run (never chosen) */
void hbao_horizon_span_reference(const hbao_horizon_job *job, int x0, int x1, int j);
int hbao_horizon_generic_available(void);
void hbao_horizon_span_generic(const hbao_horizon_job *job, int x0, int x1, int j);

/* sqrt(1 - c^2), 0 where rounding takes c past 1: the sine of an angle
 * from its cosine (a horizon's, from its elevation or its angle to V). */
static inline float hbao_sine_from_cosine(float c) {
    return sqrtf(fmaxf(0.0f, 1.0f - c * c));
}

/* acos(x) for x in [-1, 1] to 6.8e-5 absolute in floats (Abramowitz &
 * Stegun 4.4.45: 6.7e-5; the largest error lies at 0, so that a slice
 * whose projected normal points along V gets a gamma of 6.8e-5, not 0):
 * the cosine integration needs an angle for every direction's horizon and
 * every slice. A&S 4.4.46 (to 2e-8, eight terms instead of four) until
 * session 45: its arc cosines were 8 % of a 1080p frame at the defaults
 * and 11 % at 8 x 6 (perf); this one moves no AO by more than 2.3e-5 there
 * (a twentieth of a half float's step near 1) and measured, after / before
 * (scripts/bench_ab_pairs.sh, Zen 5, 1 thread), 0.993 at the defaults and
 * 0.970 at 8 x 6 + blur 15. */
#define HBAO_ACOS_A3 (-0.0187293f) /* the coefficients, x^3 first: horizon_simd.h's too */
#define HBAO_ACOS_A2 0.0742610f
#define HBAO_ACOS_A1 (-0.2121144f)
#define HBAO_ACOS_A0 1.5707288f
static inline float hbao_acos(float x) {
    const float ax = x < 0.0f ? -x : x;
    float p = HBAO_ACOS_A3;
    p = p * ax + HBAO_ACOS_A2;
    p = p * ax + HBAO_ACOS_A1;
    p = p * ax + HBAO_ACOS_A0;
    const float one_minus = 1.0f - ax;
    const float r = (one_minus > 0.0f ? sqrtf(one_minus) : 0.0f) * p;
    return x < 0.0f ? HBAO_PI - r : r;
}

#endif /* HBAO_INTERNAL_H */
