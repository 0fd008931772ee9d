/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Rows handed out to worker threads from a shared counter. Which thread
 * computes a row never changes the row's values, so results are identical
 * for any number of threads. */
#if defined(__linux__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE /* hbao_cpus.h: sched_getaffinity */
#endif
#include <pthread.h>
#include <stdatomic.h>
#include <unistd.h> /* sysconf */

#include "hbao_cpus.h"
#include "internal_hbao.h"

/* Rows taken per grab: enough to keep the counter off the hot path, few
 * enough to balance rows of uneven cost (background vs. geometry): at most
 * HBAO_ROWS_PER_GRAB, and one where a job has under HBAO_GRABS_PER_THREAD
 * grabs of them for each thread. The search's tiles (136 at half
 * resolution in 1080p) and the stages' rows keep 4 a grab up to 17 threads
 * and more. The blur's jobs (bands, 4 per thread, or their strips of
 * columns) go one a grab (hbao_parallel_each): 4 to a grab handed a
 * 2-thread blur's sky bands to one thread and its geometry to the other,
 * which then took as long as without the sky (session 47: bench_ab_pairs.sh,
 * 8 x 6 + blur 15 with the upper half background, 1.003 of the time before
 * the blur skipped background vectors on 2 threads, 0.894 on 1); one band a
 * grab took 0.881 of the time before on 2 threads. */
#define HBAO_ROWS_PER_GRAB 4
#define HBAO_GRABS_PER_THREAD 2

static int rows_per_grab(int threads, int rows) {
    return rows / (HBAO_GRABS_PER_THREAD * HBAO_ROWS_PER_GRAB) >= threads ? HBAO_ROWS_PER_GRAB : 1;
}

typedef struct row_queue {
    atomic_int next_row;
    int rows, grab;
    hbao_row_job job;
    void *context;
} row_queue;

static void *drain_rows(void *argument) {
    row_queue *queue = argument;
    const int grab = queue->grab;
    for (;;) {
        const int first = atomic_fetch_add(&queue->next_row, grab);
        if (first >= queue->rows) break;
        const int last = first + grab < queue->rows ? first + grab : queue->rows;
        for (int row = first; row < last; row++) queue->job(queue->context, row);
    }
    return NULL;
}

int hbao_available_cores(void) {
    const int cores = hbao_usable_cpus();
    return cores > HBAO_MAX_THREADS ? HBAO_MAX_THREADS : cores;
}

long hbao_core_cache_bytes(void) {
#ifdef _SC_LEVEL2_CACHE_SIZE
    static atomic_long known = -1; /* asked once: CPUID traps to a VM's host */
    long bytes = atomic_load_explicit(&known, memory_order_relaxed);
    if (bytes < 0) {
        bytes = sysconf(_SC_LEVEL2_CACHE_SIZE);
        if (bytes < 0) bytes = 0;
        atomic_store_explicit(&known, bytes, memory_order_relaxed);
    }
    return bytes;
#else
    return 0;
#endif
}

int hbao_parallel_threads(int threads, int rows) {
    const int grab = rows_per_grab(threads, rows);
    const int useful = (rows + grab - 1) / grab;
    return threads > useful ? useful : threads;
}

/* job for rows [0, rows), `grab` at a time, on up to `threads` threads */
static void run_rows(int threads, int rows, int grab, hbao_row_job job, void *context) {
    row_queue queue;
    atomic_init(&queue.next_row, 0);
    queue.rows = rows;
    queue.grab = grab;
    queue.job = job;
    queue.context = context;

    pthread_t workers[HBAO_MAX_THREADS];
    int started = 0;
    for (int t = 1; t < threads; t++) {
        if (pthread_create(&workers[started], NULL, drain_rows, &queue) != 0) break;
        started++;
    }
    drain_rows(&queue);
    for (int t = 0; t < started; t++) pthread_join(workers[t], NULL);
}

void hbao_parallel_rows(int threads, int rows, hbao_row_job job, void *context) {
    run_rows(hbao_parallel_threads(threads, rows), rows, rows_per_grab(threads, rows), job,
             context);
}

int hbao_parallel_each_threads(int threads, int jobs) {
    return threads < jobs ? threads : jobs;
}

void hbao_parallel_each(int threads, int jobs, hbao_row_job job, void *context) {
    run_rows(hbao_parallel_each_threads(threads, jobs), jobs, 1, job, context);
}
