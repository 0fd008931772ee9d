# SPDX-License-Identifier: GPL-2.0-or-later
"""ctypes binding of libhbao (csrc/include/hbao.h). Needs numpy, not bpy.

The library is loaded once, lazily, on first use (native_library.py); the
parameters go through the library's own resolver (native_params.py).

    ao = compute_ao(depth, normal, params={"radius": 0.5}, camera=camera_dict)
"""
import ctypes

import numpy as np

# Re-exported: the binding's public names live here (noqa: F401).
from .native_library import (BINDING_VERSION_MAJOR, LIBRARY_ENVIRONMENT_VARIABLE,  # noqa: F401
                             LIBRARY_FILE_NAME, HBAOError, HBAOLibraryError, check,
                             library_path, library_version, load_library, release_memory,
                             search_name, unload_library)
from .native_params import (PARAMETER_NAMES, default_params, params_struct,  # noqa: F401
                            resolve_params)
from .native_structs import HBAOCamera, HBAOChannel, HBAOParams, HBAOView  # noqa: F401
from .parameters import (FALLOFF_VALUES, INTEGRATION_VALUES, PROJECTION_VALUES,
                         SENSOR_FIT_VALUES)

__all__ = [
    "HBAOError", "HBAOLibraryError", "compute_ao", "default_params", "resolve_params",
    "camera_view", "camera_crop",
    "library_path", "load_library", "unload_library", "library_version", "release_memory",
    "search_name", "PARAMETER_NAMES", "FALLOFF_NAMES", "INTEGRATION_NAMES",
]

# Enum names as Blender spells them, mapped to the header's values (parameters.py).
FALLOFF_NAMES = FALLOFF_VALUES
INTEGRATION_NAMES = INTEGRATION_VALUES
PROJECTION_NAMES = PROJECTION_VALUES
SENSOR_FIT_NAMES = SENSOR_FIT_VALUES
_CAMERA_FLOAT_NAMES = ("lens", "sensor_width", "sensor_height", "shift_x", "shift_y",
                       "ortho_scale", "pixel_aspect_x", "pixel_aspect_y")
_FLOAT_SIZE = ctypes.sizeof(ctypes.c_float)


def _camera_struct(camera):
    library = load_library()
    structure = HBAOCamera()
    library.hbao_camera_default(ctypes.byref(structure))
    if not camera:
        return structure
    if "type" in camera:
        if camera["type"] not in PROJECTION_NAMES:
            raise ValueError(f"camera type must be PERSP or ORTHO, not {camera['type']!r} "
                             f"(panoramic cameras are not supported)")
        structure.projection = PROJECTION_NAMES[camera["type"]]
    if "sensor_fit" in camera:
        if camera["sensor_fit"] not in SENSOR_FIT_NAMES:
            raise ValueError(f"camera sensor_fit must be one of {', '.join(SENSOR_FIT_NAMES)}")
        structure.sensor_fit = SENSOR_FIT_NAMES[camera["sensor_fit"]]
    for name in _CAMERA_FLOAT_NAMES:
        if name in camera:
            setattr(structure, name, float(camera[name]))
    if "world_to_camera" in camera:
        matrix = np.asarray(camera["world_to_camera"], dtype=np.float64)
        if matrix.shape != (4, 4):
            raise ValueError(f"camera world_to_camera must be 4x4, not {matrix.shape}")
        structure.world_to_camera[:] = [float(v) for v in matrix.reshape(16)]
    return structure


_INT32_RANGE = (-2 ** 31, 2 ** 31 - 1)


def _int32s(**values):
    """The values, each an int32 as the library's arguments are; ValueError
    naming the first that is not (ctypes would wrap 2^32 + 10 to 10)."""
    for name, value in values.items():
        if not isinstance(value, (int, np.integer)) or not \
                _INT32_RANGE[0] <= int(value) <= _INT32_RANGE[1]:
            raise ValueError(f"{name} must be a whole number in the int32 range, not {value!r}")
    return [int(value) for value in values.values()]


def camera_view(camera, width, height):
    """The HBAOView of camera dict `camera` on a `width` x `height` image: libhbao's
    sensor fit (hbao_camera_view). Raises HBAOError, HBAOLibraryError, ValueError."""
    width, height = _int32s(width=width, height=height)
    view = HBAOView()
    check(load_library().hbao_camera_view(ctypes.byref(_camera_struct(camera)), width, height,
                                          ctypes.byref(view)))
    return view


def camera_crop(camera, full_width, full_height, x, y, width, height):
    """The camera dict of the `width` x `height` rectangle at column `x`, row `y` (from the
    top) of the full image seen by camera dict `camera`, with the same view rays
    (hbao_camera_crop). Raises HBAOError, HBAOLibraryError, ValueError."""
    full_width, full_height, x, y, width, height = _int32s(
        full_width=full_width, full_height=full_height, x=x, y=y, width=width, height=height)
    structure = _camera_struct(camera)
    check(load_library().hbao_camera_crop(ctypes.byref(structure), full_width, full_height,
                                          x, y, width, height, ctypes.byref(structure)))
    fit = next(name for name, value in SENSOR_FIT_NAMES.items() if value == structure.sensor_fit)
    return dict(camera or {}, sensor_fit=fit,
                **{name: getattr(structure, name) for name in _CAMERA_FLOAT_NAMES})


def clip_background_depth(clip_start, clip_end, depth):
    """The background depth of a render through a camera with this clip
    range (libhbao's hbao_clip_background_depth, the one rule the node and
    the CLI share); None or 0 for an unknown Clip Start or End."""
    return load_library().hbao_clip_background_depth(clip_start or 0.0, clip_end or 0.0, depth)


def _as_float32(array):
    """An (H, W) or (H, W, C) array as float32 without copying where the
    library can read it as it is (an hbao_channel: aligned floats, a pixel's
    components next to each other, pixels along a row and rows apart by
    whole floats, a row's pixels before the next row's, rows in either
    order); a copy otherwise (a Fortran-ordered or transposed array, a
    broadcast one, every other float: the library refused some as "a stride
    too small", and would have read others wrong)."""
    array = np.asarray(array)
    if array.dtype != np.float32:
        array = array.astype(np.float32)
    channels = array.shape[2] if array.ndim == 3 else 1
    row_extent = (array.shape[1] - 1) * array.strides[1] + channels * _FLOAT_SIZE \
        if array.ndim >= 2 else 0
    if (not array.flags.aligned or any(stride % _FLOAT_SIZE for stride in array.strides)
            or (array.ndim == 3 and array.strides[2] != _FLOAT_SIZE)
            or (array.ndim >= 2 and (array.strides[1] < channels * _FLOAT_SIZE
                                     or abs(array.strides[0]) < row_extent))):
        array = np.ascontiguousarray(array)
    return array


def _channel(array):
    """hbao_channel for an (H, W) or (H, W, C) float32 view; rows may run
    backwards (negative row stride)."""
    return HBAOChannel(array.ctypes.data_as(ctypes.POINTER(ctypes.c_float)),
                       array.strides[1] // _FLOAT_SIZE, array.strides[0] // _FLOAT_SIZE)


def compute_ao(depth, normal=None, *, params=None, camera=None, bottom_up=False, out=None,
               shape=None, back_depth=None):
    """Ambient occlusion from a planar depth image; returns (H, W) float32, 1 = unoccluded.

    depth: (H, W) float32 (or a flat buffer with shape=(H, W)); normal: world-space
    (H, W, 3) or (H, W, 4) float32, or None to reconstruct normals from depth;
    params: dict of hbao_params fields (falloff/integration by name, missing keys =
    library defaults); camera: camera dict (see camera_from_blender); bottom_up: row 0
    is the bottom image row (Blender's pass order), the result keeps that order; out:
    optional (H, W) float32 array to write into (returned); back_depth: (H, W) float32
    depth of the back faces (hbao_compute_layers), same row order as depth. Raises
    HBAOError with the library's message, HBAOLibraryError when the library is missing,
    ValueError for malformed arguments.
    """
    depth = np.asarray(depth) if not isinstance(depth, np.ndarray) else depth
    if depth.ndim == 1 or shape is not None:
        if shape is None:
            raise ValueError("a flat depth buffer needs shape=(height, width)")
        depth = np.asarray(depth).reshape(shape)
    if depth.ndim != 2:
        raise ValueError(f"depth must be (height, width), not shape {depth.shape}")
    height, width = depth.shape
    depth = _as_float32(depth)

    if normal is not None:
        normal = np.asarray(normal)
        if normal.ndim != 3:
            normal = normal.reshape(height, width, -1)
        if normal.shape[:2] != (height, width) or normal.shape[2] < 3:
            raise ValueError(f"normal must be ({height}, {width}, 3 or 4), not {normal.shape}")
        normal = _as_float32(normal)
        if normal.strides[2] != _FLOAT_SIZE:
            normal = np.ascontiguousarray(normal)

    if out is None:
        out = np.empty((height, width), dtype=np.float32)
    elif (not isinstance(out, np.ndarray) or out.dtype != np.float32 or out.shape != (height, width)
          or out.strides[1] != _FLOAT_SIZE or out.strides[0] % _FLOAT_SIZE
          or not out.flags.writeable):
        raise ValueError(f"out must be a writeable float32 ({height}, {width}) array with "
                         f"contiguous rows")

    params_structure = params_struct(params)
    camera_structure = _camera_struct(camera)

    # A bottom-up image seen through [::-1] is a top-down view whose data pointer is
    # the last row and whose row stride is negative: no copy, the library's convention.
    depth_view = depth[::-1] if bottom_up else depth
    normal_view = None if normal is None else (normal[::-1] if bottom_up else normal)
    out_view = out[::-1] if bottom_up else out

    depth_channel = _channel(depth_view)
    normal_channel = _channel(normal_view) if normal_view is not None else None
    back_channel = None
    if back_depth is not None:
        back_depth = _as_float32(np.asarray(back_depth))
        if back_depth.shape != (height, width):
            raise ValueError(f"back_depth must be ({height}, {width}), not {back_depth.shape}")
        back_channel = _channel(back_depth[::-1] if bottom_up else back_depth)
    library = load_library()
    check(library.hbao_compute_layers(
        ctypes.byref(params_structure), ctypes.byref(camera_structure), width, height,
        ctypes.byref(depth_channel),
        ctypes.byref(normal_channel) if normal_channel is not None else None,
        ctypes.byref(back_channel) if back_channel is not None else None,
        out_view.ctypes.data_as(ctypes.POINTER(ctypes.c_float)),
        out_view.strides[0] // _FLOAT_SIZE))
    return out


# hbao.h's HBAO_NOTE_* bits (tests/test_native.py holds them to the header),
# each with the short form that fits a node's status line.
NOTE_RADIUS_UNDER_A_PIXEL = 4  # always for radius 0
NOTE_SHORT_FORMS = {1: "Low memory: slow search", 2: "Radius past image: light",
                    NOTE_RADIUS_UNDER_A_PIXEL: "Radius < 1 pixel: no AO"}


def last_notes():
    """What the calling thread's last compute_ao did other than usual
    (hbao_last_notes): [(bit, the library's words)]."""
    library = load_library()
    notes = library.hbao_last_notes()
    return [(1 << bit, library.hbao_note_message(1 << bit).decode("utf-8", "replace"))
            for bit in range(32) if notes & (1 << bit)]
