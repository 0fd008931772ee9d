/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Blocks of memory for a frame's planes, in huge pages where they are
 * large enough: the one place that says how, for the library's scratch
 * (csrc/lib/scratch.c, its blocks kept from call to call) and the tool's
 * planes (the passes it reads and the AO it computes, ao_command.c). This
 * source is compiled into both, as the library hides its internals from the
 * tool.
 *
 * Why huge pages (docs/speed.md):
 * - the search's samples reach hundreds of rows away, over more 4 KiB pages
 *   than the TLB holds (bench_ab_pairs.sh, 1080p defaults on a Zen 3: 0.968
 *   and 0.977 of the time on 1 thread, 0.992 on 2; 8 x 6 + blur 15 0.982);
 * - a process faults every page of a new plane in and has the kernel clear
 *   it: in 4 KiB pages a sixth of a CLI frame's CPU time on one thread, in
 *   huge pages a few milliseconds where the kernel has them at hand (session
 *   63).
 * Why mapped, each block on its own, and not from malloc: a block may land
 * in the C library's heap (glibc raises its mapping threshold by itself
 * after a large free, and a host may raise it), and there the hint stays on the heap's pages
 * after the block is freed, and each time the heap shrinks and grows again
 * the kernel clears a whole huge page for a few kilobytes (a draft of the
 * tool's planes from posix_memalign: --keep-input took 1.04 of the time);
 * and a freed block goes back to the system at once, whatever malloc's
 * thresholds. */
#ifndef HBAO_HUGE_BLOCK_H
#define HBAO_HUGE_BLOCK_H

#include <stddef.h>

/* HBAO_HUGE_BLOCK_MAPS: 1 where blocks of 2 MiB or more are mappings of
 * their own; 0 under AddressSanitizer or HWASan, where every block comes
 * from malloc, so that the sanitizer's bounds stay at the block's own. */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_HWADDRESS__)
#define HBAO_HUGE_BLOCK_MAPS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(hwaddress_sanitizer)
#define HBAO_HUGE_BLOCK_MAPS 0
#endif
#endif
#ifndef HBAO_HUGE_BLOCK_MAPS
#define HBAO_HUGE_BLOCK_MAPS 1
#endif

/** The size of a huge page on x86-64, and on ARM64 with 4 KiB pages. */
#define HBAO_HUGE_PAGE ((size_t)2 << 20)

/** At least `bytes` of memory (0 included), not cleared, aligned as malloc
 *  aligns (a mapped block on 64 bytes), or NULL (out of memory, or about
 *  SIZE_MAX / 2 bytes or more). A block of 2 MiB or more (with its 64-byte
 *  header) is a mapping of its own, of whole huge pages, which the kernel is
 *  asked to back with huge pages (MADV_HUGEPAGE: transparent huge pages
 *  "madvise", Debian's setting, do not otherwise; a hint, which a kernel
 *  may ignore), unless HBAO_HUGE_BLOCK_MAPS is 0. A smaller one comes from
 *  malloc. Freed by hbao_huge_block_free, never by free(). */
void *hbao_huge_block_alloc(size_t bytes);

/** The bytes a block from hbao_huge_block_alloc holds for its caller:
 *  those asked for, or more (a mapping's whole huge pages). */
size_t hbao_huge_block_capacity(const void *memory);

/** Frees what hbao_huge_block_alloc gave; NULL: nothing. */
void hbao_huge_block_free(void *memory);

#endif /* HBAO_HUGE_BLOCK_H */
