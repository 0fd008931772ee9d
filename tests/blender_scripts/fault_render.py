# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_faults.py: addon_render.py with one
fault set up first, by a render_pre handler registered after the add-on's
(so it acts after the hook synced) or in the scratch folder.

  blender -b --addons hbao --python fault_render.py -- '<json spec>' <out dir> <fault>

Faults:
  unreadable_save   the scratch path (HBAO_TEMP_DIR/hbao-passes-<pid>-<thread>-0-...,
                    known here: a -b render runs in this thread, and its first
                    hand-over saves the process's first scratch file) is a link
                    to /dev/null: the save "succeeds", the file read back is
                    empty.
  interrupted       the hand-over raises KeyboardInterrupt (what Ctrl-C does
                    to a bpy render while Python runs): the frame must not
                    get the zeros of an unfilled pass (a black image).
  helper_resized    after the hook synced the helper scene, its
                    resolution_percentage is halved (meant to make its pass
                    smaller than the Render Result; Blender renders it at full
                    size anyway).
"""
import os
import runpy
import sys
import threading

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
fault = argv[2]
RENDER_SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "addon_render.py")


def helper_scenes():
    return [s for s in bpy.data.scenes if s.name.startswith(".HBAO") or s.get("hbao_main_scene")]


if fault == "unreadable_save":
    # The add-on's own naming (scratch_files.path_in): the test checks the
    # link is gone afterwards, so a changed name fails it rather than passing.
    scratch_files = sys.modules["hbao.scratch_files"]
    link = os.path.join(os.environ["HBAO_TEMP_DIR"], sys.modules["hbao.scratch_names"].name(
        os.getpid(), threading.get_ident(), 0, scratch_files._space, scratch_files._run))
    os.symlink("/dev/null", link)
    print("FAULT link", link, flush=True)
elif fault == "helper_resized":
    @bpy.app.handlers.persistent
    def _resize_helper(scene, *_args):
        for helper in helper_scenes():
            if helper != scene and helper.render.resolution_percentage == 100:
                helper.render.resolution_percentage = 50
                print("FAULT resized", helper.name, flush=True)

    bpy.app.handlers.render_pre.append(_resize_helper)
elif fault == "interrupted":
    handover = sys.modules["hbao.handover"]
    save_passes = handover.save_passes

    def _interrupted_save(*args, **kwargs):
        handover.save_passes = save_passes  # once
        print("FAULT interrupted", flush=True)
        raise KeyboardInterrupt

    handover.save_passes = _interrupted_save
else:
    raise ValueError(f"unknown fault {fault!r}")

runpy.run_path(RENDER_SCRIPT, run_name="__main__")
