"""Training frames for a single-frame estimate of young pixels: random scenes of the
phantom, the MRI and the cloud (tools/rae/gen_data.py's scene_of: viewpoint, orbit,
light kind and colour, TF preset, density scale, phase) and of the microscopy volume and
the beating shell (`FILES`: a development scene's look), each rendered for a few frames
at the scenes' 2 spp with the guides OIDN takes (TF albedo and gradient normal composited
along the ray), the surface's gradient normal (the surface features ours' prior reads,
zero where a ray finds no surface: `surface`) and a 256-spp reference per frame. One file
per clip, reused when its key matches, so a run can be resumed or extended; --ours adds
ours' output of each frame rendered as a cut (the fused network's other input), to new
clips and to kept ones, and kept clips gain `surface` when they lack it. --cuts gives half
the scenes a random clip plane and a quarter a random crop box.

    nice -n 10 .venv/bin/python tools/young/gen.py --clips 16 --datasets phantom,mri,cloud --ours
    nice -n 10 .venv/bin/python tools/young/gen.py --clips 10 --datasets microscopy,shell --ours
    nice -n 10 .venv/bin/python tools/young/gen.py --clips 12 --datasets phantom,mri --ours \
        --cuts --seed 11 --out out/young-data-cuts

Needs the dvr package in the Python that runs it (a release wheel: `maturin build
--release -m python/Cargo.toml`) and torch for train.py (tools/rae/requirements.txt).
"""
import argparse
import io
import json
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "rae"))
import gen_data  # noqa: E402
import dvr  # noqa: E402

# Volumes gen_data has no presets for, drawn from a scene file's look (its TF, channels,
# emission and lights) under a random viewpoint, orbit and light intensity.
FILES = {
    "microscopy": "assets/scenes/development/microscopy-orbit.toml",
    "shell": "assets/scenes/development/shell-beat-orbit.toml",
}


def file_scene(ds, rng, frames):
    scene = dvr.Scene.load(FILES[ds])
    scene.frames = frames
    scene.camera = gen_data.camera_of(rng)
    scale = rng.uniform(0.5, 2.0)
    for light in scene.lights:
        light.intensity = round(light.intensity * scale, 3)
    speed = gen_data.orbit_speed(rng)
    if speed != 0.0:
        scene.orbit(degrees_per_frame=speed)
    return scene, dict(file=FILES[ds], light_scale=scale, speed=speed)


def with_cut(scene, info, rng):
    """A random clip plane through the middle (half the draws), a crop box (a quarter) or
    neither: young pixels at a cut's face are where a single-frame estimate is tested most."""
    u = rng.random()
    if u < 0.5:
        th, ph = rng.uniform(0, math.pi), rng.uniform(0, 2 * math.pi)
        n = [math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)]
        pt = list(rng.uniform(-0.15, 0.15, 3))
        scene.clip = [dvr.ClipPlane(gen_data.r4(pt), gen_data.r4(n))]
        info["clip"] = gen_data.r4(n)
    elif u < 0.75:
        lo, hi = rng.uniform(-0.5, -0.1, 3), rng.uniform(0.1, 0.5, 3)
        scene.crop = dvr.CropBox(gen_data.r4(lo), gen_data.r4(hi))
        info["crop"] = True


def surface_normals(scene, size, frames):
    """The surface features' gradient normal of each frame (xyz; zero where none)."""
    r = dvr.Renderer(scene, size=size, denoisers=[])
    return np.stack([r.render(t, features=True)["features"]["normal"][..., :3] for t in range(frames)])


def ours_reset(scene, size, frames):
    """ours' output at each frame rendered as a cut (every history restarted): what ours
    gives a pixel whose history is new, its spatial estimate alone."""
    r = dvr.Renderer(scene, size=size, denoisers=["ours"])
    return np.stack([r.render(t, reset=True)["ours"] for t in range(frames)]).astype(np.float32)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--clips", type=int, default=12, help="clips per dataset")
    ap.add_argument("--frames", type=int, default=4)
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--ref-spp", type=int, default=256)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--datasets", default="phantom,mri,cloud")
    ap.add_argument("--out", default="out/young-data")
    ap.add_argument("--ours", action="store_true", help="also keep ours' output at each frame as a cut")
    ap.add_argument("--cuts", action="store_true", help="random clip planes and crop boxes")
    a = ap.parse_args()
    size = tuple(int(x) for x in a.size.lower().split("x"))
    os.makedirs(a.out, exist_ok=True)
    t0 = time.time()
    for ds in a.datasets.split(","):
        names = sorted(gen_data.TFS) + sorted(FILES)
        rng = np.random.default_rng([a.seed, names.index(ds)])
        for i in range(a.clips):
            if ds in FILES:
                scene, info = file_scene(ds, rng, a.frames)
            else:
                scene, info = gen_data.scene_of(ds, rng, a.frames, 2)
            if a.cuts:
                with_cut(scene, info, rng)
            key = json.dumps(dict(scene=scene.check(), size=a.size, ref_spp=a.ref_spp), sort_keys=True)
            path = os.path.join(a.out, f"{ds}{i:03d}.npz")
            have = None
            try:
                with np.load(path) as f:
                    if str(f["key"]) == key:
                        have = dict(f)
            except (OSError, ValueError, KeyError):
                pass
            if have is not None:
                added = []
                if a.ours and "ours" not in have:
                    have["ours"] = ours_reset(scene, size, a.frames)
                    added.append("ours")
                if "surface" not in have:
                    have["surface"] = surface_normals(scene, size, a.frames).astype(np.float32)
                    added.append("surface")
                if added:
                    buf = io.BytesIO()
                    np.savez(buf, **have)
                    gen_data.write_atomic(path, buf.getvalue())
                    print(f"{ds} {i + 1}/{a.clips}: {', '.join(added)} added {time.time() - t0:.0f}s", flush=True)
                continue
            r = dvr.Renderer(scene, size=size, denoisers=[])
            ref = np.stack([r.reference(t, spp=a.ref_spp) for t in range(a.frames)])
            outs = [r.render(t, aux=True) for t in range(a.frames)]
            clip = {k: np.stack([o[k] for o in outs]).astype(np.float32) for k in ("noisy", "albedo", "normal")}
            clip["surface"] = surface_normals(scene, size, a.frames).astype(np.float32)
            if a.ours:
                clip["ours"] = ours_reset(scene, size, a.frames)
            buf = io.BytesIO()
            np.savez(buf, ref=ref.astype(np.float32), key=np.array(key), info=np.array(str(info)), **clip)
            gen_data.write_atomic(path, buf.getvalue())
            print(f"{ds} {i + 1}/{a.clips} {info} {time.time() - t0:.0f}s", flush=True)


if __name__ == "__main__":
    main()
