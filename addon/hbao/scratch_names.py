# SPDX-License-Identifier: GPL-2.0-or-later
"""The names of the hand-over's scratch files (handover.py): one rule for
the add-on, which makes them and removes those of ended Blenders, and for
the soak, which looks for any left behind. bpy-free.

    hbao-passes-<process id>-<thread id>-<number>[<view's file suffix>].exr

Before session 19 a name had no number; such a file is still recognised,
so that it is removed once it is stale."""
import re

PREFIX = "hbao-passes-"
# A stereo or multi-view render's save adds each view's file suffix before
# the extension (view_files.view_path).
_NAME = re.compile(re.escape(PREFIX) + r"(\d+)-\d+(?:-\d+)?(?:[^/]*)\.exr")


def name(process, thread, number):
    """The scratch file name of `process`'s thread `thread`, its `number`th."""
    return f"{PREFIX}{process}-{thread}-{number}.exr"


def process_of(file_name):
    """The process id in a scratch file's name, or None for another name."""
    match = _NAME.fullmatch(file_name)
    return int(match.group(1)) if match else None


def glob_of(process):
    """A glob pattern (pathlib, fnmatch) for `process`'s scratch files and
    anything else of that process's with their prefix."""
    return f"{PREFIX}{process}-*"
