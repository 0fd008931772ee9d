# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_ui.py and
scripts/bench_memory_hold.py: F12 renders of the corner scene at WIDTH x
HEIGHT, GAP_S seconds apart, the camera nudged before each (so that each
render's passes differ and its AO is computed, not reused), with the add-on
holding the library's memory HOLD_S seconds after a render (memory_hold.py;
the add-on's preference Keep Memory After a Render, set here).
After each render it prints 'ENDED <n> {"held": ..., "rss_mb": ...}'. MODE
"wait" (the default): after the last render, it waits for the hold to end
and prints 'RELEASED {"held_rss_mb": the process's resident memory at the
last look while held, "rss_mb": right after, "waited_s": since the add-on
began to hold it}'; "quit": it quits after the last render instead;
"recomposite": with the compositor shown, one F12 render, then RENDERS - 1
changes of the node's Radius GAP_S seconds apart, each of which the add-on
re-composites from the kept passes (recomposite.py), and it quits GAP_S
after the last. The engine's timing line of each render (its AO time; a
re-composite's AO computed beforehand) is in the log.

  blender --addons hbao --python ui_memory_hold.py -- \
      OUT HOLD_S RENDERS GAP_S WIDTH HEIGHT [wait | quit | recomposite]
"""
import json
import os
import sys
import time

arguments = sys.argv[sys.argv.index("--") + 1:]
out_dir = arguments[0]
hold_s, renders, gap_s = float(arguments[1]), int(arguments[2]), float(arguments[3])
width, height = int(arguments[4]), int(arguments[5])
mode = arguments[6] if len(arguments) > 6 else "wait"
if mode not in ("wait", "quit", "recomposite"):
    raise SystemExit(f"ui_memory_hold.py: unknown mode {mode!r}")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
from hbao_preferences import hbao_preferences  # noqa: E402
import timer_guard  # noqa: E402
from process_memory import status_kib  # noqa: E402  (scripts/, on the path by f12_job)

# How long after the hold the release may come (the add-on's timer looks every second).
RELEASE_LATE_S = 10.0
TICK_S = 0.1
# The camera's move before each render (scene units; the room is 8 wide).
NUDGE = 0.002
# Each change's Radius, as a multiple of the one before.
RADIUS_STEP = 1.1

memory_hold = sys.modules["hbao.memory_hold"]
hbao_preferences().keep_memory_s = round(hold_s)
scene, node = f12_job.corner_scene_with_node(out_dir)
scene.render.resolution_x, scene.render.resolution_y = width, height
scene.render.resolution_percentage = 100
state = {"render": 0, "phase": "start", "since": None, "held_rss": None, "held_since": None}
job = f12_job.F12Job("HOLD")


def rss_mb():
    return status_kib("VmRSS") / 1024


def tick():
    now = time.monotonic()
    if state["phase"] == "start":
        if mode == "recomposite":
            f12_job.show_compositor()
        scene.camera.location.x += NUDGE
        state.update(phase="render", since=now)
        print(f"HOLD: render {state['render']}", flush=True)
        job.start()
    elif state["phase"] == "render":
        if job.finished():
            state["held_since"] = memory_hold.held_since()
            print(f"ENDED {state['render']} "
                  + json.dumps({"held": memory_hold.held(), "rss_mb": rss_mb()}), flush=True)
            state["render"] += 1
            if mode == "recomposite":
                state.update(phase="changes", since=now)
            elif state["render"] == renders and mode == "quit":
                print("HOLD: DONE", flush=True)
                timer_guard.quit_blender()
                return None
            else:
                state.update(phase="gap" if state["render"] < renders else "release", since=now)
    elif state["phase"] == "gap":
        if now - state["since"] >= gap_s:
            state["phase"] = "start"
    elif state["phase"] == "changes":
        if now - state["since"] >= gap_s:
            if state["render"] == renders:
                print("HOLD: DONE", flush=True)
                timer_guard.quit_blender()
                return None
            node.inputs["Radius"].default_value *= RADIUS_STEP
            print(f"HOLD: change {state['render']}", flush=True)
            state["render"] += 1
            state["since"] = now
    elif state["phase"] == "release" and memory_hold.held():
        if now - memory_hold.held_since() > hold_s + RELEASE_LATE_S:
            timer_guard.give_up("HOLD: NOT RELEASED")
        state["held_rss"] = rss_mb()
    elif state["phase"] == "release":
        # (held_since: the add-on's own clock, which its release counts from)
        waited_s = now - state["held_since"] if state["held_since"] is not None else -1.0
        print("RELEASED " + json.dumps({"held_rss_mb": state["held_rss"], "rss_mb": rss_mb(),
                                        "waited_s": waited_s}), flush=True)
        print("HOLD: DONE", flush=True)
        timer_guard.quit_blender()
        return None
    return TICK_S


timer_guard.guarded_timer(tick, 1.0)
