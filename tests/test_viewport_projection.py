# SPDX-License-Identifier: GPL-2.0-or-later
"""The viewport preview's camera model and parameters without Blender: the
frame from a projection matrix equals the library's camera model (libhbao's
hbao_camera_view, through the binding), and the depth-buffer linearisation
inverts the projection."""
import math
import re
import sys

import pytest

from conftest import REPO

# The add-on imports as a package without Blender.
sys.path.insert(0, str(REPO / "addon"))
from hbao import camera as camera_model  # noqa: E402
from hbao import parameters  # noqa: E402
from hbao.viewport import projection  # noqa: E402

# float64 throughout: only rounding separates the two derivations.
TOLERANCE = 1e-9
# A cropped camera's sensor and shift are float32 fields of hbao_camera (2^-24
# relative) of numbers up to a few image widths: 1e-5 pixel widths bounds their
# rounding, and 1e-6 relative the pixel sizes'.
CROP_TOLERANCE_PIXELS = 1e-5
CROP_TOLERANCE_RELATIVE = 1e-6


@pytest.fixture(autouse=True)
def library(native):
    """frame_from_camera and crop_camera call libhbao: this build's."""
    return native


def _camera_matrix(frame, near=0.1, far=100.0):
    """The OpenGL projection of `frame` (Blender's perspective_m4 / orthographic_m4
    of the view plane), built independently of projection.py."""
    left = frame.origin_x
    right = frame.origin_x + frame.width * frame.pixel_size_x
    bottom = frame.origin_y
    top = frame.origin_y + frame.height * frame.pixel_size_y
    if frame.perspective:
        # View plane at unit depth scaled to the near plane.
        left, right, bottom, top = (v * near for v in (left, right, bottom, top))
        return [[2 * near / (right - left), 0, (right + left) / (right - left), 0],
                [0, 2 * near / (top - bottom), (top + bottom) / (top - bottom), 0],
                [0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)],
                [0, 0, -1, 0]]
    return [[2 / (right - left), 0, 0, -(right + left) / (right - left)],
            [0, 2 / (top - bottom), 0, -(top + bottom) / (top - bottom)],
            [0, 0, -2 / (far - near), -(far + near) / (far - near)],
            [0, 0, 0, 1]]


CAMERAS = [
    {"type": "PERSP", "lens": 50.0},
    {"type": "PERSP", "lens": 24.0, "sensor_fit": "VERTICAL", "shift_x": 0.2, "shift_y": -0.1},
    {"type": "PERSP", "lens": 35.0, "pixel_aspect_x": 1.0, "pixel_aspect_y": 2.0},
    {"type": "ORTHO", "ortho_scale": 4.0, "shift_y": 0.3},
]


@pytest.mark.parametrize("camera", CAMERAS)
@pytest.mark.parametrize("size", [(64, 48), (30, 90)])
def test_frame_from_matrix_equals_camera_model(camera, size):
    frame = projection.frame_from_camera(camera, *size)
    again = projection.frame_from_projection_matrix(_camera_matrix(frame), *size)
    assert again.perspective == frame.perspective
    for name in ("pixel_size_x", "pixel_size_y", "origin_x", "origin_y"):
        assert getattr(again, name) == pytest.approx(getattr(frame, name), abs=TOLERANCE)


# Borders (x0, x1, y0, y1 in pixels, y from the bottom) inside both test sizes.
BORDERS = [(0, 30, 0, 48), (5, 21, 7, 40), (13, 29, 30, 47)]


@pytest.mark.parametrize("camera", CAMERAS + [{"type": "PERSP", "sensor_fit": "AUTO",
                                               "lens": 30.0, "shift_x": 0.1}])
@pytest.mark.parametrize("size", [(64, 48), (30, 90)])
@pytest.mark.parametrize("border", BORDERS)
def test_a_cropped_border_sees_the_same_pixels(camera, size, border):
    """The border's camera (camera.crop_camera, used by the render hook for
    cropped border renders) puts each of its pixels where the full frame's
    camera puts the same pixel: same pixel size, origin moved by the border's
    corner. Portrait sizes cover AUTO fitting the vertical side with
    sensor_width (one sensor_fit rule for both functions)."""
    full = projection.frame_from_camera(camera, *size)
    x0, x1, y0, y1 = border
    cropped = projection.frame_from_camera(
        camera_model.crop_camera(camera, *size, border), x1 - x0, y1 - y0)
    assert cropped.perspective == full.perspective
    assert cropped.pixel_size_x == pytest.approx(full.pixel_size_x, rel=CROP_TOLERANCE_RELATIVE)
    assert cropped.pixel_size_y == pytest.approx(full.pixel_size_y, rel=CROP_TOLERANCE_RELATIVE)
    tolerance = CROP_TOLERANCE_PIXELS * full.pixel_size_x
    assert cropped.origin_x == pytest.approx(full.origin_x + x0 * full.pixel_size_x,
                                             abs=tolerance)
    assert cropped.origin_y == pytest.approx(full.origin_y + y0 * full.pixel_size_y,
                                             abs=tolerance)


def test_camera_model_follows_blender_fit():
    # 36 mm sensor over 64 px at 50 mm: pixel size 36 / 50 / 64 per unit depth.
    wide = projection.frame_from_camera({"lens": 50.0}, 64, 48)
    assert wide.pixel_size_x == pytest.approx(36.0 / 50.0 / 64.0, abs=TOLERANCE)
    assert wide.origin_x == pytest.approx(-32 * wide.pixel_size_x, abs=TOLERANCE)
    # AUTO on a tall image spans the height with sensor_width.
    tall = projection.frame_from_camera({"lens": 50.0, "sensor_height": 10.0}, 48, 64)
    assert tall.pixel_size_y == pytest.approx(36.0 / 50.0 / 64.0, abs=TOLERANCE)
    vertical = projection.frame_from_camera({"sensor_fit": "VERTICAL", "sensor_height": 10.0},
                                            64, 48)
    assert vertical.pixel_size_y == pytest.approx(10.0 / 50.0 / 48.0, abs=TOLERANCE)


def test_without_the_library_the_frame_fails_with_its_message(library, monkeypatch, tmp_path):
    """The preview's camera frame is the library's: without libhbao it raises the
    binding's error naming the missing file (viewport/draw.py reports it)."""
    missing = tmp_path / "libhbao.so"
    monkeypatch.setenv("HBAO_LIBRARY", str(missing))
    library.unload_library()
    try:
        with pytest.raises(library.HBAOLibraryError, match=re.escape(str(missing))):
            projection.frame_from_camera({"lens": 50.0}, 64, 48)
    finally:
        library.unload_library()


def test_bad_sizes_and_cameras_are_refused():
    with pytest.raises(Exception, match="image width and height"):
        projection.frame_from_camera({}, 0, 48)
    with pytest.raises(ValueError, match="camera type"):
        projection.frame_from_camera({"type": "PANO"}, 64, 48)


@pytest.mark.parametrize("perspective", [True, False])
def test_depth_coefficients_invert_projection(perspective):
    camera = {"type": "PERSP" if perspective else "ORTHO", "ortho_scale": 5.0}
    matrix = _camera_matrix(projection.frame_from_camera(camera, 40, 30), near=0.5, far=80.0)
    a, b, c, d = projection.depth_coefficients(matrix)
    for depth in (0.5, 1.0, 7.25, 80.0):
        z = -depth
        clip_z = matrix[2][2] * z + matrix[2][3]
        clip_w = matrix[3][2] * z + matrix[3][3]
        ndc = clip_z / clip_w
        assert (a * ndc + b) / (c * ndc + d) == pytest.approx(depth, rel=1e-9)


@pytest.mark.parametrize("perspective", [True, False])
@pytest.mark.parametrize("near, far", [(0.01, 1000.0), (0.001, 10000.0), (0.5, 80.0)])
def test_depth_buffer_precision_bounds_a_buffer_steps_rounding(perspective, near, far):
    """The bound is the derivative's: one step of the stored depth (2^-24)
    moves the linearised depth by depth_buffer_precision's bound, relative
    to the depth, to first order (measured with a step a millionth as large,
    where float64 still resolves it)."""
    camera = {"type": "PERSP" if perspective else "ORTHO", "ortho_scale": 5.0}
    matrix = _camera_matrix(projection.frame_from_camera(camera, 40, 30), near=near, far=far)
    a, b, c, d = projection.depth_coefficients(matrix)
    precision = projection.depth_buffer_precision(matrix)
    scale = 1e-6
    step = 2.0 * projection.DEPTH_BUFFER_STEP * scale  # in ndc = 2 d - 1
    for depth in (2.0 * near, 1.0, 7.25, 0.5 * far):
        z = -depth
        ndc = (matrix[2][2] * z + matrix[2][3]) / (matrix[3][2] * z + matrix[3][3])
        moved = (a * (ndc + step) + b) / (c * (ndc + step) + d)
        relative = abs(moved - depth) / depth / scale
        bound = precision * (depth if perspective else 1.0 / depth)
        assert bound == pytest.approx(relative, rel=1e-2)


def test_an_orthographic_user_views_depths_are_positive():
    """A user's orthographic view clips about its pivot (-clip_end / 2 ..
    clip_end / 2): depths from the pivot would be <= 0, background, in front
    of it. They are measured from just in front of the near plane instead,
    all of them positive and their differences kept."""
    near, far = -500.0, 500.0
    p22, p23 = -2.0 / (far - near), -(far + near) / (far - near)
    matrix = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, p22, p23],
              [0.0, 0.0, 0.0, 1.0]]
    a, b, c, d = projection.depth_coefficients(matrix)
    depths = []
    # camera space z (the view looks down -z): from 1 behind the near plane,
    # in front of the pivot, to behind it
    for view_z in (499.0, 1.0, 0.0, -3.5, -499.0):
        ndc = p22 * view_z + p23
        depths.append((a * ndc + b) / (c * ndc + d))
    assert min(depths) > 0.0
    assert depths[2] - depths[1] == pytest.approx(1.0)
    assert depths[3] - depths[2] == pytest.approx(3.5)
    assert depths[0] == pytest.approx(1.0 + projection.ORTHO_NEAR_MARGIN * (far - near))


def test_parameters_clamp_like_the_library(native):
    resolved = native.resolve_params({"directions": 100, "steps": 0, "blur_size": 99,
                                      "angle_bias_degrees": 75.0, "strength": -1.0})
    assert resolved["directions"] == parameters.MAX_DIRECTIONS
    assert resolved["steps"] == 1
    assert resolved["blur_size"] == parameters.MAX_BLUR_SIZE
    assert resolved["angle_bias_degrees"] == parameters.MAX_ANGLE_BIAS_DEGREES
    assert resolved["strength"] == 0.0
    assert parameters.blur_kernel_radius(9) == 4
    assert parameters.blur_kernel_radius(8) == 3  # even sizes round down
    assert parameters.blur_kernel_radius(1) == 0
    for bad in ({"radius": -1.0}, {"radius": math.nan}, {"falloff": "LINEAR"},
                {"colour": 1}):
        with pytest.raises(ValueError):
            native.resolve_params(bad)


def test_defaults_match_header():
    header = (REPO / "csrc" / "include" / "hbao.h").read_text()
    for name, define in (("radius", "HBAO_DEFAULT_RADIUS"),
                         ("angle_bias_degrees", "HBAO_DEFAULT_ANGLE_BIAS_DEGREES"),
                         ("directions", "HBAO_DEFAULT_DIRECTIONS"),
                         ("steps", "HBAO_DEFAULT_STEPS"),
                         ("blur_size", "HBAO_DEFAULT_BLUR_SIZE"),
                         ("blur_sharpness", "HBAO_DEFAULT_BLUR_SHARPNESS"),
                         ("strength", "HBAO_DEFAULT_STRENGTH"),
                         ("background_depth", "HBAO_DEFAULT_BACKGROUND_DEPTH")):
        line = next(text for text in header.splitlines()
                    if text.startswith(f"#define {define} "))
        assert float(line.split()[2].rstrip("f")) == parameters.DEFAULTS[name]
