# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: scenes without a camera that
only composite, each with an HBAO node. "other_scene": scene Comp shows
scene Shot's render (a Render Layers node of Shot) through the HBAO node;
"connected": Connect Passes in Shot's own compositor;
"image_only": scene Plate, without a camera, multiplies a generated image
by two HBAO nodes (fed by no Render Layers node at all: one's Depth from
the Image node, the other's through a muted link); its helper gets a camera
made for it, not the add-on's own guard band camera of another scene, and
that camera goes with the helper.
Blender refused the renders of Comp and Plate ("Cannot render, no camera":
the add-on's helper scene had no camera), cancelling them. Writes OUT/<case>.png and
prints 'COMPOSITING <case> <json>' with the operator's result and the
node's status.

  blender -b --addons hbao --python compositing_scene.py -- OUT
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]
compat = sys.modules["hbao.compat"]
hbao_package = sys.modules["hbao"]
SIZE = (64, 48)


def render(scene, case):
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.render.filepath = os.path.join(out_dir, case)
    scene.render.image_settings.file_format = "PNG"
    result = bpy.ops.render.render(write_still=True, scene=scene.name)
    nodes = [node for node in compat.compositor_tree(scene).nodes
             if node.bl_idname == "CompositorNodeHBAO"]
    print("COMPOSITING", case, json.dumps({
        "result": sorted(result), "written": os.path.isfile(scene.render.filepath + ".png"),
        "status": [node.status for node in nodes]}), flush=True)


shot = blender_scenes.build_corner_scene(bpy.context.scene, SIZE, "CYCLES", 1)
shot.name = "Shot"
comp = blender_scenes.Compositor(bpy.data.scenes.new("Comp"))
source = comp.render_layers()
source.scene = shot
hbao = comp.node("CompositorNodeHBAO", (300, 0))
for name in ("Image", "Depth", "Normal"):
    comp.link(source.outputs[name], hbao.inputs[name])
comp.composite(hbao.outputs["Image"])
# Shot's Depth and Normal passes off: the node refuses another scene's
# passes, so turning them on there (a lasting change to that scene, for no
# AO) is not its business
shot_layer = shot.view_layers[0]
shot_layer.use_pass_z = shot_layer.use_pass_normal = False
render(comp.scene, "other_scene")
print("OTHER SCENE PASSES", json.dumps([shot_layer.use_pass_z, shot_layer.use_pass_normal]),
      flush=True)

# Connect Passes in Shot's own compositor, whose first Render Layers nodes
# show another scene and are muted: it links a Render Layers node of Shot
# that the node takes passes from, and the render has AO.
shot_tree = blender_scenes.Compositor(shot)
elsewhere = bpy.data.scenes.new("Elsewhere")
elsewhere.collection.objects.link(shot.camera)  # Blender renders the scenes shown
elsewhere.camera = shot.camera
shot_tree.render_layers(location=(-400, 300)).scene = elsewhere
shot_tree.render_layers(location=(-400, 0)).mute = True
hbao = shot_tree.node("CompositorNodeHBAO", (300, 0))
hbao.inputs["Blur Size"].default_value = 0
shot_tree.composite(hbao.outputs["Image"])
connected = bpy.ops.hbao.connect_passes(node_name=hbao.name)
source = hbao.inputs["Depth"].links[0].from_node
print("CONNECTED", json.dumps({
    "result": sorted(connected), "scene": source.scene.name, "muted": source.mute,
    "passes": [shot_layer.use_pass_z, shot_layer.use_pass_normal],
    "elsewhere_passes": [elsewhere.view_layers[0].use_pass_z,
                         elsewhere.view_layers[0].use_pass_normal]}),
      flush=True)
render(shot, "connected")

# Shot's node with a guard band: its hidden guard scene has a camera of the
# add-on's own, which a helper must not borrow (it outlived the band)
hbao.guard_band = 10.0
hbao_package.sync()
# an artist's object with the stand-in's name: not taken for it (a review
# found one more camera made at every sync)
artists = bpy.data.objects.new(".HBAO stand-in camera", bpy.data.meshes.new("artist's"))
shot.collection.objects.link(artists)
plate = blender_scenes.Compositor(bpy.data.scenes.new("Plate"))
image = bpy.data.images.new("plate", *SIZE)
image.generated_color = (0.5, 0.25, 0.125, 1.0)
picture = plate.node("CompositorNodeImage", (-300, 0))
picture.image = image
# Depth from the Image node (a saved render, which the node refuses: the
# CLI computes its AO), and from it through a muted link (AO off, as
# unlinked, but said so)
hbao = plate.node("CompositorNodeHBAO", (300, 0))
plate.link(picture.outputs["Image"], hbao.inputs["Image"])
plate.link(picture.outputs["Image"], hbao.inputs["Depth"])
muted = plate.node("CompositorNodeHBAO", (600, 0))
plate.link(hbao.outputs["Image"], muted.inputs["Image"])
plate.link(picture.outputs["Image"], muted.inputs["Depth"]).is_muted = True
plate.composite(muted.outputs["Image"])
render(plate.scene, "image_only")
helper = next(s for s in bpy.data.scenes if s.get("hbao_main_scene") == "Plate")
for _sync in range(3):
    hbao_package.sync()
print("PLATE HELPER CAMERA", helper.camera.name, helper.camera.type, flush=True)
# the HBAO nodes gone: the helper goes, and the camera made for it with it
for node in [n for n in plate.tree.nodes if n.bl_idname == "CompositorNodeHBAO"]:
    plate.tree.nodes.remove(node)
hbao_package.sync()
print("STAND-IN LEFT", json.dumps([item.name for item in list(bpy.data.objects)
                                   + list(bpy.data.cameras)
                                   if item.name.startswith(".HBAO stand-in")]), flush=True)
print("COMPOSITING DONE", flush=True)
