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
 * it reads four channels (exr_reader.c, read_band). A read per channel line
 * would cost a system call each; the stream gathers a chunk's reads and
 * makes one preadv() of each run of lines that follow each other.
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

/** Starts the calling thread's direct decode of one chunk (OpenEXRCore's
 *  read_uncompressed_direct, which reads each channel's line straight into
 *  its destination and reads nothing back before exr_decoding_run returns).
 *  Until exr_stream_direct_end():
 *  - reads into [discard, discard + discard_size), the destination of the
 *    channels nobody asked for, are skipped (the buffer's bytes are
 *    undefined after);
 *  - the other reads are gathered, not done: OpenEXRCore asks for a chunk's
 *    lines one after the other, and lines that follow each other in the
 *    file are read with one preadv() into their destinations, the skipped
 *    lines between them too (into the discard buffer) where they are short.
 *    On a big-endian host, where OpenEXRCore swaps each line's bytes as
 *    soon as it has read it, the reads are done at once instead.
 *  Only for a decoder that neither decompresses nor unpacks (its
 *  decompress_fn and unpack_and_convert_fn NULL). The caller must not look
 *  at the destinations before the end. */
void exr_stream_direct_begin(const void *discard, size_t discard_size);

/** Ends the direct decode that exr_stream_direct_begin() started on this
 *  thread: does the reads gathered since and forgets the discard buffer.
 *  Returns NULL, or why a read failed (static text of this thread, valid
 *  until its next read); the destinations are then incomplete. Call it
 *  after every begin, whether exr_decoding_run succeeded or not. */
const char *exr_stream_direct_end(void);

#endif /* HBAO_EXR_STREAM_H */
