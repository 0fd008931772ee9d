/* SPDX-License-Identifier: GPL-2.0-or-later */
/* A pixel rectangle as EXR files store their windows: the EXR reader fills
 * it, the tool's camera crop and EXR writer use it. */
#ifndef HBAO_EXR_PIXEL_RECT_H
#define HBAO_EXR_PIXEL_RECT_H

#include <stdint.h>

/** Image rectangle in pixels, y growing downwards (EXR convention). */
typedef struct pixel_rect {
    int32_t min_x, min_y, max_x, max_y; /* inclusive */
} pixel_rect;

#endif /* HBAO_EXR_PIXEL_RECT_H */
