/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * libhbao_exr: the OpenEXRCore reader that the hbao tool also uses
 * (exr_reader.c, compiled once into an object library both targets link) behind a small
 * interface that ctypes can call: plain C types, caller-owned buffers, a
 * result code and a message in the caller's buffer.
 */
#include "hbao_exr.h"

#include <errno.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "exr_reader.h"
#include "tool_error.h"

/* The reader takes byte strides as int32 (OpenEXRCore's user_line_stride). */
#define MAX_STRIDE_FLOATS ((int64_t)INT32_MAX / (int64_t)sizeof(float))

struct hbao_exr_file {
    exr_input input;
    char *path; /* owned: input.path points at it */
};

int32_t hbao_exr_interface_version(void) {
    return HBAO_EXR_INTERFACE_VERSION;
}

int32_t hbao_exr_channel_request_size(void) {
    return (int32_t)sizeof(hbao_exr_channel_request);
}

const char *hbao_exr_result_message(int32_t result) {
#define HBAO_EXR_RESULT_MESSAGE_CASE(name, value, message)                                         \
    case value:                                                                                    \
        return message;
    switch (result) {
        HBAO_EXR_RESULTS(HBAO_EXR_RESULT_MESSAGE_CASE)
        default:
            return "unknown result";
    }
#undef HBAO_EXR_RESULT_MESSAGE_CASE
}

static void copy_message(char *message, int32_t message_size, const char *text) {
    if (message != NULL && message_size > 0) snprintf(message, (size_t)message_size, "%s", text);
}

static int32_t fail(char *message, int32_t message_size, int32_t result, const char *format, ...)
    __attribute__((format(printf, 4, 5)));

static int32_t fail(char *message, int32_t message_size, int32_t result, const char *format, ...) {
    if (message != NULL && message_size > 0) {
        va_list arguments;
        va_start(arguments, format);
        vsnprintf(message, (size_t)message_size, format, arguments);
        va_end(arguments);
    }
    return result;
}

/* exr_input_open reports every failure the same way; tell a file that cannot
 * be opened at all (missing, unreadable) from one that is not a valid EXR. */
static int32_t open_failure(const char *path, const tool_error *error, char *message,
                            int32_t message_size) {
    if (access(path, R_OK) != 0) {
        int access_error = errno;
        char reason[256];
        if (strerror_r(access_error, reason, sizeof reason) != 0)
            snprintf(reason, sizeof reason, "error %d", access_error);
        return fail(message, message_size, HBAO_EXR_ERROR_FILE_ACCESS, "%s: cannot open: %s", path,
                    reason);
    }
    copy_message(message, message_size, error->message);
    return HBAO_EXR_ERROR_FORMAT;
}

int32_t hbao_exr_open(const char *path, hbao_exr_file **file, char *message, int32_t message_size) {
    if (file == NULL)
        return fail(message, message_size, HBAO_EXR_ERROR_INVALID_ARGUMENT,
                    "hbao_exr_open: file is NULL");
    *file = NULL;
    if (path == NULL || path[0] == '\0')
        return fail(message, message_size, HBAO_EXR_ERROR_INVALID_ARGUMENT,
                    "hbao_exr_open: no path given");
    hbao_exr_file *opened = calloc(1, sizeof *opened);
    char *path_copy = strdup(path);
    if (opened == NULL || path_copy == NULL) {
        free(opened);
        free(path_copy);
        return fail(message, message_size, HBAO_EXR_ERROR_OUT_OF_MEMORY,
                    "%s: out of memory opening the file", path);
    }
    opened->path = path_copy;
    tool_error error = {{0}};
    if (exr_input_open(&opened->input, opened->path, &error) != TOOL_EXIT_SUCCESS) {
        int32_t result = open_failure(opened->path, &error, message, message_size);
        free(opened->path);
        free(opened);
        return result;
    }
    hbao_exr_set_threads(opened, 0);
    *file = opened;
    return HBAO_EXR_SUCCESS;
}

void hbao_exr_size(const hbao_exr_file *file, int32_t *width, int32_t *height) {
    if (width != NULL) *width = file != NULL ? file->input.width : 0;
    if (height != NULL) *height = file != NULL ? file->input.height : 0;
}

void hbao_exr_set_threads(hbao_exr_file *file, int32_t threads) {
    if (file == NULL) return;
    /* exr_input_read caps it at EXR_MAX_READ_THREADS and at the rows */
    file->input.threads = threads > 0 ? threads : exr_usable_cores();
}

int32_t hbao_exr_channel_count(const hbao_exr_file *file) {
    return file != NULL ? file->input.channels->num_channels : 0;
}

const char *hbao_exr_channel_name(const hbao_exr_file *file, int32_t index) {
    if (file == NULL || index < 0 || index >= file->input.channels->num_channels) return NULL;
    return file->input.channels->entries[index].name.str;
}

int32_t hbao_exr_has_channel(const hbao_exr_file *file, const char *name) {
    return file != NULL && name != NULL && exr_input_find_channel(&file->input, name) >= 0;
}

static int32_t check_request(const hbao_exr_file *file, const hbao_exr_channel_request *requests,
                             int32_t index, char *message, int32_t message_size) {
    const hbao_exr_channel_request *request = &requests[index];
    if (request->name == NULL || request->data == NULL)
        return fail(message, message_size, HBAO_EXR_ERROR_INVALID_ARGUMENT,
                    "request %d has no channel name or no buffer", (int)index);
    if (request->pixel_stride < 1 || request->pixel_stride > MAX_STRIDE_FLOATS ||
        request->row_stride < 1 || request->row_stride > MAX_STRIDE_FLOATS)
        return fail(message, message_size, HBAO_EXR_ERROR_INVALID_ARGUMENT,
                    "channel %s: strides (%d, %lld floats) must be in [1, %lld]", request->name,
                    (int)request->pixel_stride, (long long)request->row_stride,
                    (long long)MAX_STRIDE_FLOATS);
    for (int32_t other = 0; other < index; ++other)
        if (strcmp(requests[other].name, request->name) == 0)
            return fail(message, message_size, HBAO_EXR_ERROR_INVALID_ARGUMENT,
                        "channel %s is requested twice", request->name);
    if (!hbao_exr_has_channel(file, request->name))
        return fail(message, message_size, HBAO_EXR_ERROR_MISSING_CHANNEL,
                    "%s: no channel named %s", file->path, request->name);
    return HBAO_EXR_SUCCESS;
}

int32_t hbao_exr_read_channels(hbao_exr_file *file, const hbao_exr_channel_request *requests,
                               int32_t count, char *message, int32_t message_size) {
    if (file == NULL || count < 0 || (count > 0 && requests == NULL))
        return fail(message, message_size, HBAO_EXR_ERROR_INVALID_ARGUMENT,
                    "hbao_exr_read_channels: no file, or no requests for count %d", (int)count);
    for (int32_t r = 0; r < count; ++r) {
        int32_t checked = check_request(file, requests, r, message, message_size);
        if (checked != HBAO_EXR_SUCCESS) return checked;
    }
    if (count == 0) return HBAO_EXR_SUCCESS;
    exr_channel_request *reader_requests = calloc((size_t)count, sizeof *reader_requests);
    if (reader_requests == NULL)
        return fail(message, message_size, HBAO_EXR_ERROR_OUT_OF_MEMORY, "%s: out of memory",
                    file->path);
    for (int32_t r = 0; r < count; ++r) {
        reader_requests[r].name = requests[r].name;
        reader_requests[r].type = EXR_PIXEL_FLOAT;
        reader_requests[r].data = (uint8_t *)requests[r].data;
        reader_requests[r].pixel_stride = requests[r].pixel_stride * (int32_t)sizeof(float);
        reader_requests[r].row_stride = requests[r].row_stride * (int64_t)sizeof(float);
    }
    tool_error error = {{0}};
    int status = exr_input_read(&file->input, reader_requests, count, &error);
    free(reader_requests);
    if (status != TOOL_EXIT_SUCCESS) {
        copy_message(message, message_size, error.message);
        return HBAO_EXR_ERROR_FORMAT;
    }
    return HBAO_EXR_SUCCESS;
}

int32_t hbao_exr_read_channel(hbao_exr_file *file, const char *name, float *out,
                              int32_t pixel_stride, int64_t row_stride, char *message,
                              int32_t message_size) {
    hbao_exr_channel_request request = {name, out, pixel_stride, row_stride};
    return hbao_exr_read_channels(file, &request, 1, message, message_size);
}

void hbao_exr_close(hbao_exr_file **file) {
    if (file == NULL || *file == NULL) return;
    exr_input_close(&(*file)->input);
    free((*file)->path);
    free(*file);
    *file = NULL;
}
