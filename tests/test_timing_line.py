# SPDX-License-Identifier: GPL-2.0-or-later
"""addon/hbao/timing_line.py without Blender: the parser that the benchmarks
and the soak read the add-on's timing line with gives back the figures the
line was written from, in each of its forms. tests/test_addon.py holds the
parser to the lines of real renders."""
import pytest

from conftest import REPO  # noqa: F401  (puts the add-on on sys.path)
from hbao import timing_line

PLAIN = {"save": 0.0504, "read": 0.0136, "write": 0.0061, "ao": 0.1224}


def test_a_computed_frame():
    line = timing_line.format_line(2, 1920, 1080, 0.1917, PLAIN)
    assert line == ("2 AO pass(es) 1920x1080 in 192 ms: AO 122 ms, pass hand-over 70 ms "
                    "(save 50, read 14, write 6)")
    assert timing_line.parse("HBAO: " + line) == {
        "passes": 2, "width": 1920, "height": 1080, "total_ms": 192, "ao_ms": 122,
        "threads": 0, "search": "", "reused": 0, "handover_ms": 70, "save_ms": 50, "read_ms": 14,
        "capture_ms": 0, "write_ms": 6, "kept_ms": 0, "recomposited": False, "extras_ms": {}}


@pytest.mark.parametrize("extra, expected", [
    ({"cached": 1}, {"reused": 1, "recomposited": False, "extras_ms": {}}),
    ({"threads": 1}, {"threads": 1, "reused": 0}),
    ({"threads": 16, "cached": 1}, {"threads": 16, "reused": 1}),
    ({"threads": 4, "search": "AVX-512", "cached": 1},
     {"threads": 4, "search": "AVX-512", "reused": 1}),
    ({"threads": 1, "search": "generic"}, {"threads": 1, "search": "generic", "reused": 0}),
    ({"cached": 2, "kept": 0.118},
     {"reused": 2, "recomposited": True, "kept_ms": 118, "extras_ms": {}}),
    ({"guard band save": 0.061, "guard band read": 0.0192, "back faces save": 0.05,
      "back faces read": 0.0204},
     {"reused": 0, "recomposited": False, "extras_ms": {"guard band": 80, "back faces": 70}}),
    ({"cached": 1, "kept": 0.2, "back faces save": 0.0334},
     {"reused": 1, "recomposited": True, "kept_ms": 200, "extras_ms": {"back faces": 33}}),
])
def test_reuse_recompositing_and_extra_renders(extra, expected):
    line = timing_line.format_line(2, 640, 360, 0.25, dict(PLAIN, **extra))
    figures = timing_line.parse(line)
    assert figures is not None, line
    assert {key: figures[key] for key in expected} == expected, line
    assert (figures["ao_ms"], figures["handover_ms"], figures["write_ms"]) == (122, 70, 6), line


def test_other_lines_are_not_timing_lines():
    for text in ("HBAO: created helper scene '.HBAO Scene'",
                 "HBAO: 1 AO pass(es) 640x360 in 12 ms: AO 5 ms",
                 "bench-addon: {\"ao\": 1}", ""):
        assert timing_line.parse(text) is None, text


def test_passes_taken_from_memory():
    timings = {"capture": 0.0052, "write": 0.0031, "ao": 0.0424, "threads": 2}
    line = timing_line.format_line(1, 1920, 1080, 0.0511, timings)
    assert line == ("1 AO pass(es) 1920x1080 in 51 ms: AO 42 ms on 2 threads, pass hand-over "
                    "8 ms (from memory 5, write 3)")
    figures = timing_line.parse(line)
    assert {key: figures[key] for key in ("handover_ms", "capture_ms", "save_ms", "read_ms",
                                          "write_ms")} == {
        "handover_ms": 8, "capture_ms": 5, "save_ms": 0, "read_ms": 0, "write_ms": 3}, line
