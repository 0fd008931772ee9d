# SPDX-License-Identifier: GPL-2.0-or-later
"""One click from an unlinked HBAO node to a working one: Blender's Render
Layers node shows no Depth or Normal output until the pass is ticked in the
View Layer properties, so an artist who adds the node cannot link them. The
node's "Connect Passes" button turns the passes on and links them."""
import bpy

from . import compat, compat_nodes, pass_sources
from .helper_lookup import MANAGED_NODE_KEY
from .node import hbao_nodes
from .group_layout import DEPTH_INPUT, IMAGE_INPUT, NORMAL_INPUT

# (HBAO input, Render Layers output, view layer setting; None: always there)
_LINKS = ((IMAGE_INPUT, "Image", None), (DEPTH_INPUT, "Depth", "use_pass_z"),
          (NORMAL_INPUT, "Normal", "use_pass_normal"))


def _user_render_layers(tree):
    """The artist's Render Layers nodes (not the add-on's own)."""
    return [node for node in tree.nodes
            if node.bl_idname == "CompositorNodeRLayers" and not node.get(MANAGED_NODE_KEY)]


def connect_passes(scene, node):
    """Turn on the Depth and Normal passes of the view layer of the scene's
    first Render Layers node that the node takes passes from (not another
    scene's, nor a muted one, nor of a layer that is not rendered: those it
    refuses; made if there is none) and link its Image, Depth and Normal to
    `node`'s unlinked inputs. Returns what it did, as a sentence for the
    artist."""
    tree = node.id_data
    sources = [source for source in _user_render_layers(tree)
               if pass_sources.render_layers_refusal(source, scene, "Depth") is None]
    if sources:
        source = sources[0]
    else:
        source = tree.nodes.new("CompositorNodeRLayers")
        source.location = (node.location.x - 300, node.location.y)
        source.scene = scene
        rendered = [layer for layer in scene.view_layers if layer.use]
        if rendered:
            source.layer = rendered[0].name
    view_layer = scene.view_layers.get(source.layer)
    turned_on = []
    for _input, label, attribute in _LINKS:
        if attribute and view_layer is not None and not getattr(view_layer, attribute):
            setattr(view_layer, attribute, True)
            turned_on.append(label)
    linked = []
    for input_name, output_name, _attribute in _LINKS:
        target = node.inputs[input_name]
        if target.is_linked:
            continue
        tree.links.new(compat_nodes.pass_output(source, output_name), target)
        linked.append(output_name)
    done = []
    if turned_on:
        done.append(f"turned on the {' and '.join(turned_on)} pass"
                    f"{'es' if len(turned_on) > 1 else ''} of view layer {view_layer.name!r}")
    if linked:
        done.append(f"linked {', '.join(linked)} from {source.name!r}")
    text = "; ".join(done) if done else "the passes were already linked"
    return text[0].upper() + text[1:]


class HBAO_OT_connect_passes(bpy.types.Operator):
    """Turn on the Depth and Normal passes of the view layer and link the Render Layers \
node's Image, Depth and Normal to this HBAO node"""
    bl_idname = "hbao.connect_passes"
    bl_label = "Connect Passes"
    bl_options = {"REGISTER", "UNDO"}

    node_name: bpy.props.StringProperty(name="Node", options={"SKIP_SAVE"})

    def execute(self, context):
        scene = context.scene
        node = next((n for n in hbao_nodes(compat.compositor_tree(scene))
                     if n.name == self.node_name), None)
        if node is None:
            self.report({"ERROR"}, f"HBAO: no HBAO node {self.node_name!r} in the compositor")
            return {"CANCELLED"}
        try:
            self.report({"INFO"}, f"HBAO: {connect_passes(scene, node)}")
        except (KeyError, RuntimeError) as error:
            self.report({"ERROR"}, f"HBAO: cannot link the passes ({error}); link them by hand")
            return {"CANCELLED"}
        return {"FINISHED"}


def register():
    bpy.utils.register_class(HBAO_OT_connect_passes)


def unregister():
    bpy.utils.unregister_class(HBAO_OT_connect_passes)
