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
columns (csrc/lib/blur.c). The normals are a texture of their own because
both the AO pass and the blur read them, as the library's grid->normal.
"""
from ..parameters import FALLOFF_VALUES, INTEGRATION_VALUES

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

# Shared by every pass after linearize: the background test.
COMMON = """
#define PI 3.14159265358979323846

/* Not finite, <= 0 or >= background_depth: written so that NaN is background. */
bool is_background(float z)
{
    return !(z > 0.0 && z < background_depth);
}
"""

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
"""

# Camera-space normals reconstructed from depth (docs/algorithm.md, "Normals",
# float depth: the preview's depth is float, see DEPTH_PRECISION), facing the
# viewer; (0, 0, 1) on background, as csrc/lib/normals.c writes there.
NORMAL_FRAGMENT = CAMERA + """
/* One axis of the reconstructed tangent: the neighbour difference with the
 * smaller depth change (the one before wins a tie, as in csrc/lib/normals.c);
 * false when neither neighbour is usable. */
bool tangent_along(ivec2 p, ivec2 axis, float z, vec3 position, out vec3 tangent)
{
    ivec2 after = p + axis;
    ivec2 before = p - axis;
    float z_after = all(lessThan(after, image_size)) ? depth_at(after) : 0.0;
    float z_before = all(greaterThanEqual(before, ivec2(0))) ? depth_at(before) : 0.0;
    bool has_after = !is_background(z_after);
    bool has_before = !is_background(z_before);
    if (has_before && (!has_after || abs(z_before - z) <= abs(z_after - z))) {
        tangent = position - position_at(before, z_before);
        return true;
    }
    if (has_after) {
        tangent = position_at(after, z_after) - position;
        return true;
    }
    return false;
}

vec3 reconstructed_normal(ivec2 p, float z, vec3 position, vec3 view)
{
    vec3 dx, dy;
    bool have_x = tangent_along(p, ivec2(1, 0), z, position, dx);
    bool have_y = tangent_along(p, ivec2(0, 1), z, position, dy);
    vec3 n;
    if (have_x && have_y) {
        n = cross(dx, dy);
    }
    else if (have_x || have_y) {
        /* One axis only (a strip one pixel wide or tall): V made
         * perpendicular to that tangent, so that every sample, which lies
         * along that axis, has elevation 0 on a plane. */
        vec3 t = have_x ? dx : dy;
        float t2 = dot(t, t);
        if (!(t2 > 0.0) || isinf(t2)) {
            return view;
        }
        n = view - t * (dot(view, t) / t2);
    }
    else {
        return view;
    }
    float len = length(n);
    if (!(len > 0.0) || isinf(len)) {
        return view;
    }
    n /= len;
    return dot(n, view) < 0.0 ? -n : n;
}

void main()
{
    ivec2 row_up = ivec2(gl_FragCoord.xy);
    ivec2 p = ivec2(row_up.x, image_size.y - 1 - row_up.y);
    float z = depth_at(p);
    if (is_background(z)) {
        frag_output = vec4(0.0, 0.0, 1.0, 0.0);
        return;
    }
    vec3 position = position_at(p, z);
    frag_output = vec4(reconstructed_normal(p, z, position, view_vector(position)), 0.0);
}
"""

AO_FRAGMENT = CAMERA + """
/* The interleaved 4x4 pattern of docs/algorithm.md. */
const int PATTERN[16] = int[16](0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);

float radius_in_pixels(float z)
{
    return perspective != 0 ? radius / (pixel_size.x * z) : radius / pixel_size.x;
}

/* R_block: the largest R_px >= 1 among the BLOCK_PIXELS pixels x0 + a + 4 k
 * of p's row (x0 a multiple of 4 BLOCK_PIXELS, a = p.x & 3), which march
 * with one step length in the library (csrc/lib/horizon.c, hbao_block_step).
 * p itself is one of them, with R_px >= 1. */
float block_radius(ivec2 p, float own_radius)
{
    if (perspective == 0) {
        return own_radius; /* the same for every pixel */
    }
    int first = (p.x / (4 * BLOCK_PIXELS)) * (4 * BLOCK_PIXELS) + (p.x & 3);
    int last = min(first + 4 * BLOCK_PIXELS, image_size.x);
    float largest = own_radius;
    for (int i = first; i < last; i += 4) {
        float z = depth_at(ivec2(i, p.y));
        if (is_background(z)) {
            continue;
        }
        float r = radius_in_pixels(z);
        if (r >= 1.0 && r > largest) {
            largest = r;
        }
    }
    return largest;
}

/* Cosine-weighted visibility of a half slice from V up to angle h. */
float slice_visibility(float h, float gamma)
{
    return (-cos(2.0 * h - gamma) + cos(gamma) + 2.0 * h * sin(gamma)) * 0.25;
}

float occlusion(ivec2 p)
{
    float z = depth_at(p);
    if (is_background(z)) {
        return 1.0;
    }
    float radius_px = radius_in_pixels(z);
    if (!(radius_px >= 1.0)) {
        return 1.0;
    }
    vec3 position = position_at(p, z);
    vec3 view = view_vector(position);
    vec3 normal = texelFetch(normal_texture, ivec2(p.x, image_size.y - 1 - p.y), 0).xyz;
    float n_dot_v = dot(normal, view);
    /* docs/algorithm.md, "Depth precision": what rounding the depths can
     * raise a sample above the tangent plane. */
    float height_tolerance = depth_precision
                           * abs(perspective != 0 ? dot(normal, position) : normal.z * position.z);

    float inv_ycor = pixel_size.x / pixel_size.y;
    float rotation = (float(PATTERN[(p.x & 3) + 4 * (p.y & 3)]) + 0.5) / 16.0;
    float jitter = (float(PATTERN[(p.y & 3) + 4 * (p.x & 3)]) + 0.5) / 16.0;
    float sin_bias = sin(angle_bias);
    float step_px = (block_radius(p, radius_px) - 1.0) / float(steps);

    float hbao_sum = 0.0;
    float cosine_open = 0.0;
    float cosine_visible = 0.0;
    for (int d = 0; d < directions; d++) {
        float theta = 2.0 * PI * (float(d) + rotation) / float(directions);
        float cos_theta = cos(theta);
        float sin_theta = sin(theta);
        vec3 dir3 = vec3(cos_theta, sin_theta, 0.0);
        vec3 e = normalize(dir3 - view * dot(dir3, view));
        vec3 m = cross(view, e);
        vec3 np = normal - m * dot(normal, m);
        float np_length = length(np);
        /* A normal (almost) perpendicular to the slice: no gamma, and no
         * weight in the cosine sum (csrc/lib/horizon.c, slice_setup). */
        bool usable = np_length > NORMAL_IN_SLICE_EPSILON;
        if (!usable && integration == INTEGRATION_COSINE) {
            continue;
        }
        float cos_gamma = usable ? dot(np, view) / np_length : 1.0;
        float gamma = usable ? atan(dot(np, e), dot(np, view)) : 0.0;
        bool check_past_normal = usable && gamma > 0.0;

        float sin_max = sin_bias;
        float h_open = gamma + 0.5 * PI;
        float h_max = max(0.0, h_open - angle_bias);
        bool past_normal = false;
        float occ = 0.0;
        for (int s = 0; s < steps; s++) {
            /* The block's offset, the same for its 16 pixels. */
            float t = 1.0 + (float(s) + jitter) * step_px;
            ivec2 q = p + ivec2(floor(0.5 + cos_theta * t),
                                floor(0.5 - sin_theta * t * inv_ycor));
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, image_size))) {
                break;
            }
            if (q == p) {
                continue;
            }
            float zs = depth_at(q);
            if (is_background(zs)) {
                continue;
            }
            vec3 delta = position_at(q, zs) - position;
            float dist2 = dot(delta, delta);
            /* Also what keeps a pixel to its own radius within the block's
             * longer steps. */
            if (!(dist2 < radius * radius) || !(dist2 > 0.0)) {
                continue;
            }
            float inv_dist = 1.0 / sqrt(dist2);
            float weight = falloff == FALLOFF_QUADRATIC ? 1.0 - dist2 / (radius * radius) : 1.0;
            float cos_v = dot(delta, view) * inv_dist;
            float sin_s = (dot(delta, normal) - height_tolerance) * inv_dist;
            /* Past the normal: within gamma of V and rising at least as
             * steeply as V (docs/algorithm.md, "The slice of a direction"). */
            bool beyond = check_past_normal && cos_v > cos_gamma && sin_s > n_dot_v;
            if (integration == INTEGRATION_HBAO) {
                if (beyond) {
                    /* Beyond the normal inside the slice: half occluded. */
                    occ = max(occ, 0.5 * (1.0 - sin_bias));
                    break;
                }
                if (sin_s > sin_max) {
                    occ += weight * (sin_s - sin_max);
                    sin_max = sin_s;
                }
            }
            else {
                /* The sample's angle from V through its elevation above the
                 * tangent plane; past the normal through its angle to V
                 * (docs/algorithm.md, "Integration COSINE"). */
                float h;
                if (beyond) {
                    h = acos(min(cos_v, 1.0));
                    past_normal = true;
                }
                else {
                    if (past_normal) {
                        continue;
                    }
                    float elevation = sin_s / np_length;
                    h = max(0.0, gamma + acos(clamp(elevation, -1.0, 1.0)));
                }
                if (h < h_max) {
                    occ += weight * (slice_visibility(h_max, gamma) - slice_visibility(h, gamma));
                    h_max = h;
                }
            }
        }
        if (integration == INTEGRATION_HBAO) {
            hbao_sum += occ;
        }
        else {
            float open_visibility = slice_visibility(h_open, gamma);
            cosine_open += np_length * open_visibility;
            cosine_visible += np_length * (open_visibility - occ);
        }
    }
    float ao;
    if (integration == INTEGRATION_HBAO) {
        ao = 1.0 - hbao_sum / float(directions) / (1.0 - sin_bias);
    }
    else {
        ao = cosine_open > 1e-12 ? cosine_visible / cosine_open : 1.0;
    }
    return clamp(ao, 0.0, 1.0);
}

void main()
{
    ivec2 row_up = ivec2(gl_FragCoord.xy);
    frag_output = vec4(occlusion(ivec2(row_up.x, image_size.y - 1 - row_up.y)), 0.0, 0.0, 1.0);
}
"""

# One separable pass of the cross-bilateral blur (docs/algorithm.md, "After
# sampling", 2); `blur_step` is (1, 0) for rows, (0, 1) for columns;
# `kernel_radius` and `sigma` come from parameters.blur_kernel_radius and
# blur_sigma, the library's rule. The centre weighs 1 and the taps are summed
# after it, nearest first on the negative side, as csrc/lib/blur.c does; down
# a column the order is mirrored (textures are bottom-up), which only changes
# rounding. The library evaluates exp(-x) with its own polynomial
# (hbao_exp_negative, 3e-5 relative error); the GPU's exp differs from it by
# that much in a tap's weight, far below tests/test_viewport.py's tolerances.
BLUR_FRAGMENT = COMMON + """
/* FLT_MAX: sharpness / z overflows for tiny depths; capped, a tap at the
 * same depth weighs 1 instead of 0 * inf (csrc/lib/blur.c). */
#define LARGEST_FLOAT 3.402823466e38

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    float zc = texelFetch(depth_texture, p, 0).r;
    if (is_background(zc)) {
        frag_output = vec4(1.0, 0.0, 0.0, 1.0);
        return;
    }
    float factor = min(sharpness / zc, LARGEST_FLOAT);
    vec3 nc = texelFetch(normal_texture, p, 0).xyz;
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
        float bend = max(0.0, 1.0 - dot(texelFetch(normal_texture, q, 0).xyz, nc));
        float spatial = exp(-float(x * x) / (2.0 * sigma * sigma));
        float w = spatial * exp(-(difference * difference + NORMAL_SHARPNESS * bend));
        sum += w * texelFetch(ao_texture, q, 0).r;
        weight_sum += w;
    }
    frag_output = vec4(sum / weight_sum, 0.0, 0.0, 1.0);
}
"""

# Strength, then "multiply over the viewport": premultiplied black with alpha
# 1 - ao leaves dst * ao. In POST_VIEW Blender draws into its overlay buffer,
# which is composited premultiplied over the scene (out = overlay + scene *
# (1 - alpha)); a MULTIPLY blend would only darken the (transparent) overlay
# buffer, this darkens the scene and the overlays below it alike.
COMPOSITE_FRAGMENT = """
void main()
{
    float ao = texelFetch(ao_texture, ivec2(gl_FragCoord.xy) - pixel_offset, 0).r;
    /* pow(0, 0) is undefined in GLSL; strength 0 means no AO. */
    ao = strength > 0.0 ? pow(max(ao, 0.0), strength) : 1.0;
    ao = clamp(ao, 0.0, 1.0);
    frag_output = vec4(0.0, 0.0, 0.0, 1.0 - ao);
}
"""

# The depth's rounding relative to the depth (docs/algorithm.md, "Depth
# precision"): the library's for float depth, 2^-23 (csrc/lib/internal_hbao.h,
# HBAO_FLOAT_DEPTH_PRECISION). The preview's depth is float: linearised in
# float from the viewport's depth buffer, never half floats, so the preview
# neither tests for half floats nor fits half-float normals.
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
}

BLUR_DEFINES = {
    # csrc/lib/internal_finish.h, HBAO_BLUR_NORMAL_SHARPNESS
    # (tests/test_viewport.py compares the two).
    "NORMAL_SHARPNESS": 16.0,
}
