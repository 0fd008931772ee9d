# SPDX-License-Identifier: GPL-2.0-or-later
"""Blender under faults: each failure the render hook can meet, injected into a
real render in every Blender of the matrix. In each case the render
completes (exit 0, the image written), the console says why AO is missing
(the same text reaches the render window's report), no temporary file is
left, and the user's output settings are as they were."""
import json
import os
import re
import subprocess

import numpy as np
import pytest

from conftest import EXR_LIBRARY, REPO, json_line, run_command, small_tmpfs
from test_addon import EXACT, exr, library_ao, node_outputs, node_params, render

SCRIPTS = REPO / "tests" / "blender_scripts"

pytestmark = pytest.mark.matrix
RENDER_SCRIPT = REPO / "tests" / "blender_scripts" / "addon_render.py"


@pytest.fixture
def no_leftovers(tmp_path, monkeypatch):
    """The add-on's scratch folder (HBAO_TEMP_DIR, where it writes the Render
    Result for its own reading) is private to the test and empty after it;
    so is Blender's own temporary folder (TMPDIR: Blender's session folder,
    which it removes as it exits)."""
    scratch = tmp_path / "scratch"
    system_temp = tmp_path / "tmp"
    scratch.mkdir()
    system_temp.mkdir()
    monkeypatch.setenv("HBAO_TEMP_DIR", str(scratch))
    for name in ("TMPDIR", "TMP"):  # Blender reads TMP first
        monkeypatch.setenv(name, str(system_temp))
    yield scratch
    left = sorted(p.name for p in scratch.iterdir())
    assert not left, f"temporary files left behind: {left}"
    # (Blender's own quit.blend, which a window's quit saves there, is no leftover)
    left = sorted(p.name for p in system_temp.iterdir() if p.name.startswith("blender_"))
    assert not left, f"Blender's temporary folders left behind: {left}"


def output_settings(log):
    line = next(text for text in log.splitlines() if text.startswith("OUTPUT SETTINGS "))
    return json.loads(line[len("OUTPUT SETTINGS "):])


def assert_no_ao_and_image_unchanged(out, node="HBAO0"):
    outputs = node_outputs(out, 1, node)
    assert np.all(outputs["ao"] == 1.0)
    assert np.abs(outputs["image"] - outputs["render"]).max() <= EXACT


def test_library_of_another_kind_renders_without_ao_and_says_so(
        run_in_blender, tmp_path, no_leftovers):
    # libhbao_exr in place of libhbao: a real shared library without libhbao's API.
    out, log = render(run_in_blender, tmp_path, {"nodes": [{"radius": 1.0}]},
                      env={"HBAO_LIBRARY": str(EXR_LIBRARY)})
    assert "is not a compatible libhbao" in log, log[-3000:]
    assert "Rendering without AO" in log
    assert_no_ao_and_image_unchanged(out)


def test_users_png_output_is_restored_after_the_pass_hand_over(run_in_blender, tmp_path,
                                                               no_leftovers):
    out, log = render(run_in_blender, tmp_path,
                      {"output_format": "PNG", "nodes": [{"radius": 1.0}]})
    settings = output_settings(log)
    assert settings["file_format"] == "PNG", settings
    if settings["media_type"] is not None:  # 5.0+
        assert settings["media_type"] == "IMAGE", settings
    assert (out / "frame_0001.png").is_file()
    assert node_outputs(out, 1)["ao"].min() < 0.9  # the AO itself was computed


@pytest.mark.parametrize("case", ["colorspace", "movie"])
def test_every_output_setting_is_as_it_was_after_the_hand_over_through_a_file(
        run_in_blender, tmp_path, file_route, case):
    """The hand-over through a file sets the artist's output to multilayer
    EXR for its save and puts it back, but setting the format resets more
    than the format: the output's linear colour space (4.5, 5.x: Linear
    Rec.2020 became Rec.709, in the frame's own file and the saved .blend)
    and, in 3.4, a movie's container and codec (QuickTime with PNG frames
    became a lossy .mkv); a review's find. Every plain setting of the image
    settings, of their linear colour space and of FFmpeg's is as it was."""
    completed = run_in_blender(SCRIPTS / "output_settings_kept.py", tmp_path / "out", case)
    seen = json_line(completed.stdout, "SETTINGS")
    assert seen["after"] == seen["before"], seen
    assert "AO pass(es)" in completed.stdout, completed.stdout[-3000:]


@pytest.mark.parametrize("edit", ["rename_node", "rename_helper"])
def test_renamed_node_or_helper_scene_still_renders_ao(run_in_blender, tmp_path, node_native,
                                                       no_leftovers, edit):
    out, log = render(run_in_blender, tmp_path, {
        "prepare": ["sync", edit], "nodes": [{"radius": 0.8, "blur_size": 0}]})
    assert "without AO" not in log, log[-3000:]
    ao = node_outputs(out, 1)["ao"]
    expected = library_ao(node_native, out, 1, node_params(radius=0.8, blur_size=0))
    assert np.abs(ao - expected).max() <= EXACT


def test_deleted_helper_scene_is_rebuilt_or_explained(run_in_blender, tmp_path, node_native,
                                                      no_leftovers):
    out, log = render(run_in_blender, tmp_path, {
        "prepare": ["sync", "delete_helper"], "nodes": [{"radius": 0.8, "blur_size": 0}]})
    ao = node_outputs(out, 1)["ao"]
    if np.all(ao == 1.0):
        # Where Blender forbids creating the helper during a render, the
        # artist is told what to do instead.
        assert "HBAO" in log and "helper" in log.lower(), log[-3000:]
    else:
        expected = library_ao(node_native, out, 1, node_params(radius=0.8, blur_size=0))
        assert np.abs(ao - expected).max() <= EXACT


def test_deleted_extra_renders_are_rebuilt(run_in_blender, tmp_path, no_leftovers):
    """The guard band's and the back faces' hidden scenes deleted by the
    artist after the hook was built: the next render builds them again and
    gives the AO it gives when nothing was deleted: within 1e-5 (a rebuilt
    scene's 1-sample Cycles render differs from the first in a few float
    roundings: up to 2.4e-6 measured), far below what a missing layer
    changes (hundredths)."""
    node = {"radius": 0.8, "blur_size": 0, "guard_band": 10.0, "back_faces": True}
    intact, _ = render(run_in_blender, tmp_path, {"prepare": ["sync"], "nodes": [node]},
                       name="intact")
    out, log = render(run_in_blender, tmp_path, {
        "prepare": ["sync", "delete_extra_renders"], "nodes": [node]}, name="deleted")
    assert "without AO" not in log and "no guard band" not in log, log[-3000:]
    assert log.count("created the guard band render") == 2, log[-3000:]
    difference = np.abs(node_outputs(out, 1)["ao"] - node_outputs(intact, 1)["ao"])
    assert difference.max() <= 1e-5, difference.max()


# What a worker without any OpenGL sees (a bare container without Mesa):
# glvnd finds no EGL or GLX vendor.
NO_OPENGL = {"__EGL_VENDOR_LIBRARY_DIRS": "/nonexistent", "__EGL_VENDOR_LIBRARY_FILENAMES":
             "/nonexistent", "__GLX_VENDOR_LIBRARY_NAME": "none", "DISPLAY": ""}


def test_file_reopened_without_the_add_on_renders_without_ao(
        blender, blender_user_scripts, run_in_blender, tmp_path, no_leftovers):
    """On a worker with neither the add-on nor OpenGL. The add-on's scenes
    are saved switched off (saved_switch.py): before, Blender rendered the
    helper with EEVEE there and aborted after the artist's render (3.4, 4.5,
    5.0), and rendered the guard band and back faces with Cycles for
    nothing."""
    blend = tmp_path / "hbao.blend"
    render(run_in_blender, tmp_path, {
        "save_blend": str(blend), "prepare": ["sync"],
        "nodes": [{"radius": 0.6, "guard_band": 10.0, "back_faces": True}]}, name="setup")
    out = tmp_path / "without"
    command = blender.command(blend=blend, output=out / "frame_####", frame=1, addons=())
    # bpy 5.3 itself needs OpenGL to render any file with compositor nodes
    # (a segmentation fault in its render's GPU context, a plain Cycles scene
    # with a Render Layers node too): there the saved layers below tell.
    completed = run_command(command, blender_user_scripts,
                            env=NO_OPENGL if blender.version_tuple < (5, 1) else None)
    written = out / "frame_0001.exr"
    assert written.is_file(), completed.stdout[-3000:]
    script = SCRIPTS / "saved_layers.py"
    saved = json_line(run_command(blender.command(script, blend=blend, addons=()),
                                  blender_user_scripts).stdout, "SAVED_LAYERS")
    assert len(saved) == 3 and not any(any(uses) for uses in saved.values()), saved
    # With the add-on, a save leaves the session's scenes as they were.
    log = run_command(blender.command(script, [tmp_path / "again.blend"], blend=blend),
                      blender_user_scripts).stdout
    assert json_line(log, "AFTER_SAVE") == json_line(log, "SAVED_LAYERS"), log[-3000:]
    channels = exr.channel_names(written)
    assert "ViewLayer.Combined.R" in channels
    nodes_file = tmp_path / "setup" / "nodes_0001.exr"
    if blender.version_tuple < (4, 0):
        # 3.4 composites the tree: the node group multiplies by its pass
        # input's default, 1, so the image is the render.
        nodes = node_outputs(tmp_path / "setup", 1)
        assert np.all(nodes["ao"] == 1.0)
        assert np.abs(nodes["image"] - nodes["render"]).max() <= EXACT
    elif blender.version_tuple < (5, 1):
        # 4.x and 5.0 skip compositing a tree with a node type nobody
        # registered: the file holds the render itself, no Composite layer.
        assert not nodes_file.exists()
        assert not any(name.startswith("Composite.") for name in channels)
    else:
        # 5.3 composites it and gives the unknown node's outputs 0: black.
        # Nothing of the add-on runs to prevent it; README says so.
        nodes = node_outputs(tmp_path / "setup", 1)
        assert np.all(nodes["ao"] == 0.0) and np.all(nodes["image"] == 0.0)


@pytest.fixture
def full_disk(tmp_path):
    """A 64 KiB tmpfs as the add-on's scratch folder: the Render Result of the
    test scene (about 200 KiB uncompressed) does not fit."""
    with small_tmpfs(tmp_path / "full", "64k") as folder:
        yield folder


def render_with_scratch_folder(run_in_blender, tmp_path, folder):
    """A render whose hand-over cannot use `folder`: it renders on without
    AO, the image unchanged and the PNG output settings restored; returns
    the log, for the reason."""
    out, log = render(run_in_blender, tmp_path,
                      {"output_format": "PNG", "nodes": [{"radius": 1.0}]},
                      env={"HBAO_TEMP_DIR": str(folder)})
    assert "Rendering without AO" in log, log[-3000:]
    settings = output_settings(log)
    assert settings["file_format"] == "PNG", settings
    assert_no_ao_and_image_unchanged(out)
    return log


def test_full_disk_renders_without_ao_leaves_nothing_and_restores_settings(
        run_in_blender, tmp_path, full_disk, file_route):
    log = render_with_scratch_folder(run_in_blender, tmp_path, full_disk)
    # The reason names the folder and how to choose another.
    assert f"cannot read back the passes saved in {full_disk}" in log, log[-3000:]
    assert "is it full? HBAO_TEMP_DIR names another folder" in log
    assert list(full_disk.iterdir()) == []


def test_passes_that_do_not_fit_in_the_first_scratch_folder_go_to_the_next(
        run_in_blender, tmp_path, node_native, full_disk, file_route):
    """HBAO_TEMP_DIR lists folders to try in turn (by default /dev/shm, then
    the system's temporary folder: a container's /dev/shm is 64 MB, less
    than a 1080p render's Combined, Depth and Normal, and every frame lost
    its AO there). The Render Result does not fit in the first: it is
    saved in the second, the AO is the library's, the log says where, and
    neither folder keeps a file. The full folder is tried once: the later
    hand-overs (the back faces render's, the next frame's) go to the second
    first (each filled the first again, found by a review)."""
    second = tmp_path / "second"
    second.mkdir()
    node = {"radius": 1.0, "blur_size": 0}
    out, log = render(run_in_blender, tmp_path,
                      {"frames": [1, 2], "nodes": [node, dict(node, name="HBAO1",
                                                              back_faces=True)]},
                      env={"HBAO_TEMP_DIR": f"{full_disk}{os.pathsep}{second}"})
    assert "without AO" not in log and "no back faces" not in log, log[-3000:]
    assert log.count(f"cannot read back the passes saved in {full_disk}") == 1, log[-3000:]
    assert f"saving them in {second} instead" in log
    for frame in (1, 2):
        expected = library_ao(node_native, out, frame, node_params(**node))
        assert expected.min() < 0.9
        assert np.abs(node_outputs(out, frame)["ao"] - expected).max() <= EXACT
    assert list(full_disk.iterdir()) == [] and list(second.iterdir()) == []


def test_scratch_folder_that_cannot_be_written_says_which_and_how(run_in_blender, tmp_path,
                                                                  file_route):
    blocked = tmp_path / "a file, not a folder"
    blocked.write_text("")
    log = render_with_scratch_folder(run_in_blender, tmp_path, blocked)
    assert f"the scratch folder {blocked} is not a folder" in log, log[-3000:]
    assert "HBAO_TEMP_DIR names existing folders" in log


def test_a_scratch_folder_too_long_for_blender_is_refused_and_left_empty(run_in_blender,
                                                                         tmp_path, file_route):
    """A scratch folder whose path with the file's name reaches Blender's
    limit (1024 bytes): Blender cut the name, wrote a file of the cut name
    each frame, which no removal found (no .exr), and the render had no AO
    (a review's find). Refused before the save, the reason said, nothing
    written there."""
    folder = tmp_path / "s"
    while len(os.fsencode(str(folder))) < 990:
        folder = folder / ("d" * min(200, 990 - len(os.fsencode(str(folder)))))
    folder.mkdir(parents=True)
    log = render_with_scratch_folder(run_in_blender, tmp_path, folder)
    assert "path is too long for Blender's save" in log, log[-3000:]
    assert list(folder.iterdir()) == []


def test_a_scratch_folder_that_does_not_exist_is_not_made(run_in_blender, tmp_path, node_native,
                                                          no_leftovers, file_route):
    """A mistyped HBAO_TEMP_DIR folder: Blender's save made it (parents too)
    and the passes went there, silently, the folder left behind (an
    exploratory run). It is skipped with a message naming it; the next
    folder takes the passes; a read-only folder's skipped removal says
    nothing (it said it could not remove a file that never was)."""
    missing = tmp_path / "missing" / "sub"
    read_only = tmp_path / "read-only"
    read_only.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=1m", "tmpfs",
                              str(read_only)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             text=True)
    assert mounted.returncode == 0, f"cannot mount a tmpfs (root needed): {mounted.stdout}"
    node = {"radius": 1.0, "blur_size": 0}
    try:
        out, log = render(run_in_blender, tmp_path, {"nodes": [node]}, env={
            "HBAO_TEMP_DIR": os.pathsep.join([str(missing), str(read_only), str(no_leftovers)])})
    finally:
        subprocess.run(["umount", str(read_only)], check=False)
    assert f"the scratch folder {missing} does not exist;" in log, log[-3000:]
    assert f"cannot save the passes for the AO in {read_only}" in log, log[-3000:]
    assert not (tmp_path / "missing").exists()
    assert "could not remove" not in log and "without AO" not in log, log[-3000:]
    expected = library_ao(node_native, out, 1, node_params(**node))
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT


@pytest.mark.min_blender(5, 0)
def test_two_scenes_sharing_one_compositing_group(run_in_blender, tmp_path, node_native,
                                                  no_leftovers):
    out, log = render(run_in_blender, tmp_path, {
        "prepare": ["sync", "second_scene_shares_the_tree"],
        "nodes": [{"radius": 0.8, "blur_size": 0}]})
    assert "without AO" not in log, log[-3000:]
    ao = node_outputs(out, 1)["ao"]
    expected = library_ao(node_native, out, 1, node_params(radius=0.8, blur_size=0))
    assert np.abs(ao - expected).max() <= EXACT


@pytest.mark.min_blender(5, 3)
def test_another_compositor_effect_after_the_hbao_one(run_in_blender, tmp_path, node_native,
                                                      no_leftovers):
    """5.3 composites a stack of effects; Add Effect makes the new one active,
    and the add-on, which served the active effect's group, left the HBAO
    node unserved: a black frame (AO 0) with a wrong message. It serves the
    effect that holds the HBAO node."""
    node = {"radius": 0.8, "blur_size": 0}
    out, log = render(run_in_blender, tmp_path, {"prepare": ["sync", "second_effect"],
                                                 "nodes": [node]})
    assert 'EFFECTS [["Scene Effect", false], ["Second", true]]' in log, log[-3000:]
    assert "without AO" not in log and "renders nothing" not in log, log[-3000:]
    expected = library_ao(node_native, out, 1, node_params(**node))
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT


@pytest.mark.min_blender(5, 3)
def test_an_hbao_node_in_a_second_compositor_effect_says_why_it_gives_no_ao(
        run_in_blender, tmp_path, node_native, no_leftovers):
    node = {"radius": 0.8, "blur_size": 0}
    out, log = render(run_in_blender, tmp_path, {
        "prepare": ["sync", "second_effect_with_a_node"], "nodes": [node]})
    said = ('HBAO: node "HBAO in the second effect" in compositor effect "Second": HBAO works '
            'in one compositor effect of a scene, the first enabled for renders whose node group '
            'holds an HBAO node ("Scene Effect")')
    assert log.count(said) == 1, log[-3000:]
    expected = library_ao(node_native, out, 1, node_params(**node))
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT


@pytest.mark.min_blender(5, 3)
def test_one_group_in_two_compositor_effects(run_in_blender, tmp_path, no_leftovers):
    """The HBAO effect's group in a second effect too: both run, each
    multiplying by the AO, and nothing says that one of them gives none.
    (The group's File Output node writes its file twice: not read here.)"""
    out, log = render(run_in_blender, tmp_path, {"prepare": ["sync", "same_group_twice"],
                                                 "nodes": [{"radius": 0.8, "blur_size": 0}]})
    assert "in compositor effect" not in log and "without AO" not in log, log[-3000:]
    assert "renders nothing" not in log and (out / "frame_0001.exr").is_file()


@pytest.mark.min_blender(5, 3)
def test_the_compositing_group_inside_another_group_passes_the_image_through(
        run_in_blender, tmp_path, no_leftovers):
    """5.3 renders the helper scene through the Render Layers node of a
    nested group, which the hook does not serve: its passes read 0, the
    frame came out black while the report said the AO was white. The
    helper's engine writes 1 there."""
    out, log = render(run_in_blender, tmp_path, {"prepare": ["sync", "wrap_compositing_group"],
                                                 "nodes": [{"radius": 1.0}]})
    assert 'in node group "Scene Compositing": HBAO works only at the top' in log, log[-3000:]
    assert "renders nothing" not in log and "HBAO: HBAO:" not in log, log[-3000:]
    assert_no_ao_and_image_unchanged(out)


@pytest.mark.min_blender(5, 3)
def test_the_hook_follows_the_hbao_nodes_to_another_effect(run_in_blender, tmp_path,
                                                           no_leftovers):
    """The HBAO nodes gone from the first effect, the hook serves the next
    effect that holds one; the first keeps no managed Render Layers node (it
    rendered the helper of the old group every frame, which refused)."""
    out, log = render(run_in_blender, tmp_path, {
        "prepare": ["sync", "second_effect_with_a_node", "hbao_nodes_leave_the_first_effect"],
        "nodes": [{"radius": 0.8}]})
    line = next(text for text in log.splitlines() if text.startswith("HOOKS "))
    hooks = json.loads(line[len("HOOKS "):])
    assert hooks == {"Scene Compositing": [], "Second Effect": ["HBAO Passes"]}, line
    assert "rendered through a Render Layers node" not in log, log[-3000:]


@pytest.mark.min_blender(5, 3)
def test_the_first_hbao_effect_off_for_renders_serves_the_next(run_in_blender, tmp_path,
                                                               no_leftovers):
    """Two effects with HBAO nodes, the first off for renders: the hook
    serves the second, which renders, and the first's node is told so."""
    out, log = render(run_in_blender, tmp_path, {
        "prepare": ["second_effect_with_a_node", "effect_off_for_render"],
        "nodes": [{"radius": 1.0}]})
    said = ('HBAO: node "HBAO0" in compositor effect "Scene Effect": HBAO works in one '
            'compositor effect of a scene, the first enabled for renders whose node group holds '
            'an HBAO node ("Second")')
    assert log.count(said) == 1, log[-3000:]
    assert "is off for renders" not in log, log[-3000:]


@pytest.mark.min_blender(5, 3)
def test_the_hbao_effect_off_for_renders_says_that_the_render_has_no_ao(
        run_in_blender, tmp_path, no_leftovers):
    out, log = render(run_in_blender, tmp_path, {"prepare": ["effect_off_for_render"],
                                                 "nodes": [{"radius": 1.0}]})
    assert log.count('HBAO: The compositor effect "Scene Effect" is off for renders') == 1, \
        log[-3000:]
    assert status_lines(log) == {"HBAO0": "Effect off for renders: no AO"}, log[-3000:]
    assert (out / "frame_0001.exr").exists() and not (out / "nodes_0001.exr").exists()


# The control image of viewport_compositor.py: lit, far from black.
VIEWPORT_CONTROL_MEAN_MIN = 0.3


@pytest.mark.min_blender(5, 3)
def test_the_viewport_compositor_shows_the_image_without_ao_not_black(run_in_blender):
    """The Viewport Compositor (3D view, Material Preview, Compositor Always
    or Camera) renders no other scene, so the helper's pass reads 0 there:
    the node's Image was black (its pass held the AO). The pass holds the
    occlusion since the group's layout 5, so 0 is no AO: the node's Image is
    the image, its AO 1. bpy 5.3 draws headless (gpu.init); 4.5's and 5.0's
    gpu module refuses to draw in background mode, and 3.4 has no Viewport
    Compositor."""
    completed = run_in_blender(SCRIPTS / "viewport_compositor.py")
    line = next((text for text in completed.stdout.splitlines()
                 if text.startswith("VIEWPORT COMPOSITOR ")), None)
    assert line is not None, completed.stdout[-3000:]
    for mode, drawn in json.loads(line[len("VIEWPORT COMPOSITOR "):]).items():
        assert drawn["control_mean"] >= VIEWPORT_CONTROL_MEAN_MIN, (mode, drawn)
        assert drawn["image_difference"] == EXACT, (mode, drawn)
        assert drawn["ao_range"] == [1.0, 1.0], (mode, drawn)


@pytest.mark.min_blender(4, 2)
def test_the_add_on_scenes_set_to_the_gpu_compositor(run_in_blender, tmp_path, node_native,
                                                     no_leftovers):
    """4.5 and 5.0 crash (segmentation fault, Blender's own) rendering a
    scene whose compositor renders another scene set to the GPU compositor,
    as a script that sets every scene's device makes the add-on's: they are
    kept on the CPU. With the guard band's and back faces' scenes too."""
    node = {"radius": 0.8, "blur_size": 0, "guard_band": True, "back_faces": True}
    out, log = render(run_in_blender, tmp_path, {"prepare": ["sync", "add_on_scenes_on_gpu"],
                                                 "nodes": [node]})
    assert "without AO" not in log, log[-3000:]
    assert node_outputs(out, 1)["ao"].min() < 0.9


@pytest.mark.parametrize("beside", [False, True], ids=["alone", "beside_a_top_level_node"])
def test_hbao_node_inside_a_node_group_says_why_it_gives_no_ao(run_in_blender, tmp_path,
                                                               node_native, no_leftovers, beside):
    """An HBAO node that an artist put into a node group of their own passes
    Image through with a white AO, and the render's console (and, with a
    window, the Info editor) says why, once; the node itself says so too
    (node_place.at_top_level, which its status line draws from). An HBAO node at
    the top level beside it still gets its AO."""
    nodes = [{"radius": 0.8, "blur_size": 0}] * beside + [{"radius": 1.0}]
    grouped_name = f"HBAO{len(nodes) - 1}"
    out, log = render(run_in_blender, tmp_path, {"prepare": ["group_last_node"], "nodes": nodes})
    line = next(text for text in log.splitlines() if text.startswith("GROUPED "))
    expected_places = {grouped_name: False, **({"HBAO0": True} if beside else {})}
    assert json.loads(line[len("GROUPED "):]) == expected_places
    said = f'HBAO: node "{grouped_name}" in node group "Artist Group": HBAO works only at the top'
    assert log.count(said) == 1, log[-3000:]
    assert_no_ao_and_image_unchanged(out, grouped_name)
    if beside:
        ao = node_outputs(out, 1)["ao"]
        expected = library_ao(node_native, out, 1, node_params(radius=0.8, blur_size=0))
        assert np.abs(ao - expected).max() <= EXACT


def _status_fixed(run_in_blender, tmp_path, case, said):
    log = run_in_blender(REPO / "tests" / "blender_scripts" / "status_fixed.py", case,
                         tmp_path / case).stdout
    assert json_line(log, "RENDERED") == [said, ""], log[-3000:]
    assert json_line(log, "FIXED") == ["", "Fixed: render to update"], log[-3000:]


@pytest.mark.parametrize("case, said", [("compositing", "Compositing off: no AO"),
                                        ("single_layer", "Single Layer on: AO off")])
def test_a_render_setting_put_back_takes_its_status_away(run_in_blender, tmp_path, case, said):
    """A render with Compositing off or Render Single Layer on says so on
    the node; the setting put back without rendering, the add-on's status
    timer (its steps run as its tick runs them: status_fixed.py) takes the
    line away and asks for a render (status_causes.py; the line had stayed
    until the next render)."""
    _status_fixed(run_in_blender, tmp_path, case, said)


@pytest.mark.min_blender(5, 3)
def test_the_hbao_effect_on_again_takes_its_status_away(run_in_blender, tmp_path):
    """The same with the HBAO compositor effect off for renders, then on."""
    _status_fixed(run_in_blender, tmp_path, "effect", "Effect off for renders: no AO")


def status_lines(log):
    return {entry["node"]: entry["status"] for entry in
            (json.loads(text[len("STATUS "):]) for text in log.splitlines()
             if text.startswith("STATUS "))}


def test_render_single_layer_passes_image_through_and_says_so(run_in_blender, tmp_path,
                                                              no_leftovers):
    """With Render Single Layer on Blender renders no other scene, the
    helper neither, and its AO pass read 0: a black image without a word.
    Now the hook unlinks the nodes from it (AO 1, Image passed through), and
    the render and the node say why."""
    out, log = render(run_in_blender, tmp_path, {"single_layer": True,
                                                 "nodes": [{"radius": 1.0}]})
    assert log.count("HBAO: Render Single Layer is on") == 1, log[-3000:]
    assert status_lines(log) == {"HBAO0": "Single Layer on: AO off"}, log[-3000:]
    assert node_outputs(out, 1)["render"].max() > 0.1
    assert_no_ao_and_image_unchanged(out)


def test_compositing_off_says_that_the_render_has_no_ao(run_in_blender, tmp_path, no_leftovers):
    """With Compositing off Blender runs no compositor: the render is written
    without AO, and the render's report and the node say why (nothing did)."""
    out, log = render(run_in_blender, tmp_path, {"prepare": ["compositing_off"],
                                                 "nodes": [{"radius": 1.0}]})
    assert log.count("HBAO: Compositing is off") == 1, log[-3000:]
    assert status_lines(log) == {"HBAO0": "Compositing off: no AO"}, log[-3000:]
    assert (out / "frame_0001.exr").exists() and not (out / "nodes_0001.exr").exists()


@pytest.mark.parametrize("prepare, said, short", [
    ("layer_not_rendered", "which is not rendered (its Use for Rendering is off); AO off",
     "Depth: not rendered, AO off"),
    ("mute_render_layers", "Depth comes from a muted Render Layers node", "Depth: muted, AO off"),
])
def test_passes_that_blender_does_not_render_turn_the_ao_off_and_say_why(
        run_in_blender, tmp_path, no_leftovers, prepare, said, short):
    """A node fed by a view layer that is not rendered, or by a muted Render
    Layers node: AO off with the reason, not a KeyError about a scratch file
    or a failed save that blames the folder."""
    out, log = render(run_in_blender, tmp_path, {
        "scene": "two_layers", "prepare": [prepare],
        "nodes": [{"name": "HBAO0", "layer": "Back", "radius": 1.0}]})
    assert said in log, log[-3000:]
    assert "KeyError" not in log and "cannot save" not in log, log[-3000:]
    assert status_lines(log) == {"HBAO0": short}, log[-3000:]
    assert np.all(node_outputs(out, 1)["ao"] == 1.0)


@pytest.mark.parametrize("prepare, said", [
    ("holdout_collection", 'Holdout collection "Props"'),
    ("indirect_only_collection", 'Indirect Only collection "Props"'),
    ("holdout_objects", "holdout objects"),
    ("holdout_shader", "objects with a Holdout shader"),
    ("objects_unseen_by_camera", "objects with Camera visibility off"),
    ("sync", None),
])
def test_objects_missing_from_cycles_depth_are_named(run_in_blender, tmp_path, no_leftovers,
                                                     prepare, said):
    """Cycles writes the sky's depth at a holdout's pixels and none for what
    the camera does not see, so such objects cast no AO (an exploratory run:
    the floor's mean AO 0.95 with the props held out, 0.89 without), and
    nothing said so. The render's report names them, once, for the view
    layer the node reads; the render goes on (the AO is right for the passes
    given), and a render without them says nothing."""
    out, log = render(run_in_blender, tmp_path, {"prepare": [prepare],
                                                 "nodes": [{"radius": 1.0}]})
    told = [line for line in log.splitlines() if "Cycles gives them no depth" in line]
    if said is None:
        assert told == [], told
    else:
        assert len(told) == 1 and f'HBAO: view layer "ViewLayer": {said}' in told[0], told
        # (bpy 4.5 and 5.0 then take the Floor for a holdout too, and render
        # it so: Blender's own, seen with is_holdout set on Cube and Sphere)
        assert '"Cube"' in told[0] and '"Sphere"' in told[0] or "collection" in said, told
    assert status_lines(log) == {"HBAO0": ""}, log[-3000:]
    ao = node_outputs(out, 1)["ao"]  # (4.5 and 5.0 hold the Floor out too: AO 1 there)
    assert np.all((ao >= 0.0) & (ao <= 1.0)) and (said is not None or ao.min() < 0.9)


def test_a_render_too_low_for_the_radius_says_so(run_in_blender, tmp_path, no_leftovers):
    """A render a few pixels high has every pixel near a border, so most
    samples leave the image and the AO comes out nearly white (an
    exploratory run: 4097x5, mean AO 0.9996 against Cycles' 0.65), and
    nothing said why. The library notes it (HBAO_NOTE_RADIUS_BEYOND_IMAGE)
    and the render's report says so, once for the node; the render goes on."""
    out, log = render(run_in_blender, tmp_path, {"resolution": [512, 4],
                                                 "nodes": [{"radius": 1.0}]})
    # the report's line: "Warning: HBAO: ..." in 3.4, "WARNING HBAO: ..." in bpy
    told = [line for line in log.splitlines()
            if re.search(r"(Warning:|WARNING) HBAO node \"HBAO0\": at most of the image's "
                         r"pixels the radius spans more pixels than the image's shorter side",
                         line)]
    assert len(told) == 1, log[-3000:]
    assert status_lines(log) == {"HBAO0": "Radius past image: light"}, log[-3000:]
    ao = node_outputs(out, 1)["ao"]
    assert np.all((ao >= 0.0) & (ao <= 1.0)), ao


@pytest.mark.parametrize("radius", [0.0, 1e-5])
def test_a_radius_under_a_pixel_says_why_there_is_no_ao(run_in_blender, tmp_path, radius):
    """A Radius of 0, or one too small for the scene's units, samples
    nothing: the AO is 1 everywhere, and nothing said why (a review's
    find). The library notes it (HBAO_NOTE_RADIUS_UNDER_A_PIXEL): the
    node's status line, the render's report and the console say so."""
    out, log = render(run_in_blender, tmp_path, {"nodes": [{"radius": radius}]})
    told = [line for line in log.splitlines()
            if re.search(r"(Warning:|WARNING) HBAO node \"HBAO0\": at most of the image's "
                         r"pixels the radius spans less than a pixel.*raise the radius", line)]
    assert len(told) == 1, log[-3000:]
    assert status_lines(log) == {"HBAO0": "Radius < 1 pixel: no AO"}, log[-3000:]
    assert np.all(node_outputs(out, 1)["ao"] == 1.0)


@pytest.fixture(scope="session")
def latin1_locale(tmp_path_factory):
    """LOCPATH and the name of a German ISO-8859-1 locale made for the tests
    (localedef, from the `locales` package that scripts/setup.sh installs)."""
    folder = tmp_path_factory.mktemp("locales")
    completed = subprocess.run(["localedef", "-i", "de_DE", "-f", "ISO-8859-1",
                                str(folder / "de_DE.ISO-8859-1")], capture_output=True, text=True)
    assert (folder / "de_DE.ISO-8859-1").is_dir(), completed.stderr
    return str(folder), "de_DE.ISO-8859-1"


@pytest.mark.min_blender(4, 5)
def test_a_console_and_folder_in_a_latin1_locale(run_in_blender, tmp_path, node_native,
                                                 no_leftovers, latin1_locale):
    """bpy (not 3.4's Blender, whose Python is in UTF-8 mode) under a
    non-UTF-8 locale (LANG=de_DE gives ISO-8859-1) writes its console in
    that encoding, strictly, and names files in it. A console line naming a
    scene "Szene \u2013 final" (an en dash) raised inside the render's
    handlers and engine: no AO (4.5), no compositing (5.0, 5.3); and with a
    scratch folder "\u00dcbergabe", Blender saved the passes under the
    folder's UTF-8 spelling (a second folder) and the add-on, reading the
    other, found nothing and left the file behind."""
    locale_path, locale_name = latin1_locale
    folder = no_leftovers / os.fsdecode("\u00dcbergabe".encode("latin-1"))
    folder.mkdir()
    node = {"radius": 0.8, "blur_size": 0, "guard_band": True}
    out, log = render(run_in_blender, tmp_path, {"scene_name": "Szene \u2013 final",
                                                 "nodes": [node, {"radius": 0.8}]},
                      env={"LOCPATH": locale_path, "LC_ALL": locale_name,
                           "HBAO_TEMP_DIR": str(folder)})
    assert "UnicodeEncodeError" not in log and "Traceback" not in log, log[-3000:]
    assert "without AO" not in log, log[-3000:]
    assert "created helper scene '.HBAO passes Szene \\u2013 final'" in log, log[-3000:]
    assert sorted(p.name for p in no_leftovers.iterdir()) == [folder.name]
    assert not any(folder.iterdir())
    folder.rmdir()
    expected = library_ao(node_native, out, 1, node_params(radius=0.8))
    assert np.abs(node_outputs(out, 1, "HBAO1")["ao"] - expected).max() <= EXACT


@pytest.mark.parametrize("length", [56, 57])
def test_long_view_layer_names(run_in_blender, blender, tmp_path, node_native, no_leftovers,
                               length):
    """Blender before 5.0 cuts EXR channel names at 64 bytes: a view layer
    of 56 bytes loses its Normal pass ("<layer>.Normal.X" is 65), one of 57
    its Depth too. The node then says so and reconstructs the normals, or
    turns the AO off; 5.0 and later keep the names, and the AO is exact."""
    name = "L" * length
    out, log = render(run_in_blender, tmp_path, {"layer_name": name,
                                                 "nodes": [{"radius": 0.8, "blur_size": 0}]})
    assert "KeyError" not in log, log[-3000:]
    ao = node_outputs(out, 1)["ao"]
    params = node_params(radius=0.8, blur_size=0)
    if blender.version_tuple >= (5, 0):
        expected = library_ao(node_native, out, 1, params, layer=name)
        assert np.abs(ao - expected).max() <= EXACT
    elif length == 56:
        assert "Normal comes from view layer" in log, log[-3000:]
        assert "at most 55 bytes (it has 56)" in log, log[-3000:]
        expected = library_ao(node_native, out, 1, params, with_normal=False, layer=name)
        assert np.abs(ao - expected).max() <= EXACT
    else:
        assert "Depth comes from view layer" in log, log[-3000:]
        assert "at most 56 bytes (it has 57)" in log, log[-3000:]
        assert np.all(ao == 1.0)


def test_a_long_view_layer_name_in_a_render_with_one_view(run_in_blender, blender, tmp_path,
                                                          node_native, no_leftovers):
    """Blender 3.4 saves a render with one view on (Stereoscopy, the right
    eye off) with the view in its channel names ("<layer>.Normal.left.X")
    and cuts them past 63 bytes: a 50-byte layer (a mono render keeps 55)
    lost its Normal pass, and the AO was off with a KeyError (an exploratory
    run). The node now says so and reconstructs the normals; 4.5 and later
    save the mono names, and the AO is exact."""
    name = "L" * 50
    out, log = render(run_in_blender, tmp_path, {
        "layer_name": name, "stereo": "one_view", "nodes": [{"radius": 0.8, "blur_size": 0}]})
    assert "KeyError" not in log, log[-3000:]
    # with one view on, 3.4 writes the render without its file suffix
    suffix = "_L" if (out / "frame_0001_L.exr").exists() else ""
    with_normal = blender.version_tuple >= (4, 5)
    if not with_normal:
        assert "Normal comes from view layer" in log and "rename the layer to at most 49 bytes, " \
            "or the view" in log, log[-3000:]
    channels = [f"{name}.Depth.Z"] + [f"{name}.Normal.{axis}" for axis in "XYZ"]
    passes = exr.read_channels(out / f"frame_0001{suffix}.exr", channels)
    normal = np.stack([passes[c] for c in channels[1:]], axis=-1) if with_normal else None
    description = json.loads((out / "camera_0001_L.json").read_text())
    expected = node_native.compute_ao(passes[channels[0]], normal, camera=description,
                                      params=node_params(radius=0.8, blur_size=0))
    ao = node_outputs(out, 1, view="_L" if (out / "nodes_0001_L.exr").exists() else "")["ao"]
    assert expected.min() < 0.9 and np.abs(ao - expected).max() <= EXACT


def test_a_pass_the_render_engine_does_not_make_is_not_read(run_in_blender, tmp_path, node_native,
                                                            no_leftovers):
    """A scene switched to Workbench after its passes were linked: Workbench
    makes no Normal pass, and Blender 3.4 keeps the Normal link to the Render
    Layers node (the socket hidden). The AO reconstructs the normals from
    depth, as where the link is gone, instead of failing on a channel that
    the saved file lacks."""
    out, log = render(run_in_blender, tmp_path, {"prepare": ["switch_to_workbench"],
                                                 "nodes": [{"radius": 0.8, "blur_size": 0}]})
    assert "KeyError" not in log and "Rendering without AO" not in log, log[-3000:]
    # (the engine named as the artist knows it: a review's find)
    assert "Normal is linked to the Normal pass, which Workbench does not make" in log, \
        log[-3000:]
    expected = library_ao(node_native, out, 1, node_params(radius=0.8, blur_size=0),
                          with_normal=False)
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT


FAULT_SCRIPT = REPO / "tests" / "blender_scripts" / "fault_render.py"


def render_with_fault(run_in_blender, tmp_path, spec, fault):
    out = tmp_path / fault
    completed = run_in_blender(FAULT_SCRIPT, json.dumps(spec), out, fault)
    assert "RENDERED" in completed.stdout, completed.stdout[-3000:]
    return out, completed.stdout


def test_an_interrupted_hand_over_renders_the_image_without_ao(run_in_blender, tmp_path,
                                                               no_leftovers, file_route):
    """Ctrl-C in a bpy render while the add-on's Python runs raises
    KeyboardInterrupt there, which the engine's `except Exception` let
    through: the AO passes stayed unfilled (0) and the frame was saved
    black, exit 0 (an exploratory run, bpy 5.3). Injected: the hand-over's
    save raises it. The passes say no AO (1): the image is the render."""
    out, log = render_with_fault(run_in_blender, tmp_path, {"nodes": [{"radius": 1.0}]},
                                 "interrupted")
    assert "FAULT interrupted" in log, log[-3000:]
    assert "stopped while the AO was computed" in log, log[-3000:]
    assert_no_ao_and_image_unchanged(out)


def test_unreadable_saved_passes_render_without_ao(run_in_blender, tmp_path, no_leftovers,
                                                   file_route):
    """The saved Render Result cannot be read back: the scratch path is a
    link to /dev/null, so Blender's save succeeds and the read finds an
    empty file. Observed: the render completes, AO = 1, the console says
    why (the reader's error) and "Rendering without AO", the link is
    removed, the PNG output stays PNG."""
    out, log = render_with_fault(run_in_blender, tmp_path,
                                 {"output_format": "PNG", "nodes": [{"radius": 1.0}]},
                                 "unreadable_save")
    assert "FAULT link" in log, log[-3000:]
    assert "Rendering without AO" in log, log[-3000:]
    assert output_settings(log)["file_format"] == "PNG"
    assert_no_ao_and_image_unchanged(out)


def test_internal_engine_picked_by_the_artist_explains_itself(run_in_blender, tmp_path):
    """The Render Engine menu lists the add-on's internal engine (Python
    cannot hide it). Picked for a scene of the artist's, it renders nothing
    and says what to choose instead, in the render's report; no traceback."""
    out, log = render(run_in_blender, tmp_path, {"nodes": [{"radius": 1.0}],
                                                 "prepare": ["pick_internal_engine"]})
    assert "is the HBAO add-on's internal engine and renders nothing" in log, log[-3000:]
    assert "Choose Cycles or EEVEE" in log
    assert "Traceback" not in log and "not an HBAO helper scene" not in log


def test_helper_resized_after_the_sync_still_renders_exact_ao(run_in_blender, tmp_path,
                                                              node_native, no_leftovers):
    """The helper scene is set to half size after the hook synced it (a
    render_pre handler of the artist's), to make its pass smaller than the
    Render Result. Blender renders the helper at the Render Result's size
    anyway, so the AO is computed and exact (the engine's size check, AO = 1
    with both sizes named, is not reached by this fault). Nothing is left in
    the scratch folder, the output settings are kept, and the process ends
    (bpy 4.5 deadlocked at exit after this render: scripts/bpy_blender.py)."""
    out, log = render_with_fault(run_in_blender, tmp_path,
                                 {"nodes": [{"radius": 1.0, "blur_size": 0}]},
                                 "helper_resized")
    assert "FAULT resized" in log, log[-3000:]
    assert output_settings(log)["file_format"] == "OPEN_EXR_MULTILAYER"
    assert "without AO" not in log, log[-3000:]
    expected = library_ao(node_native, out, 1, node_params(radius=1.0, blur_size=0))
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT


def test_helper_scene_rendered_by_the_artist_explains_itself(run_in_blender, tmp_path):
    """An artist makes the hidden helper scene active and renders it: it
    renders nothing, and the report says which scene to render instead."""
    out, log = render(run_in_blender, tmp_path, {"nodes": [{"radius": 1.0}],
                                                 "prepare": ["render_the_helper"]})
    assert ("\".HBAO passes Scene\" is the HBAO add-on's helper scene and renders nothing by "
            "itself. Switch back to scene \"Scene\"") in log, log[-3000:]
    assert "AO pass(es)" not in log and "Traceback" not in log


def _render_twice(run_in_blender, tmp_path, case):
    completed = run_in_blender(SCRIPTS / "render_twice.py", case, tmp_path)
    log = completed.stdout
    second = log[log.index("SECOND RENDER"):]
    after = json.loads(next(line for line in log.splitlines()
                            if line.startswith("AFTER "))[len("AFTER "):])
    return second, after


def test_deleting_the_last_node_removes_the_hook_before_the_next_render(
        run_in_blender, tmp_path):
    """A script deletes the only HBAO node and renders again (`-b`: no timer
    syncs): the render is plain, says nothing about the helper scene (it
    said the artist had rendered the helper), and the helper is gone."""
    second, after = _render_twice(run_in_blender, tmp_path, "delete_last_node")
    assert "helper scene" not in second, second[-2000:]
    assert after["scenes"] == ["Scene"], after


@pytest.mark.parametrize("case", ["guard_band_off", "back_faces_off", "guard_band_off_in_strips"])
def test_an_extra_render_turned_off_between_renders(run_in_blender, tmp_path, case):
    """A script renders with a guard band (or back faces), turns it off and
    renders again in the same process: bpy 5.3 crashed (segmentation fault,
    in render_init_depsgraph) when the second render's start removed the
    extra render's scene (an exploratory run), and every Blender crashed
    where the second render was a sequencer's animation showing the scene,
    whose strip's render ends inside it (a review). Observed: the second
    render completes with AO, and the scene is gone once it has ended."""
    second, after = _render_twice(run_in_blender, tmp_path, case)
    assert "AO pass(es)" in second, second[-2000:]
    edit = ["Edit"] if case.endswith("_in_strips") else []
    assert after["scenes"] == [".HBAO passes Scene"] + edit + ["Scene"], after
    assert node_outputs(tmp_path, 1, "HBAO0")["ao"].min() < 0.9


def test_a_panoramic_camera_says_so_on_the_node(run_in_blender, tmp_path):
    """A camera the library cannot model turns the AO off: the render's
    report said why, the node said nothing."""
    second, after = _render_twice(run_in_blender, tmp_path, "panoramic_camera")
    # (in words an artist knows, not Blender's PANO; a review's find)
    assert "camera 'Camera' is panoramic: HBAO supports perspective and orthographic" in second, \
        second[-2000:]
    assert after["statuses"] == {"HBAO0": "Panoramic camera: AO off"}, after


def test_an_edited_copy_of_the_nodes_group_is_kept(run_in_blender, tmp_path, node_native,
                                                   no_leftovers):
    """The HBAO node's group made single-user by a script (".HBAO.001") and
    edited (a Power node squares the AO): the next sync took it for File >
    Append's copy, pointed the node back at the shared group and deleted
    the copy, edit and all, without a word (an exploratory run). Observed:
    the copy is kept, and the node's AO is the library's squared."""
    out = tmp_path / "copy"
    log = run_in_blender(SCRIPTS / "node_places.py", "edited_copy", out).stdout
    assert json_line(log, "GROUP") == {"node": ".HBAO.001", "groups": [".HBAO", ".HBAO.001"]}, \
        log[-3000:]
    assert "RENDERED {'FINISHED'}" in log, log[-3000:]
    expected = library_ao(node_native, out, 1, node_params(radius=1.0, blur_size=0))
    ao = node_outputs(out, 1)["ao"]
    assert expected.min() < 0.9
    assert np.abs(ao - expected * expected).max() <= 1e-6


def test_an_error_in_a_render_handler_is_told_once_and_the_render_keeps_its_ao(
        run_in_blender, node_native, tmp_path, no_leftovers):
    """Blender prints a traceback for an error in an application handler,
    at every call (a frame's, an edit's), and the rest of the handler is
    lost. The function that gathers a render's messages made to raise
    (node_places.py failing_messages: fault injection): observed, one line
    says what could not be done, no traceback, and the node's AO is the
    library's."""
    out = tmp_path / "failing"
    log = run_in_blender(SCRIPTS / "node_places.py", "failing_messages", out,
                         addon_errors=True).stdout
    assert "RENDERED {'FINISHED'}" in log, log[-3000:]
    assert log.count("HBAO: could not prepare the render's HBAO messages: RuntimeError: "
                     "injected") == 1, log[-3000:]
    assert "Traceback" not in log, log[-3000:]
    expected = library_ao(node_native, out, 1, node_params(radius=1.0, blur_size=0))
    assert expected.min() < 0.9
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= 1e-6


def test_an_unedited_copy_gives_way_after_the_shared_group_was_edited(
        run_in_blender, tmp_path, no_leftovers):
    """File > Append of a scene whose node brings an unedited copy of the
    group (".HBAO.001") after the artist edited the shared ".HBAO" in place:
    a comparison of the two groups' contents took the copy for an edit (the
    review; so did a copy built by 4.5 opened in 5.0, whose versioning
    changes a setting). The copy is told by its own fingerprint, which
    build() keeps: observed, it gives way to the shared group."""
    source = tmp_path / "source"
    assert "SAVED" in run_in_blender(SCRIPTS / "node_places.py", "link_source", source).stdout
    log = run_in_blender(SCRIPTS / "node_places.py", "append_after_edit", tmp_path / "appended",
                         source / "source.blend").stdout
    assert json_line(log, "GROUP") == {"arrived": ".HBAO.001", "node": ".HBAO",
                                       "groups": [".HBAO"]}, log[-3000:]


@pytest.mark.min_blender(5, 1)
@pytest.mark.parametrize("case", ["strip_modifier", "compositor_strip", "muted_strip_modifier",
                                  "muted_meta"])
def test_hbao_node_in_a_strips_compositor_says_why_it_gives_no_ao(run_in_blender, tmp_path,
                                                                  no_leftovers, case):
    """An HBAO node in the node group of a sequencer strip's Compositor
    modifier, or of a Compositor strip (5.3): the node said "In a node group
    ... Ungroup it", and the render said nothing (an exploratory run).
    Observed: the node and, once, the render say that strips' compositors
    get no AO; a muted modifier's node, or one in a muted meta strip, the
    render does not (it is not composited)."""
    log = run_in_blender(SCRIPTS / "node_places.py", case, tmp_path / case).stdout
    assert "RENDERED {'FINISHED'}" in log, log[-3000:]
    assert json_line(log, "STATUS")["HBAO in strip"] == ["", "In a strip's compositor: AO off"]
    strip = "Comp" if case == "compositor_strip" else "Shot"
    said = (f'HBAO: node "HBAO in strip" in the compositor of strip "{strip}": HBAO works in '
            f"a scene's compositor, not in a sequencer strip's")
    assert log.count(said) == (0 if case.startswith("muted") else 1), log[-3000:]


@pytest.mark.min_blender(5, 0)
def test_hbao_node_in_a_linked_tree_says_why_it_gives_no_ao(run_in_blender, tmp_path,
                                                            no_leftovers):
    """A compositing node group with an HBAO node linked from another file
    (File > Link) and made the scene's compositor: each sync logged "could
    not update the HBAO hook ... Collection 'Scene Collection' is linked"
    and the node said nothing (an exploratory run). Observed: the hook
    leaves the linked tree alone, and the node and, once, the render say
    to make it local."""
    source = tmp_path / "source"
    assert "SAVED" in run_in_blender(SCRIPTS / "node_places.py", "link_source", source).stdout
    log = run_in_blender(SCRIPTS / "node_places.py", "linked_tree", tmp_path / "linked",
                         source / "source.blend").stdout
    assert "RENDERED {'FINISHED'}" in log, log[-3000:]
    assert "could not" not in log, log[-3000:]
    assert json_line(log, "STATUS")["HBAO0"] == ["", "In a linked tree: AO off"]
    said = 'HBAO: node "HBAO0" in linked tree "Look": This compositor node tree comes from'
    assert log.count(said) == 1, log[-3000:]
