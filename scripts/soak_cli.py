# SPDX-License-Identifier: GPL-2.0-or-later
"""Soak test of the `hbao` command-line tool (issue 13, item 5).

  python3 scripts/soak_cli.py [--runs M] [--fixture NAME] [--report PART.md]

Runs `hbao FIXTURE.exr -o OUT/ao.exr --camera FIXTURE.camera.json --preview
OUT/ao.png` M times in a loop, each run replacing the last run's outputs as a
render farm's repeated job would, and checks after every run:

- the exit status is 0;
- the output folder holds exactly ao.exr and ao.png (no `.hbao-tmp-` file or
  anything else left behind);
- `hbao --info --json OUT/ao.exr` reads an AO channel with every pixel finite
  and in [0, 1], and its statistics are those of the first run (the tool is
  deterministic), and the PNG starts with the PNG signature;
- at the end, the input fixture is byte for byte what it was.

Measured per run: the peak RSS (GNU time's %M: the tool's own maximum
resident set; Python's wait4 would report this Python's, which the child
inherits at fork), the wall time and the CPU time (wait4). Reported: the
medians of the first and last 100 runs. Prints a summary, writes it as
Markdown to --report, exits 1 if a check fails."""
import argparse
import hashlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BUILD = Path(os.environ.get("HBAO_BUILD_DIR", REPO / "build"))
FIXTURES = REPO / "tests" / "fixtures"
GNU_TIME = "/usr/bin/time"

DEFAULT_RUNS = 1000
DEFAULT_FIXTURE = "cycles_float_zip"
# Runs compared for steadiness (the first and the last this many).
STEADY_WINDOW = 100
# Every run is a fresh process, so its peak RSS should not depend on how many
# runs came before; anything that does (a cache or log growing on disk and
# read back, say) shows as growth. 1 MiB is 256 pages: far above the few
# pages that the loader's and allocator's randomisation move.
RSS_GROWTH_LIMIT_MIB = 1.0
# The last runs' median CPU time may be at most this multiple of the first
# runs'. CPU time, not wall time: the machine is shared and its load changes.
CPU_SLOWDOWN_LIMIT = 2.0
RUN_TIMEOUT_S = 60
# The report quotes the first few problems; the counts cover all of them.
SHOWN_PROBLEMS = 3
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
EXPECTED_OUTPUTS = {"ao.exr", "ao.png"}
MIB = 1024.0


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def run_measured(command, rss_file, log_file):
    """(exit status, peak RSS in KiB, wall s, CPU s) of one run of `command`."""
    start = time.monotonic()
    with open(log_file, "wb") as log:
        process = subprocess.Popen([GNU_TIME, "-o", str(rss_file), "-f", "%M"] + command,
                                   stdout=log, stderr=subprocess.STDOUT)
        # wait4: the CPU time of time(1) and of the tool it waited for.
        _, status, usage = os.wait4(process.pid, 0)
    wall = time.monotonic() - start
    code = os.waitstatus_to_exitcode(status)
    process.returncode = code  # reaped here: Popen must not wait for it again
    try:
        # time(1) writes a "Command exited with non-zero status" line first.
        rss = int(rss_file.read_text().split()[-1])
    except (OSError, ValueError, IndexError):
        rss = -1
    return code, rss, wall, usage.ru_utime + usage.ru_stime


def ao_statistics(tool, path):
    completed = subprocess.run([str(tool), "--info", "--json", str(path)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, timeout=RUN_TIMEOUT_S)
    if completed.returncode != 0:
        return None, completed.stderr.strip()
    description = json.loads(completed.stdout)
    channel = next((c for c in description["channels"] if c["name"] == "AO"), None)
    if channel is None:
        return None, "no AO channel"
    pixels = description["width"] * description["height"]
    if channel["nonfinite"] != 0 or channel["finite"] != pixels:
        return None, f"{channel['nonfinite']} non-finite AO value(s)"
    if not 0 <= channel["min"] <= channel["max"] <= 1:
        return None, f"AO outside [0, 1]: {channel['min']}..{channel['max']}"
    return (channel["min"], channel["max"], channel["mean"]), None


def median(values):
    return statistics.median(values) if values else float("nan")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=DEFAULT_RUNS)
    parser.add_argument("--fixture", default=DEFAULT_FIXTURE,
                        help="a tests/fixtures name with a Depth pass")
    parser.add_argument("--report", type=Path, help="write the Markdown section here")
    options = parser.parse_args(argv)
    if options.runs < 2 * STEADY_WINDOW:
        print(f"soak_cli.py: fewer than {2 * STEADY_WINDOW} runs: the first and last "
              f"windows overlap", file=sys.stderr)
    tool = BUILD / "hbao"
    source = FIXTURES / f"{options.fixture}.exr"
    camera = FIXTURES / f"{options.fixture}.camera.json"
    for needed in (tool, source, Path(GNU_TIME)):
        if not needed.exists():
            sys.exit(f"soak_cli.py: {needed} missing (build first; GNU time is Debian's "
                     f"package `time`)")
    source_hash = sha256(source)

    root = Path(tempfile.mkdtemp(prefix="hbao-soak-cli-"))
    output = root / "out"
    output.mkdir()
    command = [str(tool), str(source), "-o", str(output / "ao.exr"),
               "--preview", str(output / "ao.png")]
    if camera.is_file():
        command += ["--camera", str(camera)]
    rss, wall, cpu = [], [], []
    failures, reference = [], None
    failed_runs = leftover_runs = invalid_runs = 0
    print(f"soak: {options.runs} runs of: {' '.join(command)}", flush=True)
    start = time.monotonic()
    try:
        for run in range(1, options.runs + 1):
            code, peak, seconds, cpu_seconds = run_measured(command, root / "rss.txt",
                                                            root / "run.log")
            rss.append(peak)
            wall.append(seconds)
            cpu.append(cpu_seconds)
            problem = None
            if code != 0:
                failed_runs += 1
                problem = f"run {run}: exit status {code}: " + \
                    (root / "run.log").read_text(errors="replace").strip()[-200:]
            left = sorted(set(os.listdir(output)) - EXPECTED_OUTPUTS)
            if left:
                leftover_runs += 1
                problem = problem or f"run {run}: left {', '.join(left)}"
                for name in left:  # so the next run's check is its own
                    os.remove(output / name)
            statistics_, error = ao_statistics(tool, output / "ao.exr")
            png_ok = (output / "ao.png").is_file() and \
                (output / "ao.png").read_bytes()[:8] == PNG_SIGNATURE
            if reference is None and statistics_ is not None:
                reference = statistics_
            if error or not png_ok or statistics_ != reference:
                invalid_runs += 1
                problem = problem or (f"run {run}: invalid output: "
                                      f"{error or ('bad PNG' if not png_ok else 'AO differs')}")
            if problem and len(failures) < SHOWN_PROBLEMS:
                failures.append(problem)
            if run % 250 == 0:
                print(f"  run {run}: peak RSS {peak / MIB:.2f} MiB, "
                      f"{seconds * 1000:.0f} ms", flush=True)
    finally:
        elapsed = time.monotonic() - start
        shutil.rmtree(root, ignore_errors=True)

    source_unchanged = sha256(source) == source_hash
    window = min(STEADY_WINDOW, len(rss))
    rss_first, rss_last = median(rss[:window]) / MIB, median(rss[-window:]) / MIB
    growth = rss_last - rss_first
    cpu_first, cpu_last = median(cpu[:window]), median(cpu[-window:])
    if failed_runs or leftover_runs or invalid_runs:
        failures.insert(0, f"{failed_runs} failed run(s), {leftover_runs} with leftovers, "
                           f"{invalid_runs} with an invalid output")
    if min(rss) < 0:
        failures.append("GNU time gave no peak RSS for some run")
    if not growth <= RSS_GROWTH_LIMIT_MIB:
        failures.append(f"peak RSS grew {growth:.2f} MiB (limit {RSS_GROWTH_LIMIT_MIB:g})")
    if not cpu_last <= CPU_SLOWDOWN_LIMIT * cpu_first:
        failures.append(f"CPU time per run grew beyond {CPU_SLOWDOWN_LIMIT:g}x")
    if not source_unchanged:
        failures.append("the input fixture changed")

    display = ["hbao" if c == str(tool) else os.path.relpath(c, REPO)
               if c.startswith(str(REPO)) else c.replace(str(output), "OUT") for c in command]
    lines = [
        f"### CLI loop: {options.runs} runs",
        "",
        f"Command (OUT a fresh temp folder, outputs replaced each run): `{' '.join(display)}`",
        "",
        f"- {options.runs - failed_runs}/{options.runs} runs exited 0; {leftover_runs} left a "
        f"file other than ao.exr and ao.png in OUT; {invalid_runs} gave an invalid or "
        f"different AO (checked with `hbao --info --json` after every run); input "
        f"{'unchanged' if source_unchanged else 'CHANGED'}; {elapsed:.0f} s in all.",
        f"- Peak RSS per run (GNU time %M): median {rss_first:.2f} MiB over the first "
        f"{window}, {rss_last:.2f} MiB over the last {window} (growth {growth:+.2f} MiB, limit "
        f"{RSS_GROWTH_LIMIT_MIB:g}); min {min(rss) / MIB:.2f}, max {max(rss) / MIB:.2f} MiB.",
        f"- Wall time per run: median {median(wall) * 1000:.1f} ms; first {window} "
        f"{median(wall[:window]) * 1000:.1f} ms, last {window} "
        f"{median(wall[-window:]) * 1000:.1f} ms (medians); max {max(wall) * 1000:.0f} ms.",
        f"- CPU time per run: median {median(cpu) * 1000:.1f} ms; first {window} "
        f"{cpu_first * 1000:.1f} ms, last {window} {cpu_last * 1000:.1f} ms (limit: last <= "
        f"{CPU_SLOWDOWN_LIMIT:g}x first).",
        "",
        "**Result: " + ("PASS**" if not failures else "FAIL**: " + "; ".join(failures)),
        "",
    ]
    text = "\n".join(lines)
    print(text, flush=True)
    if options.report:
        options.report.parent.mkdir(parents=True, exist_ok=True)
        options.report.write_text(text)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
