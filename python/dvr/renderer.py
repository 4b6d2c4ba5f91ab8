"""The renderer: a live view of a scene on one Vulkan device, edited between frames."""

import threading
import warnings

import numpy as np

from . import _native
from .channels import Channel
from .labels import Labels
from .live import CameraView, ClipsView, CropView, LightsView, SettingsView, _as_dict, _plain
from .scene import Scene, TransferFunction

# The explorer's left drag turns the camera 0.01 radians per pixel (engine/src/session).
_RADIANS_PER_PIXEL = 0.01

__all__ = ["Renderer", "denoisers"]


def denoisers() -> dict:
    """The names :class:`Renderer` accepts in ``denoisers`` (the CLI's ``--denoiser``
    names), each with its one-line description."""
    return dict(_native.denoiser_names())


class Renderer:
    """Renders ``scene`` (a :class:`Scene`, a :class:`Volume` or a numpy array, both
    with :class:`Scene`'s defaults, a built-in scene name or a scene file) at ``size`` = (width, height) with ``spp`` samples per pixel per
    frame (default: the scene's) and runs each of ``denoisers`` on the same noisy
    frames. ``motion`` is what the temporal denoisers reproject with (``"features"`` or
    ``"first-hit"``, as the CLI's ``--motion``).

    A renderer is a live view, driven like the explorer: :meth:`render` renders the
    current view for as long as it is called (a still view keeps refining), and
    :attr:`camera`, :attr:`lights`, :attr:`tf`, :attr:`settings` and :attr:`denoisers`
    are its live state. Assigning one (or a field of one: ``r.camera.position = ...``,
    ``r.lights[0].intensity = 30``, ``r.settings.spp = 2``) is an edit that the next
    render reprojects rather than restarts; :meth:`orbit`, :meth:`pan` and :meth:`zoom`
    move the camera with the explorer's mouse semantics. ``render(frame=k)`` first sets
    the view to the scene's animation at frame k: rendering frames 0..n in order renders
    the animation exactly as ``dvr capture`` and ``dvr eval`` do.

    Calls from several threads serialise on the renderer's lock; the GIL is released
    while the device works. :meth:`close` (or ``with Renderer(...) as r:``) frees the
    device memory at once.

    ``device`` picks the Vulkan device by a substring of its name; by default it is the
    one the CLI picks (a discrete GPU first; ``DVR_DEVICE`` forces one). Without a
    Vulkan device, or with none of that name, this raises ``RuntimeError``.

    ``gpu_memory`` (``"512M"``, ``"2G"``, a byte count as a string) is the volume's
    budget on the device, as the CLI's ``--gpu-memory``: past it the volume is paged
    through the brick pool (:attr:`volume_residency` says how it is held).
    """

    def __init__(
        self, scene, size=(128, 128), spp=None, denoisers=("ours",), motion="features", device=None,
        gpu_memory=None,
    ):
        if isinstance(scene, str):
            scene = Scene.builtin(scene) if scene in _native.builtin_scene_names() else Scene.load(scene)
        elif isinstance(scene, (np.ndarray, _native.Volume)):
            # A volume alone is a scene with the defaults (Volume checks the array).
            scene = Scene(scene)
        elif not isinstance(scene, Scene):
            raise TypeError(
                f"Renderer: expected a Scene, a Volume, a numpy array, a built-in scene name or a scene "
                f"file, got {type(scene).__name__}"
            )
        if isinstance(denoisers, str):
            denoisers = [denoisers]
        size = _size(size)
        self.scene = scene
        tf = scene.tf.to_dict() if getattr(scene, "tf", None) is not None else None
        # Edits that read the view, change one part and write it back hold this, so two
        # threads editing different parts lose neither edit.
        self._edit = threading.Lock()
        self._r = _native.Renderer(
            scene._engine_dict(), size, list(denoisers), volume=scene.volume, tf=tf, spp=spp, motion=motion,
            device=device, gpu_memory=None if gpu_memory is None else str(gpu_memory),
        )
        _warn_unused_overrides(self.denoisers)

    # Rendering.

    def render(self, frame=None, reset=False, aux=False, features=False) -> dict:
        """Renders the current view (with ``frame``: the scene's animation at that frame)
        and returns ``{"noisy": img, "<denoiser>": img, ...}``, each ``(h, w, 3)``
        float32 linear radiance; with ``aux=True`` also ``"albedo"`` and ``"normal"``
        (the guides single-frame denoisers such as OIDN take); with ``features=True``
        also ``"features"``: ``{"position", "normal", "albedo"}``, each ``(h, w, 4)``
        (the opacity-threshold surface the temporal denoisers reproject with: world
        position with w = 1 where the ray met that surface or, through semi-transparent
        medium, at the expected first collision; normal with w = the distance along the
        ray and TF albedo with w = 1, both on the threshold surface only).
        ``reset=True`` is a cut: every history restarts."""
        return self._r.render(frame, reset, aux, features)

    def reference(self, frame=None, spp=1024):
        """A high-sample reference from its own sample stream: of the current view, or
        with ``frame`` of the scene's animation at that frame (what ``dvr reference``
        writes for it), leaving the view as it is."""
        return self._r.reference(frame, spp)

    def timings(self) -> dict:
        """GPU milliseconds per pass of the last rendered frame."""
        return self._r.timings()

    # The live state.

    @property
    def camera(self) -> CameraView:
        """The camera, live (assign a :class:`dvr.Camera`, a dict, or a field)."""
        return CameraView(lambda: self._r.view()["camera"], lambda d: self._put("camera", d), "camera")

    @camera.setter
    def camera(self, camera):
        self._put("camera", _as_dict(camera, "camera"))

    @property
    def lights(self) -> LightsView:
        """The lights, live (assign a list of light objects or dicts, or a field of
        one: ``r.lights[0].intensity = 30``)."""
        return LightsView(lambda: self._r.view().get("light", []), lambda l: self._put("light", l))

    @lights.setter
    def lights(self, lights):
        self._put("light", [_as_dict(l, "light") for l in lights])

    @property
    def clip(self) -> ClipsView:
        """The clip planes, live (at most 6; each removes the half-space behind its
        normal): ``r.clip.append(dvr.ClipPlane((0, 0, 0.05), (0, 0, 1)))``,
        ``r.clip[0].point = (...)``, ``r.clip[0].enabled = False``, ``r.clip = []``."""
        return ClipsView(lambda: self._r.view().get("clip", []), lambda l: self._put("clip", l))

    @clip.setter
    def clip(self, planes):
        self._put("clip", [_as_dict(p, "clip plane") for p in planes])

    @property
    def crop(self):
        """The crop box, live (a :class:`dvr.live.CropView`), or None; assign a
        :class:`dvr.CropBox`, a dict or None."""
        if self._r.view().get("crop") is None:
            return None
        return CropView(lambda: self._r.view()["crop"], lambda d: self._put("crop", d), "crop")

    @crop.setter
    def crop(self, crop):
        self._put("crop", None if crop is None else _as_dict(crop, "crop box"))

    @property
    def settings(self) -> SettingsView:
        """The render settings, live (``r.settings.spp = 2``; a change restarts every
        history)."""
        return SettingsView(lambda: self._r.view().get("render", {}), lambda d: self._put("render", d), "settings")

    @settings.setter
    def settings(self, settings):
        self._put("render", _as_dict(settings, "settings"))

    @property
    def tf(self) -> TransferFunction:
        """The transfer function in effect, immutable (assign a preset name, a TF file
        path, a :class:`dvr.TransferFunction` or an ``(N, 5)`` array of ``density, r,
        g, b, opacity`` rows to change it; ``r.tf.copy()`` is an editable copy)."""
        d = self._r.tf()
        return TransferFunction._frozen(d["a"]["point"], d["a"].get("name", "tf"), d["a"].get("units", "density"))

    @tf.setter
    def tf(self, tf):
        self._r.set_tf(TransferFunction.coerce(tf).to_dict())

    @property
    def time(self) -> float:
        """The time point of a series shown (fractional: the two around it interpolated,
        so playback can be smooth and slow); 0 for a volume of one time point. Assigning
        it is an edit the next render follows (``ValueError`` names the range)."""
        return self._r.time()[0]

    @time.setter
    def time(self, t):
        self._r.set_time(float(t))

    @property
    def times(self) -> int:
        """How many time points the volume has."""
        return self._r.time()[1]

    @property
    def channels(self) -> list:
        """The channels of a multi-channel medium (empty for one field), each a live
        :class:`~dvr.channels.Channel`: ``r.channels[1].visible = False``."""
        return [Channel(self._r, i) for i in range(len(self._r.channels()))]

    @property
    def labels(self) -> Labels:
        """The labels of the scene's label map (``[labels]``; empty without one), by
        value, each a live :class:`~dvr.labels.Label`: ``r.labels[3].visible = False``,
        ``r.labels.hide_all()``."""
        return Labels(self._r)

    def pick(self, x, y):
        """What lies under pixel ``(x, y)`` (row 0 at the top) at the features pass's first
        hit: a dict with ``position`` (world), ``voxel``, ``intensity`` (data units),
        ``label`` (0: none) and ``label_name``; ``None`` where the ray meets nothing.
        Renders one frame of the current view to find it."""
        return self._r.pick(int(x), int(y))

    @property
    def denoisers(self) -> tuple:
        """The denoisers this renderer runs, in order (assign a list to change them:
        every history restarts)."""
        return tuple(self._r.denoisers)

    @denoisers.setter
    def denoisers(self, names):
        if isinstance(names, str):
            names = [names]
        self._r.set_denoisers([str(n) for n in names])
        _warn_unused_overrides(self.denoisers)

    @property
    def size(self) -> tuple:
        """(width, height); assign to render at another size (histories restart)."""
        return tuple(self._r.size)

    @size.setter
    def size(self, size):
        self._r.resize(*_size(size))

    def orbit(self, degrees_x, degrees_y=0.0):
        """Orbits the camera about its target by ``degrees_x`` about the up axis, the
        way :meth:`Scene.orbit`'s positive degrees turn it (counter-clockwise seen from
        above), and ``degrees_y`` of elevation (positive as a downward drag moves it)."""
        scale = np.radians(1.0) / _RADIANS_PER_PIXEL
        # A drag to the right turns the other way round from the scene's orbit.
        self._r.orbit(-float(degrees_x) * scale, float(degrees_y) * scale)

    def orbit_pixels(self, dx, dy=0.0):
        """Orbits as a left drag of (dx, dy) pixels in the explorer does (0.01 radians
        per pixel): what a mouse-driven view (:class:`dvr.Viewer`) calls."""
        self._r.orbit(float(dx), float(dy))

    def pan(self, dx, dy):
        """Moves the camera as a right-drag of (dx, dy) pixels does: the point under the
        cursor follows it."""
        self._r.pan(float(dx), float(dy))

    def zoom(self, steps):
        """Wheel steps: positive zooms in (each step divides the distance by 1.1)."""
        self._r.zoom(float(steps))

    def reset_camera(self):
        """Back to the camera the renderer started with."""
        self._r.reset_camera()

    def fit(self):
        """Flies to fit the volume, keeping the viewing direction."""
        self._r.fit()

    # Where each named side's camera sits (a unit vector from the target) and its up
    # vector, in world space = patient RAS (+x Right, +y Anterior, +z Superior). The
    # up vectors follow the radiological convention, the patient's right on the
    # screen's left, wherever that is a free choice: the anterior view (facing the
    # patient) and the inferior view (from the feet, anterior up, as axial slices are
    # read) give it by themselves; the superior view looks down with anterior at the
    # bottom so the right stays on the left. The posterior, left and right views have
    # +z up, so the patient's right is necessarily on the screen's right from behind.
    VIEWS = {
        "anterior": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
        "posterior": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
        "left": ((-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
        "right": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
        "superior": ((0.0, 0.0, 1.0), (0.0, -1.0, 0.0)),
        "inferior": ((0.0, 0.0, -1.0), (0.0, 1.0, 0.0)),
    }

    def view_from(self, side, elevation=0.0, azimuth=0.0):
        """Moves the camera to look at its target from ``side`` (``"anterior"``,
        ``"posterior"``, ``"left"``, ``"right"``, ``"superior"`` or ``"inferior"``: the
        patient's side, world space being RAS), keeping the target and the distance;
        then turns it ``azimuth`` degrees about the view's up vector and ``elevation``
        degrees toward it. One edit: temporal denoisers reproject across it."""
        if side not in self.VIEWS:
            raise ValueError(f"view_from: side={side!r}, expected one of {', '.join(self.VIEWS)}")
        for name, v in (("elevation", elevation), ("azimuth", azimuth)):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
                raise ValueError(f"view_from: {name}={v!r} must be a finite number of degrees")
        if abs(elevation) >= 90:
            # At ±90° the view direction is the up vector: no camera basis.
            raise ValueError(f"view_from: elevation={elevation!r} must be within (-90, 90) degrees")
        direction, up = (np.array(v) for v in self.VIEWS[side])
        with self._edit:
            view = self._r.view()
            cam = view["camera"]
            target = np.asarray(cam["target"], dtype=np.float64)
            distance = float(np.linalg.norm(np.asarray(cam["position"], dtype=np.float64) - target))
            a, e = np.radians(float(azimuth)), np.radians(float(elevation))
            side_axis = np.cross(up, direction)
            d = np.cos(e) * (np.cos(a) * direction + np.sin(a) * side_axis) + np.sin(e) * up
            new_up = up if e == 0 else np.cross(np.cross(d, up), d)
            cam["position"] = (target + distance * d).tolist()
            cam["up"] = (new_up / np.linalg.norm(new_up)).tolist()
            self._r.set_view(view)

    # The rest.

    def histogram(self) -> np.ndarray:
        """Counts of the volume's normalised densities in 256 equal bins over [0, 1]
        (what a TF editor draws behind its curve)."""
        return np.asarray(self._r.histogram(), dtype=np.int64)

    def gpu_memory(self) -> dict:
        """Device memory this renderer holds, bytes: ``{"allocated": ..., "reserved":
        ...}`` (live allocations; the allocator's memory blocks, free room included). A
        long session whose figures keep growing leaks device memory."""
        allocated, reserved = self._r.gpu_memory()
        return {"allocated": allocated, "reserved": reserved}

    def close(self):
        """Frees the device memory now; the renderer is unusable after."""
        self._r.close()

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` has run (a closed renderer renders nothing more)."""
        return self._r.closed

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @property
    def frames(self) -> int:
        """Frames in the scene's animation (what ``render(frame=k)`` plays)."""
        return self._r.frames

    @property
    def frames_rendered(self) -> int:
        """Frames rendered so far (what the temporal denoisers have seen)."""
        return self._r.frames_rendered

    @property
    def device(self) -> str:
        """The Vulkan device it renders on (e.g. ``"llvmpipe (LLVM 15.0.6, 256 bits)"``)."""
        return self._r.device

    @property
    def volume_residency(self) -> str:
        """``"dense volume"``, or the brick pool's ``"brick pool: R of V visible bricks
        resident (S slots of 32³), coarse level L (dims)"`` (visible under the TF of the
        last rendered frame; 0 of 0 before the first)."""
        return self._r.volume_residency

    @property
    def spp(self) -> int:
        """Samples per pixel per frame."""
        return self._r.spp

    def _put(self, section, value):
        with self._edit:
            view = self._r.view()
            if value is None:
                view.pop(section, None)
            else:
                view[section] = _plain(value)
            self._r.set_view(view)

    def __repr__(self):
        return f"Renderer({self.scene.name!r}, size={self.size}, denoisers={self.denoisers})"


def _warn_unused_overrides(running):
    for message in _native.unused_overrides(list(running)):
        warnings.warn(message, RuntimeWarning, stacklevel=3)


def _size(size):
    try:
        w, h = size
    except (TypeError, ValueError):
        raise ValueError(f"size: expected (width, height), got {size!r}") from None
    for name, v in (("width", w), ("height", h)):
        try:
            whole = not isinstance(v, bool) and float(v).is_integer()
        except (TypeError, ValueError):
            whole = False
        if not whole:
            raise ValueError(f"size: {name} must be a whole number of pixels, got {v!r}")
    return int(w), int(h)
