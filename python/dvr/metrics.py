"""The scores ``dvr eval`` reports, on numpy images.

Every function takes linear radiance, ``(h, w, 3)`` float32 (what
:meth:`dvr.Renderer.render` returns), and tone-maps it with the eval's tone map and
exposure before comparing, so a score here equals the eval's for the same frames.
"""

import numpy as np

from . import _native

__all__ = ["psnr", "ssim", "flip", "temporal_error", "tonemap"]


def _image(a, name):
    a = np.asarray(a)
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"{name}: expected an (h, w, 3) image, got shape {a.shape}")
    if a.dtype != np.float32:
        if not np.issubdtype(a.dtype, np.floating):
            raise ValueError(f"{name}: expected linear float radiance, got dtype {a.dtype}")
        a = a.astype(np.float32)
    return np.ascontiguousarray(a)


def psnr(reference, test) -> float:
    """PSNR in dB of ``test`` against ``reference`` (display values; identical images
    are capped as in the eval)."""
    return _native.psnr(_image(reference, "reference"), _image(test, "test"))


def ssim(reference, test) -> float:
    """SSIM of ``test`` against ``reference`` (display values)."""
    return _native.ssim(_image(reference, "reference"), _image(test, "test"))


def flip(reference, test) -> float:
    """Mean LDR-FLIP error of ``test`` against ``reference`` (the eval's viewing
    distance; checked against NVIDIA's flip-evaluator)."""
    return _native.flip(_image(reference, "reference"), _image(test, "test"))


def temporal_error(prev_test, test, prev_reference, reference) -> float:
    """Mean absolute difference between the method's frame-to-frame change and the
    reference's: flicker and lag that per-frame scores do not see."""
    return _native.temporal_error(
        _image(prev_test, "prev_test"),
        _image(test, "test"),
        _image(prev_reference, "prev_reference"),
        _image(reference, "reference"),
    )


def tonemap(image) -> np.ndarray:
    """The eval's tone map: linear radiance to sRGB display values in [0, 1] (what its
    PNGs hold). ``(tonemap(x) * 255 + 0.5).astype(np.uint8)`` is the PNG."""
    return _native.tonemap(_image(image, "image"))
