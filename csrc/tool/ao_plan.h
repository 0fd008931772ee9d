/* SPDX-License-Identifier: GPL-2.0-or-later */
/* What a run computes an input's AO with, decided from the input's header
 * and the flags without reading a pixel: the passes, the camera and the
 * parameters. ao_command computes with it, and the output's hbaoSettings
 * stamp is written from it (run_settings.h), so that a sequence rerun whose
 * flags say the same thing in other words (--layer naming the file's only
 * layer, --camera-type PERSP for a perspective camera) finds its frames up
 * to date. */
#ifndef HBAO_TOOL_AO_PLAN_H
#define HBAO_TOOL_AO_PLAN_H

#include <stdbool.h>

#include "blender_layers.h"
#include "camera_settings.h"
#include "cli_options.h"
#include "exr_reader.h"
#include "tool_error.h"

typedef struct ao_plan {
    blender_passes passes;      /**< the layer's (--layer, or the one there is) */
    blender_passes back_passes; /**< --back-layer's; only where it is given */
    camera_settings camera;     /**< defaults, the header's pixel aspect, --camera, flags */
    hbao_camera cropped;        /**< camera, for the file's data window */
    hbao_params params;         /**< the flags', the background depth from the camera's */
    bool use_normals;           /**< a Normal pass there, and no --no-normals */
} ao_plan;

/**
 * The plan of `input` (opened: its header is read) for `options`: fails,
 * with the reason, where the layer or pass is not there, --camera cannot be
 * read, or the camera does not fit the file's windows.
 */
int ao_plan_make(const cli_options *options, const exr_input *input, ao_plan *plan,
                 tool_error *error);

#endif /* HBAO_TOOL_AO_PLAN_H */
