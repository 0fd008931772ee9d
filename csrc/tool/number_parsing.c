/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "number_parsing.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>

/* Parses one float at *cursor, advancing it past the number. */
static bool parse_float_at(const char **cursor, float *value) {
    const char *start = *cursor;
    if (*start == '\0' || isspace((unsigned char)*start)) return false;
    char *end = NULL;
    errno = 0;
    double parsed = strtod(start, &end);
    if (end == start || errno == ERANGE || !isfinite(parsed) || fabs(parsed) > FLT_MAX)
        return false;
    *value = (float)parsed;
    *cursor = end;
    return true;
}

bool parse_finite_float(const char *text, float *value) {
    const char *cursor = text;
    return parse_float_at(&cursor, value) && *cursor == '\0';
}

bool parse_int32(const char *text, int32_t *value) {
    if (*text == '\0' || isspace((unsigned char)*text)) return false;
    char *end = NULL;
    errno = 0;
    long long parsed = strtoll(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || parsed < INT32_MIN || parsed > INT32_MAX)
        return false;
    *value = (int32_t)parsed;
    return true;
}

static const char *skip_separators(const char *cursor) {
    while (*cursor == ',' || isspace((unsigned char)*cursor)) ++cursor;
    return cursor;
}

bool parse_float_list(const char *text, float *values, int count) {
    const char *cursor = skip_separators(text);
    for (int i = 0; i < count; ++i) {
        if (!parse_float_at(&cursor, &values[i])) return false;
        /* Numbers must be separated: "1 2" and "1,2" are fine, "1-2" is not. */
        if (*cursor != '\0' && *cursor != ',' && !isspace((unsigned char)*cursor)) return false;
        cursor = skip_separators(cursor);
    }
    return *cursor == '\0';
}
