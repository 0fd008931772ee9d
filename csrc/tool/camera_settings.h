/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Camera settings gathered from several sources, each of which may set only
 * some fields: the EXR header (pixel aspect), a camera JSON file and the
 * command-line flags. Later sources override earlier ones field by field.
 */
#ifndef HBAO_TOOL_CAMERA_SETTINGS_H
#define HBAO_TOOL_CAMERA_SETTINGS_H

#include <stdbool.h>
#include <stdint.h>

#include "hbao.h"
#include "pixel_rect.h"

/** Bits of camera_settings.fields_set, one per hbao_camera field. */
enum {
    CAMERA_FIELD_PROJECTION = 1u << 0,
    CAMERA_FIELD_LENS = 1u << 1,
    CAMERA_FIELD_SENSOR_WIDTH = 1u << 2,
    CAMERA_FIELD_SENSOR_HEIGHT = 1u << 3,
    CAMERA_FIELD_SENSOR_FIT = 1u << 4,
    CAMERA_FIELD_SHIFT_X = 1u << 5,
    CAMERA_FIELD_SHIFT_Y = 1u << 6,
    CAMERA_FIELD_ORTHO_SCALE = 1u << 7,
    CAMERA_FIELD_PIXEL_ASPECT_X = 1u << 8,
    CAMERA_FIELD_PIXEL_ASPECT_Y = 1u << 9,
    CAMERA_FIELD_WORLD_TO_CAMERA = 1u << 10,
    CAMERA_FIELD_CLIP_END = 1u << 11,  /**< clip_end, not an hbao_camera field */
    CAMERA_FIELD_CLIP_START = 1u << 12 /**< clip_start, neither */
};

typedef struct camera_settings {
    hbao_camera camera; /**< only the fields named in fields_set are meaningful */
    float clip_end;     /**< Blender's camera clip_end (CAMERA_FIELD_CLIP_END) */
    float clip_start;   /**< and clip_start (CAMERA_FIELD_CLIP_START) */
    uint32_t fields_set;
} camera_settings;

/** hbao_clip_background_depth() (the one rule, in libhbao) of the clip
 *  range the settings know: `background_depth` without a clip end, the
 *  older rule with a clip end alone (a camera file written before
 *  clip_start was). */
float camera_background_depth(const camera_settings *settings, float background_depth);

/** No field set; the values are Blender's defaults. */
void camera_settings_init(camera_settings *settings);

/** Copy into `base` every field that `override` sets. */
void camera_settings_apply(camera_settings *base, const camera_settings *override);

/**
 * The camera for the data window `data` of the display window `display`
 * (Blender's cropped border render, or overscan: a data window reaching past
 * the display window, a guard band): hbao_camera_crop() with EXR's window
 * coordinates. Its result code: HBAO_ERROR_INVALID_RECTANGLE where a
 * window's size or offset does not fit hbao_camera_crop's int32 arguments.
 */
hbao_result camera_for_data_window(const hbao_camera *camera, const pixel_rect *display,
                                   const pixel_rect *data, hbao_camera *cropped);

/** True when the library takes `matrix` as a camera's world-to-camera
 *  matrix (hbao_camera_view with Blender's default camera otherwise): its
 *  rotation part must be invertible. */
bool matrix_is_usable(const float matrix[16]);

/** True when the 4x4 matrix is the identity. */
bool matrix_is_identity(const float matrix[16]);

#endif /* HBAO_TOOL_CAMERA_SETTINGS_H */
