#!/usr/bin/env bash
# The main job: installs what is missing, then renders the default built-in scene
# (phantom/orbit) with the denoisers and writes frames, timings and an HTML page to
# out/demo (open out/demo/index.html).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cargo run --release -- capture --scene phantom/orbit --frames 24 --size 256x256 \
  --denoiser none,taa,svgf,ours --out out/demo "$@"
echo "open out/demo/index.html"
