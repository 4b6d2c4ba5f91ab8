"""``dvr.Viewer``: a live renderer in a notebook cell (JupyterLab, Jupyter Notebook, VS
Code: anywhere ipywidgets render).

A thread renders the view for as long as the viewer is open: a still view keeps
refining. Each frame is tone-mapped and encoded (JPEG by default) and sent to the
browser only when the browser has shown the one before, so a lagging browser drops
frames instead of queueing them. Mouse drags, clicks (picks), the wheel and the panel
(TF editor, denoiser switch, split view, spp, channels, labels, time) come back as
messages; the thread applies the newest of them before its next frame (drags are
summed, never queued), as edits of the live :class:`dvr.Renderer`, which the temporal
denoisers reproject. The same renderer can be edited from other cells
(``v.renderer.lights[0].intensity = 30``) while the viewer runs.

The panel always shows the renderer's current state: the render thread compares the
renderer's TF, clip planes, crop box, spp, channels and labels with what the panel
shows after each frame and sends any change, whichever road it came by (the page,
another cell, a preset); each frame carries the time point it shows, which the time
slider follows.

The render thread stops when the viewer is closed (:meth:`Viewer.close`, or the
frontend closing its comm) or the kernel is interrupted while idle. A closed viewer
leaves its last frame in the cell's output as a PNG, so a saved notebook shows it.
"""

import base64
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
from . import viewer_capture as capture
from . import viewer_channels as series
from . import viewer_labels as labelling
from . import viewer_panel as panel
from .renderer import Renderer
from .scene import Scene, TransferFunction

__all__ = ["Viewer"]

_HERE = pathlib.Path(__file__).parent
# Drag and wheel amounts from the browser beyond these are refused (a drag of a
# million pixels is no drag); edits arrive as messages anyone on the page can send.
_MAX_DRAG = 10_000.0
_MAX_ZOOM = 100.0
# A frame not acknowledged for this long is taken as lost (the view was closed or
# reloaded), so the next one may go.
_ACK_TIMEOUT_S = 2.0

_live = weakref.WeakSet()
_interrupt_lock = threading.Lock()
_interrupt_installed = False


# What the page's "view" buttons may ask for (dvr.Renderer.view_from's sides).
_SIDES = tuple(Renderer.VIEWS)
# The raw path-traced input, offered beside the denoisers: the renderer always returns
# it (as "noisy"); a renderer asked for the engine's pass-through, "none", runs no
# denoiser at all (its `denoisers` is then empty).
NOISY = "noisy"


class Viewer(anywidget.AnyWidget):
    """A live view of ``source`` in the cell: a :class:`dvr.Renderer` (edited live by
    the viewer and by the caller), or anything :class:`dvr.Renderer` takes (a
    :class:`dvr.Scene`, a built-in scene name, a :class:`dvr.Volume`), rendered at
    ``size`` with ``denoisers`` (the first is shown; ``split`` names one to show on
    the right; ``"noisy"`` is the path tracer's raw input). ``format`` is ``"jpeg"``
    (with ``quality``) or ``"png"``. Captures from the page's buttons go to
    ``captures`` (a folder, made when first needed).

    Left drag orbits, right drag pans, the wheel zooms (the explorer's mouse). The
    panel edits the TF (the opacity curve over the density histogram, with a colour
    bar: drag a point, double-click to add one, shift-click to remove one; colour
    presets), picks the shown denoiser and a split view, sets spp (within the device's
    limit), resets, fits, and views from a patient side; adds clip planes and a crop
    box; takes a screenshot or an orbit movie; and shows the frame counter, frames per
    second, the latency of the last drag, the GPU ms per pass, the patient's sides at
    the view's edges and a scale bar in mm. A medium of several channels gets a
    channels panel (each channel's colour, whether it is shown, and which channel's TF
    the editor edits); a series of time points a time slider, with playback at
    ``speed`` time points per second (``playing``) moved on by the render thread; a
    renderer with a label map a labels panel (each label's colour, whether it is
    shown, its opacity; show all, hide all, and a search by name). A click in the image
    (a press and release without a drag) picks: the panel's readout shows the label
    and the intensity under the cursor (:meth:`dvr.Renderer.pick`; also ``picked``).
    """

    _esm = (_HERE / "viewer.js").read_text(encoding="utf-8")
    _css = (_HERE / "viewer.css").read_text(encoding="utf-8")

    # State the panel shows and edits (synced with the browser).
    denoiser = traitlets.Unicode("ours").tag(sync=True)
    split = traitlets.Unicode("").tag(sync=True)
    split_position = traitlets.Float(0.5).tag(sync=True)
    spp = traitlets.Int(1).tag(sync=True)
    max_spp = traitlets.Int(1).tag(sync=True)
    preset = traitlets.Unicode("").tag(sync=True)
    tf_points = traitlets.List().tag(sync=True)
    clip_planes = traitlets.List().tag(sync=True)
    crop_box = traitlets.Dict().tag(sync=True)
    status = traitlets.Unicode("").tag(sync=True)
    captures = traitlets.List().tag(sync=True)
    # The channels panel: each channel's name, colour, visible and windows (the
    # renderer's); which channel's TF the editor edits (the page's choice), and which
    # channel's TF its points are (-1: the renderer's one TF), set with them.
    channels = traitlets.List().tag(sync=True)
    channel = traitlets.Int(0).tag(sync=True)
    tf_channel = traitlets.Int(-1).tag(sync=True)
    # The labels panel (a renderer with a label map): each label's value, name, colour,
    # opacity and visible (the renderer's), and the map's mode ("tint" or "solid"; ""
    # without a map). `picked`: what lies under the pixel the page last clicked (see
    # viewer_labels.picked), for the readout.
    labels = traitlets.List().tag(sync=True)
    label_mode = traitlets.Unicode("").tag(sync=True)
    picked = traitlets.Dict().tag(sync=True)
    # Playback of a series: the render thread moves the time on while `playing`.
    playing = traitlets.Bool(False).tag(sync=True)
    speed = traitlets.Float(4.0).tag(sync=True)
    # Fixed for the viewer's life.
    times = traitlets.Int(1).tag(sync=True)
    methods = traitlets.List().tag(sync=True)
    presets = traitlets.List().tag(sync=True)
    sides = traitlets.List().tag(sync=True)
    histogram = traitlets.List().tag(sync=True)
    volume = traitlets.Dict().tag(sync=True)
    width = traitlets.Int(256).tag(sync=True)
    height = traitlets.Int(256).tag(sync=True)

    def __init__(self, source, size=(256, 256), denoisers=("ours",), split=None, format="jpeg", quality=85,
                 captures="dvr-captures", **kwargs):
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
            shown = [NOISY if d == "none" else d for d in renderer.denoisers] or [NOISY]
        else:
            if not isinstance(source, (Scene, str)):
                source = Scene(source)
            names = _run_names(denoisers[0], split or "") + [d for d in denoisers[1:] if d != NOISY]
            renderer, self._owns = Renderer(source, size=size, denoisers=list(dict.fromkeys(names)) or ["none"], **kwargs), True
            shown = denoisers
        try:
            counts = renderer.histogram().astype(np.float64)
            info = panel.volume_info(renderer)
            limit = panel.spp_limit(renderer)
            n_channels, times = len(renderer._r.channels()), renderer.times
            mode, label_rows = renderer._r.labels()
        except BaseException:
            if self._owns:
                renderer.close()  # made here: its device memory goes now, not at GC
            raise
        super().__init__(
            denoiser=shown[0],
            split=split or "",
            spp=renderer.spp,
            max_spp=limit or renderer.spp,
            methods=[NOISY] + sorted(n for n in _native_names() if n != "none"),
            presets=TransferFunction.presets(),
            sides=list(_SIDES),
            histogram=[round(float(math.log1p(c) / math.log1p(counts.max())), 4) if counts.max() > 0 else 0.0 for c in counts],
            volume=info or {},
            width=renderer.size[0],
            height=renderer.size[1],
            times=times,
            label_mode=mode or "",
        )
        self.renderer = renderer
        self._format, self._quality = format, quality
        self._capture_dir = pathlib.Path(captures)
        self._pending = _Pending()
        # The split's method may not run yet on a renderer handed in.
        self._pending.set("denoisers", (self.denoiser, self.split))
        # Trait changes made by the kernel to show the renderer's state are not edits
        # to send back (a thread-local flag: the page's changes come on another thread).
        self._local = threading.local()
        self._shown = {}  # what the panel shows of the renderer's state, as last synced
        self._n_channels = n_channels
        # The map's label values are fixed for the renderer's life: the page's edits are
        # checked against them.
        self._label_values = frozenset(d["value"] for d in label_rows) if mode else frozenset()
        self._sync(renderer._r.view(), renderer._r.tf(), self._read(renderer))
        if limit is None:
            self.status = "the engine did not say its spp limit: the box keeps the renderer's spp"
        self._stop = threading.Event()
        self._acked = threading.Event()
        self._acked.set()
        self._sent_at = 0.0
        # Held by the render thread for each frame and by a movie for all of its frames,
        # so a movie's frames are the only ones rendered while it runs.
        self._render_lock = threading.Lock()
        self._last = None  # (frame number, composed image) of the newest frame
        self._display_id = None
        self.on_msg(self._on_message)
        if self.comm is not None:
            self.comm.on_close(lambda _msg: self.close())
        self.observe(self._on_state, names=["denoiser", "split", "spp", "preset", "tf_points", "clip_planes", "crop_box", "channel"])
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
        widget; the cell's output keeps the last frame as a PNG. Safe on a viewer whose
        construction failed part way (the widget's finaliser calls it)."""
        stop, thread = getattr(self, "_stop", None), getattr(self, "_thread", None)
        if stop is not None:
            stop.set()
        if thread is not None and thread.is_alive() and threading.current_thread() is not thread:
            thread.join(timeout=60)
        self._leave_last_frame()
        if getattr(self, "_owns", False) and getattr(self, "renderer", None) is not None:
            self.renderer.close()
            self.renderer = None
        _live.discard(self)
        super().close()

    # Captures.

    def screenshot(self, path=None):
        """Writes the frame the viewer shows (split view and all) as a lossless PNG at
        the render size, tone-mapped as the eval's PNGs; returns its path (default: a
        new file in the captures folder)."""
        frame, image = self._frame()
        path = pathlib.Path(path) if path is not None else self._capture_dir / f"dvr-frame-{frame:06d}.png"
        capture.write_png(image, path)
        self._captured("screenshot", path)
        return path

    def movie(self, path=None, frames=60, degrees=360.0, fps=30):
        """Renders an orbit of ``degrees`` about the camera's up axis in ``frames``
        frames (the shown denoiser, split view and all) and writes it as an MP4 at
        ``fps``; returns its path. The live view pauses meanwhile, and the camera comes
        back to where it was."""
        if isinstance(frames, bool) or not isinstance(frames, int) or not 2 <= frames <= 10_000:
            raise ValueError(f"frames={frames!r}: must be a whole number from 2 to 10000")
        degrees = panel.number(degrees, 36_000)
        if degrees is None:
            raise ValueError("degrees: must be a finite number (at most 100 turns)")
        r = self._renderer()
        path = pathlib.Path(path) if path is not None else self._capture_dir / f"dvr-orbit-{r.frames_rendered:06d}.mp4"
        with self._render_lock:
            start = r.camera.to_dict()
            movie = capture.Movie(path, fps)
            try:
                for i, cam in enumerate(capture.orbit_cameras(start, frames, degrees)):
                    r.camera = cam
                    image, _ = _compose(r.render(), self.denoiser, self.split, self.split_position)
                    movie.add(image)
                    if i % 10 == 0:
                        self.status = f"movie: frame {i + 1} of {frames}"
                movie.finish()
            except BaseException:
                movie.abort()
                raise
            finally:
                r.camera = start
        self.status = ""
        self._captured("movie", path)
        return path

    def _renderer(self):
        if self.renderer is None or self.renderer.closed:
            raise RuntimeError("this viewer is closed")
        return self.renderer

    def _frame(self):
        """The newest shown frame (rendering one when none has been yet)."""
        if self._last is None:
            r = self._renderer()
            with self._render_lock:
                image, _ = _compose(r.render(), self.denoiser, self.split, self.split_position)
            return r.frames_rendered, image
        return self._last

    def _captured(self, kind, path):
        """Lists a capture in the panel and sends its bytes for the page's download
        link (a movie only when small enough for one message)."""
        path = pathlib.Path(path).resolve()
        # The bytes first: the page lists the capture with its link in one go.
        if path.stat().st_size <= 32 << 20:
            mime = "image/png" if kind == "screenshot" else "video/mp4"
            self.send({"type": "capture", "kind": kind, "path": str(path), "name": path.name, "mime": mime},
                      buffers=[path.read_bytes()])
        self.captures = self.captures + [{"kind": kind, "path": str(path)}]

    # The cell's output: the widget, and its last frame once closed.

    def _ipython_display_(self):
        from IPython.display import display

        if self._display_id is None:
            self._display_id = f"dvr-viewer-{id(self):x}-{time.monotonic_ns():x}"
        bundle = self._repr_mimebundle_()
        # ipywidgets hands back (data, metadata); older versions the data alone.
        data, metadata = bundle if isinstance(bundle, tuple) else (bundle, {})
        display(data, metadata=metadata, raw=True, display_id=self._display_id)

    def _leave_last_frame(self):
        """Replaces the widget in the cell's output with its last frame as a PNG (the
        widget's view goes with its model), so the notebook keeps what was seen."""
        last, display_id = getattr(self, "_last", None), getattr(self, "_display_id", None)
        if last is None or display_id is None:
            return
        self._display_id = None  # once: a second close (the finaliser's) leaves it be
        try:
            from IPython.display import update_display

            png = _native.encode_image(last[1], "png")
            h, w = last[1].shape[:2]
            update_display(
                {"image/png": base64.b64encode(png).decode("ascii"),
                 "text/plain": f"dvr.Viewer (closed): frame {last[0]}, {w}x{h}"},
                raw=True, display_id=display_id,
            )
        except Exception as e:  # noqa: BLE001 - closing must not fail for the picture
            self.status = f"could not leave the last frame: {e}"

    # Browser to kernel.

    def _on_message(self, _widget, msg, _buffers):
        if not isinstance(msg, dict):
            self.status = "refused a message from the page (not an object)"
            return
        kind = msg.get("type")
        if kind == "ack":
            self._acked.set()
        elif kind in ("orbit", "pan"):
            dx, dy = panel.number(msg.get("dx"), _MAX_DRAG), panel.number(msg.get("dy"), _MAX_DRAG)
            if dx is None or dy is None:
                self.status = f"refused a {kind} from the page (dx, dy: numbers within ±{_MAX_DRAG:g})"
                return
            self._pending.drag(kind, dx, dy, _seq(msg))
        elif kind == "zoom":
            steps = panel.number(msg.get("steps"), _MAX_ZOOM)
            if steps is None:
                self.status = f"refused a zoom from the page (steps: a number within ±{_MAX_ZOOM:g})"
                return
            self._pending.drag("zoom", steps, 0.0, _seq(msg))
        elif kind in ("reset", "fit"):
            self._pending.set(kind, True, _seq(msg))
        elif kind == "view":
            if msg.get("side") not in _SIDES:
                self.status = f"refused a view from the page: side {msg.get('side')!r} is not one of {', '.join(_SIDES)}"
                return
            self._pending.set("view", msg["side"], _seq(msg))
        elif kind in ("channel", "time", "play"):
            series.on_message(self, kind, msg, _seq(msg))
        elif kind in ("label", "labels", "pick"):
            labelling.on_message(self, kind, msg, _seq(msg))
        elif kind in ("screenshot", "movie"):
            # Off the kernel's message thread: a movie takes seconds to minutes.
            threading.Thread(target=self._capture_from_page, args=(kind,), name=f"dvr-{kind}", daemon=True).start()
        else:
            self.status = f"refused a message from the page: unknown type {kind!r}"

    def _capture_from_page(self, kind):
        try:
            path = self.screenshot() if kind == "screenshot" else self.movie()
            self.status = f"{kind} saved: {path}"
        except Exception as e:  # noqa: BLE001 - shown in the panel
            self.status = f"{kind} failed: {e}"

    def _on_state(self, change):
        if getattr(self._local, "syncing", False):
            return
        name, value = change["name"], change["new"]
        if name == "tf_points":
            points = panel.tf_points(value)
            if points is None:
                self.status = "refused a transfer function from the page (not a list of control points)"
                self._shown.pop("tf", None)  # the panel shows the renderer's again
                return
            if self._n_channels:  # the points shown are tf_channel's
                self._pending.merge("channels", self.tf_channel, {"tf": ("points", points)})
            else:
                self._pending.set("tf", points)
        elif name == "preset":
            if value in self.presets and self._n_channels:
                self._pending.merge("channels", self.tf_channel, {"tf": ("preset", value)})
            elif value in self.presets:
                self._pending.set("preset", value)
        elif name == "channel":
            if not 0 <= value < max(1, self._n_channels):
                self.status = f"channel {value!r} refused: the volume has {self._n_channels} channel(s)"
                self._local.syncing = True
                try:
                    self.channel = change["old"]
                finally:
                    self._local.syncing = False
        elif name in ("denoiser", "split"):
            if value and value not in self.methods:
                self.status = f"unknown denoiser {value!r}"
                return
            self._pending.set("denoisers", (self.denoiser, self.split))
        elif name == "spp":
            if isinstance(value, int) and 1 <= value <= self.max_spp:
                self._pending.set("spp", value)
            else:
                self.status = f"spp {value!r} refused: this renderer takes 1 to {self.max_spp} samples per pixel per frame"
                self._shown.pop("spp", None)
        elif name == "clip_planes":
            planes = panel.clip_planes(value)
            if planes is None:
                self.status = f"refused clip planes from the page (at most {panel.MAX_CLIP_PLANES}, each a point and a non-zero normal)"
                self._shown.pop("clip", None)
                return
            self._pending.set("clip", planes)
        elif name == "crop_box":
            box = panel.crop_box(value)
            if box is None:
                self.status = "refused a crop box from the page (min < max per axis, within -0.5 to 0.5)"
                self._shown.pop("crop", None)
                return
            self._pending.set("crop", box)

    # Kernel to browser.

    def _read(self, renderer):
        """What the panel shows beyond the view and TF: :func:`viewer_channels.read`'s
        and :func:`viewer_labels.read`'s (the render thread calls it under its lock)."""
        extra = series.read(renderer, self._n_channels, self.times)
        extra.update(labelling.read(renderer, bool(self._label_values)))
        return extra

    def _sync(self, view, tf, extra):
        """Shows the renderer's TF (or the chosen channel's), clip planes, crop box, spp,
        channels and labels in the panel where they differ from what it shows (whoever
        changed them). `extra` is :meth:`_read`'s."""
        a = tf["a"]
        state = {
            "tf": (-1, a["point"], a.get("name", "")),
            "clip": [{"point": c["point"], "normal": c["normal"], "enabled": c.get("enabled", True)} for c in view.get("clip", [])],
            "crop": view.get("crop") or {},
            "spp": view.get("render", {}).get("spp", self.spp),
        }
        if "channels" in extra:
            # With channels, the renderer's one TF is not drawn: each channel has its own.
            index = min(max(self.channel, 0), len(extra["channels"]) - 1)
            state["channels"] = series.rows(extra["channels"])
            state["tf"] = (index, *series.editor_tf(extra["channels"][index]))
        if "labels" in extra:
            state["labels"] = extra["labels"]
        changed = {k: v for k, v in state.items() if self._shown.get(k) != v}
        if not changed:
            return
        # (No hold_sync here: its flag is the widget's, shared with the kernel's thread
        # applying the page's changes; each trait goes in a message of its own.)
        self._local.syncing = True
        try:
            if "tf" in changed:
                index, points, name = changed["tf"]
                self.tf_channel = index
                self._show("tf_points", [dict(p) for p in points])
                self.preset = name if name in self.presets else ""
            if "channels" in changed:
                self._show("channels", changed["channels"])
            if "labels" in changed:
                self._show("labels", changed["labels"])
            if "clip" in changed:
                self.clip_planes = changed["clip"]
            if "crop" in changed:
                crop = changed["crop"]
                if crop.get("units", "box") == "box":
                    self.crop_box = {k: crop[k] for k in ("min", "max", "enabled") if k in crop}
                else:
                    # The sliders are in the box's units; a crop in voxels stays Python's.
                    self.crop_box = {}
                    self.status = "the crop box is in voxels: the sliders show none (edit it from Python, or move one to replace it)"
            if "spp" in changed:
                self.spp = changed["spp"]
        finally:
            self._local.syncing = False
        self._shown.update(changed)

    def _show(self, name, value):
        """Sets a trait the panel shows; one already holding `value` is sent again, since
        the page may show its own refused edit (a channel edit comes as a message, which
        leaves the kernel's trait as it was)."""
        if getattr(self, name) == value:
            self.send_state(name)
        else:
            setattr(self, name, value)


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

    def edit(self, kind, change, seq=None):
        """Changes the pending edits of `kind` (a dict, made if none) in place with
        `change`, under the lock: for an edit that supersedes some of those before it."""
        with self._lock:
            change(self._edits.setdefault(kind, {}))
            if seq is not None:
                self.seq = max(self.seq, seq)

    def merge(self, kind, key, fields, seq=None):
        """Edits of one item of `kind` (a channel, by index), field by field: each field
        keeps its newest value."""
        with self._lock:
            self._edits.setdefault(kind, {}).setdefault(key, {}).update(fields)
            if seq is not None:
                self.seq = max(self.seq, seq)

    def take(self):
        with self._lock:
            edits, self._edits = self._edits, {}
            return edits, self.seq


def _render_loop(viewer_ref, renderer, pending, stop, acked):
    """The render thread: apply the newest edits, render, show the renderer's state in
    the panel, send the frame when the browser has shown the last one. Holds the viewer
    only weakly."""
    frames, started = 0, time.perf_counter()
    shown_at = []
    playback = series.Playback()
    while not stop.is_set():
        viewer = viewer_ref()
        if viewer is None:
            return
        with viewer._render_lock:
            if stop.is_set():
                return
            edits, seq = pending.take()
            status = _apply(renderer, edits)
            # A pick renders a frame of the view as edited, before the shown one.
            answer = labelling.pick(renderer, edits["pick"]) if "pick" in edits else None
            try:
                playback.step(renderer, viewer.times, viewer.playing, viewer.speed)
                out = renderer.render()
                view, tf = renderer._r.view(), renderer._r.tf()
                extra = viewer._read(renderer)
            except Exception as e:  # noqa: BLE001 - shown in the panel, then the loop ends
                viewer.status = f"render failed: {e}"
                return
        frames += 1
        now = time.perf_counter()
        shown_at.append(now)
        shown_at = shown_at[-30:]
        if status:
            viewer.status = status
            # A refused edit leaves the panel showing it: show the renderer's again.
            viewer._shown.clear()
        if isinstance(answer, str):
            viewer.status = answer
        elif answer is not None:
            viewer.picked = answer
        try:
            viewer._sync(view, tf, extra)
            image, names = _compose(out, viewer.denoiser, viewer.split, viewer.split_position)
            viewer._last = (renderer.frames_rendered, image)
            if acked.is_set() or now - viewer._sent_at > _ACK_TIMEOUT_S:
                _send_frame(viewer, renderer, image, names, view["camera"], extra.get("time"), seq, shown_at, now - started)
                acked.clear()
                viewer._sent_at = now
        except Exception as e:  # noqa: BLE001 - a frame lost is said, the loop goes on
            viewer.status = f"frame not sent: {e}"
        del viewer


def _send_frame(viewer, renderer, image, names, camera, time_point, seq, shown_at, seconds):
    data = _native.encode_image(image, viewer._format, viewer._quality)
    fps = (len(shown_at) - 1) / (shown_at[-1] - shown_at[0]) if len(shown_at) > 1 else 0.0
    physical = viewer.volume.get("physical")
    viewer.send(
        {
            "type": "frame",
            "mime": "image/jpeg" if viewer._format == "jpeg" else "image/png",
            "frame": renderer.frames_rendered,
            "seq": seq,
            "names": names,
            "spp": renderer.spp,
            "fps": round(fps, 2),
            "seconds": round(seconds, 2),
            "timings": {k: round(v, 3) for k, v in renderer.timings().items()},
            "width": image.shape[1],
            "height": image.shape[0],
            "orientation": panel.orientation(camera),
            # No bar where the volume's physical size is unknown (never a wrong one).
            "scale": panel.scale_bar(camera, image.shape[0], image.shape[1], physical) if physical else None,
            # The time point shown (a series; None otherwise): the time slider follows it.
            "time": time_point,
        },
        buffers=[data],
    )


def _run_names(left, right):
    """The denoisers a renderer runs to show `left` and `right`: "noisy" needs none (the
    renderer always returns its input)."""
    return [n for n in dict.fromkeys((left, right)) if n and n != NOISY]


def _apply(renderer, edits):
    """Applies the browser's edits to the renderer; returns a status line for the
    panel when one is refused."""
    try:
        if "denoisers" in edits:
            names = _run_names(*edits["denoisers"])
            if tuple(names) != renderer.denoisers:
                renderer.denoisers = names or ["none"]
        if "spp" in edits and edits["spp"] != renderer.spp:
            renderer.settings.spp = edits["spp"]
        if "preset" in edits:
            renderer.tf = edits["preset"]
        if "tf" in edits:
            renderer.tf = TransferFunction(edits["tf"], "edited")
        if "clip" in edits:
            renderer.clip = edits["clip"]
        if "crop" in edits:
            renderer.crop = edits["crop"] or None
        if edits.get("reset"):
            _reset_camera(renderer)
        if edits.get("fit"):
            renderer.fit()
        if "view" in edits:
            renderer.view_from(edits["view"])
        if "orbit" in edits:
            renderer.orbit_pixels(*edits["orbit"])
        if "pan" in edits:
            renderer.pan(*edits["pan"])
        if "zoom" in edits:
            renderer.zoom(edits["zoom"][0])
        # Last: a refused channel or label edit loses no camera move of the same frame.
        series.apply(renderer, edits)
        labelling.apply(renderer, edits)
    except (ValueError, TypeError, RuntimeError) as e:
        return str(e)
    return ""


def _reset_camera(renderer):
    """The engine's reset (its orbit camera's home: target, distance, yaw, pitch, field
    of view), then the scene's up vector where the view had another: the engine keeps
    the current up through a reset, so after a superior or inferior view its reset
    alone would not be the starting view."""
    renderer.reset_camera()
    home = renderer.scene.data.get("camera") if hasattr(renderer.scene, "data") else None
    if home and "up" in home and not np.allclose(renderer.camera.up, home["up"]):
        renderer.camera = dict(renderer.camera.to_dict(), **home)


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


def _seq(msg):
    seq = msg.get("seq", 0)
    return seq if isinstance(seq, int) and not isinstance(seq, bool) and seq >= 0 else 0


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
