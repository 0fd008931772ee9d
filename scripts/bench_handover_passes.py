# SPDX-License-Identifier: GPL-2.0-or-later
"""The add-on's pass hand-over against the passes a render has: the same
1920x1080 interior render (Cycles, 1 sample, the HBAO node at the library's
defaults) with only Combined, Depth and Normal, then with a compositing
artist's usual passes as well (blender_scenes.PRODUCTION_PASSES); each
with the passes taken from Cycles' memory (pass_capture.py, the default
from Blender 4.5) and through the file round trip (handover.py:
HBAO_PASSES_FROM_MEMORY=0), which saves the whole Render Result and so
grows with the passes. Prints, for each, the helper scene's whole render
(the engine's part of the frame), the AO and the hand-over (from memory,
or save and read; write) of the renders that computed the AO, as the
add-on's console lines give them.

  python3 scripts/bench_handover_passes.py [--blender bpy-5] [--repeats 4] [--size WxH]

Needs the build (build/libhbao.so, build/libhbao_exr.so, or the libraries
that HBAO_LIBRARY and HBAO_EXR_LIBRARY name, to time another build) and the
Blender named (scripts/blenders.py; default: the newest bpy)."""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import blenders

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "addon"))  # the add-on's bpy-free timing_line
from hbao import timing_line  # noqa: E402

FIELDS = ("total_ms", "ao_ms", "handover_ms", "capture_ms", "save_ms", "read_ms", "write_ms")
ROUTES = {"memory": "1", "file": "0"}  # HBAO_PASSES_FROM_MEMORY


def run(blender, passes, route, repeats, user_scripts, size):
    spec = {"scene": "interior", "width": size[0], "height": size[1], "samples": 1,
            "repeats": repeats, "threads": 2, "passes": passes,
            "node": {"directions": 4, "steps": 16, "blur_size": 5}}
    env = dict(os.environ, **blenders.user_folders(user_scripts), PYTHONUNBUFFERED="1",
               HBAO_PASSES_FROM_MEMORY=ROUTES[route])
    env.setdefault("HBAO_LIBRARY", str(REPO / "build/libhbao.so"))
    env.setdefault("HBAO_EXR_LIBRARY", str(REPO / "build/libhbao_exr.so"))
    command = blender.command(REPO / "bench" / "addon_timing.py", [json.dumps(spec)])
    completed = subprocess.run(command, env=env, capture_output=True, text=True)
    if completed.returncode != 0:
        sys.stderr.write(completed.stdout[-3000:] + completed.stderr[-3000:])
        raise SystemExit(f"bench_handover_passes: {blender.name} failed ({passes})")
    # The renders that computed the AO: the first of each timed_renders()
    # group is a warm-up; "reused" and "re-composited" lines did not compute.
    found = [timing_line.parse(line) for line in completed.stdout.splitlines()]
    rows = [tuple(figures[field] for field in FIELDS) for figures in found
            if figures is not None and not figures["reused"] and not figures["recomposited"]]
    return rows[1:]


def _size(text):
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not WxH, e.g. 1920x1080") from None
    if not (16 <= width <= 16384 and 16 <= height <= 16384):
        raise argparse.ArgumentTypeError(f"{text!r}: each side 16 to 16384 pixels")
    return width, height


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blender", default="bpy-5",
                        help="a name or prefix from scripts/blenders.py (default bpy-5)")
    parser.add_argument("--repeats", type=int, default=4)
    parser.add_argument("--size", default="1920x1080", type=_size,
                        help="WxH (default 1920x1080; 3840x2160: Cycles renders it in tiles)")
    args = parser.parse_args()
    size = args.size
    found = [b for b in blenders.all_blenders() if b.name.startswith(args.blender)]
    if not found:
        raise SystemExit(f"bench_handover_passes: no Blender named {args.blender}* here")
    blender = found[-1]
    with tempfile.TemporaryDirectory(prefix="hbao-handover-") as folder:
        user_scripts = blenders.user_scripts_with_addon(folder)
        print(f"bench_handover_passes: {blender.name}, interior {size[0]}x{size[1]}, "
              f"1 Cycles sample, "
              f"defaults; ms per render that computed the AO (median, least-greatest)")
        print("| passes | hand-over | the helper's render | AO | hand-over | from memory | save | "
              "read | write | hand-over / AO |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for passes, route in ((passes, route) for passes in ("plain", "production")
                              for route in ROUTES):
            rows = run(blender, passes, route, args.repeats, user_scripts, size)
            cells = []
            for index in range(len(FIELDS)):
                values = [row[index] for row in rows]
                cells.append(f"{statistics.median(values):.0f} ({min(values)}-{max(values)})")
            ratios = [row[2] / row[1] for row in rows]
            name = "Combined, Depth, Normal" if passes == "plain" else "production (81 channels)"
            print(f"| {name} | {route} | " + " | ".join(cells) +
                  f" | {statistics.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f}) |")


if __name__ == "__main__":
    main()
