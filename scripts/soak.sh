#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The soak test (issue 13, item 5; docs/soak.md): a long `blender -b -a`
# animation render with the HBAO node (scripts/soak_blender.py) and the `hbao`
# tool run in a loop (scripts/soak_cli.py). Each checks that memory stays flat,
# time per frame or run stays steady, no temporary file is left and every
# output is there and valid. Prints a short report, writes it as Markdown and
# exits non-zero when a check fails.
#
#   scripts/soak.sh [--frames N] [--runs M] [--blender NAME] [--report PATH]
#
# Defaults: 250 frames, 1000 runs, Debian's blender (NAME as listed by
# `python3 scripts/blenders.py`, e.g. bpy-5.0), out/soak/report.md.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${HBAO_BUILD_DIR:-$REPO/build}"
# Blender's Python is the system's; a python3 earlier on PATH (pyenv's) would
# lend its own library path to the Blender processes started from it.
PYTHON="${PYTHON:-/usr/bin/python3}"
FRAMES=250
RUNS=1000
BLENDER_NAME=blender
REPORT="$REPO/out/soak/report.md"

usage() { sed -n '10,13p' "$0" | sed 's/^# \{0,1\}//'; exit "$1"; }
while [ $# -gt 0 ]; do
    case "$1" in
        --frames) FRAMES="$2"; shift 2 ;;
        --runs) RUNS="$2"; shift 2 ;;
        --blender) BLENDER_NAME="$2"; shift 2 ;;
        --report) REPORT="$2"; shift 2 ;;
        -h|--help) usage 0 ;;
        *) echo "soak.sh: unknown option $1" >&2; usage 2 ;;
    esac
done
[ -x /usr/bin/time ] || { echo "soak.sh: GNU time missing: apt-get install time" >&2; exit 2; }

# Incremental: quick when nothing changed, and never a stale library or tool.
cmake -S "$REPO" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DHBAO_BUILD_TOOL=ON >/dev/null
cmake --build "$BUILD" -j2 --target hbao hbao_exr hbao_tool >/dev/null

mkdir -p "$(dirname "$REPORT")"
PARTS="$(mktemp -d)"
trap 'rm -rf "$PARTS"' EXIT
export HBAO_BUILD_DIR="$BUILD"

status=0
"$PYTHON" "$REPO/scripts/soak_blender.py" --frames "$FRAMES" --blender "$BLENDER_NAME" \
    --report "$PARTS/blender.md" || status=1
"$PYTHON" "$REPO/scripts/soak_cli.py" --runs "$RUNS" --report "$PARTS/cli.md" || status=1

{
    echo "# Soak test report"
    echo
    echo "$(date -u '+%Y-%m-%d %H:%M UTC'), commit $(git -C "$REPO" rev-parse --short HEAD 2>/dev/null \
        || echo '?'), $(nproc) cores, load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)."
    echo "Command: \`scripts/soak.sh --frames $FRAMES --runs $RUNS --blender $BLENDER_NAME\`"
    echo
    cat "$PARTS/blender.md" 2>/dev/null || echo "(the animation soak wrote no report)"
    echo
    cat "$PARTS/cli.md" 2>/dev/null || echo "(the CLI soak wrote no report)"
    echo
    if [ "$status" -eq 0 ]; then echo "**Overall: PASS**"; else echo "**Overall: FAIL**"; fi
} > "$REPORT"
echo
echo "soak: report written to $REPORT"
if [ "$status" -eq 0 ]; then echo "soak: PASS"; else echo "soak: FAIL"; fi
exit "$status"
