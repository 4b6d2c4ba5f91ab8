"""The renderer: a scene at one size with its denoisers on one Vulkan device."""

from . import _native
from .scene import Scene

__all__ = ["Renderer", "denoisers"]

def denoisers() -> dict:
    """The names :class:`Renderer` accepts in ``denoisers`` (the CLI's ``--denoiser``
    names), each with its one-line description."""
    return dict(_native.denoiser_names())


class Renderer:
    """Renders ``scene`` at ``size`` = (width, height) with ``spp`` samples per pixel per
    frame (default: the scene's) and runs each of ``denoisers`` on the same noisy
    frames. The temporal state lives here: calling :meth:`render` for frames 0..n in
    order renders the animation. ``motion`` is what the temporal denoisers reproject
    with (``"features"`` or ``"first-hit"``, as the CLI's ``--motion``).

    ``device`` picks the Vulkan device by a substring of its name; by default it is the
    one the CLI picks (a discrete GPU first; ``DVR_DEVICE`` forces one). Without a
    Vulkan device, or with none of that name, this raises ``RuntimeError``.

    ``gpu_memory`` (``"512M"``, ``"2G"``, a byte count as a string) is the volume's
    budget on the device, as the CLI's ``--gpu-memory``: past it the volume is paged
    through the brick pool (:attr:`volume_residency` says how it is held).
    """

    def __init__(
        self, scene: Scene, size=(128, 128), spp=None, denoisers=("ours",), motion="features", device=None,
        gpu_memory=None,
    ):
        if isinstance(scene, str):
            scene = Scene.builtin(scene) if scene in _native.builtin_scene_names() else Scene.load(scene)
        if isinstance(denoisers, str):
            denoisers = [denoisers]
        size = tuple(int(x) for x in size)
        if len(size) != 2:
            raise ValueError(f"size: expected (width, height), got {size!r}")
        self.scene = scene
        tf = scene.tf.to_dict() if getattr(scene, "tf", None) is not None else None
        self._r = _native.Renderer(
            scene._engine_dict(), size, list(denoisers), volume=scene.volume, tf=tf, spp=spp, motion=motion,
            device=device, gpu_memory=None if gpu_memory is None else str(gpu_memory),
        )

    def render(self, frame=None, reset=False, aux=False, features=False) -> dict:
        """Renders animation frame ``frame`` (default: the next) and returns
        ``{"noisy": img, "<denoiser>": img, ...}``, each ``(h, w, 3)`` float32 linear
        radiance; with ``aux=True`` also ``"albedo"`` and ``"normal"`` (the guides
        single-frame denoisers such as OIDN take); with ``features=True`` also
        ``"features"``: ``{"position", "normal", "albedo"}``, each ``(h, w, 4)`` (the
        opacity-threshold surface the temporal denoisers reproject with: world position
        with w = 1 where the ray met that surface or, through semi-transparent medium,
        at the expected first collision; normal with w = the distance along the ray and
        TF albedo with w = 1, both on the threshold surface only). ``reset=True`` is a
        cut."""
        return self._r.render(frame, reset, aux, features)

    def reference(self, frame=None, spp=1024):
        """A high-sample reference of ``frame`` (default: the last rendered), from its
        own sample stream: what ``dvr reference`` writes for that frame."""
        return self._r.reference(frame, spp)

    def timings(self) -> dict:
        """GPU milliseconds per pass of the last rendered frame."""
        return self._r.timings()

    @property
    def frames(self) -> int:
        return self._r.frames

    @property
    def denoisers(self) -> list:
        return self._r.denoisers

    @property
    def device(self) -> str:
        return self._r.device

    @property
    def volume_residency(self) -> str:
        """``"dense volume"``, or the brick pool's ``"brick pool: R of V visible bricks
        resident (S slots of 32³), coarse level L (dims)"`` (visible under the TF of the
        last rendered frame; 0 of 0 before the first)."""
        return self._r.volume_residency

    @property
    def spp(self) -> int:
        return self._r.spp

    @property
    def size(self) -> tuple:
        return self._r.size
