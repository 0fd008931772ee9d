# SPDX-License-Identifier: GPL-2.0-or-later
"""view_swaps without Blender: which of a screen's areas swapped contents
(Swap Areas) since they were last seen, and which changes are no swap: a
view navigated, an area split off (a copy of its neighbour), a swap of
two views alike. tests/test_viewport.py drives real swaps in Blender."""
import sys
from types import SimpleNamespace

import pytest

from conftest import REPO

# The add-on imports as a package without Blender.
sys.path.insert(0, str(REPO / "addon"))
from hbao.viewport import view_swaps  # noqa: E402

SCREEN = 1


class Spaces(list):
    """An area's editors, the active one first (bpy's AreaSpaces)."""

    @property
    def active(self):
        return self[0]


class Area:
    def __init__(self, pointer, kind="VIEW_3D", lens=50.0):
        self.pointer = pointer
        view = SimpleNamespace(view_perspective="PERSP", view_distance=10.0,
                               view_location=(0.0, 0.0, 0.0),
                               view_rotation=(1.0, 0.0, 0.0, 0.0))
        self.spaces = Spaces([SimpleNamespace(
            type=kind, lens=lens, clip_start=0.01, clip_end=1000.0,
            shading=SimpleNamespace(type="SOLID"), region_3d=view)])

    @property
    def type(self):
        return self.spaces.active.type

    ui_type = type

    def as_pointer(self):
        return self.pointer


@pytest.fixture(autouse=True)
def forget():
    view_swaps.forget()
    yield
    view_swaps.forget()


@pytest.fixture
def areas():
    areas = [Area(10, lens=77.0), Area(20, lens=33.0), Area(30, "PROPERTIES")]
    assert view_swaps.swapped(SCREEN, areas) == []  # first seen
    return areas


def swap(a, b):
    """As Blender's Swap Areas: each area gets a copy of the other's editors."""
    a.spaces, b.spaces = (Spaces(SimpleNamespace(**vars(space)) for space in b.spaces),
                          Spaces(SimpleNamespace(**vars(space)) for space in a.spaces))


def pointers(pairs):
    return sorted(sorted(area.pointer for area in pair) for pair in pairs)


def test_two_views_swapped(areas):
    swap(areas[0], areas[1])
    assert pointers(view_swaps.swapped(SCREEN, areas)) == [[10, 20]]
    assert view_swaps.swapped(SCREEN, areas) == []  # seen so since


def test_a_view_swapped_with_another_editor(areas):
    swap(areas[0], areas[2])
    assert pointers(view_swaps.swapped(SCREEN, areas)) == [[10, 30]]


def test_a_view_navigated_is_no_swap(areas):
    areas[0].spaces.active.region_3d.view_location = (1.0, 0.0, 0.0)
    assert view_swaps.swapped(SCREEN, areas) == []


def test_a_swap_after_the_partner_changed_unseen(areas):
    """The other view navigated since it was last seen, then swapped: the
    previewed view's content is still found in its new area."""
    areas[1].spaces.active.region_3d.view_location = (0.0, 2.0, 0.0)
    swap(areas[0], areas[1])
    assert pointers(view_swaps.swapped(SCREEN, areas)) == [[10, 20]]


def test_an_area_split_off_is_no_swap(areas):
    """A split makes a new area with a copy of the view: the view stays."""
    split = Area(40, lens=77.0)
    assert view_swaps.swapped(SCREEN, areas + [split]) == []


def test_views_alike_are_no_swap(areas):
    areas[1].spaces.active.lens = 77.0
    assert view_swaps.swapped(SCREEN, areas) == []
    swap(areas[0], areas[1])  # nothing tells them apart
    assert view_swaps.swapped(SCREEN, areas) == []


def test_screens_are_apart(areas):
    swap(areas[0], areas[1])
    assert view_swaps.swapped(SCREEN + 1, areas) == []  # another screen, first seen
    assert pointers(view_swaps.swapped(SCREEN, areas)) == [[10, 20]]
