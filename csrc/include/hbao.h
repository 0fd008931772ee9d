/* SPDX-License-Identifier: GPL-2.0-or-later */
/*
 * libhbao: horizon-based ambient occlusion (HBAO) from a depth buffer.
 *
 * The library turns Blender's Depth pass (planar camera-space depth: the
 * positive distance along the view axis) and, optionally, its Normal pass
 * (world space) into an ambient-occlusion image, 1 = unoccluded, 0 = fully
 * occluded. It follows Bavoil & Sainz 2008 ("Image-space horizon-based
 * ambient occlusion"): per pixel, N directions evenly spaced around the
 * pixel and rotated by an interleaved 4x4 pattern are marched for S jittered
 * steps inside the projected radius; the highest horizon found along each
 * direction, attenuated per sample, gives that direction's occlusion.
 *
 *   hbao_params params = HBAO_PARAMS_DEFAULT_INITIALIZER;
 *   hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
 *   hbao_channel depth = { depth_pixels, 1, width };     // strides in floats
 *   hbao_result r = hbao_compute(&params, &camera, width, height,
 *                                &depth, NULL, ao, width);
 *   if (r != HBAO_SUCCESS) fprintf(stderr, "%s\n", hbao_result_message(r));
 *
 * Conventions
 * - Images are row-major; row 0 is the TOP row of the picture. A bottom-up
 *   buffer (Blender's render passes, OpenGL) is described with a pointer to
 *   its last row and a negative row stride.
 * - Strides count floats, not bytes.
 * - Background: a depth that is not finite, <= 0, >= params.background_depth
 *   (Cycles writes 1e10), or exactly HBAO_HALF_FLOAT_SKY (65504, the largest
 *   half float: the sky of EEVEE's half-float Depth pass, whatever the
 *   background_depth, so that one above it, from a camera's Clip End, leaves
 *   geometry past 65504 to a float depth) gets AO = 1 and never occludes
 *   anything.
 * - The output is always finite and in [0, 1].
 * - Scale: depths are used in single precision as given. Scaling every
 *   length of a view (depths, radius, thickness, background_depth,
 *   ortho_scale) by a power of two leaves the AO bit for bit the same
 *   while those lengths stay between about 1e-16 and 1e19 scene units (and
 *   no depth lands exactly on HBAO_HALF_FLOAT_SKY, which is background)
 *   (test_planes.c, ao_is_the_same_at_every_scale). Depths that are all
 *   half floats (a half-float Depth pass) are an exception: their rounding
 *   is told from the values (docs/algorithm.md, "Depth precision"), and a
 *   scale that takes them out of the half-float range, or into it, changes
 *   the tolerance it gives, and so the AO. Beyond 1e19 (only with
 *   a background_depth above it) squared distances overflow, and toward
 *   the denormals (below about 1e-17; below 1.2e-38 the depth weights no
 *   longer tell depths apart) they lose precision: the AO there is finite
 *   and in [0, 1] but not that of the geometry.
 * - Every call returns a result code; hbao_result_message() turns it into
 *   text. Calls may run concurrently from several threads; the only state
 *   kept between calls is the cache of working memory (hbao_release_memory),
 *   which no result depends on. The output is bit-identical whatever the
 *   number of threads (a worker thread that cannot start leaves its rows to
 *   the others: HBAO_ERROR_THREAD, kept so that the codes keep their
 *   numbers, is not returned).
 * - Outputs are allocated by the caller.
 */
#ifndef HBAO_H
#define HBAO_H

#include <stddef.h>
#include <stdint.h>

#include "hbao_export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A release that adds to this header raises the minor version (0.6:
 * HBAO_IMPLEMENTATION_GENERIC, hbao_implementation_that_runs and
 * hbao_implementation_name); while the major version is 0 the add-on's
 * binding accepts only the minor version it mirrors (any patch):
 * addon/hbao/native_library.py, BINDING_VERSION_MINOR. */
#define HBAO_VERSION_MAJOR 0
#define HBAO_VERSION_MINOR 6
#define HBAO_VERSION_PATCH 0
/** Packed version: major * 10000 + minor * 100 + patch. */
#define HBAO_VERSION (HBAO_VERSION_MAJOR * 10000 + HBAO_VERSION_MINOR * 100 + HBAO_VERSION_PATCH)

/**
 * The result codes and their messages, generated from one list so that they
 * cannot drift apart.
 */
#define HBAO_RESULT_LIST(X)                                                                        \
    X(HBAO_SUCCESS, "success")                                                                     \
    X(HBAO_ERROR_NULL_ARGUMENT, "a required pointer argument is NULL")                             \
    X(HBAO_ERROR_INVALID_SIZE, "image width and height must be in [1, 65536]")                     \
    X(HBAO_ERROR_INVALID_STRIDE, "a pixel or row stride is too small for the image")               \
    X(HBAO_ERROR_INVALID_PARAMETER,                                                                \
      "a parameter is not a number, negative where it must not be, or an unknown "                 \
      "enum value")                                                                                \
    X(HBAO_ERROR_INVALID_CAMERA,                                                                   \
      "the camera is invalid (lens, sensor, ortho scale and pixel aspect must be "                 \
      "finite and > 0; the matrix must be finite and invertible)")                                 \
    X(HBAO_ERROR_OUT_OF_MEMORY, "out of memory")                                                   \
    X(HBAO_ERROR_THREAD, "could not start a worker thread")                                        \
    X(HBAO_ERROR_INVALID_RECTANGLE, "the crop rectangle's width and height must be in [1, 65536]")

typedef enum hbao_result_code {
#define HBAO_RESULT_ENUM_ENTRY(name, message) name,
    HBAO_RESULT_LIST(HBAO_RESULT_ENUM_ENTRY)
#undef HBAO_RESULT_ENUM_ENTRY
        HBAO_RESULT_COUNT
} hbao_result_code;

/** Every call returns one of hbao_result_code as a fixed-width integer. */
typedef int32_t hbao_result;

/** How the horizon angles are turned into occlusion. */
typedef enum hbao_integration {
    /** Bavoil & Sainz: occlusion = sin(horizon elevation above the tangent
     *  plane), averaged over directions: the fraction of the hemisphere's
     *  solid angle that is occluded. */
    HBAO_INTEGRATION_HBAO = 0,
    /** Cosine-weighted visibility, the quantity Blender's ray-traced AO pass
     *  (Cycles) measures. Directions are integrated as slices around the view
     *  vector, exactly for a height field. */
    HBAO_INTEGRATION_COSINE = 1
} hbao_integration;

/** Per-sample attenuation W(r), r = distance / radius. */
typedef enum hbao_falloff {
    HBAO_FALLOFF_QUADRATIC = 0, /**< W(r) = 1 - r^2 (Bavoil & Sainz). */
    HBAO_FALLOFF_NONE = 1       /**< W(r) = 1 inside the radius. */
} hbao_falloff;

/** Documented limits. Values outside them are clamped (counts, sizes) or
 *  rejected with HBAO_ERROR_INVALID_PARAMETER (NaN, negative radius); see
 *  hbao_params_resolve(), the one place that applies them. */
#define HBAO_MAX_DIRECTIONS 64
#define HBAO_MAX_STEPS 64
#define HBAO_MAX_BLUR_SIZE 65
#define HBAO_MAX_BLUR_SHARPNESS 1000.0f
#define HBAO_MAX_ANGLE_BIAS_DEGREES 60.0f
#define HBAO_MAX_STRENGTH 16.0f
#define HBAO_MAX_THREADS 256
#define HBAO_MAX_IMAGE_SIZE 65536

/** Algorithm parameters. Initialise with HBAO_PARAMS_DEFAULT_INITIALIZER or
 *  hbao_params_default(), then change what you need. */
typedef struct hbao_params {
    /** AO radius in scene units; 0 gives AO = 1 everywhere. Must be finite
     *  and >= 0. A pixel whose radius projects to less than one pixel gets
     *  AO = 1 without sampling. */
    float radius;
    /** Occluders less than this many degrees above the tangent plane are
     *  ignored (hides low-tessellation creases). Clamped to [0, 60]. */
    float angle_bias_degrees;
    /** Directions per pixel, clamped to [1, 64]. */
    int32_t directions;
    /** Steps per direction, clamped to [1, 64]. */
    int32_t steps;
    /** hbao_falloff; default NONE. */
    int32_t falloff;
    /** hbao_integration; default COSINE. */
    int32_t integration;
    /** Width in pixels of the cross-bilateral blur kernel; 0, 1 or 2 = no
     *  blur. Even sizes round down to the odd size below.
     *  Clamped to [0, 65]; hbao_params_resolve() gives 0 or the odd size. */
    int32_t blur_size;
    /** How strongly the blur stops at depth edges; 0 = plain Gaussian.
     *  Clamped to [0, 1000]; hbao_params_resolve() gives 0 where there is
     *  no blur (and reports no clamp there). */
    float blur_sharpness;
    /** Non-zero: AO at half resolution (every other pixel of every other
     *  row), blurred there with half the taps (the same reach), then a
     *  depth-aware upsample to full resolution. */
    int32_t half_resolution;
    /** Applied last: ao = ao^strength. 0 = no AO, 1 = as computed, larger =
     *  darker. Clamped to [0, 16]. */
    float strength;
    /** Worker threads; 0 (or less) = one per core this process may run on
     *  (its CPU affinity, which taskset or a container's cpuset narrow).
     *  Clamped to at most 256. */
    int32_t threads;
    /** Depths at or beyond this are background. Must be > 0. */
    float background_depth;
    /** hbao_implementation: which compiled code runs: the horizon kernel
     *  and the copies of the vectorized stages (given normals, upsample,
     *  blur). All give bit-identical results; choosing one exists for tests
     *  and benchmarks. */
    int32_t implementation;
    /** Occluder thickness in scene units; 0 (the default) = infinitely
     *  thick (every surface a solid block reaching back from its depth: the
     *  height-field model of every version before this field). Otherwise a
     *  surface seen at a sample is taken to occupy depths [sample depth, sample depth + thickness] along its view
     *  ray, and a sample whose block lies wholly in front of the pixel
     *  (sample depth + thickness < the pixel's depth) does not raise the
     *  horizon: light passes behind it. Must be finite and >= 0. */
    float thickness;
} hbao_params;

/** The horizon search exists as a portable scalar reference and as kernels
 *  that search 16 pixels at once, chosen at run time; every one gives the
 *  reference's floats to the bit. From the slowest to the fastest: SCALAR,
 *  GENERIC, AVX2, AVX512. A kernel the CPU (or the compiler that built the
 *  library) lacks falls back to the fastest one slower than it. Unknown
 *  values are rejected. */
typedef enum hbao_implementation {
    HBAO_IMPLEMENTATION_AUTO = 0,    /**< the fastest this CPU runs */
    HBAO_IMPLEMENTATION_SCALAR = 1,  /**< portable C, a pixel at a time: the reference */
    HBAO_IMPLEMENTATION_AVX2 = 2,    /**< in pairs of AVX2 registers (x86-64) */
    HBAO_IMPLEMENTATION_AVX512 = 3,  /**< in AVX-512 registers (x86-64) */
    HBAO_IMPLEMENTATION_GENERIC = 4, /**< in the compiler's generic vectors, for any
                                          CPU: SSE2 on x86-64, Advanced SIMD on ARM64 */
    HBAO_IMPLEMENTATION_COUNT        /**< not an implementation: one past the last */
} hbao_implementation;

/* The defaults were chosen with the accuracy benchmark (docs/benchmark.md):
 * cosine integration with no falloff is what Cycles' AO pass measures; steps
 * matter more than directions once the 4x4 pattern is blurred, so 4 x 16;
 * a 5-pixel blur hides the 4x4 sampling pattern at little cost. */
#define HBAO_DEFAULT_RADIUS 1.0f
#define HBAO_DEFAULT_ANGLE_BIAS_DEGREES 5.0f
#define HBAO_DEFAULT_DIRECTIONS 4
#define HBAO_DEFAULT_STEPS 16
#define HBAO_DEFAULT_BLUR_SIZE 5
#define HBAO_DEFAULT_BLUR_SHARPNESS 32.0f
#define HBAO_DEFAULT_STRENGTH 1.0f
/** EEVEE's half-float Depth pass stores background as 65504, Cycles as 1e10. */
#define HBAO_DEFAULT_BACKGROUND_DEPTH 65504.0f
/* Background at any background_depth (Conventions): EEVEE's half-float sky. */
#define HBAO_HALF_FLOAT_SKY 65504.0f
/** Infinitely thick occluders: on the benchmark scenes a finite thickness
 *  raised the error on three of four (docs/benchmark-layers.md). */
#define HBAO_DEFAULT_THICKNESS 0.0f

#define HBAO_PARAMS_DEFAULT_INITIALIZER                                                            \
    {                                                                                              \
        HBAO_DEFAULT_RADIUS, HBAO_DEFAULT_ANGLE_BIAS_DEGREES, HBAO_DEFAULT_DIRECTIONS,             \
            HBAO_DEFAULT_STEPS, HBAO_FALLOFF_NONE, HBAO_INTEGRATION_COSINE,                        \
            HBAO_DEFAULT_BLUR_SIZE, HBAO_DEFAULT_BLUR_SHARPNESS, 0, HBAO_DEFAULT_STRENGTH, 0,      \
            HBAO_DEFAULT_BACKGROUND_DEPTH, 0, HBAO_DEFAULT_THICKNESS                               \
    }

typedef enum hbao_projection {
    HBAO_PROJECTION_PERSPECTIVE = 0,
    HBAO_PROJECTION_ORTHOGRAPHIC = 1
} hbao_projection;

/** Blender's Camera.sensor_fit. */
typedef enum hbao_sensor_fit {
    HBAO_SENSOR_FIT_AUTO = 0,       /**< sensor_width spans the larger image side */
    HBAO_SENSOR_FIT_HORIZONTAL = 1, /**< sensor_width spans the image width */
    HBAO_SENSOR_FIT_VERTICAL = 2    /**< sensor_height spans the image height */
} hbao_sensor_fit;

/** Blender's camera model, with Blender's property names and defaults. */
typedef struct hbao_camera {
    int32_t projection;  /**< hbao_projection */
    float lens;          /**< focal length, mm (perspective) */
    float sensor_width;  /**< mm */
    float sensor_height; /**< mm */
    int32_t sensor_fit;  /**< hbao_sensor_fit */
    float shift_x;       /**< lens shift, in units of the fitted sensor side */
    float shift_y;
    float ortho_scale;    /**< view width of the fitted side (orthographic) */
    float pixel_aspect_x; /**< scene.render.pixel_aspect_x */
    float pixel_aspect_y;
    /** Row-major 4x4 world-to-camera matrix (camera.matrix_world inverted).
     *  Only its rotation is used: it maps the world-space Normal pass into
     *  camera space. Identity when the normals are already in camera space.
     *  A camera's scale may be left in: rows of unequal length (scaled
     *  unevenly) are each made unit length, as Blender renders the camera. */
    float world_to_camera[16];
} hbao_camera;

#define HBAO_CAMERA_DEFAULT_INITIALIZER                                                            \
    {                                                                                              \
        HBAO_PROJECTION_PERSPECTIVE, 50.0f, 36.0f, 24.0f, HBAO_SENSOR_FIT_AUTO, 0.0f, 0.0f, 6.0f,  \
            1.0f, 1.0f, {                                                                          \
            1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f,    \
                0.0f, 1.0f                                                                         \
        }                                                                                          \
    }

/**
 * Where a camera puts the pixels of a width x height image (docs/algorithm.md,
 * "Camera"): pixel (i, j), column i from the left and row j from the top, lies
 * at
 *
 *   x = origin_x + (i + 0.5) * pixel_size_x
 *   y = origin_y + (height - 1 - j + 0.5) * pixel_size_y
 *
 * per unit depth when perspective (camera-space P = (x depth, y depth, -depth))
 * and in scene units when orthographic (P = (x, y, -depth)). These are the
 * numbers a renderer of the same view (the add-on's GLSL preview) needs.
 */
typedef struct hbao_view {
    int32_t perspective; /**< 1 perspective, 0 orthographic */
    double pixel_size_x; /**< view-plane width of one pixel */
    double pixel_size_y; /**< its height: pixel_size_x * pixel_aspect_y / pixel_aspect_x */
    double origin_x;     /**< left edge of the image */
    double origin_y;     /**< bottom edge of the image */
} hbao_view;

/** A read-only view of one image channel (or of 3 consecutive channels, for
 *  normals). Strides count floats; row_stride may be negative. */
typedef struct hbao_channel {
    const float *data;    /**< the top-left pixel */
    int32_t pixel_stride; /**< floats from one pixel to its right neighbour, >= 1
                               (>= 3 for normals) */
    int64_t row_stride;   /**< floats from one row to the row below it */
} hbao_channel;

/** The fields of hbao_params in struct order, each with its bit in
 *  hbao_params_resolve()'s report and its name (the struct member's). */
#define HBAO_PARAM_FIELD_LIST(X)                                                                   \
    X(HBAO_PARAM_FIELD_RADIUS, 0, "radius")                                                        \
    X(HBAO_PARAM_FIELD_ANGLE_BIAS_DEGREES, 1, "angle_bias_degrees")                                \
    X(HBAO_PARAM_FIELD_DIRECTIONS, 2, "directions")                                                \
    X(HBAO_PARAM_FIELD_STEPS, 3, "steps")                                                          \
    X(HBAO_PARAM_FIELD_FALLOFF, 4, "falloff")                                                      \
    X(HBAO_PARAM_FIELD_INTEGRATION, 5, "integration")                                              \
    X(HBAO_PARAM_FIELD_BLUR_SIZE, 6, "blur_size")                                                  \
    X(HBAO_PARAM_FIELD_BLUR_SHARPNESS, 7, "blur_sharpness")                                        \
    X(HBAO_PARAM_FIELD_HALF_RESOLUTION, 8, "half_resolution")                                      \
    X(HBAO_PARAM_FIELD_STRENGTH, 9, "strength")                                                    \
    X(HBAO_PARAM_FIELD_THREADS, 10, "threads")                                                     \
    X(HBAO_PARAM_FIELD_BACKGROUND_DEPTH, 11, "background_depth")                                   \
    X(HBAO_PARAM_FIELD_IMPLEMENTATION, 12, "implementation")                                       \
    X(HBAO_PARAM_FIELD_THICKNESS, 13, "thickness")

typedef enum hbao_param_field {
#define HBAO_PARAM_FIELD_ENUM_ENTRY(name, bit, text) name = 1u << (bit),
    HBAO_PARAM_FIELD_LIST(HBAO_PARAM_FIELD_ENUM_ENTRY)
#undef HBAO_PARAM_FIELD_ENUM_ENTRY
} hbao_param_field;

/**
 * The parameters hbao_compute() will use for `in`: every limit above
 * applied in one place, which every front end (the CLI, the add-on) calls so
 * that they agree with the library. Out-of-range values are clamped to the
 * nearest limit and their bits (hbao_param_field) set in *clamped_fields, so
 * the caller can warn; negative threads become 0 (one per core) and a
 * non-zero half_resolution becomes 1, without a bit. Values that have no
 * nearest legal value (NaN, infinite floats but a background_depth of
 * +infinity, a negative radius or thickness, a background_depth <= 0,
 * unknown enum values) give
 * HBAO_ERROR_INVALID_PARAMETER, and then *clamped_fields holds the bits of
 * those invalid fields instead and *out is unchanged. A setting written in
 * more than one way comes back in one, without a bit, so that what compares
 * resolved values finds them equal: the blur size as 0 or odd, the blur
 * sharpness as 0 where nothing is blurred, and -0 as 0. (Different values
 * may still compute the same AO: at half resolution blur sizes 3 and 5 run
 * the same kernel on the half grid.) `out` may be `in`; clamped_fields may
 * be NULL.
 */
HBAO_EXPORT hbao_result hbao_params_resolve(const hbao_params *in, hbao_params *out,
                                            uint32_t *clamped_fields);

/** The name of one hbao_param_field bit ("steps", ...), or NULL for a value
 *  that is not exactly one field's bit. */
HBAO_EXPORT const char *hbao_param_field_name(uint32_t bit);

/** Packed HBAO_VERSION of the library that is loaded. */
HBAO_EXPORT int32_t hbao_version(void);

/** A static, human-readable message for a result code (never NULL). */
HBAO_EXPORT const char *hbao_result_message(hbao_result result);

/** Fill *params with the defaults (for callers that cannot use the macro). */
HBAO_EXPORT void hbao_params_default(hbao_params *params);

/** Fill *camera with Blender's default camera. */
HBAO_EXPORT void hbao_camera_default(hbao_camera *camera);

/** The hbao_implementation that HBAO_IMPLEMENTATION_AUTO runs on this CPU. */
HBAO_EXPORT int32_t hbao_best_implementation(void);

/** The hbao_implementation that runs on this CPU when `requested` is asked
 *  for: itself where the CPU and the build have it, else the fastest one
 *  slower than it (hbao_implementation's order); AUTO gives
 *  hbao_best_implementation(). An unknown value gives SCALAR (hbao_compute
 *  rejects it). */
HBAO_EXPORT int32_t hbao_implementation_that_runs(int32_t requested);

/** An hbao_implementation's name ("auto", "scalar", "AVX2", "AVX-512",
 *  "generic"), or "unknown implementation". */
HBAO_EXPORT const char *hbao_implementation_name(int32_t implementation);

/** hbao_compute and hbao_compute_layers keep their large working buffers
 *  (about 24 bytes per pixel at full resolution, at most 512 MiB in all) for
 *  the next call, which then skips faulting fresh pages in: a fifth of a
 *  1080p frame's time (csrc/bench/bench_ab.c). This frees them, say after
 *  the last frame of a render. Thread-safe; results never depend on it. */
HBAO_EXPORT void hbao_release_memory(void);

/** sizeof(hbao_params) and sizeof(hbao_camera) as compiled into the library,
 *  so that bindings (ctypes) can check their struct layouts on load. */
HBAO_EXPORT size_t hbao_params_size(void);
HBAO_EXPORT size_t hbao_camera_size(void);
/** sizeof(hbao_view) as compiled into the library (see above). */
HBAO_EXPORT size_t hbao_view_size(void);

/**
 * The background depth (hbao_params.background_depth) of a render through a
 * camera with this clip range, the rule every front end (the node, the CLI)
 * takes from here. Nothing is rendered past Clip End, and EEVEE in Blender
 * 4.5 and 5.0 writes the sky's depth as Clip End or a rounding of it
 * (8.99996 for 9; 99864 for 1e5 with Clip Start 0.1: its depth buffer holds
 * the far plane to about Clip End / Clip Start x 2^-24 of it). So depths
 * within a margin of Clip End, or past it, are background:
 * clip_end x (1 - margin), margin = max(1e-5, min(0.5, 2^-23 x clip_end /
 * clip_start)). Geometry up to there is geometry, past 65504 too.
 *
 * @param clip_start  the camera's Clip Start; not finite or <= 0 means
 *                    unknown (a camera file written before it was): then
 *                    the lesser of `depth` and clip_end x (1 - 1e-5)
 * @param clip_end    the camera's Clip End; not finite or <= 0 means
 *                    unknown: then `depth`
 * @param depth       the background depth without a camera (the
 *                    parameter's, HBAO_DEFAULT_BACKGROUND_DEPTH by default)
 */
HBAO_EXPORT float hbao_clip_background_depth(float clip_start, float clip_end, float depth);

/**
 * The view frame of `camera` on a width x height image: Blender's sensor fit
 * (BKE_camera_params_compute_viewplane), the one implementation of it that
 * hbao_compute() and every front end use.
 *
 * @param width, height  image size, each in [1, 65536]
 * @return HBAO_ERROR_NULL_ARGUMENT, HBAO_ERROR_INVALID_SIZE,
 *         HBAO_ERROR_INVALID_CAMERA (as hbao_compute() would), and then
 *         *view is unchanged
 */
HBAO_EXPORT hbao_result hbao_camera_view(const hbao_camera *camera, int32_t width, int32_t height,
                                         hbao_view *view);

/**
 * The camera of the rectangle (x, y, width, height) of a full_width x
 * full_height image (a border render, an EXR data window inside its display
 * window): each of its pixels gets the view ray the full camera gives the
 * same pixel. The rectangle may also reach past the image (overscan: a data
 * window larger than the display window, a guard band of depth around the
 * frame so that occluders just outside it count); its pixels there get the
 * rays of the full camera's view plane extended. The sensor fit is made
 * explicit (AUTO becomes the side it fitted), the fitted sensor side and
 * the ortho scale are scaled to the rectangle and the lens shift moves the
 * centre; lens, pixel aspect and matrix are kept. A crop of the whole image
 * returns the camera unchanged.
 *
 * @param full_width, full_height  the full image, each in [1, 65536]
 * @param x, y           the rectangle's top-left pixel in the full image's
 *                       pixel grid (y down); negative or past the image for
 *                       overscan
 * @param width, height  the rectangle, each in [1, 65536]
 * @param cropped        output; may be `camera`
 * @return HBAO_ERROR_NULL_ARGUMENT, HBAO_ERROR_INVALID_SIZE,
 *         HBAO_ERROR_INVALID_RECTANGLE, HBAO_ERROR_INVALID_CAMERA (for the
 *         camera, or when the cropped camera's numbers leave float's range),
 *         and then *cropped is unchanged
 */
HBAO_EXPORT hbao_result hbao_camera_crop(const hbao_camera *camera, int32_t full_width,
                                         int32_t full_height, int32_t x, int32_t y, int32_t width,
                                         int32_t height, hbao_camera *cropped);

/**
 * Compute ambient occlusion.
 *
 * @param width, height  image size, each in [1, 65536]
 * @param depth          planar depth (required)
 * @param normal         world-space normals, X Y Z consecutive; NULL (or
 *                       data NULL) = face normals reconstructed from depth.
 *                       A normal shorter than 0.1 (anti-aliased edges,
 *                       background) or not finite is reconstructed too.
 * @param ao             output, width x height floats, caller-allocated; it
 *                       may share memory with the inputs (the AO written over
 *                       its own depth): the result is the same
 * @param ao_row_stride  floats from one output row to the next (|s| >= width)
 */
HBAO_EXPORT hbao_result hbao_compute(const hbao_params *params, const hbao_camera *camera,
                                     int32_t width, int32_t height, const hbao_channel *depth,
                                     const hbao_channel *normal, float *ao, int64_t ao_row_stride);

/**
 * hbao_compute() with a second depth layer, of back faces.
 *
 * @param back_depth  per pixel, the planar depth of the first back face
 *                    behind the visible surface (Blender: a render whose
 *                    front faces are transparent, e.g. a view layer with a
 *                    material override, 1 sample, Depth only); NULL (or
 *                    data NULL) = hbao_compute(). A surface seen at a sample
 *                    then occupies [depth, back depth] along its view ray
 *                    (at least half the radius deep), and it occludes only
 *                    the angles between its front and its back point, so
 *                    light passes between a floating object and the
 *                    surface behind it. Each direction keeps a mask of 32
 *                    sectors for this (docs/algorithm.md, "Two depth
 *                    layers"). A sample beyond the radius whose occluder
 *                    reaches into the radius occludes from where it enters. Where no back face is known (0, not finite,
 *                    not behind the visible surface, or at or beyond
 *                    background_depth) the surface is infinitely thick; a
 *                    layer with no back face known anywhere gives exactly
 *                    hbao_compute()'s result. params.thickness still
 *                    applies: it skips samples as without the layer.
 */
HBAO_EXPORT hbao_result hbao_compute_layers(const hbao_params *params, const hbao_camera *camera,
                                            int32_t width, int32_t height,
                                            const hbao_channel *depth, const hbao_channel *normal,
                                            const hbao_channel *back_depth, float *ao,
                                            int64_t ao_row_stride);

/** Bits of hbao_last_notes(). HBAO_NOTE_REFERENCE_SEARCH: no memory for the
 *  SIMD search's copy of the depths (4 bytes a pixel of the grid, two with
 *  the back layer), so the scalar reference searched: the same result,
 *  several times slower (58.5 s against 6 for an 8K frame). */
#define HBAO_NOTE_REFERENCE_SEARCH 1u
/** HBAO_NOTE_RADIUS_BEYOND_IMAGE: at most of the image's foreground pixels
 *  (judged on about 4096 pixels spread over the image) the radius spans
 *  more than the image's shorter side (a render a few pixels high, or a camera
 *  very close to the surfaces): most samples then fall outside the image,
 *  so the AO comes out too light. The result is computed as usual. */
#define HBAO_NOTE_RADIUS_BEYOND_IMAGE 2u
/** HBAO_NOTE_RADIUS_UNDER_A_PIXEL: at most of the image's foreground pixels
 *  (judged as above) the radius spans less than a pixel (one far too small
 *  for the scene's units; a radius of 0 always), so nothing is sampled
 *  there and the AO is 1: a frame without AO that would otherwise say
 *  nothing. */
#define HBAO_NOTE_RADIUS_UNDER_A_PIXEL 4u

/** What the calling thread's last hbao_compute or hbao_compute_layers did
 *  other than usual (HBAO_NOTE_* bits; 0: nothing), for callers that tell
 *  their users why a frame was slow. Set by every call, failed or not. */
HBAO_EXPORT uint32_t hbao_last_notes(void);

/** What one HBAO_NOTE_* bit means, for people ("unknown note" otherwise). */
HBAO_EXPORT const char *hbao_note_message(uint32_t note);

#ifdef __cplusplus
}
#endif

#endif /* HBAO_H */
