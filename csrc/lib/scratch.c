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
#include <string.h>

#include "huge_block.h"
#include "internal_hbao.h"

/* A block of at least a huge page is a mapping of whole huge pages
 * (csrc/memory/huge_block.h), so hbao_release_memory() hands it back to
 * the system whatever the host's malloc thresholds. */
#define SCRATCH_BLOCKS 16
#define SCRATCH_MAX_BYTES ((size_t)512 << 20)

typedef struct kept_block {
    void *memory;    /* NULL: free slot */
    size_t capacity; /* hbao_huge_block_capacity(memory) */
} kept_block;

static pthread_mutex_t scratch_lock = PTHREAD_MUTEX_INITIALIZER;
static kept_block kept[SCRATCH_BLOCKS];
static size_t kept_bytes;

int (*hbao_scratch_fails)(size_t bytes) = NULL;
int hbao_scratch_fill = -1;

void *hbao_scratch_take(size_t bytes) {
    if (hbao_scratch_fails != NULL && hbao_scratch_fails(bytes)) return NULL;
    void *memory = NULL;
    pthread_mutex_lock(&scratch_lock);
    int best = -1;
    for (int k = 0; k < SCRATCH_BLOCKS; k++) /* the smallest that fits */
        if (kept[k].memory != NULL && kept[k].capacity >= bytes &&
            (best < 0 || kept[k].capacity < kept[best].capacity))
            best = k;
    if (best >= 0) {
        memory = kept[best].memory;
        kept_bytes -= kept[best].capacity;
        kept[best].memory = NULL;
    }
    pthread_mutex_unlock(&scratch_lock);
    if (memory == NULL) memory = hbao_huge_block_alloc(bytes);
    if (memory == NULL) return NULL;
    if (hbao_scratch_fill >= 0) memset(memory, hbao_scratch_fill, hbao_huge_block_capacity(memory));
    return memory;
}

void hbao_scratch_give(void *memory) {
    if (memory == NULL) return;
    const size_t capacity = hbao_huge_block_capacity(memory);
    if (capacity > SCRATCH_MAX_BYTES) { /* never kept: dropping the kept blocks makes no room */
        hbao_huge_block_free(memory);
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
            if (kept[k].memory == NULL) {
                if (slot < 0) slot = k;
            } else if (smallest < 0 || kept[k].capacity < kept[smallest].capacity) {
                smallest = k;
            }
        }
        const int fits = capacity <= SCRATCH_MAX_BYTES - kept_bytes;
        if ((slot >= 0 && fits) || smallest < 0 || kept[smallest].capacity >= capacity) break;
        hbao_huge_block_free(kept[smallest].memory);
        kept_bytes -= kept[smallest].capacity;
        kept[smallest].memory = NULL;
    }
    if (slot >= 0 && capacity <= SCRATCH_MAX_BYTES - kept_bytes) {
        kept[slot].memory = memory;
        kept[slot].capacity = capacity;
        kept_bytes += capacity;
        memory = NULL;
    }
    pthread_mutex_unlock(&scratch_lock);
    hbao_huge_block_free(memory); /* not kept: no room */
}

void hbao_release_memory(void) {
    pthread_mutex_lock(&scratch_lock);
    for (int k = 0; k < SCRATCH_BLOCKS; k++) {
        hbao_huge_block_free(kept[k].memory);
        kept[k].memory = NULL;
    }
    kept_bytes = 0;
    pthread_mutex_unlock(&scratch_lock);
}
