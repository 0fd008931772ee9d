/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "frame_pattern.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "number_parsing.h"

static bool parse_frame(const char *text, size_t length, int32_t *frame) {
    char copy[16];
    if (length == 0 || length >= sizeof copy) return false;
    memcpy(copy, text, length);
    copy[length] = '\0';
    /* Digits only: no sign, no spaces (parse_int32 would take "+5"). */
    for (size_t i = 0; i < length; ++i)
        if (copy[i] < '0' || copy[i] > '9') return false;
    return parse_int32(copy, frame) && *frame <= FRAME_MAX;
}

/* x with (a x) mod m = 1, for a and m coprime, m >= 1 (extended Euclid). */
static int64_t inverse_modulo(int64_t a, int64_t m) {
    int64_t old_r = a % m, r = m, old_s = 1, s = 0;
    while (r != 0) {
        const int64_t q = old_r / r, next_r = old_r - q * r, next_s = old_s - q * s;
        old_r = r;
        r = next_r;
        old_s = s;
        s = next_s;
    }
    return ((old_s % m) + m) % m;
}

static int64_t greatest_common_divisor(int64_t a, int64_t b) {
    while (b != 0) {
        const int64_t next = a % b;
        a = b;
        b = next;
    }
    return a;
}

/* Whether ranges a and b have a frame in common: a frame first_a + i step_a
 * = first_b + j step_b in both spans (the congruences solved, not the
 * frames walked: ranges hold up to FRAME_MAX + 1 frames, and 64 of them). */
static bool ranges_share_a_frame(const frame_range *a, const frame_range *b) {
    const int64_t low = a->first > b->first ? a->first : b->first;
    const int64_t high = a->last < b->last ? a->last : b->last;
    if (low > high) return false;
    const int64_t divisor = greatest_common_divisor(a->step, b->step);
    const int64_t difference = (int64_t)b->first - a->first;
    if (difference % divisor != 0) return false;
    /* a->first + a->step t = b->first (mod b->step) */
    const int64_t modulus = b->step / divisor;
    const int64_t t = ((difference / divisor) % modulus + modulus) % modulus *
                      inverse_modulo(a->step / divisor, modulus) % modulus;
    const int64_t period = a->step / divisor * b->step; /* <= FRAME_MAX^2 */
    int64_t frame = a->first + a->step * t;             /* a common frame, maybe below low */
    if (frame < low) frame += (low - frame + period - 1) / period * period;
    return frame <= high;
}

/* One range of a list: "7", "1-250" or "1-250x2". */
static bool parse_range(const char *text, size_t length, frame_range *range) {
    range->step = 1;
    const char *times = memchr(text, 'x', length);
    if (times != NULL) {
        int32_t step = 0;
        if (!parse_frame(times + 1, length - (size_t)(times - text) - 1, &step) || step < 1)
            return false;
        range->step = step;
        length = (size_t)(times - text);
    }
    const char *dash = memchr(text, '-', length);
    if (dash == NULL) {
        if (times != NULL || !parse_frame(text, length, &range->first)) return false;
        range->last = range->first;
        return true;
    }
    if (!parse_frame(text, (size_t)(dash - text), &range->first) ||
        !parse_frame(dash + 1, length - (size_t)(dash - text) - 1, &range->last) ||
        range->last < range->first)
        return false;
    range->last -= (range->last - range->first) % range->step; /* its last frame */
    return true;
}

bool frame_list_parse(const char *text, frame_list *list) {
    memset(list, 0, sizeof *list);
    const char *cursor = text;
    for (;;) {
        const char *end = strchr(cursor, ',');
        size_t length = end ? (size_t)(end - cursor) : strlen(cursor);
        if (list->range_count == FRAME_RANGES_MAX) return false;
        frame_range *range = &list->ranges[list->range_count];
        if (!parse_range(cursor, length, range)) return false;
        /* A frame listed twice would be computed twice, at once. */
        for (int r = 0; r < list->range_count; ++r)
            if (ranges_share_a_frame(range, &list->ranges[r])) return false;
        ++list->range_count;
        if (end == NULL) return true;
        cursor = end + 1;
    }
}

int64_t frame_list_count(const frame_list *list) {
    int64_t count = 0;
    for (int r = 0; r < list->range_count; ++r)
        count += ((int64_t)list->ranges[r].last - list->ranges[r].first) / list->ranges[r].step + 1;
    return count;
}

int32_t frame_list_at(const frame_list *list, int64_t index) {
    for (int r = 0; r < list->range_count; ++r) {
        const frame_range *range = &list->ranges[r];
        const int64_t size = ((int64_t)range->last - range->first) / range->step + 1;
        if (index < size) return (int32_t)(range->first + index * range->step);
        index -= size;
    }
    return -1;
}

bool frame_pattern_has_frame(const char *pattern) {
    return strchr(pattern, '#') != NULL;
}

bool frame_pattern_has_frame_in_name(const char *pattern) {
    const char *slash = strrchr(pattern, '/');
    return strchr(slash != NULL ? slash + 1 : pattern, '#') != NULL;
}

bool frame_pattern_path(const char *pattern, int32_t frame, char *path, size_t size) {
    const char *run_end = strrchr(pattern, '#');
    if (run_end == NULL) {
        int written = snprintf(path, size, "%s", pattern);
        return written >= 0 && (size_t)written < size;
    }
    const char *run_start = run_end;
    while (run_start > pattern && run_start[-1] == '#') --run_start;
    int written = snprintf(path, size, "%.*s%0*d%s", (int)(run_start - pattern), pattern,
                           (int)(run_end - run_start + 1), (int)frame, run_end + 1);
    return written >= 0 && (size_t)written < size;
}

bool frame_pattern_frame(const char *pattern, const char *path, int32_t *frame) {
    const char *run_end = strrchr(pattern, '#');
    if (run_end == NULL) return false;
    const char *run_start = run_end;
    while (run_start > pattern && run_start[-1] == '#') --run_start;
    const size_t prefix = (size_t)(run_start - pattern), run = (size_t)(run_end - run_start + 1);
    const size_t suffix = strlen(run_end + 1), length = strlen(path);
    if (length < prefix + run + suffix || strncmp(path, pattern, prefix) != 0 ||
        strcmp(path + length - suffix, run_end + 1) != 0)
        return false;
    const char *digits = path + prefix;
    const size_t count = length - suffix - prefix;
    /* frame_pattern_path pads to the run only: a longer number has no
     * leading zero */
    if (count > run && digits[0] == '0') return false;
    return parse_frame(digits, count, frame);
}

bool frame_list_contains(const frame_list *list, int32_t frame) {
    for (int r = 0; r < list->range_count; ++r) {
        const frame_range *range = &list->ranges[r];
        if (range->first <= frame && frame <= range->last &&
            (frame - range->first) % range->step == 0)
            return true;
    }
    return false;
}
