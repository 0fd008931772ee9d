/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Working memory kept from one call to the next. A frame's buffers (depth,
 * normals, raw AO, the deinterleaved depth: about 24 bytes per pixel) are
 * large enough that the C library hands them back to the kernel when they
 * are freed, and the next call then faults every page in again and has it
 * cleared: measured with csrc/bench/bench_ab.c, a fifth of a 1080p frame's
 * time. So a freed buffer is kept (up to SCRATCH_BLOCKS of them, at most
 * SCRATCH_MAX_BYTES together; smaller ones make room for larger ones) and
 * the next call takes the smallest that fits; hbao_release_memory() frees
 * them all. Thread-safe; which block a call
 * gets never changes its results (every buffer is written before it is
 * read). */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "huge_block.h"
#include "internal_hbao.h"

#define SCRATCH_BLOCKS 16
#define SCRATCH_MAX_BYTES ((size_t)512 << 20)
/* Each block starts with its capacity; the caller's memory follows, aligned
 * as malloc aligns. A block of at least a huge page is a mapping of whole
 * huge pages (csrc/memory/huge_block.h), so hbao_release_memory() hands it
 * back to the system whatever the host's malloc thresholds. */
#define HEADER ((size_t)64)

/* A new block for `bytes` (*bytes: its capacity, which may be larger). */
static unsigned char *new_block(size_t *bytes) {
    size_t whole = 0;
    unsigned char *start = hbao_huge_block_alloc(HEADER + *bytes, &whole);
    if (start != NULL) *bytes = whole - HEADER;
    return start;
}

typedef struct kept_block {
    unsigned char *start; /* NULL: free slot */
    size_t capacity;      /* bytes after the header */
} kept_block;

static pthread_mutex_t scratch_lock = PTHREAD_MUTEX_INITIALIZER;
static kept_block kept[SCRATCH_BLOCKS];
static size_t kept_bytes;

int (*hbao_scratch_fails)(size_t bytes) = NULL;
int hbao_scratch_fill = -1;

void *hbao_scratch_take(size_t bytes) {
    if (bytes > SIZE_MAX - HEADER) return NULL;
    if (hbao_scratch_fails != NULL && hbao_scratch_fails(bytes)) return NULL;
    unsigned char *start = NULL;
    pthread_mutex_lock(&scratch_lock);
    int best = -1;
    for (int k = 0; k < SCRATCH_BLOCKS; k++) /* the smallest that fits */
        if (kept[k].start != NULL && kept[k].capacity >= bytes &&
            (best < 0 || kept[k].capacity < kept[best].capacity))
            best = k;
    if (best >= 0) {
        start = kept[best].start;
        kept_bytes -= kept[best].capacity;
        kept[best].start = NULL;
    }
    pthread_mutex_unlock(&scratch_lock);
    if (start == NULL) {
        start = new_block(&bytes);
        if (start == NULL) return NULL;
        *(size_t *)start = bytes;
    }
    if (hbao_scratch_fill >= 0) memset(start + HEADER, hbao_scratch_fill, *(size_t *)start);
    return start + HEADER;
}

void hbao_scratch_give(void *memory) {
    if (memory == NULL) return;
    unsigned char *start = (unsigned char *)memory - HEADER;
    const size_t capacity = *(size_t *)start;
    if (capacity > SCRATCH_MAX_BYTES) { /* never kept: dropping the kept blocks makes no room */
        hbao_huge_block_free(start);
        return;
    }
    pthread_mutex_lock(&scratch_lock);
    int slot = -1;
    for (;;) {
        /* a free slot, else room made by dropping smaller kept blocks:
         * the sizes of the latest calls are the likeliest next */
        int smallest = -1;
        slot = -1;
        for (int k = 0; k < SCRATCH_BLOCKS; k++) {
            if (kept[k].start == NULL) {
                if (slot < 0) slot = k;
            } else if (smallest < 0 || kept[k].capacity < kept[smallest].capacity) {
                smallest = k;
            }
        }
        const int fits = capacity <= SCRATCH_MAX_BYTES - kept_bytes;
        if ((slot >= 0 && fits) || smallest < 0 || kept[smallest].capacity >= capacity) break;
        hbao_huge_block_free(kept[smallest].start);
        kept_bytes -= kept[smallest].capacity;
        kept[smallest].start = NULL;
    }
    if (slot >= 0 && capacity <= SCRATCH_MAX_BYTES - kept_bytes) {
        kept[slot].start = start;
        kept[slot].capacity = capacity;
        kept_bytes += capacity;
        start = NULL;
    }
    pthread_mutex_unlock(&scratch_lock);
    hbao_huge_block_free(start); /* not kept: no room */
}

void hbao_release_memory(void) {
    pthread_mutex_lock(&scratch_lock);
    for (int k = 0; k < SCRATCH_BLOCKS; k++) {
        hbao_huge_block_free(kept[k].start);
        kept[k].start = NULL;
    }
    kept_bytes = 0;
    pthread_mutex_unlock(&scratch_lock);
}
