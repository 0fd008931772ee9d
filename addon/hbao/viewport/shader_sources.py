# SPDX-License-Identifier: GPL-2.0-or-later
"""GLSL of the viewport preview: docs/algorithm.md, pass by pass. Plain strings,
no bpy, so that they can be read and diffed against csrc/lib/ without Blender.

Every pass draws one full-screen quad into a target of the image's size and
reads its inputs with texelFetch (no filtering, no normalised coordinates).
Textures are bottom-up (OpenGL rows); the algorithm's pixel (i, j) has j
counted from the top, so j = H - 1 - row wherever the pattern or the
camera model needs it.

The passes: linearize (planar depth) -> normals (camera space, as
csrc/lib/normals.c) -> AO (csrc/lib/horizon.c) -> blur along rows, then
columns (csrc/lib/blur.c) -> composite. The normals are a texture of their
own because both the AO pass and the blur read them, as both read the
library's grid->normal. The normal and AO passes' GLSL is in
normal_sources.py and horizon_sources.py, the camera model they share in
camera_sources.py. At half resolution (csrc/lib/compute.c): linearize ->
halve (every other pixel of every other row) -> normals and AO on the half
grid -> blur on the half grid (half the taps, csrc/lib/blur.c) -> upsample
(csrc/lib/upsample.c) -> composite.
"""
from ..parameters import FALLOFF_VALUES, INTEGRATION_VALUES
from . import horizon_sources, normal_sources, projection
from .camera_sources import CAMERA, COMMON

# A full-screen quad given in normalised device coordinates: no matrices, so it
# draws the same in POST_VIEW (3D matrices bound) and into our own framebuffers.
FULL_SCREEN_VERTEX = """
void main()
{
    gl_Position = vec4(position, 0.0, 1.0);
}
"""

# Planar depth from the viewport's depth buffer (d in [0, 1]). The cleared
# buffer (d = 1) is background and becomes 0, which is_background() rejects.
LINEARIZE_FRAGMENT = """
void main()
{
    float d = texelFetch(buffer_depth, ivec2(gl_FragCoord.xy), 0).r;
    float ndc = 2.0 * d - 1.0;
    float depth = (depth_coefficients.x * ndc + depth_coefficients.y)
                / (depth_coefficients.z * ndc + depth_coefficients.w);
    frag_output = vec4(d >= 1.0 ? 0.0 : depth, 0.0, 0.0, 1.0);
}
"""

# The normal and AO passes (normal_sources.py, horizon_sources.py) on the
# camera model (camera_sources.py).
NORMAL_FRAGMENT = CAMERA + normal_sources.NORMALS
AO_FRAGMENT = CAMERA + horizon_sources.HORIZON_SEARCH

# The range weight F of the blur and the upsample (csrc/lib/internal_finish.h,
# hbao_blur_power): max(0, base)^16 by the same four squarings; each caller
# forms the base as the library does.
FALLOFF = """
/* FLT_MAX: a factor sharpness / z overflows for tiny depths, and a sample at
 * the same depth would weigh 0 * inf = NaN; capped, it weighs what any
 * sample at the same depth does (csrc/lib/blur.c, upsample.c). */
#define LARGEST_FLOAT 3.402823466e38

/* hbao_blur_power: max(0, base)^16 */
float blur_power(float base)
{
    float power = max(base, 0.0);
    power *= power;
    power *= power;
    power *= power;
    return power * power;
}
"""

# One separable pass of the cross-bilateral blur (docs/algorithm.md, "After
# sampling", 2); `blur_step` is (1, 0) for rows, (0, 1) for columns;
# `kernel_radius` and `sigma` come from parameters.blur_kernel_radius and
# blur_sigma, the library's rule. The centre weighs 1 and the taps are summed
# after it, from -r up to r, as csrc/lib/blur.c does; down
# a column the order is mirrored (textures are bottom-up), which only changes
# rounding. The weight is the library's F of the same base, with the centre's
# factor and normal scaled once per pixel.
BLUR_FRAGMENT = COMMON + FALLOFF + """
/* HBAO_BLUR_NORMAL_WEIGHT: NORMAL_SHARPNESS / FALLOFF_REACH */
#define NORMAL_WEIGHT (NORMAL_SHARPNESS / FALLOFF_REACH)

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    float zc = texelFetch(depth_texture, p, 0).r;
    if (is_background(zc)) {
        frag_output = vec4(1.0, 0.0, 0.0, 1.0);
        return;
    }
    float factor = min(sharpness / zc, LARGEST_FLOAT) * DEPTH_WEIGHT;
    vec3 nc = texelFetch(normal_texture, p, 0).xyz * NORMAL_WEIGHT;
    float sum = texelFetch(ao_texture, p, 0).r;
    float weight_sum = 1.0;
    for (int x = -kernel_radius; x <= kernel_radius; x++) {
        ivec2 q = p + x * blur_step;
        if (x == 0 || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, image_size))) {
            continue;
        }
        float zq = texelFetch(depth_texture, q, 0).r;
        if (is_background(zq)) {
            continue;
        }
        float difference = (zq - zc) * factor;
        float facing = min(dot(texelFetch(normal_texture, q, 0).xyz, nc), NORMAL_WEIGHT);
        float base = (1.0 - NORMAL_WEIGHT + facing) - difference * difference;
        float spatial = exp(-float(x * x) / (2.0 * sigma * sigma));
        float w = spatial * blur_power(base);
        sum += w * texelFetch(ao_texture, q, 0).r;
        weight_sum += w;
    }
    frag_output = vec4(sum / weight_sum, 0.0, 0.0, 1.0);
}
"""

# The half-resolution grid (csrc/lib/compute.c): its pixel (i, j), j from
# the top, is full-resolution pixel (2 i, 2 j); rows are bottom-up here.
HALVE_FRAGMENT = """
void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    int j = half_size.y - 1 - p.y;
    ivec2 source = ivec2(2 * p.x, full_size.y - 1 - 2 * j);
    frag_output = vec4(texelFetch(depth_texture, source, 0).r, 0.0, 0.0, 1.0);
}
"""

# Joint bilateral upsampling of the half grid's AO to full resolution,
# csrc/lib/upsample.c operation for operation: a pixel's candidates are the
# half-grid pixels around it with bilinear weights (even columns and rows sit
# on the grid), each weighed by its depth's similarity, F of the same base.
# The half grid's AO arrives already blurred.
UPSAMPLE_FRAGMENT = COMMON + FALLOFF + """
/* HBAO_UPSAMPLE_DEPTH_WEIGHT: UPSAMPLE_SHARPNESS / sqrt(FALLOFF_REACH) */
#define UPSAMPLE_DEPTH_WEIGHT (UPSAMPLE_SHARPNESS * DEPTH_WEIGHT)

float sum, weight_sum, nearest_ao, nearest_gap;

void add_candidate(float bilinear, int k, int r, float z, float factor)
{
    ivec2 texel = ivec2(k, half_size.y - 1 - r);
    float zs = texelFetch(half_depth_texture, texel, 0).r;
    float ao = texelFetch(half_ao_texture, texel, 0).r;
    bool usable = bilinear > 0.0 && !is_background(zs);
    float gap = abs(zs - z);
    float scaled = gap * factor;
    float weight = usable ? bilinear * blur_power(1.0 - scaled * scaled) : 0.0;
    sum += weight * ao;
    weight_sum += weight;
    if (usable && gap < nearest_gap) {
        nearest_ao = ao;
        nearest_gap = gap;
    }
}

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    int i = p.x, j = full_size.y - 1 - p.y;
    float z = texelFetch(depth_texture, p, 0).r;
    int r0 = j / 2, k = i / 2;
    bool two_rows = (j & 1) != 0 && r0 + 1 < half_size.y;
    int r1 = two_rows ? r0 + 1 : r0;
    float top_weight = two_rows ? 0.5 : 1.0, bottom_weight = 1.0 - top_weight;
    sum = 0.0;
    weight_sum = 0.0;
    nearest_ao = 1.0;
    nearest_gap = LARGEST_FLOAT; /* the library's INFINITY: no finite gap is larger */
    /* upsample.c's upsample_factor, once for the pixel's candidates */
    float factor = min(UPSAMPLE_DEPTH_WEIGHT / z, LARGEST_FLOAT);
    if ((i & 1) == 0) {
        add_candidate(top_weight, k, r0, z, factor);
        if (two_rows) {
            add_candidate(bottom_weight, k, r1, z, factor);
        }
    } else {
        /* between half columns k and k + 1, if there is one */
        int odd_inner = min(full_size.x / 2, half_size.x - 1);
        int right = k < odd_inner ? k + 1 : k;
        float right_weight = k < odd_inner ? 0.5 : 0.0, left_weight = 1.0 - right_weight;
        add_candidate(left_weight * top_weight, k, r0, z, factor);
        add_candidate(right_weight * top_weight, right, r0, z, factor);
        if (two_rows) {
            add_candidate(left_weight * bottom_weight, k, r1, z, factor);
            add_candidate(right_weight * bottom_weight, right, r1, z, factor);
        }
    }
    float blended = weight_sum > 1e-6 ? sum / weight_sum : nearest_ao;
    frag_output = vec4(is_background(z) ? 1.0 : blended, 0.0, 0.0, 1.0);
}
"""

# Strength, then "multiply the scene under the overlays". In POST_VIEW Blender
# draws into its overlay buffer, which it composites premultiplied over the
# scene: out = overlay + scene * (1 - alpha). The AO belongs to the scene
# only, so the overlay's colour stays and its alpha becomes
# alpha + (1 - alpha) * (1 - ao), in two draws (pipeline.composite): a
# MULTIPLY blend with (1, 1, 1, ao) leaves the colour and makes the alpha
# alpha * ao, then an ADDITIVE_PREMULT blend with (0, 0, 0, 1 - ao) adds
# 1 - ao to it. Then out = overlay + scene * ao * (1 - alpha): the scene
# darkens as before, and a selection outline or the grid over a crease
# keeps its colour (one draw of premultiplied black with alpha 1 - ao
# darkened them too).
COMPOSITE_FRAGMENT = """
void main()
{
    float ao = texelFetch(ao_texture, ivec2(gl_FragCoord.xy) - pixel_offset, 0).r;
    /* pow(0, 0) is undefined in GLSL; strength 0 means no AO. */
    ao = strength > 0.0 ? pow(max(ao, 0.0), strength) : 1.0;
    ao = clamp(ao, 0.0, 1.0);
    frag_output = alpha_step == 0 ? vec4(1.0, 1.0, 1.0, ao) : vec4(0.0, 0.0, 0.0, 1.0 - ao);
}
"""

# The depth's rounding relative to the depth (docs/algorithm.md, "Depth
# precision"): the library's for float depth, 2^-23 (csrc/lib/internal_hbao.h,
# HBAO_FLOAT_DEPTH_PRECISION). The preview's depth is float, linearised from
# the viewport's depth buffer, whose own rounding the preview adds
# (projection.depth_buffer_precision); it never tests for half floats, but
# fits the normals as for them where a buffer step is coarse
# (NORMAL_DEFINES: BUFFER_FIT_SLOPE).
FLOAT_DEPTH_PRECISION = 1.1920929e-7

# Falloff and integration enum values as the shader sees them (the header's,
# through parameters.py).
AO_DEFINES = {
    **{f"FALLOFF_{name}": value for name, value in FALLOFF_VALUES.items()},
    **{f"INTEGRATION_{name}": value for name, value in INTEGRATION_VALUES.items()},
    # csrc/lib/horizon.c: a projected normal shorter than this has no slice
    # angle (tests/test_parameter_contract.py compares the two).
    "NORMAL_IN_SLICE_EPSILON": 1e-6,
    # csrc/lib/internal_hbao.h, HBAO_BLOCK_PIXELS: the pixels of a block,
    # which share one step length (tests/test_viewport.py compares the two).
    "BLOCK_PIXELS": 16,
    # csrc/lib/internal_hbao.h, HBAO_BEYOND_BAND_DIVISOR: steps go on past the
    # image's edges for its longer side over this many pixels.
    "BEYOND_BAND_DIVISOR": 16,
    # csrc/lib/internal_hbao.h, HBAO_BLOCK_DEPTH_RATIO: how much farther than
    # its class's nearest pixel a pixel of the class lies at most.
    "BLOCK_DEPTH_RATIO": 4.0,
    # The depth buffer's steps that the tangent test allows for
    # (projection.DEPTH_BUFFER_MARGIN).
    "DEPTH_BUFFER_MARGIN": projection.DEPTH_BUFFER_MARGIN,
}

# The range weight's (FALLOFF): csrc/lib/internal_finish.h,
# HBAO_BLUR_FALLOFF_REACH and HBAO_BLUR_DEPTH_WEIGHT (tests/test_viewport.py
# compares them).
FALLOFF_DEFINES = {
    "FALLOFF_REACH": 16.0,
    "DEPTH_WEIGHT": 0.25,
}

UPSAMPLE_DEFINES = {
    # csrc/lib/internal_hbao.h, HBAO_UPSAMPLE_SHARPNESS
    # (tests/test_viewport.py compares the two).
    "UPSAMPLE_SHARPNESS": 16.0,
    **FALLOFF_DEFINES,
}

NORMAL_DEFINES = {
    # csrc/lib/internal_hbao.h, HBAO_HALF_DEPTH_PRECISION: from this rounding
    # on, a tangent is fitted along a run of pixels (csrc/lib/normals.c,
    # fit_tangent), whose reach is HALF_DEPTH_FIT_REACH there
    # (tests/test_viewport.py compares them).
    "HALF_DEPTH_PRECISION": 9.765625e-4,
    "HALF_DEPTH_FIT_REACH": 8,
    # The preview's own: a depth buffer step that tilts a one-pixel tangent
    # by more than this (in radians, about 9 degrees) fits the tangents too.
    "BUFFER_FIT_SLOPE": 0.15,
}

BLUR_DEFINES = {
    # csrc/lib/internal_finish.h, HBAO_BLUR_NORMAL_SHARPNESS
    # (tests/test_viewport.py compares the two).
    "NORMAL_SHARPNESS": 8.0,
    **FALLOFF_DEFINES,
}
