# SPDX-License-Identifier: GPL-2.0-or-later
"""Writes a scene's camera, frame by frame, as the JSON that the `hbao` CLI
reads with --camera: for a sequence whose camera moves (or changes lens, or
is switched by markers), each frame needs its own.

    blender -b scene.blend [-S SCENE] --python scripts/export_cameras.py -- \\
        'cam_####.json' [--frames 1-250]
    hbao 'render_####.exr' -o 'ao_####.exr' --camera 'cam_####.json' --frames 1-250

The run of '#' (in the file's name, which ends in .json) is the frame
number, zero-padded to the run's length, as the CLI and Blender name frames.
Frames: as the CLI's --frames (1-250, 1-10,20,30-40, 1-250x2 for every second
frame); by default the scene's range and step. The scene is the
file's active one, or the one Blender's -S names (before --python). Each
frame's camera is the scene's at that frame, evaluated (animation,
constraints, parents, Time Remapping; with camera motion blur at the
middle of the shutter; a cropped border render's camera is the crop's), by
the add-on's own camera rule
(hbao.camera.camera_for_render_result). With Stereoscopy each view gets a
file of its own, named with the view's file suffix before `.json`
('cam_0001_L.json', as Blender names the view's render 'render_0001_L.exr'):
a Stereo 3D eye's camera as Blender places it, a Multi-View view's own
camera. A file that already holds what
would be written is left as it is, its time too, so that a rerun of the
CLI's sequence does not recompute that frame; the others are written whole
(a temporary file renamed over them; through a symbolic link, the file it
names), but for one the user may not write (read-only, or another user's),
which is refused. Exit status 2 for bad
arguments, 1 when a frame has no camera the CLI can use or a file cannot be
written.
"""
import argparse
import json
import math
import os
import re
import secrets
import stat
import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))
import frame_lists  # noqa: E402
from blender_arguments import (  # noqa: E402
    ArgumentError, ArgumentParser, end_blender, script_arguments)

try:
    import hbao  # noqa: F401  (the enabled add-on, or this checkout's below)
except ImportError:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "addon"))
from hbao import camera as camera_model  # noqa: E402
from hbao import camera_time, compat, stereo_eyes, view_cameras, view_files  # noqa: E402

EXIT_BAD_ARGUMENTS = 2
EXIT_FAILED = 1


def frame_list(text):
    """frame_lists.parse() for argparse."""
    try:
        return frame_lists.parse(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from error


def frame_path(pattern, frame):
    """`pattern` with its last '#' run replaced by `frame`, zero-padded to
    the run's length (a longer number in full), as the CLI names frames."""
    runs = list(re.finditer(r"#+", pattern))
    run = runs[-1]
    return pattern[:run.start()] + f"{frame:0{len(run.group())}d}" + pattern[run.end():]


def arguments():
    argv = script_arguments()
    parser = ArgumentParser(prog="export_cameras.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("pattern", help="output name with a run of '#' for the frame number")
    parser.add_argument("--frames", type=frame_list, help="frames to write (default: the "
                        "scene's range)")
    parsed = parser.parse_args(argv)
    name = os.path.basename(parsed.pattern)
    # The CLI takes a camera per frame only from a '#' in the file's name
    # (csrc/tool/sequence_command.c, per_frame_camera); and a camera file is
    # JSON: a render's name given by mistake must not be written over.
    if "#" not in name:
        raise ArgumentError(f"{parsed.pattern!r} needs a run of '#' for the frame number in "
                            f"its file name, e.g. cam_####.json")
    if not name.lower().endswith(".json"):
        raise ArgumentError(f"{parsed.pattern!r}: camera files end in .json (a render's name "
                            f"given by mistake would be written over)")
    return parsed


def scene_frames(scene):
    if scene.frame_start < 0:
        raise ArgumentError(f"the scene's range starts at frame {scene.frame_start}: the CLI "
                            f"takes frames from 0; give --frames")
    return list(range(scene.frame_start, scene.frame_end + 1, scene.frame_step))


STEREO_SETTINGS = ("interocular_distance", "convergence_distance", "convergence_mode", "pivot")


def cameras_at(scene, frame):
    """{view's file suffix: camera description} of `frame` ("" alone
    without Stereoscopy): the scene camera evaluated at the time the frame's
    passes show it (hbao.camera_time: with camera motion blur, the
    middle of the shutter, as the node takes it; the camera object is the
    frame's, which markers may switch); a Stereo 3D eye's as Blender places
    it (hbao.stereo_eyes), a Multi-View view's through its own camera."""
    scene.frame_set(frame)
    camera = scene.camera
    if camera is None:
        raise camera_model.CameraError(f"scene {scene.name!r} has no camera at frame {frame}")
    time = camera_time.of(scene)
    if time != frame:
        whole = math.floor(time)
        scene.frame_set(whole, subframe=time - whole)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    views = view_cameras.rendered_views(scene)
    # the camera of the image written: a cropped border's own
    if views is None:
        return {"": camera_model.camera_for_render_result(scene, camera.evaluated_get(depsgraph))}
    found = {}
    for name, suffix in views:
        if len(views) == 1 and compat.SINGLE_VIEW_WITHOUT_SUFFIX:  # as Blender names the render
            suffix = ""
        if scene.render.views_format == "MULTIVIEW":
            seen = view_cameras.multiview_camera(scene, camera, name).evaluated_get(depsgraph)
            found[suffix] = camera_model.camera_for_render_result(scene, seen)
            continue
        seen = camera.evaluated_get(depsgraph)
        stereo = {key: getattr(seen.data.stereo, key) for key in STEREO_SETTINGS}
        eye = stereo_eyes.eye(camera_model.camera_from_blender(scene, seen), stereo,
                              left=name != "right")
        found[suffix] = camera_model.camera_for_render_result(scene, description=eye)
    return found


def _new_file_beside(path):
    """A new, hidden file in `path`'s folder, opened for writing, and its
    path. Not tempfile.mkstemp(), which makes it its owner's only (0600),
    whatever the folder's default ACL grants a farm's other users; opened
    as any program opens a new file (0666), the kernel applies the umask or
    that ACL."""
    for _attempt in range(100):
        temporary = path.parent / f".export-cameras-{secrets.token_hex(4)}"
        try:
            return os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666), temporary
        except FileExistsError:
            continue
    raise FileExistsError(f"no free temporary name in {path.parent}")


def write_if_changed(path, text):
    """Write `text` to `path` whole, unless it already holds it. Returns
    whether it was written. A symbolic link is written through, as the CLI
    writes its outputs: the file it names is replaced (made, where there is
    none yet), and the link stays."""
    target = Path(os.path.realpath(path))
    try:
        if target.read_text(encoding="utf-8") == text:
            return False
    except (FileNotFoundError, UnicodeDecodeError, PermissionError):
        pass  # (one it may not read is written, if it may write it, or refused below)
    target.parent.mkdir(parents=True, exist_ok=True)
    try:
        kept_mode = stat.S_IMODE(target.stat().st_mode)
    except FileNotFoundError:
        kept_mode = None
    # One the user may not write (a camera approved and made read-only, or
    # another user's) is refused, as the CLI refuses such an output and
    # open() for writing would: the rename would replace it all the same,
    # its folder being writable. (root may write any.)
    if kept_mode is not None and not os.access(target, os.W_OK):
        raise PermissionError(f"{path} is not writable (read-only, or another user's): "
                              "refusing to replace it (make it writable, or remove it, if it "
                              "is to go)")
    descriptor, temporary = _new_file_beside(target)
    try:
        # A new file has the permissions the kernel gives any new file there
        # (the umask, or the folder's default ACL: a farm's shared folder);
        # a file it replaces keeps its own.
        if kept_mode is not None:
            os.fchmod(descriptor, kept_mode)
        with os.fdopen(descriptor, "w", encoding="utf-8") as stream:
            stream.write(text)
        os.replace(temporary, target)
    except BaseException:
        os.unlink(temporary)
        raise
    return True


def main():
    try:
        parsed = arguments()
        scene = bpy.context.scene
        frames = parsed.frames if parsed.frames is not None else scene_frames(scene)
    except ArgumentError as error:
        print(f"export_cameras.py: error: {error}", file=sys.stderr)
        return EXIT_BAD_ARGUMENTS
    except SystemExit as done:  # --help
        return done.code or 0
    written = files = 0
    try:
        for frame in frames:
            for suffix, camera in cameras_at(scene, frame).items():
                text = json.dumps(camera, indent=2) + "\n"
                path = view_files.view_path(frame_path(parsed.pattern, frame), suffix)
                written += write_if_changed(Path(path), text)
                files += 1
    except (camera_model.CameraError, OSError) as error:
        print(f"export_cameras.py: error: {error}", file=sys.stderr)
        return EXIT_FAILED
    print(f"export_cameras.py: {len(frames)} frames, {written} files written, "
          f"{files - written} already up to date")
    return 0


if __name__ == "__main__":
    end_blender(main())
