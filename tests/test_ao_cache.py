# SPDX-License-Identifier: GPL-2.0-or-later
"""addon/hbao/ao_cache.py without Blender: a stored AO comes back only for
inputs equal in every part (tests/test_addon.py renders with it)."""
import sys

import numpy as np

from conftest import REPO

# The add-on imports as a package without Blender.
sys.path.insert(0, str(REPO / "addon"))
from hbao.ao_cache import AOCache, AOInputs  # noqa: E402

PARAMS = {"radius": 0.5, "steps": 16}
CAMERA = {"lens": 50.0}


def inputs(depth, normal=None, params=PARAMS, camera=CAMERA, settings=(True, 0.0)):
    return AOInputs(dict(params), dict(camera), settings, (depth, normal))


def test_only_equal_inputs_get_the_stored_ao():
    depth = np.linspace(1.0, 2.0, 12, dtype=np.float32).reshape(3, 4)
    ao = np.full((3, 4), 0.5, np.float32)
    cache = AOCache()
    assert cache.get("node", inputs(depth)) is None
    notes = [(4, "under a pixel")]
    cache.keep_only({"node": (inputs(depth), ao, notes)})
    kept_ao, kept_notes = cache.get("node", inputs(depth.copy()))
    assert kept_ao is ao and kept_notes is notes
    assert cache.get("other node", inputs(depth)) is None
    changed = depth.copy()
    changed[1, 2] = np.nextafter(changed[1, 2], np.float32(3))
    differing = [inputs(changed), inputs(depth, normal=np.zeros((3, 4, 3), np.float32)),
                 inputs(depth.reshape(4, 3)), inputs(depth, params=dict(PARAMS, steps=8)),
                 inputs(depth, camera={"lens": 35.0}), inputs(depth, settings=(True, 0.1))]
    for other in differing:
        assert cache.get("node", other) is None


def test_nan_matches_nan_and_keep_only_forgets():
    depth = np.ones((2, 2), np.float32)
    depth[0, 0] = np.nan
    cache = AOCache()
    cache.keep_only({"node": (inputs(depth), np.ones((2, 2), np.float32), [])})
    # The library reads every NaN depth alike: the same passes, NaN included.
    assert cache.get("node", inputs(depth.copy())) is not None
    moved = depth.copy()
    moved[0, 0], moved[1, 1] = 1.0, np.nan
    assert cache.get("node", inputs(moved)) is None
    plain = np.ones((2, 2), np.float32)
    cache.keep_only({"node": (inputs(plain), plain, [])})
    cache.keep_only({})
    assert cache.get("node", inputs(plain)) is None


def test_passes_are_compared_bit_for_bit():
    depth = np.linspace(1.0, 2.0, 3 * 5000, dtype=np.float32).reshape(3, 5000)
    depth[2, 4999] = 0.0
    cache = AOCache()
    cache.keep_only({"node": (inputs(depth), np.ones_like(depth), [])})
    # Past the first probe stride too: a change only the full comparison sees.
    late = depth.copy()
    late[2, 4998] = np.nextafter(late[2, 4998], np.float32(0))
    assert cache.get("node", inputs(late)) is None
    # -0.0 equals 0.0 as a number but not as bits: a recomputation, never a wrong AO.
    signed = depth.copy()
    signed[2, 4999] = -0.0
    assert cache.get("node", inputs(signed)) is None
    assert cache.get("node", inputs(depth.astype(np.float64))) is None
    assert cache.get("node", inputs(depth.copy())) is not None


def test_passes_handed_over_from_memory_compare_in_either_order():
    # pass_capture.py hands over top-down views of Blender's bottom-up rows;
    # the file route contiguous top-down arrays. Equal pictures are equal
    # either way, and a change in any row tells them apart.
    bottom_up = np.arange(4 * 6 * 3, dtype=np.float32).reshape(4, 6, 3)
    top_down_view = bottom_up[::-1]
    cache = AOCache()
    cache.keep_only({"node": (inputs(top_down_view[..., 0], top_down_view), bottom_up, [])})
    again = bottom_up.copy()
    assert cache.get("node", inputs(again[::-1][..., 0], again[::-1]))[0] is bottom_up
    assert cache.get("node", inputs(np.ascontiguousarray(top_down_view[..., 0]),
                                    np.ascontiguousarray(top_down_view)))[0] is bottom_up
    for row in range(4):
        changed = bottom_up.copy()
        changed[row, 5, 2] += 1.0
        assert cache.get("node", inputs(changed[::-1][..., 0], changed[::-1])) is None
        assert cache.get("node", inputs(bottom_up[::-1][..., 0],
                                        np.ascontiguousarray(changed[::-1]))) is None


def test_an_ao_put_in_its_place_brings_its_own_notes():
    """A re-composite's AO (new settings, the kept passes) replaces the
    render's with its own notes: the render's (say, a radius under a pixel)
    were said again with the new AO when they lived beside the cache."""
    depth = np.ones((2, 2), np.float32)
    cache = AOCache()
    cache.keep_only({"node": (inputs(depth), np.ones_like(depth), [(4, "under a pixel")])})
    settled = inputs(depth, params=dict(PARAMS, steps=8))
    cache.put("node", settled, np.zeros_like(depth), [])
    assert cache.get("node", settled)[1] == []
    assert cache.entry("node")[0] is settled
