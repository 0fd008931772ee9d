/* SPDX-License-Identifier: GPL-2.0-or-later */
/* What an output EXR was computed with, as one line of text kept in its
 * header, so that a sequence run can tell a frame that is up to date from one
 * computed with other flags. */
#ifndef HBAO_TOOL_RUN_SETTINGS_H
#define HBAO_TOOL_RUN_SETTINGS_H

#include <openexr.h>
#include <stdbool.h>

#include "cli_options.h"

/** The header attribute (a string) that holds the settings. */
#define RUN_SETTINGS_ATTRIBUTE "hbaoSettings"
/** Room for the longest text: 13 parameters, twice 27 camera numbers (the
 *  flags' and the camera file's), a layer and a channel name. */
#define RUN_SETTINGS_MAX 2048

/**
 * Everything besides the input file that decides the output EXR's content:
 * the library version, the resolved parameters (but the thread count and the
 * SIMD implementation, which change no value), the layer, the AO channel's
 * name, --keep-input, --no-normals, the compression, --crop-to-display,
 * --overscan, the camera flags and what the camera file (--camera) holds. Two
 * runs with equal text write equal files from equal inputs. camera_file:
 * what the run read from --camera (so that the stamp is what the AO was
 * computed with, and the file is read once), or NULL to read it here. False
 * when the text did not fit (a layer name of kilobytes), or the camera file
 * cannot be read: it then must not be used to skip work.
 */
bool run_settings_text(const cli_options *options, const camera_settings *camera_file,
                       char text[RUN_SETTINGS_MAX]);

/** Whether the EXR opened as `context` holds RUN_SETTINGS_ATTRIBUTE equal
 *  to `text` in its first part (false without such an attribute). */
bool run_settings_match(exr_const_context_t context, const char *text);

/** Whether the EXR opened as `context` holds RUN_SETTINGS_ATTRIBUTE in its
 *  first part: it is an hbao output. */
bool run_settings_stamped(exr_const_context_t context);

#endif /* HBAO_TOOL_RUN_SETTINGS_H */
