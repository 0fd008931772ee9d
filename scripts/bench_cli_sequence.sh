#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The CLI on a sequence, as a render farm task runs it (issue 11): FRAMES
# frames (default 250), each a symbolic link to one 1920x1080 render of the
# demo scene (scripts/bench_cli_render.sh), computed by
#   hbao 'render_####.exr' -o 'ao_####.exr' --camera render.camera.json \
#        --frames 1-FRAMES -j JOBS
# twice in a new temporary folder: the first run computes every frame, the
# second finds every output up to date and skips it. Prints each run's wall
# time and frames per second. Exits 1 when a run fails, when an output is
# missing after the first run, or when the second run rewrites any output.
# --preview: each frame also writes its PNG preview (--preview 'ao_####.png'),
# which the second run checks too.
#   scripts/bench_cli_sequence.sh [--frames N] [--jobs J] [--preview]
#   (BLENDER=/path/to/blender renders; HBAO=/path/to/hbao runs another build)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
FRAMES=250
JOBS=2
PREVIEW=()
usage() {
    echo "usage: $0 [--frames N] [--jobs J] [--preview]   (N in [1, 9999], J in [1, 32])" >&2
    exit 2
}
while [ $# -gt 0 ]; do
    case "$1" in
        --frames) [ $# -ge 2 ] || usage; FRAMES="$2"; shift 2 ;;
        --jobs) [ $# -ge 2 ] || usage; JOBS="$2"; shift 2 ;;
        --preview) PREVIEW=(--preview 'ao_####.png'); shift ;;
        *) usage ;;
    esac
done
case "$FRAMES" in ''|*[!0-9]*) usage ;; esac
case "$JOBS" in ''|*[!0-9]*) usage ;; esac
[ ${#FRAMES} -le 4 ] && [ ${#JOBS} -le 2 ] || usage
FRAMES=$((10#$FRAMES))  # decimal, also with leading zeros
JOBS=$((10#$JOBS))
[ "$FRAMES" -ge 1 ] && [ "$FRAMES" -le 9999 ] && [ "$JOBS" -ge 1 ] && [ "$JOBS" -le 32 ] || usage

RENDER="$("$REPO/scripts/bench_cli_render.sh")"
HBAO="${HBAO:-$REPO/build/hbao}"  # (HBAO=path: another build of the tool)

WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
for ((frame = 1; frame <= FRAMES; frame++)); do
    ln -s "$RENDER.exr" "$WORK/$(printf 'render_%04d.exr' "$frame")"
done

run() {  # prints the run's wall seconds; returns hbao's exit status
    local start end status=0
    start=$(date +%s.%N)
    (cd "$WORK" && "$HBAO" 'render_####.exr' -o 'ao_####.exr' --camera "$RENDER.camera.json" \
        --frames "1-$FRAMES" -j "$JOBS" "${PREVIEW[@]}" 2>"$WORK/log.txt") || status=$?
    end=$(date +%s.%N)
    echo "$start $end" | awk '{printf "%.3f", $2 - $1}'
    return "$status"
}

echo "hbao on $FRAMES frames of $(basename "$RENDER").exr ($(du -Lh "$RENDER.exr" | cut -f1)" \
     "each), -j $JOBS${PREVIEW:+, with previews}, $(nproc) cores"
first=$(run) || { echo "first run failed:" >&2; tail -n 20 "$WORK/log.txt" >&2; exit 1; }
computed=$(ls "$WORK" | grep -c '^ao_[0-9]*\.exr$' || true)
previews=$(ls "$WORK" | grep -c '^ao_[0-9]*\.png$' || true)
if [ "$computed" -ne "$FRAMES" ] || { [ ${#PREVIEW[@]} -gt 0 ] && [ "$previews" -ne "$FRAMES" ]; }; then
    echo "first run wrote $computed of $FRAMES outputs ($previews previews)" >&2
    exit 1
fi
outputs() { (cd "$WORK" && stat -c '%n %Y.%y' ao_* | md5sum); }
before=$(outputs)
second=$(run) || { echo "second run failed:" >&2; tail -n 20 "$WORK/log.txt" >&2; exit 1; }
after=$(outputs)
skipped=$(grep -c 'is up to date, skipped' "$WORK/log.txt" || true)
if [ "$before" != "$after" ] || [ "$skipped" -ne "$FRAMES" ]; then
    echo "second run rewrote outputs (skipped $skipped of $FRAMES)" >&2
    exit 1
fi
awk -v n="$FRAMES" -v a="$first" -v b="$second" 'BEGIN {
    printf "first run (every frame computed): %.1f s, %.2f frames/s, %.0f ms a frame\n", a, n / a, 1000 * a / n
    printf "second run (every output up to date, skipped): %.3f s\n", b
}'
