/* SPDX-License-Identifier: GPL-2.0-or-later */
/* A pass of the blur over a row of centres, BLUR_LANES pixels at a time in
 * GCC vector types, and the band job that runs it: written once for every
 * instruction set, blur.c includes this header once per copy, after
 * defining BLUR_LANES (the lanes of a vector), BLUR_GROUPS (how many
 * vectors a step of the loop takes side by side), BLUR_SKIPS (1: the copy
 * skips work whose floats it knows: a row whose background taps weigh 0 by
 * themselves skips the test for them, blur.c's background_needs_check, and
 * a vector of centres that are all background skips its taps, its value
 * being 1 (background_only); 0: the copy does all of it, as the scalar
 * reference, which the tests hold the others to), BLUR_COLUMN_ROWS (the
 * rows of centres whose passes down the columns run at once, lanes_rows,
 * up to MAX_COLUMN_ROWS; 1: one at a time, lanes), BLUR_NAME(x) (the copy's
 * names), BLUR_TARGET (its instruction set's function attribute, or
 * nothing), and, where BLUR_SKIPS is 1, BLUR_ANY(mask) (whether any lane
 * of a VI compare's result is set) and, optionally, BLUR_MIN and BLUR_MAX (the
 * instruction set's minimum and maximum of two vectors of BLUR_LANES
 * floats: a < b ? a : b and a > b ? a : b, b where either is NaN). Every
 * operation is blur_pixel's (blur.c), lane by lane and never contracted
 * into an FMA (what the copy skips changes no float), so every copy gives
 * the same floats as the scalar reference. test_blur.c compares the copies
 * with each other (background_runs_blur_as_the_reference among them), and
 * each copy's blur_pixel with its vector loop
 * (blur_pixel_and_the_vector_loop_agree). */

#if BLUR_SKIPS && !defined(BLUR_ANY)
#error "a copy that skips (BLUR_SKIPS 1) needs BLUR_ANY"
#endif

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

/* A centre's state: its depth, depth factor and scaled normal, and its
 * sums (blur_pixel). */
typedef struct BLUR_NAME(centre) {
    VF zc, factor, cx, cy, cz, sum, weight_sum;
} BLUR_NAME(centre);

BLUR_TARGET static HBAO_ALWAYS_INLINE BLUR_NAME(centre)
    BLUR_NAME(centre_at)(const centre_row *c, float sharpness, int at) {
    const VF zero = {0.0f};
    BLUR_NAME(centre) s;
    s.zc = BLUR_NAME(load)(c->z + at);
    const VF scaled = BLUR_NAME(select)(s.zc > 0.0f, sharpness / s.zc, zero);
    s.factor = BLUR_NAME(select)(scaled < FLT_MAX, scaled, zero + FLT_MAX) * HBAO_BLUR_DEPTH_WEIGHT;
    s.cx = BLUR_NAME(load)(c->nx + at) * HBAO_BLUR_NORMAL_WEIGHT;
    s.cy = BLUR_NAME(load)(c->ny + at) * HBAO_BLUR_NORMAL_WEIGHT;
    s.cz = BLUR_NAME(load)(c->nz + at) * HBAO_BLUR_NORMAL_WEIGHT;
    s.sum = BLUR_NAME(load)(c->ao + at);
    s.weight_sum = zero + 1.0f;
    return s;
}

/* blur_pixel's tap of depth z, normal (nx, ny, nz) and AO ao */
BLUR_TARGET static HBAO_ALWAYS_INLINE void BLUR_NAME(add_tap)(BLUR_NAME(centre) * s, VF z, VF nx,
                                                              VF ny, VF nz, VF ao, float spatial,
                                                              int check) {
    const VF zero = {0.0f};
    const VF difference = (z - s->zc) * s->factor;
    const VF facing = nx * s->cx + ny * s->cy + nz * s->cz;
    const VF capped = BLUR_NAME(min)(facing, zero + HBAO_BLUR_NORMAL_WEIGHT);
    const VF base = (1.0f - HBAO_BLUR_NORMAL_WEIGHT + capped) - difference * difference;
    /* blur_pixel's "* valid": the product is finite, so times 1 is itself */
    const VF unchecked = spatial * BLUR_NAME(power)(base);
    const VF weight = check ? BLUR_NAME(zero_unless)(z > 0.0f, unchecked) : unchecked;
    s->sum += weight * ao;
    s->weight_sum += weight;
}

/* The centre's blurred value into target */
BLUR_TARGET static HBAO_ALWAYS_INLINE void BLUR_NAME(centre_done)(const BLUR_NAME(centre) * s,
                                                                  float *target) {
    const VF zero = {0.0f};
    const VF blurred = BLUR_NAME(select)(s->zc > 0.0f, s->sum / s->weight_sum, zero + 1.0f);
    memcpy(target, &blurred, sizeof blurred);
}

/* The lanes of the centres at z[0 .. BLUR_LANES - 1] that are not
 * background (above 0) */
BLUR_TARGET static HBAO_ALWAYS_INLINE VI BLUR_NAME(above)(const float *z) {
    return BLUR_NAME(load)(z) > 0.0f;
}

/* Whether centres whose lanes not on background are `above` (OR-ed over
 * their vectors) are all background, so that blur_pixel gives each of them
 * 1 whatever its taps; never where the copy skips nothing (BLUR_SKIPS). */
BLUR_TARGET static HBAO_ALWAYS_INLINE int BLUR_NAME(background_only)(VI above) {
#if BLUR_SKIPS
    return !BLUR_ANY(above);
#else
    (void)above;
    return 0;
#endif
}

/* 1 into target[0 .. count * BLUR_LANES - 1]. A skipped vector of
 * background centres is still written: along a row its values are the
 * column pass's taps, and a tap on background weighs +0, which would turn a
 * NaN left in the ring into a NaN sum (test_stages.c,
 * scratch_memory_is_written_before_it_is_read); down the columns
 * write_output puts 1 there anyway, and the write keeps every row whole. */
BLUR_TARGET static HBAO_ALWAYS_INLINE void BLUR_NAME(fill_ones)(float *target, int count) {
    const VF one = (VF){0.0f} + 1.0f;
    for (int g = 0; g < count; g++) memcpy(target + g * BLUR_LANES, &one, sizeof one);
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
 * result is the same for any count. Where all their centres are background
 * (background_only) they are 1, and their taps are not weighed. */
BLUR_TARGET static HBAO_ALWAYS_INLINE void BLUR_NAME(lanes)(const tap_set *taps,
                                                            const centre_row *c, float sharpness,
                                                            int i, float *target, int along_row,
                                                            int check, int groups) {
    VI above = {0};
    for (int g = 0; g < groups; g++) above |= BLUR_NAME(above)(c->z + i + g * BLUR_LANES);
    if (BLUR_NAME(background_only)(above)) {
        BLUR_NAME(fill_ones)(target + i, groups);
        return;
    }
    BLUR_NAME(centre) centre[BLUR_GROUPS];
    for (int g = 0; g < groups; g++)
        centre[g] = BLUR_NAME(centre_at)(c, sharpness, i + g * BLUR_LANES);
    for (int t = 0; t < taps->count; t++) {
        for (int g = 0; g < groups; g++) {
            const int at = i + g * BLUR_LANES + taps->depth_step[t];
            const int normal_at = along_row ? at : i + g * BLUR_LANES + taps->normal_step[t];
            BLUR_NAME(add_tap)
            (&centre[g], BLUR_NAME(load)(c->z + at), BLUR_NAME(load)(c->nx + normal_at),
             BLUR_NAME(load)(c->ny + normal_at), BLUR_NAME(load)(c->nz + normal_at),
             BLUR_NAME(load)(along_row ? c->ao + at : taps->ao[t] + i + g * BLUR_LANES),
             taps->spatial[t], check);
        }
    }
    for (int g = 0; g < groups; g++)
        BLUR_NAME(centre_done)(&centre[g], target + i + g * BLUR_LANES);
}

/* The column passes of taps->rows rows of centres at once (a single
 * vector of lanes each): taps->count rows of taps, each loaded once and
 * added to each centre it is a tap of, in the order of their rows, as each
 * row's own pass (lanes) adds them. c[0] is the first row's centres, the
 * others follow it; rows is a constant (BLUR_COLUMN_ROWS). Where every
 * row's centres are background (background_only) they are 1, and no tap is
 * weighed. */
BLUR_TARGET static HBAO_ALWAYS_INLINE void
BLUR_NAME(lanes_rows)(const column_taps *taps, const centre_row *c, float sharpness, int i,
                      float *const *targets, int check, int rows) {
    VI above = {0};
    for (int r = 0; r < rows; r++) above |= BLUR_NAME(above)(c[r].z + i);
    if (BLUR_NAME(background_only)(above)) {
        for (int r = 0; r < rows; r++) BLUR_NAME(fill_ones)(targets[r] + i, 1);
        return;
    }
    BLUR_NAME(centre) centre[MAX_COLUMN_ROWS];
    for (int r = 0; r < rows; r++) centre[r] = BLUR_NAME(centre_at)(&c[r], sharpness, i);
    for (int t = 0; t < taps->count; t++) {
        const int at = i + taps->depth_step[t], normal_at = i + taps->normal_step[t];
        const VF z = BLUR_NAME(load)(c->z + at), nx = BLUR_NAME(load)(c->nx + normal_at),
                 ny = BLUR_NAME(load)(c->ny + normal_at), nz = BLUR_NAME(load)(c->nz + normal_at),
                 ao = BLUR_NAME(load)(taps->ao[t] + i);
        for (int r = 0; r < rows; r++)
            if (taps->of[r][t])
                BLUR_NAME(add_tap)(&centre[r], z, nx, ny, nz, ao, taps->spatial[r][t], check);
    }
    for (int r = 0; r < rows; r++) BLUR_NAME(centre_done)(&centre[r], targets[r] + i);
}

/* The next row's depth, AO and normals under pixels i .. i + BLUR_GROUPS *
 * BLUR_LANES - 1, asked of memory while a row pass works on this row's: a
 * row pass is bound by streaming the grid's rows from memory, and the
 * processor's own prefetch starts each row late (session 46, bench_blur
 * on 1 thread: 0.82 of the time at blur 5, 0.95 at 15). */
BLUR_TARGET static HBAO_ALWAYS_INLINE void
BLUR_NAME(prefetch_next_row)(const tap_set *taps, const centre_row *c, int i) {
    const int next = taps->next_row;
    for (int g = 0; g < BLUR_GROUPS; g++) {
        const int at = i + g * BLUR_LANES;
        __builtin_prefetch(c->z + next + at);
        __builtin_prefetch(c->ao + next + at);
        __builtin_prefetch(c->nx + 3 * next + at);
        __builtin_prefetch(c->ny + 3 * next + at);
        __builtin_prefetch(c->nz + 3 * next + at);
    }
}

/* The vector loop of a pass over pixels i .. last - 1, as far as whole
 * vectors go: groups of vectors, then single ones. Returns the first pixel
 * left. along_row and check are constants (BLUR_NAME(lanes)). */
BLUR_TARGET static HBAO_ALWAYS_INLINE int BLUR_NAME(vectors)(const tap_set *taps,
                                                             const centre_row *c, float sharpness,
                                                             int i, int last, float *target,
                                                             int along_row, int check) {
    for (; i + BLUR_GROUPS * BLUR_LANES <= last; i += BLUR_GROUPS * BLUR_LANES) {
        if (along_row && taps->next_row) BLUR_NAME(prefetch_next_row)(taps, c, i);
        BLUR_NAME(lanes)(taps, c, sharpness, i, target, along_row, check, BLUR_GROUPS);
    }
    for (; i + BLUR_LANES <= last; i += BLUR_LANES)
        BLUR_NAME(lanes)(taps, c, sharpness, i, target, along_row, check, 1);
    return i;
}

/* Whether a pass over the centres of a row (depth z) must test its taps for
 * background (blur.c, before outside_self_masking); always where the copy
 * never skips the test. */
BLUR_TARGET static HBAO_ALWAYS_INLINE int
BLUR_NAME(background_needs_check)(const float *z, int width, float sharpness) {
    float low, high;
    if (!BLUR_SKIPS || !self_masking_bounds(sharpness, &low, &high)) return 1;
    VI outside = {0};
    int i = 0;
    for (; i + BLUR_LANES <= width; i += BLUR_LANES) {
        const VF depth = BLUR_NAME(load)(z + i);
        outside |= (depth != 0.0f) & ((depth < low) | (depth > high));
    }
    int any = 0;
    for (int l = 0; l < BLUR_LANES; l++) any |= outside[l] != 0;
    for (; i < width; i++) any |= outside_self_masking(z[i], low, high);
    return any;
}

/* Pixels [from, to) of a pass along the row (near its ends, where some
 * taps fall outside it) through the vector loop, on a copy of the row's
 * pixels from - radius on in which those outside the row are background
 * (depth and normal 0, AO -0). A tap there weighs +0 (the background
 * test, or where the copy leaves it out background_needs_check's proof),
 * and +0 * -0 = -0 added to any sum leaves it as it is, -0 included: the
 * floats are blur_pixel's, which leaves such taps out. to - from is at
 * most radius at the left end and below radius + BLUR_LANES at the right
 * (blur_pass), so the copy spans under 3 radius + 2 BLUR_LANES pixels. */
BLUR_TARGET static HBAO_ALWAYS_INLINE void BLUR_NAME(row_ends)(const tap_set *taps,
                                                               const centre_row *c, float sharpness,
                                                               int width, int radius, int from,
                                                               int to, float *target, int check) {
    enum { SPAN = 3 * MAX_BLUR_RADIUS + 2 * BLUR_LANES };
    float z[SPAN], nx[SPAN], ny[SPAN], nz[SPAN], ao[SPAN], out[SPAN];
    const int count = to - from;
    const int lanes = (count + BLUR_LANES - 1) / BLUR_LANES * BLUR_LANES;
    for (int x = 0; x < lanes + 2 * radius; x++) {
        const int p = from - radius + x;
        const int inside = p >= 0 && p < width;
        z[x] = inside ? c->z[p] : 0.0f;
        nx[x] = inside ? c->nx[p] : 0.0f;
        ny[x] = inside ? c->ny[p] : 0.0f;
        nz[x] = inside ? c->nz[p] : 0.0f;
        ao[x] = inside ? c->ao[p] : -0.0f;
    }
    const centre_row local = {z + radius, ao + radius, nx + radius, ny + radius, nz + radius};
    for (int i = 0; i < lanes; i += BLUR_LANES)
        BLUR_NAME(lanes)(taps, &local, sharpness, i, out, 1, check, 1);
    memcpy(target + from, out, (size_t)count * sizeof(float));
}

/* One pass over centres x0 .. x1 - 1 of a row into target: the vector
 * loop where every tap lies inside the row; near a row's ends row_ends; at
 * a column pass's end (under a vector) blur_pixel (blur.c). */
BLUR_TARGET static HBAO_ALWAYS_INLINE void
BLUR_NAME(blur_pass)(const tap_set *taps, const centre_row *c, float sharpness, int width,
                     int radius, int x0, int x1, float *target, int check) {
    if (taps->along_row) {
        int first = radius < width ? radius : width, last = width - radius;
        if (first < x0) first = x0;
        if (first > x1) first = x1;
        if (last > x1) last = x1;
        if (first > x0)
            BLUR_NAME(row_ends)(taps, c, sharpness, width, radius, x0, first, target, check);
        int i = first;
        if (first < last)
            i = check ? BLUR_NAME(vectors)(taps, c, sharpness, first, last, target, 1, 1)
                      : BLUR_NAME(vectors)(taps, c, sharpness, first, last, target, 1, 0);
        if (i < x1) BLUR_NAME(row_ends)(taps, c, sharpness, width, radius, i, x1, target, check);
        return;
    }
    int i = check ? BLUR_NAME(vectors)(taps, c, sharpness, x0, x1, target, 0, 1)
                  : BLUR_NAME(vectors)(taps, c, sharpness, x0, x1, target, 0, 0);
    for (; i < x1; i++) target[i] = blur_pixel(taps, c, sharpness, width, i);
}

/* The column passes of taps->rows rows (column_rows_pass), centres c[0]
 * .., into targets: lanes_rows over whole vectors, each row's blur_pixel
 * (single) for the rest. check: whether any of the rows needs the test
 * (background_needs_check); testing where one row needs it and another
 * not gives the same floats. */
BLUR_TARGET static HBAO_ALWAYS_INLINE void
BLUR_NAME(blur_rows)(const column_taps *taps, const tap_set *single, const centre_row *c, int check,
                     float sharpness, int width, int x0, int x1, float *const *targets, int rows) {
    int i = x0;
    if (check)
        for (; i + BLUR_LANES <= x1; i += BLUR_LANES)
            BLUR_NAME(lanes_rows)(taps, c, sharpness, i, targets, 1, rows);
    else
        for (; i + BLUR_LANES <= x1; i += BLUR_LANES)
            BLUR_NAME(lanes_rows)(taps, c, sharpness, i, targets, 0, rows);
    for (; i < x1; i++)
        for (int r = 0; r < rows; r++)
            targets[r][i] = blur_pixel(&single[r], &c[r], sharpness, width, i);
}

/* The copy's job for one strip of a band of output rows (part: the band
 * times the job's strips, plus the strip): each row's columns x0 .. x1 - 1
 * are made (blurred along the row into the ring) once a column pass needs
 * them, then the band's rows are blurred down those columns and written
 * out. A row pass reads the taps r columns either side of the strip from
 * the grid; the ring's other columns are never read. */
BLUR_TARGET static void BLUR_NAME(finish_band)(void *context, int part) {
    finish_job *job = context;
    const int width = job->width, radius = job->radius, height = job->height;
    const int band = part / job->strips, strip = part % job->strips;
    const int x0 = (int)((int64_t)strip * width / job->strips);
    const int x1 = (int)((int64_t)(strip + 1) * width / job->strips);
    const int slots = 2 * radius + BLUR_COLUMN_ROWS;
    const int first = band * job->band_rows;
    const int last = first + job->band_rows < height ? first + job->band_rows : height;
    band_memory m;
    const int set = band_memory_take(job, &m, slots);
    tap_set taps, single[BLUR_COLUMN_ROWS];
    int checks[2 * MAX_BLUR_RADIUS + MAX_COLUMN_ROWS]; /* of the ring's rows */
    column_taps rows_taps;
    centre_row c, centres[BLUR_COLUMN_ROWS];
    int next = first - radius > 0 ? first - radius : 0; /* the next row to make */
    /* BLUR_COLUMN_ROWS rows at a time down their columns while the band has
     * as many left, then one */
    for (int j = first; j < last;) {
        const int rows = radius > 0 && j + BLUR_COLUMN_ROWS <= last ? BLUR_COLUMN_ROWS : 1;
        const int needed = j + rows - 1 + radius < height ? j + rows - 1 + radius : height - 1;
        for (; next <= needed; next++) {
            float *slot = m.ring[next % slots];
            if (radius == 0) {
                memcpy(slot + x0, job->grid_ao + (size_t)next * width + x0,
                       (size_t)(x1 - x0) * sizeof(float));
                continue;
            }
            row_pass(job, next, &taps, &c);
            checks[next % slots] =
                BLUR_NAME(background_needs_check)(c.z + x0, x1 - x0, job->sharpness);
            BLUR_NAME(blur_pass)
            (&taps, &c, job->sharpness, width, radius, x0, x1, slot, checks[next % slots]);
        }
        if (radius == 0) {
            write_output(job->depth + (size_t)j * width + x0, m.ring[j % slots] + x0, x1 - x0,
                         job->strength, job->out + (int64_t)j * job->out_row_stride + x0);
            j++;
            continue;
        }
        if (rows == 1) {
            column_pass(job, &m, slots, j, &taps, &c);
            BLUR_NAME(blur_pass)
            (&taps, &c, job->sharpness, width, radius, x0, x1, m.finished[0], checks[j % slots]);
        } else {
            for (int r = 0; r < rows; r++)
                column_pass(job, &m, slots, j + r, &single[r], &centres[r]);
            column_rows_pass(job, &m, slots, j, rows, &rows_taps);
            int check = 0; /* any row's */
            for (int r = 0; r < rows; r++) check |= checks[(j + r) % slots];
            BLUR_NAME(blur_rows)
            (&rows_taps, single, centres, check, job->sharpness, width, x0, x1, m.finished,
             BLUR_COLUMN_ROWS);
        }
        for (int r = 0; r < rows; r++)
            write_output(job->depth + (size_t)(j + r) * width + x0, m.finished[r] + x0, x1 - x0,
                         job->strength, job->out + (int64_t)(j + r) * job->out_row_stride + x0);
        j += rows;
    }
    band_memory_give(job, set);
}

#undef VF
#undef VI
#undef BLUR_LANES
#undef BLUR_GROUPS
#undef BLUR_SKIPS
#undef BLUR_COLUMN_ROWS
#undef BLUR_NAME
#undef BLUR_TARGET
#undef BLUR_MIN
#undef BLUR_MAX
#undef BLUR_ANY
