"""What :class:`dvr.Viewer`'s panel shows and takes, kept apart from the widget: values
from the page checked before they reach the renderer (the page is anyone's; a bad
value is refused with a reason, never a crash of the render thread), and what the panel
draws read from the renderer and its volume (the spp limit, data units, the
orientation letters, the scale bar)."""

import math
import os
import re
import warnings

import numpy as np

from . import _native

# At most this many control points in a TF edited in the browser.
MAX_TF_POINTS = 256
# The engine takes at most 6 clip planes (renderer.clip's limit).
MAX_CLIP_PLANES = 6
# A volume file is read a second time for its shape and spacing (the renderer keeps its
# own copy in the engine, which Python cannot see) only below this size.
_MAX_RELOAD_BYTES = 1 << 30


def number(value, limit):
    """A finite number within ±limit from a message, else None (refused)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    value = float(value)
    if not math.isfinite(value) or abs(value) > limit:
        return None
    return value


def _vector(value, limit=1e6):
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        return None
    out = [number(c, limit) for c in value]
    return None if any(c is None for c in out) else out


def tf_points(value):
    """Control points from the page with every field a TF file holds (density, opacity,
    diffuse, specular, emissive, roughness: the engine checks their ranges and names
    any bad value); None when the shape is wrong. Fields the page did not send take the
    engine's defaults, so an edit never drops a field it did not touch."""
    if not isinstance(value, list) or not 1 <= len(value) <= MAX_TF_POINTS:
        return None
    points = []
    for p in value:
        if not isinstance(p, dict) or set(p) - {"density", "opacity", "diffuse", "specular", "emissive", "roughness"}:
            return None
        point = {}
        for key in ("density", "opacity"):
            x = number(p.get(key), 1e6)
            if x is None:
                return None
            point[key] = x
        for key in ("diffuse", "specular", "emissive"):
            if key in p or key == "diffuse":
                v = _vector(p.get(key, [1.0, 1.0, 1.0]))
                if v is None:
                    return None
                point[key] = v
        if "roughness" in p:
            r = number(p["roughness"], 1e6)
            if r is None:
                return None
            point["roughness"] = r
        points.append(point)
    return points


def clip_planes(value):
    """Clip planes from the page (``[{"point", "normal", "enabled"}]``), or None."""
    if not isinstance(value, list) or len(value) > MAX_CLIP_PLANES:
        return None
    planes = []
    for p in value:
        if not isinstance(p, dict) or set(p) - {"point", "normal", "enabled"}:
            return None
        point, normal = _vector(p.get("point"), 10.0), _vector(p.get("normal"), 10.0)
        if point is None or normal is None or math.hypot(*normal) < 1e-6:
            return None
        enabled = p.get("enabled", True)
        if not isinstance(enabled, bool):
            return None
        planes.append({"point": point, "normal": normal, "enabled": enabled})
    return planes


def crop_box(value):
    """A crop box from the page (``{"min", "max", "enabled"}`` in the box's units, -0.5
    to 0.5), ``{}`` for none, or None when malformed."""
    if value == {}:
        return {}
    if not isinstance(value, dict) or set(value) - {"min", "max", "enabled"}:
        return None
    lo, hi = _vector(value.get("min"), 0.5), _vector(value.get("max"), 0.5)
    enabled = value.get("enabled", True)
    if lo is None or hi is None or not isinstance(enabled, bool) or any(a >= b for a, b in zip(lo, hi)):
        return None
    return {"min": lo, "max": hi, "units": "box", "enabled": enabled}


def spp_limit(renderer):
    """The most samples per pixel per frame this renderer takes: the engine's scene limit
    and, below it, the device's (lavapipe takes 4 in one frame). The Python package
    exposes neither number, so both are read from the engine's own refusals: the scene
    check's ("1..=64") and, by setting that many on the renderer, the device's ("1 to 4
    samples per pixel per frame on ..."). The renderer's spp is put back after."""
    scene = renderer.scene._engine_dict()
    scene.setdefault("render", {})["spp"] = 0
    try:
        _native.check_scene(scene)
        return None  # an engine that takes 0 has changed its rule: no limit known
    except ValueError as e:
        m = re.search(r"1\.\.=(\d+)", str(e))
        if not m:
            return None
        limit = int(m.group(1))
    current = renderer.spp
    if current == limit:
        return limit
    try:
        renderer.settings.spp = limit
    except (ValueError, RuntimeError) as e:
        m = re.search(r"1 to (\d+) samples", str(e))
        return int(m.group(1)) if m else None
    renderer.settings.spp = current
    return limit


def volume_info(renderer):
    """``{"shape", "spacing", "window", "physical"}`` of the renderer's volume (shape
    and spacing in x, y, z order, spacing in mm as the engine's Volume has it, physical
    the longest extent in mm: the world box's 1 unit), or None when it cannot be read
    without a second full load of a large file."""
    volume = getattr(renderer.scene, "volume", None)
    if volume is None:
        source = renderer.scene._engine_dict().get("volume", {})
        if "builtin" in source:
            volume = _native.Volume.builtin(source["builtin"], *([source["size"]] if "size" in source else []))
        elif "file" in source and "dims" in source:
            # A raw file: its layout is in the scene; its values are not needed.
            dims, spacing = source["dims"], source.get("spacing", [1.0, 1.0, 1.0])
            return _info(tuple(dims), tuple(spacing), None)
        elif "file" in source or "files" in source:
            # A series (channels in one file or one per file, time points): its first
            # channel at its first time point has the grid the others share.
            path = source["file"] if "file" in source else source["files"][0]
            try:
                if os.path.getsize(path) > _MAX_RELOAD_BYTES:
                    return None
                with warnings.catch_warnings():
                    # That the read keeps one of them is no news here: the renderer has all.
                    warnings.simplefilter("ignore", _native.DataDroppedWarning)
                    volume = _native.Volume.load(path)
            except (OSError, ValueError):
                return None
        else:
            return None
    # The Python Volume reports (z, y, x); the world's axes are x, y, z.
    return _info(tuple(volume.shape[::-1]), tuple(volume.spacing[::-1]), tuple(volume.window))


def _info(shape, spacing, window):
    extent = [float(n) * float(s) for n, s in zip(shape, spacing)]
    return {
        "shape": [int(n) for n in shape],
        "spacing": [float(s) for s in spacing],
        "window": None if window is None else [float(window[0]), float(window[1])],
        "physical": max(extent),
    }


# World space is patient RAS: each axis's letters at its + and - ends.
_LETTERS = (("R", "L"), ("A", "P"), ("S", "I"))


def _letter(v):
    i = int(np.argmax(np.abs(v)))
    return _LETTERS[i][0 if v[i] > 0 else 1]


def camera_basis(camera):
    """(right, up, forward) of a camera dict, unit vectors in world space (the engine's:
    right = forward × up)."""
    pos, target = np.asarray(camera["position"], float), np.asarray(camera["target"], float)
    forward = target - pos
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(camera["up"], float))
    right /= np.linalg.norm(right)
    return right, np.cross(right, forward), forward


def orientation(camera):
    """The patient side each edge of the view faces: ``{"left", "right", "top",
    "bottom"}`` letters (R/L, A/P, S/I, of the world axis nearest that screen
    direction), and ``axes``: the world x, y, z axes projected on the screen (x right,
    y up) for a triad."""
    right, up, _ = camera_basis(camera)
    return {
        "right": _letter(right),
        "left": _letter(-right),
        "top": _letter(up),
        "bottom": _letter(-up),
        "axes": [[round(float(right[i]), 4), round(float(up[i]), 4)] for i in range(3)],
    }


def scale_bar(camera, height_px, width_px, mm_per_unit):
    """A scale bar for the plane through the camera's target facing it: ``{"mm",
    "fraction"}``, a round length (1, 2 or 5 × 10^k mm) about a quarter of the view's
    width, and the share of the width it spans. Exact at the target's depth only (a
    perspective view has no one scale)."""
    pos, target = np.asarray(camera["position"], float), np.asarray(camera["target"], float)
    distance = float(np.linalg.norm(target - pos))
    visible_units = 2.0 * distance * math.tan(math.radians(float(camera.get("fov_y_degrees", 40.0))) / 2.0)
    mm_per_px = visible_units * mm_per_unit / height_px
    wanted = 0.25 * width_px * mm_per_px
    k = 10.0 ** math.floor(math.log10(wanted))
    mm = max(m * k for m in (1, 2, 5) if m * k <= wanted)
    return {"mm": mm, "fraction": round(mm / mm_per_px / width_px, 5)}
