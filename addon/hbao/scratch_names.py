# SPDX-License-Identifier: GPL-2.0-or-later
"""The names of the hand-over's scratch files (handover.py): one rule for
the add-on, which makes them and removes those of ended Blenders, and for
the soak, which looks for any left behind. bpy-free.

    hbao-passes-<process id>-<thread id>-<number>-<space>-<run>[<view's file suffix>].exr

space: 8 hex digits naming where the process id means something (the
machine's boot and the PID namespace: scratch_files.process_space), so that
a Blender that shares the folder with other machines or containers judges
only its own space's process ids; run: 8 random hex digits of the process,
so that no two Blenders ever make the same name, even with the same process
and thread ids (containers, with address space randomisation off, gave two
Blenders one name and one frame the other's AO: an exploratory run).

Names without space and run (before session 33), and without a number
(before session 19), are still recognised, so that they are removed once
stale."""
import collections
import re

PREFIX = "hbao-passes-"
# A stereo or multi-view render's save adds each view's file suffix before
# the extension (view_files.view_path).
_NAME = re.compile(re.escape(PREFIX) +
                   r"(\d+)-\d+(?:-\d+(?:-([0-9a-f]{8})-([0-9a-f]{8}))?)?(?:[^/]*)\.exr")

# Whose a scratch file is: its process id, and its space and run (None in
# the names before session 33).
Owner = collections.namedtuple("Owner", "process space run")


def name(process, thread, number, space, run):
    """The scratch file name of `process`'s thread `thread`, its `number`th;
    space and run: 8 hex digits each (see above)."""
    return f"{PREFIX}{process}-{thread}-{number}-{space}-{run}.exr"


def owner_of(file_name):
    """The Owner in a scratch file's name, or None for another name."""
    match = _NAME.fullmatch(file_name)
    return Owner(int(match.group(1)), match.group(2), match.group(3)) if match else None


def glob_of(process):
    """A glob pattern (pathlib, fnmatch) for `process`'s scratch files and
    anything else of that process's with their prefix."""
    return f"{PREFIX}{process}-*"
