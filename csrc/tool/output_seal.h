/* SPDX-License-Identifier: GPL-2.0-or-later */
/* A seal on each EXR the tool writes, and on its --preview PNG: the CRC-32 of
 * the file's bytes and its size, and the file name, size and modification
 * time of the input it was computed from, kept in the file's extended
 * attribute OUTPUT_SEAL_ATTRIBUTE. A
 * sequence rerun (sequence_command.c) takes a sealed output whose bytes
 * still match, and whose input is still the file it was computed from, as
 * up to date without decoding it (a read and a CRC, about a millisecond a
 * 1080p frame, against ~17 ms of inflate). It redoes one whose bytes changed
 * since (a block overwritten in place, a hole punched, an interrupted rsync
 * --inplace), and one whose input is another file now though not a newer
 * one (another render copied over it with its time kept, cp -p or rsync -a;
 * another frame's output moved into its place). The input is named by name,
 * size and time (a time rounded down by a coarser file system's copy is the
 * same), not by content: two files of one name, size and time pass for one.
 * A --preview PNG is sealed the same way, as computed from its EXR (the
 * EXR's name, size and time, where the EXR's seal names the render): another
 * frame's whole preview copied into its place with its attributes, or one
 * left from before its EXR was computed again, is redone. Not in the file
 * itself: the same input and flags still write the same bytes. Where the
 * file system keeps no user extended attributes, or a copy dropped them (cp
 * without -a, scp), there is no seal, and the rerun decodes the output whole
 * instead, and checks the preview's PNG chunks (png_check.h). */
#ifndef HBAO_OUTPUT_SEAL_H
#define HBAO_OUTPUT_SEAL_H

#include <sys/stat.h>

#define OUTPUT_SEAL_ATTRIBUTE "user.hbao.crc32"

typedef enum output_seal_state {
    OUTPUT_SEAL_ABSENT,  /**< no seal, or one this version cannot read */
    OUTPUT_SEAL_MATCHES, /**< the bytes are the ones sealed, from the same input */
    OUTPUT_SEAL_DIFFERS, /**< the bytes or the input changed since, or cannot be read */
} output_seal_state;

/** Seals the complete file open as fd (the output's temporary, before it is
 *  renamed into place), computed from the input at input_path whose status
 *  (stat) was `input` when it was read. Best effort: where the file system refuses the
 *  attribute, the file stays unsealed. */
void output_seal_attach(int fd, const char *input_path, const struct stat *input);

/** The seal of the file open as fd against its bytes now and its input
 *  now: its path (by the file's own name) and status. */
output_seal_state output_seal_check(int fd, const char *input_path, const struct stat *input);

#endif /* HBAO_OUTPUT_SEAL_H */
