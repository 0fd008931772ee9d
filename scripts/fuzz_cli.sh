#!/bin/sh
# SPDX-License-Identifier: GPL-2.0-or-later
# Feeds the hbao tool randomly truncated and byte-flipped copies of the test
# fixtures (the project's one mutation loop of the whole command line; the
# coverage-guided fuzzing of the code inside is scripts/fuzz.sh). Every run
# must end with exit status 0, or 1 with an "hbao: error: " line, and no
# sanitizer report, and no temporary file may be left; the first file that
# fails is kept as fuzz-crash-*.exr in the work folder and the script fails.
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
python3 - "$tool" "$repo/tests/fixtures" "$work" "$cases" "$seed" <<'PYTHON'
import random
import subprocess
import sys
from pathlib import Path

tool, fixtures, work, cases, seed = sys.argv[1:6]
work, rng = Path(work), random.Random(int(seed))
sources = sorted(Path(fixtures).glob("*.exr"))
if not sources:
    sys.exit(f"fuzz_cli.sh: no fixtures in {fixtures}")
counts = {0: 0, 1: 0}
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
        mutated = work / "input.exr"
        mutated.write_bytes(bytes(content))
        for arguments in (["-o", work / "out.exr", "--keep-input", "--preview", work / "out.png"],
                          ["--info"]):
            command = [tool] + ([mutated] + arguments if arguments[0] == "-o"
                                else arguments + [mutated])
            completed = subprocess.run([str(c) for c in command], stdout=subprocess.DEVNULL,
                                       stderr=subprocess.PIPE, text=True, errors="replace",
                                       timeout=120)
            bad = (completed.returncode not in counts or "Sanitizer" in completed.stderr
                   or "runtime error" in completed.stderr
                   or (completed.returncode == 1 and "hbao: error: " not in completed.stderr)
                   or any(".hbao-tmp-" in p.name for p in work.iterdir()))
            if bad:
                kept = work / f"fuzz-crash-{source.stem}-{case}.exr"
                kept.write_bytes(bytes(content))
                print(completed.stderr[-4000:])
                sys.exit(f"fuzz_cli.sh: exit {completed.returncode} on {kept}")
            counts[completed.returncode] += 1
print(f"fuzz_cli.sh: {len(sources)} fixtures, {sum(counts.values())} runs: "
      f"{counts[0]} succeeded, {counts[1]} clean errors, 0 crashes")
PYTHON
rm -rf "$work"
