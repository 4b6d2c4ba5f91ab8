"""dvr: Monte Carlo direct volume rendering with temporal denoising, on Vulkan.

Volumes in as numpy arrays (indexed ``[z, y, x]``), frames out as ``(h, w, 3)`` float32
linear radiance, scores from :mod:`dvr.metrics` equal to what ``dvr eval`` reports::

    import numpy as np, dvr
    vol = dvr.Volume(np.load("ct.npy"), spacing=(1.0, 0.7, 0.7))
    r = dvr.Renderer(dvr.Scene(vol, tf="phantom-opaque"), size=(128, 128), denoisers=["ours", "svgf"])
    for _ in range(16):
        out = r.render()          # a still view keeps refining
    r.orbit(40, 0)                # an edit: the next frames reproject it
    r.lights[0].intensity = 30
    out = r.render()
    ref = r.reference(spp=256)    # of the current view
    print(dvr.metrics.psnr(ref, out["ours"]))

A scripted animation renders with ``r.render(frame=k)`` for k in order, as ``dvr capture``
does; :class:`dvr.Viewer` shows a live renderer in a notebook cell.
"""

from . import _native, metrics
from ._native import Volume
from .scene import (
    AreaLight,
    Camera,
    ClipPlane,
    CropBox,
    EnvironmentLight,
    PointLight,
    Scene,
    TransferFunction,
    builtin_scenes,
)
from .live import CameraView, LightsView, LightView, SettingsView
from .renderer import Renderer, denoisers

__all__ = [
    "AreaLight",
    "Camera",
    "CameraView",
    "ClipPlane",
    "CropBox",
    "EnvironmentLight",
    "LightView",
    "LightsView",
    "PointLight",
    "Renderer",
    "Scene",
    "SettingsView",
    "TransferFunction",
    "Viewer",
    "Volume",
    "builtin_scenes",
    "denoisers",
    "load_volume",
    "metrics",
]


def __getattr__(name):
    # dvr.Viewer imports anywidget (the notebook extra) only when it is used.
    if name == "Viewer":
        from .viewer import Viewer

        return Viewer
    raise AttributeError(f"module 'dvr' has no attribute {name!r}")


def load_volume(path, gpu_memory=None) -> Volume:
    """Load a volume file as the CLI does: NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr),
    DICOM (a folder or a .dcm file), OME-Zarr (an image folder: its finest level that
    a volume in memory holds and, with ``gpu_memory`` ("512M"), that fits that budget;
    or one level's folder inside it) or raw data with a ``<file>.json``/``.toml``
    sidecar."""
    return Volume.load(str(path), None if gpu_memory is None else str(gpu_memory))
