/* SPDX-License-Identifier: GPL-2.0-or-later */
#define _DEFAULT_SOURCE /* realpath */
#include "sequence_command.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ao_command.h"
#include "ao_plan.h"
#include "atomic_file.h"
#include "camera_json.h"
#include "canonical_path.h"
#include "exr_reader.h"
#include "frame_pattern.h"
#include "output_seal.h"
#include "png_check.h"
#include "run_settings.h"

typedef struct frame_outcome {
    int32_t frame;
    int status;   /* TOOL_EXIT_* */
    bool skipped; /* up to date */
    bool missing; /* no input: failed before the run (missing_inputs) */
} frame_outcome;

typedef struct sequence_run {
    const cli_options *options;
    frame_outcome *outcomes;
    int64_t count;
    int64_t to_run;        /* the frames with an input (missing_inputs) */
    int64_t next;          /* the next frame to start */
    int64_t finished;      /* for the progress count, of to_run */
    bool camera_per_frame; /* per_frame_camera */
    pthread_mutex_t lock;
} sequence_run;

static bool newer_or_equal(const struct stat *a, const struct stat *b) {
    if (a->st_mtim.tv_sec != b->st_mtim.tv_sec) return a->st_mtim.tv_sec > b->st_mtim.tv_sec;
    return a->st_mtim.tv_nsec >= b->st_mtim.tv_nsec;
}

/* The output holds `settings` (its stamp), its structure is whole
 * (exr_input_open reads every chunk's header: listed, at its rows, inside
 * the file) and so are its bytes: a sealed output's bytes are the ones the
 * tool sealed from this input (output_seal.h, a read and a CRC; `input`:
 * the input's status now), an unsealed one's AO channel decodes whole
 * (every chunk inflating, ~17 ms of CPU a 1080p frame). An output cut short
 * or damaged since the tool wrote it (an interrupted copy, rsync --inplace,
 * a block overwritten or a hole punched in place) is redone, not skipped
 * with its header intact, and so is a sealed one computed from another
 * input than the file there now. sealed_only: only a sealed output will do
 * (up_to_date: one older than its input). */
static bool output_is_whole(const cli_options *frame, const struct stat *input,
                            const char *settings, bool sealed_only) {
    exr_input output;
    tool_error ignored = {{0}};
    if (exr_input_open(&output, frame->output_path, &ignored) != TOOL_EXIT_SUCCESS) return false;
    bool whole = false;
    if (run_settings_match(output.context, settings) &&
        exr_input_find_channel(&output, frame->ao_channel) >= 0) {
        const output_seal_state seal =
            output.stream.open ? output_seal_check(output.stream.fd, frame->input_path, input)
                               : OUTPUT_SEAL_ABSENT;
        if (seal == OUTPUT_SEAL_ABSENT && !sealed_only) {
            float *pixels = malloc((size_t)output.width * (size_t)output.height * sizeof *pixels);
            const exr_channel_request request = {frame->ao_channel, EXR_PIXEL_FLOAT,
                                                 (uint8_t *)pixels, (int32_t)sizeof *pixels,
                                                 (int64_t)output.width * (int64_t)sizeof *pixels};
            whole = pixels != NULL &&
                    exr_input_read(&output, &request, 1, &ignored) == TOOL_EXIT_SUCCESS;
            free(pixels);
        } else {
            whole = seal == OUTPUT_SEAL_MATCHES;
        }
    }
    exr_input_close(&output);
    return whole;
}

/* The preview up to date: at least as new as its EXR (`output`: the EXR's
 * status now; ao_command writes the preview after the EXR, so one left from
 * before the EXR was last computed is stale), and whole and this frame's: a
 * sealed one by its seal (output_seal.h: its bytes, and the EXR it was made
 * with; so that another frame's whole preview copied into its place with its
 * attributes, or one left from before its EXR was computed again, is
 * redone), an unsealed one by its chunks' CRCs (png_check.h; a regular file
 * only, as the seal's CRC). One open, without blocking: a FIFO of that name
 * would wait for a writer. */
static bool preview_is_current(const cli_options *frame, const struct stat *output) {
    const int fd = open(frame->preview_path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return false;
    struct stat status;
    bool current = false;
    if (fstat(fd, &status) == 0 && newer_or_equal(&status, output)) {
        const output_seal_state seal = output_seal_check(fd, frame->output_path, output);
        current = seal == OUTPUT_SEAL_ABSENT ? png_fd_is_whole(fd) : seal == OUTPUT_SEAL_MATCHES;
    }
    close(fd);
    return current;
}

/* The stamp (run_settings.h) that computing `frame` would write, from its
 * input's header (ao_plan_make; no pixel is read). False where the input
 * cannot be planned: the frame then runs, and says why it fails. */
static bool planned_settings(const cli_options *frame, char settings[RUN_SETTINGS_MAX]) {
    exr_input input;
    tool_error ignored = {{0}};
    if (exr_input_open(&input, frame->input_path, &ignored) != TOOL_EXIT_SUCCESS) return false;
    ao_plan plan;
    const bool planned = ao_plan_make(frame, &input, &plan, &ignored) == TOOL_EXIT_SUCCESS &&
                         run_settings_text(frame, &plan, settings);
    exr_input_close(&input);
    return planned;
}

/* Up to date, as make decides, and computed with the same flags: every
 * output exists and is at least as new as the input, the
 * preview is current (preview_is_current), and the EXR's header holds the
 * settings this run would write (run_settings.h) and it is whole
 * (output_is_whole). An output older than its input is up to date where
 * its seal names the input as it is now (name, size and time: the output
 * was computed from it): an input whose time lies ahead of this machine's
 * clock (written by a render node whose clock is ahead, over NFS) was
 * recomputed on every run.
 * (An input re-rendered while its frame was computed gets no output:
 * ao_command's refuse_changed_input.) */
static bool up_to_date(const cli_options *frame) {
    struct stat input, output;
    if (stat(frame->input_path, &input) != 0 || stat(frame->output_path, &output) != 0 ||
        !S_ISREG(output.st_mode))
        return false;
    const bool older_than_input = !newer_or_equal(&output, &input);
    /* an output that is its input: ao_command refuses it, --force or not */
    if (output.st_dev == input.st_dev && output.st_ino == input.st_ino) return false;
    /* The camera file counts by what it holds (every camera value and the
     * background depth are in the settings below), not by its time: one
     * dated ahead of this machine's clock was redone on every run, and one
     * rewritten with the same values (an export run again) redid every
     * frame. One that cannot be read is no plan: the frame runs, and says
     * why it fails. */
    if (frame->preview_path != NULL && !preview_is_current(frame, &output)) return false;
    char settings[RUN_SETTINGS_MAX];
    return planned_settings(frame, settings) &&
           output_is_whole(frame, &input, settings, older_than_input);
}

/* A frame's progress line: one line, its path escaped as every message
 * is (tool_escape: a name with a newline or an escape sequence would split
 * the line or drive the terminal); `message` is escaped already. */
static void report(sequence_run *run, const frame_outcome *outcome, const char *output,
                   const char *message) {
    char escaped[4 * PATH_MAX + 1];
    tool_escape(output, escaped, sizeof escaped);
    pthread_mutex_lock(&run->lock);
    const int64_t done = ++run->finished;
    flockfile(stderr);
    if (outcome->status != TOOL_EXIT_SUCCESS)
        fprintf(stderr, "hbao: [%lld/%lld] frame %d failed: %s\n", (long long)done,
                (long long)run->to_run, outcome->frame, message);
    else
        fprintf(stderr, "hbao: [%lld/%lld] frame %d: %s%s\n", (long long)done,
                (long long)run->to_run, outcome->frame, escaped,
                outcome->skipped ? " is up to date, skipped" : "");
    funlockfile(stderr);
    pthread_mutex_unlock(&run->lock);
}

/* A camera file per frame (an animated camera: scripts/export_cameras.py
 * writes them): a '#' run in the camera file's name, or in a folder's where
 * no file has the path as written ("shot_##/cam.json", as the input's and
 * -o's folders are read; an existing "take #1/cam.json", or one that cannot
 * be looked up, is one camera for every frame, read once). Decided once,
 * before any frame runs. */
static bool per_frame_camera(const cli_options *options) {
    const char *path = options->camera_path;
    if (path == NULL || !frame_pattern_has_frame(path)) return false;
    if (frame_pattern_has_frame_in_name(path)) return true;
    struct stat status;
    return stat(path, &status) != 0 && (errno == ENOENT || errno == ENOTDIR);
}

static void run_frame(sequence_run *run, frame_outcome *outcome) {
    const cli_options *options = run->options;
    char input[PATH_MAX], output[PATH_MAX], preview[PATH_MAX], camera[PATH_MAX];
    cli_options frame = *options;
    tool_error error = {{0}};
    frame.mode = TOOL_MODE_COMPUTE;
    frame.input_path = input;
    frame.output_path = output;
    frame.preview_path = options->preview_path ? preview : NULL;
    /* a camera per frame (an animated camera): read by the frame itself */
    const bool camera_per_frame = run->camera_per_frame;
    if (camera_per_frame) frame.camera_path = camera;
    const char *patterns[4] = {options->input_path, options->output_path, options->preview_path,
                               camera_per_frame ? options->camera_path : NULL};
    char *paths[4] = {input, output, preview, camera};
    static const char *const names[4] = {"the input", "-o", "--preview", "--camera"};
    int too_long = -1;
    for (int k = 0; k < 4 && too_long < 0; ++k)
        if (patterns[k] != NULL &&
            !frame_pattern_path(patterns[k], outcome->frame, paths[k], PATH_MAX))
            too_long = k;
    if (too_long >= 0) {
        outcome->status = tool_fail(&error, TOOL_EXIT_USAGE,
                                    "%s of this frame would be %d bytes or longer (%s): too long",
                                    names[too_long], PATH_MAX, patterns[too_long]);
    } else if (!options->force && up_to_date(&frame)) {
        outcome->skipped = true;
        outcome->status = TOOL_EXIT_SUCCESS;
    } else {
        outcome->status = ao_command(&frame, &error);
    }
    report(run, outcome, output, error.message);
}

static void *worker(void *context) {
    sequence_run *run = context;
    for (;;) {
        pthread_mutex_lock(&run->lock);
        const int64_t index = run->next++;
        pthread_mutex_unlock(&run->lock);
        if (index >= run->count) return NULL;
        if (!run->outcomes[index].missing) run_frame(run, &run->outcomes[index]);
    }
}

/* The frames of `outcomes` that `take` picks, as ranges of frames listed
 * one after the other ("4, 17-30, 200"; 1-250x2 gives no ranges), written
 * into list (shortened with ", ..." to fit); returns how many. */
#define FRAME_RANGES_TEXT 512
static int64_t frame_ranges(const sequence_run *run, bool (*take)(const frame_outcome *),
                            char list[FRAME_RANGES_TEXT]) {
    static const char ellipsis[] = ", ...";
    int64_t taken = 0;
    size_t used = 0;
    bool shortened = false;
    list[0] = '\0';
    for (int64_t i = 0; i < run->count; ++i) {
        if (!take(&run->outcomes[i])) continue;
        int64_t last = i; /* the range's end: following frames, each taken */
        while (last + 1 < run->count && take(&run->outcomes[last + 1]) &&
               run->outcomes[last + 1].frame == run->outcomes[last].frame + 1)
            ++last;
        char item[40];
        const int first = run->outcomes[i].frame, end = run->outcomes[last].frame;
        if (first == end)
            snprintf(item, sizeof item, "%s%d", taken > 0 ? ", " : "", first);
        else
            snprintf(item, sizeof item, "%s%d-%d", taken > 0 ? ", " : "", first, end);
        taken += last - i + 1;
        i = last;
        if (shortened) continue;
        if (used + strlen(item) + sizeof ellipsis > FRAME_RANGES_TEXT) {
            strcpy(list + used, ellipsis);
            shortened = true;
        } else {
            strcpy(list + used, item);
            used += strlen(item);
        }
    }
    return taken;
}

static bool failed_frame(const frame_outcome *outcome) {
    return outcome->status != TOOL_EXIT_SUCCESS;
}

static bool missing_frame(const frame_outcome *outcome) {
    return outcome->missing;
}

/* "3 of 250 frames failed: 4, 17-18" (the list shortened to fit). */
static int summarize(const sequence_run *run, tool_error *error) {
    int status = TOOL_EXIT_SUCCESS;
    for (int64_t i = 0; i < run->count; ++i)
        if (run->outcomes[i].status > status) status = run->outcomes[i].status;
    char list[FRAME_RANGES_TEXT];
    const int64_t failed = frame_ranges(run, failed_frame, list);
    if (failed == 0) return TOOL_EXIT_SUCCESS;
    return tool_fail(error, status, "%lld of %lld frames failed: %s", (long long)failed,
                     (long long)run->count, list);
}

/* The listed frames whose input is not there fail before any frame runs,
 * said in one line of ranges: a mistyped --frames 0-1048574 over 250
 * renders printed a million lines, one a failed frame, for some 20 s.
 * Where no frame has its input, that is the error, with nothing run. An
 * input that cannot be looked up for another reason (a folder without
 * permission), or a symbolic link to no file (yet: it may name another
 * frame's output, refuse_other_frames_files), fails in its frame. */
static int missing_inputs(sequence_run *run, tool_error *error) {
    const char *pattern = run->options->input_path;
    char path[PATH_MAX], first[PATH_MAX] = "";
    int reason = 0;
    struct stat status;
    int64_t missing = 0;
    for (int64_t i = 0; i < run->count; ++i) {
        frame_outcome *outcome = &run->outcomes[i];
        if (!frame_pattern_path(pattern, outcome->frame, path, sizeof path) ||
            lstat(path, &status) == 0 || (errno != ENOENT && errno != ENOTDIR))
            continue;
        if (missing++ == 0) {
            reason = errno;
            strcpy(first, path);
        }
        outcome->missing = true;
        outcome->status = TOOL_EXIT_RUNTIME;
    }
    run->to_run = run->count - missing;
    if (missing == 0) return TOOL_EXIT_SUCCESS;
    if (missing == run->count)
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "no input for any of the %lld listed frames (%s): %s: %s",
                         (long long)run->count, pattern, first, strerror(reason));
    char list[FRAME_RANGES_TEXT];
    frame_ranges(run, missing_frame, list);
    tool_warn("no input for %lld of the %lld frames (%s; the first, %s: %s): they fail",
              (long long)missing, (long long)run->count, list, first, strerror(reason));
    return TOOL_EXIT_SUCCESS;
}

/* A frame's output or preview that is another frame's input (its render,
 * or its camera file where each frame has one) would replace it before it
 * is read (hbao 'f_#.exr' -o 'f_#0.exr'
 * --frames 1-10: frame 1 writes f_10.exr); one that is another frame's
 * preview or output, the two frames would replace each other's file
 * (-o 'o_#.exr' --preview 'o_#0.exr'), or, through a symbolic link, one
 * frame would write the other's output and that frame then find it up to
 * date (an exploratory run: a_0002.exr a link to a_0001.exr gave frame 1
 * frame 2's AO, exit 0); one that is the --camera file every frame reads
 * would replace it after the frames before it. Each frame refuses its own
 * input and a preview that is its own output (ao_command); this refuses
 * the others' before any frame runs: by name, and by file (frame_file). */
/* `pattern` with its folder made canonical (canonical_path), so that names
 * of one file compare equal ("./o_#.exr" and "o_#.exr"); as given where the
 * folder holds the '#' run or cannot be resolved. */
static const char *canonical_pattern(const char *pattern, char out[PATH_MAX]) {
    if (pattern == NULL) return NULL;
    const char *slash = strrchr(pattern, '/');
    if (slash != NULL && memchr(pattern, '#', (size_t)(slash - pattern)) != NULL) return pattern;
    return canonical_path(pattern, out) ? out : pattern;
}

/* An input file of a listed frame, by identity: an output that resolves to
 * the same directory entry (through a symbolic link of the name or of a
 * folder, a bind mount) would replace it. One file by two names (a hard
 * link) is no such case: the rename replaces that name only; a file with
 * several names is compared by its resolved path (realpath). */
typedef struct frame_file {
    dev_t device;
    ino_t inode;
    int32_t frame;
    int kind;      /* 0: the render, 1: the frame's --camera file, 2: -o, 3: --preview */
    char *path;    /* as the frame names it (owned); for a dangling link, where it points */
    bool dangling; /* a symbolic link to a file not there yet (device, inode 0) */
} frame_file;

static int compare_frame_files(const void *a, const void *b) {
    const frame_file *x = a, *y = b;
    if (x->dangling != y->dangling) return x->dangling ? -1 : 1; /* those first */
    if (x->device != y->device) return x->device < y->device ? -1 : 1;
    if (x->inode != y->inode) return x->inode < y->inode ? -1 : 1;
    return 0;
}

/* `path` with its symbolic links followed (as an output is written), its
 * folder made canonical. */
static bool final_path(const char *path, char out[PATH_MAX]) {
    char followed[PATH_MAX];
    tool_error ignored = {{0}};
    return atomic_file_follow_links(path, followed, &ignored) == TOOL_EXIT_SUCCESS &&
           canonical_path(followed, out);
}

/* Where the symbolic link (or chain of them) at `path`, whose target does
 * not exist (yet), ends (final_path). False for anything else. */
static bool dangling_link_target(const char *path, char target[PATH_MAX]) {
    struct stat status;
    return lstat(path, &status) == 0 && S_ISLNK(status.st_mode) && final_path(path, target);
}

/* The listed frames' files (FRAME_FILE_KINDS patterns: inputs, outputs)
 * that exist, sorted by identity (NULL and *found 0 where none, or no
 * memory: the names' checks still run). */
#define FRAME_FILE_KINDS 4
static frame_file *frames_files(const char *const patterns[FRAME_FILE_KINDS],
                                const sequence_run *run, size_t *found) {
    *found = 0;
    frame_file *files = malloc((size_t)run->count * FRAME_FILE_KINDS * sizeof *files);
    if (files == NULL) return NULL;
    char path[PATH_MAX];
    struct stat status;
    for (int64_t i = 0; i < run->count; ++i) {
        /* A frame with no input reads and writes nothing: only its outputs
         * that exist count (a running frame's output may reach one through
         * a folder's link, and a later run take it as that frame's), by
         * one stat each, for a mistyped range of a million frames. */
        const bool missing = run->outcomes[i].missing;
        const int32_t frame = run->outcomes[i].frame;
        for (int kind = missing ? 2 : 0; kind < FRAME_FILE_KINDS; ++kind) {
            if (patterns[kind] == NULL ||
                !frame_pattern_path(patterns[kind], frame, path, sizeof path))
                continue;
            char target[PATH_MAX];
            const bool exists = stat(path, &status) == 0;
            if (exists ? !S_ISREG(status.st_mode) : missing || !dangling_link_target(path, target))
                continue;
            char *copy = strdup(exists ? path : target);
            if (copy == NULL) continue; /* (out of memory: the names' checks still run) */
            files[(*found)++] =
                exists ? (frame_file){status.st_dev, status.st_ino, frame, kind, copy, false}
                       : (frame_file){0, 0, frame, kind, copy, true};
        }
    }
    qsort(files, *found, sizeof *files, compare_frame_files);
    return files;
}

static void free_frame_files(frame_file *files, size_t found) {
    for (size_t i = 0; i < found && files != NULL; ++i) free(files[i].path);
    free(files);
}

/* Whether `a` and `b`, two names of one file, resolve to one path. */
static bool same_resolved_path(const char *a, const char *b) {
    char first[PATH_MAX], second[PATH_MAX];
    return realpath(a, first) != NULL && realpath(b, second) != NULL && strcmp(first, second) == 0;
}

/* The first of `files` that belongs to a frame other than `frame` and that
 * writing `path` would replace (frame_file), or NULL. */
static const frame_file *other_frames_file(const frame_file *files, size_t found, const char *path,
                                           int32_t frame) {
    struct stat status;
    if (files == NULL) return NULL;
    if (stat(path, &status) != 0) {
        /* not there yet: another frame's input may be a link to where it
         * will be written */
        char canonical[PATH_MAX];
        if (found == 0 || !files[0].dangling || !final_path(path, canonical)) return NULL;
        for (size_t i = 0; i < found && files[i].dangling; ++i)
            if (files[i].frame != frame && strcmp(files[i].path, canonical) == 0) return &files[i];
        return NULL;
    }
    const frame_file key = {status.st_dev, status.st_ino, 0, 0, NULL, false};
    const frame_file *hit = bsearch(&key, files, found, sizeof *files, compare_frame_files);
    if (hit == NULL) return NULL;
    while (hit > files && compare_frame_files(hit - 1, &key) == 0) --hit;
    for (; hit < files + found && compare_frame_files(hit, &key) == 0; ++hit)
        if (hit->frame != frame && (status.st_nlink == 1 || same_resolved_path(path, hit->path)))
            return hit;
    return NULL;
}

/* What writing `path` would do to a file of another frame of `kind`
 * (frame_file.kind), for the messages below. */
static const char *clash_words(int kind) {
    return kind < 2 ? "it would be replaced before it is read"
                    : "each would replace the other, or one frame find the other's AO up to date";
}

/* The one --camera file that every frame reads (not one per frame), where
 * writing `path` would replace it: by name, or as the same file. */
static bool is_shared_camera(const char *camera, const struct stat *camera_status, const char *path,
                             const char *written) {
    struct stat status;
    if (camera == NULL) return false;
    if (strcmp(camera, path) == 0 || (written != NULL && strcmp(camera, written) == 0)) return true;
    return camera_status != NULL && stat(path, &status) == 0 &&
           status.st_dev == camera_status->st_dev && status.st_ino == camera_status->st_ino &&
           (status.st_nlink == 1 || same_resolved_path(path, camera));
}

/* A running frame's output or preview by the folder entry that writing it
 * replaces: where links at its name lead (final_path), by its folder's
 * identity (through folders' links, "..", a bind mount) and its name
 * there. frames_files compares files that exist; two frames whose files
 * are one entry not there yet (-o 'd#/ao.exr' with d1 and d2 links to one
 * folder, or -o 'd#/../ao.exr') wrote one file, the run exited 0 with one
 * frame's AO lost, and a rerun then refused it (a review's runs). */
typedef struct write_entry {
    canonical_entry entry; /* its name within `where` */
    int32_t frame;
    int kind;    /* 0: -o, 1: --preview */
    char *where; /* final_path (owned) */
    char *path;  /* as the frame names it (owned) */
} write_entry;

static int compare_write_entries(const void *a, const void *b) {
    return canonical_entry_compare(&((const write_entry *)a)->entry,
                                   &((const write_entry *)b)->entry);
}

/* The write_entry of `path` into *entry (false where its folder cannot be
 * resolved: the frame fails to write there, or no memory). */
static bool write_entry_of(const char *path, int32_t frame, int kind, write_entry *entry) {
    char where[PATH_MAX];
    if (!final_path(path, where)) return false;
    entry->where = strdup(where);
    entry->path = strdup(path);
    if (entry->where == NULL || entry->path == NULL ||
        !canonical_entry_of(entry->where, &entry->entry)) {
        free(entry->where);
        free(entry->path);
        return false;
    }
    entry->frame = frame;
    entry->kind = kind;
    return true;
}

/* Refuses two running frames whose outputs or previews (`patterns`, named
 * by `flags`) are one folder entry (write_entry). */
static int refuse_shared_entries(const sequence_run *run, const char *const patterns[2],
                                 const char *const flags[2], tool_error *error) {
    write_entry *entries = malloc((size_t)run->to_run * 2 * sizeof *entries);
    if (entries == NULL) return TOOL_EXIT_SUCCESS; /* (out of memory: the names' checks ran) */
    size_t count = 0;
    char path[PATH_MAX];
    for (int64_t i = 0; i < run->count; ++i) {
        if (run->outcomes[i].missing) continue;
        const int32_t frame = run->outcomes[i].frame;
        for (int k = 0; k < 2; ++k)
            if (patterns[k] != NULL && frame_pattern_path(patterns[k], frame, path, sizeof path) &&
                write_entry_of(path, frame, k, &entries[count]))
                ++count;
    }
    qsort(entries, count, sizeof *entries, compare_write_entries);
    int status = TOOL_EXIT_SUCCESS;
    for (size_t i = 0; i + 1 < count && status == TOOL_EXIT_SUCCESS; ++i) {
        /* the same frame's output and preview as one file: ao_command's refusal */
        for (size_t j = i + 1; j < count && compare_write_entries(&entries[i], &entries[j]) == 0;
             ++j) {
            if (entries[j].frame == entries[i].frame) continue;
            const write_entry *a = &entries[i], *b = &entries[j];
            if (a->frame > b->frame) {
                const write_entry *first = b;
                b = a;
                a = first;
            }
            status = tool_fail(error, TOOL_EXIT_USAGE,
                               "%s of frame %d (%s) is the %s of frame %d (%s) by another path, "
                               "both %s: %s",
                               flags[b->kind], (int)b->frame, b->path, flags[a->kind],
                               (int)a->frame, a->path, a->where, clash_words(2));
            break;
        }
    }
    for (size_t i = 0; i < count; ++i) {
        free(entries[i].where);
        free(entries[i].path);
    }
    free(entries);
    return status;
}

static int refuse_other_frames_files(const sequence_run *run, tool_error *error) {
    const cli_options *options = run->options;
    const bool camera_per_frame = run->camera_per_frame;
    char canonical[5][PATH_MAX];
    /* the frames' files: renders, cameras where each has its own, outputs
     * and previews (their indices in `files` are frame_file.kind) */
    const char *files_patterns[FRAME_FILE_KINDS] = {
        canonical_pattern(options->input_path, canonical[0]),
        camera_per_frame ? canonical_pattern(options->camera_path, canonical[3]) : NULL,
        canonical_pattern(options->output_path, canonical[1]),
        canonical_pattern(options->preview_path, canonical[2])};
    const char *names_of[FRAME_FILE_KINDS] = {"input", "--camera file", "-o", "--preview"};
    const char *const *patterns = files_patterns + 2;
    const char *const *flags = names_of + 2;
    /* the camera file every frame reads */
    const char *camera = !camera_per_frame && options->camera_path != NULL
                             ? canonical_pattern(options->camera_path, canonical[4])
                             : NULL;
    struct stat camera_status;
    const bool camera_exists = camera != NULL && stat(camera, &camera_status) == 0;
    char path[PATH_MAX];
    size_t found;
    frame_file *files = frames_files(files_patterns, run, &found);
    int status = TOOL_EXIT_SUCCESS;
    /* the frames that run write (the others' files: in frames_files, and
     * by name, frame_list_contains) */
    for (int64_t i = 0; i < run->count; ++i) {
        if (run->outcomes[i].missing) continue;
        const int32_t frame = run->outcomes[i].frame;
        for (int k = 0; k < 2; ++k) {
            if (patterns[k] == NULL || !frame_pattern_path(patterns[k], frame, path, sizeof path))
                continue;
            int32_t other;
            /* the name, and where a link at it writes (a file not there yet) */
            char written[PATH_MAX];
            const char *names[2] = {
                path, final_path(path, written) && strcmp(written, path) != 0 ? written : NULL};
            if (is_shared_camera(camera, camera_exists ? &camera_status : NULL, path, names[1])) {
                status = tool_fail(error, TOOL_EXIT_USAGE,
                                   "%s of frame %d (%s) is the --camera file that every frame "
                                   "reads: it would be replaced",
                                   flags[k], (int)frame, path);
                goto done;
            }
            for (int n = 0; n < 2; ++n)
                for (int in = 0; in < FRAME_FILE_KINDS; ++in)
                    if (names[n] != NULL && files_patterns[in] != NULL &&
                        frame_pattern_frame(files_patterns[in], names[n], &other) &&
                        other != frame && frame_list_contains(&options->frames, other)) {
                        status = tool_fail(
                            error, TOOL_EXIT_USAGE, "%s of frame %d (%s) is the %s of frame %d: %s",
                            flags[k], (int)frame, path, names_of[in], (int)other, clash_words(in));
                        goto done;
                    }
            const frame_file *same = other_frames_file(files, found, path, frame);
            if (same != NULL) {
                status = tool_fail(error, TOOL_EXIT_USAGE,
                                   "%s of frame %d (%s) is the %s of frame %d by another path "
                                   "(through a link or \"..\"): %s",
                                   flags[k], (int)frame, path, names_of[same->kind],
                                   (int)same->frame, clash_words(same->kind));
                goto done;
            }
        }
    }
    status = refuse_shared_entries(run, patterns, flags, error);
done:
    free_frame_files(files, found);
    return status;
}

int sequence_command(const cli_options *options, tool_error *error) {
    const bool camera_per_frame = per_frame_camera(options);
    sequence_run run = {0};
    run.camera_per_frame = camera_per_frame;
    run.count = frame_list_count(&options->frames);
    run.outcomes = calloc((size_t)run.count, sizeof *run.outcomes);
    if (run.outcomes == NULL) return tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
    for (int64_t i = 0; i < run.count; ++i)
        run.outcomes[i].frame = frame_list_at(&options->frames, i);
    run.options = options;
    int refused = missing_inputs(&run, error);
    if (refused == TOOL_EXIT_SUCCESS) refused = refuse_other_frames_files(&run, error);
    if (refused != TOOL_EXIT_SUCCESS) {
        free(run.outcomes);
        return refused;
    }

    cli_options shared = *options;
    camera_settings camera_file;
    if (options->camera_path != NULL && !camera_per_frame) {
        camera_settings_init(&camera_file);
        const int status = camera_json_load(options->camera_path, &camera_file, error);
        if (status != TOOL_EXIT_SUCCESS) {
            free(run.outcomes);
            return status;
        }
        shared.camera_file = &camera_file;
    }
    int jobs = options->jobs < 1 ? 1 : options->jobs;
    if (jobs > run.to_run) jobs = (int)run.to_run;
    /* Frames at once share the cores: each frame's computation gets its
     * part, unless --threads says otherwise. */
    if (shared.params.threads == 0 && jobs > 1) {
        shared.params.threads = exr_usable_cores() / jobs;
        if (shared.params.threads < 1) shared.params.threads = 1;
    }
    run.options = &shared;
    pthread_mutex_init(&run.lock, NULL);

    /* The workers run with the cleanup signals blocked, so that the main
     * thread (waiting below) takes them and removes every frame's
     * temporary files. */
    atomic_file_install_signal_handlers();
    sigset_t previous;
    atomic_file_block_signals(&previous);
    pthread_t threads[ATOMIC_FILE_MAX_OPEN / 2];
    int started = 0;
    for (; started < jobs; ++started)
        if (pthread_create(&threads[started], NULL, worker, &run) != 0) break;
    atomic_file_restore_signals(&previous);
    if (started == 0) worker(&run); /* no thread could start: this one does the work */
    for (int t = 0; t < started; ++t) pthread_join(threads[t], NULL);

    int status = summarize(&run, error);
    pthread_mutex_destroy(&run.lock);
    free(run.outcomes);
    return status;
}
