/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * The --preview image: the AO as an 8-bit grayscale PNG. The linear AO value
 * in [0, 1] maps straight to 0..255 (round to nearest); no sRGB or other
 * gamma curve is applied, so the file is a faithful view of the data rather
 * than a display-referred picture.
 */
#ifndef HBAO_TOOL_PNG_WRITER_H
#define HBAO_TOOL_PNG_WRITER_H

#include <stdint.h>

#include "tool_error.h"

/** Write `width` x `height` floats (top row first, rows `row_stride` floats
 *  apart) to the open descriptor `fd`; `name` is used in messages. */
int png_write_gray(int fd, const char *name, const float *pixels, int32_t width, int32_t height,
                   int64_t row_stride, tool_error *error);

#endif /* HBAO_TOOL_PNG_WRITER_H */
