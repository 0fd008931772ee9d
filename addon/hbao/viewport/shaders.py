# SPDX-License-Identifier: GPL-2.0-or-later
"""The preview's shaders, built with GPUShaderCreateInfo (Blender 3.4 and later;
the only way from 5.0). Compiled once, on first use, and dropped on unregister."""
import gpu

from . import shader_sources

_shaders = {}


def _create_info(fragment_source, push_constants, samplers, defines=None,
                 outputs=("frag_output",)):
    info = gpu.types.GPUShaderCreateInfo()
    for glsl_type, name in push_constants:
        info.push_constant(glsl_type, name)
    for slot, name in enumerate(samplers):
        info.sampler(slot, "FLOAT_2D", name)
    info.vertex_in(0, "VEC2", "position")
    for slot, name in enumerate(outputs):
        info.fragment_out(slot, "VEC4", name)
    info.vertex_source(shader_sources.FULL_SCREEN_VERTEX)
    # Plain #define lines rather than GPUShaderCreateInfo.define, which 3.4 lacks.
    define_lines = "".join(f"#define {name} {value}\n" for name, value in (defines or {}).items())
    info.fragment_source(define_lines + fragment_source)
    return info


# What the passes that place pixels in camera space (shader_sources.CAMERA) read.
_CAMERA_CONSTANTS = [("IVEC2", "image_size"), ("VEC2", "pixel_size"), ("VEC2", "origin"),
                     ("INT", "perspective"), ("FLOAT", "background_depth"),
                     ("VEC2", "depth_precision")]

_DEFINITIONS = {
    "linearize": lambda: _create_info(
        shader_sources.LINEARIZE_FRAGMENT,
        [("VEC4", "depth_coefficients")],
        ["buffer_depth"]),
    "normals": lambda: _create_info(
        shader_sources.NORMAL_FRAGMENT,
        _CAMERA_CONSTANTS,
        ["depth_texture"],
        shader_sources.NORMAL_DEFINES),
    "ao": lambda: _create_info(
        shader_sources.AO_FRAGMENT,
        _CAMERA_CONSTANTS + [
            ("FLOAT", "radius"), ("FLOAT", "angle_bias"), ("INT", "directions"),
            ("INT", "steps"), ("INT", "falloff"), ("INT", "integration"),
            ("FLOAT", "thickness")],
        ["depth_texture", "normal_texture"],
        shader_sources.AO_DEFINES),
    "halve": lambda: _create_info(
        shader_sources.HALVE_FRAGMENT,
        [("IVEC2", "full_size"), ("IVEC2", "half_size")],
        ["depth_texture"]),
    "upsample": lambda: _create_info(
        shader_sources.UPSAMPLE_FRAGMENT,
        [("IVEC2", "full_size"), ("IVEC2", "half_size"), ("FLOAT", "background_depth")],
        ["depth_texture", "half_depth_texture", "half_ao_texture"],
        shader_sources.UPSAMPLE_DEFINES),
    "blur": lambda: _create_info(
        shader_sources.BLUR_FRAGMENT,
        [("IVEC2", "image_size"), ("IVEC2", "blur_step"), ("INT", "kernel_radius"),
         ("FLOAT", "sigma"), ("FLOAT", "sharpness"), ("FLOAT", "background_depth")],
        ["depth_texture", "normal_texture", "ao_texture"],
        shader_sources.BLUR_DEFINES),
    "composite": lambda: _create_info(
        shader_sources.COMPOSITE_FRAGMENT,
        [("IVEC2", "pixel_offset"), ("FLOAT", "strength"), ("INT", "alpha_step")],
        ["ao_texture"]),
}


def get(name):
    """The compiled shader `name` (linearize, halve, normals, ao, upsample, blur,
    composite)."""
    shader = _shaders.get(name)
    if shader is None:
        shader = gpu.shader.create_from_info(_DEFINITIONS[name]())
        _shaders[name] = shader
    return shader


def release():
    _shaders.clear()
