#!/usr/bin/env python3
"""Render the results tables from the CSVs the runs wrote (Python standard library only).

Every measured number in README.md and the book (docs/src/) comes from a file under
assets/results/<set>/, written by the run that measured it (tools/measure.sh keeps them,
with meta.json: the command, commit, machine and date). A page holds a generated block
between two markers:

    <!-- results:NAME -->
    ...generated...
    <!-- /results:NAME -->

and this script rewrites every such block from its CSV:

    tools/results.py            # rewrite the blocks in README.md and docs/src/*.md
    tools/results.py --check    # exit 1, naming each block that is stale (tools/test.sh)
    tools/results.py --list     # the block names and the files each reads

A block whose name is unknown, or whose files are missing, is an error: a table is
either generated from a run's files or not there. The charts the pages show are files
drawn the same way (tools/results_figures.py: FIGURES), written and checked with the pages.
"""

import argparse
import csv
import json
import os
import re
import sys

from results_io import (
    ROOT,
    PAGES,
    BLOCK,
    COMPARED,
    Missing,
    path,
    read_csv,
    read_json,
    num,
    fmt,
    mean,
    method_order,
    scenes_of,
    means,
    best,
    table,
    bold_if,
    source,
    means_table,
    per_scene_table,
    present,
    frames_by_scene,
    worst_margin,
    below_best,
    SINGLE_FRAME,
)
from results_sets import (
    b_cuts,
    b_media,
    b_media_line,
    b_cuts_line,
    b_channels_cost,
    b_cut_cost,
    b_labels,
    b_labels_line,
    b_labels_cost,
    b_interaction,
    b_mechanisms,
    b_development_cost,
    b_setup_times,
)
from results_experiments import (b_experiments_prior, b_experiments_strata, b_experiments_motion,
                                 b_experiments_young, b_experiments_guided, b_experiments_learned,
                                 b_experiments_young_net)
from results_figures import (
    FIGURES,
    b_speed_accuracy,
    b_speed_accuracy_line,
    b_interaction_curves,
)


# ---------------------------------------------------------------------------- blocks


def b_headline():
    rows = read_csv("validation", "summary.csv")
    meta = read_json("validation", "meta.json")
    methods = present(rows, ["ours", "svgf", "taa", "rae", "oidn-aux", "oidn"])
    n = len(scenes_of(rows))
    # A scene file written since the run is named: the means are not yet over the whole set.
    others = [sc for sc in validation_scenes() if sc not in scenes_of(rows)]
    also = (f"; its other {len(others)} scenes ({', '.join(others)}) are in no run of it yet"
            if others else "")
    return "\n".join([
        means_table("validation", rows, methods),
        "",
        f"Means over {n} scenes of the validation set (never tuned on; 128×128, 48 "
        f"frames, 2 spp, 256-spp references{also}), commit {meta['commit']}, on {meta['machine']}. "
        "GPU ms count the shared passes, the features and guides each method reads, and its "
        "own; OIDN runs on the CPU (no GPU ms); `oidn-aux` is OIDN with the albedo and normal "
        "guides. Every scene and method, and the development suite: "
        "[the results](docs/src/results.md).",
    ])


def validation_scenes():
    """The labels of the validation set's scene files (`name`, else the file's stem)."""
    folder = os.path.join(ROOT, "assets", "scenes", "validation")
    if not os.path.isdir(folder):
        raise Missing(os.path.relpath(folder, ROOT))
    labels = []
    for f in sorted(os.listdir(folder)):
        if f.endswith(".toml"):
            with open(os.path.join(folder, f), encoding="utf-8") as fh:
                m = re.search(r'^name\s*=\s*"([^"]+)"', fh.read(), re.M)
            labels.append(m.group(1) if m else f[:-len(".toml")])
    return labels


def b_suite_means():
    rows = read_csv("suite", "summary.csv")
    # The ablations' rows are the validation set's (one run of the switches as they are).
    methods = [m for m in method_order({r["method"] for r in rows}) if not m.startswith("ours-")]
    return "\n".join([means_table("suite", rows, methods), "",
                      source("suite", ["summary.csv"])])


def b_suite_scenes():
    rows = read_csv("suite", "summary.csv")
    methods = present(rows, ["none", "taa", "svgf", "ours", "rae", "oidn", "oidn-aux"])
    lead = sum(
        1 for s in scenes_of(rows)
        if (lambda vals: vals.get("ours") is not None and
            fmt(vals["ours"], 2) == fmt(best({x: vals.get(x) for x in COMPARED if x in vals}, True), 2))(
            {r["method"]: num(r["psnr"]) for r in rows if r["scene"] == s})
    )
    return "\n".join([
        per_scene_table(rows, methods),
        "",
        f"`ours` has the best PSNR of the methods compared on {lead} of the "
        f"{len(scenes_of(rows))} scenes.",
        "",
        source("suite", ["summary.csv"]),
    ])


def b_ablations():
    rows = read_csv("validation", "summary.csv")
    m = means(rows)
    base = m["ours"]
    body = []
    for x in ["ours-no-gradient", "ours-no-lag", "ours-no-prior", "ours-no-atrous",
              "ours-no-feedback", "ours-no-young"]:
        if x in m:
            body.append([f"`{x}`", fmt(m[x]["psnr"], 2), f"{base['psnr'] - m[x]['psnr']:+.2f}",
                         fmt(m[x]["flip"], 4), f"{base['flip'] - m[x]['flip']:+.4f}"])
    return "\n".join([
        table(["ablation", "PSNR dB", "ours − it, dB", "FLIP", "ours − it, FLIP"], body),
        "",
        source("validation", ["summary.csv"]),
    ])


def b_demo():
    rows = read_csv("demo", "summary.csv")
    meta = read_json("demo", "meta.json")
    return "\n".join([
        means_table("demo", rows, None),
        "",
        f"The whole run took {meta['wall_s']:.0f} s of wall time after the build, "
        "references included.",
        "",
        source("demo", ["summary.csv", "metrics.csv"]),
    ])


# The development scene the results page shows (the kind ours loses; the set's other
# scenes are the cut scenes' page's).
DEVELOPMENT_SCENE = "dev/cloud-opaque-march-swing"


def b_development():
    rows = [r for r in read_csv("development", "summary.csv") if r["scene"] == DEVELOPMENT_SCENE]
    # The ablations' rows are the validation set's (one run of the switches as they are).
    methods = [m for m in method_order({r["method"] for r in rows}) if not m.startswith("ours-")]
    return "\n".join([means_table("development", rows, methods,
                                  ("psnr", "flip", "temporal_error")),
                      "", source("development", ["summary.csv"])])


def b_validation():
    rows = read_csv("validation", "summary.csv")
    methods = present(rows, ["taa", "svgf", "ours", "rae", "oidn", "oidn-aux"])
    return "\n".join([
        per_scene_table(rows, methods),
        "",
        means_table("validation", rows, None, ("psnr", "flip", "temporal_error")),
        "",
        source("validation", ["summary.csv"]),
    ])


def b_validation_frames():
    """Per validation scene, ours' worst frame after frame 4 against the best single-frame
    method (oidn, oidn-aux, rae) and against the better of svgf and taa."""
    by = frames_by_scene(read_csv("validation", "metrics.csv"))
    body = []
    for sc, frames in sorted(by.items()):
        single = worst_margin(frames, SINGLE_FRAME)
        lag = worst_margin(frames, ["svgf", "taa"])
        below = below_best(frames, SINGLE_FRAME)[0]
        body.append([sc,
                     "" if single is None else f"{single[0]:+.2f} (frame {single[1]})",
                     str(below),
                     "" if lag is None else f"{lag[0]:+.2f} (frame {lag[1]})"])
    return "\n".join([
        "Per scene, after frame 4: `ours`' lowest margin (dB of PSNR) against the best of "
        "`oidn`, `oidn-aux` and `rae` in the same frame, how many frames it is more than "
        "1 dB below that best, and its lowest margin against the better of `svgf` and `taa`:",
        "",
        table(["scene", "ours − best single-frame, worst frame", "frames > 1 dB below",
               "ours − max(svgf, taa), worst frame"], body),
        "",
        source("validation", ["metrics.csv"]),
    ])


def b_validation_line():
    """README's sentence on young history in the validation set, frame by frame."""
    by = frames_by_scene(read_csv("validation", "metrics.csv"))
    counts = [below_best(frames, SINGLE_FRAME) for frames in by.values()]
    below, n = sum(c[0] for c in counts), sum(c[1] for c in counts)
    worst = [w for w in (worst_margin(f, SINGLE_FRAME) for f in by.values()) if w]
    low = min(worst, key=lambda w: w[0]) if worst else None
    return (
        f"After frame 4, `ours` is more than 1 dB below the best single-frame method "
        f"(`oidn`, `oidn-aux`, `rae`) in {below} of the validation set's {n} frames"
        + (f" (at worst {low[0]:+.2f} dB)" if low else "") +
        ": where its history is young, after a change the gradients cannot fully measure. "
        "Per scene: [the results](docs/src/results.md#the-validation-set)."
    )


def b_validation_1spp():
    """ours at 1 spp against oidn-aux (and ours) at 2 spp, per scene and on the mean."""
    two = {(r["scene"], r["method"]): r for r in read_csv("validation", "summary.csv")}
    one = {(r["scene"], r["method"]): r for r in read_csv("validation", "spp1/summary.csv")}
    scenes = sorted({sc for sc, m in one if m == "ours"})
    body = []
    cols = {"ours 1 spp": [], "oidn-aux 2 spp": [], "ours 2 spp": []}
    for sc in scenes:
        cells = [sc]
        for name, src, m in (("ours 1 spp", one, "ours"), ("oidn-aux 2 spp", two, "oidn-aux"),
                             ("ours 2 spp", two, "ours")):
            r = src.get((sc, m))
            v = (num(r["psnr"]), num(r["flip"])) if r else (None, None)
            cols[name].append(v)
            cells.append(f"{fmt(v[0], 2)} / {fmt(v[1], 4)}")
        body.append(cells)
    body.append(["**mean**"] + [
        f"{fmt(mean(v[0] for v in cols[n]), 2)} / {fmt(mean(v[1] for v in cols[n]), 4)}"
        for n in cols])
    return "\n".join([
        "PSNR dB / FLIP per scene: `ours` fed 1 sample per pixel per frame, against "
        "`oidn-aux` and `ours` fed 2 (the same references):",
        "",
        table(["scene", "`ours`, 1 spp", "`oidn-aux`, 2 spp", "`ours`, 2 spp"], body),
        "",
        source("validation", ["spp1/summary.csv", "summary.csv"]),
    ])


def b_static():
    rows = read_csv("static", "metrics.csv")
    summ = read_csv("static", "summary.csv")
    last = max(int(r["frame"]) for r in rows)
    methods = present(summ, ["ours", "svgf", "taa", "oidn", "oidn-aux"])
    body = []
    for s in scenes_of(rows):
        vals = {r["method"]: num(r["psnr"]) for r in rows
                if r["scene"] == s and int(r["frame"]) == last}
        b = best({x: vals.get(x) for x in methods if x in COMPARED}, True)
        body.append([s] + [bold_if(fmt(vals.get(x), 2),
                                   x in COMPARED and fmt(vals.get(x), 2) == fmt(b, 2))
                           for x in methods])
    # ours only improves: its mean over the second half against the first's.
    halves = []
    mid = (last + 1) // 2
    for s in scenes_of(rows):
        ours = {int(r["frame"]): num(r["psnr"]) for r in rows
                if r["scene"] == s and r["method"] == "ours"}
        early = mean(ours.get(f) for f in range(8, mid))
        late = mean(ours.get(f) for f in range(mid, last + 1))
        worst = 0.0
        top = -1e9
        for f in range(8, last + 1):
            v = ours.get(f)
            if v is None:
                continue
            top = max(top, v)
            worst = min(worst, v - top)
        at8 = {r["method"]: num(r["psnr"]) for r in rows
               if r["scene"] == s and int(r["frame"]) == 8}
        lead8 = (f"{at8['ours'] - at8['oidn-aux']:+.2f}"
                 if at8.get("ours") is not None and at8.get("oidn-aux") is not None else "")
        halves.append([s, fmt(early, 2), fmt(late, 2), f"{worst:.2f}", lead8])
    return "\n".join([
        f"PSNR (dB) at frame {last}:",
        "",
        table(["scene"] + [f"`{x}`" for x in methods], body),
        "",
        "`ours` over time:",
        "",
        table(["scene", f"mean PSNR, frames 8–{mid - 1}", f"frames {mid}–{last}",
               "worst frame after 8 against the best so far, dB",
               "frame 8: `ours` − `oidn-aux`, dB"], halves),
        "",
        source("static", ["metrics.csv", "summary.csv"]),
    ])


def order_table(sets):
    spps = sorted(sets)
    body = []
    for scene in scenes_of(sets[spps[0]]):
        def val(spp, m):
            for r in sets[spp]:
                if r["scene"] == scene and r["method"] == m:
                    return num(r["psnr"])
            return None

        def diff(a, b):
            return " / ".join(
                f"{val(x, a) - val(x, b):+.2f}" if val(x, a) is not None and val(x, b) is not None
                else "" for x in spps)

        body.append([scene, " / ".join(fmt(val(x, "none"), 1) for x in spps),
                     diff("wrls-paper", "svgf"), diff("svgf", "taa")])
    label = " / ".join(str(x) for x in spps)
    return table(["scene", f"input dB at {label} spp", "`wrls-paper` − `svgf`",
                  "`svgf` − `taa`"], body)


def b_paper():
    sets = {}
    for spp in (1, 2, 4):
        try:
            sets[spp] = read_csv("paper", f"spp{spp}", "summary.csv")
        except Missing:
            pass
    if 2 not in sets:
        raise Missing("assets/results/paper/spp2/summary.csv")
    methods = present(sets[2], ["none", "taa", "svgf", "wrls-paper", "rls-paper", "wrls",
                                "rls", "rae", "oidn", "ours"])
    ms = {spp: means(r) for spp, r in sets.items()}
    body = []
    for x in methods:
        body.append([f"`{x}`"] + [fmt(ms[s].get(x, {}).get("psnr"), 2) for s in sorted(sets)]
                    + [fmt(ms[2][x]["flip"], 4)])
    return "\n".join([
        "Mean PSNR (dB) over the five scenes at each noise level, and FLIP at 2 spp:",
        "",
        table(["method"] + [f"{s} spp" for s in sorted(sets)] + ["FLIP at 2 spp"], body),
        "",
        "PSNR per scene at 2 spp:",
        "",
        per_scene_table(sets[2], methods),
        "",
        "Where the paper's order holds, per scene and noise level (differences of mean "
        "PSNR, dB; the paper reports wRLS above SVGF above TAA):",
        "",
        order_table(sets),
        "",
        source("paper", [f"spp{s}/summary.csv" for s in sorted(sets)]),
    ])


def b_cost():
    body = []
    sources = []
    for name in ("mri-point-light", "phantom-orbit"):
        try:
            prof = read_json("cost", f"{name}.json")
        except Missing:
            continue
        sources.append(f"{name}.json")
        rows = {m["method"]: m for m in prof.get("methods", [])}
        passes = {p["pass"]: num(p.get("mean_ms")) for p in prof["passes"]}
        if "ours" in rows and "svgf" in rows:
            o, s_ = rows["ours"], rows["svgf"]
            body.append([prof.get("scene", name),
                         fmt(num(o["own_ms"]), 1), fmt(num(o["cost_ms"]), 1),
                         fmt(num(s_["own_ms"]), 1), fmt(num(s_["cost_ms"]), 1),
                         f"{num(o['own_ms']) / num(s_['own_ms']):.2f}×",
                         f"{num(o['cost_ms']) / num(s_['cost_ms']):.2f}×",
                         f"{num(o['dispatches']):.1f} / {num(s_['dispatches']):.1f}",
                         f"{num(o['bytes_per_pixel']):.0f} / {num(s_['bytes_per_pixel']):.0f}",
                         fmt(passes.get("path_trace"), 1)])
    if not body:
        raise Missing("assets/results/cost/*.json (with the profile's per-method rows)")
    return "\n".join([
        "Mean ms per frame at 256×256. *Own* is a method's own passes; *with features* adds "
        "the passes it needs and would run alone (the surface features and the guides "
        "composited along the ray, which both read, rendered by one march); dispatches and declared bytes per "
        "pixel per frame count the same passes (a pass run only when the scene changed "
        "counts by the share of frames it ran in). The path trace, which every method "
        "shares, beside them:",
        "",
        table(["scene", "`ours` own", "`ours` with features", "`svgf` own",
               "`svgf` with features", "ours / svgf, own", "ours / svgf, with features",
               "dispatches ours / svgf", "bytes per pixel ours / svgf", "`path_trace`"], body),
        "",
        source("cost", sources),
    ])


def b_rae():
    rows = read_csv("rae", "summary.csv")
    methods = present(rows, ["svgf", "ours", "rae-phantom", "rae-mri"])
    body = []
    for sc in scenes_of(rows):
        vals = {r["method"]: r for r in rows if r["scene"] == sc}
        bp = best({x: num(vals[x]["psnr"]) for x in methods if x in vals}, True)
        bf = best({x: num(vals[x]["flip"]) for x in methods if x in vals}, False)
        cells = [sc]
        for x in methods:
            p, f = num(vals[x]["psnr"]), num(vals[x]["flip"])
            cells.append(f"{bold_if(fmt(p, 2), fmt(p, 2) == fmt(bp, 2))} / "
                         f"{bold_if(fmt(f, 3), fmt(f, 3) == fmt(bf, 3))}")
        body.append(cells)
    return "\n".join([
        "PSNR / FLIP per scene (`cloud` is in neither network's training data):",
        "",
        table(["scene"] + [f"`{x}`" for x in methods], body),
        "",
        "Means over the scenes:",
        "",
        means_table("rae", rows, None, ("psnr", "flip", "temporal_error", "gpu_ms")),
        "",
        source("rae", ["summary.csv"]),
    ])


def b_fuzz():
    rows = read_csv("fuzz", "runs.csv")
    body = []
    for r in rows:
        body.append([f"`{r['target']}`", f"{int(r['execs']):,}", r["crashes"], r["hangs"],
                     r["ooms"], fmt(num(r["seconds"]), 0), f"{num(r['exec_per_s']):,.0f}",
                     fmt(num(r["peak_rss_mb"]), 0), r["commit"][:7], r["date"][:10]])
    machines = sorted({r["machine"] for r in rows})
    return "\n".join([
        table(["target", "executions", "crashes", "hangs", "out of memory", "s", "exec/s",
               "peak RSS MB", "commit", "date"], body),
        "",
        "Source: `assets/results/fuzz/runs.csv` (with each run's command); "
        + "; ".join(f"machine: {m}" for m in machines) + ".",
    ])


def b_rae_training():
    import glob
    files = sorted(glob.glob(os.path.join(ROOT, "assets", "rae", "*.json")))
    if not files:
        raise Missing("assets/rae/*.json")
    body = []
    for f in files:
        with open(f) as fh:
            m = json.load(fh)
        if not m.get("trained"):
            continue
        pre = m.get("initialised_from") or {}
        pt = pre.get("training") or {}
        t = m["training"]
        curve = [c["validation"] for c in m.get("validation_curve", []) if c.get("validation") is not None]
        bestv = min(curve) if curve else None
        start = curve[0] if curve else None
        data = m["training_data"]
        body.append([
            f"`{m['name']}`", f"{m['parameters']:,}",
            (f"{pt['iterations']} it. in {pt['seconds']:.0f} s, {pt.get('crop')}² crops"
             if pt else ""),
            f"{t['iterations']} it. in {t['seconds']:.0f} s, {t.get('crop')}² crops",
            f"{fmt(start, 4)} → {fmt(bestv, 4)}",
            f"{fmt(t.get('final_validation_parts_l1_log_temporal', [None])[0], 4)} / "
            f"{fmt(t.get('validation_l1_of_noisy_input'), 4)}",
            f"{data['clips_train']} + {data['clips_validation']}",
        ])
    return "\n".join([
        table(["network", "parameters", "pre-training", "fine-tuning",
               "validation loss, start → best", "validation L1 (log space), network / noisy input",
               "clips: training + validation"], body),
        "",
        "Source: `assets/rae/<net>.json`, the manifests `tools/rae/train.py` writes beside "
        "the weights (settings, data hashes and the whole validation curve of each stage).",
    ])


def b_viewer():
    rows = read_csv("viewer", "viewer.csv")
    body = [[r["size"], f"`{r['denoiser']}`", r["device"], r["render_fps"], r["shown_fps"],
             f"{r['latency_ms_median']} / {r['latency_ms_max']}",
             f"{num(r['latency_frames_median']):.1f} / {num(r['latency_frames_max']):.1f}",
             r["drags"]] for r in rows]
    r0 = rows[0]
    lines = [
        table(["view", "shown", "device", "frames rendered / s", "frames shown / s",
               "drag → first frame showing it, ms (median / max)", "in frames (median / max)",
               "drags"], body),
        "",
        f"Measured in a real JupyterLab driven by headless Chromium by `{r0['command']}` at "
        f"commit {r0['commit']} ({r0['date']}) on {r0['machine']}. Source: "
        "`assets/results/viewer/viewer.csv`.",
    ]
    return "\n".join(lines)


def b_viewer_line():
    """README's sentence on the viewer: its first row's frame rate and drag latency."""
    r = read_csv("viewer", "viewer.csv")[0]
    return (
        f"At {r['size'].replace('x', '×')} on {r['device']}, {r['machine']}: it renders "
        f"{r['render_fps']} frames/s and shows {r['shown_fps']}; a drag shows in the cell "
        f"{r['latency_ms_median']} ms later (median, {num(r['latency_frames_median']):.1f} "
        f"frames), measured in JupyterLab by `{r['command'].split(' --out')[0]}`."
    )


def b_soak():
    rows = read_csv("soak", "soak.csv")
    body = [[r["session"], f"{int(r['frames']):,}", r["seconds"],
             f"{r['rss_warm_mib']} → {r['rss_end_mib']} ({100 * num(r['rss_growth']):+.1f} %)",
             f"{r['gpu_allocated_warm_mib']} → {r['gpu_allocated_end_mib']}",
             r["validation_messages"], "yes" if r["passed"] == "True" else "**no**"] for r in rows]
    r0 = rows[0]
    return "\n".join([
        table(["session", "frames", "s", "resident MiB, after warm-up → end", "device MiB allocated",
               "validation messages", "holds"], body),
        "",
        f"Made by `{r0['command']}` at commit {r0['commit']} ({r0['date']}) on {r0['machine']}. "
        "Source: `assets/results/soak/soak.csv`.",
    ])


# What the blocks of the scenes shown by kind (cuts, channels and time, label maps) read:
# each scene's figures are its set's run's.
GROUP_FILES = [f"{run}/{f}" for run in ("mechanisms", "validation")
               for f in ("summary.csv", "metrics.csv", "meta.json")]

BLOCKS = {
    "headline": (b_headline, ["validation/summary.csv", "validation/meta.json",
                              "../scenes/validation/*.toml"]),
    "suite-means": (b_suite_means, ["suite/summary.csv"]),
    "suite-scenes": (b_suite_scenes, ["suite/summary.csv"]),
    "ablations": (b_ablations, ["validation/summary.csv"]),
    "demo": (b_demo, ["demo/summary.csv"]),
    "setup-times": (b_setup_times, ["setup-times/steps.csv", "setup-times/meta.json"]),
    "development": (b_development, ["development/summary.csv"]),
    "validation": (b_validation, ["validation/summary.csv"]),
    "validation-frames": (b_validation_frames, ["validation/metrics.csv"]),
    "validation-line": (b_validation_line, ["validation/metrics.csv"]),
    "validation-1spp": (b_validation_1spp, ["validation/spp1/summary.csv",
                                            "validation/summary.csv"]),
    "static": (b_static, ["static/metrics.csv", "static/summary.csv"]),
    "paper": (b_paper, ["paper/spp{1,2,4}/summary.csv"]),
    "cost": (b_cost, ["cost/*.json"]),
    "rae": (b_rae, ["rae/summary.csv"]),
    "fuzz": (b_fuzz, ["fuzz/runs.csv"]),
    "rae-training": (b_rae_training, ["../rae/*.json"]),
    "viewer": (b_viewer, ["viewer/viewer.csv"]),
    "viewer-line": (b_viewer_line, ["viewer/viewer.csv"]),
    "soak": (b_soak, ["soak/soak.csv"]),
    "cuts": (b_cuts, GROUP_FILES),
    "media": (b_media, GROUP_FILES),
    "media-line": (b_media_line, GROUP_FILES),
    "cuts-line": (b_cuts_line, GROUP_FILES),
    "cut-cost": (b_cut_cost, ["cut-cost/profile.csv"]),
    "channels-cost": (b_channels_cost, ["channels-cost/profile.csv"]),
    "labels": (b_labels, GROUP_FILES),
    "labels-line": (b_labels_line, GROUP_FILES),
    "labels-cost": (b_labels_cost, ["labels-cost/profile.csv"]),
    "interaction": (b_interaction, ["interaction/metrics.csv", "interaction/meta.json"]),
    "interaction-curves": (b_interaction_curves, ["interaction/metrics.csv",
                                                  "interaction/meta.json"]),
    "speed-accuracy": (b_speed_accuracy, ["validation/{,spp1/,spp4/}{summary,metrics,oidn_ms}.csv"]),
    "speed-accuracy-line": (b_speed_accuracy_line,
                            ["validation/{,spp1/,spp4/}{summary,metrics,oidn_ms}.csv"]),
    "mechanisms": (b_mechanisms, ["mechanisms/*.csv", "mechanisms/meta.json"]),
    "development-cost": (b_development_cost, ["mechanisms/metrics.csv", "mechanisms/meta.json"]),
    "experiments-prior": (b_experiments_prior, ["experiments-prior/*.csv"]),
    "experiments-strata": (b_experiments_strata, ["experiments-strata/*.csv",
                                                  "experiments-strata/profile-*.json",
                                                  "experiments-prior/base-development.csv",
                                                  "experiments-prior/rivals-development.csv",
                                                  "experiments-prior/base-validation.csv"]),
    "experiments-young": (b_experiments_young, ["experiments-young/*.csv",
                                                "experiments-young/meta.json",
                                                "mechanisms/metrics.csv"]),
    "experiments-guided": (b_experiments_guided, ["experiments-guided/*.csv",
                                                  "experiments-guided/*.json",
                                                  "experiments-young/base.csv",
                                                  "mechanisms/metrics.csv"]),
    "experiments-learned": (b_experiments_learned, ["experiments-learned/*.csv",
                                                    "experiments-learned/meta.json"]),
    "experiments-young-net": (b_experiments_young_net, ["experiments-young-net/*.csv",
                                                        "experiments-young-net/meta.json",
                                                        "experiments-young/base.csv",
                                                        "mechanisms/metrics.csv"]),
    "experiments-motion": (b_experiments_motion, ["experiments-motion/*.csv",
                                                  "experiments-motion/meta.json",
                                                  "mechanisms/no-clip.csv",
                                                  "mechanisms/metrics.csv"]),
}


def render(text, where):
    errors = []

    def sub(m):
        name = m.group("name")
        if name not in BLOCKS:
            errors.append(f"{where}: unknown block results:{name}")
            return m.group(0)
        try:
            body = BLOCKS[name][0]()
        except Missing as e:
            errors.append(f"{where}: block results:{name} needs {e}")
            return m.group(0)
        return m.group(1) + body.rstrip("\n") + "\n" + m.group(4)

    return BLOCK.sub(sub, text), errors


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="fail if a page is stale")
    ap.add_argument("--list", action="store_true", help="list the blocks")
    args = ap.parse_args()
    if args.list:
        for k, (_, files) in BLOCKS.items():
            print(f"{k}: assets/results/{', assets/results/'.join(files)}")
        return 0
    stale, errors, found = [], [], 0
    for rel in PAGES:
        p = os.path.join(ROOT, rel)
        with open(p, encoding="utf-8") as f:
            text = f.read()
        found += len(BLOCK.findall(text))
        new, errs = render(text, rel)
        errors += errs
        if new != text:
            if args.check:
                stale += [m.group("name") for m, n in zip(BLOCK.finditer(text), BLOCK.finditer(new))
                          if m.group(0) != n.group(0)]
                print(f"results: {rel} is stale against its CSVs "
                      f"(blocks: {', '.join(sorted(set(stale)))}); run tools/results.py",
                      file=sys.stderr)
            else:
                with open(p, "w", encoding="utf-8") as f:
                    f.write(new)
                print(f"results: wrote {rel}")
    for rel, draw in FIGURES.items():
        p = os.path.join(ROOT, rel)
        try:
            svg = draw()
        except Missing as e:
            errors.append(f"{rel} needs {e}")
            continue
        old = open(p, encoding="utf-8").read() if os.path.exists(p) else None
        if old != svg:
            if args.check:
                stale.append(rel)
                print(f"results: {rel} is stale against its CSVs; run tools/results.py",
                      file=sys.stderr)
            else:
                with open(p, "w", encoding="utf-8") as f:
                    f.write(svg)
                print(f"results: wrote {rel}")
    for e in errors:
        print(f"results: {e}", file=sys.stderr)
    if errors or stale:
        return 1
    print(f"results: {found} blocks in {len(PAGES)} pages and {len(FIGURES)} figures "
          f"{'up to date' if args.check else 'rendered'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
