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

#include "internal_hbao.h"

#define SCRATCH_BLOCKS 16
#define SCRATCH_MAX_BYTES ((size_t)512 << 20)
/* Each block starts with its capacity; the caller's memory follows, aligned
 * as malloc aligns. */
#define HEADER ((size_t)64)

typedef struct kept_block {
    unsigned char *start; /* NULL: free slot */
    size_t capacity;      /* bytes after the header */
} kept_block;

static pthread_mutex_t scratch_lock = PTHREAD_MUTEX_INITIALIZER;
static kept_block kept[SCRATCH_BLOCKS];
static size_t kept_bytes;

void *hbao_scratch_take(size_t bytes) {
    if (bytes > SIZE_MAX - HEADER) return NULL;
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
        start = malloc(HEADER + bytes);
        if (start == NULL) return NULL;
        *(size_t *)start = bytes;
    }
    return start + HEADER;
}

void hbao_scratch_give(void *memory) {
    if (memory == NULL) return;
    unsigned char *start = (unsigned char *)memory - HEADER;
    const size_t capacity = *(size_t *)start;
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
        free(kept[smallest].start);
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
    free(start); /* not kept: no room */
}

void hbao_release_memory(void) {
    pthread_mutex_lock(&scratch_lock);
    for (int k = 0; k < SCRATCH_BLOCKS; k++) {
        free(kept[k].start);
        kept[k].start = NULL;
    }
    kept_bytes = 0;
    pthread_mutex_unlock(&scratch_lock);
}
