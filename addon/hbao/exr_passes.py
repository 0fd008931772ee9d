# SPDX-License-Identifier: GPL-2.0-or-later
"""Channels of an OpenEXR file (the multilayer EXR the render hook writes)
as numpy arrays, read by libhbao_exr through ctypes. Needs numpy, not bpy.

Why a library of its own: Blender's Python has no OpenEXR or OpenImageIO
module and `bpy.data.images.load` gives no pixels for multilayer EXRs, so the
add-on ships the `hbao` tool's OpenEXRCore reader as libhbao_exr.so
(csrc/exr/hbao_exr.h). It is separate from libhbao.so so that the AO library
itself never depends on OpenEXR. The library decodes every requested channel
in one pass straight into numpy arrays: no per-pixel work in Python.

The library is loaded once, lazily; the load checks its interface version and
struct size, so a stale or foreign library fails with a message instead of
corrupting memory.

    channels = read_channels("passes.exr", ["ViewLayer.Depth.Z"])
"""
import ctypes
import os
from pathlib import Path

import numpy as np

from . import library_loading

__all__ = ["EXRFormatError", "EXRFileError", "EXRLibraryError", "read_channels",
           "read_channel_groups", "channel_names", "image_size", "load_library",
           "unload_library", "library_path"]

#: The header's HBAO_EXR_INTERFACE_VERSION this binding mirrors.
BINDING_INTERFACE_VERSION = 2
#: Environment variable that names the library to load instead of lib/libhbao_exr.so.
LIBRARY_ENVIRONMENT_VARIABLE = "HBAO_EXR_LIBRARY"
# hbao_exr.h: HBAO_EXR_MESSAGE_SIZE holds every message the library writes.
_MESSAGE_SIZE = 1024
_FLOAT = np.dtype(np.float32)

# Result codes of hbao_exr.h.
_SUCCESS = 0
_ERROR_FILE_ACCESS = 3
_ERROR_MISSING_CHANNEL = 5


class EXRFormatError(ValueError):
    """The file is not an EXR the library can read (or it is corrupt); carries
    the library's result code and message."""

    def __init__(self, message, code=None):
        super().__init__(message)
        self.code = code


class EXRFileError(OSError):
    """The file cannot be opened (missing, unreadable)."""


class EXRLibraryError(RuntimeError):
    """libhbao_exr could not be loaded, or it does not match this binding."""


class _ChannelRequest(ctypes.Structure):
    """hbao_exr_channel_request (keep in the header's field order)."""
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("data", ctypes.POINTER(ctypes.c_float)),
        ("pixel_stride", ctypes.c_int32),
        ("row_stride", ctypes.c_int64),
    ]


_FILE_P = ctypes.c_void_p
_INT32_P = ctypes.POINTER(ctypes.c_int32)
# Every exported function: name -> (restype, argtypes). The one place they are declared.
_FUNCTIONS = {
    "hbao_exr_interface_version": (ctypes.c_int32, []),
    "hbao_exr_channel_request_size": (ctypes.c_int32, []),
    "hbao_exr_result_message": (ctypes.c_char_p, [ctypes.c_int32]),
    "hbao_exr_open": (ctypes.c_int32, [ctypes.c_char_p, ctypes.POINTER(_FILE_P),
                                       ctypes.c_char_p, ctypes.c_int32]),
    "hbao_exr_size": (None, [_FILE_P, _INT32_P, _INT32_P]),
    "hbao_exr_set_threads": (None, [_FILE_P, ctypes.c_int32]),
    "hbao_exr_channel_count": (ctypes.c_int32, [_FILE_P]),
    "hbao_exr_channel_name": (ctypes.c_char_p, [_FILE_P, ctypes.c_int32]),
    "hbao_exr_has_channel": (ctypes.c_int32, [_FILE_P, ctypes.c_char_p]),
    "hbao_exr_read_channels": (ctypes.c_int32, [_FILE_P, ctypes.POINTER(_ChannelRequest),
                                                ctypes.c_int32, ctypes.c_char_p,
                                                ctypes.c_int32]),
    "hbao_exr_close": (None, [ctypes.POINTER(_FILE_P)]),
}


_LIBRARY = library_loading.NativeLibrary(
    "hbao_exr", LIBRARY_ENVIRONMENT_VARIABLE, Path(__file__).resolve().parent / "lib",
    _FUNCTIONS, EXRLibraryError,
    handshake=library_loading.Handshake(
        "hbao_exr_interface_version", lambda version: version == BINDING_INTERFACE_VERSION,
        str(BINDING_INTERFACE_VERSION),
        [("hbao_exr_channel_request", "hbao_exr_channel_request_size", _ChannelRequest)]),
    load_hint="It needs OpenEXRCore (libOpenEXRCore-3_1.so) installed or next to it; "
              "rebuild or reinstall the add-on with scripts/install_addon.sh.")
#: The platform's file name of the library (libhbao_exr.so on Linux).
LIBRARY_FILE_NAME = _LIBRARY.file_name


# The file that load_library() loads: $LIBRARY_ENVIRONMENT_VARIABLE, else
# lib/LIBRARY_FILE_NAME here; load_library() loads it once (raises EXRLibraryError);
# unload_library() forgets it, so that the next call loads library_path() again.
library_path = _LIBRARY.path
load_library = _LIBRARY.load
unload_library = _LIBRARY.unload


def _text(raw):
    return raw.decode("utf-8", "replace") if raw else ""


class _OpenFile:
    """An open hbao_exr_file; closes it on leaving the `with` block."""

    def __init__(self, path):
        self.library = load_library()
        self.path = os.fspath(path)
        self.handle = _FILE_P()
        message = ctypes.create_string_buffer(_MESSAGE_SIZE)
        result = self.library.hbao_exr_open(os.fsencode(self.path), ctypes.byref(self.handle),
                                            message, _MESSAGE_SIZE)
        if result != _SUCCESS:
            text = _text(message.value) or _text(self.library.hbao_exr_result_message(result))
            if result == _ERROR_FILE_ACCESS:
                raise EXRFileError(text)
            raise EXRFormatError(text, result)

    def __enter__(self):
        return self

    def __exit__(self, *_exception):
        self.library.hbao_exr_close(ctypes.byref(self.handle))

    def size(self):
        width, height = ctypes.c_int32(), ctypes.c_int32()
        self.library.hbao_exr_size(self.handle, ctypes.byref(width), ctypes.byref(height))
        return width.value, height.value

    def names(self):
        return [_text(self.library.hbao_exr_channel_name(self.handle, index))
                for index in range(self.library.hbao_exr_channel_count(self.handle))]

    def read(self, requests):
        """Run hbao_exr_read_channels for [(name, array, channel offset)]."""
        table = (_ChannelRequest * len(requests))()
        for entry, (name, array, offset) in zip(table, requests):
            entry.name = name.encode("utf-8")
            entry.data = ctypes.cast(array.ctypes.data + offset * _FLOAT.itemsize,
                                     ctypes.POINTER(ctypes.c_float))
            entry.pixel_stride = array.strides[1] // _FLOAT.itemsize
            entry.row_stride = array.strides[0] // _FLOAT.itemsize
        message = ctypes.create_string_buffer(_MESSAGE_SIZE)
        result = self.library.hbao_exr_read_channels(self.handle, table, len(requests),
                                                     message, _MESSAGE_SIZE)
        if result == _ERROR_MISSING_CHANNEL:
            missing = next(name for name, _, _ in requests
                           if not self.library.hbao_exr_has_channel(self.handle,
                                                                    name.encode("utf-8")))
            raise KeyError(f"{self.path} has no channel {missing!r}; it has: "
                           f"{', '.join(sorted(self.names()))}")
        if result != _SUCCESS:
            raise EXRFormatError(
                _text(message.value) or _text(self.library.hbao_exr_result_message(result)),
                result)


def channel_names(path):
    """The channel names of an EXR file, over all its parts, sorted by name."""
    with _OpenFile(path) as exr_file:
        return exr_file.names()


def image_size(path):
    """(width, height) of an EXR file's data window."""
    with _OpenFile(path) as exr_file:
        return exr_file.size()


def read_channel_groups(path, groups, threads=0):
    """{key: float32 array, top row first} for `groups` {key: [channel names]}:
    a group of one name gives a (height, width) array, a group of n names an
    interleaved (height, width, n) array (Normal.X/Y/Z as one normal image),
    all decoded in one pass over the file by `threads` threads (0: one per
    core; the values do not depend on it). Raises EXRFileError, EXRFormatError,
    KeyError naming a missing channel and the channels the file has, or
    EXRLibraryError when libhbao_exr cannot be loaded."""
    groups = {key: [names] if isinstance(names, str) else list(names)
              for key, names in groups.items()}
    with _OpenFile(path) as exr_file:
        width, height = exr_file.size()
        result, requests = {}, []
        for key, names in groups.items():
            if not names:
                raise ValueError(f"group {key!r} names no channels")
            array = np.empty((height, width, len(names)), dtype=np.float32)
            requests += [(name, array, offset) for offset, name in enumerate(names)]
            result[key] = array[:, :, 0] if len(names) == 1 else array
        duplicates = {name for name, _, _ in requests
                      if sum(other == name for other, _, _ in requests) > 1}
        if duplicates:
            raise ValueError(f"channels requested twice: {', '.join(sorted(duplicates))}")
        if requests:
            exr_file.library.hbao_exr_set_threads(exr_file.handle, threads)
            exr_file.read(requests)
    return result


def read_channels(path, names, threads=0):
    """{name: (height, width) float32 array, top row first} for the channels
    `names` of the EXR at `path` (each channel once, whatever `names` repeats),
    decoded by `threads` threads as in read_channel_groups. Raises
    EXRFileError, EXRFormatError, KeyError naming a missing channel and the
    channels the file has, or EXRLibraryError."""
    return read_channel_groups(path, {name: [name] for name in dict.fromkeys(names)}, threads)
