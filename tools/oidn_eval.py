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

Metrics: `dvr.metrics` from the Python package (python/), i.e. the eval's own code
(engine/src/metrics/): the same tone map, PSNR, SSIM, LDR-FLIP and temporal error, so
the appended rows compare with the eval's to the last digit.
  * gpu_ms: left empty (OIDN runs on the CPU here). Its cost goes to `DIR/oidn_ms.csv`
    instead: per frame, OIDN's CPU ms and the whole frame's ms, i.e. the eval's shared
    passes (path trace, motion; `DIR/<scene>/timings.json`), plus for `oidn-aux` the
    march that wrote its guide images, plus OIDN's CPU ms. On lavapipe the GPU passes run
    on the same CPU cores as OIDN, so the sum is one machine's time.
  * frames_to_recover (summary.csv): for scenes with a sudden change (the event frame is
    read from the eval's index.html), frames after the event until PSNR stays within
    1 dB of its mean over the 5 frames before; `never` if it does not recover.

`--check` recomputes the `none` rows first and reports the largest difference from
metrics.csv (zero up to the CSV's rounding).

Usage (not part of the test suite; needs the dvr package and pip packages):
    pip install ./python pyoidn numpy OpenEXR pillow
    python3 tools/oidn_eval.py out/eval [--quality high] [--check]
"""

import argparse
import csv
import io
import json
import os
import re
import sys
import time

try:
    import dvr
except ImportError:
    sys.exit("oidn_eval: the dvr Python package is missing: pip install ./python")
try:
    import numpy as np
except ImportError:
    sys.exit("oidn_eval: numpy is missing: pip install pyoidn numpy OpenEXR pillow")

METHOD = "oidn"
METHOD_AUX = "oidn-aux"
PSNR_CAP = 100.0
RECOVERY_TOLERANCE_DB = 1.0
RECOVERY_BASELINE_FRAMES = 5
METRICS_HEADER = "scene,method,frame,psnr,ssim,flip,temporal_error,gpu_ms"
SUMMARY_HEADER = "scene,method,psnr,ssim,flip,temporal_error,gpu_ms,frames_to_recover"
MS_HEADER = "scene,method,frame,oidn_cpu_ms,frame_ms"


def need(module, pip_name):
    try:
        return __import__(module)
    except ImportError:
        sys.exit(f"oidn_eval: the Python package `{pip_name}` is missing: pip install {pip_name}")


def dir_name(scene):
    """dvr's folder name for a scene (src/eval/plan/scenes.rs: dir_name)."""
    s = "".join(c if (c.isascii() and c.isalnum()) or c in "-." else "_" for c in scene)
    s = s.strip(".")
    return s or "scene"


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


def score_sequence(out, scene, frames, images):
    """Scores `images(frame) -> HDR array` against the references with `dvr.metrics`
    (the eval's own code, through the Python package); returns rows."""
    d = os.path.join(out, dir_name(scene))
    rows, prev = [], None
    for f in frames:
        ref = read_exr(os.path.join(d, "reference", f"{f:04d}.exr"))
        test = np.ascontiguousarray(images(f), dtype=np.float32)
        te = dvr.metrics.temporal_error(prev[0], test, prev[1], ref) if prev is not None else None
        rows.append(
            {
                "frame": f,
                "psnr": dvr.metrics.psnr(ref, test),
                "ssim": dvr.metrics.ssim(ref, test),
                "flip": dvr.metrics.flip(ref, test),
                "temporal_error": te,
                "display": dvr.metrics.tonemap(test),
            }
        )
        prev = (test, ref)
    return rows


def read_metrics(metrics_path):
    """The eval's metrics.csv: its rows, the scenes with `none` rows (in file order) and
    each scene's `none` frames; exits with a message if the file is not one."""
    with open(metrics_path, newline="") as fh:
        text = fh.read()
    if not text.splitlines() or text.splitlines()[0] != METRICS_HEADER:
        sys.exit(f"oidn_eval: {metrics_path} does not start with {METRICS_HEADER!r}")
    rows = list(csv.DictReader(io.StringIO(text)))
    scenes = []
    for r in rows:
        if r["method"] == "none" and r["scene"] not in scenes:
            scenes.append(r["scene"])
    if not scenes:
        sys.exit(f"oidn_eval: {metrics_path} has no `none` rows (run dvr eval with --denoiser none,...)")
    frames = {s: sorted(int(r["frame"]) for r in rows if r["scene"] == s and r["method"] == "none") for s in scenes}
    return rows, scenes, frames


def has_aux(scene_dir, frames):
    """Whether the eval kept the albedo and normal images of every frame (`--aux`)."""
    aux_dir = os.path.join(scene_dir, "aux")
    return all(
        os.path.exists(os.path.join(aux_dir, f"{f:04d}_{kind}.exr")) for f in frames for kind in ("albedo", "normal")
    )


def event_frame(scene, events, n_frames):
    """The scene's event frame: index.html's, else the middle frame for a `tf-jump` or
    `light-jump` scene, else None."""
    event = events.get(scene)
    if event is None and any(scene.endswith(a) for a in ("/tf-jump", "/light-jump")):
        event = n_frames // 2
    return event


def metric_row(scene, method, r):
    """One metrics.csv row for a scored frame."""
    return [scene, method, str(r["frame"]), f"{r['psnr']:.6f}", f"{r['ssim']:.6f}", fmt(r["flip"], 6), fmt(r["temporal_error"], 6), ""]


def summary_row(scene, method, scored, event):
    """One summary.csv row: the means over the scored frames and frames_to_recover
    (empty without an event, `never` if PSNR does not recover)."""
    mean = lambda xs: sum(xs) / len(xs) if xs else None
    te = [r["temporal_error"] for r in scored if r["temporal_error"] is not None]
    fl = [r["flip"] for r in scored if r["flip"] is not None]
    rec = ""
    if event is not None:
        n = frames_to_recover([r["psnr"] for r in scored], event, RECOVERY_TOLERANCE_DB)
        rec = "never" if n is None else str(n)
    return [scene, method, f"{mean([r['psnr'] for r in scored]):.4f}", f"{mean([r['ssim'] for r in scored]):.6f}", fmt(mean(fl), 6), fmt(mean(te), 6), "", rec]


def frame_gpu_ms(scene_dir):
    """Per frame of the eval's `timings.json`: (the shared passes' ms, the guide march's
    ms). The march is the pass that several methods need (owner `methods`); it writes the
    guide images `oidn-aux` reads. None where the eval kept no timings."""
    p = os.path.join(scene_dir, "timings.json")
    if not os.path.exists(p):
        return None
    with open(p) as fh:
        frames = json.load(fh)["frames"]
    out = []
    for passes in frames:
        shared = sum(t["ms"] for t in passes if t.get("owner", "shared") == "shared")
        march = sum(t["ms"] for t in passes if isinstance(t.get("owner"), dict) and "methods" in t["owner"])
        out.append((shared, march))
    return out


def rewrite(path, header, extra):
    """Rewrites a CSV with `extra` in place of its earlier `oidn` and `oidn-aux` rows."""
    with open(path, newline="") as fh:
        lines = list(csv.reader(fh))
    kept = [l for l in lines[1:] if len(l) > 1 and l[1] not in (METHOD, METHOD_AUX)]
    with open(path + ".partial", "w", newline="") as fh:
        wr = csv.writer(fh, lineterminator="\n")
        fh.write(header + "\n")
        wr.writerows(kept + extra)
    os.replace(path + ".partial", path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="a dvr eval folder (with metrics.csv)")
    ap.add_argument("--quality", default="high", choices=["high", "balanced", "fast"])
    ap.add_argument("--check", action="store_true", help="first verify the Python metrics against the `none` rows")
    args = ap.parse_args(argv)

    need("OpenEXR", "OpenEXR")
    need("PIL", "pillow")
    pyoidn = need("pyoidn", "pyoidn")

    metrics_path = os.path.join(args.out, "metrics.csv")
    summary_path = os.path.join(args.out, "summary.csv")
    rows, scenes, frames = read_metrics(metrics_path)
    events = event_frames(args.out)

    if args.check:
        worst = {"psnr": 0.0, "ssim": 0.0, "flip": 0.0, "temporal_error": 0.0}
        for s in scenes:
            d = os.path.join(args.out, dir_name(s))
            got = score_sequence(args.out, s, frames[s], lambda f: read_exr(os.path.join(d, "none", f"{f:04d}.exr")))
            want = {int(r["frame"]): r for r in rows if r["scene"] == s and r["method"] == "none"}
            for g in got:
                w = want[g["frame"]]
                for k in worst:
                    if g[k] is not None and w[k] != "":
                        worst[k] = max(worst[k], abs(g[k] - float(w[k])))
        print("oidn_eval --check: largest |python - dvr| on `none`: " + ", ".join(f"{k} {v:.2e}" for k, v in worst.items()))

    new_rows, new_summary, ms_rows = [], [], []
    cpu_ms = {METHOD: [], METHOD_AUX: []}
    for s in scenes:
        d = os.path.join(args.out, dir_name(s))
        aux_dir = os.path.join(d, "aux")
        gpu = frame_gpu_ms(d)
        for method in [METHOD] + ([METHOD_AUX] if has_aux(d, frames[s]) else []):
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
                ms = 1e3 * (time.perf_counter() - t0)
                cpu_ms[method].append(ms)
                if gpu is not None and f < len(gpu):
                    shared, march = gpu[f]
                    frame = shared + (march if method == METHOD_AUX else 0.0) + ms
                    ms_rows.append([s, method, str(f), f"{ms:.4f}", f"{frame:.4f}"])
                return np.asarray(out, dtype=np.float32)

            scored = score_sequence(args.out, s, frames[s], denoised)
            for r in scored:
                write_png(os.path.join(d, method, f"{r['frame']:04d}.png"), r["display"])
                new_rows.append(metric_row(s, method, r))
            new_summary.append(summary_row(s, method, scored, event_frame(s, events, len(scored))))
            r = new_summary[-1]
            print(f"{s:<24} {method:<9} PSNR {r[2]} dB  SSIM {r[3]}  FLIP {r[4]}  temporal {r[5]}  recover {r[7]}")

    rewrite(metrics_path, METRICS_HEADER, new_rows)
    if os.path.exists(summary_path):
        rewrite(summary_path, SUMMARY_HEADER, new_summary)
    with open(os.path.join(args.out, "oidn_ms.csv"), "w", newline="") as fh:
        fh.write(MS_HEADER + "\n")
        csv.writer(fh, lineterminator="\n").writerows(ms_rows)
    for method, times in cpu_ms.items():
        if times:
            ms = sorted(times)
            print(f"oidn_eval: {method} ({args.quality}): {len(ms)} frames, CPU {ms[len(ms) // 2]:.1f} ms/frame median")
    print(f"oidn_eval: {len(new_rows)} rows of {len(scenes)} scene(s) appended to {metrics_path}")


if __name__ == "__main__":
    main()
