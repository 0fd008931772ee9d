/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Blocks in huge pages (huge_block.h says why). */
#ifndef _DEFAULT_SOURCE
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS, madvise */
#endif
#include "huge_block.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#if !defined(MAP_ANONYMOUS) && defined(MAP_ANON)
#define MAP_ANONYMOUS MAP_ANON /* older BSDs and macOS */
#endif

/* Before the caller's memory: the mapping's length (0 for a block from
 * malloc), then the caller's capacity. 64 bytes, so that a mapped block's
 * memory starts on a cache line; one from malloc is aligned as malloc
 * aligns (16 bytes), which floats and bytes need. */
#define HEADER ((size_t)64)

typedef struct block_header {
    size_t length;
    size_t capacity;
} block_header;

static void *with_header(unsigned char *start, size_t length, size_t capacity) {
    const block_header header = {length, capacity};
    memcpy(start, &header, sizeof header);
    return start + HEADER;
}

static block_header header_of(const void *memory) {
    block_header header;
    memcpy(&header, (const unsigned char *)memory - HEADER, sizeof header);
    return header;
}

void *hbao_huge_block_alloc(size_t bytes) {
    if (bytes > SIZE_MAX / 2 - 2 * HBAO_HUGE_PAGE) return NULL;
    if (!HBAO_HUGE_BLOCK_MAPS || HEADER + bytes < HBAO_HUGE_PAGE) {
        unsigned char *block = malloc(HEADER + bytes);
        return block == NULL ? NULL : with_header(block, 0, bytes);
    }
    /* Whole huge pages, starting on one: mapped with a huge page to spare,
     * then the spare part before and after unmapped. */
    const size_t length = (HEADER + bytes + HBAO_HUGE_PAGE - 1) / HBAO_HUGE_PAGE * HBAO_HUGE_PAGE;
    const size_t mapped = length + HBAO_HUGE_PAGE;
    unsigned char *map =
        mmap(NULL, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (map == MAP_FAILED) return NULL;
    const size_t lead = (HBAO_HUGE_PAGE - (uintptr_t)map % HBAO_HUGE_PAGE) % HBAO_HUGE_PAGE;
    if (lead > 0) (void)munmap(map, lead);
    if (mapped - lead > length) (void)munmap(map + lead + length, mapped - lead - length);
    unsigned char *start = map + lead;
#if defined(MADV_HUGEPAGE)
    (void)madvise(start, length, MADV_HUGEPAGE);
#endif
    return with_header(start, length, length - HEADER);
}

size_t hbao_huge_block_capacity(const void *memory) {
    return header_of(memory).capacity;
}

void hbao_huge_block_free(void *memory) {
    if (memory == NULL) return;
    unsigned char *start = (unsigned char *)memory - HEADER;
    const size_t length = header_of(memory).length;
    if (length == 0)
        free(start);
    else
        (void)munmap(start, length);
}
