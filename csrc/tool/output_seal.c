/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "output_seal.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <libdeflate.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/xattr.h>
#include <unistd.h>

/* "crc32 <8 hex digits> size <bytes> input <bytes> <seconds>.<nanoseconds>
 * <input's file name>": readable with getfattr. (An earlier version's
 * "crc32 ... size ..." names no input: it is read as no seal, and the rerun
 * decodes that output instead.) */
#define SEAL_TEXT_MAX (128 + NAME_MAX)
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

/* What a seal holds. */
typedef struct seal {
    uint32_t crc;
    int64_t size, input_size, input_seconds;
    long input_nanoseconds;
    const char *input_name; /* the file's own name, no folder */
} seal;

/* The file's own name in `path`: after its last '/'. */
static const char *file_name(const char *path) {
    const char *slash = strrchr(path, '/');
    return slash != NULL ? slash + 1 : path;
}

/* The seal's text into text[SEAL_TEXT_MAX]: its length, or -1 where it does
 * not fit. The one spelling: a seal is read back by parsing it and comparing
 * this text of what was parsed with the stored one. */
static int seal_text(const seal *v, char text[SEAL_TEXT_MAX]) {
    const int length = snprintf(
        text, SEAL_TEXT_MAX,
        "crc32 %08" PRIx32 " size %" PRId64 " input %" PRId64 " %" PRId64 ".%09ld %s", v->crc,
        v->size, v->input_size, v->input_seconds, v->input_nanoseconds, v->input_name);
    return length > 0 && length < SEAL_TEXT_MAX ? length : -1;
}

/* Parses a stored seal (NUL-terminated text of `length` bytes) into *v;
 * false where it is not the text seal_text writes. */
static bool seal_parse(const char *text, ssize_t length, seal *v) {
    int consumed = 0;
    if (sscanf(text, "crc32 %8" SCNx32 " size %" SCNd64 " input %" SCNd64 " %" SCNd64 ".%9ld%n",
               &v->crc, &v->size, &v->input_size, &v->input_seconds, &v->input_nanoseconds,
               &consumed) != 5 ||
        consumed <= 0 || consumed + 1 >= length || text[consumed] != ' ')
        return false;
    v->input_name = text + consumed + 1; /* the rest, spaces included */
    char canonical[SEAL_TEXT_MAX];
    const int canonical_length = seal_text(v, canonical);
    return canonical_length == length && memcmp(canonical, text, (size_t)length) == 0;
}

/* Whether a modification time read now (now_*) is the sealed one, or the
 * sealed one rounded down to a coarser file system's resolution, a power of
 * ten of nanoseconds up to a second, or FAT's two seconds (a copy that kept
 * times onto ext4 with small inodes, SMB, FAT): a shot copied with its
 * attributes is not recomputed for it. */
static bool same_time(int64_t sealed_seconds, long sealed_nanoseconds, int64_t now_seconds,
                      long now_nanoseconds) {
    if (now_seconds == sealed_seconds)
        for (long resolution = 1; resolution <= 1000000000L; resolution *= 10)
            if (now_nanoseconds == sealed_nanoseconds / resolution * resolution) return true;
    const int64_t even = sealed_seconds - (sealed_seconds % 2 + 2) % 2;
    return now_nanoseconds == 0 && now_seconds == even;
}

void output_seal_attach(int fd, const char *input_path, const struct stat *input) {
    seal v = {0,
              0,
              (int64_t)input->st_size,
              (int64_t)input->st_mtim.tv_sec,
              (long)input->st_mtim.tv_nsec,
              file_name(input_path)};
    if (!file_crc(fd, &v.crc, &v.size)) return;
    char text[SEAL_TEXT_MAX];
    const int length = seal_text(&v, text);
    if (length > 0) (void)fsetxattr(fd, OUTPUT_SEAL_ATTRIBUTE, text, (size_t)length, 0);
}

output_seal_state output_seal_check(int fd, const char *input_path, const struct stat *input) {
    char text[SEAL_TEXT_MAX];
    const ssize_t length = fgetxattr(fd, OUTPUT_SEAL_ATTRIBUTE, text, sizeof text - 1);
    if (length <= 0) return OUTPUT_SEAL_ABSENT;
    text[length] = '\0';
    seal sealed;
    if (!seal_parse(text, length, &sealed)) return OUTPUT_SEAL_ABSENT;
    if (sealed.input_size != (int64_t)input->st_size ||
        strcmp(sealed.input_name, file_name(input_path)) != 0 ||
        !same_time(sealed.input_seconds, sealed.input_nanoseconds, (int64_t)input->st_mtim.tv_sec,
                   (long)input->st_mtim.tv_nsec))
        return OUTPUT_SEAL_DIFFERS; /* computed from another file */
    uint32_t crc = 0;
    int64_t size = 0;
    if (!file_crc(fd, &crc, &size)) return OUTPUT_SEAL_DIFFERS;
    return crc == sealed.crc && size == sealed.size ? OUTPUT_SEAL_MATCHES : OUTPUT_SEAL_DIFFERS;
}
