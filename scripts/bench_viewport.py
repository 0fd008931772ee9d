#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Benchmark of the viewport preview's frame time at 1280x720 and 1920x1080.

    scripts/bench_viewport.py [--repeats N] [--backend-check] [--no-xvfb]
                              [--blender PATH] [--json OUT]

Starts Blender with a window (under xvfb-run unless --no-xvfb: on a machine
with a display and a real GPU, pass --no-xvfb so that Blender uses that GPU)
and this checkout's add-on with the libraries of its build (brought up to
date first, in HBAO_BUILD_DIR or build/, unless HBAO_LIBRARY and
HBAO_EXR_LIBRARY name libraries), and runs scripts/bench_viewport_blender.py, which
prints the renderer and a table of median milliseconds per frame: the scene
drawn by Blender, the depth read-back + upload alone, the whole preview with
the default blur and without blur. --backend-check only prints the renderer
(gpu.platform.renderer_get()), to see which GPU Blender would use.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

# scripts/blenders.py, beside this one
from blenders import NO_SPLASH, user_folders, user_scripts_with_addon

REPO = Path(__file__).resolve().parents[1]
INNER = REPO / "scripts" / "bench_viewport_blender.py"
# Large enough for a 1920x1080 window plus Blender's UI around the view.
XVFB_SCREEN = "-screen 0 2048x1280x24"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--backend-check", action="store_true")
    parser.add_argument("--no-xvfb", action="store_true")
    parser.add_argument("--blender", default=os.environ.get("BLENDER", "blender"))
    parser.add_argument("--json")
    args = parser.parse_args()
    blender = shutil.which(args.blender)
    if blender is None:
        sys.exit(f"blender not found ({args.blender}); pass --blender PATH")
    # The source add-on has no lib/ folder: it loads this checkout's build,
    # brought up to date here (as scripts/demo.sh does), unless the
    # environment names both libraries.
    build = Path(os.environ.get("HBAO_BUILD_DIR", REPO / "build"))
    libraries = {"HBAO_LIBRARY": build / "libhbao.so", "HBAO_EXR_LIBRARY": build / "libhbao_exr.so"}
    if not all(name in os.environ for name in libraries):
        steps = [["cmake", "--build", str(build), "-j2", "--target", "hbao", "hbao_exr"]]
        if not (build / "CMakeCache.txt").is_file():
            steps.insert(0, ["cmake", "-S", str(REPO), "-B", str(build),
                             "-DCMAKE_BUILD_TYPE=Release"])
        for step in steps:
            if shutil.which(step[0]) is None:
                sys.exit("cmake not found: run scripts/setup.sh, or set HBAO_LIBRARY and "
                         "HBAO_EXR_LIBRARY to built libraries")
            if subprocess.run(step, stdout=subprocess.DEVNULL).returncode != 0:
                sys.exit(f"building the libraries failed: {' '.join(step)}")
    with tempfile.TemporaryDirectory() as folder:
        user_scripts = str(user_scripts_with_addon(folder))
        env = dict(os.environ, **user_folders(user_scripts), PYTHONUNBUFFERED="1")
        for name, path in libraries.items():
            env.setdefault(name, str(path))
        command = [blender, "--factory-startup", "-noaudio", "--addons", "hbao",
                   "--python-exit-code", "1", "--python-expr", NO_SPLASH,
                   "--python", str(INNER), "--",
                   "--repeats", str(args.repeats)]
        if args.backend_check:
            command.append("--backend-check")
        if args.json:
            command += ["--json", str(Path(args.json).resolve())]
        if not args.no_xvfb:
            command = ["xvfb-run", "-a", "-s", XVFB_SCREEN] + command
        completed = subprocess.run(command, env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True)
    interesting = [line for line in completed.stdout.splitlines()
                   if line.startswith(("renderer:", " ", "HBAO", "Traceback", "Error"))
                   or "ms" in line or "x" in line[:10]]
    print("\n".join(interesting) if completed.returncode == 0 else completed.stdout)
    sys.exit(completed.returncode)


if __name__ == "__main__":
    main()
