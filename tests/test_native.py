# SPDX-License-Identifier: GPL-2.0-or-later
"""The ctypes binding addon/hbao/native.py against the built libhbao (plain
pytest, no Blender)."""
import ctypes
import re
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO

# The add-on imports as a package without Blender (addon/hbao/__init__.py
# imports bpy only in register()).
sys.path.insert(0, str(REPO / "addon"))
from hbao import native as native_module  # noqa: E402
from hbao import native_library  # noqa: E402

HEADER = REPO / "csrc" / "include" / "hbao.h"
# Every image in these tests is small: the library's cost is irrelevant here.
HEIGHT, WIDTH = 48, 64
# The library promises bit-identical output whatever the thread count and
# memory layout, so orientation and layout comparisons are exact.
EXACT = 0.0
# A flat plane facing the camera has its horizon exactly on the tangent plane;
# with the default 10 degree angle bias, float rounding in the horizon angles
# cannot reach the bias, so the result is 1 up to float32 rounding.
FLAT_PLANE_TOLERANCE = 1e-6
# Without the bias, the cosine integration around the view vector leaves about
# 1e-4 of rounding on the plane (measured 1.1e-4 at 64x48); 1e-3 bounds it.
FLAT_PLANE_NO_BIAS_TOLERANCE = 1e-3


def _load_native():
    """The binding, with the library loaded again on first use (each test
    may point HBAO_LIBRARY elsewhere)."""
    native_module.unload_library()
    return native_module


@pytest.fixture()
def native(built_library, monkeypatch):
    monkeypatch.setenv("HBAO_LIBRARY", str(built_library))
    module = _load_native()
    yield module
    module.unload_library()


def _header_defines():
    """#define NAME value pairs of the public header (numbers only)."""
    pattern = re.compile(r"^#define (HBAO_\w+) (-?[0-9.]+)f?$", re.M)
    return {name: float(value) for name, value in pattern.findall(HEADER.read_text())}


def _bumpy_depth():
    """A sloped floor with a box on it: depth with occluders everywhere."""
    rows, cols = np.mgrid[0:HEIGHT, 0:WIDTH].astype(np.float32)
    depth = 4.0 + 0.02 * rows + 0.01 * cols
    depth[10:30, 20:40] -= 0.8
    depth[5:8, 50:60] = 1e10  # background
    return depth.astype(np.float32)


def test_defaults_match_header(native):
    defines = _header_defines()
    defaults = native.default_params()
    assert defaults["radius"] == defines["HBAO_DEFAULT_RADIUS"]
    assert defaults["angle_bias_degrees"] == defines["HBAO_DEFAULT_ANGLE_BIAS_DEGREES"]
    assert defaults["directions"] == defines["HBAO_DEFAULT_DIRECTIONS"]
    assert defaults["steps"] == defines["HBAO_DEFAULT_STEPS"]
    assert defaults["blur_size"] == defines["HBAO_DEFAULT_BLUR_SIZE"]
    assert defaults["blur_sharpness"] == defines["HBAO_DEFAULT_BLUR_SHARPNESS"]
    assert defaults["strength"] == defines["HBAO_DEFAULT_STRENGTH"]
    assert defaults["background_depth"] == defines["HBAO_DEFAULT_BACKGROUND_DEPTH"]
    assert defaults["falloff"] == "NONE"
    assert defaults["integration"] == "COSINE"
    assert defaults["half_resolution"] is False
    assert defaults["threads"] == 0
    assert native.library_version() == "{:.0f}.{:.0f}.{:.0f}".format(
        defines["HBAO_VERSION_MAJOR"], defines["HBAO_VERSION_MINOR"],
        defines["HBAO_VERSION_PATCH"])


def test_struct_sizes_match_library(native):
    library = native.load_library()
    assert library.hbao_params_size() == ctypes.sizeof(native.HBAOParams)
    assert library.hbao_camera_size() == ctypes.sizeof(native.HBAOCamera)
    assert library.hbao_view_size() == ctypes.sizeof(native.HBAOView)


@pytest.mark.parametrize("params, camera, expected_fragment", [
    ({"radius": -1.0}, None, "a parameter is not a number"),
    ({"radius": float("nan")}, None, "a parameter is not a number"),
    ({}, {"lens": 0.0}, "the camera is invalid"),
    ({}, {"world_to_camera": [[0.0] * 4] * 4}, "the camera is invalid"),
])
def test_library_errors_become_exceptions_with_its_message(native, params, camera,
                                                           expected_fragment):
    with pytest.raises(native.HBAOError) as caught:
        native.compute_ao(_bumpy_depth(), params=params, camera=camera)
    library = native.load_library()
    assert caught.value.code != 0
    assert caught.value.library_message == library.hbao_result_message(
        caught.value.code).decode()
    assert expected_fragment in str(caught.value)


def test_bad_arguments_raise_value_error(native):
    with pytest.raises(ValueError, match="unknown HBAO parameter"):
        native.compute_ao(_bumpy_depth(), params={"raduis": 1.0})
    with pytest.raises(ValueError, match="falloff must be one of"):
        native.compute_ao(_bumpy_depth(), params={"falloff": "LINEAR"})
    with pytest.raises(ValueError, match="camera type"):
        native.compute_ao(_bumpy_depth(), camera={"type": "PANO"})
    with pytest.raises(ValueError, match="normal must be"):
        native.compute_ao(_bumpy_depth(), np.zeros((HEIGHT, WIDTH, 2), np.float32))
    with pytest.raises(ValueError, match="out must be"):
        native.compute_ao(_bumpy_depth(), out=np.zeros((HEIGHT, WIDTH), np.float64))
    with pytest.raises(ValueError, match="needs shape"):
        native.compute_ao(np.ones(HEIGHT * WIDTH, np.float32))


@pytest.mark.parametrize("integration", ["HBAO", "COSINE"])
@pytest.mark.parametrize("with_normals", [False, True])
def test_flat_plane_facing_camera_is_unoccluded(native, integration, with_normals):
    depth = np.full((HEIGHT, WIDTH), 3.0, np.float32)
    normal = None
    if with_normals:
        # Identity world_to_camera: world = camera space; the camera looks down -Z.
        normal = np.zeros((HEIGHT, WIDTH, 3), np.float32)
        normal[..., 2] = 1.0
    ao = native.compute_ao(depth, normal, params={"radius": 2.0, "integration": integration})
    assert ao.shape == (HEIGHT, WIDTH) and ao.dtype == np.float32
    assert np.all(np.abs(ao - 1.0) <= FLAT_PLANE_TOLERANCE)
    unbiased = native.compute_ao(depth, normal, params={
        "radius": 2.0, "integration": integration, "angle_bias_degrees": 0.0})
    assert np.all(np.abs(unbiased - 1.0) <= FLAT_PLANE_NO_BIAS_TOLERANCE)


def test_occluders_darken(native):
    ao = native.compute_ao(_bumpy_depth(), params={"radius": 1.0, "blur_size": 0})
    assert np.all(np.isfinite(ao)) and ao.min() >= 0.0 and ao.max() <= 1.0
    # The floor pixels next to the box's left edge see it as a wall.
    assert ao[20, 17:20].max() < 0.95
    assert np.all(ao[5:8, 50:60] == 1.0)  # background


def test_kept_working_memory_changes_no_result(native):
    """The library keeps its buffers between calls; a larger frame in
    between and release_memory() (what the add-on calls after a render)
    change nothing. Releasing without a loaded library loads none."""
    depth = _bumpy_depth()
    params = {"radius": 1.0}
    first = native.compute_ao(depth, params=params)
    native.compute_ao(np.tile(depth, (2, 3)) * 1.3, params=params)
    assert np.array_equal(native.compute_ao(depth, params=params), first)
    native.release_memory()
    assert np.array_equal(native.compute_ao(depth, params=params), first)
    native.unload_library()
    native.release_memory()
    from hbao import native_library
    assert native_library._LIBRARY.loaded() is None


def test_bottom_up_flips_consistently(native):
    depth = _bumpy_depth()
    normal = np.zeros((HEIGHT, WIDTH, 4), np.float32)
    normal[..., 1] = 0.3
    normal[..., 2] = 0.95
    top_down = native.compute_ao(depth, normal)
    bottom_up = native.compute_ao(depth[::-1].copy(), normal[::-1].copy(), bottom_up=True)
    assert np.abs(bottom_up[::-1] - top_down).max() <= EXACT
    # And not symmetric, so the comparison above means something.
    assert np.abs(top_down[::-1] - top_down).max() > 0.01


def test_layouts_need_no_copy_and_agree(native):
    depth = _bumpy_depth()
    reference = native.compute_ao(depth)
    flat = native.compute_ao(depth.reshape(-1), shape=(HEIGHT, WIDTH))
    assert np.abs(flat - reference).max() <= EXACT
    # A depth channel inside an RGBA-like buffer is passed with a pixel stride.
    packed = np.zeros((HEIGHT, WIDTH, 4), np.float32)
    packed[..., 2] = depth
    strided = native.compute_ao(packed[..., 2])
    assert np.abs(strided - reference).max() <= EXACT
    out = np.full((HEIGHT, WIDTH), -1.0, np.float32)
    returned = native.compute_ao(depth.astype(np.float64), out=out)
    assert returned is out
    assert np.abs(out - reference).max() <= EXACT


def test_any_numpy_layout_gives_the_same_ao(native):
    """Layouts the library cannot read as they are are copied first: a
    Fortran-ordered or broadcast depth was refused as "a pixel or row stride
    is too small" (an exploratory run), normals with every other float taken
    (a stride between components) and a misaligned buffer were passed on."""
    depth = _bumpy_depth()
    normal = np.zeros((HEIGHT, WIDTH, 3), np.float32)
    normal[..., 2] = 1.0
    normal[::3, ::2, 0] = 0.3
    reference = native.compute_ao(depth, normal)
    spaced = np.zeros((HEIGHT, WIDTH, 6), np.float32)
    spaced[..., ::2] = normal
    raw = np.zeros(HEIGHT * WIDTH * 4 + 1, np.uint8)
    misaligned = raw[1:].view(np.float32).reshape(HEIGHT, WIDTH)
    misaligned[...] = depth
    assert not misaligned.flags.aligned
    for name, layout_depth, layout_normal in (
            ("Fortran order", np.asfortranarray(depth), np.asfortranarray(normal)),
            ("every other float", depth, spaced[..., ::2]),
            ("misaligned", misaligned, normal)):
        assert np.abs(native.compute_ao(layout_depth, layout_normal) - reference).max() <= EXACT, \
            name
    row = np.broadcast_to(depth[:1], depth.shape)
    assert np.abs(native.compute_ao(row) - native.compute_ao(np.array(row))).max() <= EXACT


# The view numbers are the library's doubles from float camera fields: exact
# formulas evaluated in another order differ by a few double roundings.
VIEW_TOLERANCE = 1e-12


def test_camera_view_is_blenders_sensor_fit(native):
    # AUTO on a portrait image spans its height with sensor_width (never sensor_height).
    view = native.camera_view({"lens": 50.0, "sensor_height": 10.0, "shift_x": 0.125}, 30, 90)
    assert view.perspective == 1
    assert view.pixel_size_y == pytest.approx(36.0 / 50.0 / 90.0, abs=VIEW_TOLERANCE)
    assert view.pixel_size_x == pytest.approx(view.pixel_size_y, abs=VIEW_TOLERANCE)
    # shift_x counts the fitted side's length: 0.125 * 90 pixel widths to the right.
    assert view.origin_x == pytest.approx((-15 + 11.25) * view.pixel_size_x,
                                          abs=VIEW_TOLERANCE)
    vertical = native.camera_view({"sensor_fit": "VERTICAL", "sensor_height": 10.0,
                                   "type": "ORTHO", "ortho_scale": 3.0}, 90, 30)
    assert vertical.perspective == 0
    assert vertical.pixel_size_y == pytest.approx(3.0 / 30.0, abs=VIEW_TOLERANCE)


def test_camera_crop_keeps_the_dict_and_the_rays(native):
    camera = {"type": "PERSP", "lens": 35.0, "shift_y": 0.2, "pixel_aspect_y": 2.0,
              "world_to_camera": [[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0, -1.0, 0, 0], [0, 0, 0, 1]]}
    cropped = native.camera_crop(camera, 64, 48, 8, 4, 20, 30)
    assert cropped["world_to_camera"] == camera["world_to_camera"]
    assert cropped["type"] == "PERSP" and cropped["lens"] == 35.0
    # 64 x 2 * 48 is taller than wide: AUTO fitted the vertical side, now explicit.
    assert cropped["sensor_fit"] == "VERTICAL"
    full = native.camera_view(camera, 64, 48)
    crop = native.camera_view(cropped, 20, 30)
    # The crop's bottom-left pixel corner is the full image's (8, 48 - 4 - 30).
    # Float camera fields: 1e-6 of a pixel size covers their rounding.
    assert crop.origin_x == pytest.approx(full.origin_x + 8 * full.pixel_size_x,
                                          abs=1e-6 * full.pixel_size_x)
    assert crop.origin_y == pytest.approx(full.origin_y + 14 * full.pixel_size_y,
                                          abs=1e-6 * full.pixel_size_x)


@pytest.mark.parametrize("call, fragment", [
    (lambda n: n.camera_crop({}, 64, 48, -4, 0, 70000, 8), "crop rectangle"),
    (lambda n: n.camera_crop({}, 64, 48, 0, 0, 0, 8), "crop rectangle"),
    (lambda n: n.camera_crop({}, 0, 48, 0, 0, 8, 8), "image width and height"),
    (lambda n: n.camera_crop({"lens": -1.0}, 64, 48, 0, 0, 8, 8), "the camera is invalid"),
    (lambda n: n.camera_view({}, 64, 70000), "image width and height"),
    (lambda n: n.camera_view({"ortho_scale": 0.0, "type": "ORTHO"}, 64, 48),
     "the camera is invalid"),
])
def test_camera_rule_errors_carry_the_library_message(native, call, fragment):
    with pytest.raises(native.HBAOError, match=fragment):
        call(native)


def test_missing_library_names_the_path(monkeypatch, tmp_path):
    missing = tmp_path / "nowhere" / "libhbao.so"
    monkeypatch.setenv("HBAO_LIBRARY", str(missing))
    module = _load_native()
    with pytest.raises(module.HBAOLibraryError, match=re.escape(str(missing))):
        module.compute_ao(np.ones((4, 4), np.float32))


@pytest.mark.parametrize("version, left_out, message", [
    # another major version, with every function the binding declares
    (10000, (), "version 1.0.0, this add-on needs 0.6.x"),
    # a later 0.x, which may have changed what the binding calls
    (700, (), "version 0.7.0, this add-on needs 0.6.x"),
    # 0.5.0, which lacked hbao_implementation_name: named by its version,
    # not by the first function it lacks
    (500, ("hbao_implementation_name",), "version 0.5.0, this add-on needs 0.6.x"),
])
def test_incompatible_library_is_refused(monkeypatch, tmp_path, version, left_out, message):
    """A library of a version the binding cannot call: refused on load, by its version."""
    # the functions the binding declares (native_library._FUNCTIONS) but
    # left_out, as stubs
    own = {"hbao_version": f"int32_t hbao_version(void) {{ return {version}; }}",
           "hbao_params_size": "size_t hbao_params_size(void) { return 48; }",
           "hbao_camera_size": "size_t hbao_camera_size(void) { return 104; }",
           "hbao_view_size": "size_t hbao_view_size(void) { return 40; }"}
    stubs = [own.get(name, f"int32_t {name}(void) {{ return 0; }}")
             for name in native_library._FUNCTIONS if name not in left_out]
    source = tmp_path / "fake.c"
    source.write_text("#include <stddef.h>\n#include <stdint.h>\n" + "\n".join(stubs) + "\n")
    fake = tmp_path / "libfake.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-o", str(fake), str(source)], check=True)
    monkeypatch.setenv("HBAO_LIBRARY", str(fake))
    module = _load_native()
    with pytest.raises(module.HBAOLibraryError, match=re.escape(message)):
        module.load_library()


def test_the_binding_calls_the_header_it_mirrors():
    """The binding's version is the header's: a release that changes the
    minor version changes the binding's with it, after a look at what the
    binding calls. Any patch of it is accepted, and no other version."""
    header = HEADER.read_text()
    major, minor, patch = (int(re.search(rf"#define HBAO_VERSION_{part} (\d+)", header).group(1))
                           for part in ("MAJOR", "MINOR", "PATCH"))
    assert (native_library.BINDING_VERSION_MAJOR, native_library.BINDING_VERSION_MINOR) == (
        major, minor)
    for accepted in (0, patch, 99):
        assert native_library._binding_calls(major * 10000 + minor * 100 + accepted)
    for refused in ((major, minor - 1, 99), (major, minor + 1, 0), (major + 1, minor, patch)):
        assert not native_library._binding_calls(refused[0] * 10000 + refused[1] * 100
                                                 + refused[2])


def test_clamping_happens_once_and_says_so(native):
    """The library's resolver, reached through the binding, clamps and names
    each clamp in the words the node shows."""
    warnings = []
    resolved = native.resolve_params({"steps": 500, "directions": 0, "blur_size": 7.6,
                                      "strength": 20.0}, warnings)
    assert resolved["steps"] == 64  # HBAO_MAX_STEPS
    assert resolved["directions"] == 1
    # rounded by the binding to 8, then the kernel's size (even sizes round
    # down), not clamped: no warning
    assert resolved["blur_size"] == 7
    assert resolved["strength"] == 16.0  # HBAO_MAX_STRENGTH
    assert sorted(warnings) == sorted([
        "Steps 500 is above the limit 64; using 64",
        "Directions 0 is below the limit 1; using 1",
        "Strength 20 is above the limit 16; using 16"])
    # a half rounds up, as Blender rounds a keyframed integer socket (round()
    # gave 2.5 -> 2 and 3.5 -> 4)
    for fed, whole in ((2.5, 3), (3.5, 4), (-2.5, -2), (6.49, 6)):
        assert native.resolve_params({"steps": fed})["steps"] == max(whole, 1), fed
    untouched = []
    native.resolve_params(native_module.default_params(), untouched)
    assert untouched == []
    # No blur: its sharpness does nothing, so it resolves to 0 unwarned, and
    # the AO cache finds the settings equal (hbao_params_resolve).
    quiet = []
    for size, sharpness in ((0, 32.0), (1, 5000.0), (2, 8.0)):
        resolved = native.resolve_params({"blur_size": size, "blur_sharpness": sharpness}, quiet)
        assert (resolved["blur_size"], resolved["blur_sharpness"]) == (0, 0.0)
    assert quiet == []


@pytest.mark.parametrize("params, message", [
    ({"radius": float("nan")}, "Radius is not a number"),
    ({"steps": float("nan")}, "Steps is not a number"),
    # (an infinite radius was "not a number", a negative thickness "not a
    # valid value": an audit)
    ({"radius": float("inf")}, "Radius is infinite"),
    ({"steps": float("inf")}, "Steps is infinite"),
    ({"steps": "many"}, "Steps is not a number"),
    ({"background_depth": float("-inf")}, "Background Depth -inf is not above 0"),
    ({"radius": -1.0}, "Radius -1 is negative"),
    ({"thickness": -0.5}, "Thickness -0.5 is negative"),
    ({"falloff": "LINEAR"}, "falloff must be one of"),
    ({"raduis": 1.0}, "unknown HBAO parameter 'raduis'"),
])
def test_unusable_values_are_rejected_with_their_name(native, params, message):
    with pytest.raises(ValueError, match=message):
        native.resolve_params(params)


def test_values_beyond_the_binary_fields_are_clamped_not_wrapped(native):
    """A Value node may feed 1e12 Steps or 1e300 Strength: the binding keeps
    them inside int32 and float32 for the library, which clamps them; they do
    not wrap around to small numbers or become infinities it refuses."""
    warnings = []
    resolved = native.resolve_params({"steps": 1e12, "directions": -1e12, "strength": 1e300},
                                     warnings)
    assert (resolved["steps"], resolved["directions"], resolved["strength"]) == (64, 1, 16.0)
    assert sorted(warnings) == sorted([
        "Steps 1e+12 is above the limit 64; using 64",
        "Directions -1e+12 is below the limit 1; using 1",
        "Strength 1e+300 is above the limit 16; using 16"])


UPDATE_SCRIPT = r'''
import os, shutil, sys
sys.path.insert(0, sys.argv[1])
source, folder = sys.argv[2], sys.argv[3]
installed = os.path.join(folder, "libhbao.so")
shutil.copy(source, installed)
os.environ["HBAO_LIBRARY"] = installed
from hbao import native
print("FIRST", native.library_version())
native.unload_library()  # enabled again, the same files: the loaded library again
print("AGAIN", native.library_version())
shutil.copy(source, installed + ".new")
os.replace(installed + ".new", installed)  # an update while the process runs
native.unload_library()
try:
    native.library_version()
    print("LOADED THE OLD LIBRARY")
except native.HBAOLibraryError as error:
    print("REFUSED", error)
'''


def test_a_library_replaced_while_loaded_says_restart(tmp_path):
    """An update of the add-on while Blender runs replaces lib/libhbao.so;
    the dynamic loader hands back the library it loaded under that path
    without looking at the file, so the new add-on ran the old library (an
    exploratory run: the version stayed 0.3.0 after installing 0.3.2; a
    changed struct would have been refused as from "different versions",
    right after reinstalling both). The add-on now says to restart Blender.
    The same file loaded again (the add-on disabled and enabled) loads."""
    from conftest import LIBRARY
    script = tmp_path / "update.py"
    script.write_text(UPDATE_SCRIPT)
    completed = subprocess.run(
        [sys.executable, str(script), str(REPO / "addon"), str(LIBRARY.resolve()), str(tmp_path)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=120)
    assert completed.returncode == 0, completed.stdout
    assert "FIRST 0." in completed.stdout and "AGAIN 0." in completed.stdout, completed.stdout
    assert "REFUSED" in completed.stdout and "restart Blender" in completed.stdout, \
        completed.stdout


def test_integers_past_int32_are_refused_not_wrapped(native):
    """ctypes turned 2^32 + 10 into 10 for the library's int32 arguments: a
    crop at x = 2^32 + 10 gave the crop at x = 10, a view 2^32 + 64 wide the
    view 64 wide (an exploratory run). They are refused now."""
    crop = native.camera_crop({}, 1920, 1080, 10, 0, 100, 100)
    assert crop == native.camera_crop({}, 1920, 1080, np.int64(10), 0, 100, 100)
    for call in (lambda: native.camera_crop({}, 1920, 1080, 2 ** 32 + 10, 0, 100, 100),
                 lambda: native.camera_view({}, 2 ** 32 + 64, 48),
                 lambda: native.camera_view({}, 64.5, 48)):
        with pytest.raises(ValueError, match="int32 range"):
            call()


def test_the_background_below_clip_end_is_the_librarys_rule(native):
    """The node's background depth (camera.background_depth) is libhbao's
    hbao_clip_background_depth, the rule the CLI takes too (once in two
    languages; csrc/tests/test_camera.c holds its values): the sky EEVEE 4.5
    and 5.0 wrote short of a long clip range's Clip End is background,
    geometry past 65504 is not, and a camera without a clip range keeps the
    parameter's depth."""
    from hbao import camera as camera_model
    long_range = camera_model.background_depth({"clip_start": 0.1, "clip_end": 1e5}, 65504.0)
    assert long_range == native.clip_background_depth(0.1, 1e5, 65504.0)
    assert 65504.0 < long_range <= 99864.38
    assert camera_model.background_depth({"clip_start": 0.1, "clip_end": 9.0}, 65504.0) == \
        pytest.approx(9.0 * (1.0 - 2.0 ** -23 * 90.0), rel=1e-7)
    # a camera file written before clip_start was: the lesser of the two
    assert camera_model.background_depth({"clip_end": 1e6}, 65504.0) == 65504.0
    assert camera_model.background_depth({"clip_end": 9.0}, 65504.0) == \
        pytest.approx(9.0 * (1.0 - 1e-5), rel=1e-7)
    assert camera_model.background_depth({}, 1234.5) == 1234.5


def test_a_usual_compute_has_no_notes_and_each_note_has_words(native):
    """native.last_notes() (hbao_last_notes): nothing after a usual call in
    this thread; the one note there is, the reference search for want of
    memory (csrc/tests/internal/test_stages.c provokes it), is worded by
    the library for the CLI and the render's report alike."""
    depth = np.full((32, 48), 4.0, dtype=np.float32)
    native.compute_ao(depth, params={"radius": 0.5})
    assert native.last_notes() == []
    library = native_module.load_library()
    assert b"the reference search computed the AO" in library.hbao_note_message(1)
    assert b"lower the radius" in library.hbao_note_message(2)
    assert b"raise the radius" in library.hbao_note_message(4)
    assert library.hbao_note_message(8) == b"unknown note"
    # the add-on's short forms, one for each of hbao.h's notes
    header = (REPO / "csrc" / "include" / "hbao.h").read_text()
    bits = {int(value) for value in re.findall(r"#define HBAO_NOTE_\w+ (\d+)u", header)}
    assert bits == set(native_module.NOTE_SHORT_FORMS) == {1, 2, 4}
    assert all(len(short) <= 24 for short in native_module.NOTE_SHORT_FORMS.values())


def test_an_exr_library_of_another_interface_is_refused(monkeypatch, tmp_path):
    """libhbao_exr's handshake is its interface version: another one is
    refused by its number before any other function is looked up."""
    from hbao import exr_passes
    source = tmp_path / "fake_exr.c"
    source.write_text("#include <stdint.h>\n"
                      "int32_t hbao_exr_interface_version(void) { return 1; }\n")
    fake = tmp_path / "libfake_exr.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-o", str(fake), str(source)], check=True)
    monkeypatch.setenv(exr_passes.LIBRARY_ENVIRONMENT_VARIABLE, str(fake))
    exr_passes.unload_library()
    try:
        with pytest.raises(exr_passes.EXRLibraryError,
                           match=f"is version 1, this add-on needs "
                                 f"{exr_passes.BINDING_INTERFACE_VERSION}:"):
            exr_passes.load_library()
    finally:
        exr_passes.unload_library()
