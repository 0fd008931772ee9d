/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "exr_reader.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "hbao.h"

/* OpenEXRCore reports details (which attribute is bad, which chunk is
 * corrupt) through a callback rather than the result code. The callback runs
 * in the thread that made the failing call, so one buffer per thread keeps
 * libhbao_exr (which shares this reader) safe for callers in several threads. */
static _Thread_local char last_error_message[512];

static void keep_error_message(exr_const_context_t context, exr_result_t code,
                               const char *message)
{
    (void)context;
    (void)code;
    snprintf(last_error_message, sizeof last_error_message, "%s", message ? message : "");
}

void exr_clear_last_error(void) { last_error_message[0] = '\0'; }

const char *exr_error_text(exr_result_t result)
{
    if (last_error_message[0] != '\0') return last_error_message;
    return exr_get_default_error_message(result);
}

exr_context_initializer_t exr_quiet_initializer(void)
{
    exr_context_initializer_t initializer = EXR_DEFAULT_CONTEXT_INITIALIZER;
    initializer.error_handler_fn = keep_error_message;
    /* Let OpenEXRCore refuse absurd sizes in a corrupt header before anyone
     * allocates for them: hbao cannot process larger images anyway. */
    initializer.max_image_width = HBAO_MAX_IMAGE_SIZE;
    initializer.max_image_height = HBAO_MAX_IMAGE_SIZE;
    return initializer;
}

int exr_pixel_type_size(exr_pixel_type_t type) { return type == EXR_PIXEL_HALF ? 2 : 4; }

const char *exr_pixel_type_name(exr_pixel_type_t type)
{
    switch (type) {
    case EXR_PIXEL_HALF: return "half";
    case EXR_PIXEL_FLOAT: return "float";
    case EXR_PIXEL_UINT: return "uint";
    default: return "unknown";
    }
}

const char *exr_compression_name(exr_compression_t compression)
{
    static const char *const names[] = {"none", "rle",   "zips", "zip",  "piz",
                                        "pxr24", "b44", "b44a", "dwaa", "dwab"};
    if ((int)compression >= 0 && compression < EXR_COMPRESSION_LAST_TYPE)
        return names[compression];
    return "unknown";
}

#define CHECK_EXR(call, what)                                                                   \
    do {                                                                                        \
        exr_result_t check_result_ = (call);                                                    \
        if (check_result_ != EXR_ERR_SUCCESS) {                                                 \
            status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: %s: %s (%s)", input->path, what,  \
                               exr_error_text(check_result_),                                   \
                               exr_get_error_code_as_string(check_result_));                    \
            goto fail;                                                                          \
        }                                                                                       \
    } while (0)

static pixel_rect rect_from_box(const exr_attr_box2i_t *box)
{
    pixel_rect rect = {box->min.x, box->min.y, box->max.x, box->max.y};
    return rect;
}

/* The chunk that holds scanline y, checked against the data window: chunks
 * start at the window's top and follow each other; one that does not (a
 * corrupt offset table) would send the decoder's copy outside the buffers.
 * Its bytes must lie inside the file, whose size is file_size. */
static int read_chunk_info(exr_input *input, int64_t y, int64_t file_size,
                           exr_chunk_info_t *chunk, tool_error *error)
{
    int status = TOOL_EXIT_SUCCESS;
    CHECK_EXR(exr_read_scanline_chunk_info(input->context, 0, (int)y, chunk),
              "cannot read a chunk (file truncated or corrupt?)");
    const pixel_rect *window = &input->data_window;
    if (chunk->start_y != y || chunk->height < 1 || chunk->height > input->lines_per_chunk ||
        chunk->width != input->width ||
        (int64_t)chunk->start_y + chunk->height - 1 > window->max_y ||
        chunk->data_offset > (uint64_t)file_size ||
        chunk->packed_size > (uint64_t)file_size - chunk->data_offset)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: corrupt chunk at scanline %lld",
                         input->path, (long long)y);
fail:
    return status;
}

/* Every chunk the data window needs, read before anything is allocated for
 * the image: a header claiming a huge image in a small file fails here (its
 * chunk table or its chunks do not fit in the file). The chunk table itself
 * is 8 bytes per chunk, which OpenEXRCore checks against the file size. */
static int check_chunks(exr_input *input, tool_error *error)
{
    int status = TOOL_EXIT_SUCCESS;
    struct stat file_status;
    if (stat(input->path, &file_status) != 0)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: cannot read its size", input->path);
    CHECK_EXR(exr_get_scanlines_per_chunk(input->context, 0, &input->lines_per_chunk),
              "cannot read the chunk layout");
    if (input->lines_per_chunk < 1)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: invalid scanlines per chunk (%d)",
                         input->path, input->lines_per_chunk);
    const pixel_rect *window = &input->data_window;
    for (int64_t y = window->min_y; y <= window->max_y; y += input->lines_per_chunk) {
        exr_chunk_info_t chunk;
        status = read_chunk_info(input, y, (int64_t)file_status.st_size, &chunk, error);
        if (status != TOOL_EXIT_SUCCESS) {
            char detail[TOOL_ERROR_MESSAGE_SIZE];
            snprintf(detail, sizeof detail, "%s", error->message);
            return tool_fail(error, status,
                             "%s: the header claims a %dx%d image, which this %lld-byte file "
                             "does not hold (%s)",
                             input->path, input->width, input->height,
                             (long long)file_status.st_size, detail);
        }
    }
    input->file_size = (int64_t)file_status.st_size;
fail:
    return status;
}

int exr_input_open(exr_input *input, const char *path, tool_error *error)
{
    memset(input, 0, sizeof *input);
    input->path = path;
    exr_clear_last_error();
    exr_context_initializer_t initializer = exr_quiet_initializer();
    int status = TOOL_EXIT_SUCCESS;
    exr_result_t opened = exr_start_read(&input->context, path, &initializer);
    if (opened != EXR_ERR_SUCCESS) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: not a readable EXR file: %s (%s)", path,
                           exr_error_text(opened), exr_get_error_code_as_string(opened));
        goto fail;
    }

    int part_count = 0;
    CHECK_EXR(exr_get_count(input->context, &part_count), "cannot count parts");
    if (part_count != 1) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME,
                           "%s: has %d parts; only single-part EXR files (as Blender writes) "
                           "are supported",
                           path, part_count);
        goto fail;
    }
    exr_storage_t storage;
    CHECK_EXR(exr_get_storage(input->context, 0, &storage), "cannot read the storage type");
    if (storage != EXR_STORAGE_SCANLINE) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME,
                           "%s: only scanline images are supported (this one is %s)", path,
                           storage == EXR_STORAGE_TILED ? "tiled" : "deep");
        goto fail;
    }

    exr_attr_box2i_t data_window, display_window;
    CHECK_EXR(exr_get_data_window(input->context, 0, &data_window), "no data window");
    CHECK_EXR(exr_get_display_window(input->context, 0, &display_window), "no display window");
    input->data_window = rect_from_box(&data_window);
    input->display_window = rect_from_box(&display_window);
    int64_t width = (int64_t)data_window.max.x - data_window.min.x + 1;
    int64_t height = (int64_t)data_window.max.y - data_window.min.y + 1;
    if (width < 1 || height < 1 || width > HBAO_MAX_IMAGE_SIZE || height > HBAO_MAX_IMAGE_SIZE) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME,
                           "%s: data window is %lldx%lld; width and height must be in [1, %d]",
                           path, (long long)width, (long long)height, HBAO_MAX_IMAGE_SIZE);
        goto fail;
    }
    input->width = (int32_t)width;
    input->height = (int32_t)height;

    CHECK_EXR(exr_get_compression(input->context, 0, &input->compression), "no compression");
    CHECK_EXR(exr_get_lineorder(input->context, 0, &input->line_order), "no line order");
    input->pixel_aspect_ratio = 1.0f;
    input->has_pixel_aspect_ratio =
        exr_get_pixel_aspect_ratio(input->context, 0, &input->pixel_aspect_ratio) ==
        EXR_ERR_SUCCESS;
    if (!input->has_pixel_aspect_ratio) input->pixel_aspect_ratio = 1.0f;
    if (exr_get_screen_window_center(input->context, 0, &input->screen_window_center) !=
        EXR_ERR_SUCCESS) {
        input->screen_window_center.x = 0.0f;
        input->screen_window_center.y = 0.0f;
    }
    if (exr_get_screen_window_width(input->context, 0, &input->screen_window_width) !=
        EXR_ERR_SUCCESS)
        input->screen_window_width = 1.0f;

    CHECK_EXR(exr_get_channels(input->context, 0, &input->channels), "no channel list");
    if (input->channels == NULL || input->channels->num_channels < 1) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: has no channels", path);
        goto fail;
    }
    for (int c = 0; c < input->channels->num_channels; ++c) {
        const exr_attr_chlist_entry_t *channel = &input->channels->entries[c];
        if (channel->x_sampling != 1 || channel->y_sampling != 1) {
            status = tool_fail(error, TOOL_EXIT_RUNTIME,
                               "%s: channel %s is subsampled; subsampled channels are not "
                               "supported",
                               path, channel->name.str);
            goto fail;
        }
    }
    status = check_chunks(input, error);
    if (status != TOOL_EXIT_SUCCESS) goto fail;
    return TOOL_EXIT_SUCCESS;

fail:
    exr_input_close(input);
    return status;
}

int exr_input_find_channel(const exr_input *input, const char *name)
{
    for (int c = 0; c < input->channels->num_channels; ++c)
        if (strcmp(input->channels->entries[c].name.str, name) == 0) return c;
    return -1;
}

static const exr_channel_request *find_request(const exr_channel_request *requests, int count,
                                               const char *name)
{
    for (int r = 0; r < count; ++r)
        if (strcmp(requests[r].name, name) == 0) return &requests[r];
    return NULL;
}

int exr_input_read(exr_input *input, const exr_channel_request *requests, int count,
                   tool_error *error)
{
    int status = TOOL_EXIT_SUCCESS;
    exr_decode_pipeline_t decoder = EXR_DECODE_PIPELINE_INITIALIZER;
    bool decoder_ready = false;
    exr_clear_last_error();
    for (int r = 0; r < count; ++r) {
        if (exr_input_find_channel(input, requests[r].name) < 0)
            return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: no channel named %s", input->path,
                             requests[r].name);
    }

    const pixel_rect *window = &input->data_window;
    for (int64_t y = window->min_y; y <= window->max_y; y += input->lines_per_chunk) {
        exr_chunk_info_t chunk;
        status = read_chunk_info(input, y, input->file_size, &chunk, error);
        if (status != TOOL_EXIT_SUCCESS) goto fail;
        if (!decoder_ready) {
            CHECK_EXR(exr_decoding_initialize(input->context, 0, &chunk, &decoder),
                      "cannot start decoding");
            decoder_ready = true;
        } else {
            CHECK_EXR(exr_decoding_update(input->context, 0, &chunk, &decoder),
                      "cannot decode a chunk");
        }
        const int64_t first_row = chunk.start_y - window->min_y;
        for (int c = 0; c < decoder.channel_count; ++c) {
            exr_coding_channel_info_t *channel = &decoder.channels[c];
            const exr_channel_request *request =
                find_request(requests, count, channel->channel_name);
            if (request == NULL) {
                channel->decode_to_ptr = NULL;
                continue;
            }
            channel->decode_to_ptr = request->data + first_row * request->row_stride;
            channel->user_pixel_stride = request->pixel_stride;
            channel->user_line_stride = (int32_t)request->row_stride;
            channel->user_data_type = (uint16_t)request->type;
            channel->user_bytes_per_element = (int16_t)exr_pixel_type_size(request->type);
        }
        CHECK_EXR(exr_decoding_choose_default_routines(input->context, 0, &decoder),
                  "cannot decode this channel layout");
        exr_result_t decoded = exr_decoding_run(input->context, 0, &decoder);
        if (decoded == EXR_ERR_FEATURE_NOT_IMPLEMENTED) {
            /* OpenEXRCore 3.1 cannot decompress DWAA/DWAB. */
            status = tool_fail(error, TOOL_EXIT_RUNTIME,
                               "%s: this OpenEXR library cannot decode %s compression; save "
                               "the EXR with ZIP, PIZ or no compression",
                               input->path, exr_compression_name(input->compression));
            goto fail;
        }
        CHECK_EXR(decoded, "cannot decode a chunk (file truncated or corrupt?)");
    }

fail:
    if (decoder_ready) exr_decoding_destroy(input->context, &decoder);
    return status;
}

void exr_input_close(exr_input *input)
{
    if (input->context != NULL) exr_finish(&input->context);
    input->context = NULL;
    input->channels = NULL;
}
