#!/usr/bin/env python3
"""Figures for the results page from `dvr eval` folders: a strip of one frame of each
scene beside its reference (one row a scene, one column a method, each labelled), and a
copy of each scene's per-frame PSNR chart (the eval's own `plots/psnr.png`).

    python3 tools/strip.py out/mechanisms out/validation \\
        --scenes dev_mri-clip-sweep,val_cloud-oblique-clip-light --frame 30 \\
        --methods ours,oidn-aux,svgf,taa --strip assets/gallery/cuts-frame30.png

Needs Pillow. The images are the eval's own PNGs (the eval's tone map), upscaled 2x
with nearest-neighbour so pixels stay pixels.
"""

import argparse
import pathlib
import shutil

from PIL import Image, ImageDraw

LABEL = 16  # pixels above each tile for its label
BACKGROUND = (24, 26, 32)
TEXT = (230, 230, 230)


def scenes_of(eval_dir):
    """The eval's scene folders (those with a `reference/` folder), sorted by name."""
    scenes = sorted(p for p in pathlib.Path(eval_dir).iterdir() if (p / "reference").is_dir())
    if not scenes:
        raise SystemExit(f"strip: {eval_dir} has no scene folders (none holds a reference/ folder)")
    return scenes


def pick(eval_dirs, names=None):
    """The scene folders of one or more evals: every one, each eval's by name, or those
    named (folder names, e.g. `dev_mri-clip-sweep`) in the order named. A name no eval
    holds, or one two evals hold, is an error naming it."""
    found = [s for d in eval_dirs for s in scenes_of(d)]
    if names is None:
        return found
    out = []
    for n in names:
        hits = [s for s in found if s.name == n]
        if len(hits) != 1:
            where = ", ".join(str(d) for d in eval_dirs)
            raise SystemExit(f"strip: scene {n} is in {len(hits)} of the evals {where}, not one")
        out.append(hits[0])
    return out


def strip(eval_dirs, frame, methods, scale=2, names=None):
    """The strip image: one row per scene (`pick`), the reference then `methods` as
    columns, each tile `scale`x its frame's PNG under a label. A missing frame is an error
    naming it."""
    methods = ["reference"] + list(methods)
    scenes = pick([eval_dirs] if isinstance(eval_dirs, (str, pathlib.Path)) else eval_dirs, names)
    name = f"{frame:04d}.png"
    missing = [str(s / m / name) for s in scenes for m in methods if not (s / m / name).is_file()]
    if missing:
        raise SystemExit("strip: missing frame(s): " + ", ".join(missing))
    tiles = [[Image.open(s / m / name).convert("RGB") for m in methods] for s in scenes]
    w, h = tiles[0][0].size
    w, h = w * scale, h * scale
    out = Image.new("RGB", (w * len(methods), (h + LABEL) * len(scenes)), BACKGROUND)
    draw = ImageDraw.Draw(out)
    for r, (scene, row) in enumerate(zip(scenes, tiles)):
        for c, (m, img) in enumerate(zip(methods, row)):
            x, y = c * w, r * (h + LABEL)
            out.paste(img.resize((w, h), Image.NEAREST), (x, y + LABEL))
            draw.text((x + 3, y + 2), f"{scene.name} · {m}" if c == 0 else m, fill=TEXT)
    return out


def copy_plots(eval_dir, prefix):
    """Copies each scene's `plots/psnr.png` to `<prefix>-<scene>-psnr.png`; returns the copies."""
    written = []
    for s in scenes_of(eval_dir):
        src = s / "plots" / "psnr.png"
        if not src.is_file():
            raise SystemExit(f"strip: missing PSNR chart: {src}")
        dest = pathlib.Path(f"{prefix}-{s.name}-psnr.png")
        shutil.copyfile(src, dest)
        written.append(dest)
    return written


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("eval_dir", type=pathlib.Path, nargs="+")
    ap.add_argument("--scenes", help="comma list of scene folders, in the strip's order (default: all)")
    ap.add_argument("--frame", type=int, required=True)
    ap.add_argument("--methods", required=True, help="comma list, shown after the reference")
    ap.add_argument("--strip", type=pathlib.Path, required=True)
    ap.add_argument("--plots", type=pathlib.Path, help="prefix: copies <prefix>-<scene>-psnr.png")
    ap.add_argument("--scale", type=int, default=2)
    args = ap.parse_args(argv)
    names = args.scenes.split(",") if args.scenes else None
    out = strip(args.eval_dir, args.frame, args.methods.split(","), args.scale, names)
    args.strip.parent.mkdir(parents=True, exist_ok=True)
    out.save(args.strip, optimize=True)
    print(f"wrote {args.strip}")
    if args.plots:
        if len(args.eval_dir) != 1:
            raise SystemExit("strip: --plots copies one eval's charts; name one eval folder")
        for dest in copy_plots(args.eval_dir[0], args.plots):
            print(f"wrote {dest}")


if __name__ == "__main__":
    main()
