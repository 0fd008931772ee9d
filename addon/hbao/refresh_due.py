# SPDX-License-Identifier: GPL-2.0-or-later
"""Whether a scene's last render can be brought up to its HBAO nodes'
current settings from the passes that render kept (recomposite.py does
it): only the nodes' AO parameters changed since (no node added, the same
passes), each node's kept passes are in the AO cache at the size the
helper renders, and the render was neither a border nor a multi-view one."""
from . import ao_cache, compat, node, render_record
from . import camera as camera_model
from .planning import plan_node


class Due:
    """A scene whose last render can be brought up to its nodes' settings:
    the render's record (the object itself: a new render makes a new one),
    the nodes' current signatures, and the jobs whose AO changed."""

    def __init__(self, record, signatures, changed):
        self.record, self.signatures, self.changed = record, signatures, changed

    def same_as(self, other):
        return (other is not None and self.record is other.record
                and self.signatures == other.signatures)


def due_for(main, helper):
    """A Due when `main`'s last render can be brought up to its nodes'
    current settings from the cached passes, else None. The record must be
    this scene's (not one renamed to its name; a file load clears them), and
    the helper's render must come out the size of the kept passes: its old
    pass is gone once it renders again, so a mismatch found then would
    leave the compositor without AO."""
    record = render_record.last_render(main.name)
    # A stereo or multi-view render's passes are kept per view, which a
    # refresh does not read (job_inputs.kept): such a render is done again.
    if record is None or helper.render.use_border or main.render.use_multiview:
        return None
    frame, signatures, identity = record
    if identity != main.as_pointer():
        return None
    changed, current_signatures = [], []
    for hbao_node in node.hbao_nodes(compat.compositor_tree(main)):
        if hbao_node.mute or not any(output.is_linked for output in hbao_node.outputs):
            continue  # the compositor shows those at once
        if hbao_node.name not in signatures:
            return None  # added since the render
        try:
            job = plan_node(hbao_node, main, frame, [])
        except Exception:  # the next render says what is wrong
            return None
        if job is not None:
            kept = ao_cache.last_render.entry(ao_cache.key(main.name, job.pass_name))
            width, height = camera_model.render_size(helper)
            if kept is None or kept[0].arrays[0].shape != (height, width):
                return None
        recorded, current = signatures[hbao_node.name], render_record.signature_of(job)
        current_signatures.append((hbao_node.name, current))
        if current == recorded:
            continue
        if current is not None and not render_record.same_passes(recorded, current):
            return None
        changed.append(job)
    return Due(record, tuple(current_signatures), changed) if changed else None
