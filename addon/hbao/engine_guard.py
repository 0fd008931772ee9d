# SPDX-License-Identifier: GPL-2.0-or-later
"""The internal engine cannot stay picked for an artist's scene.

Blender lists every registered engine in the Render Engine menu and an
add-on cannot hide one. When the artist picks the add-on's internal engine
for a scene of their own, the scene gets back the engine it had (Cycles when
that is unknown) and a popup says why. Blender tells Python about the change
through the message bus, which runs only with a user interface; a file saved
with the engine and rendered with `blender -b` renders nothing and says
which engine to choose (engine.py)."""
import bpy

from . import compat
from .callback_guard import never_raises
from .helper_lookup import ENGINE_IDNAME, is_helper
from .report import log

# scene name -> the last engine it had other than ours
_engines = {}
# The message bus's owner of our subscription (any Python object).
_OWNER = object()

KEPT_ENGINE_MESSAGE = ("\"{label}\" is the HBAO add-on's internal engine and renders nothing, "
                       "so scene \"{scene}\" keeps {engine}. For AO, add the HBAO node in the "
                       "Compositor (Add > Filter > HBAO).")


def _fallback_engine():
    cycles = "cycles" in bpy.context.preferences.addons.keys()
    return "CYCLES" if cycles else compat.engine_identifier("BLENDER_EEVEE")


def remember_engines():
    """Note every artist scene's engine (at load and after each change)."""
    for scene in bpy.data.scenes:
        if not is_helper(scene) and scene.render.engine != ENGINE_IDNAME:
            _engines[scene.name] = scene.render.engine


def _show(message):
    log(message)
    window_manager = bpy.context.window_manager
    if window_manager is None or not window_manager.windows:
        return

    def draw(menu, _context):
        for line in message.split(". "):
            menu.layout.label(text=line.rstrip(".") + ".")
    window_manager.popup_menu(draw, title="HBAO", icon="INFO")


def restore_engines():
    """Give every artist scene that has the internal engine its engine back.
    Returns the messages shown."""
    messages = []
    for scene in bpy.data.scenes:
        if is_helper(scene) or scene.render.engine != ENGINE_IDNAME or scene.library:
            continue
        engine = _engines.get(scene.name) or _fallback_engine()
        scene.render.engine = engine
        message = KEPT_ENGINE_MESSAGE.format(label=compat.engine_label(ENGINE_IDNAME),
                                             scene=scene.name, engine=compat.engine_label(engine))
        _show(message)
        messages.append(message)
    remember_engines()
    return messages


@never_raises("check the scenes' render engines")
def _on_engine_changed(*_args):
    restore_engines()


def subscribe():
    """(Re)subscribe: loading a file clears the message bus."""
    bpy.msgbus.clear_by_owner(_OWNER)
    bpy.msgbus.subscribe_rna(key=(bpy.types.RenderSettings, "engine"), owner=_OWNER, args=(),
                             notify=_on_engine_changed)
    if isinstance(bpy.data, bpy.types.BlendData):
        remember_engines()


@bpy.app.handlers.persistent
@never_raises("check the scenes' render engines")
def _on_load_post(*_args):
    _engines.clear()
    subscribe()


def register():
    subscribe()
    if _on_load_post not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(_on_load_post)


def unregister():
    if _on_load_post in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_on_load_post)
    bpy.msgbus.clear_by_owner(_OWNER)
    _engines.clear()
