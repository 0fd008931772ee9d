# SPDX-License-Identifier: GPL-2.0-or-later
"""GLSL of the preview's normal pass: csrc/lib/normals.c, following
docs/algorithm.md ("Normals"). A fragment body: shader_sources.py puts the
camera model (camera_sources.py) in front of it and compiles it with
NORMAL_DEFINES. Plain strings, no bpy."""

# Camera-space normals reconstructed from depth, facing the viewer
# (docs/algorithm.md, "Normals"; the rule for float depth, and the fitted
# tangent where the depth is coarse: half floats, or a depth buffer's far
# steps); (0, 0, 1) on background, as csrc/lib/normals.c writes there.
NORMALS = """
/* Pixel q's depth, where it lies in the image and is not background. */
bool usable_depth(ivec2 q, out float zq)
{
    zq = 0.0;
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, image_size))) {
        return false;
    }
    zq = depth_at(q);
    return !is_background(zq);
}

/* Coarse depth (half floats, or a far depth of a view with a tiny Clip
 * Start: coarse_depth) steps in stairs:
 * the tangent along an axis is the least-squares line through the run of up
 * to HALF_DEPTH_FIT_REACH pixels on each side that continues the surface
 * (docs/algorithm.md, "Normals"; csrc/lib/normals.c, fit_tangent). */
bool fit_tangent(ivec2 p, ivec2 axis, float z0, out vec3 tangent)
{
    tangent = vec3(0.0);
    float first_step = 3.0e38;
    float zq;
    if (usable_depth(p - axis, zq)) {
        first_step = min(first_step, abs(zq - z0));
    }
    if (usable_depth(p + axis, zq)) {
        first_step = min(first_step, abs(zq - z0));
    }
    if (first_step == 3.0e38) {
        return false;
    }
    float limit = 2.0 * first_step + 2.0 * depth_rounding(z0) * z0;
    float sum_z = z0, sum_kz = 0.0, sum_kkz = 0.0;
    int sum_k = 0, sum_kk = 0, count = 1;
    for (int sign = -1; sign <= 1; sign += 2) {
        float previous = z0;
        for (int k = sign; k * sign <= HALF_DEPTH_FIT_REACH; k += sign) {
            if (!usable_depth(p + k * axis, zq) || !(abs(zq - previous) <= limit)) {
                break;
            }
            previous = zq;
            sum_z += zq;
            sum_kz += float(k) * zq;
            sum_kkz += float(k * k) * zq;
            sum_k += k;
            sum_kk += k * k;
            count++;
        }
    }
    if (count < 2) {
        return false;
    }
    /* The line through P(k) has direction sum (k - mean) P(k); the view-plane
     * coordinates are linear in k. */
    float mean = float(sum_k) / float(count);
    float weighted_z = sum_kz - mean * sum_z;
    float weighted_kz = sum_kkz - mean * sum_kz;
    if (perspective != 0) {
        vec3 base = position_at(p, 1.0);
        vec3 step = position_at(p + axis, 1.0) - base;
        tangent = vec3(base.xy * weighted_z + step.xy * weighted_kz, -weighted_z);
    }
    else {
        float weighted_k = float(sum_kk) - mean * float(sum_k);
        vec3 step = position_at(p + axis, z0) - position_at(p, z0);
        tangent = vec3(step.xy * weighted_k, -weighted_z);
    }
    return true;
}

/* Whether the depth at z is coarse enough for fitted tangents: half floats
 * (the library's rule), or a depth buffer whose step, over a pixel's width,
 * would tilt a neighbour difference by more than BUFFER_FIT_SLOPE (far
 * depths of a view with a tiny Clip Start). */
bool coarse_depth(float z)
{
    float step = buffer_rounding(z) * (perspective != 0 ? 1.0 : z);
    return depth_precision.x >= HALF_DEPTH_PRECISION || step >= BUFFER_FIT_SLOPE * pixel_size.x;
}

/* One axis of the reconstructed tangent: the neighbour difference with the
 * smaller depth change (the one before wins a tie, as in csrc/lib/normals.c);
 * false when neither neighbour is usable. Fitted where the depth is coarse. */
bool tangent_along(ivec2 p, ivec2 axis, float z, vec3 position, out vec3 tangent)
{
    if (coarse_depth(z)) {
        return fit_tangent(p, axis, z, tangent);
    }
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
