/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "exr_stream.h"

#include <errno.h>
#include <limits.h>
#include <fcntl.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static _Thread_local const char *discard_begin;
static _Thread_local size_t discard_size;

void exr_stream_discard_into(const void *begin, size_t size) {
    discard_begin = begin;
    discard_size = begin != NULL ? size : 0;
}

static int discarded(const void *buffer, uint64_t size) {
    const uintptr_t at = (uintptr_t)buffer, begin = (uintptr_t)discard_begin;
    return discard_begin != NULL && at >= begin && at - begin <= discard_size &&
           size <= discard_size - (at - begin);
}

/* The file descriptor travels as OpenEXRCore's user data, so that the
 * exr_stream itself may move. */
static int stream_fd(void *user_data) {
    return (int)(intptr_t)user_data;
}

static int64_t stream_size(exr_const_context_t context, void *user_data) {
    (void)context;
    struct stat status;
    if (fstat(stream_fd(user_data), &status) != 0) return -1; /* OpenEXRCore: size unknown */
    return (int64_t)status.st_size;
}

/* pread semantics, as OpenEXRCore asks: the bytes read (fewer at the end of
 * the file), or -1 after reporting the error. Safe from several threads. A
 * read into the thread's discard buffer answers as a whole read: only a
 * decoder's destinations are discard buffers, and the reader checks that
 * every chunk it decodes lies inside the file (read_chunk_info). */
static int64_t stream_read(exr_const_context_t context, void *user_data, void *buffer,
                           uint64_t size, uint64_t offset, exr_stream_error_func_ptr_t error) {
    if (size > (uint64_t)INT64_MAX || offset > (uint64_t)INT64_MAX - size) {
        error(context, EXR_ERR_READ_IO, "read of %llu bytes at %llu is out of range",
              (unsigned long long)size, (unsigned long long)offset);
        return -1;
    }
    if (discarded(buffer, size)) return (int64_t)size;
    uint64_t done = 0;
    while (done < size) {
        const size_t ask =
            size - done > (uint64_t)SSIZE_MAX ? (size_t)SSIZE_MAX : (size_t)(size - done);
        const ssize_t got =
            pread(stream_fd(user_data), (char *)buffer + done, ask, (off_t)(offset + done));
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            error(context, EXR_ERR_READ_IO, "cannot read the file: %s", strerror(errno));
            return -1;
        }
        if (got == 0) break; /* end of file */
        done += (uint64_t)got;
    }
    return (int64_t)done;
}

void exr_stream_open(exr_stream *stream, const char *path, exr_context_initializer_t *initializer) {
    stream->fd = open(path, O_RDONLY | O_CLOEXEC);
    stream->open = stream->fd >= 0;
    if (!stream->open) return;
    struct stat status;
    if (fstat(stream->fd, &status) != 0 || !S_ISREG(status.st_mode)) {
        /* a folder, a pipe: OpenEXRCore's own open says what it is */
        exr_stream_close(stream);
        return;
    }
    initializer->user_data = (void *)(intptr_t)stream->fd;
    initializer->read_fn = stream_read;
    initializer->size_fn = stream_size;
}

void exr_stream_close(exr_stream *stream) {
    if (stream->open) close(stream->fd);
    stream->open = false;
    stream->fd = -1;
}
