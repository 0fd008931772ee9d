# SPDX-License-Identifier: GPL-2.0-or-later
"""Which areas of a screen swapped their contents since they were last seen.

Blender's Swap Areas (Ctrl-drag of an area's corner, screen.area_swap)
copies each of two areas' editors into the other: a 3D view moves to
another area, while the area's memory address, which view_entries
follows, stays; the copies may even get the old spaces' addresses back
from the allocator (an exploratory run: a swap of two 3D views changed no
address at all). Blender tells nothing of it. A swap is seen as two areas
that both changed since they were last seen, one now showing exactly what
the other showed (a copy is exact): its editors and, for a 3D view, its
lens, clip range, shading and where it looks. Two 3D views alike in all
of that cannot be told apart, nor need to be.

No bpy here: the areas are handed in.
"""

# (screen pointer, area pointer) -> content(area) when last seen.
_seen = {}


def content(area):
    """What a swap moves and what tells 3D views apart."""
    spaces = tuple(space.type for space in area.spaces)
    space = area.spaces.active
    if area.type != "VIEW_3D" or space is None or space.region_3d is None:
        return (area.ui_type, spaces)
    view = space.region_3d
    return (area.ui_type, spaces, space.lens, space.clip_start, space.clip_end,
            space.shading.type, view.view_perspective, view.view_distance,
            tuple(view.view_location), tuple(view.view_rotation))


def swapped(screen_pointer, areas):
    """[(area, area)]: the pairs of `areas` (a screen's, whose pointer is
    `screen_pointer`) that swapped contents since the last call for that
    screen; the areas' contents are then noted as seen."""
    now = {area.as_pointer(): (area, content(area)) for area in areas}
    changed = {pointer: (area, current) for pointer, (area, current) in now.items()
               if _seen.get((screen_pointer, pointer), current) != current}
    pairs, paired = [], set()
    for pointer, (area, _current) in changed.items():
        before = _seen[(screen_pointer, pointer)]
        partners = [other for other, (_area, current) in changed.items()
                    if other != pointer and current == before]
        if len(partners) == 1 and not {pointer, partners[0]} & paired:
            paired.update((pointer, partners[0]))
            pairs.append((area, changed[partners[0]][0]))
    forget(screen_pointer)
    _seen.update(((screen_pointer, pointer), current) for pointer, (_a, current) in now.items())
    return pairs


def forget(screen_pointer=None):
    """Forget what the areas of one screen (or every screen) showed."""
    for key in [key for key in _seen if screen_pointer is None or key[0] == screen_pointer]:
        del _seen[key]
