# SPDX-License-Identifier: GPL-2.0-or-later
"""Handing the main Render Result's passes to Python: taken from the main
engine's memory where pass_capture.py can; else, as Blender gives a Python
engine no access to another scene's Render Result pixels, by saving the
Render Result as a multilayer EXR, which libhbao_exr decodes straight into
numpy arrays."""
import os
from time import perf_counter as _clock

from . import (compat, exr_passes, output_settings, pass_capture, render_slots, render_threads,
               scratch_files, view_cameras, view_files)
from .report import log


# The channels of each pass read back, as Blender names them in a saved
# multilayer EXR: "<view layer>.<pass>.<axis>".
PASS_AXES = {"Depth": "Z", "Normal": "XYZ"}


def pass_channels(layer, pass_name):
    return [f"{layer}.{pass_name}.{axis}" for axis in PASS_AXES[pass_name]]


# Blender 3.4 saves a render with a single view left on (Stereoscopy) as
# one file whose channels carry the view's name ("<layer>.Depth.left.Z",
# view_files.py), cut past 63 bytes: measured, a 49-byte layer's
# "<layer>.Normal.left.X" reads back, a 50-byte one's does not (the AO was
# off, with a KeyError). 4.5 and later save such a view with the mono names;
# the versions between are untested, taken as 3.4.
SINGLE_VIEW_CHANNEL_NAME_MAX = 63 if compat.VERSION < (4, 5, 0) else None


def named_view(scene):
    """The view whose name a save of `scene`'s Render Result puts in its
    channel names (see above), or None."""
    views = view_cameras.rendered_views(scene)
    if SINGLE_VIEW_CHANNEL_NAME_MAX is None or views is None or len(views) != 1:
        return None
    return views[0][0]


def longest_layer_name(pass_name, view=None):
    """The most bytes a view layer's name may have for its pass `pass_name`
    to be read back (compat.EXR_CHANNEL_NAME_MAX; with the channels' `view`,
    named_view, SINGLE_VIEW_CHANNEL_NAME_MAX), or None: any."""
    if view is not None:
        channel = f".{pass_name}.{view}.{PASS_AXES[pass_name][0]}"
        return SINGLE_VIEW_CHANNEL_NAME_MAX - len(channel.encode())
    if compat.EXR_CHANNEL_NAME_MAX is None:
        return None
    return compat.EXR_CHANNEL_NAME_MAX - len(pass_channels("", pass_name)[0].encode())


class ScratchFolderError(RuntimeError):
    """The passes could not be saved in, or read back from, a scratch folder."""


def save_passes(scene, path, views=None):
    """Write `scene`'s current Render Result to `path`, uncompressed 32-bit
    multilayer EXR, leaving the scene's output settings as they were; a
    stereo render's `views` [(view name, file suffix)] as view_files.py says."""
    image = render_slots.render_result_image()
    if image is None:
        raise RuntimeError("Blender has no Render Result image to read the passes from")
    other = render_slots.other_slot_shown(scene)
    if other is not None:  # (Blender saves the slot shown)
        raise RuntimeError(f"the Image Editor shows render slot {other[0]} while this render "
                           f"writes slot {other[1]}, and Blender hands over the slot it shows; "
                           f"keep slot {other[1]} shown while a render runs")
    settings = scene.render.image_settings
    saved = output_settings.saved_image_settings(settings)
    saved_ffmpeg = output_settings.saved_ffmpeg_settings(scene.render)
    try:
        compat.set_multilayer_exr(settings)
        settings.color_depth = "32"
        settings.exr_codec = "NONE"
        # a file per view (3.4 and 4.5 refuse a mono save as Stereo 3D side by side)
        settings.views_format = "INDIVIDUAL"
        try:  # the Render Result of the scene given, not only its settings
            # Blender writes a str path as UTF-8 (surrogates: as os.fsencode
            # does); Python's os and libhbao_exr use os.fsencode: give
            # Blender the str that names the same bytes.
            image.save_render(os.fsencode(path).decode("utf-8", "surrogateescape"),
                              scene=scene)
        except RuntimeError as error:  # Blender's message names neither folder nor cause,
            # and 3.4 to 5.3 say that a multi-view save failed after writing every view
            if view_files.saved(path, views):
                return
            raise ScratchFolderError(
                f"cannot save the passes for the AO in {os.path.dirname(path)} ({error}); "
                f"{scratch_files.SCRATCH_FOLDER_VARIABLE} names a writable folder for them"
            ) from error
    finally:
        # The media type and format first, so that their options are valid
        # when they are set; the user's PNG output stays PNG; a movie's
        # container and codec after the format, which resets them (3.4).
        output_settings.restore_image_settings(settings, saved)
        output_settings.restore_ffmpeg_settings(scene.render, saved_ffmpeg)


def read_passes(scene, layers, views=None, threads=0):
    """{("depth", layer): (H, W), ("normal", layer): (H, W, 3)} float32, top
    row first, of `scene`'s Render Result, for `layers` {view layer name:
    whether its normal is wanted}; with `views` [(view name, file suffix)]
    of a stereo or multi-view render, {view name: those} instead; and the
    seconds the save and the read (by `threads`, 0: one per core) took.
    Taken from the engine's memory where pass_capture.py could ({"capture":
    seconds}), else saved in the first of scratch_files.folders() that
    takes the file."""
    # (files a killed Blender left: in the background, whichever way the
    # passes come; a process that takes them all from memory left them)
    scratch_files.remove_stale_now_and_then()
    taken = pass_capture.take(scene, layers, views)
    if taken is not None:
        channels, seconds = taken
        return channels, {"capture": seconds}
    scratch_files.wait_for_older_removals()
    folders = scratch_files.folders()
    for index, folder in enumerate(folders):
        try:
            channels, timings = _save_and_read(scene, layers, views, threads, folder)
            break
        except ScratchFolderError as error:
            if index + 1 == len(folders):
                raise
            log(f"{error}; saving them in {folders[index + 1]} instead")
    return channels[None] if views is None else channels, timings


# Blender's paths (FILE_MAX): a Render Result's save cut a longer one at
# 1023 bytes and wrote a file of that name, without the .exr that the
# removal of stale files looks for, every frame (a review's find).
BLENDER_PATH_BYTES = 1024


def _save_and_read(scene, layers, views, threads, folder):
    path = scratch_files.path_in(folder)
    files = view_files.files(path, views)
    timings = {}
    folder_failed = False
    try:
        if not os.path.isdir(folder):  # Blender's save would make it, and leave it
            raise ScratchFolderError(
                f"the scratch folder {folder} "
                f"{'is not a folder' if os.path.exists(folder) else 'does not exist'}; "
                f"{scratch_files.SCRATCH_FOLDER_VARIABLE} names existing folders for the passes")
        longest = max(len(os.fsencode(file)) for file in set(files.values()) | {path})
        if longest >= BLENDER_PATH_BYTES:  # it would cut the name and write that file
            raise ScratchFolderError(
                f"the scratch folder {folder}'s path is too long for Blender's save "
                f"({longest} bytes with the file's name; Blender takes {BLENDER_PATH_BYTES - 1}); "
                f"{scratch_files.SCRATCH_FOLDER_VARIABLE} names a shorter one")
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
            raise ScratchFolderError(
                f"cannot read back the passes saved in {folder} ({error}); is it full? "
                f"{scratch_files.SCRATCH_FOLDER_VARIABLE} names another folder for them"
            ) from error
        timings["read"] = _clock() - read_start
    except ScratchFolderError:
        folder_failed = True
        raise
    finally:
        paths = set(files.values()) | {path}
        if folder_failed:
            scratch_files.failed(folder, paths)
        else:
            for file in paths:
                scratch_files.remove_later(file)
    return channels, timings


def read_main_passes(main, jobs, views=None):
    """read_passes() of the view layers and normals that `jobs` read."""
    layers = {job.layer: any(other.with_normal for other in jobs if other.layer == job.layer)
              for job in jobs}
    return read_passes(main, layers, views, render_threads.count(main))
