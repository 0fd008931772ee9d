/* SPDX-License-Identifier: GPL-2.0-or-later */
/* `hbao INPUT.exr -o OUTPUT.exr`: read the passes, compute AO, write the results. */
#ifndef HBAO_TOOL_AO_COMMAND_H
#define HBAO_TOOL_AO_COMMAND_H

#include "ao_plan.h"
#include "cli_options.h"
#include "exr_reader.h"
#include "tool_error.h"

/** What one run computed: its plan and its images; any pointer may be NULL. */
typedef struct ao_buffers {
    float *depth;
    float *normal;    /**< X Y Z interleaved; NULL when not used */
    float *back;      /**< --back-layer's depth; NULL when not used */
    float *ao;        /**< width x height, rows top first */
    uint8_t **copies; /**< --keep-input: one native-type buffer per input channel */
    int copy_count;
    ao_plan plan; /**< what the AO was computed with, for the output's hbaoSettings */
} ao_buffers;

void ao_buffers_free(ao_buffers *buffers);

/** Everything between an opened input and its AO: its plan (ao_plan_make,
 *  into buffers->plan), read Depth (and Normal), run hbao_compute into
 *  buffers->ao. */
int ao_compute_input(const cli_options *options, exr_input *input, ao_buffers *buffers,
                     tool_error *error);

/** The whole command: checks, ao_compute_input(), outputs written atomically. */
int ao_command(const cli_options *options, tool_error *error);

#endif /* HBAO_TOOL_AO_COMMAND_H */
