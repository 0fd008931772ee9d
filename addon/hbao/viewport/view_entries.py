# SPDX-License-Identifier: GPL-2.0-or-later
"""Which entry of per-3D-view preview settings (settings.py) belongs to which
3D view.

Where they live, and why: a 3D view (SpaceView3D) and its area are not ID
blocks, so Python cannot add properties to them. The Screen that holds the
area is an ID (one per workspace and window layout) and is saved with the file,
so each Screen carries a collection `hbao_viewport_views` with one entry per 3D
view that ever had the preview turned on, keyed by the area's position in
`screen.areas`. Areas have no stable identifier across saves, and their
positions shift when an area before them is joined away, so while Blender runs
an entry follows its area by the area's memory address (which stays valid as
long as the area exists), and the saved positions are refreshed just before
every save. Per scene or per workspace settings would be simpler but are not per
view: two 3D views side by side could not differ.

Swap Areas copies two areas' contents across, the areas staying: an entry
whose view so moved follows it to its new area (view_swaps.py tells).

A closed area's entry is an orphan: Blender tells nothing when an area
closes, so the entries are checked against their screen's areas whenever a
view's settings are looked up; an orphan is never found again (a view that
takes the closed one's place, or its address, starts without the preview),
turns no draw handler on, and is removed before the next save.
"""
import bpy
from bpy.app.handlers import persistent

from ..callback_guard import never_raises
from . import view_swaps

COLLECTION_NAME = "hbao_viewport_views"
# Blender names a maximized or full-screen area's temporary screen
# "<home screen>-nonnormal".
TEMPORARY_SUFFIX = "-nonnormal"
# A temporary screen's custom property, written before a save: the name of
# its maximized view's entry on the home screen. Opened again, the view had
# lost its preview (the map from its space to that entry is the session's,
# and the home screen's place for it comes back as another kind of area;
# a review's find).
HOME_VIEW_PROPERTY = "hbao_home_view"
# Another, written with it: the position in the home screen's areas of the
# place its view left. Blender saves that empty area without a space and
# reads it back as an Info editor (which the view comes back into), so
# opened again, a view turned on only then had its settings made on the
# temporary screen, lost on return.
HOME_PLACE_PROPERTY = "hbao_home_place"

# (screen pointer, area pointer) -> entry name, for the areas seen this session.
_entry_by_area = {}
# (screen pointer, area pointer) -> the pointer of the area's 3D view when its
# entry was found: an area made where a closed one was freed may get its
# address, but not with the same view as well (unless both are reused).
_space_by_area = {}
# (screen pointer, entry name) of the entries whose area closed (see above).
_orphans = set()
# space pointer -> (screen name, entry name): a maximized or full-screen view
# moves its space into a temporary screen, where it keeps its settings.
_entry_by_space = {}
# Called with no arguments when a view's `enabled` changes (draw.sync_handler).
enabled_change_callbacks = []


def _views(screen):
    return getattr(screen, COLLECTION_NAME)


def _area_index(screen, area):
    for index, candidate in enumerate(screen.areas):
        if candidate == area:
            return index
    return -1


def find(screen, area):
    """The settings of the 3D view in `area`, or None if it has none yet; a
    maximized view's are its own screen's. Reads only, so panels and draw
    callbacks may call it."""
    if screen is None or area is None:
        return None
    space = area.spaces.active
    entry = _find_on_screen(screen, area)
    if entry is not None:
        if space is not None:
            _entry_by_space[space.as_pointer()] = (screen.name, entry.name)
        return entry
    if space is not None and _temporary(screen):
        home_name, name = _entry_by_space.get(space.as_pointer(), (None, None))
        if home_name is None and screen.get(HOME_VIEW_PROPERTY):
            # a file saved with the view maximized (refresh_area_indices)
            home_name, name = screen.name[:-len(TEMPORARY_SUFFIX)], screen[HOME_VIEW_PROPERTY]
        home = bpy.data.screens.get(home_name) if home_name is not None else None
        if home is not None and home != screen:
            entry = _views(home).get(name)
            if entry is not None:
                _entry_by_space[space.as_pointer()] = (home.name, entry.name)
            return entry
    return None


def _temporary(screen):
    """A screen Blender makes for a maximized (Ctrl+Space, show_fullscreen)
    or full-screen (Ctrl+Alt+Space) area: it names both "<screen>-nonnormal"."""
    return getattr(screen, "show_fullscreen", False) or screen.name.endswith(TEMPORARY_SUFFIX)


def _home_place(screen):
    """The home screen of temporary `screen` and the area there that its view
    left (Blender leaves an empty area in its place, and moves the view back
    into it on return; in a file opened, the Info editor at
    HOME_PLACE_PROPERTY), or (None, None) where either is not found: a home
    name too long to be kept whole, or no such area."""
    if not screen.name.endswith(TEMPORARY_SUFFIX):
        return None, None
    home = bpy.data.screens.get(screen.name[:-len(TEMPORARY_SUFFIX)])
    if home is None or home == screen:
        return None, None
    empty = [area for area in home.areas if area.type == "EMPTY"]
    if len(empty) == 1:
        return home, empty[0]
    index = screen.get(HOME_PLACE_PROPERTY, -1)
    if not empty and 0 <= index < len(home.areas) and home.areas[index].type == "INFO":
        return home, home.areas[index]
    return None, None


def _orphan(key):
    """The entry followed by area `key` (screen, area pointer) lost its area."""
    name = _entry_by_area.pop(key, None)
    _space_by_area.pop(key, None)
    if name is not None:
        _orphans.add((key[0], name))
        # (find() runs in draw callbacks: the draw handler's sync waits)
        if not bpy.app.timers.is_registered(_after_close):
            bpy.app.timers.register(_after_close, first_interval=0.0)


@never_raises("turn the viewport preview off after a 3D view closed")
def _after_close():
    for callback in enabled_change_callbacks:
        callback()
    return None  # once


def _note_closed_areas(screen):
    """Orphan the entries of `screen` whose areas are gone; an entry whose
    view swapped areas (view_swaps) follows it. Reads only."""
    screen_pointer = screen.as_pointer()
    live = {area.as_pointer() for area in screen.areas}
    for key in [key for key in _entry_by_area if key[0] == screen_pointer and key[1] not in live]:
        _orphan(key)
    for pair in view_swaps.swapped(screen_pointer, screen.areas):
        keys = [(screen_pointer, area.as_pointer()) for area in pair]
        names = [_entry_by_area.pop(key, None) for key in keys]
        for key, area, name in zip(keys, pair, reversed(names)):
            _space_by_area.pop(key, None)
            space = area.spaces.active.as_pointer() if area.spaces.active is not None else 0
            _entry_by_space.pop(space, None)  # (space addresses may be reused)
            if name is not None:
                _follow(key, space, name)
                _entry_by_space[space] = (screen.name, name)


def _find_on_screen(screen, area):
    _note_closed_areas(screen)
    views = _views(screen)
    key = (screen.as_pointer(), area.as_pointer())
    space = area.spaces.active.as_pointer() if area.spaces.active is not None else 0
    name = _entry_by_area.get(key)
    followed = _space_by_area.get(key)
    if name is not None and followed and space and followed != space:
        _orphan(key)  # another area at a closed one's address
        name = None
    if name is not None:
        entry = views.get(name)
        if entry is not None:
            return entry
    index = _area_index(screen, area)
    # Entries that follow another live area of this screen are taken, and
    # those whose area closed are orphans: only an entry no area claimed
    # since the file opened is found by its saved position.
    claimed = {n for (s, _a), n in _entry_by_area.items() if s == key[0]}
    for entry in views:
        if entry.area_index == index and entry.name not in claimed \
                and (key[0], entry.name) not in _orphans:
            _follow(key, space, entry.name)
            return entry
    return None


def _follow(key, space, name):
    _entry_by_area[key] = name
    _space_by_area[key] = space


def ensure(screen, area):
    """The settings of the 3D view in `area`, created if needed (writes the
    Screen: call from operators, not from draw code). A maximized view's
    are made on its home screen (_home_place), so that they are still
    there when the view comes back."""
    entry = find(screen, area)
    if entry is not None:
        return entry
    home, place = _home_place(screen) if _temporary(screen) else (None, None)
    space = area.spaces.active
    if home is not None and space is not None:
        entry = ensure(home, place)
        _entry_by_space[space.as_pointer()] = (home.name, entry.name)
        # the view comes back into `place` (its own, not the empty area's)
        _space_by_area[(home.as_pointer(), place.as_pointer())] = space.as_pointer()
        return entry
    views = _views(screen)
    existing = {entry.name for entry in views}
    number = len(views) + 1
    while f"View {number}" in existing:
        number += 1
    entry = views.add()
    entry.name = f"View {number}"
    entry.area_index = _area_index(screen, area)
    _follow((screen.as_pointer(), area.as_pointer()),
            space.as_pointer() if space is not None else 0, entry.name)
    return entry


def any_enabled():
    """Whether any 3D view of any screen has the preview on (orphans aside)."""
    for screen in bpy.data.screens:
        _note_closed_areas(screen)
    return any(entry.enabled and (screen.as_pointer(), entry.name) not in _orphans
               for screen in bpy.data.screens for entry in _views(screen))


@persistent
@never_raises("note the viewport preview's views before the save")
def refresh_area_indices(*_args):
    """Before a save: write each entry's current area position, so the file maps
    entries to the right areas when it is opened again, and remove orphans."""
    for screen in bpy.data.screens:
        if _temporary(screen):
            _note_home_view(screen)
        views = _views(screen)
        screen_pointer = screen.as_pointer()
        _note_closed_areas(screen)
        for index in reversed(range(len(views))):
            if (screen_pointer, views[index].name) in _orphans:
                _orphans.discard((screen_pointer, views[index].name))
                views.remove(index)
        _write_area_indices(screen)


def _note_home_view(screen):
    """HOME_VIEW_PROPERTY of temporary `screen`, from its view's entry, and
    HOME_PLACE_PROPERTY."""
    home, place = _home_place(screen)
    index = _area_index(home, place) if home is not None else -1
    if index >= 0 and screen.get(HOME_PLACE_PROPERTY) != index:
        screen[HOME_PLACE_PROPERTY] = index
    for area in screen.areas:
        space = area.spaces.active if area.type == "VIEW_3D" else None
        found = _entry_by_space.get(space.as_pointer()) if space is not None else None
        if found is not None and screen.get(HOME_VIEW_PROPERTY) != found[1]:
            screen[HOME_VIEW_PROPERTY] = found[1]


def _write_area_indices(screen):
    """Each followed entry of `screen` at its area's current position."""
    views = _views(screen)
    screen_pointer = screen.as_pointer()
    for index, area in enumerate(screen.areas):
        name = _entry_by_area.get((screen_pointer, area.as_pointer()))
        entry = views.get(name) if name is not None else None
        if entry is not None and entry.area_index != index:
            entry.area_index = index


@persistent
@never_raises("forget the viewport preview's views of the file closed")
def forget_areas(*_args):
    """Before a load: areas are new objects after it; entries are found by
    position again. Opened without its UI (Load UI off, File > Revert so),
    the file keeps these screens, whose entries' positions were written at
    the last save only: an area closed or split since gave a view's preview
    and settings to another view (a review's find). So they are written
    first, as before a save, orphans removed."""
    refresh_area_indices()
    _entry_by_area.clear()
    _space_by_area.clear()
    _entry_by_space.clear()
    _orphans.clear()
    view_swaps.forget()
