/* SPDX-License-Identifier: GPL-2.0-or-later */
#define _DEFAULT_SOURCE /* realpath */
#include "canonical_path.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* `path`'s folder into `folder` ("." for a bare name, "/" at the root);
 * its name's start, or NULL where the folder does not fit. */
static const char *split_folder(const char *path, char folder[PATH_MAX]) {
    const char *slash = strrchr(path, '/');
    if (slash == NULL) {
        strcpy(folder, ".");
        return path;
    }
    if (slash == path) {
        strcpy(folder, "/");
        return slash + 1;
    }
    const int written = snprintf(folder, PATH_MAX, "%.*s", (int)(slash - path), path);
    return written < 0 || written >= PATH_MAX ? NULL : slash + 1;
}

bool canonical_same_entry(const char *a, const char *b) {
    char first[PATH_MAX], second[PATH_MAX];
    const char *first_name = split_folder(a, first), *second_name = split_folder(b, second);
    struct stat first_folder, second_folder;
    return first_name != NULL && second_name != NULL && strcmp(first_name, second_name) == 0 &&
           stat(first, &first_folder) == 0 && stat(second, &second_folder) == 0 &&
           first_folder.st_dev == second_folder.st_dev &&
           first_folder.st_ino == second_folder.st_ino;
}

bool canonical_path(const char *path, char out[PATH_MAX]) {
    const char *slash = strrchr(path, '/');
    char folder[PATH_MAX], real[PATH_MAX];
    if (split_folder(path, folder) == NULL) return false;
    if (realpath(folder, real) == NULL) return false;
    const int written = snprintf(out, PATH_MAX, "%s/%s", real, slash != NULL ? slash + 1 : path);
    return written > 0 && written < PATH_MAX;
}
