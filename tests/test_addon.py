# SPDX-License-Identifier: GPL-2.0-or-later
"""The HBAO compositor node in real headless Blender renders (Cycles CPU,
96x64, few samples): tests/blender_scripts/addon_render.py builds the scene,
this file checks the EXRs Blender wrote."""
import json
import os
import subprocess

import numpy as np
import pytest

from conftest import (BLENDER, BLENDERS, REPO, _runner, blender_environment, json_line,
                      run_command)

SCRIPTS = REPO / "tests" / "blender_scripts"
APPEND_SCRIPT = REPO / "tests" / "blender_scripts" / "addon_append.py"
RENDER_SCRIPT = SCRIPTS / "addon_render.py"
# The node computes from the same 32-bit float passes, camera and parameters
# as a direct library call on the written EXR, and the library is
# deterministic: the results must be bit-identical.
EXACT = 0.0
# Image x AO is one float32 multiply in the compositor: one rounding, at most
# half an ulp, 2^-24 relative; 1e-6 relative (+1e-7 absolute) bounds it.
PRODUCT_RELATIVE_TOLERANCE = 1e-6
PRODUCT_ABSOLUTE_TOLERANCE = 1e-7
# Node AO (COSINE integration, no falloff, radius = AO distance) against
# Cycles' ray-traced AO pass (64 samples) over the pixels that are not
# background: the mean absolute difference is the screen-space method's
# error plus Cycles' noise. Measured 0.040 on this scene; 0.08 leaves room
# for Cycles version differences but fails for a wrong camera, radius or sign.
CYCLES_MEAN_ERROR_TOLERANCE = 0.08
# Background depth in Cycles' Depth pass.
CYCLES_BACKGROUND_DEPTH = 1e9

# Every test here runs in each Blender of the matrix (tests/conftest.py).
pytestmark = pytest.mark.matrix


import blenders  # noqa: E402  (conftest puts scripts/ on sys.path)
from hbao import exr_passes as exr  # noqa: E402  (conftest puts addon/ on sys.path)
from hbao import parameters as PARAMETERS  # noqa: E402
from hbao import pass_encoding  # noqa: E402
from hbao import timing_line  # noqa: E402


def render(run_in_blender, tmp_path, spec, env=None, name="render"):
    out = tmp_path / name
    completed = run_in_blender(RENDER_SCRIPT, json.dumps(spec), out, env=env)
    assert "RENDERED" in completed.stdout or "SAVED" in completed.stdout, completed.stdout[-3000:]
    return out, completed.stdout


def extra_renders(log):
    """{render: the guard band and back faces scenes it rendered} from
    addon_render.py's EXTRA RENDERS lines ("frame 1", "sequencer 1")."""
    found = [json.loads(line[len("EXTRA RENDERS "):]) for line in log.splitlines()
             if line.startswith("EXTRA RENDERS ")]
    return {entry["render"]: entry["scenes"] for entry in found}


def frame_passes(out, frame, layer="ViewLayer", with_normal=True, view=""):
    """(depth, normal) of the main render's view layer (of a stereo render's
    view with file suffix `view`); normal None unless with_normal."""
    path = out / f"frame_{frame:04d}{view}.exr"
    normal_names = [f"{layer}.Normal.{axis}" for axis in "XYZ"] if with_normal else []
    channels = exr.read_channels(path, [f"{layer}.Depth.Z"] + normal_names)
    depth = channels[f"{layer}.Depth.Z"]
    normal = np.stack([channels[name] for name in normal_names], axis=-1) if with_normal \
        else None
    return depth, normal


def node_outputs(out, frame, node="HBAO0", view=""):
    path = out / f"nodes_{frame:04d}{view}.exr"
    names = exr.channel_names(path)
    wanted = [n for n in names if n.startswith(f"{node}_") or n.startswith("Render.")
              or n.startswith("CyclesAO.")]
    channels = exr.read_channels(path, wanted)
    # Blender 3.4 leaves out a File Output input fed by a muted node: None
    result = {"ao": channels[f"{node}_AO.V"],
              "image": np.stack([channels[f"{node}_Image.{c}"] for c in "RGB"], axis=-1),
              "render": np.stack([channels[f"Render.{c}"] for c in "RGB"], axis=-1)
              if "Render.R" in channels else None}
    if "CyclesAO.R" in channels:
        result["cycles_ao"] = channels["CyclesAO.R"]
    return result


def camera(out, frame, view=""):
    return json.loads((out / f"camera_{frame:04d}{view}.json").read_text())


def library_ao(node_native, out, frame, params, with_normal=True, layer="ViewLayer", view=""):
    depth, normal = frame_passes(out, frame, layer, with_normal, view)
    return node_native.compute_ao(depth, normal, params=params, camera=camera(out, frame, view))


def node_params(**overrides):
    """The node's defaults (node.py takes them from parameters.py) as library
    params, with overrides."""
    params = {key: PARAMETERS.DEFAULTS[key]
              for key in ("radius", "angle_bias_degrees", "directions", "steps", "blur_size",
                          "strength", "falloff", "integration", "blur_sharpness")}
    params["half_resolution"] = 0
    params.update(overrides)
    return params


def test_node_ao_matches_library_cycles_and_composites_image_times_ao(
        run_in_blender, tmp_path, node_native):
    spec = {"samples": 64, "ao_reference": 1.0,
            "nodes": [{"radius": 1.0, "integration": "COSINE", "falloff": "NONE"}]}
    out, log = render(run_in_blender, tmp_path, spec)
    assert "pass hand-over" in log  # the timing line is printed
    # (3.4's hand-over read an unset colour space: a warning a frame)
    assert "pyrna_enum_to_py" not in log, log[-3000:]
    outputs = node_outputs(out, 1)
    ao = outputs["ao"]
    assert np.all(np.isfinite(ao)) and ao.min() >= 0.0 and ao.max() <= 1.0
    assert ao.min() < 0.6  # the corner and the contacts are occluded

    expected = library_ao(node_native, out, 1, node_params(integration="COSINE", falloff="NONE"))
    assert np.abs(ao - expected).max() <= EXACT

    product = outputs["render"] * ao[..., None]
    tolerance = PRODUCT_RELATIVE_TOLERANCE * np.abs(product) + PRODUCT_ABSOLUTE_TOLERANCE
    assert np.all(np.abs(outputs["image"] - product) <= tolerance)

    depth, _ = frame_passes(out, 1)
    foreground = depth < CYCLES_BACKGROUND_DEPTH
    error = np.abs(ao - outputs["cycles_ao"])[foreground].mean()
    print(f"node AO vs Cycles AO: mean absolute difference {error:.4f}")
    assert error <= CYCLES_MEAN_ERROR_TOLERANCE


# The mean |AO difference| between the corner scene and the same scene 2^14
# times larger: Cycles' rays round differently at another scale, so depths
# move in their last bits and some steps snap to a neighbouring pixel.
SCALED_SCENE_MEAN_DIFFERENCE = 0.01
# Two renders of one scene in one Blender (Cycles' fixed seed): the same
# floats, but for the last bits where threads sum samples in another order.
SAME_RENDER_TOLERANCE = 1e-5
# Pixels of the low_poly scene where the node's AO is near black while Cycles'
# AO pass is bright there (128 samples: about +-0.05 of noise): a surface that
# hides itself. Measured at 160 x 90 in bpy 4.5, 5.0 and 5.3: 71-72 with
# shading normals that face away turned round, 0 since.
SELF_HIDDEN_BLACK, SELF_HIDDEN_BRIGHT, SELF_HIDDEN_MOST = 0.15, 0.45, 5


@pytest.mark.min_blender(4, 5)
def test_smooth_shaded_coarse_meshes_do_not_hide_themselves(run_in_blender, tmp_path):
    """Coarse meshes shaded smooth (blender_scenes' low_poly scene): their
    shading normals lean past the outline, and Cycles from 4.x writes them
    facing away from the camera (3.4's do not). The library turned them round,
    into the surface, which then hid itself: black strips on the cylinder's and
    the cube's tops and a whole facet of the cone, where Cycles' AO is 0.6. It
    now mirrors such a normal to face the viewer, as the surface's depth says
    (normals.c, turn_to_viewer)."""
    spec = {"scene": "low_poly", "resolution": [160, 90], "samples": 128, "ao_reference": 1.0,
            "nodes": [{"radius": 1.0}]}  # the default blur: no dither left black
    out, _ = render(run_in_blender, tmp_path, spec)
    outputs = node_outputs(out, 1)
    ao, cycles = outputs["ao"], outputs["cycles_ao"]
    depth, _ = frame_passes(out, 1, with_normal=False)
    hidden = (depth < CYCLES_BACKGROUND_DEPTH) & (ao < SELF_HIDDEN_BLACK) & \
        (cycles > SELF_HIDDEN_BRIGHT)
    print(f"self-hidden pixels: {int(hidden.sum())}")
    assert hidden.sum() <= SELF_HIDDEN_MOST, np.argwhere(hidden)[:20]


@pytest.mark.matrix
@pytest.mark.min_blender(5, 0)
def test_a_file_saved_in_5_keeps_the_node_settings_in_4_5(run_in_blender, blender_user_scripts,
                                                          tmp_path):
    """Blender 5.0 keeps add-on properties apart from the custom properties
    where 4.5 reads them: a file saved in 5.x gave 4.5 the node settings'
    defaults, or, for a file made in 4.5 and edited in 5.x, the values 4.5
    had saved (an exploratory run). The add-on copies them there before
    each save in 5.x (older_blenders.py): 4.5 reads what 5.x saved, both
    for a file made in 5.x and one made in 4.5; 5.x reads 4.5's."""
    lts = next((b for b in BLENDERS if b.version_tuple[:2] == (4, 5)), None)
    assert lts is not None, "the matrix has no Blender 4.5"
    run_lts = _runner(lts, blender_user_scripts)
    script = SCRIPTS / "older_blender_settings.py"
    first = {"falloff": "QUADRATIC", "integration": "HBAO", "half_resolution": True,
             "blur_sharpness": 12.0, "guard_band": 5.0, "back_faces": True}
    second = {"falloff": "NONE", "integration": "COSINE", "half_resolution": False,
              "blur_sharpness": 20.0, "guard_band": 0.0, "back_faces": False}
    made_in_5, made_in_4_5, edited = (tmp_path / name for name in ("5.blend", "4.5.blend",
                                                                   "edited.blend"))
    run_in_blender(script, made_in_5, json.dumps(first))
    assert json_line(run_lts(script, "-", "-", blend=made_in_5).stdout, "SETTINGS") == first
    run_lts(script, made_in_4_5, json.dumps(first))
    log = run_in_blender(script, edited, json.dumps(second), blend=made_in_4_5).stdout
    assert json_line(log, "SETTINGS") == first
    assert json_line(run_lts(script, "-", "-", blend=edited).stdout, "SETTINGS") == second


def test_the_release_gives_the_librarys_memory_back_inside_blender(run_in_blender):
    """hbao_release_memory(), which the add-on calls when a render ends,
    gives back to the system what the library kept: in bpy's process
    0.6.0's release gave back 24 of a 1080p frame's 52 MB (its malloc had
    put the smaller blocks in its heap; docs/speed.md, session 64). Runs
    scripts/bench_release_memory.py's part inside Blender: one 1080p AO
    through the binding, a few of the host's allocations after it, the
    release. Held: the AO's buffers were resident (40 MB or more), and at
    least 90 % of that growth goes back."""
    completed = run_in_blender(REPO / "scripts" / "bench_release_memory.py", "--inside",
                               addon=False)
    rss = json_line(completed.stdout, "RELEASE")
    grown = rss["computed"] - rss["start"]
    assert grown >= 40.0, rss
    assert rss["computed"] - rss["released"] >= 0.9 * grown, rss


def test_disabling_the_add_on_in_a_session_leaves_the_plain_render(run_in_blender, blender,
                                                                   tmp_path):
    """The add-on disabled in a session (Preferences, or before removing it),
    then a render: Blender 3.4 (which keeps the node's class) and bpy 5.3
    composited the node with its AO pass from a helper scene that no engine
    of ours rendered: the final image black, with no message. The add-on now
    unlinks the pass as it goes (the node's AO input is then 1) and mutes
    its Render Layers node, so the render is the plain one; enabled again, the
    AO is back. 4.5 and 5.0 skip the compositing of a tree with a node type
    nobody registered: the plain render as well."""
    out = tmp_path / "out"
    completed = run_in_blender(SCRIPTS / "addon_disable_in_session.py", out)
    assert "DISABLED IN SESSION DONE" in completed.stdout, completed.stdout[-3000:]
    images = {}
    for step in ("enabled", "muted", "disabled", "enabled_again", "disabled_under_another"):
        channels = exr.read_channels(out / f"{step}.exr", ["R", "G", "B"])
        images[step] = np.stack([channels[c] for c in "RGB"], axis=-1)
    assert np.abs(images["disabled"] - images["muted"]).max() <= SAME_RENDER_TOLERANCE
    assert np.abs(images["enabled_again"] - images["enabled"]).max() <= SAME_RENDER_TOLERANCE
    assert np.abs(images["disabled_under_another"] - images["muted"]).max() \
        <= SAME_RENDER_TOLERANCE
    # Cycles' own render() back once the add-on is disabled, wrapped once
    # again when it is enabled (engine_wrap.py; 3.4 is never wrapped); a
    # later wrapper of another add-on's kept.
    wrapped = "wrapped" if blender.version_tuple >= (4, 5) else "own"
    assert json_line(completed.stdout, "ENGINE RENDER") == {
        "enabled": wrapped, "disabled": "own", "enabled_again": wrapped,
        "disabled_under_another": "another's"}
    # the AO is real: the corner darker than in the plain render
    assert (images["enabled"] < images["muted"] - 0.05).any()


def test_compositing_scenes_and_the_sources_a_node_refuses(run_in_blender, blender, tmp_path):
    """Found by an exploratory run, in every Blender:
    - a scene that only composites (another scene's render, or images) with
      an HBAO node: Blender refused its render, "Cannot render, no camera"
      (the add-on's helper scene copied the scene's camera, none), and
      nothing was written. The helper borrows the shown scene's camera, or
      one made for it and removed with it; the render goes on, and the node
      says why its AO is off;
    - the node, refusing another scene's passes, still turned them on in
      that scene (a lasting change there), and its status line said "Depth
      pass turned on", not why its AO was off;
    - Connect Passes linked the tree's first Render Layers node even where
      it showed another scene or was muted, which the node then refused: it
      takes the first the node accepts, or makes one;
    - a node fed by an Image node (a saved render) now points to the CLI,
      and a muted link is called muted, not unlinked."""
    completed = run_in_blender(SCRIPTS / "compositing_scene.py", tmp_path)
    log = completed.stdout
    assert "COMPOSITING DONE" in log, log[-3000:]
    cases = {line.split(" ", 2)[1]: json.loads(line.split(" ", 2)[2])
             for line in log.splitlines()
             if line.startswith("COMPOSITING ") and line != "COMPOSITING DONE"}
    assert set(cases) == {"other_scene", "connected", "image_only"}, cases
    for case, outcome in cases.items():
        assert outcome["result"] == ["FINISHED"] and outcome["written"], (case, outcome)
        assert (tmp_path / f"{case}.png").stat().st_size > 0
    assert "no camera" not in log
    assert cases["other_scene"]["status"] == ["Depth: other scene, AO off"]
    assert "OTHER SCENE PASSES [false, false]" in log
    connected = json.loads(next(line for line in log.splitlines()
                                if line.startswith("CONNECTED "))[len("CONNECTED "):])
    assert connected == {"result": ["FINISHED"], "scene": "Shot", "muted": False,
                         "passes": [True, True], "elsewhere_passes": [False, False]}, connected
    assert cases["connected"]["status"] == [""] and "1 AO pass(es)" in log
    # (3.4 lists no muted link among a socket's links: unlinked there)
    muted = "Depth: link muted," if blender.version_tuple >= (4, 0) else "Depth not linked:"
    assert cases["image_only"]["status"] == ["Depth: wrong source, AO off", f"{muted} AO off"]
    # a camera made for the helper (not the add-on's guard band camera of
    # Shot: it outlived the band; nor an artist's object of its name, with a
    # new camera at every sync: a review), gone with the helper
    assert "PLATE HELPER CAMERA .HBAO stand-in camera.001 CAMERA" in log
    assert "STAND-IN LEFT [\".HBAO stand-in camera\"]" in log  # the artist's
    assert ("Depth must come straight from a Render Layers node (for a saved render's EXR, use "
            "the hbao command-line tool); AO off") in log


def test_disabling_after_a_reload_of_the_package_still_lets_go(run_in_blender, tmp_path):
    """Reload Scripts re-runs the package of an add-on enabled for the
    session (--addons): its list of registered modules was reset, so a later
    disable (or quit) unregistered nothing: handlers stayed, the AO pass
    stayed linked (a review). The list survives the reload now."""
    completed = run_in_blender(SCRIPTS / "addon_reload_disable.py", tmp_path)
    line = next((text for text in completed.stdout.splitlines()
                 if text.startswith("RELOAD DISABLE ")), None)
    assert line is not None, completed.stdout[-3000:]
    state = json.loads(line[len("RELOAD DISABLE "):])
    assert state == {"linked_before": True, "linked_after": False, "muted": True,
                     "handlers_left": []}, state


def test_a_sync_reads_each_scene_a_bounded_number_of_times(run_in_blender):
    """An exploratory run timed the add-on in big files: a sync of its hook
    (after every edit, at load, save and a render's end) took 0.4 s with 30
    scenes and 16-27 s with 100 in 3.4 and 4.5, and the nodes' quarter-second
    timer 0.1-8 s a tick, idle: each lookup walked every scene's tree for
    every pair of scenes. Counted (sync_scaling.py: the lookups of a tree's
    managed node, in a second sync of 8, 16 and 32 scenes of
    bench/addon_sync.py, and in the timer's refresh with no render done):
    a file twice as big costs at most 2.5 times as many (it was 6-7 times),
    the idle timer looks up nothing, and a sync walks the sequencers' strips
    once (it walked them for every helper: most of a 0.5 s sync with 3000
    strips). In 5.3 a sync reads each scene's stack of compositor effects
    about once (it read them once per helper: 1250 reads with 32 scenes, 58 %
    of a 100-scene sync); the Blenders before have no stack (0 reads)."""
    log = run_in_blender(SCRIPTS / "sync_scaling.py", "8", "16", "32").stdout
    counts = {int(count): calls for count, calls in json_line(log, "SCALING").items()}
    for count in (16, 32):
        assert counts[count][0] <= 2.5 * counts[count // 2][0], counts
        assert counts[count][0] <= 8 * count, counts
        # the file has 1.5 count + 1 scenes (a helper for every other one)
        assert counts[count][3] <= 3 * count, counts
    assert all(calls[1] == 0 and calls[2] == 1 for calls in counts.values()), counts


def test_node_thickness_reaches_the_library(run_in_blender, tmp_path, node_native):
    """The Thickness socket is the library's hbao_params.thickness: the node's
    AO equals the library's with it, and differs from infinitely thick."""
    spec = {"nodes": [{"radius": 0.7, "blur_size": 0, "thickness": 0.1}]}
    out, _ = render(run_in_blender, tmp_path, spec)
    ao = node_outputs(out, 1)["ao"]
    expected = library_ao(node_native, out, 1, node_params(radius=0.7, blur_size=0, thickness=0.1))
    assert np.abs(ao - expected).max() <= EXACT
    thick = library_ao(node_native, out, 1, node_params(radius=0.7, blur_size=0))
    assert np.abs(ao - thick).max() > 0.05  # the thickness changed the AO


def test_connect_passes_button_turns_passes_on_and_links_them(
        run_in_blender, tmp_path, node_native):
    """An artist adds the node to a view layer without Depth and Normal
    passes (Render Layers then has no such outputs to link): the node's
    Connect Passes button turns them on and links them, and the render has AO."""
    spec = {"nodes": [{"radius": 0.8, "blur_size": 0, "connect_with_operator": True}],
            "disable_depth_pass": True, "disable_normal_pass": True}
    out, log = render(run_in_blender, tmp_path, spec)
    assert "CONNECT HBAO0 {'FINISHED'}" in log, log[-3000:]
    assert ("Turned on the Depth and Normal passes of view layer 'ViewLayer'; linked Image, "
            "Depth, Normal from 'Render Layers'") in log, log[-3000:]
    ao = node_outputs(out, 1)["ao"]
    expected = library_ao(node_native, out, 1, node_params(radius=0.8, blur_size=0))
    assert ao.min() < 0.9 and np.abs(ao - expected).max() <= EXACT


def test_time_remapped_animated_camera_gets_the_rendered_cameras_ao(
        run_in_blender, tmp_path, node_native):
    """Time Remapping 100 -> 50: frame 2 shows the time of frame 1, and the
    camera moves. The node's AO is the library's with the camera Blender
    rendered (it took the camera at frame 2's own time: the helper scene did
    not have the remapping; a farm check found it)."""
    spec = {"frames": [2], "animate_camera": True, "time_remap": [100, 50],
            "nodes": [{"radius": 0.7, "blur_size": 0}]}
    out, _ = render(run_in_blender, tmp_path, spec)
    expected = library_ao(node_native, out, 2, node_params(radius=0.7, blur_size=0))
    assert np.abs(node_outputs(out, 2)["ao"] - expected).max() <= EXACT


@pytest.mark.parametrize("sequencer", ["override", "other_frame", "muted_meta", "nested",
                                       "covered"])
def test_sequencer_strip_camera_override_gets_that_cameras_ao(run_in_blender, tmp_path, node_native,
                                                              sequencer):
    """A Video Sequencer scene strip with a Camera override renders the
    scene through that camera: the node's AO in the sequencer's render is
    the library's with that camera, as when the scene itself renders
    through it (the scene camera's turned the normals by the wrong matrix,
    silently; found by an exploratory run). So too beside a strip through
    the scene's camera that shows another frame of the scene or lies in a
    muted meta strip (the AO was off: "different cameras"), and where the
    sequencer is itself shown by another's strip (the scene camera's AO,
    silently). The guard band and back faces renders follow the scene
    camera: through the strip they are left out, the node says so, and
    their scenes do not render in vain; the scene's own render after it
    renders them."""
    spec = {"sequencer": sequencer,
            "nodes": [{"radius": 0.7, "blur_size": 0},
                      {"radius": 0.7, "blur_size": 0, "back_faces": True, "guard_band": 10.0}]}
    out, log = render(run_in_blender, tmp_path, spec)
    params = node_params(radius=0.7, blur_size=0)
    expected = library_ao(node_native, out, 1, params)
    through_strip = exr.read_channels(out / "strip_nodes_0001.exr", ["HBAO0_AO.V", "HBAO1_AO.V"])
    assert expected.min() < 0.9
    for node in ("HBAO0", "HBAO1"):
        assert np.abs(through_strip[f"{node}_AO.V"] - expected).max() <= EXACT, node
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT
    assert "through camera 'Strip Camera'" in log
    for kind in ("guard band", "back faces"):
        assert f"no {kind}: a Video Sequencer strip renders the scene through another camera" \
            in log, kind
    rendered = extra_renders(log)
    # (a strip showing another frame through the scene camera uses them)
    used = [".HBAO back faces Scene", ".HBAO guard band Scene"] if sequencer == "other_frame" \
        else []
    assert sorted(rendered["sequencer 1"]) == used, rendered
    assert sorted(rendered["frame 1"]) == [".HBAO back faces Scene", ".HBAO guard band Scene"]


def test_a_sequencer_animation_that_could_not_start_leaves_no_strip_camera(
        run_in_blender, tmp_path, node_native):
    """An animation render of the sequencer's scene that cannot write its
    movie starts a render job that never ends (no render_complete nor
    render_cancel): the scene's own render after it still gets its own
    camera's AO, not the strip's (found by a review)."""
    spec = {"sequencer": "failed_movie", "nodes": [{"radius": 0.7, "blur_size": 0}]}
    out, log = render(run_in_blender, tmp_path, spec)
    assert "MOVIE" in log
    expected = library_ao(node_native, out, 1, node_params(radius=0.7, blur_size=0))
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT
    assert "rendered by a sequencer strip" not in log


def test_sequencer_strips_with_two_cameras_at_one_frame_turn_the_ao_off(run_in_blender, tmp_path):
    """Two strips show the scene at the same frame through different
    cameras: which one is rendering cannot be told, so the AO is off (1)
    and the render says why, rather than AO through a wrong camera."""
    spec = {"sequencer": "two_cameras", "nodes": [{"radius": 0.7, "blur_size": 0},
                                                  {"radius": 0.7, "back_faces": True}]}
    out, log = render(run_in_blender, tmp_path, spec)
    through_strip = exr.read_channels(out / "strip_nodes_0001.exr", ["HBAO0_AO.V"])["HBAO0_AO.V"]
    assert through_strip.min() == 1.0
    # the back faces scene, which would follow the scene camera, does not
    # render in vain (the hook's preparation raised there: found by a review)
    assert "could not prepare the HBAO hook" not in log, log[-3000:]
    assert extra_renders(log)["sequencer 1"] == []
    assert ("the Video Sequencer strips 'Shot', 'Shot again' show scene 'Scene' at its frame 1 "
            "through different cameras ('Camera', 'Strip Camera')") in log
    assert node_outputs(out, 1)["ao"].min() < 0.9  # the scene's own render has its AO


def test_a_camera_scaled_unevenly_gets_the_ao_of_the_unscaled_one(run_in_blender, tmp_path):
    """Blender renders through a camera object as if it were unscaled (it
    normalises the axes of its matrix), so a camera scaled by (1, 2, 0.5)
    gives the same passes; its node AO must be the same too. The normals
    were turned by the scaled matrix: AO off by up to 0.31, silently."""
    node = {"radius": 0.7, "blur_size": 0}
    plain, _ = render(run_in_blender, tmp_path, {"nodes": [node]}, name="plain")
    scaled, log = render(run_in_blender, tmp_path, {"nodes": [node],
                                                    "camera_scale": [1.0, 2.0, 0.5]},
                         name="scaled")
    assert "without AO" not in log, log[-3000:]
    for plain_pass, scaled_pass in zip(frame_passes(plain, 1), frame_passes(scaled, 1)):
        assert np.abs(plain_pass - scaled_pass).max() <= 1e-6  # Blender: the same render
    expected = node_outputs(plain, 1)["ao"]
    assert expected.min() < 0.9
    # (1e-5: the two matrices' inverses round differently; measured 3e-8)
    assert np.abs(node_outputs(scaled, 1)["ao"] - expected).max() <= 1e-5


@pytest.mark.parametrize("clip_end, tilt", [(5.6, 0.2), (1e5, 0.35)])
def test_the_sky_at_clip_end_is_background(run_in_blender, tmp_path, node_native, clip_end, tilt):
    """EEVEE in 4.5 and 5.0 writes the sky's Depth as the camera's Clip End
    (or a rounding of it) where 3.4 writes 65504 and 5.3 1e10: the sky was
    then a wall at Clip End, and took AO from what stood near it (0.52 off,
    the sky darkened: found by an exploratory run). A depth at Clip End is
    background: AO 1, and the rest is the library's AO with that
    background. With a long clip range (Clip End 1e5, Clip Start 0.1) 4.5
    and 5.0 write the sky a little short of Clip End (99864.38: the depth
    buffer's precision), which is background too (hbao_clip_background_depth;
    a review found it a wall once 65504 no longer capped the background)."""
    from hbao import camera as camera_model
    node = {"radius": 1.0, "blur_size": 0}
    out, log = render(run_in_blender, tmp_path, {
        "engine": "BLENDER_EEVEE", "samples": 1, "clip_end": clip_end, "camera_tilt": tilt,
        "nodes": [node]})
    assert "without AO" not in log, log[-3000:]
    depth, normal = frame_passes(out, 1)
    description = camera(out, 1)
    assert description["clip_end"] == pytest.approx(clip_end)
    background = np.float32(camera_model.background_depth(description, 65504.0))
    # what each Blender wrote for the sky past the scene (which lies within
    # 20 units) is background by the node's rule, 3.4's 65504 by libhbao's
    written_sky = (depth > 20.0) & (depth != 65504.0)
    assert np.all(depth[written_sky] >= background), (depth[written_sky].min(), background)
    sky = (depth >= background) | (depth == 65504.0)
    assert 50 < sky.sum() < depth.size - 50, sky.sum()  # sky and geometry both in view
    ao = node_outputs(out, 1)["ao"]
    assert ao.min() < 0.9 and np.all(ao[sky] == 1.0)
    expected = node_native.compute_ao(depth, normal, camera=description,
                                      params=dict(node_params(**node), background_depth=background))
    assert np.abs(ao - expected).max() <= EXACT


def test_a_scene_past_65504_units_gets_its_ao(run_in_blender, tmp_path):
    """The corner scene 2^14 times larger (depths about 70000 to 120000, the
    radius and the camera's clip range too), as a scene modelled in
    centimetres is past 655 m: every depth past 65504 was background, the AO
    1 everywhere, silently (an exploratory run). The background is now what
    lies at Clip End (camera.background_depth), and the AO is the unscaled
    scene's, but for Cycles' own rounding of the larger scene's rays."""
    ao = {}
    for name, scale in (("plain", 1.0), ("scaled", 2.0 ** 14)):
        out, _ = render(run_in_blender, tmp_path, {
            "scene_scale": scale, "nodes": [{"radius": 1.0 * scale, "blur_size": 0}]}, name=name)
        ao[name] = node_outputs(out, 1)["ao"]
    assert ao["plain"].min() < 0.7
    difference = np.abs(ao["scaled"] - ao["plain"])
    assert difference.mean() <= SCALED_SCENE_MEAN_DIFFERENCE, difference.mean()


def position_misfit(node_native, out, frame, description):
    """The median distance between where `description` (a camera dict)
    puts each foreground pixel's Depth and where Cycles' Position pass says
    its surface is: small for the camera the passes were rendered through
    (blurred passes fit no camera exactly)."""
    layer = "ViewLayer"
    names = [f"{layer}.Depth.Z"] + [f"{layer}.Position.{axis}" for axis in "XYZ"]
    channels = exr.read_channels(out / f"frame_{frame:04d}.exr", names)
    depth = channels[names[0]]
    height, width = depth.shape
    view = node_native.camera_view(description, width, height)
    columns = view.origin_x + (np.arange(width) + 0.5) * view.pixel_size_x
    rows = view.origin_y + (np.arange(height)[::-1] + 0.5) * view.pixel_size_y  # top row first
    x, y = np.meshgrid(columns, rows)
    points = np.stack([x * depth, y * depth, -depth, np.ones_like(depth)], axis=-1)
    to_world = np.linalg.inv(np.array(description["world_to_camera"], dtype=np.float64))
    world = points @ to_world.T
    position = np.stack([channels[name] for name in names[1:]], axis=-1)
    foreground = depth < 1e9
    return float(np.median(np.linalg.norm(world[..., :3] - position, axis=-1)[foreground]))


@pytest.mark.parametrize("time", [{"subframe": 0.5}, {"motion_blur": "START"},
                                  {"motion_blur": "END"}, {"motion_blur": "CENTER"},
                                  {"motion_blur": "START", "engine": "BLENDER_EEVEE",
                                   "samples": 1}],
                         ids=["subframe", "blur_start", "blur_end", "blur_center",
                              "eevee_blur_start"])
def test_a_moving_camera_at_the_time_its_passes_show(run_in_blender, blender, tmp_path, node_native,
                                                     time):
    """A render at a subframe shows the camera there, and with camera motion
    blur the passes average about the camera at the middle of the shutter
    (after the frame with Position Start, before it with End). The add-on
    took the camera at the whole frame: 0.03 to 0.16 off with a camera
    moving 0.2 units a frame (found by an exploratory run, against Cycles'
    Position pass). The node's AO is the library's with the camera that
    the test script evaluates at that time itself, and that camera fits
    Cycles' Position pass better than the whole frame's. The guard band and back
    faces, which Blender renders at the whole frame, are left out of the
    other times (not rendered, and the node says why: a review found them
    stitched to the passes from another time)."""
    node = {"radius": 0.7, "blur_size": 0}
    nodes = [node, dict(node, name="HBAO1", guard_band=10.0, back_faces=True)]
    out, log = render(run_in_blender, tmp_path, dict(time, frames=[2], animate_camera=True,
                                                     position_pass=True, nodes=nodes))
    assert "without AO" not in log, log[-3000:]
    expected = library_ao(node_native, out, 2, node_params(**node))
    assert expected.min() < 0.9
    assert np.abs(node_outputs(out, 2)["ao"] - expected).max() <= EXACT
    other_time = time.get("motion_blur") != "CENTER"
    # (3.4's EEVEE makes no Position pass; there the AO's equality above is the check)
    has_position = "ViewLayer.Position.X" in exr.channel_names(out / "frame_0002.exr")
    assert has_position or (time.get("engine") and blender.version_tuple < (4, 2))
    if other_time and has_position:  # that time's camera puts the Depth on the Position pass
        at_frame = json.loads((out / "camera_at_frame_0002.json").read_text())
        fits = [position_misfit(node_native, out, 2, description)
                for description in (camera(out, 2), at_frame)]
        assert fits[0] < 0.7 * fits[1], fits
    for kind in ("guard band", "back faces"):
        assert (f"no {kind}: the passes show the camera at another time than the frame"
                in log) == other_time, kind
    assert len(extra_renders(log)["frame 2"]) == (0 if other_time else 2)


def test_a_sheared_camera_turns_the_ao_off_and_says_why(run_in_blender, tmp_path):
    """A turned camera inside an empty scaled unevenly: Blender keeps its
    axes unit length but not square, and renders a sheared view, whose AO
    the library's pinhole camera does not give (0.15 to 0.26 off, silently:
    found by an exploratory run). The AO is off and the node and log say
    why. Inside an empty scaled evenly the camera renders as without it,
    and so does its AO."""
    node = {"radius": 0.7, "blur_size": 0}
    plain, _ = render(run_in_blender, tmp_path, {"nodes": [node], "camera_rig": [1, 1, 1]},
                      name="plain")
    even, log = render(run_in_blender, tmp_path, {"nodes": [node],
                                                  "camera_rig": [1.3, 1.3, 1.3]}, name="even")
    assert "is sheared" not in log, log[-3000:]
    expected = node_outputs(plain, 1)["ao"]
    assert expected.min() < 0.9
    # (the scaled matrix rounds differently: up to 1.6e-5 measured, in bpy 5.0)
    assert np.abs(node_outputs(even, 1)["ao"] - expected).max() <= 1e-4
    sheared, log = render(run_in_blender, tmp_path, {"nodes": [node],
                                                     "camera_rig": [1, 1.6, 0.7]}, name="sheared")
    assert "camera 'Camera' is sheared (its matrix's axes are not square" in log, log[-3000:]
    statuses = [json.loads(line[len("STATUS "):]) for line in log.splitlines()
                if line.startswith("STATUS ")]
    assert statuses == [{"node": "HBAO0", "status": "Sheared camera: AO off"}], statuses
    assert node_outputs(sheared, 1)["ao"].min() == 1.0


@pytest.mark.parametrize("border", [None, [0.2, 0.75, 0.1, 0.8]], ids=["frame", "cropped_border"])
def test_node_ao_matches_cli_with_the_written_camera(run_in_blender, tmp_path, hbao_tool,
                                                     border):
    """The CLI on the saved passes with the camera written beside them
    (blender_scenes.camera_description, as scripts/export_cameras.py writes
    it) gives the node's AO, for a cropped border render too: Blender writes
    the crop as a whole image, so the camera must be the crop's."""
    spec = {"nodes": [{"radius": 0.7, "blur_size": 0}]}
    if border:
        spec["border"] = border
    out, _ = render(run_in_blender, tmp_path, spec)
    cli_out = out / "cli_ao.exr"
    completed = subprocess.run(
        [str(hbao_tool), str(out / "frame_0001.exr"), "-o", str(cli_out), "--layer",
         "ViewLayer", "--camera", str(out / "camera_0001.json"), "--radius", "0.7",
         "--blur", "0", "--compression", "none"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert completed.returncode == 0, completed.stdout
    # (the node's AO through the helper's pass: pass_encoding)
    cli_ao = pass_encoding.node_ao(pass_encoding.occlusion_pass(
        exr.read_channels(cli_out, ["AO"])["AO"]))
    node_ao = node_outputs(out, 1)["ao"]
    assert cli_ao.shape == node_ao.shape and node_ao.min() < 0.9
    assert np.abs(node_ao - cli_ao).max() <= EXACT


def test_keyframed_radius_and_value_node(run_in_blender, tmp_path, node_native):
    spec = {"frames": [1, 2], "orthographic": True, "nodes": [
        {"name": "Keyed", "keyframes": [[1, 0.15], [2, 1.2]], "blur_size": 0},
        {"name": "Valued", "radius_from_value_node": 0.5, "normal": False}]}
    out, _ = render(run_in_blender, tmp_path, spec)
    ao = {frame: node_outputs(out, frame, "Keyed")["ao"] for frame in (1, 2)}
    for frame, radius in ((1, 0.15), (2, 1.2)):
        expected = library_ao(node_native, out, frame, node_params(radius=radius, blur_size=0))
        assert np.abs(ao[frame] - expected).max() <= EXACT
    # A larger radius sees more occluders: clearly darker on average.
    assert ao[2].mean() < ao[1].mean() - 0.02
    valued = node_outputs(out, 1, "Valued")["ao"]
    expected = library_ao(node_native, out, 1, node_params(radius=0.5), with_normal=False)
    assert np.abs(valued - expected).max() <= EXACT


def test_unchanged_frame_reuses_its_ao(run_in_blender, tmp_path, node_native):
    """Frames 1 and 2 render the same passes with the same settings: frame 2
    reuses frame 1's AO (ao_cache.py; the console line says so) and it is
    still exactly the library's. Frame 3 changes one node's radius: that
    node's AO is computed anew, the other node's reused. Two nodes reading
    the same passes with different radii each keep their own AO."""
    spec = {"frames": [1, 2, 3], "nodes": [
        {"name": "Keyed", "keyframes": [[1, 0.6], [2, 0.6], [3, 1.1]], "blur_size": 0},
        {"name": "Fixed", "radius": 0.3, "blur_size": 0}]}
    out, log = render(run_in_blender, tmp_path, spec)
    lines = [line for line in log.splitlines() if line.startswith("HBAO: 2 AO pass(es) ")]
    assert len(lines) == 3, log[-3000:]
    assert "unchanged: reused" not in lines[0], lines
    assert "(2 of 2 unchanged: reused)" in lines[1], lines
    assert "(1 of 2 unchanged: reused)" in lines[2], lines
    # The parser that the benchmarks and the soak use reads the real lines.
    figures = [timing_line.parse(line) for line in lines]
    assert [f and (f["passes"], f["reused"]) for f in figures] == [(2, 0), (2, 2), (2, 1)], lines
    passes = [frame_passes(out, frame) for frame in (1, 2, 3)]
    assert all(np.array_equal(a, b) for a, b in zip(passes[0], passes[1]))
    for frame, radius in ((1, 0.6), (2, 0.6), (3, 1.1)):
        keyed = node_outputs(out, frame, "Keyed")["ao"]
        expected = library_ao(node_native, out, frame, node_params(radius=radius, blur_size=0))
        assert np.abs(keyed - expected).max() <= EXACT
        fixed = node_outputs(out, frame, "Fixed")["ao"]
        expected = library_ao(node_native, out, frame, node_params(radius=0.3, blur_size=0))
        assert np.abs(fixed - expected).max() <= EXACT


def test_the_ao_uses_the_threads_blender_renders_with(run_in_blender, tmp_path, node_native):
    """The AO (and the passes' read) runs on as many threads as Blender
    renders the scene with (RenderSettings.threads: `-t N`, else Fixed,
    else one per CPU), so a farm worker held to N threads stays there; the
    timing line says how many. Auto counts only the CPUs the process may
    run on (Blender's own count is every CPU online): Blender runs here on
    one CPU. The number is no setting of the AO (the same for any number):
    frame 2, the same passes on other threads, reuses frame 1's AO."""
    spec = {"frames": [1, 2, 3], "render_threads": {"1": 1, "2": 3, "3": 0},
            "nodes": [{"radius": 0.6, "blur_size": 0}]}
    allowed = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(allowed)})  # Blender inherits it
    try:
        out, log = render(run_in_blender, tmp_path, spec)
    finally:
        os.sched_setaffinity(0, allowed)
    figures = [timing_line.parse(line) for line in log.splitlines()
               if line.startswith("HBAO: 1 AO pass(es) ")]
    assert [f["threads"] for f in figures] == [1, 3, 1], log[-3000:]
    # and the horizon search that ran, as the library names it
    assert [f["search"] for f in figures] == [node_native.search_name()] * 3, log[-3000:]
    assert [f["reused"] for f in figures] == [0, 1, 1]
    expected = library_ao(node_native, out, 1, node_params(radius=0.6, blur_size=0))
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT


def printed_hints(log):
    """{step label: the node's hint line, or None} from addon_render.py's HINT lines."""
    hints = {}
    for line in log.splitlines():
        if line.startswith("HINT "):
            said = json.loads(line[len("HINT "):])
            hints[said["label"]] = said["hint"][0] if said["hint"] else None
    return hints


def test_node_says_when_its_settings_changed_since_the_render(run_in_blender, tmp_path):
    """Re-compositing an existing render keeps the AO of the settings it was
    rendered with (README, Limits): after a render the node says when its
    settings no longer match (render_record.py, drawn under the settings),
    and stops saying it when they match again. The render's own frame
    counts: the keyframed radius differs at frame 5, but frame 1 was
    rendered."""
    spec = {"frames": [1], "nodes": [
        {"name": "Hinted", "keyframes": [[1, 0.6], [5, 1.1]], "blur_size": 0}],
        "after_render": [
            {"label": "as rendered"},
            {"label": "other frame", "frame": 5},
            {"label": "blur size", "socket": ["Blur Size", 3]},
            {"label": "blur size back", "socket": ["Blur Size", 0]},
            {"label": "integration", "integration": "HBAO"},
            {"label": "integration back", "integration": "COSINE"},
            {"label": "back faces", "back_faces": True},
            {"label": "back faces off", "back_faces": False},
            {"label": "blur size, muted", "socket": ["Blur Size", 5], "mute": True}]}
    _out, log = render(run_in_blender, tmp_path, spec)
    hints = printed_hints(log)
    changed = "Changed: render to update"
    assert hints == {"as rendered": None, "other frame": None,
                     "blur size": changed, "blur size back": None,
                     "integration": changed, "integration back": None,
                     "back faces": changed, "back faces off": None,
                     "blur size, muted": None}, log[-3000:]


def test_new_node_settings_reach_the_ao_without_a_render(run_in_blender, tmp_path, node_native):
    """After a render, a node whose AO parameters changed gets its AO from
    the passes that render handed over (recomposite.py: in a window the
    add-on's timer does this, the AO in a worker thread, then Blender
    composites again): no save, no read, the node's hint cleared.
    Rendering the frame again then finds that AO in the cache, so it is the
    AO a render computes; it is exactly the library's. A change that needs
    other passes (Normal unlinked) is left to the next render, and the node
    keeps saying so; so is a frame whose helper would render at another
    size than the kept passes. A file opened again keeps nothing of the
    render before it."""
    spec = {"frames": [1], "nodes": [{"name": "Hinted", "radius": 0.6, "blur_size": 0}],
            "user_handlers": True,
            "after_render": [
                {"label": "radius", "socket": ["Radius", 1.1]},
                {"label": "half size", "resolution_percentage": 50, "refresh": True},
                {"label": "full size", "resolution_percentage": 100},
                {"label": "refreshed", "refresh": True},
                {"label": "rendered again", "render": 1},
                {"label": "unchanged", "refresh": True},
                {"label": "normal unlinked", "unlink": "Normal"},
                {"label": "not refreshed", "refresh": True},
                {"label": "reopened", "reopen": True},
                {"label": "radius after reopening", "socket": ["Radius", 0.8], "refresh": True}]}
    out, log = render(run_in_blender, tmp_path, spec)
    lines = [line for line in log.splitlines() if line.startswith("HBAO: 1 AO pass(es) ")]
    assert len(lines) == 3, log[-3000:]
    assert "re-composited with new settings from the last render's passes (their AO " \
        "computed beforehand in" in lines[1], lines
    # The helper's render finds the AO computed from the kept passes in the cache.
    assert "(1 of 1 unchanged: reused)" in lines[1], lines
    assert "(save 0, read 0, write" in lines[1], lines
    assert "(1 of 1 unchanged: reused)" in lines[2], lines
    # The parser that the benchmarks use reads the real lines.
    first, refreshed_line = (timing_line.parse(line) for line in lines[:2])
    assert first and not first["recomposited"] and not first["reused"], lines
    assert refreshed_line and refreshed_line["recomposited"], lines
    assert (refreshed_line["reused"], refreshed_line["save_ms"],
            refreshed_line["read_ms"]) == (1, 0, 0), lines
    refreshed = [line.split()[1] for line in log.splitlines() if line.startswith("REFRESHED ")]
    # After the file is opened again, nothing of the render before is kept.
    assert refreshed == ["False", "True", "False", "False", "False"], log[-3000:]
    # A pipeline's own render handlers see the artist's two renders, never
    # the helper scene that the refreshes render alone (handler_hold.py).
    seen = json.loads(next(line for line in log.splitlines()
                           if line.startswith("USER HANDLERS "))[len("USER HANDLERS "):])
    assert len(seen["render_complete"]) == 2, seen
    for name, scenes in seen.items():
        helper = [scene for scene in scenes if scene.startswith(".HBAO")]
        if name.startswith("render_"):
            assert not helper, seen
        else:  # Blender sets every scene a render renders to its frame: once a render
            assert len(helper) == len(seen["render_complete"]), seen
    hints = printed_hints(log)
    changed = "Changed: render to update"
    assert hints == {"radius": changed, "half size": changed, "full size": changed,
                     "refreshed": None, "rendered again": None,
                     "unchanged": None, "normal unlinked": changed,
                     "not refreshed": changed, "reopened": None,
                     "radius after reopening": None}, log[-3000:]
    assert (out / "frame_0001_again.exr").is_file(), log[-3000:]
    # The File Output of the second render (radius 1.1) replaced the first's.
    ao = node_outputs(out, 1, "Hinted")["ao"]
    expected = library_ao(node_native, out, 1, node_params(radius=1.1, blur_size=0))
    assert np.abs(ao - expected).max() <= EXACT


def test_a_render_stops_the_refresh_worker(run_in_blender, tmp_path, node_native):
    """Two nodes' radius changed after a render: the refresh's worker
    computes their AO one after the other (recomposite.py). A render of the
    scene that begins meanwhile makes it stop after the node it is
    computing, rather than compete with the render for the cores; its AO
    is dropped, and the render's AO is the library's for the new radius."""
    spec = {"frames": [1], "nodes": [{"name": "First", "radius": 0.6, "blur_size": 0},
                                     {"name": "Second", "radius": 0.3, "blur_size": 0}],
            "after_render": [{"label": "render", "render_during_refresh": 0.9}]}
    out, log = render(run_in_blender, tmp_path, spec)
    worker = json.loads(next(line for line in log.splitlines()
                             if line.startswith("WORKER "))[len("WORKER "):])
    assert worker == {"jobs": 2, "computed": 1, "refreshed": False}, log[-3000:]
    assert printed_hints(log) == {"render": None}, log[-3000:]
    # The File Output of the render during the refresh replaced the first's.
    expected = library_ao(node_native, out, 1, node_params(radius=0.9, blur_size=0))
    for name in ("First", "Second"):
        assert np.abs(node_outputs(out, 1, name)["ao"] - expected).max() <= EXACT, name


def test_timer_waits_while_blender_refuses_writes(run_in_blender, tmp_path, node_native):
    """While another thread runs a read-only callback (a draw, Cycles'
    render), Blender refuses every write and operator from Python; a CI run
    once met that in the node timer's tick after an F12 render, which then
    raised. The step here runs in a node class's poll, where Blender refuses
    them for real. There the tick shows no message and raises nothing, and
    the next tick shows it (the tick asks first, writes.py; the messages
    are kept when a write is refused all the same); a compositing refused
    waits for the next tick; a refresh does not render and is not taken for
    a failure (which is not tried again until the settings change): the
    next tick renders the new radius (its render clears the status), and
    the AO is the library's. The sync timer that rebuilds a deleted hook
    runs again until it has, and a sync refused after it made the helper
    scene leaves none behind."""
    spec = {"frames": [1], "nodes": [{"name": "Hinted", "radius": 0.6, "blur_size": 0}],
            "after_render": [
                {"label": "refused probe", "writes_allowed": True, "refused": True},
                {"label": "probe", "writes_allowed": True},
                {"label": "refused tick", "post_message": "posted", "poll": True,
                 "refused": True},
                {"label": "next tick", "poll": True},
                {"label": "refused refresh", "socket": ["Radius", 1.1], "refresh": True,
                 "refused": True},
                {"label": "next refresh", "refresh": True},
                {"label": "rendered again", "render": 1},
                {"label": "refused apply", "post_message": "again", "apply": True,
                 "refused": True},
                {"label": "applied", "apply": True},
                {"label": "refused composite", "composite_again": True, "refused": True},
                {"label": "composited", "refresh": True},
                {"label": "refused sync tick", "delete_helper": True, "sync_tick": True,
                 "refused": True},
                {"label": "next sync tick", "sync_tick": True},
                {"label": "refused midway", "delete_helper": True, "sync_all": True,
                 "refused": True},
                {"label": "sync", "sync_all": True}]}
    out, log = render(run_in_blender, tmp_path, spec)
    said, waiting = {}, {}
    for line in log.splitlines():
        if line.startswith("HINT "):
            step = json.loads(line[len("HINT "):])
            said[step["label"]] = (step["status"], bool(step["hint"]))
            waiting[step["label"]] = step["composite_waiting"]
    assert said == {"refused probe": ("", False), "probe": ("", False),
                    "refused apply": ("", False), "applied": ("again", False),
                    "refused composite": ("again", False), "composited": ("again", False),
                    "refused tick": ("", False), "next tick": ("posted", False),
                    "refused refresh": ("posted", True), "next refresh": ("", False),
                    "rendered again": ("", False), "refused sync tick": ("again", False),
                    "next sync tick": ("again", False), "refused midway": ("again", False),
                    "sync": ("again", False)}, log[-3000:]
    # The sync timer (after an edit in a window) asks first (writes.py) and
    # runs again until the hook is rebuilt; a sync refused midway, after it
    # made the helper scene, removes it again and says so.
    helper = [".HBAO passes Scene"]
    syncs = [json.loads(line[len("SYNC "):]) for line in log.splitlines()
             if line.startswith("SYNC ")]
    assert [(sync["returned"], sync["helpers"]) for sync in syncs] == [
        ("again", []), (None, helper), (True, []), (False, helper)], log[-3000:]
    assert "could not update the HBAO hook" not in log, log[-3000:]
    # A compositing refused waits for the timer's next tick (a refresh).
    assert {label: names for label, names in waiting.items() if names} == {
        "refused composite": ["Scene"]}, log[-3000:]
    refreshed = [line.split()[1] for line in log.splitlines() if line.startswith("REFRESHED ")]
    assert refreshed == ["False", "True", "False"], log[-3000:]
    probes = [line.split()[2] for line in log.splitlines() if line.startswith("WRITES ALLOWED ")]
    assert probes == ["False", "True"], log[-3000:]
    assert "Traceback" not in log and "could not bring the AO" not in log, log[-3000:]
    ao = node_outputs(out, 1, "Hinted")["ao"]
    expected = library_ao(node_native, out, 1, node_params(radius=1.1, blur_size=0))
    assert np.abs(ao - expected).max() <= EXACT


def test_two_nodes_two_view_layers_and_muted_node(run_in_blender, tmp_path, node_native):
    spec = {"scene": "two_layers", "nodes": [
        {"name": "Small", "layer": "Front", "radius": 0.2},
        {"name": "Large", "layer": "Back", "radius": 1.5},
        {"name": "Muted", "layer": "Front", "radius": 1.0, "mute": True}]}
    out, log = render(run_in_blender, tmp_path, spec)
    small = node_outputs(out, 1, "Small")["ao"]
    large = node_outputs(out, 1, "Large")["ao"]
    assert np.abs(small - large).max() > 0.1
    assert np.abs(small - library_ao(node_native, out, 1, node_params(radius=0.2),
                                     layer="Front")).max() <= EXACT
    assert np.abs(large - library_ao(node_native, out, 1, node_params(radius=1.5),
                                     layer="Back")).max() <= EXACT
    assert "2 AO pass(es)" in log  # the muted node was not computed


def test_missing_normal_pass_is_enabled_with_a_message(run_in_blender, tmp_path, node_native):
    spec = {"disable_normal_pass": True, "nodes": [{"radius": 0.8}]}
    out, log = render(run_in_blender, tmp_path, spec)
    assert "enabled the Normal pass of view layer 'ViewLayer'" in log
    # the node says so after the render (its plan's messages replaced it)
    statuses = [json.loads(line[len("STATUS "):]) for line in log.splitlines()
                if line.startswith("STATUS ")]
    assert statuses == [{"node": "HBAO0", "status": "Normal pass turned on"}], statuses
    expected = library_ao(node_native, out, 1, node_params(radius=0.8))
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT


def test_missing_library_renders_without_ao_and_says_so(run_in_blender, tmp_path):
    missing = tmp_path / "no" / "libhbao.so"
    out, log = render(run_in_blender, tmp_path, {"nodes": [{"radius": 1.0}]},
                      env={"HBAO_LIBRARY": str(missing)})
    # (named by HBAO_LIBRARY: the variable is wrong, not the add-on)
    assert (f"{missing}, which HBAO_LIBRARY names, does not exist. Point HBAO_LIBRARY at a "
            f"built libhbao.so") in log, log[-3000:]
    # the node says so too (an artist's review found nothing in the UI)
    statuses = [json.loads(line[len("STATUS "):]) for line in log.splitlines()
                if line.startswith("STATUS ")]
    assert statuses == [{"node": "HBAO0", "status": "Library not loaded: AO off"}], statuses
    outputs = node_outputs(out, 1)
    assert np.all(outputs["ao"] == 1.0)
    assert np.abs(outputs["image"] - outputs["render"]).max() <= EXACT


def test_missing_exr_library_renders_without_ao_and_says_so(run_in_blender, tmp_path):
    missing = tmp_path / "no" / "libhbao_exr.so"
    out, log = render(run_in_blender, tmp_path, {"nodes": [{"radius": 1.0}]},
                      env={"HBAO_EXR_LIBRARY": str(missing)})
    # The message reaches Blender's UI through RenderEngine.report (a
    # WARNING, printed in -b) and says how to fix it.
    assert f"{missing}, which HBAO_EXR_LIBRARY names, does not exist" in log
    assert "Rendering without AO" in log
    assert "unset it to use the add-on's own copy" in log
    outputs = node_outputs(out, 1)
    assert np.all(outputs["ao"] == 1.0)
    assert np.abs(outputs["image"] - outputs["render"]).max() <= EXACT


@pytest.mark.parametrize("shown", ["scene", "helper"])
def test_saved_file_renders_from_the_command_line(run_in_blender, blender, blender_user_scripts,
                                                  tmp_path, node_native, shown):
    """`blender -b file.blend -f 1` renders the node's AO. Saved with the
    window on the helper scene (Scene > Delete of the active scene showed it,
    before window_scenes.py), the file rendered the helper: a frame without
    the artist's image, exit code 0 (an exploratory run). The add-on moves
    the window to the artist's scene when the file is loaded."""
    blend = tmp_path / "hbao.blend"
    out = tmp_path / "cli"
    render(run_in_blender, tmp_path, {"save_blend": str(blend),
                                      "nodes": [{"radius": 0.6, "integration": "HBAO"}],
                                      "prepare": ["show_the_helper"] if shown == "helper" else []},
           name="setup")
    # The file was saved before any render: the command line must render the
    # node as an artist's `blender -b file.blend -f 1` does, add-on enabled.
    # The script saved its outputs under the setup folder; redirect them.
    command = blender.command(blend=blend, output=out / "frame_####", frame=1)
    completed = run_command(command, blender_user_scripts)
    assert "pass hand-over" in completed.stdout, completed.stdout[-3000:]
    setup = tmp_path / "setup"
    (setup / "camera_0001.json").write_text(json.dumps(
            _camera_of(blender, blender_user_scripts, blend, tmp_path)))
    ao = node_outputs(setup, 1)["ao"]
    depth, normal = frame_passes(out, 1)
    expected = node_native.compute_ao(depth, normal,
                                      params=node_params(radius=0.6, integration="HBAO"),
                                      camera=camera(setup, 1))
    assert np.abs(ao - expected).max() <= EXACT


@pytest.mark.parametrize("remap", [None, (2, 1)])
def test_animation_renders_every_frame_at_its_keyframed_values(
        run_in_blender, blender, blender_user_scripts, tmp_path, node_native, remap):
    """`blender -b file.blend -s 1 -e 2 -a`: each frame's node AO is the
    library's AO of that frame's passes at that frame's keyframed radius,
    integration and half resolution (the node's menus and checkboxes were
    read as saved: an exploratory run), and with Time Remapping (Old 2, New
    1: frame 2 shows the animation's time 4) at the time Blender shows, as
    for the camera (the keys were read at the frame number)."""
    blend = tmp_path / "animated.blend"
    out = tmp_path / "animation"
    scale = remap[0] / remap[1] if remap else 1
    keyed = {1: (0.15, "COSINE", False), 2: (1.2, "HBAO", True)}
    render(run_in_blender, tmp_path, {
        "save_blend": str(blend), "frames": [1, 2], "time_remap": remap,
        "nodes": [{"keyframes": [[frame * scale, radius] for frame, (radius, *_) in keyed.items()],
                   "property_keyframes": [
                       [frame * scale, {"integration": integration, "half_resolution": half}]
                       for frame, (_, integration, half) in keyed.items()],
                   "blur_size": 0}]}, name="setup")
    command = blender.command(blend=blend, output=out / "frame_####", animation=(1, 2))
    log = run_command(command, blender_user_scripts).stdout
    assert "animated by" not in log, log[-3000:]
    setup = tmp_path / "setup"
    ao = {}
    for frame, (radius, integration, half) in keyed.items():
        (setup / f"camera_{frame:04d}.json").write_text(json.dumps(
            _camera_of(blender, blender_user_scripts, blend, tmp_path)))
        ao[frame] = node_outputs(setup, frame)["ao"]
        depth, normal = frame_passes(out, frame)
        params = node_params(radius=radius, blur_size=0, integration=integration,
                             half_resolution=int(half))
        expected = node_native.compute_ao(depth, normal, params=params,
                                          camera=camera(setup, frame))
        assert np.abs(ao[frame] - expected).max() <= EXACT, (frame, remap)
    # The radius really changed between the frames of one animation render.
    assert ao[2].mean() < ao[1].mean() - 0.02


def test_the_nodes_menus_and_checkbox_read_their_curves_as_blender_does(run_in_blender):
    """F-Curves without whole-number flags (made by scripts: fcurves.new),
    linear, on Integration, Half Resolution and Falloff, and a muted one on
    Blur Sharpness (property_curves.py): the hook rounded the menus where
    Blender truncates, called a checkbox on from 0.5 where Blender needs 1,
    and read muted curves (a review). Observed: the hook's value is
    Blender's own at every frame and subframe tried."""
    log = run_in_blender(SCRIPTS / "property_curves.py").stdout
    line = next((text for text in log.splitlines() if text.startswith("CHECKED ")), None)
    assert line is not None, log[-3000:]
    assert json.loads(line[len("CHECKED "):]) == {"values": 28, "differed": 0}, log[-3000:]


@pytest.mark.parametrize("animation", ["driver", "NLA", "NLA off"])
def test_a_value_animated_as_the_hook_cannot_follow_says_so(run_in_blender, tmp_path, animation):
    """A driver on Radius, or its keyframes pushed down into an NLA strip:
    a render's own depsgraph evaluates them but writes nothing back, so an
    animation render used one value for every frame and said nothing (an
    exploratory run). The node's status and the render's report now say so
    (not where the NLA is off: Blender ignores it then, a review); the AO is
    computed (at the value the socket holds)."""
    node = {"radius_driver": "0.4 + 0.2"} if animation == "driver" else {
        "keyframes": [[1, 0.3], [2, 1.0]], "keys_in_nla": "off" if animation == "NLA off" else True}
    out, log = render(run_in_blender, tmp_path, {"nodes": [dict(node, blur_size=0)]})
    statuses = [json.loads(line[len("STATUS "):]) for line in log.splitlines()
                if line.startswith("STATUS ")]
    if animation == "NLA off":
        assert "animated by" not in log, log[-3000:]
        assert statuses == [{"node": "HBAO0", "status": ""}], statuses
        return
    long = {"driver": "a driver", "NLA": "NLA strips"}[animation]
    assert f"Radius is animated by {long}, which the HBAO hook does not evaluate" in log, \
        log[-3000:]
    assert statuses == [{"node": "HBAO0", "status": f"Radius: fixed ({animation})"}], statuses
    assert node_outputs(out, 1)["ao"].min() < 0.9


def full_and_border_ao(run_in_blender, tmp_path, size, border, crop):
    """The first node's AO of the corner scene rendered whole and with
    `border` (with or without its crop), after asserting that the border
    render computed its AO."""
    common = {"resolution": list(size), "nodes": [{"radius": 0.15, "blur_size": 0}]}
    full_out, _ = render(run_in_blender, tmp_path, common, name="full")
    border_out, log = render(run_in_blender, tmp_path, dict(common, border=border, crop=crop),
                             name="border")
    assert "Rendering without AO" not in log
    return node_outputs(full_out, 1)["ao"], node_outputs(border_out, 1)["ao"]


def test_border_render_without_crop_gets_the_ao_of_the_full_frame(run_in_blender, tmp_path):
    """Without "Crop to Render Region" the main Render Result is the whole
    frame and the helper's only the border: the engine computes the whole
    frame's AO and hands over the border's part (it rendered without AO,
    "the Render Result is 256x128, the helper scene renders 128x64")."""
    width, height = 256, 128
    full, border = full_and_border_ao(run_in_blender, tmp_path, (width, height),
                                      [0.25, 0.75, 0.25, 0.75], crop=False)
    assert border.shape == full.shape == (height, width)
    # The border's pixels 64..191 and rows 32..95; away from its edge by more
    # than the projected radius (under 9 pixels), as in the cropped test.
    margin = 12
    inner = (slice(32 + margin, 96 - margin), slice(64 + margin, 192 - margin))
    assert full[inner].min() < 0.9  # there is occlusion to compare
    assert np.abs(border[inner] - full[inner]).max() <= 1e-3


@pytest.mark.parametrize("crop", [True, False])
def test_border_edges_round_as_blender_rounds_them(run_in_blender, tmp_path, crop):
    """Blender places a border's edges in single precision: at 100 x 50 the
    border 0.01-0.51 x 0.1-0.7 covers columns 1-50 and rows 5-34 from the
    bottom, where double precision gives columns 0-49 and rows 5-33. Without
    the crop the sizes then did not match (no AO); with it, the cropped
    camera was a pixel off, which sampling noise hides here: that variant
    only shows that such a border renders with AO."""
    width, height = 100, 50
    full, border = full_and_border_ao(run_in_blender, tmp_path, (width, height),
                                      [0.01, 0.51, 0.1, 0.7], crop=crop)
    rows, columns = slice(height - 35, height - 5), slice(1, 51)  # top row first
    assert border.shape == ((30, 50) if crop else (height, width))
    inside = border if crop else border[rows, columns]
    # The 4 x 4 pattern and the 64-pixel blocks do not line up with the
    # full frame's at these edges, so pixels differ by sampling noise; the
    # border's AO still follows the frame's at the same place.
    assert full[rows, columns].min() < 0.9  # there is occlusion to compare
    assert np.abs(inside - full[rows, columns]).mean() < 0.05


@pytest.mark.parametrize("stereo, views", [(True, ("_L", "_R")), ("one_view", ("_L",)),
                                           ("custom_view", ("_L", "_R", "_C"))],
                         ids=["stereo_3d", "one_view", "multi_view"])
def test_stereo_and_multi_view_renders_get_each_views_ao(run_in_blender, tmp_path, monkeypatch,
                                                         node_native, stereo, views):
    """Each view's AO is the library's from that view's passes and camera:
    Stereo 3D's eyes (the right one moved and, off-axis, shifted; the test
    works them out from the camera's Stereoscopy settings) and Multi-View's
    cameras named by view suffix. Before, the AO was off (1) in every view
    with a message. The helper has the main scene's views, so the
    compositor reads each view's pass (with one view the frame was black),
    and every view's scratch file is removed."""
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setenv("HBAO_TEMP_DIR", str(scratch))
    out, log = render(run_in_blender, tmp_path, {
        "stereo": stereo, "nodes": [{"radius": 0.7, "blur_size": 0},
                                    {"name": "HBAO1", "radius": 0.7, "blur_size": 0,
                                     "guard_band": 10.0, "back_faces": True}]})

    def suffix(name, view):  # with one view on, 3.4 writes the render without its suffix
        return view if (out / f"{name}_0001{view}.exr").exists() else ""

    expected = {}
    for view in views:
        depth, normal = frame_passes(out, 1, view=suffix("frame", view))
        expected[view] = node_native.compute_ao(depth, normal, camera=camera(out, 1, view),
                                                params=node_params(radius=0.7, blur_size=0))
    for view in views:
        outputs = node_outputs(out, 1, view=suffix("nodes", view))
        assert expected[view].min() < 0.9, view
        assert np.abs(outputs["ao"] - expected[view]).max() <= EXACT, view
        assert outputs["render"].max() > 0.1  # a render, not a black frame
        # guard band and back faces: left out, and their scenes not rendered in vain
        guarded = node_outputs(out, 1, node="HBAO1", view=suffix("nodes", view))["ao"]
        assert np.abs(guarded - expected[view]).max() <= EXACT, view
    assert "no guard band: stereo and multi-view renders have none" in log
    assert "no back faces: stereo and multi-view renders have none" in log
    assert "EXTRA SCENES []" in log
    # the views differ: a view's AO through another view's camera would not match
    assert len(views) == 1 or np.abs(expected[views[0]] - expected[views[1]]).max() > 0.1
    assert "Rendering without AO" not in log
    assert list(scratch.iterdir()) == []


# Each render the memory route is tried on (pass_capture.py): its spec;
# {(view layer, view file suffix): (node, radius)} of the AO held to the
# library's; whether the passes can be taken from memory (4.5 and later).
MEMORY_ROUTE_CASES = {
    "one_layer": ({"nodes": [{"radius": 0.7, "blur_size": 0}]},
                  {("ViewLayer", ""): ("HBAO0", 0.7)}, True),
    "two_layers": ({"scene": "two_layers", "nodes": [
        {"name": "Small", "layer": "Front", "radius": 0.2, "blur_size": 0},
        {"name": "Large", "layer": "Back", "radius": 1.5, "blur_size": 0}]},
        {("Front", ""): ("Small", 0.2), ("Back", ""): ("Large", 1.5)}, True),
    "stereo": ({"stereo": True, "nodes": [{"radius": 0.7, "blur_size": 0}]},
               {("ViewLayer", "_L"): ("HBAO0", 0.7), ("ViewLayer", "_R"): ("HBAO0", 0.7)},
               True),
    # Cycles writes a tiled render's pixels in its render_frame_finish()
    "tiles": ({"tile_size": 32, "nodes": [{"radius": 0.7, "blur_size": 0}]},
              {("ViewLayer", ""): ("HBAO0", 0.7)}, True),
    # the guard band's and back faces' renders taken too (test_back_faces_
    # give_each_occluder_its_thickness holds that AO to the library's)
    "extra_renders": ({"nodes": [{"radius": 0.7, "blur_size": 0},
                                 {"name": "HBAO1", "radius": 0.7, "blur_size": 0,
                                  "guard_band": 10.0, "back_faces": True}]},
                      {("ViewLayer", ""): ("HBAO0", 0.7)}, True),
    # an engine written in Python that is not Cycles (raycast_engine.py),
    # which writes its passes in bands, each its own begin_result()
    "python_engine": ({"python_engine": True, "nodes": [{"radius": 0.7, "blur_size": 0}]},
                      {("ViewLayer", ""): ("HBAO0", 0.7)}, True),
    # the result is the border's region until Blender places it (the border
    # tests below hold its AO)
    "border": ({"border": [0.25, 0.75, 0.25, 0.75], "crop": False,
                "nodes": [{"radius": 0.7, "blur_size": 0}]}, {}, False),
}


@pytest.mark.parametrize("case", list(MEMORY_ROUTE_CASES))
def test_passes_from_memory_give_the_ao_of_the_written_passes(run_in_blender, blender, tmp_path,
                                                              node_native, case):
    """From 4.5, Cycles' Depth and Normal reach the AO from its own Render
    Result in memory, with no scratch file (pass_capture.py); the timing
    line says "from memory". The AO is exactly the library's from the
    passes Blender wrote to the output, view by view and layer by layer (a
    wrong pass, view, layer or row order misses by far more than 0); a
    tiled render's too (before, its passes read as zeros), and that of an
    engine written in Python other than Cycles, which writes its passes in
    bands. Border renders, and every render in 3.4, take the file round
    trip."""
    spec, held, from_memory = MEMORY_ROUTE_CASES[case]
    assert_hand_over_route(run_in_blender, tmp_path, node_native, spec, held,
                           from_memory and blender.version_tuple >= (4, 5))


@pytest.mark.min_blender(4, 5)
@pytest.mark.parametrize("grease_pencil", [True, "instanced", "geometry_nodes"])
def test_grease_pencil_strokes_keep_the_file_route(run_in_blender, tmp_path, node_native,
                                                   grease_pencil):
    """Blender draws Grease Pencil strokes into the Depth pass after Cycles'
    render(): taken there, the passes missed the stroke before the camera
    (an exploratory run), also one shown through a collection instance (a
    review). Strokes that geometry nodes make (Curves to Grease Pencil) are
    drawn as a Grease Pencil object's are. While Grease Pencil objects or
    such node groups are in use the passes go through the file, and the AO
    is the written passes'. (The bpy builds here draw no stroke objects
    without OpenGL, so this holds the route, and the AO only to the passes.
    The node group's stroke is among the evaluated objects; with it, bpy
    4.5 and 5.0 here write a Depth of -0.02 to -0.04 everywhere, which
    gives no AO at all, so that case holds the route only.)"""
    made_by_nodes = grease_pencil == "geometry_nodes"
    log = assert_hand_over_route(run_in_blender, tmp_path, node_native,
                                 {"grease_pencil": grease_pencil,
                                  "nodes": [{"radius": 0.7, "blur_size": 0}]},
                                 {} if made_by_nodes else {("ViewLayer", ""): ("HBAO0", 0.7)},
                                 False)
    assert ("STROKE INSTANCES 1" in log) == made_by_nodes, log[-3000:]


def assert_hand_over_route(run_in_blender, tmp_path, node_native, spec, held, from_memory):
    """Render `spec`; every timing line says whether the passes came
    `from_memory`; the AO of `held` as MEMORY_ROUTE_CASES says. Returns the
    render's log."""
    out, log = render(run_in_blender, tmp_path, spec)
    lines = [line for line in log.splitlines() if timing_line.parse(line) is not None]
    assert lines, log[-3000:]
    for line in lines:
        figures = timing_line.parse(line)
        assert ("(from memory " in line) == from_memory, log[-3000:]
        # the log's tail, which says what the render did, for a rare miss:
        # once (session 48, bpy 5.0 under CI) the back faces' passes took the
        # file round trip, and 22 reruns since, loaded or not, did not repeat it
        assert (figures["save_ms"] + figures["read_ms"] == 0) or not from_memory, log[-3000:]
        for kind in figures["extras_ms"]:
            assert (f"{kind} passes {figures['extras_ms'][kind]} ms from memory" in line) \
                == from_memory, log[-3000:]
    if "guard_band" in str(spec):
        assert "guard band passes" in log and "back faces passes" in log, log[-3000:]
    assert "Rendering without AO" not in log and "could not take the passes" not in log
    for (layer, view), (node, radius) in held.items():
        depth, normal = frame_passes(out, 1, layer, view=view)
        expected = node_native.compute_ao(depth, normal, camera=camera(out, 1, view),
                                          params=node_params(radius=radius, blur_size=0))
        assert expected.min() < 0.9, (layer, view)
        ao = node_outputs(out, 1, node=node, view=view)["ao"]
        assert np.abs(ao - expected).max() <= EXACT, (layer, view)
    return log


def test_a_mono_render_after_a_stereo_one_gets_its_ao(run_in_blender, tmp_path):
    """Stereoscopy turned off after a stereo render whose output is one side
    by side image: the hand-over's save of the mono frame failed in 3.4 and
    4.5 (AO off, the message blamed the folder), as the stereo save had left
    Blender asking for a Stereo 3D layout (found by an exploratory run)."""
    out, log = render(run_in_blender, tmp_path, {
        "stereo": True, "stereo_off_from_frame": 2, "frames": [1, 2], "output_format": "PNG",
        "output_views_format": "STEREO_3D", "nodes": [{"radius": 0.7, "blur_size": 0}]})
    assert "Rendering without AO" not in log, log[-3000:]
    assert node_outputs(out, 1, view="_L")["ao"].min() < 0.9
    assert node_outputs(out, 2)["ao"].min() < 0.9


def test_border_crop_render_matches_the_full_frame(run_in_blender, tmp_path):
    """A render cropped to a border region gives the same AO as the full
    frame at the same pixels, away from the crop edge by more than the
    projected radius (there the crop has no samples beyond its edge). The
    add-on must describe the cropped view to the library; a camera that
    ignored the crop would misplace every position."""
    width, height = 256, 128
    common = {"resolution": [width, height], "nodes": [{"radius": 0.15, "blur_size": 0}]}
    full_out, _ = render(run_in_blender, tmp_path, common, name="full")
    crop_out, _ = render(run_in_blender, tmp_path, dict(common, border=[0.25, 0.75, 0.25, 0.75]),
                         name="crop")
    full = node_outputs(full_out, 1)["ao"]
    crop = node_outputs(crop_out, 1)["ao"]
    assert crop.shape == (height // 2, width // 2)
    # The border starts at pixel 64 from the left and row 32 from the top and
    # is 128 pixels wide: the library's sampling pattern repeats every 4 rows,
    # and its blocks (16 pixels of a 64-pixel span share one step length, see
    # docs/algorithm.md) line up with the full frame's. The radius projects to
    # under 9 pixels here, so 12 pixels keep clear of the edge.
    margin = 12
    inner_crop = crop[margin:-margin, margin:-margin]
    inner_full = full[32 + margin:32 + height // 2 - margin, 64 + margin:64 + width // 2 - margin]
    assert inner_full.min() < 0.9  # there is occlusion to compare
    # Same depths, same pattern: equal up to float rounding of positions in
    # the shifted camera (1e-7 relative), far below a misplaced camera's
    # error (several hundredths).
    assert np.abs(inner_crop - inner_full).max() <= 1e-3


def test_guard_band_sees_occluders_outside_the_frame(run_in_blender, tmp_path, node_native):
    """Two nodes, one with a guard band of 12.5 % (an extra 1-sample Cycles
    render through a camera 1.25 times as wide). The truth: the library on a
    real render 1.25 times as large through that wider camera (120x80, the
    same pixel scale), cropped to the frame. A box stands on the floor just
    past the frame's right side: near the frame's edges the node without a
    band is too bright (it takes the floor there as going on flat, without
    the box); the band's AO is far closer to the truth there, and no worse
    inside."""
    width, height, scale = 96, 64, 1.25
    columns, rows = 12, 8  # 12.5 % of 96 and 64
    node = {"radius": 1.0}
    out, log = render(run_in_blender, tmp_path,
                      {"resolution": [width, height], "box_past_frame": True,
                       "nodes": [dict(node, name="HBAO0"),
                                 dict(node, name="HBAO1", guard_band=12.5)]})
    assert "guard band" in log and "no guard band" not in log, log[-3000:]
    assert extra_renders(log)["frame 1"] == [".HBAO guard band Scene"]
    wide_out, _ = render(run_in_blender, tmp_path,
                         {"resolution": [int(width * scale), int(height * scale)],
                          "box_past_frame": True, "widen_camera": scale, "nodes": [node]},
                         name="wide")
    wide = library_ao(node_native, wide_out, 1, node_params(radius=1.0))
    truth = wide[rows:rows + height, columns:columns + width]
    without = node_outputs(out, 1, "HBAO0")["ao"]
    with_band = node_outputs(out, 1, "HBAO1")["ao"]
    edge = np.ones((height, width), bool)
    edge[6:-6, 6:-6] = False
    error_without = np.abs(without - truth)[edge].mean()
    error_with = np.abs(with_band - truth)[edge].mean()
    print(f"mean |AO - truth| within 6 px of the edges: without a band {error_without:.4f}, "
          f"with {error_with:.4f}; everywhere {np.abs(without - truth).mean():.4f}, "
          f"{np.abs(with_band - truth).mean():.4f}")
    assert error_without > 0.006  # the borders are too bright without: the test can fail
    assert error_with < 0.5 * error_without
    assert np.abs(with_band - truth).mean() < np.abs(without - truth).mean()


@pytest.mark.parametrize("size, percentage", [((200, 100), 58), ((300, 200), 41)])
def test_cropped_border_at_a_resolution_percentage(run_in_blender, tmp_path, node_native, size,
                                                   percentage):
    """Blender's image at a resolution percentage is (resolution x
    percentage) / 100 in integers: 116 x 58 for 200 x 100 at 58 %. The
    add-on's float product gave 115 x 57 at these sizes, and a cropped
    border's camera was worked out on that size: AO off by up to 0.75,
    silently (found by an exploratory run). The node's AO is the library's
    with the crop of the whole frame's camera, worked out here on Blender's
    sizes."""
    node = {"radius": 0.8, "blur_size": 0}
    border = [0.2, 0.75, 0.1, 0.8]
    common = {"resolution": list(size), "percentage": percentage, "nodes": [node]}
    full, _ = render(run_in_blender, tmp_path, common, name="full")
    cropped, log = render(run_in_blender, tmp_path, dict(common, border=border), name="crop")
    assert "without AO" not in log, log[-3000:]
    width, height = (size[0] * percentage) // 100, (size[1] * percentage) // 100
    assert frame_passes(full, 1)[0].shape == (height, width)  # Blender's size
    # a border edge: its float32 fraction times the size, truncated (Blender)
    x0, x1, y0, y1 = (int(np.float32(f) * np.float32(n))
                      for f, n in zip(border, (width, width, height, height)))
    depth, normal = frame_passes(cropped, 1)
    assert depth.shape == (y1 - y0, x1 - x0)
    crop = node_native.camera_crop(camera(full, 1), width, height, x0, height - y1, x1 - x0,
                                   y1 - y0)
    expected = node_native.compute_ao(depth, normal, params=node_params(**node), camera=crop)
    assert expected.min() < 0.9
    assert np.abs(node_outputs(cropped, 1)["ao"] - expected).max() <= EXACT


def test_border_render_gets_no_guard_band_and_says_so(run_in_blender, tmp_path, node_native):
    """A border render (cropped) with a guard band asked for: the extra
    render cannot be used; the AO is exactly the library's on the cropped
    render without a band, the render's report says why and the node shows
    it; the guard band's scene does not render in vain."""
    node = {"radius": 0.8, "blur_size": 0}
    out, log = render(run_in_blender, tmp_path, {"border": [0.25, 0.75, 0.25, 0.75],
                                                 "nodes": [dict(node, guard_band=10.0)]})
    assert "no guard band: border renders have none" in log, log[-3000:]
    statuses = [json.loads(line[len("STATUS "):]) for line in log.splitlines()
                if line.startswith("STATUS ")]
    assert statuses == [{"node": "HBAO0", "status": "No guard band"}], statuses
    assert extra_renders(log) == {"frame 1": []}
    # The camera written beside the render is the crop's (pixels 24-72 of 96
    # and 16-48 of 64, from the bottom: blender_scenes.camera_description).
    depth, normal = frame_passes(out, 1)
    assert depth.shape == (32, 48)
    expected = node_native.compute_ao(depth, normal, params=node_params(**node),
                                      camera=camera(out, 1))
    assert np.abs(node_outputs(out, 1)["ao"] - expected).max() <= EXACT


def test_back_faces_give_each_occluder_its_thickness(run_in_blender, tmp_path, node_native):
    """Two nodes, one with Back Faces (an extra 1-sample Cycles render whose
    front faces are transparent). The back render sees the far side of the
    cube and the sphere, behind their front (thickness > 0), and the floor
    and wall through nothing (unknown). The node's AO is exactly the
    library's with that layer; it differs from the one-layer AO (light
    passes behind the props; occluders just beyond the radius shade what
    their hidden sides face), and comes closer to Cycles' own AO pass."""
    node = {"radius": 1.0, "falloff": "NONE"}
    out, log = render(run_in_blender, tmp_path,
                      {"resolution": [96, 64], "samples": 64, "ao_reference": 1.0,
                       "dump_back_faces": True,
                       "nodes": [dict(node, name="HBAO0"),
                                 dict(node, name="HBAO1", back_faces=True)]})
    assert "back faces passes" in log and "no back faces" not in log, log[-3000:]
    back = np.load(out / "back_0001.npy")
    depth, normal = frame_passes(out, 1)
    known = (back > depth) & (back < 1e4)
    assert known.mean() > 0.05  # the cube and the sphere have far sides
    assert np.all(back[known] - depth[known] < 1.5)  # within the props' size
    expected = node_native.compute_ao(depth, normal, params=node_params(**node),
                                      camera=camera(out, 1), back_depth=back)
    outputs = node_outputs(out, 1, "HBAO1")
    plain = node_outputs(out, 1, "HBAO0")["ao"]
    layered = outputs["ao"]
    assert np.abs(layered - expected).max() <= EXACT
    assert np.abs(layered - plain).max() > 0.02
    foreground = depth < CYCLES_BACKGROUND_DEPTH
    errors = [np.abs(ao - outputs["cycles_ao"])[foreground].mean() for ao in (plain, layered)]
    print("node AO vs Cycles AO, mean absolute difference: %.4f with one layer, %.4f with "
          "back faces" % tuple(errors))
    assert errors[1] < errors[0]


@pytest.mark.parametrize("layout", ["current", "older"])
@pytest.mark.parametrize("how", ["append", "link"])
def test_appended_or_linked_scene_renders_with_ao(run_in_blender, blender, blender_user_scripts,
                                                  tmp_path, native, node_native, how, layout):
    """A scene with an HBAO node, appended or linked into another file, still
    renders its AO: the hook's helper scene comes along and is found again.
    From a file saved before the group's layout 5 too ("older": its pass held
    the AO): the add-on cannot rebuild a linked library's group, nor a group
    appended by a script that renders at once, so the engine writes such a
    node's pass as its group reads it (the AO was inverted: a review)."""
    blend = tmp_path / "source.blend"
    render(run_in_blender, tmp_path, {"save_blend": str(blend),
                                      "nodes": [{"radius": 0.6, "blur_size": 0}]}, name="setup")
    setup = tmp_path / "setup"
    # The file rendered as it is: its File Output writes the node's AO to
    # setup/ (the render below writes over it)
    run_command(blender.command(blend=blend, output=tmp_path / "plain" / "frame_####", frame=1),
                blender_user_scripts)
    first = node_outputs(setup, 1)["ao"]
    if layout == "older":
        made = run_in_blender(SCRIPTS / "older_layout_file.py", blend=blend, addon=False)
        assert "OLDER LAYOUT 4" in made.stdout, made.stdout[-3000:]
    out = tmp_path / how
    out.mkdir()
    completed = run_in_blender(APPEND_SCRIPT, blend, how, out)
    assert "APPEND_RENDERED" in completed.stdout, completed.stdout[-3000:]
    assert "without AO" not in completed.stdout, completed.stdout[-3000:]
    ao = node_outputs(setup, 1)["ao"]
    assert np.isfinite(ao).all() and ao.min() < 0.8  # the corner is occluded
    # the same scene rendered again (and, for layout 5, the pass's round trip)
    assert np.abs(ao - first).max() <= SAME_RENDER_TOLERANCE
    if how == "append":
        (setup / "camera_0001.json").write_text(json.dumps(
            _camera_of(blender, blender_user_scripts, blend, tmp_path)))
        depth, normal = frame_passes(out, 1)
        library = node_native if layout == "current" else native  # older: the AO itself
        expected = library.compute_ao(depth, normal,
                                      params=node_params(radius=0.6, blur_size=0),
                                      camera=camera(setup, 1))
        assert np.abs(ao - expected).max() <= EXACT


def test_a_value_that_is_not_a_number_renders_without_ao_and_says_so(run_in_blender, tmp_path):
    """A Value node feeding NaN into Radius: the render completes, that
    node's AO is 1 and the console names the node and the socket."""
    out, stdout = render(run_in_blender, tmp_path, {"nodes": [
        {"name": "Bad", "radius_from_value_node": float("nan")}]})
    outputs = node_outputs(out, 1, "Bad")
    assert np.all(outputs["ao"] == 1.0)
    assert np.abs(outputs["image"] - outputs["render"]).max() <= EXACT
    assert 'node "Bad": Radius is not a number' in stdout, stdout[-3000:]


def _camera_of(blender, user_scripts, blend, tmp_path):
    script = tmp_path / "camera.py"
    script.write_text(
        "import bpy, json, sys\n"
        f"sys.path.insert(0, {str(REPO / 'scripts')!r})\n"
        "import blender_scenes\n"
        "print('CAMERA', json.dumps(blender_scenes.camera_description(bpy.context.scene)))\n")
    completed = run_command(blender.command(script, blend=blend, addons=()), user_scripts)
    line = next(text for text in completed.stdout.splitlines() if text.startswith("CAMERA "))
    return json.loads(line[len("CAMERA "):])


@pytest.mark.ui
@pytest.mark.parametrize("views", [[""], ["_L", "_R"]], ids=["mono", "stereo"])
def test_f12_render_in_the_ui_job_thread(run_in_blender, tmp_path, node_native, views):
    """F12 in a window renders in a job thread, the engine too (with Stereo
    3D, each eye from the engine's own camera calls there)."""
    out = tmp_path / "f12"
    completed = run_in_blender(SCRIPTS / "addon_f12.py", out, *(["stereo"] if views[0] else []),
                               ui=True)
    assert "F12: RENDERED" in completed.stdout, completed.stdout[-3000:]
    assert "pass hand-over" in completed.stdout
    assert "Rendering without AO" not in completed.stdout, completed.stdout[-3000:]
    for view in views:
        ao = node_outputs(out, 1, view=view)["ao"]
        expected = library_ao(node_native, out, 1, node_params(radius=0.9), view=view)
        assert ao.min() < 0.9
        assert np.abs(ao - expected).max() <= EXACT, view


def test_eevee_main_engine(run_in_blender, tmp_path, node_native):
    spec = {"engine": "BLENDER_EEVEE", "resolution": [64, 48], "samples": 1,
            "nodes": [{"radius": 0.8}]}
    out, _ = render(run_in_blender, tmp_path, spec)
    ao = node_outputs(out, 1)["ao"]
    assert ao.min() < 0.9
    expected = library_ao(node_native, out, 1, node_params(radius=0.8))
    assert np.abs(ao - expected).max() <= EXACT


def test_add_filter_menu_of_each_blender_lists_hbao(run_in_blender):
    """Each Blender names its Add > Filter menu differently (3.4:
    NODE_MT_category_CMP_OP_FILTER, 4.x/5.x: NODE_MT_category_compositor_filter):
    the add-on's entry is drawn by the one this Blender has, adding the HBAO
    node. (Debian's Blender also opens the menu in its window: test_ui.py.)"""
    completed = run_in_blender(SCRIPTS / "addon_menu.py")
    line = next(text for text in completed.stdout.splitlines() if text.startswith("MENU "))
    menu = json.loads(line[len("MENU "):])
    assert menu["menu"] in ("NODE_MT_category_CMP_OP_FILTER",
                            "NODE_MT_category_compositor_filter"), menu
    assert menu["ours"] == ["_draw_add_menu"], menu
    assert menu["entries"] == [["node.add_node", "HBAO", "CompositorNodeHBAO"]], menu


def test_the_test_scripts_file_output_inputs_keep_their_links(run_in_blender, tmp_path):
    """scripts/file_output.py, which the tests' trees write their EXRs with:
    in bpy 4.5 an input called "Image" added after another was looked up by
    name and found the first input (whose identifier stays "Image"), so its
    link replaced the first one's and its own layer was written black (an
    exploratory run)."""
    log = run_in_blender(SCRIPTS / "file_output_inputs.py", tmp_path).stdout
    assert json_line(log, "INPUTS") == [["Render", "Image"], ["Image", "Depth"]], log[-3000:]


def test_quitting_after_a_render_reads_no_freed_memory(run_blender, tmp_path):
    """Blender disables every add-on as it quits, before it frees its data:
    3.4 then freed the HBAO node type under the view layer's evaluated copy
    of the tree, whose freeing read the freed type
    (compat.NODE_TYPE_FREED_UNDER_EVALUATED_COPIES). Debian's Blender with
    --debug-memory fills freed memory, so that read crashed the quit (exit
    139, every time); the quit after a render with the node must exit 0, and
    with nothing left unfreed (3.4 also leaked the File Output inputs that
    the test scripts removed: scripts/file_output.py). The bpy builds have
    no such option (and no such bug)."""
    spec = {"nodes": [{"radius": 0.7, "blur_size": 0}]}
    completed = run_blender(RENDER_SCRIPT, json.dumps(spec), tmp_path / "render",
                            debug_memory=True)
    assert "RENDERED" in completed.stdout, completed.stdout[-3000:]
    assert "Not freed memory blocks" not in completed.stdout, completed.stdout[-3000:]


def test_disabled_and_enabled_again_still_renders_ao(run_in_blender, tmp_path):
    """The add-on disabled by hand (with an HBAO node in the file) and enabled
    again, then disabled by Blender loading factory settings and enabled
    again, renders AO each time. The node type stays registered while a node
    uses it (compat.keep_node_type_registered: 3.4 would read it freed, and
    in every version the nodes stay defined), and enabling the add-on again
    reuses it. Debian's Blender runs with --debug-memory: any read of a
    freed type crashes it."""
    completed = run_in_blender(SCRIPTS / "addon_reenable.py", tmp_path, debug_memory=True)
    assert "REENABLE OK" in completed.stdout, completed.stdout[-3000:]
    stages = {entry["stage"]: entry for entry in (
        json.loads(line[len("STAGE "):]) for line in completed.stdout.splitlines()
        if line.startswith("STAGE "))}
    assert stages["disabled"]["registered"], stages
    for stage in ("enabled", "enabled_again", "after_factory_settings"):
        assert stages[stage]["registered"], stages
        ao = node_outputs(tmp_path / stage, 1)["ao"]
        # the corner scene's contact shadows: computed AO, not the fallback 1
        assert ao.min() < 0.7 and ao.max() <= 1.0, (stage, ao.min())


def test_hook_lifecycle(run_in_blender, tmp_path):
    completed = run_in_blender(SCRIPTS / "addon_lifecycle.py", tmp_path)
    assert "LIFECYCLE OK" in completed.stdout, completed.stdout[-3000:]


def test_a_bpy_script_ends_after_a_file_with_the_node(blender, blender_user_scripts, tmp_path):
    """A pipeline's own Python script with `import bpy` (not Blender's
    application) that enabled the add-on and opened a file holding an HBAO
    node never ended in bpy 4.5, after writing its frames: the node type,
    still registered, kept bpy alive through Python's shutdown, and bpy's
    exit then waited forever on its own sound thread (a review's find; the
    tests' bpy stand-in leaves through os._exit, which hid it). The script
    now ends, in every Blender, within the time a frame of it takes."""
    script = SCRIPTS / "module_exit.py"
    env = blender_environment(blender_user_scripts)
    path = tmp_path / "node.blend"
    for step in ("make", "render"):
        command = [blender.executable, str(script), step, str(path)] if blender.kind == "bpy" \
            else [blender.executable, "-b", "--factory-startup", "-noaudio", "--python-exit-code",
                  "1", "--python", str(script), "--", step, str(path)]
        try:
            completed = subprocess.run(command, env=env, cwd=tmp_path, stdout=subprocess.PIPE,
                                       stderr=subprocess.STDOUT, text=True, timeout=60)
        except subprocess.TimeoutExpired as expired:
            pytest.fail(f"{step}: still running after 60 s: {expired.output}")
        assert completed.returncode == 0, completed.stdout[-3000:]
        assert f"MODULE_EXIT {step} DONE" in completed.stdout, completed.stdout[-3000:]
    assert (tmp_path / "frame.png").exists()


def test_package_and_install(tmp_path):
    """package_addon.sh makes an installable zip; install_addon.sh installs
    and enables the add-on for a (temporary) Blender user."""
    import zipfile
    completed = subprocess.run([str(REPO / "scripts" / "package_addon.sh")],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert completed.returncode == 0, completed.stderr
    archive = completed.stdout.strip().splitlines()[0]  # the legacy zip; then the extension
    names = zipfile.ZipFile(archive).namelist()
    for expected in ("hbao/__init__.py", "hbao/native.py", "hbao/blender_manifest.toml",
                     "hbao/lib/libhbao.so"):
        assert expected in names
    env = blender_environment(tmp_path / "scripts")
    # Only the scripts folder is given: the preferences must go beside it, not
    # into the user's (a HOME of its own shows anything written there). The
    # user's own config folder exists, as on any machine where Blender ran:
    # with the folder beside the scripts missing, Blender saved there (a
    # review's find), so install_addon.sh must make it.
    env.pop("BLENDER_USER_CONFIG")
    (tmp_path / "scripts" / "config").rmdir()
    env["HOME"] = str(tmp_path / "home")
    version = blenders.debian_blender().version.rsplit(".", 1)[0]  # 3.4.1 -> 3.4
    (tmp_path / "home" / ".config" / "blender" / version / "config").mkdir(parents=True)
    env.pop("HBAO_LIBRARY")  # the installed copy must find its own lib/libhbao.so
    completed = subprocess.run([str(REPO / "scripts" / "install_addon.sh")], env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert completed.returncode == 0, completed.stdout
    assert (tmp_path / "scripts" / "addons" / "hbao" / "lib" / "libhbao.so").exists()
    assert (tmp_path / "scripts" / "config" / "userpref.blend").exists()
    assert not any((tmp_path / "home").rglob("userpref.blend"))
    env["BLENDER_USER_CONFIG"] = str(tmp_path / "scripts" / "config")
    check = subprocess.run(
        [BLENDER, "-b", "--python-expr",
         "import bpy, hbao.native as n; print('ENABLED', 'hbao' in "
         "bpy.context.preferences.addons, n.library_version())"],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert "ENABLED True 0." in check.stdout, check.stdout[-2000:]


def test_scratch_files_are_removed_beside_the_render_two_at_most(run_in_blender, tmp_path,
                                                                 file_route):
    """handover.py removes each scratch file in a thread of its own; a save
    waits for every removal but the latest (so at most two files at a time,
    outside the engine's removals_after block, where a frame's files go
    together), and
    Blender does not end before the last removal: the folder is empty after."""
    completed = run_in_blender(SCRIPTS / "scratch_removal.py", tmp_path)
    assert "REMOVAL OK" in completed.stdout, completed.stdout[-3000:]
    assert list(tmp_path.iterdir()) == []


def test_scratch_file_stays_until_the_ao_is_computed(run_in_blender, tmp_path, monkeypatch,
                                                     file_route):
    """The removal of a frame's scratch file, the kernel freeing its pages,
    waits until the frame's AO is computed (scratch_files.removals_after), so
    that it does not compete with the AO's threads; then it goes. Two frames,
    two nodes each: at every AO the frame's own file is in the folder, and
    the folder is empty after Blender ends."""
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setenv("HBAO_TEMP_DIR", str(scratch))
    # The radii change from frame to frame, so that frame 2 computes its AO
    # again instead of reusing frame 1's (ao_cache).
    spec = {"frames": [1, 2], "nodes": [{"keyframes": [[1, 1.0], [2, 0.8]]},
                                        {"keyframes": [[1, 0.5], [2, 0.4]]}]}
    completed = run_in_blender(SCRIPTS / "removal_order.py", json.dumps(spec), tmp_path / "out")
    assert "RENDERED" in completed.stdout, completed.stdout[-3000:]
    line = next(text for text in completed.stdout.splitlines()
                if text.startswith("SCRATCH AT AO "))
    seen = json.loads(line[len("SCRATCH AT AO "):])
    assert len(seen) == 4, seen
    # This process's scratch files are numbered in the order saved
    # (scratch_files.path_in, scratch_names.name): frame 1's 0, frame 2's 1.
    for at_ao, number in zip(seen, (0, 0, 1, 1)):
        assert any(name.split("-")[4] == str(number) for name in at_ao), seen
    assert list(scratch.iterdir()) == []


def test_an_appended_scene_uses_the_add_ons_one_group_upgraded(run_in_blender, tmp_path):
    """File > Append of a scene saved by an older add-on into a file that has
    the add-on's group: the appended node moves to that one group (no
    ".HBAO.001" beside it, left at the old layout with float sockets) and
    keeps its values, link and keyframes (ui_old_file.py: Directions 8, Steps
    from a Value node, Blur Size keyed 3 at frame 1 and 9 at frame 11)."""
    old = tmp_path / "old.blend"
    saved = run_in_blender(SCRIPTS / "ui_old_file.py", old)
    assert "OLD SOCKET NodeSocketFloat" in saved.stdout, saved.stdout[-3000:]
    out = tmp_path / "out"
    out.mkdir()
    completed = run_in_blender(SCRIPTS / "addon_append_groups.py", old, out)
    line = next((text for text in completed.stdout.splitlines() if text.startswith("GROUPS ")),
                None)
    assert line is not None, completed.stdout[-3000:]
    report = json.loads(line[len("GROUPS "):])
    assert report["groups"] == [".HBAO"] and report["used"] == [".HBAO"], report
    assert report["socket_types"] == {name: "NodeSocketInt"
                                      for name in ("Directions", "Steps", "Blur Size")}, report
    assert report["directions"] == 8 and report["steps_source"] == ["Steps Value"], report
    assert report["depth_linked"], report
    assert report["blur_at_1"] == 3 and report["blur_at_11"] == 9, report
    # the pass input's old 1 (Blender keeps a socket's value when a node
    # moves to another group) is the new layout's no AO (a review)
    assert report["ao_pass_value"] == 0.0, report
    assert "without AO" not in completed.stdout, completed.stdout[-3000:]
    assert (out / "frame.png").is_file(), completed.stdout[-3000:]


def test_a_group_rebuild_refused_midway_keeps_the_nodes_values(run_in_blender):
    """Blender may refuse a write midway (writes.py): a rebuild of the
    shared group stopped after two sockets lost the node's values and links
    once the next sync finished it (a review found it). They are kept on the
    node until a whole group takes them back."""
    completed = run_in_blender(SCRIPTS / "refused_group_rebuild.py")
    line = next((text for text in completed.stdout.splitlines() if text.startswith("STATE ")),
                None)
    assert line is not None, completed.stdout[-3000:]
    state = json.loads(line[len("STATE "):])
    assert state["refused"] and state["current"] and not state["pending"], state
    assert state["radius"] == 3.5 and state["directions"] == 7, state
    assert state["strength_from"] == ["Strength Value"] and state["depth_linked"], state
    # the pass input's value is the layout's (no occlusion), not the old 1
    assert state["ao_pass_default"] == 0.0, state


def test_a_file_with_the_old_group_keeps_its_keyframes_in_every_blender(run_in_blender, tmp_path):
    """A file saved with an older layout of the shared group, opened: the
    group is rebuilt and the node keeps its values, its Value node's link and
    its keyframes. bpy 5.3 deleted the keyframes with the interface sockets
    the rebuild removes (Blur Size then 9 at every frame, silently; an
    exploratory run); they are put back (socket_keys.restore)."""
    old = tmp_path / "old.blend"
    saved = run_in_blender(SCRIPTS / "ui_old_file.py", old)
    assert "OLD SOCKET NodeSocketFloat" in saved.stdout, saved.stdout[-3000:]
    completed = run_in_blender(SCRIPTS / "old_file_upgrade.py", blend=old)
    line = next((text for text in completed.stdout.splitlines() if text.startswith("UPGRADE ")),
                None)
    assert line is not None, completed.stdout[-3000:]
    state = json.loads(line[len("UPGRADE "):])
    assert state["current"], state
    assert state["socket_types"] == {name: "NodeSocketInt"
                                     for name in ("Directions", "Steps", "Blur Size")}, state
    assert state["directions"] == 8 and state["steps_source"] == ["Steps Value"], state
    assert state["blur"] == [3, 6, 9], state
    # The hidden pass input held the AO before layout 5 (1 unlinked), the
    # occlusion since: the old 1 is not kept (it would black the image).
    assert state["ao_pass_value"] == 0.0, state
    # an HBAO node in an artist's node group keeps its values as well
    assert state["grouped_directions"] == 7, state
    # Everything set on a curve is kept, not its keys alone (5.3 deleted the
    # modifiers, easing and keyframe types with the curve).
    curve = state["radius_curve"]
    assert curve is not None, state
    assert curve["first"] == ["BACK", "EASE_OUT", 2.5] and curve["last_type"] == "BREAKDOWN"
    assert curve["extrapolation"] == "LINEAR", curve
    assert curve["modifiers"] == [
        ["CYCLES", "REPEAT_OFFSET", 3], ["NOISE", True, 40.0, 50.0, pytest.approx(0.02)],
        ["ENVELOPE", True, 52.0, 58.0, [[55.0, pytest.approx(0.4), pytest.approx(0.9)]]]], curve
    before = json.loads(next(text for text in saved.stdout.splitlines()
                             if text.startswith("OLD RADIUS "))[len("OLD RADIUS "):])
    assert {frame: curve["values"][frame] for frame in before} == before, (before, curve)
    # ... and so is a driver (5.3 deleted it too), its curve's modifiers (the
    # Generator that driver_add gives it in some versions) as they were.
    modifiers = int(next(text for text in saved.stdout.splitlines()
                         if text.startswith("OLD DRIVER MODIFIERS ")).split()[-1])
    assert state["drivers"] == [["Thickness", "0.25 + 0.001 * frame + 0.0 * x", [
        ["frame", "SINGLE_PROP", "SCENE", "Scene", "frame_current", "LOC_X"],
        ["x", "TRANSFORMS", "OBJECT", "Camera", "", "LOC_X"]], modifiers,
        [[0.0, 0.0], [2.0, 4.0]]]], state


def test_a_background_render_releases_the_librarys_memory_at_its_end(run_in_blender, tmp_path):
    """In `-b` and bpy the add-on hands the library's working memory back
    when a render ends (memory_hold.py; a window holds it for the next F12
    render: test_ui.py): across the add-on's render_complete handler alone,
    a 1280x720 render's resident memory drops by the library's buffers
    (about 26 bytes a pixel, 23 MiB: 18 MiB or more), and nothing is left
    held."""
    completed = run_in_blender(SCRIPTS / "memory_release_b.py", tmp_path / "out", 1280, 720)
    released = json_line(completed.stdout, "RELEASE_B")
    assert not released["held"], released
    assert released["before_mb"] - released["after_mb"] >= 18.0, released
    # The add-on disabled while a render runs: its engine outlives memory_hold's
    # handler, and releases at the end of its AO itself (nothing else would
    # before Blender quits; a review's find).
    completed = run_in_blender(SCRIPTS / "memory_release_b.py", tmp_path / "outlived", 320, 180,
                               "outlived")
    released = json_line(completed.stdout, "RELEASE_B")
    assert released == {"releases": 1, "held": False}, released
