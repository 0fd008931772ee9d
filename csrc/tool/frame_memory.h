/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Memory for a frame's planes: the passes the tool reads and the AO it
 * computes. A process faults every page of them in and has the kernel
 * clear it; in 4 KiB pages that was a sixth of a 1080p frame's CPU time on
 * one thread (clear_page; docs/speed.md, session 63), in huge pages a few
 * milliseconds where the kernel has them at hand. --keep-input's copies of
 * every channel stay in malloc's memory: in huge pages too (120 MB a
 * frame), that frame took 1.03-1.05 of the time on the VM measured, whose
 * kernel cleared huge pages it had not used lately at a tenth of the speed
 * (a 320 MB buffer: 250 ms the first time, 34 ms the next). */
#ifndef HBAO_FRAME_MEMORY_H
#define HBAO_FRAME_MEMORY_H

#include <stddef.h>

/** `bytes` of memory, not cleared, or NULL (out of memory, or 0 bytes).
 *  A plane of 2 MiB or more (with a 64-byte header) is a mapping of its
 *  own, of whole huge pages, which the kernel is asked to back with huge pages (transparent
 *  huge pages "madvise", Debian's setting, do not otherwise; a hint, which
 *  a kernel may ignore). Freed by frame_memory_free, never by free(). */
void *frame_memory_alloc(size_t bytes);

/** Frees what frame_memory_alloc gave; NULL: nothing. */
void frame_memory_free(void *memory);

#endif /* HBAO_FRAME_MEMORY_H */
