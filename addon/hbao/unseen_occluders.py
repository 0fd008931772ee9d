# SPDX-License-Identifier: GPL-2.0-or-later
"""What a Cycles render leaves out of its Depth pass, so that it casts no
AO: holdouts (a collection's Holdout in the view layer, an object's
Holdout, a material's Holdout shader) and objects the camera does not see
(Indirect Only collections, an object's Camera ray visibility off). Cycles
writes the sky's depth at a holdout's pixels and none for what the camera
does not see; the HBAO node cannot tell such an object from the sky, and
the floor under it loses its contact shadow (an exploratory run: mean AO
0.95 where the render with the object gives 0.89). EEVEE writes a
holdout's depth. Read once a render job, for its view layers: the render's
report says which objects, not the node's status (the AO is right for
what the passes show)."""
from . import pass_sources
from .callback_guard import never_raises
from .node import DEPTH_INPUT, hbao_nodes

# names listed in a message before "and N more"
_NAMES_SHOWN = 3


def _layer_collections(layer_collection):
    """The view layer's collections under `layer_collection` that render."""
    for child in layer_collection.children:
        if child.exclude or child.collection.hide_render:
            continue
        yield child
        yield from _layer_collections(child)


def _has_holdout_shader(material):
    tree = getattr(material, "node_tree", None) if material is not None else None
    return tree is not None and any(
        node.bl_idname == "ShaderNodeHoldout" and not node.mute
        and any(output.is_linked for output in node.outputs) for node in tree.nodes)


def _named(kind, names):
    shown = ", ".join(f'"{name}"' for name in names[:_NAMES_SHOWN])
    more = f" and {len(names) - _NAMES_SHOWN} more" if len(names) > _NAMES_SHOWN else ""
    return f"{kind} {shown}{more}"


def _unseen(view_layer):
    """[description] of what `view_layer`'s Depth pass leaves out."""
    found = []
    collections = list(_layer_collections(view_layer.layer_collection))
    for flag, kind in (("holdout", "Holdout collection"),
                       ("indirect_only", "Indirect Only collection")):
        names = [layer.name for layer in collections
                 if getattr(layer, flag, False) and layer.collection.all_objects]
        if names:
            found.append(_named(kind + ("s" if len(names) > 1 else ""), names))
    holdouts, hidden, shaded, checked = [], [], [], {}
    for obj in view_layer.objects:
        if obj.hide_render or obj.type not in {"MESH", "CURVE", "SURFACE", "META", "FONT",
                                               "CURVES", "POINTCLOUD", "VOLUME"}:
            continue
        if getattr(obj, "is_holdout", False):
            holdouts.append(obj.name)
        elif not getattr(obj, "visible_camera", True):
            hidden.append(obj.name)
        else:
            for slot in getattr(obj, "material_slots", ()):
                material = slot.material
                key = material.name_full if material is not None else ""
                if key not in checked:
                    checked[key] = _has_holdout_shader(material)
                if checked[key]:
                    shaded.append(obj.name)
                    break
    for names, kind in ((holdouts, "holdout object"), (shaded, "object with a Holdout shader"),
                        (hidden, "object with Camera visibility off")):
        if names:
            plural = kind.replace("object", "objects", 1) if len(names) > 1 else kind
            found.append(_named(plural, names))
    return found


@never_raises("look for holdouts in the render's view layers", result=[])
def render_messages(scene, tree):
    """What a Cycles render of `scene` says about the view layers whose
    Depth the HBAO nodes of its compositor `tree` read, as
    report.NodeMessage reads: after "HBAO " in Blender's reports."""
    if scene.render.engine != "CYCLES":
        return []
    messages = []
    layer_names = {pass_sources.pass_source(node.inputs[DEPTH_INPUT], scene, "Depth")[0]
                   for node in hbao_nodes(tree)} - {None}
    for name in sorted(layer_names):
        view_layer = scene.view_layers.get(name)
        unseen = _unseen(view_layer) if view_layer is not None else []
        if unseen:
            messages.append(
                f'view layer "{name}": {"; ".join(unseen)}: Cycles gives them no depth in the '
                "Depth pass, so they cast no AO (the surfaces around them lack their contact "
                "shadows); EEVEE gives a holdout its depth")
    return messages
