/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "camera_settings.h"

#include <string.h>

void camera_settings_init(camera_settings *settings)
{
    hbao_camera defaults = HBAO_CAMERA_DEFAULT_INITIALIZER;
    settings->camera = defaults;
    settings->fields_set = 0;
}

void camera_settings_apply(camera_settings *base, const camera_settings *override)
{
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
    base->fields_set |= set;
}

static double rect_width(const pixel_rect *rect)
{
    return (double)rect->max_x - rect->min_x + 1.0;
}

static double rect_height(const pixel_rect *rect)
{
    return (double)rect->max_y - rect->min_y + 1.0;
}

hbao_camera camera_for_data_window(const hbao_camera *camera, const pixel_rect *display,
                                   const pixel_rect *data)
{
    if (memcmp(display, data, sizeof *data) == 0) return *camera;

    /* Blender's view plane, in units of display pixels horizontally and
     * ycor * pixels vertically (ycor = pixel_aspect_y / pixel_aspect_x). */
    const double full_width = rect_width(display), full_height = rect_height(display);
    const double crop_width = rect_width(data), crop_height = rect_height(data);
    const double ycor = (double)camera->pixel_aspect_y / camera->pixel_aspect_x;

    int32_t fit = camera->sensor_fit;
    if (fit == HBAO_SENSOR_FIT_AUTO)
        fit = camera->pixel_aspect_x * full_width >= camera->pixel_aspect_y * full_height
                  ? HBAO_SENSOR_FIT_HORIZONTAL
                  : HBAO_SENSOR_FIT_VERTICAL;
    /* AUTO uses sensor_width for whichever side it fits (BKE_camera_sensor_size). */
    const double sensor = camera->sensor_fit == HBAO_SENSOR_FIT_VERTICAL ? camera->sensor_height
                                                                          : camera->sensor_width;
    const bool horizontal = fit == HBAO_SENSOR_FIT_HORIZONTAL;
    const double full_fitted = horizontal ? full_width : ycor * full_height;
    const double crop_fitted = horizontal ? crop_width : ycor * crop_height;
    const double scale = crop_fitted / full_fitted;

    /* Offsets of the crop's lower-left corner from the frame's, bottom-up. */
    const double offset_x = (double)data->min_x - display->min_x;
    const double offset_y = (double)display->max_y - data->max_y;
    /* Centre shift in view-plane units: the old shift plus the move of the
     * window centre from the full frame's to the crop's. */
    const double shift_x_plane =
        camera->shift_x * full_fitted + offset_x + 0.5 * (crop_width - full_width);
    const double shift_y_plane =
        camera->shift_y * full_fitted + ycor * (offset_y + 0.5 * (crop_height - full_height));

    hbao_camera cropped = *camera;
    cropped.sensor_fit = fit;
    if (horizontal)
        cropped.sensor_width = (float)(sensor * scale);
    else
        cropped.sensor_height = (float)(sensor * scale);
    cropped.ortho_scale = (float)(camera->ortho_scale * scale);
    cropped.shift_x = (float)(shift_x_plane / crop_fitted);
    cropped.shift_y = (float)(shift_y_plane / crop_fitted);
    return cropped;
}

bool matrix_is_identity(const float matrix[16])
{
    for (int i = 0; i < 16; ++i)
        if (matrix[i] != (i % 5 == 0 ? 1.0f : 0.0f)) return false;
    return true;
}
