/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "ao_plan.h"

#include <math.h>
#include <string.h>

#include "camera_json.h"

/* Defaults, then the JSON file, then flags; the EXR header's pixel aspect
 * where neither gives a pixel aspect. Blender's pair (x, y) is one ratio in
 * the header: given x or y alone, the other is Blender's default 1, not the
 * header's ratio, which held both (--pixel-aspect-y 2 on a render of
 * aspect 1:2 made the pixels 0.25 wide for 1 tall; a review's find). */
static int resolve_camera(const cli_options *options, const exr_input *input,
                          camera_settings *resolved, tool_error *error) {
    camera_settings_init(resolved);
    if (options->camera_file != NULL) {
        camera_settings_apply(resolved, options->camera_file);
    } else if (options->camera_path != NULL) {
        camera_settings from_file;
        camera_settings_init(&from_file);
        const int status = camera_json_load(options->camera_path, &from_file, error);
        if (status != TOOL_EXIT_SUCCESS) return status;
        camera_settings_apply(resolved, &from_file);
    }
    camera_settings_apply(resolved, &options->camera_flags);
    const unsigned aspect = CAMERA_FIELD_PIXEL_ASPECT_X | CAMERA_FIELD_PIXEL_ASPECT_Y;
    if ((resolved->fields_set & aspect) == 0 && input->has_pixel_aspect_ratio &&
        input->pixel_aspect_ratio > 0.0f && isfinite(input->pixel_aspect_ratio)) {
        /* pixelAspectRatio = pixel width / pixel height = aspect_x / aspect_y. */
        resolved->camera.pixel_aspect_x = input->pixel_aspect_ratio;
        resolved->camera.pixel_aspect_y = 1.0f;
        resolved->fields_set |= aspect;
    }
    return TOOL_EXIT_SUCCESS;
}

int ao_plan_make(const cli_options *options, const exr_input *input, ao_plan *plan,
                 tool_error *error) {
    int status =
        blender_find_passes(input, options->layer, options->back_layer, &plan->passes, error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    status = resolve_camera(options, input, &plan->camera, error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    plan->use_normals = plan->passes.has_normal && !options->ignore_normals;
    const hbao_result cropping = camera_for_data_window(
        &plan->camera.camera, &input->display_window, &input->data_window, &plan->cropped);
    if (cropping != HBAO_SUCCESS)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: cannot compute AO: %s", options->input_path,
                         hbao_result_message(cropping));
    if (options->back_layer != NULL) {
        status = blender_find_passes(input, options->back_layer, NULL, &plan->back_passes, error);
        if (status != TOOL_EXIT_SUCCESS) return status;
    }
    /* a sky written at the camera's clip end (EEVEE in 4.5 and 5.0) is background */
    plan->params = options->params;
    plan->params.background_depth =
        camera_background_depth(&plan->camera, plan->params.background_depth);
    return TOOL_EXIT_SUCCESS;
}
