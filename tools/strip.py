#!/usr/bin/env python3
"""Figures for the results page from a `dvr eval` folder: a strip of one frame of each
scene beside its reference (one row a scene, one column a method, each labelled), and a
copy of each scene's per-frame PSNR chart (the eval's own `plots/psnr.png`).

    python3 tools/strip.py out/cuts --frame 30 --methods ours,oidn-aux,svgf,taa \\
        --strip assets/gallery/cuts-frame30.png --plots assets/gallery/cuts

Needs Pillow. The images are the eval's own PNGs (the eval's tone map), upscaled 2x
with nearest-neighbour so pixels stay pixels.
"""

import argparse
import pathlib
import shutil

from PIL import Image, ImageDraw


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("eval_dir", type=pathlib.Path)
    ap.add_argument("--frame", type=int, required=True)
    ap.add_argument("--methods", required=True, help="comma list, shown after the reference")
    ap.add_argument("--strip", type=pathlib.Path, required=True)
    ap.add_argument("--plots", type=pathlib.Path, help="prefix: copies <prefix>-<scene>-psnr.png")
    ap.add_argument("--scale", type=int, default=2)
    args = ap.parse_args()
    methods = ["reference"] + args.methods.split(",")
    scenes = sorted(p for p in args.eval_dir.iterdir() if (p / "reference").is_dir())
    name = f"{args.frame:04d}.png"
    tiles = [[Image.open(s / m / name).convert("RGB") for m in methods] for s in scenes]
    w, h = tiles[0][0].size
    w, h, label = w * args.scale, h * args.scale, 16
    out = Image.new("RGB", (w * len(methods), (h + label) * len(scenes)), (24, 26, 32))
    draw = ImageDraw.Draw(out)
    for r, (scene, row) in enumerate(zip(scenes, tiles)):
        for c, (m, img) in enumerate(zip(methods, row)):
            x, y = c * w, r * (h + label)
            out.paste(img.resize((w, h), Image.NEAREST), (x, y + label))
            draw.text((x + 3, y + 2), f"{scene.name} · {m}" if c == 0 else m, fill=(230, 230, 230))
    args.strip.parent.mkdir(parents=True, exist_ok=True)
    out.save(args.strip, optimize=True)
    print(f"wrote {args.strip}")
    if args.plots:
        for s in scenes:
            dest = pathlib.Path(f"{args.plots}-{s.name}-psnr.png")
            shutil.copyfile(s / "plots" / "psnr.png", dest)
            print(f"wrote {dest}")


if __name__ == "__main__":
    main()
