# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb) by tests/test_ui.py on the file
ui_old_file.py saved: what an artist meets on the HBAO node.

- the shared group was upgraded: integer sockets, values, links, keyframes kept;
- Add > Filter draws "HBAO"; the node search items do not offer ".HBAO";
- F12 renders (the render job's thread) with a fault, then with a clamped
  value, then with nothing wrong: the node's status after each, and
  screenshots of the node editor showing it;
- after the last render, the Normal input unlinked (a change that needs
  other passes, which re-compositing cannot bring: recomposite.py): the
  node's line saying that the AO shown is the last render's, and a
  screenshot of it;
- an HBAO node inside a node group of the artist's: the line that says it
  gives no AO there, and a screenshot of it.

  blender --addons hbao --python ui_node.py OLD.blend -- OUT.json SHOT_DIR
"""
import json
import os
import sys
import time
from pathlib import Path

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timer_guard  # noqa: E402
from ui_areas import node_editor, override  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
OUT, SHOTS = Path(args[0]), Path(args[1])
# Cycles at 96x64, 4 samples, takes about a second; far more means a hang.
RENDER_TIMEOUT_S = 120.0
# After the job ends the add-on's timer polls every 0.2 s: give it a few.
SETTLE_S = 1.0

node_module = sys.modules["hbao.node"]
socket_values = sys.modules["hbao.socket_values"]
compat = sys.modules["hbao.compat"]
scene = bpy.context.scene
tree = compat.compositor_tree(scene)
hbao = tree.nodes["HBAO"]
report = {}


class Recorder:
    """Stands in for a UILayout: records the text of every operator drawn."""

    def __init__(self, texts):
        self.texts = texts

    def operator(self, _idname, text="", **_kwargs):
        self.texts.append(text)
        return Recorder(self.texts)

    def __getattr__(self, _name):
        return lambda *a, **k: Recorder(self.texts)

    def __setattr__(self, name, value):
        object.__setattr__(self, name, value)


def upgrade_report():
    blur = hbao.inputs["Blur Size"]
    steps = hbao.inputs["Steps"]
    return {
        "socket_types": {name: hbao.inputs[name].bl_idname
                         for name in ("Radius", "Directions", "Steps", "Blur Size")},
        "directions": hbao.inputs["Directions"].default_value,
        "steps_source": steps.links[0].from_node.name if steps.is_linked else None,
        "depth_linked": hbao.inputs["Depth"].is_linked,
        "image_output_to": sorted(link.to_node.name for link in hbao.outputs["Image"].links),
        "blur_at_11": socket_values.socket_value(blur, 11.0, []),
        "blur_at_1": socket_values.socket_value(blur, 1.0, []),
    }


def menu_report(window, area):
    menu = compat.compositor_filter_menu()
    texts = []
    with override(window, area):
        context = bpy.context
        attributes = {"layout": Recorder(texts),
                      "bl_idname": getattr(menu, "bl_idname", menu.__name__)}
        # Blender 3.x's Add menus are node categories: their own draw
        # function reads the menu's category.
        if hasattr(menu, "category"):
            attributes["category"] = menu.category
        fake = type("FakeMenu", (), attributes)()
        menu.draw(fake, context)
        import nodeitems_utils
        labels = [item.label for item in nodeitems_utils.node_items_iter(context)
                  if hasattr(item, "label")]
    return {"menu": menu.__name__, "menu_texts": texts,
            "search_labels_with_hbao": [label for label in labels if "HBAO" in label]}


def screenshot(window, area, name):
    """The whole window, the node editor zoomed to the HBAO node (Blender
    3.4's screenshot_area gives a 1x1 image under Xvfb; the window's works)."""
    for node in tree.nodes:
        node.select = node == hbao
    tree.nodes.active = hbao
    with override(window, area):
        bpy.ops.node.view_selected()
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=2)
    with bpy.context.temp_override(window=window, screen=window.screen):
        bpy.ops.screen.screenshot(filepath=str(SHOTS / name), check_existing=False)


RENDERS = [
    # (name, what to change before rendering)
    ("depth_unlinked", lambda: tree.links.remove(hbao.inputs["Depth"].links[0])),
    ("clamped", lambda: (tree.links.new(tree.nodes["Render Layers"].outputs["Depth"],
                                        hbao.inputs["Depth"]),
                         setattr(tree.nodes["Steps Value"].outputs[0], "default_value", 100.0))),
    ("good", lambda: setattr(tree.nodes["Steps Value"].outputs[0], "default_value", 7.0)),
]
state = {"index": 0, "started": None, "done": False}


def on_done(*_args):
    state["done"] = True


def run_renders():
    window = bpy.context.window_manager.windows[0]
    area = state.get("area")
    if state["started"] is None:
        name, change = RENDERS[state["index"]]
        if state.get("changed") != state["index"]:  # once, should the step run again
            change()
            state["changed"] = state["index"]
        state["done"] = False
        # refused (timer_guard runs the step again), the state stays as it was
        print("UI: render", name, bpy.ops.render.render("INVOKE_DEFAULT"), flush=True)
        state.update(started=time.monotonic(), ended=None)
        return 0.25
    if not state["done"] or bpy.app.is_job_running("RENDER"):
        if time.monotonic() - state["started"] > RENDER_TIMEOUT_S:
            report["timeout"] = RENDERS[state["index"]][0]
            return finish()
        return 0.25
    if state["ended"] is None:
        state["ended"] = time.monotonic()
        return SETTLE_S
    name = RENDERS[state["index"]][0]
    report.setdefault("renders", {})[name] = {"status": hbao.status,
                                              "details": hbao.status_details}
    # The render window opened over the main window: screenshot the main one.
    screenshot(window, area, f"ui_node_{name}.png")
    state["index"] += 1
    state["started"] = None
    if state["index"] == len(RENDERS):
        tree.links.remove(hbao.inputs["Normal"].links[0])
        timer_guard.guarded_timer(changed_after_render, SETTLE_S)
        return None
    return 0.25


def changed_after_render():
    """The node's line once the add-on's timer has seen the change; where
    the HBAO node and the add-on's managed Render Layers node lie (drawn,
    so their dimensions are known)."""
    report["changed_after_render"] = {"hint": hbao.hint, "details": hbao.hint_details}
    managed = next(n for n in tree.nodes if n.get("hbao_managed"))
    report["layout"] = {name: {"location": list(n.location), "dimensions": list(n.dimensions)}
                        for name, n in (("hbao", hbao), ("managed", managed))}
    screenshot(bpy.context.window_manager.windows[0], state.get("area"), "ui_node_changed.png")
    report["grouped"] = grouped_node(bpy.context.window_manager.windows[0], state.get("area"))
    return finish()


def grouped_node(window, area):
    """An HBAO node in a node group of the artist's, the node editor inside
    that group: the texts its buttons draw, and a screenshot of it."""
    group = bpy.data.node_groups.new("Artist Group", "CompositorNodeTree")
    inside = group.nodes.new(node_module.NODE_IDNAME)
    holder = tree.nodes.new("CompositorNodeGroup")
    holder.node_tree = group
    holder.location = (hbao.location.x, hbao.location.y + 400)
    texts = []
    with override(window, area):
        # the class's Python function: the node's own method checks for a UILayout
        node_module.CompositorNodeHBAO.draw_buttons(inside, bpy.context, Recorder(texts))
        area.spaces.active.path.append(group, node=holder)
        for member in group.nodes:
            member.select = member == inside
        group.nodes.active = inside
        bpy.ops.node.view_selected()
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=2)
    with bpy.context.temp_override(window=window, screen=window.screen):
        bpy.ops.screen.screenshot(filepath=str(SHOTS / "ui_node_grouped.png"),
                                  check_existing=False)
    place = sys.modules["hbao.node_place"]
    return {"texts": texts, "top_level": [place.at_top_level(inside), place.at_top_level(hbao)]}


def finish():
    OUT.write_text(json.dumps(report, indent=2))
    print(json.dumps(report, indent=2))
    timer_guard.quit_blender()
    return None


def start():
    try:
        window = bpy.context.window_manager.windows[0]
        bpy.context.preferences.view.render_display_type = "NONE"  # the node editor stays
        report["upgrade"] = upgrade_report()
        area = state["area"] = node_editor(window)
        report.update(menu_report(window, area))
        bpy.app.handlers.render_complete.append(on_done)
        bpy.app.handlers.render_cancel.append(on_done)
        timer_guard.guarded_timer(run_renders, 0.5)
    except Exception as error:
        report["error"] = f"{type(error).__name__}: {error}"
        finish()
    return None


timer_guard.guarded_timer(start, 0.5)
