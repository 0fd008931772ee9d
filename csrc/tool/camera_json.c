/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "camera_json.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A camera description is a few hundred bytes; anything far larger is not one. */
#define CAMERA_JSON_MAX_BYTES (1 << 20)

typedef struct named_value {
    const char *name;
    int32_t value;
} named_value;

static const named_value projection_names[] = {
    {"PERSP", HBAO_PROJECTION_PERSPECTIVE},
    {"ORTHO", HBAO_PROJECTION_ORTHOGRAPHIC},
};

static const named_value sensor_fit_names[] = {
    {"AUTO", HBAO_SENSOR_FIT_AUTO},
    {"HORIZONTAL", HBAO_SENSOR_FIT_HORIZONTAL},
    {"VERTICAL", HBAO_SENSOR_FIT_VERTICAL},
};

typedef struct float_field {
    const char *key;
    uint32_t field;
    size_t offset;
    int must_be_positive;
} float_field;

/* offsets into camera_settings: the camera's fields and the clip range */
#define CAMERA_OFFSET(name) (offsetof(camera_settings, camera) + offsetof(hbao_camera, name))
static const float_field float_fields[] = {
    {"lens", CAMERA_FIELD_LENS, CAMERA_OFFSET(lens), 1},
    {"sensor_width", CAMERA_FIELD_SENSOR_WIDTH, CAMERA_OFFSET(sensor_width), 1},
    {"sensor_height", CAMERA_FIELD_SENSOR_HEIGHT, CAMERA_OFFSET(sensor_height), 1},
    {"shift_x", CAMERA_FIELD_SHIFT_X, CAMERA_OFFSET(shift_x), 0},
    {"shift_y", CAMERA_FIELD_SHIFT_Y, CAMERA_OFFSET(shift_y), 0},
    {"ortho_scale", CAMERA_FIELD_ORTHO_SCALE, CAMERA_OFFSET(ortho_scale), 1},
    {"pixel_aspect_x", CAMERA_FIELD_PIXEL_ASPECT_X, CAMERA_OFFSET(pixel_aspect_x), 1},
    {"pixel_aspect_y", CAMERA_FIELD_PIXEL_ASPECT_Y, CAMERA_OFFSET(pixel_aspect_y), 1},
    {"clip_end", CAMERA_FIELD_CLIP_END, offsetof(camera_settings, clip_end), 1},
    {"clip_start", CAMERA_FIELD_CLIP_START, offsetof(camera_settings, clip_start), 1},
};

#define COUNT_OF(array) (sizeof(array) / sizeof((array)[0]))

static int read_enum(const cJSON *root, const char *key, const named_value *names, size_t count,
                     uint32_t field, int32_t *out, camera_settings *settings, const char *source,
                     tool_error *error) {
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(root, key);
    if (item == NULL) return TOOL_EXIT_SUCCESS;
    if (!cJSON_IsString(item))
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: \"%s\" must be a string", source, key);
    for (size_t i = 0; i < count; ++i) {
        if (strcmp(item->valuestring, names[i].name) == 0) {
            *out = names[i].value;
            settings->fields_set |= field;
            return TOOL_EXIT_SUCCESS;
        }
    }
    char choices[128] = "";
    for (size_t i = 0; i < count; ++i) {
        strncat(choices, i ? ", " : "", sizeof choices - strlen(choices) - 1);
        strncat(choices, names[i].name, sizeof choices - strlen(choices) - 1);
    }
    return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: \"%s\" is \"%.64s\"; expected one of %s",
                     source, key, item->valuestring, choices);
}

static int read_number(const cJSON *item, const char *what, const char *source, float *out,
                       tool_error *error) {
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) || fabs(item->valuedouble) > FLT_MAX)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: %s must be a finite number", source, what);
    *out = (float)item->valuedouble;
    return TOOL_EXIT_SUCCESS;
}

static int read_matrix(const cJSON *root, camera_settings *settings, const char *source,
                       tool_error *error) {
    const char *key = "world_to_camera";
    const cJSON *rows = cJSON_GetObjectItemCaseSensitive(root, key);
    if (rows == NULL) return TOOL_EXIT_SUCCESS;
    if (!cJSON_IsArray(rows) || cJSON_GetArraySize(rows) != 4)
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "%s: \"%s\" must be 4 rows of 4 numbers (row-major)", source, key);
    float matrix[16];
    for (int r = 0; r < 4; ++r) {
        const cJSON *row = cJSON_GetArrayItem(rows, r);
        if (!cJSON_IsArray(row) || cJSON_GetArraySize(row) != 4)
            return tool_fail(error, TOOL_EXIT_RUNTIME,
                             "%s: \"%s\" row %d must be an array of 4 numbers", source, key, r);
        for (int c = 0; c < 4; ++c) {
            char what[64];
            snprintf(what, sizeof what, "\"%s\"[%d][%d]", key, r, c);
            int status =
                read_number(cJSON_GetArrayItem(row, c), what, source, &matrix[r * 4 + c], error);
            if (status != TOOL_EXIT_SUCCESS) return status;
        }
    }
    if (!matrix_is_usable(matrix))
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "%s: \"%s\" is not a camera's matrix (its upper-left 3x3 part is "
                         "singular or out of range)",
                         source, key);
    memcpy(settings->camera.world_to_camera, matrix, sizeof matrix);
    settings->fields_set |= CAMERA_FIELD_WORLD_TO_CAMERA;
    return TOOL_EXIT_SUCCESS;
}

/* A key this tool reads given twice: cJSON takes the first value, Python's
 * json and jq the last, so the AO depended on the reader; refused. */
static int repeated_key(const cJSON *root, const char *source, tool_error *error) {
    static const char *const other_keys[] = {"type", "sensor_fit", "world_to_camera"};
    const size_t key_count = COUNT_OF(float_fields) + COUNT_OF(other_keys);
    for (size_t k = 0; k < key_count; ++k) {
        const char *key = k < COUNT_OF(float_fields) ? float_fields[k].key
                                                     : other_keys[k - COUNT_OF(float_fields)];
        int seen = 0;
        for (const cJSON *item = root->child; item != NULL; item = item->next)
            if (item->string != NULL && strcmp(item->string, key) == 0 && ++seen > 1)
                return tool_fail(error, TOOL_EXIT_RUNTIME,
                                 "%s: \"%s\" is given more than once; give each key once", source,
                                 key);
    }
    return TOOL_EXIT_SUCCESS;
}

int camera_json_parse(const char *text, const char *source, camera_settings *settings,
                      tool_error *error) {
    cJSON *root = cJSON_Parse(text);
    if (root == NULL) return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: not valid JSON", source);
    int status = TOOL_EXIT_SUCCESS;
    if (!cJSON_IsObject(root)) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: expected a JSON object", source);
        goto done;
    }
    status = repeated_key(root, source, error);
    if (status != TOOL_EXIT_SUCCESS) goto done;
    status =
        read_enum(root, "type", projection_names, COUNT_OF(projection_names),
                  CAMERA_FIELD_PROJECTION, &settings->camera.projection, settings, source, error);
    if (status != TOOL_EXIT_SUCCESS) goto done;
    status =
        read_enum(root, "sensor_fit", sensor_fit_names, COUNT_OF(sensor_fit_names),
                  CAMERA_FIELD_SENSOR_FIT, &settings->camera.sensor_fit, settings, source, error);
    if (status != TOOL_EXIT_SUCCESS) goto done;
    for (size_t i = 0; i < COUNT_OF(float_fields); ++i) {
        const float_field *field = &float_fields[i];
        const cJSON *item = cJSON_GetObjectItemCaseSensitive(root, field->key);
        if (item == NULL) continue;
        char what[64];
        snprintf(what, sizeof what, "\"%s\"", field->key);
        float *out = (float *)((char *)settings + field->offset);
        status = read_number(item, what, source, out, error);
        if (status != TOOL_EXIT_SUCCESS) goto done;
        if (field->must_be_positive && !(*out > 0.0f)) {
            status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: %s must be > 0", source, what);
            goto done;
        }
        settings->fields_set |= field->field;
    }
    status = read_matrix(root, settings, source, error);
done:
    cJSON_Delete(root);
    return status;
}

int camera_json_load(const char *path, camera_settings *settings, tool_error *error) {
    FILE *file = fopen(path, "rb");
    if (file == NULL)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot open camera file %s: %s", path,
                         strerror(errno));
    char *text = malloc(CAMERA_JSON_MAX_BYTES + 1);
    if (text == NULL) {
        fclose(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
    }
    errno = 0;
    size_t length = fread(text, 1, CAMERA_JSON_MAX_BYTES + 1, file);
    const int read_errno = ferror(file) ? errno : 0; /* a folder: EISDIR */
    const int read_failed = ferror(file);
    fclose(file);
    int status;
    if (read_failed)
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "cannot read camera file %s: %s", path,
                           read_errno != 0 ? strerror(read_errno) : "read error");
    else if (length > CAMERA_JSON_MAX_BYTES)
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "camera file %s is larger than %d bytes", path,
                           CAMERA_JSON_MAX_BYTES);
    else {
        text[length] = '\0';
        status = camera_json_parse(text, path, settings, error);
    }
    free(text);
    return status;
}
