#!/usr/bin/env bash
# Renders the public scenes of scripts/fetch-scenes.sh at 1280×720 (720×1280 where the file's
# film is portrait) within a time limit each, and writes the gallery: the images to
# docs/images/gallery/ and docs/gallery.md (image, author and licence, triangles, time,
# memory, photons, estimated error; the README shows it).
#
#   scripts/gallery.sh [--scenes DIR] [--seconds S] [--bin PATH]
#
# --scenes DIR  the cache fetch-scenes.sh filled (default as there: $RASTERGI_SCENES, else
#               ~/.cache/rastergi/scenes); fetch it first, e.g.
#               scripts/fetch-scenes.sh --from ../shared/scenes
# --seconds S   rendering time per scene after set-up (default 120), the iterations done in
#               it kept (render --time-limit), then denoised
# --bin PATH    the rastergi binary (default target/release/rastergi, built if missing)
set -euo pipefail
cd "$(dirname "$0")/.."

scenes="${RASTERGI_SCENES:-${XDG_CACHE_HOME:-$HOME/.cache}/rastergi/scenes}"
seconds=120
bin=target/release/rastergi
while [ $# -gt 0 ]; do
    case "$1" in
        --scenes) scenes="${2:?--scenes needs a folder}"; shift 2 ;;
        --seconds) seconds="${2:?--seconds needs a number}"; shift 2 ;;
        --bin) bin="${2:?--bin needs a path}"; shift 2 ;;
        -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) echo "gallery: unknown option '$1' (use --scenes DIR, --seconds S, --bin PATH)" >&2; exit 2 ;;
    esac
done
[ -d "$scenes" ] || { echo "gallery: $scenes: no scenes there; run scripts/fetch-scenes.sh first" >&2; exit 1; }
[ -x "$bin" ] || cargo build --release -p rastergi-cli
out=docs/images/gallery
mkdir -p "$out"

# name | file under the cache | width x height | extra options | credit
GALLERY=(
    "staircase|staircase/scene.xml|720x1280||The Wooden Staircase by Wig42 (Blend Swap), Mitsuba conversion by Benedikt Bitterli; CC BY 3.0"
    "sponza|sponza/scene.xml|1280x720||Sponza atrium by Marko Dabrović, UV fixes Kenzie Lamar, bump maps Morgan McGuire; free for rendering research"
    "cornell-box-original|cornell-box-original/CornellBox-Original.obj|1280x720||Cornell box, Cardenas & McGuire (Computer Graphics Archive); public domain"
    "toy-car|gltf/ToyCar/glTF/ToyCar.gltf|1280x720||Toy Car, Khronos glTF sample assets; CC0"
    "hurricane-candle-holder|gltf/GlassHurricaneCandleHolder/glTF/GlassHurricaneCandleHolder.gltf|1280x720||Glass Hurricane Candle Holder by Wayfair, Khronos glTF sample assets; CC BY 4.0"
    "lights-punctual-lamp|gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf|1280x720||Lamp with punctual lights, Khronos glTF sample assets; CC BY 4.0"
    "stained-glass-lamp|gltf/StainedGlassLamp/glTF/StainedGlassLamp.gltf|1280x720||Stained Glass Lamp by Wayfair, Khronos glTF sample assets; CC BY 4.0"
    "sheen-chair|gltf/SheenChair/glTF/SheenChair.gltf|1280x720||Sheen Chair by Wayfair, Khronos glTF sample assets; CC0"
)

md=docs/gallery.md
{
    echo "# Gallery"
    echo
    echo "Published scenes by other people, rendered by \`scripts/gallery.sh --seconds $seconds\` on this project's"
    echo "machine (2 cores, no GPU: Mesa's lavapipe) after \`scripts/fetch-scenes.sh --from ../shared/scenes\`:"
    echo "each at its size for $seconds s of rendering after set-up, the photon map fitted, the traced"
    echo "gather, denoised. *Time* is the whole process (loading, BVH, textures, shaders, photons,"
    echo "rendering, denoising); *memory* its peak resident memory, which on lavapipe holds the GPU's"
    echo "buffers too; *error* the render's own estimate of its relative RMSE before denoising"
    echo "([user guide](user-guide.md)). The scenes are not in the repository; their authors and licences are"
    echo "given with each image."
    echo
} > "$md"
for entry in "${GALLERY[@]}"; do
    IFS='|' read -r name file size extra credit <<< "$entry"
    [ -f "$scenes/$file" ] || { echo "gallery: $scenes/$file: missing; run scripts/fetch-scenes.sh" >&2; exit 1; }
    w="${size%x*}"; h="${size#*x}"
    log="$(mktemp)"
    # shellcheck disable=SC2086
    /usr/bin/time -f 'gallery-time %e %M' env RUST_LOG=info "$bin" render "$scenes/$file" \
        --width "$w" --height "$h" --iterations 100000 --time-limit "$seconds" --denoise \
        --out "$out/$name.png" $extra > "$log" 2>&1 || { cat "$log" >&2; echo "gallery: $name failed" >&2; exit 1; }
    triangles="$(grep -o '[0-9]* triangles loaded' "$log" | head -1 | cut -d' ' -f1 || true)"
    photons="$(grep -o 'photons [0-9]*' "$log" | head -1 | cut -d' ' -f2 || true)"
    iterations="$(grep -o 'render\] [0-9]* iterations in' "$log" | tail -1 | cut -d' ' -f2 || true)"
    error="$(grep -o 'estimated error [0-9.]* %' "$log" | tail -1 | cut -d' ' -f3 || true)"
    read -r _ wall rss <<< "$(grep '^gallery-time' "$log")"
    warnings="$(grep -c 'WARN' "$log" || true)"
    rm -f "$out/$name.raw.png"
    {
        echo "## $name"
        echo
        echo "![$name](images/gallery/$name.png)"
        echo
        echo "$credit. \`$file\`: ${triangles:-?} triangles, ${w}×${h}, ${iterations:-?} iterations in ${wall} s"
        echo "(whole process), $((rss / 1024)) MiB, ${photons:-?} photons per pass, ${error:+estimated error $error %}${error:-no error estimate (too few iterations for its two halves)}, $warnings warnings."
        echo
    } >> "$md"
    echo "$name: ${iterations:-?} iterations, ${wall} s, $((rss / 1024)) MiB, error ${error:-?} %"
    rm -f "$log"
done
echo "wrote $md"
