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
    grid->beyond_band = (width > height ? width : height) / HBAO_BEYOND_BAND_DIVISOR;
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
