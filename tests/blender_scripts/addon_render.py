# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: builds a test scene with HBAO
nodes as a JSON spec says, renders frames, and writes per frame

  <out>/frame_<NNNN>.exr  the main render (multilayer: every pass + Composite)
  <out>/nodes_<NNNN>.exr  a File Output of each node's Image and AO, the
                          render's Image and, when asked, Cycles' AO pass

both uncompressed 32-bit float. Usage:

  blender -b --addons hbao --python addon_render.py -- '<json spec>' <out dir>

Spec keys (all optional): resolution [w, h], samples, engine, scene (a name of
blender_scenes.SCENE_BUILDERS: "corner", "two_layers", "low_poly", "demo"),
frames [..], ao_reference (distance: adds Cycles' AO pass), stereo (true: Stereo 3D; "one_view":
with its right view off; "custom_view": Multi-View with a view "center" besides left and right,
each through its own camera Camera_L, Camera_C, Camera_R; writes camera_<NNNN><view's file
suffix>.json too), stereo_settings {convergence_mode, pivot, interocular_distance, ...: the
camera's Stereoscopy settings; no view camera written then}, stereo_off_from_frame (Stereoscopy
turned off from that frame on), output_views_format (the main output's views format), orthographic,
clip_end (the camera's), scene_scale (every object's place and size and the camera's clip range
times it), camera_tilt (radians the camera turns up), camera_scale [x, y, z] (the
camera object's scale), camera_rig [x, y, z] (the camera parented to an empty of that scale, where
it was), widen_camera (factor), dump_back_faces (writes <out>/back_<NNNN>.npy: the back faces
render's Depth, top row first), border [min_x, max_x, min_y, max_y] (a border render cropped to it;
with crop false, not cropped), percentage (the resolution percentage), subframe (each frame
rendered at that subframe), motion_blur ("START", "CENTER" or "END": camera motion blur, shutter 1
frame; the camera written is the one at the shutter's middle, and camera_at_frame_<NNNN>.json the
one at the whole frame), position_pass (Cycles' Position pass on), animate_camera (the camera turns
and moves over frames 1-5), time_remap [old, new] (Time Remapping), sequencer ("override": a scene
"Edit" shows the scene in a Video Sequencer strip through a camera override, "Strip Camera"; and in
a second strip through the scene's camera, "two_cameras": at the same frames, "other_frame":
showing its frame 11 at frame 1, "muted_meta": inside a muted meta strip; "nested": Edit shown by a
strip of scene "Outer" whose input is Edit's sequencer; "covered": Shot replaces a strip of the
scene below it; each frame renders Edit (Outer) first, keeping the nodes' file as
strip_nodes_<NNNN>.exr, then the scene through Strip Camera; "failed_movie": an animation render of
Edit to a movie that cannot be written, then the scene's frames through its own camera),
save_blend_after (path: the file saved after the renders), save_blend (path: saved after the setup,
before rendering), nodes: [{name, layer, normal (bool), radius, keyframes [[frame, radius], ..],
property_keyframes [[frame, {property: value}], ..], radius_driver (a driver's expression),
keys_in_nla (the keyframes pushed down into an NLA strip; "off": the NLA then turned off),
radius_from_value_node, falloff, integration, blur_size, angle_bias, directions, steps, strength,
thickness, guard_band, back_faces, mute, connect_with_operator (left unlinked, then linked by the
node's Connect Passes operator after the passes are disabled)}], disable_normal_pass,
disable_depth_pass, output_format (the main output's file format, default OPEN_EXR_MULTILAYER),
prepare [actions before rendering: sync, compositing_off, delete_helper, delete_extra_renders,
show_the_helper (the window's scene: a file saved so renders it from the command line),
rename_helper, pick_internal_engine, render_the_helper, rename_node, second_scene_shares_the_tree,
group_last_node (the last HBAO node moved into a node group of the artist's), layer_not_rendered,
mute_render_layers, switch_to_workbench; 5.3's compositor effects: second_effect (a pass-through
effect added after the HBAO one, and so active), second_effect_with_a_node (one holding an HBAO
node), hbao_nodes_leave_the_first_effect (its HBAO nodes removed: the hook serves the second
effect, and prints HOOKS {group: [its managed node]}), same_group_twice (a second effect with the
HBAO effect's group), wrap_compositing_group (the scene's group used through a Group node of a new
group, the effect's now), effect_off_for_render; add_on_scenes_on_gpu (every scene's
compositor_device GPU)],
render_threads ({frame: the Performance panel's threads, 0 for Auto}), layer_name (the first view
layer's), scene_name, single_layer (Render Single Layer on), tile_size (Cycles renders in tiles
of that many pixels), grease_pencil (a stroke object before the camera; "instanced": in a collection
shown through an instance; "geometry_nodes": a stroke made by a Curves to Grease Pencil node;
4.5+), python_engine (rendered by raycast_engine.py, a third-party engine's stand-in),
user_handlers (a pipeline's own render and frame change handlers, which print USER HANDLERS {json}:
the scenes each list's handler saw, in order; render_stats leaves out repeats of the scene before).
Prints OUTPUT SETTINGS {json} (the main output's settings after the renders), STATUS {json} (each
node's status line) and RENDERED.
"""
import json
import math
import os
import sys
import threading

import bpy
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:]
spec = json.loads(argv[0])
out_dir = argv[1]
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402
import scene_parts  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from writes_refused import while_writes_refused  # noqa: E402

os.makedirs(out_dir, exist_ok=True)
resolution = tuple(spec.get("resolution", (96, 64)))
samples = spec.get("samples", 4)
engine = spec.get("engine", "CYCLES")
scene = bpy.context.scene
blender_scenes.SCENE_BUILDERS[spec.get("scene", "corner")](scene, resolution, engine, samples)
if spec.get("box_past_frame"):  # a box on the floor just past the frame's right side
    frame = scene.camera.data.view_frame(scene=scene)
    per_unit = max(corner.x for corner in frame) / -frame[0].z  # half the width per unit away
    away = scene["hbao_target_distance"]
    centre = scene.camera.matrix_world @ Vector((1.15 * per_unit * away, 0.0, -away))
    scene_parts.box("Past the frame", (centre.x, centre.y, 0.6), (0.3, 0.3, 1.2),
                    scene.collection)
if spec.get("ao_reference"):
    blender_scenes.configure_ao_reference(scene, spec["ao_reference"])
if spec.get("orthographic"):
    blender_scenes.make_orthographic(scene)
if spec.get("clip_end"):  # the camera's Clip End
    scene.camera.data.clip_end = spec["clip_end"]
if spec.get("scene_scale"):  # every length of the scene times it (not the lights')
    for obj in scene.objects:
        if obj.type != "LIGHT":
            obj.location = obj.location * spec["scene_scale"]
            if obj.type != "CAMERA":
                obj.scale = obj.scale * spec["scene_scale"]
    scene.camera.data.clip_start *= spec["scene_scale"]
    scene.camera.data.clip_end *= spec["scene_scale"]
if spec.get("camera_tilt"):  # the camera turned up (radians about its x axis)
    scene.camera.rotation_euler.x += spec["camera_tilt"]
if spec.get("camera_rig"):  # the camera inside an empty of this scale, where it was
    rig = bpy.data.objects.new("Rig", None)
    scene.collection.objects.link(rig)
    rig.scale = spec["camera_rig"]
    scene.camera.parent = rig  # its rotation kept: sheared unless the scale is even
    scene.camera.location = [a / b for a, b in zip(scene.camera.location, rig.scale)]
if spec.get("camera_scale"):  # the camera object scaled (Blender renders as unscaled)
    scene.camera.scale = spec["camera_scale"]
if spec.get("widen_camera"):  # a view `widen_camera` times as wide about its centre
    lens = scene.camera.data
    for name in ("sensor_width", "sensor_height", "ortho_scale"):
        setattr(lens, name, getattr(lens, name) * spec["widen_camera"])
    lens.shift_x /= spec["widen_camera"]
    lens.shift_y /= spec["widen_camera"]
if spec.get("stereo"):  # Stereoscopy on: a left and a right view, each written on its own
    scene.render.use_multiview = True
    scene.render.views_format = "STEREO_3D"
    if spec["stereo"] == "one_view":  # Stereo 3D with the right view switched off
        scene.render.views["right"].use = False
    if spec["stereo"] == "custom_view":  # Multi-View, with a view "center" besides
        scene.render.views_format = "MULTIVIEW"
        scene.render.views.new("center").camera_suffix = "_C"
        # each view's own camera: Camera_C the scene's, Camera_L and Camera_R beside it
        scene.camera.name = "Camera_C"
        for suffix, step in (("_L", -0.3), ("_R", 0.25)):
            eye = scene.camera.copy()
            eye.name = "Camera" + suffix
            eye.location.x += step
            eye.rotation_euler.z += step * 0.2
            scene.collection.objects.link(eye)
for key, value in spec.get("stereo_settings", {}).items():  # the camera's Stereoscopy panel
    setattr(scene.camera.data.stereo, key, value)
if spec.get("position_pass"):  # Cycles' Position pass: where each pixel's surface is
    for view_layer in scene.view_layers:
        view_layer.use_pass_position = True
if spec.get("grease_pencil") == "geometry_nodes":  # strokes made by geometry nodes (4.5+)
    maker = bpy.data.objects.new("Stroke maker", bpy.data.meshes.new("Stroke maker"))
    maker.matrix_world = scene.camera.matrix_world
    scene.collection.objects.link(maker)
    group = bpy.data.node_groups.new("Strokes", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    line = group.nodes.new("GeometryNodeCurvePrimitiveLine")
    line.inputs["Start"].default_value = (-1.0, -0.5, -2.0)  # 2 units before the camera
    line.inputs["End"].default_value = (1.0, 0.5, -2.0)
    radius = group.nodes.new("GeometryNodeSetCurveRadius")
    radius.inputs["Radius"].default_value = 0.1
    strokes = group.nodes.new("GeometryNodeCurvesToGreasePencil")
    strokes.inputs["Instances as Layers"].default_value = False  # (on, plain curves make none)
    output = group.nodes.new("NodeGroupOutput")
    group.links.new(line.outputs[0], radius.inputs["Curve"])
    group.links.new(radius.outputs[0], strokes.inputs[0])
    group.links.new(strokes.outputs[0], output.inputs[0])
    maker.modifiers.new("Strokes", "NODES").node_group = group
    print("STROKE INSTANCES", sum(instance.object.type == "GREASEPENCIL" for instance
                                  in bpy.context.evaluated_depsgraph_get().object_instances))
elif spec.get("grease_pencil"):  # a Grease Pencil stroke 2 units before the camera (4.5+)
    from mathutils import Vector
    bpy.ops.object.grease_pencil_add(type="STROKE",
                                     location=scene.camera.matrix_world @ Vector((0, 0, -2)))
    if spec["grease_pencil"] == "instanced":  # shown only through a collection instance
        stroke = bpy.context.active_object
        asset = bpy.data.collections.new("Stroke asset")
        for collection in list(stroke.users_collection):
            collection.objects.unlink(stroke)
        asset.objects.link(stroke)
        instance = bpy.data.objects.new("Stroke instance", None)
        instance.instance_type, instance.instance_collection = "COLLECTION", asset
        scene.collection.objects.link(instance)
if spec.get("python_engine"):  # rendered by raycast_engine.py, an engine written in Python
    import raycast_engine
    raycast_engine.register()
    scene.render.engine = raycast_engine.IDNAME
if spec.get("tile_size"):
    scene.cycles.use_auto_tile = True
    scene.cycles.tile_size = spec["tile_size"]
if spec.get("motion_blur"):  # camera motion blur, this shutter Position, 1 frame long
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 1.0
    if hasattr(scene.render, "motion_blur_position"):  # 4.2+
        scene.render.motion_blur_position = spec["motion_blur"]
    else:
        scene.cycles.motion_blur_position = spec["motion_blur"]
    if bpy.app.version < (4, 2, 0):  # 3.4's EEVEE keeps its own
        scene.eevee.use_motion_blur = True
        scene.eevee.motion_blur_shutter = 1.0
        scene.eevee.motion_blur_position = spec["motion_blur"]
if spec.get("percentage"):  # the render's resolution percentage
    scene.render.resolution_percentage = spec["percentage"]
if spec.get("border"):
    render_settings = scene.render
    (render_settings.border_min_x, render_settings.border_max_x,
     render_settings.border_min_y, render_settings.border_max_y) = spec["border"]
    render_settings.use_border = True
    render_settings.use_crop_to_border = spec.get("crop", True)
if spec.get("animate_camera"):  # the camera turns and moves from frame 1 to frame 5
    moving = scene.camera
    moving.keyframe_insert("rotation_euler", frame=1)
    moving.keyframe_insert("location", frame=1)
    moving.rotation_euler.z += 0.3
    moving.location.x += 0.8
    moving.keyframe_insert("rotation_euler", frame=5)
    moving.keyframe_insert("location", frame=5)
if spec.get("time_remap"):  # Time Remapping [old, new]: frame f shows the time f * old / new
    scene.render.frame_map_old, scene.render.frame_map_new = spec["time_remap"]
edit = None  # sequencer: the scene that shows `scene` in Video Sequencer strips
if spec.get("sequencer"):
    strip_camera = scene.camera.copy()
    strip_camera.data = scene.camera.data.copy()
    strip_camera.name = "Strip Camera"
    scene.collection.objects.link(strip_camera)
    strip_camera.location.x -= 0.6
    strip_camera.rotation_euler.z -= 0.2
    strip_camera.data.lens *= 0.8
    edit = bpy.data.scenes.new("Edit")
    edit.render.resolution_x, edit.render.resolution_y = resolution
    editor = edit.sequence_editor_create()
    strips = editor.strips if hasattr(editor, "strips") else editor.sequences
    shot = strips.new_scene("Shot", scene, channel=1, frame_start=1)
    shot.scene_camera = strip_camera
    # a second strip of the scene, through the scene's camera: at the same frames, ...
    if spec["sequencer"] == "two_cameras":
        strips.new_scene("Shot again", scene, channel=2, frame_start=1)
    elif spec["sequencer"] == "other_frame":  # ... showing its frame 11 at frame 1, ...
        strips.new_scene("Shot later", scene, channel=2, frame_start=-9)
    elif spec["sequencer"] == "muted_meta":  # ... or inside a muted meta strip
        muted = strips.new_scene("Shot muted", scene, channel=3, frame_start=1)
        meta = strips.new_meta("Muted", channel=2, frame_start=1)
        muted.move_to_meta(meta)
        meta.mute = True
    elif spec["sequencer"] == "covered":  # ... under Shot, which replaces what lies below
        shot.channel = 2
        shot.blend_type = "REPLACE"
        strips.new_scene("Shot below", scene, channel=1, frame_start=1)
    elif spec["sequencer"] == "failed_movie":  # Edit's animation cannot write its movie
        movie = edit.render.image_settings
        if hasattr(movie, "media_type"):
            movie.media_type = "VIDEO"
        movie.file_format = "FFMPEG"
        edit.render.filepath = "/dev/null/hbao-test/movie_"
        try:
            print("MOVIE", bpy.ops.render.render(animation=True, scene=edit.name), flush=True)
        except RuntimeError as error:
            print("MOVIE FAILED", error, flush=True)
        edit = None  # then the scene renders through its own camera
    elif spec["sequencer"] == "nested":  # Edit shown by another sequencer, "Outer"
        outer = bpy.data.scenes.new("Outer")
        outer.render.resolution_x, outer.render.resolution_y = resolution
        outer_editor = outer.sequence_editor_create()
        outer_strips = outer_editor.strips if hasattr(outer_editor, "strips") \
            else outer_editor.sequences
        outer_strips.new_scene("Edit", edit, channel=1, frame_start=1).scene_input = "SEQUENCER"
        edit = outer  # rendered instead

if spec.get("layer_name"):  # the first view layer renamed
    scene.view_layers[0].name = spec["layer_name"]
if spec.get("scene_name"):
    scene.name = spec["scene_name"]
if spec.get("single_layer"):  # Render Single Layer (View Layer properties)
    scene.render.use_single_layer = True

compositor = blender_scenes.Compositor(scene)
tree = compositor.tree
render_layers = {}
for index, view_layer in enumerate(scene.view_layers):
    render_layers[view_layer.name] = compositor.render_layers(view_layer.name,
                                                              (-400, -400 * index))
file_output = compositor.file_output(out_dir, "nodes_")

first_layer = scene.view_layers[0].name
file_output.add("Render", render_layers[first_layer].outputs["Image"])
if spec.get("ao_reference"):
    file_output.add("CyclesAO",
                    blender_scenes.compat_nodes.pass_output(render_layers[first_layer], "AO"))

connect_with_operator = []
for index, node_spec in enumerate(spec.get("nodes", [{}])):
    hbao = compositor.node("CompositorNodeHBAO", (300, -400 * index))
    hbao.name = node_spec.get("name", f"HBAO{index}")
    source = render_layers[node_spec.get("layer", first_layer)]
    if node_spec.get("connect_with_operator"):  # the node's Connect Passes button
        connect_with_operator.append(hbao.name)
    else:
        compositor.link(source.outputs["Image"], hbao.inputs["Image"])
        compositor.link(source.outputs["Depth"], hbao.inputs["Depth"])
    if node_spec.get("normal", True) and not node_spec.get("connect_with_operator"):
        compositor.link(source.outputs["Normal"], hbao.inputs["Normal"])
    for key, socket_name in (("radius", "Radius"), ("angle_bias", "Angle Bias"),
                             ("directions", "Directions"), ("steps", "Steps"),
                             ("blur_size", "Blur Size"), ("strength", "Strength"),
                             ("thickness", "Thickness")):
        if key in node_spec:
            hbao.inputs[socket_name].default_value = node_spec[key]
    for key in ("falloff", "integration", "half_resolution", "guard_band", "back_faces"):
        if key in node_spec:
            setattr(hbao, key, node_spec[key])
    if node_spec.get("radius_from_value_node") is not None:
        value = compositor.value(node_spec["radius_from_value_node"])
        compositor.link(value.outputs[0], hbao.inputs["Radius"])
    for frame, radius in node_spec.get("keyframes", []):
        hbao.inputs["Radius"].default_value = radius
        hbao.inputs["Radius"].keyframe_insert("default_value", frame=frame)
    for frame, values in node_spec.get("property_keyframes", []):
        for key, value in values.items():
            setattr(hbao, key, value)
            hbao.keyframe_insert(key, frame=frame)
    if node_spec.get("keys_in_nla"):  # the tree's action pushed down into an NLA strip
        animation = hbao.id_data.animation_data
        animation.nla_tracks.new().strips.new("Keys", 1, animation.action)
        animation.action = None
        animation.use_nla = node_spec["keys_in_nla"] != "off"  # (Blender then ignores them)
    if node_spec.get("radius_driver"):
        driver = hbao.inputs["Radius"].driver_add("default_value").driver
        driver.expression = node_spec["radius_driver"]
    hbao.mute = node_spec.get("mute", False)
    if index == 0:
        compositor.composite(hbao.outputs["Image"])
    file_output.add(f"{hbao.name}_Image", hbao.outputs["Image"])
    file_output.add(f"{hbao.name}_AO", hbao.outputs["AO"])

# Passes switched off after linking: the add-on must turn them back on.
for view_layer in scene.view_layers:
    if spec.get("disable_normal_pass"):
        view_layer.use_pass_normal = False
    if spec.get("disable_depth_pass"):
        view_layer.use_pass_z = False
for name in connect_with_operator:
    print("CONNECT", name, bpy.ops.hbao.connect_passes(node_name=name), flush=True)

# The main output: what the tests read back, or (output_format) an artist's
# own choice, which the add-on must leave as it found it.
output_format = spec.get("output_format", "OPEN_EXR_MULTILAYER")
blender_scenes.compat.set_image_format(scene.render.image_settings, output_format)
if output_format.startswith("OPEN_EXR"):
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "NONE"
scene.render.use_file_extension = True
if spec.get("output_views_format"):  # a stereo output's layout (STEREO_3D: side by side, ...)
    scene.render.image_settings.views_format = spec["output_views_format"]


def helper_scenes():
    return [s for s in bpy.data.scenes if s.name.startswith(".HBAO") or s.get("hbao_main_scene")]


# Faults and edits an artist may make before rendering (tests/test_faults.py).
render_scene_name = None  # another scene to render than `scene`
for action in spec.get("prepare", []):
    if action == "sync":  # what the UI does on its own after an edit
        import hbao
        hbao.sync(scene)
    elif action == "delete_helper":
        for helper in helper_scenes():
            bpy.data.scenes.remove(helper)
    elif action == "delete_extra_renders":  # the guard band's and back faces' scenes
        for extra in [s for s in bpy.data.scenes if s.get("hbao_guard_for")]:
            bpy.data.scenes.remove(extra)
    elif action == "rename_helper":
        for helper in helper_scenes():
            helper.name = "Renamed by the artist"
    elif action == "rename_node":
        for node in tree.nodes:
            if node.bl_idname == "CompositorNodeHBAO":
                node.name = node.label = "Renamed " + node.name
    elif action == "render_the_helper":  # the helper made the active scene, then F12
        import hbao
        hbao.sync(scene)
        render_scene_name = helper_scenes()[0].name
    elif action == "show_the_helper":  # the window on the helper (a scene was deleted)
        import hbao
        hbao.sync(scene)
        bpy.context.window_manager.windows[0].scene = helper_scenes()[0]
    elif action == "pick_internal_engine":  # from the Render Engine menu
        import hbao.helper_lookup
        scene.render.engine = hbao.helper_lookup.ENGINE_IDNAME
    elif action == "group_last_node":  # an artist's node group around the last HBAO node
        import hbao.node
        import hbao.node_place
        compat = blender_scenes.compat
        last = [n for n in tree.nodes if n.bl_idname == "CompositorNodeHBAO"][-1]
        group = bpy.data.node_groups.new("Artist Group", "CompositorNodeTree")
        inside = group.nodes.new("CompositorNodeHBAO")
        inside.name = last.name
        for key in ("falloff", "integration", "half_resolution"):
            setattr(inside, key, getattr(last, key))
        group_in = group.nodes.new("NodeGroupInput")
        group_out = group.nodes.new("NodeGroupOutput")
        holder = tree.nodes.new("CompositorNodeGroup")
        holder.node_tree = group
        for name in ("Image", "Depth", "Normal"):
            compat.new_group_socket(group, "INPUT", "NodeSocketColor"
                                    if name == "Image" else "NodeSocketFloat"
                                    if name == "Depth" else "NodeSocketVector", name)
            group.links.new(group_in.outputs[name], inside.inputs[name])
            for link in list(last.inputs[name].links):
                tree.links.new(link.from_socket, holder.inputs[name])
        for name in ("Image", "AO"):
            compat.new_group_socket(group, "OUTPUT", "NodeSocketColor"
                                    if name == "Image" else "NodeSocketFloat", name)
            group.links.new(inside.outputs[name], group_out.inputs[name])
            for link in list(last.outputs[name].links):
                tree.links.new(holder.outputs[name], link.to_socket)
        tree.nodes.remove(last)
        print("GROUPED", json.dumps({n.name: hbao.node_place.at_top_level(n) for n in
                                     [inside] + hbao.node.hbao_nodes(tree)}), flush=True)
    elif action == "compositing_off":  # Output properties > Post Processing > Compositing
        scene.render.use_compositing = False
    elif action == "switch_to_workbench":  # the render engine changed after linking
        scene.render.engine = "BLENDER_WORKBENCH"
    elif action == "layer_not_rendered":  # the last view layer's Use for Rendering off
        scene.view_layers[-1].use = False
    elif action == "holdout_collection":  # View Layer > the Props collection's Holdout
        scene.view_layers[0].layer_collection.children["Props"].holdout = True
    elif action == "indirect_only_collection":  # ... its Indirect Only (Cycles)
        scene.view_layers[0].layer_collection.children["Props"].indirect_only = True
    elif action in ("holdout_objects", "objects_unseen_by_camera", "holdout_shader"):
        for obj in bpy.data.collections["Props"].all_objects:
            if action == "holdout_objects":  # Object > Visibility > Holdout
                obj.is_holdout = True
            elif action == "objects_unseen_by_camera":  # ... > Ray Visibility > Camera off
                obj.visible_camera = False
            else:  # a material whose surface is a Holdout shader
                material = bpy.data.materials.new("Held out")
                blender_scenes.compat.ensure_material_nodes(material)
                nodes = material.node_tree.nodes
                output = next(n for n in nodes if n.bl_idname == "ShaderNodeOutputMaterial")
                material.node_tree.links.new(nodes.new("ShaderNodeHoldout").outputs[0],
                                             output.inputs["Surface"])
                obj.material_slots[0].material = material
    elif action == "mute_render_layers":
        for source in render_layers.values():
            source.mute = True
    elif action in ("second_effect", "second_effect_with_a_node"):
        # 5.3: Add Effect after the HBAO one, which makes the new one active:
        # its group passes the image through, or holds an HBAO node of its own
        compat = blender_scenes.compat
        group = bpy.data.node_groups.new("Second Effect", "CompositorNodeTree")
        compat.new_group_socket(group, "INPUT", "NodeSocketColor", "Image")
        compat.new_group_socket(group, "OUTPUT", "NodeSocketColor", "Image")
        group_in, group_out = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
        image = group_in.outputs["Image"]
        if action == "second_effect_with_a_node":
            inside = group.nodes.new("CompositorNodeHBAO")
            inside.name = "HBAO in the second effect"
            group.links.new(image, inside.inputs["Image"])
            image = inside.outputs["Image"]
        group.links.new(image, group_out.inputs["Image"])
        scene.compositor_effects.new(name="Second").node_group = group
        print("EFFECTS", json.dumps([[e.name, e.is_active] for e in scene.compositor_effects]),
              flush=True)
    elif action == "hbao_nodes_leave_the_first_effect":  # 5.3, after second_effect_with_a_node
        import hbao
        import hbao.helper_lookup
        for node in [n for n in tree.nodes if n.bl_idname == "CompositorNodeHBAO"]:
            tree.nodes.remove(node)
        hbao.sync(scene)  # the hook serves the second effect's group now
        print("HOOKS", json.dumps({e.node_group.name: [
            n.name for n in e.node_group.nodes if n == hbao.helper_lookup.managed_node(
                e.node_group)] for e in scene.compositor_effects}), flush=True)
    elif action == "same_group_twice":  # 5.3: a second effect with the scene's own group
        scene.compositor_effects.new(name="Again").node_group = tree
    elif action == "wrap_compositing_group":  # 5.3: the scene's group used through a Group node
        wrapper = bpy.data.node_groups.new("Wrapper", "CompositorNodeTree")
        blender_scenes.compat.new_group_socket(wrapper, "OUTPUT", "NodeSocketColor", "Image")
        holder = wrapper.nodes.new("CompositorNodeGroup")
        holder.node_tree = tree
        wrapper.links.new(holder.outputs["Image"], wrapper.nodes.new("NodeGroupOutput").inputs[0])
        scene.compositor_effects[0].node_group = wrapper
    elif action == "effect_off_for_render":  # 5.3: the HBAO effect's Enable for Render off
        scene.compositor_effects[0].enable_for_render = False
    elif action == "add_on_scenes_on_gpu":  # a script that sets every scene's compositor device
        for each in bpy.data.scenes:
            each.render.compositor_device = "GPU"
    elif action == "second_scene_shares_the_tree":  # 5.0+: one node group, two scenes
        other = scene.copy()
        other.name = "Second"
        sys.modules["hbao.compositor_effects"].set_served_group(other, tree)
    else:
        raise ValueError(f"unknown prepare action {action!r}")
    print("PREPARED", action, flush=True)

# A pipeline's own handlers (user_handlers): persistent, so that they
# outlive a "reopen" step.
USER_HANDLER_LISTS = ("render_init", "render_pre", "render_stats", "render_post", "render_write",
                      "render_complete", "render_cancel", "frame_change_pre", "frame_change_post")
seen_by_user_handlers = {name: [] for name in USER_HANDLER_LISTS}


def user_handler(list_name):
    @bpy.app.handlers.persistent
    def handler(scene, *_args):
        seen = seen_by_user_handlers[list_name]
        if list_name != "render_stats" or not seen or seen[-1] != scene.name:
            seen.append(scene.name)
    return handler


# The guard band's and back faces' scenes each render renders: Blender sets
# each scene it renders to the frame (frame_change_pre), these too.
extra_rendered = []


@bpy.app.handlers.persistent
def note_extra_render(scene, *_args):
    if scene.get("hbao_guard_for"):
        extra_rendered.append(scene.name)


def print_extra_renders(render_name):
    print("EXTRA RENDERS", json.dumps({"render": render_name, "scenes": extra_rendered}),
          flush=True)
    extra_rendered.clear()


bpy.app.handlers.frame_change_pre.append(note_extra_render)

if spec.get("user_handlers"):
    for list_name in USER_HANDLER_LISTS:
        if hasattr(bpy.app.handlers, list_name):
            getattr(bpy.app.handlers, list_name).append(user_handler(list_name))

if spec.get("save_blend"):
    bpy.ops.wm.save_as_mainfile(filepath=spec["save_blend"])
    print("SAVED", spec["save_blend"])
    sys.exit(0)


for frame in spec.get("frames", [1]):
    if edit is not None:  # the sequencer's render first, its nodes_ file kept as strip_nodes_
        edit.frame_set(frame)
        edit.render.filepath = os.path.join(out_dir, f"edit_{frame:04d}")
        bpy.ops.render.render(write_still=True, scene=edit.name)
        print_extra_renders(f"sequencer {frame}")
        os.replace(os.path.join(out_dir, f"nodes_{frame:04d}.exr"),
                   os.path.join(out_dir, f"strip_nodes_{frame:04d}.exr"))
        scene.camera = strip_camera  # then the scene itself through the strip's camera
    if spec.get("stereo_off_from_frame", frame + 1) <= frame:
        scene.render.use_multiview = False
    # The camera written is the one at the time the passes show: the
    # subframe rendered, or the middle of a motion blur shutter of 1 frame.
    shutter_middle = {"START": 0.5, "END": -0.5}.get(spec.get("motion_blur"), 0.0)
    camera_time = frame + spec.get("subframe", 0.0) + shutter_middle
    scene.frame_set(math.floor(camera_time), subframe=camera_time - math.floor(camera_time))
    try:
        description = blender_scenes.camera_description(scene)
    except ValueError as error:  # a camera the add-on cannot model (it says why)
        description = {"error": str(error)}
    scene.frame_set(frame, subframe=spec.get("subframe", 0.0))  # the time rendered
    with open(os.path.join(out_dir, f"camera_{frame:04d}.json"), "w") as stream:
        json.dump(description, stream)
    if camera_time != frame:  # and the camera at the whole frame, for comparison
        scene.frame_set(frame)
        with open(os.path.join(out_dir, f"camera_at_frame_{frame:04d}.json"), "w") as stream:
            json.dump(blender_scenes.camera_description(scene), stream)
        scene.frame_set(frame, subframe=spec.get("subframe", 0.0))
    if spec.get("stereo") and not spec.get("stereo_settings"):  # (the reference's cases)
        for suffix, description in blender_scenes.view_camera_descriptions(scene).items():
            with open(os.path.join(out_dir, f"camera_{frame:04d}{suffix}.json"), "w") as stream:
                json.dump(description, stream)
    threads = spec.get("render_threads", {}).get(str(frame))
    if threads is not None:  # the Performance panel's threads: 0 Auto, else Fixed
        scene.render.threads_mode = "FIXED" if threads else "AUTO"
        scene.render.threads = max(threads, 1)
    # Still renders do not replace '#' in the path: name the frame here.
    scene.render.filepath = os.path.join(out_dir, f"frame_{frame:04d}")
    if render_scene_name is None:
        bpy.ops.render.render(write_still=True)
    else:
        bpy.data.scenes[render_scene_name].render.filepath = scene.render.filepath
        bpy.ops.render.render(write_still=True, scene=render_scene_name)
    print_extra_renders(f"frame {frame}")
    if spec.get("dump_back_faces"):  # the back faces render's Depth, as the engine read it
        import numpy as np
        from hbao import extra_renders, handover
        helper = next(s for s in bpy.data.scenes if s.get("hbao_main_scene"))
        back = extra_renders.scene_of(helper, extra_renders.BACK)
        layer = back.view_layers[0].name
        channels, _timings = handover.read_passes(back, {layer: False})
        np.save(os.path.join(out_dir, f"back_{frame:04d}.npy"), channels[("depth", layer)])


# After the renders: change the first node step by step and print what its
# "changed since the last render" line says after each step. A step with
# "refused" runs its "refresh", "poll", "apply", "composite_again",
# "sync_tick", "sync_all" and "writes_allowed" where Blender refuses writes.
hinted = next((n for n in tree.nodes if n.bl_idname == "CompositorNodeHBAO"), None)
for step in spec.get("after_render", []):
    from hbao import node_status, recomposite, render_record, report

    def timer_action(action, refused=step.get("refused", False)):
        return while_writes_refused(action) if refused else action()
    for key, value in step.items():
        if key == "socket":
            hinted.inputs[value[0]].default_value = value[1]
        elif key == "frame":
            scene.frame_set(value)
        elif key == "refresh":  # what the add-on's timer does in a window
            print("REFRESHED", timer_action(
                lambda: recomposite.refresh_changed(in_background=True)), flush=True)
        elif key == "post_message":  # as the render thread posts them
            report.post_node_messages(scene.name, [hinted.name],
                                      [report.NodeMessage(hinted.name, value, value)])
        elif key == "poll":  # a tick of the add-on's node timer
            timer_action(node_status._poll_node_messages)
        elif key == "apply":  # what the node timer's tick calls once allowed
            timer_action(node_status.apply_node_messages)
        elif key == "composite_again":  # a refresh's last step
            from hbao import composite_trigger
            timer_action(lambda: composite_trigger.composite_again(scene))
        elif key == "writes_allowed":
            from hbao import writes
            print("WRITES ALLOWED", timer_action(writes.writes_allowed), flush=True)
        elif key == "delete_helper":
            for helper in helper_scenes():
                bpy.data.scenes.remove(helper)
        elif key in ("sync_tick", "sync_all"):  # the sync timer; the sync it runs
            from hbao import handlers, helper_scene
            job = handlers._timer_sync if key == "sync_tick" else helper_scene.sync_all
            returned = timer_action(job)
            if key == "sync_tick" and returned == handlers._REFUSED_RETRY_S:
                returned = "again"
            print("SYNC", json.dumps({"label": step["label"], "returned": returned,
                                      "helpers": sorted(s.name for s in helper_scenes())}),
                  flush=True)
        elif key == "resolution_percentage":
            scene.render.resolution_percentage = value
            import hbao
            hbao.sync(scene)  # as the add-on's timer does in a window: the helper follows
        elif key == "reopen":  # the file saved and opened again
            path = os.path.join(out_dir, "reopened.blend")
            bpy.ops.wm.save_as_mainfile(filepath=path)
            bpy.ops.wm.open_mainfile(filepath=path)
            scene = bpy.context.scene
            tree = blender_scenes.compat.compositor_tree(scene)
            hinted = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeHBAO")
        elif key == "unlink":
            tree.links.remove(hinted.inputs[value].links[0])
        elif key == "render_during_refresh":
            # Every node's radius set to `value`, then a render while the
            # refresh's worker computes the first node's AO.
            from hbao import helper_scene
            for each in tree.nodes:
                if each.bl_idname == "CompositorNodeHBAO":
                    each.inputs["Radius"].default_value = value
            started, release = threading.Event(), threading.Event()
            compute = recomposite.layer_passes.compute

            def first_job_held(*args, **kwargs):
                if not started.is_set():  # the worker's first job waits for the render
                    started.set()
                    release.wait(60)
                return compute(*args, **kwargs)
            recomposite.layer_passes.compute = first_job_held
            try:
                # What the timer's first tick does in a window: start the worker.
                helper = helper_scene.helper_scene_of(scene)
                due = sys.modules["hbao.refresh_due"].due_for(scene, helper)
                assert not recomposite._refresh(scene, helper, due, False)
                computation = recomposite._computing[scene.name]
                assert started.wait(60), "the refresh's worker did not start"
                scene.render.filepath = os.path.join(out_dir, "frame_during_refresh")
                bpy.ops.render.render(write_still=True)
            finally:
                release.set()
                recomposite.layer_passes.compute = compute
            computation.thread.join()
            print("WORKER", json.dumps({"jobs": len(computation.due.changed),
                                        "computed": len(computation.results),
                                        "refreshed": recomposite.refresh_changed(
                                            in_background=True)}), flush=True)
        elif key == "render":  # the frame rendered again, as frame_<n>_again
            scene.render.filepath = os.path.join(out_dir, f"frame_{value:04d}_again")
            bpy.ops.render.render(write_still=True)
        elif key not in ("label", "refused"):
            setattr(hinted, key, value)
    from hbao import composite_trigger
    print("HINT", json.dumps({"label": step["label"], "status": hinted.status,
                              "hint": render_record.changed_since_render(hinted),
                              # scenes whose compositing waits for a tick
                              "composite_waiting": sorted(composite_trigger._refused)}))
for node in tree.nodes:  # what each node's status line says after the renders
    if node.bl_idname == "CompositorNodeHBAO":
        print("STATUS", json.dumps({"node": node.name, "status": node.status}))
# the guard band's and back faces' scenes that exist after the renders
print("EXTRA SCENES", json.dumps(sorted(s.name for s in bpy.data.scenes
                                        if s.get("hbao_guard_for"))))
settings = scene.render.image_settings
print("OUTPUT SETTINGS", json.dumps({
    "file_format": settings.file_format, "color_depth": settings.color_depth,
    "exr_codec": settings.exr_codec, "media_type": getattr(settings, "media_type", None),
    "use_exr_interleave": getattr(settings, "use_exr_interleave", None)}))
if spec.get("user_handlers"):
    print("USER HANDLERS", json.dumps(seen_by_user_handlers))
if spec.get("save_blend_after"):  # (for a script on the file: export_cameras.py)
    bpy.ops.wm.save_as_mainfile(filepath=spec["save_blend_after"])
print("RENDERED", json.dumps({"frames": spec.get("frames", [1])}))
