"""The results blocks beside the validation set's: the scenes shown by kind (cuts,
channels and time, label maps; each scene from its set's run), the interaction set, ours'
mechanisms switched off one at a time, what a cut or a label map costs, and the time of
each step of the two commands on a fresh machine (`tools/results.py` lists every
block)."""

from results_io import (
    Missing,
    read_csv,
    read_json,
    num,
    fmt,
    mean,
    scenes_of,
    best,
    table,
    bold_if,
    source,
    present,
    frames_by_scene,
    worst_margin,
    below_best,
    gap_at,
    SINGLE_FRAME,
    own_ms,
)


def b_interaction():
    """The interaction set with the cut scenes: per scene, ours against the best
    single-frame method (oidn, oidn-aux, rae) at frame 0, at frame 1 and from frame 2 on,
    and the means over the scenes of the first two."""
    by = frames_by_scene(read_csv("interaction", "metrics.csv"))
    body, first = [], {0: [], 1: []}
    for sc, frames in sorted(by.items()):
        cells = [sc]
        for f in (0, 1):
            m = gap_at(frames, f)
            if m is not None:
                first[f].append(m)
            cells.append("" if m is None else f"{m:+.2f}")
        worst = worst_margin(frames, SINGLE_FRAME, after=1)
        below = below_best(frames, SINGLE_FRAME, after=1)
        cells += ["" if worst is None else f"{worst[0]:+.2f} (frame {worst[1]})",
                  f"{below[0]} of {below[1]}"]
        body.append(cells)
    mean = {f: sum(v) / len(v) for f, v in first.items() if v}
    return "\n".join([
        "Per scene, 128×128, 256-spp references: `ours` minus the best of `oidn`, `oidn-aux` "
        "and `rae` in the same frame (dB of PSNR) at frame 0 (a cold open) and frame 1; "
        "from frame 2 on, its lowest margin and the frames more than 1 dB below. Means over "
        "the scenes: frame 0 " + (f"{mean[0]:+.2f}" if 0 in mean else "–") + " dB, frame 1 "
        + (f"{mean[1]:+.2f}" if 1 in mean else "–") + " dB.",
        "",
        table(["scene", "frame 0", "frame 1", "worst from frame 2", "frames > 1 dB below"], body),
        "",
        source("interaction", ["metrics.csv"]),
    ])


# The scenes of each kind the results page shows together, in the order shown. Each
# scene's figures come from the one run that judges its set: the development set's
# (`tools/measure.sh mechanisms`) or the validation set's (`tools/measure.sh validation`),
# so a scene has one number wherever it appears.
GROUPS = {
    "cuts": ["dev/mri-clip-sweep", "dev/phantom-crop-shrink", "dev/phantom-clip-toggle",
             "val/cloud-oblique-clip-light"],
    "media": ["dev/shell-beat-still", "dev/shell-beat-orbit", "dev/microscopy-orbit",
              "dev/mri-statmap-light", "val/shell-twobeat-rim",
              "val/microscopy-tif-marker-light", "val/statmap-opaque-orbit"],
    "labels": ["dev/phantom-labels-skull-orbit", "dev/mri-labels-fade",
               "val/mri-labels-solid-orbit"],
}
# The run that holds each set's scenes, by the scene name's prefix, and what it is.
RUNS = {"dev/": "mechanisms", "val/": "validation"}
RUN_NAMES = {"mechanisms": "the development set's run", "validation": "the validation set's run"}
# The results page's section that shows each run's own source line.
RUN_SECTIONS = {"mechanisms": ("every mechanism", "every-mechanism-on-the-development-set"),
                "validation": ("the validation set", "the-validation-set")}


def runs_of(kind):
    """The runs that hold a group's scenes, in the order of their first scene."""
    out = []
    for sc in GROUPS[kind]:
        run = RUNS[sc[:4]]
        if run not in out:
            out.append(run)
    return out


def group_rows(kind, name):
    """A group's rows of each run's `name` (summary.csv or metrics.csv), in the group's
    scene order. A scene no run holds is an error naming it."""
    rows = [r for run in runs_of(kind) for r in read_csv(run, name)]
    held = set(scenes_of(rows))
    missing = [sc for sc in GROUPS[kind] if sc not in held]
    if missing:
        raise Missing(f"the scene(s) {', '.join(missing)} in {', '.join(runs_of(kind))}")
    order = {sc: i for i, sc in enumerate(GROUPS[kind])}
    return sorted((r for r in rows if r["scene"] in order), key=lambda r: order[r["scene"]])


def group_frames(kind):
    """{scene: {frame: {method: psnr}}} of a group, in its scene order."""
    return frames_by_scene(group_rows(kind, "metrics.csv"))


def group_source(kind):
    """Where a group's figures come from: each run's files, commit and date, and the
    section whose source line gives its command and machine."""
    parts = []
    for run in runs_of(kind):
        meta = read_json(run, "meta.json")
        parts.append(f"{RUN_NAMES[run]} (`assets/results/{run}/summary.csv`, `metrics.csv`; "
                     f"commit {meta['commit']}, {meta['date']}; its command and machine: "
                     f"[{RUN_SECTIONS[run][0]}](#{RUN_SECTIONS[run][1]}))")
    return "Sources: " + " and ".join(parts) + "."


def cut_frames(frames):
    """Per scene: the closest frame after frame 4 of ours to the better of svgf and taa,
    as (margin dB, frame)."""
    return {sc: worst_margin(f, ["svgf", "taa"]) for sc, f in frames.items()}


def group_table(kind):
    """Mean PSNR per scene of a group (128×128, 48 frames, 256-spp references), with ours'
    closest frame after frame 4 to the better of svgf and taa and ours against oidn-aux on
    the mean; the per-frame chart of ours, oidn-aux and svgf; the sources."""
    rows = group_rows(kind, "summary.csv")
    methods = present(rows, ["none", "taa", "svgf", "oidn", "oidn-aux", "ours"])
    worst = cut_frames(group_frames(kind))
    body = []
    for sc in scenes_of(rows):
        v = {r["method"]: r for r in rows if r["scene"] == sc}
        bp = best({x: num(v[x]["psnr"]) for x in methods if x in v}, True)
        cells = [sc] + [bold_if(fmt(num(v[x]["psnr"]), 2), fmt(num(v[x]["psnr"]), 2) == fmt(bp, 2))
                        for x in methods]
        w = worst.get(sc)
        cells.append(f"{w[0]:+.2f} (frame {w[1]})" if w else "")
        if "oidn-aux" in v:
            cells.append(f"{num(v['ours']['psnr']) - num(v['oidn-aux']['psnr']):+.2f}")
        body.append(cells)
    header = ["scene"] + [f"`{x}`" for x in methods] + [
        "ours − max(svgf, taa), closest frame after 4", "ours − oidn-aux, mean"]
    return "\n".join([
        "Mean PSNR (dB) per scene, 128×128, 48 frames, 256-spp references, each scene from "
        "its set's run:",
        "",
        table(header, body),
        "",
        f"![Per-frame PSNR of svgf, oidn-aux and ours on each scene](../../assets/results/curves/{kind}.svg)",
        "",
        group_source(kind),
    ])


def group_line(kind, what):
    """README's sentence on a group: ours against oidn-aux per scene, and its closest
    frame to the better of svgf and taa after frame 4."""
    rows = group_rows(kind, "summary.csv")
    worst = cut_frames(group_frames(kind))
    psnr = {(r["scene"], r["method"]): num(r["psnr"]) for r in rows}
    pairs = ", ".join(f"`{sc}` {fmt(psnr[(sc, 'ours')], 2)} / {fmt(psnr.get((sc, 'oidn-aux')), 2)}"
                      for sc in scenes_of(rows))
    closest = min((w for w in worst.values() if w), key=lambda w: w[0])
    versus = (f"is above the better of `svgf` and `taa` on every frame (closest {closest[0]:+.2f} dB)"
              if closest[0] >= 0 else
              f"falls below the better of `svgf` and `taa` (at worst {closest[0]:+.2f} dB, frame {closest[1]})")
    commits = {run: read_json(run, "meta.json")["commit"] for run in runs_of(kind)}
    runs = " and ".join(f"{RUN_NAMES[run]}" for run in commits)
    made = (f"commit {next(iter(commits.values()))} ({runs})" if len(set(commits.values())) == 1
            else "; ".join(f"{RUN_NAMES[run]} at commit {c}" for run, c in commits.items()))
    sources = ", ".join(f"`assets/results/{run}/`" for run in commits)
    return (
        f"Mean PSNR (dB) of `ours` / `oidn-aux` on {what}, 128×128, 48 frames, 256-spp "
        f"references: {pairs}. After frame 4, `ours` {versus}. From the runs that judge "
        f"each set, {made}; sources: {sources}."
    )


def b_cuts():
    return group_table("cuts")


def b_cuts_line():
    return group_line("cuts", "the cut scenes")


def b_media():
    """The channel and time scenes: several fields in one medium, 4D series played."""
    return group_table("media")


def b_media_line():
    return group_line("media", "the channel and time scenes")


def b_labels():
    """The label-map scenes: segmentations hidden, faded and shown as solid tissue."""
    return group_table("labels")


def b_labels_line():
    return group_line("labels", "the label-map scenes")


def b_labels_cost():
    """The path tracer's cost with a label map shown and with a label hidden, against the
    same view without one, run by run."""
    rows = read_csv("labels-cost", "profile.csv")
    def by_run(labels):
        return {(r["scene"], r["run"]): num(r["path_trace_ms"]) for r in rows
                if r["labels"] == labels}

    base, shown = by_run("no label map"), by_run("every label shown (tint)")
    # A view whose hidden tissue is also removed from the data: "X hidden" beside "X
    # removed from the data (no label map)" and "X removed from the data, every label
    # shown" (the same tissue through the label path).
    def removed(suffix):
        return {(r["scene"], r["run"], r["labels"][:-len(suffix)]): num(r["path_trace_ms"])
                for r in rows if r["labels"].endswith(suffix)}

    data = removed(" removed from the data (no label map)")
    same = removed(" removed from the data, every label shown")

    def ratio(r, to):
        return f"{num(r['path_trace_ms']) / to[(r['scene'], r['run'])]:.2f}×"

    def to(control):
        def cell(r):
            key = (r["scene"], r["run"], r["labels"].removesuffix(" hidden"))
            return f"{num(r['path_trace_ms']) / control[key]:.2f}×" if key in control else ""
        return cell

    to_data, to_same = to(data), to(same)
    body = [[r["scene"], r["labels"], r["run"], fmt(num(r["path_trace_ms"]), 1),
             ratio(r, base), ratio(r, shown) if r["labels"] != "no label map" else "",
             to_data(r), to_same(r), fmt(num(r["frame_ms"]), 1)]
            for r in rows]
    return "\n".join([
        "Median GPU ms per frame of the path-tracing pass and of the whole frame at 256×256, "
        "the same view without a label map, with every label shown, and with labels hidden "
        "from the outside in until every one is, runs alternating (× is to the same scene's "
        "run without a label map, or with every label shown; × data is to the tissue the "
        "view shows with the hidden tissue removed from the data and no label map, × same "
        "to that data with the label map and every label shown):",
        "",
        table(["scene", "labels", "run", "`path_trace`", "× none", "× shown", "× data",
               "× same", "frame"], body),
        "",
        source("labels-cost", ["profile.csv"]),
    ])


def b_channels_cost():
    """The path tracer's cost with 2 and 4 channels against one, run by run, and the
    mean ratio of each layout over the runs."""
    rows = read_csv("channels-cost", "profile.csv")
    one = {r["run"]: num(r["path_trace_ms"]) for r in rows if r["channels"] == "1"}
    ratio = lambda r: num(r["path_trace_ms"]) / one[r["run"]]
    body = [[r["scene"], r["channels"], r["layout"], r["run"], fmt(num(r["path_trace_ms"]), 1),
             f"{ratio(r):.2f}×", fmt(num(r["frame_ms"]), 1)] for r in rows]
    layouts = list(dict.fromkeys((r["channels"], r["layout"]) for r in rows if r["channels"] != "1"))
    means = []
    for n, layout in layouts:
        rs = [ratio(r) for r in rows if (r["channels"], r["layout"]) == (n, layout)]
        means.append([n, layout, f"{sum(rs) / len(rs):.2f}×", f"{max(rs):.2f}×"])
    return "\n".join([
        "Median GPU ms per frame of the path-tracing pass and of the whole frame at 256×256, "
        "the same view as one field and as 2 and 4 channels that make the same medium: "
        "*hidden*, every channel but the first hidden; *split*, every channel shown under the "
        "TF with its opacity divided among them. Runs alternate; × is to the same run's one "
        "channel:",
        "",
        table(["channels", "layout", "mean × one", "largest × one"], means),
        "",
        table(["scene", "channels", "layout", "run", "`path_trace`", "× one", "frame"], body),
        "",
        source("channels-cost", ["profile.csv"]),
    ])


def b_cut_cost():
    rows = read_csv("cut-cost", "profile.csv")
    body = [[r["scene"], r["cut"], r["run"], fmt(num(r["path_trace_ms"]), 1),
             fmt(num(r["frame_ms"]), 1)] for r in rows]
    return "\n".join([
        "Median GPU ms per frame of the path-tracing pass and of the whole frame, the same "
        "view with and without a plane that removes half the volume, runs alternating:",
        "",
        table(["scene", "cut", "run", "`path_trace`", "frame"], body),
        "",
        source("cut-cost", ["profile.csv"]),
    ])


def duration(s):
    """Seconds as `42 s` or `4 min 05 s`."""
    t = round(s)
    return f"{t} s" if t < 60 else f"{t // 60} min {t % 60:02d} s"


def busy_note(rows, busy=1.0):
    """The steps that started at a 1-minute load average of `busy` or more: other work
    shared the cores, so their wall times are longer than on an idle machine."""
    names = [", ".join(f"`{c}`" for c in r["step"].split(", ")) + f" ({r['what'].split(':')[0]})"
             for r in rows if num(r["load_start"]) >= busy]
    if not names:
        return ""
    return (f" The load average is the machine's; {' and '.join(names)} started at "
            f"{busy:g} or more: other work shared the cores, and the wall time is longer than on "
            "an idle machine.")


def b_setup_times():
    """The time of each step of tools/run.sh and tools/test.sh on a fresh machine, wall
    and CPU, with each command's total; a step that failed is named under the table."""
    rows = read_csv("setup-times", "steps.csv")
    meta = read_json("setup-times", "meta.json")
    body, notes = [], []
    for command in dict.fromkeys(r["command"] for r in rows):
        sel = [r for r in rows if r["command"] == command]
        for r in sel:
            step = ", ".join(f"`{c}`" for c in r["step"].split(", "))
            body.append([step, r["what"], duration(num(r["wall_s"])), duration(num(r["cpu_s"])),
                         f"{num(r['load_start']):.2f} → {num(r['load_end']):.2f}"])
            if r["note"]:
                notes.append(f"{step} ({r['what']}): {r['note']}.")
        body.append([f"**`{command}`, in all**", "",
                     f"**{duration(sum(num(r['wall_s']) for r in sel))}**",
                     f"**{duration(sum(num(r['cpu_s']) for r in sel))}**", ""])
    return "\n".join([
        table(["step", "what it does", "wall", "CPU (user + system)",
               "load average (1 min), start → end"], body),
        "",
        *([" ".join(notes), ""] if notes else []),
        f"Rust: {meta['rustc']}, from rustup, with an empty cargo registry. Wall time includes "
        "the downloads (Debian packages, crates, Python packages); CPU time is that of every "
        f"process of the step, summed over the {meta['nproc']} cores.{busy_note(rows)}",
        "",
        source("setup-times", ["steps.csv", "meta.json"]),
    ])


# Ours' mechanisms, each switched off alone: the run (a method of the mechanisms set's
# eval, or an override run of `overrides.csv`) and what it switches off.
MECHANISMS = [
    ("ours-no-gradient", "the temporal gradients (g = 1: no measured change)"),
    ("no-change-q", "the process noise of a measured change"),
    ("no-motion-q", "the process noise of a pixel that moved on screen"),
    ("ours-no-lag", "the pooled lag test's shift of the state"),
    ("no-jump", "the jump rule"),
    ("no-clip", "the outliers' redescending weight"),
    ("ours-no-prior", "the spatial prior's combination"),
    ("ours-no-atrous", "the à-trous (and with it the feedback)"),
    ("no-keep", "keeping converged estimates out of the prior and the à-trous"),
    ("ours-no-feedback", "the feedback into restarted states"),
    ("ours-no-young", "the young-pixel network on the first frame"),
]


def b_mechanisms():
    """Each of ours' mechanisms switched off alone on the development set: the mean
    PSNR, the mean gap to the best single-frame method at frames 0 and 1, the frames from
    2 on more than 1 dB below it, and whether the mechanism earns its place (switching it
    off costs at least 0.05 dB on the mean or on the gap at frame 0 or frame 1, adds a
    frame below, or raises the mean FLIP by 0.001 or more)."""
    metrics = read_csv("mechanisms", "metrics.csv")
    overrides = {r["run"]: r["override"] for r in read_csv("mechanisms", "overrides.csv")}
    rivals = [r for r in metrics if r["method"] in SINGLE_FRAME]

    def score(rows):
        rows = [dict(r, method="ours") for r in rows]
        frames = frames_by_scene(rows + rivals)
        gap = {f: mean(v[f]["ours"] - max(v[f][x] for x in SINGLE_FRAME if x in v[f])
                       for v in frames.values() if f in v) for f in (0, 1)}
        below = sum(below_best(v, SINGLE_FRAME, after=1)[0] for v in frames.values())
        return mean(num(r["psnr"]) for r in rows), mean(num(r["flip"]) for r in rows), gap, below

    def cells(psnr, flip, gap, below):
        return [fmt(psnr, 2), fmt(flip, 4), f"{gap[0]:+.2f}", f"{gap[1]:+.2f}", str(below)]

    base = score([r for r in metrics if r["method"] == "ours"])
    body = [["nothing (`ours`)", "", *cells(*base), "", ""]]
    for run, what in MECHANISMS:
        if run in overrides:
            rows, how = read_csv("mechanisms", f"{run}.csv"), f"`DVR_OURS={overrides[run]}`"
        else:
            rows, how = [r for r in metrics if r["method"] == run], f"`{run}`"
        if not rows:
            continue
        psnr, flip, gap, below = score(rows)
        cost = base[0] - psnr
        young = max(base[2][f] - gap[f] for f in (0, 1))
        earns = ("yes" if max(cost, young) >= 0.05 or below > base[3] or flip >= base[1] + 0.001
                 else "**no**")
        body.append([what, how, *cells(psnr, flip, gap, below), f"{cost:+.2f}", earns])
    n = len(frames_by_scene(metrics))
    return "\n".join([
        f"The development set ({n} scenes, 128×128, 48 frames, 256-spp references), `ours` "
        "with one mechanism switched off at a time, on the same noisy frames. The gaps are "
        "to the best of `oidn`, `oidn-aux` and `rae` in each frame, means over the scenes.",
        "",
        table(["switched off", "by", "PSNR dB", "FLIP", "gap at frame 0", "gap at frame 1",
               "frames from 2 on > 1 dB below", "ours − it, dB", "earns its place"], body),
        "",
        source("mechanisms", ["metrics.csv", "overrides.csv", "<run>.csv"]),
    ])


def b_development_cost():
    """Ours' and svgf's cost over the whole development set as `dvr eval` timed it: each
    frame's GPU ms less the path trace's (`none`), so each method's own passes and the
    features it needs, summed over every frame of every scene."""
    rows = read_csv("mechanisms", "metrics.csv")
    ms = own_ms(rows)

    def total(method, scene=None):
        return sum(v for k, v in ms[method].items() if scene is None or k[0] == scene)

    body = []
    for sc in scenes_of(rows):
        o, s, n = total("ours", sc), total("svgf", sc), sum(k[0] == sc for k in ms["none"])
        body.append([sc, fmt(o / n, 1), fmt(s / n, 1), f"{o / s:.2f}×"])
    o, s, n = total("ours"), total("svgf"), len(ms["none"])
    body.append(["**the set**", fmt(o / n, 1), fmt(s / n, 1), f"**{o / s:.2f}×**"])
    return "\n".join([
        "Mean GPU ms per frame of each method's passes and the features it needs (the "
        "frame's GPU ms in `dvr eval` less the path trace's), 128×128:",
        "",
        table(["scene", "`ours`", "`svgf`", "ours / svgf"], body),
        "",
        source("mechanisms", ["metrics.csv"]),
    ])
