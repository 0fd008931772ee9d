/* SPDX-License-Identifier: GPL-2.0-or-later */
/**
 * @file hbao_exr.h
 * libhbao_exr: reads the channels of an OpenEXR file (such as the multilayer
 * EXRs Blender writes) as 32-bit floats, through OpenEXRCore. It is the same
 * reader the `hbao` command-line tool uses, packaged for callers that cannot
 * link C, such as the Blender add-on's ctypes binding.
 *
 *     hbao_exr_file *file = NULL;
 *     char message[HBAO_EXR_MESSAGE_SIZE];
 *     if (hbao_exr_open("render.exr", &file, message, sizeof message) != HBAO_EXR_SUCCESS)
 *         fprintf(stderr, "%s\n", message);
 *     int32_t width, height;
 *     hbao_exr_size(file, &width, &height);
 *     float *depth = malloc(sizeof(float) * width * height);
 *     hbao_exr_read_channel(file, "ViewLayer.Depth.Z", depth, 1, width,
 *                           message, sizeof message);
 *     hbao_exr_close(&file);  // file is NULL again
 *
 * Errors are a result code plus a message written into the caller's buffer:
 * the library keeps no global error state. Different files may be used from
 * different threads at the same time; one file is used by one thread at a time.
 */
#ifndef HBAO_EXR_H
#define HBAO_EXR_H

#include <stdint.h>

#if defined(_WIN32)
#if defined(HBAO_EXR_BUILDING_LIBRARY)
#define HBAO_EXR_EXPORT __declspec(dllexport)
#else
#define HBAO_EXR_EXPORT __declspec(dllimport)
#endif
#else
#define HBAO_EXR_EXPORT __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Version of this interface; bumped whenever a signature or struct changes,
 *  so that a binding can refuse a library it was not written for. */
#define HBAO_EXR_INTERFACE_VERSION 2

/** A message buffer of this size holds the library's messages, but for
 *  those that name paths of a thousand bytes or more: they are cut to fit
 *  (never overrun). */
#define HBAO_EXR_MESSAGE_SIZE 1024

/* One list generates the result codes and their messages (see
 * hbao_exr_result_message), so that the two cannot drift apart. */
#define HBAO_EXR_RESULTS(X)                                                                        \
    X(HBAO_EXR_SUCCESS, 0, "success")                                                              \
    X(HBAO_EXR_ERROR_INVALID_ARGUMENT, 1, "invalid argument")                                      \
    X(HBAO_EXR_ERROR_OUT_OF_MEMORY, 2, "out of memory")                                            \
    X(HBAO_EXR_ERROR_FILE_ACCESS, 3, "the file cannot be opened")                                  \
    X(HBAO_EXR_ERROR_FORMAT, 4, "not a readable EXR file, or a corrupt or truncated one")          \
    X(HBAO_EXR_ERROR_MISSING_CHANNEL, 5, "the file has no channel of that name")

#define HBAO_EXR_RESULT_ENUM_ENTRY(name, value, message) name = value,
/** Result codes of the calls that can fail. */
typedef enum hbao_exr_result { HBAO_EXR_RESULTS(HBAO_EXR_RESULT_ENUM_ENTRY) } hbao_exr_result;
#undef HBAO_EXR_RESULT_ENUM_ENTRY

/** An open EXR file. Opaque; created by hbao_exr_open, freed by hbao_exr_close. */
typedef struct hbao_exr_file hbao_exr_file;

/** Where one channel's pixels go: a float image of the file's data-window size. */
typedef struct hbao_exr_channel_request {
    const char *name;     /**< the full channel name, "ViewLayer.Depth.Z" */
    float *data;          /**< receives the data window's top-left pixel */
    int32_t pixel_stride; /**< floats from one pixel to its right neighbour, >= 1 */
    int64_t row_stride;   /**< floats from one row to the row below it, >= 1 */
} hbao_exr_channel_request;

/** HBAO_EXR_INTERFACE_VERSION of the library that is loaded. */
HBAO_EXR_EXPORT int32_t hbao_exr_interface_version(void);

/** sizeof(hbao_exr_channel_request) in the library: a binding compares it with its own. */
HBAO_EXR_EXPORT int32_t hbao_exr_channel_request_size(void);

/** A static, never-NULL description of a result code ("unknown result" for others). */
HBAO_EXR_EXPORT const char *hbao_exr_result_message(int32_t result);

/**
 * Open the EXR at `path` and read its header. The file must have one
 * scanline part, or several (Blender 5's multi-part multilayer EXRs) that
 * share one data and display window and no channel name; channels must not be
 * subsampled, and the data window must be at most HBAO_MAX_IMAGE_SIZE (hbao.h)
 * pixels on each side; any compression OpenEXRCore decodes is accepted. On success *file is a new handle; on
 * failure *file is NULL and `message` (when not NULL, `message_size` > 0)
 * holds a sentence naming the file and the problem, truncated to fit.
 */
HBAO_EXR_EXPORT int32_t hbao_exr_open(const char *path, hbao_exr_file **file, char *message,
                                      int32_t message_size);

/** The data window's size in pixels (0 x 0 for a NULL file). */
HBAO_EXR_EXPORT void hbao_exr_size(const hbao_exr_file *file, int32_t *width, int32_t *height);

/** Number of channels in the file, over all its parts (0 for a NULL file). */
HBAO_EXR_EXPORT int32_t hbao_exr_channel_count(const hbao_exr_file *file);

/** Name of channel `index` in [0, hbao_exr_channel_count), in alphabetical
 *  (strcmp) order over all parts; owned by `file`, valid until it is closed.
 *  NULL when `index` is out of range. */
HBAO_EXR_EXPORT const char *hbao_exr_channel_name(const hbao_exr_file *file, int32_t index);

/** 1 when the file has a channel called `name`, else 0. */
HBAO_EXR_EXPORT int32_t hbao_exr_has_channel(const hbao_exr_file *file, const char *name);

/** The threads hbao_exr_read_channels decodes `file` with, each taking a band
 *  of rows: 0 (or less), the default, is one per core; more than 16 is 16.
 *  The values read are the same for any number. Ignored for a NULL file. */
HBAO_EXR_EXPORT void hbao_exr_set_threads(hbao_exr_file *file, int32_t threads);

/**
 * Decode the `count` requested channels (each name at most once, each must
 * exist) for the whole data window in one pass over the file's chunks, as
 * floats (half and uint channels are converted), top row first whatever the
 * file's line order. Request i writes pixel (x, y) to
 * requests[i].data[y * row_stride + x * pixel_stride]; the caller allocates
 * that memory. Strides are positive and at most INT32_MAX / 4 floats.
 * Channels may interleave in one buffer (data + k, pixel_stride n). On
 * failure the buffers' contents are unspecified and `message` says why.
 */
HBAO_EXR_EXPORT int32_t hbao_exr_read_channels(hbao_exr_file *file,
                                               const hbao_exr_channel_request *requests,
                                               int32_t count, char *message, int32_t message_size);

/** hbao_exr_read_channels for a single channel. */
HBAO_EXR_EXPORT int32_t hbao_exr_read_channel(hbao_exr_file *file, const char *name, float *out,
                                              int32_t pixel_stride, int64_t row_stride,
                                              char *message, int32_t message_size);

/** Close the file and set *file to NULL. NULL or an already closed handle is fine. */
HBAO_EXR_EXPORT void hbao_exr_close(hbao_exr_file **file);

#ifdef __cplusplus
}
#endif

#endif /* HBAO_EXR_H */
