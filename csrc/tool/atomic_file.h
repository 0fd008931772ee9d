/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Output files that appear complete or not at all, and that never replace
 * something that is not a regular file:
 *
 * - a regular file (or a name that does not exist yet): the data goes to a
 *   temporary file in the destination's directory, which is renamed over
 *   the destination only once everything has been written and flushed. It
 *   is unnamed (O_TMPFILE) until then where the file system and /proc allow,
 *   so that a run killed by any means leaves nothing; else, and for the
 *   moment between its naming and the rename, it is `.hbao-tmp-XXXXXX`.
 *   A failed run removes its temporary file and leaves any existing
 *   destination as it was. The temporary name has a fixed length,
 *   so that any legal destination name (up to NAME_MAX) works.
 * - a symbolic link: followed (also a dangling one); its final target is
 *   replaced as above and the link itself is kept.
 * - a FIFO or a character device (/dev/null, a terminal): written through,
 *   never replaced. The data goes to an unnamed temporary file first and is
 *   copied to the destination at commit, so a reader sees the whole image or
 *   nothing.
 * - a directory, a block device or a socket: refused (TOOL_EXIT_USAGE).
 *
 * SIGINT, SIGTERM and SIGHUP while a temporary file exists remove it, then
 * end the process by the same signal (so its exit status says so). A thread
 * of its own takes them (atomic_file_install_signal_handlers(), before any
 * other thread starts: every later thread blocks them), so several threads
 * may write files at once (the frames of a sequence).
 */
#ifndef HBAO_TOOL_ATOMIC_FILE_H
#define HBAO_TOOL_ATOMIC_FILE_H

#include <limits.h>
#include <signal.h>
#include <stdbool.h>

#include "tool_error.h"

#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

/** How many temporary files may exist at once and still be removed by a
 *  signal: two outputs (EXR, PNG) for each frame being computed. */
#define ATOMIC_FILE_MAX_OPEN 64

typedef struct atomic_file {
    int fd;                        /**< open on the temporary file; -1 once closed */
    const char *name;              /**< the destination as the user gave it, for messages */
    char destination[PATH_MAX];    /**< symbolic links followed */
    char temporary_path[PATH_MAX]; /**< its name; while unnamed, the name it will get;
                                        empty for write_through */
    bool active;                   /**< begun, not yet committed or aborted */
    bool write_through;            /**< FIFO or character device: copy, do not rename */
    bool unnamed;                  /**< O_TMPFILE: no name until commit (nothing to remove) */
    int cleanup_slot;              /**< the signal handler's record of temporary_path, or -1 */
} atomic_file;

/** A file on which atomic_file_abort() is a no-op, before atomic_file_begin(). */
#define ATOMIC_FILE_IDLE                                                                           \
    { .fd = -1, .cleanup_slot = -1 }

/** Prepare writing `destination` (kept by pointer for messages): create the
 *  temporary file (a new file's permissions: the umask or the folder's
 *  default ACL; an existing output's own where it replaces one) or refuse a
 *  destination that must not be written (a directory, a read-only file). */
int atomic_file_begin(atomic_file *file, const char *destination, tool_error *error);

/** `path` with its symbolic links followed, a dangling one too (where
 *  atomic_file_begin writes a regular file): the name that is replaced. */
int atomic_file_follow_links(const char *path, char resolved[PATH_MAX], tool_error *error);

/** Flush the temporary file and put it in place (rename or copy through).
 *  On failure the temporary file is removed. */
int atomic_file_commit(atomic_file *file, tool_error *error);

/** Whether two begun files would put their data in the same place (two
 *  names of one file: "./a.exr" and "a.exr", a link and its target; one
 *  FIFO or device, /dev/stdout and /proc/self/fd/1). */
bool atomic_file_same_destination(const atomic_file *a, const atomic_file *b);

/** Remove the temporary file (no-op when nothing is pending). */
void atomic_file_abort(atomic_file *file);

/** Start the thread that takes the signals now, and block them in the
 *  calling thread and so in every thread it starts later (where that thread
 *  cannot start: signal handlers). atomic_file_begin() does it too; call it
 *  before any thread starts (a thread started earlier could take a signal
 *  and end the process without the cleanup). */
void atomic_file_install_signal_handlers(void);

/** Block (and restore) the signals that remove temporary files, in the
 *  calling thread: threads started in between inherit the block. */
void atomic_file_block_signals(sigset_t *previous);
void atomic_file_restore_signals(const sigset_t *previous);

#endif /* HBAO_TOOL_ATOMIC_FILE_H */
