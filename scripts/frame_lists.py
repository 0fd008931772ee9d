# SPDX-License-Identifier: GPL-2.0-or-later
"""Frame lists as the `hbao` CLI's --frames takes them ("1-250",
"1-10,20,30-40", "1-250x2" for every second frame), for
scripts/export_cameras.py. The CLI's parser is C (csrc/tool/frame_pattern.c);
tests/test_cli.py runs one table of lists through both and holds these
constants to its header. bpy-free."""
import math
import re

# Blender's MAXFRAME, the CLI's frames run from 0 to it; its most ranges.
FRAME_MAX = 1048574
FRAME_RANGES_MAX = 64
# A frame number as the CLI reads it: ASCII digits, fewer than 16 of them.
_NUMBER = r"[0-9]{1,15}"
_RANGE = re.compile(rf"({_NUMBER})(?:-({_NUMBER})(?:x({_NUMBER}))?)?")


def _share_a_frame(a, b):
    """Whether ranges (first, last, step) a and b have a frame in common
    (the congruences solved, as the CLI does: no frame walked)."""
    (first_a, last_a, step_a), (first_b, last_b, step_b) = a, b
    low, high = max(first_a, first_b), min(last_a, last_b)
    divisor = math.gcd(step_a, step_b)
    if low > high or (first_b - first_a) % divisor != 0:
        return False
    modulus = step_b // divisor
    t = (first_b - first_a) // divisor * pow(step_a // divisor, -1, modulus) % modulus \
        if modulus > 1 else 0
    period = step_a // divisor * step_b
    frame = first_a + step_a * t
    if frame < low:
        frame += -(-(low - frame) // period) * period
    return frame <= high


def parse(text):
    """[frames] of `text`, in the order given; ValueError saying why not."""
    parts = text.split(",")
    if len(parts) > FRAME_RANGES_MAX:
        raise ValueError(f"{text!r}: more than {FRAME_RANGES_MAX} ranges")
    ranges = []
    for part in parts:
        match = _RANGE.fullmatch(part)
        if match is None:
            raise ValueError(f"{text!r} is not a frame list like 1-250, 1-10,20 or 1-250x2")
        first = int(match.group(1))
        last = int(match.group(2)) if match.group(2) is not None else first
        step = int(match.group(3)) if match.group(3) is not None else 1
        if first > last or last > FRAME_MAX or not 1 <= step <= FRAME_MAX:
            raise ValueError(f"{part!r}: frames run from 0 to {FRAME_MAX}, first to last, by a "
                             f"step of 1 or more")
        last -= (last - first) % step
        if any(_share_a_frame((first, last, step), other) for other in ranges):
            raise ValueError(f"{text!r}: ranges overlap")
        ranges.append((first, last, step))
    return [frame for first, last, step in ranges for frame in range(first, last + 1, step)]
