"""What :class:`dvr.Viewer`'s channels panel and time slider take and show, kept apart
from the widget: the page's channel, time and playback messages checked (a channel
index in range, a colour in [0, 1], a bool, a time within the series, a speed), the
channel edits and the time applied as edits of the renderer by the render thread, the
renderer's channels read as the panel shows them (the TF editor's points normalised
over the channel's window), and playback, which moves the renderer's time by the wall
clock between frames."""

import time

from .channels import Channel
from . import viewer_panel as panel
from .scene import TransferFunction

# Playback speeds the page may ask for, in time points per second.
MAX_SPEED = 100.0
# Playback moves the time by the wall clock between two frames, but by no more than
# this many seconds' worth in one frame: a pause of the render thread (a movie, a slow
# first frame) is not a jump.
_MAX_STEP_S = 0.25
# The editor's densities of a TF in data units are rounded to this many decimals, so an
# edit converted back to data units shows the same numbers again (nothing flickers).
_DIGITS = 6
_CHANNEL_FIELDS = {"visible", "colour", "tf", "preset"}


def channel_edit(msg, count, presets):
    """``(index, fields)`` from a ``{"type": "channel", "index", ...}`` message, its
    fields among ``visible`` (a bool), ``colour`` (three numbers in [0, 1]), ``tf``
    (control points as the editor has them: density 0–1 over the channel's window) and
    ``preset`` (a preset's name; ``tf`` and ``preset`` are both kept under ``"tf"``, so
    the newer wins); else the reason it is refused."""
    index = msg.get("index")
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < count:
        return f"index {index!r} is not a channel (0 to {count - 1})"
    unknown = set(msg) - _CHANNEL_FIELDS - {"type", "index", "seq"}
    if unknown:
        return f"unknown field(s) {', '.join(sorted(map(str, unknown)))}"
    fields = {}
    if "visible" in msg:
        if not isinstance(msg["visible"], bool):
            return f"visible {msg['visible']!r} is not true or false"
        fields["visible"] = msg["visible"]
    if "colour" in msg:
        c = msg["colour"]
        rgb = [panel.number(x, 1.0) for x in c] if isinstance(c, list) and len(c) == 3 else [None]
        if any(x is None or x < 0.0 for x in rgb):
            return f"colour {c!r} is not three numbers in [0, 1]"
        fields["colour"] = tuple(rgb)
    if "tf" in msg and "preset" in msg:
        return "a tf and a preset in one edit"
    if "tf" in msg:
        points = panel.tf_points(msg["tf"])
        if points is None:
            return "tf is not a list of control points"
        fields["tf"] = ("points", points)
    if "preset" in msg:
        if msg["preset"] not in presets:
            return f"preset {msg['preset']!r} is not one of the presets"
        fields["tf"] = ("preset", msg["preset"])
    if not fields:
        return f"nothing to edit (fields: {', '.join(sorted(_CHANNEL_FIELDS))})"
    return index, fields


def time_value(msg, times):
    """The time point a ``{"type": "time", "time"}`` message asks for (0 to
    ``times - 1``, fractional), else the reason it is refused."""
    if times < 2:
        return "this volume has one time point"
    t = panel.number(msg.get("time"), times - 1)
    if t is None or t < 0.0:
        return f"time {msg.get('time')!r} is not a number from 0 to {times - 1}"
    return t


def play_edit(msg):
    """``{"playing", "speed"}`` (either or both) from a ``{"type": "play"}`` message,
    else the reason it is refused."""
    edit = {}
    if "playing" in msg:
        if not isinstance(msg["playing"], bool):
            return f"playing {msg['playing']!r} is not true or false"
        edit["playing"] = msg["playing"]
    if "speed" in msg:
        speed = panel.number(msg["speed"], MAX_SPEED)
        if speed is None or speed <= 0.0:
            return f"speed {msg['speed']!r} is not a number of time points per second above 0, at most {MAX_SPEED:g}"
        edit["speed"] = speed
    return edit or "nothing to change (playing, speed)"


def read(renderer, channels, times):
    """``{"channels": the renderer's channel dicts, "time": its time}``, each only where
    the panel shows it (a medium of channels; a series of time points). The render
    thread reads it under its lock, with the frame."""
    out = {}
    if channels:
        out["channels"] = renderer._r.channels()
    if times > 1:
        out["time"] = renderer._r.time()[0]
    return out


def rows(channels):
    """The channels panel's rows: each channel's name, colour, visible, window and data
    window (what the TF editor's axis and histogram are placed by)."""
    return [
        {
            "name": c["name"],
            "colour": [float(x) for x in c["colour"]],
            "visible": bool(c["visible"]),
            "window": [float(x) for x in c["window"]],
            "data_window": [float(x) for x in c["data_window"]],
        }
        for c in channels
    ]


def editor_tf(channel):
    """``(points, name)`` of a channel's TF as the editor draws it: density 0–1 over the
    channel's window (a TF in data units is mapped there as the engine maps it)."""
    tf = channel["tf"]
    points = [dict(p) for p in tf["point"]]
    if tf.get("units") == "data":
        lo, hi = channel["window"]
        for p in points:
            p["density"] = round((p["density"] - lo) / (hi - lo), _DIGITS)
    return points, tf.get("name", "")


def apply(renderer, edits):
    """Applies the page's channel edits and time to the renderer (the render thread,
    before a frame). A TF edited in the editor keeps its channel's units: points of a TF
    in data units go back to data values over the channel's window. Raises what the
    renderer raises (``ValueError`` naming the field)."""
    for index, fields in sorted(edits.get("channels", {}).items()):
        channel = Channel(renderer._r, index)
        if "tf" in fields:
            kind, value = fields["tf"]
            if kind == "preset":
                channel.tf = value
            else:
                now = renderer._r.channels()[index]
                units = now["tf"].get("units", "density")
                if units == "data":
                    lo, hi = now["window"]
                    value = [dict(p, density=lo + p["density"] * (hi - lo)) for p in value]
                channel.tf = TransferFunction(value, "edited", units)
        if "colour" in fields:
            channel.colour = fields["colour"]
        if "visible" in fields:
            channel.visible = fields["visible"]
    if "time" in edits:
        renderer.time = edits["time"]


class Playback:
    """Plays a series: before each frame, moves the renderer's time on by ``speed``
    time points per second of wall clock since the frame before (at most
    ``_MAX_STEP_S`` worth), from wherever it is now (a time set from the page or a cell
    is where playback goes on from), looping after the last time point."""

    def __init__(self):
        self._last = None

    def step(self, renderer, times, playing, speed):
        """Called by the render thread before each frame, playing or not (so the first
        step of a playback is one frame's time, not the time since the last)."""
        now = time.perf_counter()
        last, self._last = self._last, now
        # (`speed` may have been set from Python: anything but a speed the page could
        # ask for plays nothing, rather than stopping the render thread.)
        speed = panel.number(speed, MAX_SPEED)
        if not playing or times < 2 or last is None or speed is None or speed <= 0.0:
            return
        span = times - 1
        renderer.time = (renderer.time + speed * min(now - last, _MAX_STEP_S)) % span


def on_message(viewer, kind, msg, seq):
    """A ``channel``, ``time`` or ``play`` message from the page (the kernel's message
    thread): checked here; a channel edit and a time go to the render thread's pending
    edits (each field's newest wins), playback to the viewer's ``playing`` and
    ``speed``. A refusal is said in the status line."""
    if kind == "channel":
        got = channel_edit(msg, viewer._n_channels, viewer.presets)
        if isinstance(got, str):
            viewer.status = f"refused a channel edit from the page: {got}"
            return
        viewer._pending.merge("channels", *got, seq)
    elif kind == "time":
        t = time_value(msg, viewer.times)
        if isinstance(t, str):
            viewer.status = f"refused a time from the page: {t}"
            return
        viewer._pending.set("time", t, seq)
    else:
        edit = play_edit(msg)
        if isinstance(edit, str):
            viewer.status = f"refused playback from the page: {edit}"
            viewer.send_state(["playing", "speed"])  # the page's boxes show the kernel's again
            return
        for name, value in edit.items():
            setattr(viewer, name, value)
