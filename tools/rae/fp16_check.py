"""Would fp16 tensors keep the RAE's accuracy? Runs a shipped network on its validation
clips twice: as the engine does now (fp32 everywhere) and with every stored tensor (the
normalised input, each convolution's output, the recurrent state) rounded to fp16, i.e.
what rgba16f tensor images with fp32 arithmetic would compute. Prints the output change
and both PSNRs against the references, in the log space the network works in and in HDR.

    /opt/rae-venv/bin/python tools/rae/fp16_check.py --net mri [--data out/rae-data]
"""
import argparse
import os

import numpy as np
import torch

import model as rae

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def psnr(a, b):
    mse = float(((a - b) ** 2).mean())
    peak = float(b.max())
    return 10 * np.log10(peak * peak / max(mse, 1e-20))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--net", required=True)
    ap.add_argument("--data", default=os.path.join(ROOT, "out", "rae-data"))
    ap.add_argument("--val-clips", type=int, default=4)
    a = ap.parse_args()
    model, manifest = rae.load(os.path.join(ROOT, "assets", "rae", f"{a.net}.json"))
    model.eval()
    d = np.load(os.path.join(a.data, f"{a.net}.npz"))
    noisy = torch.from_numpy(d["noisy"][-a.val_clips:])
    ref = torch.from_numpy(d["ref"][-a.val_clips:])

    out32 = torch.stack([rae.run_clip(model, c) for c in noisy])
    half = lambda m, i, o: o.half().float()  # noqa: E731
    hooks = [c.register_forward_hook(half) for c in model.convs.values()]
    normalise = rae.normalise
    rae.normalise = lambda x: normalise(x).half().float()
    out16 = torch.stack([rae.run_clip(model, c) for c in noisy])
    rae.normalise = normalise
    for h in hooks:
        h.remove()

    log32, log16, logref = (rae.normalise(x) for x in (out32, out16, ref))
    diff = (log16 - log32).abs()
    print(f"{a.net}: {noisy.shape[0]} validation clips {tuple(noisy.shape[1:])}")
    print(f"  fp16 vs fp32 output (log space): max |diff| {diff.max():.2e}, mean {diff.mean():.2e}")
    print(f"  PSNR vs reference, log space: fp32 {psnr(log32, logref):.3f} dB, fp16 {psnr(log16, logref):.3f} dB")
    print(f"  PSNR vs reference, HDR:       fp32 {psnr(out32, ref):.3f} dB, fp16 {psnr(out16, ref):.3f} dB")


if __name__ == "__main__":
    main()
