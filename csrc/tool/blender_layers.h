/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Finding Blender's render passes among an EXR's channels. A multilayer EXR
 * names them <ViewLayer>.<Pass>.<Channel>: "ViewLayer.Depth.Z",
 * "ViewLayer.Normal.X". A single-layer EXR saved with a Z buffer has a plain
 * "Z" channel.
 */
#ifndef HBAO_TOOL_BLENDER_LAYERS_H
#define HBAO_TOOL_BLENDER_LAYERS_H

#include <stdbool.h>

#include "exr_reader.h"
#include "tool_error.h"

#define BLENDER_CHANNEL_NAME_MAX 512
/** Blender before 5.0 cuts EXR channel names past 64 bytes (EXR_TOT_MAXNAME;
 *  addon/hbao/compat.py's EXR_CHANNEL_NAME_MAX): a view layer named with this
 *  many bytes or more loses its Normal pass ("<layer>.Normal.X", 9 more). */
#define BLENDER_NORMAL_LAYER_NAME_MAX 56

typedef struct blender_passes {
    char layer[BLENDER_CHANNEL_NAME_MAX]; /**< "" for a file without layers */
    char depth[BLENDER_CHANNEL_NAME_MAX];
    char normal[3][BLENDER_CHANNEL_NAME_MAX];
    bool has_normal;      /**< all three normal channels exist */
    bool normal_expected; /**< a layer (or Depth.Z / Depth.V): a Normal pass may be there */
    int normal_found;     /**< how many of the three exist (normal[] names all three) */
} blender_passes;

/**
 * Choose the layer: `requested` when not NULL, else the one layer with a
 * Depth pass other than `excluded` (the back layer, or NULL), else a plain
 * "Depth.Z" or "Z" channel. Fails listing the layers that do exist, also
 * where several layers could be meant.
 */
int blender_find_passes(const exr_input *input, const char *requested, const char *excluded,
                        blender_passes *passes, tool_error *error);

/** Number of layers with a Depth pass; their names go to `names` (up to `capacity`). */
int blender_depth_layers(const exr_input *input, const char **names, int capacity);

#endif /* HBAO_TOOL_BLENDER_LAYERS_H */
