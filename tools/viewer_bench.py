#!/usr/bin/env python3
"""The notebook viewer's speed in a real JupyterLab driven by headless Chromium: frames
per second reaching the page while the view refines, and the latency of a drag (from
the page sending it to the first frame that shows it on the page), in ms and in the
kernel's frame times. Writes one CSV row per size with the device, the commit and the
machine.

    target/py/bin/python tools/viewer_bench.py --size 256 --out assets/results/viewer/viewer.csv

Needs the Python package with its notebook extra and the test requirements installed
(tools/test.sh makes target/py so) and Debian's chromium.
"""

import argparse
import csv
import pathlib
import platform
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python/tests"))
from lab import CHROMIUM, Lab, Notebook, write_notebook  # noqa: E402

FIELDS = [
    "size", "scene", "denoiser", "device", "seconds", "frames_rendered", "frames_shown", "render_fps", "shown_fps",
    "drags", "latency_ms_median", "latency_ms_max", "latency_frames_median", "latency_frames_max",
    "command", "commit", "date", "machine",
]


def measure(page, nb, seconds, drags):
    counter = page.locator(".dvr-frame-counter")
    img = page.locator(".dvr-frame")
    page.wait_for_selector(".dvr-frame[data-frame]", timeout=300_000)
    # Warm-up: pipelines compiled, a few frames shown.
    while int(counter.inner_text()) < 5:
        time.sleep(0.2)
    shown, last = 0, None
    start_frame, start = int(counter.inner_text()), time.monotonic()
    while time.monotonic() - start < seconds:
        f = img.get_attribute("data-frame")
        if f != last:
            shown, last = shown + 1, f
        time.sleep(0.005)
    elapsed = time.monotonic() - start
    rendered = int(counter.inner_text()) - start_frame
    latency = page.locator(".dvr-latency")
    box = page.locator(".dvr-stage").bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    ms, frames = [], []
    for i in range(drags):
        page.wait_for_timeout(600)
        page.evaluate("document.querySelector('.dvr-latency').removeAttribute('data-ms')")
        page.mouse.move(x, y)
        page.mouse.down()
        page.mouse.move(x + (15 if i % 2 == 0 else -15), y, steps=1)
        page.mouse.up()
        deadline = time.monotonic() + 60
        while latency.get_attribute("data-ms") is None and time.monotonic() < deadline:
            time.sleep(0.005)
        ms.append(float(latency.get_attribute("data-ms")))
        frames.append(float(latency.get_attribute("data-frames")))
    return elapsed, rendered, shown, ms, frames


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, nargs="+", default=[256])
    ap.add_argument("--denoiser", default="ours")
    ap.add_argument("--scene", default="mri/point-light")
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--drags", type=int, default=10)
    ap.add_argument("--out", type=pathlib.Path, required=True)
    ap.add_argument("--screenshot", type=pathlib.Path, help="a PNG of the notebook with the viewer (the first size)")
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    machine = f"{platform.machine()}, {subprocess.run(['nproc'], capture_output=True, text=True).stdout.strip()} cores"
    rows = []
    with tempfile.TemporaryDirectory() as tmp, sync_playwright() as p:
        root = pathlib.Path(tmp)
        lab = Lab(root, root / "jupyter.log")
        browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        try:
            for size in args.size:
                name = f"bench{size}.ipynb"
                write_notebook(root / name, [
                    f"import dvr\nv = dvr.Viewer({args.scene!r}, size=({size}, {size}), denoisers=[{args.denoiser!r}])\nv",
                    "print('device', v.renderer.device)",
                    "v.close()",
                ])
                page = browser.new_page(viewport={"width": 1400, "height": 1000})
                nb = Notebook(page, lab, name)
                nb.run(0)
                elapsed, rendered, shown, ms, frames = measure(page, nb, args.seconds, args.drags)
                if args.screenshot and not rows:
                    page.wait_for_timeout(3000)  # refined after the last drag
                    page.locator(".jp-Cell").first.screenshot(path=str(args.screenshot))
                device = nb.run(1).strip().removeprefix("device ").strip()
                nb.run(2)
                page.close()
                rows.append({
                    "size": f"{size}x{size}", "scene": args.scene, "denoiser": args.denoiser, "device": device,
                    "seconds": f"{elapsed:.1f}", "frames_rendered": rendered, "frames_shown": shown,
                    "render_fps": f"{rendered / elapsed:.2f}", "shown_fps": f"{shown / elapsed:.2f}",
                    "drags": len(ms), "latency_ms_median": f"{statistics.median(ms):.0f}",
                    "latency_ms_max": f"{max(ms):.0f}", "latency_frames_median": f"{statistics.median(frames):.2f}",
                    "latency_frames_max": f"{max(frames):.2f}",
                    "command": "tools/viewer_bench.py " + " ".join(sys.argv[1:]), "commit": commit,
                    "date": time.strftime("%Y-%m-%d"), "machine": machine,
                })
                print(rows[-1], flush=True)
        finally:
            browser.close()
            lab.stop()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
