#!/usr/bin/env bash
# Installs what dvr needs on a fresh Debian 12 machine, and only that.
#
#   tools/setup.sh           what the main job (tools/run.sh) needs: the Vulkan loader,
#                            Mesa's lavapipe (CPU Vulkan), glslang/shaderc/SPIRV-Tools
#                            (static archives that build.rs links), a TrueType font for
#                            the plots of `dvr eval` (fonts-dejavu-core) and ffmpeg, which
#                            encodes the videos of `--video` and the main job.
#   tools/setup.sh --tests   also what the tests (tools/test.sh) need: the validation
#                            layers, Xvfb and the X libraries of the window tests,
#                            Chromium (the results page and JupyterLab, headless),
#                            Python 3 with venv (the package's tests), iproute2 and
#                            util-linux (`ip`, `unshare`: the Ray test's loopback-only
#                            network namespace), and mdBook (the book), from crates.io
#                            with `cargo install`, without its search index and server:
#                            Debian 12 does not package it.
# Idempotent: it installs only what is missing, so the README's commands can call it
# every time.
set -euo pipefail

tests=false
case "${1:-}" in
  --tests) tests=true ;;
  "") ;;
  *) echo "usage: tools/setup.sh [--tests]" >&2; exit 2 ;;
esac

packages=(
  mesa-vulkan-drivers libvulkan1 libvulkan-dev
  libshaderc-dev glslang-dev glslang-tools spirv-tools
  pkg-config cmake
  fonts-dejavu-core ffmpeg
)
if $tests; then
  packages+=(
    vulkan-validationlayers vulkan-tools
    python3 python3-venv python3-pip iproute2 util-linux
    chromium
    xvfb libx11-xcb1 libxcursor1 libxi6 libxrandr2 libxkbcommon-x11-0
  )
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if ! command -v cargo >/dev/null 2>&1; then
  echo "setup: cargo not found; install Rust from https://rustup.rs" >&2
  exit 1
fi

# The book's builder (tests only). --no-default-features leaves out the search index,
# the file watcher and the HTTP server (`mdbook serve`): `mdbook build` needs none of them.
if $tests && ! command -v mdbook >/dev/null 2>&1; then
  echo "setup: installing mdbook (cargo install; a few minutes)"
  cargo install mdbook --locked --no-default-features --version "^0.4" --quiet
fi
