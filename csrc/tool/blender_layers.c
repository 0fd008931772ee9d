/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "blender_layers.h"

#include <stdio.h>
#include <string.h>

static const char depth_suffix[] = ".Depth.Z";
static const char *const normal_names[3] = {"Normal.X", "Normal.Y", "Normal.Z"};

/* Length of the layer prefix when `name` is "<layer>.Depth.Z", else -1. */
static int depth_layer_length(const char *name) {
    size_t length = strlen(name), suffix = strlen(depth_suffix);
    if (length <= suffix || strcmp(name + length - suffix, depth_suffix) != 0) return -1;
    return (int)(length - suffix);
}

int blender_depth_layers(const exr_input *input, const char **names, int capacity) {
    int found = 0;
    for (int c = 0; c < input->channels->num_channels; ++c) {
        const char *name = input->channels->entries[c].name.str;
        if (depth_layer_length(name) < 0) continue;
        if (found < capacity) names[found] = name;
        ++found;
    }
    return found;
}

static bool set_name(char *out, const char *prefix, int prefix_length, const char *suffix) {
    int written = snprintf(out, BLENDER_CHANNEL_NAME_MAX, "%.*s%s", prefix_length, prefix, suffix);
    return written >= 0 && written < BLENDER_CHANNEL_NAME_MAX;
}

/* `layer` may be "" (a file without view layers: "Depth.Z", "Normal.X"). */
static int fill_passes(const exr_input *input, const char *layer, int layer_length,
                       const char *depth_channel, bool look_for_normals, blender_passes *passes,
                       tool_error *error) {
    memset(passes, 0, sizeof *passes);
    if (!set_name(passes->layer, layer, layer_length, "") ||
        !set_name(passes->depth, depth_channel, (int)strlen(depth_channel), ""))
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: channel name too long", input->path);
    passes->normal_expected = look_for_normals;
    for (int axis = 0; axis < 3 && look_for_normals; ++axis) {
        char prefix[BLENDER_CHANNEL_NAME_MAX];
        if (!set_name(prefix, layer, layer_length, layer_length > 0 ? "." : "") ||
            !set_name(passes->normal[axis], prefix, (int)strlen(prefix), normal_names[axis]))
            return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: channel name too long", input->path);
        passes->normal_found += exr_input_find_channel(input, passes->normal[axis]) >= 0;
    }
    passes->has_normal = look_for_normals && passes->normal_found == 3;
    return TOOL_EXIT_SUCCESS;
}

/* Whether `name` is "<layer>.Depth.<view>.Z", a view's Depth pass as
 * Blender names it in a multi-view render saved as one file, with a view
 * name without dots; the layer's length in *layer_length and the view's
 * name (its length) in *view. The last such split: a layer's name may hold
 * ".Depth." ("BG.Depth.Depth.left.Z" is view "left" of layer "BG.Depth"). */
static bool view_depth_name(const char *name, int *layer_length, const char **view,
                            int *view_length) {
    static const char pass[] = ".Depth.";
    const size_t length = strlen(name);
    if (length < strlen(pass) + strlen("x.Z") || strcmp(name + length - 2, ".Z") != 0) return false;
    for (const char *at = name + length - 2 - strlen(pass); at > name; --at) {
        if (*at == '.' && at[1] != 'D') return false; /* the view would hold a dot */
        if (strncmp(at, pass, strlen(pass)) != 0) continue;
        const char *start = at + strlen(pass), *end = name + length - 2;
        if (end == start || memchr(start, '.', (size_t)(end - start)) != NULL) return false;
        *layer_length = (int)(at - name);
        *view = start;
        *view_length = (int)(end - start);
        return true;
    }
    return false;
}

/* Whether `name`, split as "<layer>.Depth.<rest>" with the layer's first
 * `layer_length` bytes, is rather a pass of a longer layer that has a
 * Depth pass of its own ("BG.Depth.Normal.Z" beside "BG.Depth.Depth.Z";
 * "A.Depth.B.Depth.Z"): only prefixes from "<layer>.Depth" on. */
static bool in_layer_with_depth(const exr_input *input, const char *name, int layer_length) {
    for (const char *dot = name + layer_length + strlen(".Depth"); dot != NULL;
         dot = strchr(dot + 1, '.')) {
        char depth[BLENDER_CHANNEL_NAME_MAX];
        if (*dot == '.' && set_name(depth, name, (int)(dot - name), depth_suffix) &&
            exr_input_find_channel(input, depth) >= 0)
            return true;
    }
    return false;
}

/* Whether `name` is "<layer>.Depth.<view>.Z" for the first `layer_length`
 * bytes of `layer`: a view of that layer (a view's name may hold dots). A
 * layer whose own name ends in ".Depth" ("BG.Depth.Depth.Z") is no view. */
static bool layer_view_depth_name(const char *name, const char *layer, int layer_length,
                                  const char **view, int *view_length) {
    static const char pass[] = ".Depth.";
    const size_t length = strlen(name), prefix = (size_t)layer_length + strlen(pass);
    if (length < prefix + strlen("x.Z") || strncmp(name, layer, (size_t)layer_length) != 0 ||
        strncmp(name + layer_length, pass, strlen(pass)) != 0 ||
        strcmp(name + length - 2, ".Z") != 0)
        return false;
    *view = name + prefix;
    *view_length = (int)(length - 2 - prefix);
    return true;
}

/* A multi-view render saved as one file (Views Format: Multi-View): the
 * tool reads one view from one file, with that view's camera. With
 * `default_layer` (its first `layer_length` bytes), the layer whose
 * unnamed channels are a default view (OpenEXR's layout): only that
 * layer's views count. */
static int fail_on_views(const exr_input *input, const char *default_layer, int layer_length,
                         tool_error *error) {
    char views[300] = "";
    int count = 0;
    if (default_layer != NULL) snprintf(views, sizeof views, "%s", "\"(default)\"");
    for (int c = 0; c < input->channels->num_channels; ++c) {
        const char *view = NULL, *name = input->channels->entries[c].name.str;
        int length = 0;
        int view_layer = 0;
        if (default_layer != NULL
                ? !layer_view_depth_name(name, default_layer, layer_length, &view, &length) ||
                      in_layer_with_depth(input, name, layer_length)
                : !view_depth_name(name, &view_layer, &view, &length) ||
                      in_layer_with_depth(input, name, view_layer))
            continue;
        const size_t used = strlen(views);
        snprintf(views + used, sizeof views - used, "%s\"%.*s\"", used ? ", " : "", length, view);
        ++count;
    }
    if (count == 0) return TOOL_EXIT_SUCCESS;
    return tool_fail(
        error, TOOL_EXIT_RUNTIME,
        "%s: holds the views %s of a multi-view render in one file; " EXR_VIEWS_APART_ADVICE,
        input->path, views);
}

/* A render with a single view on, which Blender 3.4 saves with the view in
 * its channel names ("ViewLayer.Depth.left.Z", "ViewLayer.Normal.left.X"):
 * that view's passes, true; false where the file holds no such view or
 * several. */
static bool one_view_passes(const exr_input *input, blender_passes *passes) {
    const char *depth = NULL;
    for (int c = 0; c < input->channels->num_channels; ++c) {
        const char *view = NULL;
        int layer = 0, length = 0;
        const char *name = input->channels->entries[c].name.str;
        if (!view_depth_name(name, &layer, &view, &length)) continue;
        if (depth != NULL) return false;
        depth = name;
    }
    if (depth == NULL) return false;
    const char *view = NULL;
    int layer_length = 0, view_length = 0;
    view_depth_name(depth, &layer_length, &view, &view_length);
    memset(passes, 0, sizeof *passes);
    if (!set_name(passes->layer, depth, layer_length, "") ||
        !set_name(passes->depth, depth, (int)strlen(depth), ""))
        return false;
    passes->normal_expected = true;
    static const char axes[3] = {'X', 'Y', 'Z'};
    for (int axis = 0; axis < 3; ++axis) {
        const int written =
            snprintf(passes->normal[axis], BLENDER_CHANNEL_NAME_MAX, "%.*s.Normal.%.*s.%c",
                     layer_length, depth, view_length, view, axes[axis]);
        if (written < 0 || written >= BLENDER_CHANNEL_NAME_MAX) return false;
        passes->normal_found += exr_input_find_channel(input, passes->normal[axis]) >= 0;
    }
    passes->has_normal = passes->normal_found == 3;
    return true;
}

/* Whether the layer prefix of `name` (its first `length` bytes) is `layer`
 * (NULL: no layer). */
static bool is_layer(const char *name, int length, const char *layer) {
    return layer != NULL && (size_t)length == strlen(layer) &&
           strncmp(name, layer, (size_t)length) == 0;
}

static int fail_listing_layers(const exr_input *input, const char *problem, const char *excluded,
                               tool_error *error) {
    const int views = fail_on_views(input, NULL, 0, error);
    if (views != TOOL_EXIT_SUCCESS) return views;
    char list[600] = "";
    bool excluded_has_depth = false;
    for (int c = 0; c < input->channels->num_channels; ++c) {
        const char *name = input->channels->entries[c].name.str;
        int length = depth_layer_length(name);
        if (length < 0) continue;
        if (is_layer(name, length, excluded)) {
            excluded_has_depth = true;
            continue;
        }
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s\"%.*s\"", used ? ", " : "", length, name);
    }
    /* (the message listed the --back-layer's own layer as the one to use:
     * a review's find) */
    if (list[0] == '\0' && excluded_has_depth)
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "%s: no Depth pass but the --back-layer's (\"%s\"): the front faces "
                         "need a view layer of their own (--layer NAME)",
                         input->path, excluded);
    if (list[0] == '\0')
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "%s: %s; the file has no Depth pass (no channel "
                         "<ViewLayer>.Depth.Z or Z): enable the Z/Depth pass in Blender's "
                         "View Layer properties",
                         input->path, problem);
    return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: %s; layers with a Depth pass: %s", input->path,
                     problem, list);
}

int blender_find_passes(const exr_input *input, const char *requested, const char *excluded,
                        blender_passes *passes, tool_error *error) {
    if (requested != NULL) {
        char depth[BLENDER_CHANNEL_NAME_MAX];
        if (!set_name(depth, requested, (int)strlen(requested), depth_suffix))
            /* --layer's or --back-layer's: named by its start, which the
             * artist typed, not by a flag that may be the other one */
            return tool_fail(error, TOOL_EXIT_USAGE, "layer \"%.24s...\": name too long",
                             requested);
        if (exr_input_find_channel(input, depth) < 0) {
            char problem[BLENDER_CHANNEL_NAME_MAX + 64];
            snprintf(problem, sizeof problem, "no layer \"%s\" with a Depth pass (%s)", requested,
                     depth);
            return fail_listing_layers(input, problem, NULL, error);
        }
        /* (OpenEXR's multi-view layout, below, named with --layer too) */
        const int views = fail_on_views(input, requested, (int)strlen(requested), error);
        if (views != TOOL_EXIT_SUCCESS) return views;
        return fill_passes(input, requested, (int)strlen(requested), depth, true, passes, error);
    }
    /* The one layer with a Depth pass (the back layer left out): with
     * several, which one a render's node reads cannot be told from the file
     * (a default by name took "ViewLayer.001" over "ViewLayer", silently). */
    const char *chosen = NULL;
    int chosen_length = 0, candidates = 0;
    for (int c = 0; c < input->channels->num_channels; ++c) {
        const char *name = input->channels->entries[c].name.str;
        const int length = depth_layer_length(name);
        if (length < 0) continue;
        if (is_layer(name, length, excluded)) continue;
        if (candidates++ == 0) {
            chosen = name;
            chosen_length = length;
        }
    }
    if (candidates > 1)
        return fail_listing_layers(input,
                                   "the Depth pass is in several view layers; choose one with "
                                   "--layer NAME",
                                   excluded, error);
    if (chosen != NULL) {
        /* OpenEXR's own multi-view layout names the default view's channels
         * without a view ("ViewLayer.Depth.Z" beside "ViewLayer.Depth.right.Z"):
         * refused as Blender's, not read as the default view, silently */
        const int views = fail_on_views(input, chosen, chosen_length, error);
        if (views != TOOL_EXIT_SUCCESS) return views;
        return fill_passes(input, chosen, chosen_length, chosen, true, passes, error);
    }
    /* A File Output node's Depth input writes "Depth.V" beside "Normal.X" */
    static const char *const plain_depth[] = {"Depth.Z", "Depth.V", "Z"};
    for (int i = 0; i < 3; ++i)
        if (exr_input_find_channel(input, plain_depth[i]) >= 0)
            return fill_passes(input, "", 0, plain_depth[i], i < 2, passes, error);
    if (one_view_passes(input, passes)) return TOOL_EXIT_SUCCESS;
    return fail_listing_layers(input, "no Depth pass", excluded, error);
}
