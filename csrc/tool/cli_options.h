/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The hbao tool's command line: parsing, validation and --help. */
#ifndef HBAO_TOOL_CLI_OPTIONS_H
#define HBAO_TOOL_CLI_OPTIONS_H

#include <openexr.h>
#include <stdbool.h>
#include <stdio.h>

#include "atomic_file.h"
#include "camera_settings.h"
#include "frame_pattern.h"
#include "hbao.h"
#include "tool_error.h"

typedef enum tool_mode {
    TOOL_MODE_COMPUTE,  /**< hbao INPUT.exr -o OUTPUT.exr */
    TOOL_MODE_SEQUENCE, /**< hbao IN_####.exr -o OUT_####.exr --frames 1-250 */
    TOOL_MODE_INFO,     /**< hbao --info FILE.exr */
    TOOL_MODE_HELP,
    TOOL_MODE_VERSION
} tool_mode;

/** The most frames computed at once (--jobs): each holds up to two
 *  temporary files that a signal must be able to remove. */
#define CLI_MAX_JOBS (ATOMIC_FILE_MAX_OPEN / 2)

typedef struct cli_options {
    tool_mode mode;
    const char *input_path;
    const char *output_path;
    const char *preview_path; /**< NULL: no PNG */
    const char *camera_path;  /**< NULL: no camera JSON */
    /** What camera_path held, once read: a sequence reads the file once for
     *  all its frames (a pipe can be read once only, and every frame gets the
     *  same camera); NULL: each command reads it. */
    const camera_settings *camera_file;
    const char *layer;      /**< NULL: first view layer with a Depth pass */
    const char *back_layer; /**< NULL: no back-face layer (hbao_compute_layers) */
    const char *ao_channel; /**< name of the output channel, "AO" by default */
    bool keep_input;
    bool ignore_normals;
    bool crop_to_display; /**< write only the data window's part inside the display window */
    int32_t overscan;     /**< > 0: the input is a render widened by this many pixels a side */
    bool info_json;
    exr_compression_t compression;
    hbao_params params;
    camera_settings camera_flags; /**< camera fields given as flags */
    frame_list frames;            /**< --frames (TOOL_MODE_SEQUENCE) */
    int32_t jobs;                 /**< frames computed at once */
    bool force;                   /**< recompute up-to-date frames */
} cli_options;

/** Fill *options from argv; TOOL_EXIT_USAGE with a message on a bad command line. */
int cli_parse(int argc, char **argv, cli_options *options, tool_error *error);

void cli_print_help(FILE *stream);

#endif /* HBAO_TOOL_CLI_OPTIONS_H */
