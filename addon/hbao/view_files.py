# SPDX-License-Identifier: GPL-2.0-or-later
"""Where saving a stereo or multi-view Render Result writes each view, and
under which channel names (handover.py). bpy-free.

Blender writes a file per view, the view's file suffix before the extension
(render_L.exr), with the mono channel names ("ViewLayer.Depth.Z"); 3.4 writes
a render with a single view left on to the path itself, naming the channels
with the view ("ViewLayer.Depth.left.Z")."""
import os

from . import exr_passes


def view_path(path, file_suffix):
    """Where a stereo render's save to `path` writes a view."""
    stem, extension = os.path.splitext(path)
    return stem + file_suffix + extension


def files(path, views):
    """{view name: the file a save to `path` writes it to} for `views`
    [(view name, file suffix)], or {None: path} for views None (mono)."""
    if views is None:
        return {None: path}
    for name, suffix in views:  # the save, and then the removal, would reach another folder
        if "/" in suffix or os.sep in suffix:
            raise ValueError(f"view {name!r}'s file suffix {suffix!r} holds a folder separator: "
                             f"no AO for its render (Output properties > Views)")
    found = {name: view_path(path, suffix) for name, suffix in views}
    if len(found) == 1 and not os.path.exists(*found.values()) and os.path.exists(path):
        return dict.fromkeys(found, path)
    return found


def saved(path, views):
    """Whether a save to `path` that Blender said failed wrote every view
    (it says so in 3.4 to 5.3 after writing them)."""
    return views is not None and all(os.path.exists(file) for file in files(path, views).values())


def channel_groups(file, view, groups):
    """`groups` {key: [channel names]} as `file` names them: with the view's
    name before the last part where the file has only such names."""
    if view is None:
        return groups
    names = set(exr_passes.channel_names(file))
    if all(name in names for channels in groups.values() for name in channels):
        return groups

    def in_view(name):
        stem, _dot, last = name.rpartition(".")
        return f"{stem}.{view}.{last}"

    return {key: [in_view(name) for name in channels] for key, channels in groups.items()}
