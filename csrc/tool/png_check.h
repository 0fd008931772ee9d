/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Whether a PNG file is whole, by the format's own checks: the signature,
 * then chunks whose CRC-32s match, up to an IEND chunk that ends the file.
 * A sequence rerun (sequence_command.c) redoes a frame whose --preview is
 * not: one cut short by an interrupted copy, emptied, or damaged in place
 * is otherwise as new as its EXR and would be skipped. The check of a
 * preview without a seal (output_seal.h: no user extended attributes on the
 * file system, or a copy that dropped them), so it holds on every file
 * system; a preview is small (a 1080p one well under a megabyte), its read
 * and CRC a fraction of a millisecond. */
#ifndef HBAO_PNG_CHECK_H
#define HBAO_PNG_CHECK_H

#include <stdbool.h>

/** True where fd is open on a regular PNG file whose every chunk's CRC
 *  matches, up to IEND at its end; false for anything else, an unreadable
 *  file included. Reads from the file's start (moving fd's offset); fd
 *  stays open. (The caller opens it without blocking: a FIFO of that name
 *  would wait for a writer.) */
bool png_fd_is_whole(int fd);

#endif /* HBAO_PNG_CHECK_H */
