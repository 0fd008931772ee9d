/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "cli_options.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "number_parsing.h"

/* The longest channel name an EXR may hold (OpenEXR's long names). */
#define AO_CHANNEL_NAME_MAX 255

typedef enum option_id {
    OPTION_OUTPUT,
    OPTION_LAYER,
    OPTION_BACK_LAYER,
    OPTION_AO_CHANNEL,
    OPTION_KEEP_INPUT,
    OPTION_NO_NORMALS,
    OPTION_CROP_TO_DISPLAY,
    OPTION_OVERSCAN,
    OPTION_PREVIEW,
    OPTION_COMPRESSION,
    OPTION_RADIUS,
    OPTION_THICKNESS,
    OPTION_ANGLE_BIAS,
    OPTION_DIRECTIONS,
    OPTION_STEPS,
    OPTION_BLUR,
    OPTION_BLUR_SHARPNESS,
    OPTION_HALF_RES,
    OPTION_FALLOFF,
    OPTION_INTEGRATION,
    OPTION_STRENGTH,
    OPTION_THREADS,
    OPTION_CAMERA,
    OPTION_CAMERA_TYPE,
    OPTION_LENS,
    OPTION_SENSOR_WIDTH,
    OPTION_SENSOR_HEIGHT,
    OPTION_SENSOR_FIT,
    OPTION_SHIFT_X,
    OPTION_SHIFT_Y,
    OPTION_ORTHO_SCALE,
    OPTION_PIXEL_ASPECT_X,
    OPTION_PIXEL_ASPECT_Y,
    OPTION_WORLD_TO_CAMERA,
    OPTION_FRAMES,
    OPTION_JOBS,
    OPTION_FORCE,
    OPTION_INFO,
    OPTION_JSON,
    OPTION_HELP,
    OPTION_VERSION
} option_id;

typedef struct option_spec {
    const char *name; /* without the leading "--" */
    char short_name;  /* 0: none */
    option_id id;
    bool takes_value;
} option_spec;

static const option_spec option_specs[] = {
    {"output", 'o', OPTION_OUTPUT, true},
    {"layer", 0, OPTION_LAYER, true},
    {"back-layer", 0, OPTION_BACK_LAYER, true},
    {"ao-channel", 0, OPTION_AO_CHANNEL, true},
    {"keep-input", 0, OPTION_KEEP_INPUT, false},
    {"no-normals", 0, OPTION_NO_NORMALS, false},
    {"crop-to-display", 0, OPTION_CROP_TO_DISPLAY, false},
    {"overscan", 0, OPTION_OVERSCAN, true},
    {"preview", 0, OPTION_PREVIEW, true},
    {"compression", 0, OPTION_COMPRESSION, true},
    {"radius", 0, OPTION_RADIUS, true},
    {"thickness", 0, OPTION_THICKNESS, true},
    {"angle-bias", 0, OPTION_ANGLE_BIAS, true},
    {"directions", 0, OPTION_DIRECTIONS, true},
    {"steps", 0, OPTION_STEPS, true},
    {"blur", 0, OPTION_BLUR, true},
    {"blur-sharpness", 0, OPTION_BLUR_SHARPNESS, true},
    {"half-res", 0, OPTION_HALF_RES, false},
    {"falloff", 0, OPTION_FALLOFF, true},
    {"integration", 0, OPTION_INTEGRATION, true},
    {"strength", 0, OPTION_STRENGTH, true},
    {"threads", 0, OPTION_THREADS, true},
    {"camera", 0, OPTION_CAMERA, true},
    {"camera-type", 0, OPTION_CAMERA_TYPE, true},
    {"lens", 0, OPTION_LENS, true},
    {"sensor-width", 0, OPTION_SENSOR_WIDTH, true},
    {"sensor-height", 0, OPTION_SENSOR_HEIGHT, true},
    {"sensor-fit", 0, OPTION_SENSOR_FIT, true},
    {"shift-x", 0, OPTION_SHIFT_X, true},
    {"shift-y", 0, OPTION_SHIFT_Y, true},
    {"ortho-scale", 0, OPTION_ORTHO_SCALE, true},
    {"pixel-aspect-x", 0, OPTION_PIXEL_ASPECT_X, true},
    {"pixel-aspect-y", 0, OPTION_PIXEL_ASPECT_Y, true},
    {"world-to-camera", 0, OPTION_WORLD_TO_CAMERA, true},
    {"frames", 0, OPTION_FRAMES, true},
    {"jobs", 'j', OPTION_JOBS, true},
    {"force", 0, OPTION_FORCE, false},
    {"info", 0, OPTION_INFO, false},
    {"json", 0, OPTION_JSON, false},
    {"help", 'h', OPTION_HELP, false},
    {"version", 0, OPTION_VERSION, false},
};

#define OPTION_COUNT (sizeof option_specs / sizeof option_specs[0])

typedef struct choice {
    const char *name;
    int32_t value;
} choice;

static const choice falloff_choices[] = {
    {"quadratic", HBAO_FALLOFF_QUADRATIC}, {"none", HBAO_FALLOFF_NONE}, {NULL, 0}};
static const choice integration_choices[] = {
    {"hbao", HBAO_INTEGRATION_HBAO}, {"cosine", HBAO_INTEGRATION_COSINE}, {NULL, 0}};
static const choice camera_type_choices[] = {
    {"PERSP", HBAO_PROJECTION_PERSPECTIVE}, {"ORTHO", HBAO_PROJECTION_ORTHOGRAPHIC}, {NULL, 0}};
static const choice sensor_fit_choices[] = {{"AUTO", HBAO_SENSOR_FIT_AUTO},
                                            {"HORIZONTAL", HBAO_SENSOR_FIT_HORIZONTAL},
                                            {"VERTICAL", HBAO_SENSOR_FIT_VERTICAL},
                                            {NULL, 0}};
/* Lossless methods only: AO is stored as 32-bit float, which the lossy
 * methods would quantise (pxr24) or pass through uncompressed (b44). */
static const choice compression_choices[] = {
    {"none", EXR_COMPRESSION_NONE}, {"rle", EXR_COMPRESSION_RLE}, {"zips", EXR_COMPRESSION_ZIPS},
    {"zip", EXR_COMPRESSION_ZIP},   {"piz", EXR_COMPRESSION_PIZ}, {NULL, 0}};

static int parse_choice(const char *flag, const char *text, const choice *choices, int32_t *out,
                        tool_error *error) {
    char names[128] = "";
    for (const choice *c = choices; c->name != NULL; ++c) {
        if (strcmp(c->name, text) == 0) {
            *out = c->value;
            return TOOL_EXIT_SUCCESS;
        }
        strncat(names, c == choices ? "" : ", ", sizeof names - strlen(names) - 1);
        strncat(names, c->name, sizeof names - strlen(names) - 1);
    }
    return tool_fail(error, TOOL_EXIT_USAGE, "--%s: \"%s\" is not one of %s", flag, text, names);
}

/* A finite float in [minimum, maximum]; `positive` makes the minimum exclusive of 0. */
static int parse_float_flag(const char *flag, const char *text, float minimum, float maximum,
                            bool positive, float *out, tool_error *error) {
    float value;
    if (!parse_finite_float(text, &value))
        return tool_fail(error, TOOL_EXIT_USAGE, "--%s: \"%s\" is not a finite number%s", flag,
                         text, strchr(text, ',') != NULL ? " (use a decimal point)" : "");
    if (positive && !(value > 0.0f))
        return tool_fail(error, TOOL_EXIT_USAGE, "--%s: must be > 0 (got %s)", flag, text);
    if (value < minimum || value > maximum)
        return tool_fail(error, TOOL_EXIT_USAGE, "--%s: must be in [%g, %g] (got %s)", flag,
                         (double)minimum, (double)maximum, text);
    *out = value;
    return TOOL_EXIT_SUCCESS;
}

static int parse_int_flag(const char *flag, const char *text, int32_t minimum, int32_t maximum,
                          int32_t *out, tool_error *error) {
    int32_t value;
    if (!parse_int32(text, &value))
        return tool_fail(error, TOOL_EXIT_USAGE, "--%s: \"%s\" is not an integer", flag, text);
    if (value < minimum || value > maximum)
        return tool_fail(error, TOOL_EXIT_USAGE, "--%s: must be in [%d, %d] (got %s)", flag,
                         minimum, maximum, text);
    *out = value;
    return TOOL_EXIT_SUCCESS;
}

static const option_spec *find_long_option(const char *name, size_t length) {
    for (size_t i = 0; i < OPTION_COUNT; ++i)
        if (strlen(option_specs[i].name) == length &&
            strncmp(option_specs[i].name, name, length) == 0)
            return &option_specs[i];
    return NULL;
}

static const option_spec *find_short_option(char name) {
    for (size_t i = 0; i < OPTION_COUNT; ++i)
        if (option_specs[i].short_name == name) return &option_specs[i];
    return NULL;
}

static int apply_option(const option_spec *spec, const char *value, cli_options *options,
                        tool_error *error) {
    hbao_params *params = &options->params;
    camera_settings *flags = &options->camera_flags;
    hbao_camera *camera = &flags->camera;
    const char *flag = spec->name;
    int status = TOOL_EXIT_SUCCESS;
    switch (spec->id) {
        case OPTION_OUTPUT:
            options->output_path = value;
            break;
        case OPTION_LAYER:
            options->layer = value;
            break;
        case OPTION_BACK_LAYER:
            options->back_layer = value;
            break;
        case OPTION_AO_CHANNEL:
            if (value[0] == '\0')
                return tool_fail(error, TOOL_EXIT_USAGE, "--ao-channel: the name is empty");
            /* OpenEXR's longest channel name (its long-name header flag);
             * found only at the write, after the whole computation */
            if (strlen(value) > AO_CHANNEL_NAME_MAX)
                return tool_fail(error, TOOL_EXIT_USAGE,
                                 "--ao-channel: the name has %zu bytes; EXR allows %d",
                                 strlen(value), AO_CHANNEL_NAME_MAX);
            options->ao_channel = value;
            break;
        case OPTION_KEEP_INPUT:
            options->keep_input = true;
            break;
        case OPTION_NO_NORMALS:
            options->ignore_normals = true;
            break;
        case OPTION_CROP_TO_DISPLAY:
            options->crop_to_display = true;
            break;
        case OPTION_OVERSCAN:
            status = parse_int_flag(flag, value, 0, HBAO_MAX_IMAGE_SIZE, &options->overscan, error);
            break;
        case OPTION_PREVIEW:
            options->preview_path = value;
            break;
        case OPTION_COMPRESSION: {
            int32_t compression = EXR_COMPRESSION_ZIP;
            status = parse_choice(flag, value, compression_choices, &compression, error);
            options->compression = (exr_compression_t)compression;
            break;
        }
        /* AO parameters: only the syntax here; their limits are libhbao's
     * (hbao_params_resolve, in resolve_params below). */
        case OPTION_RADIUS:
            status =
                parse_float_flag(flag, value, -FLT_MAX, FLT_MAX, false, &params->radius, error);
            break;
        case OPTION_THICKNESS:
            status =
                parse_float_flag(flag, value, -FLT_MAX, FLT_MAX, false, &params->thickness, error);
            break;
        case OPTION_ANGLE_BIAS:
            status = parse_float_flag(flag, value, -FLT_MAX, FLT_MAX, false,
                                      &params->angle_bias_degrees, error);
            break;
        case OPTION_DIRECTIONS:
            status = parse_int_flag(flag, value, INT32_MIN, INT32_MAX, &params->directions, error);
            break;
        case OPTION_STEPS:
            status = parse_int_flag(flag, value, INT32_MIN, INT32_MAX, &params->steps, error);
            break;
        case OPTION_BLUR:
            status = parse_int_flag(flag, value, INT32_MIN, INT32_MAX, &params->blur_size, error);
            break;
        case OPTION_BLUR_SHARPNESS:
            status = parse_float_flag(flag, value, -FLT_MAX, FLT_MAX, false,
                                      &params->blur_sharpness, error);
            break;
        case OPTION_HALF_RES:
            params->half_resolution = 1;
            break;
        case OPTION_FALLOFF:
            status = parse_choice(flag, value, falloff_choices, &params->falloff, error);
            break;
        case OPTION_INTEGRATION:
            status = parse_choice(flag, value, integration_choices, &params->integration, error);
            break;
        case OPTION_STRENGTH:
            status =
                parse_float_flag(flag, value, -FLT_MAX, FLT_MAX, false, &params->strength, error);
            break;
        case OPTION_THREADS:
            status = parse_int_flag(flag, value, INT32_MIN, INT32_MAX, &params->threads, error);
            break;
        case OPTION_CAMERA:
            options->camera_path = value;
            break;
        case OPTION_CAMERA_TYPE:
            status = parse_choice(flag, value, camera_type_choices, &camera->projection, error);
            flags->fields_set |= CAMERA_FIELD_PROJECTION;
            break;
        case OPTION_LENS:
            status = parse_float_flag(flag, value, 0.0f, FLT_MAX, true, &camera->lens, error);
            flags->fields_set |= CAMERA_FIELD_LENS;
            break;
        case OPTION_SENSOR_WIDTH:
            status =
                parse_float_flag(flag, value, 0.0f, FLT_MAX, true, &camera->sensor_width, error);
            flags->fields_set |= CAMERA_FIELD_SENSOR_WIDTH;
            break;
        case OPTION_SENSOR_HEIGHT:
            status =
                parse_float_flag(flag, value, 0.0f, FLT_MAX, true, &camera->sensor_height, error);
            flags->fields_set |= CAMERA_FIELD_SENSOR_HEIGHT;
            break;
        case OPTION_SENSOR_FIT:
            status = parse_choice(flag, value, sensor_fit_choices, &camera->sensor_fit, error);
            flags->fields_set |= CAMERA_FIELD_SENSOR_FIT;
            break;
        case OPTION_SHIFT_X:
            status =
                parse_float_flag(flag, value, -FLT_MAX, FLT_MAX, false, &camera->shift_x, error);
            flags->fields_set |= CAMERA_FIELD_SHIFT_X;
            break;
        case OPTION_SHIFT_Y:
            status =
                parse_float_flag(flag, value, -FLT_MAX, FLT_MAX, false, &camera->shift_y, error);
            flags->fields_set |= CAMERA_FIELD_SHIFT_Y;
            break;
        case OPTION_ORTHO_SCALE:
            /* An ortho scale only means something for an orthographic camera. */
            status =
                parse_float_flag(flag, value, 0.0f, FLT_MAX, true, &camera->ortho_scale, error);
            camera->projection = HBAO_PROJECTION_ORTHOGRAPHIC;
            flags->fields_set |= CAMERA_FIELD_ORTHO_SCALE | CAMERA_FIELD_PROJECTION;
            break;
        case OPTION_PIXEL_ASPECT_X:
            status =
                parse_float_flag(flag, value, 0.0f, FLT_MAX, true, &camera->pixel_aspect_x, error);
            flags->fields_set |= CAMERA_FIELD_PIXEL_ASPECT_X;
            break;
        case OPTION_PIXEL_ASPECT_Y:
            status =
                parse_float_flag(flag, value, 0.0f, FLT_MAX, true, &camera->pixel_aspect_y, error);
            flags->fields_set |= CAMERA_FIELD_PIXEL_ASPECT_Y;
            break;
        case OPTION_WORLD_TO_CAMERA:
            if (!parse_float_list(value, camera->world_to_camera, 16))
                return tool_fail(error, TOOL_EXIT_USAGE,
                                 "--world-to-camera: expected one argument holding 16 finite "
                                 "numbers (row-major, separated by commas or spaces), got \"%s\"",
                                 value);
            if (!matrix_is_usable(camera->world_to_camera))
                return tool_fail(error, TOOL_EXIT_USAGE,
                                 "--world-to-camera: \"%s\" is not a camera's matrix (its "
                                 "upper-left 3x3 part is singular or out of range); give "
                                 "camera.matrix_world inverted",
                                 value);
            flags->fields_set |= CAMERA_FIELD_WORLD_TO_CAMERA;
            break;
        case OPTION_FRAMES:
            if (!frame_list_parse(value, &options->frames))
                return tool_fail(error, TOOL_EXIT_USAGE,
                                 "--frames: \"%s\" is not a frame list like 1-250, 1-10,20 or "
                                 "1-250x2 (frames in [0, %d], at most %d ranges, no frame "
                                 "twice)",
                                 value, FRAME_MAX, FRAME_RANGES_MAX);
            break;
        case OPTION_JOBS:
            status = parse_int_flag(flag, value, 1, CLI_MAX_JOBS, &options->jobs, error);
            break;
        case OPTION_FORCE:
            options->force = true;
            break;
        case OPTION_INFO:
            options->mode = TOOL_MODE_INFO;
            break;
        case OPTION_JSON:
            options->info_json = true;
            break;
        case OPTION_HELP: /* asked_for_text, before parsing */
            break;
        case OPTION_VERSION:
            break;
    }
    return status;
}

/* The flag of each hbao_params field the command line sets. */
static const struct {
    uint32_t field;
    const char *flag;
} param_flags[] = {
    {HBAO_PARAM_FIELD_RADIUS, "radius"},
    {HBAO_PARAM_FIELD_ANGLE_BIAS_DEGREES, "angle-bias"},
    {HBAO_PARAM_FIELD_DIRECTIONS, "directions"},
    {HBAO_PARAM_FIELD_STEPS, "steps"},
    {HBAO_PARAM_FIELD_FALLOFF, "falloff"},
    {HBAO_PARAM_FIELD_INTEGRATION, "integration"},
    {HBAO_PARAM_FIELD_BLUR_SIZE, "blur"},
    {HBAO_PARAM_FIELD_BLUR_SHARPNESS, "blur-sharpness"},
    {HBAO_PARAM_FIELD_STRENGTH, "strength"},
    {HBAO_PARAM_FIELD_THREADS, "threads"},
    {HBAO_PARAM_FIELD_THICKNESS, "thickness"},
};

static double param_value(const hbao_params *params, uint32_t field) {
    switch (field) {
        case HBAO_PARAM_FIELD_RADIUS:
            return params->radius;
        case HBAO_PARAM_FIELD_ANGLE_BIAS_DEGREES:
            return params->angle_bias_degrees;
        case HBAO_PARAM_FIELD_DIRECTIONS:
            return params->directions;
        case HBAO_PARAM_FIELD_STEPS:
            return params->steps;
        case HBAO_PARAM_FIELD_BLUR_SIZE:
            return params->blur_size;
        case HBAO_PARAM_FIELD_BLUR_SHARPNESS:
            return params->blur_sharpness;
        case HBAO_PARAM_FIELD_STRENGTH:
            return params->strength;
        case HBAO_PARAM_FIELD_THREADS:
            return params->threads;
        case HBAO_PARAM_FIELD_THICKNESS:
            return params->thickness;
        default:
            return NAN;
    }
}

/* The library decides (hbao_params_resolve): like the add-on, the tool
 * clamps out-of-range values with one warning per value and goes on; only
 * values with no nearest legal value (a negative radius) are refused. */
static int resolve_params(hbao_params *params, tool_error *error) {
    hbao_params resolved;
    uint32_t fields = 0;
    hbao_result result = hbao_params_resolve(params, &resolved, &fields);
    for (size_t i = 0; i < sizeof param_flags / sizeof param_flags[0]; ++i) {
        if (!(fields & param_flags[i].field)) continue;
        const double given = param_value(params, param_flags[i].field);
        if (result != HBAO_SUCCESS)
            return tool_fail(error, TOOL_EXIT_USAGE, "--%s %g is not valid: %s",
                             param_flags[i].flag, given, hbao_result_message(result));
        const double limit = param_value(&resolved, param_flags[i].field);
        tool_warn("--%s %g is %s the limit %g; using %g", param_flags[i].flag, given,
                  given > limit ? "above" : "below", limit, limit);
    }
    if (result != HBAO_SUCCESS)
        return tool_fail(error, TOOL_EXIT_USAGE, "invalid parameters: %s",
                         hbao_result_message(result));
    *params = resolved;
    return TOOL_EXIT_SUCCESS;
}

static void options_init(cli_options *options) {
    memset(options, 0, sizeof *options);
    options->mode = TOOL_MODE_COMPUTE;
    options->compression = EXR_COMPRESSION_ZIP;
    options->ao_channel = "AO";
    options->jobs = 1;
    hbao_params defaults = HBAO_PARAMS_DEFAULT_INITIALIZER;
    options->params = defaults;
    camera_settings_init(&options->camera_flags);
}

/* The option an argument that starts with '-' names (NULL: none), and in
 * *inline_value the value given with it (NULL: none): after '=' for a long
 * option, right after the letter for a short one that takes a value (-j2,
 * -oout.exr, as getopt reads them). */
static const option_spec *option_of(const char *argument, const char **inline_value) {
    *inline_value = NULL;
    if (argument[1] == '-') {
        const char *name = argument + 2;
        const char *equals = strchr(name, '=');
        if (equals != NULL) *inline_value = equals + 1;
        return find_long_option(name, equals ? (size_t)(equals - name) : strlen(name));
    }
    const option_spec *spec = find_short_option(argument[1]);
    if (argument[2] == '\0' || spec == NULL) return spec;
    if (!spec->takes_value) return NULL; /* -hx: no such option */
    *inline_value = argument + 2;
    return spec;
}

/* Options that name a file, a layer or the frames: given twice, which one
 * was meant is not known (a farm's wrapper adding --frames to a user's),
 * so that is refused; a number given twice takes the last, as usual. */
static bool given_once(option_id id) {
    return id == OPTION_OUTPUT || id == OPTION_PREVIEW || id == OPTION_CAMERA ||
           id == OPTION_FRAMES || id == OPTION_LAYER || id == OPTION_BACK_LAYER;
}

/* --help (-h) or --version given as an option anywhere before "--": they
 * win over everything else, a bad value of another flag too (hbao --radius
 * abc --help). A flag's value that reads "-h" (--layer -h) is a value. */
static tool_mode asked_for_text(int argc, char **argv) {
    bool version = false;
    for (int i = 1; i < argc && strcmp(argv[i], "--") != 0; ++i) {
        if (argv[i][0] != '-' || strcmp(argv[i], "-") == 0) continue;
        const char *inline_value;
        const option_spec *spec = option_of(argv[i], &inline_value);
        if (spec == NULL) continue;
        if (spec->id == OPTION_HELP) return TOOL_MODE_HELP;
        version |= spec->id == OPTION_VERSION;
        if (spec->takes_value && inline_value == NULL) ++i; /* its value, whatever it reads */
    }
    return version ? TOOL_MODE_VERSION : TOOL_MODE_COMPUTE;
}

int cli_parse(int argc, char **argv, cli_options *options, tool_error *error) {
    options_init(options);
    const tool_mode text = asked_for_text(argc, argv);
    if (text != TOOL_MODE_COMPUTE) {
        options->mode = text;
        return TOOL_EXIT_SUCCESS;
    }
    bool only_positionals = false;
    bool given[OPTION_COUNT] = {false};
    /* the first option, as typed, that does nothing with --info (every one
     * but --info and --json) */
    const char *not_for_info = NULL;
    for (int i = 1; i < argc; ++i) {
        const char *argument = argv[i];
        if (only_positionals || argument[0] != '-' || strcmp(argument, "-") == 0) {
            if (options->input_path != NULL)
                return tool_fail(error, TOOL_EXIT_USAGE,
                                 "more than one input file (\"%s\" and \"%s\")",
                                 options->input_path, argument);
            options->input_path = argument;
            continue;
        }
        if (strcmp(argument, "--") == 0) {
            only_positionals = true;
            continue;
        }
        const char *inline_value;
        const option_spec *spec = option_of(argument, &inline_value);
        /* -output=ao.exr would be -o with "utput=ao.exr" attached */
        const char *name = argument + 1, *equals = strchr(name, '=');
        const option_spec *meant =
            argument[1] != '-'
                ? find_long_option(name, equals ? (size_t)(equals - name) : strlen(name))
                : NULL;
        if (meant != NULL && argument[2] != '\0')
            return tool_fail(error, TOOL_EXIT_USAGE, "unknown option %s (did you mean --%s?)",
                             argument, meant->name);
        if (spec == NULL)
            return tool_fail(error, TOOL_EXIT_USAGE, "unknown option %s (see hbao --help)",
                             argument);
        const size_t index = (size_t)(spec - option_specs);
        if (given[index] && given_once(spec->id)) {
            if (spec->short_name != 0)
                return tool_fail(error, TOOL_EXIT_USAGE, "-%c (--%s) is given twice: give it once",
                                 spec->short_name, spec->name);
            return tool_fail(error, TOOL_EXIT_USAGE, "--%s is given twice: give it once",
                             spec->name);
        }
        given[index] = true;
        if (not_for_info == NULL && spec->id != OPTION_INFO && spec->id != OPTION_JSON)
            not_for_info = argument;
        const char *value = NULL;
        if (spec->takes_value) {
            if (inline_value != NULL) {
                value = inline_value;
            } else {
                if (i + 1 >= argc)
                    return tool_fail(error, TOOL_EXIT_USAGE, "%s needs a value", argument);
                value = argv[++i];
            }
        } else if (inline_value != NULL) {
            return tool_fail(error, TOOL_EXIT_USAGE, "--%s takes no value", spec->name);
        }
        int status = apply_option(spec, value, options, error);
        if (status != TOOL_EXIT_SUCCESS) return status;
    }

    if (options->input_path == NULL)
        return tool_fail(error, TOOL_EXIT_USAGE,
                         "no input file (usage: hbao INPUT.exr -o "
                         "OUTPUT.exr [options]; see hbao --help)");
    const bool sequence = options->frames.range_count > 0;
    if (options->mode == TOOL_MODE_INFO) {
        if (options->output_path != NULL || options->preview_path != NULL)
            return tool_fail(error, TOOL_EXIT_USAGE, "--info writes nothing: drop -o/--preview");
        if (sequence)
            return tool_fail(error, TOOL_EXIT_USAGE, "--info reads one file: drop --frames");
        /* a flag that would change nothing there (--layer, --radius -1, -j)
         * is refused rather than ignored: its user expected an effect */
        if (not_for_info != NULL)
            return tool_fail(error, TOOL_EXIT_USAGE,
                             "--info prints what the file holds and takes only --json: drop %s",
                             not_for_info);
        return TOOL_EXIT_SUCCESS;
    }
    if (!sequence && (options->jobs != 1 || options->force))
        return tool_fail(error, TOOL_EXIT_USAGE, "--jobs and --force go with --frames");
    if (options->info_json)
        return tool_fail(error, TOOL_EXIT_USAGE, "--json only goes with --info");
    if (options->crop_to_display && options->overscan > 0)
        return tool_fail(error, TOOL_EXIT_USAGE,
                         "--overscan and --crop-to-display each choose what is written: give one");
    if (options->output_path == NULL)
        return tool_fail(error, TOOL_EXIT_USAGE, "no output file: give -o OUTPUT.exr");
    if (options->output_path[0] == '\0' ||
        (options->preview_path != NULL && options->preview_path[0] == '\0') ||
        options->input_path[0] == '\0')
        return tool_fail(error, TOOL_EXIT_USAGE, "a file name is empty");
    /* "-" is no file name here: a file called "-" is rarely meant */
    if (strcmp(options->input_path, "-") == 0)
        return tool_fail(error, TOOL_EXIT_USAGE,
                         "the input is \"-\": the tool reads an EXR file, not standard input "
                         "(./- for a file named -)");
    const char *dash = strcmp(options->output_path, "-") == 0 ? "-o"
                       : options->preview_path != NULL && strcmp(options->preview_path, "-") == 0
                           ? "--preview"
                           : NULL;
    if (dash != NULL)
        return tool_fail(error, TOOL_EXIT_USAGE,
                         "%s is \"-\": give /dev/stdout for standard output, or ./- for a file "
                         "named -",
                         dash);
    if (options->preview_path != NULL && strcmp(options->preview_path, options->output_path) == 0)
        return tool_fail(error, TOOL_EXIT_USAGE, "--preview and -o name the same file");
    if (sequence) {
        /* Each frame needs its own files: a name without '#' would be
         * read (or overwritten) by every frame. */
        const char *paths[] = {options->input_path, options->output_path, options->preview_path};
        const char *flags[] = {"the input", "-o", "--preview"};
        for (int p = 0; p < 3; ++p)
            if (paths[p] != NULL && !frame_pattern_has_frame(paths[p]))
                return tool_fail(error, TOOL_EXIT_USAGE,
                                 "with --frames, %s (%s) needs a '#' run for the frame number, "
                                 "e.g. render_####.exr",
                                 flags[p], paths[p]);
        options->mode = TOOL_MODE_SEQUENCE;
    }
    return resolve_params(&options->params, error);
}

void cli_print_help(FILE *stream) {
    const hbao_camera camera = HBAO_CAMERA_DEFAULT_INITIALIZER;
    fprintf(
        stream,
        "usage: hbao INPUT.exr -o OUTPUT.exr [options]\n"
        "       hbao --info FILE.exr [--json]\n"
        "\n"
        "Horizon-based ambient occlusion from the Depth (and Normal) pass of a Blender\n"
        "multilayer OpenEXR render. Writes an EXR whose float channel `AO` holds the\n"
        "occlusion: 1 = unoccluded, 0 = fully occluded; background pixels get 1.\n"
        "\n"
        "Input and output:\n"
        "  -o, --output FILE       output EXR (required). Written to a temporary file\n"
        "                          .hbao-tmp-XXXXXX next to it and renamed over it when\n"
        "                          complete, so it appears whole or not at all; never the\n"
        "                          input, the --camera file or the preview. An input\n"
        "                          changed while its AO was computed gets no output\n"
        "                          (exit 1). A symbolic link is followed: its target is\n"
        "                          replaced, the link kept. A FIFO or character device\n"
        "                          (/dev/null, /dev/stdout) is written through, never\n"
        "                          replaced; a reader that closes its end early is a\n"
        "                          write error. A directory, block device or socket is\n"
        "                          refused (exit 2). Ctrl-C, SIGTERM and SIGHUP remove\n"
        "                          the temporary files; where one has a name (no\n"
        "                          O_TMPFILE: NFS before 4.2) and SIGKILL left it, the\n"
        "                          next run there removes it after a day. The same\n"
        "                          holds for --preview.\n"
        "  --layer NAME            view layer to use (channels NAME.Depth.Z and, if\n"
        "                          present, NAME.Normal.X/Y/Z). Default: the one layer\n"
        "                          with a Depth pass (besides --back-layer; with several,\n"
        "                          an error lists them); a plain `Depth.Z`, `Depth.V` (a\n"
        "                          File Output node's) or `Z` channel is used if no layer\n"
        "                          has one.\n"
        "  --back-layer NAME       view layer whose Depth pass holds the back faces (a\n"
        "                          layer rendered with front faces transparent, e.g. a\n"
        "                          material override, 1 sample): an occluder then spans\n"
        "                          only its front to its back (at least half the radius),\n"
        "                          so light passes between it and what is behind it.\n"
        "  --no-normals            ignore the Normal pass; reconstruct normals from depth.\n"
        "  --ao-channel NAME       name of the output channel (default AO). `Y` makes\n"
        "                          image viewers and Blender show the AO as grayscale.\n"
        "  --keep-input            also copy every input channel (same names and pixel\n"
        "                          types) and header attributes into the output; an input\n"
        "                          channel with the AO channel's name is replaced.\n"
        "  --crop-to-display       write only the part of the data window inside the\n"
        "                          display window (see Data window below).\n"
        "  --overscan N            the input is the frame rendered N pixels wider on every\n"
        "                          side (resolution + 2N, sensor or ortho scale grown in\n"
        "                          proportion; its own camera): the AO uses all of it, so\n"
        "                          the frame's borders see occluders just outside, and the\n"
        "                          output is the centre frame only. Not with\n"
        "                          --crop-to-display.\n"
        "  --compression METHOD    none, rle, zips, zip (default) or piz (lossless only).\n"
        "  --preview FILE.png      also write the AO as an 8-bit grayscale PNG: the linear\n"
        "                          AO value 0..1 maps to 0..255, no gamma curve.\n"
        "  --info                  print the file's layout (layers, channels, pixel types,\n"
        "                          compression, windows) and per-channel min/max/mean of\n"
        "                          the finite values and the count of non-finite ones.\n"
        "  --json                  with --info: print it as JSON.\n"
        "\n"
        "AO parameters (defaults and limits from libhbao; a value outside its range is\n"
        "clamped to it, with a warning, as the Blender add-on does; a number too\n"
        "large for its type, such as --steps 99999999999, is an error):\n"
        "  --radius R              AO radius in scene units (>= 0, else an error;\n"
        "                          default %g)\n"
        "  --angle-bias DEG        ignore occluders this far above the tangent plane\n"
        "                          [0, %g] (default %g)\n"
        "  --directions N          directions per pixel [1, %d] (default %d)\n"
        "  --steps N               steps per direction [1, %d] (default %d)\n"
        "  --blur N                bilateral blur width in pixels [0, %d]; 0 to 2 = off,\n"
        "                          an even N blurs as N - 1 (default %d)\n"
        "  --blur-sharpness S      how strongly the blur stops at depth edges [0, %g]\n"
        "                          (default %g)\n"
        "  --half-res              compute at half resolution, upsample depth-aware\n"
        "  --falloff F             none (default: what Cycles' AO pass measures) or\n"
        "                          quadratic (HBAO's 1 - (d/radius)^2 attenuation)\n"
        "  --integration I         cosine (default: what Cycles' AO pass measures) or hbao\n"
        "  --strength S            ao = ao^S, [0, %g] (default %g)\n"
        "  --threads N             worker threads, at most %d; 0 (or less) = one per\n"
        "                          core it may run on (default; taskset and containers\n"
        "                          narrow them). They read the input, compute the AO\n"
        "                          and compress the output; the output file does not\n"
        "                          depend on their number\n"
        "  --thickness T           occluder thickness in scene units (>= 0, else an\n"
        "                          error): a sample more than T nearer than the pixel\n"
        "                          does not occlude it (no halo on the background behind\n"
        "                          an object). 0 = infinitely thick (default)\n"
        "\n"
        "Camera (Blender's camera model and names; flags override --camera):\n"
        "  --camera FILE.json      JSON object with Blender's property names: type\n"
        "                          (\"PERSP\"/\"ORTHO\"), lens, sensor_width, sensor_height,\n"
        "                          sensor_fit (\"AUTO\"/\"HORIZONTAL\"/\"VERTICAL\"), shift_x,\n"
        "                          shift_y, ortho_scale, pixel_aspect_x, pixel_aspect_y,\n"
        "                          world_to_camera (4 rows of 4 numbers), clip_end and\n"
        "                          clip_start (a depth at the clip end, within what a long\n"
        "                          clip range rounds, or beyond is background). Missing keys keep\n"
        "                          their defaults (world_to_camera has none where the\n"
        "                          Normal pass is used: an error); unknown keys are ignored.\n"
        "  --camera-type T         PERSP or ORTHO\n"
        "  --lens MM               focal length (default %g)\n"
        "  --sensor-width MM       (default %g)\n"
        "  --sensor-height MM      (default %g)\n"
        "  --sensor-fit FIT        AUTO (default), HORIZONTAL or VERTICAL\n"
        "  --shift-x S, --shift-y S  lens shift in units of the fitted sensor side\n"
        "  --ortho-scale S         orthographic view size; implies --camera-type ORTHO\n"
        "  --pixel-aspect-x A, --pixel-aspect-y A\n"
        "                          default: x = the EXR header's pixelAspectRatio, y = 1\n"
        "  --world-to-camera \"M\"   ONE argument holding the 16 numbers of the row-major\n"
        "                          world-to-camera matrix (camera.matrix_world inverted),\n"
        "                          separated by commas and/or spaces, e.g.\n"
        "                          --world-to-camera \"1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1\".\n"
        "                          It maps Blender's world-space Normal pass into camera\n"
        "                          space. A --camera file without world_to_camera is an\n"
        "                          error when the Normal pass is used; with no camera at\n"
        "                          all the identity is used, i.e. normals are taken as\n"
        "                          already in camera space: wrong for Blender's Normal pass\n"
        "                          unless the camera sits at the origin looking down -Z, so\n"
        "                          the tool warns; pass the matrix or --no-normals.\n"
        "\n"
        "Sequences:\n"
        "  --frames LIST           compute every frame of LIST (1-250, or 1-10,20,30-40;\n"
        "                          1-250x2 every second frame, as Blender's Frame Step 2\n"
        "                          renders them; frames in [0, %d]). The input, -o and\n"
        "                          --preview names must hold a run of '#', replaced by\n"
        "                          the frame number zero-padded to the run's length, as\n"
        "                          Blender names frames: hbao 'render_####.exr' -o\n"
        "                          'ao_####.exr'\n"
        "                          --frames 1-250; up to %d comma-separated ranges. An\n"
        "                          output at least as new as its input, computed with\n"
        "                          the same settings (its header's hbaoSettings: the\n"
        "                          parameters, camera and layers used, however the\n"
        "                          flags or --camera file said them; the file counts by\n"
        "                          what it holds, not its time), with a --preview at\n"
        "                          least as new as itself, is up to date and skipped.\n"
        "                          An output or preview name that is another listed\n"
        "                          frame's input, camera, output or preview, or the one\n"
        "                          --camera file (by its name, or through a symbolic\n"
        "                          link), is refused (exit 2) before any frame runs. A\n"
        "                          --camera file name with a '#' run gives each frame\n"
        "                          its camera file (an animated camera:\n"
        "                          scripts/export_cameras.py writes them), as does a\n"
        "                          '#' run in a folder's name where no file has the\n"
        "                          path as written; without one the file is read once,\n"
        "                          for all.\n"
        "                          An output older than its input whose seal names the\n"
        "                          input as it is (an input dated ahead of this clock)\n"
        "                          is up to date too. Frames whose input is not there\n"
        "                          fail first, in one line (none there: an error, and\n"
        "                          nothing runs); then one progress line per frame.\n"
        "                          Every other frame is attempted, and the exit status\n"
        "                          is 1 (2 for a usage error in a frame) when any\n"
        "                          failed, with the failed frames as ranges (3, 7-9).\n"
        "  -j, --jobs N            frames computed at once [1, %d] (default 1); without\n"
        "                          --threads, each frame gets cores / N threads\n"
        "  --force                 recompute frames that are up to date\n"
        "\n"
        "Data window: the tool works on the EXR's data window and writes the output with\n"
        "the same data and display windows; when the data window is a part of the\n"
        "display window, the camera is adjusted to that part (same view rays). A data\n"
        "window that reaches past the display window (overscan) is a guard band: the\n"
        "camera describes the display window and is widened to the data window (same\n"
        "view rays for the display window's pixels), so occluders just outside the\n"
        "frame darken its borders; the whole data window gets AO, and viewers that show\n"
        "the display window (Blender) show the frame. --crop-to-display keeps only the\n"
        "frame's pixels (an error when the windows do not overlap). Blender\n"
        "itself always writes data window = display window: a border render without\n"
        "cropping is a full frame (unrendered pixels are background, AO 1); with\n"
        "\"Crop to Render Region\" nothing in the file says where the region was, so\n"
        "the camera must describe the cropped view (sensor and shift).\n"
        "\n"
        "Exit status: 0 success, 1 runtime error (unreadable or corrupt file, cannot\n"
        "write), 2 usage error (bad flag or value, output would overwrite the input).\n"
        "  -h, --help              this help\n"
        "  --version               print the tool's and libhbao's versions\n",
        (double)HBAO_DEFAULT_RADIUS, (double)HBAO_MAX_ANGLE_BIAS_DEGREES,
        (double)HBAO_DEFAULT_ANGLE_BIAS_DEGREES, HBAO_MAX_DIRECTIONS, HBAO_DEFAULT_DIRECTIONS,
        HBAO_MAX_STEPS, HBAO_DEFAULT_STEPS, HBAO_MAX_BLUR_SIZE, HBAO_DEFAULT_BLUR_SIZE,
        (double)HBAO_MAX_BLUR_SHARPNESS, (double)HBAO_DEFAULT_BLUR_SHARPNESS,
        (double)HBAO_MAX_STRENGTH, (double)HBAO_DEFAULT_STRENGTH, HBAO_MAX_THREADS,
        (double)camera.lens, (double)camera.sensor_width, (double)camera.sensor_height, FRAME_MAX,
        FRAME_RANGES_MAX, CLI_MAX_JOBS);
}
