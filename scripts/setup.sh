#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Installs what building, testing and running the demo need on Debian 12 or 13
# (Debian's Blender, the C toolchain, clang with its sanitizer and libFuzzer
# runtime, a cross compiler for ARM64 and qemu-user to run its tests, OpenEXR,
# libpng, cJSON, libdeflate, numpy, pytest, Xvfb). PyPI's bpy builds come
# from scripts/setup_bpy.sh. Idempotent: does nothing when everything is there.
set -euo pipefail

# clang's runtime libraries (ASan, UBSan, libFuzzer) are packaged per LLVM
# version: 14 on Debian 12 (libclang-rt-14-dev), 19 on Debian 13 (libclang-rt-19-dev).
case "$(cut -d. -f1 /etc/debian_version 2>/dev/null)" in
    12) LLVM=14 ;;
    13) LLVM=19 ;;
    *)  LLVM="$(apt-cache search --names-only '^libclang-rt-[0-9]+-dev$' 2>/dev/null |
               sed -n 's/^libclang-rt-\([0-9]*\)-dev.*/\1/p' | sort -n | tail -n 1)"
        LLVM="${LLVM:-14}" ;;
esac

PACKAGES=(
    blender            # the add-on's UI tests (3.4.1 on Debian 12, 4.3 on 13)
    cmake gcc make pkg-config
    clang "libclang-rt-$LLVM-dev"  # the SIMD kernels; fuzz targets (libFuzzer, ASan, UBSan); LLVM $LLVM
    clang-format                 # the C style check (.clang-format)
    gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user  # scripts/test_arm64.sh: ARM64 build, run emulated
    libopenexr-dev     # OpenEXRCore, the EXR reader/writer of the CLI
    openexr            # exrheader: the reference reader our written EXRs are checked with
    libpng-dev         # --preview PNGs
    libcjson-dev       # --camera FILE.json
    libdeflate-dev     # the CLI's inflate and deflate of ZIP chunks (csrc/tool/zip_chunks.c)
    python3 python3-numpy python3-pytest python3-venv
    python3-pytest-xdist  # scripts/test.sh: the Python tests on one worker a core
    python3-pycodestyle  # the PEP 8 check of the test suite
    python3-moderngl   # scripts/bench_viewport_gl.py: the preview's passes on a GPU without Blender
    libegl1            # its EGL context (Mesa's here), which moderngl opens without depending on it
    xvfb xauth         # F12 and viewport tests in a real window
    xdotool            # tests/test_faults_ui.py: a real Escape key press during F12
    time               # scripts/soak.sh: GNU time's peak memory of each run
    binutils           # readelf: tests/test_cli.py checks where the tool finds libhbao
    locales            # localedef's sources: tests/test_faults.py makes an ISO-8859-1 locale
    acl                # setfacl, getfacl: tests/test_cli.py checks outputs under a default ACL
)

missing=()
for package in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$package")
    fi
done
if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

SUDO=()
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null; then
        SUDO=(sudo)
    else
        echo "setup.sh: need root (or sudo) to install: ${missing[*]}" >&2
        exit 1
    fi
fi
echo "setup.sh: installing ${missing[*]}"
"${SUDO[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
