#!/usr/bin/env python3
"""Add Intel Open Image Denoise (OIDN) to a `dvr eval` folder, as methods `oidn` and `oidn-aux`.

Denoises the noisy input frames an eval keeps (`DIR/<scene>/none/NNNN.exr`, the
`none` method, i.e. the raw path-traced frames) with OIDN's RT filter, scores them
against the eval's references with the same metrics as `dvr eval`, writes
`DIR/<scene>/<method>/NNNN.png`, and appends rows to `DIR/metrics.csv` and
`DIR/summary.csv` (replacing any from an earlier run of this script):

  * `oidn`: the HDR colour alone (`hdr=True`, no auxiliary images);
  * `oidn-aux`: colour with OIDN's albedo and normal auxiliary images, for the scenes
    whose eval ran with `--aux` (`DIR/<scene>/aux/NNNN_albedo.exr`, `NNNN_normal.exr`:
    the TF albedo and gradient normal composited along each pixel's ray with the
    weights of its first scattering event, shaders/glsl/aux_features.comp). They are
    deterministic (no noise), so OIDN takes them as clean (`clean_aux=True`, what its
    documentation recommends for noise-free guides) instead of prefiltering them.

Both denoise every frame independently (no temporal information).

Metrics, exactly as `dvr eval` computes them (engine/src/metrics/):
  * Tone map (engine/src/metrics/tonemap.rs), per channel c, exposure e = 1:
        x = max(e * c, 0)                      (NaN -> 0)
        y = min(x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), 1)   (ACES, Narkowicz 2015)
        s = 12.92 y                  if y <= 0.0031308
            1.055 y^(1/2.4) - 0.055  otherwise                       (sRGB OETF)
  * PSNR: 10 log10(1 / MSE) over all pixels and the three channels, capped at 100 dB.
  * SSIM: on luma Y' = 0.2126 R' + 0.7152 G' + 0.0722 B' of the tone-mapped values,
    11x11 Gaussian window (sigma 1.5, normalised), K1 = 0.01, K2 = 0.03, L = 1, mean
    over the valid region (windows fully inside the image).
  * FLIP: LDR-FLIP of the tone-mapped images at 67.02 pixels per degree, via NVIDIA's
    `flip-evaluator` (which dvr's own FLIP matches to ~1e-6); left empty if that
    package is missing.
  * temporal_error: mean |(cur - prev)_oidn - (cur - prev)_reference| over pixels and
    channels, from frame 1 on.
  * gpu_ms: left empty (OIDN runs on the CPU here); the CPU time is printed.
  * frames_to_recover (summary.csv): for scenes with a sudden change (the event frame is
    read from the eval's index.html), frames after the event until PSNR stays within
    1 dB of its mean over the 5 frames before; `never` if it does not recover.

`--check` recomputes the `none` rows in Python first and reports the largest
difference from metrics.csv, which verifies the two implementations agree.

Usage (not part of the test suite; needs pip packages):
    pip install pyoidn numpy OpenEXR pillow flip-evaluator
    python3 tools/oidn_eval.py out/eval [--quality high] [--check]
"""

import argparse
import csv
import io
import json
import math
import os
import re
import sys
import time

try:
    import numpy as np
except ImportError:
    sys.exit("oidn_eval: numpy is missing: pip install pyoidn numpy OpenEXR pillow flip-evaluator")

METHOD = "oidn"
METHOD_AUX = "oidn-aux"
PSNR_CAP = 100.0
RECOVERY_TOLERANCE_DB = 1.0
RECOVERY_BASELINE_FRAMES = 5
METRICS_HEADER = "scene,method,frame,psnr,ssim,flip,temporal_error,gpu_ms"
SUMMARY_HEADER = "scene,method,psnr,ssim,flip,temporal_error,gpu_ms,frames_to_recover"


def need(module, pip_name):
    try:
        return __import__(module)
    except ImportError:
        sys.exit(f"oidn_eval: the Python package `{pip_name}` is missing: pip install {pip_name}")


def dir_name(scene):
    """dvr's folder name for a scene (src/eval/scenes.rs: dir_name)."""
    s = "".join(c if (c.isascii() and c.isalnum()) or c in "-." else "_" for c in scene)
    s = s.strip(".")
    return s or "scene"


def tonemap(hdr, exposure=1.0):
    x = np.nan_to_num(hdr.astype(np.float32) * np.float32(exposure), nan=0.0, posinf=np.inf)
    x = np.maximum(x, 0.0)
    with np.errstate(invalid="ignore", over="ignore"):
        y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)
    y = np.where(np.isnan(y), 1.0, y)  # +inf input -> white, as in the Rust code
    y = np.clip(y, 0.0, 1.0)
    s = np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1.0 / 2.4) - 0.055)
    return np.where(y >= 1.0, 1.0, s).astype(np.float32)


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    if mse == 0.0:
        return PSNR_CAP
    return min(10.0 * math.log10(1.0 / mse), PSNR_CAP)


def ssim(a, b):
    h, w = a.shape[:2]
    radius = min(5, (min(w, h) - 1) // 2)
    d = np.arange(-radius, radius + 1, dtype=np.float64)
    g = np.exp(-d * d / (2.0 * 1.5 * 1.5))
    g /= g.sum()
    lw = np.array([0.2126, 0.7152, 0.0722])
    x = a.astype(np.float64) @ lw
    y = b.astype(np.float64) @ lw
    taps = len(g)
    ow, oh = w + 1 - taps, h + 1 - taps

    def blur(img):
        hor = sum(g[k] * img[:, k : k + ow] for k in range(taps))
        return sum(g[k] * hor[k : k + oh, :] for k in range(taps))

    mx, my = blur(x), blur(y)
    vx = blur(x * x) - mx * mx
    vy = blur(y * y) - my * my
    cxy = blur(x * y) - mx * my
    c1, c2 = 0.01**2, 0.03**2
    m = ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
    return float(m.mean())


def temporal_error(prev_test, cur_test, prev_ref, cur_ref):
    dt = cur_test.astype(np.float64) - prev_test
    dr = cur_ref.astype(np.float64) - prev_ref
    return float(np.mean(np.abs(dt - dr)))


def frames_to_recover(series, event, tol):
    if event <= 0 or event >= len(series):
        return None
    before = series[max(0, event - RECOVERY_BASELINE_FRAMES) : event]
    base = sum(min(v, PSNR_CAP) for v in before) / len(before)
    ok = [min(v, PSNR_CAP) >= base - tol for v in series[event:]]
    bad = [i for i, good in enumerate(ok) if not good]
    if not bad:
        return 0
    last = bad[-1]
    return last + 1 if last + 1 < len(ok) else None


class Flip:
    def __init__(self):
        try:
            import flip_evaluator

            self.flip = flip_evaluator
        except ImportError:
            self.flip = None
            print("oidn_eval: flip-evaluator is missing (pip install flip-evaluator): FLIP left empty")

    def __call__(self, ref, test):
        if self.flip is None:
            return None
        # flip-evaluator converts its inputs in place: hand it copies.
        r = np.ascontiguousarray(ref, dtype=np.float32).copy()
        t = np.ascontiguousarray(test, dtype=np.float32).copy()
        _, mean, _ = self.flip.evaluate(r, t, "LDR")
        return float(mean)


def read_exr(path):
    OpenEXR = need("OpenEXR", "OpenEXR")
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.asarray(ch["RGB"].pixels, dtype=np.float32)
        if "RGBA" in ch:
            return np.asarray(ch["RGBA"].pixels, dtype=np.float32)[..., :3]
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float32) for c in "RGB"], axis=-1)


def write_png(path, display):
    from PIL import Image

    u8 = (np.clip(display, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
    Image.fromarray(u8, "RGB").save(path)


def event_frames(out):
    """Event frame per scene, from the data the eval put in index.html."""
    try:
        html = open(os.path.join(out, "index.html"), encoding="utf-8").read()
        m = re.search(r'<script type="application/json" id="data">(.*?)</script>', html, re.S)
        data = json.loads(m.group(1))
        return {s["name"]: s.get("event_frame") for s in data["scenes"]}
    except (OSError, AttributeError, ValueError, KeyError):
        return {}


def fmt(v, digits):
    return "" if v is None else f"{v:.{digits}f}"


def score_sequence(out, scene, frames, images, flip):
    """Scores `images(frame) -> HDR array` against the references; returns rows."""
    d = os.path.join(out, dir_name(scene))
    rows, prev = [], None
    for f in frames:
        ref = tonemap(read_exr(os.path.join(d, "reference", f"{f:04d}.exr")))
        test = tonemap(images(f))
        te = temporal_error(prev[0], test, prev[1], ref) if prev is not None else None
        rows.append(
            {"frame": f, "psnr": psnr(ref, test), "ssim": ssim(ref, test), "flip": flip(ref, test), "temporal_error": te, "display": test}
        )
        prev = (test, ref)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="a dvr eval folder (with metrics.csv)")
    ap.add_argument("--quality", default="high", choices=["high", "balanced", "fast"])
    ap.add_argument("--check", action="store_true", help="first verify the Python metrics against the `none` rows")
    args = ap.parse_args()

    need("OpenEXR", "OpenEXR")
    need("PIL", "pillow")
    pyoidn = need("pyoidn", "pyoidn")

    metrics_path = os.path.join(args.out, "metrics.csv")
    summary_path = os.path.join(args.out, "summary.csv")
    with open(metrics_path, newline="") as fh:
        text = fh.read()
    if text.splitlines()[0] != METRICS_HEADER:
        sys.exit(f"oidn_eval: {metrics_path} does not start with {METRICS_HEADER!r}")
    rows = list(csv.DictReader(io.StringIO(text)))
    scenes = []
    for r in rows:
        if r["method"] == "none" and r["scene"] not in scenes:
            scenes.append(r["scene"])
    if not scenes:
        sys.exit(f"oidn_eval: {metrics_path} has no `none` rows (run dvr eval with --denoiser none,...)")
    frames = {s: sorted(int(r["frame"]) for r in rows if r["scene"] == s and r["method"] == "none") for s in scenes}
    events = event_frames(args.out)
    flip = Flip()

    if args.check:
        worst = {"psnr": 0.0, "ssim": 0.0, "flip": 0.0, "temporal_error": 0.0}
        for s in scenes:
            d = os.path.join(args.out, dir_name(s))
            got = score_sequence(args.out, s, frames[s], lambda f: read_exr(os.path.join(d, "none", f"{f:04d}.exr")), flip)
            want = {int(r["frame"]): r for r in rows if r["scene"] == s and r["method"] == "none"}
            for g in got:
                w = want[g["frame"]]
                for k in worst:
                    if g[k] is not None and w[k] != "":
                        worst[k] = max(worst[k], abs(g[k] - float(w[k])))
        print("oidn_eval --check: largest |python - dvr| on `none`: " + ", ".join(f"{k} {v:.2e}" for k, v in worst.items()))

    new_rows, new_summary = [], []
    cpu_ms = {METHOD: [], METHOD_AUX: []}
    for s in scenes:
        d = os.path.join(args.out, dir_name(s))
        aux_dir = os.path.join(d, "aux")
        has_aux = all(
            os.path.exists(os.path.join(aux_dir, f"{f:04d}_{kind}.exr")) for f in frames[s] for kind in ("albedo", "normal")
        )
        for method in [METHOD] + ([METHOD_AUX] if has_aux else []):
            os.makedirs(os.path.join(d, method), exist_ok=True)

            def denoised(f, method=method):
                noisy = np.ascontiguousarray(read_exr(os.path.join(d, "none", f"{f:04d}.exr")))
                aux = {}
                if method == METHOD_AUX:
                    aux = {
                        "albedo": np.ascontiguousarray(np.clip(read_exr(os.path.join(aux_dir, f"{f:04d}_albedo.exr")), 0.0, 1.0)),
                        "normal": np.ascontiguousarray(np.clip(read_exr(os.path.join(aux_dir, f"{f:04d}_normal.exr")), -1.0, 1.0)),
                        "clean_aux": True,
                    }
                t0 = time.perf_counter()
                out = pyoidn.denoise(noisy, hdr=True, quality=args.quality, **aux)
                cpu_ms[method].append(1e3 * (time.perf_counter() - t0))
                return np.asarray(out, dtype=np.float32)

            scored = score_sequence(args.out, s, frames[s], denoised, flip)
            for r in scored:
                write_png(os.path.join(d, method, f"{r['frame']:04d}.png"), r["display"])
                new_rows.append(
                    [s, method, str(r["frame"]), f"{r['psnr']:.4f}", f"{r['ssim']:.6f}", fmt(r["flip"], 6), fmt(r["temporal_error"], 6), ""]
                )
            mean = lambda xs: sum(xs) / len(xs) if xs else None
            te = [r["temporal_error"] for r in scored if r["temporal_error"] is not None]
            fl = [r["flip"] for r in scored if r["flip"] is not None]
            event = events.get(s)
            if event is None and any(s.endswith(a) for a in ("/tf-jump", "/light-jump")):
                event = len(scored) // 2
            rec = ""
            if event is not None:
                n = frames_to_recover([r["psnr"] for r in scored], event, RECOVERY_TOLERANCE_DB)
                rec = "never" if n is None else str(n)
            new_summary.append(
                [s, method, f"{mean([r['psnr'] for r in scored]):.4f}", f"{mean([r['ssim'] for r in scored]):.6f}", fmt(mean(fl), 6), fmt(mean(te), 6), "", rec]
            )
            r = new_summary[-1]
            print(f"{s:<24} {method:<9} PSNR {r[2]} dB  SSIM {r[3]}  FLIP {r[4]}  temporal {r[5]}  recover {rec}")

    def rewrite(path, header, extra):
        with open(path, newline="") as fh:
            lines = list(csv.reader(fh))
        kept = [l for l in lines[1:] if len(l) > 1 and l[1] not in (METHOD, METHOD_AUX)]
        with open(path + ".partial", "w", newline="") as fh:
            wr = csv.writer(fh, lineterminator="\n")
            fh.write(header + "\n")
            wr.writerows(kept + extra)
        os.replace(path + ".partial", path)

    rewrite(metrics_path, METRICS_HEADER, new_rows)
    if os.path.exists(summary_path):
        rewrite(summary_path, SUMMARY_HEADER, new_summary)
    for method, times in cpu_ms.items():
        if times:
            ms = sorted(times)
            print(f"oidn_eval: {method} ({args.quality}): {len(ms)} frames, CPU {ms[len(ms) // 2]:.1f} ms/frame median")
    print(f"oidn_eval: {len(new_rows)} rows of {len(scenes)} scene(s) appended to {metrics_path}")


if __name__ == "__main__":
    main()
