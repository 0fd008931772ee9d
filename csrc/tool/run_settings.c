/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "run_settings.h"

#include <openexr.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* Appends to text[*used ...]; *used past RUN_SETTINGS_MAX - 1 marks a text that
 * did not fit. */
static void append(char *text, size_t *used, const char *format, ...)
    __attribute__((format(printf, 3, 4)));

static void append(char *text, size_t *used, const char *format, ...) {
    if (*used >= RUN_SETTINGS_MAX - 1) {
        *used = RUN_SETTINGS_MAX;
        return;
    }
    va_list arguments;
    va_start(arguments, format);
    const int written = vsnprintf(text + *used, RUN_SETTINGS_MAX - *used, format, arguments);
    va_end(arguments);
    *used = written < 0 ? RUN_SETTINGS_MAX : *used + (size_t)written;
}

/* The camera the AO is computed with: every hbao_camera value, whether a
 * default, the header's, the camera file's or a flag's. */
static void append_camera(char *text, size_t *used, const hbao_camera *c) {
    append(text, used, "camera %d %.9g %.9g %.9g %d %.9g %.9g %.9g %.9g %.9g", (int)c->projection,
           (double)c->lens, (double)c->sensor_width, (double)c->sensor_height, (int)c->sensor_fit,
           (double)c->shift_x, (double)c->shift_y, (double)c->ortho_scale,
           (double)c->pixel_aspect_x, (double)c->pixel_aspect_y);
    for (int i = 0; i < 16; ++i) append(text, used, " %.9g", (double)c->world_to_camera[i]);
}

bool run_settings_text(const cli_options *options, const ao_plan *plan,
                       char text[RUN_SETTINGS_MAX]) {
    const hbao_params *p = &plan->params;
    size_t used = 0;
    text[0] = '\0';
    /* %.9g: every float32 value prints to a text that reads back exactly.
     * The background depth is the one the camera's clip range made. */
    append(text, &used,
           "hbao %d; radius %.9g; angle bias %.9g; directions %d; steps %d; falloff %d; "
           "integration %d; blur size %d; blur sharpness %.9g; half resolution %d; "
           "strength %.9g; background depth %.9g; thickness %.9g; ",
           (int)HBAO_VERSION, (double)p->radius, (double)p->angle_bias_degrees, (int)p->directions,
           (int)p->steps, (int)p->falloff, (int)p->integration, (int)p->blur_size,
           (double)p->blur_sharpness, (int)p->half_resolution, (double)p->strength,
           (double)p->background_depth, (double)p->thickness);
    append(text, &used,
           "keep input %d; normals %d; compression %d; crop to display %d; overscan %d; ",
           (int)options->keep_input, (int)plan->use_normals, (int)options->compression,
           (int)options->crop_to_display, (int)options->overscan);
    append_camera(text, &used, &plan->camera.camera);
    /* the layers by the names found (a file's only layer, named or not, is
     * one layer) */
    append(text, &used, "; layer %s; back layer %s; AO channel %s", plan->passes.layer,
           options->back_layer != NULL ? plan->back_passes.layer : "(none)", options->ao_channel);
    return used < RUN_SETTINGS_MAX - 1;
}

/* The stamp of the EXR opened as `context`, or NULL with *length 0. */
static const char *stamp(exr_const_context_t context, int32_t *length) {
    const char *stored = NULL;
    *length = 0;
    if (exr_attr_get_string(context, 0, RUN_SETTINGS_ATTRIBUTE, length, &stored) !=
            EXR_ERR_SUCCESS ||
        stored == NULL || *length < 0) {
        *length = 0;
        return NULL;
    }
    return stored;
}

bool run_settings_match(exr_const_context_t context, const char *text) {
    int32_t length;
    const char *stored = stamp(context, &length);
    return stored != NULL && (size_t)length == strlen(text) &&
           memcmp(stored, text, (size_t)length) == 0;
}

bool run_settings_stamped(exr_const_context_t context) {
    int32_t length;
    return stamp(context, &length) != NULL;
}
