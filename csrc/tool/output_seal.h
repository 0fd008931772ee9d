/* SPDX-License-Identifier: GPL-2.0-or-later */
/* A seal on each EXR the tool writes: the CRC-32 of the file's bytes and its
 * size, kept in the file's extended attribute OUTPUT_SEAL_ATTRIBUTE. A
 * sequence rerun (sequence_command.c) takes a sealed output whose bytes
 * still match as whole without decoding it (a read and a CRC, about a
 * millisecond a 1080p frame, against ~17 ms of inflate), and redoes one
 * whose bytes changed since (a block overwritten in place, a hole punched,
 * an interrupted rsync --inplace). Where the file system keeps no user
 * extended attributes, or a copy dropped them (cp without -a, scp), there is
 * no seal, and the rerun decodes the output whole instead. */
#ifndef HBAO_OUTPUT_SEAL_H
#define HBAO_OUTPUT_SEAL_H

#define OUTPUT_SEAL_ATTRIBUTE "user.hbao.crc32"

typedef enum output_seal_state {
    OUTPUT_SEAL_ABSENT,  /**< no seal, or one this version cannot read */
    OUTPUT_SEAL_MATCHES, /**< the bytes are the ones sealed */
    OUTPUT_SEAL_DIFFERS, /**< the bytes changed since, or cannot be read */
} output_seal_state;

/** Seals the complete file open as fd (the output's temporary, before it is
 *  renamed into place). Best effort: where the file system refuses the
 *  attribute, the file stays unsealed. */
void output_seal_attach(int fd);

/** The seal of the file open as fd against its bytes now. */
output_seal_state output_seal_check(int fd);

#endif /* HBAO_OUTPUT_SEAL_H */
