#!/usr/bin/env bash
# Installs what rastergi needs on a fresh Debian or Ubuntu machine: a C toolchain and
# pkg-config, Mesa's Vulkan drivers of version 25 or newer (lavapipe runs the GPU code on the CPU
# when there is no GPU; on Debian 12 from bookworm-backports), the X11 libraries of the viewer's window and Xvfb for its tests, and Rust >= 1.95
# with rustfmt and clippy (and, through rustup, the wasm32-unknown-unknown target of the
# library's web build, which CI builds), and a Python virtual environment with Ray
# (scripts/ray_render.py) and maturin, pytest and numpy (the Python package, python/).
# Safe to run again: it installs only what is missing. Afterwards,
# in a new shell or after `. ~/.cargo/env`: cargo test --release
set -euo pipefail

MIN_RUST=1.95
PACKAGES=(build-essential pkg-config libvulkan1 curl ca-certificates
    # The viewer's window (`rastergi view`): the X11 libraries winit loads at run time, and
    # Xvfb + xauth (for xvfb-run) so its tests run without a display.
    libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0 xvfb xauth
    # Mesa's OpenGL through EGL: wgpu's GL backend, an adapter without ray queries, on which
    # the tests check what `--rays hardware` and `auto` do there.
    libegl1 libegl-mesa0)

say() { echo "setup: $*"; }
die() {
    echo "setup: error: $*" >&2
    exit 1
}

# Runs a command as root: directly when root, else through sudo when there is one.
as_root() {
    if [ "$(id -u)" -eq 0 ]; then
        "$@"
    elif command -v sudo >/dev/null 2>&1; then
        sudo "$@"
    else
        die "need root to run '$*'; run this script as root or install sudo"
    fi
}

# Whether version $1 (like 1.95.0) is at least $2 (like 1.88).
version_at_least() {
    [ "$(printf '%s\n%s\n' "$2" "$1" | sort -V | head -n 1)" = "$2" ]
}

# System packages.
if command -v apt-get >/dev/null 2>&1; then
    missing=()
    for p in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if [ ${#missing[@]} -gt 0 ]; then
        say "installing ${missing[*]}"
        as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
        as_root env DEBIAN_FRONTEND=noninteractive apt-get install -qq -y --no-install-recommends "${missing[@]}" >/dev/null
    else
        say "system packages present: ${PACKAGES[*]}"
    fi
else
    say "no apt-get: install the equivalents of ${PACKAGES[*]} yourself"
fi

# A lavapipe of Mesa >= 25 (llvmpipe gathers loads at divergent offsets as vectors, ~1.6x
# faster on rastergi's passes than Mesa 22.3, and lavapipe offers ray queries). Debian 12's own
# Mesa is 22.3: take mesa-vulkan-drivers from bookworm-backports (25.0), enabled in a sources file
# of its own. Debian 13 and current Ubuntu ship Mesa >= 25 themselves.
MIN_MESA=25
mesa_installed() { dpkg-query -W -f='${Status} ${Version}' mesa-vulkan-drivers 2>/dev/null |
    awk '$3 == "installed" { sub(/^[0-9]+:/, "", $4); print $4 }'; }
if command -v apt-get >/dev/null 2>&1; then
    mesa="$(mesa_installed)"
    if [ -n "$mesa" ] && version_at_least "$mesa" "$MIN_MESA"; then
        say "Mesa's Vulkan drivers $mesa present"
    else
        release="$(. /etc/os-release 2>/dev/null && echo "${ID:-}-${VERSION_CODENAME:-}")"
        if [ "$release" = debian-bookworm ]; then
            sources=/etc/apt/sources.list.d/rastergi-bookworm-backports.sources
            if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
                printf '%s\n' "Types: deb" "URIs: http://deb.debian.org/debian" "Suites: bookworm-backports" \
                    "Components: main" "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" |
                    as_root tee "$sources" >/dev/null
            fi
            say "installing Mesa's Vulkan drivers from bookworm-backports (Debian 12's own Mesa 22.3 is 1.6x slower and has no ray queries; enabled in $sources)"
            as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
            as_root env DEBIAN_FRONTEND=noninteractive apt-get install -qq -y --no-install-recommends \
                -t bookworm-backports mesa-vulkan-drivers >/dev/null ||
                die "could not install mesa-vulkan-drivers from bookworm-backports"
        elif [ -z "$mesa" ]; then
            say "installing Mesa's Vulkan drivers"
            as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
            as_root env DEBIAN_FRONTEND=noninteractive apt-get install -qq -y --no-install-recommends \
                mesa-vulkan-drivers >/dev/null || die "could not install mesa-vulkan-drivers"
        fi
        mesa="$(mesa_installed)"
        if version_at_least "${mesa:-0}" "$MIN_MESA"; then
            say "Mesa's Vulkan drivers $mesa installed"
        else
            say "Mesa's Vulkan drivers here are ${mesa:-missing}, older than $MIN_MESA, and this distribution has no newer: rastergi runs, slower and without ray queries"
        fi
    fi
fi

# Rust, through rustup.
if [ -f "$HOME/.cargo/env" ]; then
    . "$HOME/.cargo/env"
fi
install_rustup() {
    say "installing Rust with rustup (into ~/.cargo)"
    curl --proto '=https' --tlsv1.2 https://sh.rustup.rs -sSf | sh -s -- -y --profile minimal
    . "$HOME/.cargo/env"
}
if ! command -v cargo >/dev/null 2>&1; then
    install_rustup
fi
rust_version="$(rustc --version | awk '{print $2}')"
if ! version_at_least "$rust_version" "$MIN_RUST"; then
    if command -v rustup >/dev/null 2>&1; then
        say "rustc $rust_version is older than $MIN_RUST: updating the stable toolchain"
        rustup update stable
    else
        # A distribution's Rust without rustup: rustup's toolchain goes first on PATH.
        say "rustc $rust_version is older than $MIN_RUST and there is no rustup"
        install_rustup
    fi
    rust_version="$(rustc --version | awk '{print $2}')"
    version_at_least "$rust_version" "$MIN_RUST" ||
        die "rustc $rust_version is still older than $MIN_RUST; run 'rustup default stable' (or remove the override that pins an older toolchain)"
fi
if command -v rustup >/dev/null 2>&1; then
    rustup -q component add rustfmt clippy
    # The library's web build (cargo build --target wasm32-unknown-unknown -p rastergi).
    if rustup target list --installed | grep -x wasm32-unknown-unknown >/dev/null; then
        say "wasm32-unknown-unknown target present"
    else
        say "adding the wasm32-unknown-unknown target (the library's web build)"
        rustup -q target add wasm32-unknown-unknown
    fi
else
    say "no rustup: add the wasm32-unknown-unknown target yourself for the web build"
fi
say "ready: $(rustc --version), $(cargo --version)"

# A Python virtual environment of rastergi's own, so the system's Python is left alone: Ray,
# for scripts/ray_render.py (long renders over a cluster) and its test; maturin, pytest and
# numpy, for the Python package (python/) and its tests.
RAY_VENV="$HOME/.local/share/rastergi/venv"
if [ ! -x "$RAY_VENV/bin/python" ]; then
    command -v python3 >/dev/null 2>&1 || die "python3 is missing; install it (apt-get install python3 python3-venv)"
    if ! python3 -c "import ensurepip, venv" 2>/dev/null; then
        command -v apt-get >/dev/null 2>&1 || die "python3 cannot make virtual environments; install its venv module"
        as_root env DEBIAN_FRONTEND=noninteractive apt-get install -qq -y --no-install-recommends python3-venv >/dev/null
    fi
    say "creating a virtual environment in $RAY_VENV"
    python3 -m venv "$RAY_VENV" || die "could not create a virtual environment in $RAY_VENV"
fi
if "$RAY_VENV/bin/python" -c "import ray" 2>/dev/null; then
    say "Ray present in $RAY_VENV"
else
    say "installing Ray into $RAY_VENV"
    "$RAY_VENV/bin/python" -m pip install --quiet --disable-pip-version-check "ray>=2.40" ||
        die "could not install Ray (pip install ray) into $RAY_VENV"
fi
if "$RAY_VENV/bin/python" -c "import maturin, pytest, numpy" 2>/dev/null; then
    say "maturin, pytest and numpy present in $RAY_VENV"
else
    say "installing maturin, pytest and numpy into $RAY_VENV (the Python package's build and tests)"
    "$RAY_VENV/bin/python" -m pip install --quiet --disable-pip-version-check "maturin>=1.5,<2" pytest numpy ||
        die "could not install maturin, pytest and numpy (pip install maturin pytest numpy) into $RAY_VENV"
fi
