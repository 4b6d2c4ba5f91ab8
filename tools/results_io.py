"""The helpers every results block uses: where the runs' files are, reading them, and
formatting numbers and Markdown tables (`tools/results.py` holds the blocks)."""

import csv
import json
import math
import os
import re

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
RESULTS = os.path.join(ROOT, "assets", "results")
PAGES = ["README.md"] + sorted(
    os.path.join("docs", "src", f)
    for f in os.listdir(os.path.join(ROOT, "docs", "src"))
    if f.endswith(".md")
)
BLOCK = re.compile(
    r"(<!-- results:(?P<name>[a-z0-9-]+) -->\n)(?P<body>.*?)(<!-- /results:(?P=name) -->)",
    re.S,
)

# The methods compared (the others are ablations of ours or of the paper's family).
COMPARED = ["none", "taa", "svgf", "wrls-paper", "rls-paper", "wrls", "rls", "wrls-nf",
            "rls-nf", "rae", "rae-phantom", "rae-mri", "rae-fp16", "oidn", "oidn-aux", "ours"]
ORDER = ["none", "accum", "taa", "svgf", "ours", "ours-no-gradient", "ours-no-lag",
         "ours-no-prior", "ours-no-atrous", "ours-no-feedback", "ours-no-young", "wrls-paper", "rls-paper",
         "wrls", "rls", "wrls-nf", "rls-nf", "rae", "rae-phantom", "rae-mri", "rae-fp16", "oidn", "oidn-aux"]
# metric: (column title, digits, higher is better)
METRICS = {
    "psnr": ("PSNR dB", 2, True),
    "ssim": ("SSIM", 3, True),
    "flip": ("FLIP", 4, False),
    "temporal_error": ("temporal error", 5, False),
    "gpu_ms": ("GPU ms", 1, None),
}


class Missing(Exception):
    pass


def path(*parts):
    return os.path.join(RESULTS, *parts)


def read_csv(*parts):
    p = path(*parts)
    if not os.path.exists(p):
        raise Missing(os.path.relpath(p, ROOT))
    with open(p, newline="") as f:
        return list(csv.DictReader(f))


def read_json(*parts):
    p = path(*parts)
    if not os.path.exists(p):
        raise Missing(os.path.relpath(p, ROOT))
    with open(p) as f:
        return json.load(f)


def num(s):
    try:
        v = float(s)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def fmt(v, digits):
    return "" if v is None else f"{v:.{digits}f}"


def mean(xs):
    xs = [x for x in xs if x is not None]
    return sum(xs) / len(xs) if xs else None


def method_order(methods):
    return sorted(methods, key=lambda m: (ORDER.index(m) if m in ORDER else len(ORDER), m))


def scenes_of(rows):
    seen = []
    for r in rows:
        if r["scene"] not in seen:
            seen.append(r["scene"])
    return seen


def means(rows, methods=None):
    """Per method, the mean over scenes of each metric in a summary.csv."""
    out = {}
    for m in methods or method_order({r["method"] for r in rows}):
        sel = [r for r in rows if r["method"] == m]
        if sel:
            out[m] = {k: mean(num(r[k]) for r in sel) for k in METRICS}
    return out


def best(values, higher):
    vals = [v for v in values.values() if v is not None]
    if not vals:
        return None
    return max(vals) if higher else min(vals)


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def bold_if(text, cond):
    return f"**{text}**" if cond and text else text


def source(set_, files):
    meta = read_json(set_, "meta.json")
    names = ", ".join(f"`assets/results/{set_}/{f}`" for f in files)
    load = meta.get("load_average_at_end")
    busy = (f" Load average (1, 5, 15 min) as the run ended: "
            f"{', '.join(f'{x:.1f}' for x in load)}." if load else "")
    return (f"Source: {names}, made by `{meta['command']}` at commit {meta['commit']} "
            f"({meta['date']}) on {meta['machine']}.{busy}")


def means_table(set_, rows, methods, metrics=("psnr", "ssim", "flip", "temporal_error", "gpu_ms")):
    m = means(rows, methods)
    bests = {}
    for k in metrics:
        hib = METRICS[k][2]
        if hib is not None:
            bests[k] = best({x: v[k] for x, v in m.items() if x in COMPARED}, hib)
    header = ["method"] + [METRICS[k][0] for k in metrics]
    body = []
    for x, v in m.items():
        cells = [f"`{x}`"]
        for k in metrics:
            t = fmt(v[k], METRICS[k][1])
            b = x in COMPARED and k in bests and v[k] is not None and \
                fmt(v[k], METRICS[k][1]) == fmt(bests[k], METRICS[k][1])
            cells.append(bold_if(t, b))
        body.append(cells)
    return table(header, body)


def per_scene_table(rows, methods, metric="psnr", label="scene"):
    digits = METRICS[metric][1]
    hib = METRICS[metric][2]
    body = []
    for s in scenes_of(rows):
        vals = {r["method"]: num(r[metric]) for r in rows if r["scene"] == s}
        b = best({x: vals.get(x) for x in methods if x in COMPARED}, hib)
        body.append([s] + [bold_if(fmt(vals.get(x), digits),
                                   x in COMPARED and vals.get(x) is not None and
                                   fmt(vals.get(x), digits) == fmt(b, digits))
                           for x in methods])
    return table([label] + [f"`{x}`" for x in methods], body)


def present(rows, methods):
    have = {r["method"] for r in rows}
    return [m for m in methods if m in have]


# ------------------------------------------------------------- frame by frame


def frames_by_scene(metrics):
    """{scene: {frame: {method: psnr}}} of a metrics.csv."""
    by = {}
    for r in metrics:
        by.setdefault(r["scene"], {}).setdefault(int(r["frame"]), {})[r["method"]] = num(r["psnr"])
    return by


def worst_margin(frames, rivals, after=4):
    """The frame after `after` where ours is lowest against the best of `rivals` present:
    (margin dB, frame), or None."""
    worst = None
    for f, v in sorted(frames.items()):
        have = [v[x] for x in rivals if v.get(x) is not None]
        if f <= after or v.get("ours") is None or not have:
            continue
        margin = v["ours"] - max(have)
        if worst is None or margin < worst[0]:
            worst = (margin, f)
    return worst


SINGLE_FRAME = ("oidn", "oidn-aux", "rae")


def gap_at(frames, frame, rivals=SINGLE_FRAME):
    """Ours minus the best of `rivals` present at one frame of a scene's
    {frame: {method: psnr}}, or None where either is missing."""
    v = frames.get(frame, {})
    have = [v[x] for x in rivals if v.get(x) is not None]
    return None if v.get("ours") is None or not have else v["ours"] - max(have)


def below_best(frames, rivals, by=1.0, after=4):
    """(frames after `after` more than `by` dB below the best of `rivals` present, frames
    compared) of one scene's {frame: {method: psnr}}."""
    n = below = 0
    for f, v in frames.items():
        have = [v[x] for x in rivals if v.get(x) is not None]
        if f <= after or v.get("ours") is None or not have:
            continue
        n += 1
        below += v["ours"] < max(have) - by
    return below, n


# ------------------------------------------------------------- cost


def own_ms(rows):
    """{method: {(scene, frame): ms}} of a metrics.csv that timed `none` beside the
    methods: each frame's GPU ms less the path trace's (`none`'s), so a method's own
    passes and the features it needs (frames the eval did not time, such as OIDN's,
    are left out)."""
    ms = {}
    for r in rows:
        ms.setdefault(r["method"], {})[(r["scene"], r["frame"])] = num(r["gpu_ms"])
    base = ms.get("none")
    if base is None:
        raise Missing("a `none` row per frame beside the methods timed")
    return {m: {k: v - base[k] for k, v in d.items() if k in base and v is not None}
            for m, d in ms.items()}
