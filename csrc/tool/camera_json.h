/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Reads a camera description written as JSON with Blender's own property
 * names (scripts/blender_scenes.py camera_description() writes one):
 *
 *   { "type": "PERSP" | "ORTHO", "lens": 50, "sensor_width": 36,
 *     "sensor_height": 24, "sensor_fit": "AUTO" | "HORIZONTAL" | "VERTICAL",
 *     "shift_x": 0, "shift_y": 0, "ortho_scale": 6,
 *     "pixel_aspect_x": 1, "pixel_aspect_y": 1,
 *     "world_to_camera": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]] }
 *
 * Every key is optional; keys not listed are ignored (so the file may carry
 * more of Blender's camera). A listed key with a wrong type or value is an
 * error.
 */
#ifndef HBAO_TOOL_CAMERA_JSON_H
#define HBAO_TOOL_CAMERA_JSON_H

#include "camera_settings.h"
#include "tool_error.h"

/** Returns TOOL_EXIT_SUCCESS or an exit status with `error` filled. */
int camera_json_load(const char *path, camera_settings *settings, tool_error *error);

/** The same from JSON text (`source` names it in messages). */
int camera_json_parse(const char *text, const char *source, camera_settings *settings,
                      tool_error *error);

#endif /* HBAO_TOOL_CAMERA_JSON_H */
