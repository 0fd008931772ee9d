/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Fuzz target: the camera JSON parser (`--camera FILE.json`). Oracle,
 * besides the sanitizers: what it accepts is usable, i.e. every number it
 * set is finite, the enums are in range and the lengths are positive.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void require(bool condition, const char *what) {
    if (condition) return;
    fprintf(stderr, "fuzz: the parser accepted a camera whose %s\n", what);
    abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *text = malloc(size + 1);
    if (text == NULL) return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    camera_settings settings;
    camera_settings_init(&settings);
    tool_error error;
    if (camera_json_parse(text, "fuzz.json", &settings, &error) == TOOL_EXIT_SUCCESS) {
        const hbao_camera *c = &settings.camera;
        require(c->projection == HBAO_PROJECTION_PERSPECTIVE ||
                    c->projection == HBAO_PROJECTION_ORTHOGRAPHIC,
                "type is not PERSP or ORTHO");
        require(c->sensor_fit >= HBAO_SENSOR_FIT_AUTO && c->sensor_fit <= HBAO_SENSOR_FIT_VERTICAL,
                "sensor_fit is out of range");
        require(c->lens > 0.0f && isfinite(c->lens), "lens is not finite and positive");
        require(c->sensor_width > 0.0f && isfinite(c->sensor_width) && c->sensor_height > 0.0f &&
                    isfinite(c->sensor_height),
                "sensor size is not finite and positive");
        require(c->ortho_scale > 0.0f && isfinite(c->ortho_scale),
                "ortho_scale is not finite and positive");
        require(c->pixel_aspect_x > 0.0f && isfinite(c->pixel_aspect_x) &&
                    c->pixel_aspect_y > 0.0f && isfinite(c->pixel_aspect_y),
                "pixel aspect is not finite and positive");
        require(isfinite(c->shift_x) && isfinite(c->shift_y), "shift is not finite");
        for (int k = 0; k < 16; ++k)
            require(isfinite(c->world_to_camera[k]), "matrix is not finite");
    }
    free(text);
    return 0;
}
