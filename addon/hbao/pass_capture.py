# SPDX-License-Identifier: GPL-2.0-or-later
"""The main render's Depth and Normal, and those of its extra renders (guard
band, back faces), taken from Blender's memory, without the file round trip
of handover.py, where its engine is written in Python (Cycles).

Python reads a Render Result's pixels only through a RenderEngine's own
`get_result()`, and only the engine that rendered it holds one: so the
render() of the main scene's engine class is wrapped, and once the engine
has rendered a view layer, that layer's passes are copied out of its
result (`RenderPass.rect`). A tiled render's pixels are not there yet
(Blender allocates the passes only when the engine writes the whole
frame, and reads them as zeros before): Cycles writes them in its
render_frame_finish(), which is wrapped too, and they are taken after it.
The helper's render, which follows, takes them (take()) instead of saving
and reading the whole Render Result.

Anything else keeps the file round trip, which gives the same arrays
(docs/blender-integration.md, hook step 3: what and why), as does a capture
that is missing, all zeros or not of the result's size. The wrapping is
engine_wrap.py's: a failed copy is logged and costs the render nothing,
and unregister() puts the engine's own methods back.
"""
import functools
import os
from time import perf_counter as _clock

import bpy
import numpy as np

from . import compat, engine_wrap
from .report import log

SUPPORTED = compat.VERSION >= (4, 5, 0)  # (3.4 crashes reading a pass without pixels)
# Set to 0: always the file round trip (to compare, or where a wrapper misbehaves).
SWITCH_VARIABLE = "HBAO_PASSES_FROM_MEMORY"

# The channels of each pass taken, as handover.py reads them.
_CHANNELS = {"Depth": 1, "Normal": 3}

# The scenes whose renders are taken (watch()): {scene pointer: {layer: with Normal}}.
_watched = {}
# What the engines left: {(scene pointer, view layer name): {"views": {view
# name: {"depth": array, "normal": array or None}}, "seconds": float}}.
_taken = {}
_extras = {}  # {main scene pointer: [its extra renders' scene pointers]}
_later = {}  # layers written in render_frame_finish(): {engine pointer: [(scene, layer)]}


# The geometry node that makes strokes, with no Grease Pencil data behind them
_STROKE_MAKER = "GeometryNodeCurvesToGreasePencil"


def _grease_pencil_in_use():
    """Whether Grease Pencil data is in use (4.5: grease_pencils_v3; 5.x:
    grease_pencils, annotations apart): a scene's own, an instanced or a
    background set's strokes all go into Depth after render(); or a node
    group in use that makes strokes (Blender draws those as it draws a
    Grease Pencil object's)."""
    data = getattr(bpy.data, "grease_pencils_v3", None)
    if data is None:
        data = bpy.data.grease_pencils
    return any(grease_pencil.users for grease_pencil in data) or any(
        node.bl_idname == _STROKE_MAKER for group in bpy.data.node_groups
        if group.users and group.bl_idname == "GeometryNodeTree" for node in group.nodes)


def watch(scene, layers, extras=()):
    """Take the passes of `scene`'s coming frame from its engine, for
    `layers` {view layer name: whether its Normal is wanted}, and those of
    the `extras` [(scene, layers)] that its render renders as well
    (extra_renders.py); what a previous frame left is dropped."""
    forget(scene)
    # the Grease Pencil scan only where a capture would be taken; forget() undoes _watch_one
    if not _watch_one(scene, layers) or _grease_pencil_in_use():
        return forget(scene)
    for extra, extra_layers in extras:
        _forget_pointer(extra.as_pointer())
        if _watch_one(extra, extra_layers):
            _extras.setdefault(scene.as_pointer(), []).append(extra.as_pointer())


def _watch_one(scene, layers):
    if not SUPPORTED or not layers or scene.render.use_border \
            or os.environ.get(SWITCH_VARIABLE, "1").strip() == "0":
        return False
    engine_class = engine_wrap.engine_class(scene.render.engine)
    if engine_class is None:
        return False
    engine_wrap.wrap(engine_class, _after_layer, _after_frame)
    _watched[scene.as_pointer()] = dict(layers)
    return True


def forget(scene):
    """Drop what was taken of `scene`'s render and of its extra renders,
    and stop watching them."""
    pointer = scene.as_pointer()
    for extra in _extras.pop(pointer, []):
        _forget_pointer(extra)
    _forget_pointer(pointer)


def _forget_pointer(pointer):
    _watched.pop(pointer, None)
    for key in [key for key in _taken if key[0] == pointer]:
        _taken.pop(key, None)
    for engine, layers in list(_later.items()):
        _later[engine] = [entry for entry in layers if entry[0] != pointer]


def _pass_array(render_pass, width, height):
    channels = _CHANNELS[render_pass.name]
    if render_pass.channels != channels or len(render_pass.rect) != width * height:
        return None
    pixels = np.empty(width * height * channels, np.float32)  # (foreach_get: flat)
    render_pass.rect.foreach_get(pixels)
    array = pixels.reshape((height, width) if channels == 1 else (height, width, channels))
    # Blender's rows run from the bottom: a top-down view of them, no copy
    # (native.py and ao_cache.py read such views in place).
    return array[::-1]


def _falls_back_to_the_file(step):
    """A step the engine's wrapper runs: a failure is logged, and the
    render goes on with the file round trip."""
    @functools.wraps(step)
    def guarded(*args):
        try:
            step(*args)
        except Exception as error:  # the render goes on; the file route stays
            log(f"could not take the passes from the render in memory "
                f"({type(error).__name__}: {error}); saving them instead")
    return guarded


@_falls_back_to_the_file
def _after_layer(engine, depsgraph, finishes):
    """Take the layer `engine` has just rendered, or, where its pixels are
    not there yet and the engine `finishes` the frame, after that."""
    if not _watched:
        return
    pointer = depsgraph.scene.as_pointer()
    layer_name = depsgraph.view_layer.name
    if layer_name not in _watched.get(pointer, ()):
        return
    if _take(engine, pointer, layer_name) is None and finishes:
        _later.setdefault(engine.as_pointer(), []).append((pointer, layer_name))


@_falls_back_to_the_file
def _after_frame(engine):
    if not _later:
        return
    for pointer, layer_name in _later.pop(engine.as_pointer(), []):
        if layer_name in _watched.get(pointer, ()):
            _take(engine, pointer, layer_name)


def _take(engine, pointer, layer_name):
    """Copy view layer `layer_name`'s passes out of `engine`'s result: True
    when taken, None when its pixels are not there (yet), False when they
    will not do."""
    with_normal = _watched[pointer][layer_name]
    start = _clock()
    result = engine.get_result()
    if result is None:
        return False
    width, height = result.resolution_x, result.resolution_y
    layer = next((layer for layer in result.layers if layer.name == layer_name), None)
    if layer is None:
        return False
    view_names = [view.name for view in result.views] or [""]
    views = {name: {"depth": None, "normal": None} for name in view_names}
    for render_pass in layer.passes:
        wanted = render_pass.name == "Depth" or (render_pass.name == "Normal" and with_normal)
        if not wanted or not 0 <= render_pass.view_id < len(view_names):
            continue
        array = _pass_array(render_pass, width, height)
        if array is None:
            return False
        views[view_names[render_pass.view_id]][render_pass.name.lower()] = array
    for arrays in views.values():
        if arrays["depth"] is None or (with_normal and arrays["normal"] is None):
            return False
        if not arrays["depth"].any():  # no pixels behind the pass (see above)
            return None
    _taken[(pointer, layer_name)] = {"views": views, "seconds": _clock() - start}
    return True


def take(scene, layers, views=None):
    """(channels, seconds) as handover.read_passes gives them, from what
    `scene`'s engine left of its render that has just ended, for `layers`
    {view layer name: whether its normal is wanted} and `views` [(view
    name, file suffix)] (None: a mono render); or None where any of it was
    not taken. What is taken is dropped here."""
    pointer = scene.as_pointer()
    if not layers:
        return None
    found = {}
    for layer in layers:
        entry = _taken.get((pointer, layer))
        if entry is None:
            return None
        found[layer] = entry
    names = [None] if views is None else [name for name, _suffix in views]
    channels = {}
    for name in names:
        view_channels = {}
        for layer, with_normal in layers.items():
            taken_views = found[layer]["views"]
            if name is None:
                if len(taken_views) != 1:
                    return None
                arrays = next(iter(taken_views.values()))
            elif name in taken_views:
                arrays = taken_views[name]
            else:
                return None
            if with_normal and arrays["normal"] is None:
                return None
            view_channels[("depth", layer)] = arrays["depth"]
            if with_normal:
                view_channels[("normal", layer)] = arrays["normal"]
        channels[name] = view_channels
    for layer in layers:
        _taken.pop((pointer, layer), None)
    seconds = sum(entry["seconds"] for entry in found.values())
    return (channels[None] if views is None else channels), seconds


def register():
    pass  # the engines are wrapped at their first watched render


def unregister():
    _watched.clear()
    _taken.clear()
    _later.clear()
    _extras.clear()
    engine_wrap.unwrap_all()
