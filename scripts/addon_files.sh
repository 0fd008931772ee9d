# SPDX-License-Identifier: GPL-2.0-or-later
# Sourced by install_addon.sh and package_addon.sh: what an installed add-on is.
# copy_addon TARGET BUILD: the hbao package (without caches or a stale lib/)
# into TARGET, with BUILD's libhbao.so and libhbao_exr.so in TARGET/lib/.
copy_addon() {
    local target="$1" build="$2" source
    source="$(cd "$(dirname "${BASH_SOURCE[0]}")/../addon/hbao" && pwd)"
    mkdir -p "$target/lib"
    (cd "$source" && find . -name '__pycache__' -prune -o -name 'lib' -prune -o \
        -type f -print | while read -r file; do
            mkdir -p "$target/$(dirname "$file")"
            cp "$file" "$target/$file"
        done)
    cp "$build/libhbao.so" "$target/lib/libhbao.so"
    cp "$build/libhbao_exr.so" "$target/lib/libhbao_exr.so"
}
