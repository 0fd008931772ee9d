# SPDX-License-Identifier: GPL-2.0-or-later
"""HBAO: horizon-based ambient occlusion as a compositor node (Add > Filter >
HBAO) and a viewport preview, computed by the native library libhbao."""

bl_info = {
    "name": "HBAO",
    "author": "HBAO contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Compositor > Add > Filter > HBAO",
    "description": "Horizon-based ambient occlusion from the Depth and Normal passes",
    "category": "Compositing",
    "doc_url": "",
    "tracker_url": "",
    "support": "COMMUNITY",
}

import bpy  # noqa: E402  (bl_info must come first for Blender's add-on scanner)

from . import node, render_hook  # noqa: E402

_MODULES = (node, render_hook)


def sync(scene=None):
    """Build or update the render hook of `scene` (default: every scene) now.
    Scripts that add HBAO nodes in background mode may call it; renders call
    it themselves."""
    if scene is None:
        render_hook.sync_all()
        return []
    return render_hook.sync(scene)


def _viewport():
    from . import viewport
    return viewport


def register():
    for module in _MODULES:
        module.register()
    try:
        _viewport().register()
    except Exception as error:  # the compositor node works without the preview
        print(f"HBAO: the viewport preview could not be registered: {error}")
    if not isinstance(bpy.data, bpy.types.BlendData):
        return  # add-on enabled at startup: load_post syncs once a file is open
    render_hook.sync_all()


def unregister():
    try:
        _viewport().unregister()
    except Exception as error:
        print(f"HBAO: the viewport preview could not be unregistered: {error}")
    for module in reversed(_MODULES):
        module.unregister()
