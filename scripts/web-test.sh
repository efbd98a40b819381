#!/usr/bin/env bash
# scripts/web-test.sh OUT.png [web_test.py options]: builds the web page (scripts/web-build.sh),
# serves it (rastergi serve), opens it in Chromium with WebGPU (SwiftShader's Vulkan on a
# machine without a GPU; on a virtual display, xvfb-run, since headless Chromium loses the
# WebGPU device when a canvas presents: scripts/web_test.py), renders the Cornell box at 128² for 64 iterations, writes the
# image to OUT.png, drags the camera (the image must restart) and exits 0. Options after OUT.png
# go to scripts/web_test.py (--iterations, --size, --seed, --gather, --denoised, --file,
# --bad-file).
#
# RASTERGI_BIN: the rastergi binary that serves the page (default: built here, release).
#
# Installs Debian's chromium and chromium-driver where they are missing (apt, as root or with
# sudo). Exit status 3: they are missing and cannot be installed (the test suite skips then).
set -euo pipefail
cd "$(dirname "$0")/.."

say() { printf 'web-test: %s\n' "$*" >&2; }

[ $# -ge 1 ] || { say "usage: scripts/web-test.sh OUT.png [options]"; exit 2; }
out=$1
shift

if ! command -v chromium >/dev/null 2>&1 || ! command -v chromedriver >/dev/null 2>&1; then
    as_root=()
    [ "$(id -u)" -eq 0 ] || as_root=(sudo -n)
    if command -v apt-get >/dev/null 2>&1 && { [ ${#as_root[@]} -eq 0 ] || sudo -n true 2>/dev/null; }; then
        say "installing chromium and chromium-driver (apt)"
        "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq || true
        "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -qq -y --no-install-recommends \
            chromium chromium-driver >/dev/null || { say "apt-get could not install chromium"; exit 3; }
    else
        say "chromium and chromedriver are missing and cannot be installed here (no apt-get, or not root)"
        exit 3
    fi
fi

bash scripts/web-build.sh
if [ -f "$HOME/.cargo/env" ]; then
    . "$HOME/.cargo/env"
fi
# The server: RASTERGI_BIN where the caller has built it (the test suite passes its own build,
# whose features differ from this package's alone: building it here would compile the CLI again).
rastergi=${RASTERGI_BIN:-}
if [ -z "$rastergi" ]; then
    cargo build --quiet --release -p rastergi-cli
    rastergi=target/release/rastergi
fi
log=$(mktemp)
"$rastergi" serve --port 0 --dir web >"$log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null || true; rm -f "$log"' EXIT
url=
for _ in $(seq 100); do
    url=$(grep -o 'http://127.0.0.1:[0-9]*' "$log" || true)
    [ -n "$url" ] && break
    kill -0 $server 2>/dev/null || { say "rastergi serve failed: $(cat "$log")"; exit 1; }
    sleep 0.1
done
[ -n "$url" ] || { say "rastergi serve did not start"; exit 1; }
say "serving the page at $url"
command -v xvfb-run >/dev/null 2>&1 || { say "xvfb-run is missing: run scripts/setup.sh (it installs xvfb)"; exit 1; }
env -u WAYLAND_DISPLAY -u WAYLAND_SOCKET xvfb-run -a -s "-screen 0 1280x1024x24" \
    python3 scripts/web_test.py "$url" "$out" "$@"
