"""``dvr.Viewer``: a live renderer in a notebook cell (JupyterLab, Jupyter Notebook, VS
Code: anywhere ipywidgets render).

A thread renders the view for as long as the viewer is open: a still view keeps
refining. Each frame is tone-mapped and encoded (JPEG by default) and sent to the
browser only when the browser has shown the one before, so a lagging browser drops
frames instead of queueing them. Mouse drags, the wheel and the panel (TF editor,
denoiser switch, split view, spp) come back as messages; the thread applies the newest
of them before its next frame (drags are summed, never queued), as edits of the live
:class:`dvr.Renderer`, which the temporal denoisers reproject. The same renderer can be
edited from other cells (``v.renderer.lights[0].intensity = 30``) while the viewer runs.

The render thread stops when the viewer is closed (:meth:`Viewer.close`, or the
frontend closing its comm) or the kernel is interrupted while idle.
"""

import math
import pathlib
import signal
import threading
import time
import weakref

import numpy as np

try:
    import anywidget
    import traitlets
except ImportError as e:  # pragma: no cover - the notebook extra is missing
    raise ImportError(
        'dvr.Viewer needs the notebook extra: pip install "dvr[notebook]" (anywidget, ipywidgets)'
    ) from e

from . import _native
from .renderer import Renderer
from .scene import Scene, TransferFunction

__all__ = ["Viewer"]

_HERE = pathlib.Path(__file__).parent
# Drag and wheel amounts from the browser beyond these are refused (a drag of a
# million pixels is no drag); edits arrive as messages anyone on the page can send.
_MAX_DRAG = 10_000.0
_MAX_ZOOM = 100.0
# At most this many control points in a TF edited in the browser.
_MAX_TF_POINTS = 256
# A frame not acknowledged for this long is taken as lost (the view was closed or
# reloaded), so the next one may go.
_ACK_TIMEOUT_S = 2.0

_live = weakref.WeakSet()
_interrupt_lock = threading.Lock()
_interrupt_installed = False


class Viewer(anywidget.AnyWidget):
    """A live view of ``source`` in the cell: a :class:`dvr.Renderer` (edited live by
    the viewer and by the caller), or anything :class:`dvr.Renderer` takes (a
    :class:`dvr.Scene`, a built-in scene name, a :class:`dvr.Volume`), rendered at
    ``size`` with ``denoisers`` (the first is shown; ``split`` names one to show on
    the right). ``format`` is ``"jpeg"`` (with ``quality``) or ``"png"``.

    Left drag orbits, right drag pans, the wheel zooms (the explorer's mouse). The
    panel edits the TF (the opacity curve over the density histogram: drag a point,
    double-click to add one, shift-click to remove one; colour presets), picks the shown
    denoiser and a split view, sets spp, and shows the frame counter, frames per
    second, the latency of the last drag, and the GPU ms per pass.
    """

    _esm = (_HERE / "viewer.js").read_text(encoding="utf-8")
    _css = (_HERE / "viewer.css").read_text(encoding="utf-8")

    # State the panel shows and edits (synced with the browser).
    denoiser = traitlets.Unicode("ours").tag(sync=True)
    split = traitlets.Unicode("").tag(sync=True)
    split_position = traitlets.Float(0.5).tag(sync=True)
    spp = traitlets.Int(1).tag(sync=True)
    max_spp = traitlets.Int(4).tag(sync=True)
    preset = traitlets.Unicode("").tag(sync=True)
    tf_points = traitlets.List().tag(sync=True)
    status = traitlets.Unicode("").tag(sync=True)
    # Fixed for the viewer's life.
    methods = traitlets.List().tag(sync=True)
    presets = traitlets.List().tag(sync=True)
    histogram = traitlets.List().tag(sync=True)
    width = traitlets.Int(256).tag(sync=True)
    height = traitlets.Int(256).tag(sync=True)

    def __init__(self, source, size=(256, 256), denoisers=("ours",), split=None, format="jpeg", quality=85, **kwargs):
        if format not in ("jpeg", "png"):
            raise ValueError(f'format={format!r}: must be "jpeg" or "png"')
        if not isinstance(quality, int) or not 1 <= quality <= 100:
            raise ValueError(f"quality={quality!r}: must be 1 to 100")
        if isinstance(denoisers, str):
            denoisers = [denoisers]
        denoisers = list(denoisers)
        if not denoisers:
            raise ValueError("denoisers: name at least one (the shown one)")
        if isinstance(source, Renderer):
            renderer, self._owns = source, False
            shown = [d for d in renderer.denoisers] or ["none"]
        else:
            if not isinstance(source, (Scene, str)):
                source = Scene(source)
            names = denoisers + ([split] if split and split not in denoisers else [])
            renderer, self._owns = Renderer(source, size=size, denoisers=names, **kwargs), True
            shown = denoisers
        counts = renderer.histogram().astype(np.float64)
        tf = renderer.tf
        super().__init__(
            denoiser=shown[0],
            split=split or "",
            spp=renderer.spp,
            max_spp=max(4, renderer.spp),
            tf_points=[dict(p) for p in tf.points],
            preset=tf.name if tf.name in TransferFunction.presets() else "",
            methods=sorted(n for n in _native_names() if n != "none"),
            presets=TransferFunction.presets(),
            histogram=[round(float(math.log1p(c) / math.log1p(counts.max())), 4) if counts.max() > 0 else 0.0 for c in counts],
            width=renderer.size[0],
            height=renderer.size[1],
        )
        self.renderer = renderer
        self._format, self._quality = format, quality
        self._pending = _Pending()
        # The split's method may not run yet on a renderer handed in.
        self._pending.set("denoisers", (self.denoiser, self.split))
        self._stop = threading.Event()
        self._acked = threading.Event()
        self._acked.set()
        self._sent_at = 0.0
        self.on_msg(self._on_message)
        if self.comm is not None:
            self.comm.on_close(lambda _msg: self.close())
        self.observe(self._on_state, names=["denoiser", "split", "spp", "preset", "tf_points"])
        self._thread = threading.Thread(
            target=_render_loop, args=(weakref.ref(self), renderer, self._pending, self._stop, self._acked),
            name="dvr-viewer", daemon=True,
        )
        _live.add(self)
        _install_interrupt()
        self._thread.start()

    @property
    def running(self) -> bool:
        """Whether the render thread is alive."""
        return self._thread.is_alive()

    def close(self):
        """Stops the render thread, frees a renderer the viewer made, and closes the
        widget. Safe on a viewer whose construction failed part way (the widget's
        finaliser calls it)."""
        stop, thread = getattr(self, "_stop", None), getattr(self, "_thread", None)
        if stop is not None:
            stop.set()
        if thread is not None and thread.is_alive() and threading.current_thread() is not thread:
            thread.join(timeout=60)
        if getattr(self, "_owns", False) and getattr(self, "renderer", None) is not None:
            self.renderer.close()
            self.renderer = None
        _live.discard(self)
        super().close()

    # Browser to kernel.

    def _on_message(self, _widget, msg, _buffers):
        if not isinstance(msg, dict):
            return
        kind = msg.get("type")
        if kind == "ack":
            self._acked.set()
            return
        if kind in ("orbit", "pan"):
            dx, dy = _number(msg.get("dx"), _MAX_DRAG), _number(msg.get("dy"), _MAX_DRAG)
            if dx is None or dy is None:
                return
            self._pending.drag(kind, dx, dy, _seq(msg))
        elif kind == "zoom":
            steps = _number(msg.get("steps"), _MAX_ZOOM)
            if steps is not None:
                self._pending.drag("zoom", steps, 0.0, _seq(msg))
        elif kind in ("reset", "fit"):
            self._pending.set(kind, True, _seq(msg))

    def _on_state(self, change):
        name, value = change["name"], change["new"]
        if name == "tf_points":
            points = _tf_points(value)
            if points is None:
                self.status = "refused a transfer function from the page (not a list of control points)"
                return
            self._pending.set("tf", points)
        elif name == "preset":
            if value in self.presets:
                self._pending.set("preset", value)
        elif name in ("denoiser", "split"):
            if value and value not in self.methods:
                self.status = f"unknown denoiser {value!r}"
                return
            self._pending.set("denoisers", (self.denoiser, self.split))
        elif name == "spp":
            if isinstance(value, int) and 1 <= value <= self.max_spp:
                self._pending.set("spp", value)


class _Pending:
    """The newest edits from the browser, taken by the render thread before each frame.
    Drags and wheel steps are summed; every other edit keeps only its newest value, so
    nothing queues however fast the events come."""

    def __init__(self):
        self._lock = threading.Lock()
        self._edits = {}
        self.seq = 0

    def drag(self, kind, a, b, seq):
        with self._lock:
            x, y = self._edits.get(kind, (0.0, 0.0))
            self._edits[kind] = (x + a, y + b)
            self.seq = max(self.seq, seq)

    def set(self, kind, value, seq=None):
        with self._lock:
            self._edits[kind] = value
            if seq is not None:
                self.seq = max(self.seq, seq)

    def take(self):
        with self._lock:
            edits, self._edits = self._edits, {}
            return edits, self.seq


def _render_loop(viewer_ref, renderer, pending, stop, acked):
    """The render thread: apply the newest edits, render, send the frame when the
    browser has shown the last one. Holds the viewer only weakly."""
    frames, started = 0, time.perf_counter()
    shown_at = []
    while not stop.is_set():
        edits, seq = pending.take()
        status = _apply(renderer, edits)
        viewer = viewer_ref()
        if viewer is None:
            return
        try:
            out = renderer.render()
        except Exception as e:  # noqa: BLE001 - shown in the panel, then the loop ends
            viewer.status = f"render failed: {e}"
            return
        frames += 1
        now = time.perf_counter()
        shown_at.append(now)
        shown_at = shown_at[-30:]
        if status:
            viewer.status = status
        if acked.is_set() or now - viewer._sent_at > _ACK_TIMEOUT_S:
            image, names = _compose(out, viewer.denoiser, viewer.split, viewer.split_position)
            data = _native.encode_image(image, viewer._format, viewer._quality)
            fps = (len(shown_at) - 1) / (shown_at[-1] - shown_at[0]) if len(shown_at) > 1 else 0.0
            acked.clear()
            viewer._sent_at = now
            viewer.send(
                {
                    "type": "frame",
                    "mime": "image/jpeg" if viewer._format == "jpeg" else "image/png",
                    "frame": renderer.frames_rendered,
                    "seq": seq,
                    "names": names,
                    "spp": renderer.spp,
                    "fps": round(fps, 2),
                    "seconds": round(now - started, 2),
                    "timings": {k: round(v, 3) for k, v in renderer.timings().items()},
                    "width": image.shape[1],
                    "height": image.shape[0],
                },
                buffers=[data],
            )
        del viewer


def _apply(renderer, edits):
    """Applies the browser's edits to the renderer; returns a status line for the
    panel when one is refused."""
    try:
        if "denoisers" in edits:
            left, right = edits["denoisers"]
            names = [left] + ([right] if right and right != left else [])
            if tuple(names) != renderer.denoisers:
                renderer.denoisers = names
        if "spp" in edits and edits["spp"] != renderer.spp:
            renderer.settings.spp = edits["spp"]
        if "preset" in edits:
            renderer.tf = edits["preset"]
        if "tf" in edits:
            renderer.tf = TransferFunction(edits["tf"], "edited")
        if edits.get("reset"):
            renderer.reset_camera()
        if edits.get("fit"):
            renderer.fit()
        if "orbit" in edits:
            renderer.orbit(*edits["orbit"])
        if "pan" in edits:
            renderer.pan(*edits["pan"])
        if "zoom" in edits:
            renderer.zoom(edits["zoom"][0])
    except (ValueError, TypeError) as e:
        return str(e)
    return ""


def _compose(out, left, right, position):
    """The shown image: the left denoiser's, and right of the split the other's, with a
    one-pixel line between."""
    a = out.get(left, out["noisy"])
    if not right or right not in out or right == left:
        return a, [left]
    w = a.shape[1]
    x = int(np.clip(round(w * float(position)), 1, w - 1))
    image = np.concatenate([a[:, :x], out[right][:, x:]], axis=1)
    image[:, x - 1] = 1.0
    return np.ascontiguousarray(image), [left, right]


def _native_names():
    return [n for n, _ in _native.denoiser_names()]


def _number(value, limit):
    """A finite number within ±limit from a message, else None (refused)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    value = float(value)
    if not math.isfinite(value) or abs(value) > limit:
        return None
    return value


def _seq(msg):
    seq = msg.get("seq", 0)
    return seq if isinstance(seq, int) and not isinstance(seq, bool) and seq >= 0 else 0


def _tf_points(value):
    """Control points from the page, as the engine checks them (it names any bad
    value); None when the shape is wrong."""
    if not isinstance(value, list) or not 1 <= len(value) <= _MAX_TF_POINTS:
        return None
    points = []
    for p in value:
        if not isinstance(p, dict):
            return None
        point = {}
        for key in ("density", "opacity"):
            x = _number(p.get(key), 1e6)
            if x is None:
                return None
            point[key] = x
        diffuse = p.get("diffuse", [1.0, 1.0, 1.0])
        if not isinstance(diffuse, list) or len(diffuse) != 3 or any(_number(c, 1e6) is None for c in diffuse):
            return None
        point["diffuse"] = [float(c) for c in diffuse]
        points.append(point)
    return points


def _interrupt(signum, frame, previous):
    for v in list(_live):
        v._stop.set()
    if callable(previous) and previous not in (signal.SIG_IGN, signal.SIG_DFL):
        previous(signum, frame)


def _install_interrupt():
    """Stops every viewer's render thread on SIGINT (a kernel interrupt). An idle
    IPython kernel ignores SIGINT and restores its saved handler after each cell, so the
    handler goes there; elsewhere it is installed directly, chaining to the one before."""
    global _interrupt_installed
    with _interrupt_lock:
        if _interrupt_installed or threading.current_thread() is not threading.main_thread():
            return
        kernel = None
        try:
            from IPython import get_ipython

            kernel = getattr(get_ipython(), "kernel", None)
        except ImportError:
            pass
        if kernel is not None and hasattr(kernel, "saved_sigint_handler"):
            previous = kernel.saved_sigint_handler
            kernel.saved_sigint_handler = lambda s, f: _interrupt(s, f, previous)
        else:
            previous = signal.getsignal(signal.SIGINT)
            signal.signal(signal.SIGINT, lambda s, f: _interrupt(s, f, previous))
        _interrupt_installed = True
