/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "ao_command.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "ao_plan.h"
#include "atomic_file.h"
#include "blender_layers.h"
#include "exr_reader.h"
#include "exr_writer.h"
#include "huge_block.h"
#include "output_seal.h"
#include "png_writer.h"
#include "run_settings.h"

/* Refuse an output path that is the input file itself, through any name
 * (hard link, symbolic link, "./x" vs "x"): stat() identity, not strings.
 * What else may be written is atomic_file_begin()'s rule. */
/* An output that is one of the run's input files: the EXR, or the camera
 * file (compared by file, whatever the names). */
static int refuse_overwriting_input(const char *output, const char *flag,
                                    const struct stat *input_status, const char *camera_path,
                                    tool_error *error) {
    struct stat output_status, camera_status;
    if (stat(output, &output_status) != 0) return TOOL_EXIT_SUCCESS;
    if (output_status.st_dev == input_status->st_dev &&
        output_status.st_ino == input_status->st_ino)
        return tool_fail(error, TOOL_EXIT_USAGE,
                         "%s %s is the input file; refusing to overwrite it", flag, output);
    if (camera_path != NULL && stat(camera_path, &camera_status) == 0 &&
        S_ISREG(camera_status.st_mode) && output_status.st_dev == camera_status.st_dev &&
        output_status.st_ino == camera_status.st_ino)
        return tool_fail(error, TOOL_EXIT_USAGE,
                         "%s %s is the --camera file; refusing to overwrite it", flag, output);
    return TOOL_EXIT_SUCCESS;
}

/* An existing output (flag: -o or --preview) that is a render (an EXR with
 * a Depth pass the tool would read) but not an hbao output (no
 * RUN_SETTINGS_ATTRIBUTE): an -o pattern that lands on another chunk's
 * renders (-o 'render_00#0.exr' --frames 1-2 names render_0010.exr)
 * replaced them, and a --preview pattern or path did so too (with a PNG).
 * A file that is no readable EXR, or one without a Depth pass, is replaced
 * as before. */
static int refuse_replacing_a_render(const char *output, const char *flag, tool_error *error) {
    struct stat status;
    if (stat(output, &status) != 0 || !S_ISREG(status.st_mode)) return TOOL_EXIT_SUCCESS;
    exr_input existing;
    tool_error ignored = {{0}};
    if (exr_input_open(&existing, output, &ignored) != TOOL_EXIT_SUCCESS) return TOOL_EXIT_SUCCESS;
    blender_passes passes;
    const bool render =
        !run_settings_stamped(existing.context) &&
        (blender_depth_layers(&existing, NULL, 0) > 0 ||
         blender_find_passes(&existing, NULL, NULL, &passes, &ignored) == TOOL_EXIT_SUCCESS);
    exr_input_close(&existing);
    if (!render) return TOOL_EXIT_SUCCESS;
    return tool_fail(error, TOOL_EXIT_USAGE,
                     "%s %s is a render (it has a Depth pass), not an hbao output: refusing to "
                     "replace it (remove it first if it is to go)",
                     flag, output);
}

/* The input replaced or rewritten since it was opened (a render farm
 * re-rendering the frame while its AO was computed): the AO is of the old
 * render, and an output written now would be newer than the new one, so
 * that a sequence's rerun would skip the frame. Nothing is written; a rerun
 * computes it. */
static int refuse_changed_input(const exr_input *input, tool_error *error) {
    struct stat now;
    const struct stat *then = &input->file_status;
    if (stat(input->path, &now) == 0 && now.st_dev == then->st_dev && now.st_ino == then->st_ino &&
        now.st_size == then->st_size && now.st_mtim.tv_sec == then->st_mtim.tv_sec &&
        now.st_mtim.tv_nsec == then->st_mtim.tv_nsec)
        return TOOL_EXIT_SUCCESS;
    return tool_fail(error, TOOL_EXIT_RUNTIME,
                     "%s changed while its AO was computed (re-rendered?); nothing written: "
                     "run again",
                     input->path);
}

void ao_buffers_free(ao_buffers *buffers) {
    hbao_huge_block_free(buffers->depth);
    hbao_huge_block_free(buffers->normal);
    hbao_huge_block_free(buffers->back);
    hbao_huge_block_free(buffers->ao);
    for (int c = 0; c < buffers->copy_count; ++c) free(buffers->copies[c]);
    free(buffers->copies);
    memset(buffers, 0, sizeof *buffers);
}

static exr_channel_request float_request(const char *name, float *data, int components,
                                         int32_t width) {
    exr_channel_request request = {name, EXR_PIXEL_FLOAT, (uint8_t *)data,
                                   (int32_t)(components * sizeof(float)),
                                   (int64_t)width * components * (int64_t)sizeof(float)};
    return request;
}

/* A pass stored as unsigned integers (an object or material index, a
 * Cryptomatte hash written by another program) is no length or direction:
 * read as floats it gave AO from whatever those integers were, silently. */
static int refuse_integer_pass(const exr_input *input, const char *name, const char *what,
                               tool_error *error) {
    const int index = exr_input_find_channel(input, name);
    if (index < 0 || input->channels->entries[index].pixel_type != EXR_PIXEL_UINT)
        return TOOL_EXIT_SUCCESS;
    return tool_fail(error, TOOL_EXIT_RUNTIME,
                     "%s: \"%s\" holds unsigned integers, not %s (Blender writes half or "
                     "float); check which channel holds them%s",
                     input->path, name, what,
                     strcmp(what, "normals") == 0 ? ", or leave them out with --no-normals" : "");
}

/* A pass stored with loss (half floats with B44, as other programs write
 * them; Blender writes Depth and Normal as float): the AO shows the codec's
 * error in 4x4 blocks. Read all the same, with a warning per pass. */
static void warn_lossy_pass(const exr_input *input, const char *const *names, int count) {
    for (int c = 0; c < count; ++c)
        if (exr_input_channel_is_lossy(input, exr_input_find_channel(input, names[c]))) {
            tool_warn("%s: \"%s\" is stored as half floats with B44 compression, which loses "
                      "detail in them: the AO may show 4x4 blocks; store the pass as float, or "
                      "with a lossless compression (ZIP, PIZ)",
                      input->path, names[c]);
            return;
        }
}

static int read_passes(exr_input *input, const blender_passes *passes, bool use_normals,
                       const blender_passes *back, ao_buffers *buffers, tool_error *error) {
    const char *depth[1] = {passes->depth};
    const char *normal[3] = {passes->normal[0], passes->normal[1], passes->normal[2]};
    warn_lossy_pass(input, depth, 1);
    if (use_normals) warn_lossy_pass(input, normal, 3);
    int status = refuse_integer_pass(input, passes->depth, "depths", error);
    for (int axis = 0; axis < 3 && use_normals && status == TOOL_EXIT_SUCCESS; ++axis)
        status = refuse_integer_pass(input, passes->normal[axis], "normals", error);
    if (status == TOOL_EXIT_SUCCESS && back != NULL)
        status = refuse_integer_pass(input, back->depth, "depths", error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    const size_t pixel_count = (size_t)input->width * (size_t)input->height;
    /* The planes in huge pages (csrc/memory/huge_block.h); --keep-input's
     * copies of every channel stay in malloc's memory: in huge pages too (120
     * MB a 1080p frame), that frame took 1.03-1.05 of the time on the VM
     * measured, whose kernel cleared huge pages it had not used lately at a
     * tenth of the speed (a 320 MB buffer: 250 ms the first time, 34 ms the
     * next; docs/speed.md, session 63). */
    buffers->depth = hbao_huge_block_alloc(pixel_count * sizeof(float));
    buffers->ao = hbao_huge_block_alloc(pixel_count * sizeof(float));
    if (use_normals) buffers->normal = hbao_huge_block_alloc(3 * pixel_count * sizeof(float));
    if (back != NULL) buffers->back = hbao_huge_block_alloc(pixel_count * sizeof(float));
    if (buffers->depth == NULL || buffers->ao == NULL || (use_normals && buffers->normal == NULL) ||
        (back != NULL && buffers->back == NULL))
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "%s: out of memory reading the passes of a %dx%d image (%.0f MB)",
                         input->path, input->width, input->height,
                         (double)pixel_count * (8 + (use_normals ? 12 : 0) + (back ? 4 : 0)) / 1e6);
    exr_channel_request requests[5];
    int count = 0;
    requests[count++] = float_request(passes->depth, buffers->depth, 1, input->width);
    if (back != NULL) {
        if (strcmp(back->depth, passes->depth) == 0)
            return tool_fail(error, TOOL_EXIT_USAGE,
                             "--back-layer: %s is the layer the AO is computed from", back->depth);
        requests[count++] = float_request(back->depth, buffers->back, 1, input->width);
    }
    for (int axis = 0; axis < 3 && use_normals; ++axis)
        requests[count++] =
            float_request(passes->normal[axis], buffers->normal + axis, 3, input->width);
    return exr_input_read(input, requests, count, error);
}

/* --keep-input: every channel but a previous AO, decoded in its own type. */
static int read_copies(exr_input *input, const char *ao_channel, ao_buffers *buffers,
                       exr_output_channel *outputs, int *output_count, tool_error *error) {
    const int channel_count = input->channels->num_channels;
    const size_t pixel_count = (size_t)input->width * (size_t)input->height;
    buffers->copies = calloc((size_t)channel_count, sizeof *buffers->copies);
    exr_channel_request *requests = calloc((size_t)channel_count, sizeof *requests);
    if (buffers->copies == NULL || requests == NULL) {
        free(requests);
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "%s: out of memory keeping the input's channels (--keep-input)",
                         input->path);
    }
    int count = 0;
    for (int c = 0; c < channel_count; ++c) {
        const exr_attr_chlist_entry_t *channel = &input->channels->entries[c];
        if (strcmp(channel->name.str, ao_channel) == 0) {
            tool_warn("%s: replacing the input's channel \"%s\" with the new AO", input->path,
                      ao_channel);
            continue;
        }
        const int size = exr_pixel_type_size(channel->pixel_type);
        uint8_t *data = malloc(pixel_count * (size_t)size);
        if (data == NULL) {
            free(requests);
            return tool_fail(error, TOOL_EXIT_RUNTIME,
                             "%s: out of memory keeping the input's channel \"%s\" (--keep-input)",
                             input->path, channel->name.str);
        }
        buffers->copies[buffers->copy_count++] = data;
        exr_channel_request request = {channel->name.str, channel->pixel_type, data, size,
                                       (int64_t)input->width * size};
        requests[count] = request;
        exr_output_channel output = {channel->name.str,
                                     channel->pixel_type,
                                     (exr_perceptual_treatment_t)channel->p_linear,
                                     data,
                                     size,
                                     (int64_t)input->width * size};
        outputs[(*output_count)++] = output;
        ++count;
    }
    int status = exr_input_read(input, requests, count, error);
    free(requests);
    return status;
}

/* The outputs' temporary files exist from before the computation to the
 * end: an unwritable folder fails before any work, and an interruption at
 * any point is cleaned up (atomic_file.h). */
typedef struct output_files {
    atomic_file exr, png;
} output_files;

static int begin_outputs(const cli_options *options, output_files *files, tool_error *error) {
    int status = atomic_file_begin(&files->exr, options->output_path, error);
    if (status == TOOL_EXIT_SUCCESS)
        status = refuse_replacing_a_render(options->output_path, "-o", error);
    if (status == TOOL_EXIT_SUCCESS && options->preview_path != NULL)
        status = atomic_file_begin(&files->png, options->preview_path, error);
    if (status == TOOL_EXIT_SUCCESS && options->preview_path != NULL)
        status = refuse_replacing_a_render(options->preview_path, "--preview", error);
    if (status == TOOL_EXIT_SUCCESS && atomic_file_same_destination(&files->exr, &files->png))
        status = tool_fail(error, TOOL_EXIT_USAGE, "--preview %s and -o %s name the same file",
                           options->preview_path, options->output_path);
    return status;
}

static void abort_outputs(output_files *files) {
    atomic_file_abort(&files->exr);
    atomic_file_abort(&files->png);
}

/* What the output holds: `source`, the part of the input's data window
 * written (input coordinates), and the output's data and display windows.
 * By default all of it, with the input's windows; --crop-to-display: its
 * part inside the display window; --overscan N: a render widened by N pixels
 * on every side, written as the centre frame (its windows moved back to the
 * input's origin, as the frame's own render would have them). */
typedef struct output_windows {
    pixel_rect source, data, display;
} output_windows;

static int choose_output_windows(const cli_options *options, const exr_input *input,
                                 output_windows *out, tool_error *error) {
    const pixel_rect *data = &input->data_window, *display = &input->display_window;
    out->source = *data;
    out->data = *data;
    out->display = *display;
    if (options->crop_to_display) {
        pixel_rect *w = &out->source;
        w->min_x = data->min_x > display->min_x ? data->min_x : display->min_x;
        w->min_y = data->min_y > display->min_y ? data->min_y : display->min_y;
        w->max_x = data->max_x < display->max_x ? data->max_x : display->max_x;
        w->max_y = data->max_y < display->max_y ? data->max_y : display->max_y;
        if (w->min_x > w->max_x || w->min_y > w->max_y)
            return tool_fail(error, TOOL_EXIT_RUNTIME,
                             "%s: --crop-to-display: the data window does not overlap the "
                             "display window",
                             options->input_path);
        out->data = *w;
    } else if (options->overscan > 0) {
        const int64_t band = options->overscan;
        if (memcmp(data, display, sizeof *data) != 0)
            return tool_fail(error, TOOL_EXIT_RUNTIME,
                             "%s: --overscan: the data window must be the display window (a "
                             "plain render)",
                             options->input_path);
        if (2 * band >= input->width || 2 * band >= input->height)
            return tool_fail(error, TOOL_EXIT_RUNTIME,
                             "%s: --overscan %lld leaves no frame inside the %dx%d image",
                             options->input_path, (long long)band, input->width, input->height);
        out->source.min_x = (int32_t)(data->min_x + band);
        out->source.min_y = (int32_t)(data->min_y + band);
        out->source.max_x = (int32_t)(data->max_x - band);
        out->source.max_y = (int32_t)(data->max_y - band);
        out->data = out->source;
        out->data.min_x = data->min_x;
        out->data.min_y = data->min_y;
        out->data.max_x = (int32_t)(data->max_x - 2 * band);
        out->data.max_y = (int32_t)(data->max_y - 2 * band);
        out->display = out->data;
    }
    return TOOL_EXIT_SUCCESS;
}

static int write_outputs(const cli_options *options, const exr_input *input,
                         exr_output_channel *channels, int channel_count, const float *ao,
                         const ao_plan *plan, output_files *files, tool_error *error) {
    output_windows windows;
    int status = choose_output_windows(options, input, &windows, error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    /* Each channel's data moved to the written part's top-left pixel. */
    const int64_t columns = (int64_t)windows.source.min_x - input->data_window.min_x;
    const int64_t rows = (int64_t)windows.source.min_y - input->data_window.min_y;
    for (int c = 0; c < channel_count; ++c)
        channels[c].data += rows * channels[c].row_stride + columns * channels[c].pixel_stride;
    const pixel_rect *window = &windows.source;
    exr_output_layout layout = {windows.data,
                                windows.display,
                                input->pixel_aspect_ratio,
                                input->screen_window_center,
                                input->screen_window_width,
                                options->compression,
                                options->keep_input ? input->context : NULL,
                                NULL,
                                NULL,
                                input->threads}; /* as many as the AO and the read */
    char settings[RUN_SETTINGS_MAX];
    if (run_settings_text(options, plan, settings)) {
        layout.stamp_name = RUN_SETTINGS_ATTRIBUTE;
        layout.stamp_text = settings;
    }
    status = exr_write_image(files->exr.fd, options->output_path, &layout, channels, channel_count,
                             error);
    if (status == TOOL_EXIT_SUCCESS)
        output_seal_attach(files->exr.fd, input->path, &input->file_status);
    if (status == TOOL_EXIT_SUCCESS && options->preview_path != NULL) {
        status =
            png_write_gray(files->png.fd, options->preview_path, ao + rows * input->width + columns,
                           window->max_x - window->min_x + 1, window->max_y - window->min_y + 1,
                           input->width, error);
        /* sealed as computed from the EXR, whose own seal names the input */
        struct stat exr_status;
        if (status == TOOL_EXIT_SUCCESS && fstat(files->exr.fd, &exr_status) == 0)
            output_seal_attach(files->png.fd, options->output_path, &exr_status);
    }
    /* Both files are complete: only now replace the destinations, unless the
     * input changed while it was read. A FIFO's or device's first (its data
     * is copied at commit: a full device, a reader gone), so that its
     * failure leaves a file's destination as it was: --preview /dev/full
     * failed after -o had been replaced (a review's find). */
    if (status == TOOL_EXIT_SUCCESS) status = refuse_changed_input(input, error);
    atomic_file *order[2] = {&files->exr, &files->png};
    if (files->png.active && files->png.write_through && !files->exr.write_through) {
        order[0] = &files->png;
        order[1] = &files->exr;
    }
    for (int k = 0; k < 2 && status == TOOL_EXIT_SUCCESS; ++k)
        if (order[k]->active) status = atomic_file_commit(order[k], error);
    return status;
}

/* A depth that is the same everywhere gives AO 1 everywhere: Blender writes
 * a single-layer EXR's Z as 1 where the Composite node's Z input is not
 * linked, and the frame would pass as done. */
static void warn_if_depth_is_constant(const exr_input *input, const char *channel,
                                      const float *depth, float background_depth) {
    const size_t count = (size_t)input->width * (size_t)input->height;
    /* (a frame of background alone, an empty shot, says nothing: the
     * library's rule, its half-float sky and the camera's clip end included) */
    if (count < 2 || !(depth[0] > 0.0f) || !(depth[0] < background_depth) ||
        depth[0] == HBAO_HALF_FLOAT_SKY)
        return;
    for (size_t i = 1; i < count; ++i)
        if (depth[i] != depth[0]) return;
    tool_warn("%s: every pixel's depth (%s) is %g: the AO is 1 everywhere. A single-layer EXR "
              "holds Blender's depth only where the Composite node's Z input is linked; or "
              "save a multilayer EXR",
              input->path, channel, (double)depth[0]);
}

int ao_compute_input(const cli_options *options, exr_input *input, ao_buffers *buffers,
                     tool_error *error) {
    const ao_plan *plan = &buffers->plan;
    int status = ao_plan_make(options, input, &buffers->plan, error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    const blender_passes *passes = &plan->passes;
    const bool use_normals = plan->use_normals;
    /* Blender before 5.0 cuts channel names past 64 bytes: a view layer
     * named with 56 bytes or more loses its Normal pass so (a layer of
     * Depth alone, by choice, is read as it is, quietly) */
    if (passes->normal_expected && !passes->has_normal && !options->ignore_normals &&
        strlen(passes->layer) >= BLENDER_NORMAL_LAYER_NAME_MAX)
        tool_warn("%s: no Normal pass (%.*sX/Y/Z): normals are reconstructed from depth; "
                  "Blender before 5.0 cuts the Normal pass's channel names of a view layer "
                  "named with %d bytes or more",
                  input->path, (int)strlen(passes->normal[0]) - 1, passes->normal[0],
                  BLENDER_NORMAL_LAYER_NAME_MAX);
    /* part of a Normal pass (a channel lost on the way: a compositor's or
     * another program's edit) was set aside without a word (a review's find) */
    else if (passes->normal_expected && !passes->has_normal && passes->normal_found > 0 &&
             !options->ignore_normals)
        tool_warn("%s: the Normal pass has %d of its 3 channels (%.*sX/Y/Z): normals are "
                  "reconstructed from depth",
                  input->path, passes->normal_found, (int)strlen(passes->normal[0]) - 1,
                  passes->normal[0]);
    /* The passes are decoded with as many threads as the AO is computed. */
    input->threads = options->params.threads > 0 ? options->params.threads : exr_usable_cores();
    status = read_passes(input, passes, use_normals,
                         options->back_layer != NULL ? &plan->back_passes : NULL, buffers, error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    /* A camera file meant to describe the camera: without the matrix, the
     * normals would be turned wrongly and the frame would still succeed
     * (a farm would keep it). Without any camera, a warning. */
    if (use_normals && !(plan->camera.fields_set & CAMERA_FIELD_WORLD_TO_CAMERA) &&
        options->camera_path != NULL)
        return tool_fail(error, TOOL_EXIT_RUNTIME,
                         "%s has no world_to_camera, which the Normal pass (%s, in world space) "
                         "needs; add it (scripts/export_cameras.py writes it), or give "
                         "--world-to-camera or --no-normals",
                         options->camera_path, passes->normal[0]);
    if (use_normals && !(plan->camera.fields_set & CAMERA_FIELD_WORLD_TO_CAMERA))
        tool_warn("the Normal pass (%s) is in world space but no world-to-camera matrix was "
                  "given; using the identity, which is right only for a camera at the origin "
                  "looking down -Z. Give --camera FILE.json or --world-to-camera, or "
                  "--no-normals to reconstruct normals from depth",
                  passes->normal[0]);

    if (strcmp(passes->depth, "Z") == 0) /* a single-layer EXR's */
        warn_if_depth_is_constant(input, passes->depth, buffers->depth,
                                  plan->params.background_depth);
    hbao_channel depth = {buffers->depth, 1, input->width};
    hbao_channel normal = {buffers->normal, 3, (int64_t)input->width * 3};
    hbao_channel back = {buffers->back, 1, input->width};
    hbao_result result =
        hbao_compute_layers(&plan->params, &plan->cropped, input->width, input->height, &depth,
                            use_normals ? &normal : NULL, buffers->back != NULL ? &back : NULL,
                            buffers->ao, input->width);
    if (result != HBAO_SUCCESS)
        return tool_fail(error, TOOL_EXIT_RUNTIME, "%s: cannot compute AO: %s", options->input_path,
                         hbao_result_message(result));
    const uint32_t notes = hbao_last_notes();
    for (uint32_t note = 1; note != 0; note <<= 1)
        if (notes & note) tool_warn("%s: %s", options->input_path, hbao_note_message(note));
    return TOOL_EXIT_SUCCESS;
}

int ao_command(const cli_options *options, tool_error *error) {
    struct stat input_status;
    if (stat(options->input_path, &input_status) != 0)
        return tool_fail(
            error, TOOL_EXIT_RUNTIME, "cannot open %s: %s%s", options->input_path, strerror(errno),
            strchr(options->input_path, '#') != NULL ? " (for an image sequence, give --frames)"
                                                     : "");
    /* (an input that is not a regular file: exr_input_open says what it is) */
    exr_input input;
    int status = exr_input_open(&input, options->input_path, error);
    if (status != TOOL_EXIT_SUCCESS) return status;
    /* Once the input is open: an output named by a descriptor (/dev/fd/3,
     * /proc/self/fd/3: a wrapper that forgot its `3>file`) is the input
     * only now that the input has that descriptor; looked at before, it
     * passed, and the rename replaced the input (a review's find). */
    status = refuse_overwriting_input(options->output_path, "-o", &input.file_status,
                                      options->camera_path, error);
    if (status == TOOL_EXIT_SUCCESS && options->preview_path != NULL)
        status = refuse_overwriting_input(options->preview_path, "--preview", &input.file_status,
                                          options->camera_path, error);
    if (status != TOOL_EXIT_SUCCESS) {
        exr_input_close(&input);
        return status;
    }

    ao_buffers buffers = {0};
    exr_output_channel *outputs = NULL;
    output_files files = {ATOMIC_FILE_IDLE, ATOMIC_FILE_IDLE};
    status = begin_outputs(options, &files, error);
    if (status != TOOL_EXIT_SUCCESS) goto done;
    status = ao_compute_input(options, &input, &buffers, error);
    if (status != TOOL_EXIT_SUCCESS) goto done;

    outputs = calloc((size_t)input.channels->num_channels + 1, sizeof *outputs);
    if (outputs == NULL) {
        status = tool_fail(error, TOOL_EXIT_RUNTIME, "out of memory");
        goto done;
    }
    int output_count = 0;
    /* AO is a linear quantity (a visibility fraction). */
    exr_output_channel ao_channel = {options->ao_channel,     EXR_PIXEL_FLOAT,
                                     EXR_PERCEPTUALLY_LINEAR, (uint8_t *)buffers.ao,
                                     sizeof(float),           (int64_t)input.width * sizeof(float)};
    outputs[output_count++] = ao_channel;
    if (options->keep_input) {
        status = read_copies(&input, options->ao_channel, &buffers, outputs, &output_count, error);
        if (status != TOOL_EXIT_SUCCESS) goto done;
    }
    status = write_outputs(options, &input, outputs, output_count, buffers.ao, &buffers.plan,
                           &files, error);

done:
    abort_outputs(&files);
    free(outputs);
    ao_buffers_free(&buffers);
    exr_input_close(&input);
    return status;
}
