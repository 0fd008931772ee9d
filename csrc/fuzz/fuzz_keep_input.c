/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Fuzz target: `hbao IN.exr -o OUT.exr --keep-input --preview OUT.png`, the
 * whole command: every input channel decoded in its own type, written with
 * the AO and the input's header attributes to a temporary file, renamed into
 * place. Oracle, besides the sanitizers: when the command succeeds, its
 * output opens with the same reader, decodes completely and holds the
 * input's channels plus AO.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ao_command.h"
#include "cli_options.h"
#include "fuzz_input_file.h"
#include "zip_chunks.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fail(const char *what, const char *detail) {
    fprintf(stderr, "fuzz: %s: %s\n", what, detail);
    abort();
}

/* Decode every channel of the output as float. */
static void check_output(const char *path, int expected_channels) {
    exr_input output;
    tool_error error;
    if (exr_input_open(&output, path, &error) != TOOL_EXIT_SUCCESS)
        fail("the output does not open", error.message);
    const int count = output.channels->num_channels;
    if (count != expected_channels) fail("the output has the wrong channels", path);
    const size_t pixels = (size_t)output.width * (size_t)output.height;
    float *values = malloc(pixels * sizeof(float) * (size_t)count);
    exr_channel_request *requests = calloc((size_t)count, sizeof *requests);
    if (values == NULL || requests == NULL) fail("out of memory", path);
    for (int c = 0; c < count; ++c) {
        exr_channel_request request = {output.channels->entries[c].name.str, EXR_PIXEL_FLOAT,
                                       (uint8_t *)(values + pixels * (size_t)c), sizeof(float),
                                       (int64_t)output.width * (int64_t)sizeof(float)};
        requests[c] = request;
    }
    if (exr_input_read(&output, requests, count, &error) != TOOL_EXIT_SUCCESS)
        fail("the output does not decode", error.message);
    free(requests);
    free(values);
    exr_input_close(&output);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    exr_input_set_zip_decompressor(zip_chunks_decompress); /* as the tool reads */
    const char *input_path = fuzz_input_file(data, size);
    static char output_path[4200], preview_path[4200];
    snprintf(output_path, sizeof output_path, "%s/out.exr", fuzz_scratch_folder());
    snprintf(preview_path, sizeof preview_path, "%s/out.png", fuzz_scratch_folder());
    char *argv[] = {"hbao",
                    (char *)input_path,
                    "-o",
                    output_path,
                    "--keep-input",
                    "--preview",
                    preview_path,
                    "--directions",
                    "1",
                    "--steps",
                    "1",
                    "--blur",
                    "0",
                    "--threads",
                    "1",
                    NULL};
    const int argc = (int)(sizeof argv / sizeof argv[0]) - 1;
    cli_options options;
    tool_error error;
    if (cli_parse(argc, argv, &options, &error) != TOOL_EXIT_SUCCESS)
        fail("bad built-in command line", error.message);

    /* Only small images: the size check needs the header, read once more. */
    exr_input input;
    if (exr_input_open(&input, input_path, &error) != TOOL_EXIT_SUCCESS) return 0;
    const bool small = (int64_t)input.width * input.height <= FUZZ_MAX_PIXELS;
    int expected = input.channels->num_channels + 1;
    if (exr_input_find_channel(&input, "AO") >= 0) --expected; /* replaced by the new AO */
    exr_input_close(&input);
    if (!small) return 0;

    remove(output_path);
    if (ao_command(&options, &error) == TOOL_EXIT_SUCCESS) check_output(output_path, expected);
    return 0;
}
