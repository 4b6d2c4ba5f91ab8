"""Scenes, transfer functions, cameras and lights: small Python classes over the dicts
that dvr's scene and TF files hold (``engine/scene/src/lib.rs`` documents every key).
The engine checks them with the code that checks files, so errors read as the CLI's."""

import copy
import types

import numpy as np

from . import _native
from .live import CameraView, ClipsView, CropView, FieldError, LightsView, _as_dict

__all__ = [
    "FieldError",
    "AreaLight",
    "Camera",
    "ClipPlane",
    "CropBox",
    "EnvironmentLight",
    "PointLight",
    "Scene",
    "TransferFunction",
    "builtin_scenes",
]


# The keys of a TF file's [[point]] (engine/scene/src/transfer/control_point.rs).
POINT_FIELDS = ("density", "opacity", "diffuse", "specular", "emissive", "roughness")


def _check_points(points):
    for i, p in enumerate(points):
        if not isinstance(p, dict):
            raise TypeError(f"transfer function point {i}: expected a dict, got {type(p).__name__}")
        for k in p:
            if k not in POINT_FIELDS:
                raise FieldError(f"transfer function point {i} has no field {k!r} (fields: {', '.join(POINT_FIELDS)})")


def _vec(v, n, name):
    a = np.asarray(v, dtype=np.float64).reshape(-1)
    if a.shape != (n,):
        raise ValueError(f"{name}: expected {n} numbers, got {v!r}")
    return [float(x) for x in a]


def builtin_scenes() -> list:
    """The built-in scene names (``"phantom/orbit"``, ``"mri/point-light"``, ...)."""
    return list(_native.builtin_scene_names())


class TransferFunction:
    """Control points mapping normalised density in [0, 1] (or, with
    ``units="data"``, the volume's data units: Hounsfield for CT, as the ``ct-*``
    presets are written) to opacity and colour.

    Build one from a preset (:meth:`preset`), a TF file (:meth:`load`) or an ``(N, 5)``
    array of ``density, r, g, b, opacity`` rows (:meth:`from_array`). ``points`` is the
    list of point dicts as a TF file holds them (``density``, ``opacity``, ``diffuse``,
    and optionally ``specular``, ``emissive``, ``roughness``), editable in place.
    """

    def __init__(self, points, name="python", units="density"):
        self.name = name
        if units not in ("density", "data"):
            raise ValueError(f"transfer function units: expected 'density' or 'data', got {units!r}")
        self.units = units
        _check_points(points)
        self.points = [dict(p) for p in points]
        _native.check_tf(self.to_dict())

    @classmethod
    def _frozen(cls, points, name, units="density"):
        """An immutable TF (what a renderer hands out: its TF changes only by
        assignment, so an edit of a copy must not look as if it applied)."""
        tf = cls(points, name, units)
        tf.points = tuple(types.MappingProxyType(dict(p)) for p in tf.points)
        object.__setattr__(tf, "_immutable", True)
        return tf

    def __setattr__(self, name, value):
        if getattr(self, "_immutable", False):
            raise AttributeError(
                "this transfer function is the renderer's, immutable: assign a new one to "
                "r.tf (tf.copy() is an editable copy)"
            )
        object.__setattr__(self, name, value)

    def copy(self) -> "TransferFunction":
        """An editable copy."""
        return TransferFunction([dict(p) for p in self.points], self.name, self.units)

    @classmethod
    def coerce(cls, tf) -> "TransferFunction":
        """A TF from what a user may hand over: a TransferFunction, a preset name, a TF
        file path, an ``(N, 5)`` array of ``density, r, g, b, opacity`` rows, or a TF
        dict (``{"name": ..., "point": [...]}``)."""
        if isinstance(tf, cls):
            return tf
        if isinstance(tf, str):
            if tf in _native.tf_preset_names():
                return cls.preset(tf)
            return cls.load(tf)
        if isinstance(tf, dict):
            if "point" not in tf:
                raise ValueError("transfer function: a TF dict needs a 'point' list")
            return cls(tf["point"], tf.get("name", "python"), tf.get("units", "density"))
        if hasattr(tf, "__fspath__"):
            return cls.load(tf)
        if isinstance(tf, (list, tuple, np.ndarray)):
            return cls.from_array(tf)
        raise TypeError(
            f"transfer function: expected a TransferFunction, a preset name, a file path or an (N, 5) array, "
            f"got {type(tf).__name__}"
        )

    @classmethod
    def preset(cls, name: str) -> "TransferFunction":
        """A shipped preset (see :meth:`presets`)."""
        d = _native.tf_preset(name)
        return cls(d["point"], d.get("name", name), d.get("units", "density"))

    @classmethod
    def load(cls, path) -> "TransferFunction":
        """A TF file (TOML, as in ``assets/transfer/``)."""
        d = _native.tf_file(str(path))
        return cls(d["point"], d.get("name", str(path)), d.get("units", "density"))

    @classmethod
    def from_array(cls, array, name="python") -> "TransferFunction":
        """From an ``(N, 5)`` array: each row ``density, r, g, b, opacity``, all in
        [0, 1], densities increasing."""
        a = np.asarray(array, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] != 5 or a.shape[0] < 1:
            raise ValueError(f"transfer function: expected an (N, 5) array of density, r, g, b, opacity, got shape {a.shape}")
        points = [
            {"density": float(r[0]), "diffuse": [float(r[1]), float(r[2]), float(r[3])], "opacity": float(r[4])}
            for r in a
        ]
        return cls(points, name)

    @staticmethod
    def presets() -> list:
        """The names of the shipped presets."""
        return list(_native.tf_preset_names())

    def to_dict(self) -> dict:
        """The TF as a TF file holds it: its name, units and control points."""
        d = {"name": self.name, "point": [dict(p) for p in self.points]}
        if self.units == "data":
            # Densities in the volume's data units (Hounsfield for CT): the engine maps
            # them through the volume's window when the scene is set up.
            d["units"] = "data"
        return d

    def __repr__(self):
        units = ", units='data'" if self.units == "data" else ""
        return f"TransferFunction({self.name!r}, {len(self.points)} points{units})"


class Camera:
    """A pinhole camera: eye ``position``, ``target``, ``up`` (+z by default, superior
    for medical volumes) and vertical field of view in degrees. World units: the
    volume's longest side spans 1, centred on the origin."""

    def __init__(self, position=(0.45, 1.5, 0.35), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), fov_y_degrees=40.0):
        self.position = _vec(position, 3, "camera position")
        self.target = _vec(target, 3, "camera target")
        self.up = _vec(up, 3, "camera up")
        self.fov_y_degrees = float(fov_y_degrees)

    def to_dict(self) -> dict:
        """The scene file's section this stands for, as a plain dict."""
        return {"position": self.position, "target": self.target, "up": self.up, "fov_y_degrees": self.fov_y_degrees}

    @classmethod
    def from_dict(cls, d) -> "Camera":
        return cls(**{k: d[k] for k in ("position", "target", "up", "fov_y_degrees") if k in d})

    def __repr__(self):
        return f"Camera(position={self.position}, target={self.target}, fov_y_degrees={self.fov_y_degrees})"


class PointLight:
    """A point light at ``position`` with linear RGB ``colour`` and ``intensity``."""

    def __init__(self, position, colour=(1.0, 1.0, 1.0), intensity=20.0):
        self.position = _vec(position, 3, "light position")
        self.colour = _vec(colour, 3, "light colour")
        self.intensity = float(intensity)

    def to_dict(self):
        """The scene file's section this stands for, as a plain dict."""
        return {"kind": "point", "position": self.position, "colour": self.colour, "intensity": self.intensity}


class AreaLight:
    """A rectangular area light at ``position`` facing ``target``, ``size`` = (w, h)."""

    def __init__(self, position, target=(0.0, 0.0, 0.0), size=(0.5, 0.5), colour=(1.0, 1.0, 1.0), intensity=60.0):
        self.position = _vec(position, 3, "light position")
        self.target = _vec(target, 3, "light target")
        self.size = _vec(size, 2, "light size")
        self.colour = _vec(colour, 3, "light colour")
        self.intensity = float(intensity)

    def to_dict(self):
        """The scene file's section this stands for, as a plain dict."""
        return {
            "kind": "area",
            "position": self.position,
            "target": self.target,
            "size": self.size,
            "colour": self.colour,
            "intensity": self.intensity,
        }


class EnvironmentLight:
    """Light from every direction: a constant ``colour``, or a ``top``/``bottom``
    gradient when both are given."""

    def __init__(self, colour=(1.0, 1.0, 1.0), intensity=0.25, top=None, bottom=None):
        self.colour = _vec(colour, 3, "environment colour")
        self.top = None if top is None else _vec(top, 3, "environment top")
        self.bottom = None if bottom is None else _vec(bottom, 3, "environment bottom")
        self.intensity = float(intensity)

    def to_dict(self):
        """The scene file's section this stands for, as a plain dict."""
        if self.top is not None and self.bottom is not None:
            return {"kind": "environment", "mode": "gradient", "top": self.top, "bottom": self.bottom, "intensity": self.intensity}
        return {"kind": "environment", "mode": "constant", "colour": self.colour, "intensity": self.intensity}


class ClipPlane:
    """A clip plane through ``point`` (world units) that removes the half-space behind
    ``normal``; switchable with ``enabled``."""

    def __init__(self, point, normal, enabled=True):
        self.point = _vec(point, 3, "clip plane point")
        self.normal = _vec(normal, 3, "clip plane normal")
        self.enabled = bool(enabled)

    def to_dict(self):
        """The scene file's section this stands for, as a plain dict."""
        return {"point": self.point, "normal": self.normal, "enabled": self.enabled}

    def __repr__(self):
        return f"ClipPlane(point={self.point}, normal={self.normal}, enabled={self.enabled})"


class CropBox:
    """A crop box: what is outside ``min``..``max`` is removed. Corners in the volume's
    frame (-0.5 to 0.5 along each axis, ``units="box"``) or in voxel indices
    (``units="voxels"``)."""

    def __init__(self, min=(-0.5, -0.5, -0.5), max=(0.5, 0.5, 0.5), units="box", enabled=True):
        self.min = _vec(min, 3, "crop min")
        self.max = _vec(max, 3, "crop max")
        self.units = str(units)
        self.enabled = bool(enabled)

    def to_dict(self):
        """The scene file's section this stands for, as a plain dict."""
        return {"min": self.min, "max": self.max, "units": self.units, "enabled": self.enabled}

    def __repr__(self):
        return f"CropBox(min={self.min}, max={self.max}, units={self.units!r}, enabled={self.enabled})"


def _light_dict(light):
    return light.to_dict() if hasattr(light, "to_dict") else dict(light)


class Scene:
    """A volume, a transfer function, a camera, lights, render settings and an
    animation: what a scene file holds.

    ``volume`` is a :class:`Volume`, a numpy array indexed ``[z, y, x]``, ``[c, z, y,
    x]`` (channels) or ``[t, c, z, y, x]`` (time points of channels) (as :class:`Volume`
    takes it, 1 mm voxels), a built-in dataset name or a volume file.
    ``Scene(volume)`` gives sensible defaults (a camera framing the volume, a key light
    and a soft environment, the ``phantom-opaque`` TF when none is given, one frame).
    ``Scene.builtin("phantom/orbit")`` and ``Scene.load("my.toml")`` open the CLI's
    scenes. ``data`` is the scene as a dict (the file's keys), editable; the engine
    checks it when a :class:`Renderer` is made (or on :meth:`check`).
    """

    def __init__(self, volume, tf=None, camera=None, lights=None, frames=1, density_scale=150.0, render=None, name="python"):
        from ._native import Volume

        if isinstance(volume, np.ndarray):
            # Volume checks the array (3-D to 5-D, a volume dtype) and says what is wrong.
            volume = Volume(volume)
        self.volume = None
        if isinstance(volume, Volume):
            self.volume = volume
            # The scene's own source is not used when a Volume is given (the renderer
            # takes the array); a built-in name keeps the dataset's RAE network.
            source = {"builtin": volume.name if volume.name in ("phantom", "cloud", "mri") else "cloud", "size": 8}
        elif isinstance(volume, str) and volume in ("phantom", "cloud", "mri"):
            source = {"builtin": volume}
        else:
            source = {"file": str(volume)}
        self.tf = tf if tf is not None else TransferFunction.preset("phantom-opaque")
        if isinstance(self.tf, str):
            self.tf = TransferFunction.preset(self.tf)
        lights = lights if lights is not None else [
            PointLight((-0.9, 1.1, 1.0), (1.0, 0.95, 0.9), 20.0),
            EnvironmentLight(top=(0.55, 0.65, 0.8), bottom=(0.2, 0.18, 0.15), intensity=0.25),
        ]
        self.data = {
            "name": name,
            "volume": dict(source, density_scale=float(density_scale)),
            "transfer": {"a": "phantom-opaque"},
            "camera": (camera or Camera()).to_dict(),
            "light": [_light_dict(l) for l in lights],
            "render": dict(render or {}),
            "animation": {"frames": int(frames)},
        }

    @classmethod
    def builtin(cls, name: str) -> "Scene":
        """A built-in scene, e.g. ``"phantom/orbit"`` (see :func:`builtin_scenes`)."""
        return cls._from_dict(_native.scene_dict(name))

    @classmethod
    def load(cls, path) -> "Scene":
        """A scene file (TOML; relative paths in it are relative to its folder)."""
        return cls._from_dict(_native.scene_dict(str(path)))

    @classmethod
    def _from_dict(cls, d) -> "Scene":
        s = cls.__new__(cls)
        s.volume = None
        s.tf = None  # the file's transfer.a (and .b) stay in data
        s.data = d
        return s

    @property
    def name(self) -> str:
        """The scene's name (reports and file names use it)."""
        return self.data.get("name", "python")

    @property
    def frames(self) -> int:
        """Frames in the scene's animation (settable)."""
        return int(self.data.get("animation", {}).get("frames", 1))

    @frames.setter
    def frames(self, n: int):
        self.data.setdefault("animation", {})["frames"] = int(n)

    @property
    def camera(self) -> CameraView:
        """The camera at rest, live: ``scene.camera.position = (...)`` edits the scene
        (assign a :class:`Camera` or a dict to replace it)."""

        def put(d):
            self.data["camera"] = dict(d)

        return CameraView(lambda: Camera.from_dict(self.data.get("camera", {})).to_dict(), put, "camera")

    @camera.setter
    def camera(self, camera):
        self.data["camera"] = _as_dict(camera, "camera")

    @property
    def lights(self) -> LightsView:
        """The lights, live: ``scene.lights[0].intensity = 30`` edits the scene (assign
        a list of light objects or dicts to replace them)."""

        def put(lights):
            self.data["light"] = [dict(l) for l in lights]

        return LightsView(lambda: self.data.get("light", []), put)

    @lights.setter
    def lights(self, lights):
        self.data["light"] = [_light_dict(l) for l in lights]

    @property
    def clip(self) -> ClipsView:
        """The clip planes at rest, live (assign a list of :class:`ClipPlane` or dicts)."""

        def put(planes):
            self.data["clip"] = [dict(p) for p in planes]

        return ClipsView(lambda: self.data.get("clip", []), put)

    @clip.setter
    def clip(self, planes):
        self.data["clip"] = [_as_dict(p, "clip plane") for p in planes]

    @property
    def crop(self):
        """The crop box at rest, live, or None (assign a :class:`CropBox`, a dict or
        None)."""
        if self.data.get("crop") is None:
            return None

        def put(d):
            self.data["crop"] = dict(d)

        return CropView(lambda: self.data["crop"], put, "crop")

    @crop.setter
    def crop(self, crop):
        if crop is None:
            self.data.pop("crop", None)
        else:
            self.data["crop"] = _as_dict(crop, "crop box")

    @property
    def render_settings(self) -> dict:
        """The ``[render]`` section (spp, max_bounces, estimator, phase, ...)."""
        return self.data.setdefault("render", {})

    def orbit(self, degrees_per_frame=1.5, start_degrees=0.0):
        """Animate the camera on an orbit about its target."""
        anim = self.data.setdefault("animation", {})
        anim["orbit"] = {"degrees_per_frame": float(degrees_per_frame), "start_degrees": float(start_degrees)}
        return self

    def check(self) -> dict:
        """Checks the scene as a scene file is checked; returns it with defaults filled
        in. Raises ``ValueError`` with the engine's message."""
        return _native.check_scene(self._engine_dict())

    def _engine_dict(self) -> dict:
        return copy.deepcopy(self.data)

    # What a scene has; assigning anything else is a mistyped field, not a new one.
    _FIELDS = ("volume", "tf", "data", "name", "frames", "camera", "lights", "clip", "crop", "render_settings")

    def __setattr__(self, name, value):
        if name not in Scene._FIELDS:
            raise FieldError(f"Scene has no field {name!r} (fields: {', '.join(Scene._FIELDS)})")
        object.__setattr__(self, name, value)

    def __getattr__(self, name):
        # Only reached when normal lookup fails: a mistyped field.
        if name.startswith("_"):
            raise AttributeError(name)
        raise FieldError(f"Scene has no field {name!r} (fields: {', '.join(Scene._FIELDS)})")

    def __repr__(self):
        return f"Scene({self.name!r}, frames={self.frames})"
