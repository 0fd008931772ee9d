# SPDX-License-Identifier: GPL-2.0-or-later
"""The preview's GPU passes: viewport depth -> planar depth -> [half grid] ->
normals -> AO -> blur -> [upsample] -> composite, as the library orders them
(csrc/lib/blur.c: at half resolution the blur runs on the half grid). One
AOPipeline per 3D view region keeps its targets and re-creates them when the
region's size changes."""
import math

import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader

from .. import parameters
from . import projection, shader_sources, shaders

# Two triangles covering normalised device coordinates.
_QUAD = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
_batches = {}


def _draw_quad(name):
    """Draws the full-screen quad with shader `name`, which must be bound."""
    shader = shaders.get(name)
    batch = _batches.get(name)
    if batch is None:
        batch = _batches[name] = batch_for_shader(shader, "TRIS", {"position": _QUAD})
    batch.draw(shader)


def release():
    """Drop cached batches and shaders (on unregister)."""
    _batches.clear()
    shaders.release()


class _Target:
    """A float texture (one channel unless told) and the framebuffer that draws into it."""

    def __init__(self, width, height, texture_format="R32F"):
        self.texture = gpu.types.GPUTexture((width, height), format=texture_format)
        self.framebuffer = gpu.types.GPUFrameBuffer(color_slots=self.texture)


class AOPipeline:
    """The targets of one view: full-size ones, and the half grid's when the
    preview runs at half resolution; kept while the view's size (and
    resolution mode) stays, so that a frame allocates only its depth upload."""

    def __init__(self):
        self.size = None
        self._linear_depth = self._normals = self._ao = self._blurred_rows = None
        self._half_depth = self._half_normals = self._half_ao = self._half_blurred_rows = None
        self._kept = None  # (key, depth values, AO texture) of the last frame computed

    def kept_ao(self, key, depth):
        """The AO texture of the last frame computed, where `key` (the view's
        place, projection and settings) and `depth` (a gpu Buffer of floats)
        are that frame's; else None. Blender redraws a view once per
        anti-aliasing sample after each change (8 in Solid, 16 in Material
        Preview), each with the same depth: the passes ran for every one (a
        review's find)."""
        if self._kept is None or self._kept[0] != key:
            return None
        return self._kept[2] if np.array_equal(np.frombuffer(depth, np.float32),
                                               self._kept[1]) else None

    def keep(self, key, depth, ao_texture):
        """Keep the frame just computed for kept_ao (a copy of its depth: 4
        bytes a pixel); `ao_texture` stays this pipeline's until its next
        computation."""
        self._kept = (key, np.frombuffer(depth, np.float32).copy(), ao_texture)

    def _ensure_size(self, width, height, half=False):
        if self.size == (width, height, half):
            return
        self._linear_depth = _Target(width, height)
        self._ao = _Target(width, height)
        if half:
            # The search, its normals and the blur on the half grid; the
            # upsample writes self._ao.
            half_width, half_height = (width + 1) // 2, (height + 1) // 2
            self._half_depth = _Target(half_width, half_height)
            self._half_normals = _Target(half_width, half_height, "RGBA32F")
            self._half_ao = _Target(half_width, half_height)
            self._half_blurred_rows = _Target(half_width, half_height)
            self._normals = self._blurred_rows = None
        else:
            # Camera-space normals, full float: the AO pass and the blur read them.
            self._normals = _Target(width, height, "RGBA32F")
            self._blurred_rows = _Target(width, height)
            self._half_depth = self._half_normals = self._half_ao = None
            self._half_blurred_rows = None
        self.size = (width, height, half)

    def linearize(self, buffer_depth_texture, coefficients, half=False):
        """Planar depth (background 0) from a [0, 1] depth-buffer texture;
        coefficients from projection.depth_coefficients."""
        self._ensure_size(buffer_depth_texture.width, buffer_depth_texture.height, half)
        shader = shaders.get("linearize")
        with self._linear_depth.framebuffer.bind():
            shader.bind()
            shader.uniform_sampler("buffer_depth", buffer_depth_texture)
            shader.uniform_float("depth_coefficients", coefficients)
            _draw_quad("linearize")
        return self._linear_depth.texture

    def _search(self, depth_texture, frame, params, depth_precision, normals, ao):
        """The normal and AO passes over `frame`'s grid into targets `normals`
        and `ao`."""

        def bind_camera(shader):
            shader.uniform_sampler("depth_texture", depth_texture)
            shader.uniform_int("image_size", (frame.width, frame.height))
            shader.uniform_float("pixel_size", (frame.pixel_size_x, frame.pixel_size_y))
            shader.uniform_float("origin", (frame.origin_x, frame.origin_y))
            shader.uniform_int("perspective", 1 if frame.perspective else 0)
            shader.uniform_float("background_depth", params["background_depth"])
            shader.uniform_float("depth_precision", depth_precision)

        shader = shaders.get("normals")
        with normals.framebuffer.bind():
            shader.bind()
            bind_camera(shader)
            _draw_quad("normals")
        shader = shaders.get("ao")
        with ao.framebuffer.bind():
            shader.bind()
            bind_camera(shader)
            shader.uniform_sampler("normal_texture", normals.texture)
            shader.uniform_float("radius", params["radius"])
            shader.uniform_float("angle_bias", math.radians(params["angle_bias_degrees"]))
            shader.uniform_int("directions", params["directions"])
            shader.uniform_int("steps", params["steps"])
            shader.uniform_int("falloff", parameters.FALLOFF_VALUES[params["falloff"]])
            shader.uniform_int("integration",
                               parameters.INTEGRATION_VALUES[params["integration"]])
            shader.uniform_float("thickness", params["thickness"])
            _draw_quad("ao")

    def _blur(self, depth_texture, normals, ao, blurred_rows, size, kernel_radius, params):
        """The cross-bilateral blur of target `ao` in place (rows into
        `blurred_rows`, then columns back), guided by `depth_texture` and
        target `normals`, on an image of `size`."""
        shader = shaders.get("blur")
        for source, target, step in ((ao, blurred_rows, (1, 0)), (blurred_rows, ao, (0, 1))):
            with target.framebuffer.bind():
                shader.bind()
                shader.uniform_sampler("depth_texture", depth_texture)
                shader.uniform_sampler("normal_texture", normals.texture)
                shader.uniform_sampler("ao_texture", source.texture)
                shader.uniform_int("image_size", size)
                shader.uniform_int("blur_step", step)
                shader.uniform_int("kernel_radius", kernel_radius)
                shader.uniform_float("sigma", parameters.blur_sigma(kernel_radius))
                shader.uniform_float("sharpness", params["blur_sharpness"])
                shader.uniform_float("background_depth", params["background_depth"])
                _draw_quad("blur")

    def _half_resolution(self, depth_texture, frame, params, depth_precision):
        """Halve the depth, search and blur on the half grid, upsample the AO
        into self._ao."""
        grid = projection.half_frame(frame)
        sizes = {"full_size": (frame.width, frame.height), "half_size": (grid.width, grid.height)}
        shader = shaders.get("halve")
        with self._half_depth.framebuffer.bind():
            shader.bind()
            shader.uniform_sampler("depth_texture", depth_texture)
            for name, value in sizes.items():
                shader.uniform_int(name, value)
            _draw_quad("halve")
        self._search(self._half_depth.texture, grid, params, depth_precision,
                     self._half_normals, self._half_ao)
        kernel_radius = parameters.grid_blur_radius(
            parameters.blur_kernel_radius(params["blur_size"]), half=True)
        if kernel_radius >= 1:
            self._blur(self._half_depth.texture, self._half_normals, self._half_ao,
                       self._half_blurred_rows, (grid.width, grid.height), kernel_radius, params)
        shader = shaders.get("upsample")
        with self._ao.framebuffer.bind():
            shader.bind()
            shader.uniform_sampler("depth_texture", depth_texture)
            shader.uniform_sampler("half_depth_texture", self._half_depth.texture)
            shader.uniform_sampler("half_ao_texture", self._half_ao.texture)
            for name, value in sizes.items():
                shader.uniform_int(name, value)
            shader.uniform_float("background_depth", params["background_depth"])
            _draw_quad("upsample")

    def ambient_occlusion(self, depth_texture, frame, params,
                          depth_precision=shader_sources.FLOAT_DEPTH_PRECISION,
                          buffer_precision=0.0):
        """Blurred AO (before strength) of a planar-depth texture, as an R32F
        texture the size of `frame`. `params` as native.resolve_params returns
        (half_resolution: the search on the half grid, as the library does);
        `depth_precision` bounds the depth's rounding relative to the depth
        (docs/algorithm.md, "Depth precision"), and `buffer_precision` that of
        the depth buffer it was linearised from (projection.depth_buffer_precision;
        0: none, a float depth given as it is)."""
        depth_precision = (depth_precision, buffer_precision)
        width, height = frame.width, frame.height
        half = bool(params.get("half_resolution"))
        self._ensure_size(width, height, half)
        if half:
            self._half_resolution(depth_texture, frame, params, depth_precision)
            return self._ao.texture
        self._search(depth_texture, frame, params, depth_precision, self._normals, self._ao)
        kernel_radius = parameters.blur_kernel_radius(params["blur_size"])
        if kernel_radius >= 1:
            self._blur(depth_texture, self._normals, self._ao, self._blurred_rows,
                       (width, height), kernel_radius, params)
        return self._ao.texture


def composite(ao_texture, strength, pixel_offset=(0, 0)):
    """Multiplies the scene under the bound overlay framebuffer by
    ao^strength, leaving the overlays' colours (see COMPOSITE_FRAGMENT)."""
    shader = shaders.get("composite")
    previous_blend = gpu.state.blend_get()
    try:
        shader.bind()
        shader.uniform_sampler("ao_texture", ao_texture)
        shader.uniform_int("pixel_offset", pixel_offset)
        shader.uniform_float("strength", strength)
        for alpha_step, blend in enumerate(("MULTIPLY", "ADDITIVE_PREMULT")):
            gpu.state.blend_set(blend)
            shader.uniform_int("alpha_step", alpha_step)
            _draw_quad("composite")
    finally:
        gpu.state.blend_set(previous_blend)
