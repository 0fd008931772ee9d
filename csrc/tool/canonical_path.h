/* SPDX-License-Identifier: GPL-2.0-or-later */
/* One spelling for the names of one file: the folder made canonical
 * (realpath: "./", "../" and links on the way resolved), the file's own name
 * kept, so that it need not exist yet. Compares outputs with each other. */
#ifndef HBAO_TOOL_CANONICAL_PATH_H
#define HBAO_TOOL_CANONICAL_PATH_H

#include <stdbool.h>
#include <sys/types.h>

#include "atomic_file.h" /* PATH_MAX */

/** `path` with its folder made canonical into `out`; false where the folder
 *  cannot be resolved (it does not exist) or the result does not fit. */
bool canonical_path(const char *path, char out[PATH_MAX]);

/** A folder entry by identity: its folder's device and inode, so that two
 *  mount points of one folder (a bind mount, one export mounted twice),
 *  which realpath keeps apart, are one, and its name there. */
typedef struct canonical_entry {
    dev_t device;
    ino_t inode;
    const char *name; /**< within the path it was made from */
} canonical_entry;

/** `path`'s folder entry into *entry; false where its folder cannot be
 *  looked up (it does not exist) or the path does not fit. */
bool canonical_entry_of(const char *path, canonical_entry *entry);

/** An order of entries (qsort's): 0 where they are one. */
int canonical_entry_compare(const canonical_entry *a, const canonical_entry *b);

/** Whether `a` and `b` name one folder entry (canonical_entry); false where
 *  a folder cannot be looked up. */
bool canonical_same_entry(const char *a, const char *b);

#endif /* HBAO_TOOL_CANONICAL_PATH_H */
