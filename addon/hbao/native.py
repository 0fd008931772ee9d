# SPDX-License-Identifier: GPL-2.0-or-later
"""ctypes binding of libhbao (csrc/include/hbao.h). Needs numpy, not bpy.

The library is loaded once, lazily, on first use; the load checks that the
library's major version and struct sizes match this binding, so that a stale
or foreign libhbao.so fails with a message instead of corrupting memory.

    ao = compute_ao(depth, normal, params={"radius": 0.5}, camera=camera_dict)
"""
import ctypes
from pathlib import Path

import numpy as np

from . import library_loading
from .native_structs import HBAOCamera, HBAOChannel, HBAOParams, HBAOView
from .parameters import (FALLOFF_VALUES, INTEGRATION_VALUES, PROJECTION_VALUES,
                         SENSOR_FIT_VALUES)

__all__ = [
    "HBAOError", "HBAOLibraryError", "compute_ao", "default_params", "camera_view", "camera_crop",
    "library_path", "load_library", "library_version",
    "PARAMETER_NAMES", "FALLOFF_NAMES", "INTEGRATION_NAMES",
]

#: The header's HBAO_VERSION_MAJOR this binding mirrors.
BINDING_VERSION_MAJOR = 0
#: Environment variable that names the library to load instead of lib/libhbao.so.
LIBRARY_ENVIRONMENT_VARIABLE = "HBAO_LIBRARY"
_FLOAT_SIZE = ctypes.sizeof(ctypes.c_float)
_HBAO_SUCCESS = 0


class HBAOError(RuntimeError):
    """A libhbao call failed; carries the library's result code and message."""

    def __init__(self, code, message):
        super().__init__(f"libhbao: {message} (result {code})")
        self.code = code
        self.library_message = message


class HBAOLibraryError(RuntimeError):
    """libhbao could not be loaded, or it does not match this binding."""


# Enum names as Blender spells them, mapped to the header's values (parameters.py).
FALLOFF_NAMES = FALLOFF_VALUES
INTEGRATION_NAMES = INTEGRATION_VALUES
PROJECTION_NAMES = PROJECTION_VALUES
SENSOR_FIT_NAMES = SENSOR_FIT_VALUES
_ENUM_PARAMETERS = {"falloff": FALLOFF_NAMES, "integration": INTEGRATION_NAMES}
PARAMETER_NAMES = tuple(name for name, _ in HBAOParams._fields_)
_CAMERA_FLOAT_NAMES = ("lens", "sensor_width", "sensor_height", "shift_x", "shift_y",
                       "ortho_scale", "pixel_aspect_x", "pixel_aspect_y")

# Every exported function: name -> (restype, argtypes). The one place they are declared.
_PARAMS_P = ctypes.POINTER(HBAOParams)
_CAMERA_P = ctypes.POINTER(HBAOCamera)
_CHANNEL_P = ctypes.POINTER(HBAOChannel)
_FUNCTIONS = {
    "hbao_version": (ctypes.c_int32, []),
    "hbao_result_message": (ctypes.c_char_p, [ctypes.c_int32]),
    "hbao_params_default": (None, [_PARAMS_P]),
    "hbao_camera_default": (None, [_CAMERA_P]),
    "hbao_params_size": (ctypes.c_size_t, []),
    "hbao_camera_size": (ctypes.c_size_t, []),
    "hbao_view_size": (ctypes.c_size_t, []),
    "hbao_camera_view": (ctypes.c_int32, [_CAMERA_P, ctypes.c_int32, ctypes.c_int32,
                                          ctypes.POINTER(HBAOView)]),
    "hbao_camera_crop": (ctypes.c_int32, [_CAMERA_P] + [ctypes.c_int32] * 6 + [_CAMERA_P]),
    "hbao_compute": (ctypes.c_int32, [_PARAMS_P, _CAMERA_P, ctypes.c_int32, ctypes.c_int32,
                                      _CHANNEL_P, _CHANNEL_P, ctypes.POINTER(ctypes.c_float),
                                      ctypes.c_int64]),
}


def _version_text(packed):
    return f"{packed // 10000}.{packed // 100 % 100}.{packed % 100}"


_LIBRARY = library_loading.NativeLibrary(
    "hbao", LIBRARY_ENVIRONMENT_VARIABLE, Path(__file__).resolve().parent / "lib",
    _FUNCTIONS, HBAOLibraryError,
    handshake=library_loading.Handshake(
        "hbao_version", BINDING_VERSION_MAJOR,
        [("hbao_params", "hbao_params_size", HBAOParams),
         ("hbao_camera", "hbao_camera_size", HBAOCamera),
         ("hbao_view", "hbao_view_size", HBAOView)],
        version_key=lambda packed: packed // 10000,
        describe=_version_text,
        expected_text=f"{BINDING_VERSION_MAJOR}.x"),
    load_hint="Rebuild it for this machine.")
#: The platform's file name of the library (libhbao.so on Linux).
LIBRARY_FILE_NAME = _LIBRARY.file_name


# The file that load_library() loads: $LIBRARY_ENVIRONMENT_VARIABLE, else
# lib/LIBRARY_FILE_NAME here; load_library() loads it once (raises HBAOLibraryError);
# unload_library() forgets it, so that the next call loads library_path() again.
library_path = _LIBRARY.path
load_library = _LIBRARY.load
unload_library = _LIBRARY.unload


def library_version():
    """The loaded library's version as 'major.minor.patch'."""
    return _version_text(load_library().hbao_version())


def _check(result):
    if result != _HBAO_SUCCESS:
        message = load_library().hbao_result_message(result)
        raise HBAOError(result, message.decode("utf-8", "replace") if message else "unknown")


def _params_struct(params):
    library = load_library()
    structure = HBAOParams()
    library.hbao_params_default(ctypes.byref(structure))
    for key, value in (params or {}).items():
        if key not in PARAMETER_NAMES:
            raise ValueError(f"unknown HBAO parameter {key!r}; known: {', '.join(PARAMETER_NAMES)}")
        if key in _ENUM_PARAMETERS:
            names = _ENUM_PARAMETERS[key]
            if isinstance(value, str):
                if value not in names:
                    raise ValueError(f"{key} must be one of {', '.join(names)}, not {value!r}")
                value = names[value]
        field_type = dict(HBAOParams._fields_)[key]
        setattr(structure, key, int(value) if field_type is ctypes.c_int32 else float(value))
    return structure


def default_params():
    """The library's defaults as a params dict (enums by name)."""
    structure = HBAOParams()
    load_library().hbao_params_default(ctypes.byref(structure))
    result = {name: getattr(structure, name) for name in PARAMETER_NAMES}
    for key, names in _ENUM_PARAMETERS.items():
        result[key] = next((n for n, v in names.items() if v == result[key]), result[key])
    result["half_resolution"] = bool(result["half_resolution"])
    return result


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


def camera_view(camera, width, height):
    """The HBAOView of camera dict `camera` on a `width` x `height` image: libhbao's
    sensor fit (hbao_camera_view). Raises HBAOError, HBAOLibraryError, ValueError."""
    view = HBAOView()
    _check(load_library().hbao_camera_view(ctypes.byref(_camera_struct(camera)), width, height,
                                           ctypes.byref(view)))
    return view


def camera_crop(camera, full_width, full_height, x, y, width, height):
    """The camera dict of the `width` x `height` rectangle at column `x`, row `y` (from the
    top) of the full image seen by camera dict `camera`, with the same view rays
    (hbao_camera_crop). Raises HBAOError, HBAOLibraryError, ValueError."""
    structure = _camera_struct(camera)
    _check(load_library().hbao_camera_crop(ctypes.byref(structure), full_width, full_height,
                                           x, y, width, height, ctypes.byref(structure)))
    fit = next(name for name, value in SENSOR_FIT_NAMES.items() if value == structure.sensor_fit)
    return dict(camera or {}, sensor_fit=fit,
                **{name: getattr(structure, name) for name in _CAMERA_FLOAT_NAMES})


def _as_float32(array):
    """array as float32 without copying when it already is float32 with
    float-aligned strides; a copy otherwise."""
    array = np.asarray(array)
    if array.dtype != np.float32:
        array = array.astype(np.float32)
    if any(stride % _FLOAT_SIZE for stride in array.strides) or array.strides[-1] <= 0:
        array = np.ascontiguousarray(array)
    if array.ndim >= 2 and array.strides[1] <= 0:
        array = np.ascontiguousarray(array)
    return array


def _channel(array):
    """hbao_channel for an (H, W) or (H, W, C) float32 view; rows may run
    backwards (negative row stride)."""
    return HBAOChannel(array.ctypes.data_as(ctypes.POINTER(ctypes.c_float)),
                       array.strides[1] // _FLOAT_SIZE, array.strides[0] // _FLOAT_SIZE)


def compute_ao(depth, normal=None, *, params=None, camera=None, bottom_up=False, out=None,
               shape=None):
    """Ambient occlusion from a planar depth image; returns (H, W) float32, 1 = unoccluded.

    depth: (H, W) float32 (or a flat buffer with shape=(H, W)); normal: world-space
    (H, W, 3) or (H, W, 4) float32, or None to reconstruct normals from depth;
    params: dict of hbao_params fields (falloff/integration by name, missing keys =
    library defaults); camera: camera dict (see camera_from_blender); bottom_up: row 0
    is the bottom image row (Blender's pass order), the result keeps that order; out:
    optional (H, W) float32 array to write into (returned). Raises HBAOError with the
    library's message, HBAOLibraryError when the library is missing, ValueError for
    malformed arguments.
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

    params_struct = _params_struct(params)
    camera_struct = _camera_struct(camera)

    # A bottom-up image seen through [::-1] is a top-down view whose data pointer is
    # the last row and whose row stride is negative: no copy, the library's convention.
    depth_view = depth[::-1] if bottom_up else depth
    normal_view = None if normal is None else (normal[::-1] if bottom_up else normal)
    out_view = out[::-1] if bottom_up else out

    depth_channel = _channel(depth_view)
    normal_channel = _channel(normal_view) if normal_view is not None else None
    library = load_library()
    _check(library.hbao_compute(
        ctypes.byref(params_struct), ctypes.byref(camera_struct), width, height,
        ctypes.byref(depth_channel),
        ctypes.byref(normal_channel) if normal_channel is not None else None,
        out_view.ctypes.data_as(ctypes.POINTER(ctypes.c_float)),
        out_view.strides[0] // _FLOAT_SIZE))
    return out
