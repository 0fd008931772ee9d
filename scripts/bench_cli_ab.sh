#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Two builds of the hbao tool on one CLI frame, taking turns: the 1080p
# render of scripts/bench_cli_render.sh (Combined, Depth, Normal; ZIP),
#   hbao render.exr -o ao.exr --camera render.camera.json --threads T [FLAGS]
# with BEFORE, then AFTER, RUNS rounds (default 15) after one warm-up round
# each. Prints each build's median CPU seconds (user + system) and wall
# seconds a frame, fastest and slowest round in brackets, the median of the
# rounds' after/before ratios, and whether the two builds' outputs decode to
# the same AO (hbao --info's channel statistics). BEFORE and AFTER are copies
# of the tool (build/hbao-before, say: the tool finds libhbao.so.0 in its own
# folder), not build/hbao itself, which making the render rebuilds.
#   scripts/bench_cli_ab.sh BEFORE/hbao AFTER/hbao [--runs N] [--threads T] [-- FLAGS...]
#   (BLENDER=/path/to/blender renders)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
usage() {
    echo "usage: $0 BEFORE AFTER [--runs N] [--threads T] [-- FLAGS...]" \
        "  (N in [1, 99], T in [1, 64])" >&2
    exit 2
}
[ $# -ge 2 ] || usage
BEFORE="$1"
AFTER="$2"
shift 2
[ -x "$BEFORE" ] && [ -x "$AFTER" ] || { echo "$0: BEFORE and AFTER must be programs" >&2; exit 2; }
for build in "$BEFORE" "$AFTER"; do
    if [ "$(realpath "$build")" = "$(realpath -m "$REPO/build/hbao")" ]; then
        echo "$0: $build is rebuilt from this tree before the frames: give a copy" >&2
        exit 2
    fi
done
RUNS=15
THREADS=1
FLAGS=()
while [ $# -gt 0 ]; do
    case "$1" in
        --runs) [ $# -ge 2 ] || usage; RUNS="$2"; shift 2 ;;
        --threads) [ $# -ge 2 ] || usage; THREADS="$2"; shift 2 ;;
        --) shift; FLAGS=("$@"); break ;;
        *) usage ;;
    esac
done
for value in "$RUNS" "$THREADS"; do
    case "$value" in ''|*[!0-9]*) usage ;; esac
    [ ${#value} -le 2 ] || usage
done
RUNS=$((10#$RUNS))
THREADS=$((10#$THREADS))
[ "$RUNS" -ge 1 ] && [ "$THREADS" -ge 1 ] && [ "$THREADS" -le 64 ] || usage

RENDER="$("$REPO/scripts/bench_cli_render.sh")"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

frame() {  # frame BUILD NAME: prints "cpu wall" seconds of one frame
    /usr/bin/time -f '%U %S %e' -o "$WORK/time.txt" \
        "$1" "$RENDER.exr" -o "$WORK/$2.exr" --camera "$RENDER.camera.json" \
        --threads "$THREADS" "${FLAGS[@]}" 2>"$WORK/log.txt" ||
        { echo "$1 failed:" >&2; cat "$WORK/log.txt" >&2; exit 1; }
    awk '{ printf "%.3f %.3f\n", $1 + $2, $3 }' "$WORK/time.txt"
}

frame "$BEFORE" before >/dev/null
frame "$AFTER" after >/dev/null
: >"$WORK/rounds.txt"
for ((round = 1; round <= RUNS; round++)); do
    # (assignments, so that a failed frame stops the script: set -e does
    # not see a substitution inside echo's arguments)
    before=$(frame "$BEFORE" before)
    after=$(frame "$AFTER" after)
    echo "$before $after" >>"$WORK/rounds.txt"
done
ao_before=$("$BEFORE" --info "$WORK/before.exr" | grep -E '^ +AO ')
ao_after=$("$AFTER" --info "$WORK/after.exr" | grep -E '^ +AO ')
same=no
if [ -n "$ao_before" ] && [ "$ao_before" = "$ao_after" ]; then
    same=yes
fi
echo "hbao on $(basename "$RENDER").exr, --threads $THREADS ${FLAGS[*]}, $RUNS rounds," \
    "$(nproc) cores; output sizes: before $(stat -c %s "$WORK/before.exr")," \
    "after $(stat -c %s "$WORK/after.exr") bytes; same AO statistics: $same"
sort_column() { awk -v c="$1" '{ print $c }' "$WORK/rounds.txt" | sort -g; }
median() { awk '{ v[NR] = $1 } END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'; }
summary() {  # summary NAME CPU_COLUMN WALL_COLUMN
    local cpu wall
    cpu=$(sort_column "$2")
    wall=$(sort_column "$3")
    printf '%-7s CPU %.3f s [%s-%s], wall %.3f s [%s-%s]\n' "$1" \
        "$(echo "$cpu" | median)" "$(echo "$cpu" | head -1)" "$(echo "$cpu" | tail -1)" \
        "$(echo "$wall" | median)" "$(echo "$wall" | head -1)" "$(echo "$wall" | tail -1)"
}
summary before 1 2
summary after 3 4
ratio() { awk -v a="$1" -v b="$2" '$a > 0 { print $b / $a }' "$WORK/rounds.txt" | sort -g | median; }
printf 'after / before (median of the rounds): CPU %.3f, wall %.3f\n' "$(ratio 1 3)" "$(ratio 2 4)"
