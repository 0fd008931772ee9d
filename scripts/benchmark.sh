#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The accuracy benchmark (issue 5): HBAO's run time against its error, and its
# accuracy against Cycles' ray-traced AO and EEVEE's GTAO, on four scenes.
# Writes docs/benchmark.md and docs/benchmark/*.png; caches renders in
# .cache/bench/ so that a rerun renders only what is missing.
#   scripts/benchmark.sh [--quick]     (--quick: 480x270, a few minutes)
# Installs its extra packages first (assimp-testmodels, python3-matplotlib,
# npm and the npm package `bunny`); idempotent.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
CACHE="$REPO/.cache/bench"

"$REPO/scripts/setup.sh"
EXTRA=(
    assimp-testmodels   # the mechanical scene's model (STL/3DSMaxExport.STL)
    python3-matplotlib  # the report's plots and image strips
)
missing=()
for package in "${EXTRA[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$package")
    fi
done
# npm fetches the Stanford bunny (npm package `bunny`); any npm on PATH will do
# (NodeSource's nodejs bundles one that conflicts with Debian's npm package).
command -v npm >/dev/null || missing+=(npm)
if [ ${#missing[@]} -gt 0 ]; then
    SUDO=()
    [ "$(id -u)" -ne 0 ] && SUDO=(sudo)
    echo "benchmark.sh: installing ${missing[*]}"
    "${SUDO[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${SUDO[@]}" apt-get install -y -qq --no-install-recommends \
        "${missing[@]}" >/dev/null
fi

# The bunny: npm's `bunny` (positions + cells of the Stanford bunny) as JSON.
mkdir -p "$CACHE/npm"
if [ ! -s "$CACHE/bunny.json" ]; then
    if [ ! -d "$CACHE/npm/node_modules/bunny" ]; then
        (cd "$CACHE/npm" && npm install --no-audit --no-fund --silent bunny@1)
    fi
    (cd "$CACHE/npm" && node -e 'process.stdout.write(JSON.stringify(require("bunny")))') \
        > "$CACHE/bunny.json.tmp"
    mv "$CACHE/bunny.json.tmp" "$CACHE/bunny.json"
fi

cmake -S "$REPO" -B "$REPO/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$REPO/build" -j2 --target hbao hbao_exr >/dev/null
exec /usr/bin/python3 "$REPO/bench/run_benchmark.py" "$@"
