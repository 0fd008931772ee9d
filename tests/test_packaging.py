# SPDX-License-Identifier: GPL-2.0-or-later
"""The packaged add-on: scripts/package_addon.sh builds a legacy zip and a
Blender 4.2+ extension zip (validated and built by Blender's own extension
tool); the extension zip, installed the way Install from Disk does it, renders
the node's AO with the native libraries it carries, beside the OpenEXR that
Blender itself loads."""
import json
import subprocess
import zipfile

import numpy as np
import pytest

from conftest import REPO, run_command

pytestmark = pytest.mark.matrix
SCRIPTS = REPO / "tests" / "blender_scripts"


@pytest.fixture(scope="module")
def packages():
    completed = subprocess.run([str(REPO / "scripts" / "package_addon.sh")],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert completed.returncode == 0, completed.stderr
    lines = completed.stdout.strip().splitlines()
    assert "Success parsing TOML" in completed.stderr, completed.stderr  # validate passed
    legacy, extension = lines[-2], lines[-1]
    assert legacy.endswith(".zip") and extension.endswith("-extension.zip"), lines
    return legacy, extension


def test_packages_hold_the_add_on_and_its_libraries(packages):
    legacy, extension = packages
    legacy_names = zipfile.ZipFile(legacy).namelist()
    extension_names = zipfile.ZipFile(extension).namelist()
    for name in ("__init__.py", "native.py", "blender_manifest.toml", "lib/libhbao.so",
                 "lib/libhbao_exr.so", "viewport/draw.py"):
        assert f"hbao/{name}" in legacy_names
        assert name in extension_names
    assert any(name.startswith("lib/libOpenEXRCore") for name in extension_names)


@pytest.mark.extension
def test_installed_extension_renders_ao(packages, blender, blender_user_scripts, tmp_path):
    _, extension = packages
    out = tmp_path / "render"
    spec = {"nodes": [{"radius": 0.8, "blur_size": 0}]}
    command = blender.command(SCRIPTS / "extension_install.py",
                              (extension, json.dumps(spec), out), addons=())
    # The installed copy must find its own lib/, not the build folder's.
    env = {"BLENDER_USER_EXTENSIONS": str(tmp_path / "extensions"),
           "HBAO_LIBRARY": "", "HBAO_EXR_LIBRARY": ""}
    completed = run_command(command, blender_user_scripts, env)
    installed = str(tmp_path / "extensions")
    assert f"LIBRARY {installed}" in completed.stdout, completed.stdout[-3000:]
    assert "RENDERED" in completed.stdout and "without AO" not in completed.stdout, \
        completed.stdout[-3000:]
    # The node's AO is real AO: the corner of the test scene is occluded.
    import hbao.exr_passes as exr  # noqa: E402  (after conftest put addon/ on sys.path)
    ao = exr.read_channels(out / "nodes_0001.exr", ["HBAO0_AO.V"])["HBAO0_AO.V"]
    assert np.isfinite(ao).all() and ao.min() < 0.8 and ao.max() <= 1.0
