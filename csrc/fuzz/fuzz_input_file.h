/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * The tool reads EXRs by path (OpenEXRCore opens the file itself), so each
 * fuzz input is written to one scratch file per process, reused for every
 * execution.
 */
#ifndef HBAO_FUZZ_INPUT_FILE_H
#define HBAO_FUZZ_INPUT_FILE_H

#include <stddef.h>
#include <stdint.h>

/** The scratch file's path, holding exactly data[0..size); aborts on I/O
 *  failure (a broken fuzzing setup, not a finding). */
const char *fuzz_input_file(const uint8_t *data, size_t size);

/** A scratch folder of this process, removed at exit; targets write only
 *  out.exr and out.png in it. */
const char *fuzz_scratch_folder(void);

/** The largest image the compute targets process (pixels), so that each
 *  execution stays around a millisecond; larger headers are still parsed. */
#define FUZZ_MAX_PIXELS (128 * 128)

#endif /* HBAO_FUZZ_INPUT_FILE_H */
