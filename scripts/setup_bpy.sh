#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Installs PyPI's bpy (Blender as a Python module) for the test matrix, each in
# a virtual environment of its own under $HBAO_BPY_ROOT (default
# ~/.cache/hbao/bpy), reused between runs and clones:
#   bpy-4.5       bpy 4.5 LTS   (needs Python 3.11)
#   bpy-5.0       bpy 5.0       (needs Python 3.11)
#   bpy-5.2       bpy 5.2 LTS   (needs Python 3.13)
#   bpy-5-latest  the newest bpy 5.x PyPI has, 5.3 or later (Python 3.13)
# The Pythons come from pyenv when it has them, else from the system
# (python3.11 / python3.13 on PATH). A missing Python or a failed install is an
# error: the matrix must not shrink silently. Idempotent.
#   scripts/setup_bpy.sh [--upgrade]   (--upgrade: newest 5.x again)
set -euo pipefail
ROOT="${HBAO_BPY_ROOT:-$HOME/.cache/hbao/bpy}"
UPGRADE="${1:-}"
mkdir -p "$ROOT"

find_python() {  # find_python 3.11 -> path of a CPython 3.11 interpreter
    local minor="$1" candidate
    for candidate in \
        "${PYENV_ROOT:-$HOME/.pyenv}"/versions/"$minor".*/bin/python"$minor" \
        "$(command -v "python$minor" || true)"; do
        if [ -x "$candidate" ] && "$candidate" -c 'import venv, ensurepip' 2>/dev/null; then
            echo "$candidate"
            return 0
        fi
    done
    return 1
}

install_bpy() {  # install_bpy FOLDER PYTHON_MINOR REQUIREMENT
    local folder="$ROOT/$1" minor="$2" requirement="$3" python
    if [ -x "$folder/bin/python" ] && [ "$UPGRADE" != "--upgrade" ] \
        && "$folder/bin/python" -c 'import bpy' 2>/dev/null; then
        return 0
    fi
    if ! python="$(find_python "$minor")"; then
        echo "setup_bpy.sh: no Python $minor with venv found (pyenv or python$minor);" \
             "it is needed for $requirement" >&2
        return 1
    fi
    echo "setup_bpy.sh: installing $requirement with $python into $folder"
    rm -rf "$folder.partial"
    "$python" -m venv "$folder.partial"
    "$folder.partial/bin/python" -m pip install -q --disable-pip-version-check "$requirement"
    "$folder.partial/bin/python" -c 'import bpy' >/dev/null
    rm -rf "$folder"
    mv "$folder.partial" "$folder"
    # venv scripts name the folder they were made in; the interpreter link does not.
}

install_bpy bpy-4.5 3.11 'bpy==4.5.*'
install_bpy bpy-5.0 3.11 'bpy==5.0.*'
install_bpy bpy-5.2 3.13 'bpy==5.2.*'
install_bpy bpy-5-latest 3.13 'bpy>=5.3,<6'
