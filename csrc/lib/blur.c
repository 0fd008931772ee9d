/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Everything after the horizon search, on the grid the horizons were
 * searched on: cross-bilateral blur weighted by depth and normal, applied
 * separably (rows, then columns; Bavoil & Sainz: the filter is not
 * separable, but the separable version is close and costs 2r+1 taps instead
 * of (2r+1)^2) -> [half-resolution upsample (upsample.c)] -> strength -> the
 * caller's output. At half resolution the blur runs on the half grid, a
 * quarter of the pixels, with half the taps (the same reach); the upsample,
 * guided by the full-resolution depth, then keeps edges sharp.
 *
 * The blur's stages are fused per band of rows: a thread walks down its
 * band, makes each row (blurred along the row) into a ring of the last
 * 2r + BLUR_COLUMN_ROWS rows, and as soon as the rows a column tap needs
 * are there, blurs down the column and writes the finished row. Where a
 * band's rows are too wide for a core's cache, it does so strip of columns
 * by strip (STRIP_BYTES_PER_PIXEL). The AVX-512 copy blurs several rows
 * down their columns at once (BLUR_COLUMN_ROWS), loading each row of taps
 * once for all of them: the loads, not the arithmetic, bound the column
 * pass (session 46, docs/speed.md). Each row of the grid is thus read from
 * memory once. A band recomputes the r rows above and below it that its
 * neighbours also make; every row's values depend only on the input, so the
 * result is the same for any number of threads and any band height. */
#include <float.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "internal_finish.h"
#ifdef HBAO_FINISH_X86
#include <immintrin.h>
#endif

#define MAX_BLUR_RADIUS ((HBAO_MAX_BLUR_SIZE - 1) / 2)

/* Bands per thread: enough that a thread that falls behind (background rows
 * are cheap, geometry is not) is evened out by the row queue (parallel.c);
 * few enough that the 2r rows a band recomputes stay a small share. A band
 * is at least MIN_BAND_ROWS high, so that on small images or many threads it
 * does not spend most of its time remaking its neighbours' rows. */
#define BANDS_PER_THREAD 4
#define MIN_BAND_ROWS 16

/* Strips: a pass down the columns reads the 2r + 1 rows of its taps, each
 * pixel's depth, normal and AO in the ring (20 bytes), and the next row's
 * pass reads them again; a wide image's rows at a large radius do not stay
 * in a core's second-level cache (1080p at blur 15: 563 KiB; a Zen 3 core
 * has 512), and were read from the third level each time. A band is then
 * blurred in strips of columns of equal width (to a column), each a job of
 * its own, as many as bring each strip's rows within STRIP_CACHE_SHARE of
 * the cache, or as keep each at least MIN_STRIP_COLUMNS wide (so that the
 * passes' set-up for each row stays a small share), whichever are fewer:
 * every pixel has the same taps, so the floats are the same (test_stages.c,
 * blur_strips_give_the_same_floats). On a Zen 3 (session 65;
 * scripts/bench_blur_ab.sh, 10 rounds, 1 thread): 1080p at blur 15 in two
 * strips 0.937 of the time (2 threads 0.939), at blur 33 in four 0.800; a
 * draft's budget of a half cut blur 9's rows (338 KiB) and 3840 x 2160's at
 * blur 5 (375 KiB) in two, which gained nothing (1.00, 1.00-1.05), so
 * strips start at three quarters. Whole frames (bench_ab_pairs.sh, 10
 * rounds): 8 x 6 + blur 15 0.973 on 1 thread and 0.959 on 2; the defaults
 * (not cut) 0.991 and 0.998. Where the cache's size is not known,
 * STRIP_BYTES_UNKNOWN (three quarters of a Zen 3's). Without a blur
 * (radius 0) a band's rows are only copied: one strip. */
#define STRIP_BYTES_PER_PIXEL 20
#define STRIP_CACHE_SHARE 0.75
#define STRIP_BYTES_UNKNOWN (384 * 1024)
#define MIN_STRIP_COLUMNS 256

int hbao_blur_strips(int width, int radius, double budget) {
    const int most = width / MIN_STRIP_COLUMNS;
    if (radius == 0 || most <= 1) return 1;
    const double strips = ceil((2.0 * radius + 1.0) * STRIP_BYTES_PER_PIXEL * width / budget);
    if (!(strips < (double)most)) return most; /* NaN and infinity too */
    return strips > 1.0 ? (int)strips : 1;
}

double hbao_blur_strip_budget(void) {
    const long cache = hbao_core_cache_bytes();
    return cache > 0 ? STRIP_CACHE_SHARE * (double)cache : STRIP_BYTES_UNKNOWN;
}

/* The blur over the grid, row bands (in strips) in parallel. */
typedef struct finish_job {
    const hbao_grid *grid; /* the horizon grid: its normals guide the blur */
    const float *grid_ao;  /* raw AO on the grid */
    const float *depth;    /* the grid's, 0 = background */
    int width, height;     /* the grid's */
    int radius;            /* taps on each side; 0 = no blur */
    int band_rows;
    int strips; /* each band's columns in this many strips (hbao_blur_strips) */
    float sharpness;
    float strength;
    float spatial[MAX_BLUR_RADIUS + 1]; /* Gaussian weight by tap distance */
    float *out;
    int64_t out_row_stride;
    /* The bands' working rows (band_memory), one set per band that can run
     * at once, taken before any band runs: a band cannot then fail for
     * memory after others wrote their rows into the output (which may be
     * the caller's depth, in place). A band takes a free set and gives it
     * back. */
    float *pool;
    size_t pool_set_floats;
    int pool_sets;
    atomic_flag pool_taken[HBAO_MAX_THREADS];
} finish_job;

/* A row's guide normals, a row of each component (hbao_grid_normal_row). */
typedef struct normal_row {
    const float *nx, *ny, *nz;
} normal_row;

static HBAO_ALWAYS_INLINE normal_row normals_of_row(const hbao_grid *grid, int j) {
    return (normal_row){hbao_grid_normal_row(grid, j, 0), hbao_grid_normal_row(grid, j, 1),
                        hbao_grid_normal_row(grid, j, 2)};
}

/* The taps of one pass for one row of centres, the centre itself left out
 * (it weighs 1), as steps from the centre's rows (centre_row): tap t of
 * pixel i reads the depth at c->z[i + depth_step[t]], the normal at
 * c->nx, ny, nz[i + normal_step[t]] and the AO at ao[t][i + k] along a row,
 * ao[t][i] down a column. Along a row every step is the tap's offset k
 * (the same rows, shifted) and ao[t] is the centre's row; down a column the
 * steps are k rows of depth and k rows of normals (which lie three
 * components apart) and ao[t] is row j + k of the ring. Taps outside the
 * image are left out. */
typedef struct tap_set {
    int count;
    int along_row; /* 1: steps shift along the row, so edge pixels lose taps */
    /* Along a row: floats from the row's depth and AO to the next row's
     * (its normals' lie three times as far), which the pass prefetches as
     * it goes; 0: no next row. */
    int next_row;
    int depth_step[2 * MAX_BLUR_RADIUS + 1], normal_step[2 * MAX_BLUR_RADIUS + 1];
    const float *ao[2 * MAX_BLUR_RADIUS + 1];
    float spatial[2 * MAX_BLUR_RADIUS + 1];
} tap_set;

/* The most rows of centres a copy blurs down their columns at once
 * (BLUR_COLUMN_ROWS, blur_lanes.h). */
#define MAX_COLUMN_ROWS 4

/* The taps of `rows` rows' passes down the columns, rows j .. j + rows - 1
 * (blur_rows, blur_lanes.h): the rows j - r .. j + rows - 1 + r inside the
 * image in order, each with its steps from row j's (as tap_set's), its AO
 * row in the ring, and for each centre row c whether it is one of c's taps
 * (of[c]) and its spatial weight for c. */
typedef struct column_taps {
    int count, rows;
    int depth_step[2 * MAX_BLUR_RADIUS + MAX_COLUMN_ROWS],
        normal_step[2 * MAX_BLUR_RADIUS + MAX_COLUMN_ROWS];
    const float *ao[2 * MAX_BLUR_RADIUS + MAX_COLUMN_ROWS];
    float spatial[MAX_COLUMN_ROWS][2 * MAX_BLUR_RADIUS + MAX_COLUMN_ROWS];
    unsigned char of[MAX_COLUMN_ROWS][2 * MAX_BLUR_RADIUS + MAX_COLUMN_ROWS];
} column_taps;

/* The centre row of a pass: its depth, AO and guide normals. */
typedef struct centre_row {
    const float *z, *ao, *nx, *ny, *nz;
} centre_row;

/* One pixel: the centre with weight 1, then the taps in order; the weight
 * of a tap is spatial * F, 0 on background, with F of the depth difference
 * (factor * (z - zc)) and the normals as internal_finish.h forms it and
 * factor = min(sharpness / zc, FLT_MAX): sharpness / zc overflows for tiny
 * depths (below ~1e-37, denormals), and an infinite factor would turn a
 * tap at the same depth into 0 * inf = NaN; capped, a tap whose scaled
 * difference overflows weighs 0. min(n.c, 1) also keeps what a normal
 * that is not unit (infinite where a denormal depth's view vector
 * overflowed) may do: at most the weight of a tap on the same plane. A 0/1
 * factor rather than a branch marks background; the weight is finite, so
 * the product is exact. The vector loop (blur_lanes.h) gives the same
 * floats lane by lane (its mask and its min and max instructions are
 * exactly these selects and this product; where it leaves the mask out,
 * background_needs_check says why that changes nothing, and it leaves
 * out the taps of whole vectors of background centres, background_only).
 * Background centres give 1. */
static HBAO_ALWAYS_INLINE float blur_pixel(const tap_set *taps, const centre_row *c,
                                           float sharpness, int width, int i) {
    const float zc = c->z[i];
    const float scaled = zc > 0.0f ? sharpness / zc : 0.0f;
    const float factor = (scaled < FLT_MAX ? scaled : FLT_MAX) * HBAO_BLUR_DEPTH_WEIGHT;
    const float cx = c->nx[i] * HBAO_BLUR_NORMAL_WEIGHT, cy = c->ny[i] * HBAO_BLUR_NORMAL_WEIGHT,
                cz = c->nz[i] * HBAO_BLUR_NORMAL_WEIGHT;
    float sum = c->ao[i], weight_sum = 1.0f;
    for (int t = 0; t < taps->count; t++) {
        const int at = i + taps->depth_step[t], normal_at = i + taps->normal_step[t];
        if (taps->along_row && (at < 0 || at >= width)) continue;
        const float z = c->z[at];
        const float difference = (z - zc) * factor;
        const float facing = c->nx[normal_at] * cx + c->ny[normal_at] * cy + c->nz[normal_at] * cz;
        const float capped = facing < HBAO_BLUR_NORMAL_WEIGHT ? facing : HBAO_BLUR_NORMAL_WEIGHT;
        const float base = (1.0f - HBAO_BLUR_NORMAL_WEIGHT + capped) - difference * difference;
        const float valid = (float)(z > 0.0f);
        const float weight = taps->spatial[t] * hbao_blur_power(base) * valid;
        sum += weight * taps->ao[t][taps->along_row ? at : i];
        weight_sum += weight;
    }
    return zc > 0.0f ? sum / weight_sum : 1.0f;
}

/* Whether a pass over the centres of a row (depth z) must test its taps for
 * background, as blur_pixel's `valid` does. Where the sharpness is at least
 * SELF_MASKING_SHARPNESS and every centre's depth lies within a factor 2^100
 * of the sharpness, a tap on background (depth 0; the grid's depths are 0
 * or positive and finite) weighs 0 by its depth difference alone, exactly:
 * with s the sharpness and zc the centre's depth, s / zc lies in
 * [2^-100, 2^100], so the factor f = (s / zc)(1 + e1) / 4 is a normal float
 * below FLT_MAX / 4 (not capped) with |e1| <= 2^-24, and the difference
 * d = (0 - zc) f = -(s / 4)(1 + e1)(1 + e2). Then d^2 >= (s / 4)^2 (1 -
 * 2^-24)^5 >= 1 for s >= 4 (1 + 2^-21), while the base's other term
 * (1 - NW) + min(n.c, NW) is at most 1 (NW = 0.5; NaN gives NW): the base
 * is <= 0, its power +0, and the weight spatial * +0 = +0, the same float
 * that the test gives. A centre on background gives 1 whatever its taps
 * weigh. Both bounds are needed: below the lower one the factor is capped
 * (d tends to 0), and above the upper one f is denormal, 0 where the host
 * flushes denormals to zero (as Blender's threads may): test_stages checks
 * both. bench_blur's 15-pixel blur took 0.96 of the time without the test
 * (docs/speed.md). Each row is scanned once, as it is made, by the copy's
 * vector loop (blur_lanes.h), and its answer kept for its pass down the
 * columns: a scan for every pass, one float at a time, had taken 7 % of
 * the 15-pixel blur (session 46). */
#define SELF_MASKING_SHARPNESS 4.001f

/* Whether depth z lies outside the factor 2^100 around the sharpness that
 * background_needs_check (blur_lanes.h) asks of every centre: low and high
 * are self_masking_bounds'. */
static HBAO_ALWAYS_INLINE int outside_self_masking(float z, float low, float high) {
    return z != 0.0f && (z < low || z > high);
}

/* The bounds of outside_self_masking: 0 where the sharpness is too low for
 * any row to go without the test. */
static HBAO_ALWAYS_INLINE int self_masking_bounds(float sharpness, float *low, float *high) {
    *low = sharpness * 0x1p-100f;
    *high = sharpness * 0x1p100f;
    return sharpness >= SELF_MASKING_SHARPNESS;
}

/* Scratch of one band: the finished rows (one for each row of centres
 * blurred at once) and the ring of rows blurred along themselves (the rows
 * r above the first centre to r below the last: 2 r + rows slots; a copy
 * that blurs one row at a time keeps 2 r + 1, which measured 0.98 of
 * 2 r + 2 with AVX2), width floats each. */
#define BAND_ROWS(radius) (2 * (radius) + 2 * MAX_COLUMN_ROWS)
typedef struct band_memory {
    float *block;
    float *finished[MAX_COLUMN_ROWS];
    float *ring[2 * MAX_BLUR_RADIUS + MAX_COLUMN_ROWS];
} band_memory;

/* A free set of the job's pool for one band, into *m; returns its index
 * for band_memory_give. At most pool_sets bands run at once, so one is free;
 * the loop only waits out another band's give. */
static int band_memory_take(finish_job *job, band_memory *m, int slots) {
    int set = 0;
    while (atomic_flag_test_and_set(&job->pool_taken[set])) set = (set + 1) % job->pool_sets;
    const size_t row = (size_t)job->width;
    m->block = job->pool + (size_t)set * job->pool_set_floats;
    /* for tests (hbao_scratch_fill): a part reusing a set finds it filled
     * again, so that reading a column another part wrote shows */
    if (hbao_scratch_fill >= 0)
        memset(m->block, hbao_scratch_fill, job->pool_set_floats * sizeof(float));
    for (int r = 0; r < MAX_COLUMN_ROWS; r++) m->finished[r] = m->block + (size_t)r * row;
    for (int s = 0; s < slots; s++) m->ring[s] = m->block + (MAX_COLUMN_ROWS + (size_t)s) * row;
    return set;
}

static void band_memory_give(finish_job *job, int set) {
    atomic_flag_clear(&job->pool_taken[set]);
}

/* The taps and centres of row j's pass along the row (radius > 0): row j's
 * raw AO, to be blurred into its ring slot. */
static HBAO_ALWAYS_INLINE void row_pass(const finish_job *job, int j, tap_set *taps,
                                        centre_row *c) {
    const int width = job->width, radius = job->radius;
    const float *raw = job->grid_ao + (size_t)j * width;
    const normal_row n = normals_of_row(job->grid, j);
    const float *z = job->depth + (size_t)j * width;
    taps->count = 0;
    taps->along_row = 1;
    taps->next_row = j + 1 < job->height ? width : 0;
    for (int k = -radius; k <= radius; k++) {
        if (k == 0) continue;
        taps->depth_step[taps->count] = k;
        taps->normal_step[taps->count] = k;
        taps->ao[taps->count] = raw;
        taps->spatial[taps->count] = job->spatial[k < 0 ? -k : k];
        taps->count++;
    }
    *c = (centre_row){z, raw, n.nx, n.ny, n.nz};
}

/* Ring row j + k (inside the image) as a tap down the columns of row j's
 * centres, whose normals are n: its steps from the centre in the depth and
 * in the normals, and its AO. The passes of one row and of several
 * (column_pass, column_rows_pass) take their taps' rows from here. */
static HBAO_ALWAYS_INLINE void column_tap(const finish_job *job, const band_memory *m, int slots,
                                          int j, int k, normal_row n, int *depth_step,
                                          int *normal_step, const float **ao) {
    *depth_step = k * job->width;
    *normal_step = (int)(normals_of_row(job->grid, j + k).nx - n.nx);
    *ao = m->ring[(j + k) % slots];
}

/* The taps and centres of row j's pass down the column (radius > 0): rows
 * j - r .. j + r of the ring. */
static HBAO_ALWAYS_INLINE void column_pass(const finish_job *job, const band_memory *m, int slots,
                                           int j, tap_set *taps, centre_row *c) {
    const int radius = job->radius;
    taps->count = 0;
    taps->along_row = 0;
    taps->next_row = 0;
    const normal_row n = normals_of_row(job->grid, j);
    for (int k = -radius; k <= radius; k++) {
        if (k == 0 || j + k < 0 || j + k >= job->height) continue;
        const int t = taps->count++;
        column_tap(job, m, slots, j, k, n, &taps->depth_step[t], &taps->normal_step[t],
                   &taps->ao[t]);
        taps->spatial[t] = job->spatial[k < 0 ? -k : k];
    }
    *c = (centre_row){job->depth + (size_t)j * job->width, m->ring[j % slots], n.nx, n.ny, n.nz};
}

/* The taps of rows j .. j + rows - 1's passes down the columns (radius >
 * 0, j + rows <= height): column_taps. */
static HBAO_ALWAYS_INLINE void column_rows_pass(const finish_job *job, const band_memory *m,
                                                int slots, int j, int rows, column_taps *taps) {
    const int radius = job->radius;
    const normal_row n = normals_of_row(job->grid, j);
    taps->count = 0;
    taps->rows = rows;
    for (int k = -radius; k <= radius + rows - 1; k++) {
        if (j + k < 0 || j + k >= job->height) continue;
        const int t = taps->count++;
        column_tap(job, m, slots, j, k, n, &taps->depth_step[t], &taps->normal_step[t],
                   &taps->ao[t]);
        for (int c = 0; c < rows; c++) {
            const int offset = k - c < 0 ? c - k : k - c; /* from centre row j + c */
            taps->of[c][t] = offset != 0 && offset <= radius;
            taps->spatial[c][t] = job->spatial[offset <= radius ? offset : 0];
        }
    }
}

/* A finished row of AO (1 on background, where zc <= 0) to the output:
 * strength, then the clamp to [0, 1]. ao may be out itself. */
static HBAO_ALWAYS_INLINE void write_output(const float *zc, const float *ao, int width,
                                            float strength, float *out) {
    if (strength != 1.0f) {
        for (int i = 0; i < width; i++) {
            out[i] = hbao_clamp_ao(powf(zc[i] > 0.0f ? ao[i] : 1.0f, strength));
        }
        return;
    }
    for (int i = 0; i < width; i++) {
        out[i] = hbao_clamp_ao(zc[i] > 0.0f ? ao[i] : 1.0f);
    }
}

/* The passes, BLUR_GROUPS vectors of BLUR_LANES pixels at a time, and the
 * band jobs that run them (blur_lanes.h), one copy per instruction set at
 * its registers' width: GCC splits a vector wider than the registers piece
 * by piece, partly through memory, and with 16 lanes the AVX2 copy of the
 * 15-pixel blur took 2.6 times as long as with 8. Two AVX2 vectors side by
 * side instead (BLUR_GROUPS 2, each in registers of its own) took 0.87 of
 * one's time (scripts/bench_blur_ab.sh), three no less than two. The
 * baseline copy (the scalar reference's and the generic kernel's, and
 * every CPU's but x86-64's) takes four vectors of the baseline's 4 lanes
 * (SSE2, Advanced SIMD) side by side: with 16 lanes in one vector (as
 * before session 54) GCC compared them a lane at a time, with a branch
 * each, on SSE2. bench_blur_ab.sh, 1080p, 1 thread, Intel Xeon, against
 * that: 0.342 at blur 15 (133 ms -> 46), 0.352 at blur 5; two groups
 * 1.017 of four, eight 0.984 (quartiles 0.965-1.020), and four with two
 * rows down the columns 1.028. The AVX-512 copy takes
 * two groups as well: on a Zen 5 (AMD EPYC, AVX-512, session 41),
 * bench_blur_ab.sh on 1 thread, blur 3 0.916, 5 0.998-1.055 (three runs),
 * 7 1.026, 9 0.954, 11 0.932, 15 0.900; three and four groups 0.937 and
 * 0.964 at 15 and 1.29 and 1.16 at 5. Down the columns the AVX-512 copy
 * blurs four rows of centres at once (BLUR_COLUMN_ROWS; each row of taps
 * is read from the second-level cache, and now once for four rows), which
 * its 32 registers hold: bench_blur_ab.sh on 1 thread (session 46), two
 * rows against one 0.940 at blur 15 and 0.985 at 5; three against two
 * 0.974 and 0.948; four against three 0.981 and 0.986; six against four
 * 1.013 and 1.044. AVX2's two rows (16 registers) took 1.034 of one. The
 * x86 copies take their minimum and maximum from the instruction set
 * (BLUR_MIN, BLUR_MAX: a < b ? a : b and a > b ? a : b, NaN giving b, as
 * the scalar code's selects), one instruction where GCC's vector selects
 * take two. They also skip work that changes no float (BLUR_SKIPS): the
 * background test where background_needs_check proves it, and the taps of
 * vectors of background centres (a sky). The latter, AVX-512 on an Intel
 * Xeon (session 47), bench_blur_ab.sh on 1 thread against the library
 * before it (built with this bench_blur.c), the upper half background
 * (bench_blur --background 50): 0.59-0.61 at blur 15, 0.69 at 5; without
 * background 0.996 (20 rounds) and 1.012; AVX2 not measured. Down the
 * columns the four rows' taps are skipped only where all four are
 * background; skipping each row's by itself was not tried. The two skips
 * share the macro, so they are not compared apart. */
#define BLUR_LANES 4
#define BLUR_GROUPS 4
#define BLUR_SKIPS 0
#define BLUR_COLUMN_ROWS 1
#define BLUR_NAME(name) name##_portable
#define BLUR_TARGET
#include "blur_lanes.h"

#ifdef HBAO_FINISH_X86
#define BLUR_LANES 8
#define BLUR_GROUPS 2
#define BLUR_SKIPS 1
#define BLUR_COLUMN_ROWS 1
#define BLUR_MIN _mm256_min_ps
#define BLUR_MAX _mm256_max_ps
#define BLUR_ANY(mask) (_mm256_movemask_ps((__m256)(mask)) != 0)
#define BLUR_NAME(name) name##_avx2
#define BLUR_TARGET HBAO_TARGET_AVX2
#include "blur_lanes.h"

#define BLUR_LANES 16
#define BLUR_GROUPS 2
#define BLUR_SKIPS 1
#define BLUR_COLUMN_ROWS 4
#define BLUR_MIN _mm512_min_ps
#define BLUR_MAX _mm512_max_ps
#define BLUR_ANY(mask) (_mm512_test_epi32_mask((__m512i)(mask), (__m512i)(mask)) != 0)
#define BLUR_NAME(name) name##_avx512
#define BLUR_TARGET HBAO_TARGET_AVX512
#include "blur_lanes.h"
#endif

/* The blur of grid_ao over the grid, with `strength`, into out. */
static hbao_result blur_grid(const hbao_settings *settings, const hbao_grid *grid,
                             const float *grid_ao, float strength, float *out,
                             int64_t out_row_stride) {
    finish_job job;
    job.grid = grid;
    job.grid_ao = grid_ao;
    job.depth = grid->depth;
    job.width = grid->width;
    job.height = grid->height;
    job.radius = settings->grid_blur_radius;
    job.sharpness = settings->blur_sharpness;
    job.strength = strength;
    job.out = out;
    job.out_row_stride = out_row_stride;
    const float sigma = 0.5f * (float)(job.radius + 1);
    for (int k = 0; k <= job.radius; k++)
        job.spatial[k] = expf(-(float)(k * k) / (2.0f * sigma * sigma));

    const int height = job.height;
    const int bands_wanted = BANDS_PER_THREAD * settings->threads;
    int band_rows = (height + bands_wanted - 1) / bands_wanted;
    if (band_rows < MIN_BAND_ROWS) band_rows = MIN_BAND_ROWS;
    job.band_rows = band_rows;
    const int bands = (height + band_rows - 1) / band_rows;
    job.strips = settings->blur_strips > 0
                     ? settings->blur_strips
                     : hbao_blur_strips(job.width, job.radius, hbao_blur_strip_budget());
    if (job.strips > job.width) job.strips = job.width;
    const int parts = bands * job.strips;
    /* one part a grab, on no more threads than sets */
    job.pool_sets = hbao_parallel_each_threads(settings->threads, parts);
    if (job.pool_sets < 1) job.pool_sets = 1;
    job.pool_set_floats = (size_t)BAND_ROWS(job.radius) * (size_t)job.width;
    job.pool = hbao_scratch_take((size_t)job.pool_sets * job.pool_set_floats * sizeof(float));
    if (job.pool == NULL) return HBAO_ERROR_OUT_OF_MEMORY;
    for (int set = 0; set < job.pool_sets; set++) atomic_flag_clear(&job.pool_taken[set]);

    hbao_row_job run = finish_band_portable;
#ifdef HBAO_FINISH_X86
    const int implementation = hbao_finish_implementation(settings->implementation);
    if (implementation == HBAO_IMPLEMENTATION_AVX512) run = finish_band_avx512;
    if (implementation == HBAO_IMPLEMENTATION_AVX2) run = finish_band_avx2;
#endif
    hbao_parallel_each(job.pool_sets, parts, run, &job); /* no more threads than sets */
    hbao_scratch_give(job.pool);
    return HBAO_SUCCESS;
}

/* The upsample of the (blurred) half-grid AO into the output, row by row. */
typedef struct upsample_job {
    const hbao_grid *grid;
    const float *grid_ao;
    const hbao_channel *depth; /* the caller's, full resolution */
    float background;
    int width;
    int implementation;
    float strength;
    float *out;
    int64_t out_row_stride;
} upsample_job;

static void upsample_output_row(void *context, int j) {
    const upsample_job *job = context;
    float *out = job->out + (int64_t)j * job->out_row_stride;
    hbao_upsample_row(job->implementation, job->grid, job->grid_ao, job->depth, job->background,
                      job->width, j, out);
    /* already clamped, and 1 on background (which any strength keeps 1):
     * only a strength is left to apply */
    if (job->strength != 1.0f)
        for (int i = 0; i < job->width; i++) out[i] = hbao_clamp_ao(powf(out[i], job->strength));
}

hbao_result hbao_finish(const hbao_settings *settings, const hbao_grid *grid, const float *grid_ao,
                        const hbao_channel *depth, int width, int height, float *out,
                        int64_t out_row_stride) {
    if (!settings->half_resolution)
        return blur_grid(settings, grid, grid_ao, settings->strength, out, out_row_stride);
    const float *upsampled_from = grid_ao;
    float *blurred = NULL;
    if (settings->grid_blur_radius > 0) {
        blurred = hbao_scratch_take((size_t)grid->width * grid->height * sizeof(float));
        if (blurred == NULL) return HBAO_ERROR_OUT_OF_MEMORY;
        const hbao_result result = blur_grid(settings, grid, grid_ao, 1.0f, blurred, grid->width);
        if (result != HBAO_SUCCESS) {
            hbao_scratch_give(blurred);
            return result;
        }
        upsampled_from = blurred;
    }
    upsample_job job = {grid,
                        upsampled_from,
                        depth,
                        settings->background_depth,
                        width,
                        hbao_finish_implementation(settings->implementation),
                        settings->strength,
                        out,
                        out_row_stride};
    hbao_parallel_rows(settings->threads, height, upsample_output_row, &job);
    hbao_scratch_give(blurred);
    return HBAO_SUCCESS;
}
