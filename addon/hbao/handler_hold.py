# SPDX-License-Identifier: GPL-2.0-or-later
"""Renders of the add-on's own that no other handler sees: the helper scene
rendered alone to re-composite (recomposite.py)."""
import contextlib

import bpy

# The handler lists that a render runs. The helper's render is a step of the
# add-on's, not a render of the artist's: a pipeline's handlers (one that
# notifies a farm, or saves each render) must not run for it on every change
# of a value, with a scene they do not know. The add-on's own handlers do
# run (node_status.py's shows the engine's messages on the nodes).
RENDER_HANDLERS = ("render_init", "render_pre", "render_stats", "render_post", "render_write",
                   "render_complete", "render_cancel", "frame_change_pre", "frame_change_post")


def _ours(function):
    module = getattr(function, "__module__", None) or ""
    return module == __package__ or module.startswith(__package__ + ".")


@contextlib.contextmanager
def held_back():
    """Every handler of RENDER_HANDLERS but the add-on's own taken out for
    the block, and put back after it in its order (with any that the block
    added after them)."""
    held = []
    try:  # whatever fails, every list taken out of is put back
        for name in RENDER_HANDLERS:
            handlers = getattr(bpy.app.handlers, name, None)
            if handlers is not None:
                held.append((handlers, list(handlers)))
                handlers[:] = [function for function in handlers if _ours(function)]
        yield
    finally:
        for handlers, functions in held:
            handlers[:] = functions + [f for f in handlers if f not in functions]
