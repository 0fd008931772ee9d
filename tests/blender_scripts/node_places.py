# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_faults.py: HBAO nodes in the places an exploratory run
tried (node_place.py, node_group.py). CASE:

  edited_copy       the node's group copied (made single-user by a script)
                    and edited: an "Artist Power" node squares its AO output;
                    then the UI's sync and a render. Prints GROUP {json}.
  strip_modifier    (5.x) scene "Edit" shows "Shot" (which has an HBAO node)
                    in a scene strip with a Compositor modifier whose group
                    holds an HBAO node; Edit is rendered.
  muted_strip_modifier  (5.x) strip_modifier with the modifier muted.
  muted_meta        (5.x) strip_modifier with the strip inside a muted
                    meta strip, and a Color strip above.
  compositor_strip  (5.3) the same node group in a Compositor strip above.
  link_source       saves OUT_DIR/source.blend, whose compositing group
                    "Look" holds an HBAO node (a file to link from).
  linked_tree SOURCE  (5.x) "Look" linked from SOURCE (File > Link) and made
                    the scene's compositor; the UI's sync, then a render.
  failing_messages  the add-on's function that gathers a render's messages
                    (node_place.render_messages) made to raise (fault
                    injection), then a render.
  append_after_edit SOURCE  the shared group edited in place (the Power
                    node), then scene "Shot" appended from SOURCE (its node
                    with an unedited copy of the group); the UI's sync.
                    Prints GROUP {json}: the appended node's group, the groups.

Prints STATUS {json} (node: [status line, misplaced short or null]) before
the render where one renders, and RENDERED.

  blender -b --addons hbao --python node_places.py -- CASE OUT_DIR [SOURCE]
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

case, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]
compat = blender_scenes.compat


def hbao_node(tree, name):
    node = tree.nodes.new("CompositorNodeHBAO")
    node.name = name
    node.inputs["Radius"].default_value = 1.0
    node.inputs["Blur Size"].default_value = 0
    return node


def pass_through_group(name, node_name):
    """A node group Image -> an HBAO node -> Image."""
    group = bpy.data.node_groups.new(name, "CompositorNodeTree")
    compat.new_group_socket(group, "INPUT", "NodeSocketColor", "Image")
    compat.new_group_socket(group, "OUTPUT", "NodeSocketColor", "Image")
    group_in, group_out = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    node = hbao_node(group, node_name)
    group.links.new(group_in.outputs["Image"], node.inputs["Image"])
    group.links.new(node.outputs["Image"], group_out.inputs["Image"])
    return group


def square_the_ao(group):
    """The artist's edit: a Power node between the group's AO and its AO output."""
    group_out = next(node for node in group.nodes if node.bl_idname == "NodeGroupOutput")
    link = group_out.inputs["AO"].links[0]
    try:
        power = group.nodes.new("CompositorNodeMath")
    except RuntimeError:  # 5.x: the shader Math node
        power = group.nodes.new("ShaderNodeMath")
    power.name = "Artist Power"
    power.operation = "POWER"
    power.inputs[1].default_value = 2.0
    group.links.new(link.from_socket, power.inputs[0])
    group.links.new(power.outputs[0], group_out.inputs["AO"])


def statuses():
    from hbao import node_place
    found = {}
    for tree in [compat.compositor_tree(s) for s in bpy.data.scenes] + list(bpy.data.node_groups):
        for node in getattr(tree, "nodes", ()):
            if node.bl_idname == "CompositorNodeHBAO" and node.name not in found:
                misplaced = node_place.misplaced(node)
                found[node.name] = [node.status, misplaced[0] if misplaced else None]
    print("STATUS", json.dumps(found, sort_keys=True), flush=True)


def render(scene):
    """Frame 1 of `scene` to OUT_DIR/frame_0001.exr (multilayer: the
    passes), its camera to camera_0001.json."""
    settings = scene.render.image_settings
    compat.set_image_format(settings, "OPEN_EXR_MULTILAYER")
    settings.color_depth, settings.exr_codec = "32", "NONE"
    scene.render.filepath = os.path.join(out_dir, "frame_0001")  # (a still: no #### filled)
    scene.frame_set(1)
    if scene.camera is not None:
        with open(os.path.join(out_dir, "camera_0001.json"), "w") as stream:
            json.dump(blender_scenes.camera_description(scene), stream)
    statuses()
    print("RENDERED", bpy.ops.render.render(write_still=True, scene=scene.name), flush=True)


def sync():
    from hbao import handlers
    handlers._sync_everything()  # what the UI's timer does after an edit


def main():
    os.makedirs(out_dir, exist_ok=True)
    scene = bpy.context.scene
    if case == "linked_tree":
        blender_scenes.build_corner_scene(scene, (96, 64), "CYCLES", 4)
        with bpy.data.libraries.load(sys.argv[-1], link=True) as (_unused, linked):
            linked.node_groups = ["Look"]
        sys.modules["hbao.compositor_effects"].set_served_group(scene, linked.node_groups[0])
        sync()
        return render(scene)
    scene.name = "Shot"
    blender_scenes.build_corner_scene(scene, (96, 64), "CYCLES", 4)
    node = blender_scenes.hbao_test_tree(scene, out_dir, "HBAO0")
    node.inputs["Radius"].default_value = 1.0
    node.inputs["Blur Size"].default_value = 0
    sync()
    if case == "link_source":
        if compat.HAS_COMPOSITING_NODE_GROUP:  # (3.4 and 4.5: the scene's own tree)
            compat.compositor_tree(scene).name = "Look"
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out_dir, "source.blend"))
        print("SAVED", flush=True)
        return None
    if case == "append_after_edit":
        square_the_ao(node.node_tree)
        with bpy.data.libraries.load(sys.argv[-1]) as (_unused, appended):
            appended.scenes = ["Shot"]
        copy = compat.compositor_tree(appended.scenes[0]).nodes["HBAO0"]
        arrived = copy.node_tree.name
        sync()
        groups = sorted(g.name for g in bpy.data.node_groups if g.name.startswith(".HBAO"))
        print("GROUP", json.dumps({"arrived": arrived, "node": copy.node_tree.name,
                                   "groups": groups}), flush=True)
        return None
    if case == "edited_copy":
        node.node_tree = node.node_tree.copy()
        square_the_ao(node.node_tree)
        sync()
        groups = sorted(g.name for g in bpy.data.node_groups if g.name.startswith(".HBAO"))
        print("GROUP", json.dumps({"node": node.node_tree.name, "groups": groups}), flush=True)
        return render(scene)
    if case == "failing_messages":
        from hbao import node_place

        def render_messages(_scene):
            raise RuntimeError("injected")
        node_place.render_messages = render_messages
        return render(scene)
    edit = bpy.data.scenes.new("Edit")
    edit.render.resolution_x, edit.render.resolution_y = 96, 64
    strips = edit.sequence_editor_create().strips
    below = strips.new_scene("Shot", scene, channel=1, frame_start=1)
    group = pass_through_group("Strip FX", "HBAO in strip")
    if case == "compositor_strip":
        strips.new_effect(name="Comp", type="COMPOSITOR", channel=2, frame_start=1, length=10,
                          input1=below).node_group = group
    else:
        modifier = below.modifiers.new("Compositor", "COMPOSITOR")
        modifier.node_group = group
        modifier.mute = case == "muted_strip_modifier"
        if case == "muted_meta":
            meta = strips.new_meta("Meta", 2, 1)
            below.move_to_meta(meta)
            meta.mute = True
            # (a strip that renders: a sequencer with none asks for a camera)
            strips.new_effect(name="Fill", type="COLOR", channel=3, frame_start=1, length=10)
    sync()
    return render(edit)


main()
