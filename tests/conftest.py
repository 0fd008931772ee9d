# SPDX-License-Identifier: GPL-2.0-or-later
"""Shared pytest fixtures: where the built library, the tool and Blender are,
and one way to run a Python script inside a real (headless or Xvfb) Blender
with the add-on from this checkout enabled."""
import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
BUILD = Path(os.environ.get("HBAO_BUILD_DIR", REPO / "build"))
LIBRARY = BUILD / "libhbao.so"
# The add-on's EXR reader (csrc/exr): the add-on and the tests read EXRs with it.
EXR_LIBRARY = BUILD / "libhbao_exr.so"
TOOL = BUILD / "hbao"
FIXTURES = REPO / "tests" / "fixtures"
SCRIPTS = REPO / "scripts"
BLENDER = shutil.which(os.environ.get("BLENDER", "blender"))

# Tests read Blender's EXRs in this process too, through the add-on's binding
# (addon/hbao/exr_passes.py), which finds the library through this variable.
os.environ["HBAO_EXR_LIBRARY"] = str(EXR_LIBRARY)

# Generous: Cycles renders of test scenes take seconds, EEVEE on llvmpipe
# tens of seconds; a hang must still end the test rather than the CI run.
BLENDER_TIMEOUT_S = 600


@pytest.fixture(scope="session")
def built_library():
    if not LIBRARY.exists():
        pytest.fail(f"{LIBRARY} missing: build with scripts/test.sh or cmake first")
    return LIBRARY


@pytest.fixture(scope="session")
def hbao_tool():
    if not TOOL.exists():
        pytest.fail(f"{TOOL} missing: build with scripts/test.sh or cmake first")
    return TOOL


@pytest.fixture(scope="session")
def blender_user_scripts(tmp_path_factory):
    """A Blender user-scripts folder whose addons/hbao is this checkout's add-on."""
    root = tmp_path_factory.mktemp("blender_user_scripts")
    (root / "addons").mkdir()
    (root / "addons" / "hbao").symlink_to(REPO / "addon" / "hbao")
    return root


def blender_environment(user_scripts, extra=None):
    env = dict(os.environ)
    env["BLENDER_USER_SCRIPTS"] = str(user_scripts)
    env["HBAO_LIBRARY"] = str(LIBRARY)
    env["HBAO_EXR_LIBRARY"] = str(EXR_LIBRARY)
    env["PYTHONUNBUFFERED"] = "1"
    env.pop("PYTHONPATH", None)
    if extra:
        env.update(extra)
    return env


@pytest.fixture(scope="session")
def run_blender(blender_user_scripts):
    """run_blender(script, *args, blend=None, ui=False, addon=True, env=None)

    Runs `script` (a path) in Blender 3.4 (factory settings, this checkout's
    add-on enabled unless addon=False). Headless with -b, or with ui=True in a
    real window under xvfb-run. Arguments after `--` reach the script via
    sys.argv. Returns the CompletedProcess; fails the test on a non-zero exit,
    showing Blender's output."""
    if BLENDER is None:
        pytest.fail("blender not found: run scripts/setup.sh")

    def run(script, *args, blend=None, ui=False, addon=True, env=None, check=True,
            timeout=BLENDER_TIMEOUT_S):
        command = [BLENDER]
        if not ui:
            command.append("-b")
        if blend is not None:
            command.append(str(blend))
        command += ["--factory-startup", "-noaudio"]
        if addon:
            command += ["--addons", "hbao"]
        command += ["--python-exit-code", "1", "--python", str(script), "--"]
        command += [str(a) for a in args]
        if ui:
            command = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24"] + command
        completed = subprocess.run(
            command, env=blender_environment(blender_user_scripts, env),
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            timeout=timeout)
        if check and completed.returncode != 0:
            pytest.fail(f"Blender exited with {completed.returncode}:\n"
                        f"{' '.join(command)}\n{completed.stdout[-6000:]}")
        return completed

    return run
