# SPDX-License-Identifier: GPL-2.0-or-later
"""The part of Blender's background command line our scripts and tests use,
for Blender as a Python module (PyPI's `bpy`), which has no command line of
its own. Run it with the Python of a bpy install:

  python bpy_blender.py [BLEND] [--addons hbao] [-o PATH] [-f N | -s S -e E -a]
                        [--python SCRIPT] [-- ARGS...]

It does what `blender -b --factory-startup BLEND ...` does with the same
options, in the same order: open BLEND, enable the add-ons, then render a
frame (-f) or the animation (-a) to -o, or run SCRIPT with sys.argv ending in
`-- ARGS` as Blender passes them. A script's exception exits 1, like
`--python-exit-code 1`; SystemExit keeps its code.
"""
import argparse
import os
import re
import runpy
import shutil
import sys
import threading
import time
import traceback


def parse(argv):
    if "--" in argv:
        split = argv.index("--")
        argv, script_args = argv[:split], argv[split + 1:]
    else:
        script_args = []
    parser = argparse.ArgumentParser(prog="bpy_blender.py")
    parser.add_argument("blend", nargs="?")
    parser.add_argument("--addons", default="")
    parser.add_argument("-o", "--render-output")
    parser.add_argument("-f", "--render-frame", type=int)
    parser.add_argument("-s", "--frame-start", type=int)
    parser.add_argument("-e", "--frame-end", type=int)
    parser.add_argument("-a", "--render-anim", action="store_true")
    parser.add_argument("--python", dest="script")
    return parser.parse_args(argv), script_args


def main(argv):
    options, script_args = parse(argv)
    import bpy  # after parsing: --help works without loading Blender
    import addon_utils

    bpy.ops.wm.read_factory_settings(use_empty=False)
    for name in filter(None, options.addons.split(",")):
        if addon_utils.enable(name, default_set=True) is None:
            print(f"bpy_blender.py: add-on {name!r} could not be enabled", file=sys.stderr)
            return 1
    # Opened after enabling the add-ons, so that their load_post handlers see
    # the file, as with `blender -b FILE --addons ...`.
    if options.blend:
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(options.blend), load_ui=False)
    scene = bpy.context.scene
    if options.render_output:
        scene.render.filepath = options.render_output
    if options.frame_start is not None:
        scene.frame_start = options.frame_start
    if options.frame_end is not None:
        scene.frame_end = options.frame_end
    if options.render_frame is not None:
        scene.frame_set(options.render_frame)
        # Blender's -f names the file from the frame, as an animation does.
        path = scene.render.frame_path(frame=options.render_frame)
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        print(f"Saved: '{path}'", flush=True)
    if options.render_anim:
        bpy.ops.render.render(animation=True)
    if options.script:
        sys.argv = [options.script, "--"] + script_args
        try:
            runpy.run_path(options.script, run_name="__main__")
        except SystemExit as exit_request:
            code = exit_request.code
            return code if isinstance(code, int) else (0 if code is None else 1)
        except Exception:
            traceback.print_exc()
            return 1
    return 0


def wait_for_python_threads(timeout_s=60.0):
    """What Python's own shutdown does first, and Blender's WM_exit with it:
    wait for the threads that are not daemons (the add-on removes its scratch
    files in such threads)."""
    deadline = time.monotonic() + timeout_s
    for thread in threading.enumerate():
        if thread is not threading.current_thread() and not thread.daemon:
            thread.join(max(0.0, deadline - time.monotonic()))


def remove_session_temp_folder():
    """Blender's WM_exit removes the folder it made for its session
    (bpy.app.tempdir, "blender_XXXXXX" in TMPDIR); this stand-in leaves
    through os._exit, which would leave one such folder per run. Where
    Blender could not make one, bpy.app.tempdir is the base folder itself,
    which is left alone: only a folder named as Blender names a session's
    is removed."""
    bpy = sys.modules.get("bpy")
    folder = os.path.normpath(bpy.app.tempdir) if bpy is not None and bpy.app.tempdir else ""
    if re.fullmatch(r"blender_[A-Za-z0-9]{6}", os.path.basename(folder)) \
            and os.path.isdir(folder) and not os.path.islink(folder):
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    status = main(sys.argv[1:])
    wait_for_python_threads()
    remove_session_temp_folder()
    # bpy 4.5's module can deadlock in its C++ static destructors at exit
    # (its delayed file-close thread still waits on the condition variable
    # being destroyed; seen after a render whose render_pre handler changed
    # another scene's resolution). Blender itself exits through WM_exit; this
    # stand-in has written everything by now, so it leaves without running
    # the destructors, as Blender's own exit() after WM_exit would.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
