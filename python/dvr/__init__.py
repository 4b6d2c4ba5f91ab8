"""dvr: Monte Carlo direct volume rendering with temporal denoising, on Vulkan.

Volumes in as numpy arrays (indexed ``[z, y, x]``), frames out as ``(h, w, 3)`` float32
linear radiance, scores from :mod:`dvr.metrics` equal to what ``dvr eval`` reports::

    import numpy as np, dvr
    vol = dvr.Volume(np.load("ct.npy"), spacing=(1.0, 0.7, 0.7))
    scene = dvr.Scene(vol, tf=dvr.TransferFunction.preset("phantom-opaque"), frames=16)
    scene.orbit(degrees_per_frame=2.0)
    r = dvr.Renderer(scene, size=(128, 128), denoisers=["ours", "svgf"])
    frames = [r.render() for _ in range(scene.frames)]   # an animation, in order
    ref = r.reference(spp=256)                            # of the last frame
    print(dvr.metrics.psnr(ref, frames[-1]["ours"]))
"""

from . import _native, metrics
from ._native import Volume
from .scene import (
    AreaLight,
    Camera,
    EnvironmentLight,
    PointLight,
    Scene,
    TransferFunction,
    builtin_scenes,
)
from .renderer import Renderer, denoisers

__all__ = [
    "AreaLight",
    "Camera",
    "EnvironmentLight",
    "PointLight",
    "Renderer",
    "Scene",
    "TransferFunction",
    "Volume",
    "builtin_scenes",
    "denoisers",
    "load_volume",
    "metrics",
]


def load_volume(path, gpu_memory=None) -> Volume:
    """Load a volume file as the CLI does: NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr),
    DICOM (a folder or a .dcm file), OME-Zarr (an image folder: its finest level that
    a volume in memory holds and, with ``gpu_memory`` ("512M"), that fits that budget;
    or one level's folder inside it) or raw data with a ``<file>.json``/``.toml``
    sidecar."""
    return Volume.load(str(path), None if gpu_memory is None else str(gpu_memory))
