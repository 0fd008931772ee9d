/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The library's scratch asks for huge pages with the same hint
 * (csrc/lib/scratch.c), but its blocks come from posix_memalign and are
 * kept from call to call. A plane here is mapped, not taken from malloc:
 * in the C library's heap the hint stays on the heap's pages after a plane
 * is freed, and each time the heap shrinks and grows again (the EXR
 * writer's chunk buffers) the kernel clears a whole huge page for a few
 * kilobytes: with planes from posix_memalign, --keep-input took 1.04 of the
 * time, not less. Under AddressSanitizer (or HWASan) every plane comes from
 * malloc, so that the sanitizer's bounds stay at the plane's own (a mapping
 * rounds up to 2 MiB). */
#ifndef _DEFAULT_SOURCE
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS, madvise */
#endif
#include "frame_memory.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_HWADDRESS__)
#define FRAME_MEMORY_MAPS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(hwaddress_sanitizer)
#define FRAME_MEMORY_MAPS 0
#endif
#endif
#ifndef FRAME_MEMORY_MAPS
#define FRAME_MEMORY_MAPS 1
#endif
#if !defined(MAP_ANONYMOUS) && defined(MAP_ANON)
#define MAP_ANONYMOUS MAP_ANON /* older BSDs and macOS */
#endif

/* The size of a huge page on x86-64, and on ARM64 with 4 KiB pages. */
#define HUGE_PAGE ((size_t)2 << 20)
/* Before the plane: the mapping's length, 0 for a block from malloc. 64
 * bytes, so that a mapped plane starts on a cache line; one from malloc is
 * aligned as malloc aligns (16 bytes), which floats and bytes need. */
#define HEADER ((size_t)64)

void *frame_memory_alloc(size_t bytes) {
    if (bytes == 0 || bytes > SIZE_MAX / 2 - 2 * HUGE_PAGE) return NULL;
    if (!FRAME_MEMORY_MAPS || HEADER + bytes < HUGE_PAGE) {
        unsigned char *block = malloc(HEADER + bytes);
        if (block == NULL) return NULL;
        *(size_t *)block = 0;
        return block + HEADER;
    }
    /* Whole huge pages, starting on one: mapped with a huge page to spare,
     * then the spare part before and after unmapped. */
    const size_t length = (HEADER + bytes + HUGE_PAGE - 1) / HUGE_PAGE * HUGE_PAGE;
    const size_t mapped = length + HUGE_PAGE;
    unsigned char *map =
        mmap(NULL, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (map == MAP_FAILED) return NULL;
    const size_t lead = (HUGE_PAGE - (uintptr_t)map % HUGE_PAGE) % HUGE_PAGE;
    if (lead > 0) (void)munmap(map, lead);
    if (mapped - lead > length) (void)munmap(map + lead + length, mapped - lead - length);
    unsigned char *start = map + lead;
#if defined(MADV_HUGEPAGE)
    (void)madvise(start, length, MADV_HUGEPAGE);
#endif
    *(size_t *)start = length;
    return start + HEADER;
}

void frame_memory_free(void *memory) {
    if (memory == NULL) return;
    unsigned char *start = (unsigned char *)memory - HEADER;
    const size_t length = *(size_t *)start;
    if (length == 0)
        free(start);
    else
        (void)munmap(start, length);
}
