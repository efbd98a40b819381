#!/usr/bin/env bash
# Builds rastergi's web page: crates/rastergi-web for wasm32-unknown-unknown (release), then
# wasm-bindgen's JavaScript glue into web/pkg/. The page is web/ (index.html, main.js,
# style.css, pkg/): serve that folder (`rastergi serve`) and open it in a browser with WebGPU.
#
# Fetches what it needs: the wasm32 target (rustup) and wasm-bindgen-cli at the version of the
# wasm-bindgen crate in Cargo.lock (cargo install, a few minutes the first time).
set -euo pipefail
cd "$(dirname "$0")/.."

say() { printf 'web-build: %s\n' "$*" >&2; }

if [ -f "$HOME/.cargo/env" ]; then
    . "$HOME/.cargo/env"
fi
if command -v rustup >/dev/null 2>&1 && ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    say "adding the wasm32-unknown-unknown target"
    rustup target add wasm32-unknown-unknown
fi
version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/[^0-9.]/, ""); print; exit }' Cargo.lock)
[ -n "$version" ] || { say "Cargo.lock names no wasm-bindgen version"; exit 1; }
if ! wasm-bindgen --version 2>/dev/null | grep -qx "wasm-bindgen $version"; then
    say "installing wasm-bindgen-cli $version (cargo install; a few minutes)"
    cargo install --quiet wasm-bindgen-cli --version "$version"
fi
say "building crates/rastergi-web for wasm32-unknown-unknown"
cargo build --quiet --release --target wasm32-unknown-unknown -p rastergi-web
rm -rf web/pkg
wasm-bindgen --target web --no-typescript --out-dir web/pkg target/wasm32-unknown-unknown/release/rastergi_web.wasm
say "built web/pkg ($(du -sh web/pkg | cut -f1)); serve web/ with: rastergi serve"
