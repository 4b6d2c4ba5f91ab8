"""Generates RAE training clips from dvr itself: scene TOML files with scripted
variations (camera viewpoint, orbit speed and direction, field of view; light kind,
position, colour, intensity; transfer function preset and density scale, i.e. more and
less transparent), each rendered by `dvr capture --denoiser none` (the noisy input at
--spp) and `dvr reference` (the target at --ref-spp). Everything is written to
DATA/<dataset>/clipNNN/{scene.toml,none/*.exr,reference/*.exr} and packed into
DATA/<dataset>.npz (noisy, ref: (clips, frames, 3, H, W) float32) with a content hash.

    nice -n 10 /opt/rae-venv/bin/python tools/rae/gen_data.py --dataset phantom --clips 24

The defaults (64x64 clips, 256-spp references) make the cheap pre-training set; the
issue's setting (7-frame 128x128 clips with 1024-spp references, about 7 min per clip
on lavapipe with two rendering at once on this 2-core machine) is
--size 128x128 --ref-spp 1024 (pipeline.sh runs both). Clips already rendered with the
same settings (DATA/<dataset>/clipNNN/done.json) are reused, so a run can be resumed or
extended.
"""
import argparse
import hashlib
import io
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

TFS = {
    "phantom": ["phantom-layered", "phantom-layered-edit", "phantom-opaque", "phantom-opaque-edit"],
    "mri": ["mri-opaque", "mri-opaque-edit", "mri-layered", "mri-layered-edit"],
    "cloud": ["cloud", "cloud-edit"],
}


def vec(v):
    return "[" + ", ".join(f"{x:.4f}" for x in v) + "]"


def scene_toml(dataset, rng, frames, spp):
    tf = TFS[dataset][rng.integers(len(TFS[dataset]))]
    # More and less transparent: the density scale spans 4x around the built-ins' 150.
    density = float(np.exp(rng.uniform(np.log(60.0), np.log(300.0))))
    dist = rng.uniform(1.2, 2.0)
    az = rng.uniform(0, 2 * math.pi)
    el = rng.uniform(-0.35, 0.7)
    cam = [dist * math.cos(el) * math.cos(az), dist * math.cos(el) * math.sin(az), dist * math.sin(el)]
    target = rng.uniform(-0.08, 0.08, 3)
    fov = rng.uniform(30, 45)
    speed = rng.choice([0.0, 1.0, 2.0, 4.0, 8.0]) * rng.choice([-1.0, 1.0])
    lines = [
        f'name = "rae-{dataset}"',
        "[volume]",
        f'builtin = "{dataset}"',
        f"density_scale = {density:.2f}",
        "[transfer]",
        f'a = "{tf}"',
        "[camera]",
        f"position = {vec(cam)}",
        f"target = {vec(target)}",
        f"fov_y_degrees = {fov:.2f}",
    ]
    # A key light of a random kind, direction, colour and intensity (order-1 radiance on
    # lit surfaces, like the built-ins), plus (usually) a dim environment fill.
    laz = rng.uniform(0, 2 * math.pi)
    lel = rng.uniform(-0.3, 1.2)
    ld = rng.uniform(1.1, 1.8)
    lpos = [ld * math.cos(lel) * math.cos(laz), ld * math.cos(lel) * math.sin(laz), ld * math.sin(lel)]
    colour = np.clip(np.array([1.0, 0.95, 0.9]) + rng.uniform(-0.25, 0.1, 3), 0.3, 1.0)
    kind = rng.choice(["point", "point", "area", "environment"])
    if kind == "point":
        lines += ["[[light]]", 'kind = "point"', f"position = {vec(lpos)}",
                  f"colour = {vec(colour)}", f"intensity = {rng.uniform(8, 40):.2f}"]
    elif kind == "area":
        s = rng.uniform(0.2, 0.7)
        lines += ["[[light]]", 'kind = "area"', f"position = {vec(lpos)}", "target = [0.0, 0.0, 0.0]",
                  f"size = [{s:.3f}, {s * rng.uniform(0.5, 1.5):.3f}]",
                  f"colour = {vec(colour)}", f"intensity = {rng.uniform(30, 150):.2f}"]
    if kind == "environment" or rng.random() < 0.7:
        env_i = rng.uniform(0.5, 1.5) if kind == "environment" else rng.uniform(0.1, 0.4)
        lines += ["[[light]]", 'kind = "environment"', 'mode = "gradient"',
                  f"top = {vec(np.clip([0.55, 0.65, 0.8] + rng.uniform(-0.1, 0.1, 3), 0, 1))}",
                  "bottom = [0.2, 0.18, 0.15]", f"intensity = {env_i:.3f}"]
    lines += ["[render]", f"spp = {spp}", "max_bounces = 4",
              f'phase = "{rng.choice(["isotropic", "hg"])}"', f"hg_g = {rng.uniform(-0.3, 0.6):.2f}",
              "[animation]", f"frames = {frames}"]
    if speed != 0.0:
        lines += ["[animation.orbit]", f"degrees_per_frame = {speed:.1f}"]
    return "\n".join(lines) + "\n", dict(tf=tf, density=density, light=str(kind), speed=float(speed))


def read_exr(path):
    import OpenEXR
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            px = np.asarray(ch["RGB"].pixels, dtype=np.float32)
        else:
            px = np.stack([np.asarray(ch[c].pixels, dtype=np.float32) for c in "RGB"], -1)
    return np.moveaxis(px, -1, 0)  # (3,H,W)


def marker_path(clip_dir):
    return os.path.join(clip_dir, "done.json")


def read_marker(clip_dir):
    try:
        with open(marker_path(clip_dir)) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def write_atomic(path, data):
    """Writes under a temporary name, flushes to disk and renames: a crash leaves the
    old file or none, never a cut one."""
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dataset", required=True, choices=sorted(TFS))
    ap.add_argument("--clips", type=int, default=24)
    ap.add_argument("--frames", type=int, default=7)
    ap.add_argument("--size", default="64x64")
    ap.add_argument("--spp", type=int, default=2)
    ap.add_argument("--ref-spp", type=int, default=256)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--data", default=os.path.join(ROOT, "out", "rae-data"))
    ap.add_argument("--dvr", default=os.path.join(ROOT, "target", "release", "dvr"))
    a = ap.parse_args()
    rng = np.random.default_rng([a.seed, sorted(TFS).index(a.dataset)])
    base = os.path.join(a.data, a.dataset)
    os.makedirs(base, exist_ok=True)
    noisy, refs, meta = [], [], []
    t0 = time.time()
    for i in range(a.clips):
        d = os.path.join(base, f"clip{i:03d}")
        os.makedirs(d, exist_ok=True)
        text, info = scene_toml(a.dataset, rng, a.frames, a.spp)
        scene = os.path.join(d, "scene.toml")
        with open(scene, "w") as f:
            f.write(text)
        common = ["--scene", scene, "--frames", str(a.frames), "--size", a.size]
        # A clip is done when both commands finished for exactly these settings: the
        # marker is written (atomically) after them, so a crash, a cut file or other
        # settings re-render. `dvr reference` itself reuses frames rendered under the
        # same content key.
        done = dict(scene=text, frames=a.frames, size=a.size, spp=a.spp, ref_spp=a.ref_spp)
        if read_marker(d) != done:
            run([a.dvr, "capture", *common, "--spp", str(a.spp), "--denoiser", "none", "--out", d])
            run([a.dvr, "reference", *common, "--ref-spp", str(a.ref_spp), "--out", d])
            write_atomic(marker_path(d), json.dumps(done, indent=1).encode())
        noisy.append(np.stack([read_exr(os.path.join(d, "none", f"{t:04d}.exr")) for t in range(a.frames)]))
        refs.append(np.stack([read_exr(os.path.join(d, "reference", f"{t:04d}.exr")) for t in range(a.frames)]))
        meta.append(info)
        el = time.time() - t0
        print(f"{a.dataset} clip {i + 1}/{a.clips} ({info}) {el:.0f}s, ~{el / (i + 1) * (a.clips - i - 1):.0f}s left",
              flush=True)
    noisy = np.stack(noisy).astype(np.float32)
    refs = np.stack(refs).astype(np.float32)
    h = hashlib.sha256(noisy.tobytes() + refs.tobytes()).hexdigest()[:16]
    buf = io.BytesIO()
    np.savez(buf, noisy=noisy, ref=refs, hash=h,
             meta=np.array([str(m) for m in meta]),
             settings=np.array(f"{a.clips} clips x {a.frames} frames, {a.size}, {a.spp} spp input, "
                               f"{a.ref_spp}-spp references, seed {a.seed}"))
    write_atomic(os.path.join(a.data, f"{a.dataset}.npz"), buf.getvalue())
    print(f"wrote {a.data}/{a.dataset}.npz: {noisy.shape}, sha256[:16] {h}, {time.time() - t0:.0f}s")


if __name__ == "__main__":
    main()
