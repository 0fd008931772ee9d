# SPDX-License-Identifier: GPL-2.0-or-later
"""Making Blender composite a scene's tree again after a refresh rendered
its helper (recomposite.py), now or, where Blender refuses the write for
the moment (writes.writes_refused), on the timer's next tick."""
import bpy

from . import compat, node, writes
from .report import log

# Main scene names whose compositing Blender refused to start.
_refused = set()


def composite_again(main):
    """A value written to a socket of `main`'s tree (the same value):
    Blender composites the tree again (in the editors that show it), now
    with the new AO. Neither the tree's update_tag() nor a write to a node
    property does."""
    _refused.discard(main.name)
    for hbao_node in node.hbao_nodes(compat.compositor_tree(main)):
        for socket in hbao_node.inputs:
            if socket.enabled and isinstance(getattr(socket, "default_value", None),
                                             (int, float)):
                try:
                    socket.default_value = socket.default_value
                except AttributeError as error:
                    if not writes.writes_refused(error):
                        raise
                    _refused.add(main.name)
                return


def retry_refused():
    """composite_again each scene whose compositing was refused; an error
    that is not a refusal ends the retries of that scene (logged)."""
    for name in list(_refused):
        if name not in bpy.data.scenes:
            _refused.discard(name)
            continue
        try:
            composite_again(bpy.data.scenes[name])
        except Exception as error:
            _refused.discard(name)
            log(f"could not composite {name!r} again with its new AO: {error}")


def forget():
    """A file opened or the add-on disabled: nothing waits any more."""
    _refused.clear()
