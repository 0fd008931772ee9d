/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "exr_writer.h"

#include <errno.h>
#include <string.h>
#include <unistd.h>

#include "exr_reader.h"

/* OpenEXRCore writes through this callback so that the tool decides where
 * the bytes go (an atomic_file's temporary file). */
static int64_t write_to_descriptor(exr_const_context_t context, void *user_data, const void *buffer,
                                   uint64_t size, uint64_t offset,
                                   exr_stream_error_func_ptr_t error_callback) {
    const int fd = *(const int *)user_data;
    const uint8_t *bytes = buffer;
    uint64_t done = 0;
    while (done < size) {
        ssize_t written = pwrite(fd, bytes + done, (size_t)(size - done), (off_t)(offset + done));
        if (written < 0 && errno == EINTR) continue;
        if (written <= 0) {
            error_callback(context, EXR_ERR_WRITE_IO, "write failed: %s",
                           written < 0 ? strerror(errno) : "no space");
            return -1;
        }
        done += (uint64_t)written;
    }
    return (int64_t)done;
}

#define CHECK_EXR(call, what)                                                                      \
    do {                                                                                           \
        exr_result_t check_result_ = (call);                                                       \
        if (check_result_ != EXR_ERR_SUCCESS) {                                                    \
            status = tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: %s: %s (%s)", name,     \
                               what, exr_error_text(check_result_),                                \
                               exr_get_error_code_as_string(check_result_));                       \
            goto fail;                                                                             \
        }                                                                                          \
    } while (0)

static const exr_output_channel *find_channel(const exr_output_channel *channels, int count,
                                              const char *channel_name) {
    for (int c = 0; c < count; ++c)
        if (strcmp(channels[c].name, channel_name) == 0) return &channels[c];
    return NULL;
}

static exr_attr_box2i_t box_from_rect(const pixel_rect *rect) {
    exr_attr_box2i_t box;
    box.min.x = rect->min_x;
    box.min.y = rect->min_y;
    box.max.x = rect->max_x;
    box.max.y = rect->max_y;
    return box;
}

/* Scanlines per chunk for each compression, as the OpenEXR file layout
 * defines them. OpenEXRCore 3.1 computes this only when it writes the header,
 * too late for fix_copied_chunk_count(); exr_write_image() checks the two agree. */
static int32_t lines_per_chunk_for(exr_compression_t compression) {
    switch (compression) {
        case EXR_COMPRESSION_ZIP:
        case EXR_COMPRESSION_PXR24:
            return 16;
        case EXR_COMPRESSION_PIZ:
        case EXR_COMPRESSION_B44:
        case EXR_COMPRESSION_B44A:
        case EXR_COMPRESSION_DWAA:
            return 32;
        case EXR_COMPRESSION_DWAB:
            return 256;
        default:
            return 1; /* none, RLE, ZIPS */
    }
}

/* A multi-part input's part header (Blender 5) carries chunkCount, the number
 * of chunks of that part at its compression. OpenEXRCore writes a copied one
 * unchanged into a single-part file, whose header would then contradict its
 * own offset table (OpenEXR 3.1's readers recompute the count for single-part
 * files, but the file layout says the attribute is the count, and other
 * readers may trust it): it must count this file's chunks. A header without
 * one is left without one. */
static exr_result_t fix_copied_chunk_count(exr_context_t context, int part,
                                           const exr_output_layout *layout) {
    const exr_attribute_t *copied = NULL;
    if (exr_get_attribute_by_name(context, part, "chunkCount", &copied) != EXR_ERR_SUCCESS)
        return EXR_ERR_SUCCESS;
    const int64_t lines = lines_per_chunk_for(layout->compression);
    const int64_t height = (int64_t)layout->data_window.max_y - layout->data_window.min_y + 1;
    return exr_set_chunk_count(context, part, (int32_t)((height + lines - 1) / lines));
}

int exr_write_image(int fd, const char *name, const exr_output_layout *layout,
                    const exr_output_channel *channels, int count, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    int descriptor = fd;
    exr_context_t context = NULL;
    exr_encode_pipeline_t encoder = EXR_ENCODE_PIPELINE_INITIALIZER;
    int encoder_ready = 0;
    exr_clear_last_error();

    exr_context_initializer_t initializer = exr_quiet_initializer();
    initializer.user_data = &descriptor;
    initializer.write_fn = write_to_descriptor;
    CHECK_EXR(exr_start_write(&context, name, EXR_WRITE_FILE_DIRECTLY, &initializer),
              "cannot start");
    /* Blender writes names longer than the classic 31 characters (view
     * layer names, its render-stat attributes); allow them, as Blender does. */
    CHECK_EXR(exr_set_longname_support(context, 1), "cannot enable long names");
    int part = 0;
    CHECK_EXR(exr_add_part(context, NULL, EXR_STORAGE_SCANLINE, &part), "cannot add a part");
    exr_attr_box2i_t display_window = box_from_rect(&layout->display_window);
    exr_attr_box2i_t data_window = box_from_rect(&layout->data_window);
    CHECK_EXR(exr_initialize_required_attr(
                  context, part, &display_window, &data_window, layout->pixel_aspect_ratio,
                  &layout->screen_window_center, layout->screen_window_width,
                  EXR_LINEORDER_INCREASING_Y, layout->compression),
              "bad header");
    for (int c = 0; c < count; ++c) {
        CHECK_EXR(exr_add_channel(context, part, channels[c].name, channels[c].type,
                                  channels[c].perceptual, 1, 1),
                  "cannot add a channel");
    }
    if (layout->stamp_name != NULL)
        CHECK_EXR(exr_attr_set_string(context, part, layout->stamp_name, layout->stamp_text),
                  "cannot add the settings attribute");
    if (layout->copy_attributes_from != NULL) {
        CHECK_EXR(exr_copy_unset_attributes(context, part, layout->copy_attributes_from, 0),
                  "cannot copy the input's header attributes");
        CHECK_EXR(fix_copied_chunk_count(context, part, layout), "cannot set the chunk count");
    }
    CHECK_EXR(exr_write_header(context), "cannot write the header");

    int32_t lines_per_chunk = 0;
    CHECK_EXR(exr_get_scanlines_per_chunk(context, part, &lines_per_chunk), "no chunk layout");
    if (lines_per_chunk != lines_per_chunk_for(layout->compression)) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME,
                           "cannot write %s: internal: %s compression has %d scanlines per "
                           "chunk, not %d",
                           name, exr_compression_name(layout->compression), lines_per_chunk,
                           lines_per_chunk_for(layout->compression));
        goto fail;
    }
    const pixel_rect *window = &layout->data_window;
    for (int64_t y = window->min_y; y <= window->max_y; y += lines_per_chunk) {
        exr_chunk_info_t chunk;
        CHECK_EXR(exr_write_scanline_chunk_info(context, part, (int)y, &chunk),
                  "cannot start a chunk");
        if (!encoder_ready) {
            CHECK_EXR(exr_encoding_initialize(context, part, &chunk, &encoder),
                      "cannot start encoding");
            encoder_ready = 1;
        } else {
            CHECK_EXR(exr_encoding_update(context, part, &chunk, &encoder),
                      "cannot encode a chunk");
        }
        const int64_t first_row = chunk.start_y - window->min_y;
        for (int c = 0; c < encoder.channel_count; ++c) {
            exr_coding_channel_info_t *channel = &encoder.channels[c];
            const exr_output_channel *source = find_channel(channels, count, channel->channel_name);
            if (source == NULL) {
                status = tool_fail(error, TOOL_EXIT_RUNTIME, "internal: no data for channel %s",
                                   channel->channel_name);
                goto fail;
            }
            channel->encode_from_ptr = source->data + first_row * source->row_stride;
            channel->user_pixel_stride = source->pixel_stride;
            channel->user_line_stride = (int32_t)source->row_stride;
            channel->user_data_type = (uint16_t)source->type;
            channel->user_bytes_per_element = (int16_t)exr_pixel_type_size(source->type);
        }
        CHECK_EXR(exr_encoding_choose_default_routines(context, part, &encoder),
                  "cannot encode this channel layout");
        CHECK_EXR(exr_encoding_run(context, part, &encoder), "cannot encode a chunk");
    }
    CHECK_EXR(exr_encoding_destroy(context, &encoder), "cannot finish encoding");
    encoder_ready = 0;
    CHECK_EXR(exr_finish(&context), "cannot finish the file");
    return TOOL_EXIT_SUCCESS;

fail:
    if (encoder_ready) exr_encoding_destroy(context, &encoder);
    if (context != NULL) exr_finish(&context);
    return status;
}
