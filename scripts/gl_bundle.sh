#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# What scripts/bench_viewport_gl.py needs on a bare Linux x86-64 machine with
# a GPU driver and Python 3.12 but no packages and no network (a lent GPU
# machine), bundled here into gl-bundle/ (git-ignored through
# .git/info/exclude): the EGL loader's Debian packages, the moderngl and
# glcontext wheels for Python 3.12, and this checkout's libhbao (built first).
# On that machine, from the checkout's root, with gl-bundle/ carried there:
#   scripts/gl_bundle.sh --run [bench_viewport_gl.py's options]
# unpacks the packages, installs the wheels into /tmp/gl-site and runs the
# benchmark (docs/speed.md, session 48). The unpacking writes into / and runs
# ldconfig: only on a machine that is thrown away afterwards.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUNDLE="$REPO/gl-bundle"
PACKAGES=(libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
WHEELS=(moderngl==5.13.0 glcontext==3.1.0)

if [ "${1:-}" = "--run" ]; then
    shift
    for deb in "$BUNDLE"/debs/*.deb; do dpkg -x "$deb" /; done
    ldconfig
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/gl-site "$BUNDLE"/wheels/*.whl
    vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    if [ -f "$vendor" ]; then export __EGL_VENDOR_LIBRARY_FILENAMES="$vendor"; fi
    PYTHONPATH=/tmp/gl-site HBAO_LIBRARY="$BUNDLE/libhbao.so" PYTHONUNBUFFERED=1 \
        exec python3 "$REPO/scripts/bench_viewport_gl.py" "$@"
fi

grep -qx "/gl-bundle/" "$REPO/.git/info/exclude" 2>/dev/null ||
    echo "/gl-bundle/" >> "$REPO/.git/info/exclude"
# only what an earlier bundle put there: anything else in gl-bundle/ stays
rm -rf "$BUNDLE/debs" "$BUNDLE/wheels" "$BUNDLE/libhbao.so"
mkdir -p "$BUNDLE/debs" "$BUNDLE/wheels"
cmake -S "$REPO" -B "$REPO/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$REPO/build" -j2 --target hbao >/dev/null
cp "$(readlink -f "$REPO/build/libhbao.so")" "$BUNDLE/libhbao.so"
# amd64 packages whatever this machine's architecture, from apt's own lists
lists="$(mktemp -d)"
trap 'rm -rf "$lists"' EXIT
mkdir -p "$lists/partial"
apt=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists")
apt-get "${apt[@]}" update >/dev/null
(cd "$BUNDLE/debs" && apt-get "${apt[@]}" download "${PACKAGES[@]}" >/dev/null 2>&1)
python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 \
    --implementation cp --platform manylinux_2_28_x86_64 --platform manylinux_2_17_x86_64 \
    --platform manylinux2014_x86_64 --platform manylinux1_x86_64 -d "$BUNDLE/wheels" "${WHEELS[@]}"
du -sh "$BUNDLE"
