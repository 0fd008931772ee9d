/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "tool_error.h"

#include <stdarg.h>
#include <stdio.h>

int tool_fail(tool_error *error, int status, const char *format, ...) {
    va_list arguments;
    va_start(arguments, format);
    vsnprintf(error->message, sizeof error->message, format, arguments);
    va_end(arguments);
    return status;
}

void tool_warn(const char *format, ...) {
    va_list arguments;
    /* One line at a time when several frames run at once. */
    flockfile(stderr);
    fputs("hbao: warning: ", stderr);
    va_start(arguments, format);
    vfprintf(stderr, format, arguments);
    va_end(arguments);
    fputc('\n', stderr);
    funlockfile(stderr);
}
