# SPDX-License-Identifier: GPL-2.0-or-later
"""The few Blender API differences between 3.x, 4.x and 5.x, in one place."""
import sys

import bpy

from . import compositor_effects

VERSION = bpy.app.version
# The oldest Blender the add-on runs on (its bl_info says the same), and the
# newest it has been tested with; a newer one is tried, with a warning.
MIN_SUPPORTED_VERSION = (3, 4, 0)
NEWEST_KNOWN_VERSION = (5, 3)
# 4.0 replaced tree.inputs/outputs with tree.interface.
HAS_TREE_INTERFACE = VERSION >= (4, 0, 0)
# 5.0: scene.compositing_node_group (a group with a Group Output) for node_tree.
HAS_COMPOSITING_NODE_GROUP = VERSION >= (5, 0, 0)
# Blender before 5.0 cuts an EXR channel name past 64 bytes (EXR_TOT_MAXNAME): a
# view layer named with 56 bytes or more loses "<layer>.Normal.X". None: no limit.
EXR_CHANNEL_NAME_MAX = 64 if VERSION < (5, 0, 0) else None


# 5.0 lets several scenes share one compositing node group (an ID of its own).
TREES_SHARED_BETWEEN_SCENES = HAS_COMPOSITING_NODE_GROUP
# A stereo render with one view on: render_0001.exr in 3.4, _L.exr in 4.5+.
SINGLE_VIEW_WITHOUT_SUFFIX = VERSION < (4, 5, 0)
# The Value node's idname: the compositor's own until 4.x, the shared
# ShaderNodeValue in 5.x files and menus (old files may still hold either).
VALUE_NODE_IDNAMES = ("CompositorNodeValue", "ShaderNodeValue")
# 3.4 frees a node type that Python unregisters while an evaluated copy of a
# tree (a depsgraph's, after any evaluation) still holds nodes of that type,
# and reads it when it frees the copy, as it quits (a crash under
# --debug-memory): there the type stays registered while Blender may read
# it (keep_node_type_registered, docs/blender-integration.md). 4.5 and 5.x
# are unaffected; the versions between are untested and treated as 3.4.
NODE_TYPE_FREED_UNDER_EVALUATED_COPIES = VERSION < (4, 5, 0)
# bpy 4.5's module (a Python script's `import bpy`, binary_path "") hangs at
# exit, after the script's last line, where a Python node type is still
# registered with nodes of it in the file: the type keeps bpy alive through
# Python's shutdown, so bpy never stops its sound thread, and a C++
# destructor then waits forever on the condition that thread waits on (a
# review's find; 5.0 and later exit). There the node type goes at exit
# (node.py), after which nothing of it is read: 4.5 frees an undefined node.
NODE_TYPE_HOLDS_MODULE_AT_EXIT = (bpy.app.binary_path == ""
                                  and (4, 5, 0) <= VERSION < (5, 0, 0))


def _version_text(version):
    return ".".join(str(part) for part in version)


def version_is_new_enough():
    return tuple(VERSION) >= MIN_SUPPORTED_VERSION


def version_message():
    """Why this Blender may not run the add-on, or None when it is one we test."""
    if not version_is_new_enough():
        return (f"HBAO needs Blender {_version_text(MIN_SUPPORTED_VERSION)} or newer; this is "
                f"{_version_text(VERSION)}. The add-on stays off.")
    if tuple(VERSION[:2]) > NEWEST_KNOWN_VERSION:
        return (f"HBAO is tested up to Blender {_version_text(NEWEST_KNOWN_VERSION)}; this is "
                f"{_version_text(VERSION)}. Trying anyway: if renders show no AO, check the "
                f"console for HBAO messages.")
    return None


def every_addon_being_disabled():
    """Whether the caller runs inside addon_utils.disable_all: Blender
    disables every add-on so before it frees its data, as it quits and as it
    loads factory settings or another app template."""
    frame = sys._getframe(1)
    while frame is not None:
        if (frame.f_code.co_name == "disable_all"
                and frame.f_globals.get("__name__") == "addon_utils"):
            return True
        frame = frame.f_back
    return False


def keep_node_type_registered(idname):
    """Whether a disabled add-on must leave its node type `idname`
    registered: while a tree holds such a node, so that it stays defined
    (5.3 composited an undefined one black, 4.5 and 5.0 skip a tree holding
    one; hook_release.py leaves it multiplying by 1); and, so that Blender
    never reads it freed, on the versions that would, while Blender is about
    to free its data. The type then lives until Blender quits, and enabling
    the add-on again reuses it."""
    if NODE_TYPE_FREED_UNDER_EVALUATED_COPIES and every_addon_being_disabled():
        return True
    if not isinstance(bpy.data, bpy.types.BlendData):
        return False  # no file yet (add-on start-up)
    trees = list(bpy.data.node_groups) + [compositor_tree(scene) for scene in bpy.data.scenes]
    return any(node.bl_idname == idname for tree in trees if tree is not None
               for node in tree.nodes)


def set_image_format(image_format, file_format):
    """Set an ImageFormatSettings' file format. 5.0 filters the formats by
    media_type, so the media type goes first."""
    if hasattr(image_format, "media_type"):
        image_format.media_type = ("MULTI_LAYER_IMAGE" if file_format == "OPEN_EXR_MULTILAYER"
                                   else "IMAGE")
    image_format.file_format = file_format


def set_multilayer_exr(settings):
    """Make `settings` (ImageFormatSettings) save a single-part multilayer
    OpenEXR, the layout libhbao_exr reads, with no preview image beside it."""
    set_image_format(settings, "OPEN_EXR_MULTILAYER")
    if hasattr(settings, "use_exr_interleave"):
        # 5.0+ writes one part per pass unless told to interleave them.
        settings.use_exr_interleave = True
    if hasattr(settings, "use_preview"):
        settings.use_preview = False


# The menu that lists the compositor's filter nodes: 3.4 generates
# NODE_MT_category_CMP_OP_FILTER from its node categories; 4.x/5.x name it
# NODE_MT_category_compositor_filter.
_FILTER_MENUS = ("NODE_MT_category_compositor_filter", "NODE_MT_category_CMP_OP_FILTER",
                 "NODE_MT_category_CMP_FILTER")


def compositor_filter_menu():
    """The menu class Add > Filter of the compositor is, or None."""
    for name in _FILTER_MENUS:
        menu = getattr(bpy.types, name, None)
        if menu is not None:
            return menu
    return None


def settle_new_scene(scene):
    """Bring a scene whose objects the add-on just linked up to date before a
    render copies it: 5.3 crashes (BKE_view_layer_copy_data, in the render's
    depsgraph) copying a scene made in a render handler whose view layer has
    not yet been synced with its collection. Harmless before 5.3."""
    for view_layer in scene.view_layers:
        view_layer.update()


def compositor_tree(scene):
    """The scene's compositor node tree the add-on serves, or None."""
    if HAS_COMPOSITING_NODE_GROUP:
        return compositor_effects.served_group(scene)
    return scene.node_tree


def ensure_compositor_tree(scene):
    """The scene's compositor tree, created (with compositing turned on) if needed."""
    if HAS_COMPOSITING_NODE_GROUP:
        tree = compositor_tree(scene)
        if tree is None:
            tree = bpy.data.node_groups.new(f"{scene.name} Compositing", "CompositorNodeTree")
            compositor_effects.set_served_group(scene, tree)
        return tree
    scene.use_nodes = True
    return scene.node_tree


def new_group_socket(tree, in_out, socket_type, name, subtype=None):
    """Add an input ('INPUT') or output ('OUTPUT') to a node group's interface;
    `subtype` ("DISTANCE") gives a float socket its unit: a property of the
    socket from 4.0, a socket type of its own before
    (NodeSocketFloatDistance)."""
    if HAS_TREE_INTERFACE:
        socket = tree.interface.new_socket(name, in_out=in_out, socket_type=socket_type)
        if subtype is not None:
            socket.subtype = subtype
        return socket
    if subtype is not None:
        socket_type += subtype.title()
    sockets = tree.inputs if in_out == "INPUT" else tree.outputs
    return sockets.new(socket_type, name)


def group_socket_names(tree, in_out):
    if HAS_TREE_INTERFACE:
        return [item.name for item in tree.interface.items_tree
                if getattr(item, "item_type", "") == "SOCKET" and item.in_out == in_out]
    sockets = tree.inputs if in_out == "INPUT" else tree.outputs
    return [socket.name for socket in sockets]


def clear_group_interface(tree):
    if HAS_TREE_INTERFACE:
        tree.interface.clear()
    else:
        tree.inputs.clear()
        tree.outputs.clear()


def find_fcurve(id_data, data_path, index=0):
    """The F-Curve animating `data_path` of `id_data` in its active action,
    or None (legacy and 4.4+ layered actions)."""
    animation = getattr(id_data, "animation_data", None)
    if animation is None:
        return None
    return action_fcurve(animation.action, getattr(animation, "action_slot", None), data_path,
                         index)


def action_fcurve(action, slot, data_path, index=0):
    """The F-Curve of `action` (for `slot`, 4.4+) animating `data_path`, or None."""
    if action is None:
        return None
    fcurves = getattr(action, "fcurves", None)
    if fcurves is not None and VERSION < (5, 0, 0):
        return fcurves.find(data_path, index=index)
    try:
        from bpy_extras import anim_utils
        channelbag = anim_utils.action_get_channelbag_for_slot(action, slot)
    except (ImportError, AttributeError):
        return None
    return channelbag.fcurves.find(data_path, index=index) if channelbag else None


def engine_identifier(engine):
    """A render engine's identifier in this Blender: EEVEE is BLENDER_EEVEE_NEXT
    in 4.2-4.5 and BLENDER_EEVEE before and after."""
    if engine == "BLENDER_EEVEE" and (4, 2, 0) <= VERSION < (5, 0, 0):
        return "BLENDER_EEVEE_NEXT"
    return engine


def engine_label(identifier):
    """A render engine's name as Blender's menu shows it (an add-on's label)."""
    for engine in bpy.types.RenderEngine.__subclasses__():
        if getattr(engine, "bl_idname", None) == identifier:
            return engine.bl_label
    return {"CYCLES": "Cycles", "BLENDER_EEVEE": "EEVEE", "BLENDER_EEVEE_NEXT": "EEVEE",
            "BLENDER_WORKBENCH": "Workbench"}.get(identifier, identifier)


def motion_blur(scene):
    """(START, CENTER or END, shutter in frames) of the camera motion blur of
    the scene's engine, or None: 3.4's EEVEE keeps its own (scene.eevee),
    Cycles its position before 4.2; the rest is RenderSettings'."""
    render, eevee = scene.render, getattr(scene, "eevee", None)
    if render.engine == "BLENDER_EEVEE" and VERSION < (4, 2, 0):
        return (eevee.motion_blur_position, eevee.motion_blur_shutter) \
            if eevee.use_motion_blur else None
    if not render.use_motion_blur or render.engine not in ("CYCLES", engine_identifier(
            "BLENDER_EEVEE")):
        return None
    holder = render if hasattr(render, "motion_blur_position") else scene.cycles
    return holder.motion_blur_position, render.motion_blur_shutter


# 5.3 names a sequencer strip's frames anew (the old names are deprecated,
# "expected to be removed in Blender 6.0"): frame_final_start/_end are
# left_handle/right_handle, frame_start content_start, a scene strip's
# animation_offset_start content_trim_start (the same values, measured).
_STRIP_TYPE = getattr(bpy.types, "Strip", None) or getattr(bpy.types, "Sequence")
HAS_STRIP_HANDLES = "left_handle" in _STRIP_TYPE.bl_rna.properties


def strip_shown_frames(strip):
    """(first, past the last) frame of the sequencer at which `strip` shows."""
    if HAS_STRIP_HANDLES:
        return strip.left_handle, strip.right_handle
    return strip.frame_final_start, strip.frame_final_end


def strip_content_start(strip):
    """(the sequencer's frame where `strip`'s content begins, the frames of
    the content trimmed at its start: 0 where the strip has no such trim)."""
    if HAS_STRIP_HANDLES:
        return strip.content_start, getattr(strip, "content_trim_start", 0)
    return strip.frame_start, getattr(strip, "animation_offset_start", 0)


def ensure_material_nodes(material):
    """Give a new material its node tree: 4.5 and before make it on
    use_nodes, which 5.0 deprecates (a new material has its tree there)."""
    if material.node_tree is None:
        material.use_nodes = True
