#!/bin/sh
# SPDX-License-Identifier: GPL-2.0-or-later
# Feeds the hbao tool randomly truncated and byte-flipped copies of the test
# fixtures (the project's one mutation loop of the whole command line; the
# coverage-guided fuzzing of the code inside is scripts/fuzz.sh). Every run
# must end with exit status 0, or 1 with an "hbao: error: " line, and no
# sanitizer report, and no temporary file may be left; the first file that
# fails is kept as fuzz-crash-*.exr in the work folder and the script fails.
# The cases are the same for a seed; they run side by side, one a core ($JOBS
# when set), each in a folder of its own.
#
#   scripts/fuzz_cli.sh [CASES_PER_FIXTURE] [SEED]      (defaults: 500, 1)
#
# The tool is $HBAO_TOOL when set (tests/test_cli.py passes its build's);
# otherwise build-sanitize/hbao (AddressSanitizer + UndefinedBehaviorSanitizer),
# built when it is missing.
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
cases=${1:-500}
seed=${2:-1}
# shellcheck source=jobs.sh
. "$repo/scripts/jobs.sh"
jobs_check fuzz_cli.sh
tool=${HBAO_TOOL:-}
if [ -z "$tool" ]; then
    build="$repo/build-sanitize"
    tool="$build/hbao"
    if [ ! -x "$tool" ]; then
        cmake -S "$repo" -B "$build" -DHBAO_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DHBAO_BUILD_TESTS=OFF
        cmake --build "$build" -j2 --target hbao_tool
    fi
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/hbao-fuzz.XXXXXX")
echo "fuzz_cli.sh: $cases cases per fixture, seed $seed, work folder $work"
ASAN_OPTIONS=allocator_may_return_null=1:detect_leaks=1 \
UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
python3 - "$tool" "$repo/tests/fixtures" "$work" "$cases" "$seed" "${JOBS:-0}" <<'PYTHON'
import concurrent.futures
import os
import random
import shutil
import subprocess
import sys
from pathlib import Path

tool, fixtures, work, cases, seed, jobs = sys.argv[1:7]
work, rng = Path(work), random.Random(int(seed))
sources = sorted(Path(fixtures).glob("*.exr"))
if not sources:
    sys.exit(f"fuzz_cli.sh: no fixtures in {fixtures}")


def mutations():
    """Every case's bytes, in the order of the seed's random numbers."""
    for source in sources:
        data = source.read_bytes()
        for case in range(int(cases)):
            content = bytearray(data)
            if case % 3 == 0:
                content = content[:rng.randrange(len(content))]
            else:
                span = 400 if case % 3 == 1 else len(content)
                for _ in range(rng.randrange(1, 16)):
                    content[rng.randrange(min(span, len(content)))] = rng.randrange(256)
            yield source, case, bytes(content)


def run_case(source, case, content):
    """The case's two runs in a folder of its own; (exit statuses, None),
    or (None, the message) on the first bad run, whose input is kept."""
    folder = work / f"case-{source.stem}-{case}"
    folder.mkdir()
    mutated = folder / "input.exr"
    mutated.write_bytes(content)
    statuses = []
    for arguments in (["-o", folder / "out.exr", "--keep-input", "--preview", folder / "out.png"],
                      ["--info"]):
        command = [tool] + ([mutated] + arguments if arguments[0] == "-o"
                            else arguments + [mutated])
        completed = subprocess.run([str(c) for c in command], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.PIPE, text=True, errors="replace",
                                   timeout=120)
        bad = (completed.returncode not in (0, 1) or "Sanitizer" in completed.stderr
               or "runtime error" in completed.stderr
               or (completed.returncode == 1 and "hbao: error: " not in completed.stderr)
               or any(".hbao-tmp-" in p.name for p in folder.iterdir()))
        if bad:
            kept = work / f"fuzz-crash-{source.stem}-{case}.exr"
            kept.write_bytes(content)
            return None, (f"{completed.stderr[-4000:]}\n"
                          f"fuzz_cli.sh: exit {completed.returncode} on {kept}")
        statuses.append(completed.returncode)
    shutil.rmtree(folder)
    return statuses, None


# Each run is one process, so the cases run side by side, one a core ($JOBS
# when set): on 2 cores one at a time left a core idle for half the time.
counts = {0: 0, 1: 0}
workers = int(jobs) if int(jobs) > 0 else (os.cpu_count() or 1)
with concurrent.futures.ThreadPoolExecutor(workers) as pool:

    def tally(futures):
        for future in futures:
            statuses, failure = future.result()
            if failure:  # the runs under way end; those not begun never start
                pool.shutdown(wait=True, cancel_futures=True)
                sys.exit(failure)
            for status in statuses:
                counts[status] += 1

    pending = set()
    for mutation in mutations():  # a few cases a worker ahead, not all in memory
        pending.add(pool.submit(run_case, *mutation))
        if len(pending) >= 4 * workers:
            done, pending = concurrent.futures.wait(
                pending, return_when=concurrent.futures.FIRST_COMPLETED)
            tally(done)
    tally(concurrent.futures.as_completed(pending))
print(f"fuzz_cli.sh: {len(sources)} fixtures, {sum(counts.values())} runs: "
      f"{counts[0]} succeeded, {counts[1]} clean errors, 0 crashes")
PYTHON
rm -rf "$work"
