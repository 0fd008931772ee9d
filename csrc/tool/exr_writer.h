/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Writing a single-part scanline EXR through OpenEXRCore. */
#ifndef HBAO_TOOL_EXR_WRITER_H
#define HBAO_TOOL_EXR_WRITER_H

#include <openexr.h>
#include <stdint.h>

#include "pixel_rect.h"
#include "tool_error.h"

typedef struct exr_output_layout {
    pixel_rect data_window;
    pixel_rect display_window;
    float pixel_aspect_ratio;
    exr_attr_v2f_t screen_window_center;
    float screen_window_width;
    exr_compression_t compression;
    /** When not NULL, part 0's other header attributes (Blender's
     *  BlenderMultiChannel, Camera, Frame, render stats ...) are copied. */
    exr_const_context_t copy_attributes_from;
    /** When not NULL, a string attribute of this name and text (set before
     *  the copied ones, so an input's attribute of the same name is replaced). */
    const char *stamp_name;
    const char *stamp_text;
    /** Threads that encode (compress) the chunks, at most
     *  EXR_MAX_WRITE_THREADS; 0 or 1: the calling thread alone. The file does
     *  not depend on it. */
    int threads;
} exr_output_layout;

#define EXR_MAX_WRITE_THREADS 16

/** One channel to write: `data` holds pixels of type `type` (the type it is
 *  stored as in the file); strides in bytes. */
typedef struct exr_output_channel {
    const char *name;
    exr_pixel_type_t type;
    exr_perceptual_treatment_t perceptual; /**< a hint for lossy codecs; kept when copying */
    const uint8_t *data;                   /**< top-left pixel of the data window */
    int32_t pixel_stride;
    int64_t row_stride;
} exr_output_channel;

/**
 * Write the image to the open file descriptor `fd` (positioned anywhere: the
 * writer uses pwrite). `name` is only used in messages.
 */
int exr_write_image(int fd, const char *name, const exr_output_layout *layout,
                    const exr_output_channel *channels, int count, tool_error *error);

#endif /* HBAO_TOOL_EXR_WRITER_H */
