# SPDX-License-Identifier: GPL-2.0-or-later
"""The AO of a helper scene's render: the jobs that its main scene's HBAO
nodes plan (planning.py), their inputs handed over from the main Render
Result or kept from the last render (job_inputs.py), and each job's AO for
each view, from the cache where the passes and settings are the same, else
from libhbao (layer_passes.py). The engine (engine.py) publishes it."""
import time

import bpy
import numpy as np

from . import camera as camera_model
from . import ao_cache, job_inputs, layer_passes, native, render_record
from .helper_scene import scene_for_render
from .planning import node_names, plan
from .report import NodeMessage, add_node_messages, log, post_render_report

# The last render's passes and AO, reused for the same passes and settings,
# and by re-compositing (recomposite.py).
cache = ao_cache.last_render


def original(scene):
    """The scene itself where `scene` is a depsgraph's evaluated copy."""
    return scene.original if hasattr(scene, "original") else scene


def main_of(helper, request):
    """The main scene a render of `helper` is for (the request's, when
    re-compositing), or None."""
    return bpy.data.scenes.get(request.main) if request else scene_for_render(helper)


def report_warning(engine, text):
    """A warning in the render's report, and (report.py) in the Info editor."""
    engine.report({"WARNING"}, text)
    if not bpy.app.background:  # `-b`: the console has it; nothing would take it
        post_render_report(text)


def compute_passes(engine, depsgraph, width, height, request=None):
    """{(view, pass name): bottom-up (height, width) AO} for the helper being
    rendered (the view None without Stereoscopy): for the render of its main
    scene, or for `request` (recomposite.Request) from the passes of the
    last render."""
    helper = original(depsgraph.scene)
    main = main_of(helper, request)
    if main is None:
        raise RuntimeError(f"scene {helper.name!r} is not an HBAO helper scene")
    frame = request.frame if request else main.frame_current + main.frame_subframe
    jobs, warnings = plan(main, frame)
    render_record.remember(main.name, frame, jobs, node_names(main), main.as_pointer())
    for warning in warnings:
        report_warning(engine, f"HBAO {warning}")
        log(warning)
    if not jobs:
        if request is not None:
            request.completed = True
        return {}
    native.load_library()
    if request:
        inputs_of, timings, views = job_inputs.kept(main, request, cache)
    else:
        inputs_of, timings, views = job_inputs.handed_over(
            engine, depsgraph, helper, main, jobs, warnings,
            lambda text: report_warning(engine, text))

    results = {}
    # Esc: Blender asks through test_break(); the passes say no AO and
    # the render ends as Blender decides (the scratch file goes as the
    # engine.render_helper's removals_after block ends).
    if engine.test_break():
        log("render cancelled: no AO computed")
        cache.clear()
        return {}
    compute_time = 0.0
    timings["threads"] = max(job.threads for job in jobs)  # (the same for every job)
    timings["search"] = native.search_name()
    fresh, noted = {}, []
    every_job = [(view, job) for view in views for job in jobs]
    for index, (view, job) in enumerate(every_job):
        if engine.test_break():
            log("render cancelled: AO left out")
            cache.clear()
            return {}
        engine.update_stats("HBAO", f"{job.node_name}: computing AO ({index + 1}/"
                                    f"{len(every_job)})")
        inputs, depth, normal, extra = inputs_of(job, view)
        # A border render without its crop: the main Render Result is the
        # whole frame (background outside the border), the helper's only
        # the border. The AO is the whole frame's, cut to the border.
        border = camera_model.uncropped_border(main, depth.shape, (height, width))
        if depth.shape != (height, width) and border is None:
            raise RuntimeError(f"the Render Result is {depth.shape[1]}x{depth.shape[0]}, the "
                               f"helper scene renders {width}x{height}")
        compute_start = time.perf_counter()
        key = ao_cache.key(main.name, job.pass_name, view)
        kept = cache.get(key, inputs)
        if kept is None:
            ao = layer_passes.compute(job, depth, normal, inputs.camera, extra)
            notes = native.last_notes()  # (this thread's compute)
        else:
            timings["cached"] = timings.get("cached", 0) + 1
            ao, notes = kept  # the notes said again: the same AO, the same reason
        for bit, note in notes:
            message = NodeMessage(job.node_name, note, native.NOTE_SHORT_FORMS.get(bit, note))
            if message not in noted:  # (once for a stereo render's views)
                log(message)
                report_warning(engine, f"HBAO {message}")
                noted.append(message)
        fresh[key] = (inputs, ao, notes)
        if border is not None:  # bottom-up rows, as the border's y
            x0, x1, y0, y1 = border
            ao = np.ascontiguousarray(ao[y0:y1, x0:x1])
        results[(view, job.pass_name)] = ao
        compute_time += time.perf_counter() - compute_start
        engine.update_progress((index + 1) / len(every_job))
    cache.keep_only(fresh)
    if noted:  # the nodes' status lines show them with the plan's
        add_node_messages(main.name, noted)
    timings["ao"] = compute_time
    engine.hbao_timings = timings
    if request is not None:
        request.completed = True
    return results
