/* SPDX-License-Identifier: GPL-2.0-or-later */
/* `hbao render_####.exr -o ao_####.exr --frames 1-250`: ao_command() for
 * every frame, several at once, skipping outputs that are up to date. */
#ifndef HBAO_TOOL_SEQUENCE_COMMAND_H
#define HBAO_TOOL_SEQUENCE_COMMAND_H

#include "cli_options.h"
#include "tool_error.h"

/** Every frame is attempted; one progress line per frame goes to stderr.
 *  Fails (with the list of failed frames) when any frame failed. */
int sequence_command(const cli_options *options, tool_error *error);

#endif /* HBAO_TOOL_SEQUENCE_COMMAND_H */
