"""The channels of a multi-channel medium as a renderer shows them: each a live view
whose fields are edits (``r.channels[1].visible = False``)."""

from .live import FieldError
from .scene import TransferFunction

__all__ = ["Channel"]


class Channel:
    """Channel ``index`` of a renderer's medium: its ``name``, ``tf`` (a
    :class:`TransferFunction` over ``window``, or in data units), ``window`` (the data
    values the TF's 0–1 spans), ``data_window`` (the values at the channel's density 0
    and 1, fixed by its data), ``colour`` (RGB in [0, 1], tinting the TF) and
    ``visible``. Reading a field reads the renderer's current view; assigning one is an
    edit the next render re-traces, as a TF edit (``ValueError`` names a bad value)."""

    _FIELDS = ("name", "tf", "window", "data_window", "colour", "visible")

    def __init__(self, native, index):
        object.__setattr__(self, "_native", native)
        object.__setattr__(self, "_index", index)

    def _get(self):
        return self._native.channels()[self._index]

    @property
    def name(self) -> str:
        return self._get()["name"]

    @property
    def tf(self) -> TransferFunction:
        d = self._get()["tf"]
        return TransferFunction(d["point"], d.get("name", "tf"), d.get("units", "density"))

    @tf.setter
    def tf(self, tf):
        self._native.edit_channel(self._index, tf=TransferFunction.coerce(tf).to_dict())

    @property
    def window(self) -> tuple:
        return tuple(self._get()["window"])

    @window.setter
    def window(self, w):
        lo, hi = (float(x) for x in w)
        self._native.edit_channel(self._index, window=(lo, hi))

    @property
    def data_window(self) -> tuple:
        return tuple(self._get()["data_window"])

    @property
    def colour(self) -> tuple:
        return tuple(self._get()["colour"])

    @colour.setter
    def colour(self, c):
        r, g, b = (float(x) for x in c)
        self._native.edit_channel(self._index, colour=(r, g, b))

    color = colour

    @property
    def visible(self) -> bool:
        return self._get()["visible"]

    @visible.setter
    def visible(self, v):
        self._native.edit_channel(self._index, visible=bool(v))

    def __setattr__(self, name, value):
        if name == "color":
            name = "colour"
        if name not in ("tf", "window", "colour", "visible"):
            raise FieldError(
                f"channel {self._index} has no settable field {name!r} (fields: {', '.join(Channel._FIELDS)}; "
                "name and data_window are read-only)"
            )
        object.__setattr__(self, name, value)

    def __repr__(self):
        d = self._get()
        return f"Channel({self._index}, {d['name']!r}, visible={d['visible']}, colour={tuple(d['colour'])})"
