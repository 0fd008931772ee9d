/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * Fuzz target: an EXR file through the tool's whole reading path (header
 * checks, Blender pass lookup, camera from the header, Depth/Normal decode,
 * a back-face layer) and hbao_compute_layers. Oracle, besides the
 * sanitizers: whenever the computation succeeds, every AO value is finite
 * and in [0, 1] (hbao.h's contract).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "ao_command.h"
#include "cli_options.h"
#include "fuzz_input_file.h"
#include "zip_chunks.h"

/* Small settings keep an execution short; the size of the input picks one
 * of five variants so that each of the library's paths (half resolution,
 * blur, both integrations and falloffs, a back-face layer) gets inputs. The
 * blur is small and in two variants only: instrumented for coverage, its
 * per-tap comparisons took a third of the time. The back-face variant reads
 * the layers of tests/fixtures/two_layers.exr (Front, Back); other inputs
 * take its error path. */
#define VARIANTS 5
static char *variants[VARIANTS][20] = {
    {"hbao", "IN", "-o", "unused.exr", "--directions", "2", "--steps", "3", "--threads", "1",
     "--blur", "0", NULL},
    {"hbao", "IN", "-o", "unused.exr", "--directions", "3", "--steps", "2", "--threads", "1",
     "--half-res", "--integration", "hbao", "--blur", "3", NULL},
    {"hbao", "IN", "-o", "unused.exr", "--directions", "1", "--steps", "4", "--threads", "1",
     "--falloff", "quadratic", "--blur", "0", "--no-normals", NULL},
    {"hbao", "IN", "-o", "unused.exr", "--directions", "2", "--steps", "2", "--threads", "1",
     "--blur", "3", "--strength", "3", "--angle-bias", "0", NULL},
    {"hbao", "IN", "-o", "unused.exr", "--directions", "2", "--steps", "3", "--threads", "1",
     "--blur", "0", "--layer", "Front", "--back-layer", "Back", NULL},
};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    exr_input_set_zip_decompressor(zip_chunks_decompress); /* as the tool reads */
    char **argv = variants[size % VARIANTS];
    int argc = 0;
    while (argv[argc] != NULL) ++argc;
    argv[1] = (char *)fuzz_input_file(data, size);
    cli_options options;
    tool_error error;
    if (cli_parse(argc, argv, &options, &error) != TOOL_EXIT_SUCCESS) {
        fprintf(stderr, "fuzz: bad built-in command line: %s\n", error.message);
        abort();
    }
    exr_input input;
    if (exr_input_open(&input, argv[1], &error) != TOOL_EXIT_SUCCESS) return 0;
    if ((int64_t)input.width * input.height <= FUZZ_MAX_PIXELS) {
        ao_buffers buffers = {0};
        if (ao_compute_input(&options, &input, &buffers, &error) == TOOL_EXIT_SUCCESS) {
            const int64_t count = (int64_t)input.width * input.height;
            for (int64_t i = 0; i < count; ++i) {
                if (!(buffers.ao[i] >= 0.0f && buffers.ao[i] <= 1.0f)) {
                    fprintf(stderr, "fuzz: AO[%lld] = %g is outside [0, 1]\n", (long long)i,
                            (double)buffers.ao[i]);
                    abort();
                }
            }
        }
        ao_buffers_free(&buffers);
    }
    exr_input_close(&input);
    return 0;
}
