"""The results blocks of the experiments on ours' variants: each run's scores against
the single-frame methods, and the profiles of the strata (`tools/results.py` lists every
block)."""

import re

from results_io import (
    read_csv,
    read_json,
    num,
    fmt,
    mean,
    table,
    frames_by_scene,
    below_best,
    gap_at,
    SINGLE_FRAME,
    own_ms,
)


def experiment_runs(folder, validation_base=True):
    """The table of an experiments section's runs of ours' variants: each run's mean PSNR
    and FLIP, its frames after frame 4 more than 1 dB below the best single-frame method,
    and its mean gap to that method over the scenes at frames 0 and 1.
    `folder/runs.csv` names each run (run, set, build, change, and optionally file: a CSV
    under assets/results another section keeps, such as a base run on the same code);
    the validation set's base is `experiments-prior/base-validation.csv`: ours' and the
    single-frame methods' rows of the validation run these experiments were set against
    (at 8d3f4b4, ours' code as at 2cb97d6), kept when the results' run moved on; the
    development set at 128² is set against the mechanisms run's single-frame rows."""
    base = read_csv("experiments-prior", "base-validation.csv")
    rivals = {"development": read_csv("experiments-prior", "rivals-development.csv"),
              "development at 128²": [r for r in read_csv("mechanisms", "metrics.csv")
                                      if r["method"] in SINGLE_FRAME],
              "validation": [r for r in base if r["method"] in SINGLE_FRAME]}
    base_val = [r for r in base if r["method"] == "ours"]
    runs = ([("ours as on main", "validation", "main (2cb97d6 code)", base_val)]
            if validation_base else [])
    runs += [(r["change"], r["set"], r["build"],
              read_csv(*(r.get("file") or f"{folder}/{r['run']}-{r['set']}.csv").split("/")))
             for r in read_csv(folder, "runs.csv")]
    body = []
    for change, set_, build, rows in sorted(runs, key=lambda r: r[1]):
        by_scene = {}
        for r in rows:
            by_scene.setdefault(r["scene"], []).append(num(r["psnr"]))
        frames = frames_by_scene(rows + rivals[set_])
        below = sum(below_best(f, SINGLE_FRAME)[0] for f in frames.values())
        first = [f"{g:+.2f}" if g is not None else "" for g in
                 (mean(gap_at(f, k) for f in frames.values()) for k in (0, 1))]
        body.append([change, set_, build,
                     fmt(mean(mean(v) for v in by_scene.values()), 3),
                     fmt(mean(num(r["flip"]) for r in rows), 4), str(below)] + first)
    return table(["change", "set", "build", "PSNR", "FLIP", "frames > 1 dB below",
                  "frame 0", "frame 1"], body)


def b_experiments_prior():
    """The prior's features, the gradient pools and the seed reuse (at 08369ce)."""
    meta = read_json("experiments-prior", "meta.json")
    return "\n".join([
        experiment_runs("experiments-prior"),
        "",
        f"Source: `assets/results/experiments-prior/` (`runs.csv`, each run's CSV, and "
        f"`base-validation.csv`, the validation run of 8d3f4b4), made by `{meta['command']}` from "
        f"commit {meta['commit']} ({meta['date']}) on {meta['machine']}.",
    ])


def profile_table(folder, pass_header, pass_name):
    """The profiles of `folder/profiles.csv` (change, files: two or more `dvr profile
    --json` runs of each, alternated): the mean ms of ours' passes whose whole name the
    regular expression `pass_name` matches (`ours.gradient` is not `ours.gradient_pool`),
    ours' cost with its features, svgf's, their ratio and ours' bytes per pixel per frame,
    each the mean of the runs."""
    def method(d, m):
        return next(x for x in d["methods"] if x["method"] == m)

    def passes(d):
        return sum(x["mean_ms"] for x in d["passes"] if re.fullmatch(pass_name, x["pass"]))

    body = []
    for r in read_csv(folder, "profiles.csv"):
        runs = [read_json(folder, f) for f in r["files"].split()]
        ours = mean(method(d, "ours")["cost_ms"] for d in runs)
        svgf = mean(method(d, "svgf")["cost_ms"] for d in runs)
        body.append([r["change"], runs[0]["scene"], str(len(runs)),
                     fmt(mean(passes(d) for d in runs), 1), fmt(ours, 1), fmt(svgf, 1),
                     fmt(ours / svgf, 2),
                     fmt(mean(method(d, "ours")["bytes_per_pixel"] for d in runs), 0)])
    return table(["change", "scene", "runs", pass_header, "ours ms (features counted)",
                  "svgf ms", "ours / svgf", "ours bytes per pixel"], body)


def b_experiments_strata():
    """The gradients' strata at full density (`DVR_OURS=stratum=1`) against the stratum
    on main: the runs' scores, then the profiles (two runs of each, alternated): ours'
    cost with its features, svgf's, their ratio, the gradient pass and ours' bytes per
    pixel per frame, each the mean of the runs."""
    meta = read_json("experiments-strata", "meta.json")
    return "\n".join([
        experiment_runs("experiments-strata"),
        "",
        profile_table("experiments-strata", "`ours.gradient` ms", r"ours\.gradient"),
        "",
        f"Source: `assets/results/experiments-strata/` (`runs.csv` and each run's CSV, "
        f"`profiles.csv` and the profiles it names), `assets/results/experiments-prior/` "
        f"(the development set's base run and its rivals, and the validation run of "
        f"8d3f4b4), made by `{meta['command']}` from commit "
        f"{meta['commit']} ({meta['date']}) on {meta['machine']}.",
    ])


def b_experiments_motion():
    """Process noise under camera motion (at 6b4e266): the resampling error and
    `motion_q`, on the development set at 128²."""
    meta = read_json("experiments-motion", "meta.json")
    body = []
    for r in read_csv("experiments-motion", "costs.csv"):
        ms = own_ms(read_csv("experiments-motion", r["file"]))
        o, s, n = sum(ms["ours"].values()), sum(ms["svgf"].values()), len(ms["none"])
        body.append([r["change"], fmt(o / n, 1), fmt(s / n, 1), f"{o / s:.2f}×"])
    return "\n".join([
        experiment_runs("experiments-motion", validation_base=False),
        "",
        "The cost over the whole development set, each run timing `none`, `svgf` and "
        "`ours` together: mean GPU ms per frame of each method's passes and the features "
        "it needs (the frame's GPU ms less the path trace's):",
        "",
        table(["ours", "`ours` ms", "`svgf` ms", "ours / svgf"], body),
        "",
        f"Source: `assets/results/experiments-motion/` (`runs.csv`, each run's CSV, "
        f"`costs.csv` and the timed runs it names; the base is "
        f"`assets/results/mechanisms/no-clip.csv`, ours' code of 387a560) and the "
        f"mechanisms run's single-frame rows, made by `{meta['command']}` from commit "
        f"{meta['commit']} ({meta['date']}) on {meta['machine']}.",
    ])


def psnr_by(file, key):
    """{key(row): [PSNR, …]} of a run's CSV (`folder/name.csv` under assets/results)."""
    by = {}
    for r in read_csv(*file.split("/")):
        by.setdefault(key(r), []).append(num(r["psnr"]))
    return by


def scene_means(file):
    """{scene: mean PSNR} of a run's CSV."""
    return {sc: mean(v) for sc, v in psnr_by(file, lambda r: r["scene"]).items()}


def scene_table(runs):
    """Each scene's mean PSNR less the first run's, by the other runs' names (`runs`: rows
    of a runs.csv with run and file)."""
    base = scene_means(runs[0]["file"])
    others = [(r["run"], scene_means(r["file"])) for r in runs[1:]]
    body = [[sc] + [f"{m[sc] - base[sc]:+.2f}" for _, m in others] for sc in sorted(base)]
    return table(["scene"] + [f"`{run}`" for run, _ in others], body)


def b_experiments_young():
    """Ours' à-trous range and reach and its gradients' pooling, density and process noise,
    each moved alone from ours' values (at cdbdaa6), on the development set at 128²: the
    runs' scores, then each scene's mean PSNR against ours' values."""
    meta = read_json("experiments-young", "meta.json")
    return "\n".join([
        experiment_runs("experiments-young", validation_base=False),
        "",
        "Each scene's mean PSNR less ours' on main (dB), by the runs' names in "
        "`runs.csv` (`k` the range κ, `lv5` five levels, `shr` the shrinkage, `cq7` "
        "`change_q` 7, `s1` `stratum` 1):",
        "",
        scene_table(read_csv("experiments-young", "runs.csv")),
        "",
        f"Source: `assets/results/experiments-young/` (`runs.csv` and each run's CSV) and the "
        f"mechanisms run's single-frame rows, made by `{meta['command']}` from commit "
        f"{meta['commit']} ({meta['date']}) on {meta['machine']}.",
    ])


def b_experiments_young_net():
    """Ours' young-pixel network in the engine, with the first à-trous level or its own
    estimate fed back into the restarted states, against ours without it."""
    meta = read_json("experiments-young-net", "meta.json")
    return "\n".join([
        experiment_runs("experiments-young-net", validation_base=False),
        "",
        f"Source: `assets/results/experiments-young-net/` (`runs.csv` and each run's CSV) and "
        f"the mechanisms run's single-frame rows, made by `{meta['command']}` from "
        f"{meta['commit']} ({meta['date']}) on {meta['machine']}.",
    ])


def b_experiments_guided():
    """Young pixels' spatial estimate (at 5364ed7 and 2b545c3): the development set's runs
    and each scene's mean, the cloud scenes' first frames, and the guided pass's cost."""
    folder = "experiments-guided"
    meta = read_json(folder, "meta.json")
    clouds = read_csv(folder, "clouds.csv")

    def spans(file):
        by = psnr_by(file, lambda r: int(r["frame"]))
        later = [v for f, vs in by.items() if f >= 2 for v in vs]
        return [mean(by[0]), mean(by[1]), mean(later), mean(v for vs in by.values() for v in vs)]

    base = spans(clouds[0]["file"])
    last = max(psnr_by(clouds[0]["file"], lambda r: int(r["frame"])))
    body = [[clouds[0]["change"], clouds[0]["build"]] + [fmt(v, 2) for v in base]]
    for r in clouds[1:]:
        body.append([r["change"], r["build"]]
                    + [f"{v - b:+.2f}" for v, b in zip(spans(r["file"]), base)])
    return "\n".join([
        experiment_runs(folder, validation_base=False),
        "",
        "Each scene's mean PSNR less ours' on main (dB), by the runs' names in `runs.csv`:",
        "",
        scene_table(read_csv(folder, "runs.csv")),
        "",
        "The semi-transparent cloud (`cloud/orbit`, `cloud/point-light`, `cloud/dolly`, "
        f"`cloud/tf-sweep`, built-in scenes of the development set, at 128², {last + 1} "
        f"frames, 256-spp references), ours' mean PSNR over the four scenes at frame 0, "
        f"frame 1, frames 2–{last} and all frames (the first row in dB, the others less it):",
        "",
        table(["change", "build", "frame 0", "frame 1", f"frames 2–{last}", "mean"], body),
        "",
        profile_table(folder, "`ours.atrous*` ms", r"ours\.atrous\d+"),
        "",
        f"Source: `assets/results/{folder}/` (`runs.csv`, `clouds.csv` and the CSVs they "
        f"name, `profiles.csv` and the profiles it names), the mechanisms run's "
        f"single-frame rows, made by `{meta['command']}` from commit {meta['commit']} "
        f"({meta['date']}) on {meta['machine']}.",
    ])


def b_experiments_learned():
    """A learned single-frame estimate for young pixels (tools/young/, offline in torch):
    each network's frame 0 on the development set at 128² and the cloud scenes, against
    ours' frame 0 and the single-frame methods, then each scene for every network."""
    folder = "experiments-learned"
    meta = read_json(folder, "meta.json")
    runs = read_csv(folder, "runs.csv")
    body, per_scene = [], {}
    for r in runs:
        rows = [x for x in read_csv(folder, r["file"]) if int(x["frame"]) == 0]
        for x in rows:
            rivals = [num(x[m]) for m in SINGLE_FRAME if x.get(m) not in (None, "", "nan")]
            per_scene.setdefault(x["scene"], {"ours": num(x["ours"]), "best": max(rivals)})[r["run"]] = num(x["young"])
        # A convolution does one multiply-add per weight per pixel; the count below is the
        # parameters (the biases, a few percent, counted as weights) and leaves out the
        # kernels' application (4 levels × 9 taps × 3 channels). A half-resolution trunk
        # does a quarter of them per output pixel.
        macs = int(r["parameters"]) // (4 if r["half"] == "yes" else 1)
        cells = []
        for prefix in ("dev/", "cloud/"):
            sel = [x for x in rows if x["scene"].startswith(prefix)]
            young = [num(x["young"]) for x in sel]
            own = [num(x["own"]) - num(x["ours"]) for x in sel if x.get("own")]
            cells += [fmt(mean(young), 2),
                      f"{mean(y - num(x['ours']) for y, x in zip(young, sel)):+.2f}",
                      f"{mean(y - per_scene[x['scene']]['best'] for y, x in zip(young, sel)):+.2f}",
                      f"{mean(own):+.2f}" if own else ""]
        body.append([f"`{r['run']}`", r["change"], f"{macs:,}", r["clips"], r["minutes"]] + cells)
    head = ["run", "network", "multiply-adds per pixel", "training clips", "training min"]
    for s in ("development", "cloud"):
        head += [f"{s} PSNR", "less ours", "less the best single-frame", "its own estimate less ours"]
    names = [r["run"] for r in runs]
    scene_rows = [[sc, fmt(v["ours"], 2), fmt(v["best"], 2)] + [fmt(v[n], 2) if n in v else "" for n in names]
                  for sc, v in sorted(per_scene.items())]
    return "\n".join([
        table(head, body),
        "",
        "Each scene's frame 0 (PSNR, dB): ours, the best of `oidn`, `oidn-aux` and `rae`, "
        "and each network (the fused ones' output):",
        "",
        table(["scene", "ours", "best single-frame"] + [f"`{n}`" for n in names], scene_rows),
        "",
        f"Source: `assets/results/{folder}/` (`runs.csv` and the CSVs it names), made by "
        f"`{meta['command']}` from commit {meta['commit']} ({meta['date']}) on {meta['machine']}.",
    ])
