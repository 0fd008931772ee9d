/* SPDX-License-Identifier: GPL-2.0-or-later */
#if defined(__linux__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE /* hbao_cpus.h: sched_getaffinity */
#endif
#include "exr_reader.h"

#include <limits.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "exr_stream.h"
#include "hbao.h"
#include "hbao_cpus.h"

/* OpenEXRCore reports details (which attribute is bad, which chunk is
 * corrupt) through a callback rather than the result code. The callback runs
 * in the thread that made the failing call, so one buffer per thread keeps
 * libhbao_exr (which shares this reader) safe for callers in several threads. */
static _Thread_local char last_error_message[512];

static void keep_error_message(exr_const_context_t context, exr_result_t code,
                               const char *message) {
    (void)context;
    (void)code;
    snprintf(last_error_message, sizeof last_error_message, "%s", message ? message : "");
}

void exr_clear_last_error(void) {
    last_error_message[0] = '\0';
}

const char *exr_error_text(exr_result_t result) {
    if (last_error_message[0] != '\0') return last_error_message;
    return exr_get_default_error_message(result);
}

exr_context_initializer_t exr_quiet_initializer(void) {
    exr_context_initializer_t initializer = EXR_DEFAULT_CONTEXT_INITIALIZER;
    initializer.error_handler_fn = keep_error_message;
    /* Let OpenEXRCore refuse absurd sizes in a corrupt header before anyone
     * allocates for them: hbao cannot process larger images anyway. */
    initializer.max_image_width = HBAO_MAX_IMAGE_SIZE;
    initializer.max_image_height = HBAO_MAX_IMAGE_SIZE;
    return initializer;
}

int exr_pixel_type_size(exr_pixel_type_t type) {
    return type == EXR_PIXEL_HALF ? 2 : 4;
}

const char *exr_pixel_type_name(exr_pixel_type_t type) {
    switch (type) {
        case EXR_PIXEL_HALF:
            return "half";
        case EXR_PIXEL_FLOAT:
            return "float";
        case EXR_PIXEL_UINT:
            return "uint";
        default:
            return "unknown";
    }
}

const char *exr_compression_name(exr_compression_t compression) {
    static const char *const names[] = {"none",  "rle", "zips", "zip",  "piz",
                                        "pxr24", "b44", "b44a", "dwaa", "dwab"};
    if ((int)compression >= 0 && compression < EXR_COMPRESSION_LAST_TYPE) return names[compression];
    return "unknown";
}

#define CHECK_EXR(call, what)                                                                      \
    do {                                                                                           \
        exr_result_t check_result_ = (call);                                                       \
        if (check_result_ != EXR_ERR_SUCCESS) {                                                    \
            status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: %s: %s (%s)", input->path, what,     \
                               exr_error_text(check_result_),                                      \
                               exr_get_error_code_as_string(check_result_));                       \
            goto fail;                                                                             \
        }                                                                                          \
    } while (0)

static pixel_rect rect_from_box(const exr_attr_box2i_t *box) {
    pixel_rect rect = {box->min.x, box->min.y, box->max.x, box->max.y};
    return rect;
}

/* A part's name for messages: Blender names each part after its pass
 * ("ViewLayer.Depth"); a single-part file usually has none. */
static const char *part_name(const exr_input *input, int part) {
    const char *name = NULL;
    if (exr_get_name(input->context, part, &name) != EXR_ERR_SUCCESS || name == NULL)
        return "unnamed";
    return name;
}

/* The view a part holds (its "view" attribute: a multi-view file), or NULL. */
static const char *part_view(const exr_input *input, int part) {
    const char *view = NULL;
    int32_t length = 0;
    if (exr_attr_get_string(input->context, part, "view", &length, &view) != EXR_ERR_SUCCESS ||
        view == NULL || length <= 0)
        return NULL;
    return view;
}

static bool same_box(const exr_attr_box2i_t *a, const exr_attr_box2i_t *b) {
    return a->min.x == b->min.x && a->min.y == b->min.y && a->max.x == b->max.x &&
           a->max.y == b->max.y;
}

/* The image is one rectangle of pixels: every part must cover exactly the
 * same one (Blender 5 writes all passes with the render's windows), or the
 * passes would not line up pixel for pixel. */
static int check_part_windows(exr_input *input, const exr_attr_box2i_t *data_window,
                              const exr_attr_box2i_t *display_window, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    for (int part = 1; part < input->part_count; ++part) {
        exr_attr_box2i_t part_data, part_display;
        CHECK_EXR(exr_get_data_window(input->context, part, &part_data), "no data window");
        CHECK_EXR(exr_get_display_window(input->context, part, &part_display), "no display window");
        const bool data_differs = !same_box(&part_data, data_window);
        if (data_differs || !same_box(&part_display, display_window)) {
            const exr_attr_box2i_t *theirs = data_differs ? &part_data : &part_display;
            const exr_attr_box2i_t *first = data_differs ? data_window : display_window;
            const char *which = data_differs ? "data" : "display";
            return tool_fail(error, TOOL_EXIT_RUNTIME,
                             "%s: part %d (\"%s\") has %s window (%d, %d) - (%d, %d) but part "
                             "0 has (%d, %d) - (%d, %d); parts with different %s windows are "
                             "not supported",
                             input->path, part, part_name(input, part), which, theirs->min.x,
                             theirs->min.y, theirs->max.x, theirs->max.y, first->min.x,
                             first->min.y, first->max.x, first->max.y, which);
        }
    }
fail:
    return status;
}

/* Scanlines per chunk of `part` (1, 16 or 32 by compression). */
static int part_lines_per_chunk(exr_input *input, int part, int32_t *lines, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    CHECK_EXR(exr_get_scanlines_per_chunk(input->context, part, lines),
              "cannot read the chunk layout");
    if (*lines < 1)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: invalid scanlines per chunk (%d)",
                         input->path, *lines);
fail:
    return status;
}

/* The chunk of `part` that holds scanline y, checked against the data window:
 * chunks start at the window's top and follow each other; one that does not
 * (a corrupt offset table) would send the decoder's copy outside the buffers.
 * Its bytes must lie inside the file, whose size is file_size. */
static int read_chunk_info(exr_input *input, int part, int32_t lines_per_chunk, int64_t y,
                           int64_t file_size, exr_chunk_info_t *chunk, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    CHECK_EXR(exr_read_scanline_chunk_info(input->context, part, (int)y, chunk),
              "cannot read a chunk (file truncated or corrupt?)");
    const pixel_rect *window = &input->data_window;
    if (chunk->start_y != y || chunk->height < 1 || chunk->height > lines_per_chunk ||
        chunk->width != input->width ||
        (int64_t)chunk->start_y + chunk->height - 1 > window->max_y ||
        chunk->data_offset > (uint64_t)file_size ||
        chunk->packed_size > (uint64_t)file_size - chunk->data_offset)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: corrupt chunk at scanline %lld",
                         input->path, (long long)y);
fail:
    return status;
}

/* A channel and the part that holds it, while the parts' lists are merged. */
typedef struct part_channel {
    exr_attr_chlist_entry_t entry;
    int part;
} part_channel;

/* Several parts' lists, each sorted, merge into one list sorted the same way
 * (OpenEXRCore orders a part's channels by strcmp), so that the first layer
 * "in channel-name order" is the same whatever the file's part layout. */
static int compare_channel_names(const void *a, const void *b) {
    return strcmp(((const part_channel *)a)->entry.name.str,
                  ((const part_channel *)b)->entry.name.str);
}

static int fail_no_channels(const exr_input *input, int part, tool_error *error) {
    if (input->part_count == 1)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: has no channels", input->path);
    return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: part %d (\"%s\") has no channels", input->path,
                     part, part_name(input, part));
}

/* input->channels: the union of every part's channels, each with its part.
 * What it allocates, exr_input_close() frees. */
static int collect_channels(exr_input *input, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    int64_t total = 0;
    const exr_attr_chlist_t *list = NULL;
    part_channel *merged = NULL;
    for (int part = 0; part < input->part_count; ++part) {
        CHECK_EXR(exr_get_channels(input->context, part, &list), "no channel list");
        if (list == NULL || list->num_channels < 1) return fail_no_channels(input, part, error);
        total += list->num_channels;
    }
    if (total > INT_MAX / (int64_t)sizeof(part_channel))
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: too many channels (%lld)", input->path,
                         (long long)total);
    merged = malloc((size_t)total * sizeof *merged);
    exr_attr_chlist_entry_t *entries = malloc((size_t)total * sizeof *entries);
    input->channel_union.entries = entries;
    input->channel_parts = malloc((size_t)total * sizeof *input->channel_parts);
    if (merged == NULL || entries == NULL || input->channel_parts == NULL) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: out of memory for %lld channels",
                           input->path, (long long)total);
        goto fail;
    }
    int count = 0;
    for (int part = 0; part < input->part_count; ++part) {
        CHECK_EXR(exr_get_channels(input->context, part, &list), "no channel list");
        for (int c = 0; c < list->num_channels; ++c) {
            merged[count].entry = list->entries[c];
            merged[count].part = part;
            ++count;
        }
    }
    qsort(merged, (size_t)count, sizeof *merged, compare_channel_names);
    for (int c = 0; c < count; ++c) {
        entries[c] = merged[c].entry;
        input->channel_parts[c] = merged[c].part;
    }
    input->channel_union.num_channels = count;
    input->channel_union.num_alloced = count;
    input->channels = &input->channel_union;
    /* A name in two parts would make a request ambiguous (which part's
     * pixels?); sorted, duplicates are neighbours. */
    for (int c = 1; c < count; ++c) {
        if (strcmp(entries[c - 1].name.str, entries[c].name.str) == 0) {
            const int first = input->channel_parts[c - 1], second = input->channel_parts[c];
            const char *first_view = part_view(input, first),
                       *second_view = part_view(input, second);
            if (first_view != NULL && second_view != NULL && strcmp(first_view, second_view) != 0) {
                /* Blender 5 saves a multi-view render in one file as a part
                 * per view (and pass), each with the same channel names */
                status = tool_fail(error, TOOL_EXIT_RUNTIME,
                                   "%s: holds the views \"%s\" and \"%s\" of a multi-view render "
                                   "in one file (parts %d and %d); " EXR_VIEWS_APART_ADVICE,
                                   input->path, first_view, second_view, first, second);
                break;
            }
            status = tool_fail(error, TOOL_EXIT_RUNTIME,
                               "%s: channel %s is in part %d (\"%s\") and in part %d (\"%s\"); "
                               "channel names must be unique across parts",
                               input->path, entries[c].name.str, first, part_name(input, first),
                               second, part_name(input, second));
            break;
        }
    }
fail:
    free(merged);
    return status;
}

/* Every chunk of every part that the data window needs, read before
 * anything is allocated for the image: a header claiming a huge image in a
 * small file fails here (its chunk table or its chunks do not fit in the
 * file). The chunk table itself is 8 bytes per chunk, which OpenEXRCore
 * checks against the file size. */
static int check_chunks(exr_input *input, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    /* the size of the file read, not of whatever the path names by now (a
     * render written anew and renamed over it meanwhile) */
    struct stat file_status;
    const int statted = input->stream.open ? fstat(input->stream.fd, &file_status)
                                           : stat(input->path, &file_status);
    if (statted != 0)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: cannot read its size", input->path);
    const pixel_rect *window = &input->data_window;
    for (int part = 0; part < input->part_count; ++part) {
        int32_t lines_per_chunk = 0;
        status = part_lines_per_chunk(input, part, &lines_per_chunk, error);
        if (status != TOOL_EXIT_SUCCESS) return status;
        exr_compression_t compression = EXR_COMPRESSION_LAST_TYPE;
        CHECK_EXR(exr_get_compression(input->context, part, &compression), "no compression");
        for (int64_t y = window->min_y; y <= window->max_y; y += lines_per_chunk) {
            exr_chunk_info_t chunk;
            status = read_chunk_info(input, part, lines_per_chunk, y, (int64_t)file_status.st_size,
                                     &chunk, error);
            /* Uncompressed, a chunk holds its lines and nothing else: one that
             * says it is shorter would be read past its end, or (read whole)
             * leave part of the decoder's buffer unwritten. OpenEXRCore 3.4.15
             * and later refuse it in exr_read_scanline_chunk_info already. */
            if (status == TOOL_EXIT_SUCCESS && compression == EXR_COMPRESSION_NONE &&
                chunk.packed_size != chunk.unpacked_size)
                return tool_fail(error, TOOL_EXIT_RUNTIME,
                                 "%s: corrupt chunk at scanline %lld (%llu bytes for %llu)",
                                 input->path, (long long)y, (unsigned long long)chunk.packed_size,
                                 (unsigned long long)chunk.unpacked_size);
            if (status != TOOL_EXIT_SUCCESS) {
                char detail[TOOL_ERROR_MESSAGE_SIZE];
                snprintf(detail, sizeof detail, "%s", error->message);
                return tool_fail(error, status,
                                 "%s: the header claims a %dx%d image, which this %lld-byte "
                                 "file does not hold (%s)",
                                 input->path, input->width, input->height,
                                 (long long)file_status.st_size, detail);
            }
        }
    }
    input->file_size = (int64_t)file_status.st_size;
    input->file_status = file_status;
fail:
    return status;
}

/* What a path that is not a regular file is, for its message. */
static const char *file_kind(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

int exr_input_open(exr_input *input, const char *path, tool_error *error) {
    memset(input, 0, sizeof *input); /* input->stream: not open */
    input->path = path;
    input->threads = 1;
    /* Only a regular file is read: opening a FIFO waits for a writer
     * (hbao --info FIFO hung), and a folder's read error says nothing. */
    struct stat file;
    if (stat(path, &file) == 0 && !S_ISREG(file.st_mode))
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s is %s, not an EXR file", path,
                         file_kind(file.st_mode));
    exr_clear_last_error();
    exr_context_initializer_t initializer = exr_quiet_initializer();
    exr_stream_open(&input->stream, path, &initializer);
    int status = TOOL_EXIT_SUCCESS;
    exr_result_t opened = exr_start_read(&input->context, path, &initializer);
    if (opened != EXR_ERR_SUCCESS) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: not a readable EXR file: %s (%s)", path,
                           exr_error_text(opened), exr_get_error_code_as_string(opened));
        goto fail;
    }

    CHECK_EXR(exr_get_count(input->context, &input->part_count), "cannot count parts");
    if (input->part_count < 1) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "%s: has no parts", path);
        goto fail;
    }
    for (int part = 0; part < input->part_count; ++part) {
        /* A compression newer than this OpenEXR (ZSTD, HTJ2K of 3.4 and
         * later): OpenEXRCore 3.1 reports the attribute's value invalid and
         * reads on with another compression. Said so, not as a file cut
         * short where its chunks do not parse. */
        exr_compression_t compression = EXR_COMPRESSION_NONE;
        CHECK_EXR(exr_get_compression(input->context, part, &compression), "no compression");
        if ((int)compression < 0 || compression >= EXR_COMPRESSION_LAST_TYPE ||
            strstr(last_error_message, "'compression'") != NULL) {
            status = tool_fail(error, TOOL_EXIT_RUNTIME,
                               "%s: a compression that this OpenEXR library does not know "
                               "(a newer OpenEXR's, such as ZSTD or HTJ2K?): %s; save the EXR "
                               "with ZIP, PIZ or no compression",
                               path, last_error_message[0] ? last_error_message : "unknown");
            goto fail;
        }
        exr_storage_t storage;
        CHECK_EXR(exr_get_storage(input->context, part, &storage), "cannot read the storage type");
        if (storage != EXR_STORAGE_SCANLINE) {
            status = tool_fail(error, TOOL_EXIT_RUNTIME,
                               "%s: only scanline images are supported (part %d, \"%s\", is "
                               "%s)",
                               path, part, part_name(input, part),
                               storage == EXR_STORAGE_TILED ? "tiled" : "deep");
            goto fail;
        }
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
    status = check_part_windows(input, &data_window, &display_window, error);
    if (status != TOOL_EXIT_SUCCESS) goto fail;

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

    status = collect_channels(input, error);
    if (status != TOOL_EXIT_SUCCESS) goto fail;
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

int exr_usable_cores(void) {
    return hbao_usable_cpus();
}

int exr_input_find_channel(const exr_input *input, const char *name) {
    /* input->channels is sorted by strcmp, without duplicates
     * (collect_channels): a file of 20000 channels took minutes where
     * every view-like channel's layer was looked up (a review) */
    int low = 0, high = input->channels->num_channels - 1;
    while (low <= high) {
        const int middle = low + (high - low) / 2;
        const int order = strcmp(input->channels->entries[middle].name.str, name);
        if (order == 0) return middle;
        if (order < 0)
            low = middle + 1;
        else
            high = middle - 1;
    }
    return -1;
}

bool exr_input_channel_is_lossy(const exr_input *input, int channel) {
    exr_compression_t compression = EXR_COMPRESSION_NONE;
    if (channel < 0 || channel >= input->channels->num_channels ||
        input->channels->entries[channel].pixel_type != EXR_PIXEL_HALF ||
        exr_get_compression(input->context, input->channel_parts[channel], &compression) !=
            EXR_ERR_SUCCESS)
        return false;
    return compression == EXR_COMPRESSION_B44 || compression == EXR_COMPRESSION_B44A;
}

static const exr_channel_request *find_request(const exr_channel_request *requests, int count,
                                               const char *name) {
    for (int r = 0; r < count; ++r)
        if (strcmp(requests[r].name, name) == 0) return &requests[r];
    return NULL;
}

/* Whether `part` is read directly (exr_stream.h): uncompressed, and every
 * request for one of its channels in that channel's own type, so that
 * OpenEXRCore converts nothing and reads each channel's line straight into
 * its destination (the stream gathers a chunk's lines into one preadv per
 * run of lines that follow each other). Requests whose pixel stride is not
 * the type's size, `*staged` of them, go to a staging buffer first. */
static bool part_reads_direct(exr_input *input, int part, const exr_channel_request *requests,
                              int count, int *staged) {
    exr_compression_t compression = EXR_COMPRESSION_LAST_TYPE;
    const exr_attr_chlist_t *list = NULL;
    *staged = 0;
    if (exr_get_compression(input->context, part, &compression) != EXR_ERR_SUCCESS ||
        compression != EXR_COMPRESSION_NONE ||
        exr_get_channels(input->context, part, &list) != EXR_ERR_SUCCESS || list == NULL)
        return false;
    int staged_requests = 0;
    for (int c = 0; c < list->num_channels; ++c) {
        const exr_channel_request *request =
            find_request(requests, count, list->entries[c].name.str);
        if (request == NULL) continue;
        if (request->type != list->entries[c].pixel_type) return false;
        staged_requests += request->pixel_stride != exr_pixel_type_size(request->type);
    }
    *staged = staged_requests;
    return true;
}

/* Columns of the staged channels scattered together (read_band): a few KiB
 * of each request's pixels, well inside a core's L1 cache. */
#define SCATTER_COLUMNS 256

/* A staged line of `width` values of `size` bytes (2 or 4) to its request's
 * pixels, `pixel_stride` bytes apart: the element size a constant in each
 * loop, so that no value costs a call to memcpy. */
static void scatter_line(const uint8_t *from, int size, int32_t width, uint8_t *to,
                         int64_t pixel_stride) {
    if (size == 4) {
        for (int32_t x = 0; x < width; ++x) memcpy(to + x * pixel_stride, from + 4 * x, 4);
    } else {
        for (int32_t x = 0; x < width; ++x) memcpy(to + x * pixel_stride, from + 2 * x, 2);
    }
}

/* A chunk whose packed size is its unpacked size was stored uncompressed: a
 * writer does so when compression would not make it smaller (OpenEXR's rule
 * for every codec). OpenEXRCore 3.1 still ran B44's decoder over such a chunk
 * (a B44 file's float Depth and Normal, which B44 leaves as they are), giving
 * garbage without an error; its bytes are the pixels. */
static exr_result_t copy_stored_chunk(exr_decode_pipeline_t *decode) {
    if (decode->unpacked_buffer != decode->packed_buffer)
        memcpy(decode->unpacked_buffer, decode->packed_buffer, decode->chunk.packed_size);
    return EXR_ERR_SUCCESS;
}

static exr_zip_decompressor zip_decompressor;

void exr_input_set_zip_decompressor(exr_zip_decompressor decompressor) {
    zip_decompressor = decompressor;
}

bool exr_scratch_reserve(exr_scratch *scratch, size_t size) {
    if (scratch->size >= size) return true;
    uint8_t *grown = realloc(scratch->bytes, size);
    if (grown == NULL) return false;
    scratch->bytes = grown;
    scratch->size = size;
    return true;
}

/* A ZIP or ZIPS chunk through zip_decompressor, with the band's scratch
 * (decoding_user_data). */
static exr_result_t decompress_zip_chunk(exr_decode_pipeline_t *decode) {
    return zip_decompressor(decode, decode->decoding_user_data);
}

/* Decode the requests that name channels of `part`, for the chunks that
 * start at rows first_y .. last_y of the file (a band; every chunk of the
 * part when the band is the whole data window); the other requests are left
 * to the other parts (a name is in one part only).
 *
 * The part's channels that nobody asked for get a destination too, one
 * scratch chunk that is thrown away: OpenEXRCore 3.1 is told to skip a channel
 * by a NULL destination, but its fast unpackers for 3 and 4 half channels
 * converted to float write through the NULL (an RGB + Z half file whose Z
 * alone is read crashed). Every channel with a real destination keeps the
 * library on paths that need no such care. Where the part is compressed,
 * this costs a copy of channels that are decompressed anyway. Where it is
 * not (the add-on's scratch file, every pass of a render), OpenEXRCore reads
 * each channel's line into its destination, and the stream skips the reads
 * into the scratch chunk (exr_stream.h): only the requested channels' bytes
 * leave the file. */
static int read_band(exr_input *input, int part, const exr_channel_request *requests, int count,
                     int64_t first_y, int64_t last_y, atomic_bool *stop, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    exr_decode_pipeline_t decoder = EXR_DECODE_PIPELINE_INITIALIZER;
    bool decoder_ready = false;
    uint8_t *scratch = NULL, *staging = NULL;
    /* each decoder channel's request (NULL: none), looked up once: the
     * decoder keeps its channels in one order for every chunk */
    const exr_channel_request **channel_requests = NULL;
    int *staged_channels = NULL;         /* the decoder channels that go through staging */
    exr_scratch zip_scratch = {NULL, 0}; /* zip_decompressor's */

    int32_t lines_per_chunk = 0;
    status = part_lines_per_chunk(input, part, &lines_per_chunk, error);
    if (status != TOOL_EXIT_SUCCESS) goto fail;
    /* 4 bytes: the widest pixel type (float, uint). */
    const int64_t scratch_line = (int64_t)input->width * 4;
    const size_t scratch_size = (size_t)(scratch_line * lines_per_chunk);
    int staged_count = 0;
    const bool direct = part_reads_direct(input, part, requests, count, &staged_count);
    exr_compression_t compression = EXR_COMPRESSION_LAST_TYPE;
    CHECK_EXR(exr_get_compression(input->context, part, &compression), "no compression");
    const bool zip = compression == EXR_COMPRESSION_ZIP || compression == EXR_COMPRESSION_ZIPS;
    scratch = malloc(scratch_size);
    if (staged_count > 0) {
        staging = malloc(scratch_size * (size_t)staged_count);
        staged_channels = malloc((size_t)staged_count * sizeof *staged_channels);
    }
    if (scratch == NULL || (staged_count > 0 && (staging == NULL || staged_channels == NULL))) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
        goto fail;
    }

    const pixel_rect *window = &input->data_window;
    for (int64_t y = first_y; y <= last_y; y += lines_per_chunk) {
        if (atomic_load(stop)) break; /* another band failed: its message is the one */
        exr_chunk_info_t chunk;
        status = read_chunk_info(input, part, lines_per_chunk, y, input->file_size, &chunk, error);
        if (status != TOOL_EXIT_SUCCESS) goto fail;
        if (!decoder_ready) {
            CHECK_EXR(exr_decoding_initialize(input->context, part, &chunk, &decoder),
                      "cannot start decoding");
            decoder_ready = true;
            channel_requests = malloc((size_t)decoder.channel_count * sizeof *channel_requests);
            if (channel_requests == NULL) {
                status = tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
                goto fail;
            }
            for (int c = 0; c < decoder.channel_count; ++c)
                channel_requests[c] =
                    find_request(requests, count, decoder.channels[c].channel_name);
        } else {
            CHECK_EXR(exr_decoding_update(input->context, part, &chunk, &decoder),
                      "cannot decode a chunk");
        }
        const int64_t first_row = chunk.start_y - window->min_y;
        int staged = 0;
        for (int c = 0; c < decoder.channel_count; ++c) {
            exr_coding_channel_info_t *channel = &decoder.channels[c];
            const exr_channel_request *request = channel_requests[c];
            if (request == NULL) {
                channel->decode_to_ptr = scratch;
                channel->user_pixel_stride = channel->bytes_per_element;
                /* direct: every line of the chunk on the first (skipped) */
                channel->user_line_stride =
                    direct ? 0 : (int32_t)(channel->bytes_per_element * input->width);
                channel->user_data_type = channel->data_type;
                channel->user_bytes_per_element = channel->bytes_per_element;
                continue;
            }
            channel->user_data_type = (uint16_t)request->type;
            channel->user_bytes_per_element = (int16_t)exr_pixel_type_size(request->type);
            if (direct && request->pixel_stride != channel->user_bytes_per_element) {
                staged_channels[staged] = c;
                channel->decode_to_ptr = staging + scratch_size * (size_t)staged++;
                channel->user_pixel_stride = channel->user_bytes_per_element;
                channel->user_line_stride = (int32_t)scratch_line;
                continue;
            }
            channel->decode_to_ptr = request->data + first_row * request->row_stride;
            channel->user_pixel_stride = request->pixel_stride;
            channel->user_line_stride = (int32_t)request->row_stride;
        }
        CHECK_EXR(exr_decoding_choose_default_routines(input->context, part, &decoder),
                  "cannot decode this channel layout");
        if (decoder.decompress_fn != NULL && chunk.packed_size == chunk.unpacked_size) {
            decoder.decompress_fn = copy_stored_chunk;
        } else if (decoder.decompress_fn != NULL && zip && zip_decompressor != NULL) {
            decoder.decompress_fn = decompress_zip_chunk;
            decoder.decoding_user_data = &zip_scratch;
        }
        /* The stream skips and gathers reads only where OpenEXRCore chose
         * its direct read, which neither decompresses nor unpacks: its other
         * routines read their input back within exr_decoding_run. */
        const bool read_direct =
            direct && decoder.decompress_fn == NULL && decoder.unpack_and_convert_fn == NULL;
        if (read_direct) exr_stream_direct_begin(scratch, scratch_size);
        exr_result_t decoded = exr_decoding_run(input->context, part, &decoder);
        const char *unread = read_direct ? exr_stream_direct_end() : NULL;
        if (unread != NULL) { /* first: OpenEXRCore's own message says less */
            status = tool_fail(error, TOOL_EXIT_RUNTIME,
                               "%s: cannot read the chunk at scanline %lld: %s", input->path,
                               (long long)chunk.start_y, unread);
            goto fail;
        }
        if (decoded == EXR_ERR_FEATURE_NOT_IMPLEMENTED) {
            /* OpenEXRCore 3.1 cannot decompress DWAA/DWAB. */
            status = tool_fail(error, TOOL_EXIT_RUNTIME,
                               "%s: this OpenEXR library cannot decode %s compression; save "
                               "the EXR with ZIP, PIZ or no compression",
                               input->path, exr_compression_name(compression));
            goto fail;
        }
        CHECK_EXR(decoded, "cannot decode a chunk (file truncated or corrupt?)");
        /* The staged lines to their requests, SCATTER_COLUMNS columns of
         * every staged channel at a time: channels interleaved in one array
         * (Normal's X, Y, Z) share its pixels, which then stay in the cache
         * from one channel to the next instead of being fetched once each. */
        for (int32_t line = 0; line < chunk.height; ++line) {
            for (int32_t x = 0; x < input->width; x += SCATTER_COLUMNS) {
                const int32_t columns =
                    input->width - x < SCATTER_COLUMNS ? input->width - x : SCATTER_COLUMNS;
                for (int k = 0; k < staged; ++k) {
                    const exr_coding_channel_info_t *channel =
                        &decoder.channels[staged_channels[k]];
                    const exr_channel_request *request = channel_requests[staged_channels[k]];
                    const int size = channel->user_bytes_per_element;
                    scatter_line(channel->decode_to_ptr + (size_t)line * (size_t)scratch_line +
                                     (size_t)x * (size_t)size,
                                 size, columns,
                                 request->data + (first_row + line) * request->row_stride +
                                     (int64_t)x * request->pixel_stride,
                                 request->pixel_stride);
                }
            }
        }
    }

fail:
    if (status != TOOL_EXIT_SUCCESS) atomic_store(stop, true);
    if (decoder_ready) exr_decoding_destroy(input->context, &decoder);
    free(scratch);
    free(staging);
    free(channel_requests);
    free(staged_channels);
    free(zip_scratch.bytes);
    return status;
}

/* One band of a part, decoded by one thread. */
typedef struct band_job {
    exr_input *input;
    int part;
    const exr_channel_request *requests;
    int count;
    int64_t first_y, last_y;
    atomic_bool *stop;
    int status;
    tool_error error;
} band_job;

static void *run_band(void *argument) {
    band_job *band = argument;
    exr_clear_last_error(); /* this thread's copy of OpenEXRCore's detail */
    band->status = read_band(band->input, band->part, band->requests, band->count, band->first_y,
                             band->last_y, band->stop, &band->error);
    return NULL;
}

/* The part's chunks in input->threads bands of whole chunks (at most one
 * band per chunk), one thread each (OpenEXRCore reads one context from several threads; each band has
 * its own decoder). Every chunk is decoded into its own rows, so the result
 * does not depend on the number of threads. The first band that fails, from
 * the top, gives the message. */
static int read_part(exr_input *input, int part, const exr_channel_request *requests, int count,
                     tool_error *error) {
    int32_t lines_per_chunk = 0;
    int status = part_lines_per_chunk(input, part, &lines_per_chunk, error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    const pixel_rect *window = &input->data_window;
    const int64_t chunks = ((int64_t)input->height + lines_per_chunk - 1) / lines_per_chunk;
    int64_t threads = input->threads < 1 ? 1 : input->threads;
    if (threads > EXR_MAX_READ_THREADS) threads = EXR_MAX_READ_THREADS;
    if (threads > chunks) threads = chunks;
    atomic_bool stop;
    atomic_init(&stop, false);
    if (threads <= 1)
        return read_band(input, part, requests, count, window->min_y, window->max_y, &stop, error);

    band_job bands[EXR_MAX_READ_THREADS];
    pthread_t workers[EXR_MAX_READ_THREADS];
    bool started[EXR_MAX_READ_THREADS] = {false};
    for (int64_t b = 0; b < threads; ++b) {
        const int64_t first_chunk = chunks * b / threads, end_chunk = chunks * (b + 1) / threads;
        band_job job = {input,
                        part,
                        requests,
                        count,
                        window->min_y + first_chunk * lines_per_chunk,
                        window->min_y + end_chunk * lines_per_chunk - 1,
                        &stop,
                        TOOL_EXIT_SUCCESS,
                        {{0}}};
        if (job.last_y > window->max_y) job.last_y = window->max_y;
        bands[b] = job;
    }
    /* The calling thread decodes band 0; a band whose thread cannot start is
     * decoded here too, after it. */
    for (int64_t b = 1; b < threads; ++b)
        started[b] = pthread_create(&workers[b], NULL, run_band, &bands[b]) == 0;
    run_band(&bands[0]);
    for (int64_t b = 1; b < threads; ++b) {
        if (started[b])
            pthread_join(workers[b], NULL);
        else
            run_band(&bands[b]);
    }
    for (int64_t b = 0; b < threads; ++b) {
        if (bands[b].status != TOOL_EXIT_SUCCESS) {
            *error = bands[b].error;
            return bands[b].status;
        }
    }
    return TOOL_EXIT_SUCCESS;
}

int exr_input_read(exr_input *input, const exr_channel_request *requests, int count,
                   tool_error *error) {
    exr_clear_last_error();
    /* Only parts that hold a requested channel are decoded: reading Depth
     * from Blender 5's one-part-per-pass files skips Combined and the rest. */
    bool *wanted = calloc((size_t)input->part_count, sizeof *wanted);
    if (wanted == NULL) return tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
    for (int r = 0; r < count; ++r) {
        const int channel = exr_input_find_channel(input, requests[r].name);
        if (channel < 0) {
            free(wanted);
            return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: no channel named %s", input->path,
                             requests[r].name);
        }
        wanted[input->channel_parts[channel]] = true;
    }
    int status = TOOL_EXIT_SUCCESS;
    for (int part = 0; part < input->part_count && status == TOOL_EXIT_SUCCESS; ++part)
        if (wanted[part]) status = read_part(input, part, requests, count, error);
    free(wanted);
    return status;
}

void exr_input_close(exr_input *input) {
    if (input->context != NULL) exr_finish(&input->context);
    input->context = NULL;
    exr_stream_close(&input->stream);
    input->channels = NULL;
    free((void *)input->channel_union.entries);
    input->channel_union.entries = NULL;
    free(input->channel_parts);
    input->channel_parts = NULL;
}
