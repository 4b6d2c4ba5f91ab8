#!/usr/bin/env bash
# Installs what dvr needs on a fresh Debian 12 machine: the Vulkan loader, Mesa's
# lavapipe (CPU Vulkan), the validation layers, glslang/shaderc/SPIRV-Tools (static
# archives that build.rs links), Xvfb for window tests, a TrueType font for the plots of
# `dvr eval` (fonts-dejavu-core), Chromium, in which a test opens the eval's results
# page headless, ffmpeg, which encodes the videos of `--video` and the main job, and
# Python 3 with venv, for the Python package (`python/`) and its tests, and iproute2 and
# util-linux (`ip`, `unshare`), in which the Ray runner's test keeps its cluster on a
# loopback-only network namespace. Last, mdBook (the book in docs/, built by
# tools/test.sh), from crates.io with `cargo install`, without its search index and
# server: Debian 12 does not package it.
# Idempotent: it installs only what is missing, so the README's commands can call it
# every time.
set -euo pipefail

packages=(
  mesa-vulkan-drivers libvulkan1 libvulkan-dev vulkan-validationlayers vulkan-tools
  libshaderc-dev glslang-dev glslang-tools spirv-tools
  pkg-config cmake
  python3 python3-venv python3-pip iproute2 util-linux
  fonts-dejavu-core chromium ffmpeg
  xvfb libx11-xcb1 libxcursor1 libxi6 libxrandr2 libxkbcommon-x11-0
)

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

# The book's builder. --no-default-features leaves out the search index, the file
# watcher and the HTTP server (`mdbook serve`): `mdbook build` needs none of them.
if ! command -v mdbook >/dev/null 2>&1; then
  echo "setup: installing mdbook (cargo install; a few minutes)"
  cargo install mdbook --locked --no-default-features --version "^0.4" --quiet
fi
