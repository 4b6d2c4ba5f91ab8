#!/usr/bin/env python3
"""LPIPS (Zhang et al. 2018) for a `dvr eval` folder, when it can run offline.

Compares every method's frames with the references, on the PNGs the eval wrote (the
same tone-mapped sRGB images the other metrics use: exposure 1, ACES/Narkowicz, sRGB
OETF, see engine/src/metrics/tonemap.rs), and writes `DIR/lpips.csv`
(`scene,method,frame,lpips`, lower is better) plus a per-scene, per-method mean table
on stdout.

It never downloads anything. It needs, already on this machine:
  * the Python packages `lpips` and `torch` (and `torchvision`, `pillow`, `numpy`);
  * the backbone weights torchvision would otherwise fetch, in the torch hub cache
    (`$TORCH_HOME/hub/checkpoints/`, default `~/.cache/torch/hub/checkpoints/`):
    `alexnet-owt-7be5be79.pth` for `--net alex` (default, the paper's choice) or
    `vgg16-397923af.pth` for `--net vgg`;
  * the LPIPS linear layers, which the `lpips` package ships (`lpips/weights/v0.1/`).
If any of these is missing it says which, and how to get it, and exits with status 2
(so a script can tell "not available" from a failure).

Usage:
    python3 tools/lpips.py out/eval [--net alex|vgg]
"""

import argparse
import csv
import os
import sys

BACKBONES = {"alex": "alexnet-owt-7be5be79.pth", "vgg": "vgg16-397923af.pth"}
MISSING = 2


def missing(what, how):
    print(f"lpips: LPIPS not computed: {what} is not available locally. {how}", file=sys.stderr)
    print("lpips: nothing was downloaded.", file=sys.stderr)
    sys.exit(MISSING)


def load_model(net):
    try:
        import torch  # noqa: F401
        import lpips
    except ImportError as e:
        missing(f"the Python package `{e.name}`", "Install with: pip install lpips torch torchvision pillow numpy")
    import torch

    hub = torch.hub.get_dir()
    backbone = os.path.join(hub, "checkpoints", BACKBONES[net])
    if not os.path.isfile(backbone):
        missing(
            f"the {net} backbone weights ({backbone})",
            "Copy them there from a machine that has them (torchvision downloads them on "
            "first use of lpips.LPIPS with network access).",
        )
    linear = os.path.join(os.path.dirname(lpips.__file__), "weights", "v0.1", f"{net}.pth")
    if not os.path.isfile(linear):
        missing(f"the LPIPS linear weights ({linear})", "Reinstall the lpips package.")
    return lpips.LPIPS(net=net, verbose=False).eval()


def to_tensor(path):
    import numpy as np
    import torch
    from PIL import Image

    a = np.asarray(Image.open(path).convert("RGB"), dtype=np.float32) / 255.0
    return torch.from_numpy(a).permute(2, 0, 1).unsqueeze(0) * 2.0 - 1.0


def dir_name(scene):
    """dvr's folder name for a scene (src/eval/plan/scenes.rs: dir_name)."""
    s = "".join(c if (c.isascii() and c.isalnum()) or c in "-." else "_" for c in scene)
    return s.strip(".") or "scene"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="a dvr eval folder (with metrics.csv)")
    ap.add_argument("--net", default="alex", choices=sorted(BACKBONES))
    args = ap.parse_args()
    metrics = os.path.join(args.out, "metrics.csv")
    with open(metrics, newline="") as fh:
        keys = [(r["scene"], r["method"], int(r["frame"])) for r in csv.DictReader(fh)]
    if not keys:
        sys.exit(f"lpips: {metrics} has no rows")

    model = load_model(args.net)
    import torch

    rows, means = [], {}
    with torch.no_grad():
        for scene, method, frame in keys:
            d = os.path.join(args.out, dir_name(scene))
            test = os.path.join(d, method, f"{frame:04d}.png")
            if not os.path.isfile(test):
                continue
            ref = to_tensor(os.path.join(d, "reference", f"{frame:04d}.png"))
            v = float(model(ref, to_tensor(test)).item())
            rows.append((scene, method, frame, v))
            means.setdefault((scene, method), []).append(v)
    out = os.path.join(args.out, "lpips.csv")
    with open(out, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["scene", "method", "frame", "lpips"])
        w.writerows((s, m, f, f"{v:.6f}") for s, m, f, v in rows)
    for (s, m), vs in means.items():
        print(f"{s:<24} {m:<8} LPIPS {sum(vs) / len(vs):.4f}")
    print(f"lpips: {len(rows)} frames ({args.net}) -> {out}")


if __name__ == "__main__":
    main()
