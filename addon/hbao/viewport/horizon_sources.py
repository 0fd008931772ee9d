# SPDX-License-Identifier: GPL-2.0-or-later
"""GLSL of the preview's AO pass: csrc/lib/horizon.c, following
docs/algorithm.md. A fragment body: shader_sources.py puts the shared camera
model (camera_sources.py: depth_at, position_at, view_vector, is_background,
the depth's rounding) in front of it and holds the constants it is compiled
with (AO_DEFINES). Plain strings, no bpy."""

# The horizon search and its integration (csrc/lib/horizon.c, scalar
# reference), one fragment per pixel, with the step length of the pixel's
# block: the library's SIMD kernels march a block's 16 pixels together, and
# its scalar reference gives the same offsets, so the preview must too.
HORIZON_SEARCH = """
/* The interleaved 4x4 pattern of docs/algorithm.md. */
const int PATTERN[16] = int[16](0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);

float radius_in_pixels(float z)
{
    return perspective != 0 ? radius / (pixel_size.x * z) : radius / pixel_size.x;
}

/* R_block: the largest R_px >= 1 among the pixels of p's class in its block,
 * the BLOCK_PIXELS pixels x0 + a + 4 k of p's row (x0 a multiple of 4
 * BLOCK_PIXELS, a = p.x & 3), which march with one step length in the
 * library (csrc/lib/horizon.c, hbao_block_classes): the nearest depth z0
 * leads a class of the depths up to BLOCK_DEPTH_RATIO z0, the nearest
 * beyond leads the next, and so on. R_px falls as the depth grows, in
 * floats too (rounding is monotonic), and p itself is in the block with
 * R_px >= 1, so R_block is the R_px of the class's nearest depth: one
 * division instead of sixteen. */
float block_radius(ivec2 p, float z)
{
    if (perspective == 0) {
        return radius_in_pixels(z); /* the same for every pixel: one class */
    }
    int first = (p.x / (4 * BLOCK_PIXELS)) * (4 * BLOCK_PIXELS) + (p.x & 3);
    int last = min(first + 4 * BLOCK_PIXELS, image_size.x);
    float leader = z;
    for (int i = first; i < last; i += 4) {
        float zi = depth_at(ivec2(i, p.y));
        if (!is_background(zi)) {
            leader = min(leader, zi);
        }
    }
    /* the next class's leader while p lies beyond this one's: at most one
     * class a pixel, and p's own depth ends the walk */
    for (int c = 1; c < BLOCK_PIXELS && z > BLOCK_DEPTH_RATIO * leader; c++) {
        float reach = BLOCK_DEPTH_RATIO * leader;
        float next = z;
        for (int i = first; i < last; i += 4) {
            float zi = depth_at(ivec2(i, p.y));
            if (!is_background(zi) && zi > reach) {
                next = min(next, zi);
            }
        }
        leader = next;
    }
    return radius_in_pixels(leader);
}

/* csrc/lib/internal_hbao.h, hbao_beyond_depth (docs/algorithm.md, "Beyond
 * the frame"): the depth a step sees at pixel q outside the image, the
 * surface at the nearest edge pixel continued as its tangent plane and met
 * by q's view ray; 0 (background) where there is none. */
float beyond_depth(ivec2 q)
{
    ivec2 e = clamp(q, ivec2(0), image_size - 1);
    float ze = depth_at(e);
    if (is_background(ze)) {
        return 0.0;
    }
    vec3 n = texelFetch(normal_texture, ivec2(e.x, image_size.y - 1 - e.y), 0).xyz;
    float plane = dot(n, position_at(e, ze));
    /* the ray's points are start + z (position_at(q, 1) - start) */
    vec3 start = position_at(q, 0.0);
    float z = (plane - dot(n, start)) / dot(n, position_at(q, 1.0) - start);
    return z > 0.0 && !isinf(z) ? z : 0.0;
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
    float rounding = depth_precision.x + DEPTH_BUFFER_MARGIN * buffer_rounding(z);
    float height_tolerance = rounding
                           * abs(perspective != 0 ? dot(normal, position) : normal.z * position.z);
    /* docs/algorithm.md, "Thickness" (csrc/lib/internal_hbao.h,
     * hbao_near_limit): samples nearer than this are occluders wholly in
     * front of the pixel. */
    float near_limit = thickness > 0.0 ? z - thickness : 0.0;

    float inv_ycor = pixel_size.x / pixel_size.y;
    float rotation = (float(PATTERN[(p.x & 3) + 4 * (p.y & 3)]) + 0.5) / 16.0;
    float jitter = (float(PATTERN[(p.y & 3) + 4 * (p.x & 3)]) + 0.5) / 16.0;
    float sin_bias = sin(angle_bias);
    float step_px = (block_radius(p, z) - 1.0) / float(steps);
    int beyond_band = max(image_size.x, image_size.y) / BEYOND_BAND_DIVISOR;

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
            ivec2 offset = ivec2(floor(0.5 + cos_theta * t), floor(0.5 - sin_theta * t * inv_ycor));
            ivec2 q = p + offset;
            /* a whole image away (hbao_step_offset), or past the band beyond
             * the edges */
            if (any(greaterThanEqual(abs(offset), image_size))
                || any(lessThan(q, ivec2(-beyond_band)))
                || any(greaterThanEqual(q, image_size + beyond_band))) {
                break;
            }
            if (q == p) {
                continue;
            }
            bool in_image = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, image_size));
            float zs = in_image ? depth_at(q) : beyond_depth(q);
            /* a continued plane's depth is any positive one, as the library's */
            if ((in_image ? is_background(zs) : !(zs > 0.0)) || zs < near_limit) {
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
