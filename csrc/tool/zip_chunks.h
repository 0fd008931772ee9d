/* SPDX-License-Identifier: GPL-2.0-or-later */
/* ZIP and ZIPS chunks decompressed and compressed by libdeflate instead of
 * OpenEXRCore 3.1's zlib: the inflate of a Blender render's chunks is most of
 * the tool's time a frame, and libdeflate inflates them in about half of
 * zlib's time; the deflate of the AO it writes took a third of a frame's
 * CPU time (ZIP_CHUNKS_LEVEL). */
#ifndef HBAO_ZIP_CHUNKS_H
#define HBAO_ZIP_CHUNKS_H

#include <stddef.h>
#include <stdint.h>

#include "exr_reader.h"

struct libdeflate_compressor;

/** An exr_zip_decompressor: libdeflate's inflate, then OpenEXR's ZIP
 *  predictor and byte interleave undone, as OpenEXRCore does. */
exr_result_t zip_chunks_decompress(exr_decode_pipeline_t *decode, exr_scratch *scratch);

/** The deflate level of the chunks the tool writes (libdeflate's scale). */
#define ZIP_CHUNKS_LEVEL 6

/** A ZIP or ZIPS chunk of `count` packed bytes, as OpenEXRCore writes one:
 *  the bytes reordered into `scratch` (count bytes), then deflated in zlib's
 *  format into `out` (capacity: libdeflate_zlib_compress_bound's). Returns
 *  the chunk's size; where deflate does not make it smaller, the chunk is
 *  the packed bytes themselves, copied into `out` (the file layout's stored
 *  chunk, which a reader tells by its size). */
size_t zip_chunks_compress(struct libdeflate_compressor *deflater, const uint8_t *packed,
                           size_t count, uint8_t *scratch, uint8_t *out, size_t capacity);

#endif /* HBAO_ZIP_CHUNKS_H */
