/* SPDX-License-Identifier: GPL-2.0-or-later */
#define _DEFAULT_SOURCE /* realpath */
#include "canonical_path.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool canonical_path(const char *path, char out[PATH_MAX]) {
    const char *slash = strrchr(path, '/');
    char folder[PATH_MAX], real[PATH_MAX];
    if (slash == NULL) {
        strcpy(folder, ".");
    } else if (slash == path) {
        strcpy(folder, "/");
    } else {
        const int written = snprintf(folder, sizeof folder, "%.*s", (int)(slash - path), path);
        if (written < 0 || written >= PATH_MAX) return false;
    }
    if (realpath(folder, real) == NULL) return false;
    const int written = snprintf(out, PATH_MAX, "%s/%s", real, slash != NULL ? slash + 1 : path);
    return written > 0 && written < PATH_MAX;
}
