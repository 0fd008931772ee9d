/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "output_seal.h"

#include <errno.h>
#include <inttypes.h>
#include <libdeflate.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/xattr.h>
#include <unistd.h>

/* "crc32 <8 hex digits> size <bytes> input <bytes> <seconds>.<nanoseconds>":
 * readable with getfattr. (Session 40's "crc32 ... size ..." without the
 * input is read as no seal: the rerun decodes that output instead.) */
#define SEAL_TEXT_MAX 128
#define READ_BLOCK (1u << 20)

/* The CRC-32 and size of the regular file open as fd, read from its start. */
static bool file_crc(int fd, uint32_t *crc, int64_t *size) {
    struct stat status;
    if (fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) return false;
    uint8_t *block = malloc(READ_BLOCK);
    if (block == NULL) return false;
    uint32_t sum = 0;
    int64_t offset = 0;
    bool ok = true;
    for (;;) {
        const ssize_t got = pread(fd, block, READ_BLOCK, (off_t)offset);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            ok = false;
            break;
        }
        if (got == 0) break;
        sum = libdeflate_crc32(sum, block, (size_t)got);
        offset += got;
    }
    free(block);
    /* a file that grew or shrank while it was read is not the one stat saw */
    ok = ok && offset == (int64_t)status.st_size;
    *crc = sum;
    *size = offset;
    return ok;
}

void output_seal_attach(int fd, const struct stat *input) {
    uint32_t crc = 0;
    int64_t size = 0;
    if (!file_crc(fd, &crc, &size)) return;
    char text[SEAL_TEXT_MAX];
    const int length = snprintf(
        text, sizeof text,
        "crc32 %08" PRIx32 " size %" PRId64 " input %" PRId64 " %" PRId64 ".%09ld", crc, size,
        (int64_t)input->st_size, (int64_t)input->st_mtim.tv_sec, (long)input->st_mtim.tv_nsec);
    if (length > 0 && length < (int)sizeof text)
        (void)fsetxattr(fd, OUTPUT_SEAL_ATTRIBUTE, text, (size_t)length, 0);
}

output_seal_state output_seal_check(int fd, const struct stat *input) {
    char text[SEAL_TEXT_MAX];
    const ssize_t length = fgetxattr(fd, OUTPUT_SEAL_ATTRIBUTE, text, sizeof text - 1);
    if (length <= 0) return OUTPUT_SEAL_ABSENT;
    text[length] = '\0';
    uint32_t sealed_crc = 0;
    int64_t sealed_size = 0, input_size = 0, input_seconds = 0;
    long input_nanoseconds = 0;
    int consumed = 0;
    if (sscanf(text, "crc32 %8" SCNx32 " size %" SCNd64 " input %" SCNd64 " %" SCNd64 ".%9ld%n",
               &sealed_crc, &sealed_size, &input_size, &input_seconds, &input_nanoseconds,
               &consumed) != 5 ||
        consumed != length)
        return OUTPUT_SEAL_ABSENT;
    if (input_size != (int64_t)input->st_size || input_seconds != (int64_t)input->st_mtim.tv_sec ||
        input_nanoseconds != (long)input->st_mtim.tv_nsec)
        return OUTPUT_SEAL_DIFFERS; /* computed from another file */
    uint32_t crc = 0;
    int64_t size = 0;
    if (!file_crc(fd, &crc, &size)) return OUTPUT_SEAL_DIFFERS;
    return crc == sealed_crc && size == sealed_size ? OUTPUT_SEAL_MATCHES : OUTPUT_SEAL_DIFFERS;
}
