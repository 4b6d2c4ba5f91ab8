"""The charts the pages show, drawn as SVG from the runs' CSVs (standard library only, so
the same files come out on every machine and `tools/results.py --check` can compare
them): speed against accuracy on the validation set, and per-frame PSNR of the
interaction set and of the scenes shown by kind (cuts, channels and time, label maps).
`FIGURES` maps each file to the function that draws it; the blocks in tools/results.py
that show a figure also state what it shows in words."""

import math
from xml.sax.saxutils import escape

from results_io import read_csv, num, frames_by_scene, table, source
from results_sets import GROUPS, group_frames

# What the chart compares and in which colour; ours is red, as in the eval's charts.
COLOURS = {
    "none": "#7f7f7f",
    "taa": "#1f77b4",
    "svgf": "#2ca02c",
    "rae": "#9467bd",
    "oidn": "#ff7f0e",
    "oidn-aux": "#8c564b",
    "ours": "#d62728",
}
SPEED_METHODS = ["none", "taa", "svgf", "rae", "oidn", "oidn-aux", "ours"]
CURVE_METHODS = ["svgf", "oidn-aux", "ours"]
# The validation run's folders per samples per pixel (assets/results/validation/...).
SPP_FOLDERS = {1: "spp1", 2: "", 4: "spp4"}
FONT = 'font-family="DejaVu Sans, Arial, sans-serif"'


def _join(folder, name):
    return f"{folder}/{name}" if folder else name


def speed_points():
    """{method: [(spp, mean whole-frame ms, mean PSNR dB)]} over the validation set, both
    means over the scenes as the tables give them.

    The frame's ms: for the eval's methods their GPU ms in summary.csv (the path trace,
    the features they need and their own passes, after the eval's warm-up frames). For
    OIDN, `none`'s (the shared passes) plus OIDN's mean CPU ms per frame, and for
    `oidn-aux` also the march that wrote its guides: each frame's whole ms in
    `oidn_ms.csv` less its CPU ms and that frame's shared passes (`none`'s GPU ms)."""
    points = {}
    for spp, folder in SPP_FOLDERS.items():
        summary = read_csv("validation", _join(folder, "summary.csv"))
        shared = {(r["scene"], r["frame"]): num(r["gpu_ms"])
                  for r in read_csv("validation", _join(folder, "metrics.csv"))
                  if r["method"] == "none"}
        ms, psnr = {}, {}
        for r in summary:
            psnr.setdefault(r["method"], []).append(num(r["psnr"]))
            if r["gpu_ms"] not in ("", None):
                ms.setdefault(r["method"], {})[r["scene"]] = num(r["gpu_ms"])
        added = {}
        for r in read_csv("validation", _join(folder, "oidn_ms.csv")):
            extra = num(r["oidn_cpu_ms"])
            if r["method"] != "oidn":  # the guide march
                extra += num(r["frame_ms"]) - num(r["oidn_cpu_ms"]) - shared[r["scene"], r["frame"]]
            added.setdefault((r["method"], r["scene"]), []).append(extra)
        for (m, scene), v in added.items():
            ms.setdefault(m, {})[scene] = ms["none"][scene] + sum(v) / len(v)
        for m in SPEED_METHODS:
            if m in ms and m in psnr:
                v = list(ms[m].values())
                points.setdefault(m, []).append(
                    (spp, sum(v) / len(v), sum(psnr[m]) / len(psnr[m])))
    return points


def budget_leaders(points):
    """Who is most accurate within each frame budget: [(from ms, to ms or None, method,
    spp, dB)], one entry per stretch of budgets with the same best point (the most
    accurate point at no more than the budget's ms), from the cheapest point on."""
    pts = sorted((ms, -db, m, spp) for m, ps in points.items() for spp, ms, db in ps)
    out, best = [], None
    for ms, neg_db, m, spp in pts:
        if best is None or -neg_db > best[2]:
            if out:
                out[-1][1] = ms
            best = (m, spp, -neg_db)
            out.append([ms, None, m, spp, -neg_db])
    return [tuple(x) for x in out]


def _ticks(lo, hi, n=5):
    """About n round tick values inside [lo, hi]."""
    span = hi - lo or 1.0
    step = 10 ** math.floor(math.log10(span / n))
    for k in (1, 2, 5, 10):
        if span / (step * k) <= n:
            step *= k
            break
    out, v = [], math.ceil(lo / step - 1e-9) * step
    while v <= hi + 1e-9:
        out.append(round(v, 10))
        v += step
    return out


class _Plot:
    """One set of axes: maps data to pixels and writes the SVG elements."""

    def __init__(self, x0, y0, w, h, xr, yr, log_x=False):
        self.x0, self.y0, self.w, self.h = x0, y0, w, h
        self.xr, self.yr, self.log_x = xr, yr, log_x
        self.out = []

    def px(self, x):
        lo, hi = self.xr
        if self.log_x:
            x, lo, hi = math.log10(x), math.log10(lo), math.log10(hi)
        return self.x0 + (x - lo) / (hi - lo) * self.w

    def py(self, y):
        lo, hi = self.yr
        return self.y0 + self.h - (y - lo) / (hi - lo) * self.h

    def text(self, x, y, s, size, anchor="middle", extra=""):
        self.out.append(f'<text x="{x:.1f}" y="{y:.1f}" text-anchor="{anchor}" '
                        f'font-size="{size}"{extra} {FONT}>{escape(str(s))}</text>')

    def axes(self, xticks, yticks, xlabel, ylabel, title, size=11):
        x0, y0, x1, y1 = self.x0, self.y0, self.x0 + self.w, self.y0 + self.h
        self.out.append(f'<rect x="{x0}" y="{y0}" width="{self.w}" height="{self.h}" '
                        'fill="none" stroke="#444"/>')
        # Each tick: its grid line across the axes and its label outside them.
        ticks = [((x, y0, x, y1), (x, y1 + size + 3, "middle"))
                 for x in map(self.px, xticks)]
        ticks += [((x0, y, x1, y), (x0 - 4, y + size / 3, "end")) for y in map(self.py, yticks)]
        for ((ax, ay, bx, by), (tx, ty, anchor)), t in zip(ticks, list(xticks) + list(yticks)):
            self.out.append(f'<line x1="{ax:.1f}" y1="{ay:.1f}" x2="{bx:.1f}" y2="{by:.1f}" '
                            'stroke="#ddd"/>')
            self.text(tx, ty, f"{t:g}", size, anchor)
        if xlabel:
            self.text(x0 + self.w / 2, y1 + 2 * size + 8, xlabel, size + 1)
        if ylabel:
            cx, cy = x0 - 3.2 * size, y0 + self.h / 2
            self.text(cx, cy, ylabel, size + 1, extra=f' transform="rotate(-90 {cx:.1f} {cy:.1f})"')
        self.text(x0 + self.w / 2, y0 - 6, title, size + 1)

    def line(self, pts, colour, width=1.5):
        d = " ".join(f"{self.px(x):.1f},{self.py(y):.1f}" for x, y in pts)
        self.out.append(f'<polyline points="{d}" fill="none" stroke="{colour}" '
                        f'stroke-width="{width}"/>')


def _svg(w, h, body):
    return "\n".join([
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
        f'viewBox="0 0 {w} {h}">',
        f'<rect width="{w}" height="{h}" fill="white"/>',
        *body,
        "</svg>",
        "",
    ])


def speed_accuracy_svg():
    points = speed_points()
    xs = [ms for pts in points.values() for _, ms, _ in pts]
    ys = [db for pts in points.values() for _, _, db in pts]
    xr = (min(xs) / 1.25, max(xs) * 1.25)
    yr = (math.floor(min(ys)) - 0.5, math.ceil(max(ys)) + 0.5)
    p = _Plot(70, 30, 560, 360, xr, yr, log_x=True)
    xticks = [t for t in (10, 20, 50, 100, 200, 500, 1000, 2000) if xr[0] <= t <= xr[1]]
    p.axes(xticks, _ticks(*yr), "whole frame ms (log scale)", "mean PSNR dB",
           "validation set, 128×128: 1, 2 and 4 spp")
    for m in SPEED_METHODS:
        if m not in points:
            continue
        pts = sorted(points[m])
        c = COLOURS[m]
        p.line([(ms, db) for _, ms, db in pts], c, 2.5 if m == "ours" else 1.5)
        for spp, ms, db in pts:
            x, y = p.px(ms), p.py(db)
            p.out.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="4" fill="{c}"/>')
            p.out.append(f'<text x="{x + 5:.1f}" y="{y - 5:.1f}" font-size="10" fill="{c}" '
                         f'{FONT}>{spp}</text>')
    # The legend, right of the axes.
    for i, m in enumerate(m for m in SPEED_METHODS if m in points):
        y = 50 + 20 * i
        p.out.append(f'<line x1="645" y1="{y}" x2="665" y2="{y}" stroke="{COLOURS[m]}" '
                     f'stroke-width="{2.5 if m == "ours" else 1.5}"/>')
        p.out.append(f'<text x="670" y="{y + 4}" font-size="12" {FONT}>{escape(m)}</text>')
    p.out.append(f'<text x="645" y="{50 + 20 * len(points) + 10}" font-size="10" {FONT}>'
                 'labels: spp</text>')
    return _svg(760, 440, p.out)


def curves_svg(by):
    """Per-frame PSNR of svgf, oidn-aux and ours, one small chart per scene of `by`
    ({scene: {frame: {method: psnr}}}, charted in its order)."""
    scenes = list(by)
    cols = 3
    cw, ch = 300, 170
    rows = math.ceil(len(scenes) / cols)
    body = []
    for i, sc in enumerate(scenes):
        frames = by[sc]
        series = {m: [(f, v[m]) for f, v in sorted(frames.items()) if v.get(m) is not None]
                  for m in CURVE_METHODS}
        ys = [y for s in series.values() for _, y in s]
        if not ys:
            continue
        yr = (math.floor(min(ys)) - 0.5, math.ceil(max(ys)) + 0.5)
        nf = max(frames) if frames else 1
        x0, y0 = 50 + (i % cols) * cw, 30 + (i // cols) * ch
        p = _Plot(x0, y0, cw - 70, ch - 55, (0, max(nf, 1)), yr)
        p.axes(_ticks(0, nf, 4), _ticks(*yr, 4), "", "", sc, size=9)
        for m in CURVE_METHODS:
            if series[m]:
                p.line(series[m], COLOURS[m], 2.0 if m == "ours" else 1.2)
        body += p.out
    w, h = 50 + cols * cw, 30 + rows * ch + 30
    for i, m in enumerate(CURVE_METHODS):
        x = 60 + 130 * i
        body.append(f'<line x1="{x}" y1="{h - 15}" x2="{x + 20}" y2="{h - 15}" '
                    f'stroke="{COLOURS[m]}" stroke-width="2"/>')
        body.append(f'<text x="{x + 25}" y="{h - 11}" font-size="12" {FONT}>{escape(m)}</text>')
    body.append(f'<text x="{60 + 130 * len(CURVE_METHODS)}" y="{h - 11}" font-size="12" {FONT}>'
                 'PSNR dB per frame</text>')
    return _svg(w, h, body)


def interaction_curves_svg():
    """The interaction run's scenes, by name."""
    by = frames_by_scene(read_csv("interaction", "metrics.csv"))
    return curves_svg({sc: by[sc] for sc in sorted(by)})


# Each figure: its file under the repository and the function that draws it.
FIGURES = {
    "assets/results/validation/speed-accuracy.svg": speed_accuracy_svg,
    "assets/results/interaction/curves.svg": interaction_curves_svg,
    **{f"assets/results/curves/{kind}.svg": (lambda kind=kind: curves_svg(group_frames(kind)))
       for kind in GROUPS},
}


# ------------------------------------------------------------------ blocks that show them


def _front_sentence(points):
    """Which point is the most accurate within each stretch of frame budgets (ours in
    bold), so the page says where ours is on the front and where it is not."""
    leaders = budget_leaders(points)
    parts = []
    for lo, hi, m, spp, db in leaders:
        span = f"{lo:.1f}–{hi:.1f} ms" if hi is not None else f"from {lo:.1f} ms"
        who = f"`{m}` at {spp} spp ({db:.2f} dB)"
        parts.append(f"{span}: " + (f"**{who}**" if m == "ours" else who))
    verdict = ("`ours` leads within every budget that any method reaches"
               if all(m == "ours" for _, _, m, _, _ in leaders)
               else "where a stretch names another method, `ours` is not on the front")
    return ("The most accurate point within a frame budget of " + "; ".join(parts)
            + f" ({verdict}).")


def b_speed_accuracy():
    """The chart with its points as a table and where ours is not on the front."""
    points = speed_points()
    body = []
    for m in SPEED_METHODS:
        if m in points:
            cells = {spp: f"{ms:.1f} ms, {db:.2f} dB" for spp, ms, db in points[m]}
            body.append([f"`{m}`"] + [cells.get(s, "") for s in SPP_FOLDERS])
    return "\n".join([
        "![Mean PSNR against the whole frame's ms on the validation set, each method at 1, 2 "
        "and 4 spp](../../assets/results/validation/speed-accuracy.svg)",
        "",
        "Each method's mean PSNR over the validation set against its whole frame's mean ms "
        "(the path trace at 1, 2 and 4 spp, the features the method needs and its own "
        "passes; for OIDN its CPU time on the same cores, as lavapipe's GPU is those cores). "
        + _front_sentence(points),
        "",
        table(["method"] + [f"{s} spp" for s in SPP_FOLDERS], body),
        "",
        source("validation", ["summary.csv", "metrics.csv", "oidn_ms.csv", "spp1/*", "spp4/*"]),
    ])


def b_speed_accuracy_line():
    """README's chart and its one sentence."""
    points = speed_points()
    return "\n".join([
        "![Mean PSNR against the whole frame's ms on the validation set, each method at 1, 2 "
        "and 4 spp](assets/results/validation/speed-accuracy.svg)",
        "",
        "Speed against accuracy on the validation set (128×128, lavapipe on 2 CPU cores). "
        + _front_sentence(points)
        + " ([points and method](docs/src/results.md#speed-against-accuracy))",
    ])


def b_interaction_curves():
    return "\n".join([
        "![Per-frame PSNR of svgf, oidn-aux and ours on each scene of the interaction "
        "set](../../assets/results/interaction/curves.svg)",
        "",
        source("interaction", ["metrics.csv"]),
    ])
