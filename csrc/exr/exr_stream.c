/* SPDX-License-Identifier: GPL-2.0-or-later */
#define _DEFAULT_SOURCE /* preadv */
#include "exr_stream.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <stdio.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

/* A run of skipped bytes between two gathered reads at most this long is
 * read along with them (into the discard buffer) rather than splitting the
 * run into two system calls: about what a call costs in copying (a float
 * line of a 1920-pixel-wide file is 7.5 KiB). */
#define GAP_BYTES ((uint64_t)16 * 1024)
/* Reads gathered before they are done anyway (a chunk of 1920 x 1 lines of
 * 81 channels asks for 81). A run takes an iovec per gathered read, so
 * this is also the most one preadv() is given (Linux takes 1024). */
#define GATHERED_READS 256

typedef struct gathered_read {
    char *buffer; /* NULL: a skipped read, into the discard buffer */
    uint64_t size, offset;
} gathered_read;

/* The calling thread's direct decode (exr_stream_direct_begin). */
typedef struct direct_decode {
    const char *discard;
    size_t discard_size;
    bool gathering;
    int fd;
    int count;
    gathered_read reads[GATHERED_READS];
    char message[192];
} direct_decode;

static _Thread_local direct_decode direct;

/* OpenEXRCore's direct read converts each line to the host's byte order as
 * soon as it is read: a no-op on a little-endian host, where alone a read
 * may be put off. Elsewhere the reads are done at once. */
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define MAY_GATHER true
#else
#define MAY_GATHER false
#endif

void exr_stream_direct_begin(const void *discard, size_t discard_size) {
    direct.discard = discard;
    direct.discard_size = discard != NULL ? discard_size : 0;
    direct.gathering = MAY_GATHER;
    direct.count = 0;
    direct.fd = -1;
    direct.message[0] = '\0';
}

static int discarded(const void *buffer, uint64_t size) {
    const uintptr_t at = (uintptr_t)buffer, begin = (uintptr_t)direct.discard;
    return direct.discard != NULL && at >= begin && at - begin <= direct.discard_size &&
           size <= direct.discard_size - (at - begin);
}

/* preadv() of `count` iovecs, `bytes` in all (at most SSIZE_MAX), from
 * `offset`, until all are read or the file ends: the bytes read, or -1
 * (errno says why). Both the gathered runs and the reads done at once. */
static int64_t read_fully(int fd, struct iovec *iov, int count, uint64_t offset, uint64_t bytes) {
    uint64_t done = 0;
    while (done < bytes) {
        const ssize_t got = preadv(fd, iov, count, (off_t)(offset + done));
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) return -1;
        if (got == 0) break; /* end of file */
        done += (uint64_t)got;
        /* past the iovecs read whole, and into the one read in part */
        size_t left = (size_t)got;
        while (count > 0 && left >= iov->iov_len) {
            left -= iov->iov_len;
            iov++;
            count--;
        }
        if (count > 0) {
            iov->iov_base = (char *)iov->iov_base + left;
            iov->iov_len -= left;
        }
    }
    return (int64_t)done;
}

/* A gathered run, read whole: NULL, or why not (direct.message). */
static const char *read_run(struct iovec *iov, int count, uint64_t offset, uint64_t bytes) {
    const int64_t got = read_fully(direct.fd, iov, count, offset, bytes);
    if (got < 0)
        snprintf(direct.message, sizeof direct.message, "cannot read the file: %s",
                 strerror(errno));
    else if ((uint64_t)got < bytes)
        snprintf(direct.message, sizeof direct.message,
                 "the file ends at byte %llu, inside its chunk (truncated while read?)",
                 (unsigned long long)(offset + (uint64_t)got));
    else
        return NULL;
    return direct.message;
}

/* The skipped reads from reads[from] on that lie between the run's end `at`
 * and the next gathered read, short enough to read along: how many (0:
 * none, the run ends here). */
static int gap_to_read_along(int from, uint64_t at) {
    uint64_t gap = 0;
    int k = from;
    while (k < direct.count && direct.reads[k].buffer == NULL &&
           direct.reads[k].offset == at + gap && gap + direct.reads[k].size <= GAP_BYTES)
        gap += direct.reads[k++].size;
    const bool joins =
        k < direct.count && direct.reads[k].buffer != NULL && direct.reads[k].offset == at + gap;
    return joins ? k - from : 0;
}

/* Does the gathered reads, a run of reads that follow each other in the
 * file per preadv(): NULL, or why a read failed. */
static const char *flush(void) {
    struct iovec iov[GATHERED_READS];
    int k = 0;
    while (k < direct.count) {
        if (direct.reads[k].buffer == NULL) { /* skipped, and not between two reads */
            k++;
            continue;
        }
        const uint64_t start = direct.reads[k].offset;
        uint64_t bytes = 0;
        int n = 0;
        while (k < direct.count && direct.reads[k].buffer != NULL &&
               direct.reads[k].offset == start + bytes) {
            iov[n++] = (struct iovec){direct.reads[k].buffer, (size_t)direct.reads[k].size};
            bytes += direct.reads[k++].size;
            const int gaps = gap_to_read_along(k, start + bytes);
            for (int g = 0; g < gaps; g++, k++) {
                iov[n++] = (struct iovec){(void *)direct.discard, (size_t)direct.reads[k].size};
                bytes += direct.reads[k].size;
            }
        }
        const char *why = read_run(iov, n, start, bytes);
        if (why != NULL) return why;
    }
    direct.count = 0;
    return NULL;
}

const char *exr_stream_direct_end(void) {
    const char *why = direct.message[0] != '\0' ? direct.message : flush();
    direct.gathering = false;
    direct.discard = NULL;
    direct.discard_size = 0;
    direct.count = 0;
    return why;
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
 * the file), or -1 after reporting the error. Safe from several threads.
 * During a direct decode (exr_stream_direct_begin) every read answers as a
 * whole read and is gathered: a skipped one is only noted, so that a short
 * one between two reads can be read along; the reader checks that every
 * chunk it decodes lies inside the file (read_chunk_info), and
 * exr_stream_direct_end reports a read that still comes up short. */
static int64_t stream_read(exr_const_context_t context, void *user_data, void *buffer,
                           uint64_t size, uint64_t offset, exr_stream_error_func_ptr_t error) {
    if (size > (uint64_t)SSIZE_MAX || offset > (uint64_t)INT64_MAX - size) {
        error(context, EXR_ERR_READ_IO, "read of %llu bytes at %llu is out of range",
              (unsigned long long)size, (unsigned long long)offset);
        return -1;
    }
    const int fd = stream_fd(user_data);
    if (direct.gathering) {
        if (direct.count == GATHERED_READS || (direct.count > 0 && fd != direct.fd)) {
            const char *why = flush();
            if (why != NULL) {
                error(context, EXR_ERR_READ_IO, "%s", why);
                return -1;
            }
        }
        direct.fd = fd;
        const bool skipped = discarded(buffer, size);
        direct.reads[direct.count++] =
            (gathered_read){skipped ? NULL : (char *)buffer, size, offset};
        return (int64_t)size;
    }
    if (discarded(buffer, size)) return (int64_t)size; /* a direct decode done at once */
    struct iovec whole = {buffer, (size_t)size};
    const int64_t got = read_fully(fd, &whole, 1, offset, size);
    if (got < 0) error(context, EXR_ERR_READ_IO, "cannot read the file: %s", strerror(errno));
    return got;
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
