/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The planes of the image's edge pixels, which the horizon search's steps
 * past the image's edges see continued (internal_hbao.h, hbao_beyond_depth;
 * docs/algorithm.md, "Beyond the frame"). */
#include <math.h>

#include "internal_hbao.h"

/* Edge pixel (i, j)'s plane into plane[0], plane[term], plane[2 term] and
 * plane[3 term]: its normal and dot(normal, position); NaN where the pixel
 * is background. */
static void edge_plane(const hbao_grid *grid, int i, int j, float *plane, size_t term) {
    const float z = grid->depth[(size_t)j * grid->width + i];
    if (!(z > 0.0f)) {
        for (int q = 0; q < 4; q++) plane[q * term] = NAN;
        return;
    }
    float p[3], n[3];
    hbao_grid_position(grid, i, j, z, p);
    hbao_grid_normal_at(grid, i, j, n);
    plane[0] = n[0];
    plane[term] = n[1];
    plane[2 * term] = n[2];
    plane[3 * term] = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
}

void hbao_beyond_planes(hbao_grid *grid) {
    const int width = grid->width, height = grid->height;
    const int band = (width > height ? width : height) / HBAO_BEYOND_BAND_DIVISOR;
    grid->beyond_columns = band < width - 1 ? band : width - 1;
    grid->beyond_rows = band < height - 1 ? band : height - 1;
    const size_t length = hbao_beyond_row_floats(width);
    const int pad = HBAO_BEYOND_PAD(width);
    for (int r = 0; r < 2; r++) {
        const int j = r == 0 ? 0 : height - 1;
        for (size_t x = 0; x < 4 * length; x++) {
            const int c = (int)x - pad;
            const int i = c < 0 ? 0 : c >= width ? width - 1 : c;
            edge_plane(grid, i, j, grid->beyond + ((size_t)r * 16 + (x & 3)) * length + (x >> 2),
                       4 * length);
        }
    }
    float *sides = grid->beyond + 32 * length;
    for (int s = 0; s < 2; s++)
        for (int j = 0; j < height; j++)
            edge_plane(grid, s == 0 ? 0 : width - 1, j, sides + ((size_t)s * height + j) * 4, 1);
}

/* out[x] for x in [from, to): what the depth holds at column 4 x + a of row
 * j, every such column outside the image: hbao_beyond_depth's within the
 * band past the edges (grid->beyond_columns, beyond_rows), 0 past it. The same operations
 * as hbao_beyond_depth, as loops over whole runs that the compiler
 * vectorizes (the SIMD kernels' deinterleaved depth carries the band:
 * horizon.c). */
void hbao_beyond_fill(const hbao_grid *grid, int j, int a, int from, int to, float *out) {
    const int width = grid->width, height = grid->height;
    const int band = grid->beyond_columns, rows = grid->beyond_rows;
    if (j < -rows || j >= height + rows) {
        for (int x = from; x < to; x++) out[x] = 0.0f;
        return;
    }
    /* the columns within the band: 4 x + a in [-band, width + band) */
    const int first = (-band - a + 3 + 4 * (band + 4)) / 4 - (band + 4); /* ceil, exact */
    const int last = (width + band - a + 3) / 4;                         /* exclusive */
    const int lo = from > first ? from : first, hi = to < last ? to : last;
    for (int x = from; x < (lo < to ? lo : to); x++) out[x] = 0.0f;
    for (int x = (hi > from ? hi : from); x < to; x++) out[x] = 0.0f;
    if (lo >= hi) return;
    const float y = hbao_grid_y(grid, j);
    if (j < 0 || j >= height) {
        /* above or below: the top or bottom row's planes, by column phase */
        const size_t length = hbao_beyond_row_floats(width);
        const int pad = HBAO_BEYOND_PAD(width) / 4; /* x + pad: the column's table index */
        const float *terms = grid->beyond + ((size_t)(j >= 0) * 16 + (size_t)a) * length + pad;
        const float *n0 = terms, *n1 = terms + 4 * length, *n2 = terms + 8 * length;
        const float *plane = terms + 12 * length;
        for (int x = lo; x < hi; x++)
            out[x] = hbao_plane_depth(grid, n0[x], n1[x], n2[x], plane[x],
                                      hbao_grid_x(grid, 4 * x + a), y);
        return;
    }
    /* beside the image: its left or right column's plane of row j */
    const float *sides = grid->beyond + 32 * hbao_beyond_row_floats(width);
    for (int side = 0; side < 2; side++) {
        const float *t = sides + ((size_t)side * height + (size_t)j) * 4;
        /* the side's columns: x < 0 at the left, 4 x + a >= width at the right */
        const int right = (width - a + 3) / 4;
        const int from_x = side == 0 ? lo : (right > lo ? right : lo);
        const int to_x = side == 0 ? (hi < 0 ? hi : 0) : hi;
        for (int x = from_x; x < to_x; x++)
            out[x] =
                hbao_plane_depth(grid, t[0], t[1], t[2], t[3], hbao_grid_x(grid, 4 * x + a), y);
    }
}
