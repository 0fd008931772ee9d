# SPDX-License-Identifier: GPL-2.0-or-later
"""Two builds of libhbao measured side by side: each in a Python process of
its own (the binding loads one library per process), the script run again
with `--measure` and the build named by HBAO_LIBRARY; the measurement comes
back as JSON. Used by compare_accuracy.py and crop_edges.py."""
import json
import os
import subprocess
import sys
from pathlib import Path


def _run_with(script, library):
    env = dict(os.environ, HBAO_LIBRARY=str(Path(library).resolve()))
    done = subprocess.run([sys.executable, script, "--measure"], env=env,
                          capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{Path(script).name}: measuring {library} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout)


def before_and_after(script, measure, usage):
    """In the child (`--measure`): print measure()'s result as JSON and
    return None. Otherwise: (before, after), measured with the two library
    files the command line names, or exit with `usage`."""
    if sys.argv[1:] == ["--measure"]:
        print(json.dumps(measure()))
        return None
    if len(sys.argv) != 3:
        sys.exit(usage)
    for library in sys.argv[1:]:
        if not Path(library).is_file():
            sys.exit(f"{Path(script).name}: no library file {library}")
    return _run_with(script, sys.argv[1]), _run_with(script, sys.argv[2])
