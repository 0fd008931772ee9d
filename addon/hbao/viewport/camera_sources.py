# SPDX-License-Identifier: GPL-2.0-or-later
"""GLSL of the camera model that the preview's passes share (docs/algorithm.md):
the background test, a pixel's depth and camera-space position, the view
vector, and how much a depth may be rounded. Plain strings, no bpy."""

# csrc/include/hbao.h, HBAO_HALF_FLOAT_SKY: background at any background
# depth, EEVEE 3.x's half-float sky (tests/test_viewport.py compares them).
HALF_FLOAT_SKY = 65504.0

# Shared by every pass after linearize: the background test, libhbao's
# (hbao_depth_value).
COMMON = """
#define PI 3.14159265358979323846
#define HALF_FLOAT_SKY %r

/* Not finite, <= 0, >= background_depth or exactly HALF_FLOAT_SKY: written
 * so that NaN is background. */
bool is_background(float z)
{
    return !(z > 0.0 && z < background_depth && z != HALF_FLOAT_SKY);
}
""" % HALF_FLOAT_SKY

# Shared by the normal and AO passes: depth and position of a pixel (i, j),
# j from the top, through the camera model of docs/algorithm.md.
CAMERA = COMMON + """
float depth_at(ivec2 p)
{
    return texelFetch(depth_texture, ivec2(p.x, image_size.y - 1 - p.y), 0).r;
}

vec3 position_at(ivec2 p, float z)
{
    float x = origin.x + (float(p.x) + 0.5) * pixel_size.x;
    float y = origin.y + (float(image_size.y - 1 - p.y) + 0.5) * pixel_size.y;
    return perspective != 0 ? vec3(x * z, y * z, -z) : vec3(x, y, -z);
}

vec3 view_vector(vec3 position)
{
    return perspective != 0 ? normalize(-position) : vec3(0.0, 0.0, 1.0);
}

/* docs/algorithm.md, "Depth precision": how much the viewport's depth
 * buffer, which a depth z was linearised from, rounds it, relative to z: one
 * step of the buffer (depth_precision.y, projection.depth_buffer_precision;
 * 0 for a float depth given as it is). */
float buffer_rounding(float z)
{
    return depth_precision.y * (perspective != 0 ? z : 1.0 / z);
}

/* The rounding of a depth z relative to z: its own format's
 * (depth_precision.x) and one step of the buffer's. */
float depth_rounding(float z)
{
    return depth_precision.x + buffer_rounding(z);
}
"""
