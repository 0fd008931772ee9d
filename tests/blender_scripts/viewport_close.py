# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb) by tests/test_viewport.py: a 3D view with
the preview on is closed (an exploratory run found its settings taken over
by other views). Each step in its own tick of the event loop, as an
artist's clicks are:

  shift   the Timeline made a 3D view (before the big 3D view in the
          screen's areas) with the preview on; the small view closed: the
          big view, which never had the preview, takes its place.
  split   eight times: the big view split, the preview turned on in the
          new view, the new view closed; a view split off next (which may
          get the closed one's place or address) must start without it.
  saved   "shift" with the big view's preview turned on and off before,
          then the file saved and opened again.
  noui    the file saved; the preview on in the big view; the Properties
          area (before it in the screen's areas) closed, the big view split;
          the file opened again without its UI (Load UI off): 'PLACES
          <when> [...]', each 3D view's position in the screen's areas and
          whether its preview is on, before and after.
  maximized the big view's preview on, the view maximized (Ctrl+Space), the
          file saved so and opened again: 'MAXIMIZED <when> {json}', the
          window's screen, whether the maximized view's preview is on and
          the draw handler (and its radius), before the save and after the
          open.
  return  "maximized" on, the radius set while maximized, the view returned
          home (Ctrl+Space again), the file saved and opened again:
          'RETURN <when> {json}', the window's screen, its view's preview
          (null: no settings), radius and the draw handler.
  fresh_return  "return" with the preview first turned on after the open.
  swap    the Timeline made a 3D view; the big view's preview on, its
          radius set; the two views swapped (Swap Areas), the previewed
          one then swapped with the Properties; the other view's preview
          on, another radius, the two views swapped again; the file saved
          and opened again: 'SWAP <when> {json}', for each 3D view (told
          apart by its lens): its lens, preview (null: no settings) and
          radius; and the draw handler.
  targets both views' previews on, then the small view's off, then on in
          Wireframe shading (which the preview cannot draw): after each,
          'TARGETS <when> [big, small]', whether each view's region holds
          the preview's targets (draw._pipelines).

Prints 'VIEWS <when> {json}' (for each 3D view, big first: its settings'
enabled, or null), 'HANDLER <when> <bool>' (the draw handler),
'ENTRIES <when> [names]' (the window's screen's entries) and
'CLOSE: DONE'.

  blender --factory-startup --addons hbao --python viewport_close.py -- CASE OUT_DIR
"""
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timer_guard  # noqa: E402

case, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]


def window():
    return bpy.context.window_manager.windows[0]


def views_3d():
    return sorted((a for a in window().screen.areas if a.type == "VIEW_3D"),
                  key=lambda a: -a.width * a.height)


def override(area):
    region = [r for r in area.regions if r.type == "WINDOW"][-1]
    return bpy.context.temp_override(window=window(), screen=window().screen, area=area,
                                     region=region)


def entries():
    return sys.modules["hbao.viewport.view_entries"]


def enabled(area):
    found = entries().find(window().screen, area)
    return None if found is None else found.enabled


def toggle(area):
    with override(area):
        bpy.ops.hbao.viewport_preview_toggle()


def report(when):
    print(f"VIEWS {when} {json.dumps([enabled(area) for area in views_3d()])}", flush=True)
    draw = sys.modules["hbao.viewport.draw"]
    print(f"HANDLER {when} {draw.handler_registered()}", flush=True)
    print(f"ENTRIES {when} {json.dumps([e.name for e in window().screen.hbao_viewport_views])}",
          flush=True)


def redrawn_report(when):
    """report(when) after the big view drew (its preview looks its settings up)."""
    with override(views_3d()[0]):
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=2)
    yield
    report(when)


def shift_steps(big_had_it=False):
    timeline = next(a for a in window().screen.areas if a.type == "DOPESHEET_EDITOR")
    timeline.type = "VIEW_3D"
    yield
    big, small = views_3d()
    toggle(small)
    if big_had_it:
        toggle(big)
        yield
        toggle(views_3d()[0])  # the big view off again: its entry stays, off
    yield
    report("before")
    with override(views_3d()[1]):
        bpy.ops.screen.area_close()
    yield
    yield from redrawn_report("closed")


def split_steps():
    for _round in range(8):
        before = {area.as_pointer() for area in window().screen.areas}
        with override(views_3d()[0]):
            bpy.ops.screen.area_split(direction="VERTICAL", factor=0.5)
        yield
        new = next(a for a in window().screen.areas if a.as_pointer() not in before)
        print(f"NEW VIEW {json.dumps(enabled(new))}", flush=True)
        toggle(new)
        yield
        new = next(a for a in window().screen.areas if a.as_pointer() not in before)
        with override(new):
            bpy.ops.screen.area_close()
        yield
    yield from redrawn_report("split")


def saved_steps():
    yield from shift_steps(big_had_it=True)
    yield from saved_and_opened("closed.blend")
    yield from redrawn_report("opened")


def places_report(when):
    places = []
    for index, area in enumerate(window().screen.areas):
        if area.type == "VIEW_3D":
            with override(area):
                bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=1)
            places.append([index, enabled(area)])
    print(f"PLACES {when} {json.dumps(places)}", flush=True)


def no_ui_steps():
    path = os.path.join(out_dir, "no_ui.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    yield
    toggle(views_3d()[0])
    yield
    properties = next(a for a in window().screen.areas if a.type == "PROPERTIES")
    with override(properties):
        bpy.ops.screen.area_close()
    yield
    with override(views_3d()[0]):
        bpy.ops.screen.area_split(direction="VERTICAL", factor=0.5)
    yield
    places_report("before")
    yield
    bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
    yield
    places_report("opened")


def view_report(label, when):
    """'<label> <when> {json}': the window's screen, its first 3D view's
    preview and radius (after a redraw), and whether the handler is on."""
    area = views_3d()[0]
    with override(area):
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=1)
    found = entries().find(window().screen, area)
    draw = sys.modules["hbao.viewport.draw"]
    print(f"{label} {when} " + json.dumps({
        "screen": window().screen.name, "enabled": None if found is None else found.enabled,
        "radius": None if found is None else round(found.radius, 3),
        "handler": draw.handler_registered()}), flush=True)


def saved_and_opened(name):
    """Steps: the file saved as OUT/<name>, then opened again."""
    path = os.path.join(out_dir, name)
    bpy.ops.wm.save_as_mainfile(filepath=path)
    yield
    bpy.ops.wm.open_mainfile(filepath=path)
    yield


def maximized_steps():
    toggle(views_3d()[0])
    yield
    with override(views_3d()[0]):
        bpy.ops.screen.screen_full_area(use_hide_panels=False)
    yield
    view_report("MAXIMIZED", "before")
    yield from saved_and_opened("maximized.blend")
    view_report("MAXIMIZED", "opened")


def targets_report(when):
    draw = sys.modules["hbao.viewport.draw"]
    for area in views_3d():
        with override(area):
            bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=1)
    held = [any(r.as_pointer() in draw._pipelines for r in area.regions if r.type == "WINDOW")
            for area in views_3d()]
    print(f"TARGETS {when} {json.dumps(held)}", flush=True)


def targets_steps():
    timeline = next(a for a in window().screen.areas if a.type == "DOPESHEET_EDITOR")
    timeline.type = "VIEW_3D"
    yield
    for area in views_3d():
        toggle(area)
    yield
    targets_report("on")
    yield
    toggle(views_3d()[1])
    yield
    targets_report("off")
    yield
    toggle(views_3d()[1])
    views_3d()[1].spaces.active.shading.type = "WIREFRAME"
    yield
    targets_report("wireframe")


def swap_report(when):
    """Each 3D view (told apart by its lens, which moves with its content)
    after it drew: [lens, preview on (null: no settings), radius]."""
    for area in views_3d():
        with override(area):
            bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=1)
    seen = []
    for area in sorted(views_3d(), key=lambda a: a.spaces.active.lens):
        found = entries().find(window().screen, area)
        seen.append([round(area.spaces.active.lens), None if found is None else found.enabled,
                     None if found is None else round(found.radius, 3)])
    draw = sys.modules["hbao.viewport.draw"]
    print(f"SWAP {when} " + json.dumps({"views": seen, "handler": draw.handler_registered()}),
          flush=True)


def _edge(low_a, size_a, low_b, size_b):
    """The middle of the gap between ranges a and b where one ends before
    the other starts, else None."""
    if low_a + size_a <= low_b:
        return (low_a + size_a + low_b) // 2
    if low_b + size_b <= low_a:
        return (low_b + size_b + low_a) // 2
    return None


def _overlap_middle(low_a, size_a, low_b, size_b):
    return (max(low_a, low_b) + min(low_a + size_a, low_b + size_b)) // 2


def swap(area, other):
    """Blender's Swap Areas (Ctrl-drag of a corner) of neighbours `area` and
    `other`: the operator swaps the two areas on either side of the edge at
    its cursor."""
    x = _edge(area.x, area.width, other.x, other.width)
    if x is not None:
        cursor = (x, _overlap_middle(area.y, area.height, other.y, other.height))
    else:
        cursor = (_overlap_middle(area.x, area.width, other.x, other.width),
                  _edge(area.y, area.height, other.y, other.height))
    with override(area):
        assert bpy.ops.screen.area_swap(cursor=cursor) == {"FINISHED"}


def swap_steps():
    timeline = next(a for a in window().screen.areas if a.type == "DOPESHEET_EDITOR")
    timeline.type = "VIEW_3D"
    yield
    big, small = views_3d()
    big.spaces.active.lens, small.spaces.active.lens = 77, 33
    toggle(big)
    entries().find(window().screen, big).radius = 0.77
    yield
    swap_report("before")
    swap(views_3d()[0], views_3d()[1])  # the 3D views swapped
    yield
    swap_report("views")
    view = next(a for a in views_3d() if round(a.spaces.active.lens) == 77)
    properties = next(a for a in window().screen.areas if a.type == "PROPERTIES")
    swap(view, properties)  # the previewed view swapped with the Properties
    yield
    swap_report("properties")
    other = next(a for a in views_3d() if round(a.spaces.active.lens) == 33)
    toggle(other)
    entries().find(window().screen, other).radius = 0.33
    yield
    swap(views_3d()[0], views_3d()[1])  # both previewed
    yield
    swap_report("both")
    yield from saved_and_opened("swapped.blend")
    swap_report("opened")


def return_steps(fresh):
    """The big view maximized (its preview on unless `fresh`), the file
    saved so and opened again; the preview turned on if `fresh`, the
    radius set, the view returned home, the file saved and opened again."""
    if not fresh:
        toggle(views_3d()[0])
        yield
    with override(views_3d()[0]):
        bpy.ops.screen.screen_full_area(use_hide_panels=False)
    yield
    yield from saved_and_opened("maximized.blend")
    if fresh:
        toggle(views_3d()[0])
        yield
    entries().find(window().screen, views_3d()[0]).radius = 0.55
    view_report("RETURN", "maximized")
    yield
    with override(views_3d()[0]):
        bpy.ops.screen.screen_full_area(use_hide_panels=False)
    yield
    view_report("RETURN", "returned")
    yield from saved_and_opened("maximized.blend")
    view_report("RETURN", "reopened")


steps = {"shift": shift_steps, "split": split_steps, "saved": saved_steps,
         "targets": targets_steps, "noui": no_ui_steps, "maximized": maximized_steps,
         "swap": swap_steps, "return": lambda: return_steps(fresh=False),
         "fresh_return": lambda: return_steps(fresh=True)}[case]()


timer_guard.walk_steps(steps, "CLOSE", persistent=True)
