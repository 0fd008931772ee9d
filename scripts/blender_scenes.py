# SPDX-License-Identifier: GPL-2.0-or-later
"""Scenes built from scratch inside Blender, for renders, fixtures and demos.

Importable inside Blender only:

    sys.path.insert(0, scripts_dir)
    import blender_scenes
    scene = blender_scenes.build_demo_scene()

Every builder empties the scene it is given (objects, not other scenes), so the
repository holds no binary .blend file. Units are metres.
"""
import math
import sys
from pathlib import Path

import bpy
from mathutils import Matrix, Vector

try:
    import hbao  # noqa: F401  (the enabled add-on, or this checkout's below)
except ImportError:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "addon"))
from hbao import camera as camera_model  # noqa: E402
from hbao import compat, compat_nodes  # noqa: E402

import file_output  # noqa: E402  (beside this file: the File Output node's versions)
import scene_parts  # noqa: E402  (beside this file: the parts every scene is built from)

# Debian's Blender has no OpenImageDenoise; renders with denoising on fail.
# Small sample counts keep test renders at a few seconds on 2 CPU cores.
DEFAULT_SAMPLES = 16
DEFAULT_RESOLUTION = (640, 360)
DEFAULT_AO_DISTANCE = 1.0

# Names of the collections the builders create; view layers exclude them by name.
ROOM_COLLECTION = "Room"
PROPS_COLLECTION = "Props"

# Soft grey world: lights the scene a little from everywhere, so shadowed
# parts still show their colour and the AO pass has something to darken.
WORLD_COLOUR = (0.45, 0.5, 0.58, 1.0)
WORLD_STRENGTH = 0.35
# Filmic's "Medium High Contrast" look and a little less exposure keep the
# pale floor and wall from washing out the colours of the objects.
VIEW_LOOK = "Medium High Contrast"
VIEW_EXPOSURE = -0.3

ENGINES = ("CYCLES", "BLENDER_EEVEE")


# --- helpers ----------------------------------------------------------------

def _scene_or_current(scene):
    return scene if scene is not None else bpy.context.scene


def clear_scene(scene):
    """Removes every object of `scene` and its child collections."""
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for collection in list(scene.collection.children):
        scene.collection.children.unlink(collection)
        if collection.users == 0:
            bpy.data.collections.remove(collection)


def _collection(scene, name):
    collection = bpy.data.collections.new(name)
    scene.collection.children.link(collection)
    return collection


def _node_of_type(tree, idname):
    """The first node of type `idname`: by name, Blender's Translate New Data
    (a preference) would miss the default "Principled BSDF" and "Background"."""
    return next(node for node in tree.nodes if node.bl_idname == idname)


def _material(name, colour, roughness=0.6):
    material = bpy.data.materials.new(name)
    compat.ensure_material_nodes(material)
    bsdf = _node_of_type(material.node_tree, "ShaderNodeBsdfPrincipled")
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    material.diffuse_color = (*colour, 1.0)
    return material


def _add(operator, collection, material, name, **kwargs):
    """An object made by a bpy.ops primitive (spheres, a torus), moved into `collection`."""
    operator(**kwargs)
    obj = bpy.context.active_object
    obj.name = name
    return scene_parts.link(obj, collection, material)


def _smooth(obj):
    for polygon in obj.data.polygons:
        polygon.use_smooth = True


def _box(collection, material, name, size, location, rotation=(0.0, 0.0, 0.0)):
    """A box of `size` (x, y, z) metres whose centre is `location`."""
    return scene_parts.box(name, location, size, collection, material, rotation)


def _camera(scene, collection, location, target, lens=35.0, name="Camera"):
    return scene_parts.camera(scene, collection, location, target, lens=lens, name=name)


def _sun(collection, rotation_deg, strength=3.0, angle_deg=8.0):
    data = bpy.data.lights.new("Sun", type="SUN")
    data.energy = strength
    # A sun a few degrees wide gives soft-edged shadows.
    data.angle = math.radians(angle_deg)
    sun = bpy.data.objects.new("Sun", data)
    collection.objects.link(sun)
    sun.rotation_euler = [math.radians(a) for a in rotation_deg]
    return sun


def _world(scene):
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    background = _node_of_type(world.node_tree, "ShaderNodeBackground")
    background.inputs["Color"].default_value = WORLD_COLOUR
    background.inputs["Strength"].default_value = WORLD_STRENGTH
    world.color = WORLD_COLOUR[:3]
    return world


def configure_render(scene, resolution=DEFAULT_RESOLUTION, engine="CYCLES",
                     samples=DEFAULT_SAMPLES):
    """Engine, resolution and sampling; denoising always off."""
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}: use one of {', '.join(ENGINES)}")
    render = scene.render
    render.engine = compat.engine_identifier(engine)
    render.resolution_x, render.resolution_y = resolution
    render.resolution_percentage = 100
    render.pixel_aspect_x = render.pixel_aspect_y = 1.0
    render.film_transparent = False
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.preview_samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_preview_denoising = False
    scene.cycles.use_adaptive_sampling = False
    # Same seed each run: fixtures stay the same when re-rendered.
    scene.cycles.seed = 0
    scene.eevee.taa_render_samples = samples
    scene.view_settings.view_transform = "Filmic"
    # 3.x names the look "Medium High Contrast", 4.x "Filmic - Medium High Contrast".
    for look in (VIEW_LOOK, f"Filmic - {VIEW_LOOK}"):
        try:
            scene.view_settings.look = look
            break
        except TypeError:
            continue
    scene.view_settings.exposure = VIEW_EXPOSURE
    return scene


# --- passes -----------------------------------------------------------------

def enable_passes(view_layer, depth=True, normal=True, ao=False):
    """Turns on the render passes the HBAO tools read: Depth (Z), Normal, AO."""
    view_layer.use_pass_combined = True
    view_layer.use_pass_z = depth
    view_layer.use_pass_normal = normal
    view_layer.use_pass_ambient_occlusion = ao
    return view_layer


# A compositing artist's usual Cycles passes beyond those: the light passes,
# emission, environment, mist, position (where Blender has it) and
# Cryptomatte's object, material and asset passes at its default depth. With
# Combined, Depth and Normal: 81 channels in bpy 5.3, against 8.
PRODUCTION_PASSES = ("use_pass_mist", "use_pass_position", "use_pass_emit",
                     "use_pass_environment", "use_pass_diffuse_direct",
                     "use_pass_diffuse_indirect", "use_pass_diffuse_color",
                     "use_pass_glossy_direct", "use_pass_glossy_indirect",
                     "use_pass_glossy_color", "use_pass_transmission_direct",
                     "use_pass_transmission_indirect", "use_pass_transmission_color",
                     "use_pass_cryptomatte_object", "use_pass_cryptomatte_material",
                     "use_pass_cryptomatte_asset")


def enable_production_passes(view_layer):
    """Turns on PRODUCTION_PASSES as well (the hand-over saves them all)."""
    for name in PRODUCTION_PASSES:
        if hasattr(view_layer, name):  # use_pass_position: Blender 3.0 on
            setattr(view_layer, name, True)
    return view_layer


def configure_ao_reference(scene, distance=DEFAULT_AO_DISTANCE):
    """Makes the AO pass of every view layer a reference with rays `distance` long.

    Cycles traces the AO pass with world.light_settings.distance as ray length;
    EEVEE uses scene.eevee.gtao_distance before 5.0 and the world's since."""
    if distance <= 0.0 or not math.isfinite(distance):
        raise ValueError(f"AO distance must be a positive number of metres, got {distance}")
    world = scene.world or _world(scene)
    world.light_settings.distance = distance
    if hasattr(scene.eevee, "gtao_distance"):  # before 5.0; since, EEVEE uses the world's
        scene.eevee.gtao_distance = distance
    for view_layer in scene.view_layers:
        view_layer.use_pass_ambient_occlusion = True
    return scene


# --- cameras ----------------------------------------------------------------

def make_orthographic(scene, ortho_scale=None):
    """Switches the scene camera to orthographic, keeping its view.

    Without `ortho_scale`, the width seen at the camera's target distance is
    kept, so the framing stays about the same."""
    camera = scene.camera.data
    if ortho_scale is None:
        target_distance = scene.get("hbao_target_distance", 6.0)
        ortho_scale = target_distance * camera.sensor_width / camera.lens
    camera.type = "ORTHO"
    camera.ortho_scale = ortho_scale
    return scene


def camera_description(scene):
    """The scene camera as the JSON object the `hbao` CLI reads with --camera:
    the camera of the image Blender writes (a cropped border render's is the
    crop's; Blender writes the crop as a whole image).

    Keys are Blender's own property names; world_to_camera is row-major. The
    add-on's own reading of the camera makes it, so tests and the add-on agree."""
    return camera_model.camera_for_render_result(scene)


def stereo_eye(scene, right):
    """A camera object where Stereo 3D puts an eye: worked out here from
    the camera's Stereoscopy settings (pivot Left: the left eye is the camera;
    the right one an interocular distance along the camera's x, its shift
    off-axis by the distance over the convergence distance), for the tests'
    reference, apart from the add-on's way (RenderEngine.camera_model_matrix)."""
    camera = scene.camera
    stereo = camera.data.stereo
    assert stereo.pivot == "LEFT" and camera.data.sensor_fit == "AUTO"
    if not right:
        return camera
    eye = camera.copy()
    eye.data = camera.data.copy()
    eye.matrix_world = camera.matrix_world @ Matrix.Translation(
        (stereo.interocular_distance, 0.0, 0.0))
    if stereo.convergence_mode == "OFFAXIS":
        eye.data.shift_x -= (stereo.interocular_distance / camera.data.sensor_width
                             * camera.data.lens / stereo.convergence_distance)
    return eye


def view_camera_descriptions(scene):
    """{file suffix: the camera JSON of that view} of a stereo render, for
    the tests' reference."""
    if scene.render.views_format == "STEREO_3D":
        return {"_L": camera_model.camera_for_render_result(scene, stereo_eye(scene, False)),
                "_R": camera_model.camera_for_render_result(scene, stereo_eye(scene, True))}
    return {view.file_suffix: camera_model.camera_for_render_result(
        scene, scene.objects["Camera" + view.camera_suffix]) for view in scene.render.views}


# --- compositor wiring (every Blender version, through the add-on's compat) ---

class Compositor:
    """The scene's compositor tree, emptied, with helpers that hide what
    changed between Blender versions (5.0: a node group instead of
    scene.node_tree, Group Output instead of Composite, the File Output
    node's items, ShaderNodeValue)."""

    def __init__(self, scene):
        self.scene = scene
        self.tree = compat.ensure_compositor_tree(scene)
        for node in list(self.tree.nodes):
            self.tree.nodes.remove(node)

    def node(self, idname, location=(0, 0), **settings):
        node = self.tree.nodes.new(idname)
        node.location = location
        for name, value in settings.items():
            setattr(node, name, value)
        return node

    def link(self, from_socket, to_socket):
        return self.tree.links.new(from_socket, to_socket)

    def render_layers(self, view_layer=None, location=(-400, 0)):
        node = self.node("CompositorNodeRLayers", location)
        if view_layer is not None:
            node.layer = view_layer
        return node

    def composite(self, socket, location=(900, 0)):
        """The final image: Composite (<5.0) or the group's output."""
        node = compat_nodes.new_composite_output(self.tree)
        node.location = location
        self.link(socket, node.inputs[0])
        return node

    def value(self, value, location=(0, -300)):
        """A Value node (CompositorNodeValue <5.0, ShaderNodeValue 5.0+)."""
        node = compat_nodes.new_value_node(self.tree)
        node.location = location
        node.outputs[0].default_value = value
        return node

    def file_output(self, folder, prefix, location=(900, -300),
                    file_format="OPEN_EXR_MULTILAYER"):
        """A File Output node writing into FOLDER: one multilayer EXR
        PREFIX<frame>.exr, or (OPEN_EXR, PNG) one image per input, named as
        the Blender version names them (find them in the folder). EXRs are
        32-bit float, uncompressed."""
        node = self.node("CompositorNodeOutputFile", location)
        file_output.set_path(node, folder, prefix)
        compat.set_image_format(node.format, file_format)
        if file_format.startswith("OPEN_EXR"):
            node.format.color_depth = "32"
            node.format.exr_codec = "NONE"
        file_output.clear_inputs(node)
        return FileOutput(self, node)


def hbao_node_tree(scene, name):
    """Render Layers -> one HBAO node called `name` -> the final image.
    Returns the Compositor, the Render Layers node and the HBAO node."""
    compositor = Compositor(scene)
    layers = compositor.render_layers()
    node = compositor.node("CompositorNodeHBAO")
    node.name = name
    for socket in ("Image", "Depth", "Normal"):
        compositor.link(layers.outputs[socket], node.inputs[socket])
    compositor.composite(node.outputs["Image"])
    return compositor, layers, node


def hbao_test_tree(scene, out_dir, name="HBAO0"):
    """hbao_node_tree, and a File Output writing OUT_DIR/nodes_<frame>.exr
    with Render, <name>_AO and <name>_Image: the tree the F12 and fault
    scripts render. Returns the HBAO node."""
    compositor, layers, node = hbao_node_tree(scene, name)
    files = compositor.file_output(out_dir, "nodes_")
    for slot, socket in (("Render", layers.outputs["Image"]), (f"{name}_AO", node.outputs["AO"]),
                         (f"{name}_Image", node.outputs["Image"])):
        files.add(slot, socket)
    return node


class FileOutput:
    def __init__(self, compositor, node):
        self.compositor = compositor
        self.node = node

    def add(self, name, socket):
        """A new input called `name`, fed by `socket`."""
        target = file_output.new_input(self.node, name, socket)
        self.compositor.link(socket, target)
        return target


# --- scenes -----------------------------------------------------------------

def _room(scene, floor_size=12.0, wall_height=4.0, wall_y=2.0):
    """A floor at z = 0 and a back wall at y = wall_y: a concave corner."""
    room = _collection(scene, ROOM_COLLECTION)
    floor_material = _material("Floor", (0.55, 0.53, 0.50), roughness=0.8)
    wall_material = _material("Wall", (0.62, 0.60, 0.57), roughness=0.9)
    _add(bpy.ops.mesh.primitive_plane_add, room, floor_material, "Floor",
         size=floor_size, location=(0.0, 0.0, 0.0))
    wall = _add(bpy.ops.mesh.primitive_plane_add, room, wall_material, "Wall",
                size=1.0, location=(0.0, wall_y, wall_height / 2.0),
                rotation=(math.radians(90.0), 0.0, 0.0))
    wall.scale = (floor_size, wall_height, 1.0)
    return room


def build_corner_scene(scene=None, resolution=(96, 64), engine="CYCLES",
                       samples=DEFAULT_SAMPLES, with_props=True):
    """A small test scene: floor, back wall, a cube in the corner and a sphere
    on the floor, seen from the front and a little above."""
    scene = _scene_or_current(scene)
    clear_scene(scene)
    _world(scene)
    room = _room(scene, floor_size=8.0, wall_height=3.0, wall_y=1.0)
    props = _collection(scene, PROPS_COLLECTION)
    if with_props:
        _box(props, _material("Cube", (0.75, 0.25, 0.2)), "Cube",
             (0.8, 0.8, 0.8), (-0.6, 0.55, 0.4), rotation=(0.0, 0.0, math.radians(20.0)))
        sphere = _add(bpy.ops.mesh.primitive_uv_sphere_add, props,
                      _material("Sphere", (0.2, 0.4, 0.75)), "Sphere",
                      radius=0.4, segments=32, ring_count=16, location=(0.6, -0.2, 0.4))
        _smooth(sphere)
    _camera(scene, room, location=(0.6, -4.2, 2.0), target=(0.0, 0.3, 0.4), lens=40.0)
    scene["hbao_target_distance"] = (Vector((0.6, -4.2, 2.0)) - Vector((0.0, 0.3, 0.4))).length
    _sun(room, rotation_deg=(50.0, 10.0, 35.0))
    configure_render(scene, resolution, engine, samples)
    for view_layer in scene.view_layers:
        enable_passes(view_layer)
    return scene


def build_low_poly_scene(scene=None, resolution=(96, 64), engine="CYCLES",
                         samples=DEFAULT_SAMPLES):
    """The corner scene's room with coarse meshes shaded smooth, as artists
    leave them: an icosphere, a six-sided cylinder, a cube and a five-sided
    cone. Their shading normals lean past their outlines, and Cycles from 4.x
    writes such normals facing away from the camera."""
    scene = build_corner_scene(scene, resolution, engine, samples, with_props=False)
    props = scene.collection.children[PROPS_COLLECTION]
    material = _material("Props", (0.6, 0.6, 0.6))
    shapes = (
        (bpy.ops.mesh.primitive_ico_sphere_add, "Ico",
         {"radius": 0.5, "subdivisions": 1, "location": (-0.9, -0.2, 0.5)}),
        (bpy.ops.mesh.primitive_cylinder_add, "Cylinder",
         {"radius": 0.4, "depth": 1.2, "vertices": 6, "location": (0.3, 0.2, 0.6)}),
        (bpy.ops.mesh.primitive_cube_add, "Cube", {"size": 0.7, "location": (1.3, -0.6, 0.35)}),
        (bpy.ops.mesh.primitive_cone_add, "Cone",
         {"radius1": 0.8, "depth": 0.5, "vertices": 5, "location": (0.0, -1.4, 0.25)}),
    )
    for operator, name, arguments in shapes:
        _smooth(_add(operator, props, material, name, **arguments))
    return scene


def build_two_layer_scene(scene=None, resolution=(96, 64), engine="CYCLES",
                          samples=DEFAULT_SAMPLES):
    """The corner scene with two view layers, both with Depth and Normal:
    "Front" sees the room and the props, "Back" only the room (props excluded),
    so the same pixels hold different depths in the two layers."""
    scene = build_corner_scene(scene, resolution, engine, samples)
    front = scene.view_layers[0]
    front.name = "Front"
    back = scene.view_layers.get("Back") or scene.view_layers.new("Back")
    enable_passes(front)
    enable_passes(back)
    back.layer_collection.children[PROPS_COLLECTION].exclude = True
    return scene


def build_demo_scene(scene=None, resolution=DEFAULT_RESOLUTION, engine="CYCLES",
                     samples=DEFAULT_SAMPLES):
    """Objects with creases and contacts that show ambient occlusion well:
    a cube, a torus, steps, an open box, a cylinder leaning on the wall and
    touching spheres, on a floor meeting a back wall, seen in a 3/4 view."""
    scene = _scene_or_current(scene)
    clear_scene(scene)
    _world(scene)
    room = _room(scene, floor_size=14.0, wall_height=4.0, wall_y=1.6)
    props = _collection(scene, PROPS_COLLECTION)

    # A cube resting on the floor, turned a little.
    _box(props, _material("Cube", (0.80, 0.28, 0.22)), "Cube",
         (0.9, 0.9, 0.9), (-1.9, 0.2, 0.45), rotation=(0.0, 0.0, math.radians(25.0)))

    # Three steps against the wall: inner and outer edges at each riser.
    steps_material = _material("Steps", (0.80, 0.62, 0.30))
    step_depth, step_height, step_width = 0.35, 0.25, 1.2
    for index in range(3):
        depth = step_depth * (3 - index)
        _box(props, steps_material, f"Step{index}",
             (step_width, depth, step_height),
             (-0.35, 1.6 - depth / 2.0, step_height * (index + 0.5)))

    # A cylinder leaning against the wall: a contact line on the floor and
    # one on the wall.
    lean = math.radians(18.0)
    cylinder_length, cylinder_radius = 2.2, 0.18
    cylinder = _add(bpy.ops.mesh.primitive_cylinder_add, props,
                    _material("Pillar", (0.30, 0.55, 0.80)), "Pillar",
                    radius=cylinder_radius, depth=cylinder_length, vertices=48,
                    location=(1.1,
                              1.6 - cylinder_radius - math.sin(lean) * cylinder_length / 2.0,
                              math.cos(lean) * cylinder_length / 2.0 + 0.05),
                    rotation=(-lean, 0.0, 0.0))
    _smooth(cylinder)

    # An open box (no lid): inner corners along all four walls.
    box_material = _material("OpenBox", (0.35, 0.70, 0.45))
    box_centre = Vector((1.9, -0.4, 0.0))
    box_size, wall_thickness, box_height = 1.0, 0.06, 0.5
    half = box_size / 2.0
    _box(props, box_material, "OpenBoxBottom", (box_size, box_size, wall_thickness),
         box_centre + Vector((0.0, 0.0, wall_thickness / 2.0)))
    for name, size, offset in (
            ("OpenBoxLeft", (wall_thickness, box_size, box_height), (-half, 0.0)),
            ("OpenBoxRight", (wall_thickness, box_size, box_height), (half, 0.0)),
            ("OpenBoxBack", (box_size, wall_thickness, box_height), (0.0, half)),
            ("OpenBoxFront", (box_size, wall_thickness, box_height), (0.0, -half))):
        _box(props, box_material, name, size,
             box_centre + Vector((offset[0], offset[1], box_height / 2.0)))
    open_box = [o for o in props.objects if o.name.startswith("OpenBox")]
    for obj in open_box:
        obj.rotation_euler.z = math.radians(-15.0)
        # Rotate the walls about the box centre, not their own.
        relative = obj.location - box_centre
        relative.rotate(obj.rotation_euler)
        obj.location = box_centre + relative

    # A torus lying on the floor.
    torus_major, torus_minor = 0.45, 0.15
    torus = _add(bpy.ops.mesh.primitive_torus_add, props,
                 _material("Torus", (0.90, 0.60, 0.20)), "Torus",
                 major_radius=torus_major, minor_radius=torus_minor,
                 major_segments=64, minor_segments=24,
                 location=(-0.6, -1.2, torus_minor))
    _smooth(torus)

    # Spheres touching each other and the floor.
    sphere_material = _material("Spheres", (0.65, 0.35, 0.75))
    radius = 0.3
    for index, x in enumerate((0.35, 0.35 + 2.0 * radius)):
        sphere = _add(bpy.ops.mesh.primitive_uv_sphere_add, props, sphere_material,
                      f"Sphere{index}", radius=radius, segments=48, ring_count=24,
                      location=(x, -1.5, radius))
        _smooth(sphere)
    top = _add(bpy.ops.mesh.primitive_uv_sphere_add, props, sphere_material, "SphereTop",
               radius=radius, segments=48, ring_count=24,
               location=(0.35 + radius, -1.5, radius + math.sqrt(3.0) * radius))
    _smooth(top)

    camera_location, target = (4.6, -6.2, 3.4), (0.0, 0.0, 0.5)
    _camera(scene, room, location=camera_location, target=target, lens=32.0)
    scene["hbao_target_distance"] = (Vector(camera_location) - Vector(target)).length
    _sun(room, rotation_deg=(48.0, 0.0, 28.0), strength=2.5)
    configure_render(scene, resolution, engine, samples)
    for view_layer in scene.view_layers:
        enable_passes(view_layer)
    return scene


SCENE_BUILDERS = {
    "demo": build_demo_scene,
    "corner": build_corner_scene,
    "two_layers": build_two_layer_scene,
    "low_poly": build_low_poly_scene,
}
