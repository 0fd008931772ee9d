# SPDX-License-Identifier: GPL-2.0-or-later
"""The packaged add-on: scripts/package_addon.sh builds a legacy zip and a
Blender 4.2+ extension zip (validated and built by Blender's own extension
tool); the extension zip, installed the way Install from Disk does it, renders
the node's AO with the native libraries it carries, beside the OpenEXR that
Blender itself loads; the legacy zip installs over a running copy."""
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
    # Folder entries: Blender's Install with Overwrite removes the zip's
    # top-level names only, and without "hbao/" it removed nothing.
    assert {"hbao/", "hbao/lib/", "hbao/viewport/"} <= set(legacy_names)


def _other_library_zip(legacy, path):
    """A copy of the legacy zip whose lib/libhbao.so holds other bytes (those
    of lib/libhbao_exr.so): a newer version's library, as far as the code
    that a running copy has mapped is concerned."""
    with zipfile.ZipFile(legacy) as source, zipfile.ZipFile(path, "w") as copy:
        for info in source.infolist():
            name = "hbao/lib/libhbao_exr.so" if info.filename == "hbao/lib/libhbao.so" \
                else info.filename
            copy.writestr(info, source.read(name))
    return path


def test_installing_the_legacy_zip_over_the_running_add_on(packages, blender, tmp_path):
    """Install (with Overwrite) of a new legacy zip while the add-on is
    enabled, then a render: Blender 3.4 crashed (exit 139) as the render
    ended. The zip had no folder entries, so Blender removed nothing and
    extracted over the old files: the library the running add-on has mapped
    was rewritten in place. Now the old folder goes first, and the running
    copy keeps its library until Blender restarts."""
    legacy, _ = packages
    second = _other_library_zip(legacy, tmp_path / "hbao-newer.zip")
    out = tmp_path / "render"
    spec = {"nodes": [{"radius": 0.8, "blur_size": 0}]}
    command = blender.command(SCRIPTS / "legacy_reinstall.py",
                              (legacy, second, json.dumps(spec), out), addons=())
    user_scripts = tmp_path / "scripts"  # not the checkout's: the install replaces it
    (user_scripts / "addons").mkdir(parents=True)
    completed = run_command(command, user_scripts, {"HBAO_LIBRARY": "", "HBAO_EXR_LIBRARY": ""})
    assert f"LIBRARY {user_scripts}" in completed.stdout, completed.stdout[-3000:]
    assert "INSTALLED OVER" in completed.stdout and "REINSTALLED" in completed.stdout, \
        completed.stdout[-3000:]
    assert "without AO" not in completed.stdout, completed.stdout[-3000:]
    import hbao.exr_passes as exr  # noqa: E402  (after conftest put addon/ on sys.path)
    for name in ("first", "second"):
        ao = exr.read_channels(out / name / "nodes_0001.exr", ["HBAO0_AO.V"])["HBAO0_AO.V"]
        assert np.isfinite(ao).all() and ao.min() < 0.8 and ao.max() <= 1.0, name


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
