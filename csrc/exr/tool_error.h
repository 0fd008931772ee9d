/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Error reporting for the hbao tool and the EXR reader below it (which
 * libhbao_exr shares): each step fills a tool_error with a message and
 * returns the exit status the failure deserves, so that the tool's main()
 * prints one line (`hbao: error: ...`) and exits with it, and libhbao_exr
 * hands the message to its caller.
 */
#ifndef HBAO_TOOL_ERROR_H
#define HBAO_TOOL_ERROR_H

#include <stddef.h>

/** Exit statuses of the tool. */
enum {
    TOOL_EXIT_SUCCESS = 0,
    TOOL_EXIT_RUNTIME = 1, /**< a file could not be read or written, out of memory, ... */
    TOOL_EXIT_USAGE = 2    /**< bad command line: unknown flag, bad number, ... */
};

/* Room for three paths of the system's PATH_MAX (4096 on Linux) and the
 * words around them: a message names the input, an output and a camera file
 * at most, and its reason ("No such file or directory") comes last, where
 * 1024 bytes cut it off a long path's message. */
#define TOOL_ERROR_MESSAGE_SIZE (3 * 4096 + 1024)

typedef struct tool_error {
    char message[TOOL_ERROR_MESSAGE_SIZE];
} tool_error;

/** `text` into `out` (`size` bytes, NUL-terminated, cut before an escape
 *  that does not fit) with its control characters (C0, DEL, C1), bytes that
 *  are no UTF-8 and backslashes as \xNN: a channel or layer name from a
 *  file, or a path, with an escape sequence would drive the terminal, with
 *  a newline fake a line of the output. */
void tool_escape(const char *text, char *out, size_t size);

/** The length of the valid UTF-8 sequence at `text` (1 to 4 bytes; no
 *  overlong forms or surrogates), or 0. */
size_t tool_utf8_sequence(const unsigned char *text);

/** printf-style: set the message and return `status` (for `return tool_fail(...)`).
 *  Messages and warnings are escaped (tool_escape). */
int tool_fail(tool_error *error, int status, const char *format, ...)
    __attribute__((format(printf, 3, 4)));

/** Print "hbao: warning: ..." to stderr. */
void tool_warn(const char *format, ...) __attribute__((format(printf, 1, 2)));

#endif /* HBAO_TOOL_ERROR_H */
