/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * hbao: ambient occlusion for Blender's multilayer EXR renders.
 * See `hbao --help` (cli_options.c) for the command line.
 */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include "ao_command.h"
#include "atomic_file.h"
#include "cli_options.h"
#include "hbao.h"
#include "info_command.h"
#include "sequence_command.h"
#include "tool_error.h"
#include "zip_chunks.h"

/* The versions, and the horizon search this CPU runs (a farm's nodes
 * without AVX2 run the generic kernel, in about twice AVX2's time) */
static void print_version(void) {
    int32_t version = hbao_version();
    printf("hbao %d.%d.%d (libhbao %d.%d.%d; horizon search: %s)\n", HBAO_VERSION_MAJOR,
           HBAO_VERSION_MINOR, HBAO_VERSION_PATCH, version / 10000, version / 100 % 100,
           version % 100, hbao_implementation_name(hbao_best_implementation()));
}

/* A standard descriptor the caller closed (`>&-`, a daemon) would be the
 * next file the tool opens: the input, whose name /dev/stdout would then
 * be, so that -o /dev/stdout replaced it; or a temporary output, which the
 * tool's own messages would then be written into. Each closed one is
 * opened on /dev/null first (open takes the lowest free descriptor).
 * False where that fails. */
static bool open_closed_standard_descriptors(void) {
    for (int fd = 0; fd <= 2; ++fd) {
        if (fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
        const int opened = open("/dev/null", fd == 0 ? O_RDONLY : O_WRONLY);
        if (opened != fd) {
            if (opened >= 0) close(opened);
            return false;
        }
    }
    return true;
}

int main(int argc, char **argv) {
    if (!open_closed_standard_descriptors()) {
        /* stderr may be the closed one: the exit status says it */
        fprintf(stderr, "hbao: error: a standard descriptor is closed and /dev/null cannot "
                        "be opened in its place\n");
        return TOOL_EXIT_RUNTIME;
    }
    /* A reader that closes its pipe (hbao ... -o /dev/stdout | head) makes a
     * write fail with EPIPE, an error like any other (its message, exit 1,
     * the temporary files removed), instead of killing the tool mid-write. */
    signal(SIGPIPE, SIG_IGN);
    exr_input_set_zip_decompressor(zip_chunks_decompress);
    cli_options options;
    tool_error error = {{0}};
    int status = cli_parse(argc, argv, &options, &error);
    /* The runs that write files: the thread that takes the signals first,
     * before the library's, the EXR writer's or the frames' threads */
    if (status == TOOL_EXIT_SUCCESS &&
        (options.mode == TOOL_MODE_COMPUTE || options.mode == TOOL_MODE_SEQUENCE))
        atomic_file_install_signal_handlers();
    if (status == TOOL_EXIT_SUCCESS) {
        switch (options.mode) {
            case TOOL_MODE_HELP:
                cli_print_help(stdout);
                break;
            case TOOL_MODE_VERSION:
                print_version();
                break;
            case TOOL_MODE_INFO:
                status = info_command(options.input_path, options.info_json, &error);
                break;
            case TOOL_MODE_COMPUTE:
                status = ao_command(&options, &error);
                break;
            case TOOL_MODE_SEQUENCE:
                status = sequence_command(&options, &error);
                break;
        }
    }
    if (status != TOOL_EXIT_SUCCESS) fprintf(stderr, "hbao: error: %s\n", error.message);
    /* ferror: a write that failed before the last flush (output past the
     * stream's buffer) */
    if ((fflush(stdout) != 0 || ferror(stdout)) && status == TOOL_EXIT_SUCCESS) {
        /* hbao --help | head: the reader took what it wanted and left. Text
         * for a person (help, version, --info) ends there quietly, as if the
         * reader had read it all; an AO written to standard output does not
         * get here (ao_command reports its own write errors). */
        const int text_mode = options.mode == TOOL_MODE_HELP || options.mode == TOOL_MODE_VERSION ||
                              options.mode == TOOL_MODE_INFO;
        if (!(text_mode && errno == EPIPE)) {
            fprintf(stderr, "hbao: error: cannot write to standard output\n");
            status = TOOL_EXIT_RUNTIME;
        }
    }
    return status;
}
