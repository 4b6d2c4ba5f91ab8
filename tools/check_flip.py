#!/usr/bin/env python3
"""Generate FLIP agreement fixtures for `dvr_engine::metrics::flip`.

Writes a few reference/test PNG pairs (noise, blur, shift, colour change,
quantisation) and the mean LDR-FLIP error that NVIDIA's own implementation
(`pip install flip-evaluator`, the package FLIP's authors publish) reports for
each pair into `expected.json`. The Rust unit test in
`engine/src/metrics/flip.rs` loads the same PNGs and asserts that our port is
within 1 % (relative) of these means, so a regression in any stage of the
port (colour pipeline, CSF filters, Hunt, HyAB, feature detection) shows up.

Everything is deterministic (fixed seed), so re-running the script rewrites
identical PNGs; the means only change if flip-evaluator changes.

Usage:
    pip install flip-evaluator numpy pillow
    python3 tools/check_flip.py [--out tests/fixtures/flip]

Images are 8-bit sRGB PNGs, read back as value / 255 on both sides, and FLIP
is evaluated as LDR-FLIP with sRGB inputs at the default 67.02 pixels per
degree (0.7 m viewing distance, 0.7 m wide 3840-pixel monitor).
"""

import argparse
import json
import os
import sys

import numpy as np
from PIL import Image

try:
    import flip_evaluator as flip
    from importlib.metadata import version as _pkg_version
except ImportError:  # pragma: no cover - tool guidance only
    sys.exit("flip-evaluator is not installed: pip install flip-evaluator")


def base_image(width, height, seed):
    """A synthetic sRGB image in [0,1] with smooth colour gradients, hard edges,
    a thin line, dots and a fine texture, so both FLIP's colour term and its
    edge/point feature term have something to react to."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width].astype(np.float64)
    u, v = x / (width - 1), y / (height - 1)
    img = np.stack([0.15 + 0.7 * u, 0.2 + 0.6 * v, 0.8 - 0.6 * u * v], axis=-1)
    # Hard-edged rectangle and disc with saturated colours.
    rect = (u > 0.1) & (u < 0.45) & (v > 0.55) & (v < 0.9)
    img[rect] = [0.9, 0.25, 0.1]
    disc = (u - 0.7) ** 2 + (v - 0.35) ** 2 < 0.18**2
    img[disc] = [0.1, 0.35, 0.85]
    # Fine sinusoidal texture in the upper-left quadrant.
    tex = (u < 0.5) & (v < 0.5)
    img[tex] *= (0.75 + 0.25 * np.sin(2 * np.pi * x / 5.0) * np.sin(2 * np.pi * y / 7.0))[tex, None]
    # Thin dark diagonal line and a few bright dots.
    line = np.abs(x - y * width / height) < 0.6
    img[line] = [0.05, 0.05, 0.05]
    for _ in range(12):
        px, py = rng.integers(2, width - 2), rng.integers(2, height - 2)
        img[py, px] = [1.0, 1.0, 0.95]
    return np.clip(img, 0.0, 1.0)


def to_u8(img):
    return np.clip(np.rint(img * 255.0), 0, 255).astype(np.uint8)


def gaussian_blur(img, sigma):
    radius = int(np.ceil(3 * sigma))
    k = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    k /= k.sum()
    out = img.copy()
    for axis in (0, 1):
        pad = [(0, 0)] * 3
        pad[axis] = (radius, radius)
        p = np.pad(out, pad, mode="edge")
        acc = np.zeros_like(out)
        n = out.shape[axis]
        for i, w in enumerate(k):
            sl = [slice(None)] * 3
            sl[axis] = slice(i, i + n)
            acc += w * p[tuple(sl)]
        out = acc
    return out


def make_pairs():
    """(name, reference, test) in sRGB [0,1]; sizes differ and are not square
    so a transposed index in the port cannot go unnoticed."""
    pairs = []
    rng = np.random.default_rng(2020)

    ref = base_image(96, 80, 1)
    pairs.append(("noise", ref, np.clip(ref + rng.normal(0.0, 0.06, ref.shape), 0, 1)))

    ref = base_image(112, 96, 2)
    pairs.append(("blur", ref, gaussian_blur(ref, 1.2)))

    ref = base_image(128, 96, 3)
    pairs.append(("shift", ref, np.roll(ref, shift=(1, 2), axis=(0, 1))))

    ref = base_image(96, 112, 4)
    test = ref * np.array([0.85, 1.0, 1.12])
    pairs.append(("colour", ref, np.clip(test, 0, 1)))

    ref = base_image(80, 80, 5)
    pairs.append(("quantise", ref, np.floor(ref * 6.0 + 0.5) / 6.0))

    # Low-amplitude noise: small errors, where FLIP's power-law remapping is
    # steepest and the relative comparison is strictest.
    ref = base_image(72, 64, 6)
    pairs.append(("faint_noise", ref, np.clip(ref + rng.normal(0.0, 0.01, ref.shape), 0, 1)))
    return pairs


def flip_mean(ref_u8, test_u8):
    # flip-evaluator converts sRGB -> linear in place, so hand it fresh copies.
    r = np.ascontiguousarray(ref_u8.astype(np.float32) / 255.0)
    t = np.ascontiguousarray(test_u8.astype(np.float32) / 255.0)
    _, mean, params = flip.evaluate(r, t, "LDR")
    return float(mean), float(params["ppd"])


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(root, "tests", "fixtures", "flip"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    entries = []
    ppd = None
    for name, ref, test in make_pairs():
        ref_u8, test_u8 = to_u8(ref), to_u8(test)
        ref_file, test_file = f"{name}_ref.png", f"{name}_test.png"
        Image.fromarray(ref_u8, "RGB").save(os.path.join(args.out, ref_file), optimize=True)
        Image.fromarray(test_u8, "RGB").save(os.path.join(args.out, test_file), optimize=True)
        # Evaluate on what was written, exactly as the Rust test will read it.
        ref_back = np.asarray(Image.open(os.path.join(args.out, ref_file)).convert("RGB"))
        test_back = np.asarray(Image.open(os.path.join(args.out, test_file)).convert("RGB"))
        mean, ppd = flip_mean(ref_back, test_back)
        h, w = ref_u8.shape[:2]
        entries.append({"name": name, "reference": ref_file, "test": test_file,
                        "width": w, "height": h, "mean": mean})
        print(f"{name:12s} {w}x{h}  mean FLIP = {mean:.6f}")

    out = {
        "generator": "tools/check_flip.py",
        "flip_evaluator_version": _pkg_version("flip-evaluator"),
        "mode": "LDR, sRGB inputs",
        "ppd": ppd,
        "pairs": entries,
    }
    with open(os.path.join(args.out, "expected.json"), "w") as f:
        json.dump(out, f, indent=2)
        f.write("\n")
    print(f"wrote {len(entries)} pairs to {args.out}")


if __name__ == "__main__":
    main()
