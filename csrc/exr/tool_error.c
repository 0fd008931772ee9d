/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "tool_error.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>

size_t tool_utf8_sequence(const unsigned char *text) {
    const unsigned char lead = text[0];
    size_t length;
    unsigned lowest; /* the least code point of that length: no overlong forms */
    if (lead < 0x80) return 1;
    if (lead >= 0xC2 && lead <= 0xDF)
        length = 2, lowest = 0x80;
    else if (lead >= 0xE0 && lead <= 0xEF)
        length = 3, lowest = 0x800;
    else if (lead >= 0xF0 && lead <= 0xF4)
        length = 4, lowest = 0x10000;
    else
        return 0;
    unsigned code = lead & (0x7F >> length);
    for (size_t k = 1; k < length; ++k) {
        if ((text[k] & 0xC0) != 0x80) return 0; /* also stops at the terminating 0 */
        code = (code << 6) | (text[k] & 0x3F);
    }
    if (code < lowest || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
    return length;
}

void tool_escape(const char *text, char *out, size_t size) {
    static const char digits[] = "0123456789abcdef";
    const unsigned char *in = (const unsigned char *)text;
    size_t used = 0;
    while (*in != '\0') {
        size_t length = tool_utf8_sequence(in);
        /* C0 controls, DEL and the backslash that starts an escape; C1
         * controls (U+0080 to U+009F) and bytes that are no UTF-8: as \xNN */
        const bool escaped = length == 0 ||
                             (length == 1 && (*in < 0x20 || *in == 0x7F || *in == '\\')) ||
                             (length == 2 && in[0] == 0xC2 && in[1] < 0xA0);
        if (length == 0) length = 1;
        if (used + (escaped ? 4 * length : length) >= size) break;
        for (size_t k = 0; k < length; ++k, ++in) {
            if (escaped) {
                out[used++] = '\\';
                out[used++] = 'x';
                out[used++] = digits[*in >> 4];
                out[used++] = digits[*in & 15];
            } else {
                out[used++] = (char)*in;
            }
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
