/* SPDX-License-Identifier: GPL-2.0-or-later */
/* One spelling for the names of one file: the folder made canonical
 * (realpath: "./", "../" and links on the way resolved), the file's own name
 * kept, so that it need not exist yet. Compares outputs with each other. */
#ifndef HBAO_TOOL_CANONICAL_PATH_H
#define HBAO_TOOL_CANONICAL_PATH_H

#include <stdbool.h>

#include "atomic_file.h" /* PATH_MAX */

/** `path` with its folder made canonical into `out`; false where the folder
 *  cannot be resolved (it does not exist) or the result does not fit. */
bool canonical_path(const char *path, char out[PATH_MAX]);

/** Whether `a` and `b` name one folder entry: the same name in one folder,
 *  the folders compared by device and inode, so that two mount points of
 *  one folder (a bind mount, one export mounted twice), which realpath
 *  keeps apart, are one; false where a folder cannot be looked up. */
bool canonical_same_entry(const char *a, const char *b);

#endif /* HBAO_TOOL_CANONICAL_PATH_H */
