/* SPDX-License-Identifier: GPL-2.0-or-later */
/* What an output EXR was computed with, as one line of text kept in its
 * header, so that a sequence run can tell a frame that is up to date from one
 * computed with other flags. */
#ifndef HBAO_TOOL_RUN_SETTINGS_H
#define HBAO_TOOL_RUN_SETTINGS_H

#include <openexr.h>
#include <stdbool.h>

#include "ao_plan.h"
#include "cli_options.h"

/** The header attribute (a string) that holds the settings. */
#define RUN_SETTINGS_ATTRIBUTE "hbaoSettings"
/** Room for the longest text: 13 parameters, 26 camera numbers, two layer
 *  names and a channel name. */
#define RUN_SETTINGS_MAX 2048

/**
 * Everything besides the input file that decides the output EXR's content,
 * as the run computes it (ao_plan.h): the library version, the parameters
 * (but the thread count and the SIMD implementation, which change no
 * value; the background depth as the camera's clip range made it), whether
 * normals are read, --keep-input, the compression, --crop-to-display,
 * --overscan, every value of the camera (however it was given: a default,
 * the header, --camera, a flag), the layers found and the AO channel's
 * name. Two runs with equal text write equal files from equal inputs, and
 * flags that say the same in other words give the same text. False when the
 * text did not fit (a layer name of kilobytes): it then must not be used to
 * skip work.
 */
bool run_settings_text(const cli_options *options, const ao_plan *plan,
                       char text[RUN_SETTINGS_MAX]);

/** Whether the EXR opened as `context` holds RUN_SETTINGS_ATTRIBUTE equal
 *  to `text` in its first part (false without such an attribute). */
bool run_settings_match(exr_const_context_t context, const char *text);

/** Whether the EXR opened as `context` holds RUN_SETTINGS_ATTRIBUTE in its
 *  first part: it is an hbao output. */
bool run_settings_stamped(exr_const_context_t context);

#endif /* HBAO_TOOL_RUN_SETTINGS_H */
