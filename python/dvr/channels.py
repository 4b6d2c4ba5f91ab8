"""The channels of a multi-channel medium as a renderer shows them: each a live view
whose fields are edits (``r.channels[1].visible = False``)."""

from .live import _Item, _rgb, item_field
from .scene import TransferFunction

__all__ = ["Channel"]


def _pair(w):
    lo, hi = (float(x) for x in w)
    return (lo, hi)


class Channel(_Item):
    """Channel ``index`` of a renderer's medium: its ``name``, ``tf`` (a
    :class:`TransferFunction` over ``window``, or in data units), ``window`` (the data
    values the TF's 0–1 spans), ``data_window`` (the values at the channel's density 0
    and 1, fixed by its data), ``colour`` (RGB in [0, 1], tinting the TF) and
    ``visible``. Reading a field reads the renderer's current view; assigning one is an
    edit the next render re-traces, as a TF edit (``ValueError`` names a bad value)."""

    _FIELDS = ("name", "tf", "window", "data_window", "colour", "visible")
    _SETTABLE = ("tf", "window", "colour", "visible")

    def __init__(self, native, index):
        object.__setattr__(self, "_native", native)
        object.__setattr__(self, "_index", index)

    def _get(self):
        return self._native.channels()[self._index]

    def _edit(self, **change):
        self._native.edit_channel(self._index, **change)

    def _what(self):
        return f"channel {self._index}"

    name = item_field("name")
    window = item_field("window", lambda w: _pair(w), tuple)
    data_window = item_field("data_window", read=tuple)
    colour = item_field("colour", _rgb, tuple)
    color = colour
    visible = item_field("visible", bool)

    @property
    def tf(self) -> TransferFunction:
        d = self._get()["tf"]
        return TransferFunction(d["point"], d.get("name", "tf"), d.get("units", "density"))

    @tf.setter
    def tf(self, tf):
        self._edit(tf=TransferFunction.coerce(tf).to_dict())

    def __repr__(self):
        d = self._get()
        return f"Channel({self._index}, {d['name']!r}, visible={d['visible']}, colour={tuple(d['colour'])})"
