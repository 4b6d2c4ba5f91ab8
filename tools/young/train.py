"""Trains tools/young/model.py on tools/young/gen.py's frames: random 64×64 crops with
flips and quarter turns, L1 on dvr's display tone map, Adam with a cosine schedule; every
sixth clip held out, the best held-out checkpoint kept.

    .venv/bin/python tools/young/train.py --minutes 20 --fuse --half --width 12 --out out/young-models/w12fh.pt

(--fuse needs the clips' `ours`, from gen.py --ours.) --normal surface trains on the
surface features' normal, the one the engine's `ours` has, instead of the composited one.
"""
import argparse
import glob
import os
import sys
import time

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(__file__))
from model import Young, psnr, tonemap  # noqa: E402


def load(data, fuse, normal):
    files = sorted(glob.glob(os.path.join(data, "*.npz")))
    train, held = [], []
    for i, path in enumerate(files):
        with np.load(path) as f:
            keys = ("noisy", "albedo", normal, "ref") + (("ours",) if fuse else ())
            fr = [torch.from_numpy(np.moveaxis(f[k], -1, 1).copy()) for k in keys]
        (held if i % 6 == 5 else train).append(torch.stack(fr, 1))  # (T, 4, 3, H, W)
    cat = lambda xs: torch.cat(xs, 0) if xs else None  # noqa: E731
    return cat(train), cat(held), len(files)


def batch(data, n, crop, rng):
    idx = rng.integers(0, data.shape[0], n)
    H, W = data.shape[-2:]
    out = []
    for i in idx:
        y, x = rng.integers(0, H - crop + 1), rng.integers(0, W - crop + 1)
        c = data[i, :, :, y : y + crop, x : x + crop]
        k = int(rng.integers(4))
        c = torch.rot90(c, k, (-2, -1))
        if rng.random() < 0.5:
            c = torch.flip(c, (-1,))
        out.append(c)
    b = torch.stack(out)
    # The normals are world-space guides, which turning the image does not change.
    return b[:, 0], b[:, 1], b[:, 2], b[:, 3], (b[:, 4] if b.shape[1] > 4 else None)


def evaluate(model, held):
    with torch.no_grad():
        ps = []
        for i in range(held.shape[0]):
            n, a, m, r = (held[i : i + 1, j] for j in range(4))
            o = held[i : i + 1, 4] if held.shape[1] > 4 else None
            ps.append(psnr(tonemap(model(n, a, m, o)), tonemap(r)))
            ps.append(psnr(tonemap(n if o is None else o), tonemap(r)))
    ps = np.array(ps).reshape(-1, 2)
    return ps[:, 0].mean(), ps[:, 1].mean()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default="out/young-data")
    ap.add_argument("--out", required=True)
    ap.add_argument("--minutes", type=float, default=20)
    ap.add_argument("--width", type=int, default=24)
    ap.add_argument("--half", action="store_true")
    ap.add_argument("--demod", type=float, default=0.0)
    ap.add_argument("--fuse", action="store_true")
    ap.add_argument("--normal", choices=("normal", "surface"), default="normal",
                    help="the normal guide: composited along the ray (OIDN's) or the surface's")
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--crop", type=int, default=64)
    ap.add_argument("--lr", type=float, default=2e-3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    torch.set_num_threads(a.threads)
    torch.manual_seed(a.seed)
    rng = np.random.default_rng(a.seed)
    train, held, nfiles = load(a.data, a.fuse, a.normal)
    print(f"{nfiles} clips: {train.shape[0]} training frames, {held.shape[0]} held out", flush=True)
    model = Young(width=a.width, half=a.half, demod=a.demod, fuse=a.fuse)
    print(f"{sum(p.numel() for p in model.parameters())} parameters", flush=True)
    opt = torch.optim.Adam(model.parameters(), lr=a.lr)
    t0, it, best = time.time(), 0, -1.0
    total = a.minutes * 60
    while time.time() - t0 < total:
        frac = (time.time() - t0) / total
        for g in opt.param_groups:
            g["lr"] = a.lr * (0.5 * (1 + np.cos(np.pi * frac)) * 0.95 + 0.05)
        n, al, nm, r, o = batch(train, a.batch, a.crop, rng)
        # With a fusion, the network's own estimate is scored too: else the blend learns
        # to keep ours' at once and the kernels, weighted by it, stop learning.
        out, own = model.estimates(n, al, nm, o)
        tr = tonemap(r)
        loss = torch.mean(torch.abs(tonemap(out) - tr))
        if a.fuse:
            loss = loss + torch.mean(torch.abs(tonemap(own) - tr))
        opt.zero_grad()
        loss.backward()
        opt.step()
        it += 1
        if it % 200 == 0:
            p, p0 = evaluate(model, held)
            tag = ""
            if p > best:
                best = p
                os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
                torch.save({"state": model.state_dict(), "width": a.width, "half": a.half, "demod": a.demod, "fuse": a.fuse,
                            "normal": a.normal}, a.out)
                tag = " *"
            print(f"it {it} {time.time() - t0:.0f}s loss {loss.item():.4f} held {p:.2f} dB (input {p0:.2f}){tag}",
                  flush=True)
    print(f"best held-out {best:.2f} dB after {it} iterations")


if __name__ == "__main__":
    main()
