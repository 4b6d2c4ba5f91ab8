#!/usr/bin/env bash
# The main job: installs what is missing, builds, then runs `dvr demo`: a small `dvr eval`
# of the default scene (phantom/orbit) in which the noisy input, taa, svgf, ours and the
# RAE are scored against references, with videos. On a discrete GPU it renders 1280x720
# with 1024-spp references; otherwise it is sized for a 2-core CPU (the time it
# took is in the book's results: the main job). References are cached in out/demo, so a second run is faster. Writes
# out/demo/index.html and opens it when there is a display. Extra arguments go to
# `dvr demo` (e.g. --size 256x256 --frames 24 --ref-spp 512).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cargo build --release
started=$(date +%s)
target/release/dvr demo --out out/demo "$@"
echo "main job: $(($(date +%s) - started)) s after the build"
page=out/demo/index.html
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ] && command -v xdg-open >/dev/null 2>&1; then
  xdg-open "$page" >/dev/null 2>&1 || true
fi
echo "open $page"
