#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Installs what building, testing and running the demo need on Debian 12
# (Blender 3.4 from Debian, the C toolchain, OpenEXR, libpng, cJSON, numpy,
# pytest, Xvfb). Idempotent: does nothing when everything is installed.
set -euo pipefail

PACKAGES=(
    blender            # the renderer the add-on runs in (3.4.1 on Debian 12)
    cmake gcc make pkg-config
    libopenexr-dev     # OpenEXRCore, the EXR reader/writer of the CLI
    openexr            # exrheader, exrmultipart, exrmaketiled: tests check and make EXRs with them
    libpng-dev         # --preview PNGs
    libcjson-dev       # --camera FILE.json
    python3 python3-numpy python3-pytest
    python3-pycodestyle  # the PEP 8 check of the test suite
    xvfb xauth         # F12 and viewport tests in a real window
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
