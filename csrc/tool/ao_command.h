/* SPDX-License-Identifier: GPL-2.0-or-later */
/* `hbao INPUT.exr -o OUTPUT.exr`: read the passes, compute AO, write the results. */
#ifndef HBAO_TOOL_AO_COMMAND_H
#define HBAO_TOOL_AO_COMMAND_H

#include "cli_options.h"
#include "tool_error.h"

int ao_command(const cli_options *options, tool_error *error);

#endif /* HBAO_TOOL_AO_COMMAND_H */
