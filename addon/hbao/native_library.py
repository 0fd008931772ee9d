# SPDX-License-Identifier: GPL-2.0-or-later
"""Loading libhbao for the ctypes binding (native.py): its functions' types,
its errors, the version and struct-size handshake. Needs neither numpy nor bpy.

The library is loaded once, lazily, on first use; the load checks that the
library's version is the one this binding mirrors (BINDING_VERSION_MAJOR and
BINDING_VERSION_MINOR; any patch) and that its struct sizes match this
binding, so that a stale or foreign libhbao.so fails with a message instead
of corrupting memory."""
import ctypes
from pathlib import Path

from . import library_loading
from .native_structs import HBAOCamera, HBAOChannel, HBAOParams, HBAOView

#: The header's HBAO_VERSION_MAJOR this binding mirrors.
BINDING_VERSION_MAJOR = 0
#: And its HBAO_VERSION_MINOR. While the major version is 0 a minor version
#: may change anything (0.6 added hbao_implementation_name, which this
#: binding calls), so only the minor version this binding was written for is
#: accepted: a library of another one is refused by its version, not called
#: with what it may no longer mean. test_native.py holds both to hbao.h.
BINDING_VERSION_MINOR = 6
#: Environment variable that names the library to load instead of lib/libhbao.so.
LIBRARY_ENVIRONMENT_VARIABLE = "HBAO_LIBRARY"
HBAO_SUCCESS = 0


class HBAOError(RuntimeError):
    """A libhbao call failed; carries the library's result code and message."""

    def __init__(self, code, message):
        super().__init__(f"libhbao: {message} (result {code})")
        self.code = code
        self.library_message = message


class HBAOLibraryError(RuntimeError):
    """libhbao could not be loaded, or it does not match this binding."""


# Every exported function: name -> (restype, argtypes). The one place they are declared.
_PARAMS_P = ctypes.POINTER(HBAOParams)
_CAMERA_P = ctypes.POINTER(HBAOCamera)
_CHANNEL_P = ctypes.POINTER(HBAOChannel)
_FUNCTIONS = {
    "hbao_version": (ctypes.c_int32, []),
    "hbao_best_implementation": (ctypes.c_int32, []),
    "hbao_implementation_name": (ctypes.c_char_p, [ctypes.c_int32]),
    "hbao_result_message": (ctypes.c_char_p, [ctypes.c_int32]),
    "hbao_params_default": (None, [_PARAMS_P]),
    "hbao_params_resolve": (ctypes.c_int32, [_PARAMS_P, _PARAMS_P,
                                             ctypes.POINTER(ctypes.c_uint32)]),
    "hbao_param_field_name": (ctypes.c_char_p, [ctypes.c_uint32]),
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
    "hbao_release_memory": (None, []),
    "hbao_last_notes": (ctypes.c_uint32, []),
    "hbao_note_message": (ctypes.c_char_p, [ctypes.c_uint32]),
    "hbao_clip_background_depth": (ctypes.c_float, [ctypes.c_float] * 3),
    "hbao_compute_layers": (ctypes.c_int32, [_PARAMS_P, _CAMERA_P, ctypes.c_int32, ctypes.c_int32,
                                             _CHANNEL_P, _CHANNEL_P, _CHANNEL_P,
                                             ctypes.POINTER(ctypes.c_float), ctypes.c_int64]),
}


def _version_text(packed):
    return f"{packed // 10000}.{packed // 100 % 100}.{packed % 100}"


def _binding_calls(packed):
    """Whether this binding can call a library of packed version `packed`
    (HBAO_VERSION: major * 10000 + minor * 100 + patch)."""
    return (packed // 10000 == BINDING_VERSION_MAJOR
            and packed // 100 % 100 == BINDING_VERSION_MINOR)


_LIBRARY = library_loading.NativeLibrary(
    "hbao", LIBRARY_ENVIRONMENT_VARIABLE, Path(__file__).resolve().parent / "lib",
    _FUNCTIONS, HBAOLibraryError,
    handshake=library_loading.Handshake(
        "hbao_version", _binding_calls,
        f"{BINDING_VERSION_MAJOR}.{BINDING_VERSION_MINOR}.x",
        [("hbao_params", "hbao_params_size", HBAOParams),
         ("hbao_camera", "hbao_camera_size", HBAOCamera),
         ("hbao_view", "hbao_view_size", HBAOView)],
        describe=_version_text),
    load_hint="Rebuild it for this machine.")
#: The platform's file name of the library (libhbao.so on Linux).
LIBRARY_FILE_NAME = _LIBRARY.file_name


# The file that load_library() loads: $LIBRARY_ENVIRONMENT_VARIABLE, else
# lib/LIBRARY_FILE_NAME here; load_library() loads it once (raises HBAOLibraryError);
# unload_library() forgets it, so that the next call loads library_path() again.
library_path = _LIBRARY.path
load_library = _LIBRARY.load
unload_library = _LIBRARY.unload


def release_memory():
    """Let the library free the working memory it keeps between calls
    (hbao_release_memory); does not load it to do so."""
    library = _LIBRARY.loaded()
    if library is not None:
        library.hbao_release_memory()


def library_version():
    """The loaded library's version as 'major.minor.patch'."""
    return _version_text(load_library().hbao_version())


def search_name():
    """The horizon search this CPU runs ("AVX-512", "AVX2", "generic" where
    a CPU has no AVX2): a farm's nodes may differ."""
    library = load_library()
    return library.hbao_implementation_name(library.hbao_best_implementation()).decode("ascii")


def check(result):
    """Raises HBAOError with the library's message unless `result` is HBAO_SUCCESS."""
    if result != HBAO_SUCCESS:
        message = load_library().hbao_result_message(result)
        raise HBAOError(result, message.decode("utf-8", "replace") if message else "unknown")
