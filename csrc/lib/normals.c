/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Camera-space normals for every grid pixel: Blender's world-space Normal
 * pass rotated into the camera, or face normals reconstructed from depth
 * (Bavoil & Sainz: face normals avoid the false occlusion that interpolated
 * normals give). Every normal is turned to face the viewer. */
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>

#include "internal_finish.h"

typedef struct normal_job {
    const hbao_camera *camera;
    hbao_grid *grid;
    const hbao_channel *given; /* NULL: reconstruct everything */
    int scale;
    int implementation; /* the compiled copy of given_normals_row to run */
} normal_job;

/* A tangent's components scaled by one power of two where its largest lies
 * outside [2^-28, 2^28], to within [0.5, 1): a product of two such vectors'
 * components, squared, would overflow (a face normal's cross product of
 * two tangents of about 1e9 each, at depths from about 1e11) or underflow
 * (below about 1e-9). The scaling is exact unless a component is below
 * 2^-125 of the largest, so the cross product and its normalisation give
 * the direction that the unscaled tangents would without overflow; the
 * tangents of every ordinary scene lie inside the range and are left as
 * they are. */
#define HBAO_SCALE_FREE_REACH 0x1p28f
static void keep_in_range(float v[3]) {
    const float largest = fmaxf(fmaxf(fabsf(v[0]), fabsf(v[1])), fabsf(v[2]));
    if (!(largest > 0.0f) || !isfinite(largest)) return;
    if (largest <= HBAO_SCALE_FREE_REACH && largest >= 1.0f / HBAO_SCALE_FREE_REACH) return;
    int exponent;
    frexpf(largest, &exponent);
    for (int c = 0; c < 3; c++) v[c] = ldexpf(v[c], -exponent);
}

static void view_vector(const hbao_grid *grid, const float position[3], float v[3]) {
    if (grid->orthographic) {
        v[0] = 0.0f;
        v[1] = 0.0f;
        v[2] = 1.0f;
        return;
    }
    const float length =
        sqrtf(position[0] * position[0] + position[1] * position[1] + position[2] * position[2]);
    v[0] = -position[0] / length;
    v[1] = -position[1] / length;
    v[2] = -position[2] / length;
}

/* The neighbour difference along one axis whose depth changes least, so that
 * a depth discontinuity on one side does not bend the normal. Returns 0 when
 * neither neighbour is usable. */
static int pick_tangent(const hbao_grid *grid, int i, int j, int di, int dj, const float center[3],
                        float tangent[3]) {
    float best[3] = {0.0f, 0.0f, 0.0f};
    float best_change = INFINITY;
    for (int side = -1; side <= 1; side += 2) {
        const int ni = i + side * di, nj = j + side * dj;
        if (ni < 0 || nj < 0 || ni >= grid->width || nj >= grid->height) continue;
        const float z = grid->depth[(size_t)nj * grid->width + ni];
        if (z <= 0.0f) continue;
        float p[3];
        hbao_grid_position(grid, ni, nj, z, p);
        const float change = fabsf(p[2] - center[2]);
        if (change < best_change) {
            best_change = change;
            for (int c = 0; c < 3; c++) best[c] = side * (p[c] - center[c]);
        }
    }
    for (int c = 0; c < 3; c++) tangent[c] = best[c];
    return best_change < INFINITY;
}

/* Depths rounded to half floats (EEVEE) step in stairs: on a plane tilted
 * 30 degrees at 10 m, a 1-pixel difference is either 0 or one 8 mm step, so
 * the normal from neighbours is off by tens of degrees. There the tangent
 * along an axis is the least-squares line through the run of up to
 * HALF_DEPTH_FIT_REACH pixels on each side that continues the surface:
 * points of a plane along a row or column lie on one 3D line, so the fit
 * keeps the exact direction, while the rounding errors average out
 * (measured by the half-depth cases of test_planes.c). */
#define HALF_DEPTH_FIT_REACH 8

static int usable_depth(const hbao_grid *grid, int i, int j, float *z) {
    if (i < 0 || j < 0 || i >= grid->width || j >= grid->height) return 0;
    *z = grid->depth[(size_t)j * grid->width + i];
    return *z > 0.0f;
}

static int fit_tangent(const hbao_grid *grid, int i, int j, int di, int dj, const float center[3],
                       float tangent[3]) {
    const float z0 = -center[2];
    /* The surface's depth step per pixel: the smaller of the two first steps
     * (the other may cross a silhouette). A tap continues the run while its
     * step stays within twice that plus two rounding steps (staircase). */
    float first_step = INFINITY;
    for (int side = -1; side <= 1; side += 2) {
        float z;
        if (usable_depth(grid, i + side * di, j + side * dj, &z))
            first_step = fminf(first_step, fabsf(z - z0));
    }
    if (first_step == INFINITY) return 0;
    const float limit = 2.0f * first_step + 2.0f * grid->depth_precision * z0;
    /* Walk the run outwards on both sides, summing what the least-squares
     * slope needs: with offsets k and depths z(k), sum z, sum k z, sum k^2 z,
     * sum k and sum k^2. */
    float sum_z = z0, sum_kz = 0.0f, sum_kkz = 0.0f;
    int sum_k = 0, sum_kk = 0, count = 1;
    for (int sign = -1; sign <= 1; sign += 2) {
        float previous = z0, z;
        for (int k = sign; k * sign <= HALF_DEPTH_FIT_REACH; k += sign) {
            if (!usable_depth(grid, i + k * di, j + k * dj, &z) || !(fabsf(z - previous) <= limit))
                break;
            previous = z;
            sum_z += z;
            sum_kz += (float)k * z;
            sum_kkz += (float)(k * k) * z;
            sum_k += k;
            sum_kk += k * k;
            count++;
        }
    }
    if (count < 2) return 0;
    /* The line through P(k) has direction sum (k - mean) P(k). The view-plane
     * coordinates are linear in k (one step is (di x_step, dj y_step)); in
     * perspective P(k) = z(k) (x(k), y(k), -1), in orthographic views
     * P(k) = (x(k), y(k), -z(k)). */
    const float mean = (float)sum_k / (float)count;
    const float weighted_z = sum_kz - mean * sum_z;    /* sum (k - mean) z(k) */
    const float weighted_kz = sum_kkz - mean * sum_kz; /* sum (k - mean) k z(k) */
    const float step_x = (float)di * grid->x_step, step_y = (float)dj * grid->y_step;
    if (grid->orthographic) {
        const float weighted_k = (float)sum_kk - mean * (float)sum_k; /* sum (k - mean) k */
        tangent[0] = step_x * weighted_k;
        tangent[1] = step_y * weighted_k;
    } else {
        tangent[0] = hbao_grid_x(grid, i) * weighted_z + step_x * weighted_kz;
        tangent[1] = hbao_grid_y(grid, j) * weighted_z + step_y * weighted_kz;
    }
    tangent[2] = -weighted_z;
    return 1;
}

static int tangent_along(const hbao_grid *grid, int i, int j, int di, int dj, const float center[3],
                         float tangent[3]) {
    if (grid->depth_precision >= HBAO_HALF_DEPTH_PRECISION)
        return fit_tangent(grid, i, j, di, dj, center, tangent);
    return pick_tangent(grid, i, j, di, dj, center, tangent);
}

static int normalize3(float n[3]) {
    const float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(length > 0.0f) || !isfinite(length)) return 0;
    for (int c = 0; c < 3; c++) n[c] /= length;
    return 1;
}

static int reconstruct_normal(const hbao_grid *grid, int i, int j, const float center[3],
                              const float v[3], float n[3]) {
    float dx[3], dy[3];
    const int have_x = tangent_along(grid, i, j, 1, 0, center, dx);
    const int have_y = tangent_along(grid, i, j, 0, 1, center, dy);
    if (have_x) keep_in_range(dx);
    if (have_y) keep_in_range(dy);
    if (have_x && have_y) {
        n[0] = dx[1] * dy[2] - dx[2] * dy[1];
        n[1] = dx[2] * dy[0] - dx[0] * dy[2];
        n[2] = dx[0] * dy[1] - dx[1] * dy[0];
        return normalize3(n);
    }
    if (!have_x && !have_y) return 0;
    /* One axis only (an image or a strip one pixel wide or tall): the normal
     * is perpendicular to that tangent; of those, the one nearest V, the
     * guess that the unseen axis faces the camera. Every sample the march
     * can take lies along that same axis, on the tangent's line for a plane,
     * so it has elevation 0 whatever the unseen axis does. */
    const float *t = have_x ? dx : dy;
    const float t2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
    if (!(t2 > 0.0f) || !isfinite(t2)) return 0;
    const float along = (v[0] * t[0] + v[1] * t[1] + v[2] * t[2]) / t2;
    for (int c = 0; c < 3; c++) n[c] = v[c] - along * t[c];
    return normalize3(n);
}

/* The normal of a pixel without a usable given normal: the face normal
 * from depth (returns 1), or V where depth gives none (returns 0). */
static int face_normal(const hbao_grid *grid, int i, int j, float n[3]) {
    const float z = grid->depth[(size_t)j * grid->width + i];
    if (z <= 0.0f) {
        n[0] = 0.0f;
        n[1] = 0.0f;
        n[2] = 1.0f;
        return 0;
    }
    float p[3], v[3];
    hbao_grid_position(grid, i, j, z, p);
    view_vector(grid, p, v);
    if (!reconstruct_normal(grid, i, j, p, v, n)) {
        for (int c = 0; c < 3; c++) n[c] = v[c];
        return 0;
    }
    if (n[0] * v[0] + n[1] * v[1] + n[2] * v[2] < 0.0f) {
        for (int c = 0; c < 3; c++) n[c] = -n[c];
    }
    return 1;
}

/* ... into grid->normal */
static void fallback_normal(const normal_job *job, int i, int j) {
    hbao_grid *grid = job->grid;
    float n[3];
    face_normal(grid, i, j, n);
    for (int c = 0; c < 3; c++) hbao_grid_normal_row(grid, j, c)[i] = n[c];
}

/* A given normal u (unit, in grid->normal) that faces away from the viewer,
 * dot(u, V) < 0, turned to face it, one of two ways. A surface seen from
 * behind (a single-sided plane, whose pass holds its front's normal): -u.
 * A surface that faces the camera under a shading normal tilted past its
 * outline (smooth shading of a coarse mesh, a bump; Cycles from 4.x writes
 * these): u mirrored across the plane perpendicular to V, u - 2 dot(u, V)
 * V, which faces the viewer as much as u faced away and keeps its tilt;
 * turned round, such a normal pointed into the surface, which then hid
 * itself (AO 0.03 where Cycles gives 0.63). The face normal from depth
 * tells the cases apart: the candidate nearer to it; -u on a tie and where
 * depth gives no face normal. A normal more than 30 degrees
 * past edge-on (dot(u, V) < -1/2) is no tilted shading normal: -u. */
#define HBAO_MOST_TILT_PAST_EDGE_ON (-0.5f)
static void turn_to_viewer(const normal_job *job, int i, int j) {
    hbao_grid *grid = job->grid;
    float u[3], v[3], face[3];
    for (int c = 0; c < 3; c++) u[c] = hbao_grid_normal_row(grid, j, c)[i];
    if (grid->orthographic) {
        v[0] = 0.0f;
        v[1] = 0.0f;
        v[2] = 1.0f;
    } else {
        /* V at any depth: the direction (-x, -y, 1), which no depth overflows */
        const float x = ((float)i + grid->x_offset) * grid->x_step;
        const float y = hbao_grid_y(grid, j);
        const float length = sqrtf(x * x + y * y + 1.0f);
        v[0] = -x / length;
        v[1] = -y / length;
        v[2] = 1.0f / length;
    }
    const float u_dot_v = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    if (!(u_dot_v < 0.0f)) return; /* edge-on, to rounding: u as it is */
    if (u_dot_v < HBAO_MOST_TILT_PAST_EDGE_ON) {
        for (int c = 0; c < 3; c++) hbao_grid_normal_row(grid, j, c)[i] = -u[c];
        return;
    }
    if (!face_normal(grid, i, j, face)) { /* depth cannot tell: -u */
        for (int c = 0; c < 3; c++) hbao_grid_normal_row(grid, j, c)[i] = -u[c];
        return;
    }
    float mirror[3];
    for (int c = 0; c < 3; c++) mirror[c] = u[c] - 2.0f * u_dot_v * v[c];
    const float mirror_agrees = mirror[0] * face[0] + mirror[1] * face[1] + mirror[2] * face[2];
    const float turned_agrees = -(u[0] * face[0] + u[1] * face[1] + u[2] * face[2]);
    const int keep_tilt = mirror_agrees > turned_agrees;
    for (int c = 0; c < 3; c++) hbao_grid_normal_row(grid, j, c)[i] = keep_tilt ? mirror[c] : -u[c];
}

/* The given normals of CHUNK pixels at a time, in lanes (no FMA
 * contraction: internal_finish.h), so every compiled copy gives the same
 * normals: world to camera space, scaled to unit length by one reciprocal,
 * and turned towards the camera. A pixel whose given normal is unusable, or
 * that is background, is marked for fallback_normal. */
#define CHUNK 64

/* 2^-64 for a vector with a component past 2^62, whose squares could
 * overflow float; else 1 (NaN too: the length test refuses it). */
static HBAO_ALWAYS_INLINE float shrink_factor(float x, float y, float z) {
    const float ax = fabsf(x), ay = fabsf(y), az = fabsf(z);
    const float largest = ax > ay ? (ax > az ? ax : az) : (ay > az ? ay : az);
    return largest > 0x1p62f ? 0x1p-64f : 1.0f;
}

static HBAO_ALWAYS_INLINE void given_normals_row(const normal_job *job, int j) {
    hbao_grid *grid = job->grid;
    const hbao_channel *given = job->given;
    const float *m = job->camera->world_to_camera;
    const float y = hbao_grid_y(grid, j);
    const int orthographic = grid->orthographic;
    const float *source_row = given->data + (int64_t)(j * job->scale) * given->row_stride;
    const int64_t pixel_step = (int64_t)job->scale * given->pixel_stride;
    float *out[3];
    for (int c = 0; c < 3; c++) out[c] = hbao_grid_normal_row(grid, j, c);
    const float *depth_row = grid->depth + (size_t)j * grid->width;
    for (int i0 = 0; i0 < grid->width; i0 += CHUNK) {
        const int count = grid->width - i0 < CHUNK ? grid->width - i0 : CHUNK;
        float wx[CHUNK], wy[CHUNK], wz[CHUNK], z[CHUNK];
        float nx[CHUNK], ny[CHUNK], nz[CHUNK];
        int usable[CHUNK], away[CHUNK];
        if (count == CHUNK && pixel_step == 3) {
            /* x, y, z interleaved (a numpy array, an EXR read) at full
             * resolution: with the stride a constant, the compiler reads
             * whole vectors and shuffles them, not a float at a time */
            const float *w = source_row + (int64_t)i0 * 3;
            for (int k = 0; k < CHUNK; k++) {
                wx[k] = w[3 * k];
                wy[k] = w[3 * k + 1];
                wz[k] = w[3 * k + 2];
                z[k] = depth_row[i0 + k];
            }
        } else {
            for (int k = 0; k < count; k++) {
                const float *w = source_row + (int64_t)(i0 + k) * pixel_step;
                wx[k] = w[0];
                wy[k] = w[1];
                wz[k] = w[2];
                z[k] = depth_row[i0 + k];
            }
        }
        for (int k = 0; k < count; k++) {
            /* the camera-space normal, unit length. A finite normal of any
             * length: one whose squares would overflow (a component past
             * 2^62), or that the matrix makes so long, is scaled by 2^-64
             * first, exactly, which leaves its direction's floats as they
             * are (and its length above HBAO_MIN_NORMAL_LENGTH). */
            const float w_shrink = shrink_factor(wx[k], wy[k], wz[k]);
            const float w0 = wx[k] * w_shrink, w1 = wy[k] * w_shrink, w2 = wz[k] * w_shrink;
            /* its squared length, tested as the length's square root
             * would be (HBAO_MIN_NORMAL_LENGTH_SQUARED): one square root
             * fewer a pixel, the stages without the search 0.947 of the
             * time (docs/speed.md, session 59) */
            const float world_length2 = w0 * w0 + w1 * w1 + w2 * w2;
            const float t0 = m[0] * w0 + m[1] * w1 + m[2] * w2;
            const float t1 = m[4] * w0 + m[5] * w1 + m[6] * w2;
            const float t2 = m[8] * w0 + m[9] * w1 + m[10] * w2;
            const float n_shrink = shrink_factor(t0, t1, t2);
            const float n0 = t0 * n_shrink, n1 = t1 * n_shrink, n2 = t2 * n_shrink;
            const float length = sqrtf(n0 * n0 + n1 * n1 + n2 * n2);
            const float inverse = 1.0f / length;
            const float u0 = n0 * inverse, u1 = n1 * inverse, u2 = n2 * inverse;
            /* isfinite(x) as x <= FLT_MAX (on |x| where x may be
             * negative): NaN fails, and it vectorizes; the squared length
             * is finite exactly where the length is */
            usable[k] = z[k] > 0.0f && world_length2 <= 3.40282347e38f &&
                        world_length2 >= HBAO_MIN_NORMAL_LENGTH_SQUARED &&
                        fabsf(length) <= 3.40282347e38f && length > 0.0f;
            /* Turned towards the camera: dot(u, V) >= 0. V is +z
             * orthographic, and in perspective the position p = z (x, y,
             * -1) negated and scaled by 1 / |p| (view_vector): for the
             * usable pixels (z > 0) its sign is that of dot(u, (-x, -y,
             * 1)), which needs neither |p| nor the depth, so that no
             * depth in the float range overflows it. */
            const float x = ((float)(i0 + k) + grid->x_offset) * grid->x_step;
            const float facing = orthographic ? u2 : u2 - (u0 * x + u1 * y);
            away[k] = facing < 0.0f;
            nx[k] = u0;
            ny[k] = u1;
            nz[k] = u2;
        }
        /* a whole chunk in copies of a constant size, which compile to
         * vector moves; spelled out, since a loop over the three made GCC
         * merge them into one copy of `count` floats, `rep movs`, and the
         * stage 1.4x slower */
        if (count == CHUNK) {
            memcpy(out[0] + i0, nx, sizeof nx);
            memcpy(out[1] + i0, ny, sizeof ny);
            memcpy(out[2] + i0, nz, sizeof nz);
        } else {
            const size_t bytes = (size_t)count * sizeof(float);
            memcpy(out[0] + i0, nx, bytes);
            memcpy(out[1] + i0, ny, bytes);
            memcpy(out[2] + i0, nz, bytes);
        }
        int any_unusable = 0, any_away = 0;
        for (int k = 0; k < count; k++) {
            any_unusable |= !usable[k];
            any_away |= usable[k] & away[k];
        }
        if (any_unusable)
            for (int k = 0; k < count; k++)
                if (!usable[k]) fallback_normal(job, i0 + k, j);
        if (any_away)
            for (int k = 0; k < count; k++)
                if (usable[k] & away[k]) turn_to_viewer(job, i0 + k, j);
    }
}

static void given_normals_row_portable(const normal_job *job, int j) {
    given_normals_row(job, j);
}

#ifdef HBAO_FINISH_X86
HBAO_TARGET_AVX2 static void given_normals_row_avx2(const normal_job *job, int j) {
    given_normals_row(job, j);
}

HBAO_TARGET_AVX512 static void given_normals_row_avx512(const normal_job *job, int j) {
    given_normals_row(job, j);
}
#endif

static void normal_row(void *context, int j) {
    const normal_job *job = context;
    if (job->given != NULL) {
#ifdef HBAO_FINISH_X86
        if (job->implementation == HBAO_IMPLEMENTATION_AVX512) {
            given_normals_row_avx512(job, j);
            return;
        }
        if (job->implementation == HBAO_IMPLEMENTATION_AVX2) {
            given_normals_row_avx2(job, j);
            return;
        }
#endif
        given_normals_row_portable(job, j);
        return;
    }
    for (int i = 0; i < job->grid->width; i++) fallback_normal(job, i, j);
}

/* Whether a depth is exactly a half float: a normal one, in [2^-14, 65504]
 * with its 13 low mantissa bits zero, or a subnormal one, a multiple of
 * 2^-24 below 2^-14 (a surface crossing the camera plane reaches those). */
static int is_half_float(float z) {
    union {
        float f;
        uint32_t u;
    } bits;
    bits.f = z;
    if (z < 6.103515625e-5f) {
        const float scaled = z * 16777216.0f; /* exact: a power of two, result < 1024 */
        return scaled == (float)(int)scaled;
    }
    return z <= 65504.0f && (bits.u & 0x1FFFu) == 0;
}

typedef struct precision_job {
    const hbao_grid *grid;
    atomic_int not_half; /* set by any row that has a depth which is not a half float */
} precision_job;

static void precision_row(void *context, int j) {
    precision_job *job = context;
    /* One depth that is no half float decides: float depth (Cycles') is
     * told from its first row (detect_depth_precision reads it first), and
     * rows still to come stop at once. */
    if (atomic_load_explicit(&job->not_half, memory_order_relaxed)) return;
    const float *row = job->grid->depth + (size_t)j * job->grid->width;
    for (int i = 0; i < job->grid->width; i++) {
        if (!(row[i] <= 0.0f || is_half_float(row[i]))) { /* background is 0 */
            atomic_store_explicit(&job->not_half, 1, memory_order_relaxed);
            return;
        }
    }
}

/* The depth's format, told from its values: half floats (EEVEE's Depth pass)
 * if every depth is one, else floats. A float image whose every depth
 * happens to be a half float (a plane facing the camera at an integer
 * distance) gets the half tolerance, which then costs nothing as no sample
 * rises above its plane. */
static float detect_depth_precision(const hbao_settings *settings, const hbao_grid *grid) {
    precision_job job;
    job.grid = grid;
    atomic_init(&job.not_half, 0);
    /* The first row alone first: it decides almost every float image, and
     * then no thread is started for the others (the scan took 0.08-0.1 ms
     * of a 2-thread frame). */
    precision_row(&job, 0);
    /* the rows' threads have all finished when this returns */
    if (!atomic_load(&job.not_half))
        hbao_parallel_rows(settings->threads, grid->height, precision_row, &job);
    return atomic_load(&job.not_half) ? HBAO_FLOAT_DEPTH_PRECISION : HBAO_HALF_DEPTH_PRECISION;
}

/* world_to_camera's rotation rows made one length where a camera's uneven
 * scale made them unequal: the inverse of camera.matrix_world (R S) is
 * S^-1 R^T, whose rows are R^T's each over one axis's scale, and turned by
 * it the normals leaned towards the shorter axes (up to 0.25 of AO; a
 * review's find). Each such row is made unit length, which gives R^T; rows
 * of one length (a rotation, or one scaled evenly, which the normals'
 * normalisation undoes) are left as they are, to the bit. */
#define UNEVEN_ROWS 1e-5
static void even_rotation_rows(float m[16]) {
    double length[3];
    for (int r = 0; r < 3; r++)
        length[r] = sqrt((double)m[4 * r] * m[4 * r] + (double)m[4 * r + 1] * m[4 * r + 1] +
                         (double)m[4 * r + 2] * m[4 * r + 2]);
    const double shortest = fmin(length[0], fmin(length[1], length[2]));
    const double longest = fmax(length[0], fmax(length[1], length[2]));
    if (!(longest - shortest > UNEVEN_ROWS * longest)) return;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) m[4 * r + c] = (float)(m[4 * r + c] / length[r]);
}

void hbao_compute_normals(const hbao_settings *settings, const hbao_camera *camera, hbao_grid *grid,
                          const hbao_channel *normal, int scale) {
    grid->depth_precision = detect_depth_precision(settings, grid);
    hbao_camera turned = *camera;
    even_rotation_rows(turned.world_to_camera);
    normal_job job = {&turned, grid, normal, scale,
                      hbao_finish_implementation(settings->implementation)};
    hbao_parallel_rows(settings->threads, grid->height, normal_row, &job);
    float *padding = hbao_grid_normal_row(grid, grid->height, 0); /* past the last row */
    for (int k = 0; k < HBAO_NORMAL_PADDING; k++) padding[k] = 0.0f;
}
