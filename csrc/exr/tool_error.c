/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "tool_error.h"

#include <stdarg.h>
#include <stdio.h>

void tool_escape(const char *text, char *out, size_t size) {
    static const char digits[] = "0123456789abcdef";
    size_t used = 0;
    for (; *text != '\0'; ++text) {
        const unsigned char byte = (unsigned char)*text;
        const int control = byte < 0x20 || byte == 0x7f;
        if (used + (control ? 4 : 1) >= size) break;
        if (control) {
            out[used++] = '\\';
            out[used++] = 'x';
            out[used++] = digits[byte >> 4];
            out[used++] = digits[byte & 15];
        } else {
            out[used++] = (char)byte;
        }
    }
    if (size > 0) out[used] = '\0';
}

int tool_fail(tool_error *error, int status, const char *format, ...) {
    char raw[TOOL_ERROR_MESSAGE_SIZE];
    va_list arguments;
    va_start(arguments, format);
    vsnprintf(raw, sizeof raw, format, arguments);
    va_end(arguments);
    tool_escape(raw, error->message, sizeof error->message);
    return status;
}

void tool_warn(const char *format, ...) {
    char raw[TOOL_ERROR_MESSAGE_SIZE], message[TOOL_ERROR_MESSAGE_SIZE];
    va_list arguments;
    va_start(arguments, format);
    vsnprintf(raw, sizeof raw, format, arguments);
    va_end(arguments);
    tool_escape(raw, message, sizeof message);
    /* One line at a time when several frames run at once. */
    flockfile(stderr);
    fprintf(stderr, "hbao: warning: %s\n", message);
    funlockfile(stderr);
}
