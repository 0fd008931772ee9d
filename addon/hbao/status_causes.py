# SPDX-License-Identifier: GPL-2.0-or-later
"""Whether what a node's status line says about the last render still
holds: Compositing off, an effect off for renders, Render Single Layer on,
a scene camera the library cannot model, or what the node's own plan said
(Depth not linked, a value out of range). Once the artist has fixed such a
cause, the status line drops its message (node_status.py) and the hint line
asks for a render (render_record.py): the compositor still shows the last
render's result. A message without a cause (report.NodeMessage: what the
AO's computation found, a failed library) holds until the next render.

Main thread, no render running (the add-on's timer): the checks read the
scene as it is now."""
from . import camera as camera_model
from . import helper_render_settings as settings
from . import planning, report

# (short, full): the node's hint line and its tooltip
FIXED_HINT = ("Fixed: render to update",
              "Since the last render, this no longer holds: {causes}. The compositor still "
              "shows that render's result: render again (F12) to update it.")


class _Plans:
    """What plan_node says of one node now, at each frame asked (computed
    once per frame for all its messages)."""

    def __init__(self, scene, node):
        self.scene, self.node, self.said = scene, node, {}

    def says(self, frame, message):
        if frame not in self.said:
            warnings = []
            planning.plan_node(self.node, self.scene, frame, warnings)
            self.said[frame] = set(warnings)
        return message in self.said[frame]


def _holds(message, scene, plans):
    cause = message.cause
    if cause[0] == planning.PLAN_CAUSE:
        return plans.says(cause[1], message)
    if cause in settings.SETTING_CAUSES:
        return cause in settings.causes_now(scene)
    if cause == camera_model.SCENE_CAMERA_CAUSE:
        return camera_model.scene_camera_fails(scene)
    return True


def holding(messages, scene, node):
    """Those of `messages` (NodeMessages about `node` of `scene`) that
    still hold; one whose check fails is kept (the next render says what
    is wrong)."""
    plans = _Plans(scene, node)
    kept = []
    for message in messages:
        try:
            holds = getattr(message, "cause", None) is None or _holds(message, scene, plans)
        except Exception:  # a scene being edited: the next render says
            holds = True
        if holds:
            kept.append(message)
    return kept


def fixed_since_render(scene, node):
    """FIXED_HINT naming what the last render said of `node` that no longer
    holds, or None."""
    said = report.last_node_messages(scene.name).get(node.name, ())
    kept = {id(message) for message in holding(said, scene, node)}
    fixed = [message.short for message in said if id(message) not in kept]
    if not fixed:
        return None
    short, full = FIXED_HINT
    return short, full.format(causes="; ".join(fixed))
