#!/usr/bin/env bash
# The whole RAE training run as shipped: data for phantom and mri, then one network
# each. Needs target/release/dvr and a Python with tools/rae/requirements.txt.
# Everything runs at nice 10 (the machine is shared). Training uses one thread: on a
# shared 2-core machine, two OpenMP threads stall on each other (measured 5 s per
# iteration with 2 threads vs well under 1 s with 1).
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-/opt/rae-venv/bin/python}
CLIPS=${CLIPS:-24}
MINUTES=${MINUTES:-10}
for ds in phantom mri; do
  [ -f "out/rae-data/$ds.npz" ] || nice -n 10 "$PY" tools/rae/gen_data.py --dataset "$ds" --clips "$CLIPS"
done
for ds in phantom mri; do
  nice -n 10 "$PY" tools/rae/train.py --dataset "$ds" --minutes "$MINUTES" --batch 4 --threads 1
done
