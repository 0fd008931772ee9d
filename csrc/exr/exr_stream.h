/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * The reader's file, given to OpenEXRCore as a custom stream (its
 * read_fn / size_fn hooks) instead of letting it open the path itself, so
 * that a read whose destination is the calling thread's discard buffer is
 * skipped. OpenEXRCore still parses everything and decides every offset; the
 * stream only declines to fetch bytes the reader would throw away.
 *
 * What it is for: OpenEXRCore reads an uncompressed chunk straight into the
 * decoder's destinations, one channel's line at a time, when every channel
 * has one (read_uncompressed_direct). The reader points the channels nobody
 * asked for at its discard buffer, so only the requested channels' bytes are
 * read: the add-on's scratch file holds every pass of the render, of which
 * it reads four channels (exr_reader.c, read_band).
 */
#ifndef HBAO_EXR_STREAM_H
#define HBAO_EXR_STREAM_H

#include <openexr.h>
#include <stdbool.h>
#include <stddef.h>

typedef struct exr_stream {
    bool open; /**< false (as zeroed): OpenEXRCore opens the path itself */
    int fd;
} exr_stream;

/** Opens `path` for reading and hooks it into *initializer. Where the file
 *  cannot be opened, the stream stays closed and *initializer unchanged, so
 *  that OpenEXRCore's own open reports why. */
void exr_stream_open(exr_stream *stream, const char *path, exr_context_initializer_t *initializer);

/** Closes the file: after exr_finish() of every context that used it. */
void exr_stream_close(exr_stream *stream);

/** The calling thread's discard buffer: reads into [begin, begin + size)
 *  are skipped (their bytes are left as they were). NULL, 0: none. */
void exr_stream_discard_into(const void *begin, size_t size);

#endif /* HBAO_EXR_STREAM_H */
