/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * `hbao --info FILE.exr [--json]`: what the tool sees in an EXR (its own
 * reader, the same code path as the AO command): layout, Blender layers with
 * a Depth pass, and per-channel statistics of the decoded values.
 */
#ifndef HBAO_TOOL_INFO_COMMAND_H
#define HBAO_TOOL_INFO_COMMAND_H

#include <stdbool.h>

#include "tool_error.h"

int info_command(const char *path, bool as_json, tool_error *error);

#endif /* HBAO_TOOL_INFO_COMMAND_H */
