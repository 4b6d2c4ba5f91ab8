"""Writes a randomly initialised network as assets/rae/<net>.{json,bin} (to prove the
inference path before training; train.py overwrites it)."""
import os
import sys

import torch

import model as rae

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
net = sys.argv[1] if len(sys.argv) > 1 else "phantom"
torch.manual_seed(0)
m = rae.Rae([16, 24, 32, 48])
d = os.path.join(ROOT, "assets", "rae")
os.makedirs(d, exist_ok=True)
rae.save(m, os.path.join(d, f"{net}.bin"), os.path.join(d, f"{net}.json"),
         {"name": net, "trained": False, "note": "random initialisation (torch.manual_seed(0))"})
print("wrote", net)
