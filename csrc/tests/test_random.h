/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The pseudo-random inputs of the tests and benchmarks: one linear
 * congruential generator (Numerical Recipes' constants), so that a seed
 * gives the same inputs on every machine and in every program. */
#ifndef HBAO_TEST_RANDOM_H
#define HBAO_TEST_RANDOM_H

#include <stdint.h>

/* The next state after *state, stored and returned: all 32 bits; the high
 * ones are the more random (state >> 8 for 24 bits). */
static inline uint32_t test_random(uint32_t *state) {
    *state = *state * 1664525u + 1013904223u;
    return *state;
}

#endif /* HBAO_TEST_RANDOM_H */
