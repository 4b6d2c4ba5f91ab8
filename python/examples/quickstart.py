"""Quickstart: the bundled MRI loaded with nibabel, 16 frames of an orbit denoised by
`ours`, a PNG strip (noisy / ours / reference of the last frame) and PSNR against a
256-spp reference. Runs on lavapipe in about a minute.

    python python/examples/quickstart.py [out.png]
"""

import pathlib
import sys

import nibabel
import numpy as np

import dvr

root = pathlib.Path(__file__).resolve().parents[2]
img = nibabel.load(str(root / "assets/volumes/mni152_t1.nii.gz"))
# nibabel indexes [x, y, z]; dvr takes [z, y, x] with spacing in the same order.
data = np.ascontiguousarray(np.asarray(img.dataobj).transpose(2, 1, 0))
spacing = tuple(float(s) for s in reversed(img.header.get_zooms()[:3]))
volume = dvr.Volume(data, spacing=spacing, name="mni152")
print(volume)

scene = dvr.Scene(volume, tf=dvr.TransferFunction.preset("mri-opaque"), frames=16)
scene.camera = dvr.Camera(position=(0.45, 1.5, 0.35))
scene.orbit(degrees_per_frame=2.0)

renderer = dvr.Renderer(scene, size=(128, 128), spp=2, denoisers=["ours"])
print(f"{renderer.device}: {renderer.frames} frames at {renderer.size}, {renderer.spp} spp")
for frame in range(scene.frames):
    out = renderer.render(frame)
reference = renderer.reference(spp=256)

print(f"last frame, PSNR against a 256-spp reference: noisy {dvr.metrics.psnr(reference, out['noisy']):.2f} dB, "
      f"ours {dvr.metrics.psnr(reference, out['ours']):.2f} dB")
print("GPU ms per pass:", {k: round(v, 2) for k, v in renderer.timings().items()})

strip = np.concatenate([dvr.metrics.tonemap(x) for x in (out["noisy"], out["ours"], reference)], axis=1)
path = sys.argv[1] if len(sys.argv) > 1 else "quickstart.png"
try:
    from PIL import Image

    Image.fromarray((strip * 255 + 0.5).astype(np.uint8)).save(path)
except ImportError:  # numpy alone: a binary PPM instead
    path = str(pathlib.Path(path).with_suffix(".ppm"))
    h, w, _ = strip.shape
    with open(path, "wb") as f:
        f.write(b"P6 %d %d 255\n" % (w, h) + (strip * 255 + 0.5).astype(np.uint8).tobytes())
print("wrote", path)
