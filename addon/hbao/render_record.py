# SPDX-License-Identifier: GPL-2.0-or-later
"""What the last render of each scene computed each HBAO node with, so that
a node whose settings changed since can say so: the AO is computed while
Blender renders, and re-compositing an existing render (what Blender does
when a node's value changes) shows the AO of the old settings until the
next render, unless recomposite.py can bring it up to date from the kept
passes (README, Limits).

The render thread records (`remember`, plain Python objects only); the
add-on's timer compares (`apply_hints`, main thread, no render running) and
writes the node's hint line, which the node only draws. The
comparison is the render's own plan of the node (planning.plan_node), at the
frame that was rendered, so a keyframed value that differs at another frame
does not count as a change."""
from . import compat, node, node_status, render_slots, status_causes
from .planning import plan_node

# (short, full): the node's line and its tooltip
HINT = ("Changed: render to update",
        "This node's settings changed since the last render. The AO in the compositor is "
        "still the last render's: render again (F12) to update it. (Changes to the AO "
        "settings alone follow by themselves while the compositor is open and the Render "
        "Result shows the last completed render, in its slot; other changes, another slot "
        "shown, a cancelled render or Display Mode \"Keep User Interface\" need a render.)")

# {main scene name: (frame, {node name: signature}, the scene's as_pointer())};
# replaced whole per render, so the main thread never reads a half-written
# record. A new record is a new object: recomposite.py tells renders apart
# by it.
_records = {}


def _signature(job):
    if job is None:
        return None
    return (job.params, job.layer, job.with_normal, job.guard_band, job.back_faces)


def remember(main_name, frame, jobs, node_names, main_uid=None):
    """Called by the hook for each render of `main_name` (whose
    as_pointer() is `main_uid`): the nodes in `node_names` were rendered at `frame`, those
    with a job with its settings, the others without AO."""
    signatures = {name: None for name in node_names}
    signatures.update({job.node_name: _signature(job) for job in jobs})
    put_back(main_name, (frame, signatures, main_uid))


def put_back(main_name, record):
    """Make `record` (a last_render() value, or None) `main_name`'s again."""
    global _records
    records = dict(_records)
    if record is None:
        records.pop(main_name, None)
    else:
        records[main_name] = record
    _records = records


def last_render(main_name):
    """(frame, {node name: signature or None}, the scene's as_pointer()) of
    `main_name`'s last render, or None; None too where the Render Result
    no longer shows that render (a cancelled one since, or another slot:
    render_slots), which a refresh must then leave alone. Main thread."""
    record = _records.get(main_name)
    return record if record is not None and render_slots.shows_last_render(main_name) else None


def signature_of(job):
    """What a render records of a job (None: the node computed nothing)."""
    return _signature(job)


def same_passes(recorded, current):
    """Whether two signatures read the same passes (view layer, normals,
    guard band, back faces) and so differ at most in the AO parameters."""
    return recorded is not None and current is not None and recorded[1:] == current[1:]


def forget():
    global _records
    _records = {}


def changed_since_render(hbao_node, main=None):
    """HINT when `hbao_node` (of `main`'s compositor tree; found when not
    given) would get another AO than the last render of `main` computed,
    status_causes.FIXED_HINT where what that render said of it no longer
    holds, else None (also when `main` was not rendered since the add-on
    loaded, or the node is muted or unused: the compositor shows those at
    once)."""
    if main is None:
        import bpy
        main = next((scene for scene in bpy.data.scenes
                     if compat.compositor_tree(scene) == hbao_node.id_data), None)
    if main is None or hbao_node.mute or not any(output.is_linked
                                                 for output in hbao_node.outputs):
        return None
    fixed = status_causes.fixed_since_render(main, hbao_node)
    if fixed is not None:
        return fixed
    record = _records.get(main.name)
    if record is None:
        return None
    frame, signatures, _uid = record
    if hbao_node.name not in signatures:
        return HINT  # added since
    try:
        now = _signature(plan_node(hbao_node, main, frame, []))
    except Exception:  # the next render says what is wrong
        return None
    return None if now == signatures[hbao_node.name] else HINT


def apply_hints():
    """Bring every HBAO node's hint line up to date (node_status.hint_refreshers:
    main thread, no render running). Writes only what changed, since a
    write makes Blender composite again. Returns whether it wrote."""
    import bpy
    changed = False
    for scene in bpy.data.scenes:
        for hbao_node in node.hbao_nodes(compat.compositor_tree(scene)):
            short, details = changed_since_render(hbao_node, scene) or ("", "")
            if hbao_node.hint != short or hbao_node.hint_details != details:
                try:
                    hbao_node.hint, hbao_node.hint_details = short, details
                except (AttributeError, RuntimeError):  # a linked, read-only tree
                    continue
                changed = True
    return changed


def register():
    if apply_hints not in node_status.hint_refreshers:
        node_status.hint_refreshers.append(apply_hints)


def unregister():
    if apply_hints in node_status.hint_refreshers:
        node_status.hint_refreshers.remove(apply_hints)
    forget()
