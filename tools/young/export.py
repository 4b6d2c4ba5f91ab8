"""Writes a trained young-pixel network (train.py's checkpoint: fused, half-resolution
trunk, the surface normal) as the engine's weights, `assets/young/young.{json,bin}`, and
the test fixture tests/young.rs compares the engine's shaders with:
tests/fixtures/young/young.bin, one synthetic frame through the network in torch (fp32).

    .venv/bin/python tools/young/export.py out/young-models/w12fhs.pt

Weight layout (the engine's, as tools/rae's): per layer, for output group go (4 output
channels), input group gi, tap t (row-major over the 3×3 window; one tap for the 1×1
head) and input channel c of the group, a vec4 over the group's output channels; then
the biases, one vec4 per output group. Channels past a layer's count are zero.

Fixture layout (little-endian): u32 width, height; then the inputs noisy, albedo,
normal, ours and the expected output, each height × width × 4 f32 (rgba, a = 1).
"""
import argparse
import json
import os
import struct
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(__file__))
from model import DILATIONS, SLOPE, Young  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FORMAT = "dvr-young-1"


def groups(c):
    return (c + 3) // 4


def pack(conv):
    w = conv.weight.detach().double().numpy()  # (out, in, k, k)
    b = conv.bias.detach().double().numpy()
    o, i, k, _ = w.shape
    arr = np.zeros((groups(o), groups(i), k * k, 4, 4))  # [go][gi][t][c][r]
    for ci in range(i):
        for co in range(o):
            arr[co // 4, ci // 4, :, ci % 4, co % 4] = w[co, ci].reshape(-1)
    bias = np.zeros(groups(o) * 4)
    bias[:o] = b
    return arr.reshape(-1), bias


def synthetic(w, h, seed=5):
    """One noisy HDR frame with fireflies, a smooth albedo, normals with a no-surface
    region (zero), and a smooth 'ours' estimate: (4, 3, h, w) float32."""
    rng = np.random.default_rng(seed)
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64)
    base = np.stack([0.6 + 0.5 * np.sin(0.3 * xs), 0.4 + 0.3 * np.cos(0.2 * ys), 0.3 + 0.2 * np.sin(0.15 * (xs + ys))])
    noisy = base * rng.exponential(1.0, base.shape) * (rng.random(base.shape) < 0.6) / 0.6
    noisy[:, rng.integers(0, h, 3), rng.integers(0, w, 3)] = 9.0
    albedo = np.stack([0.5 + 0.4 * np.sin(0.1 * xs), 0.5 + 0.4 * np.cos(0.13 * ys), 0.3 + 0 * xs])
    n = rng.normal(size=(3, h, w))
    n /= np.linalg.norm(n, axis=0, keepdims=True)
    n[:, :, : w // 4] = 0.0
    ours = base * 1.1
    return np.stack([noisy, albedo, n, ours]).astype(np.float32)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("checkpoint")
    ap.add_argument("--name", default="young")
    ap.add_argument("--size", default="29x21", help="the fixture's size (odd: the half-resolution trunk's edges)")
    a = ap.parse_args()
    ck = torch.load(a.checkpoint, weights_only=True)
    if not (ck.get("fuse") and ck.get("half") and ck.get("normal") == "surface" and not ck.get("demod")):
        sys.exit(f"{a.checkpoint}: the engine runs the fused, half-resolution network on the surface normal")
    model = Young(width=ck["width"], half=True, fuse=True)
    model.load_state_dict(ck["state"])
    model.eval()
    dilations = [c.dilation[0] for c in model.trunk]
    layers, chunks, offset = [], [], 0
    for name, conv in [(f"trunk{i}", c) for i, c in enumerate(model.trunk)] + [("head", model.head)]:
        wts, bias = pack(conv)
        layers.append(dict(name=name, inputs=conv.in_channels, outputs=conv.out_channels,
                           taps=conv.kernel_size[0] * conv.kernel_size[1], dilation=conv.dilation[0],
                           weights_offset=offset, bias_offset=offset + wts.size))
        chunks += [wts, bias]
        offset += wts.size + bias.size
    floats = np.concatenate(chunks).astype("<f4")
    manifest = dict(
        format=FORMAT,
        architecture="young: features averaged 2x2, dilated 3x3 trunk with leaky ReLU, 1x1 head, "
        "bilinear upsampling, softmax 3x3 kernel cascade on the noisy radiance, sigmoid blend with ours",
        inputs="log1p(max(noisy, 0)), clamp(albedo, 0, 1), clamp(surface normal, -1, 1), log1p(max(ours, 0))",
        width=ck["width"],
        trunk_dilations=dilations,
        kernel_dilations=list(DILATIONS),
        leaky_relu_slope=SLOPE,
        weights=f"{a.name}.bin",
        floats=int(floats.size),
        parameters=int(sum(p.numel() for p in model.parameters())),
        source=os.path.basename(a.checkpoint),
        layers=layers,
    )
    out = os.path.join(ROOT, "assets", "young")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, f"{a.name}.json"), "w") as f:
        json.dump(manifest, f, indent=2)
        f.write("\n")
    floats.tofile(os.path.join(out, f"{a.name}.bin"))
    w, h = (int(v) for v in a.size.split("x"))
    ins = torch.from_numpy(synthetic(w, h))
    with torch.no_grad():
        y = model(ins[0:1], ins[1:2], ins[2:3], ins[3:4])[0]
    imgs = torch.cat([ins, y[None]]).numpy()  # (5, 3, h, w)
    rgba = np.concatenate([np.moveaxis(imgs, 1, -1), np.ones((5, h, w, 1), np.float32)], -1).astype("<f4")
    path = os.path.join(ROOT, "tests", "fixtures", "young", f"{a.name}.bin")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(struct.pack("<2I", w, h))
        f.write(rgba.tobytes())
    print(f"{out}/{a.name}.json: {floats.size} floats; {path}: {w}x{h}, output {y.min():.4f}..{y.max():.4f}")


if __name__ == "__main__":
    main()
