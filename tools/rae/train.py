"""Trains one RAE (tools/rae/model.py) on a dataset packed by gen_data.py, on the CPU,
and ships it: assets/rae/<net>.{bin,json} (the manifest holds the architecture, widths,
normalisation, training data hash, settings, training time and the validation curve),
then regenerates the agreement fixture tests/fixtures/rae/<net>.bin.

    nice -n 10 /opt/rae-venv/bin/python tools/rae/train.py --dataset phantom --minutes 10

Loss (Chaitanya et al. 2017), in the network's log1p space, per frame t of a clip with
weights rising towards the clip's end: 0.8 L1(y, r) + 0.1 L1(LoG*y, LoG*r)
+ 0.1 L1(y_t - y_{t-1}, r_t - r_{t-1}).
Augmentation: random square crops (--crop), flips, 90-degree rotations, time reversal.

--init assets/rae/<net>.json starts from a shipped network instead of random weights
(fine-tuning: a network pre-trained on a larger, cheaper data set, then trained on the
scarce full-specification clips); the manifest records where it started from.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np
import torch
import torch.nn.functional as F

import model as rae

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
# Later frames of a clip count more (the recurrent state has warmed up); the paper's
# schedule for 7 frames.
FRAME_WEIGHTS = torch.tensor([0.011, 0.044, 0.135, 0.325, 0.607, 0.882, 1.0])


def log_kernel(sigma=1.0, size=7):
    r = size // 2
    y, x = np.mgrid[-r : r + 1, -r : r + 1].astype(np.float64)
    q = (x * x + y * y) / (2 * sigma * sigma)
    k = (q - 1) * np.exp(-q)
    k -= k.mean()
    return torch.tensor(k / np.abs(k).sum(), dtype=torch.float32)


LOG = log_kernel().view(1, 1, 7, 7).repeat(3, 1, 1, 1)


def highpass(x):
    return F.conv2d(F.pad(x, (3, 3, 3, 3), mode="replicate"), LOG, groups=3)


def clip_loss(model, noisy, ref):
    """noisy, ref: (N,T,3,H,W) normalised. Returns the weighted loss and its parts."""
    n, T, _, H, W = noisy.shape
    state = model.init_state(n, H, W)
    wts = FRAME_WEIGHTS[-T:] / FRAME_WEIGHTS[-T:].sum()
    prev_y = prev_r = None
    total = 0.0
    parts = np.zeros(3)
    for t in range(T):
        y, state = model.step(noisy[:, t], state)
        r = ref[:, t]
        ls = (y - r).abs().mean()
        lg = (highpass(y) - highpass(r)).abs().mean()
        lt = ((y - prev_y) - (r - prev_r)).abs().mean() if t > 0 else torch.zeros(())
        total = total + wts[t] * (0.8 * ls + 0.1 * lg + 0.1 * lt)
        parts += wts[t].item() * np.array([ls.item(), lg.item(), lt.item()])
        prev_y, prev_r = y, r
    return total, parts


def augment(noisy, ref, rng, crop):
    n, T, C, H, W = noisy.shape
    y0 = rng.integers(0, H - crop + 1)
    x0 = rng.integers(0, W - crop + 1)
    noisy = noisy[..., y0 : y0 + crop, x0 : x0 + crop]
    ref = ref[..., y0 : y0 + crop, x0 : x0 + crop]
    k = int(rng.integers(4))
    noisy = torch.rot90(noisy, k, (3, 4))
    ref = torch.rot90(ref, k, (3, 4))
    if rng.random() < 0.5:
        noisy, ref = noisy.flip(4), ref.flip(4)
    if rng.random() < 0.5:
        noisy, ref = noisy.flip(1), ref.flip(1)
    return noisy.contiguous(), ref.contiguous()


def load_clips(folder, dataset):
    """A gen_data.py pack: normalised noisy and reference clips, and what the manifest
    records of it (file relative to the repository, content hash, settings)."""
    path = os.path.join(os.path.abspath(folder), f"{dataset}.npz")
    d = np.load(path)
    info = {"file": os.path.relpath(path, ROOT), "sha256_16": str(d["hash"]), "settings": str(d["settings"])}
    return rae.normalise(torch.from_numpy(d["noisy"])), rae.normalise(torch.from_numpy(d["ref"])), info


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dataset", required=True)
    ap.add_argument("--net", default=None, help="output name (default: the dataset)")
    ap.add_argument("--data", default=os.path.join(ROOT, "out", "rae-data"))
    ap.add_argument("--widths", default="16,24,32,48")
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--batch", type=int, default=4)
    ap.add_argument("--crop", type=int, default=48)
    ap.add_argument("--lr", type=float, default=2e-3)
    ap.add_argument("--val-clips", type=int, default=4)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--init", default=None, help="manifest of a network to start from (fine-tuning)")
    ap.add_argument("--extra-data", default=None,
                    help="another gen_data.py folder whose clips of this dataset join the training set "
                         "(half of each batch; none are used for validation)")
    a = ap.parse_args()
    net = a.net or a.dataset
    torch.set_num_threads(a.threads)
    torch.manual_seed(a.seed)
    rng = np.random.default_rng(a.seed)

    noisy, ref, data_info = load_clips(a.data, a.dataset)
    n = noisy.shape[0]
    nv = min(a.val_clips, n // 4)
    tr_n, tr_r = noisy[: n - nv], ref[: n - nv]
    va_n, va_r = noisy[n - nv :], ref[n - nv :]
    print(f"{a.dataset}: {n - nv} training clips, {nv} validation clips, {tuple(noisy.shape[1:])}", flush=True)
    extra = None
    if a.extra_data:
        extra = load_clips(a.extra_data, a.dataset)
        print(f"  + {extra[0].shape[0]} extra training clips {tuple(extra[0].shape[1:])} from {a.extra_data}",
              flush=True)

    init = None
    if a.init:
        model, m0 = rae.load(a.init)
        init = {"manifest": os.path.relpath(os.path.abspath(a.init), ROOT),
                "training_data": m0.get("training_data"), "training": m0.get("training"),
                "initialised_from": m0.get("initialised_from"),
                "validation_curve": m0.get("validation_curve")}
        a.widths = ",".join(str(w) for w in model.widths)
    else:
        model = rae.Rae([int(w) for w in a.widths.split(",")])
    opt = torch.optim.Adam(model.parameters(), lr=a.lr)
    budget = a.minutes * 60
    t0 = time.time()
    curve = []
    best = (math.inf, None)
    it = 0
    run_loss = []

    def validate():
        model.eval()
        with torch.no_grad():
            loss, parts = clip_loss(model, va_n, va_r)
        model.train()
        return loss.item(), parts

    if init is not None:
        # Where fine-tuning starts: the pre-trained network on these validation clips.
        vl, parts = validate()
        curve.append({"iteration": 0, "seconds": 0.0, "train": None, "validation": round(vl, 5)})
        print(f"it 0 (pre-trained {a.init}) val {vl:.4f} (l1 {parts[0]:.4f} log {parts[1]:.4f} "
              f"temporal {parts[2]:.4f})", flush=True)
        best = (vl, {k: v.clone() for k, v in model.state_dict().items()})
    while True:
        el = time.time() - t0
        if el > budget:
            break
        lr = a.lr * 0.5 * (1 + math.cos(math.pi * min(el / budget, 1.0)))
        for g in opt.param_groups:
            g["lr"] = lr
        if extra is None:
            idx = rng.choice(tr_n.shape[0], a.batch, replace=False)
            bn, br = augment(tr_n[idx], tr_r[idx], rng, a.crop)
        else:
            # Half the batch from each set; crops may not exceed the smaller clips.
            k = a.batch // 2
            idx = rng.choice(tr_n.shape[0], a.batch - k, replace=False)
            jdx = rng.choice(extra[0].shape[0], k, replace=False)
            bn, br = augment(tr_n[idx], tr_r[idx], rng, a.crop)
            en, er = augment(extra[0][jdx], extra[1][jdx], rng, a.crop)
            bn, br = torch.cat([bn, en]), torch.cat([br, er])
        loss, _ = clip_loss(model, bn, br)
        opt.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        run_loss.append(loss.item())
        it += 1
        if it % 50 == 0:
            vl, parts = validate()
            tl = float(np.mean(run_loss))
            run_loss = []
            curve.append({"iteration": it, "seconds": round(time.time() - t0, 1), "train": round(tl, 5),
                          "validation": round(vl, 5)})
            print(f"it {it} {time.time() - t0:.0f}s lr {lr:.2e} train {tl:.4f} val {vl:.4f} "
                  f"(l1 {parts[0]:.4f} log {parts[1]:.4f} temporal {parts[2]:.4f})", flush=True)
            if vl < best[0]:
                best = (vl, {k: v.clone() for k, v in model.state_dict().items()})
    train_s = time.time() - t0
    if best[1] is not None:
        model.load_state_dict(best[1])
    vl, parts = validate()
    # The identity baseline: the validation L1 of the noisy input itself.
    with torch.no_grad():
        base = sum(((va_n[:, t] - va_r[:, t]).abs().mean().item()) for t in range(va_n.shape[1])) / va_n.shape[1]
    record = {
        "name": net,
        "trained": True,
        "dataset": a.dataset,
        "training_data": {**data_info, "clips_train": int(n - nv), "clips_validation": int(nv),
                          "extra_training_data": None if extra is None else {
                              **extra[2], "clips_train": int(extra[0].shape[0]), "share_of_each_batch": 0.5}},
        "training": {"seconds": round(train_s, 1), "iterations": it, "batch": a.batch, "crop": a.crop,
                     "optimizer": f"Adam lr {a.lr} cosine to 0", "threads": a.threads, "seed": a.seed,
                     "loss": "0.8 L1 + 0.1 L1(LoG 7x7 sigma 1) + 0.1 L1(temporal difference), log1p space, "
                             "frame weights " + str(FRAME_WEIGHTS.tolist()),
                     "augmentation": f"{a.crop}x{a.crop} crops, flips, rot90, time reversal",
                     "final_validation_loss": round(vl, 5),
                     "final_validation_parts_l1_log_temporal": [round(p, 5) for p in parts],
                     "validation_l1_of_noisy_input": round(base, 5)},
        "initialised_from": init,
        "validation_curve": curve,
        "deviations": "one recurrent conv per encoder level and one conv per decoder level; widths " + a.widths
                      + " (sized for CPU training and lavapipe inference)",
    }
    out = os.path.join(ROOT, "assets", "rae")
    rae.save(model, os.path.join(out, f"{net}.bin"), os.path.join(out, f"{net}.json"), record)
    print(f"saved assets/rae/{net}: {rae.param_count(model)} parameters, {it} iterations in {train_s:.0f}s, "
          f"validation {vl:.4f} (noisy input L1 {base:.4f})", flush=True)
    subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__), "fixture.py"), "--net", net], check=True)


if __name__ == "__main__":
    main()
