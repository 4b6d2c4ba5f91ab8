#!/usr/bin/env python3
"""A CT in Hounsfield units seen the right way round: writes a synthetic head CT as a
NIfTI file (int16 HU, RAS affine) with a marker on the patient's right, then shows it in
`dvr explore` with the `ct-bone` preset from the front and from the left (the explorer's
orientation letters, scale bar and the TF editor's HU axis in view), and puts the two
screenshots side by side (Pillow).

    tools/ct_views.py --dvr target/release/dvr --out assets/screenshots/ct-views.png

The head is the built-in `phantom` (CT-like: air, scalp, brain, ventricles, bone,
contrast-filled vessels) with its densities mapped to typical HU; the marker is a small
bone knob on the right (+x) side and one on the forehead, so a mirrored image shows at
once. Needs the Python
package (`dvr`), numpy, nibabel, Pillow and Xvfb.
"""

import argparse
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

# Phantom density -> HU at its tissues (see engine/volume/src/phantom.rs): air, CSF in the
# ventricles, scalp, brain, bone, contrast-filled vessels. Linear between.
DENSITY = [0.0, 0.14, 0.32, 0.45, 0.80, 1.0]
HU = [-1000.0, 5.0, -60.0, 35.0, 1400.0, 350.0]
SPACING = 1.5  # mm


def ct_volume(size):
    import dvr

    phantom = dvr.Volume.builtin("phantom", size)
    d = np.asarray(phantom.data, dtype=np.float64)  # [z, y, x]
    hu = np.interp(d, DENSITY, HU)
    # Bone knobs on the skull: one on the patient's right (+x), one at the front of the
    # forehead (+y, high), so either view shows which way round it is.
    z, y, x = np.indices(d.shape)
    n = d.shape[2]
    for cx, cy, cz in [(0.9, 0.5, 0.55), (0.5, 0.93, 0.75)]:
        knob = (x - cx * n) ** 2 + (y - cy * n) ** 2 + (z - cz * n) ** 2 < (0.06 * n) ** 2
        hu[knob] = 1400.0
    return np.round(hu).astype(np.int16)


def write_nifti(hu, path):
    import nibabel as nib

    affine = np.diag([SPACING, SPACING, SPACING, 1.0])  # RAS: +x right, +y anterior
    img = nib.Nifti1Image(np.ascontiguousarray(hu.transpose(2, 1, 0)), affine)  # x, y, z
    img.set_sform(affine, code=1)
    nib.save(img, str(path))


def scene(nifti, path):
    path.write_text(f"""name = "ct-head"
[volume]
file = "{nifti}"
[transfer]
a = "ct-bone"
[camera]
position = [0.0, 1.6, 0.0]
[[light]]
kind = "point"
position = [-0.6, 1.2, 1.6]
intensity = 30.0
[[light]]
kind = "environment"
mode = "constant"
intensity = 0.5
""")


def free_display():
    for n in range(90, 140):
        if not os.path.exists(f"/tmp/.X11-unix/X{n}") and not os.path.exists(f"/tmp/.X{n}-lock"):
            return n
    raise SystemExit("ct_views: no free X display")


def shot(dvr_bin, scene_path, key, out, display):
    cmd = [dvr_bin, "explore", "--scene", str(scene_path), "--size", "360x360", "--frames", "60",
           "--script", f"key:{key}@0", "--screenshot", str(out)]
    env = dict(os.environ, DISPLAY=f":{display}")
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    if r.returncode != 0 or not out.is_file():
        raise SystemExit(f"ct_views: {' '.join(cmd)} failed:\n{r.stderr}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dvr", default="target/release/dvr", help="the dvr binary")
    ap.add_argument("--out", default="assets/screenshots/ct-views.png")
    ap.add_argument("--size", type=int, default=160, help="the phantom's edge in voxels")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        nifti = tmp / "ct-head.nii.gz"
        write_nifti(ct_volume(args.size), nifti)
        scene_path = tmp / "ct-head.toml"
        scene(nifti, scene_path)
        display = free_display()
        xvfb = subprocess.Popen(["Xvfb", f":{display}", "-screen", "0", "1280x800x24"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            time.sleep(1.0)
            front, side = tmp / "anterior.png", tmp / "left.png"
            shot(args.dvr, scene_path, "anterior", front, display)
            shot(args.dvr, scene_path, "left", side, display)
        finally:
            xvfb.kill()
        out = pathlib.Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        from PIL import Image

        a, b = Image.open(front), Image.open(side)
        both = Image.new("RGB", (a.width + b.width, max(a.height, b.height)))
        both.paste(a, (0, 0))
        both.paste(b, (a.width, 0))
        both.save(out)
    print(f"ct_views: wrote {out}")


if __name__ == "__main__":
    sys.exit(main())
