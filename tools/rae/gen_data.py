"""Generates RAE training clips from dvr itself, in process through the Python package
(`import dvr`, python/): scenes with scripted variations (camera viewpoint, orbit speed
and direction, field of view; light kind, position, colour, intensity; transfer
function preset and density scale, i.e. more and less transparent), each rendered by a
`dvr.Renderer` (the noisy input at --spp, frame after frame) and its references (the
target at --ref-spp). Each clip is cached as DATA/<dataset>/clipNNN.npz (with the scene
and settings it was rendered for), and all are packed into DATA/<dataset>.npz (noisy,
ref: (clips, frames, 3, H, W) float32) with a content hash.

    nice -n 10 /opt/rae-venv/bin/python tools/rae/gen_data.py --dataset phantom --clips 24

(the venv needs the package: `pip install ./python`). The defaults (64x64 clips,
256-spp references) make the cheap pre-training set; the training setting (7-frame
128x128 clips with 1024-spp references, about 7 min per clip on lavapipe with two
rendering at once on this 2-core machine) is --size 128x128 --ref-spp 1024
(pipeline.sh runs both). Clips already rendered with the same settings are reused, so a
run can be resumed or extended.
"""
import argparse
import hashlib
import io
import json
import math
import os
import time

import numpy as np

import dvr

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

TFS = {
    "phantom": ["phantom-layered", "phantom-layered-edit", "phantom-opaque", "phantom-opaque-edit"],
    "mri": ["mri-opaque", "mri-opaque-edit", "mri-layered", "mri-layered-edit"],
    "cloud": ["cloud", "cloud-edit"],
}


def r4(v):
    """Values as the clips' scenes have always held them (4 decimals), so a clip is the
    same whichever version of this tool made it."""
    return [round(float(x), 4) for x in v]


def camera_of(rng):
    """A random viewpoint around the volume: distance, azimuth, elevation, a target near
    the centre and a field of view."""
    dist = rng.uniform(1.2, 2.0)
    az = rng.uniform(0, 2 * math.pi)
    el = rng.uniform(-0.35, 0.7)
    cam = [dist * math.cos(el) * math.cos(az), dist * math.cos(el) * math.sin(az), dist * math.sin(el)]
    target = rng.uniform(-0.08, 0.08, 3)
    return dvr.Camera(r4(cam), r4(target), fov_y_degrees=round(rng.uniform(30, 45), 2))


def orbit_speed(rng):
    """A random orbit speed in degrees per frame, either way round (0: still)."""
    return float(rng.choice([0.0, 1.0, 2.0, 4.0, 8.0]) * rng.choice([-1.0, 1.0]))


def scene_of(dataset, rng, frames, spp):
    """A random scene of `dataset` and what was drawn for it."""
    tf = TFS[dataset][rng.integers(len(TFS[dataset]))]
    # More and less transparent: the density scale spans 4x around the built-ins' 150.
    density = float(np.exp(rng.uniform(np.log(60.0), np.log(300.0))))
    camera = camera_of(rng)
    speed = orbit_speed(rng)
    # A key light of a random kind, direction, colour and intensity (order-1 radiance on
    # lit surfaces, like the built-ins), plus (usually) a dim environment fill.
    laz = rng.uniform(0, 2 * math.pi)
    lel = rng.uniform(-0.3, 1.2)
    ld = rng.uniform(1.1, 1.8)
    lpos = [ld * math.cos(lel) * math.cos(laz), ld * math.cos(lel) * math.sin(laz), ld * math.sin(lel)]
    colour = np.clip(np.array([1.0, 0.95, 0.9]) + rng.uniform(-0.25, 0.1, 3), 0.3, 1.0)
    kind = rng.choice(["point", "point", "area", "environment"])
    lights = []
    if kind == "point":
        lights.append(dvr.PointLight(r4(lpos), r4(colour), round(rng.uniform(8, 40), 2)))
    elif kind == "area":
        s = rng.uniform(0.2, 0.7)
        lights.append(dvr.AreaLight(r4(lpos), size=(round(s, 3), round(s * rng.uniform(0.5, 1.5), 3)),
                                    colour=r4(colour), intensity=round(rng.uniform(30, 150), 2)))
    if kind == "environment" or rng.random() < 0.7:
        env_i = rng.uniform(0.5, 1.5) if kind == "environment" else rng.uniform(0.1, 0.4)
        top = np.clip([0.55, 0.65, 0.8] + rng.uniform(-0.1, 0.1, 3), 0, 1)
        lights.append(dvr.EnvironmentLight(top=r4(top), bottom=(0.2, 0.18, 0.15), intensity=round(env_i, 3)))
    render = {"spp": spp, "max_bounces": 4, "phase": str(rng.choice(["isotropic", "hg"])),
              "hg_g": round(float(rng.uniform(-0.3, 0.6)), 2)}
    scene = dvr.Scene(dataset, tf=dvr.TransferFunction.preset(tf), lights=lights, frames=frames,
                      camera=camera,
                      density_scale=round(density, 2),
                      render=render, name=f"rae-{dataset}")
    if speed != 0.0:
        scene.orbit(degrees_per_frame=round(float(speed), 1))
    return scene, dict(tf=tf, density=density, light=str(kind), speed=float(speed))


def render_clip(scene, size, ref_spp):
    """The clip's references and noisy frames (in order: the renderer's own animation),
    each (frames, 3, H, W). References first: a reference's sample stream starts after
    the frames rendered before it, so these are the ones `dvr reference` writes."""
    r = dvr.Renderer(scene, size=size, denoisers=[])
    refs = np.stack([r.reference(t, spp=ref_spp) for t in range(scene.frames)])
    noisy = np.stack([r.render(t)["noisy"] for t in range(scene.frames)])
    return np.moveaxis(noisy, -1, 1), np.moveaxis(refs, -1, 1)


def write_atomic(path, data):
    """Writes under a temporary name, flushes to disk and renames: a crash leaves the
    old file or none, never a cut one."""
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


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
    a = ap.parse_args()
    rng = np.random.default_rng([a.seed, sorted(TFS).index(a.dataset)])
    base = os.path.join(a.data, a.dataset)
    os.makedirs(base, exist_ok=True)
    size = tuple(int(x) for x in a.size.lower().split("x"))
    noisy, refs, meta = [], [], []
    t0 = time.time()
    for i in range(a.clips):
        scene, info = scene_of(a.dataset, rng, a.frames, a.spp)
        # A clip is reused only when rendered for exactly this scene and these settings
        # (the key is stored in its file, written atomically after rendering).
        key = json.dumps(dict(scene=scene.check(), size=a.size, spp=a.spp, ref_spp=a.ref_spp), sort_keys=True)
        path = os.path.join(base, f"clip{i:03d}.npz")
        clip = None
        try:
            with np.load(path) as f:
                if str(f["key"]) == key:
                    clip = (f["noisy"], f["ref"])
        except (OSError, ValueError, KeyError):
            pass
        if clip is None:
            clip = render_clip(scene, size, a.ref_spp)
            buf = io.BytesIO()
            np.savez(buf, noisy=clip[0], ref=clip[1], key=np.array(key))
            write_atomic(path, buf.getvalue())
        noisy.append(clip[0])
        refs.append(clip[1])
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
