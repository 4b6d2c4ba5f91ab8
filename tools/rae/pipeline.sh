#!/usr/bin/env bash
# The whole RAE training run as shipped, per dataset (phantom, mri):
#  1. pre-training data: 24 clips of 7 frames at 64x64 with 256-spp references (cheap:
#     ~10 min per dataset on lavapipe), and a network trained on it from scratch;
#  2. the training data proper: 7-frame 128x128 clips at 2 spp with 1024-spp references
#     (~6 min per clip on this 2-core machine, so fewer clips), and the network
#     fine-tuned on it (--init), validated on held-out 128x128 clips.
# Needs a Python with tools/rae/requirements.txt and the dvr package (`pip install ./python`
# into it: gen_data.py renders in process), and target/release/dvr. Everything runs
# at nice 10 (the machine is shared). Training uses one thread: on a shared 2-core
# machine, two OpenMP threads stall on each other (measured 5 s per iteration with 2
# threads vs well under 1 s with 1).
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-/opt/rae-venv/bin/python}
CLIPS=${CLIPS:-24}
SPEC_CLIPS=${SPEC_CLIPS:-10}
MINUTES=${MINUTES:-10}
FINETUNE_MINUTES=${FINETUNE_MINUTES:-25}
for ds in phantom mri; do
  [ -f "out/rae-data/$ds.npz" ] || nice -n 10 "$PY" tools/rae/gen_data.py --dataset "$ds" --clips "$CLIPS"
  [ -f "out/rae-data-spec/$ds.npz" ] || nice -n 10 "$PY" tools/rae/gen_data.py --dataset "$ds" \
    --clips "$SPEC_CLIPS" --size 128x128 --ref-spp 1024 --data out/rae-data-spec
done
for ds in phantom mri; do
  nice -n 10 "$PY" tools/rae/train.py --dataset "$ds" --minutes "$MINUTES" --batch 4 --threads 1
  nice -n 10 "$PY" tools/rae/train.py --dataset "$ds" --data out/rae-data-spec --init "assets/rae/$ds.json" \
    --minutes "$FINETUNE_MINUTES" --crop 64 --lr 1e-3 --batch 4 --threads 1
done
