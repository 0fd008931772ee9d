/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Whether a PNG file is whole, by the format's own checks: the signature,
 * then chunks whose CRC-32s match, up to an IEND chunk that ends the file.
 * A sequence rerun (sequence_command.c) redoes a frame whose --preview is
 * not: one cut short by an interrupted copy, emptied, or damaged in place
 * is otherwise as new as its EXR and would be skipped. Needs no extended
 * attribute (output_seal.h), so it holds on every file system; a preview is
 * small (a 1080p one well under a megabyte), its read and CRC a fraction of
 * a millisecond. */
#ifndef HBAO_PNG_CHECK_H
#define HBAO_PNG_CHECK_H

#include <stdbool.h>

/** True where `path` is a regular PNG file whose every chunk's CRC matches,
 *  up to IEND at its end; false for anything else, an unreadable file and
 *  a FIFO (not waited on) included. */
bool png_file_is_whole(const char *path);

#endif /* HBAO_PNG_CHECK_H */
