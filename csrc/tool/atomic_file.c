/* SPDX-License-Identifier: GPL-2.0-or-later */
#if defined(__linux__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE /* O_TMPFILE */
#endif
#include "atomic_file.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "canonical_path.h"
#include "tool_error.h"

/* Linux's limit on symbolic links followed in one lookup (MAXSYMLINKS). */
#define SYMLINK_HOPS_MAX 40

/* --- removing temporary files when a signal ends the run -------------------
 * A thread of its own takes the signals (sigwait: take_signals): it waits
 * for the slots (slots_lock), under which every thread creates, names,
 * renames and removes its temporaries and records them, and keeps them, so
 * that no thread makes a temporary after it has looked; it unlinks those
 * recorded and ends the process by the same signal. A handler, which runs
 * in whatever thread the signal lands and can take no lock, once did this:
 * in a sequence its thread went over the slots while a worker created or
 * named a temporary, and an interrupted run left a frame's whole file
 * behind (a review's runs: 2 to 10 of 150 interrupted sequences). Where
 * that thread cannot start, that handler is still used
 * (remove_temporary_files); it may only use async-signal-safe calls. */

#define CLEANUP_SLOTS ATOMIC_FILE_MAX_OPEN

static const int cleanup_signals[] = {SIGINT, SIGTERM, SIGHUP};
#define CLEANUP_SIGNAL_COUNT (int)(sizeof cleanup_signals / sizeof cleanup_signals[0])

static char cleanup_paths[CLEANUP_SLOTS][PATH_MAX];
static volatile sig_atomic_t cleanup_active[CLEANUP_SLOTS];
static bool handlers_installed;
/* Frames of a sequence write their outputs from several threads: the slots
 * and the handler installation take turns. */
static pthread_mutex_t slots_lock = PTHREAD_MUTEX_INITIALIZER;
/* The cleanup signals that take_signals waits for: those not ignored when
 * installed (nohup's stay ignored). */
static sigset_t taken_signals;

static void unlink_recorded_temporaries(void) {
    for (int s = 0; s < CLEANUP_SLOTS; ++s)
        if (cleanup_active[s]) unlink(cleanup_paths[s]);
}

/* Die of `signal_number`, so that the parent (a shell, a render farm) sees
 * that the run was interrupted rather than a normal exit: its default
 * action, unblocked in this thread (take_signals'). */
static void die_of(int signal_number) {
    signal(signal_number, SIG_DFL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, signal_number);
    pthread_sigmask(SIG_UNBLOCK, &one, NULL);
    raise(signal_number);
    _exit(128 + signal_number); /* (not reached: the default action ends the process) */
}

static void remove_temporary_files(int signal_number) {
    unlink_recorded_temporaries();
    /* The signal is blocked while its handler runs: delivered on return. */
    signal(signal_number, SIG_DFL);
    raise(signal_number);
}

static void *take_signals(void *unused) {
    (void)unused;
    int signal_number = 0;
    while (sigwait(&taken_signals, &signal_number) != 0) continue;
    pthread_mutex_lock(&slots_lock); /* for good */
    unlink_recorded_temporaries();
    die_of(signal_number);
    return NULL;
}

/* The fallback: the handler in every thread that does not block the signals. */
static void install_handlers(void) {
    for (int i = 0; i < CLEANUP_SIGNAL_COUNT; ++i) {
        if (!sigismember(&taken_signals, cleanup_signals[i])) continue;
        struct sigaction action;
        memset(&action, 0, sizeof action);
        action.sa_handler = remove_temporary_files;
        sigfillset(&action.sa_mask); /* one handler at a time */
        sigaction(cleanup_signals[i], &action, NULL);
    }
}

void atomic_file_install_signal_handlers(void) {
    pthread_mutex_lock(&slots_lock);
    if (handlers_installed) {
        pthread_mutex_unlock(&slots_lock);
        return;
    }
    handlers_installed = true;
    sigemptyset(&taken_signals);
    bool any = false;
    for (int i = 0; i < CLEANUP_SIGNAL_COUNT; ++i) {
        struct sigaction previous;
        /* A signal the caller chose to ignore (nohup) stays ignored. */
        if (sigaction(cleanup_signals[i], NULL, &previous) != 0 || previous.sa_handler == SIG_IGN)
            continue;
        sigaddset(&taken_signals, cleanup_signals[i]);
        any = true;
    }
    if (any) {
        /* blocked in this thread and every thread it starts from now on:
         * take_signals alone takes them */
        sigset_t previous;
        pthread_sigmask(SIG_BLOCK, &taken_signals, &previous);
        pthread_attr_t attributes;
        bool started = false;
        if (pthread_attr_init(&attributes) == 0) {
            pthread_t thread;
            started = pthread_attr_setdetachstate(&attributes, PTHREAD_CREATE_DETACHED) == 0 &&
                      pthread_create(&thread, &attributes, take_signals, NULL) == 0;
            pthread_attr_destroy(&attributes);
        }
        if (!started) {
            pthread_sigmask(SIG_SETMASK, &previous, NULL);
            install_handlers();
        }
    }
    pthread_mutex_unlock(&slots_lock);
}

/* Creating, renaming and unlinking a temporary file happen with the cleanup
 * signals blocked, so that the handler never misses a file that exists nor
 * sees a half-written path. */
void atomic_file_block_signals(sigset_t *previous) {
    sigset_t blocked;
    sigemptyset(&blocked);
    for (int i = 0; i < CLEANUP_SIGNAL_COUNT; ++i) sigaddset(&blocked, cleanup_signals[i]);
    pthread_sigmask(SIG_BLOCK, &blocked, previous);
}

void atomic_file_restore_signals(const sigset_t *previous) {
    pthread_sigmask(SIG_SETMASK, previous, NULL);
}

static void block_cleanup_signals(sigset_t *previous) {
    atomic_file_block_signals(previous);
    pthread_mutex_lock(&slots_lock);
}

static void restore_signals(const sigset_t *previous) {
    pthread_mutex_unlock(&slots_lock);
    atomic_file_restore_signals(previous);
}

/* Called with the slots locked. With no free slot the file is still
 * written, only not removed by a signal; ATOMIC_FILE_MAX_OPEN is sized so
 * that this does not happen. */
static int claim_cleanup_slot(const char *path) {
    for (int s = 0; s < CLEANUP_SLOTS; ++s) {
        if (cleanup_active[s]) continue;
        strcpy(cleanup_paths[s], path); /* both are PATH_MAX buffers */
        cleanup_active[s] = 1;
        return s;
    }
    return -1;
}

static void release_cleanup_slot(atomic_file *file) {
    if (file->cleanup_slot >= 0) cleanup_active[file->cleanup_slot] = 0;
    file->cleanup_slot = -1;
}

/* --- where to write -------------------------------------------------------- */

/* Follow `path` while it is a symbolic link (a dangling one too: writing
 * through it creates its target, as `echo > link` does). */
int atomic_file_follow_links(const char *path, char resolved[PATH_MAX], tool_error *error) {
    if (strlen(path) >= PATH_MAX)
        return tool_fail(error, TOOL_EXIT_USAGE, "output path too long: %s", path);
    strcpy(resolved, path);
    for (int hops = 0;; ++hops) {
        struct stat status;
        if (lstat(resolved, &status) != 0 || !S_ISLNK(status.st_mode)) return TOOL_EXIT_SUCCESS;
        if (hops == SYMLINK_HOPS_MAX)
            return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: too many levels of symbolic links",
                             path);
        char target[PATH_MAX];
        ssize_t length = readlink(resolved, target, sizeof target - 1);
        if (length < 0)
            return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot read the link %s: %s", resolved,
                             strerror(errno));
        target[length] = '\0';
        /* A relative target is relative to the link's own directory. */
        const char *slash = strrchr(resolved, '/');
        int directory_length = target[0] == '/' || slash == NULL ? 0 : (int)(slash - resolved + 1);
        char next[PATH_MAX];
        int written = snprintf(next, sizeof next, "%.*s%s", directory_length, resolved, target);
        if (written < 0 || written >= PATH_MAX)
            return tool_fail(error, TOOL_EXIT_USAGE, "output path too long: %s", path);
        strcpy(resolved, next);
    }
}

/* The destination's directory: "." for a bare name, else the path up to its
 * last slash ("/" for a file at the root). False when too long. */
static bool destination_directory(const atomic_file *file, char directory[PATH_MAX]) {
    const char *slash = strrchr(file->destination, '/');
    if (slash == NULL) {
        strcpy(directory, ".");
        return true;
    }
    const int length = slash == file->destination ? 1 : (int)(slash - file->destination);
    return snprintf(directory, PATH_MAX, "%.*s", length, file->destination) < PATH_MAX;
}

/* An output's temporary file is created with the mode a plain
 * open(O_CREAT, 0666) asks for, so that the kernel applies the umask or,
 * where the folder has a default ACL, that ACL (a farm's shared folder
 * giving a group write access): a mode worked out here and set with
 * fchmod() applied the umask where the ACL should have decided, and took
 * the group's write access away. An existing output's own permissions are
 * kept instead (atomic_file_begin). */
#define NEW_FILE_MODE 0666

/* The six letters that end a temporary file's name (TEMPORARY_PREFIX
 * "XXXXXX"), from *seed, which it moves on: tried until one is free. */
static void next_temporary_suffix(char *suffix, uint64_t *seed) {
    static const char letters[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    *seed = *seed * 6364136223846793005u + 1442695040888963407u;
    for (int k = 0; k < 6; ++k) suffix[k] = letters[(*seed >> (8 * k + 10)) % 62];
}

/* A seed for next_temporary_suffix: this process, this file and this
 * moment, so that runs on a farm's nodes sharing a folder start apart. */
static uint64_t temporary_seed(const atomic_file *file) {
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    return (uint64_t)getpid() * 2654435761u ^ (uint64_t)(uintptr_t)file ^
           ((uint64_t)now.tv_sec << 30) ^ (uint64_t)now.tv_nsec;
}

/* An unnamed file in the destination's directory (Linux's O_TMPFILE), named
 * only at commit: a run killed by a signal no handler sees (SIGKILL, the
 * out-of-memory killer, a farm's hard timeout) leaves nothing behind. The
 * name is given through /proc/self/fd (linkat), so this needs /proc; -1
 * where either is missing (file systems without O_TMPFILE: NFS before 4.2,
 * some FUSE ones), and the named temporary below is used instead. */
static int open_unnamed_in_directory(const atomic_file *file) {
#ifdef O_TMPFILE
    /* HBAO_TMPFILE=0: named temporaries only (the tests' way to the other
     * path; a file system whose O_TMPFILE misbehaves) */
    const char *wanted = getenv("HBAO_TMPFILE");
    if (wanted != NULL && strcmp(wanted, "0") == 0) return -1;
    char directory[PATH_MAX];
    if (access("/proc/self/fd", X_OK) != 0 || !destination_directory(file, directory)) return -1;
    /* read too: the finished file is read back for its seal (output_seal.h);
     * 0666, so that the kernel gives it a new file's permissions (the umask,
     * or the folder's default ACL: NEW_FILE_MODE) */
    return open(directory, O_TMPFILE | O_RDWR | O_CLOEXEC, NEW_FILE_MODE);
#else
    (void)file;
    return -1;
#endif
}

static int name_unnamed(atomic_file *file);

/* --- named temporaries left behind -----------------------------------------
 * Where the file system has no O_TMPFILE (NFS before 4.2), a run that
 * SIGKILL ends (a farm's hard timeout, the out-of-memory killer: no handler
 * runs) leaves its named temporary in the output's folder, up to a frame's
 * size, and a farm that reruns the task piles them up (an exploratory run).
 * Before its first temporary in a folder, named or not, a run removes those
 * of its own user that nothing has written for STALE_TEMPORARY_S. A running
 * one is created before its frame is read and computed and written after,
 * which takes seconds to minutes; a day leaves room for a task a farm
 * suspended (SIGSTOP) and for a node's clock ahead of the file server's. */
#define STALE_TEMPORARY_S (24 * 3600)
#define TEMPORARY_PREFIX ".hbao-tmp-"
/* Folders this run swept (slots_lock): an output's and a preview's
 * alternate frame by frame, and each is swept once. */
#define SWEPT_FOLDERS 8

/* Whether `name` is a temporary's: TEMPORARY_PREFIX and six letters. */
static bool is_temporary_name(const char *name) {
    const size_t prefix = sizeof TEMPORARY_PREFIX - 1;
    return strncmp(name, TEMPORARY_PREFIX, prefix) == 0 && strlen(name) == prefix + 6;
}

/* Whether this run has swept `directory` already; marks it swept. */
static bool swept_before(const char *directory) {
    static char swept[SWEPT_FOLDERS][PATH_MAX];
    static int next;
    pthread_mutex_lock(&slots_lock);
    bool found = false;
    for (int k = 0; k < SWEPT_FOLDERS && !found; ++k) found = strcmp(swept[k], directory) == 0;
    if (!found) {
        snprintf(swept[next], PATH_MAX, "%s", directory);
        next = (next + 1) % SWEPT_FOLDERS;
    }
    pthread_mutex_unlock(&slots_lock);
    return found;
}

static void remove_stale_temporaries(const char *directory) {
    DIR *folder = swept_before(directory) ? NULL : opendir(directory);
    if (folder == NULL) return;
    const time_t now = time(NULL);
    int removed = 0;
    for (const struct dirent *entry; (entry = readdir(folder)) != NULL;) {
        struct stat status;
        if (!is_temporary_name(entry->d_name) ||
            fstatat(dirfd(folder), entry->d_name, &status, AT_SYMLINK_NOFOLLOW) != 0)
            continue;
        if (S_ISREG(status.st_mode) && status.st_uid == geteuid() &&
            now - status.st_mtime >= STALE_TEMPORARY_S &&
            unlinkat(dirfd(folder), entry->d_name, 0) == 0)
            removed++;
    }
    closedir(folder);
    if (removed > 0)
        tool_warn("removed %d temporary file%s (" TEMPORARY_PREFIX
                  "*) that a killed run left in %s",
                  removed, removed == 1 ? "" : "s", directory);
}

/* The failure to create a temporary beside file->destination (errno
 * `saved`), said by what is wrong: hbao makes no folders, as a missing one
 * is more often a typo than a wish. */
static int creation_failure(const atomic_file *file, int saved, tool_error *error) {
    const char *slash = strrchr(file->destination, '/');
    const int folder_length = slash == NULL                ? 1
                              : slash == file->destination ? 1
                                                           : (int)(slash - file->destination);
    const char *folder = slash == NULL ? "." : file->destination;
    if (saved == ENOENT)
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "cannot write %s: its folder %.*s does not exist (hbao makes no "
                         "folders: make it first)",
                         file->name, folder_length, folder);
    if (saved == ENOTDIR)
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "cannot write %s: a part of its folder's path %.*s is not a folder",
                         file->name, folder_length, folder);
    return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot create a file in the folder of %s: %s",
                     file->name, strerror(saved));
}

/* A temporary file in the destination's directory, so that rename() stays
 * on one file system; the leading dot keeps it out of casual listings. The
 * name has a fixed length, whatever the destination's. */
static int create_named_temporary(atomic_file *file, tool_error *error) {
    const char *slash = strrchr(file->destination, '/');
    int directory_length = slash ? (int)(slash - file->destination + 1) : 0;
    int written = snprintf(file->temporary_path, sizeof file->temporary_path,
                           "%.*s" TEMPORARY_PREFIX "XXXXXX", directory_length, file->destination);
    if (written < 0 || (size_t)written >= sizeof file->temporary_path)
        return tool_fail(error, TOOL_EXIT_USAGE, "output path too long: %s", file->name);
    /* Whatever this run's own temporaries will be: a farm's nodes may
     * mount the folder by NFS versions with and without O_TMPFILE. */
    char directory[PATH_MAX];
    if (destination_directory(file, directory)) remove_stale_temporaries(directory);
    file->fd = open_unnamed_in_directory(file);
    if (file->fd >= 0) {
        /* A second unnamed file, named and removed at once: so that naming
         * works here (a file system or sandbox may allow O_TMPFILE and not
         * the link) is known now, not after the work. (A file, once
         * linked, cannot be linked again after its unlink.) */
        atomic_file probe = *file;
        probe.fd = open_unnamed_in_directory(file);
        sigset_t blocked;
        block_cleanup_signals(&blocked);
        const bool nameable = probe.fd >= 0 && name_unnamed(&probe) == 0;
        if (nameable) {
            unlink(probe.temporary_path);
            release_cleanup_slot(&probe);
        }
        restore_signals(&blocked);
        if (probe.fd >= 0) close(probe.fd);
        if (nameable) {
            file->unnamed = true; /* temporary_path: the template of its name at commit */
            return TOOL_EXIT_SUCCESS;
        }
        close(file->fd);
        file->fd = -1; /* a named file instead, below */
    }
    /* not mkstemp(), which creates 0600 whatever the folder's ACL says */
    char *suffix = file->temporary_path + strlen(file->temporary_path) - 6;
    uint64_t seed = temporary_seed(file);
    int saved = EEXIST;
    for (int attempt = 0; attempt < 100 && file->fd < 0 && saved == EEXIST; ++attempt) {
        next_temporary_suffix(suffix, &seed);
        sigset_t previous;
        block_cleanup_signals(&previous);
        file->fd = open(file->temporary_path, O_CREAT | O_EXCL | O_RDWR | O_CLOEXEC | O_NOCTTY,
                        NEW_FILE_MODE);
        saved = errno;
        if (file->fd >= 0) file->cleanup_slot = claim_cleanup_slot(file->temporary_path);
        restore_signals(&previous);
    }
    if (file->fd < 0) return creation_failure(file, saved, error);
    return TOOL_EXIT_SUCCESS;
}

/* For a FIFO or a device: an unnamed file in $TMPDIR (unlinked at once, so
 * nothing can be left behind) that holds the data until commit. */
static int create_unnamed_temporary(atomic_file *file, tool_error *error) {
    const char *folder = getenv("TMPDIR");
    if (folder == NULL || folder[0] == '\0') folder = "/tmp";
    char path[PATH_MAX];
    int written = snprintf(path, sizeof path, "%s/" TEMPORARY_PREFIX "XXXXXX", folder);
    if (written < 0 || (size_t)written >= sizeof path)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "TMPDIR too long: %s", folder);
    sigset_t previous;
    block_cleanup_signals(&previous);
    file->fd = mkstemp(path);
    int saved = errno;
    if (file->fd >= 0) unlink(path);
    restore_signals(&previous);
    file->temporary_path[0] = '\0';
    if (file->fd < 0)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot create a temporary file in %s: %s",
                         folder, strerror(saved));
    return TOOL_EXIT_SUCCESS;
}

int atomic_file_begin(atomic_file *file, const char *destination, tool_error *error) {
    memset(file, 0, sizeof *file);
    file->fd = -1;
    file->cleanup_slot = -1;
    file->name = destination;
    atomic_file_install_signal_handlers();

    /* What the name finally points to decides how it is written. stat()
     * follows links as open() would, also the kernel's magic ones
     * (/dev/stdout -> /proc/self/fd/1 -> "pipe:[...]") that readlink()
     * cannot turn into a path. */
    struct stat existing;
    bool exists = stat(destination, &existing) == 0;
    if (exists && S_ISDIR(existing.st_mode))
        return tool_fail(error, TOOL_EXIT_USAGE, "%s is a directory", destination);
    const size_t length = strlen(destination);
    if (length > 0 && destination[length - 1] == '/')
        return tool_fail(error, TOOL_EXIT_USAGE,
                         "%s ends in '/', so it names a folder, not a file: give the file's "
                         "name (without the last '/')",
                         destination);
    if (exists && (S_ISBLK(existing.st_mode) || S_ISSOCK(existing.st_mode)))
        return tool_fail(error, TOOL_EXIT_USAGE,
                         "%s is a %s; hbao writes only regular files, FIFOs and character "
                         "devices",
                         destination, S_ISBLK(existing.st_mode) ? "block device" : "socket");
    file->write_through = exists && (S_ISFIFO(existing.st_mode) || S_ISCHR(existing.st_mode));
    int status = TOOL_EXIT_SUCCESS;
    if (file->write_through) {
        if (strlen(destination) >= sizeof file->destination)
            return tool_fail(error, TOOL_EXIT_USAGE, "output path too long: %s", destination);
        strcpy(file->destination, destination);
    } else {
        /* The rename must replace the link's target, not the link. */
        status = atomic_file_follow_links(destination, file->destination, error);
        if (status != TOOL_EXIT_SUCCESS) return status;
    }

    /* An existing regular file that the rename will replace. One the user
     * may not write (an approved frame made read-only) is refused, as
     * open() for writing would refuse it (and Blender's own render output):
     * the rename would replace it all the same, its folder being writable.
     * (root may write any.) */
    const bool replaces = !file->write_through && exists && S_ISREG(existing.st_mode);
    if (replaces && access(file->destination, W_OK) != 0 && errno == EACCES)
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "%s is not writable (read-only, or another user's): refusing to "
                         "replace it (make it writable, or remove it, if it is to go)",
                         destination);
    status = file->write_through ? create_unnamed_temporary(file, error)
                                 : create_named_temporary(file, error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    file->active = true;
    /* The temporary has a new file's permissions (NEW_FILE_MODE); an
     * existing output's own are kept, as an editor saving over it keeps
     * them (a file made private stays private). */
    if (replaces && fchmod(file->fd, existing.st_mode & 0777) != 0) {
        int saved = errno;
        atomic_file_abort(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot set permissions of %s: %s", destination,
                         strerror(saved));
    }
    return TOOL_EXIT_SUCCESS;
}

bool atomic_file_same_destination(const atomic_file *a, const atomic_file *b) {
    if (!a->active || !b->active) return false;
    if (a->write_through || b->write_through) {
        /* one FIFO or device by two names (/dev/stdout and /proc/self/fd/1):
         * both files' bytes would go into it, one after the other */
        struct stat first, second;
        return a->write_through && b->write_through && stat(a->destination, &first) == 0 &&
               stat(b->destination, &second) == 0 && first.st_dev == second.st_dev &&
               first.st_ino == second.st_ino && first.st_rdev == second.st_rdev;
    }
    char first[PATH_MAX], second[PATH_MAX];
    return (canonical_path(a->destination, first) && canonical_path(b->destination, second) &&
            strcmp(first, second) == 0) ||
           canonical_same_entry(a->destination, b->destination);
}

/* Copy the whole temporary file to the FIFO or device, in order. */
static int copy_through(atomic_file *file, tool_error *error) {
    if (lseek(file->fd, 0, SEEK_SET) != 0)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot reread the data for %s: %s", file->name,
                         strerror(errno));
    /* No O_CREAT: the destination exists; no O_TRUNC: a device or FIFO has
     * nothing to truncate. Opening a FIFO waits for its reader. */
    int sink = open(file->destination, O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (sink < 0)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot open %s: %s", file->name,
                         strerror(errno));
    char buffer[1 << 16];
    int status = TOOL_EXIT_SUCCESS;
    for (;;) {
        ssize_t got = read(file->fd, buffer, sizeof buffer);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            status = tool_fail(error, TOOL_EXIT_RUNTIME, "cannot reread the data for %s: %s",
                               file->name, strerror(errno));
            break;
        }
        if (got == 0) break;
        for (ssize_t done = 0; done < got;) {
            ssize_t put = write(sink, buffer + done, (size_t)(got - done));
            if (put < 0 && errno == EINTR) continue;
            if (put <= 0) {
                status = tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: %s", file->name,
                                   put < 0 ? strerror(errno) : "nothing written");
                break;
            }
            done += put;
        }
        if (status != TOOL_EXIT_SUCCESS) break;
    }
    if (close(sink) != 0 && status == TOOL_EXIT_SUCCESS)
        status =
            tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: %s", file->name, strerror(errno));
    return status;
}

/* Gives the unnamed file a fresh name from its template (".hbao-tmp-"
 * and six characters), recorded for the signal handler; called with the
 * cleanup signals blocked and the slots locked. 0, or -1 with errno set. */
static int name_unnamed(atomic_file *file) {
    char proc_path[64];
    snprintf(proc_path, sizeof proc_path, "/proc/self/fd/%d", file->fd);
    char *suffix = file->temporary_path + strlen(file->temporary_path) - 6;
    uint64_t seed = temporary_seed(file);
    for (int attempt = 0; attempt < 100; ++attempt) {
        next_temporary_suffix(suffix, &seed);
        if (linkat(AT_FDCWD, proc_path, AT_FDCWD, file->temporary_path, AT_SYMLINK_FOLLOW) == 0) {
            file->unnamed = false;
            file->cleanup_slot = claim_cleanup_slot(file->temporary_path);
            return 0;
        }
        if (errno != EEXIST) return -1;
    }
    return -1;
}

int atomic_file_commit(atomic_file *file, tool_error *error) {
    if (!file->active) return tool_fail(error, TOOL_EXIT_RUNTIME, "internal: nothing to commit");
    if (file->write_through) {
        int status = copy_through(file, error);
        atomic_file_abort(file);
        return status;
    }
    if (fsync(file->fd) != 0) {
        int saved = errno;
        atomic_file_abort(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: %s", file->name,
                         strerror(saved));
    }
    /* The unnamed file gets its name first; then the file is closed (a
     * close error leaves the destination as it was), then renamed. */
    sigset_t previous;
    block_cleanup_signals(&previous);
    int named = file->unnamed ? name_unnamed(file) : 0;
    int saved = errno;
    restore_signals(&previous);
    if (named != 0) {
        atomic_file_abort(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot create %s: %s", file->name,
                         strerror(saved));
    }
    const int closed = close(file->fd);
    saved = errno;
    file->fd = -1;
    if (closed != 0) {
        atomic_file_abort(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: %s", file->name,
                         strerror(saved));
    }
    block_cleanup_signals(&previous);
    const int renamed = rename(file->temporary_path, file->destination);
    saved = errno;
    if (renamed == 0) {
        release_cleanup_slot(file);
        file->active = false;
    }
    restore_signals(&previous);
    if (renamed != 0) {
        atomic_file_abort(file);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot create %s: %s", file->name,
                         strerror(saved));
    }
    return TOOL_EXIT_SUCCESS;
}

void atomic_file_abort(atomic_file *file) {
    if (file->fd >= 0) close(file->fd);
    file->fd = -1;
    sigset_t previous;
    block_cleanup_signals(&previous);
    if (file->active && !file->unnamed && file->temporary_path[0] != '\0')
        unlink(file->temporary_path);
    release_cleanup_slot(file);
    file->active = false;
    restore_signals(&previous);
}
