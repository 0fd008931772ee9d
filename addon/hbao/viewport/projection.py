# SPDX-License-Identifier: GPL-2.0-or-later
"""How a pixel of the preview maps to camera space. Needs neither bpy nor gpu,
so that plain pytest can check it.

The shaders place pixel (i, j) (column i from the left, row j from the top, as in
docs/algorithm.md) at

    x = origin_x + (i + 0.5) * pixel_size_x
    y = origin_y + (H - 1 - j + 0.5) * pixel_size_y

per unit depth (perspective: P = (x * depth, y * depth, -depth)) or in scene
units (orthographic: P = (x, y, -depth)). A ViewFrame holds those four numbers.
The C library derives them from a Blender camera (frame_from_camera calls its
hbao_camera_view through the binding, so it needs libhbao); the 3D viewport has
no camera in free view, only its projection matrix (frame_from_projection_matrix).
Both give the same frame for the same view, which tests/test_viewport_projection.py
checks.
"""
from dataclasses import dataclass

from .. import native


@dataclass(frozen=True)
class ViewFrame:
    width: int
    height: int
    perspective: bool
    pixel_size_x: float
    pixel_size_y: float
    origin_x: float
    origin_y: float

    @property
    def pixel_aspect(self):
        """ycor of docs/algorithm.md: a pixel's height over its width."""
        return self.pixel_size_y / self.pixel_size_x


def frame_from_camera(camera, width, height):
    """The frame of docs/algorithm.md's camera model (Blender's
    BKE_camera_params_compute_viewplane) for a camera dict as native.compute_ao takes:
    libhbao's own numbers (native.camera_view). Raises native.HBAOLibraryError when
    the library cannot be loaded, native.HBAOError for a size or camera it refuses,
    ValueError for a malformed camera dict."""
    view = native.camera_view(camera, width, height)
    return ViewFrame(
        width=width, height=height, perspective=bool(view.perspective),
        pixel_size_x=view.pixel_size_x, pixel_size_y=view.pixel_size_y,
        origin_x=view.origin_x, origin_y=view.origin_y)


def frame_from_projection_matrix(matrix, width, height):
    """The frame of an OpenGL projection matrix (Blender's RegionView3D.window_matrix;
    `matrix[row][column]`) drawn into `width` x `height` pixels. Normalised device x
    of pixel centre i is 2 (i + 0.5) / W - 1; with z = -depth, perspective clip
    x = P00 x + P02 z over w = depth gives x / depth = (ndc_x + P02) / P00;
    orthographic ndc_x = P00 x + P03 gives x = (ndc_x - P03) / P00."""
    if width < 1 or height < 1:
        raise ValueError(f"image size must be positive, not {width}x{height}")
    p = [[float(matrix[r][c]) for c in range(4)] for r in range(4)]
    perspective = is_perspective_matrix(p)
    if perspective:
        origin_x = (p[0][2] - 1.0) / p[0][0]
        origin_y = (p[1][2] - 1.0) / p[1][1]
    else:
        origin_x = (-1.0 - p[0][3]) / p[0][0]
        origin_y = (-1.0 - p[1][3]) / p[1][1]
    return ViewFrame(
        width=width, height=height, perspective=perspective,
        pixel_size_x=2.0 / (width * p[0][0]), pixel_size_y=2.0 / (height * p[1][1]),
        origin_x=origin_x, origin_y=origin_y)


def half_frame(frame):
    """The frame of the half-resolution grid of `frame` (csrc/lib/camera.c,
    hbao_grid_set_projection with scale 2): its pixel (i, j), j from the
    top, is `frame`'s pixel (2 i, 2 j); the grid has ceil(W / 2) x
    ceil(H / 2) pixels."""
    width, height = (frame.width + 1) // 2, (frame.height + 1) // 2
    return ViewFrame(
        width=width, height=height, perspective=frame.perspective,
        pixel_size_x=2.0 * frame.pixel_size_x, pixel_size_y=2.0 * frame.pixel_size_y,
        origin_x=frame.origin_x - 0.5 * frame.pixel_size_x,
        origin_y=frame.origin_y + (frame.height + 0.5 - 2 * height) * frame.pixel_size_y)


def is_perspective_matrix(matrix):
    """A perspective projection puts -z into w (row 3 = 0 0 -1 0); an orthographic one
    keeps w = 1."""
    return abs(float(matrix[3][3])) < 0.5


# The view's sky (its cleared depth buffer) linearises to 0, background;
# every depth the buffer holds is geometry, at any distance. So the preview's
# background depth is float's largest: the parameter's 65504 hid a scene past
# 65504 units in the preview, though the render (camera's Clip End) shades it.
BACKGROUND_DEPTH = 3.4028234663852886e38


# An orthographic user view (not a camera's) clips from -clip_end / 2 to
# +clip_end / 2 about its pivot (P23 = 0): depths measured from the pivot are
# negative in front of it, and the AO takes a depth <= 0 for background (no AO
# there, nor occlusion from it). An orthographic AO does not change when every
# depth moves by the same amount (positions shift along the view; only the
# blur's and the upsampling's depth weights, relative to the depth, soften),
# so such a view's depths are measured from a plane this fraction of its
# clip range in front of its near clip plane instead.
ORTHO_NEAR_MARGIN = 1.0e-3


def depth_coefficients(matrix):
    """(a, b, c, d) with planar depth = (a ndc + b) / (c ndc + d), ndc = 2 d_buffer - 1,
    for the depth buffer of projection `matrix`. Perspective: ndc = (P22 z + P23) / -z
    gives depth = P23 / (ndc + P22); orthographic: ndc = P22 z + P23 gives
    depth = (P23 - ndc) / P22, moved (ORTHO_NEAR_MARGIN) where the near clip
    plane is not in front of the view (depth <= 0 there)."""
    p22, p23 = float(matrix[2][2]), float(matrix[2][3])
    if is_perspective_matrix(matrix):
        return (0.0, p23, 1.0, p22)
    near, far = (p23 + 1.0) / p22, (p23 - 1.0) / p22
    shift = 0.0 if near > 0.0 else ORTHO_NEAR_MARGIN * (far - near) - near
    return (-1.0 / p22, p23 / p22 + shift, 0.0, 1.0)


# The stored value of a viewport's depth buffer steps by at most 2^-24: a
# 24-bit normalised integer (Blender 3.4's), or a float in [0.5, 1) (a 32-bit
# float buffer, where all but the nearest depths lie).
DEPTH_BUFFER_STEP = 2.0 ** -24
# The steps the preview's tangent test allows for: the rounding of the
# pixel's depth and of its sample's, and samples a little deeper than the
# pixel (the term grows with the depth).
DEPTH_BUFFER_MARGIN = 4.0


def depth_buffer_precision(matrix):
    """How much one step of the depth buffer of projection `matrix` moves a
    linearised depth, relative to the depth (docs/algorithm.md, "Depth
    precision"): per unit of depth in perspective (a step of ndc = 2 d - 1
    moves depth = P23 / (ndc + P22) by depth^2 / |P23| per unit of ndc: a
    small Clip Start makes far depths coarse), or times the depth's inverse
    in orthographic views (depth moves by 1 / |P22| per unit of ndc, the same
    everywhere). The preview's tangent test allows for DEPTH_BUFFER_MARGIN
    such steps beside the float depth's own rounding, and its normals are
    fitted where one step over a pixel's width tilts a tangent by more than
    BUFFER_FIT_SLOPE (shader_sources.NORMAL_DEFINES)."""
    p22, p23 = float(matrix[2][2]), float(matrix[2][3])
    ndc_step = 2.0 * DEPTH_BUFFER_STEP
    return ndc_step / abs(p23 if is_perspective_matrix(matrix) else p22)
