# SPDX-License-Identifier: GPL-2.0-or-later
"""Finding and loading the add-on's native libraries (libhbao, libhbao_exr):
once, lazily and thread-safely, with every function's signature declared in
one place and errors that say what to do. No bpy."""
import ctypes
import os
import threading
from pathlib import Path


class NativeLibrary:
    """One shared library: $<environment_variable> if set, else
    <folder>/<file_name>. `functions` maps names to (restype, argtypes);
    `check(library, path)` may raise `error_class` for an incompatible one."""

    def __init__(self, file_name, environment_variable, folder, functions, error_class,
                 check=None, load_hint=""):
        self.file_name = file_name
        self.environment_variable = environment_variable
        self.default_path = Path(folder) / file_name
        self.functions = functions
        self.error_class = error_class
        self.check = check
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

    def unload(self):
        """Forget the loaded library so that the next load() reads path() again."""
        with self._lock:
            self._library = None

    def _open(self, path):
        name = self.file_name.rsplit(".so", 1)[0]
        if not path.is_file():
            raise self.error_class(
                f"{name} not found at {path}. Build it with `cmake -S . -B build && cmake "
                f"--build build` and copy build/{self.file_name} to {self.default_path.parent}/ "
                f"(scripts/install_addon.sh does both), or set {self.environment_variable} "
                f"to its path.")
        try:
            library = ctypes.CDLL(str(path))
        except OSError as error:
            raise self.error_class(f"{name} at {path} could not be loaded: {error}. "
                                   f"{self.load_hint}") from error
        for function_name, (restype, argtypes) in self.functions.items():
            try:
                function = getattr(library, function_name)
            except AttributeError as error:
                raise self.error_class(
                    f"{name} at {path} lacks {function_name}(): it is not a compatible "
                    f"{name}; rebuild it from this add-on's sources.") from error
            function.restype = restype
            function.argtypes = argtypes
        if self.check is not None:
            self.check(library, path)
        return library
