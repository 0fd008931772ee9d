/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Output files that appear complete or not at all: the data goes to a
 * temporary file in the destination's directory, which is renamed over the
 * destination only once everything has been written and flushed. A failed
 * run removes its temporary file and leaves any existing destination as it
 * was.
 */
#ifndef HBAO_TOOL_ATOMIC_FILE_H
#define HBAO_TOOL_ATOMIC_FILE_H

#include <limits.h>
#include <stdbool.h>

#include "tool_error.h"

#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

typedef struct atomic_file {
    int fd;                          /**< open on the temporary file; -1 once closed */
    char destination[PATH_MAX];
    char temporary_path[PATH_MAX];
    bool active;                     /**< the temporary file exists */
} atomic_file;

/** Create the temporary file for `destination` (mode 0666 & ~umask). */
int atomic_file_begin(atomic_file *file, const char *destination, tool_error *error);

/** Flush, close and rename the temporary file over the destination. On
 *  failure the temporary file is removed. */
int atomic_file_commit(atomic_file *file, tool_error *error);

/** Remove the temporary file (no-op when nothing is pending). */
void atomic_file_abort(atomic_file *file);

#endif /* HBAO_TOOL_ATOMIC_FILE_H */
