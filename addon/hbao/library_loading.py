# SPDX-License-Identifier: GPL-2.0-or-later
"""Finding and loading the add-on's native libraries (libhbao, libhbao_exr):
once, lazily and thread-safely, with every function's signature declared in
one place, one compatibility handshake, and errors that say what to do. No bpy."""
import ctypes
import os
import sys
import threading
from pathlib import Path


def library_file_name(stem, platform=None):
    """The file CMake builds for shared library `stem` ("hbao") on `platform`
    (default: this one): libhbao.so, libhbao.dylib, or hbao.dll (MSVC builds
    have no "lib" prefix)."""
    platform = sys.platform if platform is None else platform
    if platform.startswith("win"):
        return f"{stem}.dll"
    if platform == "darwin":
        return f"lib{stem}.dylib"
    return f"lib{stem}.so"


def mapped_from_a_replaced_file(path, maps="/proc/self/maps"):
    """Whether this process has `path` mapped from a file that has been
    replaced since (its device and inode are no longer those of the file the
    path names): an add-on updated while Blender runs. The dynamic loader
    hands back a library already loaded under the same path without looking
    at the file, so the old code would run with the new add-on. False where
    `path` is not mapped, or where this system has no such list."""
    try:
        status = os.stat(path)
        name = os.path.realpath(path)  # as the system lists it
        with open(maps, encoding="utf-8", errors="replace") as lines:
            for line in lines:
                fields = line.rstrip("\n").split(maxsplit=5)
                if len(fields) < 6 or fields[5].removesuffix(" (deleted)") != name:
                    continue
                major, minor = (int(number, 16) for number in fields[3].split(":"))
                return (int(fields[4]), major, minor) != (
                    status.st_ino, os.major(status.st_dev), os.minor(status.st_dev))
    except (OSError, ValueError):
        pass
    return False


class Handshake:
    """What a library must report to match its binding: `version_function()`
    must give a value that `accepts(value)` holds true (`expected_text` says
    which, in messages; `describe(value)` prints a version), and each
    (C type name, size function, ctypes structure) of `structures` must have
    the structure's size, or the library and the binding disagree on memory
    layout. The version is asked before any other function is looked up, so
    that an older library, which lacks the newer functions, is named by its
    version."""

    def __init__(self, version_function, accepts, expected_text, structures, describe=str):
        self.version_function = version_function
        self.accepts = accepts
        self.expected_text = expected_text
        self.structures = structures
        self.describe = describe

    def check_version(self, version, path, name, error_class):
        if not self.accepts(version):
            raise error_class(
                f"{name} at {path} is version {self.describe(version)}, this add-on needs "
                f"{self.expected_text}: install the library that came with the add-on.")

    def check_structures(self, library, path, name, error_class):
        for c_type, size_function, structure in self.structures:
            size = getattr(library, size_function)()
            if size != ctypes.sizeof(structure):
                raise error_class(
                    f"{name} at {path}: sizeof({c_type}) is {size} bytes, the add-on "
                    f"expects {ctypes.sizeof(structure)}: the library and add-on come from "
                    f"different versions; reinstall both together.")


class NativeLibrary:
    """One shared library: $<environment_variable> if set, else
    <folder>/<platform file name of stem>. `functions` maps names to
    (restype, argtypes); `handshake` (a Handshake) rejects an incompatible
    library with `error_class`."""

    def __init__(self, stem, environment_variable, folder, functions, error_class,
                 handshake=None, load_hint=""):
        self.name = f"lib{stem}"
        self.file_name = library_file_name(stem)
        self.environment_variable = environment_variable
        self.default_path = Path(folder) / self.file_name
        self.functions = functions
        self.error_class = error_class
        self.handshake = handshake
        self.load_hint = load_hint
        self._library = None
        self._lock = threading.Lock()

    def path(self):
        """The file that load() loads."""
        override = os.environ.get(self.environment_variable)
        return Path(override) if override else self.default_path

    def load(self):
        """The loaded library (loaded on the first call). Raises error_class."""
        with self._lock:
            if self._library is None:
                self._library = self._open(self.path())
            return self._library

    def loaded(self):
        """The library if load() has loaded it, else None (loads nothing)."""
        with self._lock:
            return self._library

    def unload(self):
        """Forget the loaded library so that the next load() reads path() again."""
        with self._lock:
            self._library = None

    def _open(self, path):
        name = self.name
        given = os.environ.get(self.environment_variable)
        if given and not path.is_file():
            # the artist's or pipeline's variable, not the add-on, is wrong
            what = "is a folder, not a file" if path.is_dir() else "does not exist"
            raise self.error_class(
                f"{path}, which {self.environment_variable} names, {what}. Point "
                f"{self.environment_variable} at a built {self.file_name}, or unset it to use "
                f"the add-on's own copy of {name}.")
        if not path.is_file():
            raise self.error_class(
                f"{name} not found at {path}: the add-on is incomplete. Reinstall it from its "
                f"zip, which carries the library; from a source checkout, "
                f"scripts/install_addon.sh builds and installs it (or build it with CMake and "
                f"set {self.environment_variable} to build/{self.file_name}).")
        if mapped_from_a_replaced_file(path):
            raise self.error_class(
                f"{name} at {path} was replaced since Blender loaded it (the add-on was updated "
                f"while Blender runs), and Blender keeps the old library until it quits: restart "
                f"Blender to finish the update.")
        try:
            library = ctypes.CDLL(str(path))
        except OSError as error:
            raise self.error_class(f"{name} at {path} could not be loaded: {error}. "
                                   f"{self.load_hint}") from error
        # The version first (the handshake's function is declared with the
        # others), then every function, then the structures' sizes.
        names = list(self.functions)
        if self.handshake is not None:
            names.remove(self.handshake.version_function)
            self._bind(library, path, self.handshake.version_function)
            version = getattr(library, self.handshake.version_function)()
            self.handshake.check_version(version, path, name, self.error_class)
        for function_name in names:
            self._bind(library, path, function_name)
        if self.handshake is not None:
            self.handshake.check_structures(library, path, name, self.error_class)
        return library

    def _bind(self, library, path, function_name):
        """Declares `function_name`'s types on `library`; error_class where it lacks it."""
        restype, argtypes = self.functions[function_name]
        try:
            function = getattr(library, function_name)
        except AttributeError as error:
            raise self.error_class(
                f"{self.name} at {path} lacks {function_name}(): it is not a compatible "
                f"{self.name}; rebuild it from this add-on's sources.") from error
        function.restype = restype
        function.argtypes = argtypes
