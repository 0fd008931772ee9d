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

bool frame_list_parse(const char *text, frame_list *list) {
    memset(list, 0, sizeof *list);
    const char *cursor = text;
    for (;;) {
        const char *end = strchr(cursor, ',');
        size_t length = end ? (size_t)(end - cursor) : strlen(cursor);
        if (list->range_count == FRAME_RANGES_MAX) return false;
        frame_range *range = &list->ranges[list->range_count];
        const char *dash = memchr(cursor, '-', length);
        if (dash == NULL) {
            if (!parse_frame(cursor, length, &range->first)) return false;
            range->last = range->first;
        } else if (!parse_frame(cursor, (size_t)(dash - cursor), &range->first) ||
                   !parse_frame(dash + 1, length - (size_t)(dash - cursor) - 1, &range->last) ||
                   range->last < range->first) {
            return false;
        }
        /* A frame listed twice would be computed twice, at once. */
        for (int r = 0; r < list->range_count; ++r)
            if (range->first <= list->ranges[r].last && list->ranges[r].first <= range->last)
                return false;
        ++list->range_count;
        if (end == NULL) return true;
        cursor = end + 1;
    }
}

int64_t frame_list_count(const frame_list *list) {
    int64_t count = 0;
    for (int r = 0; r < list->range_count; ++r)
        count += (int64_t)list->ranges[r].last - list->ranges[r].first + 1;
    return count;
}

int32_t frame_list_at(const frame_list *list, int64_t index) {
    for (int r = 0; r < list->range_count; ++r) {
        const int64_t size = (int64_t)list->ranges[r].last - list->ranges[r].first + 1;
        if (index < size) return (int32_t)(list->ranges[r].first + index);
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
    for (int r = 0; r < list->range_count; ++r)
        if (list->ranges[r].first <= frame && frame <= list->ranges[r].last) return true;
    return false;
}
