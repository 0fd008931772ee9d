/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Image sequences as Blender names them: a run of '#' in a path stands for
 * the frame number, zero-padded to the run's length (render_####.exr ->
 * render_0012.exr); a longer number is written in full. The last run in the
 * path is the one replaced, as in Blender's output paths.
 */
#ifndef HBAO_TOOL_FRAME_PATTERN_H
#define HBAO_TOOL_FRAME_PATTERN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/** Blender's largest frame number (MAXFRAME); frames are in [0, FRAME_MAX]. */
#define FRAME_MAX 1048574
/** How many comma-separated ranges --frames takes. */
#define FRAME_RANGES_MAX 64

typedef struct frame_range {
    int32_t first, last; /* inclusive, first <= last; last is a frame of the range */
    int32_t step;        /* >= 1: every step-th frame from first ("1-250x2") */
} frame_range;

typedef struct frame_list {
    frame_range ranges[FRAME_RANGES_MAX];
    int range_count;
} frame_list;

/** Parse "1-250", "7", "1-10,20-30", "1-250x2" (every second frame, as a
 *  render with Blender's Frame Step 2 writes them): true on success; no
 *  frame may be in two ranges. */
bool frame_list_parse(const char *text, frame_list *list);

/** The number of frames in the list. */
int64_t frame_list_count(const frame_list *list);

/** The index-th frame, in the order given. */
int32_t frame_list_at(const frame_list *list, int64_t index);

/** True when `pattern` holds a '#'. */
bool frame_pattern_has_frame(const char *pattern);

/** True when the file name of `pattern` (after its last '/') holds a '#'. */
bool frame_pattern_has_frame_in_name(const char *pattern);

/** `pattern` with its last '#' run replaced by `frame`; false when the
 *  result does not fit in `size` bytes. */
bool frame_pattern_path(const char *pattern, int32_t frame, char *path, size_t size);

/** The frame whose frame_pattern_path() is `path`, in *frame: true when
 *  there is one (the path's number written as frame_pattern_path writes
 *  it: no shorter than the run, without leading zeros beyond it). */
bool frame_pattern_frame(const char *pattern, const char *path, int32_t *frame);

/** Whether `frame` is in the list. */
bool frame_list_contains(const frame_list *list, int32_t frame);

#endif /* HBAO_TOOL_FRAME_PATTERN_H */
