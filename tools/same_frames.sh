#!/usr/bin/env bash
# Whether two builds of dvr render the same frames, byte for byte: every built-in scene
# captured by each (3 frames at 48x48 on a 48^3 procedural volume, the noisy input
# denoised by ours and svgf, EXR and PNG), then compared file by file. For a change that
# must leave today's scenes as they are (a feature compiled out when a scene does not
# use it). Prints each scene that differs and a count; exits 1 if any differs.
#
#   tools/same_frames.sh OLD_DVR NEW_DVR [OUT_DIR]
set -euo pipefail
old=$1 new=$2 out=${3:-$(mktemp -d)}
same=0 differ=0
for scene in $("$new" scenes); do
  for side in old new; do
    bin=$old; [ "$side" = new ] && bin=$new
    "$bin" capture --quiet --scene "$scene" --frames 3 --size 48x48 --volume-size 48 \
      --denoiser ours --denoiser svgf --out "$out/$side/${scene//\//_}" >/dev/null 2>&1
  done
  if diff -rq --exclude='*.html' --exclude='*.json' "$out/old/${scene//\//_}" "$out/new/${scene//\//_}" >/dev/null; then
    same=$((same + 1))
  else
    differ=$((differ + 1))
    echo "differs: $scene"
  fi
done
echo "scenes with the same frames: $same; differing: $differ (captures in $out)"
[ "$differ" -eq 0 ]
