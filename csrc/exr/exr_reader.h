/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Reading scanline EXR files (what Blender writes) through OpenEXRCore:
 * single-part (Blender before 5.0, or 5.x with "interleave") or multi-part
 * with one data window (Blender 5.x's default, one part per pass). The image
 * is the data window; rows are stored top row first, whatever the file's line
 * order. The header fields below come from part 0.
 */
#ifndef HBAO_EXR_READER_H
#define HBAO_EXR_READER_H

#include <openexr.h>
#include <stdbool.h>
#include <sys/stat.h>
#include <stdint.h>

#include "exr_stream.h"
#include "pixel_rect.h"
#include "tool_error.h"

typedef struct exr_input {
    exr_context_t context;
    exr_stream stream; /**< the file the context reads */
    const char *path;
    pixel_rect data_window;
    pixel_rect display_window;
    int32_t width, height;    /**< of the data window */
    float pixel_aspect_ratio; /**< pixel width / height; 1 when absent */
    bool has_pixel_aspect_ratio;
    exr_attr_v2f_t screen_window_center;
    float screen_window_width;
    exr_compression_t compression;
    exr_lineorder_t line_order;
    int64_t file_size;       /**< in bytes, when opened */
    struct stat file_status; /**< the file as it was opened (device, inode, size, time) */
    int part_count;
    /** Threads exr_input_read decodes with (each part in bands of rows): 1
     *  after exr_input_open; the caller may raise it, up to
     *  EXR_MAX_READ_THREADS. The values read do not depend on it. */
    int threads;
    /** Every part's channels, sorted by name; names are unique across parts. */
    const exr_attr_chlist_t *channels;
    int *channel_parts;              /**< the part that holds channels->entries[c] */
    exr_attr_chlist_t channel_union; /* storage behind `channels`; names owned by the context */
} exr_input;

/** The most threads exr_input_read uses. */
#define EXR_MAX_READ_THREADS 16

/** Where one channel's pixels go. Strides are in bytes. */
typedef struct exr_channel_request {
    const char *name;
    exr_pixel_type_t type; /**< EXR_PIXEL_FLOAT converts half and uint to float */
    uint8_t *data;         /**< the top-left pixel of the data window */
    int32_t pixel_stride;
    int64_t row_stride;
} exr_channel_request;

/**
 * Open `path`, check that it is an image the tool can read (scanline parts
 * that share one data and display window, no channel name in two parts,
 * channels not subsampled, size within hbao's limits, every chunk of every
 * part that the data window needs listed and inside the file) and fill
 * *input. So a caller may allocate for width x height once this succeeds: a
 * corrupt header's size claim is refused here, before anyone reserves memory
 * for it.
 * On failure *input needs no exr_input_close().
 */
int exr_input_open(exr_input *input, const char *path, tool_error *error);

/** Decode the requested channels (each must exist) for the whole data window,
 *  from whichever parts hold them. */
int exr_input_read(exr_input *input, const exr_channel_request *requests, int count,
                   tool_error *error);

/** A buffer a decoding thread keeps from chunk to chunk; grown with
 *  realloc by whoever needs more, freed by the reader. */
typedef struct exr_scratch {
    uint8_t *bytes;
    size_t size;
} exr_scratch;

/** Whether scratch holds at least size bytes, growing it where not. */
bool exr_scratch_reserve(exr_scratch *scratch, size_t size);

/** Decompresses one chunk of a ZIP or ZIPS part into decode->unpacked_buffer
 *  (decode->chunk.unpacked_size bytes, as OpenEXRCore's own routine would
 *  give them) from decode->packed_buffer; scratch is the thread's. Returns
 *  EXR_ERR_SUCCESS, EXR_ERR_CORRUPT_CHUNK or EXR_ERR_OUT_OF_MEMORY. */
typedef exr_result_t (*exr_zip_decompressor)(exr_decode_pipeline_t *decode, exr_scratch *scratch);

/** The decompressor exr_input_read uses for ZIP and ZIPS chunks from now
 *  on; NULL (the default): OpenEXRCore's. Set it before any read starts
 *  (the tool sets it in main; libhbao_exr never does). */
void exr_input_set_zip_decompressor(exr_zip_decompressor decompressor);

/** What to do with a multi-view render saved in one file (the reader's
 *  part per view, the tool's view-named channels say it). */
#define EXR_VIEWS_APART_ADVICE                                                                     \
    "the tool reads one view from a file of its own: save each view to its own file (Output "      \
    "properties > Views > Views Format: Individual, as render_0001_L.exr) and run the tool on "    \
    "each with that view's camera (scripts/export_cameras.py writes one per view)"

/** The cores this process may run on (at least 1; hbao_cpus.h): the threads
 *  a caller reads and computes with when nobody asked for a number. */
int exr_usable_cores(void);

/** Index of the channel called `name`, or -1. */
int exr_input_find_channel(const exr_input *input, const char *name);

/** Whether channel `channel` (an index of input->channels) is stored with
 *  loss: half floats in a B44 or B44A part (whose 4x4 blocks keep about 6
 *  bits of each value's difference from the block's largest; float and
 *  uint channels it stores whole). DWAA and DWAB are refused on open. */
bool exr_input_channel_is_lossy(const exr_input *input, int channel);

void exr_input_close(exr_input *input);

/** Bytes per pixel of a channel type (2 for half, 4 otherwise). */
int exr_pixel_type_size(exr_pixel_type_t type);

/** "half", "float", "uint". */
const char *exr_pixel_type_name(exr_pixel_type_t type);

/** Lower-case compression names as used by --compression ("zip", "piz", ...). */
const char *exr_compression_name(exr_compression_t compression);

/** Context initializer whose error handler keeps the library's last message
 *  (see exr_last_error_message()) instead of printing it. */
exr_context_initializer_t exr_quiet_initializer(void);

/** A message for an OpenEXRCore result: the library's last detailed message
 *  if it reported one since exr_clear_last_error(), else the default text. */
const char *exr_error_text(exr_result_t result);
void exr_clear_last_error(void);

#endif /* HBAO_EXR_READER_H */
