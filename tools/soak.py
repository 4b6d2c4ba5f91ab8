#!/usr/bin/env python3
"""Soaks of live sessions with random edits (python/tests/soak.py): a Python renderer for
10,000 renders, a 4D series played for 10,000 frames, the explorer under Xvfb for 10,000 frames, the notebook viewer left
refining for 30 minutes. Prints each session's figures and writes them, with the
command, commit and machine, to the CSV given; exits 1 if one fails (resident memory
more than 5 % above the warm-up's, device memory grown, or a validation message).

    DVR_VALIDATION=1 target/py/bin/python tools/soak.py --out assets/results/soak/soak.csv

Needs what tools/test.sh installs (target/py with the package, Xvfb, Chromium) and the
dvr binary (DVR_BIN, default target/debug/dvr).
"""

import argparse
import csv
import os
import pathlib
import platform
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python/tests"))
import soak  # noqa: E402
from lab import CHROMIUM, Lab  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--renders", type=int, default=10_000)
    ap.add_argument("--frames", type=int, default=10_000)
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--only", choices=["python", "series", "explorer", "notebook"], action="append")
    ap.add_argument("--out", type=pathlib.Path, required=True)
    args = ap.parse_args()
    only = set(args.only or ["python", "series", "explorer", "notebook"])
    dvr_bin = os.environ.get("DVR_BIN", str(ROOT / "target/debug/dvr"))
    rows = []
    if "python" in only:
        rows.append(soak.python_session(args.renders))
        print(rows[-1], flush=True)
    if "series" in only:
        rows.append(soak.series_session(args.renders))
        print(rows[-1], flush=True)
    if "explorer" in only:
        rows.append(soak.explorer_session(dvr_bin, args.frames))
        print(rows[-1], flush=True)
    if "notebook" in only:
        from playwright.sync_api import sync_playwright

        with tempfile.TemporaryDirectory() as tmp, sync_playwright() as p:
            lab = Lab(pathlib.Path(tmp), pathlib.Path(tmp) / "jupyter.log")
            browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
            try:
                rows.append(soak.notebook_session(lab, browser, args.minutes * 60))
            finally:
                browser.close()
                lab.stop()
        print(rows[-1], flush=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    cores = os.cpu_count()
    for r in rows:
        r.update(passed=soak.passed(r), command="tools/soak.py " + " ".join(sys.argv[1:]), commit=commit,
                 date=time.strftime("%Y-%m-%d"), machine=f"{platform.machine()}, {cores} cores, lavapipe")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {args.out}")
    sys.exit(0 if all(r["passed"] for r in rows) else 1)


if __name__ == "__main__":
    main()
