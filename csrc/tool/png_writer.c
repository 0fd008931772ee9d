/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "png_writer.h"

#include <png.h>
#include <setjmp.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#define PNG_MAX_VALUE 255.0f

static uint8_t to_byte(float value) {
    /* The library guarantees [0, 1]; clamp anyway so a NaN can never
     * become an undefined conversion. */
    if (!(value > 0.0f)) return 0;
    if (value >= 1.0f) return (uint8_t)PNG_MAX_VALUE;
    return (uint8_t)(value * PNG_MAX_VALUE + 0.5f);
}

typedef struct png_sink {
    int fd;
    int failed;
} png_sink;

static void write_bytes(png_structp png, png_bytep data, size_t length) {
    png_sink *sink = png_get_io_ptr(png);
    size_t done = 0;
    while (done < length) {
        ssize_t written = write(sink->fd, data + done, length - done);
        if (written < 0 && errno == EINTR) continue;
        if (written <= 0) {
            sink->failed = 1;
            /* the reason (a full disk), not only that it failed */
            png_error(png, written < 0 ? strerror(errno) : "write failed");
        }
        done += (size_t)written;
    }
}

static void flush_nothing(png_structp png) {
    (void)png;
}

/* libpng reports errors by longjmp; this keeps the message for our error. */
static _Thread_local char png_message[256];

static void on_png_error(png_structp png, png_const_charp message) {
    snprintf(png_message, sizeof png_message, "%s", message);
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp message) {
    (void)png;
    (void)message;
}

int png_write_gray(int fd, const char *name, const float *pixels, int32_t width, int32_t height,
                   int64_t row_stride, tool_error *error) {
    png_sink sink = {fd, 0};
    png_message[0] = '\0';
    /* volatile: modified between setjmp and a possible longjmp. */
    uint8_t *volatile row = malloc((size_t)width);
    if (row == NULL) return tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
    png_structp png =
        png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, on_png_error, on_png_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (png == NULL || info == NULL) {
        png_destroy_write_struct(&png, &info);
        free(row);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        free(row);
        return tool_fail(error, TOOL_EXIT_RUNTIME, "cannot write %s: %s", name,
                         png_message[0] ? png_message : "libpng error");
    }
    png_set_write_fn(png, &sink, write_bytes, flush_nothing);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_GRAY,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    /* Each row as its Paeth prediction, deflated as runs (zlib's Z_RLE):
     * libpng's default (a filter chosen row by row, zlib level 6) took 50-105
     * ms of a 1080p frame's preview, this 17-20 (tested on three previews of
     * the demo render: the defaults' 1.5 % smaller, blur 0's 14.5 % and half
     * resolution with blur 15's 11 % larger; docs/speed.md, session 63). An AO
     * image is smooth, so Paeth's residuals are mostly runs of small values. */
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_PAETH);
    png_set_compression_strategy(png, Z_RLE);
    png_write_info(png, info);
    for (int32_t y = 0; y < height; ++y) {
        const float *source = pixels + y * row_stride;
        for (int32_t x = 0; x < width; ++x) row[x] = to_byte(source[x]);
        png_write_row(png, row);
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(row);
    return TOOL_EXIT_SUCCESS;
}
