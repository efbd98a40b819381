#!/usr/bin/env bash
# Gets the public scenes that the gallery (scripts/gallery.sh) and the measurements use into a
# cache outside the repository — they are other people's work under their own licences, never
# committed here (docs/scenes.md lists them with their authors and licences).
#
#   scripts/fetch-scenes.sh [--from DIR] [--dest DIR] [SCENE ...]
#
# SCENE       only these (staircase, sponza, cornell-box-original, gltf/ToyCar,
#             gltf/GlassHurricaneCandleHolder, gltf/LightsPunctualLamp, gltf/StainedGlassLamp,
#             gltf/SheenChair, env); all of them by default.
# --from DIR  copies them from a local folder laid out as ../shared/scenes (each scene a folder
#             with a FILES.txt of "size path" lines, which every copied file must match; files
#             it lists that the folder lacks are counted and left out);
#             without it, each is downloaded from its upstream address (curl, unzip).
# --dest DIR  the cache (default $RASTERGI_SCENES, else ${XDG_CACHE_HOME:-~/.cache}/rastergi/scenes).
#
# Safe to run again: a scene whose files are all there with their sizes is left as it is.
# Prints one line per scene and the cache's path last; exits non-zero, with one line saying
# which file and why, when a scene cannot be got.
set -euo pipefail

from=""
only=()
dest="${RASTERGI_SCENES:-${XDG_CACHE_HOME:-$HOME/.cache}/rastergi/scenes}"
while [ $# -gt 0 ]; do
    case "$1" in
        --from) from="${2:?--from needs a folder}"; shift 2 ;;
        --dest) dest="${2:?--dest needs a folder}"; shift 2 ;;
        -h|--help) sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) echo "fetch-scenes: unknown option '$1' (use --from DIR, --dest DIR, scene names)" >&2; exit 2 ;;
        *) only+=("$1"); shift ;;
    esac
done

# The scenes: folder, then the upstream address its files come from.
SCENES=(
    "staircase|https://benedikt-bitterli.me/resources/mitsuba/staircase.zip"
    "sponza|"
    "cornell-box-original|https://casual-effects.com/g3d/data10/research/model/CornellBox/CornellBox.zip"
    "gltf/ToyCar|khronos"
    "gltf/GlassHurricaneCandleHolder|khronos"
    "gltf/LightsPunctualLamp|khronos"
    "gltf/StainedGlassLamp|khronos"
    "gltf/SheenChair|khronos"
    "env|polyhaven"
)
KHRONOS=https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Assets/main/Models
POLYHAVEN=https://dl.polyhaven.org/file/ph-assets/HDRIs/hdr/1k

fail() { echo "fetch-scenes: $*" >&2; exit 1; }

# Whether every "size path" line of MANIFEST whose file SRC has names a file under DIR of
# that size.
complete() {
    local manifest="$1" src="$2" dir="$3" size path
    [ -f "$manifest" ] || return 1
    while read -r size path; do
        [ -n "$path" ] && [ -f "$src/$path" ] || continue
        [ -f "$dir/$path" ] && [ "$(stat -c %s "$dir/$path")" = "$size" ] || return 1
    done < "$manifest"
}

copy_scene() {
    local name="$1" src="$from/$1" out="$dest/$1" size path copied=0 absent=0
    [ -d "$src" ] || fail "$src: no such folder (--from names a folder laid out as ../shared/scenes)"
    [ -f "$src/FILES.txt" ] || fail "$src/FILES.txt: missing (each scene folder lists its files with their sizes)"
    if complete "$src/FILES.txt" "$src" "$out"; then
        echo "$name: already in $out"
        return
    fi
    mkdir -p "$out"
    while read -r size path; do
        [ -n "$path" ] || continue
        # Listed upstream but not in the local copy (the integrator variants of the Mitsuba
        # scenes): nothing a renderer reads.
        if [ ! -f "$src/$path" ]; then
            absent=$((absent + 1))
            continue
        fi
        [ "$(stat -c %s "$src/$path")" = "$size" ] \
            || fail "$src/$path: $(stat -c %s "$src/$path") bytes, FILES.txt says $size (a truncated or changed copy)"
        mkdir -p "$out/$(dirname "$path")"
        cp "$src/$path" "$out/$path"
        copied=$((copied + 1))
    done < "$src/FILES.txt"
    cp "$src/FILES.txt" "$out/FILES.txt"
    complete "$out/FILES.txt" "$src" "$out" || fail "$out: the copy does not match FILES.txt (disk full?)"
    echo "$name: copied $copied files to $out$([ "$absent" = 0 ] || echo " ($absent listed in FILES.txt are not in $src)")"
}

download() {
    local url="$1" to="$2"
    command -v curl >/dev/null || fail "curl is needed to download $url (or copy the scenes with --from DIR)"
    mkdir -p "$(dirname "$to")"
    curl --fail --location --silent --show-error --retry 2 -o "$to.part" "$url" || fail "$url: download failed"
    mv "$to.part" "$to"
}

fetch_scene() {
    local name="$1" url="$2" out="$dest/$1" tmp
    if [ -f "$out/.fetched" ]; then
        echo "$name: already in $out"
        return
    fi
    case "$url" in
        "") fail "$name: its Mitsuba conversion has no public address recorded here; copy it with --from DIR" ;;
        khronos)
            local model="${name#gltf/}" gltf
            download "$KHRONOS/$model/glTF/$model.gltf" "$out/glTF/$model.gltf"
            download "$KHRONOS/$model/LICENSE.md" "$out/LICENSE.md"
            download "$KHRONOS/$model/README.md" "$out/README.md"
            # The buffers and images the .gltf names (relative URIs).
            gltf="$out/glTF/$model.gltf"
            grep -o '"uri" *: *"[^"]*"' "$gltf" | sed 's/.*"\([^"]*\)"$/\1/' | grep -v '^data:' | while read -r uri; do
                download "$KHRONOS/$model/glTF/$uri" "$out/glTF/$uri"
            done ;;
        polyhaven)
            for sky in aerodynamics_workshop brown_photostudio_02; do
                download "$POLYHAVEN/${sky}_1k.hdr" "$out/${sky}_1k.hdr"
            done ;;
        *.zip)
            command -v unzip >/dev/null || fail "unzip is needed for $url"
            tmp="$(mktemp -d)"
            download "$url" "$tmp/scene.zip"
            unzip -q "$tmp/scene.zip" -d "$tmp/x" || fail "$url: not a zip archive"
            mkdir -p "$out"
            # The archive's one top folder, or its files directly.
            if [ "$(find "$tmp/x" -mindepth 1 -maxdepth 1 | wc -l)" = 1 ] && [ -d "$(find "$tmp/x" -mindepth 1 -maxdepth 1)" ]; then
                cp -r "$(find "$tmp/x" -mindepth 1 -maxdepth 1)"/. "$out"/
            else
                cp -r "$tmp/x"/. "$out"/
            fi
            rm -rf "$tmp" ;;
    esac
    touch "$out/.fetched"
    echo "$name: downloaded to $out"
}

for name in "${only[@]}"; do
    printf '%s\n' "${SCENES[@]%%|*}" | grep -qx -- "$name" \
        || { echo "fetch-scenes: unknown scene '$name' (one of:$(printf ' %s' "${SCENES[@]%%|*}"))" >&2; exit 2; }
done
mkdir -p "$dest" || fail "$dest: cannot create the cache folder"
for entry in "${SCENES[@]}"; do
    name="${entry%%|*}"
    url="${entry#*|}"
    if [ "${#only[@]}" -gt 0 ] && ! printf '%s\n' "${only[@]}" | grep -qx -- "$name"; then
        continue
    fi
    if [ -n "$from" ]; then
        copy_scene "$name"
    else
        fetch_scene "$name" "$url"
    fi
done
[ -z "$from" ] || { [ -f "$from/README.md" ] && cp "$from/README.md" "$dest/README.md"; }
echo "$dest"
