"""Writes tests/fixtures/rae/<net>.bin: a short clip through the shipped network in
torch (fp32), for tests/rae.rs to compare the compute shaders against.

Layout (little-endian): u32 width, height, frames; then frames x height x width x 4 f32
input (HDR rgba, a = 1), then the same shape of expected output (rgba, a = 1).
The size is deliberately not a multiple of 2^levels (the engine pads).

    /opt/rae-venv/bin/python tools/rae/fixture.py --net phantom
"""
import argparse
import os
import struct

import numpy as np
import torch

import model as rae

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def synthetic_clip(w, h, frames, seed=7):
    """A moving HDR gradient with bright spots and 2-spp-like noise, values ~0..8."""
    rng = np.random.default_rng(seed)
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64)
    out = []
    for t in range(frames):
        base = np.stack([
            0.5 + 0.4 * np.sin(0.3 * xs + 0.5 * t),
            0.4 + 0.3 * np.cos(0.2 * ys - 0.3 * t),
            0.3 + 0.2 * np.sin(0.15 * (xs + ys)),
        ])
        noise = rng.exponential(1.0, size=base.shape) * (rng.random(base.shape) < 0.6) / 0.6
        img = base * noise
        img[:, rng.integers(0, h, 3), rng.integers(0, w, 3)] = 8.0  # fireflies
        out.append(img.astype(np.float32))
    return np.stack(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--net", default="phantom")
    ap.add_argument("--size", default="30x22")
    ap.add_argument("--frames", type=int, default=3)
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    model, _ = rae.load(os.path.join(ROOT, "assets", "rae", f"{a.net}.json"))
    model.eval()
    clip = synthetic_clip(w, h, a.frames)
    out = rae.run_clip(model, torch.from_numpy(clip)).numpy()

    def rgba(x):  # (T,3,H,W) -> (T,H,W,4)
        t = np.moveaxis(x, 1, -1)
        return np.concatenate([t, np.ones(t.shape[:-1] + (1,), np.float32)], -1).astype("<f4")

    path = os.path.join(ROOT, "tests", "fixtures", "rae", f"{a.net}.bin")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(struct.pack("<3I", w, h, a.frames))
        f.write(rgba(clip).tobytes())
        f.write(rgba(out).tobytes())
    print(f"{path}: {w}x{h}, {a.frames} frames, output range {out.min():.4f}..{out.max():.4f}")


if __name__ == "__main__":
    main()
