/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "info_command.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "blender_layers.h"
#include "exr_reader.h"

typedef struct channel_statistics {
    double minimum, maximum, mean; /* over the finite values */
    int64_t finite_count, nonfinite_count;
} channel_statistics;

static channel_statistics measure(const float *values, int64_t count) {
    channel_statistics stats = {INFINITY, -INFINITY, 0.0, 0, 0};
    double sum = 0.0;
    for (int64_t i = 0; i < count; ++i) {
        double value = values[i];
        if (!isfinite(value)) {
            ++stats.nonfinite_count;
            continue;
        }
        ++stats.finite_count;
        sum += value;
        if (value < stats.minimum) stats.minimum = value;
        if (value > stats.maximum) stats.maximum = value;
    }
    if (stats.finite_count > 0) stats.mean = sum / (double)stats.finite_count;
    return stats;
}

static cJSON *rect_json(const pixel_rect *rect) {
    int values[4] = {rect->min_x, rect->min_y, rect->max_x, rect->max_y};
    return cJSON_CreateIntArray(values, 4);
}

static void print_text(const exr_input *input, const channel_statistics *stats, const char **layers,
                       int layer_count) {
    const pixel_rect *data = &input->data_window, *display = &input->display_window;
    /* names from the file (and the path) with their control characters escaped */
    char name[TOOL_ERROR_MESSAGE_SIZE];
    tool_escape(input->path, name, sizeof name);
    printf("%s\n", name);
    printf("  size (data window): %dx%d\n", input->width, input->height);
    printf("  data window: (%d, %d) - (%d, %d)\n", data->min_x, data->min_y, data->max_x,
           data->max_y);
    printf("  display window: (%d, %d) - (%d, %d)\n", display->min_x, display->min_y,
           display->max_x, display->max_y);
    printf("  parts: %d\n", input->part_count);
    printf("  compression: %s\n", exr_compression_name(input->compression));
    printf("  pixel aspect ratio: %g%s\n", (double)input->pixel_aspect_ratio,
           input->has_pixel_aspect_ratio ? "" : " (not in header)");
    printf("  layers with a Depth pass:");
    for (int l = 0; l < layer_count; ++l) {
        char layer[BLENDER_CHANNEL_NAME_MAX];
        snprintf(layer, sizeof layer, "%.*s", (int)(strlen(layers[l]) - strlen(".Depth.Z")),
                 layers[l]);
        tool_escape(layer, name, sizeof name);
        printf("%s %s", l ? "," : "", name);
    }
    printf("%s\n", layer_count ? "" : " none");
    printf("  channels: %d\n", input->channels->num_channels);
    for (int c = 0; c < input->channels->num_channels; ++c) {
        const exr_attr_chlist_entry_t *channel = &input->channels->entries[c];
        const channel_statistics *s = &stats[c];
        tool_escape(channel->name.str, name, sizeof name);
        printf("    %-28s %-5s", name, exr_pixel_type_name(channel->pixel_type));
        if (s->finite_count > 0)
            printf("  min %-12.6g max %-12.6g mean %-12.6g", s->minimum, s->maximum, s->mean);
        else
            printf("  no finite values");
        printf("  non-finite %lld\n", (long long)s->nonfinite_count);
    }
}

/* A JSON string of `raw` (a path or a name from the file, any bytes): JSON
 * text must be UTF-8, so each byte that is not part of a valid sequence
 * becomes U+FFFD, the replacement character. NULL when out of memory. */
static cJSON *json_string(const char *raw) {
    const unsigned char *in = (const unsigned char *)raw;
    char *text = malloc(3 * strlen(raw) + 1);
    if (text == NULL) return NULL;
    size_t used = 0;
    while (*in != 0) {
        const size_t length = tool_utf8_sequence(in);
        if (length == 0) {
            memcpy(text + used, "\xEF\xBF\xBD", 3);
            used += 3;
            ++in;
        } else {
            memcpy(text + used, in, length);
            used += length;
            in += length;
        }
    }
    text[used] = '\0';
    cJSON *string = cJSON_CreateString(text);
    free(text);
    return string;
}

static int print_json(const exr_input *input, const channel_statistics *stats, const char **layers,
                      int layer_count, tool_error *error) {
    cJSON *root = cJSON_CreateObject();
    cJSON *layer_list = cJSON_CreateArray();
    cJSON *channel_list = cJSON_CreateArray();
    if (root == NULL || layer_list == NULL || channel_list == NULL) goto out_of_memory;
    cJSON_AddItemToObject(root, "path", json_string(input->path));
    cJSON_AddNumberToObject(root, "width", input->width);
    cJSON_AddNumberToObject(root, "height", input->height);
    cJSON_AddItemToObject(root, "data_window", rect_json(&input->data_window));
    cJSON_AddItemToObject(root, "display_window", rect_json(&input->display_window));
    cJSON_AddNumberToObject(root, "parts", input->part_count);
    cJSON_AddStringToObject(root, "compression", exr_compression_name(input->compression));
    cJSON_AddNumberToObject(root, "pixel_aspect_ratio", input->pixel_aspect_ratio);
    for (int l = 0; l < layer_count; ++l) {
        size_t length = strlen(layers[l]) - strlen(".Depth.Z");
        char name[BLENDER_CHANNEL_NAME_MAX];
        snprintf(name, sizeof name, "%.*s", (int)length, layers[l]);
        cJSON_AddItemToArray(layer_list, json_string(name));
    }
    cJSON_AddItemToObject(root, "layers", layer_list);
    layer_list = NULL;
    for (int c = 0; c < input->channels->num_channels; ++c) {
        const exr_attr_chlist_entry_t *channel = &input->channels->entries[c];
        cJSON *item = cJSON_CreateObject();
        if (item == NULL) goto out_of_memory;
        cJSON_AddItemToArray(channel_list, item);
        cJSON_AddItemToObject(item, "name", json_string(channel->name.str));
        cJSON_AddStringToObject(item, "type", exr_pixel_type_name(channel->pixel_type));
        cJSON_AddNumberToObject(item, "part", input->channel_parts[c]);
        if (stats[c].finite_count > 0) {
            cJSON_AddNumberToObject(item, "min", stats[c].minimum);
            cJSON_AddNumberToObject(item, "max", stats[c].maximum);
            cJSON_AddNumberToObject(item, "mean", stats[c].mean);
        } else {
            cJSON_AddNullToObject(item, "min");
            cJSON_AddNullToObject(item, "max");
            cJSON_AddNullToObject(item, "mean");
        }
        cJSON_AddNumberToObject(item, "finite", (double)stats[c].finite_count);
        cJSON_AddNumberToObject(item, "nonfinite", (double)stats[c].nonfinite_count);
    }
    cJSON_AddItemToObject(root, "channels", channel_list);
    channel_list = NULL;
    char *text = cJSON_Print(root);
    if (text == NULL) goto out_of_memory;
    puts(text);
    cJSON_free(text);
    cJSON_Delete(root);
    return TOOL_EXIT_SUCCESS;
out_of_memory:
    cJSON_Delete(layer_list);
    cJSON_Delete(channel_list);
    cJSON_Delete(root);
    return tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
}

int info_command(const char *path, bool as_json, tool_error *error) {
    exr_input input;
    int status = exr_input_open(&input, path, error);
    if (status != TOOL_EXIT_SUCCESS) return status;

    const int channel_count = input.channels->num_channels;
    const int64_t pixel_count = (int64_t)input.width * input.height;
    float *pixels = malloc((size_t)channel_count * (size_t)pixel_count * sizeof(float));
    exr_channel_request *requests = calloc((size_t)channel_count, sizeof *requests);
    channel_statistics *stats = calloc((size_t)channel_count, sizeof *stats);
    const char **layers = calloc((size_t)channel_count, sizeof *layers);
    if (pixels == NULL || requests == NULL || stats == NULL || layers == NULL) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
        goto done;
    }
    for (int c = 0; c < channel_count; ++c) {
        requests[c].name = input.channels->entries[c].name.str;
        requests[c].type = EXR_PIXEL_FLOAT;
        requests[c].data = (uint8_t *)(pixels + (int64_t)c * pixel_count);
        requests[c].pixel_stride = sizeof(float);
        requests[c].row_stride = (int64_t)input.width * (int64_t)sizeof(float);
    }
    status = exr_input_read(&input, requests, channel_count, error);
    if (status != TOOL_EXIT_SUCCESS) goto done;
    for (int c = 0; c < channel_count; ++c)
        stats[c] = measure(pixels + (int64_t)c * pixel_count, pixel_count);
    int layer_count = blender_depth_layers(&input, layers, channel_count);
    if (as_json)
        status = print_json(&input, stats, layers, layer_count, error);
    else
        print_text(&input, stats, layers, layer_count);
done:
    free(layers);
    free(stats);
    free(requests);
    free(pixels);
    exr_input_close(&input);
    return status;
}
