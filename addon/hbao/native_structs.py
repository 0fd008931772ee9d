# SPDX-License-Identifier: GPL-2.0-or-later
"""libhbao's public structs (csrc/include/hbao.h) mirrored in ctypes, for the
binding (native.py). Keep each in the header's field order: the binding checks
their sizes against the library's on load, and
tests/test_parameter_contract.py checks their fields against the header."""
import ctypes


class HBAOParams(ctypes.Structure):
    _fields_ = [
        ("radius", ctypes.c_float),
        ("angle_bias_degrees", ctypes.c_float),
        ("directions", ctypes.c_int32),
        ("steps", ctypes.c_int32),
        ("falloff", ctypes.c_int32),
        ("integration", ctypes.c_int32),
        ("blur_size", ctypes.c_int32),
        ("blur_sharpness", ctypes.c_float),
        ("half_resolution", ctypes.c_int32),
        ("strength", ctypes.c_float),
        ("threads", ctypes.c_int32),
        ("background_depth", ctypes.c_float),
        ("implementation", ctypes.c_int32),
        ("thickness", ctypes.c_float),
    ]


class HBAOCamera(ctypes.Structure):
    _fields_ = [
        ("projection", ctypes.c_int32),
        ("lens", ctypes.c_float),
        ("sensor_width", ctypes.c_float),
        ("sensor_height", ctypes.c_float),
        ("sensor_fit", ctypes.c_int32),
        ("shift_x", ctypes.c_float),
        ("shift_y", ctypes.c_float),
        ("ortho_scale", ctypes.c_float),
        ("pixel_aspect_x", ctypes.c_float),
        ("pixel_aspect_y", ctypes.c_float),
        ("world_to_camera", ctypes.c_float * 16),
    ]


class HBAOView(ctypes.Structure):
    _fields_ = [
        ("perspective", ctypes.c_int32),
        ("pixel_size_x", ctypes.c_double),
        ("pixel_size_y", ctypes.c_double),
        ("origin_x", ctypes.c_double),
        ("origin_y", ctypes.c_double),
    ]


class HBAOChannel(ctypes.Structure):
    _fields_ = [
        ("data", ctypes.POINTER(ctypes.c_float)),
        ("pixel_stride", ctypes.c_int32),
        ("row_stride", ctypes.c_int64),
    ]
