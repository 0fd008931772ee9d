# SPDX-License-Identifier: GPL-2.0-or-later
"""Handing the main Render Result's passes to Python: Blender gives a
Python engine no access to another scene's Render Result pixels, but it can
save the Render Result as a multilayer EXR, which libhbao_exr decodes
straight into numpy arrays."""
import contextlib
import itertools
import os
import tempfile
import threading
import time
from time import perf_counter as _clock

import bpy

from . import compat, exr_passes, render_threads, scratch_names, view_files
from .report import log


def _render_result_image():
    for image in bpy.data.images:
        if image.type == "RENDER_RESULT":
            return image
    return None


# Environment variable naming the folder for the scratch EXR instead.
SCRATCH_FOLDER_VARIABLE = "HBAO_TEMP_DIR"


# Each scratch file its own number: the last one may still be being removed
# (_remove_later) when the next is saved.
_scratch_numbers = itertools.count()


def _scratch_folder():
    # Memory-backed where there is one: the file lives for milliseconds.
    folder = os.environ.get(SCRATCH_FOLDER_VARIABLE)
    if not folder:
        folder = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) \
            else tempfile.gettempdir()
    return folder


# The channels of each pass read back, as Blender names them in a saved
# multilayer EXR: "<view layer>.<pass>.<axis>".
PASS_AXES = {"Depth": "Z", "Normal": "XYZ"}


def pass_channels(layer, pass_name):
    return [f"{layer}.{pass_name}.{axis}" for axis in PASS_AXES[pass_name]]


def longest_layer_name(pass_name):
    """The most bytes a view layer's name may have for its pass `pass_name`
    to be read back (compat.EXR_CHANNEL_NAME_MAX), or None: any."""
    if compat.EXR_CHANNEL_NAME_MAX is None:
        return None
    return compat.EXR_CHANNEL_NAME_MAX - len(pass_channels("", pass_name)[0].encode())


def _scratch_path():
    return os.path.join(_scratch_folder(), scratch_names.name(
        os.getpid(), threading.get_ident(), next(_scratch_numbers)))


def _process_ended(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except (OSError, OverflowError):  # another user's (alive), or no process id at all
        return False
    return False


# A scratch file lives for a second at most; one this old is left over.
STALE_AGE_S = 600


def remove_stale_scratch_files():
    """Remove the scratch files of Blender processes that have ended: one
    killed while it handed passes over, or a bpy script that ended by
    os._exit before its removal thread was done. Only files older than
    STALE_AGE_S: a process of another PID namespace that shares the folder
    looks ended from here, but its files are never that old. A file of a
    running process, or one this user may not remove, is left alone.
    Returns the paths removed."""
    folder = _scratch_folder()
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    now = time.time()
    for name in names:
        process = scratch_names.process_of(name)
        if process is None or not _process_ended(process):
            continue
        path = os.path.join(folder, name)
        try:
            if now - os.stat(path).st_mtime < STALE_AGE_S:
                continue
            os.remove(path)
            removed.append(path)
        except OSError:
            pass
    return removed


_stale_files_checked = False


def _remove(path):
    try:
        os.remove(path)
    except FileNotFoundError:
        pass
    except OSError as error:
        log(f"could not remove the scratch file {path}: {error}")


# The removals started and not yet waited for.
_removals = []
_removals_lock = threading.Lock()


def _in_background(removal, *args):
    """removal(*args) in a thread of its own, counted among the removals
    that the next save waits for. Freeing a large file's pages is the
    kernel's work, and long: a 1920x1080 render with 81 channels, 672 MB,
    took 115 ms on tmpfs (docs/speed.md, session 19), which the render need
    not wait for (nor the AO share the cores with: removals_after). Not a
    daemon thread: Python waits for it before the process ends, so no
    scratch file outlives Blender (a process that ends by os._exit skips
    that wait: scripts/bpy_blender.py waits first). Where no thread can be
    started (the process has run out of them), it runs at once, and the
    render waits for it."""
    thread = threading.Thread(target=removal, args=args, name="hbao-scratch-removal")
    try:
        thread.start()
    except RuntimeError as error:
        log(f"removing scratch files in the render's own thread: {error}")
        removal(*args)
        return
    with _removals_lock:
        _removals.append(thread)


# The scratch files whose removal waits for the end of a removals_after()
# block of this thread; None outside one.
_deferred = threading.local()


def _remove_later(path):
    """Remove `path` in the background (_in_background), or at the end of
    the removals_after() block this thread is in."""
    waiting = getattr(_deferred, "paths", None)
    if waiting is not None:
        waiting.append(path)
    else:
        _in_background(_remove, path)


@contextlib.contextmanager
def removals_after():
    """Within the block, the hand-over's scratch files are removed only when
    it ends (however it ends), all of them by one removal in the background.
    The engine computes the AO in such a block: the removal's kernel work
    then runs beside what Blender does after the AO, not beside the AO's
    threads, which keep every core busy (docs/speed.md, session 23). A
    block within a block of the same thread leaves its files to the outer
    one; other threads' removals are not held back."""
    outer = getattr(_deferred, "paths", None)
    _deferred.paths = [] if outer is None else outer
    try:
        yield
    finally:
        if outer is None:
            waiting, _deferred.paths = _deferred.paths, None
            if waiting:
                _in_background(_remove_all, waiting)


def _remove_all(paths):
    for path in paths:
        _remove(path)


def _remove_stale_files():
    for stale in remove_stale_scratch_files():
        log(f"removed {stale}, left by a Blender that has ended")


def _wait_for_older_removals():
    """Before the next save: every removal but the latest done, so that
    besides the files being saved and read, only the latest removal's may
    still exist (a frame's, up to three with a guard band and back faces:
    removals_after), however quickly frames follow each other; a frame's
    second save (a guard band's, a back face layer's) does not wait for the
    removal before it."""
    with _removals_lock:
        older = _removals[:-1]
        del _removals[:-1]
    for thread in older:
        thread.join()


def save_passes(scene, path, views=None):
    """Write `scene`'s current Render Result to `path`, uncompressed 32-bit
    multilayer EXR, leaving the scene's output settings as they were; a
    stereo render's `views` [(view name, file suffix)] as view_files.py says."""
    image = _render_result_image()
    if image is None:
        raise RuntimeError("Blender has no Render Result image to read the passes from")
    settings = scene.render.image_settings
    saved = compat.saved_image_settings(settings)
    try:
        compat.set_multilayer_exr(settings)
        settings.color_depth = "32"
        settings.exr_codec = "NONE"
        # a file per view (3.4 and 4.5 refuse a mono save as Stereo 3D side by side)
        settings.views_format = "INDIVIDUAL"
        try:  # the Render Result of the scene given, not only its settings
            image.save_render(path, scene=scene)
        except RuntimeError as error:  # Blender's message names neither folder nor cause,
            # and 3.4 to 5.3 say that a multi-view save failed after writing every view
            if view_files.saved(path, views):
                return
            raise RuntimeError(
                f"cannot save the passes for the AO in {os.path.dirname(path)} ({error}); "
                f"{SCRATCH_FOLDER_VARIABLE} names a writable folder for them") from error
    finally:
        # The media type and format first, so that their options are valid
        # when they are set; the user's PNG output stays PNG.
        compat.restore_image_settings(settings, saved)


def read_passes(scene, layers, views=None, threads=0):
    """{("depth", layer): (H, W), ("normal", layer): (H, W, 3)} float32, top
    row first, of `scene`'s Render Result, for `layers` {view layer name:
    whether its normal is wanted}; with `views` [(view name, file suffix)]
    of a stereo or multi-view render, {view name: those} instead; and the
    seconds the save and the read (by `threads`, 0: one per core) took."""
    global _stale_files_checked
    if not _stale_files_checked:  # a process's first hand-over, which need not wait for it
        _stale_files_checked = True
        _in_background(_remove_stale_files)
    _wait_for_older_removals()
    channels, timings = _save_and_read(scene, layers, views, threads)
    return channels[None] if views is None else channels, timings


def _save_and_read(scene, layers, views, threads):
    path = _scratch_path()
    files = view_files.files(path, views)
    timings = {}
    try:
        start = _clock()
        save_passes(scene, path, views)
        timings["save"] = _clock() - start
        files = view_files.files(path, views)
        # One decode pass: each layer's depth, its normal as one (H, W, 3) image.
        groups = {}
        for layer, with_normal in layers.items():
            groups[("depth", layer)] = pass_channels(layer, "Depth")
            if with_normal:
                groups[("normal", layer)] = pass_channels(layer, "Normal")
        read_start = _clock()
        try:
            channels = {view: exr_passes.read_channel_groups(
                file, view_files.channel_groups(file, view, groups), threads)
                for view, file in files.items()}
        except (exr_passes.EXRFormatError, exr_passes.EXRFileError) as error:
            # Blender's save does not say when the folder filled up: the
            # file is then cut short.
            raise RuntimeError(
                f"cannot read back the passes saved in {os.path.dirname(path)} ({error}); is "
                f"it full? {SCRATCH_FOLDER_VARIABLE} names another folder for them") from error
        timings["read"] = _clock() - read_start
    finally:
        for file in set(files.values()) | {path}:
            _remove_later(file)
    return channels, timings


def read_main_passes(main, jobs, views=None):
    """read_passes() of the view layers and normals that `jobs` read."""
    layers = {job.layer: any(other.with_normal for other in jobs if other.layer == job.layer)
              for job in jobs}
    return read_passes(main, layers, views, render_threads.count(main))
