/* SPDX-License-Identifier: GPL-2.0-or-later */
/* ZIP and ZIPS chunks decompressed by libdeflate instead of OpenEXRCore 3.1's
 * zlib: the inflate of a Blender render's chunks is most of the tool's time
 * a frame, and libdeflate inflates them in about half of zlib's time. */
#ifndef HBAO_ZIP_CHUNKS_H
#define HBAO_ZIP_CHUNKS_H

#include "exr_reader.h"

/** An exr_zip_decompressor: libdeflate's inflate, then OpenEXR's ZIP
 *  predictor and byte interleave undone, as OpenEXRCore does. */
exr_result_t zip_chunks_decompress(exr_decode_pipeline_t *decode, exr_scratch *scratch);

#endif /* HBAO_ZIP_CHUNKS_H */
