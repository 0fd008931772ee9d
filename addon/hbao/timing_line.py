# SPDX-License-Identifier: GPL-2.0-or-later
"""The add-on's timing line, printed once per helper render (console and
render stats), and the one parser of it that the benchmarks and the soak
read it with. bpy-free.

    2 AO pass(es) 1920x1080 in 190 ms: AO 120 ms on 8 threads with AVX-512
    (1 of 2 unchanged: reused), pass hand-over 70 ms (save 50, read 14, write 6)
    [, re-composited ...]
    [...] pass hand-over 8 ms (from memory 5, write 3) [...]   (pass_capture.py)
    [, guard band passes 80 ms][, back faces passes 75 ms][ from memory]
"""
import re

_LINE = re.compile(
    r"(?P<passes>\d+) AO pass\(es\) (?P<width>\d+)x(?P<height>\d+) in (?P<total_ms>\d+) ms: "
    r"AO (?P<ao_ms>\d+) ms(?: on (?P<threads>\d+) threads?)?(?: with (?P<search>[\w-]+))?"
    r"(?: \((?P<reused>\d+) of \d+ unchanged: reused\))?, "
    r"pass hand-over (?P<handover_ms>\d+) ms "
    r"\((?:save (?P<save_ms>\d+), read (?P<read_ms>\d+)|from memory (?P<capture_ms>\d+)), "
    r"write (?P<write_ms>\d+)\)"
    r"(?P<recomposited>, re-composited"
    r"(?:[^(]*\(their AO computed beforehand in (?P<kept_ms>\d+) ms\))?)?")
_EXTRA = re.compile(r", (?P<kind>[a-z ]+) passes (?P<ms>\d+) ms")


def format_line(count, width, height, total, timings):
    """The line for a helper render of `count` AO passes: `total` and the
    values of `timings` in seconds (save and read, or capture: the passes
    taken from memory; write, ao, kept, and "<kind> save" and "<kind>
    read" for each extra render's passes, layer_passes.py),
    `timings["cached"]` the passes reused, `timings["threads"]` the
    AO's threads and `timings["search"]` the horizon search that ran
    (native.search_name())."""
    milliseconds = {name: timings.get(name, 0.0) * 1000
                    for name in ("save", "read", "capture", "write", "ao")}
    handover_ms = sum(milliseconds[name] for name in ("save", "read", "capture", "write"))
    cached = f" ({timings['cached']} of {count} unchanged: reused)" if "cached" in timings else ""
    threads = timings.get("threads")
    on = "" if threads is None else f" on {threads} thread{'' if threads == 1 else 's'}"
    if "search" in timings:
        on += f" with {timings['search']}"
    if "capture" in timings:
        passes = f"from memory {milliseconds['capture']:.0f}"
    else:
        passes = f"save {milliseconds['save']:.0f}, read {milliseconds['read']:.0f}"
    line = (f"{count} AO pass(es) {width}x{height} in {total * 1000:.0f} ms: AO "
            f"{milliseconds['ao']:.0f} ms{on}{cached}, pass hand-over {handover_ms:.0f} ms "
            f"({passes}, write {milliseconds['write']:.0f})")
    if "kept" in timings:
        line += (f", re-composited with new settings from the last render's passes (their AO "
                 f"computed beforehand in {timings['kept'] * 1000:.0f} ms)")
    kinds = dict.fromkeys(key.rsplit(" ", 1)[0] for key in timings
                          if key.endswith((" save", " capture")))
    for kind in kinds:
        seconds = sum(timings.get(f"{kind} {name}", 0.0) for name in ("save", "read", "capture"))
        memory = " from memory" if f"{kind} capture" in timings else ""
        line += f", {kind} passes {seconds * 1000:.0f} ms{memory}"
    return line


def parse(text):
    """The figures of the timing line found in `text` (a log line, with or
    without the "HBAO: " prefix), or None: passes, width, height and the
    milliseconds as ints (total_ms, ao_ms, handover_ms, save_ms, read_ms,
    capture_ms: the passes taken from memory, write_ms, kept_ms: a
    re-composite's AO, computed before its render; 0 where absent),
    threads (the AO's, 0 where the line has none), search (the horizon
    search's name, "" where the line has none), reused (passes whose AO
    was reused, 0 if none), recomposited (bool) and extras_ms ({kind: ms}
    for the extra renders' passes)."""
    match = _LINE.search(text)
    if match is None:
        return None
    found = {name: int(value) for name, value in match.groupdict(default="0").items()
             if name not in ("recomposited", "search")}
    found["search"] = match.group("search") or ""
    found["recomposited"] = match.group("recomposited") is not None
    found["extras_ms"] = {extra.group("kind"): int(extra.group("ms"))
                          for extra in _EXTRA.finditer(text, match.end())}
    return found
