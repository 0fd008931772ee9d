# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb) by tests/test_ui.py: the artist picks the
add-on's internal engine in the Render Engine menu (the same property set
the menu makes, from a timer so that the window's message bus runs), once
from Cycles and once from EEVEE. Prints 'ENGINE <n> <engine a second
later>' and writes a screenshot of the window with the popup that says why.

  blender --addons hbao --python ui_engine_guard.py -- SHOT_DIR
"""
import os
import sys
import time
from pathlib import Path

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timer_guard  # noqa: E402

SHOTS = Path(sys.argv[sys.argv.index("--") + 1])
# The message bus runs on the next event loop turns: far less than this.
SETTLE_S = 1.0

compat = sys.modules["hbao.compat"]
INTERNAL = sys.modules["hbao.helper_lookup"].ENGINE_IDNAME
EEVEE = compat.engine_identifier("BLENDER_EEVEE")
scene = bpy.context.scene
# (the engine the artist had, then the internal one is picked)
TRIES = ["CYCLES", EEVEE]
state = {"try": 0, "phase": "set_own", "since": time.monotonic()}


def tick():
    now = time.monotonic()
    if state["phase"] == "set_own":
        scene.render.engine = TRIES[state["try"]]
        state.update(phase="pick_internal", since=now)
    elif state["phase"] == "pick_internal" and now - state["since"] > SETTLE_S:
        scene.render.engine = INTERNAL
        print(f"PICKED {state['try']} {INTERNAL} over {TRIES[state['try']]}", flush=True)
        state.update(phase="look", since=now)
    elif state["phase"] == "look" and now - state["since"] > SETTLE_S:
        print(f"ENGINE {state['try']} {scene.render.engine}", flush=True)
        window = bpy.context.window_manager.windows[0]
        with bpy.context.temp_override(window=window, screen=window.screen):
            bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=2)
            bpy.ops.screen.screenshot(filepath=str(SHOTS / f"ui_engine_kept_{state['try']}.png"),
                                      check_existing=False)
        state["try"] += 1
        if state["try"] == len(TRIES):
            print("GUARD: DONE", flush=True)
            timer_guard.quit_blender()
            return None
        state.update(phase="set_own", since=now)
    return 0.1


timer_guard.guarded_timer(tick, 1.0)
