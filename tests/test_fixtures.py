# SPDX-License-Identifier: GPL-2.0-or-later
"""The EXR fixtures and the scripts that make them (scripts/render_passes.py,
scripts/blender_scenes.py), checked with Blender itself: which view layers and
passes Blender finds in each file, the camera JSON next to it, and
render_passes.py's answers to good and bad arguments."""
import json
import math
import subprocess

import pytest

from conftest import BLENDER, FIXTURES, REPO, SCRIPTS

EXR_PASSES = REPO / "tests" / "blender_scripts" / "exr_passes.py"
RENDER_PASSES = SCRIPTS / "render_passes.py"

# name: {view layer: passes Blender must find}. "Combined" and "Alpha" are
# the Image node's names for the Combined pass.
EXPECTED_PASSES = {
    "cycles_float_zip": {"ViewLayer": {"Combined", "Alpha", "Depth", "Normal", "AO"}},
    "cycles_half_piz": {"ViewLayer": {"Combined", "Alpha", "Depth", "Normal", "AO"}},
    "cycles_float_none": {"ViewLayer": {"Combined", "Alpha", "Depth", "Normal"}},
    "cycles_half_b44": {"ViewLayer": {"Combined", "Alpha", "Depth", "Normal"}},
    "cycles_half_b44_tail": {"ViewLayer": {"Combined", "Alpha", "Depth", "Normal"}},
    "cycles_half_zip_tail": {"ViewLayer": {"Combined", "Alpha", "Depth", "Normal"}},
    "eevee_half": {"ViewLayer": {"Combined", "Alpha", "Depth", "Normal"}},
    "ortho_float": {"ViewLayer": {"Combined", "Alpha", "Depth", "Normal"}},
    "two_layers": {"Front": {"Combined", "Alpha", "Depth", "Normal"},
                   "Back": {"Combined", "Alpha", "Depth", "Normal"}},
    "no_depth": {"ViewLayer": {"Combined", "Alpha", "Normal"}},
}
ORTHO_FIXTURES = {"ortho_float"}

CAMERA_KEYS = {
    "type": str, "lens": float, "sensor_width": float, "sensor_height": float,
    "sensor_fit": str, "shift_x": float, "shift_y": float, "ortho_scale": float,
    "pixel_aspect_x": float, "pixel_aspect_y": float, "world_to_camera": list,
}
# world_to_camera of an unscaled camera is a rigid motion: its 3x3 part is a
# rotation. The JSON holds floats of Blender's single-precision matrices,
# whose products are good to a few 1e-7; 1e-5 leaves room and still catches
# a transposed or scaled matrix.
ROTATION_TOLERANCE = 1e-5


def passes_found(run_blender, tmp_path, paths):
    out = tmp_path / "passes.json"
    run_blender(EXR_PASSES, out, *paths, addon=False)
    return json.loads(out.read_text())


def test_fixtures_hold_the_expected_layers_and_passes(run_blender, tmp_path):
    paths = [str(FIXTURES / f"{name}.exr") for name in EXPECTED_PASSES]
    found = passes_found(run_blender, tmp_path, paths)
    for name, layers in EXPECTED_PASSES.items():
        description = found[str(FIXTURES / f"{name}.exr")]
        assert description["type"] == "MULTILAYER", name
        assert set(description["layers"]) == set(layers), name
        for layer, passes in layers.items():
            assert set(description["layers"][layer]) == passes, (name, layer)


def check_camera_description(camera, name, written_now=False):
    """`camera` has CAMERA_KEYS and, written by today's scripts, the camera's
    clip_start and clip_end too (which fixtures written before them lack)."""
    keys = CAMERA_KEYS
    if written_now or "clip_end" in camera:
        keys = dict(keys, clip_end=float)
    if written_now or "clip_start" in camera:
        keys = dict(keys, clip_start=float)
    assert set(camera) == set(keys), name
    for key, kind in keys.items():
        assert isinstance(camera[key], kind), (name, key)
    assert camera.get("clip_end", 1.0) > 0, name
    assert camera["type"] in ("PERSP", "ORTHO"), name
    assert camera["sensor_fit"] in ("AUTO", "HORIZONTAL", "VERTICAL"), name
    assert camera["lens"] > 0 and camera["ortho_scale"] > 0, name
    matrix = camera["world_to_camera"]
    assert len(matrix) == 4 and all(len(row) == 4 for row in matrix), name
    assert all(isinstance(v, float) and math.isfinite(v) for row in matrix for v in row), name
    assert matrix[3] == [0.0, 0.0, 0.0, 1.0], name
    for i in range(3):
        for j in range(3):
            dot = sum(matrix[i][k] * matrix[j][k] for k in range(3))
            assert dot == pytest.approx(1.0 if i == j else 0.0, abs=ROTATION_TOLERANCE), name


@pytest.mark.parametrize("name", sorted(EXPECTED_PASSES))
def test_fixture_camera_json(name):
    camera = json.loads((FIXTURES / f"{name}.camera.json").read_text())
    check_camera_description(camera, name)
    assert camera["type"] == ("ORTHO" if name in ORTHO_FIXTURES else "PERSP")


def render_passes(tmp_path, *arguments):
    command = [BLENDER, "-b", "--factory-startup", "-noaudio", "--python-exit-code", "1",
               "--python", str(RENDER_PASSES), "--", *[str(a) for a in arguments]]
    return subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=300, cwd=tmp_path)


@pytest.mark.parametrize("arguments, message", [
    (["--scene", "nonsense"], "invalid choice"),
    (["--scene", "corner", "--codec", "JPEG"], "invalid choice"),
    (["--scene", "corner", "--width", "32"], "both --width and --height"),
    (["--scene", "corner", "--samples", "0"], "positive integer"),
    (["--scene", "corner", "--ao-distance", "-1"], "positive number"),
    (["--scene", "corner", "--ao-distance", "nan"], "positive number"),
    (["--scene", "corner", "--engine", "WORKBENCH"], "invalid choice"),
    (["--scene", "corner", "--out", "/nonexistent/folder/x"], "does not exist"),
])
def test_render_passes_rejects_bad_arguments(tmp_path, arguments, message):
    if "--out" not in arguments:
        arguments = arguments + ["--out", tmp_path / "x"]
    completed = render_passes(tmp_path, *arguments)
    assert completed.returncode == 2, completed.stdout[-3000:]
    assert "render_passes.py: error:" in completed.stdout
    assert message in completed.stdout
    assert not (tmp_path / "x.exr").exists()


def test_render_passes_writes_what_was_asked_and_keeps_existing_files(run_blender, tmp_path):
    out = tmp_path / "small"
    arguments = ["--scene", "two_layers", "--out", out, "--width", "32", "--height", "24",
                 "--samples", "2", "--ortho", "--ao-distance", "0.5", "--codec", "PIZ", "--half"]
    completed = render_passes(tmp_path, *arguments)
    assert completed.returncode == 0, completed.stdout[-3000:]
    exr = tmp_path / "small.exr"
    camera = json.loads((tmp_path / "small.camera.json").read_text())
    check_camera_description(camera, "small", written_now=True)
    assert camera["type"] == "ORTHO"

    found = passes_found(run_blender, tmp_path, [exr])[str(exr)]
    passes = {"Combined", "Alpha", "Depth", "Normal", "AO"}
    assert {layer: set(names) for layer, names in found["layers"].items()} == {
        "Front": passes, "Back": passes}

    # A second run without --force must not overwrite the user's files.
    before = exr.read_bytes()
    again = render_passes(tmp_path, *arguments)
    assert again.returncode == 2
    assert "pass --force" in again.stdout
    assert exr.read_bytes() == before
