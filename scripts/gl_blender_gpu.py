# SPDX-License-Identifier: GPL-2.0-or-later
"""The part of Blender's `gpu` and `gpu_extras.batch` modules that the
viewport preview's passes use (addon/hbao/viewport/pipeline.py and
shaders.py), on an OpenGL context of moderngl's, so that those passes run
unchanged where no Blender can: on a GPU machine without one
(scripts/bench_viewport_gl.py, and its test in tests/test_viewport.py). What
the preview does in Blender is tested in Blender (tests/test_viewport.py).

What it does as Blender's OpenGL backend does: GPUShaderCreateInfo's push
constants become uniforms, its samplers sampler2D uniforms on the texture
units of their slots, its vertex input and fragment outputs `in`/`out`
declarations ahead of the sources; setting a uniform the compiled program
lacks raises ValueError, as Blender's uniform_float and uniform_int do;
blend modes as GPU_blend's; the formats named as GPUTexture names them.

    install(context)  # before importing hbao.viewport
    with timing_draws() as draws:  # [(shader, GPU nanoseconds)] of each draw
        ...
"""
import contextlib
import sys
import types

import moderngl
import numpy as np

_GLSL_TYPES = {"INT": "int", "IVEC2": "ivec2", "FLOAT": "float", "VEC2": "vec2",
               "VEC3": "vec3", "VEC4": "vec4"}
# GPUTexture's formats: (components, moderngl dtype, OpenGL internal format
# or None for moderngl's own). SRGB8_A8 is the 3D view's overlay buffer,
# which the preview's composite draws into.
_GL_SRGB8_ALPHA8 = 0x8C43
_FORMATS = {"R32F": (1, "f4", None), "RG32F": (2, "f4", None), "RGBA32F": (4, "f4", None),
            "RGBA8": (4, "f1", None), "SRGB8_A8": (4, "f1", _GL_SRGB8_ALPHA8)}
_CONTEXT = None
_timed_draws = None


class GPUShaderCreateInfo:
    def __init__(self):
        self.uniforms, self.samplers, self.inputs, self.outputs = [], [], [], []
        self.vertex = self.fragment = ""

    def push_constant(self, glsl_type, name):
        self.uniforms.append((_GLSL_TYPES[glsl_type], name))

    def sampler(self, slot, sampler_type, name):
        if sampler_type != "FLOAT_2D":
            raise ValueError(f"sampler type {sampler_type} is not stood in for")
        self.samplers.append((slot, name))

    def vertex_in(self, slot, glsl_type, name):
        self.inputs.append((slot, _GLSL_TYPES[glsl_type], name))

    def fragment_out(self, slot, glsl_type, name):
        self.outputs.append((slot, _GLSL_TYPES[glsl_type], name))

    def vertex_source(self, source):
        self.vertex = source

    def fragment_source(self, source):
        self.fragment = source

    def sources(self):
        """(vertex, fragment) GLSL with the interface declared ahead."""
        header = "#version 430 core\n" + "".join(
            f"uniform {glsl_type} {name};\n" for glsl_type, name in self.uniforms) + "".join(
            f"uniform sampler2D {name};\n" for _, name in self.samplers)
        vertex = header + "".join(
            f"layout(location = {slot}) in {glsl_type} {name};\n"
            for slot, glsl_type, name in self.inputs) + self.vertex
        fragment = header + "".join(
            f"layout(location = {slot}) out {glsl_type} {name};\n"
            for slot, glsl_type, name in self.outputs) + self.fragment
        return vertex, fragment


class GPUShader:
    def __init__(self, info):
        vertex, fragment = info.sources()
        self.program = _CONTEXT.program(vertex_shader=vertex, fragment_shader=fragment)
        self.units = {name: slot for slot, name in info.samplers}

    def bind(self):
        pass  # moderngl binds the program when it draws

    def _set(self, name, value):
        uniform = self.program.get(name, None)
        if uniform is None:  # Blender: "uniform not found" (also where the compiler dropped it)
            raise ValueError(f"GPUShader.uniform: uniform {name} not found")
        uniform.value = value

    def uniform_sampler(self, name, texture):
        texture.texture.use(location=self.units[name])
        self._set(name, self.units[name])

    def uniform_float(self, name, value):
        self._set(name, tuple(value) if isinstance(value, (list, tuple)) else float(value))

    def uniform_int(self, name, value):
        self._set(name, tuple(value) if isinstance(value, (list, tuple)) else int(value))


class GPUTexture:
    def __init__(self, size, format="RGBA8", data=None):
        components, dtype, internal_format = _FORMATS[format]
        self.width, self.height = size
        self.texture = _CONTEXT.texture(size, components, data=data, dtype=dtype,
                                        internal_format=internal_format)
        self.texture.filter = (moderngl.NEAREST, moderngl.NEAREST)


class GPUFrameBuffer:
    def __init__(self, color_slots):
        self.framebuffer = _CONTEXT.framebuffer(color_attachments=[color_slots.texture])

    def bind(self):
        return _Binding(self.framebuffer)

    def clear(self, color):
        self.framebuffer.clear(*color)


class _Binding:
    def __init__(self, framebuffer):
        self.framebuffer = framebuffer
        self.previous = None

    def __enter__(self):
        self.previous = _CONTEXT.fbo
        self.framebuffer.use()
        return self

    def __exit__(self, *exc):
        if self.previous is not None:  # a standalone context has no framebuffer of its own
            self.previous.use()
        return False


class _Batch:
    def __init__(self, shader, primitive, attributes):
        if primitive != "TRIS":
            raise ValueError(f"primitive {primitive} is not stood in for")
        (name, points), = attributes.items()
        buffer = _CONTEXT.buffer(np.asarray(points, dtype="f4").tobytes())
        self.array = _CONTEXT.vertex_array(shader.program, [(buffer, "2f", name)])

    def draw(self, shader):
        if _timed_draws is None:
            self.array.render(moderngl.TRIANGLES)
            return
        query = _CONTEXT.query(time=True)
        with query:
            self.array.render(moderngl.TRIANGLES)
        _timed_draws.append((shader, query))


@contextlib.contextmanager
def timing_draws():
    """Times each draw inside the block with its own timer query: yields a
    list that receives (shader, GPU nanoseconds) of each draw once the block
    ends. Timer queries cannot nest, so neither can these blocks, and no
    other timer query may be open around one."""
    global _timed_draws
    if _timed_draws is not None:
        raise RuntimeError("timing_draws blocks cannot nest")
    _timed_draws = queries = []
    draws = []
    try:
        yield draws
    finally:
        _timed_draws = None
    _CONTEXT.finish()
    draws.extend((shader, query.elapsed) for shader, query in queries)


def install(context):
    """Makes `gpu` and `gpu_extras.batch` importable, drawing on moderngl
    `context`. A standalone context has no framebuffer of its own: the
    caller binds the one that stands for the view's."""
    global _CONTEXT
    _CONTEXT = context
    gpu = types.ModuleType("gpu")
    gpu.types = types.SimpleNamespace(
        GPUShaderCreateInfo=GPUShaderCreateInfo, GPUTexture=GPUTexture,
        GPUFrameBuffer=GPUFrameBuffer)
    gpu.shader = types.SimpleNamespace(create_from_info=GPUShader)
    gpu.state = types.SimpleNamespace(blend_get=lambda: _blend[0], blend_set=_blend_set)
    extras = types.ModuleType("gpu_extras")
    batch = types.ModuleType("gpu_extras.batch")
    batch.batch_for_shader = _Batch
    extras.batch = batch
    sys.modules.update({"gpu": gpu, "gpu_extras": extras, "gpu_extras.batch": batch})


# GPU_blend's factors, (source, destination), for the modes the preview sets.
_BLENDS = {"MULTIPLY": (moderngl.DST_COLOR, moderngl.ZERO),
           "ADDITIVE_PREMULT": (moderngl.ONE, moderngl.ONE)}
_blend = ["NONE"]


def _blend_set(mode):
    _blend[0] = mode
    if mode == "NONE":
        _CONTEXT.disable(moderngl.BLEND)
    else:
        _CONTEXT.enable(moderngl.BLEND)
        _CONTEXT.blend_func = _BLENDS[mode]
