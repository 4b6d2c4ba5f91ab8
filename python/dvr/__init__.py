"""dvr: Monte Carlo direct volume rendering with temporal denoising, on Vulkan.

Volumes in as numpy arrays (indexed ``[z, y, x]``), frames out as ``(h, w, 3)`` float32
linear radiance, scores from :mod:`dvr.metrics` equal to what ``dvr eval`` reports::

    import numpy as np, dvr
    vol = dvr.Volume(np.load("ct.npy"), spacing=(1.0, 0.7, 0.7))
    r = dvr.Renderer(dvr.Scene(vol, tf="phantom-opaque"), size=(128, 128), denoisers=["ours", "svgf"])
    for _ in range(16):
        out = r.render()          # a still view keeps refining
    r.orbit(20, 0)                # an edit (degrees): the next frames reproject it
    r.lights[0].intensity = 30
    out = r.render()
    ref = r.reference(spp=256)    # of the current view
    print(dvr.metrics.psnr(ref, out["ours"]))

A scripted animation renders with ``r.render(frame=k)`` for k in order, as ``dvr capture``
does; :class:`dvr.Viewer` shows a live renderer in a notebook cell.
"""

import pathlib as _pathlib

from . import _native

# The wheel carries the presets, the MRI and the networks (python/dvr/assets links
# to the repository's assets/, followed when the wheel is built): the engine reads them
# from here, not from the checkout it was built in. $DVR_ASSETS still overrides.
_PACKAGED_ASSETS = _pathlib.Path(__file__).resolve().parent / "assets"
if (_PACKAGED_ASSETS / "transfer").is_dir():
    _native.set_assets_dir(str(_PACKAGED_ASSETS))

from . import metrics  # noqa: E402
from ._native import DataDroppedWarning, Volume  # noqa: E402
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
from .live import CameraView, FieldError, LightsView, LightView, SettingsView
from .renderer import Renderer, denoisers

__all__ = [
    "AreaLight",
    "Camera",
    "CameraView",
    "ClipPlane",
    "CropBox",
    "DataDroppedWarning",
    "FieldError",
    "EnvironmentLight",
    "LightView",
    "LightsView",
    "PointLight",
    "Renderer",
    "Scene",
    "SettingsView",
    "TransferFunction",
    "Viewer",
    "assets_dir",
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


def assets_dir() -> _pathlib.Path:
    """The folder the presets, the bundled MRI and the RAE networks are read from: the
    wheel's own copy, or ``$DVR_ASSETS`` when set."""
    return _pathlib.Path(_native.assets_dir())


def load_volume(path, gpu_memory=None) -> Volume:
    """Load a volume file as the CLI does: NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr),
    DICOM (a folder or a .dcm file), numpy's .npy (1 mm voxels), OME-Zarr (an image folder: its finest level that
    a volume in memory holds and, with ``gpu_memory`` ("512M"), that fits that budget;
    or one level's folder inside it) or raw data with a ``<file>.json``/``.toml``
    sidecar. The voxels come back in RAS order (x along +Right, y +Anterior, z
    +Superior, whatever the file's orientation: a flipped affine renders mirrored).
    What a loader drops (extra channels or time points) raises a
    :class:`DataDroppedWarning`."""
    return Volume.load(str(path), None if gpu_memory is None else str(gpu_memory), _stacklevel=2)
