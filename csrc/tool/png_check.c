/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "png_check.h"

#include <fcntl.h>
#include <libdeflate.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define READ_BLOCK 16384u
/* PNG's limit on a chunk's length (2^31 - 1) */
#define MAX_CHUNK_LENGTH 0x7fffffffu

static bool read_exactly(FILE *file, uint8_t *bytes, size_t count) {
    return fread(bytes, 1, count, file) == count;
}

static uint32_t big_endian(const uint8_t bytes[4]) {
    return (uint32_t)bytes[0] << 24 | (uint32_t)bytes[1] << 16 | (uint32_t)bytes[2] << 8 |
           (uint32_t)bytes[3];
}

/* One chunk after its length and type (already read, the type into *crc):
 * its data through the CRC, then the stored CRC compared. */
static bool chunk_matches(FILE *file, uint32_t length, uint32_t crc, uint8_t *block) {
    while (length > 0) {
        const size_t part = length < READ_BLOCK ? length : READ_BLOCK;
        if (!read_exactly(file, block, part)) return false;
        crc = libdeflate_crc32(crc, block, part);
        length -= (uint32_t)part;
    }
    uint8_t stored[4];
    return read_exactly(file, stored, sizeof stored) && big_endian(stored) == crc;
}

static bool chunks_are_whole(FILE *file) {
    static const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    uint8_t head[8];
    if (!read_exactly(file, head, sizeof signature) || memcmp(head, signature, 8) != 0)
        return false;
    uint8_t block[READ_BLOCK];
    /* every chunk takes at least 12 bytes of a finite file: the loop ends */
    for (;;) {
        if (!read_exactly(file, head, sizeof head)) return false; /* no IEND */
        const uint32_t length = big_endian(head);
        if (length > MAX_CHUNK_LENGTH) return false;
        const uint32_t crc = libdeflate_crc32(0, head + 4, 4);
        if (!chunk_matches(file, length, crc, block)) return false;
        if (memcmp(head + 4, "IEND", 4) == 0) return length == 0 && fgetc(file) == EOF;
    }
}

bool png_fd_is_whole(int fd) {
    struct stat status;
    if (fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) return false;
    /* a descriptor of its own for the stream, so that fd stays open (it
     * shares fd's offset: read from the file's start) */
    const int own = fcntl(fd, F_DUPFD_CLOEXEC, 0);
    FILE *file = own >= 0 ? fdopen(own, "rb") : NULL;
    if (file == NULL) {
        if (own >= 0) close(own);
        return false;
    }
    const bool whole = fseeko(file, 0, SEEK_SET) == 0 && chunks_are_whole(file);
    fclose(file);
    return whole;
}
