# SPDX-License-Identifier: GPL-2.0-or-later
"""The AO of the last render, reused when the next render hands over the
same passes with the same settings: an artist re-rendering a frame after
changing lights or materials gets the AO without computing it again.

Inputs are compared exactly (the passes bit for bit, == on the parameters
and camera), never hashed: a reused AO is the AO those inputs give. Only
the last render's results are kept, so the cache holds at most one frame's
passes and AO per node."""
import numpy as np


class AOInputs:
    """Everything a node's AO depends on: its parameters, the camera, the
    settings of its extra renders and the arrays the library reads."""

    def __init__(self, params, camera, settings, arrays):
        self.params = params
        self.camera = camera
        self.settings = settings
        self.arrays = tuple(arrays)

    def same_as(self, other):
        if (self.params != other.params or self.camera != other.camera
                or self.settings != other.settings or len(self.arrays) != len(other.arrays)):
            return False
        for mine, theirs in zip(self.arrays, other.arrays):
            if mine is theirs:
                continue  # re-compositing reuses the kept arrays themselves
            if mine is None or theirs is None:
                return False
            if mine.shape != theirs.shape or not _equal(mine, theirs):
                return False
        return True


# Every this-many-th value is compared first: a changed frame (most of an
# animation) usually differs there, and is told apart without reading all
# of its passes.
_PROBE_STRIDE = 4099


def key(scene_name, pass_name, view=None):
    """The cache's key of the AO of pass `pass_name` of scene `scene_name`'s
    render, in `view` of a stereo render (None: a mono render's, which
    re-compositing reads)."""
    return (scene_name, pass_name) if view is None else (scene_name, pass_name, view)


def _reversed_rows(array):
    """Whether `array` is a top-down view of bottom-up contiguous rows (as
    pass_capture.py hands them over)."""
    return (not array.flags.c_contiguous and array.ndim >= 2 and array.strides[0] < 0
            and array[::-1].flags.c_contiguous)


def _bits(array):
    """The array flat, floats as the unsigned integers of their bits."""
    flat = np.ascontiguousarray(array).reshape(-1)
    if flat.dtype.kind == "f":
        return flat.view(np.dtype(f"u{flat.dtype.itemsize}"))
    return flat


def _equal(mine, theirs):
    # Bit for bit: a NaN equals the same NaN (the library reads every NaN
    # depth the same way), and -0.0 differs from 0.0, which only costs a
    # recomputation. numpy.array_equal(..., equal_nan=True) gave the same
    # answers but took 49 ms for a 1080p frame's passes with Debian's numpy
    # 1.24 (Blender 3.4), against 2 ms for the integers.
    if mine.dtype != theirs.dtype:
        return False
    if _reversed_rows(mine) and _reversed_rows(theirs):  # both in their own order: no copies
        mine, theirs = mine[::-1], theirs[::-1]
    mine_bits, theirs_bits = _bits(mine), _bits(theirs)
    if not np.array_equal(mine_bits[::_PROBE_STRIDE], theirs_bits[::_PROBE_STRIDE]):
        return False
    return np.array_equal(mine_bits, theirs_bits)


class AOCache:
    def __init__(self):
        self._entries = {}

    def entry(self, key):
        """(AOInputs, ao, notes) stored under `key`, or None; notes: the
        library's about that AO (native.last_notes), said again where the AO
        is reused."""
        return self._entries.get(key)

    def get(self, key, inputs):
        """(ao, notes) stored under `key` for the same inputs, or None."""
        entry = self._entries.get(key)
        if entry is None or not entry[0].same_as(inputs):
            return None
        return entry[1], entry[2]

    def put(self, key, inputs, ao, notes):
        """Store `ao` (with its notes) as the AO of `inputs` under `key`,
        replacing what was there."""
        entries = dict(self._entries)
        entries[key] = (inputs, ao, notes)
        self._entries = entries

    def keep_only(self, entries):
        """Forget everything but `entries` {key: (AOInputs, ao, notes)}: this
        render's."""
        self._entries = dict(entries)

    def clear(self):
        self._entries = {}


# The last render's passes and AO of every node, keyed (main scene name, pass
# name): helper_ao.compute_passes fills it, re-compositing reads it
# (recomposite.py).
last_render = AOCache()
