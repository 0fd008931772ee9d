/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Where a test picture of at least 150 x 90 pixels is background, for the
 * blur's skip of vectors of background centres (blur_lanes.h:
 * background_only): a solid block (24 rows of 96 pixels, whole vectors of
 * 16 and 32 lanes at full and half resolution, and groups of four rows all
 * background) and runs of 40 pixels along the rows, moved every 3 rows and
 * shifted every 4 (vectors all background, all geometry and mixed, and
 * groups of rows that differ in them). */
#ifndef HBAO_TEST_BACKGROUND_RUNS_H
#define HBAO_TEST_BACKGROUND_RUNS_H

static inline int background_runs_at(int i, int j) {
    return (j >= 40 && j < 64 && i >= 24 && i < 120) || ((i + 7 * (j / 4)) / 40 + j / 3) % 3 == 0;
}

#endif
