# SPDX-License-Identifier: GPL-2.0-or-later
"""The HBAO parameters as artists set them: the C library's hbao_params
(csrc/include/hbao.h) by the names addon/hbao/native.py uses, with the
header's defaults, limits and enum values and the menus' items, for the
sockets and settings the artist edits. Values are resolved (completed and
clamped) in one place, the library's hbao_params_resolve, reached from Python
through native.resolve_params. No bpy and no imports from the package: the
compositor node, the viewport preview, the tests and the benchmark share it.

tests/test_parameter_contract.py checks every number here against the header
and csrc/lib/, so a copy cannot drift from the library."""
# csrc/include/hbao.h, HBAO_DEFAULT_* (falloff and integration: the
# HBAO_PARAMS_DEFAULT_INITIALIZER's enum values).
DEFAULTS = {
    "radius": 1.0,
    "angle_bias_degrees": 5.0,
    "directions": 4,
    "steps": 16,
    "falloff": "NONE",
    "integration": "COSINE",
    "blur_size": 5,
    "blur_sharpness": 32.0,
    "strength": 1.0,
    "background_depth": 65504.0,
    "thickness": 0.0,
}
# csrc/include/hbao.h, HBAO_MAX_*.
MAX_DIRECTIONS = 64
MAX_STEPS = 64
MAX_BLUR_SIZE = 65
MAX_BLUR_SHARPNESS = 1000.0
MAX_ANGLE_BIAS_DEGREES = 60.0
MAX_STRENGTH = 16.0
MAX_IMAGE_SIZE = 65536

# The header's enums by the names Blender uses for them: hbao_falloff,
# hbao_integration, hbao_projection (Camera.type), hbao_sensor_fit
# (Camera.sensor_fit). The binding, the menus and the GLSL defines use these.
FALLOFF_VALUES = {"QUADRATIC": 0, "NONE": 1}
INTEGRATION_VALUES = {"HBAO": 0, "COSINE": 1}
PROJECTION_VALUES = {"PERSP": 0, "ORTHO": 1}
SENSOR_FIT_VALUES = {"AUTO": 0, "HORIZONTAL": 1, "VERTICAL": 2}

# The limits the library clamps to (hbao.h documents each field's range), as
# the node's sockets and the viewport's settings offer them: key -> (lowest,
# highest, whole number). Values are resolved by the library itself
# (native.resolve_params -> hbao_params_resolve), never by these numbers.
LIMITS = {
    "angle_bias_degrees": (0.0, MAX_ANGLE_BIAS_DEGREES, False),
    "directions": (1, MAX_DIRECTIONS, True),
    "steps": (1, MAX_STEPS, True),
    "blur_size": (0, MAX_BLUR_SIZE, True),
    "blur_sharpness": (0.0, MAX_BLUR_SHARPNESS, False),
    "strength": (0.0, MAX_STRENGTH, False),
}
# Each parameter as the node's sockets and the panel name it, for messages.
LABELS = {
    "radius": "Radius",
    "angle_bias_degrees": "Angle Bias",
    "directions": "Directions",
    "steps": "Steps",
    "falloff": "Falloff",
    "integration": "Integration",
    "blur_size": "Blur Size",
    "blur_sharpness": "Blur Sharpness",
    "strength": "Strength",
    "background_depth": "Background Depth",
    "thickness": "Thickness",
}

# What each setting does, as the node's socket and the viewport panel's
# setting say it in their tooltips: the effect first, then the cost.
DESCRIPTIONS = {
    "radius": "How far away, in scene units, an occluder still shades a point (like Cycles' AO "
              "Distance)",
    "angle_bias_degrees": "Occluders less than this many degrees above the surface are "
                          "ignored: raise it if flat or finely tessellated surfaces look dirty",
    "directions": "Directions searched around each pixel: more is smoother and slower",
    "steps": "Samples along each direction: more finds thinner occluders, and is slower",
    "blur_size": "Width in pixels of the edge-aware blur that hides the sampling pattern; 0 to "
                 "2 = no blur (the pattern shows); even widths blur as the odd one below",
    "blur_sharpness": "How strongly the blur stops at depth edges; 0 = a plain blur",
    "strength": "How dark the AO is: 1 as computed, 2 darker, 0.5 lighter, 0 none (the AO is "
                "raised to this power)",
    "thickness": "How thick occluders are taken to be, in scene units: an object more than "
                 "this in front of a surface does not shade it (no dark halo behind it). 0 = "
                 "no limit",
    "half_resolution": "Compute the AO on every other pixel of every other row and upsample "
                       "it, edge-aware: about 3 times faster, a little softer",
}


def item_name(items, identifier):
    """The name a menu's `items` (FALLOFF_ITEMS, INTEGRATION_ITEMS) show for
    `identifier`."""
    return next((name for key, name, _tip in items if key == identifier), identifier)


# The menus of the node and of the viewport panel: (identifier, name, tip).
FALLOFF_ITEMS = [
    ("QUADRATIC", "Quadratic", "Occluders count less the farther they are: 1 - (d/radius)^2"),
    ("NONE", "None", "Every occluder inside the radius counts fully, as in Cycles' AO"),
]
INTEGRATION_ITEMS = [
    ("COSINE", "Cosine", "Weighs the sky by its angle to the surface, as Cycles' AO pass does"),
    ("HBAO", "HBAO", "The classic HBAO measure (the share of the sky hidden): darker in "
                     "creases than Cycles"),
]

# The blur (csrc/lib/internal_hbao.h and blur.c): a kernel of size b has radius
# (b - 1) / 2 taps each side for b >= 2 (even sizes round down, 0, 1 and 2 mean
# no blur), and its Gaussian has sigma = BLUR_SIGMA_PER_TAP * (radius +
# BLUR_SIGMA_TAP_OFFSET), so the outermost tap keeps a weight of about
# exp(-2): wide enough to hide the 4x4 pattern, narrow enough to stay local.
BLUR_SIGMA_PER_TAP = 0.5
BLUR_SIGMA_TAP_OFFSET = 1


def blur_kernel_radius(blur_size):
    """Taps each side of the blur kernel of size `blur_size` (0: no blur)."""
    return (blur_size - 1) // 2 if blur_size >= 2 else 0


def grid_blur_radius(kernel_radius, half):
    """Taps each side of the blur on the grid it runs on: at half
    resolution it runs on the half grid before the upsample, with half the
    taps (rounded up), so that it reaches as far."""
    return (kernel_radius + 1) // 2 if half else kernel_radius


def blur_sigma(kernel_radius):
    """The blur Gaussian's sigma, in pixels, for a kernel of `kernel_radius` taps each side."""
    return BLUR_SIGMA_PER_TAP * (kernel_radius + BLUR_SIGMA_TAP_OFFSET)
