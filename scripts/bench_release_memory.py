# SPDX-License-Identifier: GPL-2.0-or-later
"""How much of the library's kept memory hbao_release_memory() (what the
add-on calls when a render ends) hands back to the system inside a real
Blender process: in each Blender named, one 1920x1080 AO at the defaults
through the add-on's binding (hbao.native), a few small allocations of the
host's after it, then the release; the process's resident memory (RSS)
before the AO, after it and after the release. Run with two builds of the
library to compare them.

  python3 scripts/bench_release_memory.py [--blender bpy-5] [--library PATH ...]

--blender: a name or prefix from scripts/blenders.py (default: every
Blender found); --library: a libhbao.so (default build/libhbao.so), given
once per build. Prints a table: Blender, library, RSS (MB) at each point,
and how much the release gave back."""
import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def inside_blender():
    """The part that runs in Blender: prints 'RELEASE {json}'."""
    import bpy  # noqa: F401  (Blender's libraries and allocator in the process)
    import numpy as np
    sys.path.insert(0, str(REPO / "addon"))
    sys.path.insert(0, str(REPO / "scripts"))
    from hbao import native
    from process_memory import status_kib

    def rss_mb():
        return status_kib("VmRSS") / 1024

    y, x = np.mgrid[0:1080, 0:1920]
    depth = (3.0 + 0.001 * x + 0.5 * ((x // 40 + y // 40) % 2)).astype(np.float32)
    start = rss_mb()
    native.compute_ao(depth)
    computed = rss_mb()
    later = [bytearray(4096) for _ in range(64)]  # the host's, after the library's
    native.release_memory()
    released = rss_mb()
    print("RELEASE " + json.dumps({"start": start, "computed": computed, "released": released,
                                   "kept_after": len(later)}), flush=True)


def measure(blender, library):
    env = dict(os.environ, HBAO_LIBRARY=str(library), PYTHONUNBUFFERED="1")
    command = blender.command(Path(__file__).resolve(), ["--inside"], addons=())
    completed = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
    line = next((text for text in completed.stdout.splitlines() if text.startswith("RELEASE ")),
                None)
    if completed.returncode != 0 or line is None:
        sys.stderr.write(completed.stdout[-3000:] + completed.stderr[-3000:])
        raise SystemExit(f"bench_release_memory: {blender.name} failed")
    return json.loads(line[len("RELEASE "):])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blender", default="",
                        help="a name or prefix from scripts/blenders.py (default: every one)")
    parser.add_argument("--library", action="append", type=Path,
                        help="a libhbao.so (default build/libhbao.so); once per build")
    args = parser.parse_args()
    sys.path.insert(0, str(REPO / "scripts"))
    import blenders
    libraries = args.library or [REPO / "build" / "libhbao.so"]
    for library in libraries:
        if not library.is_file():
            raise SystemExit(f"bench_release_memory: {library}: no such file")
    found = [b for b in blenders.all_blenders() if b.name.startswith(args.blender)]
    if not found:
        raise SystemExit(f"bench_release_memory: no Blender named {args.blender}* here")
    print("| Blender | library | RSS before the AO (MB) | after the AO | after the release | "
          "given back |")
    print("|---|---|---|---|---|---|")
    for blender in found:
        for library in libraries:
            rss = measure(blender, library)
            print(f"| {blender.name} | {library} | {rss['start']:.0f} | {rss['computed']:.0f} | "
                  f"{rss['released']:.0f} | {rss['computed'] - rss['released']:.0f} of "
                  f"{rss['computed'] - rss['start']:.0f} |", flush=True)


if __name__ == "__main__":
    if "--inside" in sys.argv:
        inside_blender()
    else:
        main()
