# SPDX-License-Identifier: GPL-2.0-or-later
"""The HBAO parameters as artists set them: the C library's hbao_params
(csrc/include/hbao.h) by the names addon/hbao/native.py uses, with the
header's defaults and limits and the menus' items. No bpy: the compositor
node, the viewport preview and the tests share it."""
import math

# csrc/include/hbao.h, HBAO_DEFAULT_* and HBAO_MAX_*.
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
}
MAX_DIRECTIONS = 64
MAX_STEPS = 64
MAX_BLUR_SIZE = 65
MAX_BLUR_SHARPNESS = 1000.0
MAX_ANGLE_BIAS_DEGREES = 60.0
MAX_STRENGTH = 16.0
FALLOFF_VALUES = {"QUADRATIC": 0, "NONE": 1}
INTEGRATION_VALUES = {"HBAO": 0, "COSINE": 1}

# The menus of the node and of the viewport panel: (identifier, name, tip).
FALLOFF_ITEMS = [
    ("QUADRATIC", "Quadratic", "Occluders count less with distance: 1 - (d/radius)^2"),
    ("NONE", "None", "Every occluder inside the radius counts fully"),
]
INTEGRATION_ITEMS = [
    ("COSINE", "Cosine", "Cosine-weighted visibility, as Cycles' AO pass measures it"),
    ("HBAO", "HBAO", "Bavoil & Sainz: the occluded fraction of the hemisphere"),
]


def _clamp(value, low, high):
    return min(max(value, low), high)


def resolved(params):
    """`params` (any subset of DEFAULTS' keys) completed with the defaults and
    clamped to the header's limits, as the C library clamps them. Raises
    ValueError where the library returns HBAO_ERROR_INVALID_PARAMETER."""
    unknown = set(params or {}) - set(DEFAULTS) - {"half_resolution", "threads"}
    if unknown:
        raise ValueError(f"unknown HBAO parameters: {', '.join(sorted(unknown))}")
    merged = dict(DEFAULTS)
    merged.update({k: v for k, v in (params or {}).items() if k in DEFAULTS})
    for name in ("radius", "angle_bias_degrees", "blur_sharpness", "strength",
                 "background_depth"):
        if not math.isfinite(float(merged[name])):
            raise ValueError(f"{name} must be a finite number, not {merged[name]}")
    if merged["radius"] < 0.0 or merged["background_depth"] <= 0.0:
        raise ValueError("radius must be >= 0 and background_depth > 0")
    if merged["falloff"] not in FALLOFF_VALUES:
        raise ValueError(f"falloff must be one of {', '.join(FALLOFF_VALUES)}")
    if merged["integration"] not in INTEGRATION_VALUES:
        raise ValueError(f"integration must be one of {', '.join(INTEGRATION_VALUES)}")
    blur_size = _clamp(int(merged["blur_size"]), 0, MAX_BLUR_SIZE)
    return {
        "radius": float(merged["radius"]),
        "angle_bias_degrees": _clamp(float(merged["angle_bias_degrees"]), 0.0,
                                     MAX_ANGLE_BIAS_DEGREES),
        "directions": _clamp(int(merged["directions"]), 1, MAX_DIRECTIONS),
        "steps": _clamp(int(merged["steps"]), 1, MAX_STEPS),
        "falloff": merged["falloff"],
        "integration": merged["integration"],
        "blur_size": blur_size,
        "blur_sharpness": _clamp(float(merged["blur_sharpness"]), 0.0, MAX_BLUR_SHARPNESS),
        "strength": _clamp(float(merged["strength"]), 0.0, MAX_STRENGTH),
        "background_depth": float(merged["background_depth"]),
    }


def blur_kernel_radius(blur_size):
    """docs/algorithm.md: r = (b - 1) / 2 for b >= 2 (even sizes round down), else no blur."""
    return (blur_size - 1) // 2 if blur_size >= 2 else 0
