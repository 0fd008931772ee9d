/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "exr_writer.h"

#include <errno.h>
#include <libdeflate.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "exr_reader.h"
#include "zip_chunks.h"

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

/* The message of a failed OpenEXRCore call while writing `name`: one
 * wording for the header's calls (CHECK_EXR) and the chunks' (CHUNK_CHECK). */
static int write_failure(tool_error *error, const char *name, const char *what,
                         exr_result_t result) {
    return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: %s: %s (%s)", name, what,
                     exr_error_text(result), exr_get_error_code_as_string(result));
}

#define CHECK_EXR(call, what)                                                                      \
    do {                                                                                           \
        exr_result_t check_result_ = (call);                                                       \
        if (check_result_ != EXR_ERR_SUCCESS) {                                                    \
            status = write_failure(error, name, what, check_result_);                              \
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

/* The input's attributes of types OpenEXRCore does not know (opaque: a
 * studio's own type), copied as their bytes, before
 * exr_copy_unset_attributes, which refuses them (3.1.5: "the opaque type is
 * not actually a built-in type") but leaves attributes already set alone: a
 * valid render with one failed --keep-input after its whole AO was
 * computed (a review's find). */
static exr_result_t copy_opaque_attributes(exr_context_t context, int part,
                                           exr_const_context_t source) {
    int32_t count = 0;
    exr_result_t result = exr_get_attribute_count(source, 0, &count);
    for (int32_t i = 0; i < count && result == EXR_ERR_SUCCESS; ++i) {
        const exr_attribute_t *attribute = NULL;
        result = exr_get_attribute_by_index(source, 0, EXR_ATTR_LIST_FILE_ORDER, i, &attribute);
        if (result != EXR_ERR_SUCCESS || attribute->type != EXR_ATTR_OPAQUE) continue;
        const char *type = NULL;
        int32_t size = 0;
        const void *bytes = NULL;
        result = exr_attr_get_user(source, 0, attribute->name, &type, &size, &bytes);
        if (result != EXR_ERR_SUCCESS) continue;
        /* one of no bytes cannot be copied: exr_attr_set_user's allocation
         * of no bytes is never freed, and one declared without bytes cannot
         * be written (OpenEXRCore 3.1.5; a fuzzer's find): refused, as the
         * copy below refuses every opaque one */
        result = size > 0 ? exr_attr_set_user(context, part, attribute->name, type, size, bytes)
                          : EXR_ERR_ATTR_SIZE_MISMATCH;
    }
    return result;
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

/* The chunks of the part, encoded (packed and compressed) by up to
 * layout->threads threads and written in file order. A thread claims the
 * next chunk, encodes it, waits in the pipeline's yield_until_ready_fn until
 * every chunk before it is written, and writes it: chunks are claimed in
 * order, so the next one to write is always held by a thread that is not
 * waiting, whichever threads started. The file is the same for any number
 * of threads; the first chunk that fails, from the top, gives the message. */
typedef struct chunk_writing {
    exr_context_t context;
    int part;
    const char *name;
    const pixel_rect *window;
    const exr_output_channel *channels;
    int count;
    int32_t lines_per_chunk;
    exr_compression_t compression; /* the part's, as its header was written */
    int64_t chunks;
    pthread_mutex_t lock;
    pthread_cond_t written; /* next_to_write moved, or a chunk failed */
    int64_t next_to_claim, next_to_write;
    int64_t failed_chunk; /* the first chunk that failed; chunks if none */
    int status;           /* and its message */
    tool_error error;
} chunk_writing;

/* One thread's pipeline; first, so that yield_until_ready_fn and
 * compress_fn find the rest */
typedef struct chunk_encoder {
    exr_encode_pipeline_t pipeline;
    exr_result_t (*library_compress)(exr_encode_pipeline_t *pipeline);
    struct libdeflate_compressor *deflater; /* ZIP and ZIPS (compress_zip) */
    int ready;
    chunk_writing *writing;
    int64_t chunk;
    int cancelled; /* the chunk stopped because one before it failed */
} chunk_encoder;

/* Returns once every chunk before this one is written; an error (which
 * stops this chunk, the file being incomplete anyway) if one failed. */
static exr_result_t wait_for_turn(exr_encode_pipeline_t *pipeline) {
    chunk_encoder *encoder = (chunk_encoder *)pipeline;
    chunk_writing *writing = encoder->writing;
    pthread_mutex_lock(&writing->lock);
    while (writing->next_to_write != encoder->chunk && writing->failed_chunk > encoder->chunk)
        pthread_cond_wait(&writing->written, &writing->lock);
    encoder->cancelled = writing->next_to_write != encoder->chunk;
    pthread_mutex_unlock(&writing->lock);
    return encoder->cancelled ? EXR_ERR_INCORRECT_CHUNK : EXR_ERR_SUCCESS;
}

/* A chunk whose compressed size equals its packed size is read back as
 * stored, uncompressed (the file layout's rule for a compressor that does
 * not pay). OpenEXRCore up to 3.4.7 at least (Debian's 3.1.5 too; its issue
 * 2306) kept its zlib bytes when they came to exactly the packed size, so
 * ZIP and ZIPS wrote such a chunk as garbage: rare and data-dependent (2 of
 * 48 radii on one 320x180 test scene). The packed bytes themselves are then
 * what the chunk must hold, whichever compressor ran. ZIP and ZIPS now go
 * through compress_zip, which stores such a chunk itself; 3.1.5's RLE and
 * PIZ, the other compressions the CLI writes, store a chunk that does not
 * shrink already, and this keeps the rule for them in any version. */
static exr_result_t compress_or_store(exr_encode_pipeline_t *pipeline) {
    chunk_encoder *encoder = (chunk_encoder *)pipeline;
    const exr_result_t result = encoder->library_compress(pipeline);
    if (result == EXR_ERR_SUCCESS && pipeline->compressed_bytes == pipeline->packed_bytes &&
        pipeline->compressed_buffer != pipeline->packed_buffer)
        memcpy(pipeline->compressed_buffer, pipeline->packed_buffer, pipeline->packed_bytes);
    return result;
}

/* The pipeline's buffers come from here (alloc_fn, free_fn), so that
 * compress_zip may size the ones it fills with the same allocator. */
static void *pipeline_alloc(exr_transcoding_pipeline_buffer_id_t buffer, size_t bytes) {
    (void)buffer;
    return malloc(bytes);
}

static void pipeline_free(exr_transcoding_pipeline_buffer_id_t buffer, void *memory) {
    (void)buffer;
    free(memory);
}

/* At least `bytes` in the pipeline's buffer `id` at *memory (of *size bytes;
 * 0: not the pipeline's own, as compressed_buffer aliasing packed_buffer). */
static bool reserve(exr_transcoding_pipeline_buffer_id_t id, void **memory, size_t *size,
                    size_t bytes) {
    if (*memory != NULL && *size >= bytes) return true;
    if (*size > 0) pipeline_free(id, *memory);
    *memory = pipeline_alloc(id, bytes);
    *size = *memory != NULL ? bytes : 0;
    return *memory != NULL;
}

/* ZIP and ZIPS chunks deflated by libdeflate (zip_chunks_compress), in
 * place of OpenEXRCore 3.1's zlib: the same layout, a standard zlib stream
 * that any reader inflates; a chunk that deflate does not make smaller is
 * stored, as compress_or_store makes sure for the library's compressors. */
static exr_result_t compress_zip(exr_encode_pipeline_t *pipeline) {
    chunk_encoder *encoder = (chunk_encoder *)pipeline;
    if (encoder->deflater == NULL)
        encoder->deflater = libdeflate_alloc_compressor(ZIP_CHUNKS_LEVEL);
    if (encoder->deflater == NULL) return EXR_ERR_OUT_OF_MEMORY;
    const size_t count = pipeline->packed_bytes;
    size_t capacity = libdeflate_zlib_compress_bound(encoder->deflater, count);
    if (capacity < count) capacity = count;
    if (!reserve(EXR_TRANSCODE_BUFFER_SCRATCH1, &pipeline->scratch_buffer_1,
                 &pipeline->scratch_alloc_size_1, count) ||
        !reserve(EXR_TRANSCODE_BUFFER_COMPRESSED, &pipeline->compressed_buffer,
                 &pipeline->compressed_alloc_size, capacity))
        return EXR_ERR_OUT_OF_MEMORY;
    pipeline->compressed_bytes = zip_chunks_compress(
        encoder->deflater, pipeline->packed_buffer, count, pipeline->scratch_buffer_1,
        pipeline->compressed_buffer, pipeline->compressed_alloc_size);
    return EXR_ERR_SUCCESS;
}

#define CHUNK_CHECK(call, what)                                                                    \
    do {                                                                                           \
        exr_result_t check_result_ = (call);                                                       \
        if (check_result_ != EXR_ERR_SUCCESS)                                                      \
            return write_failure(error, writing->name, what, check_result_);                       \
    } while (0)

/* Encodes and writes chunk `encoder->chunk` with the encoder's pipeline. */
static int write_chunk(chunk_writing *writing, chunk_encoder *encoder, int ordered,
                       tool_error *error) {
    const int64_t y = writing->window->min_y + encoder->chunk * writing->lines_per_chunk;
    exr_chunk_info_t chunk;
    CHUNK_CHECK(exr_write_scanline_chunk_info(writing->context, writing->part, (int)y, &chunk),
                "cannot start a chunk");
    exr_encode_pipeline_t *pipeline = &encoder->pipeline;
    if (!encoder->ready) {
        CHUNK_CHECK(exr_encoding_initialize(writing->context, writing->part, &chunk, pipeline),
                    "cannot start encoding");
        pipeline->alloc_fn = pipeline_alloc;
        pipeline->free_fn = pipeline_free;
        encoder->ready = 1;
    } else {
        CHUNK_CHECK(exr_encoding_update(writing->context, writing->part, &chunk, pipeline),
                    "cannot encode a chunk");
    }
    const int64_t first_row = chunk.start_y - writing->window->min_y;
    for (int c = 0; c < pipeline->channel_count; ++c) {
        exr_coding_channel_info_t *channel = &pipeline->channels[c];
        const exr_output_channel *source =
            find_channel(writing->channels, writing->count, channel->channel_name);
        if (source == NULL)
            return tool_fail(error, TOOL_EXIT_RUNTIME, "internal: no data for channel %s",
                             channel->channel_name);
        channel->encode_from_ptr = source->data + first_row * source->row_stride;
        channel->user_pixel_stride = source->pixel_stride;
        channel->user_line_stride = (int32_t)source->row_stride;
        channel->user_data_type = (uint16_t)source->type;
        channel->user_bytes_per_element = (int16_t)exr_pixel_type_size(source->type);
    }
    CHUNK_CHECK(exr_encoding_choose_default_routines(writing->context, writing->part, pipeline),
                "cannot encode this channel layout");
    if (writing->compression == EXR_COMPRESSION_ZIP ||
        writing->compression == EXR_COMPRESSION_ZIPS) {
        pipeline->compress_fn = compress_zip;
    } else if (pipeline->compress_fn != NULL) {
        encoder->library_compress = pipeline->compress_fn;
        pipeline->compress_fn = compress_or_store;
    }
    if (ordered) pipeline->yield_until_ready_fn = wait_for_turn;
    CHUNK_CHECK(exr_encoding_run(writing->context, writing->part, pipeline),
                "cannot encode a chunk");
    return TOOL_EXIT_SUCCESS;
}

static int finish_encoder(chunk_writing *writing, chunk_encoder *encoder, tool_error *error) {
    libdeflate_free_compressor(encoder->deflater);
    encoder->deflater = NULL;
    if (!encoder->ready) return TOOL_EXIT_SUCCESS;
    encoder->ready = 0;
    CHUNK_CHECK(exr_encoding_destroy(writing->context, &encoder->pipeline),
                "cannot finish encoding");
    return TOOL_EXIT_SUCCESS;
}

static void *write_chunks(void *argument) {
    chunk_writing *writing = argument;
    exr_clear_last_error(); /* this thread's copy of OpenEXRCore's detail */
    chunk_encoder encoder = {EXR_ENCODE_PIPELINE_INITIALIZER, NULL, NULL, 0, writing, 0, 0};
    tool_error error;
    for (;;) {
        pthread_mutex_lock(&writing->lock);
        encoder.chunk = writing->next_to_claim++;
        const int stop = encoder.chunk >= writing->failed_chunk; /* chunks if none failed */
        pthread_mutex_unlock(&writing->lock);
        if (stop) break;
        encoder.cancelled = 0;
        const int status = write_chunk(writing, &encoder, 1, &error);
        pthread_mutex_lock(&writing->lock);
        if (status == TOOL_EXIT_SUCCESS) {
            writing->next_to_write = encoder.chunk + 1;
        } else if (!encoder.cancelled && encoder.chunk < writing->failed_chunk) {
            writing->failed_chunk = encoder.chunk;
            writing->status = status;
            writing->error = error;
        }
        pthread_cond_broadcast(&writing->written);
        pthread_mutex_unlock(&writing->lock);
    }
    finish_encoder(writing, &encoder, &error);
    return NULL;
}

/* The part's data, chunk by chunk, with up to `threads` threads. */
static int write_data(chunk_writing *writing, int threads, tool_error *error) {
    if (threads > EXR_MAX_WRITE_THREADS) threads = EXR_MAX_WRITE_THREADS;
    if (threads > writing->chunks) threads = (int)writing->chunks;
    if (threads <= 1 || writing->compression == EXR_COMPRESSION_NONE) {
        /* one pipeline, OpenEXRCore's own order check */
        chunk_encoder encoder = {EXR_ENCODE_PIPELINE_INITIALIZER, NULL, NULL, 0, writing, 0, 0};
        int status = TOOL_EXIT_SUCCESS;
        for (; encoder.chunk < writing->chunks && status == TOOL_EXIT_SUCCESS; ++encoder.chunk)
            status = write_chunk(writing, &encoder, 0, error);
        tool_error finish_error;
        const int finished = finish_encoder(writing, &encoder, &finish_error);
        if (status == TOOL_EXIT_SUCCESS && finished != TOOL_EXIT_SUCCESS) {
            *error = finish_error;
            status = finished;
        }
        return status;
    }
    writing->next_to_claim = writing->next_to_write = 0;
    writing->failed_chunk = writing->chunks;
    writing->status = TOOL_EXIT_SUCCESS;
    if (pthread_mutex_init(&writing->lock, NULL) != 0)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: no lock", writing->name);
    if (pthread_cond_init(&writing->written, NULL) != 0) {
        pthread_mutex_destroy(&writing->lock);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: no lock", writing->name);
    }
    pthread_t workers[EXR_MAX_WRITE_THREADS];
    bool started[EXR_MAX_WRITE_THREADS] = {false};
    for (int t = 1; t < threads; ++t)
        started[t] = pthread_create(&workers[t], NULL, write_chunks, writing) == 0;
    write_chunks(writing); /* the calling thread takes part; enough alone */
    for (int t = 1; t < threads; ++t)
        if (started[t]) pthread_join(workers[t], NULL);
    pthread_cond_destroy(&writing->written);
    pthread_mutex_destroy(&writing->lock);
    if (writing->failed_chunk < writing->chunks) {
        *error = writing->error;
        return writing->status;
    }
    return TOOL_EXIT_SUCCESS;
}

int exr_write_image(int fd, const char *name, const exr_output_layout *layout,
                    const exr_output_channel *channels, int count, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    int descriptor = fd;
    exr_context_t context = NULL;
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
        CHECK_EXR(copy_opaque_attributes(context, part, layout->copy_attributes_from),
                  "cannot copy the input's header attributes");
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
    chunk_writing writing;
    writing.context = context;
    writing.part = part;
    writing.name = name;
    writing.window = &layout->data_window;
    writing.channels = channels;
    writing.count = count;
    writing.lines_per_chunk = lines_per_chunk;
    writing.compression = layout->compression;
    writing.chunks =
        ((int64_t)layout->data_window.max_y - layout->data_window.min_y + lines_per_chunk) /
        lines_per_chunk;
    status = write_data(&writing, layout->threads, error);
    if (status != TOOL_EXIT_SUCCESS) goto fail;
    CHECK_EXR(exr_finish(&context), "cannot finish the file");
    return TOOL_EXIT_SUCCESS;

fail:
    if (context != NULL) exr_finish(&context);
    return status;
}
