/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "atomic_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int atomic_file_begin(atomic_file *file, const char *destination, tool_error *error)
{
    memset(file, 0, sizeof *file);
    file->fd = -1;
    if (strlen(destination) >= sizeof file->destination)
        return tool_fail(error, TOOL_EXIT_USAGE, "output path too long: %s", destination);
    strcpy(file->destination, destination);

    /* Same directory as the destination, so that rename() stays on one file
     * system; a leading dot keeps it out of casual directory listings. */
    const char *slash = strrchr(destination, '/');
    int directory_length = slash ? (int)(slash - destination + 1) : 0;
    const char *base = destination + directory_length;
    int written = snprintf(file->temporary_path, sizeof file->temporary_path,
                           "%.*s.%s.hbao-tmp-XXXXXX", directory_length, destination, base);
    if (written < 0 || (size_t)written >= sizeof file->temporary_path)
        return tool_fail(error, TOOL_EXIT_USAGE, "output path too long: %s", destination);

    file->fd = mkstemp(file->temporary_path);
    if (file->fd < 0)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot create a file next to %s: %s",
                         destination, strerror(errno));
    file->active = true;
    /* mkstemp creates 0600; give the result the permissions a plain
     * open(O_CREAT, 0666) would have. */
    mode_t mask = umask(0);
    umask(mask);
    if (fchmod(file->fd, 0666 & ~mask) != 0) {
        int saved = errno;
        atomic_file_abort(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot set permissions of %s: %s",
                         destination, strerror(saved));
    }
    return TOOL_EXIT_SUCCESS;
}

int atomic_file_commit(atomic_file *file, tool_error *error)
{
    if (!file->active) return tool_fail(error, TOOL_EXIT_RUNTIME, "internal: nothing to commit");
    if (fsync(file->fd) != 0 || close(file->fd) != 0) {
        int saved = errno;
        file->fd = -1;
        atomic_file_abort(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: %s", file->destination,
                         strerror(saved));
    }
    file->fd = -1;
    if (rename(file->temporary_path, file->destination) != 0) {
        int saved = errno;
        atomic_file_abort(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot create %s: %s", file->destination,
                         strerror(saved));
    }
    file->active = false;
    return TOOL_EXIT_SUCCESS;
}

void atomic_file_abort(atomic_file *file)
{
    if (file->fd >= 0) close(file->fd);
    file->fd = -1;
    if (file->active) unlink(file->temporary_path);
    file->active = false;
}
