/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Strict number parsing for flags: the whole text must be one finite number. */
#ifndef HBAO_TOOL_NUMBER_PARSING_H
#define HBAO_TOOL_NUMBER_PARSING_H

#include <stdbool.h>
#include <stdint.h>

/** A finite float (no NaN, no infinity, no overflow, nothing after it). */
bool parse_finite_float(const char *text, float *value);

/** A decimal integer in [INT32_MIN, INT32_MAX], nothing after it. */
bool parse_int32(const char *text, int32_t *value);

/**
 * Exactly `count` finite floats separated by commas and/or white space
 * (e.g. "1,0,0,0, 0,1,0,0 ..."). Returns false on garbage or a wrong count.
 */
bool parse_float_list(const char *text, float *values, int count);

#endif /* HBAO_TOOL_NUMBER_PARSING_H */
