# SPDX-License-Identifier: GPL-2.0-or-later
"""How the render hook tells the artist what happened: one console prefix,
and whether the caller may change Blender data (only the main thread may)."""
import threading

LOG_PREFIX = "HBAO:"


def log(message):
    print(f"{LOG_PREFIX} {message}", flush=True)


def in_main_thread():
    """F12 runs the render handlers in the render job's thread, where adding
    or removing data blocks and nodes is not allowed."""
    return threading.current_thread() is threading.main_thread()
