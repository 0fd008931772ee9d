# SPDX-License-Identifier: GPL-2.0-or-later
"""A render engine written in Python (Cycles) with its render() and, where
it has one, its render_frame_finish() wrapped, so that the add-on's step
runs in the engine's own call, right after it (pass_capture.py: the passes
are copied out of the engine's result there, the only place Python can
read them). The wrappers call the engine's own method first and return
what it returns; the steps must not raise (pass_capture.py guards its own).
unwrap_all() puts the engine's own methods back, or leaves wrappers that
only pass through where another add-on has wrapped them since."""
import bpy

# Engine classes wrapped: {class: ({method name: its own function}, the
# wrappers' state, {method name: the wrapper})}.
_wrapped = {}


def engine_class(engine_name):
    """The registered Python class of the render engine `engine_name`, or
    None (an engine written in C, or the add-on's own). A class replaced by
    a new registration (Cycles reloaded) stays among the subclasses while
    anything holds it: the last registered one is Blender's."""
    found = None
    for candidate in bpy.types.RenderEngine.__subclasses__():
        if getattr(candidate, "bl_idname", None) == engine_name \
                and getattr(candidate, "is_registered", True):
            found = candidate
    if found is None:
        return None
    module = found.__module__
    if module == __package__ or module.startswith(__package__ + "."):
        return None
    return found if "render" in found.__dict__ else None


def wrap(wrapped_class, after_render, after_frame):
    """Wrap `wrapped_class` (engine_class's) where it is not wrapped yet:
    after its render(), after_render(engine, depsgraph, finishes) runs
    (finishes: whether the class has a render_frame_finish(), which Cycles
    writes a tiled render's pixels in), and after its render_frame_finish()
    after_frame(engine); after_render not for a preview render. Neither may
    raise. Lets go of classes replaced by a new registration."""
    for stale in [cls for cls in _wrapped if not getattr(cls, "is_registered", True)]:
        _wrapped.pop(stale)[1]["active"] = False
    if not _needs_wrapping(wrapped_class):
        return
    own = {name: wrapped_class.__dict__[name] for name in ("render", "render_frame_finish")
           if name in wrapped_class.__dict__}
    state = {"active": True}

    def render(self, depsgraph):
        result = own["render"](self, depsgraph)
        if state["active"] and not self.is_preview:
            after_render(self, depsgraph, "render_frame_finish" in own)
        return result

    def render_frame_finish(self):
        result = own["render_frame_finish"](self)
        if state["active"]:
            after_frame(self)
        return result

    wrappers = {name: function for name, function in (
        ("render", render), ("render_frame_finish", render_frame_finish)) if name in own}
    for name, function in wrappers.items():
        setattr(wrapped_class, name, function)
    _wrapped[wrapped_class] = (own, state, wrappers)


def _needs_wrapping(wrapped_class):
    """Not wrapped yet, or its own render() put back since (by another
    add-on that had wrapped it before this one); a wrapper of another
    add-on's over this one's keeps this one inside."""
    entry = _wrapped.get(wrapped_class)
    if entry is None:
        return True
    own, state, _wrappers = entry
    if wrapped_class.__dict__.get("render") is own["render"]:
        state["active"] = False
        return True
    return False


def unwrap_all():
    for wrapped_class, (own, state, wrappers) in list(_wrapped.items()):
        state["active"] = False
        for name, function in own.items():
            if wrapped_class.__dict__.get(name) is wrappers[name]:
                setattr(wrapped_class, name, function)
            # else wrapped again by someone else since: the chain stays, ours passes through
    _wrapped.clear()
