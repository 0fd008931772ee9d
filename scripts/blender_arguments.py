# SPDX-License-Identifier: GPL-2.0-or-later
"""Arguments of a script that Blender runs (`blender -b --python S -- ARGS`):
argparse that raises instead of exiting, so that the script ends Blender with
its own status (render_passes.py, export_cameras.py)."""
import argparse
import os
import sys


class ArgumentError(Exception):
    pass


class ArgumentParser(argparse.ArgumentParser):
    """argparse that raises ArgumentError for a bad argument and SystemExit
    (after printing) for --help, instead of exiting Blender."""

    def error(self, message):
        raise ArgumentError(message)

    def exit(self, status=0, message=None):
        if message:
            print(message, end="", file=sys.stderr if status else sys.stdout)
        raise SystemExit(status)


def script_arguments():
    """The arguments after Blender's `--`, or none."""
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def end_blender(status):
    """Ends a script that Blender runs: on a non-zero `status`, Blender ends
    with it (sys.exit inside --python does not always end Blender with the
    status; os._exit does, once the streams are flushed)."""
    sys.stdout.flush()
    sys.stderr.flush()
    if status:
        os._exit(status)
