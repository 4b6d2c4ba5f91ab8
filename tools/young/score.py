"""Scores a trained young-pixel estimate on an eval's kept frames (`dvr eval --aux
--denoiser none,...`: none/NNNN.exr, aux/NNNN_{albedo,normal}.exr, reference/NNNN.exr)
and sets it beside the methods a metrics.csv holds for the same frames.

    .venv/bin/python tools/young/score.py out/young-models/a.pt out/young-dev \
        --metrics assets/results/mechanisms/metrics.csv --frames 0,1 --csv out/young-a.csv
"""
import argparse
import csv
import glob
import os
import sys

import numpy as np
import torch

import dvr

sys.path.insert(0, os.path.dirname(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
from model import Young, psnr, tonemap  # noqa: E402
from oidn_eval import read_exr  # noqa: E402


def t(img):
    return torch.from_numpy(np.moveaxis(img, -1, 0)[None].copy())


def ours_frame0(scene, size):
    """ours' float output at frame 0 (its spatial estimate alone), rendered in process."""
    if scene.startswith("dev/"):
        sc = dvr.Scene.load(f"assets/scenes/development/{scene[4:]}.toml")
    else:
        sc = dvr.Scene.builtin(scene)
    return dvr.Renderer(sc, size=size, denoisers=["ours"]).render(0)["ours"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("model")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--metrics", action="append", default=[])
    ap.add_argument("--methods", default="ours,oidn,oidn-aux,rae")
    ap.add_argument("--frames", default="0,1")
    ap.add_argument("--csv")
    a = ap.parse_args()
    ck = torch.load(a.model, weights_only=True)
    fuse = ck.get("fuse", False)
    model = Young(width=ck["width"], half=ck.get("half", False), demod=ck.get("demod", 0.0), fuse=fuse)
    model.load_state_dict(ck["state"])
    model.eval()
    known = {}
    for path in a.metrics:
        with open(path) as f:
            for r in csv.DictReader(f):
                known[(r["scene"], r["method"], int(r["frame"]))] = float(r["psnr"])
    methods = a.methods.split(",")
    frames = [int(x) for x in a.frames.split(",")]
    rows = []
    for run in a.runs:
        for sd in sorted(glob.glob(os.path.join(run, "*", "aux"))):
            sd = os.path.dirname(sd)
            d = os.path.basename(sd)
            scene = d.replace("dev_", "dev/", 1) if d.startswith("dev_") else d.replace("_", "/", 1)
            for fr in frames:
                n = read_exr(f"{sd}/none/{fr:04d}.exr")
                al = read_exr(f"{sd}/aux/{fr:04d}_albedo.exr")
                nm = read_exr(f"{sd}/aux/{fr:04d}_normal.exr")
                ref = tonemap(t(read_exr(f"{sd}/reference/{fr:04d}.exr")))
                o = None
                if fuse:
                    if fr != 0:
                        continue
                    o = t(ours_frame0(scene, n.shape[1::-1]))
                with torch.no_grad():
                    y, own = model.estimates(t(n), t(al), t(nm), o)
                row = dict(scene=scene, frame=fr, noisy=psnr(tonemap(t(n)), ref), young=psnr(tonemap(y), ref))
                if o is not None:
                    row["own"] = psnr(tonemap(own), ref)
                    row["ours (py)"] = psnr(tonemap(o), ref)
                for m in methods:
                    row[m] = known.get((scene, m, fr), float("nan"))
                rows.append(row)
    cols = ["scene", "frame", "noisy", "young"] + methods + (["own", "ours (py)"] if fuse else [])
    print(" ".join(f"{c:>12}" for c in cols))
    for r in rows:
        print(" ".join(f"{r[c]:>12.2f}" if isinstance(r[c], float) else f"{str(r[c])[-12:]:>12}" for c in cols))
    for fr in frames:
        sel = [r for r in rows if r["frame"] == fr]
        if not sel:
            continue
        best = [max(r[m] for m in methods if m != "ours" and not np.isnan(r[m])) if any(
            not np.isnan(r[m]) for m in methods if m != "ours") else np.nan for r in sel]
        yo = np.array([r["young"] for r in sel])
        ou = np.array([r["ours"] for r in sel])
        print(f"frame {fr}: young {yo.mean():.3f}  ours {np.nanmean(ou):.3f}  "
              f"young-best {np.nanmean(yo - np.array(best)):+.3f}  ours-best {np.nanmean(ou - np.array(best)):+.3f}")
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, cols)
            w.writeheader()
            w.writerows({k: f"{v:.4f}" if isinstance(v, float) else v for k, v in r.items()} for r in rows)


if __name__ == "__main__":
    main()
