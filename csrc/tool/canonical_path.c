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

bool canonical_entry_of(const char *path, canonical_entry *entry) {
    char folder[PATH_MAX];
    struct stat status;
    entry->name = split_folder(path, folder);
    if (entry->name == NULL || stat(folder, &status) != 0) return false;
    entry->device = status.st_dev;
    entry->inode = status.st_ino;
    return true;
}

int canonical_entry_compare(const canonical_entry *a, const canonical_entry *b) {
    if (a->device != b->device) return a->device < b->device ? -1 : 1;
    if (a->inode != b->inode) return a->inode < b->inode ? -1 : 1;
    return strcmp(a->name, b->name);
}

bool canonical_same_entry(const char *a, const char *b) {
    canonical_entry first, second;
    return canonical_entry_of(a, &first) && canonical_entry_of(b, &second) &&
           canonical_entry_compare(&first, &second) == 0;
}

bool canonical_path(const char *path, char out[PATH_MAX]) {
    const char *slash = strrchr(path, '/');
    char folder[PATH_MAX], real[PATH_MAX];
    if (split_folder(path, folder) == NULL) return false;
    if (realpath(folder, real) == NULL) return false;
    const int written = snprintf(out, PATH_MAX, "%s/%s", real, slash != NULL ? slash + 1 : path);
    return written > 0 && written < PATH_MAX;
}
