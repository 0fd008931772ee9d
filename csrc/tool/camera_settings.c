/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "camera_settings.h"

#include <string.h>

void camera_settings_init(camera_settings *settings) {
    hbao_camera defaults = HBAO_CAMERA_DEFAULT_INITIALIZER;
    settings->camera = defaults;
    settings->clip_end = 0.0f;
    settings->clip_start = 0.0f;
    settings->fields_set = 0;
}

float camera_background_depth(const camera_settings *settings, float background_depth) {
    const float clip_end = settings->fields_set & CAMERA_FIELD_CLIP_END ? settings->clip_end : 0.0f;
    const float clip_start =
        settings->fields_set & CAMERA_FIELD_CLIP_START ? settings->clip_start : 0.0f;
    return hbao_clip_background_depth(clip_start, clip_end, background_depth);
}

void camera_settings_apply(camera_settings *base, const camera_settings *override) {
    const hbao_camera *from = &override->camera;
    hbao_camera *to = &base->camera;
    uint32_t set = override->fields_set;
    if (set & CAMERA_FIELD_PROJECTION) to->projection = from->projection;
    if (set & CAMERA_FIELD_LENS) to->lens = from->lens;
    if (set & CAMERA_FIELD_SENSOR_WIDTH) to->sensor_width = from->sensor_width;
    if (set & CAMERA_FIELD_SENSOR_HEIGHT) to->sensor_height = from->sensor_height;
    if (set & CAMERA_FIELD_SENSOR_FIT) to->sensor_fit = from->sensor_fit;
    if (set & CAMERA_FIELD_SHIFT_X) to->shift_x = from->shift_x;
    if (set & CAMERA_FIELD_SHIFT_Y) to->shift_y = from->shift_y;
    if (set & CAMERA_FIELD_ORTHO_SCALE) to->ortho_scale = from->ortho_scale;
    if (set & CAMERA_FIELD_PIXEL_ASPECT_X) to->pixel_aspect_x = from->pixel_aspect_x;
    if (set & CAMERA_FIELD_PIXEL_ASPECT_Y) to->pixel_aspect_y = from->pixel_aspect_y;
    if (set & CAMERA_FIELD_WORLD_TO_CAMERA)
        memcpy(to->world_to_camera, from->world_to_camera, sizeof to->world_to_camera);
    if (set & CAMERA_FIELD_CLIP_END) base->clip_end = override->clip_end;
    if (set & CAMERA_FIELD_CLIP_START) base->clip_start = override->clip_start;
    base->fields_set |= set;
}

/* The full image's size and the crop's place in it, as int32 or -1 where a
 * header's 32-bit window coordinates overflow it (hbao_camera_crop refuses -1). */
static int32_t as_int32(int64_t value) {
    return value >= INT32_MIN && value <= INT32_MAX ? (int32_t)value : -1;
}

hbao_result camera_for_data_window(const hbao_camera *camera, const pixel_rect *display,
                                   const pixel_rect *data, hbao_camera *cropped) {
    const int64_t full_width = (int64_t)display->max_x - display->min_x + 1;
    const int64_t full_height = (int64_t)display->max_y - display->min_y + 1;
    const int64_t width = (int64_t)data->max_x - data->min_x + 1;
    const int64_t height = (int64_t)data->max_y - data->min_y + 1;
    return hbao_camera_crop(camera, as_int32(full_width), as_int32(full_height),
                            as_int32((int64_t)data->min_x - display->min_x),
                            as_int32((int64_t)data->min_y - display->min_y), as_int32(width),
                            as_int32(height), cropped);
}

bool matrix_is_usable(const float matrix[16]) {
    hbao_camera camera;
    hbao_camera_default(&camera);
    memcpy(camera.world_to_camera, matrix, sizeof camera.world_to_camera);
    hbao_view view;
    return hbao_camera_view(&camera, 1, 1, &view) == HBAO_SUCCESS;
}

bool matrix_is_identity(const float matrix[16]) {
    for (int i = 0; i < 16; ++i)
        if (matrix[i] != (i % 5 == 0 ? 1.0f : 0.0f)) return false;
    return true;
}
